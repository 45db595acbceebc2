//! Which lengths solve keeps a long substep stable: the direct solve while the chain's tension allows it, else
//! a projection (bug 10 in docs/robustness.md).
//!
//! The direct solve ([`inextensible`](super::inextensible)) corrects along the start bonds. For a chain's
//! sideways motion that is an explicit step, like leapfrog's: a taut chain's shortest sideways wave, its joints
//! alternating from side to side (a zig-zag), stays bounded only while the substep is short for the chain's
//! tension. On a longer one the zig-zag grows from rounding until the direct solve fails, and the chain jitters
//! by tens of degrees a frame without ever settling: 16-joint hair of 2.5 cm segments did at 60 Hz (LOD 2 at the
//! default rate) at every stiffness, and at 120 Hz (LOD 1) from stiffness 0.72 on.
//!
//! A linear model of one substep, for the zig-zag's amplitude `y` and its change `u` over the substep before:
//! shape matching's passes take the prediction `y + u` to `A (y + u)`, and the lengths solves add
//! - the direct solve (corrections along the start bonds): `- b y`, stable while `b <= 1 + 3 A`;
//! - the Gauss-Newton projection (corrections along the bonds as they are, first those of the prediction):
//!   roughly `A (y + u) (1 - b)`; this part of the model is cruder (the projection relinearises as it goes),
//!   so its bound is measured: [`GAUSS_NEWTON_LOWEST`];
//! - the exact projection (the nearest positions that meet the lengths): `A (y + u) / (1 + b)`, always stable.
//!
//! `b = 4 T`, where the tension `T` adds up the largest multiplier of each direct solve of the substep (a
//! multiplier scales its start bond, so a bond's correction moves each end by the multiplier times the bond;
//! the zig-zag's bonds lean alternately, so a joint's two corrections add up sideways, four times the lean).
//! `A = (1 - ZIGZAG_PER_PULL alpha)^iterations`. The stability bounds are those of `y' = c y + d u` with
//! `u' = y' - y` (Jury's conditions).

/// How much of a zig-zag one shape-matching pass removes per unit of its pull `alpha` (`A` above), for the
/// modes that grow: fitted to where the direct solve's jitter began in throwaway runs of a 16-joint chain of
/// 2.5 cm segments sticking out sideways (`tests/level_of_detail.rs` runs the same chain): at 120 Hz with one
/// iteration it held at a pull of 0.807 and grew at 0.837 with a tension of 0.23 (1.227 to 1.273); at 80 Hz
/// with two iterations it grew with two tensions of about 0.33 and held at 90 Hz with 0.26 to 0.28 (both
/// within the bound this value gives).
const ZIGZAG_PER_PULL: f64 = 1.25;

/// The lowest `A (1 - b)` at which the Gauss-Newton projection keeps a chain settling; below it the exact
/// projection takes over (it costs more: at LOD 2 it took 38 % of a 1000 x 16 hair frame where it ran for
/// every refused solve). Measured with every refused solve forced onto the Gauss-Newton projection
/// (a throwaway build) on the chain of `tests/skipping.rs`' `every_level_of_detail_lets_a_chain_settle`
/// (damping 1/s, 60 fps, at 30 to 80 Hz with one or two iterations): it settled in every run whose median of
/// `A (1 - b)` was -3.45 or above and kept jittering by 1 to 5 degrees a frame in runs at -4.7 and below
/// (limp and soft chains); the hair of the report's scenes runs at -0.2 to -0.4 at LOD 2. The exact projection
/// held in all of them.
const GAUSS_NEWTON_LOWEST: f64 = -2.0;

/// The zig-zag's gain `A` of a substep's shape-matching passes.
pub fn zigzag_gain(alpha_per_iteration: f32, iterations: u32) -> f64 {
    (1.0 - ZIGZAG_PER_PULL * alpha_per_iteration as f64).powi(iterations.max(1) as i32)
}

/// The projection that takes over from a direct solve the budget refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Projection {
    /// The Gauss-Newton projection first (the exact one if it fails), as after a failed direct solve.
    GaussNewton,
    /// The exact projection first.
    Exact,
}

/// The tension a substep's direct solves may still carry, and what takes over when one would carry more.
#[derive(Clone, Copy, Debug)]
pub struct TensionBudget {
    gain: f64,
    spent: f64,
    limited: bool,
}

