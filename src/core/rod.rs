//! One chain as an elastic rod of oriented particles (Müller & Chentanez 2011, rods case) kept
//! inextensible by [`inextensible`](super::inextensible). This module advances one chain by one internal
//! substep; the engine decides when and with which kinematic input.

use glam::{DVec3, Mat3A, Quat, Vec3, Vec3A};

use super::arcs::ArcColumns;
use super::collision::{ContactInput, SegmentBounds, collide, pre_stabilise};
use super::elementary;
use super::inextensible::{self, ConstraintScratch, SlidingMemory, SolveMemory};
use super::math::{Transform, align_hemisphere, exp_small, log_small, nlerp_shorter};
use super::params::{ChainParams, EngineSettings};
use super::polar::{extract_rotation, landing_angle};
use super::rest_carry::carry_orientations;
use super::shape::Shape;
use super::stability::{self, TensionBudget};

/// Warm-started rotation extraction (Newton steps where the problem is well conditioned) reaches float
/// precision in 2-3 iterations and stops early once converged; the cap only bounds the worst case.
pub(crate) const POLAR_ITERATIONS: u32 = 8;

/// A third, in double precision: a full group's centre is its members' sum times this rather than divided by 3,
/// which the compiler may not do itself (the two round differently, by at most one unit in the last place). The
/// divider takes double-precision divisions at a seventeenth of the multipliers' rate on stop 41's AVX2 machine
/// (`docs/performance.md`, machine table), and the centre took three per group, iteration and lane.
pub(crate) const THIRD: f64 = 1.0 / 3.0;

/// Most rounds of (lengths, contacts) in the last solver iteration; they stop once the contacts move
/// nothing by more than `CONTACT_SETTLED` of the shortest segment.
pub(crate) const FINAL_CONTACT_ROUNDS: u32 = 16;
pub(crate) const CONTACT_SETTLED: f32 = 1e-4;

/// The dynamic state of a chain's particles, relative to the engine's origin. Particle 0 is kinematic.
///
/// Positions are double precision: a soft chain's per-substep pull towards its rest shape is a small
/// fraction of a small error, and in float32 it rounds away (the chain stalls short of its rest shape by
/// an amount inversely proportional to the stiffness). Everything else is single precision.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RodState {
    pub x: Vec<DVec3>,
    pub v: Vec<Vec3>,
    pub q: Vec<Quat>,
    pub w: Vec<Vec3>,
    /// Each shape-matching group's last rotation: the warm start of the next extraction.
    pub group_rotation: Vec<Quat>,
    /// What the lengths solve learnt for the next substep (the scalar solver's).
    pub solve_memory: SolveMemory,
}

impl RodState {
    /// Particles at the rest shape under `anchor`, at rest.
    pub fn at_rest(rest: &Shape, anchor: &Transform) -> Self {
        let n = rest.len();
        let mut s = Self {
            x: vec![DVec3::ZERO; n],
            v: vec![Vec3::ZERO; n],
            q: vec![Quat::IDENTITY; n],
            w: vec![Vec3::ZERO; n],
            group_rotation: vec![anchor.rotation; n],
            solve_memory: SolveMemory::new(n.saturating_sub(1)),
        };
        s.place_at_rest(rest, anchor);
        s
    }

    pub fn place_at_rest(&mut self, rest: &Shape, anchor: &Transform) {
        for j in 0..rest.len() {
            self.x[j] = anchor.place_f64(rest.positions[j]);
            self.q[j] = (anchor.rotation * rest.orientations[j]).normalize();
        }
        self.v.fill(Vec3::ZERO);
        self.w.fill(Vec3::ZERO);
        self.group_rotation.fill(anchor.rotation);
        self.solve_memory.forget();
    }

    /// Moves the whole chain rigidly by `delta` (a teleport carried with the anchor); velocities turn
    /// with it, so no kinetic energy is added.
    pub fn carry(&mut self, delta: &Transform) {
        for x in &mut self.x {
            *x = delta.transform_point_f64(*x);
        }
        for v in self.v.iter_mut().chain(self.w.iter_mut()) {
            *v = delta.rotation * *v;
        }
        for q in self.q.iter_mut().chain(self.group_rotation.iter_mut()) {
            *q = (delta.rotation * *q).normalize();
        }
        self.solve_memory.turn(delta.rotation);
    }

    pub fn translate(&mut self, offset: DVec3) {
        for x in &mut self.x {
            *x += offset;
        }
    }

