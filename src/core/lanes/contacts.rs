//! The contact pass of a lane group, between the kernel's vector phases. Contacts are sparse (a few joints of a
//! strand touch the head or a shoulder), branchy and different for every chain: each is resolved by
//! `collision`'s scalar code. Against spheres and capsules, in groups of 8, the lanes screen each segment at once,
//! segment after segment, and only the lanes the screen cannot clear take the scalar test ([`outside`]; the
//! first pass of pre-stabilisation too); against other colliders the pass is `collision`'s, one lane at a time. The lanes also gain
//! the rest of the substep (shape matching and the lengths), which a chain near a collider would otherwise run
//! on the scalar solver.

use glam::{DVec3, Vec3};

use super::group::LaneGroup;
use super::outside::{self, ScreenFn};
use super::simd::{DV3, Mask};
use crate::core::buffers::reserve_total;
use crate::core::collider::ColliderSweep;
use crate::core::collision::{self, ContactInput, ContactPass};
use crate::core::inextensible::{self, SlidingMemory};
use crate::core::rod::FINAL_CONTACT_ROUNDS;

/// What one lane's chain needs for its contacts during a step.
#[derive(Default)]
pub(crate) struct LaneContacts {
    /// Indices (in collider order) of the colliders the chain can touch this step.
    pub candidates: Vec<usize>,
    /// Their sweeps in the current substep.
    pub sweeps: Vec<ColliderSweep>,
    /// Collision radius of each particle (m, scaled).
    pub radii: Vec<f32>,
    /// Rest length of each segment (m), as the lengths solve keeps them.
    pub lengths: Vec<f32>,
    pub friction: f32,
    /// `ContactInput::slop`.
    pub slop: f32,
    /// A contact pass whose corrections stay below this (m) has settled.
    pub settled: f32,
    /// The last contact pass of the current substep.
    pub pass: Option<ContactPass>,
    /// `SubstepInput::starts_clear`: the substep before, in the same step, ended on a pass that touched nothing.
    pub starts_clear: bool,
    /// The contact normal of each particle that slides on a collider in the contact rounds' lengths solves
    /// (`collision::collide`; zero for none), since the last iteration's contact pass.
    pub normals: Vec<Vec3>,
    /// Some particle has a normal in `normals`.
    pub sliding: bool,
    /// How the current substep's sliding solves ended (`inextensible::solve_sliding`).
    pub sliding_memory: SlidingMemory,
}

impl LaneContacts {
    /// Room for a chain of `joints` joints that may touch `colliders` colliders.
    pub(super) fn reserve(&mut self, joints: usize, colliders: usize) {
        reserve_total(&mut self.radii, joints);
        reserve_total(&mut self.normals, joints);
        reserve_total(&mut self.lengths, joints.saturating_sub(1));
        reserve_total(&mut self.candidates, colliders);
        reserve_total(&mut self.sweeps, colliders);
    }

    pub(super) fn input(&self) -> ContactInput<'_> {
        ContactInput {
            colliders: &self.sweeps,
            radii: &self.radii,
            lengths: &self.lengths,
            friction: self.friction,
            slop: self.slop,
        }
    }

    /// The sweeps of substep `s`, from every collider's sweeps of the step (`[substep * colliders + c]`).
    pub fn select_sweeps(&mut self, all: &[ColliderSweep], colliders: usize, s: usize) {
        let row = &all[s * colliders..][..colliders];
        self.sweeps.clear();
        self.sweeps.extend(self.candidates.iter().map(|&c| row[c]));
        self.starts_clear = s > 0 && self.pass.is_some_and(|pass| !pass.touching);
        self.pass = None;
        self.sliding_memory = SlidingMemory::default();
    }
}

