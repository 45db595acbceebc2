//! Moving a quantity between the chains' arrays and a lane group's: a matrix transpose. A chain holds its
//! joints' values in a row (`[joint][component]`, `K` numbers), a group one row per number with a lane per chain
//! (`[joint][component][lane]`), so loading `L` chains turns an `L x K` matrix into its `K x L` transpose, and
//! storing them turns it back.
//!
//! Number by number (a load and a store each, at a scattered address on one side) this was dear: on an AMD
//! EPYC with AVX-512 (groups of 16), a build that ran that `LaneGroup::load` twice, the second time from the
//! cache, took 1.09x the time of `scene_cost 80 1000x16 lanes` (`tools/ab.sh --abba`). With AVX2 the transpose
//! runs in 8 x 8 blocks of single- and 4 x 4 blocks of double-precision numbers, whole registers loaded,
//! shuffled and stored; the portable copy, and the numbers after the last whole block, go number by number.
//! Moving numbers changes none of them: the same bits either way.

use multiversion::multiversion;
use multiversion::target::match_target;

/// `rows[k][lane] = sources[lane][k]` for every `k` of `rows` (each source holds at least `rows.len()` numbers).
#[multiversion(targets("x86_64+avx2"))]
pub(crate) fn gather_f32<const L: usize>(sources: &[&[f32]; L], rows: &mut [[f32; L]]) {
    let sources = sources.each_ref().map(|s| &s[..rows.len()]);
    let done = match_target! {
        "x86_64+avx2" => if L.is_multiple_of(8) { avx2::gather_f32(&sources, rows) } else { 0 },
        _ => 0,
    };
    gather_from(done, &sources, rows);
}

/// As [`gather_f32`], in double precision.
#[multiversion(targets("x86_64+avx2"))]
pub(crate) fn gather_f64<const L: usize>(sources: &[&[f64]; L], rows: &mut [[f64; L]]) {
    let sources = sources.each_ref().map(|s| &s[..rows.len()]);
    let done = match_target! {
        "x86_64+avx2" => if L.is_multiple_of(4) { avx2::gather_f64(&sources, rows) } else { 0 },
        _ => 0,
    };
    gather_from(done, &sources, rows);
}

/// The way back: `lanes[lane * rows.len() + k] = rows[k][lane]`, each lane's numbers in a row of `lanes`.
#[multiversion(targets("x86_64+avx2"))]
pub(crate) fn scatter_f32<const L: usize>(rows: &[[f32; L]], lanes: &mut [f32]) {
    let k_len = rows.len();
    let lanes = &mut lanes[..L * k_len];
    if k_len == 0 {
        return;
    }
    let done = match_target! {
        "x86_64+avx2" => if L.is_multiple_of(8) { avx2::scatter_f32(rows, lanes) } else { 0 },
        _ => 0,
    };
    scatter_from(done, rows, lanes);
}

/// As [`scatter_f32`], in double precision.
#[multiversion(targets("x86_64+avx2"))]
pub(crate) fn scatter_f64<const L: usize>(rows: &[[f64; L]], lanes: &mut [f64]) {
    let k_len = rows.len();
    let lanes = &mut lanes[..L * k_len];
    if k_len == 0 {
        return;
    }
    let done = match_target! {
        "x86_64+avx2" => if L.is_multiple_of(4) { avx2::scatter_f64(rows, lanes) } else { 0 },
        _ => 0,
    };
    scatter_from(done, rows, lanes);
}

/// The gather number by number, from row `done` on.
fn gather_from<T: Copy, const L: usize>(done: usize, sources: &[&[T]; L], rows: &mut [[T; L]]) {
    for (k, row) in rows.iter_mut().enumerate().skip(done) {
        for (value, source) in row.iter_mut().zip(sources) {
            *value = source[k];
        }
    }
}

/// The scatter number by number, from row `done` on (`lanes` holds a row of `rows.len()` numbers per lane).
fn scatter_from<T: Copy, const L: usize>(done: usize, rows: &[[T; L]], lanes: &mut [T]) {
    for (lane, out) in lanes.chunks_exact_mut(rows.len()).enumerate() {
        for (value, row) in out.iter_mut().zip(rows).skip(done) {
            *value = row[lane];
        }
    }
}

/// The blocks with AVX2 registers. Each function handles the whole blocks of `rows` (8 or 4 numbers of every
/// source at a time) and returns how many rows it did; the callers do the rest number by number. Registers are
/// filled from arrays and emptied into them with `bytemuck` (a plain copy the compiler turns into one load or
/// store), so no pointer is handled here.
#[cfg(target_arch = "x86_64")]
mod avx2 {
    use std::arch::x86_64::{
        __m256, __m256d, _mm256_permute2f128_pd, _mm256_permute2f128_ps, _mm256_shuffle_ps, _mm256_unpackhi_pd,
        _mm256_unpackhi_ps, _mm256_unpacklo_pd, _mm256_unpacklo_ps,
    };

