//! The direct inextensibility solve (`inextensible::newton_along_directions`) on every lane of a group.
//!
//! The passes over the bonds, which do most of the work, are written as loops over the lanes whose bodies are one
//! lane's scalar arithmetic, for the reason given in [`polar`](super::polar): with 8-lane array operations
//! on double-precision 3-vectors the vectoriser grouped the 24 values of a vector across its components
//! (4-, 2- and 1-wide pieces), and most of a pass ran in 128-bit or scalar instructions. The arithmetic is
//! the same, operation for operation, so the bits are the same.

use super::group::LaneGroup;
use super::simd::{D, DV3, Mask};
use crate::core::inextensible::{
    LANDING_GATE, MAX_NEWTON_ITERATIONS, MIN_PIVOT, STAGNATION_LIMIT, TOLERANCE, TRUSTED_START,
};
use crate::core::warm_start::MultiplierHistory;

type DVec = [f64; 3];

/// The passes over the bonds (the two kinds of forward pass, and [`after_step`] after each Newton step), as
/// functions compiled for the instruction set at hand (`mod.rs`). They
/// must stay real functions taking every buffer as a separate slice: only across such a call does the
/// compiler know the buffers do not overlap, which it must to vectorise the lane loops (inlined, with the
/// slices cut from the group's `Vec`s, the loops stayed scalar). As functions they run 70 % 256-bit
/// instructions (`tools/instruction_mix.py corrected_pass8_avx2_version -- target/release/examples/step_cost
/// 64 16 20 sway`).
pub struct Passes<const L: usize> {
    pub first: FirstPass<L>,
    pub corrected: CorrectedPass<L>,
    pub after_step: AfterStep<L>,
}

pub type FirstPass<const L: usize> =
    fn(&[DV3<L>], &[DV3<L>], &[D<L>], &[D<L>], &mut [D<L>], &mut [D<L>], &mut ForwardPass<L>);
pub type CorrectedPass<const L: usize> =
    fn(&[DV3<L>], &mut [DV3<L>], &[D<L>], &[DV3<L>], &[D<L>], &[D<L>], &mut [D<L>], &mut [D<L>], &mut ForwardPass<L>);
pub type AfterStep<const L: usize> = fn(&[DV3<L>], &mut [DV3<L>], &[D<L>], &[D<L>], &[DV3<L>], &[D<L>]) -> D<L>;

impl<const L: usize> Passes<L> {
    /// The passes compiled for the baseline instruction set.
    pub const PORTABLE: Self = Self { first: first_pass, corrected: corrected_pass, after_step };
}

/// The direct solve on the lanes of `lanes`, from the multiplier history `warm` (a slot of `g.warm`) or from
/// none; returns the lanes where it converged (their `p` holds the result; every other lane's `p` is
/// untouched), and the history learns from them (and forgets the lanes of `lanes` that failed).
#[inline(always)]
pub fn solve_lengths<const L: usize>(
    g: &mut LaneGroup<L>,
    lanes: Mask<L>,
    warm: Option<usize>,
    passes: &Passes<L>,
) -> Mask<L> {
    let m = g.n - 1;
    // `inextensible::newton_along_directions` from `Start::Warm` on the lanes that remember multipliers, from
    // `Start::Cold` on the others (their first pass, under no multipliers, computes the cold pass's values).
    let started = warm.map_or(Mask([false; L]), |slot| g.warm[slot].remembered.and(lanes));
    match warm {
        Some(slot) if started.all() => {
            let history = &g.warm[slot];
            for ((mu, &last), &before) in g.mu[..m].iter_mut().zip(&history.last[..m]).zip(&history.before[..m]) {
                *mu = last.zip(before, MultiplierHistory::start);
            }
        }
        Some(slot) if started.any() => {
            let history = &g.warm[slot];
            for ((mu, &last), &before) in g.mu[..m].iter_mut().zip(&history.last[..m]).zip(&history.before[..m]) {
                let start = last.zip(before, MultiplierHistory::start);
                *mu = D::select(started, start, D::select(lanes, D::splat(0.0), *mu));
            }
        }
        _ => zero_multipliers(g, m, lanes),
    }
    g.refused = Mask([false; L]);
    let mut solved = newton(g, lanes, started, passes);
    if let Some(slot) = warm {
        // As `inextensible::solve_warm`: a warm start that failed tries again from none before the fallback
        // (not one the budget refused: it met the lengths).
        let retry = started.and(solved.not()).and(g.refused.not());
        if retry.any() {
            zero_multipliers(g, m, retry);
            solved = solved.or(newton(g, retry, Mask([false; L]), passes));
        }
        learn(g, slot, m, solved);
    }
    solved
}

