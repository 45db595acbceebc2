//! The lane solver: chains of the same joint count stepped side by side, one chain per SIMD lane.
//!
//! Most chains of a character are alike (a head of hair: dozens of strands of one length), and the scalar
//! solver leaves most of a modern CPU's vector width unused. Here a step sorts the chains it simulates by
//! joint count (and limp or not), cuts each run of equal length into groups of 16 (on CPUs with AVX-512:
//! `has_avx512`), 8 and 4 chains (the last group of a run may repeat one of its chains in its spare lanes),
//! and advances each group through all of the step's substeps in structure-of-arrays buffers. The last 1 or
//! 2 chains of a run after its full groups, too few for a group to pay, take the scalar solver.
//!
//! - [`simd`]: lane arithmetic; [`kernel`]: one substep of a group, whose phases are compiled one by one;
//!   [`polar`], [`lengths`] and [`rotations`]: the parts written as loops over lanes, with one lane's
//!   arithmetic in [`scalar`]; [`contacts`]: the contact pass ([`outside`] and [`screen_avx2`] for spheres and
//!   capsules); [`group`]: the buffers, loaded from the chains and stored back by [`transpose`].
//! - The wide copies of the kernel are compiled for AVX2 (groups of 8 and 4) and AVX-512 (groups of 16) next
//!   to the portable (SSE2) one and chosen at run time by CPU-feature detection ([`multiversion`]); no build
//!   needs `target-cpu=native`.
//! - Determinism: a chain's result does not depend on its lane, on the group it shares (16, 8 or 4 wide), or on
//!   which copy of the kernel ran (no fused or reordered floating-point operations): the same bits on every
//!   x86-64 and aarch64 CPU. It differs from the scalar solver ([`Solver::Scalar`]) by float rounding only
//!   (the two implement the same operations, grouped differently); `tests/lanes.rs` and the accuracy report
//!   measure by how much. So whether a chain runs in lanes (every chain of a joint count does but the last 1
//!   or 2 after its full groups) changes its motion by rounding, never more; the same inputs always give the
//!   same bits.
//! - Chains that may touch a collider run in lanes too. Against spheres and capsules, the colliders of a
//!   character, the contact pass (and pre-stabilisation's first pass) screens every lane's segment at once,
//!   segment after segment, and takes the scalar test and correction only where a segment may touch
//!   ([`outside`]); against a ground plane or an inside collider it runs the
//!   scalar pass one lane at a time ([`contacts`]). Either way a chain's contacts are the scalar solver's, bit
//!   for bit, given the same positions. The render pose is computed in lanes as well
//!   ([`output`], the scalar code's operations); everything else a chain does (sleeping, teleports, momentum
//!   suppression) is shared with the scalar solver.

mod contacts;
mod group;
mod kernel;
mod lengths;
mod matching;
mod output;
mod outside;
mod polar;
mod prefetch;
mod rotations;
pub(crate) mod scalar;
#[cfg(target_arch = "x86_64")]
mod screen_avx2;
mod simd;
mod transpose;

use glam::DVec3;
use multiversion::multiversion;
use multiversion::target::match_target;

use super::arena::Arena;
use super::chain::Chain;
use super::math::Transform;
use super::reach::Reach;
use super::rod::ChainConstants;
use group::{GroupSettings, LaneChain, LaneGroup};
use kernel::Phases;
use lengths::{ForwardPass, Passes};
use matching::Stiffness;
use simd::{D, DV3, F, M3, Mask, Q, V3};

/// Which solver steps the chains.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Solver {
    /// Chains of equal joint count side by side in SIMD lanes (the default).
    #[default]
    Lanes,
    /// [`Lanes`](Self::Lanes) with the portable copy of its kernel (SSE2 on x86-64) whatever the CPU has: the
    /// same bits, slower. For checking the determinism policy on one machine.
    LanesPortable,
    /// One chain at a time: the reference implementation (and what the last 1 or 2 chains of a joint count
    /// after its full lane groups use).
    Scalar,
}

