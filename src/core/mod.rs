//! The simulation core: plain safe Rust, no C types.
//!
//! - [`math`]: rigid transforms and quaternion helpers
//! - [`shape`]: shapes and their encoded form (SPEC 3.1)
//! - [`weights`]: view direction and blend weights (3.2)
//! - [`blend`]: blending encoded shapes (3.3)
//! - [`polar`], [`rod`], [`inextensible`], [`warm_start`], [`implicit`]: the oriented-particle rod and its
//!   constraints (3.4)
//! - [`lanes`]: the same rod, chains of equal length side by side in SIMD lanes
//! - [`collider`], [`collision`]: colliders and the contact pass (3.7)
//! - [`batch`]: many engines in one call (optionally on a thread pool)
//! - [`params`]: settings, parameters, units
//! - [`buffers`]: reusable buffers sized before the steps that fill them
//! - `prefetch`: cache lines asked for ahead of the loops that read them
//! - [`arena`], [`chain`], [`engine`]: objects, ids and the stepping loop (3.5, 3.6, 3.9)

pub(crate) mod arcs;
pub mod arena;
pub mod batch;
pub mod blend;
pub(crate) mod bones;
pub(crate) mod buffers;
pub mod chain;
pub mod collider;
pub mod collision;
pub(crate) mod elementary;
pub mod engine;
pub mod error;
pub(crate) mod glam_order;
pub mod implicit;
pub mod inextensible;
pub mod lanes;
pub mod math;
pub mod params;
pub mod polar;
pub(crate) mod prefetch;
pub(crate) mod reach;
pub(crate) mod rest_carry;
pub mod rod;
pub mod shape;
pub mod sketch;
pub mod stability;
pub mod warm_start;
pub mod weights;

pub use batch::step_engines;
pub use chain::ViewShapeId;
pub use collider::{ColliderDef, ColliderId, ColliderShape};
pub use engine::{ChainId, Engine, Stats};
pub use error::{Error, ErrorKind, Result};
pub use lanes::{Solver, simd_path};
pub use math::Transform;
pub use params::{AnchorSource, ChainParams, EngineSettings, TeleportMode};

/// Whether this build has `portable-determinism`: the same inputs give the same bits on x86-64 and aarch64, as
/// the arithmetic calls no C library function (README, "Same bits on x86-64 and aarch64"). Builds without it
/// agree only with themselves on one kind of machine. Hosts that replay or run in lockstep across machines check
/// it on every peer.
pub const fn portable_determinism() -> bool {
    cfg!(feature = "portable-determinism")
}
