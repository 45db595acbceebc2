//! `kdw_engines_step`: many engines in one call, for hosts without a job system.

use std::collections::HashSet;

use super::engine::kdw_engine;
use super::guard::{EngineBox, guard, poison_all, read, slice};
use super::status::{FfiError, KDW_STATUS_INVALID_ARGUMENT, KDW_STATUS_NULL_POINTER, KDW_STATUS_PANIC, kdw_status};
use super::types::{kdw_transform, kdw_vec3};
use crate::core::{Engine, Transform, step_engines};

/// Steps `count` distinct engines by `dt` with one camera, engine i with its view reference
/// `view_references[i]` (as `kdw_engine_step` each). Built with the `parallel` feature, the engines are
/// stepped on a small thread pool; otherwise one after the other (the Unity package ships without it:
/// Unity hosts step from their own jobs). Every handle and input is checked before any engine moves: a NULL
/// (`KDW_STATUS_NULL_POINTER`), poisoned (`KDW_STATUS_PANIC`) or repeated (`KDW_STATUS_INVALID_ARGUMENT`)
/// handle, or any bad input, fails the whole call and changes nothing. A panic while
/// stepping poisons every engine of the call.
#[unsafe(no_mangle)]
pub extern "C" fn kdw_engines_step(
    engines: *const *mut kdw_engine,
    count: u32,
    dt: f32,
    camera_position: *const kdw_vec3,
    view_references: *const kdw_transform,
) -> kdw_status {
    guard(|| {
        // SAFETY: the caller passes `count` readable handles.
        let handles = unsafe { slice(engines, count, "engines") }?;
        // SAFETY: the caller passes a readable kdw_vec3.
        let camera = unsafe { read(camera_position, "camera_position") }?;
        // SAFETY: the caller passes `count` readable transforms.
        let references = unsafe { slice(view_references, count, "view_references") }?;
        let mut seen = HashSet::with_capacity(handles.len());
        for (i, handle) in handles.iter().enumerate() {
            if handle.is_null() || !handle.is_aligned() {
                return Err(FfiError::new(KDW_STATUS_NULL_POINTER, format!("engines[{i}] is NULL or misaligned")));
            }
            if !seen.insert(*handle) {
                let message = format!("engines[{i}] repeats an earlier handle: each engine may be stepped once");
                return Err(FfiError::new(KDW_STATUS_INVALID_ARGUMENT, message));
            }
        }
        // SAFETY: non-NULL, aligned and pairwise distinct live handles (checked above; liveness is the
        // caller's contract), so the exclusive references do not alias.
        let mut boxes: Vec<&mut EngineBox> = handles.iter().map(|&h| unsafe { &mut *h.cast::<EngineBox>() }).collect();
        if let Some(i) = boxes.iter().position(|b| b.poisoned) {
            let message = format!("engines[{i}] was poisoned by an earlier internal error; destroy it");
            return Err(FfiError::new(KDW_STATUS_PANIC, message));
        }
        let references: Vec<Transform> = references.iter().map(|t| Transform::from(*t)).collect();
        let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            let mut engines: Vec<&mut Engine> = boxes.iter_mut().map(|b| &mut b.engine).collect();
            step_engines(&mut engines, dt, (*camera).into(), &references)
        }));
        match result {
            Ok(stepped) => Ok(stepped?),
            Err(payload) => {
                poison_all(&mut boxes);
                std::panic::resume_unwind(payload)
            }
        }
    })
}
