//! The structure-of-arrays buffers of one lane group: `L` chains of `n` joints, one lane each, loaded from the
//! chains before a step's substeps and stored back after them.

use glam::{DVec3, Quat, Vec3, Vec3A};

use super::contacts::LaneContacts;
use super::simd::{D, DV3, F, M3, Mask, Q, V3};
use super::transpose;
use crate::core::buffers::reserve_total;
use crate::core::collider::ColliderSweep;
use crate::core::collision::SegmentBounds;
use crate::core::inextensible::{ConstraintScratch, SolveMemory};
use crate::core::math::Transform;
use crate::core::rod::{ChainConstants, RodState};
use crate::core::shape::Shape;
use crate::core::stability;
use crate::core::warm_start::WARM_SLOTS;

/// What one chain brings to a lane group for one step.
pub(crate) struct LaneChain<'a> {
    pub state: &'a RodState,
    pub rest: &'a Shape,
    /// `RestGroups` offsets of `rest`.
    pub offsets: &'a [[Vec3A; 3]],
    pub lengths: &'a [f32],
    pub constants: &'a ChainConstants,
    pub half_kick: bool,
    /// Added to the positions as they load ([`LaneJob::rebase`](super::LaneJob)).
    pub rebase: Option<DVec3>,
    /// `Chain::local_current` (the previous pose of a step of one substep) and `Chain::bone_axes`.
    pub local_current: &'a [Transform],
    pub bone_axes: &'a [Vec3],
}

/// Settings every lane of a group shares.
#[derive(Clone, Copy)]
pub(crate) struct GroupSettings {
    pub joints: usize,
    pub h: f32,
    pub iterations: u32,
    /// False for limp chains (stiffness 0): no shape matching, one iteration.
    pub shape_matching: bool,
    pub substeps: usize,
}

