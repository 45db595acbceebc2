//! The contact pass of a lane group's chains against spheres and capsules, the colliders of a dressed
//! character, with the lanes side by side: each segment's quick reject and closest-point test run on every
//! lane at once, and only a lane whose segment may touch takes `collision`'s scalar test and correction.
//!
//! Most pairs past the quick reject touch nothing (86 % of them in the resting hair of
//! `scene_cost 40 1000x16 colliders`: `docs/performance-history.md`, stop 42). The test that says so, the
//! screen, is `collision::segment_contact`'s arithmetic written in lanes operation for operation as glam
//! computes it on one chain (`Quat * Vec3` as [`Turn`]; no fused or reordered operations), in AVX2's vectors
//! (`screen_avx2`) for groups of 8, the only width that takes this pass (written in the generic lane types, it
//! compiled to two-lane vectors and did not pay: stop 43). The screen takes a collider's segments one after
//! another, each with the positions and drift the segments before left (stop 44; until then it screened every
//! segment up front, and after a lane's first contact all its later segments took the scalar test). So a lane
//! the screen clears is one the scalar test would clear, each lane still meets its (collider, segment) pairs in
//! the scalar pass's order, and a chain's bits are those of the scalar contact pass. Pre-stabilisation's first
//! pass ([`pre_stabilise`]) runs the same way, at the colliders' start pose.

use glam::DVec3;

use super::contacts::{LaneContacts, extract, write_back};
use super::group::LaneGroup;
use super::simd::{D, DV3, F, Mask, Q, V3};
use crate::core::collider::{ColliderShape, ColliderSweep};
use crate::core::collision::{self, ContactPass, OutsideCollider, Pose, SegmentEnds};

/// Whether the lane pass can take `sweep`: a sphere or a capsule that keeps the chain outside.
pub fn is_outside(sweep: &ColliderSweep) -> bool {
    matches!(sweep.shape, ColliderShape::Sphere { .. } | ColliderShape::Capsule { .. })
}

/// Lanes at a collider below which each takes the scalar test on every segment, unscreened.
const SCREEN_MIN_LANES: usize = 4;

/// The screen of the lanes of a mask against one collider (`screen_avx2::screen_all`, where the CPU has AVX2;
/// [`every_segment`] elsewhere): segment after segment, in the scalar pass's order, it tests each lane's segment
/// with the lane's positions and drift as they are then, and calls [`Resolve`] with the lanes whose segment may
/// touch.
pub type ScreenFn<const L: usize> = fn(
    &Screen<L>,
    Mask<L>,
    &mut [DV3<L>],
    &mut [DV3<L>],
    &[F<L>],
    &[(DV3<L>, D<L>)],
    &mut D<L>,
    F<L>,
    &mut Resolve<'_, L>,
);

/// The scalar test and correction of segment `k` of the lanes set in a bit mask, which may touch the collider:
/// moves their joints (start positions and positions) and adds to their drift.
pub type Resolve<'a, const L: usize> = dyn FnMut(usize, u32, &mut [DV3<L>], &mut [DV3<L>], &mut D<L>) + 'a;

/// One contact pass (`collision::collide`) on the lanes of `lanes`, whose chains can touch only spheres and
/// capsules. Returns each lane's pass.
#[inline(always)]
pub fn collide<const L: usize>(g: &mut LaneGroup<L>, lanes: Mask<L>, screen: ScreenFn<L>) -> [ContactPass; L] {
    let n = g.n;
    let LaneGroup { x, p, contacts, contact_radii, contact_bounds, lane_x, lane_p, .. } = g;
    let scratch = Scratch { radii: contact_radii, bounds: contact_bounds, lane_x, lane_p };
    pass(&mut x[..n], &mut p[..n], contacts, scratch, lanes, screen, Pose::End)
}

/// The first contact pass of pre-stabilisation (`collision::pre_stabilise`) on the lanes of `lanes`, whose chains
/// can touch only spheres and capsules: the start positions against the colliders at their start pose, from a
/// copy of them (`LaneGroup::contact_start`, which keeps what the pass did to it for the rounds that may follow).
/// Returns each lane's pass.
#[inline(always)]
pub fn pre_stabilise<const L: usize>(g: &mut LaneGroup<L>, lanes: Mask<L>, screen: ScreenFn<L>) -> [ContactPass; L] {
    let n = g.n;
    let LaneGroup { x, contact_start, contacts, contact_radii, contact_bounds, lane_x, lane_p, .. } = g;
    contact_start[..n].copy_from_slice(&x[..n]);
    let scratch = Scratch { radii: contact_radii, bounds: contact_bounds, lane_x, lane_p };
    pass(&mut contact_start[..n], &mut x[..n], contacts, scratch, lanes, screen, Pose::Start)
}