    pub fn is_finite(&self) -> bool {
        self.x.iter().all(|x| x.is_finite())
            && self.v.iter().chain(&self.w).all(|v| v.is_finite())
            && self.q.iter().all(|q| q.is_finite())
    }
}

/// A chain's solver inputs that stay the same through a step (both solvers take them).
#[derive(Clone, Copy, Debug)]
pub struct ChainConstants {
    /// Fraction of the way to the shape-matching goals per iteration.
    pub alpha_per_iteration: f32,
    /// `exp(-damping * h)`.
    pub velocity_decay: f32,
    pub gravity: Vec3,
    /// `a^2 / 5`: weight of particle orientations in the group matrix.
    pub orientation_weight: f32,
    /// What the substep's shape-matching passes leave of a zig-zag: how much tension its direct lengths
    /// solves may carry ([`stability`]).
    pub zigzag_gain: f64,
}

impl ChainConstants {
    pub fn new(params: &ChainParams, settings: &EngineSettings, h: f32, iterations: u32) -> Self {
        let alpha_per_iteration = params.alpha_per_iteration(h, iterations);
        // Without shape matching a substep runs one iteration (`substep`).
        let passes = if alpha_per_iteration > 0.0 { iterations.max(1) } else { 1 };
        Self {
            alpha_per_iteration,
            velocity_decay: elementary::exp(-params.damping * h),
            gravity: settings.gravity * (params.gravity_scale * settings.scale),
            orientation_weight: (params.radius * settings.scale).powi(2) / 5.0,
            zigzag_gain: stability::zigzag_gain(alpha_per_iteration, passes),
        }
    }
}

/// Everything a substep needs besides the state.
pub struct SubstepInput<'a> {
    pub h: f32,
    /// The anchor at the end of this substep, relative to the engine origin.
    pub anchor: Transform,
    pub constants: ChainConstants,
    pub iterations: u32,
    pub rest: &'a Shape,
    /// Derived from `rest`.
    pub rest_groups: &'a RestGroups,
    /// A contact pass whose corrections stay below this (m) has settled (`Chain::contact_settled`).
    pub contact_settled: f32,
    /// First substep after placement: a half gravity kick starts the leapfrog.
    pub half_kick: bool,
    /// The colliders this chain can touch during this substep; `None` runs no collision code.
    pub contacts: Option<ContactInput<'a>>,
    /// The substep before, in the same step, ended on a contact pass that touched nothing
    /// ([`SubstepReport::ended_clear`]): the positions start outside every collider at this substep's start
    /// pose (that substep's end pose), so pre-stabilisation would find nothing and is skipped.
    pub starts_clear: bool,
}

/// What a substep reports back for the engine's counters.
#[derive(Clone, Copy, Debug, Default)]
pub struct SubstepReport {
    /// The inextensibility solve had to fall back in some iteration.
    pub fallback: bool,
    /// (segment or particle, collider) pairs tested.
    pub contact_pairs: u64,
    /// The substep's last contact pass touched nothing.
    pub ended_clear: bool,
}

/// Per-particle buffers reused across chains and substeps.
#[derive(Default)]
pub struct RodScratch {
    p: Vec<DVec3>,
    qp: Vec<Quat>,
    /// Positions of the chain carried over to a new rest shape (momentum suppression).
    p_old: Vec<DVec3>,
    /// The momentum suppression's segment arcs.
    arcs: ArcColumns,
    constraints: ConstraintScratch,
    bounds: SegmentBounds,
    /// The contact normal of each particle that slides on a collider in the contact rounds' lengths solves
    /// (`collision::collide`; zero for none), since the last iteration's contact pass.
    normals: Vec<Vec3>,
}

impl RodScratch {
    /// Room for a chain of `n` joints.
    pub(crate) fn reserve(&mut self, n: usize) {
        if self.p.len() < n {
            self.p.resize(n, DVec3::ZERO);
            self.qp.resize(n, Quat::IDENTITY);
            self.p_old.resize(n, DVec3::ZERO);
            self.normals.resize(n, Vec3::ZERO);
        }
        self.arcs.reserve(n.saturating_sub(1));
        self.constraints.reserve(n.saturating_sub(1));
        self.bounds.reserve(n.saturating_sub(1));
    }
}