#[derive(Default)]
pub struct LaneGroup<const L: usize> {
    pub(super) n: usize,
    pub(super) h: f32,
    pub(super) iterations: u32,
    pub(super) shape_matching: bool,
    pub(super) substeps: usize,
    // Particle state.
    pub(super) x: Vec<DV3<L>>,
    pub(super) v: Vec<V3<L>>,
    pub(super) q: Vec<Q<L>>,
    pub(super) w: Vec<V3<L>>,
    pub(super) group_rotation: Vec<Q<L>>,
    // Rest shape and lengths.
    pub(super) rest_root: V3<L>,
    pub(super) qbar: Vec<Q<L>>,
    pub(super) qbar_inv: Vec<Q<L>>,
    pub(super) offsets: Vec<[V3<L>; 3]>,
    pub(super) lengths: Vec<F<L>>,
    pub(super) length_squared: Vec<D<L>>,
    pub(super) inverse_length_squared: Vec<D<L>>,
    // Per-chain parameters.
    pub(super) alpha: F<L>,
    pub(super) decay: F<L>,
    pub(super) gravity: V3<L>,
    pub(super) orientation_weight: F<L>,
    /// `ChainConstants::zigzag_gain`, and the tension it allows a substep's direct solves (`stability`).
    pub(super) zigzag_gain: D<L>,
    pub(super) tension_limit: D<L>,
    pub(super) half_kick: Mask<L>,
    /// The anchor (position, rotation) at the end of each substep of the step.
    pub(super) anchors: Vec<(V3<L>, Q<L>)>,
    // Solver scratch.
    pub(super) p: Vec<DV3<L>>,
    pub(super) qp: Vec<Q<L>>,
    /// Shape matching's orientation terms of the joints' predicted rotations (`kernel::match_shape`).
    pub(super) orientation_terms: Vec<M3<L>>,
    pub(super) start_bonds: Vec<DV3<L>>,
    pub(super) corrected: Vec<DV3<L>>,
    pub(super) mu: Vec<D<L>>,
    /// The tension budget of the substep's solves (`stability::TensionBudget`, lane by lane): what the direct
    /// solves spent, the largest multiplier the next may end with, the largest multiplier each lane's last
    /// converged direct solve ended with, and the lanes whose last direct solve the budget refused.
    pub(super) tension_spent: D<L>,
    pub(super) tension_room: D<L>,
    pub(super) tension: D<L>,
    pub(super) refused: Mask<L>,
    /// The direct solve's multiplier histories (`warm_start`), one per solve of a substep: each lane's
    /// chain's `SolveMemory::warm`, loaded and stored with it.
    pub(super) warm: [WarmLanes<L>; WARM_SLOTS],
    /// The direct solve's last Newton step of the multipliers.
    pub(super) step: Vec<D<L>>,
    pub(super) c_prime: Vec<D<L>>,
    pub(super) d_prime: Vec<D<L>>,
    // The render pose (`lanes::output`): positions and rotations relative to the anchor, and the bone axes.
    pub(super) local_previous: Vec<(V3<L>, Q<L>)>,
    pub(super) local_current: Vec<(V3<L>, Q<L>)>,
    pub(super) output: Vec<(V3<L>, Q<L>)>,
    pub(super) bone_axes: Vec<V3<L>>,
    /// The transposes' scratch ([`transpose`]): a quantity's numbers with a row per number and a lane per chain
    /// (`rows32`, `rows64`), and with a row per chain (`lanes32`, `lanes64`: the store's way out).
    rows32: Vec<[f32; L]>,
    rows64: Vec<[f64; L]>,
    lanes32: Vec<f32>,
    lanes64: Vec<f64>,
    /// The multiplier history of a lane that remembers none (`load_warm_starts`).
    zeros: Vec<f64>,
    /// Each lane's contacts this step, and the lanes that have any.
    pub(super) contacts: Vec<LaneContacts>,
    pub(super) contact_lanes: Mask<L>,
    // One lane at a time, for the scalar fallback and the contact pass.
    pub(super) lane_x: Vec<DVec3>,
    pub(super) lane_p: Vec<DVec3>,
    pub(super) lane_scratch: Vec<DVec3>,
    pub(super) lane_lengths: Vec<f32>,
    /// The lane's multipliers from the direct solve, for the fallback's exact projection.
    pub(super) lane_mu: Vec<f64>,
    /// Each lane's chain's `RodState::solve_memory`, loaded and stored with it.
    pub(super) memories: Vec<SolveMemory>,
    pub(super) constraints: ConstraintScratch,
    pub(super) segment_bounds: SegmentBounds,
    /// The contact passes in lanes (`outside::collide`, `outside::pre_stabilise`): each joint's collision radius
    /// and each segment's quick-reject bound.
    pub(super) contact_radii: Vec<F<L>>,
    pub(super) contact_bounds: Vec<(DV3<L>, D<L>)>,
    /// Pre-stabilisation's copy of the start positions (`outside::pre_stabilise`).
    pub(super) contact_start: Vec<DV3<L>>,
}

/// `MultiplierHistory` on every lane.
pub struct WarmLanes<const L: usize> {
    pub(super) last: Vec<D<L>>,
    pub(super) before: Vec<D<L>>,
    pub(super) remembered: Mask<L>,
    /// `MultiplierHistory::relinearized`: each lane's streak of Gauss-Newton projections.
    pub(super) relinearized: [u32; L],
}

impl<const L: usize> Default for WarmLanes<L> {
    fn default() -> Self {
        Self { last: Vec::new(), before: Vec::new(), remembered: Mask::default(), relinearized: [0; L] }
    }
}

impl<const L: usize> Default for V3<L> {
    fn default() -> Self {
        Self::ZERO
    }
}

impl<const L: usize> Default for F<L> {
    fn default() -> Self {
        Self([0.0; L])
    }
}

impl<const L: usize> Default for D<L> {
    fn default() -> Self {
        Self([0.0; L])
    }
}

impl<const L: usize> Default for Mask<L> {
    fn default() -> Self {
        Self([false; L])
    }
}

