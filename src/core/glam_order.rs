//! glam's quaternion arithmetic on plain arrays, operation for operation and with its sums grouped as glam's
//! SSE2 code groups them, so that a loop over several joints, which the compiler can run side by side in vector
//! registers, computes the bits that glam computes one joint at a time ([`bones`](super::bones),
//! [`rest_carry`](super::rest_carry)). The lane kernel's own mirrors (`lanes::scalar`) group some sums
//! differently. This is glam's SSE2 code as this crate builds it for x86-64 (no `target-cpu=native`, so no FMA).
//! Off x86-64, or with `portable-determinism`, the crate builds glam's plain scalar code (`scalar-math`, see
//! `Cargo.toml`), which sums a quaternion product's terms in another order: there the blocked loops and glam's
//! code one joint at a time differ in the last bits, and their tests check agreement to rounding
//! ([`assert_as_glam`]).

use super::lanes::scalar::Quaternion;

/// `Quat * Quat` (rtm's `quat_mul`).
#[inline(always)]
pub fn mul([ax, ay, az, aw]: Quaternion, [bx, by, bz, bw]: Quaternion) -> Quaternion {
    [
        (aw * bx + ax * bw) + (ay * bz - az * by),
        (aw * by - ax * bz) + (ay * bw + az * bx),
        (aw * bz + ax * by) + (az * bw - ay * bx),
        (aw * bw - ax * bx) - (ay * by + az * bz),
    ]
}

/// `Quat::dot`: `(x x' + z z') + (y y' + w w')`.
#[inline(always)]
pub fn dot(a: Quaternion, b: Quaternion) -> f32 {
    (a[0] * b[0] + a[2] * b[2]) + (a[1] * b[1] + a[3] * b[3])
}

/// `Quat::normalize`: the length from [`dot`] of itself, and a division by it.
#[inline(always)]
pub fn normalize(q: Quaternion) -> Quaternion {
    let length = dot(q, q).sqrt();
    [q[0] / length, q[1] / length, q[2] / length, q[3] / length]
}

/// `Quat::conjugate` (and `Quat::inverse`, which is it).
#[inline(always)]
pub fn conjugate([x, y, z, w]: Quaternion) -> Quaternion {
    [-x, -y, -z, w]
}

/// `a * s + b * t`, as `Quat * f32` and `Quat + Quat`.
#[inline(always)]
pub fn mix(a: Quaternion, s: f32, b: Quaternion, t: f32) -> Quaternion {
    [a[0] * s + b[0] * t, a[1] * s + b[1] * t, a[2] * s + b[2] * t, a[3] * s + b[3] * t]
}

/// What the tests of the blocked loops built on these mirrors check: on x86-64 (without `portable-determinism`),
/// the bits of glam's own code one joint at a time. Elsewhere glam's code is not the SSE2 code mirrored here (see the module's documentation),
/// so the two agree to float rounding only: every component of the unit quaternions within [`ROUNDING`] of
/// glam's.
#[cfg(test)]
pub fn assert_as_glam(blocked: &[glam::Quat], glam: &[glam::Quat]) {
    let bits = |q: &[glam::Quat]| q.iter().flat_map(|q| q.to_array().map(f32::to_bits)).collect::<Vec<_>>();
    if cfg!(all(target_arch = "x86_64", not(feature = "portable-determinism"))) {
        assert_eq!(bits(blocked), bits(glam));
        return;
    }
    assert_eq!(blocked.len(), glam.len());
    for (j, (a, b)) in blocked.iter().zip(glam).enumerate() {
        let apart = (*a - *b).to_array().into_iter().fold(0.0f32, |far, d| far.max(d.abs()));
        assert!(apart <= ROUNDING, "joint {j}: {a} against glam's {b}, {apart:e} apart");
    }
}

/// The largest difference [`assert_as_glam`] allows off x86-64 in a unit quaternion's components: a few
/// roundings of numbers up to 1 (one product and one normalisation, each off by a rounding or two).
#[cfg(test)]
const ROUNDING: f32 = 4.0 * f32::EPSILON;