/// The group's buffers a pass works in besides the positions.
struct Scratch<'g, const L: usize> {
    radii: &'g [F<L>],
    bounds: &'g mut [(DV3<L>, D<L>)],
    lane_x: &'g mut Vec<DVec3>,
    lane_p: &'g mut Vec<DVec3>,
}

/// A contact pass of the lanes of `lanes` moving `p` (and `start`, where a joint was inside at the start),
/// against the colliders at their `pose`: `collision::collide_at`'s outside passes, lane by lane, bit for bit.
///
/// The colliders come in their order. For each, `screen` takes the segments one after another, testing every
/// lane's at once with its positions and drift as the segments before left them, and only a lane whose segment
/// it cannot clear takes the scalar test and correction: so each lane meets its (collider, segment) pairs in the
/// scalar pass's order, with the scalar pass's inputs. A lane whose root holds joints inside the collider (bug
/// 9) takes the scalar turn and tests instead, as does every lane at a collider with few lanes at it. The normals
/// of sliding joints are kept at the end pose only (pre-stabilisation has none).
#[inline(always)]
fn pass<const L: usize>(
    start: &mut [DV3<L>],
    p: &mut [DV3<L>],
    contacts: &mut [LaneContacts],
    scratch: Scratch<'_, L>,
    lanes: Mask<L>,
    screen: ScreenFn<L>,
    pose: Pose,
) -> [ContactPass; L] {
    let n = p.len();
    let mut passes = [ContactPass::nothing(0); L];
    let x = start;
    let Scratch { radii, bounds, lane_x, lane_p } = scratch;
    let (radii, bounds) = (&radii[..n], &mut bounds[..n - 1]);
    segment_bounds(x, p, radii, bounds);
    let bounds = &*bounds;
    let slop = F(std::array::from_fn(|lane| contacts[lane].slop));
    let mut drift = D::<L>::splat(0.0);
    // Each lane's next candidate; the colliders come in their order, as in the scalar pass.
    let mut cursor = [0usize; L];
    loop {
        let next = lanes_of(lanes).filter_map(|lane| contacts[lane].candidates.get(cursor[lane]).copied()).min();
        let Some(next) = next else { break };
        let mut here = Mask([false; L]);
        let mut first = L;
        for lane in lanes_of(lanes) {
            let contact = &contacts[lane];
            if contact.candidates.get(cursor[lane]) == Some(&next) {
                here.0[lane] = true;
                first = first.min(lane);
                cursor[lane] += 1;
            }
        }
        // Every lane's sweeps of a collider are copies of the same row.
        let sweep = collision::at(&contacts[first].sweeps[cursor[first] - 1], pose);
        for lane in lanes_of(here) {
            passes[lane].tested += n as u64 - 1;
        }
        let mut colliders = [None; L];
        let mut screened = Mask([false; L]);
        // With few lanes at this collider, the screen would do the work of all of them for those few.
        if count(here) >= SCREEN_MIN_LANES {
            for lane in lanes_of(here) {
                let collider = OutsideCollider::new(&sweep, &contacts[lane].input(), DVec3::from_array(p[0].get(lane)));
                // A lane whose root holds joints inside takes the scalar turn and tests.
                screened.0[lane] = collider.held.joints == 0;
                colliders[lane] = Some(collider);
            }
            if count(screened) < SCREEN_MIN_LANES {
                screened = Mask([false; L]);
            }
        }
        if screened.any() {
            let mut resolve = |k: usize, touching: u32, x: &mut [DV3<L>], p: &mut [DV3<L>], drift: &mut D<L>| {
                for lane in bits_of(touching) {
                    let collider = colliders[lane].as_ref().expect("a screened lane at the collider");
                    let moved = test_segment(
                        k,
                        lane,
                        x,
                        p,
                        bounds,
                        &sweep,
                        &contacts[lane],
                        collider,
                        drift.0[lane],
                        &mut passes[lane],
                    );
                    drift.0[lane] += moved;
                }
            };
            screen(&Screen::new(&sweep), screened, x, p, radii, bounds, &mut drift, slop, &mut resolve);
        }
        for lane in lanes_of(here.and(screened.not())) {
            let collider = colliders[lane].unwrap_or_else(|| {
                OutsideCollider::new(&sweep, &contacts[lane].input(), DVec3::from_array(p[0].get(lane)))
            });
            let lane_scratch = (&mut *lane_x, &mut *lane_p);
            scalar_turn(
                lane,
                x,
                p,
                bounds,
                &sweep,
                &mut contacts[lane],
                &collider,
                &mut drift.0[lane],
                &mut passes[lane],
                lane_scratch,
                pose,
            );
        }
    }
    passes
}

