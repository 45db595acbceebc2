//! A global allocator that counts heap allocations (and reallocations) per thread: the no-allocation tests
//! install it with `#[global_allocator] static GLOBAL: Counting = Counting;` and hold one test per file; the
//! performance report (`benches/support/perf_report.rs`) includes this file for its allocations per frame.
//!
//! Per thread, because the test harness's main thread allocates too while it sets up its wait for the test's
//! thread (std's channel receive with a timeout allocates). Counted process-wide, those fell into a counted frame whenever the main thread
//! got there late on a loaded machine: `tests/no_alloc_changes.rs` failed once in a full `cargo test --release`
//! run and passed on every rerun. What is counted is what the calling thread allocates, which is all a step
//! does: the engine starts no threads (the `parallel` feature's batch call does, and the tests leave its
//! count out).

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

pub struct Counting;

thread_local! {
    // `const` and without a destructor: reading it neither allocates nor registers anything, as an allocator
    // must not.
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

fn count() {
    // `try_with`: a thread that is exiting may allocate after its thread-locals are gone.
    let _ = ALLOCATIONS.try_with(|n| n.set(n.get() + 1));
}

/// Allocations and reallocations this thread has made so far through [`Counting`].
pub fn allocations() -> usize {
    ALLOCATIONS.with(Cell::get)
}

// SAFETY: forwards to the system allocator unchanged; only counts.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count();
        // SAFETY: the caller's contract, passed on.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: the caller's contract, passed on.
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count();
        // SAFETY: the caller's contract, passed on.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}
