//! The `ktx2_strand` example as a test: a small Marschner convolution table is baked, written as
//! `.sltab`, exported as KTX2 (half, and float where the device filters rgba32float), and a
//! strand lit on the GPU from the export alone matches the runtime's lookup of the same table
//! within the tolerance the example derives (half rounding + 8-bit filter weights + f32).

use crate::common;
#[path = "../../examples/ktx2_strand.rs"]
mod example;

use example::Sampling;
use std::path::PathBuf;
use strandlight_precompute::convolution::ConvolutionSettings;
use strandlight_precompute::convolution_table::{
    ConvolutionResolution, DirectionAxes, bake_convolution_table,
};
use strandlight_tables::FiberAngles;
use strandlight_tables::asset::{
    AssetDescription, CreationInfo, Generator, Storage, read_asset, write_asset,
};
use strandlight_tables::lut_export::{TexelStorage, export_ktx2, write_wgsl};
use strandlight_tables::marschner::{Marschner, MarschnerParams};
use strandlight_tables::scattering::ScatteringFunction;

fn scratch() -> PathBuf {
    let dir = std::env::temp_dir().join(format!("strandlight-ktx2-strand-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("ktx2")).unwrap();
    dir
}

/// A coarse Marschner I(u·ξ, u·ω_o, cos Δφ, 1/λ) with the production axis mappings.
fn bake_small_marschner(dir: &std::path::Path) {
    let fiber = Marschner::new(MarschnerParams::default()).unwrap();
    let resolution = ConvolutionResolution {
        u_dot_xi: 12,
        u_dot_wo: 16,
        cos_dphi: 12,
        inv_lambda: 5,
        axes: DirectionAxes::Angular,
        ..Default::default()
    };
    let settings = ConvolutionSettings {
        theta_panels: 48,
        phi_panels: 16,
        max_harmonic: None,
    };
    let table =
        bake_convolution_table(&|a: &FiberAngles| fiber.eval(a), &resolution, &settings).unwrap();
    let description = AssetDescription {
        name: "marschner".into(),
        quantity: "I_M (test bake)".into(),
        scattering_function: "marschner".into(),
        fiber_parameters: serde_json::json!({}),
        generator: Generator {
            name: "test".into(),
            version: "0".into(),
        },
        created: CreationInfo::now(),
        inputs_key: None,
    };
    write_asset(
        &dir.join("marschner.sltab"),
        &table,
        &description,
        Storage::F32,
    )
    .unwrap();
}

#[test]
fn a_strand_lit_from_the_exported_lut_alone_matches_the_runtime() {
    let dir = scratch();
    bake_small_marschner(&dir);
    let asset = read_asset(&dir.join("marschner.sltab")).unwrap();
    let export = dir.join("ktx2");
    write_wgsl(&export).unwrap();
    let gpu = common::gpu();
    // Float exports need `float32-filterable` for the filtered path only; the exact path
    // reads them anywhere.
    let storages = [TexelStorage::Half, TexelStorage::Float];
    let mut results = Vec::new();
    for (storage, sampling) in storages
        .into_iter()
        .flat_map(|s| [Sampling::Filtered, Sampling::Exact].map(move |m| (s, m)))
    {
        if storage == TexelStorage::Float
            && sampling == Sampling::Filtered
            && !gpu.float32_filterable
        {
            eprintln!(
                "{}: no float32-filterable; the filtered float case is skipped",
                gpu.report
            );
            continue;
        }
        export_ktx2(&asset, &export, storage).unwrap();
        let c = example::run(&gpu, &export, &dir, "marschner", sampling).unwrap();
        eprintln!(
            "{storage:?}, {sampling:?} on {}: {} points, max error {:.2e} of the largest radiance {:.3e}, max relative {:.2e}, {:.3} of the tolerance",
            gpu.report,
            c.points,
            c.max_error_of_max,
            c.largest_radiance,
            c.max_relative_error,
            c.worst_over_tolerance
        );
        assert!(
            c.largest_radiance > 0.0,
            "the strand is black: nothing was compared"
        );
        results.push((storage, sampling, c.worst_over_tolerance));
    }
    for (storage, sampling, worst) in results {
        assert!(
            worst <= 1.0,
            "{storage:?}, {sampling:?}: the GPU strand is {worst:.2}× the tolerance away from the runtime's"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
