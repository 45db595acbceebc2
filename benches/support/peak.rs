//! The arithmetic peak of one core, measured rather than assumed: how many lane operations per second it
//! runs when nothing but independent multiplies and adds are in flight, and when nothing but independent
//! divisions, or square roots, are (they take a divider that accepts a new operation only every few cycles,
//! where the multipliers and adders accept two per cycle). The kernel's determinism policy
//! (`src/core/lanes/mod.rs`) rules out fused multiply-adds, so neither are they used here: the peak is the
//! one the code as written could reach. Ratios of the rod's operation counts to these rates give the compute
//! lines of the report's lower bound.

use std::hint::black_box;
use std::time::Instant;

use multiversion::multiversion;
use multiversion::target::match_target;

/// Rounds of one timed pass: about 2 ms at a peak of 1e11 lane operations per second for 16 lanes (12 chains).
const ROUNDS: u64 = 1 << 20;

/// Lane operations per second, best of a few passes.
#[derive(Clone, Copy, Debug)]
pub struct Peak {
    /// Single precision, one lane at a time (scalar code: the scalar solver's rate).
    pub scalar_f32: f64,
    /// Single and double precision, `lanes` lanes per operation, compiled like the lane kernel's widest copy.
    pub simd_f32: f64,
    pub simd_f64: f64,
    pub lanes: usize,
    /// Divisions and square roots, one lane at a time and `lanes` at once.
    pub scalar_f32_divider: Divider,
    pub scalar_f64_divider: Divider,
    pub simd_f32_divider: Divider,
    pub simd_f64_divider: Divider,
}

/// Division and square root rates (lane operations per second).
#[derive(Clone, Copy, Debug)]
pub struct Divider {
    pub division: f64,
    pub root: f64,
}

impl Peak {
    /// `sixteen`: the lane solver ran its 16-lane (AVX-512) kernel; else its 8-lane one (AVX2 where the CPU has
    /// it, else the portable copy).
    pub fn measure(sixteen: bool) -> Self {
        Self::measure_with(sixteen, 5)
    }

    /// [`measure`](Self::measure) with each rate the best of `passes` timed passes (a few milliseconds each).
    pub fn measure_with(sixteen: bool, passes: usize) -> Self {
        let best = |run| best_of(run, ROUNDS, passes);
        let (simd_f32, simd_f64) = if sixteen { (best(f32x16), best(f64x16)) } else { (best(f32x8), best(f64x8)) };
        let divider = |division: fn(u64) -> (u64, f64), root: fn(u64) -> (u64, f64)| Divider {
            division: best_of(division, DIVIDER_ROUNDS, passes),
            root: best_of(root, DIVIDER_ROUNDS, passes),
        };
        let (simd_f32_divider, simd_f64_divider) = if sixteen {
            (divider(div_f32x16, sqrt_f32x16), divider(div_f64x16, sqrt_f64x16))
        } else {
            (divider(div_f32x8, sqrt_f32x8), divider(div_f64x8, sqrt_f64x8))
        };
        let scalar_f32 = best(f32x1);
        // Even 4-lane registers (the portable copy's SSE2 or NEON) run twice the scalar rate; below that a SIMD
        // probe's code did not vectorise (its accumulators went to memory: see `chains!`), and every bound
        // derived from it would be wrong.
        assert!(
            simd_f32 > 2.0 * scalar_f32 && simd_f64 > scalar_f32,
            "the {}-lane SIMD probes ran at f32 {:.1} and f64 {:.1} G lane operations/s against a scalar {:.1}: \
             their code did not vectorise (disassemble f32x16 / f32x8 in benches/support/peak.rs)",
            if sixteen { 16 } else { 8 },
            simd_f32 / 1e9,
            simd_f64 / 1e9,
            scalar_f32 / 1e9
        );
        Self {
            scalar_f32,
            simd_f32,
            simd_f64,
            lanes: if sixteen { 16 } else { 8 },
            scalar_f32_divider: divider(div_f32x1, sqrt_f32x1),
            scalar_f64_divider: divider(div_f64x1, sqrt_f64x1),
            simd_f32_divider,
            simd_f64_divider,
        }
    }
}

/// Rounds of a timed division or square root pass: those run about a tenth as fast as multiplies and adds.
const DIVIDER_ROUNDS: u64 = ROUNDS / 8;

