//! A chain: its shapes (base and view shapes), the rest shape blended from them, its particles, and the
//! output pose at the call's time, from its last two internal states.

use glam::{Quat, Vec3};

use super::arena::Id;
use super::blend::blend_into;
use super::bones::swing_onto_segments;
use super::buffers::reserve_total;
use super::error::{Error, Result};
use super::math::{Transform, direction, nlerp_shorter, swing_to};
use super::params::{ChainParams, EngineSettings, SLEEP_DELAY};
use super::prefetch::{lines, region};
use super::rod::{CONTACT_SETTLED, ChainConstants, RestGroups, RodState};
use super::shape::{EncodedShape, Shape, ShapeFrame};
use super::weights::{ViewWeighting, blend_weights};

/// Marker type for view shape ids.
pub enum ViewShapeTag {}
pub type ViewShapeId = Id<ViewShapeTag>;

/// A view shape as stored by its chain.
#[derive(Clone, Debug)]
pub(crate) struct ViewShape {
    pub id: ViewShapeId,
    pub weighting: ViewWeighting,
    pub encoded: EncodedShape,
}

/// A view direction closer than this (in unit-vector distance, ~radians) to the last blended one reuses
/// the last blend.
const VIEW_EPSILON: f32 = 1e-6;

pub struct Chain {
    pub params: ChainParams,
    pub(crate) frame: ShapeFrame,
    base: EncodedShape,
    /// Each joint's bone axis in its own frame (from the base shape); the tip repeats its parent's.
    pub(crate) bone_axes: Vec<Vec3>,
    pub(crate) views: Vec<ViewShape>,
    weights: Vec<f32>,
    /// The base shape's weight in the last blend.
    base_weight: f32,
    blended: EncodedShape,
    /// The rest shape the solver pulls towards (anchor frame).
    pub(crate) rest: Shape,
    /// The rest shape of the last substep; differs from `rest` while `rest_changed`.
    pub(crate) rest_used: Shape,
    pub(crate) rest_changed: bool,
    /// What the shape-matching groups need of `rest`, rebuilt by [`Chain::refresh_rest_groups`] when stale.
    pub(crate) rest_groups: RestGroups,
    rest_groups_stale: bool,
    /// The shortest of `frame.lengths`.
    pub(crate) shortest_segment: f32,
    blended_for: Option<Vec3>,
    shapes_dirty: bool,
    pub(crate) state: RodState,
    /// False until the first step places the particles under a known anchor (and after a reset).
    pub(crate) placed: bool,
    pub(crate) half_kick: bool,
    /// The anchor of the last step (world) and the one supplied for the next (own anchors only).
    pub(crate) anchor: Transform,
    pub(crate) anchor_pending: Transform,
    /// The anchor exactly as the host last gave it (`anchor_pending` is it normalised): the same bits again
    /// need neither the check nor the normalisation, which were most of a sleeping chain's cost.
    pub(crate) anchor_given: Option<Transform>,
    /// The last two internal states in the anchor frame, for the output pose (see [`output_fraction`]).
    pub(crate) local_previous: Vec<Transform>,
    pub(crate) local_current: Vec<Transform>,
    /// Interpolated, skinning-ready pose in the anchor frame.
    pub(crate) output: Vec<Transform>,
    /// Per-joint collision radii (character units); empty: every joint uses `params.radius`.
    pub(crate) joint_radii: Vec<f32>,
    /// An explicit teleport was asked for: the next step treats the anchor's motion as one.
    pub(crate) teleport_requested: bool,
    /// A disabled (culled) chain is not simulated; it follows its anchor rigidly.
    pub(crate) enabled: bool,
    /// The anchor (world) the particle state was last simulated under, while the chain is disabled: the next
    /// step after re-enabling carries the state from there to the current anchor.
    pub(crate) resume_from: Option<Transform>,
    /// Sleeping: nothing moved for a while; the chain is skipped until something changes.
    pub(crate) asleep: bool,
    /// While asleep: the world pose under the anchor it fell asleep under, `asleep_anchor` (the output is
    /// frozen, so while the anchor stays there the host's read-back copies it instead of transforming every
    /// joint again; capacity reserved at creation).
    asleep_world: Vec<Transform>,
    asleep_anchor: Transform,
    /// Simulated seconds the chain has been still (towards falling asleep).
    pub(crate) still_time: f32,
    /// The last step's solver constants and what they were computed from (see [`constants`](Self::constants)).
    constants: Option<CachedConstants>,
}