/// One lane's turn at a collider in `collision`'s scalar code: the held run's turn where its root holds joints
/// inside (bug 9), then the test of every segment past them.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn scalar_turn<const L: usize>(
    lane: usize,
    x: &mut [DV3<L>],
    p: &mut [DV3<L>],
    bounds: &[(DV3<L>, D<L>)],
    sweep: &ColliderSweep,
    contact: &mut LaneContacts,
    collider: &OutsideCollider,
    drift: &mut f64,
    pass: &mut ContactPass,
    (lane_x, lane_p): (&mut Vec<DVec3>, &mut Vec<DVec3>),
    pose: Pose,
) {
    let n = p.len();
    // Segments before `held` join joints the root holds inside (or the root itself).
    let held = collider.held.joints;
    if held > 0 && held < n - 1 {
        // The held run's last segment: the scalar turn (rare), then the segment's test as any other.
        let k = held;
        extract(x, lane, lane_x);
        extract(p, lane, lane_p);
        let bound = (DVec3::from_array(bounds[k].0.get(lane)), bounds[k].1.0[lane]);
        let mut normals = std::mem::take(&mut contact.normals);
        collision::turn_held(
            lane_x,
            lane_p,
            sweep,
            &contact.input(),
            collider,
            bound,
            drift,
            (pose == Pose::End).then_some(&mut normals[..]),
            pass,
        );
        contact.normals = normals;
        write_back(lane_x, lane, x);
        write_back(lane_p, lane, p);
    }
    for k in held..n - 1 {
        *drift += test_segment(k, lane, x, p, bounds, sweep, contact, collider, *drift, pass);
    }
}

/// `collision::segment_contact` and, on a contact, `resolve_segment` for segment `k` of `lane`: returns how far
/// it moved the lane's joints (zero without a contact).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn test_segment<const L: usize>(
    k: usize,
    lane: usize,
    x: &mut [DV3<L>],
    p: &mut [DV3<L>],
    bounds: &[(DV3<L>, D<L>)],
    sweep: &ColliderSweep,
    contact: &LaneContacts,
    collider: &OutsideCollider,
    drift: f64,
    pass: &mut ContactPass,
) -> f64 {
    let input = contact.input();
    let mut ends = SegmentEnds {
        start: [x[k].get(lane), x[k + 1].get(lane)].map(DVec3::from_array),
        p: [p[k].get(lane), p[k + 1].get(lane)].map(DVec3::from_array),
    };
    let bound = (DVec3::from_array(bounds[k].0.get(lane)), bounds[k].1.0[lane]);
    let Some(found) = collision::segment_contact(k, bound, &ends, sweep, &input, collider, drift) else {
        return 0.0;
    };
    let moved = collision::resolve_segment(k, &found, sweep, input.friction, &mut ends, pass);
    x[k].set(lane, ends.start[0].to_array());
    x[k + 1].set(lane, ends.start[1].to_array());
    p[k].set(lane, ends.p[0].to_array());
    p[k + 1].set(lane, ends.p[1].to_array());
    moved
}

/// The screen where there is none: every segment of the lanes of `lanes` may touch, so each lane takes the scalar
/// test on all of them.
#[allow(clippy::too_many_arguments)]
pub fn every_segment<const L: usize>(
    lanes: Mask<L>,
    start: &mut [DV3<L>],
    p: &mut [DV3<L>],
    segments: usize,
    drift: &mut D<L>,
    resolve: &mut Resolve<'_, L>,
) {
    let lanes = lanes.0.iter().enumerate().fold(0, |bits, (lane, &set)| bits | (set as u32) << lane);
    for k in 0..segments {
        resolve(k, lanes, start, p, drift);
    }
}

