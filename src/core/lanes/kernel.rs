//! One substep of a lane group: [`rod::substep`](crate::core::rod::substep) for `L` chains of the same
//! joint count at once (the contacts: [`contacts`]). Same algorithm, same constants, same order of operations within
//! a lane; only the data layout differs (one array per quantity, one lane per chain). Where the scalar
//! solver branches on a value (convergence, a rotation too large for a series, a failed direct solve), the
//! lanes keep a mask, and the rare lanes that need the scalar code get it one by one.

use super::contacts;
use super::group::LaneGroup;
use super::lengths::{Passes, solve_lengths};
use super::matching::{self, Stiffness};
use super::output;
use super::rotations::{Predict, Spin, angular_velocities, predict_orientations};
use super::simd::{D, DV3, F, M3, Mask, Q, V3};
use crate::core::inextensible::{self, SolveMemory, Solved};
use crate::core::polar::landing_angle;
use crate::core::rod::FINAL_CONTACT_ROUNDS;
use crate::core::stability::{self, Projection};
use crate::core::warm_start::WARM_SLOTS;

/// The vector phases of a substep, each compiled as its own function (a copy per instruction set:
/// `mod.rs`). One function holding the whole substep is too large for the compiler's vectoriser: it split
/// most 8-lane operations into 4-lane halves and spilled them (measured: about 8x the instructions of the
/// operation count).
pub struct Phases<const L: usize> {
    pub begin: fn(&mut LaneGroup<L>, usize),
    /// One shape-matching pass; its polar decompositions land below the given angle (`polar::landing_angle`).
    pub match_shape: fn(&mut LaneGroup<L>, f32),
    /// The direct solve on some lanes, from a multiplier history (a slot of `LaneGroup::warm`) or none.
    pub solve_lengths: fn(&mut LaneGroup<L>, Mask<L>, Option<usize>) -> Mask<L>,
    pub finish: fn(&mut LaneGroup<L>),
    /// The render pose: the capture after substep `s`, and the output at fraction `t` ([`output`]).
    pub capture: fn(&mut LaneGroup<L>, usize),
    pub output: fn(&mut LaneGroup<L>, f32),
    /// One contact pass on some lanes ([`contacts::collide`]); returns the pairs tested.
    pub collide: fn(&mut LaneGroup<L>, Mask<L>, bool) -> u64,
    /// Pre-stabilisation of some lanes ([`contacts::pre_stabilise`]).
    pub pre_stabilise: fn(&mut LaneGroup<L>, Mask<L>),
}

impl<const L: usize> Phases<L> {
    /// The phases compiled for the baseline instruction set.
    pub const PORTABLE: Self = Self {
        begin: |g, s| begin_substep(g, s, predict_orientations),
        match_shape: |g, landing| match_shape(g, landing, sweep, orientation_terms),
        solve_lengths: |g, lanes, warm| solve_lengths(g, lanes, warm, &Passes::PORTABLE),
        finish: |g| finish_substep(g, angular_velocities),
        capture: output::capture,
        output: output::write,
        collide: |g, lanes, fresh| contacts::collide(g, lanes, fresh, None),
        pre_stabilise: |g, lanes| contacts::pre_stabilise(g, lanes, None),
    };
}

/// Advances every lane of `g` by substep `s` of the current step. Returns the lanes whose direct
/// inextensibility solve failed in some iteration (the scalar fallback ran for them).
pub fn substep<const L: usize>(g: &mut LaneGroup<L>, s: usize, phases: &Phases<L>) -> Mask<L> {
    (phases.begin)(g, s);
    let mut fell_back = Mask([false; L]);
    for iteration in 0..iterations(g) {
        fell_back = fell_back.or(iterate(g, phases, iteration as usize));
    }
    (phases.finish)(g);
    fell_back
}

