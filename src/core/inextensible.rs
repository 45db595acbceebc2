//! Inextensibility: the chain's distance constraints solved together, the way molecular dynamics solves
//! rigid bonds (SHAKE). Corrections act along the bond directions of the previous substep, which keeps the
//! scheme symplectic and second order; the coupled system is tridiagonal, so a Newton iteration is one
//! O(n) Thomas solve. Where it fails (long or fine chains, bug 1 in docs/robustness.md), [`implicit`] solves
//! the exact projection instead.

use glam::{DVec3, Vec3};

use super::buffers::reserve_total;
use super::implicit::{self, ImplicitScratch};
use super::stability::{Projection, TensionBudget};
use super::warm_start::{MultiplierHistory, WARM_SLOTS};

/// Relative error of `|b|^2 / l^2 - 1` below which a bond counts as satisfied: 5e-8 in length, the float32
/// floor (a chain's lengths are float32, so they are known to 6e-8 of themselves; the render pose is float32).
/// Solving tighter (it was 1e-9) takes one more pass of the solve in most substeps of a swaying chain, for no
/// change the accuracy report shows beyond float rounding (stretch unchanged): `valgrind --tool=callgrind
/// target/release/examples/step_cost 64 16 20 sway` counted 23.7M instructions in `solve_lengths8` at 1e-9,
/// 19.9M here (with `polar::LANDING_ANGLE` raised in the same commit, 49a58a2).
pub(crate) const TOLERANCE: f64 = 1e-7;
pub(crate) const MAX_NEWTON_ITERATIONS: usize = 8;
/// Largest error still accepted as a rounding floor when Newton stops improving.
pub(crate) const STAGNATION_LIMIT: f64 = 1e-3;
const FALLBACK_SWEEPS: usize = 64;
/// Iterations of the relinearized fallback (it converges in 3 to 6 where it converges at all).
const RELINEARIZED_ITERATIONS: usize = 16;
/// The relinearized fallback has lost its way once an iteration leaves its bonds off by more than their own
/// squared length (`|b|^2 / l^2 - 1 > 1`) and this many times its start's error: on bug 1's fine ropes its
/// first step overshoots by far more and it never recovers within its iterations, where on the hair ropes it
/// converges on it stays within that (docs/robustness.md, bug 1).
const RELINEARIZED_LOST: f64 = 4.0;
/// A pivot of the Newton system smaller than this share of its largest diagonal entry counts as vanishing.
pub(crate) const MIN_PIVOT: f64 = 1e-7;

/// Reusable buffers, one entry per bond unless noted. The dynamic particles' masses are uniform, so they
/// cancel out of the solve: only the kinematic root's infinite mass (it never moves) shapes it.
#[derive(Default)]
pub struct ConstraintScratch {
    /// The start positions' bonds, from [`prepare`]: the direct solve's correction directions.
    start_bonds: Vec<DVec3>,
    /// The current bonds: the fallback's correction directions.
    current_bonds: Vec<DVec3>,
    /// Squared rest lengths and their reciprocals, from [`prepare`].
    length_squared: Vec<f64>,
    inverse_length_squared: Vec<f64>,
    newton: NewtonScratch,
    implicit: ImplicitScratch,
}

#[derive(Default)]
struct NewtonScratch {
    /// Correction multipliers (inverse mass included).
    mu: Vec<f64>,
    /// The Thomas algorithm's modified upper diagonal and right-hand side.
    c_prime: Vec<f64>,
    d_prime: Vec<f64>,
    /// Positions under the current multipliers (one per particle).
    corrected: Vec<DVec3>,
    /// The last Newton step of the multipliers.
    step: Vec<f64>,
    /// The Gauss-Newton projection's rows of the system, before its elimination ([`TwistedPass`]).
    rows: Vec<BondRow>,
    /// The largest multiplier of the last direct solve that converged, and whether the budget refused it.
    tension: f64,
    refused: bool,
}

impl ConstraintScratch {
    pub fn reserve(&mut self, bonds: usize) {
        let NewtonScratch { mu, c_prime, d_prime, corrected, step, rows, .. } = &mut self.newton;
        for v in [&mut self.length_squared, &mut self.inverse_length_squared, mu, c_prime, d_prime, step] {
            if v.len() < bonds {
                v.resize(bonds, 0.0);
            }
        }
        for v in [&mut self.start_bonds, &mut self.current_bonds] {
            if v.len() < bonds {
                v.resize(bonds, DVec3::ZERO);
            }
        }
        if rows.len() < bonds {
            rows.resize(bonds, BondRow::default());
        }
        if corrected.len() < bonds + 1 {
            corrected.resize(bonds + 1, DVec3::ZERO);
        }
        self.implicit.reserve(bonds);
    }
}

/// Prepares [`solve_prepared`] for the start positions `x` of a substep: their bonds are the correction
/// directions of every solve until `x` moves (the contact pass can move it; prepare again then).
pub fn prepare(x: &[DVec3], lengths: &[f32], s: &mut ConstraintScratch) {
    let m = lengths.len();
    debug_assert!(x.len() == m + 1);
    set_lengths(lengths, s);
    for k in 0..m {
        s.start_bonds[k] = x[k + 1] - x[k];
    }
}

/// Moves `p` so that `|p[k+1] - p[k]| = lengths[k]` for every bond, correcting along the previous
/// positions' bonds `x[k+1] - x[k]`. Particle 0 never moves. Returns `false` when that direct solve failed
/// (a bond turned by about 90 degrees in one substep, as at the tip of a whipping rope, or a long chain of
/// millimetre segments whose multipliers dwarf its segments) and the fallback ran (see `fall_back`): a
/// Gauss-Newton projection along the current bonds, re-read every iteration (not symplectic); if that fails,
/// the exact projection ([`implicit`]); if even that fails, Gauss-Seidel projection from the positions the
/// fallback was given.
pub fn solve(x: &[DVec3], p: &mut [DVec3], lengths: &[f32], s: &mut ConstraintScratch) -> bool {
    prepare(x, lengths, s);
    solve_prepared(p, lengths, s)
}

/// [`solve`] with the previous positions given to the last [`prepare`] (with the same `lengths`).
pub fn solve_prepared(p: &mut [DVec3], lengths: &[f32], s: &mut ConstraintScratch) -> bool {
    let mut unlimited = TensionBudget::UNLIMITED;
    solve_direct(p, lengths, s, &mut unlimited) == Solved::Direct
}

/// Which solve met the lengths.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Solved {
    Direct,
    GaussNewton,
    Exact,
    GaussSeidel,
}

/// The direct solve within `budget` ([`super::stability`]), or what takes over from it.
fn solve_direct(p: &mut [DVec3], lengths: &[f32], s: &mut ConstraintScratch, budget: &mut TensionBudget) -> Solved {
    let m = lengths.len();
    debug_assert!(p.len() == m + 1 && s.start_bonds.len() >= m);
    let (l2, inv_l2) = (&s.length_squared[..m], &s.inverse_length_squared[..m]);
    let room = budget.room();
    if newton_along_directions(p, &s.start_bonds[..m], &Free, l2, inv_l2, &mut s.newton, Start::Cold, room) {
        budget.spend(s.newton.tension);
        return Solved::Direct;
    }
    fall_back_within(p, lengths, s, budget)
}

/// After a direct solve that failed or that `budget` refused (either leaves `p` as it was, and its last
/// multipliers in `s.newton.mu`): `fall_back`, from the projection the budget picks for the tension the direct
/// solve ended with (for one that failed, the tension of its last step).
fn fall_back_within(p: &mut [DVec3], lengths: &[f32], s: &mut ConstraintScratch, budget: &TensionBudget) -> Solved {
    let tension = if s.newton.refused { s.newton.tension } else { largest_multiplier(&s.newton.mu[..lengths.len()]) };
    fall_back(p, lengths, s, budget.projection(tension))
}

/// [`solve_direct`] from the multipliers `history` extrapolates ([`super::warm_start`]), or from none if it
/// remembers none; `history` learns how it ended. While the same solve of the last substeps kept ending in
/// the Gauss-Newton projection, this one goes straight to it, except every [`RETRY_DIRECT`]-th substep: the
/// direct solve fails on such chains after two to four passes, some twice (warm, then cold; on the report's
/// 1 x 1000 hair rope it took 20 % of the samples, `docs/robustness.md` bug 1), and a failed direct solve
/// leaves `p` as it was, so the projection computes what it would have computed after it, to the bit.
fn solve_warm(
    p: &mut [DVec3],
    lengths: &[f32],
    s: &mut ConstraintScratch,
    history: &mut MultiplierHistory,
    budget: &mut TensionBudget,
) -> Solved {
    let m = lengths.len();
    debug_assert!(p.len() == m + 1 && s.start_bonds.len() >= m);
    if relinearizes(history.relinearized) {
        // No direct solve's multipliers: the exact projection, if the Gauss-Newton one fails, starts from none.
        s.newton.mu[..m].fill(0.0);
        let solved = fall_back(p, lengths, s, Projection::GaussNewton);
        history.relinearized = relinearized_after(history.relinearized, solved);
        return solved;
    }
    let start = if history.remembered() {
        history.write_start(&mut s.newton.mu[..m]);
        Start::Warm
    } else {
        Start::Cold
    };
    let (l2, inv_l2) = (&s.length_squared[..m], &s.inverse_length_squared[..m]);
    let room = budget.room();
    let direct = newton_along_directions(p, &s.start_bonds[..m], &Free, l2, inv_l2, &mut s.newton, start, room)
        // A warm start that failed tries again from none before the fallback, so that it never brings one on
        // (one the budget refused met the lengths: from none it would meet them with the same tension).
        || (start == Start::Warm
            && !s.newton.refused
            && newton_along_directions(p, &s.start_bonds[..m], &Free, l2, inv_l2, &mut s.newton, Start::Cold, room));
    let solved = if direct {
        budget.spend(s.newton.tension);
        Solved::Direct
    } else {
        fall_back_within(p, lengths, s, budget)
    };
    if solved == Solved::Direct {
        history.learn(&s.newton.mu[..m]);
    } else {
        history.forget();
    }
    history.relinearized = relinearized_after(history.relinearized, solved);
    solved
}

