//! The contact pass's screen (`outside::ScreenFn`) for groups of 8 lanes, in AVX2's 256-bit vectors: 8 singles or
//! 4 doubles to a register. It computes `collision::segment_contact`'s quick reject, closest point and
//! `contact_outside` tests with glam's operations in glam's order, so a segment it clears is one the scalar test
//! clears (`outside`'s test checks it on random segments). Written in the crate's generic lane types, the
//! same screen compiled to two-lane vectors (`docs/performance-history.md`, stop 43).

use std::arch::x86_64::*;

use super::outside::{Resolve, Screen, Turn};
use super::simd::{D, DV3, F, Mask, V3};
use crate::core::collision::ROOT_LEVER_MIN;

/// 8 doubles: lanes 0-3 and 4-7.
#[derive(Clone, Copy)]
struct D8(__m256d, __m256d);

/// Three coordinates of 8 lanes.
#[derive(Clone, Copy)]
struct V8 {
    x: __m256,
    y: __m256,
    z: __m256,
}

#[derive(Clone, Copy)]
struct DV8 {
    x: D8,
    y: D8,
    z: D8,
}

fn f8(v: &F<8>) -> __m256 {
    bytemuck::cast(v.0)
}

fn d8(v: &D<8>) -> D8 {
    let [low, high]: [[f64; 4]; 2] = bytemuck::cast(v.0);
    D8(bytemuck::cast(low), bytemuck::cast(high))
}

fn v8(v: &V3<8>) -> V8 {
    V8 { x: f8(&v.x), y: f8(&v.y), z: f8(&v.z) }
}

fn dv8(v: &DV3<8>) -> DV8 {
    DV8 { x: d8(&v.x), y: d8(&v.y), z: d8(&v.z) }
}

/// The screen of every segment against one collider, segment after segment, with `resolve` taking the lanes
/// each may touch (see `outside::ScreenFn`).
#[allow(clippy::too_many_arguments)]
#[target_feature(enable = "avx2")]
pub fn screen_all(
    screen: &Screen<8>,
    lanes: Mask<8>,
    start: &mut [DV3<8>],
    p: &mut [DV3<8>],
    radii: &[F<8>],
    bounds: &[(DV3<8>, D<8>)],
    drift: &mut D<8>,
    slop: F<8>,
    resolve: &mut Resolve<'_, 8>,
) {
    let mut constants = Constants::new(screen, *drift, slop);
    let lanes = lanes.0.iter().enumerate().fold(0, |bits, (lane, &set)| bits | (set as i32) << lane);
    for (k, bound) in bounds.iter().enumerate() {
        let touch = segment(&constants, k, lanes, start, p, radii, bound);
        if touch != 0 {
            resolve(k, touch as u32, start, p, drift);
            // A contact moved the lane's joints: its drift grew.
            constants.drift_3 = times_3(drift);
        }
    }
}

/// What every segment's screen against the collider shares, in registers.
struct Constants {
    centre: DV8,
    start_centre: DV8,
    to_end: Turn8,
    to_start: Turn8,
    /// The quick reject's terms: the collider's reach and travel, and three times each lane's drift.
    solid: __m256d,
    collider_travel: __m256d,
    drift_3: D8,
    radius: __m256,
    half_height: __m256,
    axis: (V8, V8),
    slop: __m256,
}

impl Constants {
    #[target_feature(enable = "avx2")]
    fn new(screen: &Screen<8>, drift: D<8>, slop: F<8>) -> Self {
        Self {
            centre: dv8(&screen.centre),
            start_centre: dv8(&screen.start_centre),
            to_end: Turn8::new(&screen.to_end),
            to_start: Turn8::new(&screen.to_start),
            solid: _mm256_set1_pd(screen.solid),
            collider_travel: _mm256_set1_pd(screen.collider_travel),
            drift_3: times_3(&drift),
            radius: f8(&screen.radius),
            half_height: f8(&screen.half_height),
            axis: (v8(&screen.axis.0), v8(&screen.axis.1)),
            slop: f8(&slop),
        }
    }
}

/// Three times each lane's drift, as the quick reject widens by it.
#[inline]
#[target_feature(enable = "avx2")]
fn times_3(drift: &D<8>) -> D8 {
    let (drift, three) = (d8(drift), _mm256_set1_pd(3.0));
    D8(_mm256_mul_pd(drift.0, three), _mm256_mul_pd(drift.1, three))
}

/// `outside::Turn` in registers.
struct Turn8 {
    b: V8,
    scale: __m256,
    twice_w: __m256,
}

impl Turn8 {
    #[target_feature(enable = "avx2")]
    fn new(turn: &Turn<8>) -> Self {
        Self { b: v8(&turn.b), scale: f8(&turn.scale), twice_w: f8(&turn.twice_w) }
    }

