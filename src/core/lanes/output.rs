//! The render pose of every lane: `Chain::capture_local` after each of a step's last two substeps and
//! `Chain::write_output` after the last, on the group's buffers. Per chain and joint these are a dozen square
//! roots and divisions with nothing to overlap them in scalar code; on 1000 x 16 chains they took about a
//! sixth of the lane solver's frame (`perf record -e cpu-clock` of `scene_cost 200 1000x16` at 24e6f43), a
//! share that lanes cut with the rest of the substep.
//!
//! Same operations as the scalar functions, per lane (glam's scalar formulas, as everywhere in the lanes):
//! the results agree with the scalar solver's up to rounding and do not depend on the lane or the kernel.

use glam::{DQuat, Quat, Vec3};

use super::group::LaneGroup;
use super::scalar::{Vec, cross, direction, dot, mul, normalize, rotate, sub};
use super::simd::{F, Mask, Q, V3};
use crate::core::math::swing_to;

/// `Chain::capture_local` on every lane: the pose after substep `s` relative to that substep's anchor becomes
/// the newest, the one before it the previous.
///
/// The rotations are a loop over the lanes whose body is one lane's scalar code (`scalar`, and `Q::rotate`'s
/// operations in its order), like the polar decomposition: written with the lane types' operations, the
/// compiler split the whole capture into 128-bit halves and kept them on the stack. `tools/instruction_mix.py
/// capture8_avx2_version -- target/release/examples/scene_cost 20 1000x16 lanes`: 28.2M instructions, 74 %
/// 128-bit and 45 % reading or writing the stack, before; 10.7M, 95 % 256-bit, now. The same bits.
#[inline(always)]
pub fn capture<const L: usize>(g: &mut LaneGroup<L>, s: usize) {
    std::mem::swap(&mut g.local_previous, &mut g.local_current);
    let (anchor_position, anchor_rotation) = &g.anchors[s];
    let n = g.n;
    let (x, q, local) = (&g.x[..n], &g.q[..n], &mut g.local_current[..n]);
    for ((x, q), (position, rotation)) in x.iter().zip(q).zip(local.iter_mut()) {
        // The offsets from the anchor first, on their own: in one loop with the single-precision work, the
        // compiler ran all of it at the double-precision width (4 lanes a register).
        let offset = (*x - anchor_position.to_f64()).to_f32();
        let (mut to_position, mut to_rotation) = (V3::ZERO, *q);
        for lane in 0..L {
            let [ax, ay, az, aw] = anchor_rotation.get(lane);
            let inverse = [-ax, -ay, -az, aw];
            to_position.set(lane, rotate(inverse, offset.get(lane)));
            to_rotation.set(lane, normalize(mul(inverse, q.get(lane))));
        }
        (*position, *rotation) = (to_position, to_rotation);
    }
}

/// `Chain::write_output` on every lane, at fraction `t` along the last two captured poses.
#[inline(always)]
pub fn write<const L: usize>(g: &mut LaneGroup<L>, t: f32) {
    let n = g.n;
    let t = F::splat(t);
    for j in 0..n {
        let ((_, from), (_, to)) = (g.local_previous[j], g.local_current[j]);
        g.output[j].1 = from.nlerp_shorter(to, t);
    }
    g.output[0].0 = g.local_previous[0].0.scale(F::splat(1.0) - t) + g.local_current[0].0.scale(t);
    bones(
        &g.local_previous[..n],
        &g.local_current[..n],
        &g.bone_axes[..n],
        &g.lengths[..n - 1],
        t.0[0],
        &mut g.output[..n],
    );
}