/// The lanes set in `mask`.
fn count<const L: usize>(mask: Mask<L>) -> usize {
    mask.0.iter().filter(|&&set| set).count()
}

/// The lanes set in a bit mask, in order.
#[inline(always)]
fn bits_of(mut bits: u32) -> impl Iterator<Item = usize> {
    std::iter::from_fn(move || {
        (bits != 0).then(|| {
            let lane = bits.trailing_zeros() as usize;
            bits &= bits - 1;
            lane
        })
    })
}

/// The lanes set in `mask`, in order (from a bit mask: two branches per lane set, not per lane).
#[inline(always)]
fn lanes_of<const L: usize>(mask: Mask<L>) -> impl Iterator<Item = usize> {
    bits_of(mask.0.iter().enumerate().fold(0u32, |bits, (lane, &set)| bits | (set as u32) << lane))
}

/// `collision::SegmentBounds::compute` on every lane.
#[inline(always)]
fn segment_bounds<const L: usize>(start: &[DV3<L>], p: &[DV3<L>], radii: &[F<L>], bounds: &mut [(DV3<L>, D<L>)]) {
    let length = |v: DV3<L>| v.length_squared().sqrt();
    let mut travel_before = length(p[0] - start[0]);
    for (k, bound) in bounds.iter_mut().enumerate() {
        let half = length(p[k + 1] - p[k]) * 0.5;
        let travel_after = length(p[k + 1] - start[k + 1]);
        let travel = travel_before.zip(travel_after, f64::max);
        travel_before = travel_after;
        let thickness = radii[k].zip(radii[k + 1], f32::max).to_f64();
        *bound = ((p[k] + p[k + 1]) * 0.5, thickness + half + travel);
    }
}

/// One collider of the pass, as the screen needs it (`OutsideCollider`'s quick-reject terms and the sweep's
/// frames), splat across the lanes. Only `screen_avx2` reads it: elsewhere every segment takes the scalar test.
#[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
pub struct Screen<const L: usize> {
    pub(super) centre: DV3<L>,
    pub(super) start_centre: DV3<L>,
    /// The inverse rotations of the sweep's end and start poses.
    pub(super) to_end: Turn<L>,
    pub(super) to_start: Turn<L>,
    pub(super) solid: f64,
    pub(super) collider_travel: f64,
    pub(super) radius: F<L>,
    pub(super) half_height: F<L>,
    pub(super) axis: (V3<L>, V3<L>),
}

impl<const L: usize> Screen<L> {
    #[inline(always)]
    fn new(sweep: &ColliderSweep) -> Self {
        let (radius, half_height) = sweep.shape.capsule().expect("outside colliders are spheres or capsules");
        let splat = |v: DVec3| DV3 { x: D::splat(v.x), y: D::splat(v.y), z: D::splat(v.z) };
        let inverse = |q: glam::Quat| {
            let q = q.inverse();
            Turn::new(Q { x: F::splat(q.x), y: F::splat(q.y), z: F::splat(q.z), w: F::splat(q.w) })
        };
        let axis_end = |y: f32| V3 { x: F::splat(0.0), y: F::splat(y), z: F::splat(0.0) };
        Self {
            centre: splat(sweep.end.centre),
            start_centre: splat(sweep.start.centre),
            to_end: inverse(sweep.end.rotation),
            to_start: inverse(sweep.start.rotation),
            solid: (radius + half_height) as f64,
            collider_travel: (sweep.end.centre - sweep.start.centre).length(),
            radius: F::splat(radius),
            half_height: F::splat(half_height),
            axis: (axis_end(-half_height), axis_end(half_height)),
        }
    }
}

/// `Q::rotate` (glam's `Quat * Vec3`) by one quaternion, with what does not depend on the vector computed once:
/// `screen_avx2` turns by it with the same operations on the same numbers, so the same bits.
#[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
pub(super) struct Turn<const L: usize> {
    pub(super) b: V3<L>,
    /// `w * w - b.b`
    pub(super) scale: F<L>,
    /// `2 w`
    pub(super) twice_w: F<L>,
}

