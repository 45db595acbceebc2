//! The contact pass (SPEC 3.7): pushes a chain's particles and segments out of (or, for inside colliders,
//! back into) the colliders it can touch, with Coulomb friction, inside the solver iterations.
//!
//! Segments, not only particles, are tested against spheres and capsules, and each contact is found
//! continuously in the collider's own frame: the material point's position at the start of the substep
//! (under the collider's start pose) and at the end (under its end pose) span the relative motion, and a
//! point that crossed the surface on the way is put back on the side it came from. So neither a fast chain
//! nor a fast collider (a swinging arm) skips over the other between substeps.

use glam::{DQuat, DVec3, Vec3};

use super::buffers::reserve_total;
use super::collider::{ColliderShape, ColliderSweep};

/// Below this share of a root segment's length from its kinematic end, a contact cannot be resolved by
/// turning the segment (the lever would multiply the push); the tip particle is tested instead.
pub(crate) const ROOT_LEVER_MIN: f32 = 0.25;

/// A joint that the chain from the root could lift clear of a collider only by pointing within 60 degrees of
/// straight out (cos 60° = 0.5 of its rest length along the chain gained as distance) is left inside: near
/// that straight line a push on the joint barely turns the chain (the lever of `ROOT_LEVER_MIN` again), so the
/// contact and the lengths would trade the overlap back and forth for every round of every substep.
const CLEARING_SLANT: f32 = 0.5;

/// A contact next to the joints the root holds turns them about the root only where the normal is at least this
/// sine away from the lever (the turn is then at most 4 times the push along the arc); otherwise it pushes.
const MIN_TURN_LEVER: f32 = 0.25;
/// Largest turn (radians) of the held joints in one step of [`turn_held_run`].
const MAX_TURN: f64 = 0.5;
/// Turns at most per contact next to the held joints.
const TURN_STEPS: usize = 3;

/// What the contact pass needs of a chain besides its positions.
pub struct ContactInput<'a> {
    /// This substep's sweeps of the colliders the chain can touch.
    pub colliders: &'a [ColliderSweep],
    /// Collision radius of each particle (m, already scaled).
    pub radii: &'a [f32],
    /// Rest length of each segment (m), as the inextensibility solve keeps them: how far a joint can be from
    /// the kinematic root.
    pub lengths: &'a [f32],
    /// Coulomb friction coefficient.
    pub friction: f32,
    /// How deep (m) a joint must have been at the start of the substep to count as overlapping since then.
    /// Joints that the last substep left on a surface are inside or outside it by rounding only; without
    /// this margin that rounding would decide whether their next push becomes velocity.
    pub slop: f32,
}

/// One Gauss-Seidel pass over the contacts. `start` are the positions at the start of the substep, `p` the
/// current estimate of its end. Particle 0 is kinematic and never moved.
///
/// A joint that was already inside at the start of the substep is pushed out with `start` moving along, so
/// the push does not become velocity (see also [`pre_stabilise`]). A joint that should slide on a collider in
/// the lengths solves of the contact rounds (`inextensible::solve_sliding`) gets its world normal in
/// `normals` (one per particle; the others are left as they are): the first joint past those the root holds
/// inside a collider (see [`held_by_root`]) once its contact turned them.
pub fn collide(
    start: &mut [DVec3],
    p: &mut [DVec3],
    input: &ContactInput<'_>,
    bounds: &mut SegmentBounds,
    normals: &mut [Vec3],
) -> ContactPass {
    collide_at(start, p, input, Pose::End, bounds, Some(normals))
}

/// Each segment's quick-reject bound for one contact pass, shared by every sphere and capsule the pass
/// tests (computing it per collider cost three square roots per segment and collider). Reusable scratch.
#[derive(Default)]
pub struct SegmentBounds {
    /// Per segment: its midpoint, and how far from it the segment and its particles can reach during the
    /// substep (half its length, the larger travel of its ends since the substep's start, its thickness).
    bounds: Vec<(DVec3, f64)>,
}

impl SegmentBounds {
    pub fn reserve(&mut self, segments: usize) {
        reserve_total(&mut self.bounds, segments);
    }

    fn compute(&mut self, start: &[DVec3], p: &[DVec3], radii: &[f32]) {
        self.bounds.clear();
        // Each joint's travel once, for the two segments it ends.
        let mut travel_before = (p[0] - start[0]).length();
        for k in 0..p.len() - 1 {
            let half = (p[k + 1] - p[k]).length() * 0.5;
            let travel_after = (p[k + 1] - start[k + 1]).length();
            let travel = travel_before.max(travel_after);
            travel_before = travel_after;
            let thickness = radii[k].max(radii[k + 1]) as f64;
            self.bounds.push((p[k].midpoint(p[k + 1]), thickness + half + travel));
        }
    }
}

/// Which of a sweep's poses the contacts are resolved against.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(crate) enum Pose {
    /// The end of the substep: the normal case.
    End,
    /// The start: pre-stabilisation of the positions the substep starts from.
    Start,
}

/// Pre-stabilisation (Macklin et al. 2014, "Unified Particle Physics for Real-Time Applications", 4.4): joints
/// that start a substep inside a collider (it was created on the chain, it or the chain teleported, the
/// chain was enabled inside it) are moved out together with the rest of the chain, in position only, with
/// the colliders at their start pose. Their velocities are untouched, so a deep overlap is resolved without
/// flinging the chain away at depth / h. `scratch` must hold as many positions as `x`. Returns whether
/// anything was deeper inside than `settled`.
pub fn pre_stabilise(
    x: &mut [DVec3],
    scratch: &mut [DVec3],
    input: &ContactInput<'_>,
    rounds: u32,
    keep_lengths: impl FnMut(&[DVec3], &mut [DVec3]),
    settled: f32,
    bounds: &mut SegmentBounds,
) -> bool {
    scratch.copy_from_slice(x);
    let pass = collide_at(scratch, x, input, Pose::Start, bounds, None);
    // Joints left on a surface by the last substep touch it within rounding: only a real overlap needs rounds.
    if pass.deepest <= settled {
        return false;
    }
    pre_stabilise_rounds(x, scratch, input, rounds, keep_lengths, settled, bounds);
    true
}

