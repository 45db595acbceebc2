//! The structure-of-arrays buffers of one lane group: `L` chains of `n` joints, one lane each, loaded from the
//! chains before a step's substeps and stored back after them.

use glam::{DVec3, Quat, Vec3, Vec3A};

use super::contacts::LaneContacts;
use super::simd::{D, DV3, F, M3, Mask, Q, V3};
use crate::core::buffers::reserve_total;
use crate::core::collider::ColliderSweep;
use crate::core::collision::SegmentBounds;
use crate::core::inextensible::{ConstraintScratch, SolveMemory};
use crate::core::math::Transform;
use crate::core::rod::{ChainConstants, RodState};
use crate::core::shape::Shape;
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
}

/// `MultiplierHistory` on every lane.
#[derive(Default)]
pub struct WarmLanes<const L: usize> {
    pub(super) last: Vec<D<L>>,
    pub(super) before: Vec<D<L>>,
    pub(super) remembered: Mask<L>,
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
    }

    /// Loads `chains[lane]` into every lane. Joint by joint across the lanes: the buffers of one joint (a few
    /// cache lines per quantity) are written by every lane before the next joint's, where lane by lane every
    /// lane would write all of the group's buffers, more than the L1 cache holds at 16 lanes.
    pub(crate) fn load(&mut self, chains: &[LaneChain<'_>; L]) {
        let n = self.n;
        // Every chain's arrays cut to `n` up front, so the loops below index them without bounds checks.
        let states = chains.each_ref().map(|c| {
            let st = c.state;
            (&st.x[..n], &st.v[..n], &st.q[..n], &st.w[..n], &st.group_rotation[..n])
        });
        let rests = chains.each_ref().map(|c| (&c.bone_axes[..n], &c.rest.orientations[..n], &c.offsets[..n]));
        let rebases = chains.each_ref().map(|c| c.rebase);
        let (x, v, q, w, group_rotation) =
            (&mut self.x[..n], &mut self.v[..n], &mut self.q[..n], &mut self.w[..n], &mut self.group_rotation[..n]);
        let (bone_axes, qbars, qbar_invs, offsets) =
            (&mut self.bone_axes[..n], &mut self.qbar[..n], &mut self.qbar_inv[..n], &mut self.offsets[..n]);
        for j in 0..n {
            for (lane, st) in states.iter().enumerate() {
                // `RodState::translate`'s addition, as the engine would have made it before the step.
                let position = match rebases[lane] {
                    Some(shift) => st.0[j] + shift,
                    None => st.0[j],
                };
                x[j].set(lane, position.to_array());
                v[j].set(lane, st.1[j].to_array());
                q[j].set(lane, st.2[j].to_array());
                w[j].set(lane, st.3[j].to_array());
                group_rotation[j].set(lane, st.4[j].to_array());
            }
            for (lane, rest) in rests.iter().enumerate() {
                bone_axes[j].set(lane, rest.0[j].to_array());
                let qbar = rest.1[j];
                qbars[j].set(lane, qbar.to_array());
                qbar_invs[j].set(lane, qbar.inverse().to_array());
                let [a, b, c] = rest.2[j];
                let offsets = &mut offsets[j];
                offsets[0].set(lane, a.to_array());
                offsets[1].set(lane, b.to_array());
                offsets[2].set(lane, c.to_array());
            }
        }
        if self.substeps < 2 {
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
        for (lane, chain) in chains.iter().enumerate() {
            let memory = &chain.state.solve_memory;
            let applies = memory.warm_applies(self.h, solves);
            for (warm, history) in self.warm.iter_mut().zip(&memory.warm) {
                let remembered = applies && history.remembered() && history.last.len() == bonds;
                warm.remembered.0[lane] = remembered;
                if remembered {
                    for (to, &from) in warm.last[..bonds].iter_mut().zip(&history.last) {
                        to.0[lane] = from;
                    }
                    for (to, &from) in warm.before[..bonds].iter_mut().zip(&history.before) {
                        to.0[lane] = from;
                    }
                }
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

    /// The particle state of `lane` into `state`.
    pub(crate) fn store(&self, lane: usize, state: &mut RodState) {
        let n = self.n;
        // Cut to `n` up front: no bounds checks in the loop.
        let (x, q, v, w, group_rotation) = (
            &mut state.x[..n],
            &mut state.q[..n],
            &mut state.v[..n],
            &mut state.w[..n],
            &mut state.group_rotation[..n],
        );
        let (lane_x, lane_q, lane_v, lane_w, lane_rotation) =
            (&self.x[..n], &self.q[..n], &self.v[..n], &self.w[..n], &self.group_rotation[..n]);
        for j in 0..n {
            x[j] = DVec3::from_array(lane_x[j].get(lane));
            q[j] = Quat::from_array(lane_q[j].get(lane));
            v[j] = Vec3::from_array(lane_v[j].get(lane));
            w[j] = Vec3::from_array(lane_w[j].get(lane));
            group_rotation[j] = Quat::from_array(lane_rotation[j].get(lane));
        }
        let memory = &mut state.solve_memory;
        memory.copy_streak_from(&self.memories[lane]);
        memory.set_learnt_at(self.h, self.solves());
        for (warm, history) in self.warm.iter().zip(&mut memory.warm) {
            if warm.remembered.0[lane] && history.last.len() == self.n - 1 {
                for (to, from) in history.last.iter_mut().zip(&warm.last) {
                    *to = from.0[lane];
                }
                for (to, from) in history.before.iter_mut().zip(&warm.before) {
                    *to = from.0[lane];
                }
                history.remembered = true;
            } else {
                history.forget();
            }
        }
    }

    /// The render poses of `lane` (`lanes::output`) into its chain's buffers.
    pub(crate) fn store_render(
        &self,
        lane: usize,
        previous: &mut [Transform],
        current: &mut [Transform],
        output: &mut [Transform],
    ) {
        let transform = |(position, rotation): &(V3<L>, Q<L>)| {
            Transform::new(Vec3::from_array(position.get(lane)), Quat::from_array(rotation.get(lane)))
        };
        for j in 0..self.n {
            previous[j] = transform(&self.local_previous[j]);
            current[j] = transform(&self.local_current[j]);
            output[j] = transform(&self.output[j]);
        }
    }
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