/// The best rate of `run` over `passes` passes of `rounds` rounds.
fn best_of(run: fn(u64) -> (u64, f64), rounds: u64, passes: usize) -> f64 {
    let mut best = 0.0f64;
    for _ in 0..passes {
        let start = Instant::now();
        let (operations, value) = run(black_box(rounds));
        black_box(value);
        best = best.max(operations as f64 / start.elapsed().as_secs_f64());
    }
    best
}

/// Independent accumulators, one per name in the list (as many as the vector registers hold), the first of each
/// pair multiplied and the second added to each round, with the operations `$mul` and `$add` (intrinsics, or
/// lane loops the vectoriser compiles to one instruction per register) written out so that no compiler pass can
/// regroup them. Named locals, not an array indexed in a loop: an array's accumulators could stay in memory,
/// each round a load, the operation and a store (rustc 1.95 did so with the 16-lane arrays, and the probes
/// measured a fifth of the core's rate). Evaluates to the lane operations run and a value that depends on every
/// one of them.
macro_rules! chains {
    ($rounds:expr, $elem:ty, $lanes:literal, $splat:expr, $mul:expr, $add:expr, $sum:expr, [$($m:ident $a:ident),+]) => {{
        let mut start: $elem = 0.0;
        // Opaque start values: the compiler can neither merge chains nor fold the rounds.
        $(
            start += 1.0;
            let mut $m = black_box($splat(start));
            start += 1.0;
            let mut $a = black_box($splat(start));
        )+
        let (factor, step) = ($splat(black_box(0.999_999_9)), $splat(black_box(1e-7)));
        for _ in 0..$rounds {
            $(
                $m = $mul($m, factor);
                $a = $add($a, step);
            )+
        }
        let chains: u64 = 0 $(+ { let _ = stringify!($m); 2 })+;
        ($rounds * chains * $lanes, 0.0 $(+ $sum(&$m) + $sum(&$a))+)
    }};
}

// The targets of the lane kernel's copies (`src/core/lanes/mod.rs`). A 16-lane quantity takes one 512-bit
// register in single precision and two in double: 12 chains of 16 lanes, then 24 of 8 (32 registers). With
// AVX2, 8 lanes: 12 chains of 8, then 12 of 4 (16 registers).
#[multiversion(targets(
    "x86_64+avx512f+avx512vl+avx512bw+avx512dq+avx512cd+avx512ifma+avx512vbmi+avx512vbmi2+avx512vnni+avx512bitalg+avx512vpopcntdq+gfni+vaes+vpclmulqdq"
))]
fn f32x16(rounds: u64) -> (u64, f64) {
    // Arrays rather than the 512-bit intrinsics (stable only after the crate's minimum Rust version); the
    // vectoriser compiles these to one register per chain.
    chains!(
        rounds,
        f32,
        16,
        |x| [x; 16],
        lanewise::<f32, 16>(|a, b| a * b),
        lanewise::<f32, 16>(|a, b| a + b),
        |v: &[f32; 16]| v.iter().map(|&x| f64::from(x)).sum::<f64>(),
        [m0 a0, m1 a1, m2 a2, m3 a3, m4 a4, m5 a5]
    )
}

#[multiversion(targets(
    "x86_64+avx512f+avx512vl+avx512bw+avx512dq+avx512cd+avx512ifma+avx512vbmi+avx512vbmi2+avx512vnni+avx512bitalg+avx512vpopcntdq+gfni+vaes+vpclmulqdq"
))]
fn f64x16(rounds: u64) -> (u64, f64) {
    chains!(
        rounds,
        f64,
        16,
        |x| [x; 16],
        lanewise::<f64, 16>(|a, b| a * b),
        lanewise::<f64, 16>(|a, b| a + b),
        |v: &[f64; 16]| v.iter().sum::<f64>(),
        [m0 a0, m1 a1, m2 a2, m3 a3, m4 a4, m5 a5]
    )
}

/// `op` lane by lane.
#[inline(always)]
fn lanewise<T: Copy, const L: usize>(op: impl Fn(T, T) -> T) -> impl Fn([T; L], [T; L]) -> [T; L] {
    move |mut a, b| {
        for (a, b) in a.iter_mut().zip(b) {
            *a = op(*a, b);
        }
        a
    }
}

/// The lanes of an AVX2 register summed (only to keep every chain's result alive), for code that has
/// `std::arch::x86_64::*` in scope and AVX2 enabled.
#[cfg(target_arch = "x86_64")]
macro_rules! sum_ps {
    () => {
        |v: &__m256| {
            let halves = _mm_add_ps(_mm256_castps256_ps128(*v), _mm256_extractf128_ps::<1>(*v));
            let pairs = _mm_hadd_ps(halves, halves);
            f64::from(_mm_cvtss_f32(_mm_hadd_ps(pairs, pairs)))
        }
    };
}