/// [`ChainConstants`] with their inputs.
#[derive(Clone, Copy)]
struct CachedConstants {
    params: ChainParams,
    settings: EngineSettings,
    h: f32,
    iterations: u32,
    constants: ChainConstants,
}

impl Chain {
    pub fn new(params: ChainParams, joints: &[Transform]) -> Result<Self> {
        params.validate()?;
        let base_shape = Shape::from_joints(joints)?;
        let n = base_shape.len();
        let frame = ShapeFrame::from_base(&base_shape);
        let base = EncodedShape::encode(&base_shape, frame.reference);
        let shortest_segment = shortest(&frame.lengths);
        let local: Vec<Transform> =
            base_shape.positions.iter().zip(&base_shape.orientations).map(|(p, q)| Transform::new(*p, *q)).collect();
        let mut chain = Self {
            params,
            bone_axes: bone_axes(&base_shape),
            frame,
            base,
            views: Vec::new(),
            weights: Vec::new(),
            base_weight: 1.0,
            blended: EncodedShape::identity(n),
            rest: base_shape.clone(),
            rest_used: base_shape.clone(),
            rest_changed: false,
            rest_groups: RestGroups::default(),
            rest_groups_stale: true,
            shortest_segment,
            blended_for: None,
            shapes_dirty: true,
            state: RodState::at_rest(&base_shape, &Transform::IDENTITY),
            placed: false,
            half_kick: true,
            anchor: Transform::IDENTITY,
            anchor_pending: Transform::IDENTITY,
            anchor_given: None,
            local_previous: local.clone(),
            local_current: local.clone(),
            output: local,
            joint_radii: Vec::new(),
            teleport_requested: false,
            enabled: true,
            resume_from: None,
            asleep: false,
            asleep_world: Vec::with_capacity(n),
            asleep_anchor: Transform::IDENTITY,
            still_time: 0.0,
            constants: None,
        };
        chain.update_rest(None);
        chain.rest_used.clone_from(&chain.rest);
        chain.rest_changed = false;
        // Built here rather than by the first step, which may come long after (a chain created disabled).
        chain.refresh_rest_groups();
        chain.write_output(0.0);
        Ok(chain)
    }

    pub fn joint_count(&self) -> usize {
        self.rest.len()
    }

    /// Sum of the segment lengths: no particle is ever farther than this from the root.
    pub(crate) fn reach(&self) -> f32 {
        self.frame.lengths.iter().sum()
    }

    /// How deep (m) a joint must have been inside a collider at the start of a substep to count as overlapping
    /// since then (`ContactInput::slop`): a share of the chain's shortest segment.
    pub(crate) fn contact_slop(&self) -> f32 {
        CONTACT_SLOP * self.shortest_segment
    }

    /// A contact pass whose corrections stay below this (m) has settled (`rod::substep`'s final rounds).
    pub(crate) fn contact_settled(&self) -> f32 {
        CONTACT_SETTLED * self.shortest_segment
    }

    /// Collision radius of each joint in metres under `scale`, into `out`.
    pub(crate) fn scaled_radii(&self, scale: f32, out: &mut Vec<f32>) {
        out.clear();
        if self.joint_radii.is_empty() {
            out.resize(self.joint_count(), self.params.radius * scale);
        } else {
            out.extend(self.joint_radii.iter().map(|r| r * scale));
        }
    }

    /// Validates and encodes a view shape for this chain (lengths and root come from the base).
    pub(crate) fn encode_view_shape(&self, joints: &[Transform]) -> Result<EncodedShape> {
        if joints.len() != self.joint_count() {
            return Err(Error::invalid_argument(format!(
                "a view shape needs as many joints as its chain ({}), got {}",
                self.joint_count(),
                joints.len()
            )));
        }
        let shape = Shape::from_joints(joints)?;
        Ok(EncodedShape::encode(&shape, self.frame.reference))
    }

