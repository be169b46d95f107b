//! strandlight-tests's integration tests in one binary: each file here was a test binary of its own,
//! and linking each cost CI time.

mod bake_and_check;
mod env_vs_reference;
mod scene_grooms;
mod scene_heads;
