//! Plain C structs that cross the boundary. All are padding-free (tests prove it) and use `uint32_t`
//! where C would use `bool`, so Unity Burst and IL2CPP can pass them as they are.

use glam::{Quat, Vec3};

use crate::core::{AnchorSource, ChainParams, EngineSettings, Stats, Transform};

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
    /// World gravity, m/s², each component within ±1e6. Default (0, -9.81, 0).
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
    /// An anchor moving farther than this (m) in one step is a teleport: the chain is carried rigidly.
    /// > 0; FLT_MAX disables. Default 1.
    pub teleport_distance: f32,
    /// An anchor turning more than this (radians) in one step is a teleport. > 0; above pi disables.
    /// Default pi/2.
    pub teleport_angle: f32,
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
    /// Particle radius, m, in [0, 1e6] (weight of orientations in shape matching). Default 0.02.
    pub radius: f32,
    /// Multiplier on the engine's gravity, in [-100, 100]. Default 1.
    pub gravity_scale: f32,
    /// `KDW_ANCHOR_VIEW_REFERENCE` (default) or `KDW_ANCHOR_OWN`.
    pub anchor: u32,
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
    pub reserved: u32,
    pub substeps_total: u64,
    /// Internal steps where the direct inextensibility solve failed and a fallback ran.
    pub solver_fallbacks: u64,
    /// Simulated seconds dropped because a step needed more than `max_substeps`.
    pub time_dropped: f64,
    /// Simulated seconds advanced in total.
    pub simulated_time: f64,
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
        }
    }
}

impl From<&kdw_engine_def> for EngineSettings {
    fn from(d: &kdw_engine_def) -> Self {
        Self {
            gravity: d.gravity.into(),
            substep_rate: d.substep_rate,
            max_substeps: d.max_substeps,
            iterations: d.iterations,
            time_scale: d.time_scale,
            teleport_distance: d.teleport_distance,
            teleport_angle: d.teleport_angle,
        }
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
        })
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
            reserved: 0,
            substeps_total: s.substeps_total,
            solver_fallbacks: s.solver_fallbacks,
            time_dropped: s.time_dropped,
            simulated_time: s.simulated_time,
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
        assert_eq!(size_of::<kdw_engine_def>(), 4 + 12 + 6 * 4);
        assert_eq!(size_of::<kdw_chain_def>(), 8 * 4);
        assert_eq!(size_of::<kdw_engine_stats>(), 6 * 4 + 4 * 8);
    }
}
