//! strandlight-precompute's integration tests in one binary: each file here was a test binary of its own,
//! and linking each cost CI time.

mod chiang_tables;
mod envmap_loading;
mod srbf_fitting;
mod thread_count_determinism;
