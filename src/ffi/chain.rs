//! `kdw_chain_*`: a joint chain (`ViewDependentPhysicalObject`), its base shape and parameters.

use super::engine::kdw_engine;
use super::guard::{check_out, check_struct_size, fill, guard, query, read, slice, store_each, with_engine_mut, write};
use super::status::{FfiResult, kdw_status};
use super::types::{kdw_chain_def, kdw_chain_id, kdw_transform};
use crate::core::{ChainId, ChainParams, Transform};

/// Joints from C, converted for the core (shapes are copied at creation anyway).
pub(crate) fn joints_from(joints: &[kdw_transform]) -> Vec<Transform> {
    joints.iter().map(|t| (*t).into()).collect()
}

fn params_from(def: &kdw_chain_def) -> FfiResult<ChainParams> {
    check_struct_size::<kdw_chain_def>(def.struct_size, "kdw_chain_def")?;
    Ok(ChainParams::try_from(def)?)
}

/// Default chain parameters (stiffness 0.5, damping 1/s, full momentum suppression, anchored to the view
/// reference).
#[unsafe(no_mangle)]
pub extern "C" fn kdw_chain_def_default() -> kdw_chain_def {
    ChainParams::default().into()
}

/// Creates a chain from its base shape: `joint_count >= 2` joints in the anchor frame, root first. Joint 0
/// is attached to the anchor; segment lengths are taken from this shape and kept by every view shape.
#[unsafe(no_mangle)]
pub extern "C" fn kdw_chain_create(
    engine: *mut kdw_engine,
    def: *const kdw_chain_def,
    base_joints: *const kdw_transform,
    joint_count: u32,
    out_chain: *mut kdw_chain_id,
) -> kdw_status {
    guard(|| {
        check_out(out_chain, "out_chain")?;
        // SAFETY: the caller passes a readable kdw_chain_def.
        let params = params_from(unsafe { read(def, "def") }?)?;
        // SAFETY: the caller passes `joint_count` readable transforms.
        let joints = joints_from(unsafe { slice(base_joints, joint_count, "base_joints") }?);
        // SAFETY: live engine handle, this thread only.
        let id = unsafe { with_engine_mut(engine, |e| Ok(e.create_chain(params, &joints)?)) }?;
        // SAFETY: checked by check_out.
        unsafe { write(out_chain, id.to_bits()) };
        Ok(())
    })
}

/// Destroys a chain and its view shapes. Later chains keep their relative order in batched calls.
#[unsafe(no_mangle)]
pub extern "C" fn kdw_chain_destroy(engine: *mut kdw_engine, chain: kdw_chain_id) -> kdw_status {
    // SAFETY: live engine handle, this thread only.
    guard(|| unsafe { with_engine_mut(engine, |e| Ok(e.destroy_chain(ChainId::from_bits(chain))?)) })
}

/// `*out_valid` = 1 if `chain` names a live chain of this engine, else 0.
#[unsafe(no_mangle)]
pub extern "C" fn kdw_chain_is_valid(
    engine: *const kdw_engine,
    chain: kdw_chain_id,
    out_valid: *mut u32,
) -> kdw_status {
    query(engine, out_valid, "out_valid", |e| Ok(e.is_chain_valid(ChainId::from_bits(chain)) as u32))
}

/// Reads a chain's parameters.
#[unsafe(no_mangle)]
pub extern "C" fn kdw_chain_get_def(
    engine: *const kdw_engine,
    chain: kdw_chain_id,
    out_def: *mut kdw_chain_def,
) -> kdw_status {
    query(engine, out_def, "out_def", |e| Ok(e.chain_params(ChainId::from_bits(chain))?.into()))
}

/// Replaces a chain's parameters (validated as a whole; nothing changes on error). Takes effect at the
/// next step.
#[unsafe(no_mangle)]
pub extern "C" fn kdw_chain_set_def(
    engine: *mut kdw_engine,
    chain: kdw_chain_id,
    def: *const kdw_chain_def,
) -> kdw_status {
    guard(|| {
        // SAFETY: the caller passes a readable kdw_chain_def.
        let params = params_from(unsafe { read(def, "def") }?)?;
        // SAFETY: live engine handle, this thread only.
        unsafe { with_engine_mut(engine, |e| Ok(e.set_chain_params(ChainId::from_bits(chain), params)?)) }
    })
}

/// Replaces the base shape (same joint count), e.g. for animated hair. Segment lengths follow the new
/// base; view shapes keep their bends. The change is blended in without injecting momentum.
#[unsafe(no_mangle)]
pub extern "C" fn kdw_chain_set_base_shape(
    engine: *mut kdw_engine,
    chain: kdw_chain_id,
    joints: *const kdw_transform,
    joint_count: u32,
) -> kdw_status {
    guard(|| {
        // SAFETY: the caller passes `joint_count` readable transforms.
        let joints = joints_from(unsafe { slice(joints, joint_count, "joints") }?);
        // SAFETY: live engine handle, this thread only.
        unsafe { with_engine_mut(engine, |e| Ok(e.set_base_shape(ChainId::from_bits(chain), &joints)?)) }
    })
}

/// Puts the chain back to its current rest shape, at rest, at the next step.
#[unsafe(no_mangle)]
pub extern "C" fn kdw_chain_reset(engine: *mut kdw_engine, chain: kdw_chain_id) -> kdw_status {
    // SAFETY: live engine handle, this thread only.
    guard(|| unsafe { with_engine_mut(engine, |e| Ok(e.reset_chain(ChainId::from_bits(chain))?)) })
}