/// Advances one chain by one substep.
pub fn substep(
    state: &mut RodState,
    lengths: &[f32],
    input: &SubstepInput<'_>,
    scratch: &mut RodScratch,
) -> SubstepReport {
    let n = state.x.len();
    scratch.reserve(n);
    let h = input.h;
    let RodScratch { p, qp, p_old, constraints, bounds, normals, .. } = scratch;
    let settled = input.contact_settled;
    if let Some(contacts) = &input.contacts {
        let keep_lengths = |previous: &[DVec3], x: &mut [DVec3]| {
            inextensible::solve(previous, x, lengths, constraints);
        };
        if !input.starts_clear {
            pre_stabilise(&mut state.x, &mut p_old[..n], contacts, FINAL_CONTACT_ROUNDS, keep_lengths, settled, bounds);
        } else if cfg!(debug_assertions) {
            // The skip must change nothing: pre-stabilise a copy (in `p`, not yet written) and compare.
            p[..n].copy_from_slice(&state.x);
            pre_stabilise(&mut p[..n], &mut p_old[..n], contacts, FINAL_CONTACT_ROUNDS, keep_lengths, settled, bounds);
            debug_assert!(same_bits(&p[..n], &state.x), "a substep that starts clear had something to pre-stabilise");
        }
    }
    // The start positions give the inextensibility solve its correction directions; only the contact pass
    // moves them (joints already inside a collider), and every solve after it is prepared again.
    inextensible::prepare(&state.x, lengths, constraints);
    let (p, qp) = (&mut p[..n], &mut qp[..n]);

    // Kinematic root.
    p[0] = input.anchor.place_f64(input.rest.positions[0]);
    qp[0] = (input.anchor.rotation * input.rest.orientations[0]).normalize();

    // Predict the dynamic particles. Damping acts on velocity relative to the root, so a character moving
    // at constant velocity (a train, an elevator) swings exactly like one standing still.
    let kick = if input.half_kick { 0.5 * h } else { h };
    let root_velocity = ((p[0] - state.x[0]) / h as f64).as_vec3();
    for i in 1..n {
        let relative = state.v[i] - root_velocity;
        state.v[i] = root_velocity + relative * input.constants.velocity_decay + input.constants.gravity * kick;
        state.w[i] *= input.constants.velocity_decay;
        p[i] = state.x[i] + (state.v[i] * h).as_dvec3();
        qp[i] = (exp_small(state.w[i] * h) * state.q[i]).normalize();
    }

    let alpha = input.constants.alpha_per_iteration;
    let iterations = if alpha > 0.0 { input.iterations.max(1) } else { 1 };
    state.solve_memory.begin_substep(h, iterations);
    let mut budget = TensionBudget::new(input.constants.zigzag_gain);
    let mut report = SubstepReport::default();
    for iteration in 0..iterations {
        if alpha > 0.0 {
            match_shape(
                &mut state.group_rotation,
                p,
                qp,
                input.rest,
                input.rest_groups,
                &input.constants,
                landing_angle(iteration, iterations),
            );
        }
        let solved = if iteration == 0 {
            inextensible::solve_first(p, lengths, constraints, &mut state.solve_memory, &mut budget)
        } else {
            inextensible::solve_again(p, lengths, constraints, &mut state.solve_memory, iteration as usize, &mut budget)
        };
        report.fallback |= !solved;
        if let Some(contacts) = &input.contacts {
            let normals = &mut normals[..n];
            normals.fill(Vec3::ZERO);
            let mut pass = collide(&mut state.x, p, contacts, bounds, normals);
            let mut sliding = pass.sliding;
            inextensible::prepare(&state.x, lengths, constraints);
            report.contact_pairs += pass.tested;
            // A collider pushing hard (a swinging arm) moves a few particles far in one substep; the rest of
            // the chain follows through more rounds of lengths then contacts. The substep ends on contacts.
            if iteration + 1 == iterations {
                let mut sliding_memory = SlidingMemory::default();
                for _ in 1..FINAL_CONTACT_ROUNDS {
                    if !pass.touching || pass.deepest <= settled {
                        break;
                    }
                    // Joints the contacts gave a normal slide on their colliders here, so the lengths do not
                    // undo those contacts round after round (bug 9 in docs/robustness.md).
                    let direct = if sliding {
                        inextensible::solve_sliding(p, lengths, normals, constraints, &mut sliding_memory)
                    } else {
                        inextensible::solve_prepared(p, lengths, constraints)
                    };
                    report.fallback |= !direct;
                    pass = collide(&mut state.x, p, contacts, bounds, normals);
                    sliding |= pass.sliding;
                    inextensible::prepare(&state.x, lengths, constraints);
                    report.contact_pairs += pass.tested;
                }
            }
            report.ended_clear = !pass.touching;
        }
    }

    // Velocities from positions.
    let inv_h = 1.0 / h;
    for i in 1..n {
        state.v[i] = (p[i] - state.x[i]).as_vec3() * inv_h;
        state.w[i] = log_small(align_hemisphere(qp[i] * state.q[i].inverse(), Quat::IDENTITY)) * inv_h;
        state.x[i] = p[i];
        state.q[i] = qp[i];
    }
    state.x[0] = p[0];
    state.q[0] = qp[0];
    report
}

