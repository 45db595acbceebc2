//! The engine: one per character. Owns chains and view shapes, the clock, and the solver scratch; one
//! `step` advances every chain.

use std::collections::BTreeMap;
use std::hash::{Hash, Hasher};
use std::sync::atomic::{AtomicU16, Ordering};

use glam::{Quat, Vec3};

use super::arena::{Arena, Id, Kind};
use super::buffers::reserve_total;
use super::chain::{Chain, ViewShape, ViewShapeId, output_fraction, same_bits};
use super::collider::{Collider, ColliderDef, ColliderId, ColliderPose, ColliderSweep};
use super::collision::ContactInput;
use super::error::{Error, Result};
use super::lanes::{Clock, FEWEST_IN_A_GROUP, LaneJob, LaneSolver, Solver};
use super::math::{Transform, normalized_direction, normalized_rotation, rotation_angle};
use super::params::{AnchorSource, ChainParams, EngineSettings, MAX_COORDINATE, MAX_RADIUS, TeleportMode};
use super::prefetch;
use super::reach::Reach;
use super::rod::{ChainConstants, RodScratch, SubstepInput, carry_to_new_rest, substep};
use super::weights::{ViewWeighting, view_direction};

pub type ChainId = Id<Chain>;

/// How many chains ahead the read-backs ask for a chain's pose, and the step for what its rest update reads:
/// enough for a memory access (a few hundred cycles) to finish while the chains in between are handled.
const READ_AHEAD: usize = 4;

/// Counters a host can show in a profiler overlay.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Stats {
    pub chain_count: u32,
    pub joint_count: u32,
    /// Internal substeps run by the last `step`.
    pub substeps_last_step: u32,
    /// Chains that cost nothing in the last step (sleeping or disabled). Always 0 until sleeping lands.
    pub chains_asleep: u32,
    /// Substeps where the direct inextensibility solve failed, or was skipped for a chain whose first solves
    /// keep failing it, and a fallback ran.
    pub solver_fallbacks: u64,
    pub substeps_total: u64,
    /// Simulated seconds dropped because a call needed more than `max_substeps`.
    pub time_dropped: f64,
    /// Simulated seconds advanced (after time scale), including the part not yet run as a substep.
    pub simulated_time: f64,
    pub collider_count: u32,
    /// (segment or particle, collider) pairs the contact pass tested, over all steps: 0 while no chain can
    /// touch a collider.
    pub contact_pairs_tested: u64,
    /// Chains the lane solver stepped in the last step (the others the scalar solver, or none).
    pub lane_chains: u32,
}

/// One chain's substeps of a step on the scalar solver.
struct ScalarRun<'a> {
    /// The anchor at the start and end of the step, relative to the engine origin.
    start: Transform,
    target: Transform,
    constants: ChainConstants,
    iterations: u32,
    h: f64,
    /// Fraction of the anchor motion reached at the end of each substep.
    progress: &'a [f32],
    /// The step's colliders and their sweeps.
    reach: &'a Reach<'a>,
}

impl ScalarRun<'_> {
    /// Runs the substeps, with contacts against `contacts.candidates` when given (and not empty). Returns the
    /// substeps whose direct inextensibility solve fell back and the contact pairs tested.
    fn step(
        &self,
        chain: &mut Chain,
        mut contacts: Option<&mut ContactScratch>,
        scratch: &mut RodScratch,
    ) -> (u64, u64) {
        let (h, collider_count) = (self.h, self.reach.order.len());
        let slop = chain.contact_slop();
        let substeps = self.progress.len();
        let (mut fallbacks, mut contact_pairs) = (0, 0);
        let mut ended_clear = false;
        for (s, &progress) in self.progress.iter().enumerate() {
            let anchor = self.start.interpolate(&self.target, progress);
            let touching = contacts.as_ref().is_some_and(|c| !c.candidates.is_empty());
            if let Some(contacts) = contacts.as_deref_mut().filter(|_| touching) {
                let row = &self.reach.sweeps[s * collider_count..][..collider_count];
                contacts.chain_sweeps.clear();
                contacts.chain_sweeps.extend(contacts.candidates.iter().map(|&c| row[c]));
            }
            let input = SubstepInput {
                h: h as f32,
                anchor,
                constants: self.constants,
                iterations: self.iterations,
                rest: &chain.rest,
                rest_groups: &chain.rest_groups,
                contact_settled: chain.contact_settled(),
                half_kick: chain.half_kick,
                contacts: contacts.as_deref().filter(|_| touching).map(|contacts| ContactInput {
                    colliders: &contacts.chain_sweeps,
                    radii: &contacts.radii,
                    lengths: &chain.frame.lengths,
                    friction: chain.params.friction,
                    slop,
                }),
                starts_clear: s > 0 && ended_clear,
            };
            let report = substep(&mut chain.state, &chain.frame.lengths, &input, scratch);
            ended_clear = report.ended_clear;
            fallbacks += report.fallback as u64;
            contact_pairs += report.contact_pairs;
            chain.half_kick = false;
            if s + 2 >= substeps {
                chain.capture_local(&anchor);
            }
        }
        (fallbacks, contact_pairs)
    }
}

/// Salts ids so that an id from one engine is rejected by another. Only distinguishes engines; it never
/// influences simulation results, so it is the one piece of process-wide state the library keeps.
static NEXT_SALT: AtomicU16 = AtomicU16::new(1);

pub struct Engine {
    settings: EngineSettings,
    chains: Arena<Chain>,
    /// Chain slots in creation order: the order of every batched read and write.
    order: Vec<u32>,
    view_shapes: Arena<u32>,
    colliders: Arena<Collider>,
    /// Collider slots in creation order: the order of `set_collider_transforms`.
    collider_order: Vec<u32>,
    accumulator: f64,
    /// World position the particle state is relative to: the view reference position of the last step,
    /// so a character far from the world origin keeps full float precision.
    origin: Vec3,
    view_reference: Option<Transform>,
    view: Option<Vec3>,
    joint_count: usize,
    scratch: RodScratch,
    contact_scratch: ContactScratch,
    /// Every collider's sweep in every substep of the current step: `[substep * colliders + collider]`.
    collider_sweeps: Vec<ColliderSweep>,
    solver: Solver,
    lanes: LaneSolver,
    /// The chains the lane solver steps in the current step, and the anchor progress of each substep.
    lane_jobs: Vec<LaneJob>,
    lane_leftovers: Vec<LaneJob>,
    progress: Vec<f32>,
    /// How many chains the engine holds of each joint count: what the step's buffers are sized for.
    chains_by_joints: BTreeMap<usize, usize>,
    stats: Stats,
}