/// The instruction set the lane solver's kernel runs with on this CPU: `"avx512"` (groups of 16 in 512-bit
/// registers, groups of 8 and 4 with AVX2), `"avx2"`, `"sse2"` (the portable x86-64 build), `"neon"` (aarch64)
/// or `"scalar"`.
pub fn simd_path() -> &'static str {
    #[cfg(target_arch = "x86_64")]
    {
        if has_avx512() {
            "avx512"
        } else if std::is_x86_feature_detected!("avx2") {
            "avx2"
        } else {
            "sse2"
        }
    }
    #[cfg(target_arch = "aarch64")]
    {
        "neon"
    }
    #[cfg(not(any(target_arch = "x86_64", target_arch = "aarch64")))]
    {
        "scalar"
    }
}

/// Whether this CPU runs the 16-lane kernel: `WIDE16`'s target, whose features are these. `multiversion` adds
/// the Ice Lake generation's AVX-512 extensions to any AVX-512 target (so that CPUs whose 512-bit code runs at
/// a lowered clock keep the AVX2 copy), and dispatches to the portable copy where one is missing; groups of 16
/// must not run there. (`std` caches the detection.)
fn has_avx512() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::is_x86_feature_detected as has;
        has!("avx512f")
            && has!("avx512vl")
            && has!("avx512bw")
            && has!("avx512dq")
            && has!("avx512cd")
            && has!("avx512ifma")
            && has!("avx512vbmi")
            && has!("avx512vbmi2")
            && has!("avx512vnni")
            && has!("avx512bitalg")
            && has!("avx512vpopcntdq")
            && has!("gfni")
            && has!("vaes")
            && has!("vpclmulqdq")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// One chain the step hands to the lane solver, with its per-step constants (computed like the scalar
/// solver's inputs).
#[derive(Clone, Copy, Debug)]
pub(crate) struct LaneJob {
    pub slot: u32,
    pub joints: usize,
    /// The anchor at the start and at the end of the step (relative to the engine origin).
    pub start: Transform,
    pub target: Transform,
    pub constants: ChainConstants,
    /// Nothing about the chain changed this step (towards sleeping).
    pub still: bool,
    /// The shift of the engine origin its positions have yet to take this step (`Engine::advance`).
    pub rebase: Option<DVec3>,
}

impl LaneJob {
    fn key(&self) -> (usize, bool) {
        (self.joints, self.constants.alpha_per_iteration > 0.0)
    }
}

/// The timing of one step, shared by every chain.
pub(crate) struct Clock<'a> {
    pub h: f32,
    pub iterations: u32,
    /// Fraction of the step's anchor motion reached at the end of each substep.
    pub progress: &'a [f32],
    /// Where the render pose lies along the last two internal states (`Chain::write_output`'s `t`).
    pub output_fraction: f32,
}

/// The lane solver's reusable buffers (one group of each width).
#[derive(Default)]
pub struct LaneSolver {
    /// Used only where the CPU has AVX-512.
    g16: LaneGroup<16>,
    g8: LaneGroup<8>,
    g4: LaneGroup<4>,
}

/// The fewest chains of one kind (joint count, limp or not) that [`group_widths`] puts in a lane group.
pub(crate) const FEWEST_IN_A_GROUP: usize = 3;

