//! Shapes of a chain and their encoded form (SPEC 3.1).
//!
//! A shape is `n >= 2` joint transforms in the anchor frame. Its encoded form keeps what view shapes may
//! change (per-joint bend rotations `r_j` and orientations `o_j`); segment lengths and the root position
//! always come from the base shape, so any blend decodes to a chain of the base's lengths.

use glam::{Quat, Vec3};

use super::error::{Error, Result};
use super::math::{Transform, direction, normalized_rotation, shortest_arc};
use super::params::MAX_COORDINATE;

/// A validated shape: positions and unit orientations in the anchor frame.
#[derive(Debug, PartialEq)]
pub struct Shape {
    pub positions: Vec<Vec3>,
    pub orientations: Vec<Quat>,
}

/// By hand so that `clone_from` reuses the buffers: the step copies rest shapes every time they change, and
/// the derived `clone_from` would allocate each time.
impl Clone for Shape {
    fn clone(&self) -> Self {
        Self { positions: self.positions.clone(), orientations: self.orientations.clone() }
    }

    fn clone_from(&mut self, source: &Self) {
        self.positions.clone_from(&source.positions);
        self.orientations.clone_from(&source.orientations);
    }
}

/// Segments shorter than this fraction of the chain's extent count as zero length.
const MIN_RELATIVE_SEGMENT: f32 = 1e-6;

impl Shape {
    /// Validates joints: `n >= 2`, all finite, no null quaternion, no zero-length segment. Rotations are
    /// normalised.
    pub fn from_joints(joints: &[Transform]) -> Result<Self> {
        if joints.len() < 2 {
            return Err(Error::invalid_argument(format!("a chain needs at least 2 joints, got {}", joints.len())));
        }
        let mut positions = Vec::with_capacity(joints.len());
        let mut orientations = Vec::with_capacity(joints.len());
        for (i, joint) in joints.iter().enumerate() {
            if !joint.is_finite() {
                return Err(Error::invalid_argument(format!("joint {i} has a non-finite position or rotation")));
            }
            if joint.position.abs().max_element() > MAX_COORDINATE {
                return Err(Error::invalid_argument(format!("joint {i} lies beyond +-{MAX_COORDINATE} m")));
            }
            let Some(rotation) = normalized_rotation(joint.rotation) else {
                return Err(Error::invalid_argument(format!("joint {i} has a null rotation quaternion")));
            };
            positions.push(joint.position);
            orientations.push(rotation);
        }
        let extent = positions.iter().map(|p| (*p - positions[0]).length()).fold(0.0f32, f32::max);
        for j in 0..positions.len() - 1 {
            let len = (positions[j + 1] - positions[j]).length();
            if !(len > MIN_RELATIVE_SEGMENT * extent && len > f32::MIN_POSITIVE) {
                return Err(Error::invalid_argument(format!("segment {j} (joints {j}-{}) has zero length", j + 1)));
            }
        }
        Ok(Self { positions, orientations })
    }

    pub fn len(&self) -> usize {
        self.positions.len()
    }

    pub fn is_empty(&self) -> bool {
        self.positions.is_empty()
    }

    pub fn segment_lengths(&self) -> Vec<f32> {
        self.positions.windows(2).map(|w| (w[1] - w[0]).length()).collect()
    }

    /// Direction of the first segment: the fixed reference direction of the encoding.
    pub fn first_direction(&self) -> Vec3 {
        direction(self.positions[1] - self.positions[0]).unwrap_or(Vec3::Y)
    }
}

/// The part of a shape that view shapes control: bend rotations `r_0..r_{n-2}` and orientations
/// `o_0..o_{n-1}`.
#[derive(Debug, PartialEq)]
pub struct EncodedShape {
    pub bends: Vec<Quat>,
    pub orientations: Vec<Quat>,
}

/// By hand so that `clone_from` reuses the buffers (see [`Shape`]'s).
impl Clone for EncodedShape {
    fn clone(&self) -> Self {
        Self { bends: self.bends.clone(), orientations: self.orientations.clone() }
    }

    fn clone_from(&mut self, source: &Self) {
        self.bends.clone_from(&source.bends);
        self.orientations.clone_from(&source.orientations);
    }
}

/// What all shapes of a chain share: the root position, the reference direction of `r_0`, and the
/// segment lengths (all from the base shape).
#[derive(Clone, Debug, PartialEq)]
pub struct ShapeFrame {
    pub root: Vec3,
    pub reference: Vec3,
    pub lengths: Vec<f32>,
}

impl ShapeFrame {
    pub fn from_base(base: &Shape) -> Self {
        Self { root: base.positions[0], reference: base.first_direction(), lengths: base.segment_lengths() }
    }