impl<const L: usize> LaneGroup<L> {
    /// Sizes the buffers for `settings` (allocates only when they grow: see [`reserve`](Self::reserve)).
    pub(crate) fn begin(&mut self, settings: GroupSettings) {
        self.reserve(settings.joints, settings.substeps, 0);
        self.n = settings.joints;
        self.h = settings.h;
        self.iterations = settings.iterations;
        self.shape_matching = settings.shape_matching;
        self.substeps = settings.substeps;
        self.contact_lanes = Mask([false; L]);
    }

    /// Room for a group of chains of `joints` joints over `substeps` substeps, each touching up to
    /// `colliders` colliders, so that no step that fits allocates (the engine reserves it when it learns of
    /// such chains; `begin` when a step meets more).
    pub(crate) fn reserve(&mut self, joints: usize, substeps: usize, colliders: usize) {
        let n = joints;
        fn fit<T: Clone>(v: &mut Vec<T>, len: usize, value: T) {
            if v.len() < len {
                v.resize(len, value);
            }
        }
        let zero_q = Q::IDENTITY;
        for v in [&mut self.x, &mut self.p, &mut self.start_bonds, &mut self.corrected] {
            fit(v, n, DV3::ZERO);
        }
        for v in [&mut self.v, &mut self.w] {
            fit(v, n, V3::ZERO);
        }
        for v in [&mut self.q, &mut self.group_rotation, &mut self.qbar, &mut self.qbar_inv, &mut self.qp] {
            fit(v, n, zero_q);
        }
        fit(&mut self.offsets, n, [V3::ZERO; 3]);
        let zero_m = M3 { x_axis: V3::ZERO, y_axis: V3::ZERO, z_axis: V3::ZERO };
        fit(&mut self.orientation_terms, n, zero_m);
        fit(&mut self.lengths, n, F([0.0; L]));
        for v in [
            &mut self.length_squared,
            &mut self.inverse_length_squared,
            &mut self.mu,
            &mut self.step,
            &mut self.c_prime,
            &mut self.d_prime,
        ] {
            fit(v, n, D([0.0; L]));
        }
        for warm in &mut self.warm {
            fit(&mut warm.last, n, D([0.0; L]));
            fit(&mut warm.before, n, D([0.0; L]));
        }
        fit(&mut self.anchors, substeps, (V3::ZERO, zero_q));
        for v in [&mut self.local_previous, &mut self.local_current, &mut self.output] {
            fit(v, n, (V3::ZERO, zero_q));
        }
        fit(&mut self.bone_axes, n, V3::ZERO);
        // The widest quantity a transpose moves: the rest offsets, three 4-number vectors per joint (`Vec3A`).
        fit(&mut self.rows32, 12 * n, [0.0; L]);
        fit(&mut self.rows64, 3 * n, [0.0; L]);
        fit(&mut self.lanes32, (RENDER_START + 3 * 7) * n * L, 0.0);
        // The positions, then the multiplier histories (two per slot).
        fit(&mut self.lanes64, (3 + 2 * WARM_SLOTS) * n * L, 0.0);
        fit(&mut self.zeros, n, 0.0);
        if self.contacts.len() < L {
            self.contacts.resize_with(L, LaneContacts::default);
        }
        // Per lane, room for a chain of this length, whichever chain lands in the lane (which lane a chain
        // takes changes from step to step as others sleep, wake or come within reach of a collider).
        for contact in &mut self.contacts {
            contact.reserve(n, colliders);
        }
        // The lane scratch keeps the length of its last use (a fallback's or a contact pass's lane): counted
        // from zero, or every group's first step after such a use grew it again.
        reserve_total(&mut self.lane_x, n);
        reserve_total(&mut self.lane_scratch, n);
        reserve_total(&mut self.lane_p, n);
        reserve_total(&mut self.lane_lengths, n);
        reserve_total(&mut self.lane_mu, n);
        self.memories.resize_with(L, SolveMemory::default);
        for memory in &mut self.memories {
            memory.reserve(n.saturating_sub(1));
        }
        self.constraints.reserve(n);
        self.segment_bounds.reserve(n);
        fit(&mut self.contact_radii, n, F([0.0; L]));
        fit(&mut self.contact_bounds, n, (DV3::ZERO, D([0.0; L])));
        fit(&mut self.contact_start, n, DV3::ZERO);
    }