/// How a run of `len` chains of one kind is cut into lane groups: full groups of 16 where the CPU has AVX-512
/// (`sixteen`), full groups of 8, then the rest as one group of 8 or 4 whose spare lanes repeat a chain of the
/// group (computed, never stored), or on the scalar solver. Measured in instructions (callgrind, `step_cost 4
/// 16 100 sway` on both solvers and `8 16 100`): a group of 4 costs 2.0x less than 4 chains on the scalar
/// solver (39.1M against 79.0M) and a group of 8 1.33x as much as a group of 4 (51.8M), so 5-7 chains are
/// cheapest as a padded group of 8, 3 as a padded group of 4, and 1-2 on the scalar solver (a group of 4
/// holding 2 costs what they cost there). A group of 16 in 512-bit registers runs the same operations on
/// twice the chains per instruction. The kernel is bound by the latency of its chains of dependent operations
/// (shape matching goes root to tip), so that shortens its time per chain: 0.76x that of groups of 8 with
/// AVX2 (`step_cost 1000 16 10 sway` built at 28d84ce and at its parent, run alternately 16 times: median
/// ratio). With AVX2 alone (two 256-bit halves per operation) groups of 16 were no faster than groups of 8, and
/// on a Zen 1, which splits each 256-bit operation again, slower: 1.09x the time of `scene_cost 40 1000x16
/// lanes` (`tools/ab.sh --abba`, stop 41). Nor did two groups of 8 whose shape-matching sweeps ran side by side,
/// in the lane loops or in AVX2 intrinsics (stops 32-33 and 45, `docs/performance-history.md`): with 16 vector
/// registers the second group's values spill, and the spills take back what the overlap gains.
fn group_widths(len: usize, sixteen: bool) -> impl Iterator<Item = (usize, usize)> {
    let sixteens = if sixteen { len / 16 } else { 0 };
    let rest = len - 16 * sixteens;
    let full = rest / 8;
    let tail = match rest % 8 {
        rest @ 5..=7 => Some((rest, 8)),
        rest @ FEWEST_IN_A_GROUP..=4 => Some((rest, 4)),
        _ => None,
    };
    std::iter::repeat_n((16, 16), sixteens).chain(std::iter::repeat_n((8, 8), full)).chain(tail)
}

impl LaneSolver {
    /// Room for lane groups of chains of `joints` joints over up to `substeps` substeps, touching up to
    /// `colliders` colliders, in every width this CPU runs (`LaneGroup::reserve`).
    pub(crate) fn reserve(&mut self, joints: usize, substeps: usize, colliders: usize) {
        if has_avx512() {
            self.g16.reserve(joints, substeps, colliders);
        }
        self.g8.reserve(joints, substeps, colliders);
        self.g4.reserve(joints, substeps, colliders);
    }

    /// Runs every substep of the step for the chains of `jobs` (reordered by joint count) that go into lane
    /// groups ([`group_widths`]), and moves the others to `leftovers` for the scalar solver. Returns the
    /// substeps, summed over the chains, in which the direct inextensibility solve fell back, and the contact
    /// pairs tested.
    pub(crate) fn step(
        &mut self,
        chains: &mut Arena<Chain>,
        jobs: &mut Vec<LaneJob>,
        leftovers: &mut Vec<LaneJob>,
        clock: &Clock<'_>,
        reach: &Reach<'_>,
        portable: bool,
    ) -> (u64, u64) {
        jobs.sort_unstable_by_key(|j| (j.key(), j.slot));
        let sixteen = !portable && has_avx512();
        leftovers.clear();
        let mut kept = 0;
        let mut first = 0;
        while first < jobs.len() {
            let key = jobs[first].key();
            let len = jobs[first..].iter().take_while(|j| j.key() == key).count();
            let grouped: usize = group_widths(len, sixteen).map(|(chains, _)| chains).sum();
            for i in first..first + len {
                if i - first < grouped {
                    jobs[kept] = jobs[i];
                    kept += 1;
                } else {
                    leftovers.push(jobs[i]);
                }
            }
            first += len;
        }
        jobs.truncate(kept);
        let (mut fallbacks, mut pairs) = (0, 0);
        let mut rest = &jobs[..];
        while let Some(first) = rest.first() {
            let same = rest.iter().take_while(|j| j.key() == first.key()).count();
            let (mut run, tail) = rest.split_at(same);
            rest = tail;
            for (count, width) in group_widths(same, sixteen) {
                let (group, remaining) = run.split_at(count);
                run = remaining;
                // The next group: the first of the rest of this run, or of the next run (at most `width` chains;
                // a smaller next group's neighbours come along).
                let ahead = if run.is_empty() { rest } else { run };
                let next = &ahead[..ahead.len().min(width)];
                let (group_fallbacks, group_pairs) = match (width, portable) {
                    (16, _) => run_group(&mut self.g16, chains, group, next, clock, reach, &WIDE16),
                    (8, false) => run_group(&mut self.g8, chains, group, next, clock, reach, &WIDE8),
                    (8, true) => run_group(&mut self.g8, chains, group, next, clock, reach, &Phases::PORTABLE),
                    (_, false) => run_group(&mut self.g4, chains, group, next, clock, reach, &WIDE4),
                    (_, true) => run_group(&mut self.g4, chains, group, next, clock, reach, &Phases::PORTABLE),
                };
                fallbacks += group_fallbacks;
                pairs += group_pairs;
            }
        }
        (fallbacks, pairs)
    }
}