/// Pre-stabilisation (`collision::pre_stabilise`) of the start positions of the lanes in `lanes` (not those
/// that start clear: see `LaneContacts::starts_clear`). With a screen, the first contact pass of the lanes whose
/// chains can touch only spheres and capsules runs in lanes ([`outside::pre_stabilise`]); the rare lanes it
/// finds deeper inside than their settled distance take the rounds that follow, and the other lanes the whole
/// of it, in `collision`'s scalar code one lane at a time.
#[inline(always)]
pub fn pre_stabilise<const L: usize>(g: &mut LaneGroup<L>, lanes: Mask<L>, screen: Option<ScreenFn<L>>) {
    let mut in_lanes = Mask([false; L]);
    let mut scalar = Mask([false; L]);
    for lane in (0..L).filter(|&lane| lanes.0[lane]) {
        let contact = &g.contacts[lane];
        // A lane that starts clear is skipped; debug builds pre-stabilise it anyway (scalar, below) and check
        // that nothing moves.
        if contact.starts_clear {
            scalar.0[lane] = cfg!(debug_assertions);
        } else if screen.is_some() && contact.sweeps.iter().all(outside::is_outside) {
            in_lanes.0[lane] = true;
        } else {
            scalar.0[lane] = true;
        }
    }
    if let Some(screen) = screen.filter(|_| in_lanes.any()) {
        let passes = outside::pre_stabilise(g, in_lanes, screen);
        for lane in (0..L).filter(|&lane| in_lanes.0[lane]) {
            // Joints left on a surface by the last substep touch it within rounding: only a real overlap needs
            // rounds.
            if passes[lane].deepest > g.contacts[lane].settled {
                pre_stabilise_lane(g, lane, true);
            }
        }
    }
    for lane in (0..L).filter(|&lane| scalar.0[lane]) {
        pre_stabilise_lane(g, lane, false);
    }
}

/// `collision::pre_stabilise` of one lane in `collision`'s scalar code: the whole of it, or (`after_first_pass`)
/// the rounds after the first pass that [`outside::pre_stabilise`] ran in lanes, from the start positions it left
/// in `LaneGroup::contact_start`.
fn pre_stabilise_lane<const L: usize>(g: &mut LaneGroup<L>, lane: usize, after_first_pass: bool) {
    let n = g.n;
    let LaneGroup {
        x,
        contact_start,
        lengths,
        lane_x,
        lane_scratch,
        lane_lengths,
        contacts,
        constraints,
        segment_bounds,
        ..
    } = g;
    extract(&x[..n], lane, lane_x);
    lane_lengths.clear();
    lane_lengths.extend(lengths[..n - 1].iter().map(|l| l.0[lane]));
    let keep_lengths = |previous: &[DVec3], x: &mut [DVec3]| {
        inextensible::solve(previous, x, lane_lengths, constraints);
    };
    let contact = &contacts[lane];
    let (input, settled) = (contact.input(), contact.settled);
    if after_first_pass {
        extract(&contact_start[..n], lane, lane_scratch);
        collision::pre_stabilise_rounds(
            lane_x,
            lane_scratch,
            &input,
            FINAL_CONTACT_ROUNDS,
            keep_lengths,
            settled,
            segment_bounds,
        );
    } else {
        lane_scratch.resize(n, DVec3::ZERO);
        collision::pre_stabilise(
            lane_x,
            lane_scratch,
            &input,
            FINAL_CONTACT_ROUNDS,
            keep_lengths,
            settled,
            segment_bounds,
        );
        if contact.starts_clear {
            extract(&x[..n], lane, lane_scratch);
            debug_assert!(
                crate::core::rod::same_bits(lane_x, lane_scratch),
                "lane {lane} had something to pre-stabilise"
            );
            return;
        }
    }
    write_back(lane_x, lane, &mut x[..n]);
}
/// One contact pass (`collision::collide`) on the lanes in `lanes`, moving their positions and, where a joint
/// was inside already at the start of the substep, their start positions. An iteration's pass (`fresh`)
/// forgets the contact normals of the passes before; a contact round's adds to them. Returns the pairs tested.
///
/// Lanes whose chains can touch only spheres and capsules (a character's head and limbs) take the pass in
/// lanes ([`outside`]); the others (a ground plane, an inside collider) the scalar pass, one lane at a time.
#[inline(always)]
pub fn collide<const L: usize>(g: &mut LaneGroup<L>, lanes: Mask<L>, fresh: bool, screen: Option<ScreenFn<L>>) -> u64 {
    let n = g.n;
    let mut tested = 0;
    let mut in_lanes = Mask([false; L]);
    for lane in (0..L).filter(|&lane| lanes.0[lane]) {
        let contact = &mut g.contacts[lane];
        // All zero already unless some joint slid.
        if fresh && (contact.sliding || contact.normals.len() != n) {
            contact.normals.clear();
            contact.normals.resize(n, Vec3::ZERO);
            contact.sliding = false;
        }
        in_lanes.0[lane] = screen.is_some() && contact.sweeps.iter().all(outside::is_outside);
    }
    if let Some(screen) = screen.filter(|_| in_lanes.any()) {
        let passes = outside::collide(g, in_lanes, screen);
        for lane in (0..L).filter(|&lane| in_lanes.0[lane]) {
            let contact = &mut g.contacts[lane];
            contact.sliding |= passes[lane].sliding;
            contact.pass = Some(passes[lane]);
            tested += passes[lane].tested;
        }
    }
    for lane in (0..L).filter(|&lane| lanes.0[lane] && !in_lanes.0[lane]) {
        let LaneGroup { x, p, lane_x, lane_p, contacts, segment_bounds, .. } = g;
        extract(&x[..n], lane, lane_x);
        extract(&p[..n], lane, lane_p);
        let contact = &mut contacts[lane];
        // Out of `contact` for the pass, which reads the rest of it (a move: no allocation).
        let mut normals = std::mem::take(&mut contact.normals);
        let pass = collision::collide(lane_x, lane_p, &contact.input(), segment_bounds, &mut normals);
        contact.normals = normals;
        contact.sliding |= pass.sliding;
        contact.pass = Some(pass);
        tested += pass.tested;
        // Only a contact moves positions, and only a joint inside since the start moves start positions.
        if pass.moved_start {
            write_back(lane_x, lane, &mut x[..n]);
        }
        if pass.touching {
            write_back(lane_p, lane, &mut p[..n]);
        }
    }
    tested
}