/// Whether a solve that ended in the Gauss-Newton projection in the last `streak` substeps in a row goes
/// straight to it ([`solve_warm`]; the lane solver decides the same per lane).
#[inline(always)]
pub(crate) fn relinearizes(streak: u32) -> bool {
    streak >= RELINEARIZE_AFTER && !streak.is_multiple_of(RETRY_DIRECT)
}

/// The Gauss-Newton projections in a row after which a solve goes straight to it: one alone is most often
/// a jolt (a collider's push, a fast turn of the root) on a chain whose direct solve works again in the next
/// substep, and a lane that skips it runs the projection on its own while its group's direct solve runs anyway.
const RELINEARIZE_AFTER: u32 = 4;

/// A solve's streak of Gauss-Newton projections after it ended in `solved`.
#[inline(always)]
pub(crate) fn relinearized_after(streak: u32, solved: Solved) -> u32 {
    // Wrapping: a streak of 2^32 substeps (200 days at 240 Hz) starts again from the direct solve, not a panic.
    if solved == Solved::GaussNewton { streak.wrapping_add(1) } else { 0 }
}

/// [`solve_prepared`] for the solve after iteration `iteration` (from 1) of a substep's shape matching: from
/// the multipliers the same solve ended with in the last substeps, where it has a slot of the chain's
/// `memory` ([`super::warm_start`]). Returns `false` when the direct solve failed (a fallback ran).
pub fn solve_again(
    p: &mut [DVec3],
    lengths: &[f32],
    s: &mut ConstraintScratch,
    memory: &mut SolveMemory,
    iteration: usize,
    budget: &mut TensionBudget,
) -> bool {
    match memory.warm.get_mut(iteration) {
        Some(history) if history.last.len() == lengths.len() => {
            solve_warm(p, lengths, s, history, budget) == Solved::Direct
        }
        _ => solve_direct(p, lengths, s, budget) == Solved::Direct,
    }
}

/// [`solve_prepared`] for a contact round that ends a substep where some particles slide on a collider: a
/// particle with a contact normal in `normals` (one per particle; zero for none) moves only across it, so
/// the lengths stop undoing the contact that gave it. The direct solve runs so restricted and, where it
/// fails, the Gauss-Newton fallback too; where that fails as well, the lengths are met as [`solve_prepared`]
/// meets them (contacts aside), from where that projection got to if it is nearer the lengths than the
/// positions given, else from those. On the report's 0.8 m rope of 1000 joints with colliders, the
/// projection fails in the first rounds of a substep (its start is 0.4 to 0.5 off in `|b|^2 / l^2 - 1`);
/// met from the positions given, the lengths left the contacts about as deep as before, half a millimetre,
/// for up to ten rounds. Returns `false` when the restricted direct solve failed (a fallback ran).
///
/// `memory` is how the substep's earlier sliding solves ended. On long chains of fine segments (bug 1 in
/// docs/robustness.md) the restricted direct solve fails round after round (on the report's 0.8 m rope of
/// 1000 joints with colliders, in 86 % of the rounds, and in 92 % of those after a round where it failed):
/// after a round whose restricted direct solve failed, the substep's next rounds go straight to the restricted
/// projection, except every [`RETRY_DIRECT`]-th round in a row without it. A failed direct solve leaves `p` as it was and the
/// projection does not read its multipliers, so a skipped direct solve that would have failed changes no bit;
/// one that would have met the lengths leaves it to the projection, restricted alike. (The projection is
/// never skipped: where it meets the lengths, the sliding joints keep the contacts that bug 9's fix needs,
/// and a memory that skipped it after failures stretched `tests/collisions.rs`' 257-joint rope rooted inside
/// the head by 6.3 %.)
pub fn solve_sliding(
    p: &mut [DVec3],
    lengths: &[f32],
    normals: &[Vec3],
    s: &mut ConstraintScratch,
    memory: &mut SlidingMemory,
) -> bool {
    let m = lengths.len();
    debug_assert!(p.len() == m + 1 && normals.len() == m + 1 && s.start_bonds.len() >= m);
    let (l2, inv_l2) = (&s.length_squared[..m], &s.inverse_length_squared[..m]);
    let sliding = Sliding(normals);
    if memory.direct_failed.is_multiple_of(RETRY_DIRECT)
        && newton_along_directions(
            p,
            &s.start_bonds[..m],
            &sliding,
            l2,
            inv_l2,
            &mut s.newton,
            Start::Cold,
            f64::INFINITY,
        )
    {
        memory.direct_failed = 0;
        return true;
    }
    // Wrapping: see `relinearized_after`.
    memory.direct_failed = memory.direct_failed.wrapping_add(1);
    // The Gauss-Newton projection moves `p` as it goes: keep the given positions, for the unrestricted solve
    // should it get nowhere.
    s.newton.corrected[..=m].copy_from_slice(p);
    for k in 0..m {
        s.current_bonds[k] = p[k + 1] - p[k];
    }
    if !project_relinearized(p, &mut s.current_bonds[..m], &sliding, l2, inv_l2, &mut s.newton) {
        let given = &s.newton.corrected[..=m];
        let reached = largest_error(p, l2, inv_l2);
        if above(reached, largest_error(given, l2, inv_l2)) {
            p.copy_from_slice(given);
        }
        solve_prepared(p, lengths, s);
    }
    false
}

/// What the sliding solves ([`solve_sliding`]) of a chain's contact rounds have learnt in the current substep
/// (each substep starts with a new one).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SlidingMemory {
    /// Rounds in a row whose restricted direct solve failed or was skipped.
    direct_failed: u32,
}

/// Which moves the solve may give each particle (its inverse mass as a projection).
trait Mobility {
    /// The part of `v` particle `j` may move along.
    fn allowed(&self, j: usize, v: DVec3) -> DVec3;
}

/// Every particle moves freely.
struct Free;

impl Mobility for Free {
    #[inline(always)]
    fn allowed(&self, _: usize, v: DVec3) -> DVec3 {
        v
    }
}

/// A particle with a (unit) contact normal moves only across it; a zero normal leaves it free.
struct Sliding<'a>(&'a [Vec3]);

impl Mobility for Sliding<'_> {
    #[inline(always)]
    fn allowed(&self, j: usize, v: DVec3) -> DVec3 {
        let normal = self.0[j].as_dvec3();
        v - normal * normal.dot(v)
    }
}

/// What a chain's solves learn for its next substep: where the direct solve fails on a substep's first
/// solve (long or fine chains, bug 1 in docs/robustness.md), it fails on the next substep's too, and the
/// tensions hardly change in a substep. Part of the chain's state.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SolveMemory {
    /// The multipliers of the last exact projection, one per bond, and its correction (answer minus
    /// prediction), one per particle: the next one's start (room for both from the start, so that no step
    /// allocates).
    tension: Vec<f64>,
    correction: Vec<DVec3>,
    /// Substeps in a row whose first solve took the exact projection.
    exact_streak: u32,
    /// The direct solve's multipliers, one history per solve of a substep ([`super::warm_start`]), and the
    /// substep length and iterations they were learnt at (another rate gives other multipliers).
    pub(crate) warm: [MultiplierHistory; WARM_SLOTS],
    learnt_at: (u32, u32),
}

/// A chain whose first solves keep taking the exact projection, or a solve that keeps ending in the
/// Gauss-Newton projection, tries the direct solve again every this many substeps (every 33 ms at the default
/// 240 Hz), so that it goes back to it soon after it works again.
const RETRY_DIRECT: u32 = 8;

impl SolveMemory {
    pub fn new(bonds: usize) -> Self {
        Self {
            tension: vec![0.0; bonds],
            correction: vec![DVec3::ZERO; bonds + 1],
            exact_streak: 0,
            warm: std::array::from_fn(|_| MultiplierHistory::new(bonds)),
            learnt_at: (0, 0),
        }
    }

    /// Forgets what was learnt (the chain was placed anew).
    pub fn forget(&mut self) {
        self.exact_streak = 0;
        self.warm.iter_mut().for_each(MultiplierHistory::forget_all);
    }

    /// Before a substep of length `h` with `iterations` solves (one per iteration): the multipliers learnt
    /// at another substep length or iteration count are forgotten, and so are those of solves this substep
    /// does not run.
    pub fn begin_substep(&mut self, h: f32, iterations: u32) {
        if !self.warm_applies(h, iterations) {
            self.warm.iter_mut().for_each(MultiplierHistory::forget_all);
            self.set_learnt_at(h, iterations);
        }
    }

    /// Whether the multiplier histories were learnt at substeps of length `h` with `iterations` solves.
    pub(crate) fn warm_applies(&self, h: f32, iterations: u32) -> bool {
        self.learnt_at == (h.to_bits(), iterations)
    }

    pub(crate) fn set_learnt_at(&mut self, h: f32, iterations: u32) {
        self.learnt_at = (h.to_bits(), iterations);
    }