#[cfg(target_arch = "x86_64")]
macro_rules! sum_pd {
    () => {
        |v: &__m256d| {
            let halves = _mm_add_pd(_mm256_castpd256_pd128(*v), _mm256_extractf128_pd::<1>(*v));
            _mm_cvtsd_f64(_mm_hadd_pd(halves, halves))
        }
    };
}

#[multiversion(targets("x86_64+avx2"))]
fn f32x8(rounds: u64) -> (u64, f64) {
    match_target! {
        "x86_64+avx2" => {
            use std::arch::x86_64::*;
            chains!(rounds, f32, 8, _mm256_set1_ps, _mm256_mul_ps, _mm256_add_ps, sum_ps!(), [m0 a0, m1 a1, m2 a2, m3 a3, m4 a4, m5 a5])
        }
        // The portable kernel (SSE2, NEON): arrays, few enough chains for 16 128-bit registers.
        _ => chains!(
            rounds,
            f32,
            8,
            |x| [x; 8],
            lanewise::<f32, 8>(|a, b| a * b),
            lanewise::<f32, 8>(|a, b| a + b),
            |v: &[f32; 8]| v.iter().map(|&x| f64::from(x)).sum::<f64>(),
            [m0 a0, m1 a1, m2 a2]
        ),
    }
}

#[multiversion(targets("x86_64+avx2"))]
fn f64x8(rounds: u64) -> (u64, f64) {
    match_target! {
        "x86_64+avx2" => {
            use std::arch::x86_64::*;
            chains!(rounds, f64, 4, _mm256_set1_pd, _mm256_mul_pd, _mm256_add_pd, sum_pd!(), [m0 a0, m1 a1, m2 a2, m3 a3, m4 a4, m5 a5])
        }
        _ => chains!(
            rounds,
            f64,
            8,
            |x| [x; 8],
            lanewise::<f64, 8>(|a, b| a * b),
            lanewise::<f64, 8>(|a, b| a + b),
            |v: &[f64; 8]| v.iter().sum::<f64>(),
            [m0 a0]
        ),
    }
}

/// The scalar solver's code is compiled for the baseline instruction set.
#[inline(never)]
fn f32x1(rounds: u64) -> (u64, f64) {
    chains!(
        rounds,
        f32,
        1,
        |x: f32| x,
        |a: f32, b: f32| a * b,
        |a: f32, b: f32| a + b,
        |&v: &f32| f64::from(v),
        [m0 a0, m1 a1, m2 a2, m3 a3, m4 a4, m5 a5]
    )
}

/// Independent accumulators, one per name in the list, each replaced every round by `$op(accumulator, factor)`
/// (a division by a factor near 1, or a square root, which keeps the values near 1: no special values). As
/// [`chains!`] (and named locals for its reason), evaluates to the lane operations run and a value that depends
/// on every one of them.
macro_rules! divider_chains {
    ($rounds:expr, $elem:ty, $lanes:literal, $splat:expr, $op:expr, $sum:expr, [$($a:ident)+]) => {{
        let mut start: $elem = 0.0;
        $(
            start += 1.0;
            let mut $a = black_box($splat(start));
        )+
        let factor = $splat(black_box(0.999_999_9));
        for _ in 0..$rounds {
            $(
                $a = $op($a, factor);
            )+
        }
        let chains: u64 = 0 $(+ { let _ = stringify!($a); 1 })+;
        ($rounds * chains * $lanes, 0.0 $(+ $sum(&$a))+)
    }};
}

/// A division, and a square root (ignoring its second argument), lane by lane.
#[inline(always)]
fn lane_division<T: Copy + std::ops::Div<Output = T>, const L: usize>(mut a: [T; L], b: [T; L]) -> [T; L] {
    for (a, b) in a.iter_mut().zip(b) {
        *a = *a / b;
    }
    a
}

macro_rules! lane_root {
    ($elem:ty, $lanes:literal) => {
        |mut a: [$elem; $lanes], _: [$elem; $lanes]| -> [$elem; $lanes] {
            for a in &mut a {
                *a = a.sqrt();
            }
            a
        }
    };
}

