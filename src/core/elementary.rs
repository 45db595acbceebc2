//! The elementary functions the core calls itself (glam calls its own, routed the same way by its `libm`
//! feature, see `Cargo.toml`).
//!
//! By default they are the standard library's, which calls the C library's `expf`, `powf` and so on. Those
//! round differently from one C library, CPU or architecture to another: glibc 2.36's aarch64 `expm1f` and
//! `atan2f` are compiled with fused multiply-adds (12 and 2 of them) where its x86-64 ones have none, so the two
//! give other bits on some inputs (`examples/elementary_bits.rs`), and that split `scene_cost 20 100x16 lod2`
//! across the architectures (`docs/performance-history.md`, stop 47). With `portable-determinism` they are the
//! `libm` crate's instead: plain Rust that rustc compiles without fusing or reordering anything, so the same bits
//! on every target.

#[cfg(not(feature = "portable-determinism"))]
mod chosen {
    #[inline]
    pub fn exp(x: f32) -> f32 {
        x.exp()
    }

    #[inline]
    pub fn exp_m1(x: f32) -> f32 {
        x.exp_m1()
    }

    #[inline]
    pub fn ln(x: f32) -> f32 {
        x.ln()
    }

    #[inline]
    pub fn powf(x: f32, y: f32) -> f32 {
        x.powf(y)
    }

    #[inline]
    pub fn atan2(y: f32, x: f32) -> f32 {
        y.atan2(x)
    }

    #[inline]
    pub fn tan_f64(x: f64) -> f64 {
        x.tan()
    }
}

#[cfg(feature = "portable-determinism")]
mod chosen {
    pub use libm::{atan2f as atan2, expf as exp, expm1f as exp_m1, logf as ln, powf, tan as tan_f64};
}

pub use chosen::*;

#[cfg(test)]
mod tests {
    use super::*;

    /// Either choice computes the functions it names (to well within a float's rounding on these inputs).
    #[test]
    fn computes_the_named_functions() {
        let close = |a: f32, b: f64| assert!((a as f64 - b).abs() <= 2.0 * f32::EPSILON as f64 * b.abs(), "{a} {b}");
        close(exp(-0.375), (-0.375f64).exp());
        close(exp_m1(-1e-3), (-1e-3f64).exp_m1());
        close(ln(0.625), 0.625f64.ln());
        close(powf(0.8125, 2.5), 0.8125f64.powf(2.5));
        close(atan2(0.25, -0.75), 0.25f64.atan2(-0.75));
        assert!((tan_f64(0.5) - 0.5f64.tan()).abs() <= f64::EPSILON * 0.5f64.tan());
    }

    /// `portable-determinism` holds only if the crate's own code calls no elementary function of the standard
    /// library but through this module: none in `src/` outside it and outside test modules.
    #[test]
    fn the_crate_calls_them_only_here() {
        const STANDARD: [&str; 22] = [
            ".exp(",
            ".exp2(",
            ".exp_m1(",
            ".ln(",
            ".ln_1p(",
            ".log(",
            ".log2(",
            ".log10(",
            ".powf(",
            ".cbrt(",
            ".hypot(",
            ".sin(",
            ".cos(",
            ".tan(",
            ".sin_cos(",
            ".asin(",
            ".acos(",
            ".atan(",
            ".atan2(",
            ".sinh(",
            ".cosh(",
            ".tanh(",
        ];
        let mut files = vec![std::path::PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/src"))];
        let mut found = Vec::new();
        let mut scanned = 0;
        while let Some(path) = files.pop() {
            if path.is_dir() {
                files.extend(std::fs::read_dir(&path).unwrap().map(|entry| entry.unwrap().path()));
                continue;
            }
            if path.extension().is_none_or(|e| e != "rs") || path.ends_with("core/elementary.rs") {
                continue;
            }
            scanned += 1;
            let text = std::fs::read_to_string(&path).unwrap();
            // Up to the test module, which ends every file that has one (test-only items before it are
            // scanned too).
            let code = text.split("#[cfg(test)]\nmod tests").next().unwrap();
            for (number, line) in code.lines().enumerate() {
                let line = line.split("//").next().unwrap();
                if STANDARD.iter().any(|call| line.contains(call)) {
                    found.push(format!("{}:{}: {}", path.display(), number + 1, line.trim()));
                }
            }
        }
        assert!(scanned > 40, "{scanned} source files");
        assert!(found.is_empty(), "call these through core::elementary:\n{}", found.join("\n"));
    }
}
