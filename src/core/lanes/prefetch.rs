//! Software prefetch of the chain data the next lane group loads, issued before the current group's substeps
//! so that it arrives while they run. A group's chains live in separate allocations (a dozen per chain), and
//! loading them joint by joint across the lanes touches more streams than the hardware prefetchers follow.
//! Sampled with `perf record -e cpu-clock` on an AMD EPYC (AVX2, groups of 8) at cf4ade5,
//! `LaneGroup::load` took 11.7 % of the samples of `step_cost 1000 16 300 sway` against 5.5 % of those of
//! `step_cost 100 16 3000 sway`, whose chains stay in cache: we estimate that about half of the load's time on
//! 1000 x 16 went waiting on memory. Prefetching changes no result, only when data arrives.

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
            region(&chain.frame.lengths),
            region(&chain.local_previous),
            region(&chain.local_current),
            region(&chain.output),
        ]);
    }
}