/// [`substep`] for a group where some lanes may touch colliders, with `rod::substep`'s contact handling on
/// those lanes ([`contacts`]: `collision`'s scalar code, screened in lanes against spheres and capsules):
/// pre-stabilisation, a contact pass after every
/// iteration, and the final rounds of lengths then contacts until the contacts settle. The other lanes do
/// exactly what [`substep`] does. Returns the lanes that fell back and the (segment or particle, collider)
/// pairs tested.
pub fn substep_with_contacts<const L: usize>(g: &mut LaneGroup<L>, s: usize, phases: &Phases<L>) -> (Mask<L>, u64) {
    let touching = g.contact_lanes;
    (phases.pre_stabilise)(g, touching);
    (phases.begin)(g, s);
    let iterations = iterations(g);
    let mut fell_back = Mask([false; L]);
    let mut pairs = 0;
    for iteration in 0..iterations {
        fell_back = fell_back.or(iterate(g, phases, iteration as usize));
        pairs += (phases.collide)(g, touching, true);
        start_bonds(g);
        if iteration + 1 == iterations {
            for _ in 1..FINAL_CONTACT_ROUNDS {
                let again = contacts::unsettled(g, touching);
                if !again.any() {
                    break;
                }
                // Lanes with a joint that slides on a collider take the scalar sliding solve, lane by lane (as
                // the scalar solver does); the others the vector solve, as before.
                let sliding = contacts::sliding(g, again);
                let vector = again.and(sliding.not());
                if vector.any() {
                    // Restoring the lengths after the contacts: no budget (`stability::TensionBudget::UNLIMITED`).
                    g.tension_room = D::splat(f64::INFINITY);
                    let solved = (phases.solve_lengths)(g, vector, None);
                    let failed = vector.and(solved.not());
                    if failed.any() {
                        fell_back = fell_back.or(failed);
                        fall_back(g, failed, Mask([false; L]), false, false);
                    }
                }
                if sliding.any() {
                    fell_back = fell_back.or(contacts::solve_sliding(g, sliding));
                }
                pairs += (phases.collide)(g, again, false);
                start_bonds(g);
            }
        }
    }
    (phases.finish)(g);
    (fell_back, pairs)
}

#[inline(always)]
fn iterations<const L: usize>(g: &LaneGroup<L>) -> u32 {
    if g.shape_matching { g.iterations.max(1) } else { 1 }
}

/// The start positions' bonds: the direct solve's correction directions until the contact pass moves them.
#[inline(always)]
fn start_bonds<const L: usize>(g: &mut LaneGroup<L>) {
    for k in 0..g.n - 1 {
        g.start_bonds[k] = g.x[k + 1] - g.x[k];
    }
}

/// Correction directions, the kinematic root, and the prediction of the dynamic particles.
#[inline(always)]
pub fn begin_substep<const L: usize>(g: &mut LaneGroup<L>, s: usize, predict: Predict<L>) {
    let n = g.n;
    let h = g.h;
    let (anchor_position, anchor_rotation) = g.anchors[s];
    start_bonds(g);
    g.tension_spent = D::splat(0.0);

    // Kinematic root.
    g.p[0] = anchor_position.to_f64() + anchor_rotation.rotate(g.rest_root).to_f64();
    g.qp[0] = anchor_rotation.mul(g.qbar[0]).normalize();

    // Predict, damping relative to the root.
    let kick = F::select(g.half_kick, F::splat(0.5 * h), F::splat(h));
    g.half_kick = Mask([false; L]);
    let root_velocity = (g.p[0] - g.x[0]).scale(D::splat(1.0 / h as f64)).to_f32();
    for i in 1..n {
        let relative = g.v[i] - root_velocity;
        g.v[i] = root_velocity + relative.scale(g.decay) + g.gravity.scale(kick);
        g.w[i] = g.w[i].scale(g.decay);
        g.p[i] = g.x[i] + (g.v[i] * h).to_f64();
    }
    predict(&g.w[1..n], &g.q[1..n], &mut g.qp[1..n], h);
}

