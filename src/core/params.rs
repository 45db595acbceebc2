//! Engine settings and chain parameters, their defaults, units and valid ranges.

use glam::Vec3;

use super::elementary;
use super::error::{Error, Result};

/// Where a chain's anchor (the kinematic bone joint 0 is attached to) comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AnchorSource {
    /// The view reference joint K given with every step (the default).
    ViewReference,
    /// The chain's own entry in the batched anchors.
    Own,
}

/// What happens to a chain whose anchor teleports (jumps farther or turns more than the engine's thresholds
/// in one step, or is told to with an explicit teleport call).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TeleportMode {
    /// Move the chain rigidly with its anchor: it keeps its current shape and its motion relative to the
    /// anchor, and gains no energy from the jump.
    CarryShape,
    /// Put the chain back to its rest shape under the new anchor, at rest.
    Reset,
}

/// Engine-wide settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EngineSettings {
    /// World gravity in character units per s² (× `scale` m/s²), each component within ±1e6.
    pub gravity: Vec3,
    /// Internal fixed steps per simulated second, Hz. Range [30, 10000].
    pub substep_rate: f32,
    /// Most internal steps one `step` call may run; time beyond is dropped and counted. Range [1, 1000].
    pub max_substeps: u32,
    /// Shape-matching + inextensibility passes per internal step. Range [1, 64].
    pub iterations: u32,
    /// Simulated seconds per real second; 0 pauses. Range [0, 100].
    pub time_scale: f32,
    /// An anchor moving farther than this in one call is a teleport, in character units (× `scale` m).
    /// > 0; `f32::MAX` disables.
    pub teleport_distance: f32,
    /// An anchor turning more than this in one call (radians) is a teleport. > 0; above pi disables.
    pub teleport_angle: f32,
    /// What a teleport does to a chain.
    pub teleport_mode: TeleportMode,
    /// A chain whose particles all move slower than this relative to its root (character units/s, × `scale`)
    /// for `SLEEP_DELAY` seconds, under a still anchor, rest shape and colliders, sleeps: it costs almost
    /// nothing until any of them changes. In [0, 1e6]; 0 never sleeps. Default 5e-6: low enough that a chain
    /// falls asleep within 1e-5 chain lengths of its resting pose (SPEC 6.1 rest fidelity).
    pub sleep_speed: f32,
    /// Level of detail for distant characters, in [0, 3]: each level halves the internal step rate (not
    /// below 30 Hz) and the iterations (not below 1). Stiffness and damping keep their meaning; accuracy
    /// drops as `docs/accuracy.md` shows. Default 0.
    pub lod: u32,
    /// Size of the character relative to the units its parameters are tuned in, dimensionless, in
    /// [1e-6, 1e6]. Multiplies every length-valued parameter: gravity, `teleport_distance`, chain and joint
    /// radii. A character scaled by 100 with `scale` 100 moves exactly like the unscaled one, 100 times
    /// larger. Transforms, joint positions and collider sizes are world units and are not scaled.
    pub scale: f32,
}

impl Default for EngineSettings {
    fn default() -> Self {
        Self {
            gravity: Vec3::new(0.0, -9.81, 0.0),
            substep_rate: 240.0,
            max_substeps: 16,
            iterations: 2,
            time_scale: 1.0,
            teleport_distance: 1.0,
            teleport_angle: std::f32::consts::FRAC_PI_2,
            teleport_mode: TeleportMode::CarryShape,
            sleep_speed: 5e-6,
            lod: 0,
            scale: 1.0,
        }
    }
}

fn check(ok: bool, message: impl FnOnce() -> String) -> Result<()> {
    if ok { Ok(()) } else { Err(Error::invalid_argument(message())) }
}

impl EngineSettings {
    pub fn validate(&self) -> Result<()> {
        check(self.gravity.is_finite() && self.gravity.abs().max_element() <= MAX_GRAVITY, || {
            format!("gravity components must be within +-{MAX_GRAVITY} m/s^2")
        })?;
        check((30.0..=10000.0).contains(&self.substep_rate), || {
            format!("substep_rate {} outside [30, 10000] Hz", self.substep_rate)
        })?;
        check((1..=1000).contains(&self.max_substeps), || {
            format!("max_substeps {} outside [1, 1000]", self.max_substeps)
        })?;
        check((1..=64).contains(&self.iterations), || format!("iterations {} outside [1, 64]", self.iterations))?;
        check((0.0..=100.0).contains(&self.time_scale), || format!("time_scale {} outside [0, 100]", self.time_scale))?;
        check(self.teleport_distance > 0.0 && self.teleport_distance.is_finite(), || {
            format!("teleport_distance {} must be finite and > 0", self.teleport_distance)
        })?;
        check(self.teleport_angle > 0.0 && self.teleport_angle.is_finite(), || {
            format!("teleport_angle {} must be finite and > 0", self.teleport_angle)
        })?;
        check((0.0..=1e6).contains(&self.sleep_speed), || {
            format!("sleep_speed {} outside [0, 1e6]", self.sleep_speed)
        })?;
        check(self.lod <= MAX_LOD, || format!("lod {} outside [0, {MAX_LOD}]", self.lod))?;
        check((MIN_SCALE..=MAX_SCALE).contains(&self.scale), || {
            format!("scale {} outside [{MIN_SCALE}, {MAX_SCALE}]", self.scale)
        })?;
        Ok(())
    }