    /// Loads `chains[lane]` into every lane: quantity by quantity, each chain's array read as numbers and
    /// transposed into rows of lanes ([`transpose`]), which the group's vectors take row by row.
    pub(crate) fn load(&mut self, chains: &[LaneChain<'_>; L]) {
        let n = self.n;
        let x = gather64(&mut self.rows64, chains.each_ref().map(|c| bytemuck::cast_slice(&c.state.x[..n])));
        for (to, from) in self.x[..n].iter_mut().zip(x.chunks_exact(3)) {
            (to.x.0, to.y.0, to.z.0) = (from[0], from[1], from[2]);
        }
        // `RodState::translate`'s addition, as the engine would have made it before the step.
        for (lane, chain) in chains.iter().enumerate() {
            if let Some(shift) = chain.rebase {
                for x in &mut self.x[..n] {
                    x.set(lane, (DVec3::from_array(x.get(lane)) + shift).to_array());
                }
            }
        }
        let v = gather32(&mut self.rows32, chains.each_ref().map(|c| bytemuck::cast_slice(&c.state.v[..n])));
        rows_to_vectors(v, &mut self.v[..n]);
        let w = gather32(&mut self.rows32, chains.each_ref().map(|c| bytemuck::cast_slice(&c.state.w[..n])));
        rows_to_vectors(w, &mut self.w[..n]);
        let q = gather32(&mut self.rows32, chains.each_ref().map(|c| bytemuck::cast_slice(&c.state.q[..n])));
        rows_to_quaternions(q, &mut self.q[..n]);
        let rotation =
            gather32(&mut self.rows32, chains.each_ref().map(|c| bytemuck::cast_slice(&c.state.group_rotation[..n])));
        rows_to_quaternions(rotation, &mut self.group_rotation[..n]);
        let axes = gather32(&mut self.rows32, chains.each_ref().map(|c| bytemuck::cast_slice(&c.bone_axes[..n])));
        rows_to_vectors(axes, &mut self.bone_axes[..n]);
        let qbar =
            gather32(&mut self.rows32, chains.each_ref().map(|c| bytemuck::cast_slice(&c.rest.orientations[..n])));
        rows_to_quaternions(qbar, &mut self.qbar[..n]);
        for (inverse, qbar) in self.qbar_inv[..n].iter_mut().zip(&self.qbar[..n]) {
            // `Quat::inverse` of a unit quaternion: its conjugate (a sign flip, exact).
            *inverse = Q { x: -qbar.x, y: -qbar.y, z: -qbar.z, w: qbar.w };
        }
        // Three `Vec3A` a joint: four numbers each, the fourth unused.
        let offsets = gather32(&mut self.rows32, chains.each_ref().map(|c| bytemuck::cast_slice(&c.offsets[..n])));
        for (to, from) in self.offsets[..n].iter_mut().zip(offsets.chunks_exact(12)) {
            for (member, from) in to.iter_mut().zip(from.chunks_exact(4)) {
                (member.x.0, member.y.0, member.z.0) = (from[0], from[1], from[2]);
            }
        }
        if self.one_substep() {
            // The one capture of the step turns the chain's newest pose into the previous one.
            for j in 0..n {
                for (lane, chain) in chains.iter().enumerate() {
                    let local = &chain.local_current[j];
                    self.local_current[j].0.set(lane, local.position.to_array());
                    self.local_current[j].1.set(lane, local.rotation.to_array());
                }
            }
        }
        for k in 0..n - 1 {
            for (lane, chain) in chains.iter().enumerate() {
                let l = chain.lengths[k];
                let l2 = l as f64 * l as f64;
                self.lengths[k].0[lane] = l;
                self.length_squared[k].0[lane] = l2;
                self.inverse_length_squared[k].0[lane] = 1.0 / l2;
            }
        }
        for (lane, chain) in chains.iter().enumerate() {
            debug_assert_eq!(chain.state.x.len(), n);
            self.rest_root.set(lane, chain.rest.positions[0].to_array());
            let constants = chain.constants;
            self.alpha.0[lane] = constants.alpha_per_iteration;
            self.decay.0[lane] = constants.velocity_decay;
            self.gravity.set(lane, constants.gravity.to_array());
            self.orientation_weight.0[lane] = constants.orientation_weight;
            self.zigzag_gain.0[lane] = constants.zigzag_gain;
            self.tension_limit.0[lane] = stability::direct_limit(constants.zigzag_gain);
            self.half_kick.0[lane] = chain.half_kick;
            self.memories[lane].copy_streak_from(&chain.state.solve_memory);
        }
        self.load_warm_starts(chains);
    }

    /// The solves of a substep, one per iteration.
    fn solves(&self) -> u32 {
        if self.shape_matching { self.iterations.max(1) } else { 1 }
    }

    /// The lanes' multiplier histories (`SolveMemory::warm`), as `rod::substep` reads them after its
    /// `begin_substep` (every substep of the step has the group's length and iterations).
    #[inline(never)]
    fn load_warm_starts(&mut self, chains: &[LaneChain<'_>; L]) {
        let bonds = self.n - 1;
        let solves = self.solves();
        let applies = chains.each_ref().map(|c| c.state.solve_memory.warm_applies(self.h, solves));
        for (slot, warm) in self.warm.iter_mut().enumerate() {
            let history = |lane: usize| &chains[lane].state.solve_memory.warm[slot];
            let remembered = std::array::from_fn(|lane| {
                applies[lane] && history(lane).remembered() && history(lane).last.len() == bonds
            });
            warm.remembered = Mask(remembered);
            // As `SolveMemory::begin_substep`: another rate or iteration count ends the streak too.
            warm.relinearized = std::array::from_fn(|lane| {
                if applies[lane] && history(lane).last.len() == bonds { history(lane).relinearized } else { 0 }
            });
            if !warm.remembered.any() {
                continue;
            }
            // Lanes that remember nothing take zeros, which no solve reads (`lengths::solve_lengths` starts
            // them from none).
            let zeros = &self.zeros[..bonds];
            let last = std::array::from_fn(|lane| if remembered[lane] { &history(lane).last[..bonds] } else { zeros });
            for (to, from) in warm.last[..bonds].iter_mut().zip(gather64(&mut self.rows64, last)) {
                to.0 = *from;
            }
            let before =
                std::array::from_fn(|lane| if remembered[lane] { &history(lane).before[..bonds] } else { zeros });
            for (to, from) in warm.before[..bonds].iter_mut().zip(gather64(&mut self.rows64, before)) {
                to.0 = *from;
            }
        }
    }

    /// The contacts of `lane` this step: `find` writes the colliders its chain can touch (indices in collider
    /// order, of `colliders`; none for a chain that touches nothing) and the chain's scaled radii; then its
    /// friction, slop and settled distance (see `rod::substep`). The buffers hold room for every collider, so
    /// no later step allocates whichever chain lands in this lane.
    pub(crate) fn load_contacts(
        &mut self,
        lane: usize,
        colliders: usize,
        find: impl FnOnce(&mut Vec<usize>, &mut Vec<f32>),
        friction: f32,
        slop: f32,
        settled: f32,
    ) {
        let contact = &mut self.contacts[lane];
        contact.candidates.clear();
        contact.candidates.reserve(colliders);
        contact.sweeps.clear();
        contact.sweeps.reserve(colliders);
        find(&mut contact.candidates, &mut contact.radii);
        for (row, &radius) in self.contact_radii.iter_mut().zip(&contact.radii) {
            row.0[lane] = radius;
        }
        contact.lengths.clear();
        if !contact.candidates.is_empty() {
            contact.lengths.extend(self.lengths[..self.n - 1].iter().map(|l| l.0[lane]));
        }
        contact.friction = friction;
        contact.slop = slop;
        contact.settled = settled;
        contact.pass = None;
        self.contact_lanes.0[lane] = !contact.candidates.is_empty();
    }

    /// Every contact lane's collider sweeps for substep `s`.
    pub(crate) fn select_sweeps(&mut self, all: &[ColliderSweep], colliders: usize, s: usize) {
        for lane in 0..L {
            if self.contact_lanes.0[lane] {
                self.contacts[lane].select_sweeps(all, colliders, s);
            }
        }
    }

    /// The anchor of `lane` at the end of substep `s` (relative to the engine origin).
    pub(crate) fn set_anchor(&mut self, s: usize, lane: usize, anchor: &Transform) {
        let (position, rotation) = &mut self.anchors[s];
        position.set(lane, anchor.position.to_array());
        rotation.set(lane, anchor.rotation.to_array());
    }

    /// Turns the particle state into a row per lane and quantity, for [`store`](Self::store) to copy out.
    pub(crate) fn prepare_store(&mut self) {
        let n = self.n;
        let rows = &mut self.rows64[..3 * n];
        for (to, from) in rows.chunks_exact_mut(3).zip(&self.x[..n]) {
            (to[0], to[1], to[2]) = (from.x.0, from.y.0, from.z.0);
        }
        let (x_lanes, warm_lanes) = self.lanes64.split_at_mut(3 * n * L);
        transpose::scatter_f64(rows, x_lanes);
        // The multiplier histories: each slot's last and before, as `store` copies them.
        let bonds = n - 1;
        let histories = self.warm.iter().flat_map(|warm| [&warm.last, &warm.before]);
        for (region, history) in histories.enumerate() {
            let rows = &mut self.rows64[..bonds];
            for (to, from) in rows.iter_mut().zip(&history[..bonds]) {
                *to = from.0;
            }
            transpose::scatter_f64(rows, &mut warm_lanes[region * bonds * L..]);
        }
        let (v, rest) = self.lanes32.split_at_mut(3 * n * L);
        let (w, rest) = rest.split_at_mut(3 * n * L);
        let (q, rotation) = rest.split_at_mut(4 * n * L);
        vectors_to_lanes(&self.v[..n], &mut self.rows32, v);
        vectors_to_lanes(&self.w[..n], &mut self.rows32, w);
        quaternions_to_lanes(&self.q[..n], &mut self.rows32, q);
        quaternions_to_lanes(&self.group_rotation[..n], &mut self.rows32, rotation);
        // The render poses: 7 numbers a joint (position, rotation), a row per pose and lane. The previous one of a
        // step of one substep is the chain's newest pose as it loaded: `store_render` takes it from the chain.
        let skipped = self.one_substep() as usize;
        let poses = &mut self.lanes32[RENDER_START * n * L..];
        let stored = [&self.local_previous, &self.local_current, &self.output];
        for (pose, lanes) in stored.into_iter().zip(poses.chunks_exact_mut(7 * n * L)).skip(skipped) {
            let rows = &mut self.rows32[..7 * n];
            for (to, (position, rotation)) in rows.chunks_exact_mut(7).zip(&pose[..n]) {
                (to[0], to[1], to[2]) = (position.x.0, position.y.0, position.z.0);
                (to[3], to[4], to[5], to[6]) = (rotation.x.0, rotation.y.0, rotation.z.0, rotation.w.0);
            }
            transpose::scatter_f32(rows, lanes);
        }
    }

    /// The particle state of `lane` into `state` ([`prepare_store`](Self::prepare_store) first).
    pub(crate) fn store(&self, lane: usize, state: &mut RodState) {
        let n = self.n;
        // `prepare_store`'s rows: the velocities, angular velocities, rotations and group rotations one after
        // the other, each with `width` numbers a joint and a row per lane.
        let mut start = 0;
        let mut row = |width: usize| {
            let row = &self.lanes32[start + lane * width * n..][..width * n];
            start += width * n * L;
            row
        };
        state.x[..n].copy_from_slice(bytemuck::cast_slice(&self.lanes64[lane * 3 * n..(lane + 1) * 3 * n]));
        state.v[..n].copy_from_slice(bytemuck::cast_slice(row(3)));
        state.w[..n].copy_from_slice(bytemuck::cast_slice(row(3)));
        state.q[..n].copy_from_slice(bytemuck::cast_slice(row(4)));
        state.group_rotation[..n].copy_from_slice(bytemuck::cast_slice(row(4)));
        let memory = &mut state.solve_memory;
        memory.copy_streak_from(&self.memories[lane]);
        memory.set_learnt_at(self.h, self.solves());
        let bonds = n - 1;
        // `prepare_store`'s rows of the histories: each slot's last and before, a row per lane.
        let rows = &self.lanes64[3 * n * L..];
        let row = |region: usize| &rows[(region * L + lane) * bonds..][..bonds];
        for (slot, (warm, history)) in self.warm.iter().zip(&mut memory.warm).enumerate() {
            if history.last.len() != bonds {
                history.forget();
                continue;
            }
            history.relinearized = warm.relinearized[lane];
            if warm.remembered.0[lane] {
                history.last.copy_from_slice(row(2 * slot));
                history.before.copy_from_slice(row(2 * slot + 1));
                history.remembered = true;
            } else {
                history.forget();
            }
        }
    }

    /// The render poses of `lane` (`lanes::output`) into its chain's buffers. After a step of one substep the
    /// previous pose is the one the chain held as its newest (its single capture shifted that pose, as loaded,
    /// into the previous one: the same bits), so the chain's two buffers swap and only the newest and the output
    /// are written. On a LOD 2 frame (one substep) writing the three poses was the costliest part of `run_group`.
    pub(crate) fn store_render(
        &self,
        lane: usize,
        previous: &mut Vec<Transform>,
        current: &mut Vec<Transform>,
        output: &mut [Transform],
    ) {
        let n = self.n;
        let poses = &self.lanes32[RENDER_START * n * L..];
        let write = |pose: usize, to: &mut [Transform]| {
            let row = &poses[(pose * L + lane) * 7 * n..][..7 * n];
            for (to, from) in to[..n].iter_mut().zip(row.chunks_exact(7)) {
                *to = Transform::new(Vec3::from_slice(&from[..3]), Quat::from_slice(&from[3..]));
            }
        };
        if self.one_substep() {
            std::mem::swap(previous, current);
        } else {
            write(0, previous);
        }
        write(1, current);
        write(2, output);
    }

    /// Whether the step has one substep: its one capture makes the loaded newest pose the previous one.
    fn one_substep(&self) -> bool {
        self.substeps < 2
    }
}

/// Where the render poses start in `LaneGroup::lanes32` (numbers per joint and lane): after the particle
/// state's 14 (`LaneGroup::prepare_store`).
const RENDER_START: usize = 14;

/// [`transpose::gather_f32`] of `sources` (one chain's numbers each, all as many) into `rows`.
fn gather32<'r, const L: usize>(rows: &'r mut [[f32; L]], sources: [&[f32]; L]) -> &'r [[f32; L]] {
    let rows = &mut rows[..sources[0].len()];
    transpose::gather_f32(&sources, rows);
    rows
}