/// The rounds of [`pre_stabilise`] after its first contact pass found an overlap deeper than `settled`
/// (`scratch` as that pass left it): lengths, then contacts, until they settle.
pub fn pre_stabilise_rounds(
    x: &mut [DVec3],
    scratch: &mut [DVec3],
    input: &ContactInput<'_>,
    rounds: u32,
    mut keep_lengths: impl FnMut(&[DVec3], &mut [DVec3]),
    settled: f32,
    bounds: &mut SegmentBounds,
) {
    for _ in 1..rounds {
        keep_lengths(scratch, x);
        let pass = collide_at(scratch, x, input, Pose::Start, bounds, None);
        if pass.deepest <= settled {
            break;
        }
    }
}

fn collide_at(
    start: &mut [DVec3],
    p: &mut [DVec3],
    input: &ContactInput<'_>,
    pose: Pose,
    bounds: &mut SegmentBounds,
    mut normals: Option<&mut [Vec3]>,
) -> ContactPass {
    let mut result = ContactPass { tested: 0, touching: false, deepest: 0.0, moved_start: false, sliding: false };
    let outside =
        |sweep: &ColliderSweep| matches!(sweep.shape, ColliderShape::Sphere { .. } | ColliderShape::Capsule { .. });
    if input.colliders.iter().any(outside) {
        bounds.compute(start, p, input.radii);
    }
    // How far the pass has moved particles and start positions since the bounds were computed, summed: the
    // quick reject widens by three times that to stay conservative (a segment's midpoint, half length and
    // travel each change by at most the sum).
    let mut drift = 0.0;
    for sweep in input.colliders {
        let pass = match sweep.shape {
            ColliderShape::Plane => collide_plane(start, p, &at(sweep, pose), input, &mut drift),
            ColliderShape::InsideSphere { .. } | ColliderShape::InsideCapsule { .. } => {
                collide_inside(start, p, &at(sweep, pose), input, &mut drift)
            }
            ColliderShape::Sphere { .. } | ColliderShape::Capsule { .. } => {
                collide_outside(start, p, &at(sweep, pose), input, &bounds.bounds, &mut drift, normals.as_deref_mut())
            }
        };
        result.tested += pass.tested;
        result.touching |= pass.touching;
        result.deepest = result.deepest.max(pass.deepest);
        result.moved_start |= pass.moved_start;
        result.sliding |= pass.sliding;
    }
    result
}

pub(crate) fn at(sweep: &ColliderSweep, pose: Pose) -> ColliderSweep {
    match pose {
        Pose::End => *sweep,
        Pose::Start => ColliderSweep { end: sweep.start, ..*sweep },
    }
}

/// What a contact pass found.
#[derive(Clone, Copy, Debug)]
pub struct ContactPass {
    /// (segment or particle, collider) pairs tested.
    pub tested: u64,
    /// Some pair was in contact and was corrected.
    pub touching: bool,
    /// The largest correction made (m).
    pub deepest: f32,
    /// Some start position was moved too (a joint inside since the start of the substep).
    pub moved_start: bool,
    /// Some joint got a normal to slide along (see [`collide`]).
    pub sliding: bool,
}

impl ContactPass {
    /// A pass that tested `tested` pairs and touched nothing.
    pub(crate) const fn nothing(tested: u64) -> Self {
        Self { tested, touching: false, deepest: 0.0, moved_start: false, sliding: false }
    }
}

fn collide_plane(
    start: &mut [DVec3],
    p: &mut [DVec3],
    sweep: &ColliderSweep,
    input: &ContactInput<'_>,
    drift: &mut f64,
) -> ContactPass {
    let mut touching = false;
    let mut deepest = 0.0f32;
    let mut moved_start = false;
    let root_height = sweep.end.to_local(p[0]).y;
    let held = if root_height < input.radii[1] {
        held_by_root(input.lengths, |j, along| root_height + along * CLEARING_SLANT < input.radii[j]).joints
    } else {
        0
    };
    let free = held + 1..p.len();
    let joints = p[free.clone()].iter_mut().zip(&mut start[free.clone()]).zip(&input.radii[free]);
    for ((p, start), &radius) in joints {
        let local = sweep.end.to_local(*p);
        let depth = radius - local.y;
        if depth > 0.0 {
            touching = true;
            let moved = sweep.start.to_local(*start);
            let overlapping_at_start = moved.y < radius - input.slop;
            deepest = deepest.max(depth);
            moved_start |= overlapping_at_start;
            let contact = Contact { normal: Vec3::Y, depth, overlapping_at_start };
            *drift += contact.push_particle(start, p, sweep, local, moved, input.friction);
        }
    }
    ContactPass { tested: p.len() as u64 - 1, touching, deepest, moved_start, sliding: false }
}

fn collide_inside(
    start: &mut [DVec3],
    p: &mut [DVec3],
    sweep: &ColliderSweep,
    input: &ContactInput<'_>,
    drift: &mut f64,
) -> ContactPass {
    let mut touching = false;
    let mut deepest = 0.0f32;
    let mut moved_start = false;
    let (radius, half_height) = sweep.shape.capsule().expect("inside colliders are capsules");
    let root_distance = distance_from_axis(sweep.end.to_local(p[0]), half_height);
    let held = held_by_root(input.lengths, |j, along| {
        root_distance - along * CLEARING_SLANT > (radius - input.radii[j]).max(0.0)
    })
    .joints;
    for j in held + 1..p.len() {
        let local = sweep.end.to_local(p[j]);
        let axis_point = Vec3::new(0.0, local.y.clamp(-half_height, half_height), 0.0);
        let offset = local - axis_point;
        let distance = offset.length();
        let limit = (radius - input.radii[j]).max(0.0);
        if distance > limit {
            touching = true;
            let moved = sweep.start.to_local(start[j]);
            let moved_axis_point = Vec3::new(0.0, moved.y.clamp(-half_height, half_height), 0.0);
            let overlapping_at_start = (moved - moved_axis_point).length() > limit + input.slop;
            let depth = distance - limit;
            deepest = deepest.max(depth);
            moved_start |= overlapping_at_start;
            let contact = Contact { normal: -offset / distance, depth, overlapping_at_start };
            *drift += contact.push_particle(&mut start[j], &mut p[j], sweep, local, moved, input.friction);
        }
    }
    ContactPass { tested: p.len() as u64 - 1, touching, deepest, moved_start, sliding: false }
}