/// The screen of 8 lanes in AVX2's vectors ([`screen_avx2`]) where the CPU has it.
#[allow(clippy::too_many_arguments)]
#[multiversion(targets("x86_64+avx2"))]
fn screen8(
    screen: &outside::Screen<8>,
    lanes: Mask<8>,
    start: &mut [DV3<8>],
    p: &mut [DV3<8>],
    radii: &[F<8>],
    bounds: &[(DV3<8>, D<8>)],
    drift: &mut D<8>,
    slop: F<8>,
    resolve: &mut outside::Resolve<'_, 8>,
) {
    match_target! {
        "x86_64+avx2" => screen_avx2::screen_all(screen, lanes, start, p, radii, bounds, drift, slop, resolve),
        _ => {
            let _ = (screen, radii, slop);
            outside::every_segment(lanes, start, p, bounds.len(), drift, resolve)
        }
    }
}

/// The kernel's phases compiled for `$target` where the CPU has it, one dispatching function per phase and width.
macro_rules! wide_phases {
    ($name:ident, $lanes:literal, $target:literal, $begin:ident, $match_shape:ident, $sweep:ident, $terms:ident, $solve:ident, $passes:ident, $first:ident, $corrected:ident, $after:ident, $finish:ident, $predict:ident, $spin:ident, $capture:ident, $output:ident, $collide:ident, $pre_stabilise:ident, $screen:expr) => {
        #[multiversion(targets($target))]
        fn $begin(g: &mut LaneGroup<$lanes>, s: usize) {
            kernel::begin_substep(g, s, $predict)
        }

        #[multiversion(targets($target))]
        fn $predict(w: &[V3<$lanes>], q: &[Q<$lanes>], qp: &mut [Q<$lanes>], h: f32) {
            rotations::predict_orientations(w, q, qp, h)
        }

        #[multiversion(targets($target))]
        fn $spin(qp: &[Q<$lanes>], q: &[Q<$lanes>], w: &mut [V3<$lanes>], inv_h: f32) {
            rotations::angular_velocities(qp, q, w, inv_h)
        }

        #[multiversion(targets($target))]
        fn $match_shape(g: &mut LaneGroup<$lanes>, landing: f32) {
            kernel::match_shape(g, landing, $sweep, $terms)
        }

        #[multiversion(targets($target))]
        fn $terms(qp: &[Q<$lanes>], qbar_inv: &[Q<$lanes>], weight: F<$lanes>, terms: &mut [M3<$lanes>]) {
            kernel::orientation_terms(qp, qbar_inv, weight, terms)
        }

        #[allow(clippy::too_many_arguments)]
        #[multiversion(targets($target))]
        fn $sweep(
            p: &mut [DV3<$lanes>],
            qp: &mut [Q<$lanes>],
            qbar: &[Q<$lanes>],
            qbar_inv: &[Q<$lanes>],
            offsets: &[[V3<$lanes>; 3]],
            terms: &[M3<$lanes>],
            group_rotation: &mut [Q<$lanes>],
            stiffness: &Stiffness<$lanes>,
            landing: f32,
        ) {
            kernel::sweep(p, qp, qbar, qbar_inv, offsets, terms, group_rotation, stiffness, landing)
        }

        #[multiversion(targets($target))]
        fn $solve(g: &mut LaneGroup<$lanes>, lanes: Mask<$lanes>, warm: Option<usize>) -> Mask<$lanes> {
            lengths::solve_lengths(g, lanes, warm, &$passes)
        }

        #[multiversion(targets($target))]
        fn $first(
            p: &[DV3<$lanes>],
            d: &[DV3<$lanes>],
            l2: &[D<$lanes>],
            inv_l2: &[D<$lanes>],
            c_prime: &mut [D<$lanes>],
            d_prime: &mut [D<$lanes>],
            pass: &mut ForwardPass<$lanes>,
        ) {
            lengths::first_pass(p, d, l2, inv_l2, c_prime, d_prime, pass)
        }

        #[allow(clippy::too_many_arguments)]
        #[multiversion(targets($target))]
        fn $corrected(
            p: &[DV3<$lanes>],
            corrected: &mut [DV3<$lanes>],
            mu: &[D<$lanes>],
            d: &[DV3<$lanes>],
            l2: &[D<$lanes>],
            inv_l2: &[D<$lanes>],
            c_prime: &mut [D<$lanes>],
            d_prime: &mut [D<$lanes>],
            pass: &mut ForwardPass<$lanes>,
        ) {
            lengths::corrected_pass(p, corrected, mu, d, l2, inv_l2, c_prime, d_prime, pass)
        }

        #[multiversion(targets($target))]
        fn $after(
            p: &[DV3<$lanes>],
            corrected: &mut [DV3<$lanes>],
            mu: &[D<$lanes>],
            step: &[D<$lanes>],
            d: &[DV3<$lanes>],
            inv_l2: &[D<$lanes>],
        ) -> D<$lanes> {
            lengths::after_step(p, corrected, mu, step, d, inv_l2)
        }

        const $passes: Passes<$lanes> = Passes { first: $first, corrected: $corrected, after_step: $after };

        #[multiversion(targets($target))]
        fn $finish(g: &mut LaneGroup<$lanes>) {
            kernel::finish_substep(g, $spin)
        }

        #[multiversion(targets($target))]
        fn $capture(g: &mut LaneGroup<$lanes>, s: usize) {
            output::capture(g, s)
        }

        #[multiversion(targets($target))]
        fn $output(g: &mut LaneGroup<$lanes>, t: f32) {
            output::write(g, t)
        }

        #[multiversion(targets($target))]
        fn $collide(g: &mut LaneGroup<$lanes>, lanes: Mask<$lanes>, fresh: bool) -> u64 {
            contacts::collide(g, lanes, fresh, $screen)
        }

        #[multiversion(targets($target))]
        fn $pre_stabilise(g: &mut LaneGroup<$lanes>, lanes: Mask<$lanes>) {
            contacts::pre_stabilise(g, lanes, $screen)
        }

        const $name: Phases<$lanes> = Phases {
            begin: $begin,
            match_shape: $match_shape,
            solve_lengths: $solve,
            finish: $finish,
            capture: $capture,
            output: $output,
            collide: $collide,
            pre_stabilise: $pre_stabilise,
        };
    };
}

