//! Software prefetch: asking for the cache lines of data a loop will read a little later, so that it arrives
//! while the loop works on what came before. Chains live in separate allocations (a dozen per chain), too
//! many streams for the hardware prefetchers to follow: the engine's read-backs, which read each chain's pose
//! long after the step wrote it, and the rest-shape updates ask for them a few chains ahead. Prefetching
//! changes no result, only when data arrives.
//!
//! The lane solver asked for the whole next group's chains (about a thousand lines for 16 chains) and no
//! longer does: on an AMD EPYC with AVX-512 that burst made the frame slower, not faster (a build without it,
//! loading the chains with [`super::lanes`]' transposes, was 0.95x the time of one with it on `scene_cost 80
//! 1000x16 lanes`, and 0.92x to 0.95x on 16384 x 16, which does not fit in the cache), while the read-backs'
//! one chain at a time still pays (1.04x without it).

use multiversion::multiversion;
use multiversion::target::match_target;

/// A byte range to prefetch: its start and length. The address is never dereferenced here (a prefetch
/// cannot fault), so it is carried as a plain address.
pub(crate) type Region = (*const i8, usize);

/// The bytes of `v`.
pub(crate) fn region<T>(v: &[T]) -> Region {
    (v.as_ptr().cast(), std::mem::size_of_val(v))
}

/// One prefetch per 64-byte line of each non-empty region where the CPU has AVX2; nothing elsewhere. The
/// intrinsic is safe to call only in a function compiled with a target feature that implies SSE (that SSE is
/// enabled for the whole x86-64 build does not count), hence the `multiversion` copy rather than plain code.
#[multiversion(targets("x86_64+avx2"))]
pub(crate) fn lines(regions: &[Region]) {
    match_target! {
        "x86_64+avx2" => {
            use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
            for &(start, bytes) in regions.iter().filter(|region| region.1 > 0) {
                // From the line that holds the first byte to the one that holds the last, as a plain loop over
                // addresses (`step_by` over offsets: a quarter more instructions in `lines`).
                let end = start as usize + bytes;
                let mut line = start.wrapping_sub(start as usize % 64);
                while (line as usize) < end {
                    _mm_prefetch::<_MM_HINT_T0>(line);
                    line = line.wrapping_add(64);
                }
            }
        }
        _ => {
            let _ = regions;
        }
    }
}