    /// The internal step rate after the level of detail.
    pub fn effective_substep_rate(&self) -> f32 {
        (self.substep_rate / (1u32 << self.lod) as f32).max(MIN_SUBSTEP_RATE.min(self.substep_rate))
    }

    /// The iterations after the level of detail.
    pub fn effective_iterations(&self) -> u32 {
        (self.iterations >> self.lod).max(1)
    }

    pub fn substep(&self) -> f32 {
        1.0 / self.effective_substep_rate()
    }
}

/// Per-chain parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChainParams {
    /// Pull towards the rest shape, dimensionless in [0, 1]: 0 is limp (an n-pendulum), 1 is rigid.
    /// In between the rest shape acts like a spring of angular frequency `STIFFNESS_FREQUENCY * s / (1 - s)`
    /// rad/s, independent of substep rate and iterations.
    pub stiffness: f32,
    /// Velocity damping per second, 1/s: velocity relative to the chain's root decays by `exp(-damping * t)`
    /// (relative, so motion does not depend on how fast the whole character travels). Range [0, 1000].
    pub damping: f32,
    /// Share of the motion caused by a changing rest shape that is not turned into velocity, [0, 1].
    pub momentum_suppression: f32,
    /// Mass of each particle, kg, in [1e-6, 1e6]. (Uniform masses: only matters once forces other than gravity act.)
    pub mass: f32,
    /// Particle radius in character units (× the engine's `scale` m), in [0, 1e6]: the collision radius of
    /// every joint (unless per-joint radii are set) and the weight of orientations in shape matching.
    pub radius: f32,
    /// Multiplier on the engine's gravity, dimensionless. Range [-100, 100].
    pub gravity_scale: f32,
    pub anchor: AnchorSource,
    /// Collision layers this chain collides with: a collider affects it when `collision_mask & layers` is
    /// non-zero. 0 turns collisions off for the chain (it then runs no collision code). Default: all.
    pub collision_mask: u32,
    /// Coulomb friction coefficient against colliders, dimensionless, in [0, 10]: a particle pressed onto a
    /// collider does not slide while the tangential pull is below `friction` times the normal one.
    pub friction: f32,
}

/// Ranges that keep every product in the solver (radius², 1/mass, g·h², mass·v²) far from float32
/// overflow, while covering characters from millimetres to kilometres.
pub const MAX_GRAVITY: f32 = 1e6;
pub const MIN_MASS: f32 = 1e-6;
pub const MAX_MASS: f32 = 1e6;
pub const MAX_RADIUS: f32 = 1e6;
pub const MAX_FRICTION: f32 = 10.0;
pub const MAX_LOD: u32 = 3;
/// Lowest internal step rate (Hz) a level of detail goes down to.
pub const MIN_SUBSTEP_RATE: f32 = 30.0;
/// Seconds a chain must stay below `sleep_speed` before it sleeps.
pub const SLEEP_DELAY: f32 = 0.5;
/// Range of the engine's `scale`: characters from micrometre to kilometre size relative to their tuning.
pub const MIN_SCALE: f32 = 1e-6;
pub const MAX_SCALE: f32 = 1e6;
/// Largest accepted coordinate of any position (m). Beyond it float32 resolves less than 60 m anyway.
pub const MAX_COORDINATE: f32 = 1e9;

/// Angular frequency (rad/s) of each shape-matching group's pull at stiffness 0.5 (10 Hz). The bending
/// modes of a whole chain are slower: a group sees only its local share of a global shape error.
pub const STIFFNESS_FREQUENCY: f32 = 20.0 * std::f32::consts::PI;

