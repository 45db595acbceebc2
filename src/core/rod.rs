//! One chain as an elastic rod of oriented particles (Müller & Chentanez 2011, rods case) kept
//! inextensible by [`inextensible`](super::inextensible). This module advances one chain by one internal
//! substep; the engine decides when and with which kinematic input.

use glam::{Mat3, Quat, Vec3};

use super::inextensible::{self, ConstraintScratch};
use super::math::{Transform, align_hemisphere, nlerp_shorter};
use super::polar::extract_rotation;
use super::shape::Shape;

/// Warm-started rotation extraction gains about 3x per iteration and starts from last substep's answer,
/// so a few iterations reach float precision; it stops early once converged.
const POLAR_ITERATIONS: u32 = 8;

/// The dynamic state of a chain's particles, relative to the engine's origin. Particle 0 is kinematic.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RodState {
    pub x: Vec<Vec3>,
    pub v: Vec<Vec3>,
    pub q: Vec<Quat>,
    pub w: Vec<Vec3>,
    /// Each shape-matching group's last rotation: the warm start of the next extraction.
    pub group_rotation: Vec<Quat>,
}

impl RodState {
    /// Particles at the rest shape under `anchor`, at rest.
    pub fn at_rest(rest: &Shape, anchor: &Transform) -> Self {
        let n = rest.len();
        let mut s = Self {
            x: vec![Vec3::ZERO; n],
            v: vec![Vec3::ZERO; n],
            q: vec![Quat::IDENTITY; n],
            w: vec![Vec3::ZERO; n],
            group_rotation: vec![anchor.rotation; n],
        };
        s.place_at_rest(rest, anchor);
        s
    }

    pub fn place_at_rest(&mut self, rest: &Shape, anchor: &Transform) {
        for j in 0..rest.len() {
            self.x[j] = anchor.transform_point(rest.positions[j]);
            self.q[j] = (anchor.rotation * rest.orientations[j]).normalize();
        }
        self.v.fill(Vec3::ZERO);
        self.w.fill(Vec3::ZERO);
        self.group_rotation.fill(anchor.rotation);
    }

    /// Moves the whole chain rigidly by `delta` (a teleport carried with the anchor); velocities turn
    /// with it, so no kinetic energy is added.
    pub fn carry(&mut self, delta: &Transform) {
        for x in &mut self.x {
            *x = delta.transform_point(*x);
        }
        for v in self.v.iter_mut().chain(self.w.iter_mut()) {
            *v = delta.rotation * *v;
        }
        for q in self.q.iter_mut().chain(self.group_rotation.iter_mut()) {
            *q = (delta.rotation * *q).normalize();
        }
    }

    pub fn translate(&mut self, offset: Vec3) {
        for x in &mut self.x {
            *x += offset;
        }
    }

    pub fn is_finite(&self) -> bool {
        self.x
            .iter()
            .chain(&self.v)
            .chain(&self.w)
            .all(|v| v.is_finite())
            && self.q.iter().all(|q| q.is_finite())
    }
}

/// Everything a substep needs besides the state.
pub struct SubstepInput<'a> {
    pub h: f32,
    /// The anchor at the end of this substep, relative to the engine origin.
    pub anchor: Transform,
    pub gravity: Vec3,
    /// `exp(-damping * h)`.
    pub velocity_decay: f32,
    /// Fraction of the way to the shape-matching goals per iteration.
    pub alpha_per_iteration: f32,
    pub iterations: u32,
    pub inv_mass: f32,
    /// `a^2 / 5`: weight of particle orientations in the group matrix.
    pub orientation_weight: f32,
    pub rest: &'a Shape,
    /// The rest shape of the previous substep when it differs from `rest` (momentum suppression).
    pub previous_rest: Option<&'a Shape>,
    pub momentum_suppression: f32,
    /// First substep after placement: a half gravity kick starts the leapfrog.
    pub half_kick: bool,
}

/// Per-particle buffers reused across chains and substeps.
#[derive(Default)]
pub struct RodScratch {
    p: Vec<Vec3>,
    qp: Vec<Quat>,
    /// Displacement caused by the rest shape's own change: moved, but not turned into velocity.
    suppressed: Vec<Vec3>,
    suppressed_turn: Vec<Vec3>,
    constraints: ConstraintScratch,
}

impl RodScratch {
    fn reserve(&mut self, n: usize) {
        if self.p.len() < n {
            self.p.resize(n, Vec3::ZERO);
            self.qp.resize(n, Quat::IDENTITY);
            self.suppressed.resize(n, Vec3::ZERO);
            self.suppressed_turn.resize(n, Vec3::ZERO);
        }
        self.constraints.reserve(n.saturating_sub(1));
    }
}