    /// Adds a view shape, with room for its blend weight (reserved here so that no step allocates it).
    pub(crate) fn push_view(&mut self, view: ViewShape) {
        self.views.push(view);
        reserve_total(&mut self.weights, self.views.len());
        self.mark_shapes_dirty();
    }

    pub(crate) fn mark_shapes_dirty(&mut self) {
        self.shapes_dirty = true;
        self.wake();
    }

    /// Something about the chain changed: simulate it again from the next step.
    pub(crate) fn wake(&mut self) {
        self.asleep = false;
        self.still_time = 0.0;
    }

    /// Fastest particle speed relative to the root, from the internal velocities.
    pub(crate) fn relative_speed(&self) -> f32 {
        let root = self.state.v[0];
        self.state.v[1..].iter().map(|v| (*v - root).length_squared()).fold(0.0, f32::max).sqrt()
    }

    /// Falls asleep: velocities to zero and the output pose frozen at the newest internal state.
    pub(crate) fn fall_asleep(&mut self) {
        self.asleep = true;
        self.state.v.fill(Vec3::ZERO);
        self.state.w.fill(Vec3::ZERO);
        self.local_previous.clone_from(&self.local_current);
        self.write_output(1.0);
        let anchor = self.anchor;
        self.asleep_anchor = anchor;
        self.asleep_world.clear();
        self.asleep_world.extend(self.output.iter().map(|local| anchor.mul(local)));
    }

    /// Asleep under the anchor it fell asleep under: its world pose is the stored one.
    fn shows_stored_pose(&self) -> bool {
        self.asleep && same_bits(&self.anchor, &self.asleep_anchor)
    }

    /// The pose the world read-backs show: the stored one for a sleeping chain that has not moved, the output
    /// pose (relative to the anchor) otherwise.
    pub(crate) fn shown_pose(&self) -> &[Transform] {
        if self.shows_stored_pose() { &self.asleep_world } else { &self.output }
    }

    /// The output pose, relative to the anchor, whose rotations the local-rotation read-backs give.
    pub(crate) fn output_pose(&self) -> &[Transform] {
        &self.output
    }

    /// [`for_each_world_transform`](Self::for_each_world_transform) into `out` (the chain's joint count): a
    /// copy of the stored pose for a sleeping chain.
    pub(crate) fn write_world(&self, out: &mut [Transform]) {
        self.write_world_as(out, |world| world);
    }

    /// [`write_world`](Self::write_world), each transform converted by `convert`.
    pub(crate) fn write_world_as<T>(&self, out: &mut [T], convert: impl Fn(Transform) -> T) {
        if self.shows_stored_pose() {
            for (slot, world) in out.iter_mut().zip(&self.asleep_world) {
                *slot = convert(*world);
            }
        } else {
            for (slot, local) in out.iter_mut().zip(&self.output) {
                *slot = convert(self.anchor.mul(local));
            }
        }
    }

