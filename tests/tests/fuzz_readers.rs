//! Every file reader fuzzed from its seed corpus (issue #15, "Bad input"): see
//! `strandlight_tests::fuzz` for what is checked. The executions per target are the `execs` of
//! `fuzz::targets::all()` times `STRANDLIGHT_FUZZ_EXECS` (default 1):
//!
//! ```text
//! cargo test -p strandlight-tests --test fuzz_readers -- --nocapture
//! STRANDLIGHT_FUZZ_EXECS=10 cargo test -p strandlight-tests --test fuzz_readers -- --nocapture
//! ```
//!
//! The targets share one process-wide allocation counter, so they run one at a time (each test
//! holds `fuzz::alloc::MEASURING`).

use strandlight_tests::fuzz::{self, alloc};

#[global_allocator]
static COUNTING: alloc::CountingAlloc = alloc::CountingAlloc;

#[test]
fn the_counting_allocator_is_installed() {
    let _measuring = alloc::MEASURING.lock().unwrap_or_else(|e| e.into_inner());
    assert!(alloc::is_installed());
    // And it sees a large request as one.
    let (v, largest) = alloc::measure(|| std::hint::black_box(vec![0u8; 3 << 20]));
    assert!(largest >= v.len());
}

#[test]
fn every_target_has_a_test_here() {
    let names: Vec<_> = fuzz::targets::all().iter().map(|t| t.name).collect();
    assert_eq!(
        names,
        ["hair", "tfx", "data", "ply", "hdr", "exr", "sltab", "srbf"]
    );
}

#[test]
fn hair() {
    fuzz::fuzz_target("hair");
}

#[test]
fn tfx() {
    fuzz::fuzz_target("tfx");
}

#[test]
fn data() {
    fuzz::fuzz_target("data");
}

#[test]
fn ply() {
    fuzz::fuzz_target("ply");
}

#[test]
fn hdr() {
    fuzz::fuzz_target("hdr");
}

#[test]
fn exr() {
    fuzz::fuzz_target("exr");
}

#[test]
fn sltab() {
    fuzz::fuzz_target("sltab");
}

#[test]
fn srbf() {
    fuzz::fuzz_target("srbf");
}