wide_phases!(
    WIDE8,
    8,
    "x86_64+avx2",
    begin8,
    match_shape8,
    sweep8,
    terms8,
    solve_lengths8,
    PASSES8,
    first_pass8,
    corrected_pass8,
    after_step8,
    finish8,
    predict8,
    spin8,
    capture8,
    output8,
    collide8,
    pre_stabilise8,
    Some(screen8)
);
wide_phases!(
    WIDE16,
    16,
    // Spelled out as `multiversion` completes it (see `has_avx512`).
    "x86_64+avx512f+avx512vl+avx512bw+avx512dq+avx512cd+avx512ifma+avx512vbmi+avx512vbmi2+avx512vnni+avx512bitalg+avx512vpopcntdq+gfni+vaes+vpclmulqdq",
    begin16,
    match_shape16,
    sweep16,
    terms16,
    solve_lengths16,
    PASSES16,
    first_pass16,
    corrected_pass16,
    after_step16,
    finish16,
    predict16,
    spin16,
    capture16,
    output16,
    collide16,
    pre_stabilise16,
    None
);
wide_phases!(
    WIDE4,
    4,
    "x86_64+avx2",
    begin4,
    match_shape4,
    sweep4,
    terms4,
    solve_lengths4,
    PASSES4,
    first_pass4,
    corrected_pass4,
    after_step4,
    finish4,
    predict4,
    spin4,
    capture4,
    output4,
    collide4,
    pre_stabilise4,
    None
);

