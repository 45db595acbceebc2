//! `kdw_engines_step`: many engines in one call, for hosts without a job system.

use super::engine::kdw_engine;
use super::guard::{EngineBox, guard, read, slice};
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
        SCRATCH.with_borrow_mut(|scratch| {
            let BatchScratch { sorted, engines, references: converted } = scratch;
            for (i, handle) in handles.iter().enumerate() {
                if handle.is_null() || !handle.cast::<EngineBox>().is_aligned() {
                    let message = format!("engines[{i}] is NULL or misaligned");
                    return Err(FfiError::new(KDW_STATUS_NULL_POINTER, message));
                }
            }
            sorted.clear();
            sorted.extend(handles.iter().map(|h| *h as usize));
            sorted.sort_unstable();
            if let Some(pair) = sorted.windows(2).find(|w| w[0] == w[1]) {
                let i = handles.iter().rposition(|h| *h as usize == pair[0]).expect("from the list");
                let message = format!("engines[{i}] repeats an earlier handle: each engine may be stepped once");
                return Err(FfiError::new(KDW_STATUS_INVALID_ARGUMENT, message));
            }
            for (i, &handle) in handles.iter().enumerate() {
                // SAFETY: non-NULL, aligned, live (the caller's contract); read only.
                if unsafe { (*handle.cast::<EngineBox>()).poisoned } {
                    let message = format!("engines[{i}] was poisoned by an earlier internal error; destroy it");
                    return Err(FfiError::new(KDW_STATUS_PANIC, message));
                }
            }
            converted.clear();
            converted.extend(references.iter().map(|t| Transform::from(*t)));
            engines.clear();
            // SAFETY: pairwise distinct (checked above), live EngineBoxes; the pointers are used only during
            // this call, while the caller guarantees no other use of these engines.
            engines.extend(handles.iter().map(|&h| unsafe { &raw mut (*h.cast::<EngineBox>()).engine }));
            // SAFETY: `*mut Engine` and `&mut Engine` have the same layout; every pointer is valid, distinct and
            // exclusively ours for the lifetime of this slice (see above).
            let exclusive: &mut [&mut Engine] =
                unsafe { std::slice::from_raw_parts_mut(engines.as_mut_ptr().cast::<&mut Engine>(), engines.len()) };
            let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                step_engines(exclusive, dt, (*camera).into(), converted)
            }));
            match result {
                Ok(stepped) => Ok(stepped?),
                Err(payload) => {
                    for &handle in handles {
                        // SAFETY: as above; the step that panicked has unwound, nothing else holds the engine.
                        unsafe { (*handle.cast::<EngineBox>()).poisoned = true };
                    }
                    std::panic::resume_unwind(payload)
                }
            }
        })
    })
}

/// Buffers of the batch call, reused so that a frame allocates nothing once they have grown.
#[derive(Default)]
struct BatchScratch {
    sorted: Vec<usize>,
    engines: Vec<*mut Engine>,
    references: Vec<Transform>,
}

thread_local! {
    static SCRATCH: std::cell::RefCell<BatchScratch> = std::cell::RefCell::new(BatchScratch::default());
}