/// Buffers of the contact pass, reused across steps.
#[derive(Default)]
struct ContactScratch {
    /// Indices (in collider order) of the colliders the current chain can touch this step.
    candidates: Vec<usize>,
    /// Their sweeps in the current substep.
    chain_sweeps: Vec<ColliderSweep>,
    radii: Vec<f32>,
}

impl Engine {
    pub fn new(settings: EngineSettings) -> Result<Self> {
        settings.validate()?;
        let salt = NEXT_SALT.fetch_add(1, Ordering::Relaxed);
        let mut engine = Self {
            settings,
            chains: Arena::new(Kind::Chain, salt),
            order: Vec::new(),
            view_shapes: Arena::new(Kind::ViewShape, salt),
            colliders: Arena::new(Kind::Collider, salt),
            collider_order: Vec::new(),
            accumulator: 0.0,
            origin: Vec3::ZERO,
            view_reference: None,
            view: None,
            joint_count: 0,
            scratch: RodScratch::default(),
            contact_scratch: ContactScratch::default(),
            collider_sweeps: Vec::new(),
            solver: Solver::default(),
            lanes: LaneSolver::default(),
            lane_jobs: Vec::new(),
            lane_leftovers: Vec::new(),
            progress: Vec::new(),
            chains_by_joints: BTreeMap::new(),
            stats: Stats::default(),
        };
        engine.reserve_step_buffers();
        Ok(engine)
    }

    /// Sizes the step's buffers for the chains and colliders the engine holds and for `max_substeps`, so
    /// that no step allocates however its work changes (a longer chain enabled or woken, a slow frame's
    /// extra substeps, chains moving between lane groups and the scalar solver as others sleep). Called
    /// whenever one of those grows; buffers only grow.
    fn reserve_step_buffers(&mut self) {
        let substeps = self.settings.max_substeps as usize;
        let colliders = self.collider_order.len();
        let chains = self.order.len();
        let longest = self.chains_by_joints.keys().next_back().copied().unwrap_or(0);
        self.scratch.reserve(longest);
        let contacts = &mut self.contact_scratch;
        reserve_total(&mut contacts.radii, longest);
        reserve_total(&mut contacts.candidates, colliders);
        reserve_total(&mut contacts.chain_sweeps, colliders);
        reserve_total(&mut self.progress, substeps);
        reserve_total(&mut self.collider_sweeps, substeps * colliders);
        reserve_total(&mut self.lane_jobs, chains);
        reserve_total(&mut self.lane_leftovers, chains);
        // Lane groups only for joint counts with enough chains to fill one (a single 1000-joint rope never
        // runs in lanes, and 16 lanes of it would take megabytes).
        let grouped = self.chains_by_joints.iter().rev().find(|&(_, &count)| count >= FEWEST_IN_A_GROUP);
        if let Some((&joints, _)) = grouped {
            self.lanes.reserve(joints, substeps, colliders);
        }
    }

    pub fn settings(&self) -> &EngineSettings {
        &self.settings
    }

    pub fn set_settings(&mut self, settings: EngineSettings) -> Result<()> {
        settings.validate()?;
        self.settings = settings;
        self.reserve_step_buffers();
        self.wake_all();
        Ok(())
    }

    /// Every chain simulates again from the next step (settings or colliders changed).
    fn wake_all(&mut self) {
        for &slot in &self.order {
            self.chains.at_mut(slot as usize).expect("live").wake();
        }
    }

    /// Which solver steps the chains ([`Solver::Lanes`] by default). Both give the same
    /// motion up to float rounding; the scalar one is the reference the lane solver is tested against.
    pub fn set_solver(&mut self, solver: Solver) {
        self.solver = solver;
    }

    pub fn solver(&self) -> Solver {
        self.solver
    }

    pub fn set_gravity(&mut self, gravity: Vec3) -> Result<()> {
        self.set_settings(EngineSettings { gravity, ..self.settings })
    }

    pub fn chain_count(&self) -> usize {
        self.order.len()
    }

    pub fn joint_count(&self) -> usize {
        self.joint_count
    }

    pub fn stats(&self) -> Stats {
        Stats {
            chain_count: self.order.len() as u32,
            joint_count: self.joint_count as u32,
            collider_count: self.collider_order.len() as u32,
            ..self.stats
        }
    }

    // ---- chains -------------------------------------------------------------------------------------

    pub fn create_chain(&mut self, params: ChainParams, joints: &[Transform]) -> Result<ChainId> {
        if !self.chains.has_room() {
            return Err(Error::capacity("the engine holds the maximum number of chains"));
        }
        let mut chain = Chain::new(params, joints)?;
        // Until its first step a new chain reads back in its rest shape under the last known anchor.
        chain.anchor = self.view_reference.unwrap_or(Transform::IDENTITY);
        let n = chain.joint_count();
        let id = self.chains.insert(chain).expect("room checked above");
        self.order.push(self.chains.index_of(id).expect("just inserted") as u32);
        self.joint_count += n;
        *self.chains_by_joints.entry(n).or_default() += 1;
        self.reserve_step_buffers();
        Ok(id)
    }

    pub(crate) fn chain(&self, id: ChainId) -> Result<&Chain> {
        self.chains
            .get(id)
            .ok_or_else(|| Error::invalid_id(format!("chain id {:#x} is null, stale or foreign", id.to_bits())))
    }

    fn chain_mut(&mut self, id: ChainId) -> Result<&mut Chain> {
        self.chains
            .get_mut(id)
            .ok_or_else(|| Error::invalid_id(format!("chain id {:#x} is null, stale or foreign", id.to_bits())))
    }

    pub fn is_chain_valid(&self, id: ChainId) -> bool {
        self.chains.get(id).is_some()
    }

    pub fn destroy_chain(&mut self, id: ChainId) -> Result<()> {
        let index = self
            .chains
            .index_of(id)
            .ok_or_else(|| Error::invalid_id(format!("chain id {:#x} is null, stale or foreign", id.to_bits())))?;
        let chain = self.chains.remove(id).expect("checked above");
        for view in &chain.views {
            self.view_shapes.remove(Id::from_bits(view.id.to_bits()));
        }
        self.order.retain(|&slot| slot as usize != index);
        self.joint_count -= chain.joint_count();
        if let Some(count) = self.chains_by_joints.get_mut(&chain.joint_count()) {
            *count -= 1;
            if *count == 0 {
                self.chains_by_joints.remove(&chain.joint_count());
            }
        }
        Ok(())
    }

    pub fn chain_joint_count(&self, id: ChainId) -> Result<usize> {
        Ok(self.chain(id)?.joint_count())
    }

    pub fn chain_params(&self, id: ChainId) -> Result<ChainParams> {
        Ok(self.chain(id)?.params)
    }

    pub fn set_chain_params(&mut self, id: ChainId, params: ChainParams) -> Result<()> {
        params.validate()?;
        let chain = self.chain_mut(id)?;
        chain.params = params;
        chain.wake();
        Ok(())
    }