    /// Each joint's rotation relative to its parent (joint 0: relative to the anchor).
    pub(crate) fn local_rotations(&self) -> impl Iterator<Item = Quat> + '_ {
        self.output.iter().scan(Quat::IDENTITY, |parent, local| {
            let relative = relative_rotation(*parent, local.rotation);
            *parent = local.rotation;
            Some(relative)
        })
    }

    /// Calls `f` with each joint's world transform (the anchor times the output pose).
    pub(crate) fn for_each_world_transform(&self, mut f: impl FnMut(Transform)) {
        if self.shows_stored_pose() {
            self.asleep_world.iter().for_each(|world| f(*world));
        } else {
            self.output.iter().for_each(|local| f(self.anchor.mul(local)));
        }
    }

    /// Replaces the base shape (same joint count). View shapes keep their bends and take the new lengths.
    pub(crate) fn set_base_shape(&mut self, joints: &[Transform]) -> Result<()> {
        if joints.len() != self.joint_count() {
            return Err(Error::invalid_argument(format!(
                "the base shape must keep the chain's {} joints, got {}",
                self.joint_count(),
                joints.len()
            )));
        }
        let shape = Shape::from_joints(joints)?;
        let frame = ShapeFrame::from_base(&shape);
        for view in &mut self.views {
            view.encoded.rebase_reference(self.frame.reference, frame.reference);
        }
        self.base = EncodedShape::encode(&shape, frame.reference);
        self.bone_axes = bone_axes(&shape);
        self.shortest_segment = shortest(&frame.lengths);
        self.frame = frame;
        self.shapes_dirty = true;
        Ok(())
    }

    /// The solver constants of a step of substep `h` and `iterations` iterations under `settings`: those of the
    /// last step unless an input changed. Computing them takes a few transcendental functions per chain
    /// (`libm`'s `expm1f`, `logf` and `expf`: 2.3 % of the samples of `perf record -F 10000` of `scene_cost 1500
    /// 100x16 lod2` built at 7e7ed77, none after), for inputs that a scene rarely changes.
    pub(crate) fn constants(&mut self, settings: &EngineSettings, h: f32, iterations: u32) -> ChainConstants {
        let params = self.params;
        match self.constants {
            Some(cached)
                if cached.params == params
                    && cached.settings == *settings
                    && cached.h == h
                    && cached.iterations == iterations =>
            {
                cached.constants
            }
            _ => {
                let constants = ChainConstants::new(&params, settings, h, iterations);
                self.constants = Some(CachedConstants { params, settings: *settings, h, iterations, constants });
                constants
            }
        }
    }

    /// Re-blends the rest shape for view direction `view` when it or the shapes changed. A changed rest
    /// shape is flagged so the next substep can suppress the momentum it would inject.
    pub(crate) fn update_rest(&mut self, view: Option<Vec3>) {
        if self.blend_rest(view) {
            self.update_rest_after_blend();
        }
    }

    /// [`update_rest`](Self::update_rest) of `N` chains, their decodes side by side when every one is due
    /// ([`EncodedShape::decode_side_by_side`]): the same results as one after the other, sooner.
    pub(crate) fn update_rest_together<const N: usize>(mut chains: [&mut Chain; N], view: Option<Vec3>) {
        let due = chains.each_mut().map(|chain| chain.blend_rest(view));
        if due.iter().all(|&due| due) {
            EncodedShape::decode_side_by_side(chains.each_mut().map(|chain| {
                let chain: &mut Chain = chain;
                (&chain.blended, &chain.frame, &mut chain.rest.positions[..])
            }));
            for chain in chains {
                chain.orient_rest();
            }
        } else {
            for (chain, due) in chains.into_iter().zip(due) {
                if due {
                    chain.update_rest_after_blend();
                }
            }
        }
    }

    /// The first part of [`update_rest`](Self::update_rest): the blend of the view shapes for `view`, if the
    /// rest shape is due for an update (returned).
    fn blend_rest(&mut self, view: Option<Vec3>) -> bool {
        if !self.rest_update_due(view) {
            return false;
        }
        self.shapes_dirty = false;
        self.blended_for = view;
        if self.views.is_empty() || view.is_none() {
            self.blended.clone_from(&self.base);
            self.weights.clear();
            self.base_weight = 1.0;
        } else {
            let d = view.unwrap_or(Vec3::Z);
            self.weights.resize(self.views.len(), 0.0);
            let weightings = self.views.iter().map(|v| v.weighting);
            let w0 = blend_weights(d, weightings, &mut self.weights);
            self.base_weight = w0;
            let views = self.views.iter().zip(self.weights.iter()).map(|(v, w)| (&v.encoded, *w));
            blend_into(&self.base, w0, views, &mut self.blended);
        }
        true
    }

    fn update_rest_after_blend(&mut self) {
        self.blended.decode_into(&self.frame, &mut self.rest.positions);
        self.orient_rest();
    }

    /// The last part of [`update_rest`](Self::update_rest), after the decode of the blend into the rest
    /// positions: the rest orientations (each joint's bone swung onto its segment), and the change flagged.
    fn orient_rest(&mut self) {
        let rest = &mut self.rest;
        swing_onto_segments(&self.blended.orientations, &self.bone_axes, &rest.positions, &mut rest.orientations);
        self.rest_groups_stale = true;
        if self.rest != self.rest_used {
            self.rest_changed = true;
        }
    }

    /// Whether [`update_rest`](Self::update_rest) for view direction `view` has anything to do.
    pub(crate) fn rest_update_due(&self, view: Option<Vec3>) -> bool {
        let view_moved = || match (view, self.blended_for) {
            (Some(v), Some(b)) => (v - b).length() > VIEW_EPSILON,
            (a, b) => a.is_some() != b.is_some(),
        };
        self.shapes_dirty || (!self.views.is_empty() && view_moved())
    }

    /// Asks for the cache lines that [`update_rest`](Self::update_rest) for `view`, and the carry to the new
    /// rest shape after it, will read and write, if it has anything to do: the view shapes, the blend, the
    /// rest shapes and the particle state live in separate allocations, and on 1000 x 16 chains whose rest
    /// shape follows the camera the blend waited on memory for each of them.
    pub(crate) fn prefetch_rest_update(&self, view: Option<Vec3>) {
        if !self.rest_update_due(view) {
            return;
        }
        let encoded = |e: &EncodedShape| [region(&e.bends), region(&e.orientations)];
        let [base_bends, base_orientations] = encoded(&self.base);
        let [blended_bends, blended_orientations] = encoded(&self.blended);
        lines(&[
            region(&self.views),
            base_bends,
            base_orientations,
            blended_bends,
            blended_orientations,
            region(&self.frame.lengths),
            region(&self.bone_axes),
            region(&self.rest.positions),
            region(&self.rest.orientations),
            region(&self.rest_used.positions),
            region(&self.rest_used.orientations),
            region(&self.rest_groups.offsets),
            region(&self.state.x),
            region(&self.state.q),
        ]);
        for view in &self.views {
            lines(&encoded(&view.encoded));
        }
    }

    /// Brings `rest_groups` up to date with `rest`; cheap when it is.
    #[inline]
    pub(crate) fn refresh_rest_groups(&mut self) {
        if self.rest_groups_stale {
            self.rest_groups.rebuild(&self.rest);
            self.rest_groups_stale = false;
        }
    }

    /// Particles back at the rest shape under `anchor` (relative to the engine origin), at rest.
    pub(crate) fn place(&mut self, anchor: &Transform) {
        self.rest_used.clone_from(&self.rest);
        self.rest_changed = false;
        self.state.place_at_rest(&self.rest, anchor);
        for (j, local) in self.local_current.iter_mut().enumerate() {
            *local = Transform::new(self.rest.positions[j], self.rest.orientations[j]);
        }
        self.local_previous.clone_from(&self.local_current);
        self.placed = true;
        self.half_kick = true;
    }

    /// Records the state after a substep under `anchor` as the newest internal pose.
    pub(crate) fn capture_local(&mut self, anchor: &Transform) {
        std::mem::swap(&mut self.local_previous, &mut self.local_current);
        let inverse = anchor.inverse();
        for (j, local) in self.local_current.iter_mut().enumerate() {
            *local = Transform::new(
                anchor.inverse_transform_point_f64(self.state.x[j]),
                (inverse.rotation * self.state.q[j]).normalize(),
            );
        }
    }

    /// Output pose at fraction `t` along the last two internal states (see [`output_fraction`]), with every
    /// joint's bone axis swung onto the next joint (skinning-ready) and its twist kept. The pose is rebuilt
    /// from the root along the blended segment directions with the exact segment lengths: blending positions
    /// directly would shorten a fast-turning bone (interpolated, by up to 2 % at render rates that do not
    /// divide the substep rate).
    pub(crate) fn write_output(&mut self, t: f32) {
        let render = RenderInput {
            previous: &self.local_previous,
            current: &self.local_current,
            bone_axes: &self.bone_axes,
            lengths: &self.frame.lengths,
        };
        render.pose(t, &mut self.output);
    }

    /// After a step's substeps: the output pose for render time `after` seconds past the newest internal state
    /// (`h` the substep), and the way to sleep (`still`: nothing about the chain changed this step).
    pub(crate) fn finish_step(&mut self, still: bool, substeps: u64, h: f64, after: f64, settings: &EngineSettings) {
        self.write_output(output_fraction(h, after));
        self.track_sleep(still, substeps, h, settings);
    }

    /// [`finish_step`](Self::finish_step) for a chain whose output the lane solver wrote: towards sleeping.
    pub(crate) fn track_sleep(&mut self, still: bool, substeps: u64, h: f64, settings: &EngineSettings) {
        if settings.sleep_speed > 0.0 && substeps > 0 {
            if still && self.relative_speed() < settings.sleep_speed * settings.scale {
                self.still_time += (substeps as f64 * h) as f32;
                if self.still_time >= SLEEP_DELAY {
                    self.fall_asleep();
                }
            } else {
                self.still_time = 0.0;
            }
        }
    }

    /// Weights of the last blend: the base shape's, then each view shape's in the order they were added
    /// (0 for shapes added since). Updated by every step.
    pub(crate) fn weights(&self) -> impl Iterator<Item = f32> + '_ {
        let views = (0..self.views.len()).map(|i| self.weights.get(i).copied().unwrap_or(0.0));
        std::iter::once(self.base_weight).chain(views)
    }

    pub(crate) fn view_shape_index(&self, id: ViewShapeId) -> Option<usize> {
        self.views.iter().position(|v| v.id == id)
    }
}

