//! The orientations' part of the carry to a new rest shape ([`rod::carry_to_new_rest`](super::rod::carry_to_new_rest)),
//! several joints at a time. Joint by joint, each joint's two normalisations (of the carried orientation and of
//! the blend towards it) kept the divider busy one number at a time: on `scene_cost 200 1000x16 views`, whose
//! chains' rest shapes follow the orbiting camera every frame, their divisions and the stores waiting on them
//! took about a fifth of the samples of the engine's own per-chain loop. A loop over a block of joints, whose
//! body is one joint's arithmetic in glam's order ([`glam_order`](super::glam_order)), runs them side by side in
//! vector registers, with the same bits.

use glam::Quat;
use multiversion::multiversion;

use super::glam_order::{conjugate, dot, mix, mul, normalize};

/// Joints per block.
const BLOCK: usize = 8;

/// Every `q[j]` turned towards `q[j] old[j]⁻¹ new[j]` (normalised) by the share `share` of the way, along the
/// shorter arc: [`math::nlerp_shorter`](super::math::nlerp_shorter)`(q[j], (q[j] * old[j].inverse() *
/// new[j]).normalize(), share)`. The three slices are as long.
#[multiversion(targets("x86_64+avx2"))]
pub fn carry_orientations(q: &mut [Quat], old: &[Quat], new: &[Quat], share: f32) {
    let n = q.len();
    let (old, new) = (&old[..n], &new[..n]);
    for first in (0..n).step_by(BLOCK) {
        let count = (n - first).min(BLOCK);
        // Spare lanes stay identities (finite, and not stored).
        let identity = Quat::IDENTITY.to_array();
        let (mut current, mut from, mut to) = ([identity; BLOCK], [identity; BLOCK], [identity; BLOCK]);
        for lane in 0..count {
            let j = first + lane;
            current[lane] = q[j].to_array();
            from[lane] = old[j].to_array();
            to[lane] = new[j].to_array();
        }
        let mut carried = [identity; BLOCK];
        for lane in 0..BLOCK {
            let target = normalize(mul(mul(current[lane], conjugate(from[lane])), to[lane]));
            // `math::align_hemisphere`: the target's sign on the current orientation's side.
            let aligned = if dot(target, current[lane]) < 0.0 { target.map(|c| -c) } else { target };
            carried[lane] = normalize(mix(current[lane], 1.0 - share, aligned, share));
        }
        for lane in 0..count {
            q[first + lane] = Quat::from_array(carried[lane]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::core::math::nlerp_shorter;
    use proptest::prelude::*;

    fn one_by_one(q: &[Quat], old: &[Quat], new: &[Quat], share: f32) -> Vec<Quat> {
        q.iter()
            .zip(old.iter().zip(new))
            .map(|(&q, (&old, &new))| nlerp_shorter(q, (q * old.inverse() * new).normalize(), share))
            .collect()
    }

    fn bits(q: &[Quat]) -> Vec<u32> {
        q.iter().flat_map(|q| q.to_array().map(f32::to_bits)).collect()
    }

    fn unit((x, y, z, w): (f32, f32, f32, f32)) -> Quat {
        Quat::from_xyzw(x, y, z, w).normalize()
    }

    #[test]
    fn every_block_length_and_an_opposite_target_carry_as_one_by_one() {
        for n in 0..20usize {
            let q: Vec<Quat> = (0..n).map(|j| Quat::from_rotation_z(0.3 * j as f32)).collect();
            let old: Vec<Quat> = (0..n).map(|j| Quat::from_rotation_x(0.1 * j as f32)).collect();
            // Joint 2's target is the negated quaternion of its current orientation (the same rotation): the
            // hemisphere test flips it.
            let new: Vec<Quat> =
                (0..n).map(|j| if j == 2 { -old[j] } else { Quat::from_rotation_y(0.2 * j as f32) }).collect();
            for share in [0.0, 0.25, 1.0] {
                let mut carried = q.clone();
                carry_orientations(&mut carried, &old, &new, share);
                assert_eq!(bits(&carried), bits(&one_by_one(&q, &old, &new, share)), "n {n}, share {share}");
            }
        }
    }

    proptest! {
        #[test]
        fn any_orientations_carry_as_one_by_one(
            joints in prop::collection::vec(
                (
                    (-1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0, 0.1f32..1.0),
                    (-1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0),
                    (-1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0),
                ),
                0..40,
            ),
            share in 0.0f32..=1.0,
        ) {
            let q: Vec<Quat> = joints.iter().map(|&(q, _, _)| unit(q)).collect();
            let old: Vec<Quat> = joints.iter().map(|&(_, o, _)| unit(o)).collect();
            let new: Vec<Quat> = joints.iter().map(|&(_, _, n)| unit(n)).collect();
            let mut carried = q.clone();
            carry_orientations(&mut carried, &old, &new, share);
            prop_assert_eq!(bits(&carried), bits(&one_by_one(&q, &old, &new, share)));
        }
    }
}
