//! End to end on the GPU (Ren 2010 §8): a small procedural groom under a procedural environment,
//! rendered with the fitted SRBF lights and the convolution tables, against the brute-force
//! reference (one directional light per cube-map texel, shaded with the fiber function itself).
//! The two paths share only the renderer's rasterization; the lights (an L-BFGS fit vs texel
//! integrals) and the tables (a convolution over the SRBF vs S·cos θ) are computed
//! independently, so their agreement checks the SRBF approximation end to end.
//!
//! The error is split in two by a third rendering, the directional reference of the map the
//! fitted lobes themselves draw: SRBF vs that isolates the method (tables, effective
//! transmittance), that vs the map's reference isolates the fit. Each part has its own bound
//! (see the constants), and a light set turned 90° about up must exceed the total bound.
//! Sizes (800 strands, 128×96, 384 reference lights, 256² light maps) keep both tests at ~36 s
//! on 2 cores with lavapipe; without a GPU device they print why and pass, unless
//! `STRANDLIGHT_REQUIRE_TOOLS=1` (CI) makes that a failure.

use std::collections::BTreeMap;
use std::sync::{Arc, OnceLock};
use std::time::Instant;
use strandlight_precompute::bake::bake_job;
use strandlight_precompute::bake_plan::{
    BakeResolution, DEFAULT_MULTIPLE_THRESHOLD, FiberDescription, Model, PlanOptions, plan,
};
use strandlight_precompute::compact_sources::SourceOptions;
use strandlight_precompute::env_lights::{
    LightSpec, reference_lights, srbf_set_lights, total_power,
};
use strandlight_precompute::srbf_set::{Source, SrbfSet};
use strandlight_precompute::{FitOptions, procedural_env};
use strandlight_runtime::camera::{Camera, UpAxis};
use strandlight_runtime::env::{EnvRenderOptions, EnvRenderer, EnvTables};
use strandlight_runtime::env_light::EnvLight;
use strandlight_runtime::gpu::GpuContext;
use strandlight_runtime::hair::{GroomParams, HairModel, generate_groom};
use strandlight_runtime::multiple::ForwardScatteringSource;
use strandlight_runtime::multiple::{
    CpuForwardScattering, ForwardScatteringSettings, ForwardScatteringTables, GpuForwardScattering,
    VoxelSettings,
};
use strandlight_scene::env_orientation::EnvOrientation;
use strandlight_tables::asset::{Storage, read_asset};
use strandlight_tables::outside_tools::skip_or_fail;
use strandlight_tables::table::Table;

const WIDTH: u32 = 128;
const HEIGHT: u32 = 96;
/// Cube texels per face edge of the reference: 6·8² = 384 lights.
const REFERENCE_FACE: usize = 8;
/// Nodes per direction axis of the single-scattering tables (`marschner`, `marschner_direct`,
/// and their `_full` variants). Measured on this scene, the SRBF image against the directional
/// reference of the same lobes (unshadowed): 0.28 at 8 nodes, 0.071 at 16, 0.020 at 24: the
/// convolution table's interpolation dominates below 24.
const SINGLE_TABLE_NODES: usize = 24;
/// Nodes of the multiple-scattering tables (I_G and the fiber averages are smooth).
const MULTIPLE_TABLE_NODES: usize = 8;
const SINGLE_TABLES: [&str; 4] = [
    "marschner",
    "marschner_direct",
    "marschner_full",
    "marschner_full_direct",
];
const MULTIPLE_TABLES: [&str; 4] = [
    "multiple",
    "fiber_averages",
    "attenuation_ratio",
    "srbf_spread",
];
/// Light-pass map resolution for every light of both paths (half the default: the groom spans
/// ~100 pixels, and the light pass dominates the reference's 384 lights).
const DODM_RESOLUTION: u32 = 256;
/// Pixels whose reference alpha exceeds this are hair (as `scene/src/image_metrics.rs`).
const HAIR_ALPHA: f32 = 1e-3;

/// Everything both tests share: built once per test binary.
struct Scene {
    gpu: GpuContext,
    renderer: EnvRenderer,
    hair: HairModel,
    camera: Camera,
    srbf: Vec<EnvLight>,
    reference: Vec<EnvLight>,
    /// The cube-texel reference of the map the fitted lobes draw.
    fitted_reference: Vec<EnvLight>,
    srbf_specs: Vec<LightSpec>,
    reference_specs: Vec<LightSpec>,
    up: UpAxis,
    tables: BTreeMap<String, Arc<Table>>,
}

