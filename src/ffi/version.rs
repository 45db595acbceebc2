//! Version queries. The shims compare `kdw_abi_version()` with the `KDW_ABI_VERSION` they were built
//! against and refuse to run on a mismatch.

use std::ffi::c_char;

/// Bumped on every incompatible change of the C ABI (signatures, struct layouts, semantics).
pub const KDW_ABI_VERSION: u32 = 2;

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