/// One pass of the sphere or capsule `sweep` over the chain (see [`collide`]); `bounds` are the pass's
/// quick-reject bounds and `drift` how far the pass has moved things since they were computed. The lane
/// solver's pass (`lanes::outside`) does the same with its lanes side by side.
fn collide_outside(
    start: &mut [DVec3],
    p: &mut [DVec3],
    sweep: &ColliderSweep,
    input: &ContactInput<'_>,
    bounds: &[(DVec3, f64)],
    drift: &mut f64,
    normals: Option<&mut [Vec3]>,
) -> ContactPass {
    let mut pass = ContactPass::nothing(p.len() as u64 - 1);
    let collider = OutsideCollider::new(sweep, input, p[0]);
    let held = collider.held;
    // (Outside the loop: inside, its code made the loop slower for every chain. When the root holds every joint,
    // there is no such segment.)
    if held.joints > 0 && held.joints < bounds.len() {
        turn_held(start, p, sweep, input, &collider, bounds[held.joints], drift, normals, &mut pass);
    }
    // Segments before `held` join joints the root holds inside (or the root itself): nothing to test.
    for (i, &bound) in bounds[held.joints..].iter().enumerate() {
        let k = held.joints + i;
        let mut ends = SegmentEnds::of(start, p, k);
        let Some(found) = segment_contact(k, bound, &ends, sweep, input, &collider, *drift) else {
            continue;
        };
        *drift += resolve_segment(k, &found, sweep, input.friction, &mut ends, &mut pass);
        ends.store(start, p, k);
    }
    pass
}

/// The segment leaving the joints the root holds inside `collider` (`bound` its quick-reject bound): pushing its
/// far end alone would stretch the held run, which the lengths would undo round after round (bug 9 in
/// docs/robustness.md). The run turns about the root instead, and its last joint slides on the collider in the
/// contact rounds' lengths solves (its normal goes to `normals`). The pass then tests the segment like any
/// other: it pushes what depth the turns left, or all of it where the run cannot turn.
#[allow(clippy::too_many_arguments)]
pub(crate) fn turn_held(
    start: &mut [DVec3],
    p: &mut [DVec3],
    sweep: &ColliderSweep,
    input: &ContactInput<'_>,
    collider: &OutsideCollider,
    bound: (DVec3, f64),
    drift: &mut f64,
    normals: Option<&mut [Vec3]>,
    pass: &mut ContactPass,
) {
    let k = collider.held.joints;
    let found = segment_contact(k, bound, &SegmentEnds::of(start, p, k), sweep, input, collider, *drift);
    let turned = found.as_ref().and_then(|found| turn_held_run(start, p, k, found, sweep, collider, input.slop));
    if let (Some(found), Some(turned)) = (found, turned) {
        pass.touching = true;
        pass.deepest = pass.deepest.max(found.contact.depth);
        *drift += turned.drift;
        pass.moved_start |= turned.moved_start;
        if let Some(normals) = normals {
            normals[k + 1] = turned.normal;
            pass.sliding = true;
        }
    }
}

/// The ends of segment `k` of a chain: their positions at the start of the substep and now.
#[derive(Clone, Copy)]
pub(crate) struct SegmentEnds {
    pub start: [DVec3; 2],
    pub p: [DVec3; 2],
}

impl SegmentEnds {
    #[inline(always)]
    fn of(start: &[DVec3], p: &[DVec3], k: usize) -> Self {
        Self { start: [start[k], start[k + 1]], p: [p[k], p[k + 1]] }
    }

    #[inline(always)]
    fn store(self, start: &mut [DVec3], p: &mut [DVec3], k: usize) {
        [start[k], start[k + 1]] = self.start;
        [p[k], p[k + 1]] = self.p;
    }
}

/// Resolves the contact `found` of segment `k` (`ends`) with `sweep`: moves the segment's two ends so that its
/// contact point moves out, with friction, and its start positions too where the point was inside already at
/// the start of the substep. Records the contact in `pass`; returns how far it moved things (the drift).
#[inline(always)]
pub(crate) fn resolve_segment(
    k: usize,
    found: &SegmentContact,
    sweep: &ColliderSweep,
    friction: f32,
    ends: &mut SegmentEnds,
    pass: &mut ContactPass,
) -> f64 {
    let SegmentContact { t, point, before, contact, .. } = *found;
    let Contact { normal, depth, overlapping_at_start } = contact;
    pass.touching = true;
    pass.deepest = pass.deepest.max(depth);
    let correction = contact.correction(point, before, friction);
    // Move the segment's two ends so that the point at `t` moves by `correction` (unit masses; the root's
    // inverse mass is 0).
    let (wa, wb) = (if k == 0 { 0.0 } else { 1.0 - t }, t);
    let scale = 1.0 / (wa * wa + wb * wb);
    let world = sweep.end.direction_to_world(correction * scale);
    ends.p[0] += world * wa as f64;
    ends.p[1] += world * wb as f64;
    let mut drift = world.length() * (wa + wb) as f64;
    if overlapping_at_start {
        pass.moved_start = true;
        let push = sweep.end.direction_to_world(normal * (depth * scale));
        ends.start[0] += push * wa as f64;
        ends.start[1] += push * wb as f64;
        drift += push.length() * (wa + wb) as f64;
    }
    drift
}

/// An outside collider as [`segment_contact`] tests segments against it.
#[derive(Clone, Copy)]
pub(crate) struct OutsideCollider {
    pub centre: DVec3,
    pub collider_travel: f64,
    /// Its radius plus half height: how far its surface reaches from its centre.
    pub solid: f64,
    pub radius: f32,
    pub half_height: f32,
    /// Its axis segment, in its own frame.
    axis: (Vec3, Vec3),
    /// The joints the chain's root holds inside it.
    pub held: Held,
    /// The root's distance from the axis (infinite when the root holds nothing).
    root_distance: f32,
}

