//! Plain C structs that cross the boundary. All are padding-free (tests prove it) and use `uint32_t`
//! where C would use `bool`, so Unity Burst and IL2CPP can pass them as they are.

use glam::{Quat, Vec3};

use crate::core::{
    AnchorSource, ChainParams, ColliderDef, ColliderShape, EngineSettings, Solver, Stats, TeleportMode, Transform,
};

/// A 3D vector, the layout of Unity's `Vector3`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct kdw_vec3 {
    pub x: f32,
    pub y: f32,
    pub z: f32,
}

/// A rotation quaternion (x, y, z, w), the layout of Unity's `Quaternion`. Need not be unit: it is
/// normalised on the way in; a null quaternion is rejected.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct kdw_quat {
    pub x: f32,
    pub y: f32,
    pub z: f32,
    pub w: f32,
}

/// Position + rotation: 28 bytes, the layout of a Unity `Vector3` followed by a `Quaternion`. Positions
/// must be finite and within ±1e9 m.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct kdw_transform {
    pub position: kdw_vec3,
    pub rotation: kdw_quat,
}

/// A chain (`ViewDependentPhysicalObject`). Index + generation + owner; 0 is the null id.
pub type kdw_chain_id = u64;
/// A view shape of a chain. 0 is the null id.
pub type kdw_view_shape_id = u64;

/// A collider. 0 is the null id.
pub type kdw_collider_id = u64;

/// A teleport moves the chain rigidly with its anchor, keeping its shape and adding no energy.
pub const KDW_TELEPORT_CARRY_SHAPE: u32 = 0;
/// A teleport puts the chain back to its rest shape under the new anchor, at rest.
pub const KDW_TELEPORT_RESET: u32 = 1;

/// The lane solver (the default): chains of equal joint count are stepped side by side, one chain per SIMD
/// lane, with the widest kernel copy this CPU has (`kdw_simd_path`); the contact pass of chains that may touch
/// a collider resolves each contact in scalar code, lane by lane, and the last 1 or 2 chains of a joint count
/// after its groups of 16 or 8 (too few for a group to pay) take the scalar solver in a step. It agrees
/// with `KDW_SOLVER_SCALAR` up to float rounding; a chain's bits do not depend on its lane, its group or the
/// kernel copy.
pub const KDW_SOLVER_LANES: u32 = 0;
/// `KDW_SOLVER_LANES` with the portable copy of its kernel (SSE2 on x86-64) whatever the CPU has: the same
/// bits, slower. For checking the determinism policy on one machine.
pub const KDW_SOLVER_LANES_PORTABLE: u32 = 1;
/// One chain at a time: the reference implementation the lane solver is tested against (and what chains near
/// colliders always use).
pub const KDW_SOLVER_SCALAR: u32 = 2;

/// The chain's anchor is the view reference joint K given with each step.
pub const KDW_ANCHOR_VIEW_REFERENCE: u32 = 0;
/// The chain's anchor is its own entry in `kdw_engine_set_anchors`.
pub const KDW_ANCHOR_OWN: u32 = 1;

/// Engine settings; obtain defaults from `kdw_engine_def_default()`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct kdw_engine_def {
    /// `sizeof(kdw_engine_def)`; lets the struct grow without breaking old callers.
    pub struct_size: u32,
    /// World gravity in character units/s² (× `scale` m/s²), each component within ±1e6. Default (0, -9.81, 0).
    pub gravity: kdw_vec3,
    /// Internal fixed steps per simulated second, Hz, in [30, 10000]. Default 240.
    pub substep_rate: f32,
    /// Most internal steps per `kdw_engine_step`, in [1, 1000]; time beyond is dropped and counted.
    /// Default 16.
    pub max_substeps: u32,
    /// Shape-matching + inextensibility passes per internal step, in [1, 64]. Default 2.
    pub iterations: u32,
    /// Simulated seconds per second of `dt`, in [0, 100]; 0 pauses. Default 1.
    pub time_scale: f32,
    /// An anchor moving farther than this in one step is a teleport, in character units (× `scale` m).
    /// > 0; FLT_MAX disables. Default 1.
    pub teleport_distance: f32,
    /// An anchor turning more than this (radians) in one step is a teleport. > 0; above pi disables.
    /// Default pi/2.
    pub teleport_angle: f32,
    /// What a teleport does: `KDW_TELEPORT_CARRY_SHAPE` (default) or `KDW_TELEPORT_RESET`.
    pub teleport_mode: u32,
    /// A chain whose joints all move slower than this relative to its root (character units/s, × `scale`)
    /// for 0.5 s, under a still anchor, rest shape and colliders, sleeps until any of them changes. In
    /// [0, 1e6]; 0 never sleeps. Default 5e-6 (falls asleep within 1e-5 chain lengths of its resting pose).
    pub sleep_speed: f32,
    /// Level of detail for distant characters, in [0, 3]: each level halves the internal step rate (not
    /// below 30 Hz) and the iterations (not below 1). Default 0.
    pub lod: u32,
    /// Size of the character relative to the units its parameters are tuned in, in [1e-6, 1e6]: multiplies
    /// gravity, `teleport_distance` and chain/joint radii, so a character scaled by 100 with scale 100 moves
    /// like the unscaled one. Transforms and collider sizes are world units. Default 1.
    pub scale: f32,
}