/// One solver iteration: shape matching, then the lengths on every lane. Returns the lanes that fell back.
/// The first iteration's solve is `inextensible::solve_first` on every lane: lanes whose chains' first
/// solves have been taking the exact projection start with it, from their remembered tensions.
fn iterate<const L: usize>(g: &mut LaneGroup<L>, phases: &Phases<L>, iteration: usize) -> Mask<L> {
    let first = iteration == 0;
    let slot = (iteration < WARM_SLOTS).then_some(iteration);
    if g.shape_matching {
        (phases.match_shape)(g, landing_angle(iteration as u32, iterations(g)));
    }
    // Most groups have no lane that remembers anything.
    let remembering = first && g.memories.iter().any(SolveMemory::in_streak);
    let pending = if remembering { exact_from_memory(g) } else { Mask([true; L]) };
    // Lanes whose solve keeps ending in the Gauss-Newton projection go straight to it (`inextensible::solve_warm`).
    // Most groups have no lane in such a streak.
    let streaking = slot.filter(|&slot| g.warm[slot].relinearized != [0; L]);
    let relinearizing = match streaking {
        Some(slot) => Mask(g.warm[slot].relinearized.map(inextensible::relinearizes)).and(pending),
        None => Mask([false; L]),
    };
    let direct = pending.and(relinearizing.not());
    g.tension_room = g.tension_limit - g.tension_spent;
    let solved = (phases.solve_lengths)(g, direct, slot);
    g.tension_spent = D::select(solved, g.tension_spent + g.tension, g.tension_spent);
    if remembering {
        for lane in (0..L).filter(|&lane| solved.0[lane]) {
            g.memories[lane].learn(Solved::Direct, &g.constraints, g.n - 1);
        }
    }
    let failed = direct.and(solved.not());
    let falling_back = failed.or(relinearizing).any();
    let ended = if falling_back { fall_back(g, failed, relinearizing, first, true) } else { [None; L] };
    if let Some(slot) = slot.filter(|_| falling_back || streaking.is_some()) {
        // Every lane's streak as `inextensible::relinearized_after` leaves it; a lane that did not fall back
        // ended in the direct solve or the exact projection from memory (`solve_first`), which ends it.
        let streaks = &mut g.warm[slot].relinearized;
        for (streak, ended) in streaks.iter_mut().zip(ended) {
            *streak = ended.map_or(0, |solved| inextensible::relinearized_after(*streak, solved));
        }
    }
    solved.not()
}

/// `inextensible::exact_from_memory` on every lane; returns the lanes it did not solve.
#[cold]
fn exact_from_memory<const L: usize>(g: &mut LaneGroup<L>) -> Mask<L> {
    let n = g.n;
    let mut left = Mask([true; L]);
    for lane in 0..L {
        if !g.memories[lane].wants_exact() {
            continue;
        }
        contacts::extract(&g.p[..n], lane, &mut g.lane_p);
        g.lane_lengths.clear();
        g.lane_lengths.extend(g.lengths[..n - 1].iter().map(|l| l.0[lane]));
        if inextensible::exact_from_memory(&mut g.lane_p, &g.lane_lengths, &mut g.constraints, &mut g.memories[lane]) {
            contacts::write_back(&g.lane_p, lane, &mut g.p[..n]);
            left.0[lane] = false;
        }
    }
    left
}

/// Velocities from positions; the end of the substep becomes the start of the next.
#[inline(always)]
pub fn finish_substep<const L: usize>(g: &mut LaneGroup<L>, spin: Spin<L>) {
    let n = g.n;
    let inv_h = 1.0 / g.h;
    spin(&g.qp[1..n], &g.q[1..n], &mut g.w[1..n], inv_h);
    for i in 1..n {
        g.v[i] = (g.p[i] - g.x[i]).to_f32() * inv_h;
        g.x[i] = g.p[i];
        g.q[i] = g.qp[i];
    }
    g.x[0] = g.p[0];
    g.q[0] = g.qp[0];
}