    pub fn set_base_shape(&mut self, id: ChainId, joints: &[Transform]) -> Result<()> {
        self.chain_mut(id)?.set_base_shape(joints)
    }

    /// Back to the rest shape under the current anchor, at rest, at the next step.
    pub fn reset_chain(&mut self, id: ChainId) -> Result<()> {
        self.chain_mut(id)?.placed = false;
        Ok(())
    }

    pub fn reset_all(&mut self) {
        for &slot in &self.order {
            if let Some(chain) = self.chains.at_mut(slot as usize) {
                chain.placed = false;
            }
        }
    }

    /// Anchors for the next step, one per chain in creation order (entries of chains anchored to the view
    /// reference are validated but unused).
    pub fn set_anchors<I>(&mut self, anchors: I) -> Result<()>
    where
        I: ExactSizeIterator<Item = Transform> + Clone,
    {
        if anchors.len() != self.order.len() {
            return Err(Error::invalid_argument(format!(
                "set_anchors needs one transform per chain ({}), got {}",
                self.order.len(),
                anchors.len()
            )));
        }
        let unchanged = |chain: &Chain, anchor: &Transform| chain.anchor_given.is_some_and(|g| same_bits(&g, anchor));
        for (i, (&slot, anchor)) in self.order.iter().zip(anchors.clone()).enumerate() {
            let chain = self.chains.at(slot as usize).expect("order holds live chains");
            if !unchanged(chain, &anchor) {
                check_transform(&anchor).map_err(|e| Error::invalid_argument(format!("anchor {i}: {e}")))?;
            }
        }
        for (&slot, anchor) in self.order.iter().zip(anchors) {
            let chain = self.chains.at_mut(slot as usize).expect("order holds live chains");
            if !unchanged(chain, &anchor) {
                chain.anchor_pending = normalized_transform(&anchor);
                chain.anchor_given = Some(anchor);
            }
            if !chain.placed && chain.params.anchor == AnchorSource::Own {
                // Until its first step a new chain reads back in its rest shape under this anchor.
                chain.anchor = chain.anchor_pending;
            }
        }
        Ok(())
    }

    /// Per-joint collision radii in character units (× `scale` m), one per joint, each in [0, 1e6]; an empty
    /// slice goes back to `params.radius` for every joint.
    pub fn set_chain_joint_radii(&mut self, id: ChainId, radii: &[f32]) -> Result<()> {
        let chain = self.chain(id)?;
        if !radii.is_empty() && radii.len() != chain.joint_count() {
            return Err(Error::invalid_argument(format!(
                "set_chain_joint_radii needs one radius per joint ({}) or none, got {}",
                chain.joint_count(),
                radii.len()
            )));
        }
        if let Some((j, r)) = radii.iter().enumerate().find(|(_, r)| !(0.0..=MAX_RADIUS).contains(*r)) {
            return Err(Error::invalid_argument(format!("joint radius {j} is {r}, outside [0, {MAX_RADIUS}]")));
        }
        let chain = self.chain_mut(id)?;
        chain.joint_radii.clear();
        chain.joint_radii.extend_from_slice(radii);
        chain.wake();
        Ok(())
    }

    /// A disabled (culled) chain is not simulated and costs nothing; it follows its anchor rigidly in its last
    /// pose. Enabled again, it carries on from that pose, carried rigidly to where its anchor is now (no whip,
    /// in either teleport mode).
    pub fn set_chain_enabled(&mut self, id: ChainId, enabled: bool) -> Result<()> {
        let chain = self.chain_mut(id)?;
        if chain.enabled && !enabled {
            // The state stays where it was simulated last; re-enabled, it is carried (whatever the teleport mode)
            // from that anchor to the current one by the next step.
            chain.resume_from = Some(chain.anchor);
        }
        if enabled != chain.enabled {
            chain.wake();
        }
        chain.enabled = enabled;
        Ok(())
    }

    pub fn is_chain_enabled(&self, id: ChainId) -> Result<bool> {
        Ok(self.chain(id)?.enabled)
    }

    /// Whether the chain slept through the last step.
    pub fn is_chain_asleep(&self, id: ChainId) -> Result<bool> {
        Ok(self.chain(id)?.asleep)
    }

    /// The next step treats the chain's anchor motion as a teleport (see [`TeleportMode`]), whatever its size.
    pub fn teleport_chain(&mut self, id: ChainId) -> Result<()> {
        self.chain_mut(id)?.teleport_requested = true;
        Ok(())
    }

    /// [`teleport_chain`](Self::teleport_chain) for every chain: the character jumped.
    pub fn teleport_all(&mut self) {
        for &slot in &self.order {
            if let Some(chain) = self.chains.at_mut(slot as usize) {
                chain.teleport_requested = true;
            }
        }
    }

    // ---- colliders ----------------------------------------------------------------------------------

    pub fn create_collider(&mut self, def: &ColliderDef) -> Result<ColliderId> {
        def.validate()?;
        let pose = validate_transform(&def.transform).map_err(|e| Error::invalid_argument(format!("collider: {e}")))?;
        if !self.colliders.has_room() {
            return Err(Error::capacity("the engine holds the maximum number of colliders"));
        }
        let id = self.colliders.insert(Collider::new(def, pose)).expect("room checked above");
        self.wake_all();
        self.collider_order.push(self.colliders.index_of(id).expect("just inserted") as u32);
        self.reserve_step_buffers();
        Ok(Id::from_bits(id.to_bits()))
    }

    pub fn destroy_collider(&mut self, id: ColliderId) -> Result<()> {
        let own = Id::from_bits(id.to_bits());
        let index = self.colliders.index_of(own).ok_or_else(|| collider_not_found(id))?;
        self.colliders.remove(own);
        self.collider_order.retain(|&slot| slot as usize != index);
        self.wake_all();
        Ok(())
    }

    pub fn is_collider_valid(&self, id: ColliderId) -> bool {
        self.colliders.get(Id::from_bits(id.to_bits())).is_some()
    }

    pub fn collider_count(&self) -> usize {
        self.collider_order.len()
    }

