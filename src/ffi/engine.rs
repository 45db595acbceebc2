//! `kdw_engine`: create, configure, step, read back.

use super::guard::{
    check_out, check_struct_size, destroy_handle, fill, guard, into_handle, query, read, slice, slice_mut,
    with_engine_mut, write,
};
use super::status::{KDW_STATUS_OK, kdw_status};
use super::types::{
    kdw_chain_id, kdw_engine_def, kdw_engine_stats, kdw_quat, kdw_transform, kdw_vec3, solver_code, solver_from_code,
};
use crate::core::{Engine, EngineSettings, Transform};

/// One per character: owns chains and view shapes, gravity and solver settings. Opaque.
pub struct kdw_engine {
    _private: [u8; 0],
}

/// Default engine settings (240 Hz substeps, 2 iterations, gravity -9.81 on y, ...).
#[unsafe(no_mangle)]
pub extern "C" fn kdw_engine_def_default() -> kdw_engine_def {
    EngineSettings::default().into()
}

/// Creates an engine. `*out_engine` receives it; destroy it with `kdw_engine_destroy`.
#[unsafe(no_mangle)]
pub extern "C" fn kdw_engine_create(def: *const kdw_engine_def, out_engine: *mut *mut kdw_engine) -> kdw_status {
    guard(|| {
        check_out(out_engine, "out_engine")?;
        // SAFETY: the caller passes a readable kdw_engine_def (NULL and alignment are checked).
        let def = unsafe { read(def, "def") }?;
        check_struct_size::<kdw_engine_def>(def.struct_size, "kdw_engine_def")?;
        let engine = Engine::new(EngineSettings::try_from(def)?)?;
        // SAFETY: checked by check_out; the caller provides a writable pointer slot.
        unsafe { write(out_engine, into_handle(engine)) };
        Ok(())
    })
}

/// Destroys an engine and everything it owns. Every id of it becomes invalid. NULL is a no-op (like
/// `free(NULL)`), so cleanup paths need no check.
#[unsafe(no_mangle)]
pub extern "C" fn kdw_engine_destroy(engine: *mut kdw_engine) -> kdw_status {
    if engine.is_null() {
        return KDW_STATUS_OK;
    }
    // SAFETY: the caller passes a pointer from kdw_engine_create that it no longer uses afterwards.
    guard(|| unsafe { destroy_handle(engine) })
}

/// Reads the engine's current settings.
#[unsafe(no_mangle)]
pub extern "C" fn kdw_engine_get_def(engine: *const kdw_engine, out_def: *mut kdw_engine_def) -> kdw_status {
    query(engine, out_def, "out_def", |e| Ok((*e.settings()).into()))
}

/// Replaces all settings at once (validated as a whole; nothing changes on error).
#[unsafe(no_mangle)]
pub extern "C" fn kdw_engine_set_def(engine: *mut kdw_engine, def: *const kdw_engine_def) -> kdw_status {
    guard(|| {
        // SAFETY: the caller passes a readable kdw_engine_def.
        let def = unsafe { read(def, "def") }?;
        check_struct_size::<kdw_engine_def>(def.struct_size, "kdw_engine_def")?;
        let settings = EngineSettings::try_from(def)?;
        // SAFETY: `engine` is a live engine handle used by this thread only.
        unsafe { with_engine_mut(engine, |e| Ok(e.set_settings(settings)?)) }
    })
}

/// Sets world gravity, m/s².
#[unsafe(no_mangle)]
pub extern "C" fn kdw_engine_set_gravity(engine: *mut kdw_engine, gravity: *const kdw_vec3) -> kdw_status {
    guard(|| {
        // SAFETY: the caller passes a readable kdw_vec3.
        let gravity = unsafe { read(gravity, "gravity") }?;
        // SAFETY: live engine handle, this thread only.
        unsafe { with_engine_mut(engine, |e| Ok(e.set_gravity((*gravity).into())?)) }
    })
}

/// Selects the solver for the engine's chains: `KDW_SOLVER_LANES` (the default),
/// `KDW_SOLVER_LANES_PORTABLE` or `KDW_SOLVER_SCALAR`. They agree up to float rounding; the choice is part of
/// `kdw_engine_state_hash`. Any other value is rejected with `KDW_STATUS_INVALID_ARGUMENT` and changes nothing.
#[unsafe(no_mangle)]
pub extern "C" fn kdw_engine_set_solver(engine: *mut kdw_engine, solver: u32) -> kdw_status {
    guard(|| {
        let solver = solver_from_code(solver)?;
        // SAFETY: live engine handle, this thread only.
        unsafe {
            with_engine_mut(engine, |e| {
                e.set_solver(solver);
                Ok(())
            })
        }
    })
}

