//! The boundary discipline in one place: the panic guard every exported body runs in, the pointer checks,
//! and the one cast between `kdw_engine*` and the real engine.

use std::panic::{AssertUnwindSafe, catch_unwind};

use super::engine::kdw_engine;
use super::status::{
    FfiError, FfiResult, KDW_STATUS_NULL_POINTER, KDW_STATUS_OK, KDW_STATUS_PANIC, kdw_status, set_last_error,
};
use crate::core::Engine;

/// Runs an exported function's body: maps its error to a status and records the message; a panic becomes
/// `KDW_STATUS_PANIC` instead of unwinding into C.
pub(crate) fn guard(body: impl FnOnce() -> FfiResult<()>) -> kdw_status {
    match catch_unwind(AssertUnwindSafe(body)) {
        Ok(Ok(())) => KDW_STATUS_OK,
        Ok(Err(error)) => {
            set_last_error(&error.message);
            error.status
        }
        Err(payload) => {
            set_last_error(&panic_message(payload.as_ref()));
            KDW_STATUS_PANIC
        }
    }
}

fn panic_message(payload: &(dyn std::any::Any + Send)) -> String {
    let detail = payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown panic".into());
    format!("internal error: {detail}")
}

fn check_pointer<T>(ptr: *const T, what: &str) -> FfiResult<()> {
    if ptr.is_null() {
        return Err(FfiError::new(KDW_STATUS_NULL_POINTER, format!("{what} is NULL")));
    }
    if !ptr.is_aligned() {
        return Err(FfiError::new(KDW_STATUS_NULL_POINTER, format!("{what} is misaligned")));
    }
    Ok(())
}

/// Checks an out-pointer up front, so that nothing is computed (or changed) for a call that cannot
/// deliver its result.
pub(crate) fn check_out<T>(ptr: *mut T, what: &str) -> FfiResult<()> {
    check_pointer(ptr.cast_const(), what)
}

/// # Safety
/// `ptr`, if non-NULL and aligned, must point to a valid `T` for `'a`.
pub(crate) unsafe fn read<'a, T>(ptr: *const T, what: &str) -> FfiResult<&'a T> {
    check_pointer(ptr, what)?;
    // SAFETY: non-NULL and aligned (checked); validity is the caller's contract.
    Ok(unsafe { &*ptr })
}

/// # Safety
/// `ptr`, if non-NULL and aligned, must point to `len` valid `T`s for `'a`.
pub(crate) unsafe fn slice<'a, T>(ptr: *const T, len: u32, what: &str) -> FfiResult<&'a [T]> {
    if len == 0 {
        return Ok(&[]);
    }
    check_pointer(ptr, what)?;
    // SAFETY: non-NULL, aligned, and the caller guarantees `len` readable elements.
    Ok(unsafe { std::slice::from_raw_parts(ptr, len as usize) })
}

/// # Safety
/// `ptr`, if non-NULL and aligned, must point to `len` writable `T`s for `'a`, not aliased elsewhere.
pub(crate) unsafe fn slice_mut<'a, T>(ptr: *mut T, len: u32, what: &str) -> FfiResult<&'a mut [T]> {
    if len == 0 {
        return Ok(&mut []);
    }
    check_pointer(ptr.cast_const(), what)?;
    // SAFETY: non-NULL, aligned, and the caller guarantees `len` writable, unaliased elements.
    Ok(unsafe { std::slice::from_raw_parts_mut(ptr, len as usize) })
}

/// # Safety
/// `ptr` must have passed [`check_out`] and point to a writable `T`.
pub(crate) unsafe fn write<T>(ptr: *mut T, value: T) {
    // SAFETY: checked non-NULL and aligned by `check_out`; writability is the caller's contract.
    unsafe { ptr.write(value) }
}

/// What a `kdw_engine*` really points to.
pub(crate) struct EngineBox {
    pub engine: Engine,
    /// Set when a panic unwound out of a mutating call: the state may be half-updated, so the engine
    /// refuses further work (destroying it is still allowed).
    pub poisoned: bool,
}

fn poisoned_error() -> FfiError {
    FfiError::new(KDW_STATUS_PANIC, "the engine was poisoned by an earlier internal error; destroy it")
}

pub(crate) fn into_handle(engine: Engine) -> *mut kdw_engine {
    Box::into_raw(Box::new(EngineBox { engine, poisoned: false })).cast()
}