    /// Collider ids in creation order (the order of [`set_collider_transforms`](Self::set_collider_transforms)).
    pub fn collider_ids(&self) -> impl Iterator<Item = ColliderId> + '_ {
        self.collider_order
            .iter()
            .map(|&slot| Id::from_bits(self.colliders.id_at(slot as usize).expect("live").to_bits()))
    }

    /// Changes a collider's size (its kind stays): `radius` and `half_height` as in [`ColliderShape`], both
    /// validated like at creation; a field the shape does not use must still be finite and in range.
    pub fn set_collider_size(&mut self, id: ColliderId, radius: f32, half_height: f32) -> Result<()> {
        let collider = self.colliders.get(Id::from_bits(id.to_bits())).ok_or_else(|| collider_not_found(id))?;
        let shape = collider.shape.resized(radius, half_height)?;
        self.colliders.get_mut(Id::from_bits(id.to_bits())).expect("checked above").shape = shape;
        self.wake_all();
        Ok(())
    }

    /// Changes a collider's layers.
    pub fn set_collider_layers(&mut self, id: ColliderId, layers: u32) -> Result<()> {
        self.colliders.get_mut(Id::from_bits(id.to_bits())).ok_or_else(|| collider_not_found(id))?.layers = layers;
        self.wake_all();
        Ok(())
    }

    /// World poses of every collider for the next step, in creation order. The step moves each collider
    /// from its last pose to this one across its substeps; a jump beyond the teleport thresholds is not swept.
    pub fn set_collider_transforms<I>(&mut self, transforms: I) -> Result<()>
    where
        I: ExactSizeIterator<Item = Transform> + Clone,
    {
        if transforms.len() != self.collider_order.len() {
            return Err(Error::invalid_argument(format!(
                "set_collider_transforms needs one transform per collider ({}), got {}",
                self.collider_order.len(),
                transforms.len()
            )));
        }
        for (i, t) in transforms.clone().enumerate() {
            check_transform(&t).map_err(|e| Error::invalid_argument(format!("collider transform {i}: {e}")))?;
        }
        for (&slot, t) in self.collider_order.iter().zip(transforms) {
            let collider = self.colliders.at_mut(slot as usize).expect("order holds live colliders");
            collider.pending = normalized_transform(&t);
        }
        Ok(())
    }

    // ---- view shapes --------------------------------------------------------------------------------

    pub fn add_view_shape(
        &mut self,
        chain_id: ChainId,
        view_direction: Vec3,
        joints: &[Transform],
        influence: f32,
    ) -> Result<ViewShapeId> {
        let slot = self.chains.index_of(chain_id).ok_or_else(|| {
            Error::invalid_id(format!("chain id {:#x} is null, stale or foreign", chain_id.to_bits()))
        })?;
        let direction = validate_direction(view_direction)?;
        validate_influence(influence)?;
        let chain = self.chains.at(slot).expect("checked");
        let encoded = chain.encode_view_shape(joints)?;
        if !self.view_shapes.has_room() {
            return Err(Error::capacity("the engine holds the maximum number of view shapes"));
        }
        let id = Id::from_bits(self.view_shapes.insert(slot as u32).expect("room checked").to_bits());
        let chain = self.chains.at_mut(slot).expect("checked");
        chain.push_view(ViewShape { id, weighting: ViewWeighting { direction, influence }, encoded });
        Ok(id)
    }

    fn view_shape_mut(&mut self, id: ViewShapeId) -> Result<(&mut Chain, usize)> {
        let err = || Error::invalid_id(format!("view shape id {:#x} is null, stale or foreign", id.to_bits()));
        let slot = *self.view_shapes.get(Id::from_bits(id.to_bits())).ok_or_else(err)?;
        let chain = self.chains.at_mut(slot as usize).ok_or_else(err)?;
        let index = chain.view_shape_index(id).ok_or_else(err)?;
        Ok((chain, index))
    }

    pub fn is_view_shape_valid(&self, id: ViewShapeId) -> bool {
        self.view_shapes.get(Id::from_bits(id.to_bits())).is_some()
    }

    pub fn set_view_shape_influence(&mut self, id: ViewShapeId, influence: f32) -> Result<()> {
        validate_influence(influence)?;
        let (chain, index) = self.view_shape_mut(id)?;
        chain.views[index].weighting.influence = influence;
        chain.mark_shapes_dirty();
        Ok(())
    }

    pub fn set_view_shape_direction(&mut self, id: ViewShapeId, view_direction: Vec3) -> Result<()> {
        let direction = validate_direction(view_direction)?;
        let (chain, index) = self.view_shape_mut(id)?;
        chain.views[index].weighting.direction = direction;
        chain.mark_shapes_dirty();
        Ok(())
    }

    pub fn set_view_shape_joints(&mut self, id: ViewShapeId, joints: &[Transform]) -> Result<()> {
        let (chain, index) = self.view_shape_mut(id)?;
        let encoded = chain.encode_view_shape(joints)?;
        chain.views[index].encoded = encoded;
        chain.mark_shapes_dirty();
        Ok(())
    }

    pub fn remove_view_shape(&mut self, id: ViewShapeId) -> Result<()> {
        let (chain, index) = self.view_shape_mut(id)?;
        chain.views.remove(index);
        chain.mark_shapes_dirty();
        self.view_shapes.remove(Id::from_bits(id.to_bits()));
        Ok(())
    }

    pub fn view_shape_count(&self, chain_id: ChainId) -> Result<usize> {
        Ok(self.chain(chain_id)?.views.len())
    }

    // ---- stepping -----------------------------------------------------------------------------------

    /// Advances the simulation by `dt` seconds of real time (scaled by `time_scale`) with the camera at
    /// `camera` and the view reference joint K at `view_reference` (world space). Inputs are validated
    /// before anything changes; `dt == 0` changes nothing.
    pub fn step(&mut self, dt: f32, camera: Vec3, view_reference: Transform) -> Result<()> {
        let k = validate_step(dt, camera, &view_reference)?;
        if dt > 0.0 {
            self.advance(dt, camera, k);
        }
        Ok(())
    }

    /// A whole frame in one call: the anchors for this step (as [`set_anchors`](Self::set_anchors)), then the
    /// step. Every input is validated before anything changes; with `dt == 0` only the anchors are stored.
    pub fn step_with_anchors<I>(&mut self, anchors: I, dt: f32, camera: Vec3, view_reference: Transform) -> Result<()>
    where
        I: ExactSizeIterator<Item = Transform> + Clone,
    {
        let k = validate_step(dt, camera, &view_reference)?;
        self.set_anchors(anchors)?;
        if dt > 0.0 {
            self.advance(dt, camera, k);
        }
        Ok(())
    }

    /// The step itself, on validated input (`dt > 0`, K normalised).
    fn advance(&mut self, dt: f32, camera: Vec3, k: Transform) {
        // The particle state is rebased on the new origin once per chain: for a chain the lane solver steps, as
        // its lane group loads it (a pass over every chain's positions fewer); for any other, below, before
        // anything reads it.
        let origin = k.position;
        let shift = self.origin - origin;
        let rebase = (shift != Vec3::ZERO).then(|| shift.as_dvec3());
        self.origin = origin;
        if let Some(d) = view_direction(camera, &k) {
            self.view = Some(d);
        }
        self.view_reference = Some(k);

        // Clock: fixed substeps from an accumulator, capped.
        let settings = self.settings;
        let h = 1.0 / settings.effective_substep_rate() as f64;
        let iterations = settings.effective_iterations();
        let simulated = dt as f64 * settings.time_scale as f64;
        let before = self.accumulator;
        let mut available = before + simulated;
        let mut substeps = (available / h).floor() as u64;
        let mut dropped = 0.0;
        if substeps > settings.max_substeps as u64 {
            substeps = settings.max_substeps as u64;
            dropped = available - substeps as f64 * h;
            available = substeps as f64 * h;
        }
        let after = (available - substeps as f64 * h).max(0.0);
        // Fraction of this call's motion reached at the end of each substep, for anchor interpolation.
        let span = available - before;
        let progress = |s: u64| {
            if span > 0.0 { (((s + 1) as f64 * h - before) / span).clamp(0.0, 1.0) as f32 } else { 1.0 }
        };

        self.progress.clear();
        self.progress.extend((0..substeps).map(progress));
        let progress_at_start = |s: u64| if s == 0 { 0.0 } else { progress(s - 1) };
        self.sweep_colliders(substeps, origin, progress_at_start, progress);
        let reach = Reach {
            colliders: &self.colliders,
            order: &self.collider_order,
            sweeps: &self.collider_sweeps,
            substeps: substeps as usize,
            scale: settings.scale,
        };
        let teleport_distance = settings.teleport_distance * settings.scale;

        let mut fallbacks = 0u64;
        let mut contact_pairs = 0u64;
        let mut idle = 0u32;
        let mut lane_chains = 0u32;
        let view = self.view;
        let rest_update_ahead = |chains: &Arena<Chain>, slot: Option<&u32>| {
            if let Some(chain) = slot.and_then(|&slot| chains.at(slot as usize)) {
                chain.prefetch_rest_update(view);
            }
        };
        self.order.iter().take(READ_AHEAD).for_each(|slot| rest_update_ahead(&self.chains, Some(slot)));
        for (index, &slot) in self.order.iter().enumerate() {
            rest_update_ahead(&self.chains, self.order.get(index + READ_AHEAD));
            // A chain whose rest shape is due for an update takes the next three chains' along, or the next one's
            // (`Chain::update_rest_together`), whose own `update_rest` below then has nothing to do. A scene whose
            // rest shapes stay (no view shapes, a still camera) pays this one check per chain.
            let due = self.chains.at(slot as usize).is_some_and(|chain| chain.enabled && chain.rest_update_due(view));
            if due && !update_rests_together::<4>(&self.order, &mut self.chains, index, view) {
                update_rests_together::<2>(&self.order, &mut self.chains, index, view);
            }
            let chain = self.chains.at_mut(slot as usize).expect("live");
            let mut rebase = rebase;
            let mut rebase_now = |chain: &mut Chain| {
                if let Some(shift) = rebase.take() {
                    chain.state.translate(shift);
                }
            };
            let anchor_world = match chain.params.anchor {
                AnchorSource::ViewReference => k,
                AnchorSource::Own => chain.anchor_pending,
            };
            let to_relative = |t: &Transform| Transform::new(t.position - origin, t.rotation);
            let target = to_relative(&anchor_world);
            let mut start = to_relative(&chain.anchor);
            if !chain.enabled {
                rebase_now(chain);
                chain.anchor = anchor_world;
                idle += 1;
                continue;
            }
            let resuming = chain.resume_from.take();
            if let Some(from) = resuming {
                start = to_relative(&from);
            }
            let anchor_still = start == target && chain.placed;
            chain.update_rest(self.view);
            let teleport = std::mem::take(&mut chain.teleport_requested)
                || is_teleport(&start, &target, teleport_distance, settings.teleport_angle);
            if !chain.placed || (teleport && settings.teleport_mode == TeleportMode::Reset && resuming.is_none()) {
                rebase_now(chain);
                chain.place(&target);
                start = target;
            } else if teleport || resuming.is_some() {
                // Carry the chain rigidly: keeps its shape, adds no energy, no whip.
                rebase_now(chain);
                chain.state.carry(&target.mul(&start.inverse()));
                start = target;
            }
            chain.anchor = anchor_world;

            // The colliders this chain can touch during this step: on a layer of its mask and close enough. A chain
            // whose anchor or rest shape moves is not still whatever they do, and the lane solver finds them itself
            // when it loads the chain: looked for here too, they took 1.6 % of the instructions of `scene_cost 10
            // 1000x16 colliders`.
            let may_rest = anchor_still && !teleport && !chain.rest_changed;
            let to_lanes = self.solver != Solver::Scalar && substeps > 0;
            let (candidates, radii) = (&mut self.contact_scratch.candidates, &mut self.contact_scratch.radii);
            candidates.clear();
            if may_rest || !to_lanes {
                reach.candidates(chain, &start, &target, candidates, radii);
            }

            // Sleeping (SPEC 3.8): skipped while its anchor, rest shape and nearby colliders stay still.
            let colliders_moving = candidates.iter().any(|&c| {
                let (first, last) = reach.first_and_last(c);
                first.start.centre != last.end.centre || first.start.rotation != last.end.rotation
            });
            let still = may_rest && !colliders_moving;
            if chain.asleep {
                if still {
                    rebase_now(chain);
                    idle += 1;
                    continue;
                }
                chain.wake();
            }

            let params = chain.params;
            let constants = chain.constants(&settings, h as f32, iterations);
            if substeps > 0 {
                if chain.rest_changed {
                    let share = params.momentum_suppression * params.alpha_per_substep(h as f32);
                    if share > 0.0 {
                        rebase_now(chain);
                        let anchor = start.interpolate(&target, progress(0));
                        carry_to_new_rest(
                            &mut chain.state,
                            &anchor,
                            &chain.rest_used,
                            &chain.rest,
                            share,
                            &mut self.scratch,
                        );
                    }
                    chain.rest_used.clone_from(&chain.rest);
                    chain.rest_changed = false;
                }
                chain.refresh_rest_groups();
            }
            if self.solver != Solver::Scalar && substeps > 0 {
                let joints = chain.joint_count();
                self.lane_jobs.push(LaneJob { slot, joints, start, target, constants, still, rebase });
                continue;
            }
            rebase_now(chain);
            let run = ScalarRun { start, target, constants, iterations, h, progress: &self.progress, reach: &reach };
            let (chain_fallbacks, pairs) = run.step(chain, Some(&mut self.contact_scratch), &mut self.scratch);
            fallbacks += chain_fallbacks;
            contact_pairs += pairs;
            chain.finish_step(still, substeps, h, after, &settings);
        }
        if !self.lane_jobs.is_empty() {
            let clock =
                Clock { h: h as f32, iterations, progress: &self.progress, output_fraction: output_fraction(h, after) };
            let portable = self.solver == Solver::LanesPortable;
            let (lane_fallbacks, lane_pairs) = self.lanes.step(
                &mut self.chains,
                &mut self.lane_jobs,
                &mut self.lane_leftovers,
                &clock,
                &reach,
                portable,
            );
            fallbacks += lane_fallbacks;
            contact_pairs += lane_pairs;
            lane_chains = self.lane_jobs.len() as u32;
            // The last 1 or 2 chains of a joint count after its full lane groups are faster on the scalar solver.
            for job in &self.lane_leftovers {
                let chain = self.chains.at_mut(job.slot as usize).expect("live");
                if let Some(shift) = job.rebase {
                    chain.state.translate(shift);
                }
                let run = ScalarRun {
                    start: job.start,
                    target: job.target,
                    constants: job.constants,
                    iterations,
                    h,
                    progress: &self.progress,
                    reach: &reach,
                };
                let (candidates, radii) = (&mut self.contact_scratch.candidates, &mut self.contact_scratch.radii);
                reach.candidates(chain, &job.start, &job.target, candidates, radii);
                let (chain_fallbacks, pairs) = run.step(chain, Some(&mut self.contact_scratch), &mut self.scratch);
                fallbacks += chain_fallbacks;
                contact_pairs += pairs;
            }
            for job in self.lane_jobs.drain(..) {
                let chain = self.chains.at_mut(job.slot as usize).expect("live");
                chain.track_sleep(job.still, substeps, h, &settings);
            }
            for job in self.lane_leftovers.drain(..) {
                let chain = self.chains.at_mut(job.slot as usize).expect("live");
                chain.finish_step(job.still, substeps, h, after, &settings);
            }
        }
        if substeps > 0 {
            for &slot in &self.collider_order {
                let collider = self.colliders.at_mut(slot as usize).expect("live");
                collider.previous = collider.current;
            }
        }
        self.accumulator = after;
        self.stats.contact_pairs_tested += contact_pairs;
        self.stats.chains_asleep = idle;
        self.stats.lane_chains = lane_chains;
        self.stats.substeps_last_step = substeps as u32;
        self.stats.substeps_total += substeps;
        self.stats.solver_fallbacks += fallbacks;
        self.stats.time_dropped += dropped;
        self.stats.simulated_time += simulated;
    }

    /// Moves every collider to the pose set for this step and records its pose at the start and end of
    /// each substep (relative to the engine origin). A collider that jumped beyond the teleport thresholds
    /// is not swept: it appears at its new pose.
    fn sweep_colliders(
        &mut self,
        substeps: u64,
        origin: Vec3,
        at_start: impl Fn(u64) -> f32,
        at_end: impl Fn(u64) -> f32,
    ) {
        let settings = self.settings;
        let sweeps = &mut self.collider_sweeps;
        sweeps.clear();
        for &slot in &self.collider_order {
            let collider = self.colliders.at_mut(slot as usize).expect("live");
            collider.current = collider.pending;
            if is_teleport(
                &collider.previous,
                &collider.current,
                settings.teleport_distance * settings.scale,
                settings.teleport_angle,
            ) {
                collider.previous = collider.current;
            }
        }
        for s in 0..substeps {
            for &slot in &self.collider_order {
                let collider = self.colliders.at(slot as usize).expect("live");
                // A still collider keeps its pose to the bit: interpolating a pose with itself can round off it,
                // which made a still ground plane or sphere count as moving (never out of reach, never letting
                // a chain near it sleep).
                let still = same_bits(&collider.previous, &collider.current);
                let pose = |t: f32| {
                    let at = if still { collider.current } else { collider.previous.interpolate(&collider.current, t) };
                    ColliderPose::new(&at, origin)
                };
                sweeps.push(ColliderSweep { shape: collider.shape, start: pose(at_start(s)), end: pose(at_end(s)) });
            }
        }
    }

    // ---- reading ------------------------------------------------------------------------------------

    fn chains_in_order(&self) -> impl Iterator<Item = &Chain> {
        self.order.iter().map(|&slot| self.chains.at(slot as usize).expect("live"))
    }

    /// [`chains_in_order`](Self::chains_in_order) for the read-backs, which read each chain's `pose` long
    /// after the step wrote it: the pose of a chain is asked for ([`prefetch`]) `READ_AHEAD` chains before it
    /// is read.
    fn chains_to_read(&self, pose: fn(&Chain) -> &[Transform]) -> impl Iterator<Item = &Chain> {
        let chain = |slot: &u32| self.chains.at(*slot as usize).expect("live");
        let ask = move |chain: &Chain| prefetch::lines(&[prefetch::region(pose(chain))]);
        self.order.iter().take(READ_AHEAD).for_each(|slot| ask(chain(slot)));
        let ahead = self.order.iter().skip(READ_AHEAD).map(Some).chain(std::iter::repeat(None));
        self.order.iter().zip(ahead).map(move |(slot, ahead)| {
            if let Some(ahead) = ahead {
                ask(chain(ahead));
            }
            chain(slot)
        })
    }

    /// Chain ids in creation order (the order of batched reads and writes).
    pub fn chain_ids(&self) -> impl Iterator<Item = ChainId> + '_ {
        self.order.iter().map(|&slot| self.chains.id_at(slot as usize).expect("live"))
    }

    /// Calls `f` with the world transform of every joint of every chain, in creation order; fails
    /// without calling it when `capacity` is below the joint count.
    pub fn for_each_world_transform(&self, capacity: usize, mut f: impl FnMut(Transform)) -> Result<()> {
        self.check_capacity(capacity)?;
        for chain in self.chains_to_read(Chain::shown_pose) {
            chain.for_each_world_transform(&mut f);
        }
        Ok(())
    }

    /// Calls `f` with each joint's rotation relative to its parent (joint 0: relative to the anchor), in
    /// the order of [`for_each_world_transform`](Self::for_each_world_transform).
    pub fn for_each_local_rotation(&self, capacity: usize, mut f: impl FnMut(Quat)) -> Result<()> {
        self.check_capacity(capacity)?;
        for chain in self.chains_to_read(Chain::output_pose) {
            chain.local_rotations().for_each(&mut f);
        }
        Ok(())
    }

    /// World transforms of every joint of every chain, in creation order. Returns how many were written.
    pub fn read_world(&self, out: &mut [Transform]) -> Result<usize> {
        self.read_world_as(out, |world| world)
    }

    /// [`read_world`](Self::read_world) into a host's own transform type, each converted by `convert` (the
    /// C ABI's `kdw_transform`): one pass over every chain's joints, with no call per joint to a callback that
    /// the compiler cannot inline.
    pub fn read_world_as<T>(&self, out: &mut [T], convert: impl Fn(Transform) -> T) -> Result<usize> {
        self.fill_by_chain(out, Chain::shown_pose, |chain, slots| chain.write_world_as(slots, &convert))
    }

    /// Local rotations (see [`for_each_local_rotation`](Self::for_each_local_rotation)) into `out`.
    pub fn read_local_rotations(&self, out: &mut [Quat]) -> Result<usize> {
        self.read_local_rotations_as(out, |rotation| rotation)
    }

    /// [`read_local_rotations`](Self::read_local_rotations) into a host's own quaternion type, each converted by
    /// `convert` (see [`read_world_as`](Self::read_world_as)).
    pub fn read_local_rotations_as<T>(&self, out: &mut [T], convert: impl Fn(Quat) -> T) -> Result<usize> {
        self.fill_by_chain(out, Chain::output_pose, |chain, slots| {
            for (slot, rotation) in slots.iter_mut().zip(chain.local_rotations()) {
                *slot = convert(rotation);
            }
        })
    }

    /// Checks that `out` holds every joint, then hands `fill` each chain, in creation order (its `pose` asked for
    /// ahead: [`chains_to_read`](Self::chains_to_read)), with its joints' slots of `out`. Returns how many were
    /// written.
    fn fill_by_chain<T>(
        &self,
        out: &mut [T],
        pose: fn(&Chain) -> &[Transform],
        mut fill: impl FnMut(&Chain, &mut [T]),
    ) -> Result<usize> {
        self.check_capacity(out.len())?;
        let mut written = 0;
        for chain in self.chains_to_read(pose) {
            let joints = chain.joint_count();
            fill(chain, &mut out[written..written + joints]);
            written += joints;
        }
        Ok(written)
    }

    /// Calls `f` with the world transform of each joint of one chain; fails without calling it when
    /// `capacity` is below the chain's joint count.
    pub fn for_each_chain_world_transform(&self, id: ChainId, capacity: usize, f: impl FnMut(Transform)) -> Result<()> {
        let chain = self.chain(id)?;
        check_chain_capacity(chain, capacity)?;
        chain.for_each_world_transform(f);
        Ok(())
    }

    /// Calls `f` with each joint of the rest shape a chain is currently pulled towards (anchor frame).
    pub fn for_each_chain_rest_transform(
        &self,
        id: ChainId,
        capacity: usize,
        mut f: impl FnMut(Transform),
    ) -> Result<()> {
        let chain = self.chain(id)?;
        check_chain_capacity(chain, capacity)?;
        for (p, q) in chain.rest.positions.iter().zip(&chain.rest.orientations) {
            f(Transform::new(*p, *q));
        }
        Ok(())
    }

    /// Calls `f` with the world position of each particle of one chain in the latest internal state (not
    /// interpolated for rendering): what the solver and the contact pass see.
    pub fn for_each_chain_particle(&self, id: ChainId, mut f: impl FnMut(Vec3)) -> Result<()> {
        let chain = self.chain(id)?;
        let origin = self.origin.as_dvec3();
        chain.state.x.iter().for_each(|x| f((*x + origin).as_vec3()));
        Ok(())
    }

    /// World transforms of one chain's joints into `out`; returns how many were written.
    pub fn read_chain_world(&self, id: ChainId, out: &mut [Transform]) -> Result<usize> {
        let chain = self.chain(id)?;
        check_chain_capacity(chain, out.len())?;
        let n = chain.joint_count();
        chain.write_world(&mut out[..n]);
        Ok(n)
    }

    /// The rest shape a chain is currently pulled towards (anchor frame) into `out`.
    pub fn chain_rest_shape(&self, id: ChainId, out: &mut [Transform]) -> Result<usize> {
        fill_slice(out, |capacity, f| self.for_each_chain_rest_transform(id, capacity, f))
    }

    /// Calls `f` with the weights of the chain's last blend: the base shape's first, then each view shape's in
    /// the order they were added (what a gizmo shows). Fails without calling it when `capacity` is below
    /// `1 + view_shape_count`.
    pub fn for_each_chain_weight(&self, id: ChainId, capacity: usize, f: impl FnMut(f32)) -> Result<()> {
        let chain = self.chain(id)?;
        if capacity < 1 + chain.views.len() {
            return Err(Error::buffer_too_small(format!(
                "buffer holds {capacity} weights, the chain needs {} (base + view shapes)",
                1 + chain.views.len()
            )));
        }
        chain.weights().for_each(f);
        Ok(())
    }

    /// Kinetic energy of a chain's dynamic particles (J), from internal velocities.
    pub fn chain_kinetic_energy(&self, id: ChainId) -> Result<f32> {
        let chain = self.chain(id)?;
        Ok(0.5 * chain.params.mass * chain.state.v[1..].iter().map(|v| v.length_squared()).sum::<f32>())
    }

    fn check_capacity(&self, capacity: usize) -> Result<()> {
        if capacity < self.joint_count {
            return Err(Error::buffer_too_small(format!(
                "buffer holds {capacity} entries, the engine has {} joints",
                self.joint_count
            )));
        }
        Ok(())
    }

    /// Hash of everything that determines future results: for determinism tests and for checking that a
    /// rejected call left the engine bit-identical.
    pub fn state_hash(&self) -> u64 {
        let mut hasher = std::collections::hash_map::DefaultHasher::new();
        let mut f = |x: f32| x.to_bits().hash(&mut hasher);
        let s = &self.settings;
        for x in [
            s.gravity.x,
            s.gravity.y,
            s.gravity.z,
            s.substep_rate,
            s.time_scale,
            s.teleport_distance,
            s.teleport_angle,
            s.scale,
            s.sleep_speed,
        ] {
            f(x);
        }
        for x in [self.origin.x, self.origin.y, self.origin.z] {
            f(x);
        }
        let mut words: Vec<u64> = vec![
            self.accumulator.to_bits(),
            s.max_substeps as u64,
            s.iterations as u64,
            s.teleport_mode as u64,
            s.lod as u64,
            // The solver changes results by float rounding (Lanes and LanesPortable give the same bits, but are
            // still different settings); a fixed code per solver, independent of the enum's declaration order.
            match self.solver {
                Solver::Lanes => 0,
                Solver::LanesPortable => 1,
                Solver::Scalar => 2,
            },
            self.order.len() as u64,
            self.collider_order.len() as u64,
        ];
        for &slot in &self.collider_order {
            let collider = self.colliders.at(slot as usize).expect("live");
            let (radius, half_height) = collider.shape.capsule().unwrap_or((-1.0, -1.0));
            words.extend([collider.kind_code(), collider.layers as u64]);
            words.extend([radius, half_height].map(|x| x.to_bits() as u64));
            for t in [&collider.previous, &collider.current, &collider.pending] {
                words
                    .extend(t.position.to_array().into_iter().chain(t.rotation.to_array()).map(|x| x.to_bits() as u64));
            }
        }
        for chain in self.chains_in_order() {
            let p = &chain.params;
            words.push(
                chain.placed as u64
                    | (chain.half_kick as u64) << 1
                    | (chain.rest_changed as u64) << 2
                    | (chain.teleport_requested as u64) << 3
                    | (chain.enabled as u64) << 4
                    | (chain.asleep as u64) << 5,
            );
            words.push(chain.still_time.to_bits() as u64);
            words.push(p.collision_mask as u64);
            words.extend(chain.joint_radii.iter().chain([&p.friction]).map(|x| x.to_bits() as u64));
            words.push(chain.views.len() as u64);
            for view in &chain.views {
                words.extend(
                    [
                        view.weighting.direction.x,
                        view.weighting.direction.y,
                        view.weighting.direction.z,
                        view.weighting.influence,
                    ]
                    .map(|x| x.to_bits() as u64),
                );
                words.extend(
                    view.encoded
                        .bends
                        .iter()
                        .chain(&view.encoded.orientations)
                        .flat_map(|q| q.to_array())
                        .map(|x| x.to_bits() as u64),
                );
            }
            words.extend(
                [p.stiffness, p.damping, p.momentum_suppression, p.mass, p.radius, p.gravity_scale]
                    .map(|x| x.to_bits() as u64),
            );
            let st = &chain.state;
            words.extend(st.x.iter().flat_map(|v| v.to_array()).map(f64::to_bits));
            let vecs = st.v.iter().chain(&st.w).chain(&chain.rest.positions);
            words.extend(vecs.flat_map(|v| v.to_array()).map(|x| x.to_bits() as u64));
            words.extend(chain.frame.lengths.iter().map(|x| x.to_bits() as u64));
            let quats = st.q.iter().chain(&st.group_rotation).chain(&chain.rest.orientations);
            words.extend(quats.flat_map(|q| q.to_array()).map(|x| x.to_bits() as u64));
            words.extend(st.solve_memory.words());
            for t in [&chain.anchor, &chain.anchor_pending]
                .into_iter()
                .chain(&chain.output)
                .chain(&chain.local_current)
                .chain(&chain.local_previous)
            {
                words
                    .extend(t.position.to_array().into_iter().chain(t.rotation.to_array()).map(|x| x.to_bits() as u64));
            }
        }
        words.hash(&mut hasher);
        hasher.finish()
    }
}