/// Steps the chains of `jobs` (at most `L`) in `g`, and asks for those of `next` ([`prefetch`]). Spare lanes
/// repeat the first chain without its contacts; they are computed like any lane (lanes never affect each
/// other) but not stored or counted.
fn run_group<const L: usize>(
    g: &mut LaneGroup<L>,
    chains: &mut Arena<Chain>,
    jobs: &[LaneJob],
    next: &[LaneJob],
    clock: &Clock<'_>,
    reach: &Reach<'_>,
    phases: &Phases<L>,
) -> (u64, u64) {
    debug_assert!(!jobs.is_empty() && jobs.len() <= L);
    let substeps = clock.progress.len();
    let first = &jobs[0];
    g.begin(GroupSettings {
        joints: first.joints,
        h: clock.h,
        iterations: clock.iterations,
        shape_matching: first.constants.alpha_per_iteration > 0.0,
        substeps,
    });
    let anchor = |job: &LaneJob, s: usize| job.start.interpolate(&job.target, clock.progress[s]);
    let job_at = |lane: usize| jobs.get(lane).unwrap_or(first);
    g.load(&std::array::from_fn(|lane| {
        let job = job_at(lane);
        let chain = chains.at(job.slot as usize).expect("live");
        LaneChain {
            state: &chain.state,
            rest: &chain.rest,
            offsets: &chain.rest_groups.offsets,
            lengths: &chain.frame.lengths,
            constants: &job.constants,
            half_kick: chain.half_kick,
            rebase: job.rebase,
            local_current: &chain.local_current,
            bone_axes: &chain.bone_axes,
        }
    }));
    for lane in 0..L {
        let real = lane < jobs.len();
        let job = job_at(lane);
        let chain = chains.at(job.slot as usize).expect("live");
        for s in 0..substeps {
            g.set_anchor(s, lane, &anchor(job, s));
        }
        g.load_contacts(
            lane,
            reach.order.len(),
            |candidates, radii| {
                if real {
                    reach.candidates(chain, &job.start, &job.target, candidates, radii)
                }
            },
            chain.params.friction,
            chain.contact_slop(),
            chain.contact_settled(),
        );
    }
    let touching = g.contact_lanes.any();
    prefetch::chains_of(chains, next);
    let (mut fallbacks, mut pairs) = (0, 0);
    for s in 0..substeps {
        let fell_back = if touching {
            g.select_sweeps(reach.sweeps, reach.order.len(), s);
            let (fell_back, tested) = kernel::substep_with_contacts(g, s, phases);
            pairs += tested;
            fell_back
        } else {
            kernel::substep(g, s, phases)
        };
        fallbacks += fell_back.0[..jobs.len()].iter().filter(|&&f| f).count() as u64;
        // The output pose uses the last two internal poses.
        if s + 2 >= substeps {
            (phases.capture)(g, s);
        }
    }
    (phases.output)(g, clock.output_fraction);
    g.prepare_store();
    for (lane, job) in jobs.iter().enumerate() {
        let chain = chains.at_mut(job.slot as usize).expect("live");
        g.store(lane, &mut chain.state);
        g.store_render(lane, &mut chain.local_previous, &mut chain.local_current, &mut chain.output);
        chain.half_kick = false;
    }
    (fallbacks, pairs)
}