/// A division or square root probe for the 16-lane (AVX-512) kernel: arrays, as [`f32x16`].
macro_rules! divider16 {
    ($name:ident, $elem:ty, $op:expr) => {
        #[multiversion(targets(
            "x86_64+avx512f+avx512vl+avx512bw+avx512dq+avx512cd+avx512ifma+avx512vbmi+avx512vbmi2+avx512vnni+avx512bitalg+avx512vpopcntdq+gfni+vaes+vpclmulqdq"
        ))]
        fn $name(rounds: u64) -> (u64, f64) {
            divider_chains!(
                rounds,
                $elem,
                16,
                |x| [x; 16],
                $op,
                |v: &[$elem; 16]| v.iter().map(|&x| x as f64).sum::<f64>(),
                [d0 d1 d2 d3 d4 d5 d6 d7 d8 d9 d10 d11]
            )
        }
    };
}

divider16!(div_f32x16, f32, lane_division::<f32, 16>);
divider16!(sqrt_f32x16, f32, lane_root!(f32, 16));
divider16!(div_f64x16, f64, lane_division::<f64, 16>);
divider16!(sqrt_f64x16, f64, lane_root!(f64, 16));

/// A division or square root probe for the 8-lane kernel: AVX2 intrinsics where the CPU has them (`$lanes` per
/// register, 12 chains), arrays of 8 in the portable copy (the `$portable_chains` named), as [`f32x8`] and
/// [`f64x8`]. `$avx2` and `$sum` may name `std::arch::x86_64` items.
macro_rules! divider8 {
    ($name:ident, $elem:ty, $lanes:literal, $splat:expr, $avx2:expr, $sum:expr, [$($portable_chains:ident)+], $portable:expr) => {
        #[multiversion(targets("x86_64+avx2"))]
        fn $name(rounds: u64) -> (u64, f64) {
            match_target! {
                "x86_64+avx2" => {
                    use std::arch::x86_64::*;
                    divider_chains!(rounds, $elem, $lanes, $splat, $avx2, $sum, [d0 d1 d2 d3 d4 d5 d6 d7 d8 d9 d10 d11])
                }
                _ => divider_chains!(
                    rounds,
                    $elem,
                    8,
                    |x| [x; 8],
                    $portable,
                    |v: &[$elem; 8]| v.iter().map(|&x| x as f64).sum::<f64>(),
                    [$($portable_chains)+]
                ),
            }
        }
    };
}

divider8!(div_f32x8, f32, 8, _mm256_set1_ps, _mm256_div_ps, sum_ps!(), [p0 p1 p2 p3 p4 p5], lane_division::<f32, 8>);
divider8!(sqrt_f32x8, f32, 8, _mm256_set1_ps, |a, _| _mm256_sqrt_ps(a), sum_ps!(), [p0 p1 p2 p3 p4 p5], lane_root!(f32, 8));
divider8!(div_f64x8, f64, 4, _mm256_set1_pd, _mm256_div_pd, sum_pd!(), [p0 p1], lane_division::<f64, 8>);
divider8!(sqrt_f64x8, f64, 4, _mm256_set1_pd, |a, _| _mm256_sqrt_pd(a), sum_pd!(), [p0 p1], lane_root!(f64, 8));

/// The scalar solver's code is compiled for the baseline instruction set.
#[inline(never)]
fn div_f32x1(rounds: u64) -> (u64, f64) {
    divider_chains!(rounds, f32, 1, |x: f32| x, |a: f32, b: f32| a / b, |&v: &f32| f64::from(v), [d0 d1 d2 d3 d4 d5 d6 d7 d8 d9 d10 d11])
}

#[inline(never)]
fn sqrt_f32x1(rounds: u64) -> (u64, f64) {
    divider_chains!(rounds, f32, 1, |x: f32| x, |a: f32, _: f32| a.sqrt(), |&v: &f32| f64::from(v), [d0 d1 d2 d3 d4 d5 d6 d7 d8 d9 d10 d11])
}

#[inline(never)]
fn div_f64x1(rounds: u64) -> (u64, f64) {
    divider_chains!(rounds, f64, 1, |x: f64| x, |a: f64, b: f64| a / b, |&v: &f64| v, [d0 d1 d2 d3 d4 d5 d6 d7 d8 d9 d10 d11])
}

#[inline(never)]
fn sqrt_f64x1(rounds: u64) -> (u64, f64) {
    divider_chains!(rounds, f64, 1, |x: f64| x, |a: f64, _: f64| a.sqrt(), |&v: &f64| v, [d0 d1 d2 d3 d4 d5 d6 d7 d8 d9 d10 d11])
}
