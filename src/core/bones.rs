//! A chain's bones swung onto their segments ([`math::swing_to`] of every joint towards the next one), several
//! joints at a time. Joint by joint, each swing's square roots and divisions (the segment's direction, the
//! normalised product) kept the divider busy one number at a time: `Chain::orient_rest` took 4.4 % of the samples
//! of `perf record -e cpu-clock target/release/examples/scene_cost 120 1000x16 views`. Here a loop over a block of
//! joints, whose body is one joint's arithmetic on plain arrays, runs them side by side in vector registers. That
//! arithmetic is glam's, operation for operation and grouped as glam groups its sums (the lane kernel's mirrors
//! in `lanes::scalar` where they agree with glam; the quaternion product and normalisation of
//! [`glam_order`](super::glam_order) where they do not), so the result has the same bits; the joints more than a
//! right angle from their segment take [`math::swing_to`] itself.

use glam::{Quat, Vec3};
use multiversion::multiversion;

use super::glam_order;
use super::lanes::scalar::{cross, direction, dot, rotate, sub};
use super::math::swing_to;

/// Joints per block.
const BLOCK: usize = 8;

/// `out[j]` = `orientations[j]` swung so that its local `axes[j]` points from `positions[j]` to
/// `positions[j + 1]` (`math::swing_to`), or `orientations[j]` where that segment has no direction
/// (`math::direction`) and for the last joint. All four slices are as long.
#[multiversion(targets("x86_64+avx2"))]
pub fn swing_onto_segments(orientations: &[Quat], axes: &[Vec3], positions: &[Vec3], out: &mut [Quat]) {
    let n = positions.len();
    let (orientations, axes, out) = (&orientations[..n], &axes[..n], &mut out[..n]);
    let segments = n.saturating_sub(1);
    for first in (0..segments).step_by(BLOCK) {
        let count = (segments - first).min(BLOCK);
        // The block's joints number by number; spare lanes stay zero (no direction: not used).
        let (mut q, mut axis, mut segment) = ([[0.0; 4]; BLOCK], [[0.0; 3]; BLOCK], [[0.0; 3]; BLOCK]);
        for lane in 0..count {
            let j = first + lane;
            q[lane] = orientations[j].to_array();
            axis[lane] = axes[j].to_array();
            segment[lane] = sub(positions[j + 1].to_array(), positions[j].to_array());
        }
        let (mut swung, mut along, mut found, mut folded) =
            ([[0.0; 4]; BLOCK], [[0.0; 3]; BLOCK], [false; BLOCK], [false; BLOCK]);
        for lane in 0..BLOCK {
            let (unit, exists) = direction(segment[lane]);
            // `math::swing_to`'s single-precision arc within a right angle.
            let at = rotate(q[lane], axis[lane]);
            let (cos, turn) = (dot(at, unit), cross(at, unit));
            swung[lane] = glam_order::normalize(glam_order::mul([turn[0], turn[1], turn[2], 1.0 + cos], q[lane]));
            along[lane] = unit;
            found[lane] = exists;
            // Not within a right angle, or NaN: `!(cos > 0.0)`.
            folded[lane] = cos.is_nan() | (cos <= 0.0);
        }
        for lane in 0..count {
            let j = first + lane;
            out[j] = match (found[lane], folded[lane]) {
                (false, _) => orientations[j],
                (true, false) => Quat::from_array(swung[lane]),
                (true, true) => swing_to(orientations[j], axes[j], Vec3::from_array(along[lane])),
            };
        }
    }
    if let Some(last) = n.checked_sub(1) {
        out[last] = orientations[last];
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::core::math::direction as unit_direction;
    use proptest::prelude::*;

    /// `Chain::orient_rest`'s joint-by-joint loop.
    fn one_by_one(orientations: &[Quat], axes: &[Vec3], positions: &[Vec3]) -> Vec<Quat> {
        let n = positions.len();
        (0..n)
            .map(|j| match (j + 1 < n).then(|| unit_direction(positions[j + 1] - positions[j])) {
                Some(Some(dir)) => swing_to(orientations[j], axes[j], dir),
                _ => orientations[j],
            })
            .collect()
    }

    fn bits(q: &[Quat]) -> Vec<u32> {
        q.iter().flat_map(|q| q.to_array().map(f32::to_bits)).collect()
    }

    fn check(orientations: &[Quat], axes: &[Vec3], positions: &[Vec3]) {
        let mut out = vec![Quat::from_xyzw(f32::NAN, 0.0, 0.0, 0.0); positions.len()];
        swing_onto_segments(orientations, axes, positions, &mut out);
        assert_eq!(bits(&out), bits(&one_by_one(orientations, axes, positions)));
    }

    #[test]
    fn folded_bones_repeated_joints_and_short_chains_swing_as_one_by_one() {
        let axis = Vec3::new(0.1, 1.0, 0.05).normalize();
        for n in 0..20usize {
            let positions: Vec<Vec3> = (0..n)
                .map(|j| match j {
                    // Joint 3 repeats joint 2: a segment without a direction.
                    3 => Vec3::new(0.02, 0.04, 0.0),
                    _ => Vec3::new(0.01 * j as f32, 0.02 * j.min(2) as f32 + 0.03 * j.saturating_sub(3) as f32, 0.0),
                })
                .collect();
            let orientations: Vec<Quat> = (0..n)
                .map(|j| match j {
                    // Joint 1 more than a right angle from its segment, joint 5 exactly opposite it.
                    1 => Quat::from_rotation_x(2.1),
                    5 => Quat::from_rotation_z(std::f32::consts::PI),
                    _ => Quat::from_rotation_z(0.1 * j as f32),
                })
                .collect();
            check(&orientations, &vec![axis; n], &positions);
        }
    }

    proptest! {
        #[test]
        fn any_chain_swings_as_one_by_one(
            joints in prop::collection::vec(
                ((-1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0), (-1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0, 0.1f32..1.0)),
                0..40,
            )
        ) {
            let positions: Vec<Vec3> = joints.iter().map(|&((x, y, z), _)| Vec3::new(x, y, z)).collect();
            let orientations: Vec<Quat> =
                joints.iter().map(|&(_, (x, y, z, w))| Quat::from_xyzw(x, y, z, w).normalize()).collect();
            let axes: Vec<Vec3> = orientations.iter().map(|q| (q.conjugate() * Vec3::Y).normalize()).collect();
            check(&orientations, &axes, &positions);
        }
    }
}