impl<const L: usize> Turn<L> {
    #[inline(always)]
    fn new(q: Q<L>) -> Self {
        let b = q.xyz();
        Self { b, scale: q.w * q.w - b.dot(b), twice_w: q.w * 2.0 }
    }
}

#[cfg(test)]
mod tests {
    use glam::{DVec3, Quat};

    use super::super::simd::{D, DV3, F, Mask};
    use super::{Screen, segment_bounds};
    use crate::core::collider::{ColliderPose, ColliderShape, ColliderSweep};
    use crate::core::collision::{ContactInput, OutsideCollider, SegmentEnds, segment_contact};

    const LANES: usize = 8;
    const JOINTS: usize = 6;

    /// xorshift64*: the same cases on every run.
    struct Numbers(u64);

    impl Numbers {
        fn unit(&mut self) -> f64 {
            self.0 ^= self.0 >> 12;
            self.0 ^= self.0 << 25;
            self.0 ^= self.0 >> 27;
            (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
        }

        fn between(&mut self, low: f64, high: f64) -> f64 {
            low + (high - low) * self.unit()
        }

        fn direction(&mut self) -> DVec3 {
            loop {
                let v = DVec3::new(self.between(-1.0, 1.0), self.between(-1.0, 1.0), self.between(-1.0, 1.0));
                if v.length_squared() > 1e-3 && v.length_squared() <= 1.0 {
                    return v.normalize();
                }
            }
        }

        fn rotation(&mut self) -> Quat {
            let axis = self.direction().as_vec3();
            Quat::from_axis_angle(axis, self.between(0.0, std::f64::consts::TAU) as f32)
        }
    }

    /// A sphere or capsule that moves and turns a little during the substep.
    fn sweep(numbers: &mut Numbers) -> ColliderSweep {
        let radius = numbers.between(0.04, 0.1) as f32;
        let shape = if numbers.unit() < 0.5 {
            ColliderShape::Sphere { radius }
        } else {
            ColliderShape::Capsule { radius, half_height: numbers.between(0.02, 0.1) as f32 }
        };
        let end = ColliderPose { centre: numbers.direction() * 0.01, rotation: numbers.rotation() };
        let turn = Quat::from_axis_angle(numbers.direction().as_vec3(), numbers.between(0.0, 0.2) as f32);
        let start = ColliderPose { centre: end.centre + numbers.direction() * 0.005, rotation: turn * end.rotation };
        ColliderSweep { shape, start, end }
    }

    /// Per lane, a chain of `JOINTS` joints (positions at the start of the substep and now), its radii and its
    /// rest lengths, rooted around the collider.
    struct Chains {
        start: Vec<DV3<LANES>>,
        p: Vec<DV3<LANES>>,
        radii: Vec<F<LANES>>,
        lengths: Vec<[f32; LANES]>,
    }

    fn chains(numbers: &mut Numbers) -> Chains {
        let mut c = Chains {
            start: vec![DV3::ZERO; JOINTS],
            p: vec![DV3::ZERO; JOINTS],
            radii: vec![F([0.0; LANES]); JOINTS],
            lengths: vec![[0.0; LANES]; JOINTS - 1],
        };
        for lane in 0..LANES {
            let mut joint = numbers.direction() * numbers.between(0.06, 0.4);
            for j in 0..JOINTS {
                if j > 0 {
                    let length = numbers.between(0.01, 0.05);
                    joint += numbers.direction() * length;
                    c.lengths[j - 1][lane] = length as f32;
                }
                c.p[j].set(lane, joint.to_array());
                let moved = if j == 0 { joint } else { joint + numbers.direction() * numbers.between(0.0, 0.03) };
                c.start[j].set(lane, moved.to_array());
                c.radii[j].0[lane] = numbers.between(0.0, 0.01) as f32;
            }
        }
        c
    }

    /// A random collider, lanes of chains near it, and their segments' bounds.
    fn case(numbers: &mut Numbers) -> (ColliderSweep, Chains, Vec<(DV3<LANES>, D<LANES>)>) {
        let sweep = sweep(numbers);
        let c = chains(numbers);
        let mut bounds = vec![(DV3::ZERO, D([0.0; LANES])); JOINTS - 1];
        segment_bounds(&c.start, &c.p, &c.radii, &mut bounds);
        (sweep, c, bounds)
    }

