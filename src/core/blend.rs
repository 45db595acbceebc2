//! Blending encoded shapes by weight (SPEC 3.3).

use glam::Quat;

use super::math::align_hemisphere;
use super::shape::EncodedShape;

/// `out = w_0 base + sum_i w_i views[i]` per joint, each quaternion sign-aligned to the base's before
/// summing (q and -q are one rotation; an unaligned sum pops), then normalised.
pub fn blend_into<'a, I>(base: &EncodedShape, w0: f32, views: I, out: &mut EncodedShape)
where
    I: Iterator<Item = (&'a EncodedShape, f32)> + Clone,
{
    blend_quats(&base.bends, w0, views.clone().map(|(s, w)| (&s.bends[..], w)), &mut out.bends);
    blend_quats(&base.orientations, w0, views.map(|(s, w)| (&s.orientations[..], w)), &mut out.orientations);
}

fn blend_quats<'a>(base: &[Quat], w0: f32, views: impl Iterator<Item = (&'a [Quat], f32)>, out: &mut [Quat]) {
    let n = base.len().min(out.len());
    let (base, out) = (&base[..n], &mut out[..n]);
    // View by view over every joint rather than joint by joint over the views: each pass streams two arrays,
    // and every joint's sum still adds its terms in the same order (the same bits).
    for (sum, reference) in out.iter_mut().zip(base) {
        *sum = *reference * w0;
    }
    for (view, w) in views {
        if w > 0.0 {
            for ((sum, reference), q) in out.iter_mut().zip(base).zip(&view[..n]) {
                *sum += align_hemisphere(*q, *reference) * w;
            }
        }
    }
    for (slot, reference) in out.iter_mut().zip(base) {
        // Every term lies in the base's hemisphere, so the sum vanishes only when the weights do; the
        // base is the natural fallback.
        let len = slot.length();
        *slot = if len > 1e-12 { *slot / len } else { *reference };
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::core::math::{Transform, rotation_angle};
    use crate::core::shape::{Shape, ShapeFrame};
    use crate::core::weights::{ViewWeighting, blend_weights};
    use glam::Vec3;

    fn chain(points: &[Vec3], twist: f32) -> Shape {
        let joints: Vec<Transform> = points.iter().map(|p| Transform::new(*p, Quat::from_rotation_y(twist))).collect();
        Shape::from_joints(&joints).unwrap()
    }

    #[test]
    fn single_weight_reproduces_shape() {
        let base = chain(&[Vec3::ZERO, Vec3::Y, Vec3::new(0.0, 2.0, 0.0)], 0.0);
        let view = chain(&[Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0)], 0.5);
        let frame = ShapeFrame::from_base(&base);
        let (eb, ev) = (EncodedShape::encode(&base, frame.reference), EncodedShape::encode(&view, frame.reference));
        let mut out = EncodedShape::identity(3);
        blend_into(&eb, 0.0, [(&ev, 1.0)].into_iter(), &mut out);
        let decoded = out.decode(&frame);
        for (a, b) in decoded.positions.iter().zip(&view.positions) {
            assert!((*a - *b).length() < 1e-6);
        }
        blend_into(&eb, 1.0, [(&ev, 0.0)].into_iter(), &mut out);
        assert_eq!(out, eb);
    }

    #[test]
    fn half_blend_bends_halfway() {
        // Base straight up, view bent 90 degrees at the root: half weight bends 45 degrees.
        let base = chain(&[Vec3::ZERO, Vec3::Y, Vec3::new(0.0, 2.0, 0.0)], 0.0);
        let view = chain(&[Vec3::ZERO, Vec3::X, Vec3::new(2.0, 0.0, 0.0)], 0.0);
        let frame = ShapeFrame::from_base(&base);
        let (eb, ev) = (EncodedShape::encode(&base, frame.reference), EncodedShape::encode(&view, frame.reference));
        let mut out = EncodedShape::identity(3);
        blend_into(&eb, 0.5, [(&ev, 0.5)].into_iter(), &mut out);
        assert!((rotation_angle(out.bends[0]) - std::f32::consts::FRAC_PI_4).abs() < 1e-5);
    }

    /// Orbit the camera in 1 degree steps around two view shapes whose quaternions are stored in opposite
    /// hemispheres; the blended shape may move only as much as the weights' change implies.
    #[test]
    fn orbit_has_no_pops() {
        let n = 8;
        let base_pts: Vec<Vec3> = (0..n).map(|i| Vec3::new(0.0, i as f32 * 0.1, 0.0)).collect();
        let left_pts: Vec<Vec3> = (0..n).map(|i| Vec3::new(-0.05 * i as f32, 0.08 * i as f32, 0.0)).collect();
        let right_pts: Vec<Vec3> =
            (0..n).map(|i| Vec3::new(0.05 * i as f32, 0.06 * i as f32, 0.02 * i as f32)).collect();
        let base = chain(&base_pts, 0.0);
        let frame = ShapeFrame::from_base(&base);
        let eb = EncodedShape::encode(&base, frame.reference);
        let el = EncodedShape::encode(&chain(&left_pts, 2.5), frame.reference);
        let mut er = EncodedShape::encode(&chain(&right_pts, -2.5), frame.reference);
        // Store one shape with negated quaternions: the same rotations, the other hemisphere.
        for q in er.bends.iter_mut().chain(er.orientations.iter_mut()) {
            *q = -*q;
        }
        let views = [
            ViewWeighting { direction: -Vec3::X, influence: 1.0 },
            ViewWeighting { direction: Vec3::X, influence: 2.0 },
        ];
        let mut w = [0.0; 2];
        let mut out = EncodedShape::identity(n);
        let mut previous: Option<(Vec<Vec3>, Vec<Quat>, [f32; 3])> = None;
        let chain_length = frame.chain_length();
        for deg in 0..=720 {
            let a = (deg as f32).to_radians();
            let d = Vec3::new(a.cos(), 0.0, a.sin());
            let w0 = blend_weights(d, views, &mut w);
            blend_into(&eb, w0, [(&el, w[0]), (&er, w[1])].into_iter(), &mut out);
            let shape = out.decode(&frame);
            let weights = [w0, w[0], w[1]];
            if let Some((pp, pq, pw)) = &previous {
                let dw: f32 = weights.iter().zip(pw).map(|(a, b)| (a - b).abs()).sum();
                let max_move = shape.positions.iter().zip(pp).map(|(a, b)| (*a - *b).length()).fold(0.0, f32::max);
                let max_turn = shape
                    .orientations
                    .iter()
                    .zip(pq)
                    .map(|(a, b)| rotation_angle(a.inverse() * *b))
                    .fold(0.0, f32::max);
                // A full swap between shapes (dw = 2) moves a joint at most ~2 chain lengths and turns it at
                // most pi; a weight change dw moves it proportionally (factor 2 margin for the nonlinearity
                // of normalisation). A pop would show as a jump with dw ~ 0.
                assert!(max_move <= 2.0 * dw * chain_length + 1e-5, "deg {deg}: moved {max_move} for dw {dw}");
                assert!(max_turn <= 2.0 * dw * std::f32::consts::PI + 2e-3, "deg {deg}: turned {max_turn} for dw {dw}");
                assert!(max_move < 0.05 * chain_length, "deg {deg}: moved {max_move}");
            }
            previous = Some((shape.positions, shape.orientations, weights));
        }
    }
}
