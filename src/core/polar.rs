//! Rotation part of a 3x3 matrix, after Müller et al. 2016, "A Robust Method to Extract the Rotational
//! Part of Deformations": iterate a quaternion towards the rotation that best aligns its columns with the
//! matrix's, warm-started from the previous step's answer. Unlike SVD-based polar decomposition it never
//! flips on reflections and degrades gracefully for rank-deficient matrices (two-particle groups).

use glam::{Mat3, Quat};

/// Rotation updates below this (radians) change nothing at float32 precision.
const CONVERGED_ANGLE: f32 = 1e-7;

/// Improves `q` in place towards the rotation part of `a`, for at most `max_iterations` iterations.
#[inline]
pub fn extract_rotation(a: &Mat3, q: &mut Quat, max_iterations: u32) {
    // The guard against a vanishing denominator scales with the matrix, so a millimetre-sized chain (entries
    // ~1e-7) is treated exactly like a metre-sized one.
    let guard = 1e-9 * (a.x_axis.length_squared() + a.y_axis.length_squared() + a.z_axis.length_squared()).sqrt()
        + f32::MIN_POSITIVE;
    for _ in 0..max_iterations {
        let r = Mat3::from_quat(*q);
        let omega_num = r.x_axis.cross(a.x_axis) + r.y_axis.cross(a.y_axis) + r.z_axis.cross(a.z_axis);
        let omega_den = (r.x_axis.dot(a.x_axis) + r.y_axis.dot(a.y_axis) + r.z_axis.dot(a.z_axis)).abs() + guard;
        let omega = omega_num / omega_den;
        let angle = omega.length();
        if angle < CONVERGED_ANGLE {
            break;
        }
        *q = (Quat::from_axis_angle(omega / angle, angle) * *q).normalize();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::core::math::rotation_angle;
    use glam::Vec3;

    #[test]
    fn recovers_rotation_of_stretched_matrix() {
        let truth = Quat::from_euler(glam::EulerRot::YXZ, 0.8, -0.4, 1.9);
        let stretch = Mat3::from_diagonal(Vec3::new(2.0, 0.5, 1.3));
        let a = Mat3::from_quat(truth) * stretch;
        let mut q = Quat::IDENTITY;
        extract_rotation(&a, &mut q, 100);
        assert!(rotation_angle(q.inverse() * truth) < 1e-4);
    }

    #[test]
    fn warm_start_converges_linearly() {
        // For a pure rotation the error shrinks by about 3x per iteration.
        let truth = Quat::from_euler(glam::EulerRot::XYZ, 0.5, 0.2, -0.1);
        let a = Mat3::from_quat(truth);
        let mut q = Quat::from_euler(glam::EulerRot::XYZ, 0.45, 0.22, -0.12);
        let mut error = rotation_angle(q.inverse() * truth);
        for _ in 0..4 {
            extract_rotation(&a, &mut q, 1);
            let next = rotation_angle(q.inverse() * truth);
            assert!(next < 0.5 * error, "{next} vs {error}");
            error = next;
        }
        extract_rotation(&a, &mut q, 12);
        assert!(rotation_angle(q.inverse() * truth) < 1e-6);
    }

    #[test]
    fn rank_deficient_matrix_stays_finite() {
        // A two-point group without orientation terms: rank 1.
        let a = Mat3::from_cols(Vec3::new(0.0, 1.0, 0.0), Vec3::ZERO, Vec3::ZERO);
        let mut q = Quat::IDENTITY;
        extract_rotation(&a, &mut q, 20);
        assert!(q.is_finite() && (q.length() - 1.0).abs() < 1e-5);
        // The one constrained column is aligned: x maps to y.
        assert!((q * Vec3::X - Vec3::Y).length() < 1e-3);
    }

    #[test]
    fn zero_matrix_leaves_guess() {
        let mut q = Quat::from_rotation_x(0.3);
        extract_rotation(&Mat3::ZERO, &mut q, 10);
        assert_eq!(q, Quat::from_rotation_x(0.3));
    }
}