    /// A segment the screen clears is one whose scalar test finds no contact, given the same positions and drift (the
    /// pass resolves nothing here). Where the CPU has AVX2 it clears most segments; elsewhere it flags them all.
    #[test]
    fn the_screen_clears_only_segments_the_scalar_test_clears() {
        let mut numbers = Numbers(0x9e37_79b9_7f4a_7c15);
        let (mut flagged, mut cleared, mut touching) = (0, 0, 0);
        for _ in 0..400 {
            let (sweep, c, bounds) = case(&mut numbers);
            let drift = D(std::array::from_fn(|_| if numbers.unit() < 0.5 { 0.0 } else { numbers.between(0.0, 0.05) }));
            let slop = F([1e-4; LANES]);
            let screen = Screen::new(&sweep);
            let all = Mask([true; LANES]);
            // Nothing is resolved: every segment is screened with the same positions and drift.
            let mut maybe = [0u32; JOINTS - 1];
            let (mut start, mut p, mut screened_drift) = (c.start.clone(), c.p.clone(), drift);
            let mut record = |k: usize, lanes: u32, _: &mut [DV3<LANES>], _: &mut [DV3<LANES>], _: &mut D<LANES>| {
                assert_eq!(maybe[k], 0, "segment {k} screened twice");
                maybe[k] = lanes;
            };
            super::super::screen8(
                &screen,
                all,
                &mut start,
                &mut p,
                &c.radii,
                &bounds,
                &mut screened_drift,
                slop,
                &mut record,
            );
            for lane in 0..LANES {
                let radii: Vec<f32> = c.radii.iter().map(|r| r.0[lane]).collect();
                let lengths: Vec<f32> = c.lengths.iter().map(|l| l[lane]).collect();
                let input =
                    ContactInput { colliders: &[sweep], radii: &radii, lengths: &lengths, friction: 0.3, slop: 1e-4 };
                let at = |v: &DV3<LANES>| DVec3::from_array(v.get(lane));
                let collider = OutsideCollider::new(&sweep, &input, at(&c.p[0]));
                // A lane whose root holds joints takes the scalar turn, unscreened (`pass`); the screen does not
                // know the rule of the segment leaving the held joints.
                let first = collider.held.joints + (collider.held.joints > 0) as usize;
                for k in first..JOINTS - 1 {
                    let ends = SegmentEnds {
                        start: [at(&c.start[k]), at(&c.start[k + 1])],
                        p: [at(&c.p[k]), at(&c.p[k + 1])],
                    };
                    let bound = (at(&bounds[k].0), bounds[k].1.0[lane]);
                    let found = segment_contact(k, bound, &ends, &sweep, &input, &collider, drift.0[lane]);
                    if maybe[k] & 1 << lane != 0 {
                        flagged += 1;
                    } else {
                        cleared += 1;
                        assert!(found.is_none(), "segment {k} of lane {lane} cleared but touching");
                    }
                    touching += found.is_some() as usize;
                }
            }
        }
        // The cases reach both sides of the screen's decision.
        assert!(touching > 1000 && flagged >= touching, "{flagged} {cleared} {touching}");
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            assert!(cleared > 10 * touching, "{flagged} {cleared} {touching}");
            return;
        }
        assert_eq!(cleared, 0, "no screen: every segment flagged");
    }