impl OutsideCollider {
    /// The sphere or capsule `sweep` for a chain rooted at `root`.
    #[inline(always)]
    pub fn new(sweep: &ColliderSweep, input: &ContactInput<'_>, root: DVec3) -> Self {
        let (radius, half_height) = sweep.shape.capsule().expect("outside colliders are spheres or capsules");
        let axis = (Vec3::new(0.0, -half_height, 0.0), Vec3::new(0.0, half_height, 0.0));
        // Quick reject, in world space and conservative: a segment whose every point stays farther from the
        // collider's centre than the collider's reach, over the whole substep, cannot touch it. Saves the frame
        // changes and closest-point tests for the many segments of a long chain far from a collider.
        let centre = sweep.end.centre;
        let collider_travel = (sweep.end.centre - sweep.start.centre).length();
        let solid = (radius + half_height) as f64;
        // A root clear of the collider by joint 1's radius holds nothing: one world-space test for most chains.
        let near_root = (radius + half_height + input.radii[1]) as f64;
        let (held, root_distance) = if (root - centre).length_squared() < near_root * near_root {
            let root_distance = distance_from_axis(sweep.end.to_local(root), half_height);
            let reach = |j: usize| radius + input.radii[j];
            (held_by_root(input.lengths, |j, along| root_distance + along * CLEARING_SLANT < reach(j)), root_distance)
        } else {
            (Held::NONE, f32::INFINITY)
        };
        Self { centre, collider_travel, solid, radius, half_height, axis, held, root_distance }
    }
}

/// Where a segment meets an outside collider: at `t` along it, the material point now at `point` and at
/// `before` at the start of the substep (both in the collider's frame), whose reach there is `reach`.
pub(crate) struct SegmentContact {
    t: f32,
    point: Vec3,
    before: Vec3,
    reach: f32,
    contact: Contact,
}

/// The contact of segment `k` (its quick-reject bound `bound`, its ends `ends`) with `collider`, if any. `drift`
/// is how far the pass has moved things since the bounds were computed.
#[inline(always)]
pub(crate) fn segment_contact(
    k: usize,
    (midpoint, segment_reach): (DVec3, f64),
    ends: &SegmentEnds,
    sweep: &ColliderSweep,
    input: &ContactInput<'_>,
    collider: &OutsideCollider,
    drift: f64,
) -> Option<SegmentContact> {
    let OutsideCollider { centre, collider_travel, solid, radius, half_height, axis, held, root_distance } = *collider;
    let clear = solid + segment_reach + collider_travel + 3.0 * drift;
    if (midpoint - centre).length_squared() > clear * clear {
        return None;
    }
    let (a, b) = (sweep.end.to_local(ends.p[0]), sweep.end.to_local(ends.p[1]));
    let (mut t, _) = closest_between_segments((a, b), axis);
    // The root is kinematic: a contact next to it could only be met by a large turn of the segment.
    if k == 0 && t < ROOT_LEVER_MIN {
        t = 1.0;
    }
    let reach_at = |t: f32| radius + input.radii[k] + (input.radii[k + 1] - input.radii[k]) * t;
    // The segment from the last joint the root holds inside: its points near that joint are held too.
    if k > 0 && k == held.joints && root_distance + (held.along + t * input.lengths[k]) * CLEARING_SLANT < reach_at(t) {
        t = 1.0;
    }
    let point = a.lerp(b, t);
    let reach = reach_at(t);
    let before = sweep.start.to_local(ends.start[0].lerp(ends.start[1], t as f64));
    let contact = contact_outside(before, point, reach, half_height, input.slop)?;
    Some(SegmentContact { t, point, before, reach, contact })
}

/// The turn about `root` that moves `point` out along `normal` (unit) by `depth`, to first order: `None` where
/// the normal points nearly along the lever from the root, so a turn would have to be far larger than the
/// push (below [`MIN_TURN_LEVER`]) or more than [`MAX_TURN`] radians.
fn turn_out(root: DVec3, point: DVec3, normal: Vec3, depth: f32) -> Option<DQuat> {
    // |lever x normal| is the lever's length times the sine between them: a turn by `theta` about that axis
    // moves the point by `theta` times it along the normal.
    let axis = (point - root).cross(normal.as_dvec3());
    let arm = axis.length();
    if arm <= MIN_TURN_LEVER as f64 * (point - root).length() {
        return None;
    }
    let angle = depth as f64 / arm;
    (angle <= MAX_TURN).then(|| DQuat::from_axis_angle(axis / arm, angle))
}

/// What [`turn_held_run`] did: how far it moved joints (for the quick reject's drift), whether it moved start
/// positions, and the contact normal of its last turn.
struct Turned {
    drift: f64,
    moved_start: bool,
    normal: Vec3,
}

/// Turns the held joints and the joint `k + 1` past them about the root until the contact point of segment `k`
/// (`found`) is out, up to [`TURN_STEPS`] turns (a turn is right to first order; the surface's curvature
/// leaves a little depth). Start positions turn along when the contact overlapped at the start
/// (pre-stabilisation). `None` (nothing moved) where a turn cannot push the point out (see [`turn_out`]).
#[cold]
#[inline(never)]
fn turn_held_run(
    start: &mut [DVec3],
    p: &mut [DVec3],
    k: usize,
    found: &SegmentContact,
    sweep: &ColliderSweep,
    collider: &OutsideCollider,
    slop: f32,
) -> Option<Turned> {
    let SegmentContact { t, mut before, reach, ref contact, .. } = *found;
    let normal = sweep.end.rotation * contact.normal;
    let mut turn = turn_out(p[0], p[k].lerp(p[k + 1], t as f64), normal, contact.depth)?;
    let mut turned = Turned { drift: 0.0, moved_start: false, normal };
    for _ in 0..TURN_STEPS {
        turned.drift += 2.0 * turn_about_root(&mut p[..=k + 1], turn);
        if contact.overlapping_at_start {
            turned.moved_start = true;
            turned.drift += 2.0 * turn_about_root(&mut start[..=k + 1], turn);
            before = sweep.start.to_local(start[k].lerp(start[k + 1], t as f64));
        }
        let point = p[k].lerp(p[k + 1], t as f64);
        let Some(left) = contact_outside(before, sweep.end.to_local(point), reach, collider.half_height, slop) else {
            break;
        };
        turned.normal = sweep.end.rotation * left.normal;
        let Some(next) = turn_out(p[0], point, turned.normal, left.depth) else { break };
        turn = next;
    }
    Some(turned)
}

