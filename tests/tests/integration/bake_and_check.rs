//! End to end: a reduced-resolution bake of every table for several fibers, each table checked
//! against direct f64 integration (the full-resolution check is a benchmark: docs/BENCHMARKS.md).

use strandlight_precompute::bake::bake_job;
use strandlight_precompute::bake_plan::{
    BakeResolution, FiberDescription, Model, PlanOptions, plan,
};
use strandlight_precompute::baked_tables_check::{check_asset, check_asset_at_nodes};
use strandlight_tables::asset::{Storage, TableAsset, read_asset};
use strandlight_tables::table::Table;

fn temp_dir(tag: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("strandlight-e2e-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// Bakes `fiber` at 8 nodes per direction axis and checks every table at 40 points.
/// Returns (name, max, rms) per table.
fn bake_and_check(
    fiber: &FiberDescription,
    tag: &str,
    force_multiple: bool,
) -> Vec<(String, f64, f64)> {
    let dir = temp_dir(tag);
    let options = PlanOptions {
        models: vec![Model::Marschner, Model::KajiyaKay, Model::Artist],
        resolution: BakeResolution::reduced(8),
        force_multiple,
        ..Default::default()
    };
    let plan = plan(fiber, &options).unwrap();
    let mut out = Vec::new();
    for job in plan.jobs {
        let baked = bake_job(job, &dir, Storage::F32).unwrap();
        let asset = read_asset(&baked.path).unwrap();
        let stats = asset.table.stats();
        assert_eq!(stats.nan_count + stats.infinite_count, 0, "{}", baked.name);
        let acc = check_asset(&asset, 40, 3).unwrap();
        println!(
            "{tag:>8} {:<18} max {:.3e} rms {:.3e} max rel {:.3e}",
            acc.name, acc.max_abs_error, acc.rms_abs_error, acc.max_rel_error
        );
        out.push((acc.name, acc.max_abs_error, acc.rms_abs_error));
    }
    std::fs::remove_dir_all(&dir).unwrap();
    out
}

/// Bounds at 8 nodes per axis: the interpolation error of an 8-node grid over lobes a few
/// nodes wide. Measured values are ~3× below these (printed above); a broken axis, a wrong
/// sign or a mismatched convention gives errors of order one.
fn assert_within(results: &[(String, f64, f64)], max_bound: f64, rms_bound: f64) {
    for (name, max, rms) in results {
        // The point-light textures and the KK specular lobe (p = 40, ~9° wide) are the
        // narrowest functions on the coarsest grids here.
        let loose = matches!(name.as_str(), "lut_n" | "lut_m" | "kk_specular");
        let (mb, rb) = if loose {
            (0.6, 0.15)
        } else {
            (max_bound, rms_bound)
        };
        assert!(*max < mb && *rms < rb, "{name}: max {max}, rms {rms}");
    }
}

#[test]
fn brown_fiber_tables_match_direct_integration() {
    let r = bake_and_check(&FiberDescription::preset("brown").unwrap(), "brown", false);
    assert_eq!(r.len(), 14, "every table of every model (11 + 3 direct)");
    assert_within(&r, 0.1, 0.02);
}

#[test]
fn hard_fibers_bake_finite_checked_tables() {
    // Very narrow lobes (β_R = 2°), white (σ_a = 0) and very dark hair.
    let mut narrow = FiberDescription::preset("blonde").unwrap();
    narrow.marschner.beta_deg = [2.0, 1.0, 4.0];
    let r = bake_and_check(&narrow, "narrow", false);
    // An 8-node grid cannot follow a 1° TT lobe: only finiteness and an order-one bound here;
    // the resolution needed is measured in docs/BENCHMARKS.md.
    for (name, max, _) in &r {
        assert!(*max < 1.0, "{name}: {max}");
    }
    let white = bake_and_check(&FiberDescription::preset("white").unwrap(), "white", false);
    assert_within(&white, 0.1, 0.02);
    let dark = bake_and_check(&FiberDescription::preset("dark").unwrap(), "dark", true);
    assert_within(&dark, 0.1, 0.02);
}

#[test]
fn dark_hair_skips_the_multiple_scattering_table_and_says_why() {
    let options = PlanOptions {
        models: vec![Model::Marschner],
        resolution: BakeResolution::reduced(4),
        ..Default::default()
    };
    let p = plan(&FiberDescription::preset("dark").unwrap(), &options).unwrap();
    let skipped = p
        .skipped
        .iter()
        .find(|s| s.name == "multiple")
        .expect("dark hair skips I_G");
    println!("{}", skipped.reason);
    assert!(skipped.reason.contains("threshold"));
}

/// The multiple-scattering table's relative error is measured over real points and can fail:
/// its maximum is a corner singularity (u·ξ = −u·ω_o = ±1, σ̄_f → 0) far above the rest, so
/// relative errors are taken above 1% of the 99.9th percentile rather than of the maximum, which
/// no sampled point reached (the check used to report 0). At the table's nodes, where
/// interpolation adds nothing, the bake's product integration and the reference's 2D quadrature
/// agree within a few percent (3.4% measured at 8 nodes, where narrow σ̄_f nodes are hardest),
/// and a copy scaled by 1.05 shows 5% at the nodes both integrate alike.
#[test]
fn the_multiple_scattering_table_relative_error_can_fail() {
    let dir = temp_dir("multiple-rel");
    let options = PlanOptions {
        models: vec![Model::Marschner],
        resolution: BakeResolution::reduced(8),
        force_multiple: true,
        ..Default::default()
    };
    let fiber = FiberDescription::preset("brown").unwrap();
    let job = plan(&fiber, &options)
        .unwrap()
        .jobs
        .into_iter()
        .find(|j| j.name == "multiple")
        .expect("a multiple-scattering job");
    let baked = bake_job(job, &dir, Storage::F32).unwrap();
    let asset = read_asset(&baked.path).unwrap();
    let scaled = TableAsset {
        table: Table::new(
            asset.table.axes().to_vec(),
            asset.table.channels(),
            asset.table.values().iter().map(|v| v * 1.05).collect(),
        )
        .unwrap()
        .into(),
        ..asset.clone()
    };
    let random = check_asset(&asset, 200, 5).unwrap();
    let good = check_asset_at_nodes(&asset, 200, 5).unwrap();
    let bad = check_asset_at_nodes(&scaled, 200, 5).unwrap();
    println!(
        "multiple at 8 nodes: random points max rel {:.3e} over {} of {}; at nodes {:.3e} over {}; scaled by 1.05 {:.3e}",
        random.max_rel_error,
        random.rel_samples,
        random.samples,
        good.max_rel_error,
        good.rel_samples,
        bad.max_rel_error
    );
    assert!(random.rel_samples > 0 && random.max_rel_error > 0.0);
    assert!(good.rel_samples >= 20, "{} points", good.rel_samples);
    assert!(good.max_rel_error < 0.06, "{}", good.max_rel_error);
    assert!(
        (bad.max_rel_error - 0.05).abs() < 0.01,
        "{}",
        bad.max_rel_error
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
