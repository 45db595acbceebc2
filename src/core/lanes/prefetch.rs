//! Software prefetch of the chain data the next lane group loads, issued before the current group's substeps
//! so that it arrives while they run. A group's chains live in separate allocations (a dozen per chain), and
//! loading them joint by joint across the lanes touches more streams than the hardware prefetchers follow.
//! Sampled with `perf record -e cpu-clock` on this stop's AMD EPYC (AVX2, groups of 8) at cf4ade5,
//! `LaneGroup::load` took 11.7 % of the samples of `step_cost 1000 16 300 sway` against 5.5 % of those of
//! `step_cost 100 16 3000 sway`, whose chains stay in cache: we estimate that about half of the load's time on
//! 1000 x 16 went waiting on memory. Prefetching changes no result, only when data arrives.

use multiversion::multiversion;
use multiversion::target::match_target;

use super::LaneJob;
use crate::core::arena::Arena;
use crate::core::chain::Chain;

/// A byte range to prefetch: its start and length. The address is never dereferenced here (a prefetch
/// cannot fault), so it is carried as a plain address.
type Region = (*const i8, usize);

fn region<T>(v: &[T]) -> Region {
    (v.as_ptr().cast(), std::mem::size_of_val(v))
}

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

/// One prefetch per 64-byte line of each non-empty region where the CPU has AVX2; nothing elsewhere. The
/// intrinsic is safe to call only in a function compiled with a target feature that implies SSE (that SSE is
/// enabled for the whole x86-64 build does not count), hence the `multiversion` copy rather than plain code.
#[multiversion(targets("x86_64+avx2"))]
fn lines(regions: &[Region]) {
    match_target! {
        "x86_64+avx2" => {
            use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
            for &(start, bytes) in regions.iter().filter(|region| region.1 > 0) {
                // From the line that holds the first byte.
                let skew = start as usize % 64;
                let first_line = start.wrapping_sub(skew);
                for offset in (0..bytes + skew).step_by(64) {
                    _mm_prefetch::<_MM_HINT_T0>(first_line.wrapping_add(offset));
                }
            }
        }
        _ => {
            let _ = regions;
        }
    }
}