/// Turns `run[1..]` by `turn` about `run[0]`, which keeps the run's lengths. Returns the largest move of a joint.
fn turn_about_root(run: &mut [DVec3], turn: DQuat) -> f64 {
    let root = run[0];
    let mut largest = 0.0f64;
    for joint in &mut run[1..] {
        let turned = root + turn * (*joint - root);
        largest = largest.max((turned - *joint).length());
        *joint = turned;
    }
    largest
}

/// How many of the chain's first dynamic joints the kinematic root holds on the wrong side of a collider's
/// surface: `held(j, along)` says whether joint `j`, `along` m of rest length from the root, is held (see
/// [`CLEARING_SLANT`]). Pushing such a joint out fights the lengths every round: the contact rounds never
/// settle, the segments next to the root end the substep stretched (by up to 146 % in
/// `tests/collisions.rs`), and the lengths solve fails. So those contacts are not made: the lengths win. With
/// the slant at 1 the bound would be exact for any convex collider, whose distance function changes by at
/// most the distance moved. Almost always 0 after one test: only a root inside a collider's reach by more
/// than half its first segment (a hair root within the head sphere's reach, fine segments) holds any.
fn held_by_root(lengths: &[f32], mut held: impl FnMut(usize, f32) -> bool) -> Held {
    let mut along = 0.0;
    for (k, &length) in lengths.iter().enumerate() {
        if !held(k + 1, along + length) {
            return Held { joints: k, along };
        }
        along += length;
    }
    Held { joints: lengths.len(), along }
}

/// What [`held_by_root`] found: the first `joints` dynamic joints are held; the last of them is `along` m of
/// rest length from the root.
#[derive(Clone, Copy)]
pub(crate) struct Held {
    pub joints: usize,
    along: f32,
}

impl Held {
    const NONE: Self = Self { joints: 0, along: 0.0 };
}

/// Distance of `q` from the local Y segment of half length `half_height` (a capsule's axis).
fn distance_from_axis(q: Vec3, half_height: f32) -> f32 {
    (q - Vec3::new(0.0, q.y.clamp(-half_height, half_height), 0.0)).length()
}

/// The contact of a material point that moved (in the collider's frame) from `before` to `now` with the
/// capsule of radius `reach` around the local Y segment of half length `half_height`: the outward normal
/// and how far `now` lies behind the surface along it, or `None` when it is clear.
///
/// A point still on the side of the axis it came from is pushed out the shortest way. A point that came
/// from outside and is now past the axis went through: it is put back on the tangent plane where its path
/// entered, so it ends on the side it came from whatever the step size.
#[inline(always)]
fn contact_outside(before: Vec3, now: Vec3, reach: f32, half_height: f32, slop: f32) -> Option<Contact> {
    let axis_point = |q: Vec3| Vec3::new(0.0, q.y.clamp(-half_height, half_height), 0.0);
    let (from_axis_before, from_axis_now) = (before - axis_point(before), now - axis_point(now));
    let started_outside = from_axis_before.length() >= reach - slop;
    if started_outside && from_axis_before.dot(from_axis_now) <= 0.0 {
        if let Some((entry, normal)) = ray_capsule(before, now, reach, half_height) {
            let depth = (entry - now).dot(normal);
            return (depth > 0.0).then_some(Contact { normal, depth, overlapping_at_start: false });
        }
    }
    let distance = from_axis_now.length();
    if distance >= reach {
        return None;
    }
    // On its own side, or overlapping since the start of the substep (e.g. a collider created inside the
    // chain): out along the shortest way, or any way from the axis itself.
    let normal = if distance > reach * 1e-6 { from_axis_now / distance } else { fallback_normal(from_axis_before) };
    Some(Contact { normal, depth: reach - distance, overlapping_at_start: !started_outside })
}

/// A contact to resolve: push the point `depth` along `normal`.
#[derive(Clone, Copy)]
struct Contact {
    normal: Vec3,
    depth: f32,
    /// The point was inside already at the start of the substep.
    overlapping_at_start: bool,
}

impl Contact {
    /// The move of the contact point now at `now` (it was at `before` at the start of the substep, both in
    /// the collider's frame): out along the normal, plus friction against its tangential motion.
    fn correction(&self, now: Vec3, before: Vec3, coefficient: f32) -> Vec3 {
        let push = self.normal * self.depth;
        push + friction(now + push - before, self.normal, self.depth, coefficient)
    }

    /// Resolves the contact of one particle (`p` its position, `start` its position at the start of the
    /// substep, `local` and `moved` the same in the collider's frame); a particle already inside at the start
    /// has its start moved out too (pre-stabilisation), so the push adds no velocity. Returns how far it moved
    /// the two (for the quick reject's drift).
    fn push_particle(
        &self,
        start: &mut DVec3,
        p: &mut DVec3,
        sweep: &ColliderSweep,
        local: Vec3,
        moved: Vec3,
        coefficient: f32,
    ) -> f64 {
        let push = sweep.end.direction_to_world(self.correction(local, moved, coefficient));
        *p += push;
        let mut moved_by = push.length();
        if self.overlapping_at_start {
            let out = sweep.end.direction_to_world(self.normal * self.depth);
            *start += out;
            moved_by += out.length();
        }
        moved_by
    }
}

fn fallback_normal(v: Vec3) -> Vec3 {
    let horizontal = Vec3::new(v.x, 0.0, v.z);
    horizontal.try_normalize().unwrap_or(Vec3::X)
}