    /// The chain was carried rigidly by `rotation` (a teleport): the remembered corrections, world vectors,
    /// turn with it (the tensions do not depend on the orientation).
    pub fn turn(&mut self, rotation: glam::Quat) {
        let rotation = rotation.as_dquat();
        for c in &mut self.correction {
            *c = rotation * *c;
        }
    }

    /// Words for the engine's state hash (the tensions only while they are used).
    pub fn words(&self) -> impl Iterator<Item = u64> + '_ {
        let (tension, correction) =
            if self.exact_streak > 0 { (&self.tension[..], &self.correction[..]) } else { (&[][..], &[][..]) };
        let correction = correction.iter().flat_map(|c| c.to_array()).map(f64::to_bits);
        let warm = self.warm.iter().flat_map(MultiplierHistory::words);
        std::iter::once(self.exact_streak as u64)
            .chain(tension.iter().map(|t| t.to_bits()))
            .chain(correction)
            .chain(warm)
    }
}

/// [`solve_prepared`] for the first solve of a substep, with what the chain's previous substep learnt: while
/// its first solves need the exact projection, this one goes straight to it, from the last one's tensions
/// (the direct solve and the Gauss-Newton projection would fail first, and the start is closer), except every
/// [`RETRY_DIRECT`]-th substep. Returns `false` when the direct solve was not used.
pub fn solve_first(
    p: &mut [DVec3],
    lengths: &[f32],
    s: &mut ConstraintScratch,
    memory: &mut SolveMemory,
    budget: &mut TensionBudget,
) -> bool {
    if exact_from_memory(p, lengths, s, memory) {
        memory.warm[0].forget_all();
        return false;
    }
    let solved = if memory.warm[0].last.len() == lengths.len() {
        solve_warm(p, lengths, s, &mut memory.warm[0], budget)
    } else {
        solve_direct(p, lengths, s, budget)
    };
    memory.learn(solved, s, lengths.len());
    solved == Solved::Direct
}

/// The first step of [`solve_first`]: the exact projection from the remembered tensions, if the chain's
/// first solves have been taking it. Returns whether it ran and converged (`p` is untouched otherwise).
pub fn exact_from_memory(
    p: &mut [DVec3],
    lengths: &[f32],
    s: &mut ConstraintScratch,
    memory: &mut SolveMemory,
) -> bool {
    let m = lengths.len();
    if memory.tension.len() != m || !memory.wants_exact() {
        return false;
    }
    set_lengths(lengths, s);
    let (l2, inv_l2) = (&s.length_squared[..m], &s.inverse_length_squared[..m]);
    s.implicit.begin_shifted(p, &memory.tension, &memory.correction);
    if !implicit::project(p, l2, inv_l2, TOLERANCE, &mut s.implicit) {
        return false;
    }
    memory.tension.copy_from_slice(s.implicit.multipliers(m));
    memory.correction.copy_from_slice(s.implicit.correction(m));
    memory.exact_streak += 1;
    true
}

impl SolveMemory {
    /// What a first solve that ran the direct solve (`solved` says how it ended) teaches.
    pub fn learn(&mut self, solved: Solved, s: &ConstraintScratch, bonds: usize) {
        if solved == Solved::Exact && self.tension.len() == bonds {
            self.tension.copy_from_slice(s.implicit.multipliers(bonds));
            self.correction.copy_from_slice(s.implicit.correction(bonds));
            self.exact_streak += 1;
        } else {
            self.exact_streak = 0;
        }
    }

    /// Room for a chain of `bonds` bonds, so that [`copy_streak_from`](Self::copy_streak_from) such a chain's memory does
    /// not allocate.
    pub fn reserve(&mut self, bonds: usize) {
        reserve_total(&mut self.tension, bonds);
        reserve_total(&mut self.correction, bonds + 1);
    }

    /// The most bonds a chain's memory can have for [`copy_streak_from`](Self::copy_streak_from) to fit without allocating.
    #[cfg(test)]
    pub fn room(&self) -> usize {
        self.tension.capacity().min(self.correction.capacity().saturating_sub(1))
    }

    /// Whether the last first solves took the exact projection.
    pub fn in_streak(&self) -> bool {
        self.exact_streak > 0
    }

    /// Whether the next first solve starts with the exact projection.
    pub fn wants_exact(&self) -> bool {
        !self.exact_streak.is_multiple_of(RETRY_DIRECT)
    }

    /// The exact projection's part of `other` (its streak, tensions and corrections; not the multiplier
    /// histories), in the room `self` has (no allocation once it has held a chain of that length): what a
    /// lane group keeps per lane. The tensions and corrections are only read while the streak runs, and
    /// written before it starts, so they are copied only then: most chains never fall back, and their
    /// memory costs a word.
    pub fn copy_streak_from(&mut self, other: &SolveMemory) {
        if other.exact_streak > 0 || self.tension.len() != other.tension.len() {
            self.tension.clear();
            self.tension.extend_from_slice(&other.tension);
            self.correction.clear();
            self.correction.extend_from_slice(&other.correction);
        }
        self.exact_streak = other.exact_streak;
    }
}

fn set_lengths(lengths: &[f32], s: &mut ConstraintScratch) {
    let m = lengths.len();
    s.reserve(m);
    for k in 0..m {
        // Exact: a float32 squared fits in a double.
        let l2 = lengths[k] as f64 * lengths[k] as f64;
        s.length_squared[k] = l2;
        s.inverse_length_squared[k] = 1.0 / l2;
    }
}

/// What [`solve_prepared`] does when the direct solve fails, for a solver that ran its own direct solve (the
/// lane path), whose last multipliers are `multipliers`: see `fall_back`.
pub fn solve_fallback(
    p: &mut [DVec3],
    lengths: &[f32],
    multipliers: &[f64],
    s: &mut ConstraintScratch,
    first: Projection,
) -> Solved {
    let m = lengths.len();
    set_lengths(lengths, s);
    s.newton.mu[..m].copy_from_slice(&multipliers[..m]);
    fall_back(p, lengths, s, first)
}

/// After a failed direct solve (its last multipliers in `s.newton.mu`): the Gauss-Newton projection along
/// the current bonds, cheap where it converges (hair-length segments); if it fails, the exact projection
/// (`implicit`), which converges on the fine ropes that defeat both (bug 1); if even that fails,
/// Gauss-Seidel sweeps from the positions the fallback was given. `first` at `Exact` skips the Gauss-Newton
/// projection, where it would feed the chain's zig-zag ([`super::stability`]).
fn fall_back(p: &mut [DVec3], lengths: &[f32], s: &mut ConstraintScratch, first: Projection) -> Solved {
    let m = lengths.len();
    let (l2, inv_l2) = (&s.length_squared[..m], &s.inverse_length_squared[..m]);
    // The Gauss-Newton projection moves `p`: the exact one starts from the positions and multipliers given.
    s.implicit.begin(p, &s.newton.mu[..m]);
    if first == Projection::GaussNewton {
        for k in 0..m {
            s.current_bonds[k] = p[k + 1] - p[k];
        }
        if project_relinearized(p, &mut s.current_bonds[..m], &Free, l2, inv_l2, &mut s.newton) {
            return Solved::GaussNewton;
        }
    }
    if implicit::project(p, l2, inv_l2, TOLERANCE, &mut s.implicit) {
        return Solved::Exact;
    }
    project_gauss_seidel(p, lengths);
    Solved::GaussSeidel
}

/// Gauss-Newton projection of `p` onto the bond lengths: each iteration corrects along the bonds as they are
/// then (`d` is scratch for them), so unlike [`newton_along_directions`] it follows the chain as it turns.
/// That matters on long, fine chains (hundreds of millimetre segments), where the multipliers of one substep
/// are many segment lengths and directions fixed for the whole solve send it astray. Applies the corrections
/// as it goes; returns `false` (with `p` finite but not yet converged) when it fails.
fn project_relinearized(
    p: &mut [DVec3],
    d: &mut [DVec3],
    mobility: &impl Mobility,
    length_squared: &[f64],
    inverse_length_squared: &[f64],
    s: &mut NewtonScratch,
) -> bool {
    let m = d.len();
    let p = &mut p[..m + 1];
    let (l2, inv_l2) = (&length_squared[..m], &inverse_length_squared[..m]);
    // Each iteration's multipliers are a step of their own, from the bonds as they are then: `step` holds them
    // (`s.mu`, the failed direct solve's, stays as it was).
    let (c_prime, d_prime, step) = (&mut s.c_prime[..m], &mut s.d_prime[..m], &mut s.step[..m]);
    let rows = &mut s.rows[..m];
    let mut previous_worst = f64::INFINITY;
    let mut lost = f64::INFINITY;
    // No bonds: nothing to meet (and `TwistedPass` needs a middle bond).
    if m == 0 {
        return true;
    }
    for iteration in 0..RELINEARIZED_ITERATIONS {
        for k in 0..m {
            d[k] = p[k + 1] - p[k];
        }
        let twisted = TwistedPass::run(d, mobility, l2, inv_l2, rows, c_prime, d_prime);
        let pass = &twisted.summary;
        if pass.converged(previous_worst) {
            return true;
        }
        if iteration == 0 {
            lost = (RELINEARIZED_LOST * pass.worst).max(1.0);
        } else if pass.worst > lost {
            return false;
        }
        previous_worst = pass.worst;
        if !pass.pivots_usable() {
            return false;
        }
        if !twisted.back_substitute(c_prime, d_prime, step) {
            return false;
        }
        // As in the direct solve: a step predicted to land within the tolerance ends the projection, without
        // the pass that would confirm it on these same positions (along the current bonds, `error_after_step`
        // is exact here too).
        let landed = pass.worst <= LANDING_GATE && error_after_step(d, mobility, step, inv_l2) <= TOLERANCE;
        for j in 1..=m {
            p[j] += shift(d, mobility, step, j);
        }
        if landed {
            return true;
        }
    }
    false
}

