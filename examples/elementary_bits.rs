//! Why `portable-determinism` takes its elementary functions from the `libm` crate: on the same inputs, how often
//! the C library's `expf`, `expm1f`, `logf`, `powf`, `atan2f` and `tan` give other bits than the crate's, a hash
//! of the C library's results, and how often each misses the float nearest the exact value and by how much at
//! worst, in ulps (against the double precision result; not for `tan`, itself double). Run it on two targets: where the hashes differ, so
//! do those targets' C libraries (with glibc 2.36, x86-64 and aarch64 differ on `expm1f` and `atan2f`).
//!
//!   cargo run --release --example elementary_bits --features portable-determinism [SAMPLES]
//!
//! and for aarch64 with `--target aarch64-unknown-linux-gnu`, the linker and runner of `tools/test_aarch64.sh`.

fn main() {
    let samples: u32 = std::env::args().nth(1).and_then(|s| s.parse().ok()).unwrap_or(4_000_000);
    // xorshift64: the same inputs on every target, uniform in [0, 1) with 24 bits.
    let mut state = 0x9E37_79B9_7F4A_7C15u64;
    let mut uniform = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 40) as f32 / (1u64 << 24) as f32
    };
    let names = ["expf", "expm1f", "logf", "powf", "atan2f", "tan"];
    let mut differ = [0u32; 6];
    let mut hash = [0u64; 6];
    let mut not_nearest = [[0u32; 2]; 6];
    let mut worst_ulps = [[0f64; 2]; 6];
    for _ in 0..samples {
        let (a, b) = (uniform(), uniform());
        let (x, y, z) = (-a * 0.5, -a * 2.0, a + 1e-3);
        let (p, t) = (b * 8.0, b - 0.5);
        let angle = a as f64 * 1.5;
        // (C library's, libm crate's, exact), over the ranges the engine uses them on.
        let single: [(f32, f32, f64); 5] = [
            (x.exp(), libm::expf(x), f64::from(x).exp()),
            (y.exp_m1(), libm::expm1f(y), f64::from(y).exp_m1()),
            (z.ln(), libm::logf(z), f64::from(z).ln()),
            (a.powf(p), libm::powf(a, p), f64::from(a).powf(f64::from(p))),
            (a.atan2(t), libm::atan2f(a, t), f64::from(a).atan2(f64::from(t))),
        ];
        for (k, (c_library, crate_libm, exact)) in single.into_iter().enumerate() {
            differ[k] += u32::from(c_library.to_bits() != crate_libm.to_bits());
            hash[k] = hash[k].wrapping_mul(31).wrapping_add(c_library.to_bits().into());
            let nearest = exact as f32;
            // The spacing of floats at the result; exact zeros (none on these inputs) are skipped.
            let ulp = f64::from(f32::from_bits(nearest.abs().to_bits() + 1) - nearest.abs());
            for (side, result) in [c_library, crate_libm].into_iter().enumerate() {
                not_nearest[k][side] += u32::from(result.to_bits() != nearest.to_bits());
                if exact != 0.0 {
                    worst_ulps[k][side] = worst_ulps[k][side].max((f64::from(result) - exact).abs() / ulp);
                }
            }
        }
        differ[5] += u32::from(angle.tan().to_bits() != libm::tan(angle).to_bits());
        hash[5] = hash[5].wrapping_mul(31).wrapping_add(angle.tan().to_bits());
    }
    println!(
        "of {samples} inputs: differ, hash of the C library's results; not the nearest float, worst error in ulps (C library, libm crate)"
    );
    for k in 0..names.len() {
        let [c_library, crate_libm] = not_nearest[k];
        let [c_worst, crate_worst] = worst_ulps[k];
        let nearest =
            if k == 5 { "-".to_string() } else { format!("{c_library} {crate_libm}, {c_worst:.3} {crate_worst:.3}") };
        println!("{:7} {:7} {:016x}; {nearest}", names[k], differ[k], hash[k]);
    }
}