#[cfg(test)]
mod tests {
    use super::{FEWEST_IN_A_GROUP, group_widths};
    use crate::core::{ChainParams, Engine, EngineSettings, Transform};
    use glam::{Quat, Vec3};

    /// After a step of one substep the previous of the last two render poses is the newest one the chain held
    /// before the step, to the bit (`LaneGroup::store_render` takes it from the chain instead of writing it). At
    /// 144 fps a 240 Hz engine runs one substep in some frames and two in others.
    #[test]
    fn a_step_of_one_substep_keeps_the_newest_pose_as_the_previous() {
        let mut engine = Engine::new(EngineSettings::default()).unwrap();
        let ids: Vec<_> = (0..8)
            .map(|i| {
                let down = Vec3::new((i as f32).cos(), -3.0, (i as f32).sin()).normalize();
                let joints: Vec<Transform> =
                    (0..16).map(|j| Transform::new(down * (0.025 * j as f32), Quat::IDENTITY)).collect();
                engine.create_chain(ChainParams::default(), &joints).unwrap()
            })
            .collect();
        let bits = |poses: &[Transform]| -> Vec<[u32; 7]> {
            let word = |t: &Transform| {
                let (p, q) = (t.position.to_array(), t.rotation.to_array());
                [p[0], p[1], p[2], q[0], q[1], q[2], q[3]].map(f32::to_bits)
            };
            poses.iter().map(word).collect()
        };
        let (mut one, mut two) = (0, 0);
        for frame in 0..60 {
            let t = frame as f32 / 144.0;
            let head = Transform::new(Vec3::new(0.2 * (9.0 * t).sin(), 1.6, 0.0), Quat::from_rotation_y(2.0 * t));
            let newest: Vec<_> = ids.iter().map(|&id| bits(&engine.chain(id).unwrap().local_current)).collect();
            let before = engine.stats().substeps_total;
            engine.step(1.0 / 144.0, Vec3::new(3.0 * t.cos(), 1.6, 3.0 * t.sin()), head).unwrap();
            assert_eq!(engine.stats().lane_chains, 8);
            match engine.stats().substeps_total - before {
                // The first step places the chains: their poses before it are not the ones it continues.
                _ if frame == 0 => {}
                1 => {
                    one += 1;
                    for (&id, newest) in ids.iter().zip(&newest) {
                        assert_eq!(&bits(&engine.chain(id).unwrap().local_previous), newest, "frame {frame}");
                    }
                }
                _ => two += 1,
            }
        }
        println!("{one} frames of one substep checked, {two} of two");
        assert!(one >= 15 && two >= 15, "{one} frames of one substep, {two} of two");
    }

    #[test]
    fn runs_are_cut_into_groups_of_16_only_where_the_kernel_has_them() {
        let cut = |len, sixteen| group_widths(len, sixteen).collect::<Vec<_>>();
        assert_eq!(cut(2, true), []);
        assert_eq!(cut(FEWEST_IN_A_GROUP - 1, false), []);
        assert_eq!(cut(FEWEST_IN_A_GROUP, false), [(FEWEST_IN_A_GROUP, 4)]);
        assert_eq!(cut(16, false), [(8, 8), (8, 8)]);
        assert_eq!(cut(16, true), [(16, 16)]);
        assert_eq!(cut(29, true), [(16, 16), (8, 8), (5, 8)]);
        assert_eq!(cut(35, true), [(16, 16), (16, 16), (3, 4)]);
        assert_eq!(cut(18, true), [(16, 16)]);
        for len in 0..100 {
            for sixteen in [false, true] {
                let groups = cut(len, sixteen);
                let grouped: usize = groups.iter().map(|&(chains, _)| chains).sum();
                assert!(len - grouped <= 2, "{len}: at most 2 left for the scalar solver");
                assert!(groups.iter().all(|&(chains, width)| chains <= width && (sixteen || width < 16)));
            }
        }
    }
}