    /// The screen walks the segments in order and reads what the contacts before moved: at each segment it calls
    /// back, a contact here moves the reported lanes' joints (start positions and positions of the segment's
    /// ends, by up to 2 cm, or towards the collider) and adds to their drift, and the lanes it left out must be ones whose scalar test,
    /// on the positions and drift as they are then, finds no contact. Some lanes are outside the mask and must
    /// never be reported. Without AVX2 (an aarch64 build, say) there is no screen: every segment of every lane in
    /// the mask is reported.
    #[test]
    fn the_screen_reads_the_positions_and_drift_the_contacts_before_left() {
        let mut numbers = Numbers(0x2545_f491_4f6c_dd1d);
        let (mut checked, mut reported, mut moved, mut offered) = (0, 0, 0, 0);
        for _ in 0..1000 {
            let (sweep, c, bounds) = case(&mut numbers);
            let (mut start, mut p) = (c.start.clone(), c.p.clone());
            let mut drift = D([0.0; LANES]);
            let slop = F([1e-4; LANES]);
            let mask: Mask<LANES> = Mask(std::array::from_fn(|_| numbers.unit() < 0.8));
            let inputs: Vec<(Vec<f32>, Vec<f32>)> = (0..LANES)
                .map(|lane| (c.radii.iter().map(|r| r.0[lane]).collect(), c.lengths.iter().map(|l| l[lane]).collect()))
                .collect();
            let input = |lane: usize| ContactInput {
                colliders: std::slice::from_ref(&sweep),
                radii: &inputs[lane].0,
                lengths: &inputs[lane].1,
                friction: 0.3,
                slop: 1e-4,
            };
            let colliders: Vec<OutsideCollider> = (0..LANES)
                .map(|lane| OutsideCollider::new(&sweep, &input(lane), DVec3::from_array(c.p[0].get(lane))))
                .collect();
            // Lanes whose root holds joints are never screened (`pass`).
            let mask: Mask<LANES> = Mask(std::array::from_fn(|lane| mask.0[lane] && colliders[lane].held.joints == 0));
            offered += mask.0.iter().filter(|&&set| set).count() * (JOINTS - 1);
            // Every segment up to `k`, of every lane in the mask, but those reported at `k`, tested on the state
            // as the screen saw it (nothing moves between two calls).
            let mut next = 0;
            let mut check_up_to =
                |k: usize, reported_here: u32, start: &[DV3<LANES>], p: &[DV3<LANES>], drift: &D<LANES>| {
                    for j in next..=k.min(JOINTS - 2) {
                        for lane in (0..LANES).filter(|&lane| mask.0[lane]) {
                            if j == k && reported_here & 1 << lane != 0 {
                                continue;
                            }
                            let at = |v: &DV3<LANES>| DVec3::from_array(v.get(lane));
                            let ends = SegmentEnds {
                                start: [at(&start[j]), at(&start[j + 1])],
                                p: [at(&p[j]), at(&p[j + 1])],
                            };
                            let bound = (at(&bounds[j].0), bounds[j].1.0[lane]);
                            let found =
                                segment_contact(j, bound, &ends, &sweep, &input(lane), &colliders[lane], drift.0[lane]);
                            assert!(found.is_none(), "segment {j} of lane {lane} left out but touching");
                            checked += 1;
                        }
                    }
                    next = k + 1;
                };
            let mut record =
                |k: usize, lanes: u32, start: &mut [DV3<LANES>], p: &mut [DV3<LANES>], drift: &mut D<LANES>| {
                    check_up_to(k, lanes, start, p, drift);
                    for lane in (0..LANES).filter(|&lane| lanes & 1 << lane != 0) {
                        assert!(mask.0[lane], "lane {lane} reported outside the mask");
                        reported += 1;
                        if numbers.unit() < 0.5 {
                            continue;
                        }
                        moved += 1;
                        let mut push = 0.0;
                        for joint in [k, k + 1].into_iter().filter(|&joint| joint > 0) {
                            // Towards the collider, or anywhere: a far joint may come within reach.
                            let to_centre = sweep.end.centre - DVec3::from_array(p[joint].get(lane));
                            let step = to_centre * numbers.between(0.0, 1.0) * numbers.between(0.0, 1.0).round()
                                + numbers.direction() * numbers.between(0.0, 0.02);
                            push += step.length();
                            for v in [&mut start[joint], &mut p[joint]] {
                                v.set(lane, (DVec3::from_array(v.get(lane)) + step).to_array());
                            }
                        }
                        drift.0[lane] += push;
                    }
                };
            super::super::screen8(
                &Screen::new(&sweep),
                mask,
                &mut start,
                &mut p,
                &c.radii,
                &bounds,
                &mut drift,
                slop,
                &mut record,
            );
            check_up_to(JOINTS - 1, 0, &start, &p, &drift);
        }
        let counts = format!("{checked} segments checked, {reported} reported, {moved} moved, {offered} offered");
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            assert!(moved > 500 && checked > 20000, "{counts}");
            return;
        }
        // No screen (`every_segment`): every segment of every lane in the mask goes to the scalar test.
        assert!(checked == 0 && reported == offered && moved > 500, "{counts}");
    }
}
