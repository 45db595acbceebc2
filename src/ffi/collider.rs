//! `kdw_collider_*`: kinematic collision shapes owned by an engine, moved in one batched call per frame.

use super::engine::kdw_engine;
use super::guard::{check_out, check_struct_size, fill, guard, query, read, slice, with_engine_mut, write};
use super::status::kdw_status;
use super::types::{kdw_collider_def, kdw_collider_id, kdw_transform};
use crate::core::{ColliderDef, ColliderId, Transform};

/// Default collider: a sphere of radius 0.1 m at the origin on layer 1.
#[unsafe(no_mangle)]
pub extern "C" fn kdw_collider_def_default() -> kdw_collider_def {
    ColliderDef::default().into()
}

/// Creates a collider. Chains whose `collision_mask` shares a bit with its `layers` are kept out of it (or
/// inside it). `*out_collider` receives its id.
#[unsafe(no_mangle)]
pub extern "C" fn kdw_collider_create(
    engine: *mut kdw_engine,
    def: *const kdw_collider_def,
    out_collider: *mut kdw_collider_id,
) -> kdw_status {
    guard(|| {
        check_out(out_collider, "out_collider")?;
        // SAFETY: the caller passes a readable kdw_collider_def.
        let def = unsafe { read(def, "def") }?;
        check_struct_size::<kdw_collider_def>(def.struct_size, "kdw_collider_def")?;
        let def = ColliderDef::try_from(def)?;
        // SAFETY: live engine handle, this thread only.
        let id = unsafe { with_engine_mut(engine, |e| Ok(e.create_collider(&def)?)) }?;
        // SAFETY: checked by check_out.
        unsafe { write(out_collider, id.to_bits()) };
        Ok(())
    })
}

/// Destroys a collider. Later colliders keep their relative order in `kdw_engine_set_collider_transforms`.
#[unsafe(no_mangle)]
pub extern "C" fn kdw_collider_destroy(engine: *mut kdw_engine, collider: kdw_collider_id) -> kdw_status {
    // SAFETY: live engine handle, this thread only.
    guard(|| unsafe { with_engine_mut(engine, |e| Ok(e.destroy_collider(ColliderId::from_bits(collider))?)) })
}

/// `*out_valid` = 1 if `collider` names a live collider of this engine, else 0.
#[unsafe(no_mangle)]
pub extern "C" fn kdw_collider_is_valid(
    engine: *const kdw_engine,
    collider: kdw_collider_id,
    out_valid: *mut u32,
) -> kdw_status {
    query(engine, out_valid, "out_valid", |e| Ok(e.is_collider_valid(ColliderId::from_bits(collider)) as u32))
}

/// Resizes a collider (its shape kind stays): `radius` and `half_height` as in `kdw_collider_def`, validated
/// the same way. For a collider following a bone whose scale changes.
#[unsafe(no_mangle)]
pub extern "C" fn kdw_collider_set_size(
    engine: *mut kdw_engine,
    collider: kdw_collider_id,
    radius: f32,
    half_height: f32,
) -> kdw_status {
    // SAFETY: live engine handle, this thread only.
    guard(|| unsafe {
        with_engine_mut(engine, |e| Ok(e.set_collider_size(ColliderId::from_bits(collider), radius, half_height)?))
    })
}

/// Moves a collider to other layers.
#[unsafe(no_mangle)]
pub extern "C" fn kdw_collider_set_layers(
    engine: *mut kdw_engine,
    collider: kdw_collider_id,
    layers: u32,
) -> kdw_status {
    // SAFETY: live engine handle, this thread only.
    guard(|| unsafe {
        with_engine_mut(engine, |e| Ok(e.set_collider_layers(ColliderId::from_bits(collider), layers)?))
    })
}

/// Sets every collider's world pose for the next step: `count` must equal the collider count (`transforms`
/// may be NULL only when it is 0), entry i belongs to the i-th collider in creation order. The step sweeps each collider from its last pose to
/// this one across its substeps (a jump beyond the teleport thresholds is not swept).
#[unsafe(no_mangle)]
pub extern "C" fn kdw_engine_set_collider_transforms(
    engine: *mut kdw_engine,
    transforms: *const kdw_transform,
    count: u32,
) -> kdw_status {
    guard(|| {
        // SAFETY: the caller passes `count` readable transforms (NULL is accepted when count is 0).
        let transforms = if count == 0 { &[][..] } else { unsafe { slice(transforms, count, "transforms") }? };
        // SAFETY: live engine handle, this thread only.
        unsafe {
            with_engine_mut(engine, |e| Ok(e.set_collider_transforms(transforms.iter().map(|t| Transform::from(*t)))?))
        }
    })
}

/// Number of colliders.
#[unsafe(no_mangle)]
pub extern "C" fn kdw_engine_collider_count(engine: *const kdw_engine, out_count: *mut u32) -> kdw_status {
    query(engine, out_count, "out_count", |e| Ok(e.collider_count() as u32))
}

/// Collider ids in creation order (the order of `kdw_engine_set_collider_transforms`). `capacity` must be
/// at least the collider count.
#[unsafe(no_mangle)]
pub extern "C" fn kdw_engine_get_collider_ids(
    engine: *const kdw_engine,
    out_ids: *mut kdw_collider_id,
    capacity: u32,
    out_written: *mut u32,
) -> kdw_status {
    fill(engine, out_ids, capacity, out_written, "out_ids", |e, out| {
        if out.len() < e.collider_count() {
            let message = format!("buffer holds {} ids, the engine has {} colliders", out.len(), e.collider_count());
            return Err(crate::core::Error::buffer_too_small(message).into());
        }
        for (slot, id) in out.iter_mut().zip(e.collider_ids()) {
            *slot = id.to_bits();
        }
        Ok(e.collider_count())
    })
}
