//! Version queries. The shims compare `kdw_abi_version()` with the `KDW_ABI_VERSION` they were built
//! against and refuse to run on a mismatch.

use std::ffi::{CString, c_char};
use std::sync::OnceLock;

/// Bumped on every incompatible change of the C ABI (signatures, struct layouts, semantics). 3: solver
/// selection, `kdw_engine_stats.lane_chains`.
pub const KDW_ABI_VERSION: u32 = 3;

/// The ABI version of the loaded library.
#[unsafe(no_mangle)]
pub extern "C" fn kdw_abi_version() -> u32 {
    KDW_ABI_VERSION
}

/// The library's version, e.g. "0.1.0": static, NUL-terminated, never NULL.
#[unsafe(no_mangle)]
pub extern "C" fn kdw_version_string() -> *const c_char {
    concat!(env!("CARGO_PKG_VERSION"), "\0").as_ptr().cast()
}

/// The instruction set `KDW_SOLVER_LANES` runs its kernel with on this CPU: "avx512" (groups of 16 chains in
/// 512-bit registers, smaller groups with AVX2), "avx2", "sse2" (the portable x86-64 kernel), "neon" (aarch64)
/// or "scalar" (no SIMD kernel for this architecture).
/// `KDW_SOLVER_LANES_PORTABLE` always runs the portable kernel. Static, NUL-terminated, never NULL.
#[unsafe(no_mangle)]
pub extern "C" fn kdw_simd_path() -> *const c_char {
    static PATH: OnceLock<CString> = OnceLock::new();
    // The core's names contain no NUL, so the conversion cannot fail (the empty default is never used).
    PATH.get_or_init(|| CString::new(crate::core::simd_path()).unwrap_or_default()).as_ptr()
}

/// 1 if this library was built with the `portable-determinism` cargo feature, else 0. Builds with it compute the
/// same bits on x86-64 and aarch64, as their arithmetic calls no C library function (a replay recorded on one
/// plays back on the other, and lockstep peers stay in step); builds without it agree only with themselves on
/// one kind of machine. Hosts that rely on it check it on every peer, and compare `kdw_engine_state_hash`es to
/// detect a divergence.
#[unsafe(no_mangle)]
pub extern "C" fn kdw_portable_determinism() -> u32 {
    crate::core::portable_determinism() as u32
}