/// Runs a visitor (`for_each_*`) into `out`, in order; returns how many items were stored. The visitor
/// checks the capacity before it calls back.
fn fill_slice<T>(out: &mut [T], visit: impl FnOnce(usize, &mut dyn FnMut(T)) -> Result<()>) -> Result<usize> {
    let capacity = out.len();
    let mut stored = 0;
    visit(capacity, &mut |item| {
        out[stored] = item;
        stored += 1;
    })?;
    Ok(stored)
}

fn check_chain_capacity(chain: &Chain, capacity: usize) -> Result<()> {
    if capacity < chain.joint_count() {
        return Err(Error::buffer_too_small(format!(
            "buffer holds {capacity} transforms, the chain has {}",
            chain.joint_count()
        )));
    }
    Ok(())
}

fn is_teleport(from: &Transform, to: &Transform, distance: f32, angle: f32) -> bool {
    // An unmoved anchor (every sleeping chain's) never teleports; this skips the angle's arctangent.
    if from == to {
        return false;
    }
    (to.position - from.position).length() > distance || rotation_angle(from.rotation.inverse() * to.rotation) > angle
}

fn collider_not_found(id: ColliderId) -> Error {
    Error::invalid_id(format!("collider id {:#x} is null, stale or foreign", id.to_bits()))
}