/// As [`gather32`], in double precision.
fn gather64<'r, const L: usize>(rows: &'r mut [[f64; L]], sources: [&[f64]; L]) -> &'r [[f64; L]] {
    let rows = &mut rows[..sources[0].len()];
    transpose::gather_f64(&sources, rows);
    rows
}

/// Rows of `x, y, z` numbers, joint after joint, into vectors.
fn rows_to_vectors<const L: usize>(rows: &[[f32; L]], vectors: &mut [V3<L>]) {
    for (to, from) in vectors.iter_mut().zip(rows.chunks_exact(3)) {
        (to.x.0, to.y.0, to.z.0) = (from[0], from[1], from[2]);
    }
}

/// Rows of `x, y, z, w` numbers, joint after joint, into quaternions.
fn rows_to_quaternions<const L: usize>(rows: &[[f32; L]], quaternions: &mut [Q<L>]) {
    for (to, from) in quaternions.iter_mut().zip(rows.chunks_exact(4)) {
        (to.x.0, to.y.0, to.z.0, to.w.0) = (from[0], from[1], from[2], from[3]);
    }
}

/// Vectors as rows of numbers (`rows`, scratch), then as a row per lane (`lanes`).
fn vectors_to_lanes<const L: usize>(vectors: &[V3<L>], rows: &mut [[f32; L]], lanes: &mut [f32]) {
    let rows = &mut rows[..3 * vectors.len()];
    for (to, from) in rows.chunks_exact_mut(3).zip(vectors) {
        (to[0], to[1], to[2]) = (from.x.0, from.y.0, from.z.0);
    }
    transpose::scatter_f32(rows, lanes);
}

