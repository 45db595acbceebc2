//! The orientation halves of a substep's prediction and velocity update (`rod::substep`): `qp = exp(w h) q`
//! and `w = log(qp q^-1) / h`, on every lane. Written as loops over lanes in functions that take each buffer
//! as a separate slice, for the reasons given in [`polar`](super::polar) and [`lengths`](super::lengths);
//! the same operations as the array-operation version, so the same bits.

use glam::{Quat, Vec3};

use super::scalar::{Quaternion, exp_series, log_series, mul, normalize, scale};
use super::simd::{Q, V3};

/// [`predict_orientations`]' signature.
pub type Predict<const L: usize> = fn(&[V3<L>], &[Q<L>], &mut [Q<L>], f32);
/// [`angular_velocities`]' signature.
pub type Spin<const L: usize> = fn(&[Q<L>], &[Q<L>], &mut [V3<L>], f32);

/// `qp[i] = normalize(exp(w[i] h) q[i])` for every particle of the slices.
#[inline(always)]
pub fn predict_orientations<const L: usize>(w: &[V3<L>], q: &[Q<L>], qp: &mut [Q<L>], h: f32) {
    for ((w, q), qp) in w.iter().zip(q).zip(qp.iter_mut()) {
        let mut any_far = false;
        for lane in 0..L {
            let (turn, far) = exp_series(scale(w.get(lane), h));
            any_far |= far;
            qp.set(lane, normalize(mul(turn, q.get(lane))));
        }
        if any_far {
            exact_predictions(w, q, qp, h);
        }
    }
}

/// The lanes of one particle whose turn is too long for the series (more than a radian in a substep), with
/// the exact exponential (rare).
#[cold]
#[inline(never)]
fn exact_predictions<const L: usize>(w: &V3<L>, q: &Q<L>, qp: &mut Q<L>, h: f32) {
    for lane in 0..L {
        let e = scale(w.get(lane), h);
        if exp_series(e).1 {
            let turn = Quat::from_scaled_axis(Vec3::from_array(e)).to_array();
            qp.set(lane, normalize(mul(turn, q.get(lane))));
        }
    }
}

/// `w[i] = log(qp[i] q[i]^-1) / h` (the shorter way round) for every particle of the slices, with `inv_h`
/// `1 / h`.
#[inline(always)]
pub fn angular_velocities<const L: usize>(qp: &[Q<L>], q: &[Q<L>], w: &mut [V3<L>], inv_h: f32) {
    for ((qp, q), w) in qp.iter().zip(q).zip(w.iter_mut()) {
        let mut any_exact = false;
        for lane in 0..L {
            let (log, exact) = log_series(relative(qp.get(lane), q.get(lane)));
            any_exact |= exact;
            w.set(lane, scale(log, inv_h));
        }
        if any_exact {
            exact_velocities(qp, q, w, inv_h);
        }
    }
}

/// The lanes of one particle outside the logarithm's series, with the exact logarithm (rare).
#[cold]
#[inline(never)]
fn exact_velocities<const L: usize>(qp: &Q<L>, q: &Q<L>, w: &mut V3<L>, inv_h: f32) {
    for lane in 0..L {
        let turn = relative(qp.get(lane), q.get(lane));
        if log_series(turn).1 {
            w.set(lane, scale(Quat::from_array(turn).to_scaled_axis().to_array(), inv_h));
        }
    }
}

/// `(qp q^-1)` in the hemisphere of the identity (`Q::align_hemisphere`).
#[inline(always)]
fn relative(qp: Quaternion, q: Quaternion) -> Quaternion {
    let turn = mul(qp, [-q[0], -q[1], -q[2], q[3]]);
    // `Q::dot` with the identity, literally: the products by zero decide the sign of a zero `w`.
    let along_identity = turn[0] * 0.0 + turn[1] * 0.0 + turn[2] * 0.0 + turn[3] * 1.0;
    if along_identity < 0.0 { [-turn[0], -turn[1], -turn[2], -turn[3]] } else { turn }
}
