//! End-to-end tests across crates live in `tests/tests/`; [`fuzz`] is the in-process fuzzer of
//! every file reader that `tests/tests/fuzz_readers.rs` runs; [`scene_grooms`] writes USD and
//! Alembic grooms with other projects' writers.

pub mod fuzz;
pub mod scene_grooms;