/// Coulomb friction for a contact whose normal push was `depth`: the tangential part of the point's motion
/// relative to the collider, `motion`, is cancelled up to `coefficient * depth` (position-based friction,
/// Macklin et al. 2014).
fn friction(motion: Vec3, normal: Vec3, depth: f32, coefficient: f32) -> Vec3 {
    if coefficient <= 0.0 {
        return Vec3::ZERO;
    }
    let tangential = motion - normal * motion.dot(normal);
    let length = tangential.length();
    if length <= 0.0 {
        return Vec3::ZERO;
    }
    -tangential * (coefficient * depth / length).min(1.0)
}

/// Where the path from `from` to `to` (starting outside) first enters the capsule of radius `radius`
/// around the local Y segment of half length `half_height`, and the outward normal there.
fn ray_capsule(from: Vec3, to: Vec3, radius: f32, half_height: f32) -> Option<(Vec3, Vec3)> {
    let d = to - from;
    let mut best: Option<(f32, Vec3)> = None;
    let mut consider = |u: f32, normal: Vec3| {
        if (0.0..=1.0).contains(&u) && best.is_none_or(|(b, _)| u < b) {
            best = Some((u, normal));
        }
    };
    // Relative to the radius, so that results do not depend on the engine's scale.
    let negligible = (radius * 1e-6).powi(2);
    // The cylinder between the caps.
    let a = d.x * d.x + d.z * d.z;
    if a > negligible {
        let b = from.x * d.x + from.z * d.z;
        let c = from.x * from.x + from.z * from.z - radius * radius;
        let disc = b * b - a * c;
        if disc >= 0.0 {
            let u = (-b - disc.sqrt()) / a;
            let hit = from + d * u;
            if hit.y.abs() <= half_height {
                consider(u, Vec3::new(hit.x, 0.0, hit.z) / radius);
            }
        }
    }
    // The two caps (one when the capsule is a sphere).
    let a = d.length_squared();
    if a > negligible {
        for centre_y in if half_height > 0.0 { [-half_height, half_height] } else { [0.0, 0.0] } {
            let centre = Vec3::new(0.0, centre_y, 0.0);
            let oc = from - centre;
            let b = oc.dot(d);
            let c = oc.length_squared() - radius * radius;
            let disc = b * b - a * c;
            if disc >= 0.0 {
                let u = (-b - disc.sqrt()) / a;
                consider(u, (from + d * u - centre) / radius);
            }
        }
    }
    best.map(|(u, normal)| (from + d * u, normal.normalize_or(Vec3::X)))
}

/// Parameters `(s, t)` of the closest points of segments `p` and `q` (Ericson, Real-Time Collision
/// Detection, 5.1.9), each in [0, 1].
#[inline(always)]
pub(crate) fn closest_between_segments(p: (Vec3, Vec3), q: (Vec3, Vec3)) -> (f32, f32) {
    let (d1, d2) = (p.1 - p.0, q.1 - q.0);
    let r = p.0 - q.0;
    let (a, e, f) = (d1.length_squared(), d2.length_squared(), d2.dot(r));
    // Degenerate (point) segments and parallel ones, judged relative to the segments' own lengths so that
    // the result does not depend on the engine's scale.
    if a <= 0.0 && e <= 0.0 {
        return (0.0, 0.0);
    }
    if a <= 0.0 {
        return (0.0, (f / e).clamp(0.0, 1.0));
    }
    let c = d1.dot(r);
    if e <= 0.0 {
        return ((-c / a).clamp(0.0, 1.0), 0.0);
    }
    let b = d1.dot(d2);
    let denom = a * e - b * b;
    let mut s = if denom > 1e-10 * a * e { ((b * f - c * e) / denom).clamp(0.0, 1.0) } else { 0.0 };
    let mut t = (b * s + f) / e;
    if t < 0.0 {
        t = 0.0;
        s = (-c / a).clamp(0.0, 1.0);
    } else if t > 1.0 {
        t = 1.0;
        s = ((b - c) / a).clamp(0.0, 1.0);
    }
    (s, t)
}

#[cfg(test)]
mod tests {
    use glam::Quat;

    use super::super::collider::ColliderPose;
    use super::*;

    /// Room for the contact normals of any chain these tests build.
    fn normals() -> Vec<Vec3> {
        vec![Vec3::ZERO; 64]
    }

    fn still(shape: ColliderShape) -> ColliderSweep {
        let pose = ColliderPose { centre: DVec3::ZERO, rotation: Quat::IDENTITY };
        ColliderSweep { shape, start: pose, end: pose }
    }

    #[test]
    fn closest_points_of_crossing_segments() {
        let (s, t) = closest_between_segments(
            (Vec3::new(-1.0, 0.5, 0.0), Vec3::new(1.0, 0.5, 0.0)),
            (Vec3::new(0.0, -1.0, 0.0), Vec3::new(0.0, 1.0, 0.0)),
        );
        assert!((s - 0.5).abs() < 1e-6 && (t - 0.75).abs() < 1e-6, "{s} {t}");
    }

    #[test]
    fn ray_enters_capsule_side_and_cap() {
        let (entry, normal) = ray_capsule(Vec3::new(-2.0, 0.0, 0.0), Vec3::new(2.0, 0.0, 0.0), 0.5, 1.0).unwrap();
        assert!((entry - Vec3::new(-0.5, 0.0, 0.0)).length() < 1e-6 && (normal + Vec3::X).length() < 1e-6);
        let (entry, normal) = ray_capsule(Vec3::new(0.0, 3.0, 0.0), Vec3::new(0.0, 0.0, 0.0), 0.5, 1.0).unwrap();
        assert!((entry - Vec3::new(0.0, 1.5, 0.0)).length() < 1e-6 && (normal - Vec3::Y).length() < 1e-6);
        assert!(ray_capsule(Vec3::new(-2.0, 0.0, 1.0), Vec3::new(2.0, 0.0, 1.0), 0.5, 1.0).is_none());
    }

    #[test]
    fn point_that_passed_through_goes_back_to_its_side() {
        // From the left of a sphere of reach 0.5 straight through to the right: back onto the left surface.
        let Contact { normal, depth, overlapping_at_start } =
            contact_outside(Vec3::new(-1.0, 0.0, 0.0), Vec3::new(0.7, 0.0, 0.0), 0.5, 0.0, 0.0).unwrap();
        assert!(!overlapping_at_start);
        assert!((normal + Vec3::X).length() < 1e-6 && (depth - 1.2).abs() < 1e-6, "{normal} {depth}");
    }