    /// glam's `Quat * Vec3` by `outside::Turn`'s quaternion.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn rotate(&self, v: V8) -> V8 {
        let b = self.b;
        let along = _mm256_mul_ps(dot(v, b), _mm256_set1_ps(2.0));
        let cross = V8 {
            x: _mm256_sub_ps(_mm256_mul_ps(b.y, v.z), _mm256_mul_ps(v.y, b.z)),
            y: _mm256_sub_ps(_mm256_mul_ps(b.z, v.x), _mm256_mul_ps(v.z, b.x)),
            z: _mm256_sub_ps(_mm256_mul_ps(b.x, v.y), _mm256_mul_ps(v.x, b.y)),
        };
        let coordinate = |v: __m256, b: __m256, cross: __m256| {
            _mm256_add_ps(
                _mm256_add_ps(_mm256_mul_ps(v, self.scale), _mm256_mul_ps(b, along)),
                _mm256_mul_ps(cross, self.twice_w),
            )
        };
        V8 { x: coordinate(v.x, b.x, cross.x), y: coordinate(v.y, b.y, cross.y), z: coordinate(v.z, b.z, cross.z) }
    }
}

/// `x * x + y * y + z * z` in that order, as `V3::dot`.
#[inline]
#[target_feature(enable = "avx2")]
fn dot(a: V8, b: V8) -> __m256 {
    _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(a.x, b.x), _mm256_mul_ps(a.y, b.y)), _mm256_mul_ps(a.z, b.z))
}

#[inline]
#[target_feature(enable = "avx2")]
fn sub(a: V8, b: V8) -> V8 {
    V8 { x: _mm256_sub_ps(a.x, b.x), y: _mm256_sub_ps(a.y, b.y), z: _mm256_sub_ps(a.z, b.z) }
}

/// Double-precision operations on both halves.
#[inline]
#[target_feature(enable = "avx2")]
fn dsub(a: D8, b: D8) -> D8 {
    D8(_mm256_sub_pd(a.0, b.0), _mm256_sub_pd(a.1, b.1))
}

#[inline]
#[target_feature(enable = "avx2")]
fn dmul(a: D8, b: D8) -> D8 {
    D8(_mm256_mul_pd(a.0, b.0), _mm256_mul_pd(a.1, b.1))
}

#[inline]
#[target_feature(enable = "avx2")]
fn dadd(a: D8, b: D8) -> D8 {
    D8(_mm256_add_pd(a.0, b.0), _mm256_add_pd(a.1, b.1))
}

/// `as f32` on every lane.
#[inline]
#[target_feature(enable = "avx2")]
fn to_f32(v: D8) -> __m256 {
    _mm256_set_m128(_mm256_cvtpd_ps(v.1), _mm256_cvtpd_ps(v.0))
}

/// `as f64` on every lane.
#[inline]
#[target_feature(enable = "avx2")]
fn to_f64(v: __m256) -> D8 {
    D8(_mm256_cvtps_pd(_mm256_castps256_ps128(v)), _mm256_cvtps_pd(_mm256_extractf128_ps::<1>(v)))
}

/// `(q - centre).to_f32()`.
#[inline]
#[target_feature(enable = "avx2")]
fn relative(q: DV8, centre: DV8) -> V8 {
    V8 { x: to_f32(dsub(q.x, centre.x)), y: to_f32(dsub(q.y, centre.y)), z: to_f32(dsub(q.z, centre.z)) }
}

/// `if m { a } else { b }` (`m` from a comparison: all bits set or none).
#[inline]
#[target_feature(enable = "avx2")]
fn select(m: __m256, a: __m256, b: __m256) -> __m256 {
    _mm256_blendv_ps(b, a, m)
}

/// `f32::clamp` (NaN stays NaN).
#[inline]
#[target_feature(enable = "avx2")]
fn clamp(v: __m256, min: __m256, max: __m256) -> __m256 {
    let v = select(_mm256_cmp_ps::<_CMP_LT_OQ>(v, min), min, v);
    select(_mm256_cmp_ps::<_CMP_GT_OQ>(v, max), max, v)
}

/// `collision::closest_between_segments(p, q).0`, every branch computed and the one taken selected.
#[inline]
#[target_feature(enable = "avx2")]
fn closest_on_first(p: (V8, V8), q: (V8, V8)) -> __m256 {
    let (zero, one) = (_mm256_set1_ps(0.0), _mm256_set1_ps(1.0));
    let (d1, d2) = (sub(p.1, p.0), sub(q.1, q.0));
    let r = sub(p.0, q.0);
    let (a, e, f) = (dot(d1, d1), dot(d2, d2), dot(d2, r));
    let c = dot(d1, r);
    let b = dot(d1, d2);
    let denom = _mm256_sub_ps(_mm256_mul_ps(a, e), _mm256_mul_ps(b, b));
    let threshold = _mm256_mul_ps(_mm256_mul_ps(a, _mm256_set1_ps(1e-10)), e);
    let general = clamp(_mm256_div_ps(_mm256_sub_ps(_mm256_mul_ps(b, f), _mm256_mul_ps(c, e)), denom), zero, one);
    let s = select(_mm256_cmp_ps::<_CMP_GT_OQ>(denom, threshold), general, zero);
    let t = _mm256_div_ps(_mm256_add_ps(_mm256_mul_ps(b, s), f), e);
    let minus_c = _mm256_xor_ps(c, _mm256_set1_ps(-0.0));
    let from_start = clamp(_mm256_div_ps(minus_c, a), zero, one);
    let from_end = clamp(_mm256_div_ps(_mm256_sub_ps(b, c), a), zero, one);
    let s = select(
        _mm256_cmp_ps::<_CMP_LT_OQ>(t, zero),
        from_start,
        select(_mm256_cmp_ps::<_CMP_GT_OQ>(t, one), from_end, s),
    );
    let s = select(_mm256_cmp_ps::<_CMP_LE_OQ>(e, zero), from_start, s);
    select(_mm256_cmp_ps::<_CMP_LE_OQ>(a, zero), zero, s)
}