#[inline(always)]
fn zero_multipliers<const L: usize>(g: &mut LaneGroup<L>, m: usize, lanes: Mask<L>) {
    for mu in &mut g.mu[..m] {
        *mu = D::select(lanes, D::splat(0.0), *mu);
    }
}

/// `inextensible::newton_along_directions` on the lanes of `lanes`, from the multipliers in `g.mu`: a warm start
/// on the lanes of `started`, none on the others (whose multipliers are zero).
#[inline(always)]
fn newton<const L: usize>(g: &mut LaneGroup<L>, lanes: Mask<L>, started: Mask<L>, passes: &Passes<L>) -> Mask<L> {
    let m = g.n - 1;
    let mut active = lanes;
    let mut solved = Mask([false; L]);
    let mut previous_worst = D::splat(f64::INFINITY);
    for iteration in 0..MAX_NEWTON_ITERATIONS {
        let corrected = iteration > 0 || started.any();
        let pass = forward_pass(g, iteration, corrected, passes);
        let converged = active.and(pass.converged(previous_worst));
        if converged.any() {
            let converged = within_room(g, m, converged);
            if g.refused.any() {
                active = active.and(g.refused.not());
            }
            if corrected {
                take_corrected(g, m, converged);
            }
            solved = solved.or(converged);
            active = active.and(converged.not());
        }
        // Lanes whose start is worse than none (`inextensible::TRUSTED_START`) start again: their next pass,
        // under no multipliers, is the cold start's first (`le(..).not()`: a NaN error too).
        let mut restart = Mask([false; L]);
        if iteration == 0 {
            let doubtful = active.and(started).and(pass.worst.le(D::splat(TRUSTED_START)).not());
            if doubtful.any() {
                restart = doubtful.and(pass.worst.le(largest_error(g, m)).not());
            }
        }
        if restart.any() {
            for mu in &mut g.mu[..m] {
                *mu = D::select(restart, D::splat(0.0), *mu);
            }
        }
        let stepping = active.and(restart.not());
        active = active.and(restart.or(pass.diverging(previous_worst).not().and(pass.pivots_usable())));
        previous_worst = D::select(restart, D::splat(f64::INFINITY), pass.worst);
        if iteration == 0 {
            // Lanes that fail before their first step keep no multipliers from an earlier solve (another
            // chain may have held the lane): their fallback starts from none, as on the scalar solver.
            let stopped = lanes.and(active.not()).and(solved.not());
            if stopped.any() {
                for mu in &mut g.mu[..m] {
                    *mu = D::select(stopped, D::splat(0.0), *mu);
                }
            }
        }
        if !active.any() {
            break;
        }
        // Back substitution (the Thomas algorithm's pass back), into the multipliers of the stepping lanes.
        let stepping = stepping.and(active);
        let mut next = D::splat(0.0);
        let (c_prime, d_prime) = (&g.c_prime[..m], &g.d_prime[..m]);
        let every_lane = stepping.all();
        for (((step, mu), &c), &d) in g.step[..m].iter_mut().zip(&mut g.mu[..m]).zip(c_prime).zip(d_prime).rev() {
            next = d - c * next;
            *step = next;
            *mu = if every_lane { *mu + next } else { D::select(stepping, *mu + next, *mu) };
        }
        active = active.and(restart.or(next.is_finite()));
        // The positions under the new multipliers, which the next pass reads, and
        // `inextensible::error_after_step`: lanes whose step lands within the tolerance take those positions
        // without the pass that would confirm it.
        let after = positions_after_step(g, m, passes);
        let near = stepping.and(active).and(pass.worst.le(D::splat(LANDING_GATE)));
        if near.any() {
            let landed = near.and(after.le(D::splat(TOLERANCE)));
            if landed.any() {
                let landed = within_room(g, m, landed);
                if g.refused.any() {
                    active = active.and(g.refused.not());
                }
                take_corrected(g, m, landed);
                solved = solved.or(landed);
                active = active.and(landed.not());
            }
        }
        if !active.any() {
            break;
        }
    }
    solved
}