/// Where [`newton_along_directions`] starts.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Start {
    /// From no multipliers.
    Cold,
    /// From the multipliers in the scratch's `mu` ([`super::warm_start`]); from none again if with them the
    /// bonds are further off than without.
    Warm,
}

/// Newton iterations on the multipliers `mu` of corrections along the directions `d` (one per bond):
/// particle `j` moves by `d[j-1] mu[j-1] - d[j] mu[j]` (the root not at all), or by the part of that its
/// `mobility` allows. Applies them to `p` and returns `true` when converged, leaves `p` untouched otherwise.
/// On success `mu` holds the multipliers that moved `p` (none where the first pass found it converged), and
/// `s.tension` the largest of them. A solve that converged with a multiplier above `room` is refused: it
/// returns `false` with `s.refused` set, `s.tension` and `mu` as it ended, and `p` untouched
/// ([`super::stability`]).
///
/// Each iteration is one pass root to tip that evaluates the bonds under the current multipliers and runs
/// the forward elimination of the Thomas algorithm on the tridiagonal Newton system `J delta = -F/2`
/// (`F_k = |b_k|^2 - l_k^2`, `J` the halved Jacobian `dF/dmu`), then one pass back. The elimination of the
/// last, converged pass is wasted, but the fused pass reads every bond once and overlaps the elimination's
/// chain of divisions with independent work.
#[allow(clippy::too_many_arguments)]
fn newton_along_directions(
    p: &mut [DVec3],
    d: &[DVec3],
    mobility: &impl Mobility,
    length_squared: &[f64],
    inverse_length_squared: &[f64],
    s: &mut NewtonScratch,
    start: Start,
    room: f64,
) -> bool {
    let m = d.len();
    let p = &mut p[..m + 1];
    s.refused = false;
    let (l2, inv_l2) = (&length_squared[..m], &inverse_length_squared[..m]);
    let (mu, corrected, step) = (&mut s.mu[..m], &mut s.corrected[..m + 1], &mut s.step[..m]);
    let (c_prime, d_prime) = (&mut s.c_prime[..m], &mut s.d_prime[..m]);
    let warm = start == Start::Warm;
    if !warm {
        mu.fill(0.0);
    }
    let mut previous_worst = f64::INFINITY;
    for iteration in 0..MAX_NEWTON_ITERATIONS {
        let mut pass = ForwardPass::default();
        if iteration == 0 && !warm {
            // No corrections yet: the bonds of `p`.
            for k in 0..m {
                pass.row(k, p[k + 1] - p[k], d, mobility, l2[k], inv_l2[k], c_prime, d_prime);
            }
        } else {
            corrected[0] = p[0];
            for k in 0..m {
                corrected[k + 1] = p[k + 1] + shift(d, mobility, mu, k + 1);
                pass.row(k, corrected[k + 1] - corrected[k], d, mobility, l2[k], inv_l2[k], c_prime, d_prime);
            }
        }
        if pass.converged(previous_worst) {
            s.tension = largest_multiplier(mu);
            if above(s.tension, room) {
                s.refused = true;
                return false;
            }
            if iteration > 0 || warm {
                p[1..].copy_from_slice(&corrected[1..]);
            }
            return true;
        }
        if iteration == 0 && warm && above(pass.worst, TRUSTED_START) && above(pass.worst, largest_error(p, l2, inv_l2))
        {
            // The start is worse than none: the next pass, with no multipliers, is the cold start's first.
            mu.fill(0.0);
            continue;
        }
        if pass.diverging(previous_worst) {
            return false;
        }
        previous_worst = pass.worst;
        if !pass.pivots_usable() {
            if iteration == 0 {
                // No step was taken: the fallback must not start from an earlier solve's multipliers (the
                // scratch is shared by every chain).
                mu.fill(0.0);
            }
            return false;
        }
        if !back_substitute(c_prime, d_prime, mu, step) {
            return false;
        }
        if pass.worst <= LANDING_GATE && error_after_step(d, mobility, step, inv_l2) <= TOLERANCE {
            s.tension = largest_multiplier(mu);
            if above(s.tension, room) {
                s.refused = true;
                return false;
            }
            // The pass that would confirm it computes these same positions.
            for j in 1..=m {
                p[j] += shift(d, mobility, mu, j);
            }
            return true;
        }
    }
    false
}

/// A warm start whose first pass finds no bond error above this is kept without comparing it with no start (a
/// cold start's first pass met 1e-2 to 1e-1 on the benchmark scenes' hair, and from errors up to this Newton's
/// next pass meets about their square).
pub(crate) const TRUSTED_START: f64 = 1e-2;

/// The largest multiplier by magnitude (the tension a direct solve carries, [`super::stability`]); a NaN one
/// is passed over (the solve that ends with it has not converged).
#[inline(always)]
pub(crate) fn largest_multiplier(mu: &[f64]) -> f64 {
    mu.iter().fold(0.0, |largest, mu| larger(largest, mu.abs()))
}

/// `b` if it is larger than `a`, else `a`: a plain comparison, which the lane solver's copy
/// (`lanes::lengths::within_room`) vectorises to one maximum per bond (`f64::max` took 4 instructions a lane).
#[inline(always)]
pub(crate) fn larger(a: f64, b: f64) -> f64 {
    if b > a { b } else { a }
}

/// Whether `error` is above `bound` or NaN.
#[allow(clippy::neg_cmp_op_on_partial_ord)]
#[inline(always)]
pub(crate) fn above(error: f64, bound: f64) -> bool {
    !(error <= bound)
}

/// The largest relative bond error `|F_k| / l_k^2` of `p` (NaN if any is).
fn largest_error(p: &[DVec3], l2: &[f64], inv_l2: &[f64]) -> f64 {
    let mut worst = 0.0f64;
    for k in 0..l2.len() {
        let error = (((p[k + 1] - p[k]).length_squared() - l2[k]) * inv_l2[k]).abs();
        // Unlike the passes' maximum, a NaN wins: a warm start must not beat it.
        if error > worst || error.is_nan() {
            worst = error;
        }
    }
    worst
}

/// Errors above this are too large for one more step to land within [`TOLERANCE`], so the prediction is not
/// computed (a step from a relative error `e` leaves about `e^2`, often less: the gate is three times
/// `sqrt(TOLERANCE)`).
pub(crate) const LANDING_GATE: f64 = 1e-3;

/// The largest relative bond error `|F_k| / l_k^2` after the multipliers' Newton step `step` along the
/// directions `d`, exactly: each `F_k` is quadratic in the multipliers and the step zeroes its linear part,
/// so what remains is `|Δb_k|^2`, the square of the bond's change. This is what the next pass would measure
/// (up to its rounding), without the pass's elimination.
#[inline]
fn error_after_step(d: &[DVec3], mobility: &impl Mobility, step: &[f64], inv_l2: &[f64]) -> f64 {
    let m = d.len();
    let mut worst = 0.0f64;
    let mut below = DVec3::ZERO;
    for k in 0..m {
        let above = shift(d, mobility, step, k + 1);
        let error = (above - below).length_squared() * inv_l2[k];
        if error > worst {
            worst = error;
        }
        below = above;
    }
    worst
}

/// The Thomas algorithm's pass back: solves for the step from the forward elimination's `c_prime` and
/// `d_prime` and adds it to `mu`. Returns `false` if the step is not finite (the fallback's exact projection
/// then starts from no multiplier where they are not finite).
#[inline]
fn back_substitute(c_prime: &[f64], d_prime: &[f64], mu: &mut [f64], step: &mut [f64]) -> bool {
    // A non-finite entry makes every later one non-finite (`x - c * inf` is infinite or NaN, `0 * inf` NaN),
    // so checking the last is enough.
    let mut next = 0.0f64;
    for k in (0..mu.len()).rev() {
        next = d_prime[k] - c_prime[k] * next;
        step[k] = next;
        mu[k] += next;
    }
    next.is_finite()
}

/// How far the multipliers `mu` along the directions `d` move particle `j >= 1`.
#[inline(always)]
fn shift(d: &[DVec3], mobility: &impl Mobility, mu: &[f64], j: usize) -> DVec3 {
    let pulled = d[j - 1] * mu[j - 1];
    mobility.allowed(j, if j < d.len() { pulled - d[j] * mu[j] } else { pulled })
}

/// Bond `k`'s row of the Newton system: its `F_k` and its entries in `J`.
#[derive(Clone, Copy, Default)]
struct BondRow {
    f: f64,
    diagonal: f64,
    /// Towards bond `k - 1` (zero for the first bond) and bond `k + 1` (zero for the last).
    lower: f64,
    upper: f64,
}

impl BondRow {
    /// Of bond `k` with vector `b`, corrected along the directions `d`.
    #[inline(always)]
    fn new(k: usize, b: DVec3, d: &[DVec3], mobility: &impl Mobility, l2: f64) -> Self {
        let m = d.len();
        let f = b.length_squared() - l2;
        // The bond as each of its ends may change it (the mobility is a projection: `b . W d = W b . d`). For
        // free particles both are `b`, and the diagonal is `2 b . d[k]` to the bit.
        let (at_start, at_end) = (mobility.allowed(k, b), mobility.allowed(k + 1, b));
        // The root's end of bond 0 does not move, so bond 0's own correction counts once.
        let diagonal = if k > 0 { at_end.dot(d[k]) + at_start.dot(d[k]) } else { at_end.dot(d[k]) };
        let lower = if k > 0 { -at_start.dot(d[k - 1]) } else { 0.0 };
        let upper = if k + 1 < m { -at_end.dot(d[k + 1]) } else { 0.0 };
        Self { f, diagonal, lower, upper }
    }
}