/// Momentum suppression (SPEC 3.6): the rest shape changed from `old` to `new` since the last substep.
/// Instead of letting the shape-matching goals jump (which the position-based update would turn into
/// velocity), the share of the change that the chain's stiffness realises in one substep is applied to
/// the positions directly: every segment keeps its current rotation relative to its rest segment, so the
/// chain's own deformation (and its velocity) is carried over to the new rest shape with exact lengths.
/// At stiffness 1 the chain lands on the new rest shape; a soft chain still lags behind it naturally.
pub fn carry_to_new_rest(
    state: &mut RodState,
    anchor: &Transform,
    old: &Shape,
    new: &Shape,
    share: f32,
    scratch: &mut RodScratch,
) {
    let n = state.x.len();
    scratch.reserve(n);
    let RodScratch { p_old: target, arcs, .. } = scratch;
    // Every array cut to `n` up front, so that the compiler drops the bounds checks of the loops below.
    let (old_positions, new_positions) = (&old.positions[..n], &new.positions[..n]);
    let (old_orientations, new_orientations) = (&old.orientations[..n], &new.orientations[..n]);
    let (x, q, target) = (&mut state.x[..n], &mut state.q[..n], &mut target[..n]);
    // Each segment's deformation: the shortest arc from its old rest direction to its current one, all
    // segments' arcs at once (`ArcColumns`). A segment of no length has no direction to carry: its arc is the
    // identity, and it keeps its new rest direction.
    arcs.set_all(n - 1, |k| {
        let old_segment = anchor.rotation * (old_positions[k + 1] - old_positions[k]);
        (old_segment, (x[k + 1] - x[k]).as_vec3())
    });
    arcs.compute(n - 1);
    target[0] = x[0];
    for (k, arc) in arcs.arcs(n - 1).enumerate() {
        let new_segment = anchor.rotation * (new_positions[k + 1] - new_positions[k]);
        target[k + 1] = target[k] + (arc * new_segment).as_dvec3();
    }
    let share_f64 = share as f64;
    for j in 1..n {
        x[j] = x[j] + (target[j] - x[j]) * share_f64;
    }
    if n > 1 {
        carry_orientations(&mut q[1..], &old_orientations[1..], &new_orientations[1..], share);
    }
}

/// What the shape-matching groups need of a rest shape, derived once per rest shape (it changes at most once
/// per step, while the groups are matched in every solver iteration of every substep).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RestGroups {
    /// Indexed by a group's middle particle `i` (entry 0 unused): the rest offsets of its members `i-1, i, i+1`
    /// from its rest centre. The root's group is centred on the root (see [`match_shape`]); the last group
    /// has no third member (zero offset).
    pub(crate) offsets: Vec<[Vec3A; 3]>,
}

impl RestGroups {
    /// Recomputes everything from `rest` (reusing the allocation).
    pub fn rebuild(&mut self, rest: &Shape) {
        let xbar = &rest.positions;
        let n = xbar.len();
        self.offsets.clear();
        self.offsets.push([Vec3A::ZERO; 3]);
        if n < 2 {
            return;
        }
        let root_offset = |j: usize| if j < n { Vec3A::from(xbar[j] - xbar[0]) } else { Vec3A::ZERO };
        self.offsets.push([Vec3A::ZERO, root_offset(1), root_offset(2)]);
        for i in 2..n {
            let lo = i - 1;
            let offsets = if i + 1 < n {
                let c_rest = (Vec3::ZERO + xbar[lo] + xbar[i] + xbar[i + 1]) / 3.0;
                [xbar[lo] - c_rest, xbar[i] - c_rest, xbar[i + 1] - c_rest]
            } else {
                let c_rest = (Vec3::ZERO + xbar[lo] + xbar[i]) / 2.0;
                [xbar[lo] - c_rest, xbar[i] - c_rest, Vec3::ZERO]
            };
            self.offsets.push(offsets.map(Vec3A::from));
        }
    }