/// What [`Chain::write_output`] blends: the last two captured poses (relative to the anchor), the bone
/// axes and the segment lengths.
pub(crate) struct RenderInput<'a> {
    pub previous: &'a [Transform],
    pub current: &'a [Transform],
    pub bone_axes: &'a [Vec3],
    pub lengths: &'a [f32],
}

impl RenderInput<'_> {
    /// The pose at fraction `t` along the two (beyond 1: extrapolated), into `output` (see [`Chain::write_output`]).
    pub(crate) fn pose(&self, t: f32, output: &mut [Transform]) {
        let (previous, current) = (self.previous, self.current);
        let n = output.len();
        for j in 0..n {
            output[j].rotation = nlerp_shorter(previous[j].rotation, current[j].rotation, t);
        }
        output[0].position = previous[0].position.lerp(current[0].position, t);
        for j in 0..n - 1 {
            let before = previous[j + 1].position - previous[j].position;
            let after = current[j + 1].position - current[j].position;
            let blended = match (direction(before), direction(after)) {
                (Some(a), Some(b)) => direction(a.lerp(b, t)).unwrap_or(b),
                (_, Some(b)) => b,
                (Some(a), None) => a,
                (None, None) => self.bone_axes[j],
            };
            output[j + 1].position = output[j].position + blended * self.lengths[j];
            output[j].rotation = swing_to(output[j].rotation, self.bone_axes[j], blended);
        }
    }
}