/// The bones of [`write`] after the root's position: each segment's direction blended between the last two
/// poses, the next joint's position along it, and the joint's rotation swung onto it. A loop over the lanes
/// whose body is one lane's scalar code (`scalar`; the lane types' operations in their order), like
/// [`capture`]: written with the lane types' operations, the per-lane conditions (`Mask`, an array of `bool`)
/// kept half of the phase in 128-bit instructions and a fifth of it on the stack. The same bits.
#[inline(always)]
fn bones<const L: usize>(
    previous: &[(V3<L>, Q<L>)],
    current: &[(V3<L>, Q<L>)],
    axes: &[V3<L>],
    lengths: &[F<L>],
    t: f32,
    output: &mut [(V3<L>, Q<L>)],
) {
    let lerp = |a: Vec, b: Vec| [a[0] * (1.0 - t) + b[0] * t, a[1] * (1.0 - t) + b[1] * t, a[2] * (1.0 - t) + b[2] * t];
    for j in 0..lengths.len() {
        let (from, to) = ((&previous[j].0, &previous[j + 1].0), (&current[j].0, &current[j + 1].0));
        let (axis, length, start, q) = (&axes[j], &lengths[j], output[j].0, output[j].1);
        let (mut next, mut blended, mut turned, mut swung) = (V3::ZERO, V3::ZERO, V3::ZERO, q);
        let mut folded = [false; L];
        for lane in 0..L {
            let (a, a_found) = direction(sub(from.1.get(lane), from.0.get(lane)));
            let (b, b_found) = direction(sub(to.1.get(lane), to.0.get(lane)));
            let (mixed, mixed_found) = direction(lerp(a, b));
            let axis = axis.get(lane);
            // `write_output`'s match: both directions, then whichever exists, then the bone axis.
            let either = if b_found {
                b
            } else if a_found {
                a
            } else {
                axis
            };
            let along = if a_found & b_found { if mixed_found { mixed } else { b } } else { either };
            let (p, l) = (start.get(lane), length.0[lane]);
            next.set(lane, [p[0] + along[0] * l, p[1] + along[1] * l, p[2] + along[2] * l]);
            blended.set(lane, along);
            // `math::swing_to`'s single-precision arc within a right angle; the lanes beyond it: `swing_folded`.
            let q = q.get(lane);
            let at = rotate(q, axis);
            let (cos, turn) = (dot(at, along), cross(at, along));
            swung.set(lane, normalize(mul([turn[0], turn[1], turn[2], 1.0 + cos], q)));
            turned.set(lane, at);
            // Not within a right angle, or NaN: `!(cos > 0.0)`.
            folded[lane] = cos.is_nan() | (cos <= 0.0);
        }
        output[j + 1].0 = next;
        let folded = Mask(folded);
        output[j].1 = if folded.any() { swing_folded(q, *axis, turned, blended, folded, swung) } else { swung };
    }
}

/// The lanes of `folded` (a bone more than a right angle from its segment: common on limp chains, whose
/// particles' orientations do not follow their segments) swung with `math::shortest_arc`'s arc: the body of
/// glam's `DQuat::from_rotation_arc` of the normalised vectors, lane by lane in a loop the compiler vectorises
/// (it was `math::swing_to` called lane by lane: 14 % of the limp 1000 x 16 frame, `perf record` of
/// `scene_cost 300 1000x16 limp`). The arc's 180-degree singularity, where glam picks an axis, takes
/// `math::swing_to` itself (rare).
#[inline(always)]
fn swing_folded<const L: usize>(
    q: Q<L>,
    axis: V3<L>,
    current: V3<L>,
    direction: V3<L>,
    folded: Mask<L>,
    swung: Q<L>,
) -> Q<L> {
    const ONE_MINUS_EPS: f64 = 1.0 - 2.0 * f64::EPSILON;
    let mut arcs = Q::IDENTITY;
    let mut singular = [false; L];
    for lane in 0..L {
        let from = Vec3::from_array(current.get(lane)).as_dvec3().normalize();
        let to = Vec3::from_array(direction.get(lane)).as_dvec3().normalize();
        let dot = from.dot(to);
        let c = from.cross(to);
        let arc = DQuat::from_xyzw(c.x, c.y, c.z, 1.0 + dot).normalize().as_quat();
        singular[lane] = dot < -ONE_MINUS_EPS;
        arcs.set(lane, if dot > ONE_MINUS_EPS { [0.0, 0.0, 0.0, 1.0] } else { arc.to_array() });
    }
    let mut swung = Q::select(folded, arcs.mul(q).normalize(), swung);
    for lane in (0..L).filter(|&lane| folded.0[lane] && singular[lane]) {
        let exact = swing_to(
            Quat::from_array(q.get(lane)),
            Vec3::from_array(axis.get(lane)),
            Vec3::from_array(direction.get(lane)),
        );
        swung.set(lane, exact.to_array());
    }
    swung
}