/// The runtime lights of `specs` over a hair with `up`, placed as every frame places them.
fn to_env_lights(specs: &[LightSpec], up: UpAxis) -> Vec<EnvLight> {
    EnvOrientation::upright(up).lights(specs)
}

/// The scene, or the reason there is none (no GPU device).
fn scene() -> Result<&'static Scene, String> {
    static SCENE: OnceLock<Result<Scene, String>> = OnceLock::new();
    SCENE
        .get_or_init(build_scene)
        .as_ref()
        .map_err(Clone::clone)
}

fn build_scene() -> Result<Scene, String> {
    let t0 = Instant::now();
    let gpu = GpuContext::new_headless().map_err(|e| e.to_string())?;
    let renderer = EnvRenderer::new(&gpu);
    eprintln!(
        "device + pipelines: {:.2} s ({})",
        t0.elapsed().as_secs_f64(),
        gpu.report.name
    );
    let lights = fit_lights();
    let tables = bake_tables(&lights.srbf);

    let hair = generate_groom(&GroomParams {
        strand_count: 800,
        points_per_strand: 12,
        clump_count: 40,
        ..GroomParams::default()
    })
    .expect("groom");
    let up = UpAxis::detect(&hair);
    let camera = Camera::framing_front(hair.bounds(), WIDTH as f32 / HEIGHT as f32, false, up);
    Ok(Scene {
        gpu,
        renderer,
        srbf: to_env_lights(&lights.srbf, up),
        reference: to_env_lights(&lights.reference, up),
        fitted_reference: to_env_lights(&lights.fitted_reference, up),
        srbf_specs: lights.srbf,
        reference_specs: lights.reference,
        hair,
        camera,
        up,
        tables,
    })
}

/// The three light sets of the studio map that the tests compare.
struct LightSets {
    /// The fitted SRBF lobes.
    srbf: Vec<LightSpec>,
    /// One directional light per cube texel of the map.
    reference: Vec<LightSpec>,
    /// One directional light per cube texel of the map the fitted lobes draw.
    fitted_reference: Vec<LightSpec>,
}

/// Fits the studio map with a small SRBF set (the paper's pure fit, no compact source taken
/// out: this test measures its method) and builds the cube-texel references of the map and of
/// the fitted lobes, which separate the fit's error from the method's.
fn fit_lights() -> LightSets {
    let t = Instant::now();
    let map = procedural_env::by_name("studio", 256).expect("studio is a procedural map");
    let options = FitOptions {
        initial_lobes: 8,
        max_lobes: 24,
        target_relative_mse: 0.03,
        grid_width: 64,
        lambda_max: 64.0, // λ ≤ grid_width²/64
        iterations_per_round: 10,
        final_iterations: 40,
        sources: SourceOptions::none(),
        ..FitOptions::default()
    };
    let source = Source {
        map: &map,
        name: "procedural:studio".into(),
        sha256: String::new(),
        sanitized: Default::default(),
    };
    let set = SrbfSet::fit(&source, &options, &mut |_| {}).expect("fit");
    let srbf_specs = srbf_set_lights(&set);
    let reference_specs =
        reference_lights(&map, REFERENCE_FACE, &options.sources).expect("reference lights");
    let fitted_map = procedural_env::from_srbf_lobes(256, &set.lobes);
    let fitted_reference_specs =
        reference_lights(&fitted_map, REFERENCE_FACE, &options.sources).expect("reference lights");
    eprintln!(
        "fit: {} lobes in {:.2} s (relative MSE {:.4} on the fit grid, {:.4} at full resolution); reference: {} lights",
        srbf_specs.len(),
        t.elapsed().as_secs_f64(),
        set.relative_mse,
        set.full_resolution_relative_mse,
        reference_specs.len()
    );
    LightSets {
        srbf: srbf_specs,
        reference: reference_specs,
        fitted_reference: fitted_reference_specs,
    }
}