/// Where the render pose lies on the line through the last two internal states (0 the older, 1 the newest),
/// for render time `after` seconds past the newest (`h` the substep, `0 <= after < h`): the pose shows the
/// call's own time, so it has no display latency. Between 1 and 2 it carries the last substep's motion on,
/// by less than one substep. At render rates that divide the substep rate (30, 60, 120, 240 Hz at 240 Hz)
/// `after` is zero up to the float32 rounding of the frame time (`1 / 60` as an `f32` adds about 9e-10 s a
/// frame, so `t` creeps up by 2e-7 a frame until the clock takes one substep more) and the pose is the newest
/// state. Interpolating between the two (`after / h`, the usual fixed-step scheme and SPEC 3.5's) shows the
/// state one substep earlier instead: 1.1e-2 chain lengths of error as seen on the double pendulum at
/// 240 Hz, against 2.7e-5 here (`tests/physics.rs`, `the_pose_shows_the_call_time`). What carrying the motion
/// on costs, at render rates that do not divide the substep rate only: where the last substep stopped a
/// joint (a contact, a pre-stabilisation push) the pose runs on past it by up to that substep's motion until
/// the next substep lands, and each new substep changes the pose by its second difference (`a h^2`).
pub(crate) fn output_fraction(h: f64, after: f64) -> f32 {
    (1.0 + after / h) as f32
}