/// The running state of one root-to-tip pass of [`newton_along_directions`]; also [`TwistedPass`]'s summary of
/// its two sweeps, whose `sweep` then holds only their smallest pivot (its last row's entries mean nothing).
#[derive(Default)]
struct ForwardPass {
    /// Largest relative error `|F_k| / l_k^2`.
    worst: f64,
    /// Largest diagonal entry of `J` by magnitude.
    scale: f64,
    sweep: Sweep,
}

impl ForwardPass {
    /// Bond `k` with vector `b`: its error, and its row of the forward elimination (one division).
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn row(
        &mut self,
        k: usize,
        b: DVec3,
        d: &[DVec3],
        mobility: &impl Mobility,
        l2: f64,
        inv_l2: f64,
        c_prime: &mut [f64],
        d_prime: &mut [f64],
    ) {
        let row = BondRow::new(k, b, d, mobility, l2);
        self.take_row(&row, inv_l2);
        self.sweep.eliminate(&row, row.lower, row.upper);
        (c_prime[k], d_prime[k]) = (self.sweep.c_last, self.sweep.d_last);
    }

    /// A row's error and diagonal entry.
    #[inline(always)]
    fn take_row(&mut self, row: &BondRow, inv_l2: f64) {
        let error = (row.f * inv_l2).abs();
        // As `f64::max`: a NaN error is ignored here (and fails the elimination instead).
        if error > self.worst {
            self.worst = error;
        }
        if row.diagonal.abs() > self.scale {
            self.scale = row.diagonal.abs();
        }
    }

    /// Converged, or at the rounding floor: Newton converges quadratically, so a pass that fails to halve the
    /// error of the one before has reached it. (The system is solved in f64: its condition grows like n^2.)
    fn converged(&self, previous_worst: f64) -> bool {
        self.worst <= TOLERANCE || (self.worst > 0.5 * previous_worst && self.worst < STAGNATION_LIMIT)
    }

    /// The error grew (and is above the rounding floor, or the pass would count as converged): the direct
    /// solve is going astray. Measured on bug 1's ropes (docs/robustness.md, 200 and 1000 joints): of 665
    /// solves whose error grew, 630 failed after all their iterations and 35 ended at the stagnation floor
    /// (errors of 1e-4 to 1e-3, far above the tolerance), which the converging fallback now handles instead.
    fn diverging(&self, previous_worst: f64) -> bool {
        self.worst > previous_worst
    }

    /// No pivot vanished (relative to the largest diagonal entry); false for NaN too.
    fn pivots_usable(&self) -> bool {
        self.scale > 0.0 && self.sweep.smallest_pivot > self.scale * MIN_PIVOT
    }
}

/// The forward elimination of the Thomas algorithm as it goes, one row at a time: the smallest pivot by
/// magnitude, and the last row's modified entries.
struct Sweep {
    smallest_pivot: f64,
    c_last: f64,
    d_last: f64,
}

impl Default for Sweep {
    fn default() -> Self {
        Self { smallest_pivot: f64::INFINITY, c_last: 0.0, d_last: 0.0 }
    }
}

impl Sweep {
    /// A row of the sweep (one division): `done` is its entry towards the rows already eliminated, `next`
    /// towards those still to come.
    #[inline(always)]
    fn eliminate(&mut self, row: &BondRow, done: f64, next: f64) {
        let den = row.diagonal - done * self.c_last;
        self.take_pivot(den);
        let inv = 1.0 / den;
        self.c_last = next * inv;
        self.d_last = (-0.5 * row.f - done * self.d_last) * inv;
    }

    #[inline(always)]
    fn take_pivot(&mut self, pivot: f64) {
        // As `f64::min`: a NaN pivot is skipped here but turns every later `d_prime` into NaN, so the back
        // substitution fails.
        if pivot.abs() < self.smallest_pivot {
            self.smallest_pivot = pivot.abs();
        }
    }
}

/// One elimination of the Gauss-Newton projection, from both ends of the chain at once (a twisted
/// factorisation): the bonds below the middle one root to tip, those above it tip to root, a row of each
/// sweep in turn, and the middle bond's row from both. Each sweep is a chain of dependent divisions; the two
/// halves overlap, where one sweep over every bond waits on each division in turn (on long chains whose solves
/// keep ending in the projection, about half of its time went to the elimination and the back substitution).
/// The same system, and the same tests on its errors and pivots as [`ForwardPass`]'s, but not the same pivots:
/// for a straight chain, in units of a bond's squared length, the middle row's is about `2/m` where the
/// one-ended elimination's stay near 1: far above the relative [`MIN_PIVOT`] (1e-7) for any chain length.
struct TwistedPass {
    /// Both sweeps' and the middle row's errors, diagonal and pivots, as one pass over every bond has them.
    summary: ForwardPass,
    /// The middle bond, and its step.
    twist: usize,
    middle: f64,
}

impl TwistedPass {
    /// The elimination of the system along the directions `d` at the bonds `d` (at least one), into `c_prime`
    /// and `d_prime` (the sweep from the root's below the middle bond, the sweep from the tip's above it).
    /// Every row is set up first (`rows` is scratch), so that the sweeps' loop holds only their chains of
    /// divisions and the core's window reaches far enough ahead to run both at once.
    #[inline(always)]
    fn run(
        d: &[DVec3],
        mobility: &impl Mobility,
        l2: &[f64],
        inv_l2: &[f64],
        rows: &mut [BondRow],
        c_prime: &mut [f64],
        d_prime: &mut [f64],
    ) -> Self {
        let m = d.len();
        let (rows, c_prime, d_prime) = (&mut rows[..m], &mut c_prime[..m], &mut d_prime[..m]);
        let mut summary = ForwardPass::default();
        for (k, row) in rows.iter_mut().enumerate() {
            *row = BondRow::new(k, d[k], d, mobility, l2[k]);
            summary.take_row(row, inv_l2[k]);
        }
        let twist = m / 2;
        // Bonds above the middle; there are as many below it, or one more.
        let paired = m - 1 - twist;
        let (mut from_root, mut from_tip) = (Sweep::default(), Sweep::default());
        for below in 0..paired {
            let above = m - 1 - below;
            from_root.eliminate(&rows[below], rows[below].lower, rows[below].upper);
            (c_prime[below], d_prime[below]) = (from_root.c_last, from_root.d_last);
            from_tip.eliminate(&rows[above], rows[above].upper, rows[above].lower);
            (c_prime[above], d_prime[above]) = (from_tip.c_last, from_tip.d_last);
        }
        if twist > paired {
            from_root.eliminate(&rows[paired], rows[paired].lower, rows[paired].upper);
            (c_prime[paired], d_prime[paired]) = (from_root.c_last, from_root.d_last);
        }
        let row = &rows[twist];
        let den = row.diagonal - row.lower * from_root.c_last - row.upper * from_tip.c_last;
        let middle = (-0.5 * row.f - row.lower * from_root.d_last - row.upper * from_tip.d_last) / den;
        summary.sweep.take_pivot(from_root.smallest_pivot);
        summary.sweep.take_pivot(from_tip.smallest_pivot);
        summary.sweep.take_pivot(den);
        Self { summary, twist, middle }
    }

    /// The passes back, from the middle bond to both ends side by side, into `step`. Returns `false` if the
    /// step is not finite (as [`back_substitute`]).
    #[inline(always)]
    fn back_substitute(&self, c_prime: &[f64], d_prime: &[f64], step: &mut [f64]) -> bool {
        let (m, twist) = (step.len(), self.twist);
        let paired = m - 1 - twist;
        step[twist] = self.middle;
        let (mut toward_root, mut toward_tip) = (self.middle, self.middle);
        for i in 1..=paired {
            let below = twist - i;
            toward_root = d_prime[below] - c_prime[below] * toward_root;
            step[below] = toward_root;
            let above = twist + i;
            toward_tip = d_prime[above] - c_prime[above] * toward_tip;
            step[above] = toward_tip;
        }
        if twist > paired {
            toward_root = d_prime[0] - c_prime[0] * toward_root;
            step[0] = toward_root;
        }
        // As in `back_substitute`: a non-finite entry makes every later one of its pass non-finite.
        toward_root.is_finite() && toward_tip.is_finite()
    }
}