    #[test]
    fn segment_across_a_sphere_is_pushed_out_at_its_middle() {
        // A segment whose ends are both outside a sphere but whose middle passes through it.
        let mut start = [DVec3::new(-1.0, 0.5, 0.0), DVec3::new(-0.5, 0.5, 0.0), DVec3::new(0.5, 0.5, 0.0)];
        let mut p = [DVec3::new(-1.0, 0.2, 0.0), DVec3::new(-0.5, 0.2, 0.0), DVec3::new(0.5, 0.2, 0.0)];
        let sweep = still(ColliderShape::Sphere { radius: 0.4 });
        let input =
            ContactInput { colliders: &[sweep], radii: &[0.0; 3], lengths: &[0.5, 1.0], friction: 0.0, slop: 0.0 };
        collide(&mut start, &mut p, &input, &mut SegmentBounds::default(), &mut normals());
        let (a, b) = (p[1].as_vec3(), p[2].as_vec3());
        let (t, _) = closest_between_segments((a, b), (Vec3::ZERO, Vec3::ZERO));
        let distance = a.lerp(b, t).length();
        assert!(distance >= 0.4 - 1e-5, "segment still inside: {distance}");
        assert_eq!(p[0], DVec3::new(-1.0, 0.2, 0.0), "the root never moves");
    }

    fn sphere_at(centre: DVec3, radius: f32) -> ColliderSweep {
        let pose = ColliderPose { centre, rotation: Quat::IDENTITY };
        ColliderSweep { shape: ColliderShape::Sphere { radius }, start: pose, end: pose }
    }

    #[test]
    fn a_push_into_a_later_collider_is_caught_although_the_bounds_predate_it() {
        // Sphere A pushes the short tip segment 3 cm down, into sphere B, which the segment cleared by 1 cm
        // (beyond B's quick-reject reach) when the pass computed its bounds. One pass over [A, B] must do
        // exactly what a pass over A then a pass over B (with fresh bounds) does.
        let a = sphere_at(DVec3::new(1.02, 0.5, 0.0), 0.53);
        let b = sphere_at(DVec3::new(1.01, -0.56, 0.0), 0.54);
        let chain = [DVec3::ZERO, DVec3::new(1.0, 0.0, 0.0), DVec3::new(1.02, 0.0, 0.0)];
        let (both, only_a, only_b) = ([a, b], [a], [b]);
        let input =
            |colliders| ContactInput { colliders, radii: &[0.0; 3], lengths: &[1.0, 0.02], friction: 0.0, slop: 0.0 };
        let (mut start, mut p) = (chain, chain);
        let together = collide(&mut start, &mut p, &input(&both), &mut SegmentBounds::default(), &mut normals());
        let (mut start_apart, mut apart) = (chain, chain);
        let first =
            collide(&mut start_apart, &mut apart, &input(&only_a), &mut SegmentBounds::default(), &mut normals());
        let second =
            collide(&mut start_apart, &mut apart, &input(&only_b), &mut SegmentBounds::default(), &mut normals());
        assert!(first.touching && second.touching, "the scene must need both pushes");
        assert_eq!((p, start), (apart, start_apart));
        assert_eq!(together.deepest, first.deepest.max(second.deepest));
    }

    #[test]
    fn joints_the_root_holds_inside_are_left_and_the_rest_pushed_out() {
        // Root 0.1 inside the reach of a unit sphere (joint radius 0), chain of 0.05 segments along the surface:
        // joints 1 to 3 (0.05 to 0.15 along) could clear it only pointing within 60 degrees of straight out.
        // They are not pushed one by one: the contact of the segment leaving them turns them, with joint 4,
        // about the root, so their lengths stay.
        let chain: Vec<DVec3> = (0..6).map(|j| DVec3::new(0.9, -0.05 * j as f64, 0.0)).collect();
        let sphere = still(ColliderShape::Sphere { radius: 1.0 });
        let input =
            ContactInput { colliders: &[sphere], radii: &[0.0; 6], lengths: &[0.05; 5], friction: 0.0, slop: 0.0 };
        let (mut start, mut p) = (chain.clone(), chain.clone());
        let mut found = normals();
        collide(&mut start, &mut p, &input, &mut SegmentBounds::default(), &mut found);
        assert_eq!(p[0], chain[0], "the root stays");
        for j in 1..=4 {
            let (from_root, before) = ((p[j] - p[0]).length(), (chain[j] - chain[0]).length());
            assert!((from_root - before).abs() < 1e-12, "joint {j} turned about the root: {from_root} vs {before}");
            let segment = (p[j] - p[j - 1]).length();
            assert!((segment - 0.05).abs() < 1e-12, "segment {} keeps its length: {segment}", j - 1);
        }
        assert!(p[1].x > chain[1].x, "the held joints turned outwards: {p:?}");
        assert!(p[4..].iter().all(|q| q.length() >= 1.0 - 1e-6), "{p:?}");
        // Joint 4 slides on the sphere in the lengths solves of the contact rounds; the others move freely.
        assert!((found[4].length() - 1.0).abs() < 1e-6, "{found:?}");
        assert!(found.iter().enumerate().all(|(j, n)| j == 4 || *n == Vec3::ZERO), "{found:?}");
        // The same under the ground: root 0.1 below it, chain lying level.
        let plane = still(ColliderShape::Plane);
        let input = ContactInput { colliders: &[plane], radii: &[0.0; 6], ..input };
        let below: Vec<DVec3> = (0..6).map(|j| DVec3::new(0.05 * j as f64, -0.1, 0.0)).collect();
        let (mut start, mut p) = (below.clone(), below.clone());
        collide(&mut start, &mut p, &input, &mut SegmentBounds::default(), &mut normals());
        assert_eq!(p[..4], below[..4]);
        assert!(p[4..].iter().all(|q| q.y.abs() < 1e-6), "{p:?}");
    }