impl Default for ChainParams {
    fn default() -> Self {
        Self {
            stiffness: 0.5,
            damping: 1.0,
            momentum_suppression: 1.0,
            mass: 1.0,
            radius: 0.02,
            gravity_scale: 1.0,
            anchor: AnchorSource::ViewReference,
            collision_mask: u32::MAX,
            friction: 0.3,
        }
    }
}

impl ChainParams {
    pub fn validate(&self) -> Result<()> {
        check((0.0..=1.0).contains(&self.stiffness), || format!("stiffness {} outside [0, 1]", self.stiffness))?;
        check((0.0..=1000.0).contains(&self.damping), || format!("damping {} outside [0, 1000] 1/s", self.damping))?;
        check((0.0..=1.0).contains(&self.momentum_suppression), || {
            format!("momentum_suppression {} outside [0, 1]", self.momentum_suppression)
        })?;
        check((MIN_MASS..=MAX_MASS).contains(&self.mass), || {
            format!("mass {} outside [{MIN_MASS}, {MAX_MASS}] kg", self.mass)
        })?;
        check((0.0..=MAX_RADIUS).contains(&self.radius), || {
            format!("radius {} outside [0, {MAX_RADIUS}] m", self.radius)
        })?;
        check((-100.0..=100.0).contains(&self.gravity_scale), || {
            format!("gravity_scale {} outside [-100, 100]", self.gravity_scale)
        })?;
        check((0.0..=MAX_FRICTION).contains(&self.friction), || {
            format!("friction {} outside [0, {MAX_FRICTION}]", self.friction)
        })?;
        Ok(())
    }

    /// Fraction of the way to the goals per substep of length `h`: `1 - exp(-(omega h)^2)`, a spring of
    /// frequency omega for small `omega h` (acceleration `omega^2` times the distance to the goal, whatever
    /// `h`), saturating at 1 (rigid) as the stiffness reaches 1. Where `omega h > 1` the spring is stiffer
    /// than one substep can resolve and the chain is simply rigid at that rate.
    pub fn alpha_per_substep(&self, h: f32) -> f32 {
        if self.stiffness <= 0.0 {
            return 0.0;
        }
        if self.stiffness >= 1.0 {
            return 1.0;
        }
        let omega = STIFFNESS_FREQUENCY * self.stiffness / (1.0 - self.stiffness);
        let x = omega * h;
        -elementary::exp_m1(-(x * x))
    }

    /// The per-iteration fraction whose `iterations`-fold application equals the per-substep one.
    pub fn alpha_per_iteration(&self, h: f32, iterations: u32) -> f32 {
        let a = self.alpha_per_substep(h);
        if a >= 1.0 || a <= 0.0 {
            return a;
        }
        -elementary::exp_m1(elementary::ln(1.0 - a) / iterations as f32)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid() {
        EngineSettings::default().validate().unwrap();
        ChainParams::default().validate().unwrap();
    }

    #[test]
    fn alpha_limits_and_iteration_split() {
        let p = |s| ChainParams { stiffness: s, ..Default::default() };
        assert_eq!(p(0.0).alpha_per_substep(1.0 / 240.0), 0.0);
        assert_eq!(p(1.0).alpha_per_iteration(1.0 / 240.0, 4), 1.0);
        let a = p(0.7).alpha_per_substep(1.0 / 240.0);
        let a4 = p(0.7).alpha_per_iteration(1.0 / 240.0, 4);
        assert!((1.0 - (1.0 - a4).powi(4) - a).abs() < 1e-6);
        // Small-step limit: alpha / h^2 is the spring constant omega^2, independent of h.
        // Stiffness 0.1: omega = STIFFNESS_FREQUENCY / 9, so omega h << 1 at both rates.
        let omega = STIFFNESS_FREQUENCY / 9.0;
        let k1 = p(0.1).alpha_per_substep(1.0 / 240.0) * 240.0f32.powi(2);
        let k2 = p(0.1).alpha_per_substep(1.0 / 960.0) * 960.0f32.powi(2);
        assert!((k1 / k2 - 1.0).abs() < 0.01 && (k2 / (omega * omega) - 1.0).abs() < 0.01, "{k1} {k2}");
    }

    #[test]
    fn rejects_out_of_range() {
        assert!(ChainParams { stiffness: f32::NAN, ..Default::default() }.validate().is_err());
        assert!(ChainParams { mass: 0.0, ..Default::default() }.validate().is_err());
        assert!(EngineSettings { iterations: 0, ..Default::default() }.validate().is_err());
        assert!(
            EngineSettings { gravity: Vec3::new(0.0, f32::INFINITY, 0.0), ..Default::default() }.validate().is_err()
        );
    }
}