#[cfg(test)]
mod tests {
    use glam::{Quat, Vec3};

    use super::super::group::{GroupSettings, LaneGroup};
    use crate::core::chain::RenderInput;
    use crate::core::math::Transform;

    /// Two poses per lane, each lane its own: smooth bends, a segment of zero length (no direction) in one
    /// pose, then in both, and a bone axis pointing away from its segment (the swing beyond a right angle).
    fn poses(lane: usize, n: usize) -> (Vec<Transform>, Vec<Transform>, Vec<Vec3>) {
        let pose = |phase: f32| {
            let mut position = Vec3::new(0.01 * lane as f32, 0.0, 0.0);
            (0..n)
                .map(|j| {
                    let angle = phase + 0.3 * j as f32 + 0.17 * lane as f32;
                    let rotation = Quat::from_euler(glam::EulerRot::YXZ, angle, 0.5 * angle, -0.2 * angle);
                    let here = Transform::new(position, rotation);
                    let degenerate = (lane == 1 && j == 2 && phase > 0.0) || (lane == 2 && j == 3);
                    if !degenerate {
                        position += rotation * Vec3::new(0.0, 0.02 + 0.001 * j as f32, 0.0);
                    }
                    here
                })
                .collect::<Vec<_>>()
        };
        // Lane 3's joint 1: 120 degrees from its segment (at 180 the arc's axis is any perpendicular one).
        let folded = Quat::from_rotation_x(2.1) * Vec3::Y;
        let axes = (0..n).map(|j| if lane == 3 && j == 1 { folded } else { Vec3::new(0.1, 1.0, 0.05).normalize() });
        (pose(0.0), pose(0.05), axes.collect())
    }

    #[test]
    fn the_lanes_write_the_scalar_render_pose() {
        const L: usize = 8;
        let n = 6;
        let mut g = LaneGroup::<L>::default();
        g.begin(GroupSettings { joints: n, h: 1.0 / 240.0, iterations: 2, shape_matching: true, substeps: 2 });
        let lengths: Vec<f32> = (0..n - 1).map(|k| 0.02 + 0.001 * k as f32).collect();
        for lane in 0..L {
            let (previous, current, axes) = poses(lane, n);
            for j in 0..n {
                g.local_previous[j].0.set(lane, previous[j].position.to_array());
                g.local_previous[j].1.set(lane, previous[j].rotation.to_array());
                g.local_current[j].0.set(lane, current[j].position.to_array());
                g.local_current[j].1.set(lane, current[j].rotation.to_array());
                g.bone_axes[j].set(lane, axes[j].to_array());
            }
            for (k, &l) in lengths.iter().enumerate() {
                g.lengths[k].0[lane] = l;
            }
        }
        // 1 to 2: the pose carried on past the newest state (`chain::output_fraction`).
        for t in [0.0, 0.4, 1.0, 1.5, 1.99] {
            super::write(&mut g, t);
            for lane in 0..L {
                let (previous, current, axes) = poses(lane, n);
                let mut expected = vec![Transform::IDENTITY; n];
                let input = RenderInput { previous: &previous, current: &current, bone_axes: &axes, lengths: &lengths };
                input.pose(t, &mut expected);
                for (j, want) in expected.iter().enumerate() {
                    let position = Vec3::from_array(g.output[j].0.get(lane));
                    let rotation = Quat::from_array(g.output[j].1.get(lane));
                    let what = format!("t {t}, lane {lane}, joint {j}");
                    assert!((position - want.position).length() < 1e-7, "{what}: {position} vs {}", want.position);
                    // Component by component: `angle_between`'s arccosine cannot resolve a rounding difference.
                    let off = (glam::Vec4::from(rotation) - glam::Vec4::from(want.rotation)).abs().max_element();
                    assert!(off < 1e-6, "{what}: {rotation} vs {}", want.rotation);
                }
            }
        }
    }
}
