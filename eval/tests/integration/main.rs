//! strandlight-eval's integration tests in one binary: each file here was a test binary of its own,
//! and linking each cost CI time.

mod docs_links;
mod ground_truth_conventions;
mod ground_truth_head;
mod hdr_flip_vs_nvidia;
mod multiple_scattering_slab;

/// Mitsuba and a GPU device, or the reason to skip printed (a failure under
/// `STRANDLIGHT_REQUIRE_TOOLS=1`): what every test against the path-traced truth needs.
fn mitsuba_and_gpu() -> bool {
    use strandlight_eval::ground_truth::INSTALL_HINT;
    use strandlight_scene::env_frame::env_adapter;
    use strandlight_tables::outside_tools::{require_python_modules, skip_or_fail};
    if !require_python_modules(&["mitsuba"], INSTALL_HINT) {
        return false;
    }
    if let Err(e) = env_adapter() {
        skip_or_fail(&format!("no GPU device for the env-lit renderer: {e:#}"));
        return false;
    }
    true
}