/// The two transforms are the same to the bit (unlike `==`, which takes `-0.0` for `0.0`): a pose stored under
/// one is the pose computed under the other.
#[inline]
pub(crate) fn same_bits(a: &Transform, b: &Transform) -> bool {
    let (p, q) = (a.position.to_array(), a.rotation.to_array());
    let (r, s) = (b.position.to_array(), b.rotation.to_array());
    // Folded with `&`, not `&&`: seven compares without a branch each.
    p.iter().zip(&r).chain(q.iter().zip(&s)).fold(true, |same, (x, y)| same & (x.to_bits() == y.to_bits()))
}

/// Share of a chain's shortest segment a joint must have been inside a collider at the start of a substep to
/// count as overlapping since then (see [`ContactInput::slop`](super::collision::ContactInput::slop)).
const CONTACT_SLOP: f32 = 1e-3;

fn shortest(lengths: &[f32]) -> f32 {
    lengths.iter().copied().fold(f32::INFINITY, f32::min)
}

fn bone_axes(shape: &Shape) -> Vec<Vec3> {
    let n = shape.len();
    let mut axes = Vec::with_capacity(n);
    for j in 0..n - 1 {
        let world = shape.positions[j + 1] - shape.positions[j];
        axes.push(direction(shape.orientations[j].inverse() * world).unwrap_or(Vec3::Y));
    }
    let tip = axes[n - 2];
    axes.push(tip);
    axes
}

/// Rotation of `q` relative to `parent`, the form Unity's `localRotation` takes.
#[inline]
pub(crate) fn relative_rotation(parent: Quat, q: Quat) -> Quat {
    (parent.inverse() * q).normalize()
}

#[cfg(test)]
mod tests {
    use glam::{Quat, Vec3};

    use super::*;

    /// A chain of `joints` joints hanging down, with a view shape from +X that leans it sideways by `lean`.
    fn leaning_chain(joints: usize, lean: f32) -> Chain {
        let at = |i: usize, x: f32| Transform::new(Vec3::new(x * i as f32, -0.1 * i as f32, 0.0), Quat::IDENTITY);
        let straight: Vec<Transform> = (0..joints).map(|i| at(i, 0.0)).collect();
        let leaning: Vec<Transform> = (0..joints).map(|i| at(i, lean)).collect();
        let mut chain = Chain::new(ChainParams::default(), &straight).unwrap();
        let encoded = chain.encode_view_shape(&leaning).unwrap();
        let weighting = ViewWeighting { direction: Vec3::X, influence: 2.0 };
        chain.push_view(ViewShape { id: ViewShapeId::from_bits(1), weighting, encoded });
        chain
    }

    fn rest_bits(c: &Chain) -> (Vec<u32>, bool) {
        let positions = c.rest.positions.iter().flat_map(|p| p.to_array());
        let orientations = c.rest.orientations.iter().flat_map(|q| q.to_array());
        (positions.chain(orientations).map(f32::to_bits).collect(), c.rest_changed)
    }

    /// `N` chains of different lengths updated together, each due or not (already blended for this view) in
    /// every combination, give each chain the bits of its own update.
    fn assert_updated_together_as_each_alone<const N: usize>(lengths: [usize; N]) {
        let view = Some(Vec3::new(0.6, 0.0, 0.8));
        let lean = |i: usize| 0.03 - 0.02 * i as f32;
        for due_mask in 0..(1u32 << N) {
            let due: [bool; N] = std::array::from_fn(|i| due_mask & (1 << i) != 0);
            let prepared = || -> Vec<Chain> {
                (0..N)
                    .map(|i| {
                        let mut chain = leaning_chain(lengths[i], lean(i));
                        if !due[i] {
                            chain.update_rest(view);
                            chain.rest_changed = false;
                        }
                        chain
                    })
                    .collect()
            };
            let mut together = prepared();
            let mut alone = prepared();
            for chain in &mut alone {
                chain.update_rest(view);
            }
            let group: [&mut Chain; N] = together.get_disjoint_mut(std::array::from_fn(|i| i)).unwrap();
            Chain::update_rest_together(group, view);
            for i in 0..N {
                assert_eq!(together[i].rest_changed, due[i], "chains {lengths:?}, due {due:?}");
                assert_eq!(rest_bits(&together[i]), rest_bits(&alone[i]), "chains {lengths:?}, due {due:?}");
                assert!(!together[i].rest_update_due(view));
            }
        }
    }