impl TensionBudget {
    /// No limit, and the Gauss-Newton projection after a failed direct solve: for the solves that restore the
    /// lengths after contacts (and `inextensible::solve_prepared`'s other callers), as before the budget.
    pub const UNLIMITED: Self = Self { gain: 1.0, spent: 0.0, limited: false };

    /// A substep's budget, for shape-matching passes of zig-zag gain `gain` ([`zigzag_gain`]).
    pub fn new(gain: f64) -> Self {
        Self { gain, spent: 0.0, limited: true }
    }

    /// The largest multiplier the next direct solve may end with.
    pub fn room(&self) -> f64 {
        if self.limited { direct_limit(self.gain) - self.spent } else { f64::INFINITY }
    }

    /// A direct solve ended with largest multiplier `tension`.
    pub fn spend(&mut self, tension: f64) {
        self.spent += tension;
    }

    /// What takes over from a direct solve that would have ended with largest multiplier `tension`.
    pub fn projection(&self, tension: f64) -> Projection {
        if self.limited { projection(self.gain, self.spent + tension) } else { Projection::GaussNewton }
    }
}

/// The tension a substep's direct solves may carry in all, for shape-matching passes of zig-zag gain `gain`
/// (a tension spent is never NaN: `inextensible::largest_multiplier` passes NaN over).
#[inline(always)]
pub fn direct_limit(gain: f64) -> f64 {
    (1.0 + 3.0 * gain) / 4.0
}

/// [`TensionBudget::projection`] for a substep of gain `gain` whose tension would add up to `tension`.
#[inline(always)]
pub fn projection(gain: f64, tension: f64) -> Projection {
    let c = gain * (1.0 - 4.0 * tension);
    if (GAUSS_NEWTON_LOWEST..=1.0).contains(&c) { Projection::GaussNewton } else { Projection::Exact }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The bounds of the module's documentation: iterate the model's 2 x 2 map and see which amplitudes grow.
    fn grows(c: f64, d: f64) -> bool {
        let (mut y, mut u) = (1.0f64, 0.0f64);
        for _ in 0..4000 {
            let next = c * y + d * u;
            u = next - y;
            y = next;
            // Growth is exponential; the leapfrog's neutral oscillation (gain 1, no shape matching) stays near 1.
            if y.abs() + u.abs() > 1e3 {
                return true;
            }
        }
        false
    }

    #[test]
    fn the_budget_is_the_direct_solves_stability_bound() {
        for gain in [-0.3, -0.1, 0.0, 0.2, 0.5, 0.9, 1.0] {
            let limit = direct_limit(gain);
            // The direct solve: y' = A (y + u) - b y.
            let direct = |tension: f64| grows(gain - 4.0 * tension, gain);
            assert!(!direct(limit * 0.98), "gain {gain}: tension {} should hold", limit * 0.98);
            assert!(direct(limit * 1.02 + 1e-3), "gain {gain}: tension {} should grow", limit * 1.02 + 1e-3);
        }
        // A limp chain (no shape matching): the leapfrog bound of the zig-zag, a largest multiplier of 1.
        assert_eq!(direct_limit(zigzag_gain(0.0, 1)), 1.0);
        let mut budget = TensionBudget::new(1.0);
        budget.spend(0.25);
        assert_eq!(budget.room(), 0.75);
        assert_eq!(TensionBudget::UNLIMITED.room(), f64::INFINITY);
    }

    #[test]
    fn the_exact_projection_takes_over_where_the_gauss_newton_one_kept_jittering() {
        // The hair of the report's scenes at LOD 2 (gain 0.167, tensions 0.54 to 0.86): Gauss-Newton.
        for tension in [0.54, 0.7, 0.86] {
            assert_eq!(projection(0.167, tension), Projection::GaussNewton);
        }
        // A limp chain at 60 Hz (gain 1, tension about 1.6) and a soft one (gain 0.92, tension about 1.5).
        assert_eq!(projection(1.0, 1.6), Projection::Exact);
        assert_eq!(projection(0.92, 1.5), Projection::Exact);
        assert_eq!(projection(1.0, f64::NAN), Projection::Exact);
        // Exact: A / (1 + b) holds for every tension at every gain a pass can have (from 1 - ZIGZAG_PER_PULL).
        assert_eq!(zigzag_gain(1.0, 1), -0.25);
        for gain in [-0.25, 0.0, 1.0] {
            for tension in [0.0, 1.0, 100.0] {
                let c = gain / (1.0 + 4.0 * tension);
                assert!(!grows(c, c));
            }
        }
    }
}