/// The screen of segment `k` of the lanes in `lanes` (a bit per lane): those past the quick reject whose closest
/// point is inside the reach or went through it (`collision::contact_outside`).
#[inline]
#[target_feature(enable = "avx2")]
fn segment(
    c: &Constants,
    k: usize,
    lanes: i32,
    start: &[DV3<8>],
    p: &[DV3<8>],
    radii: &[F<8>],
    (midpoint, segment_reach): &(DV3<8>, D<8>),
) -> i32 {
    // The quick reject, in double precision.
    let reach = d8(segment_reach);
    let clear = D8(
        _mm256_add_pd(_mm256_add_pd(_mm256_add_pd(c.solid, reach.0), c.collider_travel), c.drift_3.0),
        _mm256_add_pd(_mm256_add_pd(_mm256_add_pd(c.solid, reach.1), c.collider_travel), c.drift_3.1),
    );
    let midpoint = dv8(midpoint);
    let (dx, dy, dz) = (dsub(midpoint.x, c.centre.x), dsub(midpoint.y, c.centre.y), dsub(midpoint.z, c.centre.z));
    let distance_squared = dadd(dadd(dmul(dx, dx), dmul(dy, dy)), dmul(dz, dz));
    let clear_squared = dmul(clear, clear);
    let near = _mm256_movemask_pd(_mm256_cmp_pd::<_CMP_NGT_UQ>(distance_squared.0, clear_squared.0))
        | _mm256_movemask_pd(_mm256_cmp_pd::<_CMP_NGT_UQ>(distance_squared.1, clear_squared.1)) << 4;
    let near = near & lanes;
    if near == 0 {
        return 0;
    }
    let a = c.to_end.rotate(relative(dv8(&p[k]), c.centre));
    let b = c.to_end.rotate(relative(dv8(&p[k + 1]), c.centre));
    let t = closest_on_first((a, b), c.axis);
    let lever_min = _mm256_set1_ps(if k == 0 { ROOT_LEVER_MIN } else { f32::NEG_INFINITY });
    let one = _mm256_set1_ps(1.0);
    let t = select(_mm256_cmp_ps::<_CMP_LT_OQ>(t, lever_min), one, t);
    let (r0, r1) = (f8(&radii[k]), f8(&radii[k + 1]));
    let reach = _mm256_add_ps(_mm256_add_ps(c.radius, r0), _mm256_mul_ps(_mm256_sub_ps(r1, r0), t));
    let rest = _mm256_sub_ps(one, t);
    let lerp = |a: __m256, b: __m256| _mm256_add_ps(_mm256_mul_ps(a, rest), _mm256_mul_ps(b, t));
    let point = V8 { x: lerp(a.x, b.x), y: lerp(a.y, b.y), z: lerp(a.z, b.z) };
    let t64 = to_f64(t);
    let rest64 = dsub(D8(_mm256_set1_pd(1.0), _mm256_set1_pd(1.0)), t64);
    let (s0, s1) = (dv8(&start[k]), dv8(&start[k + 1]));
    let dlerp = |a: D8, b: D8| dadd(dmul(a, rest64), dmul(b, t64));
    let before = DV8 { x: dlerp(s0.x, s1.x), y: dlerp(s0.y, s1.y), z: dlerp(s0.z, s1.z) };
    let before = c.to_start.rotate(relative(before, c.start_centre));
    // `contact_outside`'s tests.
    let zero = _mm256_set1_ps(0.0);
    let minus_half_height = _mm256_xor_ps(c.half_height, _mm256_set1_ps(-0.0));
    let from_axis = |q: V8| V8 {
        x: _mm256_sub_ps(q.x, zero),
        y: _mm256_sub_ps(q.y, clamp(q.y, minus_half_height, c.half_height)),
        z: _mm256_sub_ps(q.z, zero),
    };
    let (from_axis_before, from_axis_now) = (from_axis(before), from_axis(point));
    let started_outside = _mm256_cmp_ps::<_CMP_GE_OQ>(
        _mm256_sqrt_ps(dot(from_axis_before, from_axis_before)),
        _mm256_sub_ps(reach, c.slop),
    );
    let went_through =
        _mm256_and_ps(started_outside, _mm256_cmp_ps::<_CMP_LE_OQ>(dot(from_axis_before, from_axis_now), zero));
    let inside_now = _mm256_cmp_ps::<_CMP_NGE_UQ>(_mm256_sqrt_ps(dot(from_axis_now, from_axis_now)), reach);
    near & _mm256_movemask_ps(_mm256_or_ps(went_through, inside_now))
}