/// Bakes the blonde Marschner tables the tests read ([`SINGLE_TABLES`] at
/// [`SINGLE_TABLE_NODES`], [`MULTIPLE_TABLES`] at [`MULTIPLE_TABLE_NODES`]), their 1/λ axis
/// spanning the bandwidths of `srbf_specs` with a 10% margin.
fn bake_tables(srbf_specs: &[LightSpec]) -> BTreeMap<String, Arc<Table>> {
    let t = Instant::now();
    let (lo, hi) = srbf_specs
        .iter()
        .filter_map(|s| s.lambda)
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), l| {
            (lo.min(l), hi.max(l))
        });
    let (lo, hi) = (lo / 1.1, (hi * 1.1).max(lo * 1.01 / 1.1));
    // Blonde: light enough that the plan bakes `multiple` (dark hair skips it).
    let fiber = FiberDescription::preset("blonde").expect("preset");
    let dir = std::env::temp_dir().join(format!(
        "strandlight-env-vs-reference-{}",
        std::process::id()
    ));
    let mut tables = BTreeMap::new();
    for (nodes, wanted) in [
        (SINGLE_TABLE_NODES, &SINGLE_TABLES[..]),
        (MULTIPLE_TABLE_NODES, &MULTIPLE_TABLES[..]),
    ] {
        let plan_options = PlanOptions {
            models: vec![Model::Marschner],
            resolution: BakeResolution::reduced(nodes).with_lambda_range(lo, hi),
            force_multiple: false,
            multiple_threshold: DEFAULT_MULTIPLE_THRESHOLD,
            tables: None,
        };
        for job in plan(&fiber, &plan_options)
            .expect("plan")
            .jobs
            .into_iter()
            .filter(|j| wanted.contains(&j.name))
        {
            let baked = bake_job(job, &dir.join(nodes.to_string()), Storage::F32).expect("bake");
            eprintln!(
                "  baked {:<22} at {nodes:>2} nodes: {:.2} s",
                baked.name, baked.seconds
            );
            tables.insert(
                baked.name.clone(),
                read_asset(&baked.path).expect("read table").table,
            );
        }
        for name in wanted {
            assert!(tables.contains_key(*name), "table {name} was not baked");
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    eprintln!(
        "bake (λ ∈ [{lo:.1}, {hi:.1}]): {:.2} s",
        t.elapsed().as_secs_f64()
    );
    tables
}

/// Renders `lights` (all of one kind) with κ = 1; `full` adds multiple scattering from
/// `forward`. Returns the pixels and the seconds taken.
fn render(
    scene: &Scene,
    lights: &[EnvLight],
    tables: EnvTables,
    shadowed: bool,
    forward: Option<&dyn ForwardScatteringSource>,
) -> (Vec<[f32; 4]>, f64) {
    let t = Instant::now();
    let mut options = EnvRenderOptions {
        kappa: 1.0,
        shadowed,
        ..EnvRenderOptions::default()
    };
    options.dodm.resolution = DODM_RESOLUTION;
    let frame = scene
        .renderer
        .render(
            &scene.gpu,
            &scene.hair,
            &scene.camera,
            WIDTH,
            HEIGHT,
            lights,
            &tables,
            &options,
            forward,
        )
        .expect("render");
    if std::env::var_os("STRANDLIGHT_TIMINGS").is_some() {
        eprintln!(
            "    {} lights: {:?}",
            lights.len(),
            frame
                .stats
                .timings
                .iter()
                .map(|t| format!("{} {:.0} ms", t.pass, t.milliseconds))
                .collect::<Vec<_>>()
        );
    }
    (frame.pixels, t.elapsed().as_secs_f64())
}

/// √(Σ‖a − r‖² / Σ‖r‖²) over RGB of the pixels where the reference's alpha exceeds
/// [`HAIR_ALPHA`] (the definition of `scene/src/image_metrics.rs`).
fn relative_rmse(a: &[[f32; 4]], r: &[[f32; 4]]) -> f64 {
    let (mut num, mut den) = (0.0f64, 0.0f64);
    for (a, r) in a.iter().zip(r).filter(|(_, r)| r[3] > HAIR_ALPHA) {
        for c in 0..3 {
            num += (a[c] as f64 - r[c] as f64).powi(2);
            den += (r[c] as f64).powi(2);
        }
    }
    assert!(den > 0.0, "the reference is black over the hair");
    (num / den).sqrt()
}

fn assert_finite(what: &str, pixels: &[[f32; 4]]) {
    let bad = pixels
        .iter()
        .filter(|p| p.iter().any(|c| !c.is_finite()))
        .count();
    assert_eq!(bad, 0, "{what}: {bad} pixels not finite");
}

fn coverage(pixels: &[[f32; 4]]) -> usize {
    pixels.iter().filter(|p| p[3] > HAIR_ALPHA).count()
}

/// Mean of ‖rgb‖ over hair pixels (a scale for the printout).
fn mean_hair(pixels: &[[f32; 4]]) -> f64 {
    let hair: Vec<_> = pixels.iter().filter(|p| p[3] > HAIR_ALPHA).collect();
    hair.iter()
        .map(|p| (p[0] + p[1] + p[2]) as f64 / 3.0)
        .sum::<f64>()
        / hair.len().max(1) as f64
}

/// `lights` turned by `degrees` about the world's up.
fn rotated(lights: &[EnvLight], up: UpAxis, degrees: f32) -> Vec<EnvLight> {
    let q = glam::Quat::from_axis_angle(up.vector(), degrees.to_radians());
    lights
        .iter()
        .map(|l| EnvLight {
            direction: (q * l.direction).normalize(),
            ..*l
        })
        .collect()
}

fn table(scene: &Scene, name: &str) -> Arc<Table> {
    scene.tables[name].clone()
}

/// The relative RMSEs of one shadowing mode, against the map's reference.
struct SingleScatteringErrors {
    shadowed: bool,
    /// The SRBF image.
    total: f64,
    /// The SRBF lights turned 90° about up: must exceed the bound, or the test is blind.
    turned: f64,
    /// The SRBF image against the reference of the fitted lobes: the method alone.
    method: f64,
}

/// The fit preserves the map's power; the cube texels integrate the same map: the two light
/// sets' total powers agree to 10⁻³ in every channel.
fn assert_srbf_power_matches_the_reference(scene: &Scene) {
    let (ps, pr) = (
        total_power(&scene.srbf_specs),
        total_power(&scene.reference_specs),
    );
    for c in 0..3 {
        let rel = (ps[c] - pr[c]).abs() / pr[c];
        eprintln!(
            "power channel {c}: SRBF {:.5} reference {:.5} (relative difference {rel:.2e})",
            ps[c], pr[c]
        );
        assert!(
            rel < 1e-3,
            "channel {c}: SRBF power {} vs reference {}",
            ps[c],
            pr[c]
        );
    }
}

/// Renders the SRBF image, the map's reference, the fitted lobes' reference and the turned
/// SRBF lights in one shadowing mode; checks that all are finite and that the paths rasterize
/// the same hair, and returns the errors for the caller's bounds.
fn single_scattering_errors(scene: &Scene, shadowed: bool) -> SingleScatteringErrors {
    let srbf_tables = EnvTables {
        srbf: Some(table(scene, "marschner")),
        ..EnvTables::default()
    };
    let direct_tables = EnvTables {
        direct: Some(table(scene, "marschner_direct")),
        ..EnvTables::default()
    };
    let (a, ta) = render(scene, &scene.srbf, srbf_tables.clone(), shadowed, None);
    let (r, tr) = render(
        scene,
        &scene.reference,
        direct_tables.clone(),
        shadowed,
        None,
    );
    assert_finite("SRBF image", &a);
    assert_finite("reference image", &r);
    assert_eq!(
        coverage(&a),
        coverage(&r),
        "both paths rasterize the same hair"
    );
    assert!(
        coverage(&r) > 500,
        "the groom covers {} pixels",
        coverage(&r)
    );
    let e = relative_rmse(&a, &r);
    let (f, tf) = render(
        scene,
        &scene.fitted_reference,
        direct_tables.clone(),
        shadowed,
        None,
    );
    let e_method = relative_rmse(&a, &f);
    let e_fit = relative_rmse(&f, &r);
    eprintln!(
        "shadowed {shadowed:5}: SRBF vs reference of the fitted lobes {e_method:.4}; fitted-lobe reference vs map reference {e_fit:.4} ({tf:.2} s)"
    );
    eprintln!(
        "shadowed {shadowed:5}: relative RMSE {e:.4} over {} hair pixels; mean SRBF {:.4e}, reference {:.4e}; SRBF {ta:.2} s, reference {tr:.2} s",
        coverage(&r),
        mean_hair(&a),
        mean_hair(&r)
    );
    let (turned, _) = render(
        scene,
        &rotated(&scene.srbf, scene.up, 90.0),
        srbf_tables.clone(),
        shadowed,
        None,
    );
    let e_turned = relative_rmse(&turned, &r);
    eprintln!(
        "shadowed {shadowed:5}: SRBF lights turned 90° about up: relative RMSE {e_turned:.4}"
    );
    SingleScatteringErrors {
        shadowed,
        total: e,
        turned: e_turned,
        method: e_method,
    }
}

#[test]
fn srbf_single_scattering_matches_the_directional_reference() {
    let start = Instant::now();
    let scene = match scene() {
        Ok(s) => s,
        Err(reason) => {
            skip_or_fail(&format!("no GPU device ({reason})"));
            return;
        }
    };
    eprintln!(
        "scene ready after {:.2} s; groom up axis {:?}, {} SRBF lights, {} reference lights",
        start.elapsed().as_secs_f64(),
        scene.up,
        scene.srbf.len(),
        scene.reference.len()
    );
    assert_srbf_power_matches_the_reference(scene);

    let errors: Vec<SingleScatteringErrors> = [false, true]
        .into_iter()
        .map(|shadowed| single_scattering_errors(scene, shadowed))
        .collect();
    eprintln!("total {:.2} s", start.elapsed().as_secs_f64());
    for SingleScatteringErrors {
        shadowed,
        total: e,
        turned: e_turned,
        method: e_method,
    } in errors
    {
        let method_bound = if shadowed {
            METHOD_SHADOWED_BOUND
        } else {
            METHOD_UNSHADOWED_BOUND
        };
        assert!(
            e_method < method_bound,
            "shadowed {shadowed}: SRBF vs the directional reference of the same lobes {e_method} ≥ {method_bound}"
        );
        let bound = if shadowed {
            SHADOWED_BOUND
        } else {
            UNSHADOWED_BOUND
        };
        assert!(
            e < bound,
            "shadowed {shadowed}: relative RMSE {e} ≥ {bound}"
        );
        assert!(
            e_turned > bound,
            "shadowed {shadowed}: a 90°-turned environment gives {e_turned}, not above {bound}: the test cannot see a wrong light set"
        );
    }
}

/// SRBF image vs the directional render of the SAME lobes, unshadowed. Only two approximations
/// separate them: (1) the convolution table's multilinear interpolation on
/// [`SINGLE_TABLE_NODES`] nodes per direction axis (the direct table has 4× as many), and (2)
/// the reference's splitting of each lobe (λ ≈ 57–70, angular width 1/√λ ≈ 7°) into cube texels
/// ~11° apart. (2) was measured by rendering the lobes at 16×16 texels per face instead of 8×8:
/// the error moved by 0.009. (1) converges as 0.28 (8 nodes), 0.071 (16), 0.020–0.023 (24)
/// (measured while sizing this test, 400–1500 strands). The bound is ~2× the 24-node value and below the 16-node one, so tables half as fine,
/// or any convention mismatch (an error of order one), fail.
const METHOD_UNSHADOWED_BOUND: f64 = 0.05;
/// The same, shadowed: adds the effective transmittance (one box average of the convolution
/// optical depth map over the SRBF's support, Ren §5, in place of per-direction transmittance).
/// Shadowing removes ~9% of the reference's light on this groom (mean 1.27e-2 vs 1.39e-2), so
/// an effective transmittance wrong by half of (1 − T) everywhere adds ≤ ~0.05: bound =
/// 0.05 + 0.05. Measured 0.043.
const METHOD_SHADOWED_BOUND: f64 = 0.10;
/// SRBF image vs the reference of the MAP: adds the fit's own error, measured independently of
/// the SRBF renderer (the directional render of the fitted lobes vs that of the map: 0.10 with
/// 9 lobes whose radiance is off by 0.42 in relative L2 — the fiber's broad lobes average most
/// of it away). Bound = 0.10 (fit) + 0.05 (method). The 90°-turned light set gives ~0.67.
const UNSHADOWED_BOUND: f64 = 0.15;
const SHADOWED_BOUND: f64 = 0.15;

#[test]
fn srbf_full_scattering_matches_the_directional_reference() {
    let start = Instant::now();
    let scene = match scene() {
        Ok(s) => s,
        Err(reason) => {
            skip_or_fail(&format!("no GPU device ({reason})"));
            return;
        }
    };
    let forward_tables = || {
        ForwardScatteringTables::from_tables(
            &scene.tables["fiber_averages"],
            &scene.tables["attenuation_ratio"],
            &scene.tables["srbf_spread"],
        )
        .expect("forward-scattering tables")
    };
    let t = Instant::now();
    let voxels = VoxelSettings {
        voxels_longest_side: FORWARD_VOXELS,
        ..VoxelSettings::default()
    };
    let interactive = CpuForwardScattering::new(
        &scene.hair,
        forward_tables(),
        ForwardScatteringSettings {
            voxels,
            ..ForwardScatteringSettings::default()
        },
    )
    .expect("voxelize");
    let dense = CpuForwardScattering::new(
        &scene.hair,
        forward_tables(),
        ForwardScatteringSettings {
            voxels,
            ..ForwardScatteringSettings::dense_reference()
        },
    )
    .expect("voxelize");
    eprintln!("voxelization (both): {:.2} s", t.elapsed().as_secs_f64());
    let srbf_tables = EnvTables {
        srbf: Some(table(scene, "marschner_full")),
        multiple: Some(table(scene, "multiple")),
        ..EnvTables::default()
    };
    let direct_tables = EnvTables {
        direct: Some(table(scene, "marschner_full_direct")),
        multiple: Some(table(scene, "multiple")),
        ..EnvTables::default()
    };
    let (a, ta) = render(
        scene,
        &scene.srbf,
        srbf_tables.clone(),
        true,
        Some(&interactive),
    );
    let (r, tr) = render(scene, &scene.reference, direct_tables, true, Some(&dense));
    assert_finite("SRBF image", &a);
    assert_finite("reference image", &r);
    assert_eq!(coverage(&a), coverage(&r));
    let e = relative_rmse(&a, &r);
    eprintln!(
        "full: relative RMSE {e:.4}; mean SRBF {:.4e}, reference {:.4e}; SRBF {ta:.2} s, reference {tr:.2} s",
        mean_hair(&a),
        mean_hair(&r)
    );
    // The same frame with the shadow paths marched by the compute shader: the same image.
    let on_gpu = GpuForwardScattering::new(&scene.gpu, interactive.clone()).expect("GPU march");
    let (g, tg) = render(scene, &scene.srbf, srbf_tables.clone(), true, Some(&on_gpu));
    let e_devices = relative_rmse(&g, &a);
    eprintln!(
        "full: GPU-marched grid vs CPU-marched grid: relative RMSE {e_devices:.2e} ({tg:.2} s vs {ta:.2} s)"
    );
    assert!(
        e_devices < 1e-4,
        "GPU and CPU forward scattering differ: {e_devices}"
    );
    let (turned, _) = render(
        scene,
        &rotated(&scene.srbf, scene.up, 90.0),
        srbf_tables,
        true,
        Some(&interactive),
    );
    let e_turned = relative_rmse(&turned, &r);
    eprintln!(
        "full: SRBF lights turned 90° about up: relative RMSE {e_turned:.4}; total {:.2} s",
        start.elapsed().as_secs_f64()
    );
    assert!(e < FULL_BOUND, "full: relative RMSE {e} ≥ {FULL_BOUND}");
    assert!(
        e_turned > FULL_BOUND,
        "full: a 90°-turned environment gives {e_turned}, not above {FULL_BOUND}"
    );
}

/// Full scattering (single + I_G·T_f): the single-scattering bound plus the paper's allowance
/// for the multiple-scattering approximation (Ren's targets: 5% single, 8% full → +0.03), which
/// here covers the interactive forward-scattering grid (¼ of the sample points, half-voxel
/// steps) against the dense reference grid. Measured 0.084; the 90°-turned set gives ~0.60.
const FULL_BOUND: f64 = 0.18;
/// Voxels along the groom's longest side for both forward-scattering grids (half the default:
/// the groom spans ~100 pixels here, and the dense reference's 384 per-light sweeps dominate).
const FORWARD_VOXELS: u32 = 32;
