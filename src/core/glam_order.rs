//! glam's quaternion arithmetic on plain arrays, operation for operation and with its sums grouped as glam
//! groups them, so that a loop over several joints, which the compiler can run side by side in vector
//! registers, computes the bits that glam computes one joint at a time ([`bones`](super::bones),
//! [`rest_carry`](super::rest_carry)). glam has two codes for these: its SSE2 code, which this crate builds on
//! x86-64 (no `target-cpu=native`, so no FMA), and its plain scalar code (`scalar-math`), which it builds
//! elsewhere and with `portable-determinism` (see `Cargo.toml`). They sum a product's and a dot product's terms
//! in other orders and normalise by a division or by a reciprocal, so each has its mirror, chosen as glam is:
//! the SSE2 code's here, the scalar code's in the lane kernel's own mirrors (`lanes::scalar`), which are it.

use super::lanes::scalar::Quaternion;

/// Whether glam runs its SSE2 code (else its scalar code): as `Cargo.toml` builds it.
macro_rules! glam_sse2 {
    ($($item:item)*) => { $( #[cfg(all(target_arch = "x86_64", not(feature = "portable-determinism")))] $item )* };
}

glam_sse2! {
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
}

// Else glam's scalar code, which the lane kernel's mirrors are.
#[cfg(not(all(target_arch = "x86_64", not(feature = "portable-determinism"))))]
pub use super::lanes::scalar::{dot4 as dot, mul, normalize};

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