/// One Gauss-Seidel pass over the shape-matching groups, root to tip (see `rod::match_shape`).
#[inline(always)]
pub fn match_shape<const L: usize>(
    g: &mut LaneGroup<L>,
    landing: f32,
    sweep: SweepFn<L>,
    orientation_terms: OrientationTerms<L>,
) {
    let n = g.n;
    let alpha = g.alpha;
    let alpha64 = alpha.to_f64();
    let ow = g.orientation_weight;
    // Every array cut to the joint count up front: the loop indexes them without bounds checks.
    let (p, qp, qbar, qbar_inv) = (&mut g.p[..n], &mut g.qp[..n], &g.qbar[..n], &g.qbar_inv[..n]);
    let (offsets, group_rotation) = (&g.offsets[..n], &mut g.group_rotation[..n]);
    let terms = &mut g.orientation_terms[..n];

    // The root's group, clamped to the root.
    let rotation = qp[0].mul(qbar_inv[0]).normalize();
    group_rotation[1] = rotation;
    let centre = p[0];
    for j in 1..n.min(3) {
        p[j] = pull_to_goal(p[j], centre, rotation.rotate(offsets[1][j]), alpha64);
    }
    qp[1] = qp[1].nlerp_shorter(rotation.mul(qbar[1]), alpha);

    // A joint's rotation changes only in its own group, after its last use as a group's middle or upper member:
    // those terms can all be taken before the sweep (a loop of its own, which keeps the sweep's registers
    // free); only the lower member's, updated by the group before, is taken in the sweep.
    orientation_terms(&qp[2..], &qbar_inv[2..], ow, &mut terms[2..]);
    let stiffness = Stiffness { orientation_weight: ow, alpha, alpha64 };
    sweep(p, qp, qbar, qbar_inv, offsets, terms, group_rotation, &stiffness, landing);
}

/// The sweep's groups after the root's ([`matching::match_group`]), every buffer cut to the joint count. A
/// function of its own, compiled per instruction set (`mod.rs`), that takes every buffer as a separate slice:
/// only so does the compiler know they do not overlap, which it must to vectorise the groups' lane loops
/// (inlined into [`match_shape`], whose buffers are fields of the group, the loops ran lane by lane).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub fn sweep<const L: usize>(
    p: &mut [DV3<L>],
    qp: &mut [Q<L>],
    qbar: &[Q<L>],
    qbar_inv: &[Q<L>],
    offsets: &[[V3<L>; 3]],
    terms: &[M3<L>],
    group_rotation: &mut [Q<L>],
    stiffness: &Stiffness<L>,
    landing: f32,
) {
    let n = p.len();
    let (qp, qbar, qbar_inv, offsets, terms, group_rotation) =
        (&mut qp[..n], &qbar[..n], &qbar_inv[..n], &offsets[..n], &terms[..n], &mut group_rotation[..n]);
    // The tip's group has no upper member: this stands in for it, neither read nor written.
    let mut spare = DV3::ZERO;
    for i in 2..n {
        let (below, above) = p.split_at_mut(i);
        let (middle, above) = above.split_first_mut().expect("a middle member");
        let lower = &mut below[i - 1];
        let (qp_below, qp_above) = qp.split_at_mut(i);
        let lower_turn = [&qp_below[i - 1], &qbar_inv[i - 1]];
        let (rotation, qbar, qp) = (&mut group_rotation[i], &qbar[i], &mut qp_above[0]);
        match above.first_mut() {
            Some(upper) => matching::match_group::<L, true>(
                lower,
                middle,
                upper,
                &offsets[i],
                lower_turn,
                [&terms[i], &terms[i + 1]],
                rotation,
                qbar,
                qp,
                stiffness,
                landing,
            ),
            None => matching::match_group::<L, false>(
                lower,
                middle,
                &mut spare,
                &offsets[i],
                lower_turn,
                [&terms[i], &terms[i]],
                rotation,
                qbar,
                qp,
                stiffness,
                landing,
            ),
        }
    }
}

