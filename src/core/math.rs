//! Small math helpers on top of glam: rigid transforms and the quaternion operations the shape code needs.

use super::elementary;
use glam::{DVec3, Quat, Vec3};

/// A rigid transform: rotate, then translate. Mirrors Unity's `Transform` (position + rotation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    pub position: Vec3,
    pub rotation: Quat,
}

impl Default for Transform {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl Transform {
    pub const IDENTITY: Self = Self { position: Vec3::ZERO, rotation: Quat::IDENTITY };

    #[inline]
    pub fn new(position: Vec3, rotation: Quat) -> Self {
        Self { position, rotation }
    }

    #[inline]
    pub fn transform_point(&self, p: Vec3) -> Vec3 {
        self.position + self.rotation * p
    }

    #[inline]
    pub fn inverse_transform_point(&self, p: Vec3) -> Vec3 {
        self.rotation.inverse() * (p - self.position)
    }

    /// `transform_point` for double-precision particle positions.
    #[inline]
    pub fn transform_point_f64(&self, p: DVec3) -> DVec3 {
        self.position.as_dvec3() + self.rotation.as_dquat() * p
    }

    /// A local offset (single precision) placed under this transform, in double precision.
    #[inline]
    pub fn place_f64(&self, local: Vec3) -> DVec3 {
        self.position.as_dvec3() + (self.rotation * local).as_dvec3()
    }

    /// `inverse_transform_point` for a double-precision position whose local result is small.
    #[inline]
    pub fn inverse_transform_point_f64(&self, p: DVec3) -> Vec3 {
        self.rotation.inverse() * (p - self.position.as_dvec3()).as_vec3()
    }

    /// `self * other`: apply `other` first, then `self`.
    #[inline]
    pub fn mul(&self, other: &Transform) -> Transform {
        Transform { position: self.transform_point(other.position), rotation: self.rotation * other.rotation }
    }

    #[inline]
    pub fn inverse(&self) -> Transform {
        let inv = self.rotation.inverse();
        Transform { position: inv * -self.position, rotation: inv }
    }

    /// Interpolation used for kinematic bones across substeps: lerp of positions, shorter-arc nlerp of
    /// rotations (substeps are small, so nlerp's speed error is far below the solver's).
    #[inline]
    pub fn interpolate(&self, to: &Transform, t: f32) -> Transform {
        Transform {
            position: self.position.lerp(to.position, t),
            rotation: nlerp_shorter(self.rotation, to.rotation, t),
        }
    }

