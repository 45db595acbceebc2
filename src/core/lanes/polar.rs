//! `polar::extract_rotation` on every lane of a group, its arithmetic written as a loop over the lanes whose
//! body is one lane's scalar code. The compiler vectorises that loop to the full width; the same iteration
//! written with 8-lane array operations (`simd`) inside one function for the whole substep was split into
//! 4-lane halves and scalar pieces. `tools/instruction_mix.py` on `step_cost 64 16 20 sway`: the kernel as one
//! function (commit 77a1d8a) ran 62 % 128-bit, 11 % scalar and 17 % 256-bit instructions; this function runs
//! 84 % 256-bit. The loop body must stay free of branches and conditional
//! stores (either makes the compiler give up and run it lane by lane): the per-lane choices are `&` and
//! selects, and the masked update of `q` is an array operation after the loop.
//!
//! The arithmetic is the lane kernel's, operation for operation and in the same order, so the results are
//! the bits the array-operation version gave: the determinism policy of `simd` holds unchanged.

use glam::{Quat, Vec3};

use super::scalar::{Mat, Vec, from_quat, length_squared, mul};
use super::simd::{M3, Mask, Q, V3};
use crate::core::polar::{CONVERGED_ANGLE, LONG_TURN, MAX_NEWTON_ANGLE, MIN_PIVOT};
use crate::core::rod::POLAR_ITERATIONS;

/// Improves every lane's `q` towards the rotation part of its `a`; a lane stops changing once it has
/// converged or its Newton step has landed (shorter than `landing`: `polar::landing_angle`). Returns the
/// rotation matrices of the final `q`.
#[inline(always)]
pub fn extract_rotation<const L: usize>(a: &M3<L>, q: &mut Q<L>, landing: f32) -> M3<L> {
    let norm = (a.x_axis.length_squared() + a.y_axis.length_squared() + a.z_axis.length_squared()).sqrt();
    let guard = norm * 1e-9 + f32::MIN_POSITIVE;
    let mut active = [true; L];
    let mut turning = [false; L];
    let mut steps = V3::ZERO;
    let mut next = *q;
    for _ in 0..POLAR_ITERATIONS {
        let mut any_active = false;
        let mut any_far = false;
        for lane in 0..L {
            let quat = q.get(lane);
            let r = from_quat(quat);
            let (ax, ay, az) = (a.x_axis.get(lane), a.y_axis.get(lane), a.z_axis.get(lane));
            // Columns of `S = R^T A`.
            let s = [transpose_mul(&r, ax), transpose_mul(&r, ay), transpose_mul(&r, az)];
            let g = [s[1][2] - s[2][1], s[2][0] - s[0][2], s[0][1] - s[1][0]];
            let trace = s[0][0] + s[1][1] + s[2][2];
            let inv = 1.0 / (trace.abs() + guard.0[lane]);
            let muller = [g[0] * inv, g[1] * inv, g[2] * inv];
            let converged = length_squared(muller) < CONVERGED_ANGLE * CONVERGED_ANGLE;
            // `&` rather than `&&`: no branch in the loop body.
            let still = active[lane] & !converged;
            turning[lane] = still;
            let (step, lands) = newton_step(&s, g, trace, muller, landing);
            active[lane] = still & !lands;
            any_active |= active[lane];
            // `polar::turn`: the Cayley map, and the exponential for long steps (after the loop: rare).
            let turn = [step[0] * 0.5, step[1] * 0.5, step[2] * 0.5, 1.0];
            any_far |= still & (length_squared(step) > LONG_TURN * LONG_TURN);
            steps.set(lane, step);
            next.set(lane, mul(quat, turn));
        }
        if any_far {
            exact_turns(q, &steps, &turning, &mut next);
        }
        *q = Q::select(Mask(turning), next.normalize(), *q);
        if !any_active {
            break;
        }
    }
    M3::from_quat(*q)
}

/// The turned rotation of the active lanes whose step is longer than `polar::LONG_TURN`, with the exponential
/// (rare).
#[cold]
#[inline(never)]
fn exact_turns<const L: usize>(q: &Q<L>, steps: &V3<L>, active: &[bool; L], next: &mut Q<L>) {
    for lane in 0..L {
        let step = steps.get(lane);
        if active[lane] && length_squared(step) > LONG_TURN * LONG_TURN {
            let turn = Quat::from_scaled_axis(Vec3::from_array(step)).to_array();
            next.set(lane, mul(q.get(lane), turn));
        }
    }
}

/// `polar::newton_step`, or the Müller step `muller` where the Newton step is not trusted, and whether the step
/// lands (a Newton step shorter than `landing`). A mirror rather than a call: that one takes glam's SIMD `Mat3A`
/// and returns an `Option`, and either keeps the lane loop scalar.
#[inline(always)]
fn newton_step(s: &Mat, g: Vec, trace: f32, muller: Vec, landing: f32) -> (Vec, bool) {
    let (h00, h11, h22) = (trace - s[0][0], trace - s[1][1], trace - s[2][2]);
    let h01 = (s[1][0] + s[0][1]) * -0.5;
    let h02 = (s[2][0] + s[0][2]) * -0.5;
    let h12 = (s[2][1] + s[1][2]) * -0.5;
    let c00 = h11 * h22 - h12 * h12;
    let c01 = h02 * h12 - h01 * h22;
    let c02 = h01 * h12 - h02 * h11;
    let c11 = h00 * h22 - h02 * h02;
    let c12 = h01 * h02 - h00 * h12;
    let c22 = h00 * h11 - h01 * h01;
    let det = h00 * c00 + h01 * c01 + h02 * c02;
    let pivot = trace.abs() * MIN_PIVOT;
    let definite = (h00 > pivot) & (c22 > pivot * pivot) & (det > pivot * pivot * pivot);
    let inv_det = 1.0 / det;
    let step = [
        (c00 * g[0] + c01 * g[1] + c02 * g[2]) * inv_det,
        (c01 * g[0] + c11 * g[1] + c12 * g[2]) * inv_det,
        (c02 * g[0] + c12 * g[1] + c22 * g[2]) * inv_det,
    ];
    let step_squared = length_squared(step);
    let newton = definite & (step_squared <= MAX_NEWTON_ANGLE * MAX_NEWTON_ANGLE);
    let lands = newton & (step_squared < landing * landing);
    (if newton { step } else { muller }, lands)
}

/// `M3::transpose_mul`: `r^T v`.
#[inline(always)]
fn transpose_mul(r: &Mat, v: Vec) -> Vec {
    let dot = |c: Vec| c[0] * v[0] + c[1] * v[1] + c[2] * v[2];
    [dot(r[0]), dot(r[1]), dot(r[2])]
}