/// # Safety
/// `handle` must be NULL or a pointer from [`into_handle`] not yet destroyed.
pub(crate) unsafe fn destroy_handle(handle: *mut kdw_engine) -> FfiResult<()> {
    check_pointer(handle.cast_const().cast::<EngineBox>(), "engine")?;
    // SAFETY: created by `into_handle` (Box::into_raw of an EngineBox) and not destroyed yet.
    drop(unsafe { Box::from_raw(handle.cast::<EngineBox>()) });
    Ok(())
}

/// Runs `f` on the engine behind `handle` for reading.
///
/// # Safety
/// `handle` must be NULL or a live pointer from [`into_handle`], not used by another thread meanwhile.
pub(crate) unsafe fn with_engine<R>(
    handle: *const kdw_engine,
    f: impl FnOnce(&Engine) -> FfiResult<R>,
) -> FfiResult<R> {
    check_pointer(handle.cast::<EngineBox>(), "engine")?;
    // SAFETY: a live EngineBox per the contract; shared access only.
    let boxed = unsafe { &*handle.cast::<EngineBox>() };
    if boxed.poisoned {
        return Err(poisoned_error());
    }
    f(&boxed.engine)
}

/// Runs `f` on the engine behind `handle` for writing; a panic inside poisons the engine.
///
/// # Safety
/// As [`with_engine`], and no other reference to the engine may exist during the call.
pub(crate) unsafe fn with_engine_mut<R>(
    handle: *mut kdw_engine,
    f: impl FnOnce(&mut Engine) -> FfiResult<R>,
) -> FfiResult<R> {
    check_pointer(handle.cast_const().cast::<EngineBox>(), "engine")?;
    // SAFETY: a live EngineBox per the contract; exclusive for the duration of the call.
    let boxed = unsafe { &mut *handle.cast::<EngineBox>() };
    if boxed.poisoned {
        return Err(poisoned_error());
    }
    match catch_unwind(AssertUnwindSafe(|| f(&mut boxed.engine))) {
        Ok(result) => result,
        Err(payload) => {
            boxed.poisoned = true;
            Err(FfiError::new(KDW_STATUS_PANIC, panic_message(payload.as_ref())))
        }
    }
}

/// A `struct_size` check for def structs coming in.
pub(crate) fn check_struct_size<T>(struct_size: u32, name: &str) -> FfiResult<()> {
    let expected = size_of::<T>() as u32;
    if struct_size != expected {
        return Err(FfiError::new(
            super::status::KDW_STATUS_STRUCT_SIZE_MISMATCH,
            format!(
                "{name}.struct_size is {struct_size}, this library expects {expected}: initialise it with {name}_default()"
            ),
        ));
    }
    Ok(())
}

/// The shape of every read-only query: check the out-pointer, run `f` on the engine, write its result
/// only on success.
pub(crate) fn query<T>(
    engine: *const kdw_engine,
    out: *mut T,
    what: &str,
    f: impl FnOnce(&Engine) -> FfiResult<T>,
) -> kdw_status {
    guard(|| {
        check_out(out, what)?;
        // SAFETY: `engine` is a live engine handle (caller contract, NULL checked inside).
        let value = unsafe { with_engine(engine, f) }?;
        // SAFETY: checked by check_out; writability is the caller's contract.
        unsafe { write(out, value) };
        Ok(())
    })
}

/// The shape of every batched read: `f` fills the caller's buffer of `capacity` elements and returns how
/// many it wrote, which goes to `*out_written` only on success.
pub(crate) fn fill<T>(
    engine: *const kdw_engine,
    buffer: *mut T,
    capacity: u32,
    out_written: *mut u32,
    what: &str,
    f: impl FnOnce(&Engine, &mut [T]) -> FfiResult<usize>,
) -> kdw_status {
    guard(|| {
        check_out(out_written, "out_written")?;
        // SAFETY: the caller passes `capacity` writable elements at `buffer`.
        let out = unsafe { slice_mut(buffer, capacity, what) }?;
        // SAFETY: `engine` is a live engine handle (caller contract, NULL checked inside).
        let written = unsafe { with_engine(engine, |e| f(e, out)) }?;
        // SAFETY: checked by check_out.
        unsafe { write(out_written, written as u32) };
        Ok(())
    })
}

/// Adapts a core visitor (`for_each_*`) to a C output buffer: converts and stores each item in order and
/// returns how many were stored. The visitor checks the capacity before it calls back.
pub(crate) fn store_each<T, C: From<T>>(
    out: &mut [C],
    visit: impl FnOnce(usize, &mut dyn FnMut(T)) -> crate::core::Result<()>,
) -> FfiResult<usize> {
    let capacity = out.len();
    let mut stored = 0;
    visit(capacity, &mut |item| {
        out[stored] = item.into();
        stored += 1;
    })?;
    Ok(stored)
}
