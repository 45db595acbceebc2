//! One lane's arithmetic, for the kernel parts written as loops over lanes ([`polar`](super::polar),
//! [`rotations`](super::rotations), [`output`](super::output)): the lane types' operations (`simd`) on plain arrays, operation for
//! operation and in the same order, so a lane loop computes the bits the array operations would.

/// A 3-vector.
pub type Vec = [f32; 3];
/// A quaternion, `x, y, z, w`.
pub type Quaternion = [f32; 4];
/// A 3x3 matrix by columns.
pub type Mat = [Vec; 3];

#[inline(always)]
pub fn length_squared(v: Vec) -> f32 {
    v[0] * v[0] + v[1] * v[1] + v[2] * v[2]
}

/// `V3::dot`.
#[inline(always)]
pub fn dot(a: Vec, b: Vec) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `V3::cross`: `a x b`.
#[inline(always)]
pub fn cross(a: Vec, b: Vec) -> Vec {
    [a[1] * b[2] - b[1] * a[2], a[2] * b[0] - b[2] * a[0], a[0] * b[1] - b[0] * a[1]]
}

#[inline(always)]
pub fn sub(a: Vec, b: Vec) -> Vec {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// `math::direction` (the lanes' `output` mirror of it): the unit vector and whether there is one.
#[inline(always)]
pub fn direction(v: Vec) -> (Vec, bool) {
    let length = length_squared(v).sqrt();
    let found = (length > f32::MIN_POSITIVE.sqrt()) & length.is_finite();
    ([v[0] / length, v[1] / length, v[2] / length], found)
}

/// `Q::rotate`: `q` rotating `v`.
#[inline(always)]
pub fn rotate([bx, by, bz, w]: Quaternion, v: Vec) -> Vec {
    let b = [bx, by, bz];
    let (s1, along, s3) = (w * w - length_squared(b), dot(v, b) * 2.0, w * 2.0);
    let cross = cross(b, v);
    [
        v[0] * s1 + bx * along + cross[0] * s3,
        v[1] * s1 + by * along + cross[1] * s3,
        v[2] * s1 + bz * along + cross[2] * s3,
    ]
}

#[inline(always)]
pub fn scale(v: Vec, s: f32) -> Vec {
    [v[0] * s, v[1] * s, v[2] * s]
}

#[inline(always)]
pub fn dot4(a: Quaternion, b: Quaternion) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]
}

/// `Q::mul`: the Hamilton product `a * b`.
#[inline(always)]
pub fn mul([ax, ay, az, aw]: Quaternion, [bx, by, bz, bw]: Quaternion) -> Quaternion {
    [
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
        aw * bw - ax * bx - ay * by - az * bz,
    ]
}

/// `Q::normalize`.
#[inline(always)]
pub fn normalize(q: Quaternion) -> Quaternion {
    let inv = 1.0 / dot4(q, q).sqrt();
    [q[0] * inv, q[1] * inv, q[2] * inv, q[3] * inv]
}

/// `math::exp_small`'s series, and whether the turn is too long for it.
#[inline(always)]
pub fn exp_series(e: Vec) -> (Quaternion, bool) {
    let x2 = length_squared(e) * 0.25;
    let cos = x2 * (x2 * (x2 * (x2 * (1.0 / 40320.0) + -1.0 / 720.0) + 1.0 / 24.0) + -1.0 / 2.0) + 1.0;
    let sinc = x2 * (x2 * (x2 * (x2 * (1.0 / 362880.0) + -1.0 / 5040.0) + 1.0 / 120.0) + -1.0 / 6.0) + 1.0;
    let half = sinc * 0.5;
    ([e[0] * half, e[1] * half, e[2] * half, cos], x2 > 0.25)
}

/// `math::log_small`'s series, zero where it does not apply, and whether the exact
/// logarithm is needed (outside the series' range and not below glam's threshold, where it returns zero).
#[inline(always)]
pub fn log_series(q: Quaternion) -> (Vec, bool) {
    let v = [q[0], q[1], q[2]];
    let s2 = length_squared(v);
    let inv_w = 1.0 / q[3];
    let t2 = s2 * inv_w * inv_w;
    let atan_t_over_t = t2 * (t2 * (t2 * (t2 * (1.0 / 9.0) + -1.0 / 7.0) + 1.0 / 5.0) + -1.0 / 3.0) + 1.0;
    let series = scale(v, inv_w * 2.0 * atan_t_over_t);
    let in_range = (q[3] > 0.0) & (s2 <= q[3] * q[3] * 0.04) & (s2 >= 1e-16);
    let tiny = s2 < 1e-16;
    (if in_range { series } else { [0.0; 3] }, !(in_range | tiny))
}

/// `M3::from_quat`.
#[inline(always)]
pub fn from_quat([x, y, z, w]: Quaternion) -> Mat {
    let (x2, y2, z2) = (x + x, y + y, z + z);
    let (xx, xy, xz) = (x * x2, x * y2, x * z2);
    let (yy, yz, zz) = (y * y2, y * z2, z * z2);
    let (wx, wy, wz) = (w * x2, w * y2, w * z2);
    [[1.0 - (yy + zz), xy + wz, xz - wy], [xy - wz, 1.0 - (xx + zz), yz + wx], [xz + wy, yz - wx, 1.0 - (xx + yy)]]
}