/// Number of joints of a chain.
#[unsafe(no_mangle)]
pub extern "C" fn kdw_chain_joint_count(
    engine: *const kdw_engine,
    chain: kdw_chain_id,
    out_count: *mut u32,
) -> kdw_status {
    query(engine, out_count, "out_count", |e| Ok(e.chain_joint_count(ChainId::from_bits(chain))? as u32))
}

/// One chain's world transforms (as `kdw_engine_read_world`, for that chain only).
#[unsafe(no_mangle)]
pub extern "C" fn kdw_chain_read_world(
    engine: *const kdw_engine,
    chain: kdw_chain_id,
    out_transforms: *mut kdw_transform,
    capacity: u32,
    out_written: *mut u32,
) -> kdw_status {
    fill(engine, out_transforms, capacity, out_written, "out_transforms", |e, out| {
        store_each(out, |capacity, f| e.for_each_chain_world_transform(ChainId::from_bits(chain), capacity, f))
    })
}

/// The rest shape the chain is currently pulled towards (the blend of its shapes for the last view
/// direction), in the anchor frame.
#[unsafe(no_mangle)]
pub extern "C" fn kdw_chain_read_rest_shape(
    engine: *const kdw_engine,
    chain: kdw_chain_id,
    out_transforms: *mut kdw_transform,
    capacity: u32,
    out_written: *mut u32,
) -> kdw_status {
    fill(engine, out_transforms, capacity, out_written, "out_transforms", |e, out| {
        store_each(out, |capacity, f| e.for_each_chain_rest_transform(ChainId::from_bits(chain), capacity, f))
    })
}

/// Kinetic energy of the chain's dynamic joints, J (mass x velocity^2 / 2 summed).
#[unsafe(no_mangle)]
pub extern "C" fn kdw_chain_kinetic_energy(
    engine: *const kdw_engine,
    chain: kdw_chain_id,
    out_energy: *mut f32,
) -> kdw_status {
    query(engine, out_energy, "out_energy", |e| Ok(e.chain_kinetic_energy(ChainId::from_bits(chain))?))
}

/// Per-joint collision radii in character units (× the engine's `scale` m), each in [0, 1e6]: `count` must
/// equal the chain's joint count, or be 0 to go back to the chain def's `radius` for every joint. Wakes the
/// chain if it was asleep.
#[unsafe(no_mangle)]
pub extern "C" fn kdw_chain_set_joint_radii(
    engine: *mut kdw_engine,
    chain: kdw_chain_id,
    radii: *const f32,
    count: u32,
) -> kdw_status {
    guard(|| {
        // SAFETY: the caller passes `count` readable floats (NULL is accepted when count is 0).
        let radii = if count == 0 { &[][..] } else { unsafe { slice(radii, count, "radii") }? };
        // SAFETY: live engine handle, this thread only.
        unsafe { with_engine_mut(engine, |e| Ok(e.set_chain_joint_radii(ChainId::from_bits(chain), radii)?)) }
    })
}

/// The chain treats its anchor's motion in the next step as a teleport (the engine's `teleport_mode`).
#[unsafe(no_mangle)]
pub extern "C" fn kdw_chain_teleport(engine: *mut kdw_engine, chain: kdw_chain_id) -> kdw_status {
    // SAFETY: live engine handle, this thread only.
    guard(|| unsafe { with_engine_mut(engine, |e| Ok(e.teleport_chain(ChainId::from_bits(chain))?)) })
}

/// Enables (1) or disables (0) a chain. A disabled (culled) chain is not simulated and costs nothing; it
/// follows its anchor rigidly in its last pose, and enabled again carries on from there without a whip (carried
/// to its current anchor whatever the `teleport_mode`).
#[unsafe(no_mangle)]
pub extern "C" fn kdw_chain_set_enabled(engine: *mut kdw_engine, chain: kdw_chain_id, enabled: u32) -> kdw_status {
    // SAFETY: live engine handle, this thread only.
    guard(|| unsafe {
        with_engine_mut(engine, |e| {
            if enabled > 1 {
                let message = format!("enabled must be 0 or 1, got {enabled}");
                return Err(crate::core::Error::invalid_argument(message).into());
            }
            Ok(e.set_chain_enabled(ChainId::from_bits(chain), enabled == 1)?)
        })
    })
}

/// `*out_enabled` = 1 if the chain is enabled, else 0.
#[unsafe(no_mangle)]
pub extern "C" fn kdw_chain_is_enabled(
    engine: *const kdw_engine,
    chain: kdw_chain_id,
    out_enabled: *mut u32,
) -> kdw_status {
    query(engine, out_enabled, "out_enabled", |e| Ok(e.is_chain_enabled(ChainId::from_bits(chain))? as u32))
}

/// `*out_asleep` = 1 if the chain slept through the last step (its anchor, rest shape and nearby colliders
/// were still and its motion had died out), else 0.
#[unsafe(no_mangle)]
pub extern "C" fn kdw_chain_is_asleep(
    engine: *const kdw_engine,
    chain: kdw_chain_id,
    out_asleep: *mut u32,
) -> kdw_status {
    query(engine, out_asleep, "out_asleep", |e| Ok(e.is_chain_asleep(ChainId::from_bits(chain))? as u32))
}