/// Chain parameters; obtain defaults from `kdw_chain_def_default()`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct kdw_chain_def {
    /// `sizeof(kdw_chain_def)`.
    pub struct_size: u32,
    /// Pull towards the rest shape in [0, 1]: 0 limp (an n-pendulum), 1 rigid. Independent of substep
    /// rate and iterations. Default 0.5.
    pub stiffness: f32,
    /// Velocity damping per second, 1/s, in [0, 1000], acting on velocity relative to the chain's root.
    /// Default 1.
    pub damping: f32,
    /// Share of the motion caused by a changing rest shape that is not turned into velocity, [0, 1].
    /// Default 1.
    pub momentum_suppression: f32,
    /// Mass per particle, kg, in [1e-6, 1e6]. Default 1.
    pub mass: f32,
    /// Particle radius in character units (× the engine's `scale` m), in [0, 1e6]: every joint's collision
    /// radius unless `kdw_chain_set_joint_radii` set them, and the weight of orientations in shape matching.
    /// Default 0.02.
    pub radius: f32,
    /// Multiplier on the engine's gravity, in [-100, 100]. Default 1.
    pub gravity_scale: f32,
    /// `KDW_ANCHOR_VIEW_REFERENCE` (default) or `KDW_ANCHOR_OWN`.
    pub anchor: u32,
    /// Collision layers the chain collides with (a collider whose `layers` share a bit). 0: no collisions,
    /// and no collision cost. Default 0xFFFFFFFF.
    pub collision_mask: u32,
    /// Coulomb friction against colliders, in [0, 10]. Default 0.3.
    pub friction: f32,
}

/// Counters for profiling overlays.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct kdw_engine_stats {
    /// `sizeof(kdw_engine_stats)` as written by the library.
    pub struct_size: u32,
    pub chain_count: u32,
    pub joint_count: u32,
    /// Internal steps run by the last `kdw_engine_step`.
    pub substeps_last_step: u32,
    /// Chains that cost nothing in the last step (sleeping or disabled).
    pub chains_asleep: u32,
    /// Chains the lane solver stepped in the last `kdw_engine_step`; the others ran on the scalar solver or
    /// were asleep or disabled. 0 on `KDW_SOLVER_SCALAR`.
    pub lane_chains: u32,
    pub collider_count: u32,
    /// Always 0: keeps the 64-bit fields that follow aligned without hidden padding.
    pub reserved: u32,
    pub substeps_total: u64,
    /// Internal steps where the direct inextensibility solve failed, or was skipped for a chain whose first
    /// solves keep failing it, and a fallback ran.
    pub solver_fallbacks: u64,
    /// Simulated seconds dropped because a step needed more than `max_substeps`.
    pub time_dropped: f64,
    /// Simulated seconds advanced in total.
    pub simulated_time: f64,
    /// (segment or particle, collider) pairs tested by the contact pass in total.
    pub contact_pairs_tested: u64,
}

/// Keeps particles outside a ball of `radius`.
pub const KDW_COLLIDER_SPHERE: u32 = 0;
/// Keeps particles outside a capsule: `radius` around the segment from -`half_height` to +`half_height`
/// on the collider's local Y axis.
pub const KDW_COLLIDER_CAPSULE: u32 = 1;
/// Keeps particles on the local +Y side of the plane through the collider's origin.
pub const KDW_COLLIDER_PLANE: u32 = 2;
/// Keeps particles inside a ball of `radius`.
pub const KDW_COLLIDER_INSIDE_SPHERE: u32 = 3;
/// Keeps particles inside a capsule.
pub const KDW_COLLIDER_INSIDE_CAPSULE: u32 = 4;

/// A collider; obtain defaults from `kdw_collider_def_default()`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct kdw_collider_def {
    /// `sizeof(kdw_collider_def)`.
    pub struct_size: u32,
    /// One of `KDW_COLLIDER_*`. Default `KDW_COLLIDER_SPHERE`.
    pub shape: u32,
    /// Sphere and capsule radius, m (world units), in [0, 1e6]; > 0 for inside colliders. Default 0.1.
    pub radius: f32,
    /// Capsule half length of the axis, m, in [0, 1e6]. Default 0. Fields a shape does not use are ignored
    /// but must still be finite and in range.
    pub half_height: f32,
    /// Initial world pose; `kdw_engine_set_collider_transforms` moves it every frame.
    pub transform: kdw_transform,
    /// Layers the collider is on: it affects chains whose `collision_mask` shares a bit (0: none). Default 1.
    pub layers: u32,
}