    #[target_feature(enable = "avx2")]
    pub(super) fn gather_f32<const L: usize>(sources: &[&[f32]; L], rows: &mut [[f32; L]]) -> usize {
        let whole = rows.len() / 8 * 8;
        for (block, k) in rows[..whole].chunks_exact_mut(8).zip((0..whole).step_by(8)) {
            for lanes in (0..L).step_by(8) {
                let t = transpose8(std::array::from_fn(|i| load8(&sources[lanes + i][k..k + 8])));
                for (row, column) in block.iter_mut().zip(t) {
                    row[lanes..lanes + 8].copy_from_slice(&bytemuck::cast::<__m256, [f32; 8]>(column));
                }
            }
        }
        whole
    }

    #[target_feature(enable = "avx2")]
    pub(super) fn gather_f64<const L: usize>(sources: &[&[f64]; L], rows: &mut [[f64; L]]) -> usize {
        let whole = rows.len() / 4 * 4;
        for (block, k) in rows[..whole].chunks_exact_mut(4).zip((0..whole).step_by(4)) {
            for lanes in (0..L).step_by(4) {
                let t = transpose4(std::array::from_fn(|i| load4(&sources[lanes + i][k..k + 4])));
                for (row, column) in block.iter_mut().zip(t) {
                    row[lanes..lanes + 4].copy_from_slice(&bytemuck::cast::<__m256d, [f64; 4]>(column));
                }
            }
        }
        whole
    }

    #[target_feature(enable = "avx2")]
    pub(super) fn scatter_f32<const L: usize>(rows: &[[f32; L]], lanes: &mut [f32]) -> usize {
        let k_len = rows.len();
        let whole = k_len / 8 * 8;
        for (block, k) in rows[..whole].chunks_exact(8).zip((0..whole).step_by(8)) {
            for first in (0..L).step_by(8) {
                let t = transpose8(std::array::from_fn(|c| load8(&block[c][first..first + 8])));
                for (i, column) in t.into_iter().enumerate() {
                    let at = (first + i) * k_len + k;
                    lanes[at..at + 8].copy_from_slice(&bytemuck::cast::<__m256, [f32; 8]>(column));
                }
            }
        }
        whole
    }

    #[target_feature(enable = "avx2")]
    pub(super) fn scatter_f64<const L: usize>(rows: &[[f64; L]], lanes: &mut [f64]) -> usize {
        let k_len = rows.len();
        let whole = k_len / 4 * 4;
        for (block, k) in rows[..whole].chunks_exact(4).zip((0..whole).step_by(4)) {
            for first in (0..L).step_by(4) {
                let t = transpose4(std::array::from_fn(|c| load4(&block[c][first..first + 4])));
                for (i, column) in t.into_iter().enumerate() {
                    let at = (first + i) * k_len + k;
                    lanes[at..at + 4].copy_from_slice(&bytemuck::cast::<__m256d, [f64; 4]>(column));
                }
            }
        }
        whole
    }

    #[inline(always)]
    fn load8(values: &[f32]) -> __m256 {
        bytemuck::cast::<[f32; 8], __m256>(values.try_into().expect("8 numbers"))
    }

    #[inline(always)]
    fn load4(values: &[f64]) -> __m256d {
        bytemuck::cast::<[f64; 4], __m256d>(values.try_into().expect("4 numbers"))
    }

    /// The 8 x 8 transpose: register `i` of the result holds element `i` of every register given.
    #[target_feature(enable = "avx2")]
    fn transpose8(r: [__m256; 8]) -> [__m256; 8] {
        // Pairs of rows interleaved, then pairs of pairs, then the 128-bit halves exchanged.
        let t0 = _mm256_unpacklo_ps(r[0], r[1]);
        let t1 = _mm256_unpackhi_ps(r[0], r[1]);
        let t2 = _mm256_unpacklo_ps(r[2], r[3]);
        let t3 = _mm256_unpackhi_ps(r[2], r[3]);
        let t4 = _mm256_unpacklo_ps(r[4], r[5]);
        let t5 = _mm256_unpackhi_ps(r[4], r[5]);
        let t6 = _mm256_unpacklo_ps(r[6], r[7]);
        let t7 = _mm256_unpackhi_ps(r[6], r[7]);
        let s0 = _mm256_shuffle_ps::<0x44>(t0, t2);
        let s1 = _mm256_shuffle_ps::<0xEE>(t0, t2);
        let s2 = _mm256_shuffle_ps::<0x44>(t1, t3);
        let s3 = _mm256_shuffle_ps::<0xEE>(t1, t3);
        let s4 = _mm256_shuffle_ps::<0x44>(t4, t6);
        let s5 = _mm256_shuffle_ps::<0xEE>(t4, t6);
        let s6 = _mm256_shuffle_ps::<0x44>(t5, t7);
        let s7 = _mm256_shuffle_ps::<0xEE>(t5, t7);
        [
            _mm256_permute2f128_ps::<0x20>(s0, s4),
            _mm256_permute2f128_ps::<0x20>(s1, s5),
            _mm256_permute2f128_ps::<0x20>(s2, s6),
            _mm256_permute2f128_ps::<0x20>(s3, s7),
            _mm256_permute2f128_ps::<0x31>(s0, s4),
            _mm256_permute2f128_ps::<0x31>(s1, s5),
            _mm256_permute2f128_ps::<0x31>(s2, s6),
            _mm256_permute2f128_ps::<0x31>(s3, s7),
        ]
    }