/// Quaternions as rows of numbers (`rows`, scratch), then as a row per lane (`lanes`).
fn quaternions_to_lanes<const L: usize>(quaternions: &[Q<L>], rows: &mut [[f32; L]], lanes: &mut [f32]) {
    let rows = &mut rows[..4 * quaternions.len()];
    for (to, from) in rows.chunks_exact_mut(4).zip(quaternions) {
        (to[0], to[1], to[2], to[3]) = (from.x.0, from.y.0, from.z.0, from.w.0);
    }
    transpose::scatter_f32(rows, lanes);
}

#[cfg(test)]
mod tests {
    use super::{GroupSettings, LaneGroup};
    use glam::DVec3;

    fn settings(joints: usize) -> GroupSettings {
        GroupSettings { joints, h: 1.0 / 240.0, iterations: 2, shape_matching: true, substeps: 4 }
    }

    /// The lane scratch as the contact pass and the scalar fallback leave it: full to the chain's length.
    fn use_lane_scratch(g: &mut LaneGroup<8>, n: usize) {
        g.lane_x.resize(n, DVec3::ONE);
        g.lane_scratch.resize(n, DVec3::ONE);
        g.lane_p.resize(n, DVec3::ONE);
        g.lane_lengths.resize(n - 1, 1.0);
        g.lane_mu.resize(n - 1, 1.0);
    }

