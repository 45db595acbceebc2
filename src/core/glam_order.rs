//! glam's quaternion arithmetic on plain arrays, operation for operation and with its sums grouped as glam
//! groups them, so that a loop over several joints, which the compiler can run side by side in vector
//! registers, computes the bits that glam computes one joint at a time ([`bones`](super::bones),
//! [`rest_carry`](super::rest_carry)). The lane kernel's own mirrors (`lanes::scalar`) group some sums
//! differently. glam has two codes for these: its SSE2 code, which this crate builds on x86-64 (no
//! `target-cpu=native`, so no FMA), and its plain scalar code (`scalar-math`), which it builds elsewhere and
//! with `portable-determinism` (see `Cargo.toml`). They sum a product's and a dot product's terms in other
//! orders and normalise by a division or by a reciprocal, so each has its mirror here, chosen as glam is.

use super::lanes::scalar::Quaternion;

/// Whether glam runs its SSE2 code (else its scalar code): as `Cargo.toml` builds it.
macro_rules! glam_sse2 {
    ($($item:item)*) => { $( #[cfg(all(target_arch = "x86_64", not(feature = "portable-determinism")))] $item )* };
}

macro_rules! glam_scalar {
    ($($item:item)*) => { $( #[cfg(not(all(target_arch = "x86_64", not(feature = "portable-determinism"))))] $item )* };
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

glam_scalar! {
    /// `Quat * Quat`: each component's four products summed left to right.
    #[inline(always)]
    pub fn mul([x0, y0, z0, w0]: Quaternion, [x1, y1, z1, w1]: Quaternion) -> Quaternion {
        [
            w0 * x1 + x0 * w1 + y0 * z1 - z0 * y1,
            w0 * y1 - x0 * z1 + y0 * w1 + z0 * x1,
            w0 * z1 + x0 * y1 - y0 * x1 + z0 * w1,
            w0 * w1 - x0 * x1 - y0 * y1 - z0 * z1,
        ]
    }

    /// `Quat::dot`: `x x' + y y' + z z' + w w'`, left to right.
    #[inline(always)]
    pub fn dot(a: Quaternion, b: Quaternion) -> f32 {
        a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]
    }

    /// `Quat::normalize`: a product by the reciprocal of the length from [`dot`].
    #[inline(always)]
    pub fn normalize(q: Quaternion) -> Quaternion {
        let inverse = 1.0 / dot(q, q).sqrt();
        [q[0] * inverse, q[1] * inverse, q[2] * inverse, q[3] * inverse]
    }
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
