//! kodawari: a view-dependent elastic-rod engine for the secondary motion of character joint chains.
//!
//! The artist gives, for a few view directions, how a chain (hair strand, ear, tail) should look from
//! there; every step the engine blends those shapes by the current camera direction and uses the blend as
//! the rest shape of an elastic rod that is simulated as usual.
//!
//! - [`core`]: the engine in plain safe Rust.
//! - `ffi` (hidden): the C ABI in `include/kodawari.h`, the only place with `extern "C"`.
#![deny(unsafe_op_in_unsafe_fn)]
// Numerical kernels index several parallel arrays with one joint index; iterator zips would hide that.
#![allow(clippy::needless_range_loop)]

pub mod core;
/// The C ABI. Public only so Rust tests and fuzzers can drive the exact functions C hosts call; not a Rust
/// API (use [`core`]).
#[doc(hidden)]
pub mod ffi;

pub use crate::core::*;