    /// The 4 x 4 transpose of double-precision registers.
    #[target_feature(enable = "avx2")]
    fn transpose4(r: [__m256d; 4]) -> [__m256d; 4] {
        let t0 = _mm256_unpacklo_pd(r[0], r[1]);
        let t1 = _mm256_unpackhi_pd(r[0], r[1]);
        let t2 = _mm256_unpacklo_pd(r[2], r[3]);
        let t3 = _mm256_unpackhi_pd(r[2], r[3]);
        [
            _mm256_permute2f128_pd::<0x20>(t0, t2),
            _mm256_permute2f128_pd::<0x20>(t1, t3),
            _mm256_permute2f128_pd::<0x31>(t0, t2),
            _mm256_permute2f128_pd::<0x31>(t1, t3),
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Distinct numbers: lane `l`, number `k`.
    fn source(lane: usize, k_len: usize) -> Vec<f32> {
        (0..k_len).map(|k| (lane * 1000 + k) as f32).collect()
    }

    fn round_trip<const L: usize>(k_len: usize) {
        let sources: Vec<Vec<f32>> = (0..L).map(|lane| source(lane, k_len + 3)).collect();
        let refs: [&[f32]; L] = std::array::from_fn(|lane| &sources[lane][..]);
        let mut rows = vec![[f32::NAN; L]; k_len];
        gather_f32(&refs, &mut rows);
        for (k, row) in rows.iter().enumerate() {
            for (lane, &value) in row.iter().enumerate() {
                assert_eq!(value, (lane * 1000 + k) as f32, "gather L {L} K {k_len}: row {k} lane {lane}");
            }
        }
        let mut lanes = vec![f32::NAN; L * k_len + 5];
        scatter_f32(&rows, &mut lanes);
        for lane in 0..L {
            assert_eq!(lanes[lane * k_len..(lane + 1) * k_len], sources[lane][..k_len], "scatter L {L} K {k_len}");
        }
        assert!(lanes[L * k_len..].iter().all(|v| v.is_nan()), "scatter wrote past its rows");

        let sources64: Vec<Vec<f64>> = sources.iter().map(|s| s.iter().map(|&v| v as f64 + 0.5).collect()).collect();
        let refs64: [&[f64]; L] = std::array::from_fn(|lane| &sources64[lane][..]);
        let mut rows64 = vec![[f64::NAN; L]; k_len];
        gather_f64(&refs64, &mut rows64);
        for (k, row) in rows64.iter().enumerate() {
            for (lane, &value) in row.iter().enumerate() {
                assert_eq!(value, (lane * 1000 + k) as f64 + 0.5, "gather_f64 L {L} K {k_len}");
            }
        }
        let mut lanes64 = vec![f64::NAN; L * k_len];
        scatter_f64(&rows64, &mut lanes64);
        for lane in 0..L {
            assert_eq!(lanes64[lane * k_len..(lane + 1) * k_len], sources64[lane][..k_len], "scatter_f64 L {L}");
        }
    }

    #[test]
    fn transposes_every_width_and_length() {
        // Whole blocks, a partial block after them, and fewer numbers than a block.
        for k_len in [0, 1, 3, 4, 7, 8, 9, 15, 16, 24, 45, 48, 64, 143] {
            round_trip::<4>(k_len);
            round_trip::<8>(k_len);
            round_trip::<16>(k_len);
        }
    }

    #[test]
    fn keeps_every_bit() {
        // Negative zero, infinities, a NaN payload and subnormals come through unchanged.
        let special = [-0.0f32, f32::INFINITY, f32::from_bits(0x7fc0_1234), f32::MIN_POSITIVE / 4.0, -1e-40];
        let sources: Vec<Vec<f32>> =
            (0..8).map(|lane| (0..16).map(|k| special[(lane + k) % special.len()]).collect()).collect();
        let refs: [&[f32]; 8] = std::array::from_fn(|lane| &sources[lane][..]);
        let mut rows = vec![[0.0f32; 8]; 16];
        gather_f32(&refs, &mut rows);
        for (k, row) in rows.iter().enumerate() {
            for (lane, value) in row.iter().enumerate() {
                assert_eq!(value.to_bits(), sources[lane][k].to_bits());
            }
        }
    }
}