/// The lanes of `lanes` (whose solve converged) that the tension budget admits (`inextensible::newton_along_directions`
/// with its `room`); it refuses the others (`g.refused`). Records each of them's largest multiplier (`g.tension`).
#[inline(always)]
fn within_room<const L: usize>(g: &mut LaneGroup<L>, m: usize, lanes: Mask<L>) -> Mask<L> {
    // `inextensible::largest_multiplier`, lane by lane: the same operations in the same order.
    let largest =
        g.mu[..m].iter().fold(D::splat(0.0), |largest, mu| largest.zip(mu.abs(), crate::core::inextensible::larger));
    g.tension = D::select(lanes, largest, g.tension);
    // `le`: a NaN is refused, as `inextensible::above` refuses it.
    let admitted = lanes.and(largest.le(g.tension_room));
    if admitted != lanes {
        g.refused = g.refused.or(lanes.and(admitted.not()));
    }
    admitted
}

/// `MultiplierHistory::learn` on the lanes of `solved`, `forget` on the others.
#[inline(always)]
fn learn<const L: usize>(g: &mut LaneGroup<L>, slot: usize, m: usize, solved: Mask<L>) {
    let history = &mut g.warm[slot];
    let remembered = history.remembered;
    if solved.all() && remembered.all() {
        // The history moves on one solve: the last multipliers become the ones before.
        std::mem::swap(&mut history.last, &mut history.before);
        history.last[..m].copy_from_slice(&g.mu[..m]);
        history.remembered = solved;
        return;
    }
    for ((&mu, last), before) in g.mu[..m].iter().zip(&mut history.last[..m]).zip(&mut history.before[..m]) {
        *before = D::select(solved, D::select(remembered, *last, mu), *before);
        *last = D::select(solved, mu, *last);
    }
    history.remembered = solved;
}

/// `inextensible::largest_error` on every lane: the largest relative bond error of `p` (NaN if any is).
#[inline(always)]
fn largest_error<const L: usize>(g: &LaneGroup<L>, m: usize) -> D<L> {
    let (p, l2, inv_l2) = (&g.p[..=m], &g.length_squared[..m], &g.inverse_length_squared[..m]);
    let mut worst = [0.0; L];
    for k in 0..m {
        let (tip, start, l2, inv) = (&p[k + 1], &p[k], &l2[k], &inv_l2[k]);
        for lane in 0..L {
            let b = sub(tip.get(lane), start.get(lane));
            let error = ((dot(b, b) - l2.0[lane]) * inv.0[lane]).abs();
            worst[lane] = if error > worst[lane] || error.is_nan() { error } else { worst[lane] };
        }
    }
    D(worst)
}

/// `p` takes the positions of `g.corrected` on the lanes of `lanes`.
#[inline(always)]
fn take_corrected<const L: usize>(g: &mut LaneGroup<L>, m: usize, lanes: Mask<L>) {
    if lanes.all() {
        // The buffers trade places rather than copy (2.9 KB a group of 8 with 16 joints): `corrected` is
        // scratch until a pass writes it again, and every pass that fills it starts with `corrected[0] = p[0]`,
        // so the root stays.
        debug_assert!((0..L).all(|lane| g.corrected[0].get(lane) == g.p[0].get(lane)));
        std::mem::swap(&mut g.p, &mut g.corrected);
    } else {
        for (p, &corrected) in g.p[1..=m].iter_mut().zip(&g.corrected[1..=m]) {
            *p = DV3::select(lanes, corrected, *p);
        }
    }
}

/// After a Newton step: [`after_step`] on the group's buffers.
#[inline(always)]
fn positions_after_step<const L: usize>(g: &mut LaneGroup<L>, m: usize, passes: &Passes<L>) -> D<L> {
    let (d, inv_l2) = (&g.start_bonds[..m], &g.inverse_length_squared[..m]);
    (passes.after_step)(&g.p[..=m], &mut g.corrected[..=m], &g.mu[..m], &g.step[..m], d, inv_l2)
}