    pub fn is_finite(&self) -> bool {
        self.position.is_finite() && self.rotation.is_finite()
    }
}

/// `q` or `-q`, whichever lies in the same hemisphere as `reference` (they are the same rotation).
#[inline]
pub fn align_hemisphere(q: Quat, reference: Quat) -> Quat {
    if q.dot(reference) < 0.0 { -q } else { q }
}

/// Normalised linear interpolation along the shorter arc.
#[inline]
pub fn nlerp_shorter(from: Quat, to: Quat, t: f32) -> Quat {
    let to = align_hemisphere(to, from);
    (from * (1.0 - t) + to * t).normalize()
}

/// The rotation with the smallest angle that turns `from` into `to` (both unit vectors). Antiparallel input
/// turns about a fixed perpendicular axis, so encoding and decoding stay exact inverses there too.
/// Computed in double precision: near a 180-degree fold the `1 + cos` term cancels, and in float32 the
/// arc would miss `to` by up to 1e-4.
#[inline]
pub fn shortest_arc(from: Vec3, to: Vec3) -> Quat {
    glam::DQuat::from_rotation_arc(from.as_dvec3().normalize(), to.as_dvec3().normalize()).as_quat()
}

/// Rotates `q` by the smallest swing that makes its local `axis` point along `direction` (unit), keeping
/// the twist about that axis. This is what makes an output rotation skinning-ready.
#[inline(always)]
pub fn swing_to(q: Quat, axis: Vec3, direction: Vec3) -> Quat {
    let current = q * axis;
    let cos = current.dot(direction);
    // Within 90 degrees (every output bone but a folded one) `1 + cos` does not cancel, so float32 gives the
    // arc to its rounding, without `shortest_arc`'s square roots and divisions in double precision. The arc is
    // left unnormalised: the product is normalised anyway.
    let arc = if cos > 0.0 {
        let axis = current.cross(direction);
        Quat::from_xyzw(axis.x, axis.y, axis.z, 1.0 + cos)
    } else {
        shortest_arc(current, direction)
    };
    (arc * q).normalize()
}

/// `exp` of a rotation vector: the quaternion turning by `|e|` about `e`, as `Quat::from_scaled_axis`. Short
/// vectors (the usual case: a particle's turn in one substep) use Taylor series accurate
/// to float32 rounding up to 1 radian, with no square root and no call to `sincosf`.
#[inline]
pub fn exp_small(e: Vec3) -> Quat {
    let x2 = 0.25 * e.length_squared();
    if x2 <= 0.25 {
        // cos(x) and sin(x)/x for the half angle x = |e|/2 <= 0.5; the first omitted terms are < 3e-10.
        let cos = 1.0 + x2 * (-1.0 / 2.0 + x2 * (1.0 / 24.0 + x2 * (-1.0 / 720.0 + x2 * (1.0 / 40320.0))));
        let sinc = 1.0 + x2 * (-1.0 / 6.0 + x2 * (1.0 / 120.0 + x2 * (-1.0 / 5040.0 + x2 * (1.0 / 362880.0))));
        let v = e * (0.5 * sinc);
        Quat::from_xyzw(v.x, v.y, v.z, cos)
    } else {
        Quat::from_scaled_axis(e)
    }
}

/// `log` of a unit quaternion: its rotation vector, as `Quat::to_scaled_axis`. Rotations by less than about
/// 0.4 radians with `w > 0` (the usual case: a particle's turn in one substep) use a series accurate to
/// float32 rounding, with no call to `atan2f`.
#[inline]
pub fn log_small(q: Quat) -> Vec3 {
    let v = q.xyz();
    let s2 = v.length_squared();
    // Below glam's threshold `to_scaled_axis` returns zero; the exact path keeps that.
    if q.w > 0.0 && s2 <= 0.04 * (q.w * q.w) && s2 >= 1e-16 {
        // `2 atan2(s, w) / s = (2 / w) atan(t) / t` with `t = s / w <= 0.2`; the first omitted term is < 1e-8.
        let inv_w = 1.0 / q.w;
        let t2 = s2 * inv_w * inv_w;
        let atan_t_over_t = 1.0 + t2 * (-1.0 / 3.0 + t2 * (1.0 / 5.0 + t2 * (-1.0 / 7.0 + t2 * (1.0 / 9.0))));
        v * (2.0 * inv_w * atan_t_over_t)
    } else {
        q.to_scaled_axis()
    }
}

/// Angle of the rotation `q` in radians, in [0, pi].
#[inline]
pub fn rotation_angle(q: Quat) -> f32 {
    // atan2 keeps full precision for small angles, where acos(w) loses half the digits.
    2.0 * elementary::atan2(q.xyz().length(), q.w.abs())
}

/// `q` normalised, for any finite non-zero input (tiny or huge components alike: the largest component
/// is scaled to 1 first, so squaring neither underflows nor overflows); `None` for zero or non-finite.
pub fn normalized_rotation(q: Quat) -> Option<Quat> {
    let largest = q.x.abs().max(q.y.abs()).max(q.z.abs()).max(q.w.abs());
    if !(largest > 0.0 && largest.is_finite() && q.is_finite()) {
        return None;
    }
    Some((q / largest).normalize())
}

/// Unit direction of any finite non-zero `v` (scaled like [`normalized_rotation`]); `None` otherwise.
pub fn normalized_direction(v: Vec3) -> Option<Vec3> {
    let largest = v.abs().max_element();
    if !(largest > 0.0 && largest.is_finite() && v.is_finite()) {
        return None;
    }
    Some((v / largest).normalize())
}

/// Unit direction of `v`, or `None` when it is too short to have one.
#[inline]
pub fn direction(v: Vec3) -> Option<Vec3> {
    let len = v.length();
    if len > f32::MIN_POSITIVE.sqrt() && len.is_finite() { Some(v / len) } else { None }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn transform_inverse_round_trips() {
        let t = Transform::new(Vec3::new(1.0, -2.0, 3.0), Quat::from_euler(glam::EulerRot::XYZ, 0.3, -1.1, 2.0));
        let p = Vec3::new(0.5, 0.25, -4.0);
        let back = t.inverse().transform_point(t.transform_point(p));
        assert!((back - p).length() < 1e-5);
        assert!((t.inverse_transform_point(t.transform_point(p)) - p).length() < 1e-5);
        let ident = t.mul(&t.inverse());
        assert!(ident.position.length() < 1e-5);
        assert!(rotation_angle(ident.rotation) < 1e-3);
    }

    #[test]
    fn swing_keeps_twist_and_hits_direction() {
        let twist = Quat::from_rotation_y(0.7);
        let target = Vec3::new(1.0, 1.0, 0.0).normalize();
        let q = swing_to(twist, Vec3::Y, target);
        assert!((q * Vec3::Y - target).length() < 1e-6);
        // Twist is preserved: the swing is the shortest arc, so the result's twist about the new axis
        // equals the original twist about the old one.
        let untwisted = swing_to(Quat::IDENTITY, Vec3::Y, target);
        let relative = untwisted.inverse() * q;
        assert!((rotation_angle(relative) - 0.7).abs() < 1e-5);
        assert!((relative * Vec3::Y - Vec3::Y).length() < 1e-5);
    }

    #[test]
    fn swing_within_a_right_angle_matches_the_double_precision_arc() {
        let twist = Quat::from_euler(glam::EulerRot::YXZ, 0.4, -1.2, 2.1);
        let axis = Vec3::new(0.2, 1.0, -0.3).normalize();
        let current = twist * axis;
        let mut worst: f32 = 0.0;
        for i in 0..2000 {
            let angle = i as f32 * 0.37;
            let turn = Quat::from_axis_angle(
                current.any_orthonormal_vector(),
                1e-6 + 0.9999 * std::f32::consts::FRAC_PI_2 * (i as f32 / 2000.0),
            );
            let target = (Quat::from_axis_angle(current, angle) * turn * current).normalize();
            let fast = swing_to(twist, axis, target);
            let reference = (shortest_arc(current, target) * twist).normalize();
            assert!((fast * axis - target).length() < 1e-6, "{i}");
            worst = worst.max(rotation_angle(fast.inverse() * reference));
        }
        assert!(worst < 1e-6, "{worst}");
    }

    #[test]
    fn shortest_arc_antiparallel_is_exact() {
        let q = shortest_arc(Vec3::Y, -Vec3::Y);
        assert!((q * Vec3::Y + Vec3::Y).length() < 1e-6);
    }

    #[test]
    fn normalisation_accepts_any_finite_nonzero_input() {
        let tiny = normalized_rotation(Quat::from_xyzw(0.0, 5e-7, 0.0, 5e-7)).unwrap();
        let huge = normalized_rotation(Quat::from_xyzw(0.0, 1e20, 0.0, 1e20)).unwrap();
        let denormal = normalized_rotation(Quat::from_xyzw(0.0, 0.0, 0.0, 1e-40)).unwrap();
        assert!((tiny.length() - 1.0).abs() < 1e-6 && tiny.dot(huge) > 0.999_999);
        assert_eq!(denormal, Quat::IDENTITY);
        assert!(normalized_rotation(Quat::from_xyzw(0.0, 0.0, 0.0, 0.0)).is_none());
        assert!(normalized_rotation(Quat::from_xyzw(f32::NAN, 0.0, 0.0, 1.0)).is_none());
        assert_eq!(normalized_direction(Vec3::new(1e-20, 0.0, 0.0)), Some(Vec3::X));
        assert_eq!(normalized_direction(Vec3::new(0.0, -3e38, 0.0)), Some(-Vec3::Y));
        assert!(normalized_direction(Vec3::ZERO).is_none());
    }

    #[test]
    fn series_exp_and_log_match_the_exact_functions() {
        let axis = Vec3::new(0.3, -0.8, 0.5).normalize();
        for angle in [0.0f32, 1e-9, 1e-7, 1e-4, 0.01, 0.1, 0.3, 0.39, 0.41, 0.9, 1.0, 1.1, 2.5] {
            let e = axis * angle;
            let exact = Quat::from_scaled_axis(e);
            let series = exp_small(e);
            assert!((series - exact).length() <= 2.0 * f32::EPSILON, "exp at {angle}: {series:?} vs {exact:?}");
            let back = log_small(exact);
            let reference = exact.to_scaled_axis();
            let tolerance = 4.0 * f32::EPSILON * angle.max(f32::MIN_POSITIVE);
            assert!((back - reference).length() <= tolerance, "log at {angle}: {back} vs {reference}");
        }
        // The other hemisphere and the identity take the exact path.
        let far = -Quat::from_scaled_axis(axis * 0.1);
        assert_eq!(log_small(far), far.to_scaled_axis());
        assert_eq!(log_small(Quat::IDENTITY), Vec3::ZERO);
    }

    #[test]
    fn nlerp_takes_shorter_arc() {
        let a = Quat::from_rotation_z(0.1);
        let b = -Quat::from_rotation_z(0.3);
        let m = nlerp_shorter(a, b, 0.5);
        assert!((rotation_angle(m) - 0.2).abs() < 1e-4);
    }
}
