//! strandlight-eval's integration tests in one binary: each file here was a test binary of its own,
//! and linking each cost CI time.

mod docs_links;
mod ground_truth_conventions;
mod ground_truth_head;
mod hdr_flip_vs_nvidia;
mod multiple_scattering_slab;