impl From<ColliderDef> for kdw_collider_def {
    fn from(d: ColliderDef) -> Self {
        let (shape, radius, half_height) = match d.shape {
            ColliderShape::Sphere { radius } => (KDW_COLLIDER_SPHERE, radius, 0.0),
            ColliderShape::Capsule { radius, half_height } => (KDW_COLLIDER_CAPSULE, radius, half_height),
            ColliderShape::Plane => (KDW_COLLIDER_PLANE, 0.0, 0.0),
            ColliderShape::InsideSphere { radius } => (KDW_COLLIDER_INSIDE_SPHERE, radius, 0.0),
            ColliderShape::InsideCapsule { radius, half_height } => (KDW_COLLIDER_INSIDE_CAPSULE, radius, half_height),
        };
        Self {
            struct_size: size_of::<Self>() as u32,
            shape,
            radius,
            half_height,
            transform: d.transform.into(),
            layers: d.layers,
        }
    }
}

impl TryFrom<&kdw_collider_def> for ColliderDef {
    type Error = crate::core::Error;
    fn try_from(d: &kdw_collider_def) -> Result<Self, Self::Error> {
        let (radius, half_height) = (d.radius, d.half_height);
        // Fields a shape does not use are ignored, but a NaN or negative one is still a caller's mistake.
        for (name, value) in [("radius", radius), ("half_height", half_height)] {
            if !(value.is_finite() && (0.0..=crate::core::params::MAX_RADIUS).contains(&value)) {
                let message = format!("collider {name} {value} must be finite and in [0, 1e6] (even where unused)");
                return Err(crate::core::Error::invalid_argument(message));
            }
        }
        let shape = match d.shape {
            KDW_COLLIDER_SPHERE => ColliderShape::Sphere { radius },
            KDW_COLLIDER_CAPSULE => ColliderShape::Capsule { radius, half_height },
            KDW_COLLIDER_PLANE => ColliderShape::Plane,
            KDW_COLLIDER_INSIDE_SPHERE => ColliderShape::InsideSphere { radius },
            KDW_COLLIDER_INSIDE_CAPSULE => ColliderShape::InsideCapsule { radius, half_height },
            other => return Err(crate::core::Error::invalid_argument(format!("unknown collider shape {other}"))),
        };
        Ok(Self { shape, transform: d.transform.into(), layers: d.layers })
    }
}

impl From<kdw_vec3> for Vec3 {
    fn from(v: kdw_vec3) -> Self {
        Vec3::new(v.x, v.y, v.z)
    }
}

impl From<Vec3> for kdw_vec3 {
    fn from(v: Vec3) -> Self {
        Self { x: v.x, y: v.y, z: v.z }
    }
}

impl From<kdw_quat> for Quat {
    fn from(q: kdw_quat) -> Self {
        Quat::from_xyzw(q.x, q.y, q.z, q.w)
    }
}

impl From<Quat> for kdw_quat {
    fn from(q: Quat) -> Self {
        Self { x: q.x, y: q.y, z: q.z, w: q.w }
    }
}

impl From<kdw_transform> for Transform {
    fn from(t: kdw_transform) -> Self {
        Transform::new(t.position.into(), t.rotation.into())
    }
}

impl From<Transform> for kdw_transform {
    fn from(t: Transform) -> Self {
        Self { position: t.position.into(), rotation: t.rotation.into() }
    }
}

impl From<EngineSettings> for kdw_engine_def {
    fn from(s: EngineSettings) -> Self {
        Self {
            struct_size: size_of::<Self>() as u32,
            gravity: s.gravity.into(),
            substep_rate: s.substep_rate,
            max_substeps: s.max_substeps,
            iterations: s.iterations,
            time_scale: s.time_scale,
            teleport_distance: s.teleport_distance,
            teleport_angle: s.teleport_angle,
            teleport_mode: match s.teleport_mode {
                TeleportMode::CarryShape => KDW_TELEPORT_CARRY_SHAPE,
                TeleportMode::Reset => KDW_TELEPORT_RESET,
            },
            sleep_speed: s.sleep_speed,
            lod: s.lod,
            scale: s.scale,
        }
    }
}