/// Advances one chain by one substep. Returns `false` if the inextensibility solve had to fall back.
pub fn substep(
    state: &mut RodState,
    lengths: &[f32],
    input: &SubstepInput<'_>,
    scratch: &mut RodScratch,
) -> bool {
    let n = state.x.len();
    scratch.reserve(n);
    let h = input.h;
    let RodScratch {
        p,
        qp,
        suppressed,
        suppressed_turn,
        constraints,
    } = scratch;
    let (p, qp) = (&mut p[..n], &mut qp[..n]);

    // Kinematic root.
    p[0] = input.anchor.transform_point(input.rest.positions[0]);
    qp[0] = (input.anchor.rotation * input.rest.orientations[0]).normalize();

    // Predict the dynamic particles.
    let kick = if input.half_kick { 0.5 * h } else { h };
    for i in 1..n {
        state.v[i] = state.v[i] * input.velocity_decay + input.gravity * kick;
        state.w[i] *= input.velocity_decay;
        p[i] = state.x[i] + state.v[i] * h;
        qp[i] = (Quat::from_scaled_axis(state.w[i] * h) * state.q[i]).normalize();
    }

    let suppress = input.previous_rest.is_some() && input.momentum_suppression > 0.0;
    if suppress {
        suppressed[..n].fill(Vec3::ZERO);
        suppressed_turn[..n].fill(Vec3::ZERO);
    }
    let alpha = input.alpha_per_iteration;
    let iterations = if alpha > 0.0 {
        input.iterations.max(1)
    } else {
        1
    };
    let mut direct = true;
    for iteration in 0..iterations {
        if alpha > 0.0 {
            // Share of this pass's rest-change displacement that survives the later passes, so that the
            // suppressed total equals what the rest change actually caused.
            let survive = (1.0 - alpha).powi((iterations - 1 - iteration) as i32);
            match_shape(
                state,
                p,
                qp,
                input,
                alpha,
                survive,
                suppress.then_some((&mut suppressed[..n], &mut suppressed_turn[..n])),
            );
        }
        direct &= inextensible::solve(&state.x, p, lengths, input.inv_mass, constraints);
    }

    // Velocities from positions, minus what the rest change moved.
    let inv_h = 1.0 / h;
    for i in 1..n {
        let mut displacement = p[i] - state.x[i];
        let mut turn =
            align_hemisphere(qp[i] * state.q[i].inverse(), Quat::IDENTITY).to_scaled_axis();
        if suppress {
            displacement -= suppressed[i] * input.momentum_suppression;
            turn -= suppressed_turn[i] * input.momentum_suppression;
        }
        state.v[i] = displacement * inv_h;
        state.w[i] = turn * inv_h;
        state.x[i] = p[i];
        state.q[i] = qp[i];
    }
    state.x[0] = p[0];
    state.q[0] = qp[0];
    direct
}

/// One Gauss-Seidel pass over the shape-matching groups `{i-1, i, i+1}`, root to tip.
fn match_shape(
    state: &mut RodState,
    p: &mut [Vec3],
    qp: &mut [Quat],
    input: &SubstepInput<'_>,
    alpha: f32,
    survive: f32,
    mut suppression: Option<(&mut [Vec3], &mut [Vec3])>,
) {
    let n = p.len();
    let rest = input.rest;
    for i in 1..n {
        let lo = i - 1;
        let hi = (i + 1).min(n - 1);
        let count = (hi - lo + 1) as f32;
        let c = p[lo..=hi].iter().sum::<Vec3>() / count;
        let c_rest = rest.positions[lo..=hi].iter().sum::<Vec3>() / count;
        // Uniform masses cancel out of the group matrix.
        let mut a = Mat3::ZERO;
        for j in lo..=hi {
            a += Mat3::from_quat(qp[j] * rest.orientations[j].inverse()) * input.orientation_weight;
            let (pj, rj) = (p[j] - c, rest.positions[j] - c_rest);
            a += Mat3::from_cols(pj * rj.x, pj * rj.y, pj * rj.z);
        }
        let mut rotation = state.group_rotation[i];
        extract_rotation(&a, &mut rotation, POLAR_ITERATIONS);
        state.group_rotation[i] = rotation;

        let previous_centre = input
            .previous_rest
            .map(|old| old.positions[lo..=hi].iter().sum::<Vec3>() / count);
        for j in lo.max(1)..=hi {
            let goal = rotation * (rest.positions[j] - c_rest) + c;
            p[j] += (goal - p[j]) * alpha;
            if let (Some((moved, _)), Some(old), Some(old_centre)) =
                (suppression.as_mut(), input.previous_rest, previous_centre)
            {
                let old_goal = rotation * (old.positions[j] - old_centre) + c;
                moved[j] += (goal - old_goal) * (alpha * survive);
            }
        }
        let target = rotation * rest.orientations[i];
        if let (Some((_, turned)), Some(old)) = (suppression.as_mut(), input.previous_rest) {
            let old_target = rotation * old.orientations[i];
            let change =
                align_hemisphere(target * old_target.inverse(), Quat::IDENTITY).to_scaled_axis();
            turned[i] += change * (alpha * survive);
        }
        qp[i] = nlerp_shorter(qp[i], target, alpha);
    }
}