/// One pass root to tip: the bonds under the current multipliers (`corrected`; the bonds of `p` itself
/// before the first step), their errors, and the forward elimination of the Newton system.
#[inline(always)]
fn forward_pass<const L: usize>(
    g: &mut LaneGroup<L>,
    iteration: usize,
    corrected: bool,
    passes: &Passes<L>,
) -> ForwardPass<L> {
    let m = g.n - 1;
    let mut pass = ForwardPass::new();
    let (d, l2, inv_l2) = (&g.start_bonds[..m], &g.length_squared[..m], &g.inverse_length_squared[..m]);
    let (c_prime, d_prime) = (&mut g.c_prime[..m], &mut g.d_prime[..m]);
    if iteration > 0 {
        // `after_step` left the positions under the current multipliers in `corrected`: the bonds of those.
        (passes.first)(&g.corrected[..=m], d, l2, inv_l2, c_prime, d_prime, &mut pass);
    } else if corrected {
        (passes.corrected)(&g.p[..=m], &mut g.corrected[..=m], &g.mu[..m], d, l2, inv_l2, c_prime, d_prime, &mut pass);
    } else {
        (passes.first)(&g.p[..=m], d, l2, inv_l2, c_prime, d_prime, &mut pass);
    }
    pass
}

/// Bond `k`'s row inputs; `first` and `last` say whether it is the chain's first or last bond.
#[inline(always)]
fn bond<'a, const L: usize>(
    k: usize,
    (first, last): (bool, bool),
    d: &'a [DV3<L>],
    l2: &'a [D<L>],
    inv_l2: &'a [D<L>],
) -> Bond<'a, L> {
    let end = d.len() - 1;
    Bond {
        first,
        last,
        length_squared: &l2[k],
        inverse_length_squared: &inv_l2[k],
        lower: &d[k.saturating_sub(1)],
        own: &d[k],
        upper: &d[(k + 1).min(end)],
    }
}

/// Runs `$row` for every bond `$k` of `$m`, root to tip, with `$ends` = (first bond, last bond), and with the first
/// and the last bond peeled off the loop: the row code of the bonds between them has no test of the chain's ends
/// (with the ends tested per bond, the compiler loaded the neighbours' bonds under masks, `vmaskmovpd`, and built
/// the masks for every bond). A macro, not a function taking a closure: the closure's captured slices lose what
/// the compiler knows of their not overlapping, and the lane loops ran in scalar instructions.
macro_rules! each_bond {
    ($m:expr, |$k:ident, $ends:ident| $row:block) => {{
        let m = $m;
        if m == 1 {
            let ($k, $ends) = (0, (true, true));
            $row
        } else {
            {
                let ($k, $ends) = (0, (true, false));
                $row
            }
            for $k in 1..m - 1 {
                let $ends = (false, false);
                $row
            }
            {
                let ($k, $ends) = (m - 1, (false, true));
                $row
            }
        }
    }};
}

/// A pass over the bonds of `p` as they are: the first (no multipliers yet) and every pass after a step (the
/// positions [`after_step`] moved).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub fn first_pass<const L: usize>(
    p: &[DV3<L>],
    d: &[DV3<L>],
    l2: &[D<L>],
    inv_l2: &[D<L>],
    c_prime: &mut [D<L>],
    d_prime: &mut [D<L>],
    pass: &mut ForwardPass<L>,
) {
    let m = d.len();
    // As in `corrected_pass`.
    let (p, l2, inv_l2, c_prime, d_prime) = (&p[..=m], &l2[..m], &inv_l2[..m], &mut c_prime[..m], &mut d_prime[..m]);
    each_bond!(m, |k, ends| {
        let bond = bond(k, ends, d, l2, inv_l2);
        let (tip, start) = (&p[k + 1], &p[k]);
        let (c_row, d_row) = (&mut c_prime[k], &mut d_prime[k]);
        for lane in 0..L {
            pass.row(lane, sub(tip.get(lane), start.get(lane)), &bond, c_row, d_row);
        }
    });
}

