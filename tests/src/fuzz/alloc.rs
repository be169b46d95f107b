//! A counting allocator: the test binary installs it as its `#[global_allocator]` and the harness
//! reads the largest single request made while an execution ran. Counting is process-wide (not
//! per thread) because the EXR decoder allocates on rayon worker threads too; the harness runs
//! one execution at a time, under [`MEASURING`].

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

static LARGEST: AtomicUsize = AtomicUsize::new(0);

/// Held by whoever is measuring, so that two tests of one binary do not mix their figures.
pub static MEASURING: Mutex<()> = Mutex::new(());

/// The system allocator, recording the largest request since [`reset_largest`].
pub struct CountingAlloc;

fn record(size: usize) {
    LARGEST.fetch_max(size, Ordering::Relaxed);
}

unsafe impl GlobalAlloc for CountingAlloc {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        record(layout.size());
        unsafe { System.alloc(layout) }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        record(layout.size());
        unsafe { System.alloc_zeroed(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        record(new_size);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

/// Starts a new measurement window.
pub fn reset_largest() {
    LARGEST.store(0, Ordering::Relaxed);
}

/// The largest single allocation requested since [`reset_largest`]. Zero when the test binary
/// did not install [`CountingAlloc`], which [`is_installed`] detects.
pub fn largest() -> usize {
    LARGEST.load(Ordering::Relaxed)
}

/// Whether [`CountingAlloc`] is the global allocator (so that a bound checked on [`largest`]
/// cannot pass vacuously).
pub fn is_installed() -> bool {
    reset_largest();
    let probe = std::hint::black_box(vec![0u8; 12_345]);
    let seen = largest() >= probe.len();
    drop(probe);
    seen
}

/// Runs `f` and returns its result with the largest allocation it made.
pub fn measure<T>(f: impl FnOnce() -> T) -> (T, usize) {
    reset_largest();
    let out = f();
    (out, largest())
}