/// The engine's solver: one of `KDW_SOLVER_*`.
#[unsafe(no_mangle)]
pub extern "C" fn kdw_engine_get_solver(engine: *const kdw_engine, out_solver: *mut u32) -> kdw_status {
    query(engine, out_solver, "out_solver", |e| Ok(solver_code(e.solver())))
}

/// Advances every chain by `dt` seconds (scaled by the time scale) in fixed internal steps. `camera_position`
/// and `view_reference` (the joint K the view direction is measured from; also the anchor of chains with
/// `KDW_ANCHOR_VIEW_REFERENCE`) are in world space. `dt` must be finite and >= 0; `dt == 0` changes
/// nothing.
#[unsafe(no_mangle)]
pub extern "C" fn kdw_engine_step(
    engine: *mut kdw_engine,
    dt: f32,
    camera_position: *const kdw_vec3,
    view_reference: *const kdw_transform,
) -> kdw_status {
    guard(|| {
        // SAFETY: the caller passes readable structs.
        let camera = unsafe { read(camera_position, "camera_position") }?;
        // SAFETY: as above.
        let k = unsafe { read(view_reference, "view_reference") }?;
        // SAFETY: live engine handle, this thread only.
        unsafe { with_engine_mut(engine, |e| Ok(e.step(dt, (*camera).into(), (*k).into())?)) }
    })
}

/// A whole frame in one call, for hosts that pay per native call (Unity): sets the anchors (as
/// `kdw_engine_set_anchors`; `anchor_count` must equal the chain count), steps (as `kdw_engine_step`), and
/// writes every joint's local rotation (as `kdw_engine_read_local_rotations`; `capacity` must be at least
/// the joint count). Everything is validated before anything changes; with `dt == 0` only the anchors are
/// stored.
#[unsafe(no_mangle)]
pub extern "C" fn kdw_engine_step_and_read(
    engine: *mut kdw_engine,
    dt: f32,
    camera_position: *const kdw_vec3,
    view_reference: *const kdw_transform,
    anchors: *const kdw_transform,
    anchor_count: u32,
    out_local_rotations: *mut kdw_quat,
    capacity: u32,
    out_written: *mut u32,
) -> kdw_status {
    guard(|| {
        check_out(out_written, "out_written")?;
        // SAFETY: the caller passes readable structs.
        let camera = unsafe { read(camera_position, "camera_position") }?;
        // SAFETY: as above.
        let k = unsafe { read(view_reference, "view_reference") }?;
        // SAFETY: the caller passes `anchor_count` readable transforms.
        let anchors = unsafe { slice(anchors, anchor_count, "anchors") }?;
        // SAFETY: the caller passes `capacity` writable quaternions.
        let out = unsafe { slice_mut(out_local_rotations, capacity, "out_local_rotations") }?;
        // SAFETY: live engine handle, this thread only.
        let written = unsafe {
            with_engine_mut(engine, |e| {
                if out.len() < e.joint_count() {
                    let message =
                        format!("buffer holds {} rotations, the engine has {} joints", out.len(), e.joint_count());
                    return Err(crate::core::Error::buffer_too_small(message).into());
                }
                e.step_with_anchors(anchors.iter().map(|t| Transform::from(*t)), dt, (*camera).into(), (*k).into())?;
                Ok(e.read_local_rotations_as(out, kdw_quat::from)?)
            })
        }?;
        // SAFETY: checked by check_out.
        unsafe { write(out_written, written as u32) };
        Ok(())
    })
}

/// Sets every chain's anchor for the next step: `count` must equal the chain count, entry i belongs to
/// the i-th chain in creation order (entries of chains anchored to the view reference are checked but
/// unused). World space. Interpolated across the substeps of the next step.
#[unsafe(no_mangle)]
pub extern "C" fn kdw_engine_set_anchors(
    engine: *mut kdw_engine,
    anchors: *const kdw_transform,
    count: u32,
) -> kdw_status {
    guard(|| {
        // SAFETY: the caller passes `count` readable transforms.
        let anchors = unsafe { slice(anchors, count, "anchors") }?;
        // SAFETY: live engine handle, this thread only.
        unsafe { with_engine_mut(engine, |e| Ok(e.set_anchors(anchors.iter().map(|t| Transform::from(*t)))?)) }
    })
}