/// A later pass: `p` moved by the multipliers `mu` along the start bonds (`inextensible::shift`), kept in
/// `corrected`. Every slice is indexed before the lane loops: a bounds check inside one keeps it scalar.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub fn corrected_pass<const L: usize>(
    p: &[DV3<L>],
    corrected: &mut [DV3<L>],
    mu: &[D<L>],
    d: &[DV3<L>],
    l2: &[D<L>],
    inv_l2: &[D<L>],
    c_prime: &mut [D<L>],
    d_prime: &mut [D<L>],
    pass: &mut ForwardPass<L>,
) {
    let m = d.len();
    // Every slice cut to its length up front: a bounds check in the loop would keep it scalar-stepped and make
    // `pass` go back to memory at each bond (a panic there must see its fields).
    let (p, corrected, mu, l2, inv_l2) = (&p[..=m], &mut corrected[..=m], &mu[..m], &l2[..m], &inv_l2[..m]);
    let (c_prime, d_prime) = (&mut c_prime[..m], &mut d_prime[..m]);
    corrected[0] = p[0];
    each_bond!(m, |k, ends| {
        let bond = bond(k, ends, d, l2, inv_l2);
        let tip = &p[k + 1];
        let (own_mu, upper_mu) = (&mu[k], &mu[(k + 1).min(m - 1)]);
        let (below, at) = corrected.split_at_mut(k + 1);
        let (start, moved_tip) = (&below[k], &mut at[0]);
        let (c_row, d_row) = (&mut c_prime[k], &mut d_prime[k]);
        for lane in 0..L {
            let shift =
                bond_shift(bond.own.get(lane), own_mu.0[lane], bond.upper.get(lane), upper_mu.0[lane], bond.last);
            let moved = add(tip.get(lane), shift);
            moved_tip.set(lane, moved);
            pass.row(lane, sub(moved, start.get(lane)), &bond, c_row, d_row);
        }
    });
}

/// After a Newton step of the multipliers: the positions under the new multipliers `mu` (`p` moved as
/// [`corrected_pass`] moves it, into `corrected`, which the next pass reads and a landing step takes), and
/// `inextensible::error_after_step` from the step `step`, returned. One pass over the bonds for both, lane by
/// lane within each bond as the other passes (and for their reason): the two were separate loops before, and
/// the positions were computed again by the next pass.
#[inline(always)]
pub fn after_step<const L: usize>(
    p: &[DV3<L>],
    corrected: &mut [DV3<L>],
    mu: &[D<L>],
    step: &[D<L>],
    d: &[DV3<L>],
    inv_l2: &[D<L>],
) -> D<L> {
    let m = d.len();
    // Every slice cut to its length up front, as in `corrected_pass`.
    let (p, corrected, mu, step, inv_l2) = (&p[..=m], &mut corrected[..=m], &mu[..m], &step[..m], &inv_l2[..m]);
    corrected[0] = p[0];
    let mut worst = [0.0; L];
    let mut below = DV3::<L>::ZERO;
    each_bond!(m, |k, ends| {
        let last = ends.1;
        let upper = (k + 1).min(m - 1);
        let (own, next, own_step, next_step, inv) = (&d[k], &d[upper], &step[k], &step[upper], &inv_l2[k]);
        let (own_mu, next_mu, tip) = (&mu[k], &mu[upper], &p[k + 1]);
        let moved_tip = &mut corrected[k + 1];
        for lane in 0..L {
            let (own_bond, next_bond) = (own.get(lane), next.get(lane));
            let above = bond_shift(own_bond, own_step.0[lane], next_bond, next_step.0[lane], last);
            let e = sub(above, below.get(lane));
            let error = dot(e, e) * inv.0[lane];
            // As the scalar code: a NaN error is ignored here (its lane's step was not finite: not active).
            worst[lane] = if error > worst[lane] { error } else { worst[lane] };
            below.set(lane, above);
            let shift = bond_shift(own_bond, own_mu.0[lane], next_bond, next_mu.0[lane], last);
            moved_tip.set(lane, add(tip.get(lane), shift));
        }
    });
    D(worst)
}

