//! View direction and blend weights (SPEC 3.2).

use glam::Vec3;

use super::elementary;
use super::math::{Transform, direction};

/// Direction from the view reference joint K to the camera, in K's local frame; `None` when the camera
/// sits on K (no direction to speak of: callers keep the previous one).
#[inline]
pub fn view_direction(camera: Vec3, view_reference: &Transform) -> Option<Vec3> {
    direction(view_reference.rotation.inverse() * (camera - view_reference.position))
}

/// One view shape's contribution to the weights.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ViewWeighting {
    /// Unit direction in the view reference frame.
    pub direction: Vec3,
    /// `k_i > 0`: larger means the shape acts in a narrower cone around its direction.
    pub influence: f32,
}

/// Writes `w_1..w_m` into `out` and returns the base shape's weight `w_0`.
///
/// `w_i = ((d_i . d + 1) / 2)^k_i`; if they sum to 1 or more they are normalised and `w_0 = 0`, otherwise
/// `w_0 = 1 - sum`. All weights are continuous in `d`, non-negative, and sum to 1.
pub fn blend_weights(view: Vec3, shapes: impl IntoIterator<Item = ViewWeighting>, out: &mut [f32]) -> f32 {
    let mut sum = 0.0f32;
    for (shape, w) in shapes.into_iter().zip(out.iter_mut()) {
        // Clamp: rounding can push the cosine a hair past +-1, and powf of a negative base is NaN.
        let closeness = ((shape.direction.dot(view) + 1.0) * 0.5).clamp(0.0, 1.0);
        *w = elementary::powf(closeness, shape.influence);
        sum += *w;
    }
    if sum >= 1.0 {
        for w in out.iter_mut() {
            *w /= sum;
        }
        0.0
    } else {
        1.0 - sum
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Quat;

    fn shape(direction: Vec3, influence: f32) -> ViewWeighting {
        ViewWeighting { direction, influence }
    }

    #[test]
    fn no_view_shapes_means_base_only() {
        assert_eq!(blend_weights(Vec3::Z, std::iter::empty(), &mut []), 1.0);
    }

    #[test]
    fn head_on_shape_takes_everything() {
        let mut w = [0.0];
        let w0 = blend_weights(Vec3::X, [shape(Vec3::X, 1.0)], &mut w);
        assert_eq!((w0, w[0]), (0.0, 1.0));
    }

    #[test]
    fn opposite_view_falls_back_to_base() {
        let mut w = [0.0];
        let w0 = blend_weights(-Vec3::X, [shape(Vec3::X, 1.0)], &mut w);
        assert_eq!((w0, w[0]), (1.0, 0.0));
    }

    #[test]
    fn side_view_with_influences() {
        // Seen at 90 degrees: closeness 1/2, so w = 0.5^k.
        let mut w = [0.0];
        for (k, expected) in [(0.5f32, std::f32::consts::FRAC_1_SQRT_2), (1.0, 0.5), (8.0, 1.0 / 256.0)] {
            let w0 = blend_weights(Vec3::Y, [shape(Vec3::X, k)], &mut w);
            assert!((w[0] - expected).abs() < 1e-6, "k={k}: {}", w[0]);
            assert!((w0 - (1.0 - expected)).abs() < 1e-6);
        }
        // At 60 degrees: closeness (cos 60 + 1) / 2 = 0.75.
        let d = Vec3::new(0.5, 3f32.sqrt() / 2.0, 0.0);
        blend_weights(d, [shape(Vec3::X, 8.0)], &mut w);
        assert!((w[0] - 0.75f32.powi(8)).abs() < 1e-6);
    }

    #[test]
    fn sum_at_least_one_is_normalised() {
        // Two shapes at +-45 degrees around the view, influence 1: each (cos45 + 1)/2 = 0.853..., sum > 1.
        let a = Vec3::new(1.0, 1.0, 0.0).normalize();
        let b = Vec3::new(1.0, -1.0, 0.0).normalize();
        let mut w = [0.0; 2];
        let w0 = blend_weights(Vec3::X, [shape(a, 1.0), shape(b, 1.0)], &mut w);
        assert_eq!(w0, 0.0);
        assert!((w[0] - 0.5).abs() < 1e-6 && (w[1] - 0.5).abs() < 1e-6);
        // Below one: two shapes at 90 degrees with influence 2 give 0.25 each.
        let w0 = blend_weights(Vec3::Z, [shape(Vec3::X, 2.0), shape(Vec3::Y, 2.0)], &mut w);
        assert!((w0 - 0.5).abs() < 1e-6 && (w[0] - 0.25).abs() < 1e-6);
    }

    #[test]
    fn view_direction_is_in_reference_frame() {
        // K turned 90 degrees about Y: a camera on world +X is on K's local +Z.
        let k = Transform::new(Vec3::new(0.0, 1.0, 0.0), Quat::from_rotation_y(std::f32::consts::FRAC_PI_2));
        let d = view_direction(Vec3::new(5.0, 1.0, 0.0), &k).unwrap();
        assert!((d - Vec3::Z).length() < 1e-6, "{d}");
        assert!(view_direction(k.position, &k).is_none());
    }

    #[test]
    fn weights_sum_to_one_everywhere() {
        let shapes = [shape(Vec3::X, 0.7), shape(-Vec3::X, 3.0), shape(Vec3::Y, 1.0)];
        let mut w = [0.0; 3];
        for i in 0..360 {
            let a = (i as f32).to_radians();
            let d = Vec3::new(a.cos(), 0.3, a.sin()).normalize();
            let w0 = blend_weights(d, shapes, &mut w);
            let total = w0 + w.iter().sum::<f32>();
            assert!((total - 1.0).abs() < 1e-6 && w0 >= 0.0 && w.iter().all(|x| *x >= 0.0));
        }
    }
}