/// The lanes of `lanes` with a particle that slides on a collider in the contact rounds.
pub fn sliding<const L: usize>(g: &LaneGroup<L>, lanes: Mask<L>) -> Mask<L> {
    let mut out = Mask([false; L]);
    for lane in (0..L).filter(|&lane| lanes.0[lane]) {
        out.0[lane] = g.contacts[lane].sliding;
    }
    out
}

/// The lengths solve of a contact round (`inextensible::solve_sliding`) on the lanes of `lanes`, one lane at a
/// time, as the scalar solver runs it. Returns the lanes where no direct solve converged (the fallback ran).
pub fn solve_sliding<const L: usize>(g: &mut LaneGroup<L>, lanes: Mask<L>) -> Mask<L> {
    let n = g.n;
    let mut fell_back = Mask([false; L]);
    for lane in (0..L).filter(|&lane| lanes.0[lane]) {
        let LaneGroup { x, p, lengths, lane_x, lane_p, lane_lengths, contacts, constraints, .. } = g;
        extract(&x[..n], lane, lane_x);
        extract(&p[..n], lane, lane_p);
        lane_lengths.clear();
        lane_lengths.extend(lengths[..n - 1].iter().map(|l| l.0[lane]));
        inextensible::prepare(lane_x, lane_lengths, constraints);
        let LaneContacts { normals, sliding_memory, .. } = &mut contacts[lane];
        fell_back.0[lane] = !inextensible::solve_sliding(lane_p, lane_lengths, normals, constraints, sliding_memory);
        write_back(lane_p, lane, &mut p[..n]);
    }
    fell_back
}

/// The lanes of `lanes` whose last contact pass corrected something by more than their settled distance:
/// they need another round of lengths then contacts (`rod::substep`'s final rounds).
pub fn unsettled<const L: usize>(g: &LaneGroup<L>, lanes: Mask<L>) -> Mask<L> {
    let mut out = Mask([false; L]);
    for lane in (0..L).filter(|&lane| lanes.0[lane]) {
        let contact = &g.contacts[lane];
        out.0[lane] = contact.pass.is_some_and(|pass| pass.touching && pass.deepest > contact.settled);
    }
    out
}

/// One lane of `from` into `to`.
pub(super) fn extract<const L: usize>(from: &[DV3<L>], lane: usize, to: &mut Vec<DVec3>) {
    to.clear();
    to.extend(from.iter().map(|v| DVec3::from_array(v.get(lane))));
}

/// `from` into one lane of `to`.
pub(super) fn write_back<const L: usize>(from: &[DVec3], lane: usize, to: &mut [DV3<L>]) {
    for (to, from) in to.iter_mut().zip(from) {
        to.set(lane, from.to_array());
    }
}
