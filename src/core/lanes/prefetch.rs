//! Software prefetch of the chain data the next lane group loads and stores, asked for before the current
//! group's substeps so that it arrives while they run. A group's chains live in separate allocations (a dozen
//! per chain), and the transposes that load them wait on each (`transpose::gather_f32` took 6 % of the samples
//! of `perf record -e cpu-clock target/release/examples/scene_cost 150 1000x16 lanes`, mostly on its loads).
//!
//! On an AMD EPYC with AVX-512 (groups of 16), with `tools/ab.sh --abba` against the build without it (fcecd29):
//! 0.958x and 0.961x the time of `scene_cost 60 1000x16 lanes`, 0.909x that of `scene_cost 5 16384x16 lanes`,
//! 0.989x that of `scene_cost 400 100x16 lanes` (in cache: the cost of asking). Adding the segment lengths and
//! the multiplier histories to the lines asked for: 0.951x and 0.974x again (1000 x 16), 0.920x (16384 x 16).
//! Stop 37 had dropped a prefetch of the next group for slowing the frame on this machine: it asked into the
//! first-level cache as well, which this one does not (see `crate::core::prefetch`). Prefetching changes no
//! result, only when data arrives.

use super::LaneJob;
use crate::core::arena::Arena;
use crate::core::chain::Chain;
use crate::core::prefetch::{lines, region};

/// Asks for the cache lines of what [`super::group::LaneGroup::load`] reads and `run_group` writes for the
/// chains of `jobs`.
pub(super) fn chains_of(chains: &Arena<Chain>, jobs: &[LaneJob]) {
    for job in jobs {
        let Some(chain) = chains.at(job.slot as usize) else { continue };
        let state = &chain.state;
        lines(&[
            region(&state.x),
            region(&state.v),
            region(&state.q),
            region(&state.w),
            region(&state.group_rotation),
            region(&chain.rest.orientations),
            region(&chain.rest_groups.offsets),
            region(&chain.bone_axes),
            region(&chain.local_previous),
            region(&chain.local_current),
            region(&chain.output),
            region(&chain.frame.lengths),
        ]);
        for history in &state.solve_memory.warm {
            lines(&[region(&history.last), region(&history.before)]);
        }
    }
}