impl TryFrom<&kdw_engine_def> for EngineSettings {
    type Error = crate::core::Error;
    fn try_from(d: &kdw_engine_def) -> Result<Self, Self::Error> {
        let teleport_mode = match d.teleport_mode {
            KDW_TELEPORT_CARRY_SHAPE => TeleportMode::CarryShape,
            KDW_TELEPORT_RESET => TeleportMode::Reset,
            other => return Err(crate::core::Error::invalid_argument(format!("unknown teleport mode {other}"))),
        };
        Ok(Self {
            gravity: d.gravity.into(),
            substep_rate: d.substep_rate,
            max_substeps: d.max_substeps,
            iterations: d.iterations,
            time_scale: d.time_scale,
            teleport_distance: d.teleport_distance,
            teleport_angle: d.teleport_angle,
            teleport_mode,
            sleep_speed: d.sleep_speed,
            lod: d.lod,
            scale: d.scale,
        })
    }
}

impl From<ChainParams> for kdw_chain_def {
    fn from(p: ChainParams) -> Self {
        Self {
            struct_size: size_of::<Self>() as u32,
            stiffness: p.stiffness,
            damping: p.damping,
            momentum_suppression: p.momentum_suppression,
            mass: p.mass,
            radius: p.radius,
            gravity_scale: p.gravity_scale,
            anchor: match p.anchor {
                AnchorSource::ViewReference => KDW_ANCHOR_VIEW_REFERENCE,
                AnchorSource::Own => KDW_ANCHOR_OWN,
            },
            collision_mask: p.collision_mask,
            friction: p.friction,
        }
    }
}

impl TryFrom<&kdw_chain_def> for ChainParams {
    type Error = crate::core::Error;
    fn try_from(d: &kdw_chain_def) -> Result<Self, Self::Error> {
        let anchor = match d.anchor {
            KDW_ANCHOR_VIEW_REFERENCE => AnchorSource::ViewReference,
            KDW_ANCHOR_OWN => AnchorSource::Own,
            other => {
                return Err(crate::core::Error::invalid_argument(format!("unknown anchor source {other}")));
            }
        };
        Ok(Self {
            stiffness: d.stiffness,
            damping: d.damping,
            momentum_suppression: d.momentum_suppression,
            mass: d.mass,
            radius: d.radius,
            gravity_scale: d.gravity_scale,
            anchor,
            collision_mask: d.collision_mask,
            friction: d.friction,
        })
    }
}

/// The `KDW_SOLVER_*` value of a solver.
pub(crate) fn solver_code(solver: Solver) -> u32 {
    match solver {
        Solver::Lanes => KDW_SOLVER_LANES,
        Solver::LanesPortable => KDW_SOLVER_LANES_PORTABLE,
        Solver::Scalar => KDW_SOLVER_SCALAR,
    }
}

/// The solver a `KDW_SOLVER_*` value names; any other value is an invalid argument.
pub(crate) fn solver_from_code(code: u32) -> crate::core::Result<Solver> {
    match code {
        KDW_SOLVER_LANES => Ok(Solver::Lanes),
        KDW_SOLVER_LANES_PORTABLE => Ok(Solver::LanesPortable),
        KDW_SOLVER_SCALAR => Ok(Solver::Scalar),
        other => Err(crate::core::Error::invalid_argument(format!(
            "unknown solver {other}: expected KDW_SOLVER_LANES (0), KDW_SOLVER_LANES_PORTABLE (1) or \
             KDW_SOLVER_SCALAR (2)"
        ))),
    }
}

impl From<Stats> for kdw_engine_stats {
    fn from(s: Stats) -> Self {
        Self {
            struct_size: size_of::<Self>() as u32,
            chain_count: s.chain_count,
            joint_count: s.joint_count,
            substeps_last_step: s.substeps_last_step,
            chains_asleep: s.chains_asleep,
            lane_chains: s.lane_chains,
            collider_count: s.collider_count,
            reserved: 0,
            substeps_total: s.substeps_total,
            solver_fallbacks: s.solver_fallbacks,
            time_dropped: s.time_dropped,
            simulated_time: s.simulated_time,
            contact_pairs_tested: s.contact_pairs_tested,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// No padding anywhere: every struct's size is the sum of its fields' sizes.
    #[test]
    fn structs_are_padding_free() {
        assert_eq!(size_of::<kdw_vec3>(), 12);
        assert_eq!(size_of::<kdw_quat>(), 16);
        assert_eq!(size_of::<kdw_transform>(), 28);
        assert_eq!(size_of::<kdw_engine_def>(), 4 + 12 + 10 * 4);
        assert_eq!(size_of::<kdw_chain_def>(), 10 * 4);
        assert_eq!(size_of::<kdw_engine_stats>(), 8 * 4 + 5 * 8);
        assert_eq!(size_of::<kdw_collider_def>(), 4 * 4 + 28 + 4);
    }
}