    pub fn chain_length(&self) -> f32 {
        self.lengths.iter().sum()
    }
}

impl EncodedShape {
    /// Encodes `shape` with `reference` as the direction that `r_0` turns from.
    pub fn encode(shape: &Shape, reference: Vec3) -> Self {
        let n = shape.len();
        let mut bends = Vec::with_capacity(n - 1);
        let mut previous = reference;
        for j in 0..n - 1 {
            let dir = direction(shape.positions[j + 1] - shape.positions[j]).unwrap_or(previous);
            bends.push(shortest_arc(previous, dir));
            previous = dir;
        }
        Self { bends, orientations: shape.orientations.clone() }
    }

    /// An encoded shape of `n` joints filled with identities, for use as a reusable output buffer.
    pub fn identity(n: usize) -> Self {
        Self { bends: vec![Quat::IDENTITY; n - 1], orientations: vec![Quat::IDENTITY; n] }
    }

    /// Forward kinematics: root, then rotate the running direction by each `r_j` and step `l_j`.
    pub fn decode_into(&self, frame: &ShapeFrame, positions: &mut [Vec3]) {
        Self::decode_side_by_side([(self, frame, positions)]);
    }

    /// `N` shapes' [`decode_into`](Self::decode_into), joint by joint side by side: each decode is a chain of
    /// dependent steps (a rotation and a normalisation per joint) that alone leaves the core waiting on their
    /// latency; independent chains overlap. Each shape's arithmetic is its own decode's: the same bits.
    pub fn decode_side_by_side<const N: usize>(mut jobs: [(&Self, &ShapeFrame, &mut [Vec3]); N]) {
        let mut walks: [Walk; N] = std::array::from_fn(|i| {
            let (_, frame, positions) = &mut jobs[i];
            Walk::new(frame, positions)
        });
        let common = jobs.iter().map(|(shape, ..)| shape.bends.len()).min().unwrap_or(0);
        for j in 0..common {
            for (walk, (shape, frame, positions)) in walks.iter_mut().zip(jobs.iter_mut()) {
                walk.step(&shape.bends[j], frame, positions, j);
            }
        }
        for (walk, (shape, frame, positions)) in walks.iter_mut().zip(jobs.iter_mut()) {
            for (j, bend) in shape.bends.iter().enumerate().skip(common) {
                walk.step(bend, frame, positions, j);
            }
        }
    }

    pub fn decode(&self, frame: &ShapeFrame) -> Shape {
        let mut positions = vec![Vec3::ZERO; self.orientations.len()];
        self.decode_into(frame, &mut positions);
        Shape { positions, orientations: self.orientations.clone() }
    }

    /// Re-expresses `r_0` for a new reference direction, leaving the decoded shape unchanged.
    pub fn rebase_reference(&mut self, old_reference: Vec3, new_reference: Vec3) {
        let first = (self.bends[0] * old_reference).normalize();
        self.bends[0] = shortest_arc(new_reference, first);
    }
}

/// Where forward kinematics has got to: the running direction and the last joint placed.
struct Walk {
    running: Vec3,
    p: Vec3,
}

impl Walk {
    /// At the root, which it places.
    #[inline(always)]
    fn new(frame: &ShapeFrame, positions: &mut [Vec3]) -> Self {
        positions[0] = frame.root;
        Self { running: frame.reference, p: frame.root }
    }

    /// Turns by bend `j` and places joint `j + 1`.
    #[inline(always)]
    fn step(&mut self, bend: &Quat, frame: &ShapeFrame, positions: &mut [Vec3], j: usize) {
        // Renormalising bounds the drift of long chains to one rounding per joint.
        self.running = (*bend * self.running).normalize();
        self.p += self.running * frame.lengths[j];
        positions[j + 1] = self.p;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn joints_from(points: &[Vec3]) -> Vec<Transform> {
        points.iter().map(|p| Transform::new(*p, Quat::IDENTITY)).collect()
    }

    #[test]
    fn rejects_degenerate_input() {
        assert!(Shape::from_joints(&joints_from(&[Vec3::ZERO])).is_err());
        assert!(Shape::from_joints(&joints_from(&[Vec3::ZERO, Vec3::ZERO])).is_err());
        assert!(Shape::from_joints(&joints_from(&[Vec3::ZERO, Vec3::new(f32::NAN, 0.0, 0.0)])).is_err());
        let mut j = joints_from(&[Vec3::ZERO, Vec3::Y]);
        j[1].rotation = Quat::from_xyzw(0.0, 0.0, 0.0, 0.0);
        assert!(Shape::from_joints(&j).is_err());
    }

    #[test]
    fn normalises_rotations() {
        let mut j = joints_from(&[Vec3::ZERO, Vec3::Y]);
        j[0].rotation = Quat::from_xyzw(0.0, 0.0, 0.0, 3.0);
        let s = Shape::from_joints(&j).unwrap();
        assert_eq!(s.orientations[0], Quat::IDENTITY);
    }

    #[test]
    fn rebase_keeps_decoded_shape() {
        let shape = Shape::from_joints(&joints_from(&[Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0)])).unwrap();
        let frame = ShapeFrame::from_base(&shape);
        let mut enc = EncodedShape::encode(&shape, frame.reference);
        let new_ref = Vec3::new(0.0, 0.6, 0.8);
        enc.rebase_reference(frame.reference, new_ref);
        let frame2 = ShapeFrame { reference: new_ref, ..frame };
        let back = enc.decode(&frame2);
        for (a, b) in back.positions.iter().zip(&shape.positions) {
            assert!((*a - *b).length() < 1e-6);
        }
    }

