//! `kdw_view_shape_*`: how a chain should look when seen from a direction.

use super::chain::joints_from;
use super::engine::kdw_engine;
use super::guard::{check_out, fill, guard, query, read, slice, store_each, with_engine_mut, write};
use super::status::kdw_status;
use super::types::{kdw_chain_id, kdw_transform, kdw_vec3, kdw_view_shape_id};
use crate::core::{ChainId, ViewShapeId};

/// Adds a view shape to a chain: when the camera is seen from `direction` (in the view reference joint's
/// local frame; need not be unit, must not be zero), the chain's rest shape becomes `joints` (anchor frame,
/// as many as the chain has). Only its bends and orientations are used: the root position and segment
/// lengths stay the base shape's. `influence > 0` narrows (large) or widens (small) the cone of directions
/// it acts in: weight `((dot(d_i, d) + 1) / 2)^influence`.
#[unsafe(no_mangle)]
pub extern "C" fn kdw_chain_add_view_shape(
    engine: *mut kdw_engine,
    chain: kdw_chain_id,
    direction: *const kdw_vec3,
    joints: *const kdw_transform,
    joint_count: u32,
    influence: f32,
    out_view_shape: *mut kdw_view_shape_id,
) -> kdw_status {
    guard(|| {
        check_out(out_view_shape, "out_view_shape")?;
        // SAFETY: the caller passes a readable kdw_vec3.
        let direction = unsafe { read(direction, "direction") }?;
        // SAFETY: the caller passes `joint_count` readable transforms.
        let joints = joints_from(unsafe { slice(joints, joint_count, "joints") }?);
        // SAFETY: live engine handle, this thread only.
        let id = unsafe {
            with_engine_mut(engine, |e| {
                Ok(e.add_view_shape(ChainId::from_bits(chain), (*direction).into(), &joints, influence)?)
            })
        }?;
        // SAFETY: checked by check_out.
        unsafe { write(out_view_shape, id.to_bits()) };
        Ok(())
    })
}

/// Sets a view shape's influence (> 0).
#[unsafe(no_mangle)]
pub extern "C" fn kdw_view_shape_set_influence(
    engine: *mut kdw_engine,
    view_shape: kdw_view_shape_id,
    influence: f32,
) -> kdw_status {
    // SAFETY: live engine handle, this thread only.
    guard(|| unsafe {
        with_engine_mut(engine, |e| Ok(e.set_view_shape_influence(ViewShapeId::from_bits(view_shape), influence)?))
    })
}

/// Sets a view shape's direction (view reference frame, non-zero).
#[unsafe(no_mangle)]
pub extern "C" fn kdw_view_shape_set_direction(
    engine: *mut kdw_engine,
    view_shape: kdw_view_shape_id,
    direction: *const kdw_vec3,
) -> kdw_status {
    guard(|| {
        // SAFETY: the caller passes a readable kdw_vec3.
        let direction = unsafe { read(direction, "direction") }?;
        // SAFETY: live engine handle, this thread only.
        unsafe {
            with_engine_mut(engine, |e| {
                Ok(e.set_view_shape_direction(ViewShapeId::from_bits(view_shape), (*direction).into())?)
            })
        }
    })
}

/// Replaces a view shape's joints (as many as its chain has).
#[unsafe(no_mangle)]
pub extern "C" fn kdw_view_shape_set_joints(
    engine: *mut kdw_engine,
    view_shape: kdw_view_shape_id,
    joints: *const kdw_transform,
    joint_count: u32,
) -> kdw_status {
    guard(|| {
        // SAFETY: the caller passes `joint_count` readable transforms.
        let joints = joints_from(unsafe { slice(joints, joint_count, "joints") }?);
        // SAFETY: live engine handle, this thread only.
        unsafe {
            with_engine_mut(engine, |e| Ok(e.set_view_shape_joints(ViewShapeId::from_bits(view_shape), &joints)?))
        }
    })
}

/// Removes a view shape from its chain.
#[unsafe(no_mangle)]
pub extern "C" fn kdw_view_shape_remove(engine: *mut kdw_engine, view_shape: kdw_view_shape_id) -> kdw_status {
    // SAFETY: live engine handle, this thread only.
    guard(|| unsafe { with_engine_mut(engine, |e| Ok(e.remove_view_shape(ViewShapeId::from_bits(view_shape))?)) })
}

/// Number of view shapes of a chain.
#[unsafe(no_mangle)]
pub extern "C" fn kdw_chain_view_shape_count(
    engine: *const kdw_engine,
    chain: kdw_chain_id,
    out_count: *mut u32,
) -> kdw_status {
    query(engine, out_count, "out_count", |e| Ok(e.view_shape_count(ChainId::from_bits(chain))? as u32))
}

/// `*out_valid` = 1 if `view_shape` names a live view shape of this engine, else 0.
#[unsafe(no_mangle)]
pub extern "C" fn kdw_view_shape_is_valid(
    engine: *const kdw_engine,
    view_shape: kdw_view_shape_id,
    out_valid: *mut u32,
) -> kdw_status {
    query(engine, out_valid, "out_valid", |e| Ok(e.is_view_shape_valid(ViewShapeId::from_bits(view_shape)) as u32))
}

/// The weights of the chain's last blend (updated by every step): `out_weights[0]` is the base shape's,
/// then one per view shape in the order they were added. They are >= 0 and sum to 1. `capacity` must be at
/// least `1 + view shape count`.
#[unsafe(no_mangle)]
pub extern "C" fn kdw_chain_read_weights(
    engine: *const kdw_engine,
    chain: kdw_chain_id,
    out_weights: *mut f32,
    capacity: u32,
    out_written: *mut u32,
) -> kdw_status {
    fill(engine, out_weights, capacity, out_written, "out_weights", |e, out| {
        store_each(out, |capacity, f| e.for_each_chain_weight(ChainId::from_bits(chain), capacity, f))
    })
}