/// Classic position-based projection along the current bonds: always well defined, slow to converge on
/// long chains. Only used when the direct solve fails.
fn project_gauss_seidel(p: &mut [DVec3], lengths: &[f32]) {
    // Inverse masses relative to the uniform dynamic one.
    let w = |j: usize| if j == 0 { 0.0 } else { 1.0f64 };
    for _ in 0..FALLBACK_SWEEPS {
        for (k, &rest) in lengths.iter().enumerate() {
            let (wa, wb) = (w(k), w(k + 1));
            let delta = p[k + 1] - p[k];
            let len = delta.length();
            if len <= f64::MIN_POSITIVE {
                continue;
            }
            let correction = delta * ((len - rest as f64) / (len * (wa + wb)));
            p[k] += correction * wa;
            p[k + 1] -= correction * wb;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// No tension budget: these tests are about the solves themselves ([`super::super::stability`]).
    fn unlimited() -> TensionBudget {
        TensionBudget::UNLIMITED
    }

    /// The Gauss-Newton step of bonds `d` from both ends at once ([`TwistedPass`]) against the one-ended
    /// Thomas solve of the same rows ([`ForwardPass`], [`back_substitute`]): every chain length from one bond,
    /// even and odd, free and with sliding particles. The two differ by rounding alone, and the passes' error
    /// and diagonal checks agree to the bit.
    #[test]
    fn the_two_ended_elimination_solves_the_one_ended_system() {
        for m in (1..=12).chain([63, 64, 1000]) {
            let d: Vec<DVec3> = (0..m)
                .map(|k| {
                    let t = k as f64;
                    DVec3::new(0.02 * (0.9 * t).cos(), -0.025 + 0.004 * (1.3 * t).sin(), 0.01 * (0.4 * t).sin())
                })
                .collect();
            // Rest lengths 0 % to 10 % shorter than the bonds, so that most rows have an error to correct.
            let l2: Vec<f64> =
                d.iter().enumerate().map(|(k, b)| b.length_squared() * (0.9 + 0.02 * (k % 6) as f64)).collect();
            let normals: Vec<Vec3> =
                (0..=m).map(|j| if j % 3 == 1 { Vec3::new(0.6, 0.0, 0.8) } else { Vec3::ZERO }).collect();
            assert_twisted_matches_thomas(&d, &l2, &Free);
            assert_twisted_matches_thomas(&d, &l2, &Sliding(&normals));
        }
    }

    fn assert_twisted_matches_thomas(d: &[DVec3], l2: &[f64], mobility: &impl Mobility) {
        let m = d.len();
        let inv_l2: Vec<f64> = l2.iter().map(|l| 1.0 / l).collect();
        let zeros = || vec![0.0f64; m];
        let (mut c_prime, mut d_prime, mut mu, mut step) = (zeros(), zeros(), zeros(), zeros());
        let mut one_ended = ForwardPass::default();
        for k in 0..m {
            one_ended.row(k, d[k], d, mobility, l2[k], inv_l2[k], &mut c_prime, &mut d_prime);
        }
        assert!(back_substitute(&c_prime, &d_prime, &mut mu, &mut step));
        let (mut c_twisted, mut d_twisted, mut step_twisted) = (zeros(), zeros(), zeros());
        let mut rows = vec![BondRow::default(); m];
        let twisted = TwistedPass::run(d, mobility, l2, &inv_l2, &mut rows, &mut c_twisted, &mut d_twisted);
        assert!(twisted.back_substitute(&c_twisted, &d_twisted, &mut step_twisted));
        let largest = step.iter().fold(0.0f64, |a, s| a.max(s.abs()));
        assert!(largest > 0.0, "m {m}");
        for k in 0..m {
            let (one, two) = (step[k], step_twisted[k]);
            assert!((one - two).abs() <= 1e-9 * largest, "m {m}, bond {k}: {one} vs {two}");
        }
        assert_eq!(twisted.summary.worst, one_ended.worst, "m {m}");
        assert_eq!(twisted.summary.scale, one_ended.scale, "m {m}");
        assert!(twisted.summary.pivots_usable() && one_ended.pivots_usable(), "m {m}");
    }

    fn max_stretch(p: &[DVec3], lengths: &[f32]) -> f64 {
        lengths
            .iter()
            .enumerate()
            .map(|(k, l)| ((p[k + 1] - p[k]).length() / *l as f64 - 1.0).abs())
            .fold(0.0, f64::max)
    }

    fn line(n: usize, spacing: f64) -> Vec<DVec3> {
        (0..n).map(|i| DVec3::new(spacing * i as f64, 0.0, 0.0)).collect()
    }

    #[test]
    fn restores_lengths_after_a_small_step() {
        let x = line(9, 0.1);
        let lengths = vec![0.1; 8];
        // Gravity drop of one 240 Hz step on every dynamic particle.
        let mut p: Vec<DVec3> =
            x.iter().enumerate().map(|(i, v)| if i == 0 { *v } else { *v - DVec3::Y * 1.7e-4 }).collect();
        let mut s = ConstraintScratch::default();
        assert!(solve(&x, &mut p, &lengths, &mut s));
        assert!(max_stretch(&p, &lengths) < 1e-6, "{}", max_stretch(&p, &lengths));
        assert_eq!(p[0], x[0]);
    }

    /// The direct solve ends on a step whose predicted error (`error_after_step`) is within the tolerance,
    /// without measuring it: measured at the result, the error is indeed within it, and the prediction was
    /// the error itself (a Newton step on these quadratic constraints leaves exactly the squared bond change).
    #[test]
    fn a_landed_step_meets_the_tolerance_it_predicted() {
        let n = 16;
        let x: Vec<DVec3> = (0..n).map(|i| DVec3::new(0.025 * i as f64, 0.01 * (0.4 * i as f64).sin(), 0.0)).collect();
        let lengths: Vec<f32> = (0..n - 1).map(|k| (x[k + 1] - x[k]).length() as f32).collect();
        let mut p: Vec<DVec3> = x
            .iter()
            .enumerate()
            .map(|(i, v)| *v + DVec3::new(1e-3 * (i as f64).sqrt(), -2e-3 * (0.7 * i as f64).cos(), 1e-3))
            .collect();
        p[0] = x[0];
        let mut s = ConstraintScratch::default();
        prepare(&x, &lengths, &mut s);
        let m = n - 1;
        let (d, l2, inv_l2) =
            (s.start_bonds[..m].to_vec(), s.length_squared[..m].to_vec(), s.inverse_length_squared[..m].to_vec());
        let mut stepped = p.clone();
        assert!(newton_along_directions(
            &mut stepped,
            &d,
            &Free,
            &l2,
            &inv_l2,
            &mut s.newton,
            Start::Cold,
            f64::INFINITY
        ));
        let measured = (0..m)
            .map(|k| (((stepped[k + 1] - stepped[k]).length_squared() - l2[k]) * inv_l2[k]).abs())
            .fold(0.0, f64::max);
        let predicted = error_after_step(&d, &Free, &s.newton.step[..m], &inv_l2);
        assert!(measured <= TOLERANCE, "{measured}");
        assert!((measured - predicted).abs() <= 1e-14, "{measured} vs {predicted}");
        assert!(predicted > 0.0);
    }

    /// A hanging chain's start `x`, `lengths` and prediction `p`, and its direct solve from no start: the
    /// positions `cold` and the multipliers.
    type HangingSolve = (Vec<DVec3>, Vec<f32>, Vec<DVec3>, Vec<DVec3>, Vec<f64>);

    fn hanging_solve() -> HangingSolve {
        let n = 16;
        let x: Vec<DVec3> =
            (0..n).map(|i| DVec3::new(0.02 * i as f64, -0.01 * i as f64, 0.003 * (i % 2) as f64)).collect();
        let lengths: Vec<f32> = (0..n - 1).map(|k| (x[k + 1] - x[k]).length() as f32).collect();
        let p: Vec<DVec3> = x
            .iter()
            .enumerate()
            .map(|(i, v)| if i == 0 { *v } else { *v + DVec3::new(2e-4 * (i as f64).sin(), -1.7e-4, 0.0) })
            .collect();
        let mut s = ConstraintScratch::default();
        prepare(&x, &lengths, &mut s);
        let mut cold = p.clone();
        let mut history = MultiplierHistory::new(n - 1);
        assert_eq!(solve_warm(&mut cold, &lengths, &mut s, &mut history, &mut unlimited()), Solved::Direct);
        assert!(history.remembered());
        (x, lengths, p, cold, history.last.clone())
    }

    /// The solve of `hanging_solve`'s prediction from a history that learnt `start`: the positions, the
    /// history after it.
    fn solve_from(x: &[DVec3], lengths: &[f32], p: &[DVec3], start: &[f64]) -> (Vec<DVec3>, MultiplierHistory) {
        let mut s = ConstraintScratch::default();
        prepare(x, lengths, &mut s);
        let mut history = MultiplierHistory::new(lengths.len());
        history.learn(start);
        let mut warm = p.to_vec();
        assert_eq!(solve_warm(&mut warm, lengths, &mut s, &mut history, &mut unlimited()), Solved::Direct);
        (warm, history)
    }

    /// From the multipliers that solved it, the same solve needs no Newton step: the first pass meets the
    /// lengths and the positions are those multipliers' (within the tolerance of the cold answer).
    #[test]
    fn a_warm_start_at_the_answer_ends_in_its_first_pass() {
        let (x, lengths, p, cold, multipliers) = hanging_solve();
        let (warm, history) = solve_from(&x, &lengths, &p, &multipliers);
        assert!(max_stretch(&warm, &lengths) < 1e-6, "{}", max_stretch(&warm, &lengths));
        let apart = warm.iter().zip(&cold).map(|(a, b)| (*a - *b).length()).fold(0.0, f64::max);
        assert!(apart < 1e-9, "{apart}");
        // No step was taken: the history learnt the start itself.
        assert_eq!(history.last, multipliers);
    }

    /// A start worse than none (multipliers of another chain, far off) is dropped: the solve then computes
    /// exactly what it computes from no start, to the bit.
    #[test]
    fn a_warm_start_worse_than_none_gives_the_cold_answer() {
        let (x, lengths, p, cold, multipliers) = hanging_solve();
        let wrong: Vec<f64> = multipliers.iter().map(|mu| -40.0 * mu - 0.05).collect();
        let (warm, history) = solve_from(&x, &lengths, &p, &wrong);
        assert_eq!(warm, cold);
        // What it learnt: the answer's multipliers, with the wrong ones as the one before.
        assert_eq!(history.last, multipliers);
        assert_eq!(history.before, wrong);
    }

    #[test]
    fn long_chain_converges() {
        let x = line(1000, 0.01);
        let lengths = vec![0.01; 999];
        let mut p: Vec<DVec3> = x
            .iter()
            .enumerate()
            .map(|(i, v)| *v + DVec3::new(0.0, -1e-4 * (i as f64).sqrt(), 2e-5 * (i % 3) as f64))
            .collect();
        p[0] = x[0];
        let mut s = ConstraintScratch::default();
        assert!(solve(&x, &mut p, &lengths, &mut s));
        assert!(max_stretch(&p, &lengths) < 1e-6, "{}", max_stretch(&p, &lengths));
    }

    /// A fine rope of `n` joints of 1 mm in a gentle S (positions, lengths) and a prediction that moves each
    /// dynamic joint by `push` times a few tenths of a segment.
    fn fine_rope(n: usize, push: f64) -> (Vec<DVec3>, Vec<f32>, Vec<DVec3>) {
        let x: Vec<DVec3> = (0..n)
            .map(|i| {
                let s = i as f64 * 1e-3;
                DVec3::new(0.02 * (s * 20.0).sin(), -s, 0.0)
            })
            .collect();
        let lengths: Vec<f32> = x.windows(2).map(|w| (w[1] - w[0]).length() as f32).collect();
        let offset = |i: f64| DVec3::new(2e-4 * (i * 0.05).sin(), -3e-4, 2e-4 * (i * 0.031).cos()) * push;
        let predicted = x.iter().enumerate().map(|(i, v)| if i == 0 { *v } else { *v + offset(i as f64) }).collect();
        (x, lengths, predicted)
    }

    /// A fine rope (400 joints of 1 mm in a gentle S) whose every joint the prediction moved by a few tenths of
    /// a segment: the Gauss-Newton projection loses its way, the exact projection converges, and its answer is
    /// nearer the prediction than the direct solve's (both keep the lengths; the projection is the nearest
    /// such positions).
    #[test]
    fn fine_rope_projection_converges_where_gauss_newton_does_not() {
        let n = 400;
        let (x, lengths, predicted) = fine_rope(n, 1.0);
        let distance = |p: &[DVec3]| p.iter().zip(&predicted).map(|(a, b)| (*a - *b).length_squared()).sum::<f64>();
        let mut s = ConstraintScratch::default();
        let m = n - 1;
        let mut direct = predicted.clone();
        assert!(solve(&x, &mut direct, &lengths, &mut s));
        let multipliers = s.newton.mu[..m].to_vec();

        let mut relinearized = predicted.clone();
        s.current_bonds[..m].copy_from_slice(&predicted.windows(2).map(|w| w[1] - w[0]).collect::<Vec<_>>());
        let (l2, inv_l2) = (&s.length_squared[..m], &s.inverse_length_squared[..m]);
        assert!(!project_relinearized(&mut relinearized, &mut s.current_bonds[..m], &Free, l2, inv_l2, &mut s.newton));

        let mut projected = predicted.clone();
        s.implicit.begin(&projected, &multipliers);
        assert!(implicit::project(&mut projected, l2, inv_l2, TOLERANCE, &mut s.implicit));
        let mut portable = predicted.clone();
        s.implicit.begin(&portable, &multipliers);
        assert!(implicit::project_portable(&mut portable, l2, inv_l2, TOLERANCE, &mut s.implicit).is_some());
        assert!(crate::core::rod::same_bits(&projected, &portable));
        assert!(max_stretch(&projected, &lengths) < 1e-6, "{}", max_stretch(&projected, &lengths));
        assert_eq!(projected[0], x[0]);
        let (nearest, other) = (distance(&projected), distance(&direct));
        assert!(nearest < other, "projection moved the joints by {nearest:.3e} m^2, the direct solve by {other:.3e}");
    }

    /// A sliding solve that skips the restricted direct solve its memory says will fail gives the bits of one
    /// that runs and fails it: the fine rope of the test above, pushed further, with two joints sliding on
    /// planes.
    #[test]
    fn a_sliding_solve_that_skips_failing_solves_keeps_the_bits() {
        let n = 400;
        let (x, lengths, predicted) = fine_rope(n, 20.0);
        let mut normals = vec![Vec3::ZERO; n];
        normals[120] = Vec3::X;
        normals[260] = Vec3::new(0.6, 0.0, 0.8);
        let mut s = ConstraintScratch::default();
        let mut memory = SlidingMemory::default();
        let mut first = predicted.clone();
        prepare(&x, &lengths, &mut s);
        assert!(!solve_sliding(&mut first, &lengths, &normals, &mut s, &mut memory), "the direct solve fails");
        assert_eq!(memory.direct_failed, 1);
        assert!(max_stretch(&first, &lengths) < 1e-6, "{}", max_stretch(&first, &lengths));
        // Again from the same positions: now without the direct solve, to the same bits.
        let mut again = predicted.clone();
        prepare(&x, &lengths, &mut s);
        assert!(!solve_sliding(&mut again, &lengths, &normals, &mut s, &mut memory));
        assert!(crate::core::rod::same_bits(&first, &again));
        assert_eq!(memory.direct_failed, 2);
        // The retry every `RETRY_DIRECT` rounds runs the direct solve, and fails it again.
        memory.direct_failed = RETRY_DIRECT;
        let mut retried = predicted.clone();
        prepare(&x, &lengths, &mut s);
        assert!(!solve_sliding(&mut retried, &lengths, &normals, &mut s, &mut memory));
        assert!(crate::core::rod::same_bits(&first, &retried));
        assert_eq!(memory.direct_failed, RETRY_DIRECT + 1);
    }

    /// A fine rope lying on the ground (400 joints of 0.8 mm) whose every other joint a contact pass pushed up
    /// by about half a millimetre, with one joint sliding on a collider: the restricted Gauss-Newton projection
    /// does not converge from so far off (as in the contact rounds of the report's 1000-joint rope). The lengths
    /// are then met from where it got to, near the given positions: within 1.5 times the least move that meets
    /// them (the exact projection's). Met from the given positions instead, the direct solve along the start
    /// bonds met them by drawing the rope in along itself, about 34 000 times as far (sums of squared moves;
    /// `cargo test --release --lib a_failed_sliding -- --nocapture` prints both).
    #[test]
    fn a_failed_sliding_projection_hands_on_its_progress() {
        let (n, segment) = (400, 8e-4);
        let x: Vec<DVec3> = (0..n).map(|i| DVec3::new(segment * i as f64, 0.0, 0.0)).collect();
        let lengths = vec![segment as f32; n - 1];
        let lift = |i: usize| 5e-4 * (1.0 + 0.3 * (0.37 * i as f64).sin());
        let given: Vec<DVec3> = x
            .iter()
            .enumerate()
            .map(|(i, v)| if i % 2 == 1 { *v + DVec3::Y * lift(i) } else { *v - DVec3::Y * 2e-5 })
            .collect();
        let mut normals = vec![Vec3::ZERO; n];
        normals[40] = Vec3::Y;
        let moved = |p: &[DVec3]| p.iter().zip(&given).map(|(a, b)| (*a - *b).length_squared()).sum::<f64>();
        let mut s = ConstraintScratch::default();
        prepare(&x, &lengths, &mut s);
        let m = n - 1;
        let (l2, inv_l2) = (s.length_squared[..m].to_vec(), s.inverse_length_squared[..m].to_vec());
        let mut restricted = given.clone();
        s.current_bonds[..m].copy_from_slice(&given.windows(2).map(|w| w[1] - w[0]).collect::<Vec<_>>());
        let sliding = Sliding(&normals);
        assert!(!project_relinearized(
            &mut restricted,
            &mut s.current_bonds[..m],
            &sliding,
            &l2,
            &inv_l2,
            &mut s.newton
        ));

        let mut p = given.clone();
        // A memory of one failed round: straight to the projection, as in the rounds after the first.
        let mut memory = SlidingMemory { direct_failed: 1 };
        assert!(!solve_sliding(&mut p, &lengths, &normals, &mut s, &mut memory));
        assert!(max_stretch(&p, &lengths) < 1e-6, "{}", max_stretch(&p, &lengths));
        let mut nearest = given.clone();
        s.implicit.begin(&nearest, &vec![0.0; m]);
        assert!(implicit::project(&mut nearest, &l2, &inv_l2, TOLERANCE, &mut s.implicit));
        let (least, solved) = (moved(&nearest), moved(&p));
        assert!(solved <= 1.5 * least, "the solve moved the joints by {solved:.3e} m^2, the least move is {least:.3e}");
        // What the solve did before: the unrestricted solve from the given positions.
        let mut from_given = given.clone();
        prepare(&x, &lengths, &mut s);
        solve_prepared(&mut from_given, &lengths, &mut s);
        let before = moved(&from_given);
        println!(
            "moved {solved:.3e} m^2 ({:.2} times the least), from the given positions {before:.3e} ({:.0} times)",
            solved / least,
            before / least
        );
        assert!(max_stretch(&from_given, &lengths) < 1e-6 && before > solved, "{before:.3e} against {solved:.3e}");
    }

    /// A chain whose restricted direct solve meets the lengths keeps trying it first.
    #[test]
    fn a_sliding_solve_that_meets_the_lengths_directly_stays_direct() {
        let x = line(9, 0.1);
        let lengths = vec![0.1; 8];
        let mut p: Vec<DVec3> =
            x.iter().enumerate().map(|(i, v)| if i == 0 { *v } else { *v - DVec3::Y * 1.7e-4 }).collect();
        let mut normals = vec![Vec3::ZERO; 9];
        normals[4] = Vec3::Y;
        let mut s = ConstraintScratch::default();
        let mut memory = SlidingMemory::default();
        prepare(&x, &lengths, &mut s);
        assert!(solve_sliding(&mut p, &lengths, &normals, &mut s, &mut memory));
        assert!(max_stretch(&p, &lengths) < 1e-6, "{}", max_stretch(&p, &lengths));
        assert_eq!(memory.direct_failed, 0);
        // A memory that would retry now (after `RETRY_DIRECT` rounds without) forgets its failures on success.
        let mut memory = SlidingMemory { direct_failed: RETRY_DIRECT };
        let mut q = x.clone();
        q[1..].iter_mut().for_each(|v| *v -= DVec3::Y * 1.7e-4);
        prepare(&x, &lengths, &mut s);
        assert!(solve_sliding(&mut q, &lengths, &normals, &mut s, &mut memory));
        assert_eq!(memory.direct_failed, 0);
    }

    /// The exact projection started from the chain's last correction (`ImplicitScratch::begin_shifted`): a
    /// fine rope predicted almost as in the substep before reaches the same answer as from the prediction
    /// itself (the nearest positions with those lengths are unique), in fewer Newton steps.
    #[test]
    fn a_shifted_start_reaches_the_same_projection_sooner() {
        let n = 400;
        let x: Vec<DVec3> =
            (0..n).map(|i| DVec3::new(0.02 * (i as f64 * 0.02).sin(), -(i as f64) * 1e-3, 0.0)).collect();
        let lengths: Vec<f32> = x.windows(2).map(|w| (w[1] - w[0]).length() as f32).collect();
        let predict = |nudge: f64| -> Vec<DVec3> {
            let offset = |i: f64| {
                DVec3::new(2e-4 * (i * 0.05).sin() + nudge * (i * 0.11).cos(), -3e-4, 2e-4 * (i * 0.031).cos())
            };
            x.iter().enumerate().map(|(i, v)| if i == 0 { *v } else { *v + offset(i as f64) }).collect()
        };
        let m = n - 1;
        let mut s = ConstraintScratch::default();
        set_lengths(&lengths, &mut s);
        let (l2, inv_l2) = (s.length_squared[..m].to_vec(), s.inverse_length_squared[..m].to_vec());
        let mut project = |p: &mut Vec<DVec3>, tension: &[f64], shift: Option<&[DVec3]>| {
            match shift {
                Some(shift) => s.implicit.begin_shifted(p, tension, shift),
                None => s.implicit.begin(p, tension),
            }
            // Tighter than `TOLERANCE`, so that "the same projection" can be told to 1e-12 m (within `TOLERANCE`
            // two starts may land 2e-11 m apart on these 1 mm segments).
            let steps = implicit::project_portable(p, &l2, &inv_l2, 1e-9, &mut s.implicit).expect("converges");
            (s.implicit.multipliers(m).to_vec(), s.implicit.correction(m).to_vec(), steps)
        };
        let mut before = predict(0.0);
        let (tension, correction, _) = project(&mut before, &vec![0.0; m], None);
        let (mut plain, mut shifted) = (predict(2e-5), predict(2e-5));
        let (_, _, plain_steps) = project(&mut plain, &tension, None);
        let (_, _, shifted_steps) = project(&mut shifted, &tension, Some(&correction));
        let apart = plain.iter().zip(&shifted).map(|(a, b)| (*a - *b).length()).fold(0.0, f64::max);
        println!(
            "{plain_steps} Newton steps from the prediction, {shifted_steps} from the shifted start; answers {apart:.1e} m apart"
        );
        assert!(apart < 1e-12, "{apart}");
        assert!(shifted_steps < plain_steps, "{shifted_steps} vs {plain_steps}");
        assert!(max_stretch(&shifted, &lengths) < 1e-6);

        // The rope carried rigidly by a half turn about its root (a teleport, `RodState::carry`; exact in
        // floating point, so the turned answer is the answer turned): its memory turns with it and gives the
        // turned start the same head start.
        let turn = glam::Quat::from_xyzw(0.0, 0.0, 1.0, 0.0);
        let mut memory = SolveMemory::new(m);
        memory.correction.copy_from_slice(&correction);
        memory.turn(turn);
        let rotate = |v: &DVec3| turn.as_dquat() * *v;
        let mut turned: Vec<DVec3> = predict(2e-5).iter().map(rotate).collect();
        let (_, _, turned_steps) = project(&mut turned, &tension, Some(&memory.correction));
        let apart = turned.iter().zip(&shifted).map(|(a, b)| (*a - rotate(b)).length()).fold(0.0, f64::max);
        assert!(apart < 1e-12, "{apart}");
        assert_eq!(turned_steps, shifted_steps);
        let mut unturned: Vec<DVec3> = predict(2e-5).iter().map(rotate).collect();
        s.implicit.begin_shifted(&unturned, &tension, &correction);
        let unturned_steps = implicit::project_portable(&mut unturned, &l2, &inv_l2, TOLERANCE, &mut s.implicit);
        println!("unturned memory: {unturned_steps:?} steps");
        assert!(
            unturned_steps.is_none_or(|steps| steps > shifted_steps),
            "the turn must matter for this test to mean anything"
        );
    }

    /// A hair rope of 2.5 cm segments, straight at the substep's start and predicted bent through a quarter
    /// turn and stretched: too far turned for corrections along the start bonds (the direct solve), not for
    /// the Gauss-Newton projection. Start, lengths, prediction.
    fn turned_hair() -> (Vec<DVec3>, Vec<f32>, Vec<DVec3>) {
        let n = 40;
        let x = line(n, 0.025);
        let lengths = vec![0.025; n - 1];
        let p: Vec<DVec3> = (0..n)
            .map(|i| {
                let angle = std::f64::consts::FRAC_PI_2 * i as f64 / (n - 1) as f64;
                let radius = 1.02 * 0.025 * (n - 1) as f64 / std::f64::consts::FRAC_PI_2;
                DVec3::new(radius * angle.sin(), radius * (angle.cos() - 1.0), 0.001 * (i % 3) as f64)
            })
            .collect();
        (x, lengths, p)
    }

    /// A solve that ended in the Gauss-Newton projection `RELINEARIZE_AFTER` times in a row goes straight to
    /// it in the next substeps (the direct solve does not run: its scratch positions stay as they were), with
    /// the same answer to the bit, because a failed direct solve leaves the positions untouched; every
    /// `RETRY_DIRECT`-th substep it tries the direct solve again, and a solve that ends in the direct solve
    /// ends the streak.
    #[test]
    fn a_solve_that_keeps_falling_back_goes_straight_to_gauss_newton() {
        let (x, lengths, p) = turned_hair();
        let m = lengths.len();
        let mut s = ConstraintScratch::default();
        prepare(&x, &lengths, &mut s);
        let mut history = MultiplierHistory::new(m);
        let mut first = p.clone();
        assert_eq!(solve_warm(&mut first, &lengths, &mut s, &mut history, &mut unlimited()), Solved::GaussNewton);
        assert!(max_stretch(&first, &lengths) < 1e-6, "{}", max_stretch(&first, &lengths));
        assert_eq!(history.relinearized, 1);
        for streak in 1..=RETRY_DIRECT {
            s.newton.corrected.fill(DVec3::NAN);
            let mut again = p.clone();
            assert_eq!(solve_warm(&mut again, &lengths, &mut s, &mut history, &mut unlimited()), Solved::GaussNewton);
            assert!(crate::core::rod::same_bits(&again, &first), "streak {streak}");
            assert_eq!(history.relinearized, streak + 1);
            let direct_ran = !s.newton.corrected[1].is_nan();
            assert_eq!(direct_ran, streak < RELINEARIZE_AFTER || streak == RETRY_DIRECT, "streak {streak}");
        }
        // A prediction the direct solve meets, at a retry: the streak ends.
        history.relinearized = 2 * RETRY_DIRECT;
        let mut easy: Vec<DVec3> = x.iter().map(|v| *v - DVec3::Y * 1.7e-4 * (v.x / 0.025)).collect();
        assert_eq!(solve_warm(&mut easy, &lengths, &mut s, &mut history, &mut unlimited()), Solved::Direct);
        assert_eq!(history.relinearized, 0);
        // And forgetting the chain's memory (placed anew) ends one too.
        let mut memory = SolveMemory::new(m);
        memory.warm[1].relinearized = 3;
        memory.forget();
        assert_eq!(memory.warm[1].relinearized, 0);
    }

    #[test]
    fn folded_chain_falls_back_and_stays_finite() {
        // Previous bonds perpendicular to the target bonds: the direct solve has no purchase.
        let x = vec![DVec3::ZERO, DVec3::X, DVec3::new(2.0, 0.0, 0.0)];
        let mut p = vec![DVec3::ZERO, DVec3::new(0.0, 3.0, 0.0), DVec3::new(0.0, 3.0, 2.0)];
        let mut s = ConstraintScratch::default();
        assert!(!solve(&x, &mut p, &[1.0, 1.0], &mut s));
        assert!(p.iter().all(|v| v.is_finite()));
        assert!(max_stretch(&p, &[1.0, 1.0]) < 1e-3);
    }
}
