//! The C ABI: the only module with `extern "C"`, raw pointers and `catch_unwind`.
//!
//! - [`types`]: plain C structs (vectors, transforms, ids) and their conversions to core types
//! - [`status`]: `kdw_status`, its strings, the thread-local error message
//! - [`guard`]: the panic guard and the pointer checks every exported body goes through
//! - one module per C concept: [`engine`], [`batch`], [`chain`], [`collider`], [`view_shape`], [`version`]

#![allow(non_camel_case_types)]
// C names, exactly as in the header.
// Entry points are safe `extern "C"` functions, as in rustls-ffi: they check what can be checked (NULL,
// alignment, ids, values) and the validity of non-NULL pointers is the C caller's contract, stated in the
// header. Rust code reaches them only from tests.
#![allow(clippy::not_unsafe_ptr_arg_deref)]

pub mod batch;
pub mod chain;
pub mod collider;
pub mod engine;
pub mod guard;
pub mod sketch;
pub mod status;
pub mod types;
pub mod version;
pub mod view_shape;