/// Number of chains.
#[unsafe(no_mangle)]
pub extern "C" fn kdw_engine_chain_count(engine: *const kdw_engine, out_count: *mut u32) -> kdw_status {
    query(engine, out_count, "out_count", |e| Ok(e.chain_count() as u32))
}

/// Total number of joints of all chains: the size `kdw_engine_read_world` needs.
#[unsafe(no_mangle)]
pub extern "C" fn kdw_engine_joint_count(engine: *const kdw_engine, out_count: *mut u32) -> kdw_status {
    query(engine, out_count, "out_count", |e| Ok(e.joint_count() as u32))
}

/// Chain ids in creation order (the order of every batched call). `capacity` must be at least the chain
/// count; `*out_written` receives how many were written.
#[unsafe(no_mangle)]
pub extern "C" fn kdw_engine_get_chain_ids(
    engine: *const kdw_engine,
    out_ids: *mut kdw_chain_id,
    capacity: u32,
    out_written: *mut u32,
) -> kdw_status {
    fill(engine, out_ids, capacity, out_written, "out_ids", |e, out| {
        if out.len() < e.chain_count() {
            let message = format!("buffer holds {} ids, the engine has {} chains", out.len(), e.chain_count());
            return Err(crate::core::Error::buffer_too_small(message).into());
        }
        for (slot, id) in out.iter_mut().zip(e.chain_ids()) {
            *slot = id.to_bits();
        }
        Ok(e.chain_count())
    })
}

/// World transforms of every joint of every chain, chains in creation order, joints root to tip, at the
/// time of the last step's call (from the last two internal states; no display latency). Rotations are skinning-ready: each
/// joint's bone axis points at the next joint. `capacity` must be at least the joint count.
#[unsafe(no_mangle)]
pub extern "C" fn kdw_engine_read_world(
    engine: *const kdw_engine,
    out_transforms: *mut kdw_transform,
    capacity: u32,
    out_written: *mut u32,
) -> kdw_status {
    fill(engine, out_transforms, capacity, out_written, "out_transforms", |e, out| {
        Ok(e.read_world_as(out, kdw_transform::from)?)
    })
}

/// Each joint's rotation relative to its parent joint (joint 0: relative to its anchor), in the order of
/// `kdw_engine_read_world`: what Unity writes to `Transform.localRotation`.
#[unsafe(no_mangle)]
pub extern "C" fn kdw_engine_read_local_rotations(
    engine: *const kdw_engine,
    out_rotations: *mut kdw_quat,
    capacity: u32,
    out_written: *mut u32,
) -> kdw_status {
    fill(engine, out_rotations, capacity, out_written, "out_rotations", |e, out| {
        Ok(e.read_local_rotations_as(out, kdw_quat::from)?)
    })
}

/// Counters: chains, joints, substeps run, time dropped, chains asleep, chains on the lane solver.
#[unsafe(no_mangle)]
pub extern "C" fn kdw_engine_get_stats(engine: *const kdw_engine, out_stats: *mut kdw_engine_stats) -> kdw_status {
    query(engine, out_stats, "out_stats", |e| Ok(e.stats().into()))
}

/// Puts every chain back to its rest shape, at rest, at the next step.
#[unsafe(no_mangle)]
pub extern "C" fn kdw_engine_reset(engine: *mut kdw_engine) -> kdw_status {
    // SAFETY: live engine handle, this thread only.
    guard(|| unsafe {
        with_engine_mut(engine, |e| {
            e.reset_all();
            Ok(())
        })
    })
}

/// Every chain treats its anchor's motion in the next step as a teleport (the engine's `teleport_mode`),
/// however small: call it when the character is placed somewhere new.
#[unsafe(no_mangle)]
pub extern "C" fn kdw_engine_teleport(engine: *mut kdw_engine) -> kdw_status {
    // SAFETY: live engine handle, this thread only.
    guard(|| unsafe {
        with_engine_mut(engine, |e| {
            e.teleport_all();
            Ok(())
        })
    })
}

/// A hash of everything that determines future results. Equal hashes after equal calls show determinism;
/// an unchanged hash after a rejected call shows the engine was left untouched.
#[unsafe(no_mangle)]
pub extern "C" fn kdw_engine_state_hash(engine: *const kdw_engine, out_hash: *mut u64) -> kdw_status {
    query(engine, out_hash, "out_hash", |e| Ok(e.state_hash()))
}