/// [`sweep`] compiled for the instruction set at hand.
pub type SweepFn<const L: usize> =
    fn(&mut [DV3<L>], &mut [Q<L>], &[Q<L>], &[Q<L>], &[[V3<L>; 3]], &[M3<L>], &mut [Q<L>], &Stiffness<L>, f32);

/// [`orientation_terms`] compiled for the instruction set at hand (`mod.rs`).
pub type OrientationTerms<const L: usize> = fn(&[Q<L>], &[Q<L>], F<L>, &mut [M3<L>]);

/// Every joint's orientation term of the group matrix.
#[inline(always)]
pub fn orientation_terms<const L: usize>(qp: &[Q<L>], qbar_inv: &[Q<L>], weight: F<L>, terms: &mut [M3<L>]) {
    for ((term, &qp), &qbar_inv) in terms.iter_mut().zip(qp).zip(qbar_inv) {
        *term = rotation_term(qp, qbar_inv, weight);
        // An empty barrier: it keeps the compiler from vectorising this loop across the joints (8 joints' terms
        // at once, every value gathered and scattered); each joint's term is then computed across the lanes.
        // Callgrind on `scene_cost 20 1000x16 lanes`: 83 instructions per term (`terms8_avx2_version`, 23.3M for
        // 280 000 terms), 208 in a build without the barrier (not in the repository).
        std::hint::black_box(());
    }
}

/// The orientation term of a member whose predicted rotation is `qp`: its turn from rest as a matrix, weighted.
#[inline(always)]
fn rotation_term<const L: usize>(qp: Q<L>, qbar_inv: Q<L>, weight: F<L>) -> M3<L> {
    M3::from_quat(qp.mul(qbar_inv)).scale(weight)
}

#[inline(always)]
fn pull_to_goal<const L: usize>(p: DV3<L>, centre: DV3<L>, offset: V3<L>, alpha: D<L>) -> DV3<L> {
    let goal = centre + offset.to_f64();
    p + (goal - p).scale(alpha)
}

/// The scalar fallback for every lane in `failed` (from its direct solve's last multipliers) and in
/// `relinearizing` (from none: it skipped the direct solve), one lane at a time; a substep's first solve
/// (`learn`) also updates the lane's solve memory. A `budgeted` solve (one of the iterations', not a contact
/// round's) falls back to the projection its tension calls for. Returns how each of those lanes' solve ended.
#[cold]
fn fall_back<const L: usize>(
    g: &mut LaneGroup<L>,
    failed: Mask<L>,
    relinearizing: Mask<L>,
    learn: bool,
    budgeted: bool,
) -> [Option<Solved>; L] {
    let n = g.n;
    let mut ended = [None; L];
    for lane in 0..L {
        if !(failed.0[lane] || relinearizing.0[lane]) {
            continue;
        }
        contacts::extract(&g.p[..n], lane, &mut g.lane_p);
        g.lane_lengths.clear();
        g.lane_lengths.extend(g.lengths[..n - 1].iter().map(|l| l.0[lane]));
        g.lane_mu.clear();
        if relinearizing.0[lane] {
            g.lane_mu.resize(n - 1, 0.0);
        } else {
            g.lane_mu.extend(g.mu[..n - 1].iter().map(|mu| mu.0[lane]));
        }
        // After a direct solve, the projection its tension calls for (`inextensible::fall_back_within`).
        let first = if budgeted && failed.0[lane] {
            let tension =
                if g.refused.0[lane] { g.tension.0[lane] } else { inextensible::largest_multiplier(&g.lane_mu) };
            stability::projection(g.zigzag_gain.0[lane], g.tension_spent.0[lane] + tension)
        } else {
            Projection::GaussNewton
        };
        let solved =
            inextensible::solve_fallback(&mut g.lane_p, &g.lane_lengths, &g.lane_mu, &mut g.constraints, first);
        if learn {
            g.memories[lane].learn(solved, &g.constraints, n - 1);
        }
        contacts::write_back(&g.lane_p, lane, &mut g.p[..n]);
        ended[lane] = Some(solved);
    }
    ended
}