/// Finite and within the coordinate range the solver can subtract and square without overflow.
pub(crate) fn within_world(p: Vec3) -> bool {
    p.is_finite() && p.abs().max_element() <= MAX_COORDINATE
}

pub(crate) fn validate_step(dt: f32, camera: Vec3, view_reference: &Transform) -> Result<Transform> {
    if !(dt.is_finite() && dt >= 0.0) {
        return Err(Error::invalid_argument(format!("dt must be finite and >= 0, got {dt}")));
    }
    if !within_world(camera) {
        return Err(Error::invalid_argument(format!("camera position must be finite and within +-{MAX_COORDINATE} m")));
    }
    validate_transform(view_reference).map_err(|e| Error::invalid_argument(format!("view reference: {e}")))
}

/// A transform from outside, checked and with its rotation normalised: finite, rotation not all zero.
pub(crate) fn validate_transform(t: &Transform) -> Result<Transform> {
    check_transform(t)?;
    Ok(normalized_transform(t))
}

/// [`validate_transform`]'s checks alone: batches check every entry before they change anything, then
/// normalise each once.
fn check_transform(t: &Transform) -> Result<()> {
    if !t.is_finite() {
        return Err(Error::invalid_argument("non-finite position or rotation"));
    }
    if !within_world(t.position) {
        return Err(Error::invalid_argument(format!("position beyond +-{MAX_COORDINATE} m")));
    }
    // Finite, so `normalized_rotation` fails only on a rotation of zeros.
    if t.rotation == Quat::from_xyzw(0.0, 0.0, 0.0, 0.0) {
        return Err(Error::invalid_argument("null rotation quaternion"));
    }
    Ok(())
}

