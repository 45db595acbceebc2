//! Software prefetch: asking for the cache lines of data a loop will read a little later, so that it arrives
//! while the loop works on what came before. Chains live in separate allocations (a dozen per chain), too
//! many streams for the hardware prefetchers to follow: the engine's read-backs, which read each chain's pose
//! long after the step wrote it, and the rest-shape updates ask for them a few chains ahead, the lane solver
//! for the next group's chains while a group runs its substeps. Prefetching changes no result, only when data
//! arrives.
//!
//! The lines go to the second-level cache, not the first (hint T1). On an AMD EPYC with AVX-512, with
//! `tools/ab.sh --abba` against one build asking into every level (T0) for all three: 0.970x the time of
//! `scene_cost 60 1000x16 lanes` and 0.948x and 0.966x that of `scene_cost 60 1000x16 views`; for the lane
//! solver's prefetch alone, 0.944x.

use multiversion::multiversion;
use multiversion::target::match_target;

/// A byte range to prefetch: its start and length. The address is never dereferenced here (a prefetch
/// cannot fault), so it is carried as a plain address.
pub(crate) type Region = (*const i8, usize);

/// The bytes of `v`.
pub(crate) fn region<T>(v: &[T]) -> Region {
    (v.as_ptr().cast(), std::mem::size_of_val(v))
}

/// One prefetch per 64-byte line of each non-empty region where the CPU has AVX2, into the second-level cache
/// (see the module's documentation); nothing elsewhere. The intrinsic is safe to call only in a function
/// compiled with a target feature that implies SSE (that SSE is enabled for the whole x86-64 build does not
/// count), hence the `multiversion` copy rather than plain code.
#[multiversion(targets("x86_64+avx2"))]
pub(crate) fn lines(regions: &[Region]) {
    match_target! {
        "x86_64+avx2" => {
            use std::arch::x86_64::{_MM_HINT_T1, _mm_prefetch};
            for &(start, bytes) in regions.iter().filter(|region| region.1 > 0) {
                // From the line that holds the first byte to the one that holds the last, as a plain loop over
                // addresses (`step_by` over offsets: a quarter more instructions in `lines`).
                let end = start as usize + bytes;
                let mut line = start.wrapping_sub(start as usize % 64);
                while (line as usize) < end {
                    _mm_prefetch::<_MM_HINT_T1>(line);
                    line = line.wrapping_add(64);
                }
            }
        }
        _ => {
            let _ = regions;
        }
    }
}