    #[test]
    fn a_chain_the_root_holds_whole_is_left_alone() {
        // Root 0.5 inside a unit sphere's reach, three 0.05 segments: every joint is held, none is tested.
        let chain: Vec<DVec3> = (0..4).map(|j| DVec3::new(0.5, -0.05 * j as f64, 0.0)).collect();
        let sphere = still(ColliderShape::Sphere { radius: 1.0 });
        let input =
            ContactInput { colliders: &[sphere], radii: &[0.0; 4], lengths: &[0.05; 3], friction: 0.0, slop: 0.0 };
        let (mut start, mut p) = (chain.clone(), chain.clone());
        let pass = collide(&mut start, &mut p, &input, &mut SegmentBounds::default(), &mut normals());
        assert!(!pass.touching && !pass.sliding);
        assert_eq!(p, chain);
    }

    #[test]
    fn plane_friction_stops_slow_sliding_and_not_fast() {
        let plane = still(ColliderShape::Plane);
        let mut start = [DVec3::ZERO, DVec3::new(1.0, 0.0, 0.0)];
        // Pressed 0.1 into the plane while sliding 0.05 sideways: friction 1 holds it (0.05 < 1 * 0.1).
        let mut p = [DVec3::ZERO, DVec3::new(1.05, -0.1, 0.0)];
        collide(
            &mut start,
            &mut p,
            &ContactInput { colliders: &[plane], radii: &[0.0; 2], lengths: &[1.0], friction: 1.0, slop: 0.0 },
            &mut SegmentBounds::default(),
            &mut normals(),
        );
        assert!((p[1] - DVec3::new(1.0, 0.0, 0.0)).length() < 1e-6, "{}", p[1]);
        // Sliding 0.5: friction removes 0.1 of it.
        let mut p = [DVec3::ZERO, DVec3::new(1.5, -0.1, 0.0)];
        collide(
            &mut start,
            &mut p,
            &ContactInput { colliders: &[plane], radii: &[0.0; 2], lengths: &[1.0], friction: 1.0, slop: 0.0 },
            &mut SegmentBounds::default(),
            &mut normals(),
        );
        assert!((p[1] - DVec3::new(1.4, 0.0, 0.0)).length() < 1e-6, "{}", p[1]);
    }

    /// What lets a substep skip pre-stabilisation (`SubstepInput::starts_clear`): positions that a contact pass
    /// left touching nothing are untouched, to the bit, by pre-stabilisation against the colliders' pose at
    /// the end of that pass (the next substep's start pose). Moving spheres, a capsule, a plane and an inside
    /// sphere, chains placed at random near them.
    #[test]
    fn a_pass_that_touched_nothing_leaves_nothing_to_pre_stabilise() {
        let mut seed = 0x2545f4914f6cdd1du64;
        let mut unit = move || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        let pose = |centre: DVec3, turn: f32| ColliderPose { centre, rotation: Quat::from_rotation_z(turn) };
        let (mut clear, mut touched) = (0, 0);
        for _ in 0..2000 {
            let mut random = || DVec3::new(unit(), unit(), unit());
            let shapes = [
                (ColliderShape::Sphere { radius: 0.3 }, DVec3::new(0.5, 0.0, 0.0)),
                (ColliderShape::Capsule { radius: 0.2, half_height: 0.3 }, DVec3::new(-0.5, 0.2, 0.0)),
                (ColliderShape::Plane, DVec3::new(0.0, -0.9, 0.0)),
                (ColliderShape::InsideSphere { radius: 2.0 }, DVec3::ZERO),
            ];
            let (first, second, third) = (random() * 0.05, random() * 0.05, random() * 0.05);
            let substep = |from: DVec3, to: DVec3| -> Vec<ColliderSweep> {
                shapes
                    .iter()
                    .map(|&(shape, centre)| ColliderSweep {
                        shape,
                        start: pose(centre + from, from.x as f32),
                        end: pose(centre + to, to.x as f32),
                    })
                    .collect()
            };
            let (this, next) = (substep(first, second), substep(second, third));
            let root = random() * 0.8;
            let mut start: Vec<DVec3> = (0..5).map(|j| root + random() * 0.15 * j as f64).collect();
            let mut p: Vec<DVec3> = start.iter().map(|x| *x + random() * 0.05).collect();
            p[0] = start[0];
            let radii = [0.02f32; 5];
            let lengths: Vec<f32> = p.windows(2).map(|w| (w[1] - w[0]).length() as f32).collect();
            let input =
                |colliders| ContactInput { colliders, radii: &radii, lengths: &lengths, friction: 0.5, slop: 1e-4 };
            let pass = collide(&mut start, &mut p, &input(&this), &mut SegmentBounds::default(), &mut normals());
            if pass.touching {
                touched += 1;
                continue;
            }
            clear += 1;
            let (mut x, mut scratch) = (p.clone(), vec![DVec3::ZERO; p.len()]);
            let keep_lengths = |_: &[DVec3], _: &mut [DVec3]| panic!("nothing to keep");
            let moved =
                pre_stabilise(&mut x, &mut scratch, &input(&next), 4, keep_lengths, 0.0, &mut SegmentBounds::default());
            assert!(!moved);
            assert!(crate::core::rod::same_bits(&x, &p));
        }
        assert!(clear > 100 && touched > 100, "clear {clear}, touched {touched}: the test needs both");
    }

    #[test]
    fn inside_sphere_keeps_particles_within_radius_minus_their_own() {
        let sweep = still(ColliderShape::InsideSphere { radius: 1.0 });
        let mut start = [DVec3::ZERO, DVec3::new(0.5, 0.0, 0.0)];
        let mut p = [DVec3::ZERO, DVec3::new(2.0, 0.0, 0.0)];
        collide(
            &mut start,
            &mut p,
            &ContactInput { colliders: &[sweep], radii: &[0.1; 2], lengths: &[0.5], friction: 0.0, slop: 0.0 },
            &mut SegmentBounds::default(),
            &mut normals(),
        );
        assert!((p[1] - DVec3::new(0.9, 0.0, 0.0)).length() < 1e-6, "{}", p[1]);
    }
}