    #[test]
    fn chains_updated_together_update_their_rest_shapes_as_each_alone() {
        assert_updated_together_as_each_alone([5, 9]);
        assert_updated_together_as_each_alone([9, 5]);
        assert_updated_together_as_each_alone([5, 9, 3, 16]);
        assert_updated_together_as_each_alone([16, 16, 16, 16]);
    }

    #[test]
    fn cached_constants_follow_every_input() {
        let joints: Vec<Transform> =
            (0..4).map(|i| Transform::new(Vec3::new(0.0, 0.1 * i as f32, 0.0), Quat::IDENTITY)).collect();
        let mut chain = Chain::new(ChainParams::default(), &joints).unwrap();
        let bits = |c: ChainConstants| {
            [c.alpha_per_iteration, c.velocity_decay, c.gravity.x, c.gravity.y, c.gravity.z, c.orientation_weight]
                .map(f32::to_bits)
        };
        let check = |chain: &mut Chain, settings: EngineSettings, h: f32, iterations: u32| {
            let expected = ChainConstants::new(&chain.params, &settings, h, iterations);
            assert_eq!(bits(chain.constants(&settings, h, iterations)), bits(expected));
        };
        let settings = EngineSettings::default();
        check(&mut chain, settings, 1.0 / 240.0, 2);
        check(&mut chain, settings, 1.0 / 240.0, 2);
        check(&mut chain, settings, 1.0 / 120.0, 2);
        check(&mut chain, settings, 1.0 / 120.0, 1);
        check(&mut chain, EngineSettings { gravity: Vec3::new(0.0, -3.0, 0.0), ..settings }, 1.0 / 120.0, 1);
        check(&mut chain, EngineSettings { scale: 2.0, ..settings }, 1.0 / 120.0, 1);
        chain.params.stiffness = 0.25;
        check(&mut chain, settings, 1.0 / 120.0, 1);
        chain.params.damping = 7.0;
        check(&mut chain, settings, 1.0 / 120.0, 1);
        chain.params.radius = 0.05;
        check(&mut chain, settings, 1.0 / 120.0, 1);
    }

    fn collect(chain: &Chain) -> Vec<Transform> {
        let mut out = Vec::new();
        chain.for_each_world_transform(|t| out.push(t));
        out
    }

    #[test]
    fn a_sleeping_chains_world_pose_is_its_output_under_the_current_anchor() {
        let joints: Vec<Transform> =
            (0..5).map(|i| Transform::new(Vec3::new(0.0, -0.05 * i as f32, 0.01 * i as f32), Quat::IDENTITY)).collect();
        let mut chain = Chain::new(ChainParams::default(), &joints).unwrap();
        chain.anchor = Transform::new(Vec3::new(0.3, 1.6, -0.2), Quat::from_rotation_y(0.7));
        let under = |chain: &Chain, anchor: &Transform| chain.output.iter().map(|l| anchor.mul(l)).collect::<Vec<_>>();
        chain.fall_asleep();
        assert_eq!(collect(&chain), under(&chain, &chain.anchor), "asleep: the stored pose");
        // An anchor that changed without the chain waking (e.g. by rounding of the engine-relative anchor).
        let moved = Transform::new(Vec3::new(0.3, 1.6, -0.2 + 1e-6), Quat::from_rotation_y(0.7));
        chain.anchor = moved;
        assert_eq!(collect(&chain), under(&chain, &moved), "asleep under a moved anchor");
        chain.wake();
        assert_eq!(collect(&chain), under(&chain, &moved), "awake");
    }
}