/// What one bond's row of the pass reads.
struct Bond<'a, const L: usize> {
    /// Whether this is the chain's first bond (none below it) or its last (none above it).
    first: bool,
    last: bool,
    length_squared: &'a D<L>,
    inverse_length_squared: &'a D<L>,
    /// The start bonds before, of and after this one (clamped at the ends, where they do not count).
    lower: &'a DV3<L>,
    own: &'a DV3<L>,
    upper: &'a DV3<L>,
}

/// `inextensible::ForwardPass` on every lane.
pub struct ForwardPass<const L: usize> {
    worst: D<L>,
    scale: D<L>,
    smallest_pivot: D<L>,
    c_last: D<L>,
    d_last: D<L>,
}

impl<const L: usize> ForwardPass<L> {
    #[inline(always)]
    fn new() -> Self {
        Self {
            worst: D::splat(0.0),
            scale: D::splat(0.0),
            smallest_pivot: D::splat(f64::INFINITY),
            c_last: D::splat(0.0),
            d_last: D::splat(0.0),
        }
    }

    /// Bond `bond.k` of `lane` with vector `b`: its error, and its row of the forward elimination.
    #[inline(always)]
    fn row(&mut self, lane: usize, b: DVec, bond: &Bond<'_, L>, c_prime: &mut D<L>, d_prime: &mut D<L>) {
        let f = dot(b, b) - bond.length_squared.0[lane];
        let error = (f * bond.inverse_length_squared.0[lane]).abs();
        // As the scalar pass: a NaN error is ignored here.
        let worst = self.worst.0[lane];
        self.worst.0[lane] = if error > worst { error } else { worst };
        // Every product is computed and the ends' unused ones dropped by selects: loads under a condition keep
        // the loop from being vectorised.
        let (own, lower, upper) =
            (dot(b, bond.own.get(lane)), -dot(b, bond.lower.get(lane)), -dot(b, bond.upper.get(lane)));
        let diagonal = if bond.first { own } else { own * 2.0 };
        let lower = if bond.first { 0.0 } else { lower };
        let upper = if bond.last { 0.0 } else { upper };
        let den = diagonal - lower * self.c_last.0[lane];
        let diagonal_size = diagonal.abs();
        let scale = self.scale.0[lane];
        self.scale.0[lane] = if diagonal_size > scale { diagonal_size } else { scale };
        let pivot_size = den.abs();
        let smallest = self.smallest_pivot.0[lane];
        self.smallest_pivot.0[lane] = if pivot_size < smallest { pivot_size } else { smallest };
        let inv = 1.0 / den;
        let c_last = upper * inv;
        let d_last = (f * -0.5 - lower * self.d_last.0[lane]) * inv;
        self.c_last.0[lane] = c_last;
        self.d_last.0[lane] = d_last;
        c_prime.0[lane] = c_last;
        d_prime.0[lane] = d_last;
    }

    #[inline(always)]
    fn converged(&self, previous_worst: D<L>) -> Mask<L> {
        let floor = self.worst.gt(previous_worst * 0.5).and(self.worst.lt(D::splat(STAGNATION_LIMIT)));
        self.worst.le(D::splat(TOLERANCE)).or(floor)
    }

    #[inline(always)]
    fn diverging(&self, previous_worst: D<L>) -> Mask<L> {
        self.worst.gt(previous_worst)
    }

    #[inline(always)]
    fn pivots_usable(&self) -> Mask<L> {
        self.scale.gt(D::splat(0.0)).and(self.smallest_pivot.gt(self.scale * MIN_PIVOT))
    }
}

/// How far a bond's tip moves under the multipliers `own` (its bond's) and `upper` (the next bond's, none at the
/// last bond): pulled along its own start bond, pushed back along the next one (`inextensible::shift`).
#[inline(always)]
fn bond_shift(own_bond: DVec, own: f64, upper_bond: DVec, upper: f64, last: bool) -> DVec {
    let pulled = scale(own_bond, own);
    if last { pulled } else { sub(pulled, scale(upper_bond, upper)) }
}

#[inline(always)]
fn dot(a: DVec, b: DVec) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline(always)]
fn add(a: DVec, b: DVec) -> DVec {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

#[inline(always)]
fn sub(a: DVec, b: DVec) -> DVec {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[inline(always)]
fn scale(a: DVec, s: f64) -> DVec {
    [a[0] * s, a[1] * s, a[2] * s]
}
