//! `kdw_chain_*`: a joint chain (`ViewDependentPhysicalObject`), its base shape and parameters.

use super::engine::kdw_engine;
use super::guard::{check_out, check_struct_size, guard, read, slice, slice_mut, with_engine, with_engine_mut, write};
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
    guard(|| {
        check_out(out_valid, "out_valid")?;
        // SAFETY: live engine handle.
        let valid = unsafe { with_engine(engine, |e| Ok(e.is_chain_valid(ChainId::from_bits(chain)) as u32)) }?;
        // SAFETY: checked by check_out.
        unsafe { write(out_valid, valid) };
        Ok(())
    })
}

/// Reads a chain's parameters.
#[unsafe(no_mangle)]
pub extern "C" fn kdw_chain_get_def(
    engine: *const kdw_engine,
    chain: kdw_chain_id,
    out_def: *mut kdw_chain_def,
) -> kdw_status {
    guard(|| {
        check_out(out_def, "out_def")?;
        // SAFETY: live engine handle.
        let params = unsafe { with_engine(engine, |e| Ok(e.chain_params(ChainId::from_bits(chain))?)) }?;
        // SAFETY: checked by check_out.
        unsafe { write(out_def, params.into()) };
        Ok(())
    })
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
    guard(|| {
        check_out(out_count, "out_count")?;
        // SAFETY: live engine handle.
        let n = unsafe { with_engine(engine, |e| Ok(e.chain_joint_count(ChainId::from_bits(chain))? as u32)) }?;
        // SAFETY: checked by check_out.
        unsafe { write(out_count, n) };
        Ok(())
    })
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
    read_chain_transforms(engine, chain, out_transforms, capacity, out_written, |e, id, out| {
        e.read_chain_world(id, out)
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
    read_chain_transforms(engine, chain, out_transforms, capacity, out_written, |e, id, out| {
        e.chain_rest_shape(id, out)
    })
}

/// Kinetic energy of the chain's dynamic joints, J (mass x velocity^2 / 2 summed).
#[unsafe(no_mangle)]
pub extern "C" fn kdw_chain_kinetic_energy(
    engine: *const kdw_engine,
    chain: kdw_chain_id,
    out_energy: *mut f32,
) -> kdw_status {
    guard(|| {
        check_out(out_energy, "out_energy")?;
        // SAFETY: live engine handle.
        let energy = unsafe { with_engine(engine, |e| Ok(e.chain_kinetic_energy(ChainId::from_bits(chain))?)) }?;
        // SAFETY: checked by check_out.
        unsafe { write(out_energy, energy) };
        Ok(())
    })
}

fn read_chain_transforms(
    engine: *const kdw_engine,
    chain: kdw_chain_id,
    out_transforms: *mut kdw_transform,
    capacity: u32,
    out_written: *mut u32,
    read_into: impl FnOnce(&crate::core::Engine, ChainId, &mut [Transform]) -> crate::core::Result<usize>,
) -> kdw_status {
    guard(|| {
        check_out(out_written, "out_written")?;
        // SAFETY: the caller passes `capacity` writable transforms.
        let out = unsafe { slice_mut(out_transforms, capacity, "out_transforms") }?;
        // SAFETY: live engine handle.
        let written = unsafe {
            with_engine(engine, |e| {
                let id = ChainId::from_bits(chain);
                let mut buffer = vec![Transform::IDENTITY; e.chain_joint_count(id)?.min(out.len())];
                let n = read_into(e, id, &mut buffer)?;
                for (slot, t) in out.iter_mut().zip(&buffer) {
                    *slot = (*t).into();
                }
                Ok(n as u32)
            })
        }?;
        // SAFETY: checked by check_out.
        unsafe { write(out_written, written) };
        Ok(())
    })
}