/// The transform of a [`check_transform`]ed `t`, its rotation normalised.
fn normalized_transform(t: &Transform) -> Transform {
    Transform::new(t.position, normalized_rotation(t.rotation).expect("checked: finite and not zero"))
}

fn validate_direction(d: Vec3) -> Result<Vec3> {
    if !d.is_finite() {
        return Err(Error::invalid_argument("view direction must be finite"));
    }
    normalized_direction(d).ok_or_else(|| Error::invalid_argument("view direction must not be zero"))
}

fn validate_influence(k: f32) -> Result<()> {
    if k > 0.0 && k.is_finite() {
        Ok(())
    } else {
        Err(Error::invalid_argument(format!("influence must be finite and > 0, got {k}")))
    }
}

/// [`Chain::update_rest_together`] of the `N` chains from `index` in `order`, if they all exist and are enabled
/// (the caller has found the first one's rest update due); whether it ran.
fn update_rests_together<const N: usize>(
    order: &[u32],
    chains: &mut Arena<Chain>,
    index: usize,
    view: Option<Vec3>,
) -> bool {
    let Some(slots) = order.get(index..index + N) else {
        return false;
    };
    let Some(group) = chains.many_at_mut::<N>(std::array::from_fn(|i| slots[i] as usize)) else {
        return false;
    };
    if !group.iter().all(|chain| chain.enabled) {
        return false;
    }
    Chain::update_rest_together(group, view);
    true
}
