//! Status codes, their static strings, and the thread-local message of the last failure.

use std::cell::RefCell;
use std::ffi::{CString, c_char};

use crate::core::{Error, ErrorKind};

/// Result of every fallible call: 0 is success, negative values are errors (`KDW_STATUS_*`). Kept a plain
/// integer so that an unknown value coming back from C is never undefined behaviour.
pub type kdw_status = i32;

pub const KDW_STATUS_OK: kdw_status = 0;
/// A required pointer was NULL or misaligned.
pub const KDW_STATUS_NULL_POINTER: kdw_status = -1;
/// An id is null, stale (its object was destroyed), of another kind, or from another engine.
pub const KDW_STATUS_INVALID_ID: kdw_status = -2;
/// A value is out of range: non-finite float, zero-length segment, fewer than 2 joints, wrong count, ...
pub const KDW_STATUS_INVALID_ARGUMENT: kdw_status = -3;
/// An output buffer is too small; nothing was written.
pub const KDW_STATUS_BUFFER_TOO_SMALL: kdw_status = -4;
/// The engine holds the maximum number of objects of that kind.
pub const KDW_STATUS_CAPACITY_EXCEEDED: kdw_status = -5;
/// `struct_size` of a def struct does not match this library.
pub const KDW_STATUS_STRUCT_SIZE_MISMATCH: kdw_status = -6;
/// The library's `kdw_abi_version()` differs from the `KDW_ABI_VERSION` a caller (or a binding) was
/// built against. Never returned by the library itself; the C++ and C# bindings report it.
pub const KDW_STATUS_ABI_MISMATCH: kdw_status = -7;
/// A bug inside the library was caught at the boundary. The engine involved refuses further calls
/// except `kdw_engine_destroy`.
pub const KDW_STATUS_PANIC: kdw_status = -100;

/// An error on its way out through the boundary.
#[derive(Debug)]
pub struct FfiError {
    pub status: kdw_status,
    pub message: String,
}

impl FfiError {
    pub fn new(status: kdw_status, message: impl Into<String>) -> Self {
        Self { status, message: message.into() }
    }
}

impl From<Error> for FfiError {
    fn from(e: Error) -> Self {
        let status = match e.kind {
            ErrorKind::InvalidId => KDW_STATUS_INVALID_ID,
            ErrorKind::InvalidArgument => KDW_STATUS_INVALID_ARGUMENT,
            ErrorKind::CapacityExceeded => KDW_STATUS_CAPACITY_EXCEEDED,
            ErrorKind::BufferTooSmall => KDW_STATUS_BUFFER_TOO_SMALL,
        };
        Self { status, message: e.message }
    }
}

pub type FfiResult<T> = Result<T, FfiError>;

thread_local! {
    static LAST_ERROR: RefCell<CString> = RefCell::new(CString::default());
}

pub(crate) fn set_last_error(message: &str) {
    // Interior NULs would truncate the C string silently; replace them visibly.
    let text = CString::new(message.replace('\0', "?")).unwrap_or_default();
    LAST_ERROR.with(|slot| *slot.borrow_mut() = text);
}

/// A static, NUL-terminated description of `status` ("unknown status" for values this library never
/// returns). Never NULL.
#[unsafe(no_mangle)]
pub extern "C" fn kdw_status_str(status: kdw_status) -> *const c_char {
    let text: &'static [u8] = match status {
        KDW_STATUS_OK => b"ok\0",
        KDW_STATUS_NULL_POINTER => b"null or misaligned pointer\0",
        KDW_STATUS_INVALID_ID => b"invalid id (null, stale, foreign or of another kind)\0",
        KDW_STATUS_INVALID_ARGUMENT => b"invalid argument\0",
        KDW_STATUS_BUFFER_TOO_SMALL => b"buffer too small\0",
        KDW_STATUS_CAPACITY_EXCEEDED => b"capacity exceeded\0",
        KDW_STATUS_STRUCT_SIZE_MISMATCH => b"struct_size does not match this library\0",
        KDW_STATUS_ABI_MISMATCH => b"the library's ABI version differs from the header's\0",
        KDW_STATUS_PANIC => b"internal error (panic caught at the boundary)\0",
        _ => b"unknown status\0",
    };
    text.as_ptr().cast()
}

/// Copies this thread's message about its last failed call into `buffer` (NUL-terminated) and its length
/// (without the NUL) into `*out_length` when not NULL. An empty string if no call has failed yet.
/// If `capacity` is too small the message is truncated to fit (still NUL-terminated) and
/// `KDW_STATUS_BUFFER_TOO_SMALL` is returned; `*out_length` still receives the full length. `buffer` may
/// be NULL when `capacity` is 0, to query the length.
#[unsafe(no_mangle)]
pub extern "C" fn kdw_last_error_message(buffer: *mut c_char, capacity: u32, out_length: *mut u32) -> kdw_status {
    let result = std::panic::catch_unwind(|| {
        LAST_ERROR.with(|slot| {
            let message = slot.borrow();
            let bytes = message.as_bytes();
            if capacity > 0 && buffer.is_null() {
                return KDW_STATUS_NULL_POINTER;
            }
            let fits = bytes.len() < capacity as usize;
            if capacity > 0 {
                let copied = bytes.len().min(capacity as usize - 1);
                // SAFETY: the caller guarantees `buffer` points to `capacity` writable bytes (checked
                // non-NULL above); we write `copied + 1 <= capacity` bytes.
                unsafe {
                    std::ptr::copy_nonoverlapping(bytes.as_ptr(), buffer.cast::<u8>(), copied);
                    *buffer.add(copied) = 0;
                }
            }
            if !out_length.is_null() {
                // SAFETY: non-NULL, and the caller guarantees it points to a writable uint32_t.
                unsafe { *out_length = bytes.len() as u32 };
            }
            if fits || capacity == 0 && buffer.is_null() { KDW_STATUS_OK } else { KDW_STATUS_BUFFER_TOO_SMALL }
        })
    });
    result.unwrap_or(KDW_STATUS_PANIC)
}