    fn len(&self) -> usize {
        self.offsets.len()
    }
}

/// One Gauss-Seidel pass over the shape-matching groups `{i-1, i, i+1}`, root to tip.
///
/// The group holding the kinematic root is clamped to it: its frame is the root's orientation and its
/// centre the root itself (infinite mass). Otherwise a rigid turn of the whole chain about its root would
/// be a zero mode that only the particles' small orientation terms resist, and a chain could not hold a
/// shape against gravity.
fn match_shape(
    group_rotation: &mut [Quat],
    p: &mut [DVec3],
    qp: &mut [Quat],
    rest: &Shape,
    groups: &RestGroups,
    constants: &ChainConstants,
    landing: f32,
) {
    let (orientation_weight, alpha) = (constants.orientation_weight, constants.alpha_per_iteration);
    let n = p.len();
    if n < 2 {
        return;
    }
    debug_assert_eq!(groups.len(), n, "rest groups derived from another rest shape");
    let (qbar, offsets, group_rotation) = (&rest.orientations[..n], &groups.offsets[..n], &mut group_rotation[..n]);
    let alpha_f64 = alpha as f64;

    // The root's group {0, 1, 2}.
    let rotation = (qp[0] * qbar[0].inverse()).normalize();
    group_rotation[1] = rotation;
    let centre = p[0];
    for j in 1..n.min(3) {
        pull_to_goal(&mut p[j], centre, rotation * offsets[1][j], alpha_f64);
    }
    qp[1] = nlerp_shorter(qp[1], rotation * qbar[1], alpha);

    // A member's orientation term does not change between the group where it is the last member and the
    // next one, where it is the middle member (a group only turns its middle particle): computed once.
    let mut carried: Option<Mat3A> = None;
    for i in 2..n {
        let lo = i - 1;
        let full = i + 1 < n;
        let [r_lo, r_mid, r_hi] = offsets[i];
        let orientation_term = |j: usize| Mat3A::from_quat(qp[j] * qbar[j].inverse()) * orientation_weight;
        let m_lo = orientation_term(lo);
        let m_mid = carried.take().unwrap_or_else(|| orientation_term(i));
        // Uniform masses cancel out of the group matrix. Its position terms `sum (p_k - c) r_k^T` are taken
        // relative to the middle particle instead of the centre `c`: the rest offsets `r_k` sum to zero, so
        // that changes only rounding, the middle particle's term vanishes, and the matrix does not wait for the
        // centre's division (`docs/performance-history.md`, stop 31).
        let (c, a) = if full {
            let hi = i + 1;
            let m_hi = orientation_term(hi);
            carried = Some(m_hi);
            let c = (DVec3::ZERO + p[lo] + p[i] + p[hi]) * THIRD;
            let a =
                m_lo + outer((p[lo] - p[i]).as_vec3a(), r_lo) + m_mid + m_hi + outer((p[hi] - p[i]).as_vec3a(), r_hi);
            (c, a)
        } else {
            let c = (DVec3::ZERO + p[lo] + p[i]) / 2.0;
            let a = m_lo + outer((p[lo] - p[i]).as_vec3a(), r_lo) + m_mid;
            (c, a)
        };
        let mut rotation = group_rotation[i];
        let frame = extract_rotation(&a, &mut rotation, POLAR_ITERATIONS, landing);
        group_rotation[i] = rotation;
        pull_to_goal(&mut p[lo], c, frame * r_lo, alpha_f64);
        pull_to_goal(&mut p[i], c, frame * r_mid, alpha_f64);
        if full {
            pull_to_goal(&mut p[i + 1], c, frame * r_hi, alpha_f64);
        }
        qp[i] = nlerp_shorter(qp[i], rotation * qbar[i], alpha);
    }
}

/// `p` moved the fraction `alpha` of the way to its shape-matching goal `centre + offset`.
#[inline(always)]
fn pull_to_goal(p: &mut DVec3, centre: DVec3, offset: Vec3A, alpha: f64) {
    let goal = centre + offset.as_dvec3();
    *p += (goal - *p) * alpha;
}

/// `u v^T`.
#[inline(always)]
fn outer(u: Vec3A, v: Vec3A) -> Mat3A {
    Mat3A::from_cols(u * v.x, u * v.y, u * v.z)
}

/// The positions are equal to the bit (debug checks).
pub(crate) fn same_bits(a: &[DVec3], b: &[DVec3]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(a, b)| a.to_array().map(f64::to_bits) == b.to_array().map(f64::to_bits))
}