    fn arb_chain() -> impl Strategy<Value = Vec<Transform>> {
        let step = (-1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0, 0.05f32..2.0);
        let rot = (-1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0);
        prop::collection::vec((step, rot), 2..40).prop_filter_map("degenerate", |items| {
            let mut p = Vec3::new(0.3, -0.2, 0.1);
            let mut out = Vec::new();
            for ((x, y, z, len), (a, b, c, d)) in items {
                let q = Quat::from_xyzw(a, b, c, d);
                if q.length() < 0.1 {
                    return None;
                }
                out.push(Transform::new(p, q.normalize()));
                let dir = direction(Vec3::new(x, y, z))?;
                p += dir * len;
            }
            Some(out)
        })
    }

    proptest! {
        /// Encoding then decoding reproduces a shape to float precision (relative to chain length).
        #[test]
        fn encode_decode_round_trip(joints in arb_chain()) {
            let shape = Shape::from_joints(&joints).unwrap();
            let frame = ShapeFrame::from_base(&shape);
            let back = EncodedShape::encode(&shape, frame.reference).decode(&frame);
            let tolerance = 4e-6 * frame.chain_length().max(1.0);
            for (a, b) in back.positions.iter().zip(&shape.positions) {
                prop_assert!((*a - *b).length() <= tolerance, "{a} vs {b}");
            }
            prop_assert_eq!(back.orientations, shape.orientations);
        }

        /// Shapes decoded side by side, of any lengths, give each the bits of its own decode.
        #[test]
        fn shapes_side_by_side_decode_as_each_alone(first in arb_chain(), second in arb_chain(), third in arb_chain()) {
            let encoded = |joints: &[Transform]| {
                let shape = Shape::from_joints(joints).unwrap();
                let frame = ShapeFrame::from_base(&shape);
                (EncodedShape::encode(&shape, frame.reference), frame)
            };
            let ((a, a_frame), (b, b_frame), (c, c_frame)) = (encoded(&first), encoded(&second), encoded(&third));
            let bits = |positions: &[Vec3]| positions.iter().flat_map(|p| p.to_array().map(f32::to_bits)).collect::<Vec<_>>();
            let (mut a_pair, mut b_pair) = (vec![Vec3::NAN; first.len()], vec![Vec3::NAN; second.len()]);
            EncodedShape::decode_side_by_side([(&a, &a_frame, &mut a_pair[..]), (&b, &b_frame, &mut b_pair[..])]);
            prop_assert_eq!(bits(&a_pair), bits(&a.decode(&a_frame).positions));
            prop_assert_eq!(bits(&b_pair), bits(&b.decode(&b_frame).positions));
            let mut quad: Vec<Vec<Vec3>> = [first.len(), second.len(), third.len(), first.len()]
                .iter()
                .map(|&n| vec![Vec3::NAN; n])
                .collect();
            let [q0, q1, q2, q3] = quad.get_disjoint_mut([0, 1, 2, 3]).unwrap();
            EncodedShape::decode_side_by_side([(&a, &a_frame, &mut q0[..]), (&b, &b_frame, &mut q1[..]), (&c, &c_frame, &mut q2[..]), (&a, &a_frame, &mut q3[..])]);
            prop_assert_eq!(bits(&quad[0]), bits(&a.decode(&a_frame).positions));
            prop_assert_eq!(bits(&quad[1]), bits(&b.decode(&b_frame).positions));
            prop_assert_eq!(bits(&quad[2]), bits(&c.decode(&c_frame).positions));
            prop_assert_eq!(bits(&quad[3]), bits(&a.decode(&a_frame).positions));
        }
    }
}