    fn capacities(g: &LaneGroup<8>) -> [usize; 5] {
        [
            g.lane_x.capacity(),
            g.lane_scratch.capacity(),
            g.lane_p.capacity(),
            g.lane_lengths.capacity(),
            g.lane_mu.capacity(),
        ]
    }

    #[test]
    fn a_group_that_was_used_begins_again_without_growing() {
        let mut g = LaneGroup::<8>::default();
        g.begin(settings(16));
        let sized = capacities(&g);
        assert!(sized.iter().all(|&c| c >= 16), "room for a lane of 16 joints: {sized:?}");
        use_lane_scratch(&mut g, 16);
        assert_eq!(capacities(&g), sized, "a lane's use fits in what begin reserved");
        for joints in [16, 8, 16] {
            g.begin(settings(joints));
            assert_eq!(capacities(&g), sized, "begin({joints}) after a use");
            use_lane_scratch(&mut g, joints);
        }
        g.begin(settings(32));
        assert!(capacities(&g).iter().all(|&c| c >= 32), "grows for longer chains");
    }

    #[test]
    fn every_lane_has_room_for_a_chain_of_the_group_length() {
        let mut g = LaneGroup::<8>::default();
        for joints in [4, 16, 8, 32] {
            g.begin(settings(joints));
            for lane in 0..8 {
                let contact = &g.contacts[lane];
                assert!(contact.radii.capacity() >= joints, "radii, lane {lane}, {joints} joints");
                assert!(contact.lengths.capacity() >= joints - 1, "lengths, lane {lane}, {joints} joints");
                assert!(g.memories[lane].room() >= joints - 1, "solve memory, lane {lane}, {joints} joints");
            }
        }
    }
}
