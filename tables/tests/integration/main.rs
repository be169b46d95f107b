//! strandlight-tables's integration tests in one binary: each file here was a test binary of its own,
//! and linking each cost CI time.

mod chiang_vs_mitsuba;
mod dual_scattering_of_fibers;
mod ktx2_export_readback;
