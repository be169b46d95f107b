//! Forward-scattering grids on `straight.hair` (Ren 2010 Fig. 6): timings of the voxelization
//! and of the shadow paths for 16 and 50 lights, and a convergence study of T_f and σ̄_f at
//! fixed points on the hair versus sample-grid density, step size and voxel resolution — so
//! the reference renderer can pick a density that has converged.
//!
//! `cargo run --release -p strandlight-runtime --example forward_scattering_convergence`
//! (reads `hair/straight.hair` from the shared data folder; prints why and exits if absent).
//! Tables come from the precompute crate (a dev-dependency) with the bake's layout.

use std::time::Instant;

use glam::Vec3;
use strandlight_precompute::attenuation_ratio::attenuation_ratio_table;
use strandlight_precompute::srbf_spread::srbf_spread_table;
use strandlight_runtime::env_light::EnvLight;
use strandlight_runtime::gpu::GpuContext;
use strandlight_runtime::hair::HairModel;
use strandlight_runtime::multiple::ForwardScatteringSource;
use strandlight_runtime::multiple::shadow_paths::LightMedium;
use strandlight_runtime::multiple::{
    CpuForwardScattering, ForwardScatteringSettings, ForwardScatteringTables, GpuForwardScattering,
    HairVolume, VoxelSettings, interpolate_grid,
};
use strandlight_tables::dual_scattering::{
    DualScatteringAverages, DualScatteringConfig, LobeDecomposition,
};
use strandlight_tables::marschner::{Marschner, MarschnerParams};
use strandlight_tables::table::Table;

/// The `fiber_averages` table as the bake writes it, from Marschner's default fiber.
fn fiber_averages_table(thetas: usize) -> Table {
    let m =
        Marschner::new(MarschnerParams::default()).expect("default Marschner parameters are valid");
    let averages = DualScatteringAverages::new(
        &m as &dyn LobeDecomposition,
        DualScatteringConfig::default(),
    )
    .expect("default dual-scattering configuration is valid");
    strandlight_precompute::bake_plan::fiber_averages_table(&averages, thetas)
        .expect("fiber-average axes are valid")
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Directions spread over the sphere (Fibonacci spiral).
fn sphere_directions(n: usize) -> Vec<Vec3> {
    let golden = std::f32::consts::PI * (3.0 - 5f32.sqrt());
    (0..n)
        .map(|i| {
            let z = 1.0 - 2.0 * (i as f32 + 0.5) / n as f32;
            let r = (1.0 - z * z).sqrt();
            let a = golden * i as f32;
            Vec3::new(r * a.cos(), r * a.sin(), z)
        })
        .collect()
}

/// Every `stride`-th hair point: where shading happens.
fn probe_points(model: &HairModel, count: usize) -> Vec<Vec3> {
    let stride = (model.point_count() / count).max(1);
    model
        .points()
        .iter()
        .step_by(stride)
        .take(count)
        .copied()
        .collect()
}

/// RMS and max of |ΔT| (channel mean) and of |Δσ̄| between two probe sets.
fn differences(a: &[[f32; 4]], b: &[[f32; 4]]) -> (f64, f64, f64, f64) {
    let (mut st, mut mt, mut ss, mut ms) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for (x, y) in a.iter().zip(b) {
        let dt = (0..3).map(|c| (x[c] - y[c]).abs() as f64).sum::<f64>() / 3.0;
        let ds = (x[3] - y[3]).abs() as f64;
        st += dt * dt;
        ss += ds * ds;
        mt = mt.max(dt);
        ms = ms.max(ds);
    }
    let n = a.len().max(1) as f64;
    ((st / n).sqrt(), mt, (ss / n).sqrt(), ms)
}

fn mean_t(v: &[[f32; 4]]) -> (f64, f64) {
    let n = v.len().max(1) as f64;
    (
        v.iter()
            .map(|x| (x[0] + x[1] + x[2]) as f64 / 3.0)
            .sum::<f64>()
            / n,
        v.iter().map(|x| x[3] as f64).sum::<f64>() / n,
    )
}

/// CPU (rayon) vs GPU (compute shader) forward-scattering grids for the same batches: medians
/// of 5 after one warm-up, and the largest difference between the two grids.
fn compare_devices(model: &HairModel, tables: &ForwardScatteringTables) {
    let gpu = match GpuContext::new_headless() {
        Ok(gpu) => gpu,
        Err(e) => return println!("\n## CPU vs GPU march: skipped ({e})"),
    };
    println!(
        "\n## CPU vs GPU march (grid() for a batch of SRBF lights λ=32; median of 5 after a warm-up)"
    );
    println!(
        "GPU: {}; CPU: rayon, {} threads. Both include the per-light table lookups on the CPU.",
        gpu.report,
        rayon::current_num_threads()
    );
    println!(
        "Differences: f32 vs f64 recursions, and positions that round into the neighbouring voxel (nearest-voxel"
    );
    println!("lookups are discontinuous; the shader's division need not round as the CPU's does).");
    println!(
        "| voxels | coarse factor | taps | sample vertices | lights | CPU ms | GPU ms | GPU / CPU | RMS |ΔT_f| | max |ΔT_f| | values with |ΔT_f| > 10⁻³ | max |Δσ̄_f| |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|");
    for &(voxels, coarse, taps) in &[(64u32, 4u32, 2u32), (90, 4, 2), (64, 2, 2), (64, 1, 1)] {
        let settings = ForwardScatteringSettings {
            voxels: VoxelSettings {
                voxels_longest_side: voxels,
                default_diameter: None,
            },
            coarse_factor: coarse,
            filter_taps: taps,
            ..Default::default()
        };
        let cpu = CpuForwardScattering::new(model, tables.clone(), settings).expect("source");
        let vertices = cpu.sample_grid().vertex_count();
        let on_gpu = GpuForwardScattering::new(&gpu, cpu.clone()).expect("GPU source");
        for &count in &[16usize, 50] {
            let lights: Vec<EnvLight> = sphere_directions(count)
                .into_iter()
                .map(|d| EnvLight::srbf(d, 32.0, [1.0; 3]))
                .collect();
            let time = |source: &dyn ForwardScatteringSource| {
                let mut last = source.grid(&lights).expect("grid");
                let times = (0..5)
                    .map(|_| {
                        let t = Instant::now();
                        last = source.grid(&lights).expect("grid");
                        t.elapsed().as_secs_f64() * 1e3
                    })
                    .collect();
                (median(times), last)
            };
            let (cpu_ms, a) = time(&cpu);
            let (gpu_ms, b) = time(&on_gpu);
            let (mut dt, mut ds, mut sum2, mut off) = (0.0f32, 0.0f32, 0.0f64, 0usize);
            for (x, y) in a.values.iter().zip(&b.values) {
                let d = (0..3).map(|c| (x[c] - y[c]).abs()).fold(0.0, f32::max);
                dt = dt.max(d);
                sum2 += (d as f64).powi(2);
                off += (d > 1e-3) as usize;
                ds = ds.max((x[3] - y[3]).abs());
            }
            let n = a.values.len().max(1);
            println!(
                "| {voxels} | {coarse} | {taps}³ | {vertices} | {count} | {cpu_ms:.1} | {gpu_ms:.1} | {:.2} | {:.1e} | {dt:.1e} | {off} of {n} | {ds:.1e} |",
                gpu_ms / cpu_ms,
                (sum2 / n as f64).sqrt()
            );
        }
    }
}

fn main() {
    let Some(path) = strandlight_tables::shared_data::shared_file("hair/straight.hair") else {
        return;
    };
    let model = strandlight_runtime::hair::load(&path)
        .expect("straight.hair loads")
        .model;
    println!(
        "straight.hair: {} strands, {} points, bounds {:?}..{:?}, thickness {:?}; rayon threads {}",
        model.strand_count(),
        model.point_count(),
        model.bounds().min,
        model.bounds().max,
        model.thickness().map(|t| t.at(0)),
        rayon::current_num_threads()
    );
    let t0 = Instant::now();
    let fiber = fiber_averages_table(128);
    let ratio = attenuation_ratio_table(32, 32, 1.0).expect("attenuation ratio table");
    let spread = srbf_spread_table(32, 64, 16.0, 64.0).expect("srbf spread table");
    let tables =
        ForwardScatteringTables::from_tables(&fiber, &ratio, &spread).expect("table shapes");
    println!(
        "tables built in {:.2} s (bake-time work, not part of the runtime)",
        t0.elapsed().as_secs_f64()
    );

    // Optional section names on the command line (voxels, paths, gpu, medium, convergence).
    let only: Vec<String> = std::env::args().skip(1).collect();
    let want = |section: &str| only.is_empty() || only.iter().any(|s| s == section);

    if want("voxels") {
        voxelization_times(&model);
    }
    if want("paths") {
        shadow_path_times(&model, &tables);
    }
    // The same march on the GPU (compute shader) vs rayon: which source the device wants.
    if want("gpu") {
        compare_devices(&model, &tables);
    }
    if want("medium") {
        medium_times(&model, &tables);
    }
    if want("convergence") {
        convergence(&model, &tables);
    }
}

/// Voxelization time (dynamic hair rebuilds it every frame).
fn voxelization_times(model: &HairModel) {
    println!("\n## Voxelization (median of 5)");
    println!(
        "| voxels (longest side) | grid | occupied | voxel side | max σ_t⊥·h | mean σ_t⊥·h (occupied) | median ms |"
    );
    println!("|---|---|---|---|---|---|---|");
    for &n in &[32u32, 64, 90, 128] {
        let settings = VoxelSettings {
            voxels_longest_side: n,
            default_diameter: None,
        };
        let mut times = Vec::new();
        let mut volume = None;
        for _ in 0..5 {
            let t = Instant::now();
            volume = Some(HairVolume::build(model, &settings, 1.0).expect("voxelization"));
            times.push(t.elapsed().as_secs_f64() * 1e3);
        }
        let v = volume.unwrap();
        let h = v.grid.voxel_size;
        let occ: Vec<f32> = v.sigma_perp.iter().copied().filter(|&s| s > 0.0).collect();
        let max = occ.iter().cloned().fold(0.0, f32::max) * h;
        let mean = occ.iter().map(|&s| s as f64).sum::<f64>() / occ.len().max(1) as f64 * h as f64;
        println!(
            "| {n} | {:?} | {} | {h:.4} | {max:.3} | {mean:.3} | {:.1} |",
            v.grid.dims,
            occ.len(),
            median(times)
        );
    }
}

/// Shadow-path time per light batch.
fn shadow_path_times(model: &HairModel, tables: &ForwardScatteringTables) {
    println!(
        "\n## Shadow paths (grid() for a batch; median of 3, one run for the slow per-vertex dense case)"
    );
    println!(
        "| voxels | coarse factor | method | step | lights | kind | sample vertices | batch ms | ms / light |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    let timing_cases = [
        (64u32, 4u32, 2u32, 0.5f32, false),
        (64, 4, 1, 0.5, false),
        (64, 4, 1, 0.5, true),
        (90, 4, 2, 0.5, false),
        (90, 4, 1, 0.5, true),
        (64, 1, 1, 0.25, true),
        (90, 1, 1, 0.25, true),
        (64, 1, 2, 0.25, false),
    ];
    for &(voxels, coarse, taps, step, sweep) in &timing_cases {
        let settings = ForwardScatteringSettings {
            voxels: VoxelSettings {
                voxels_longest_side: voxels,
                default_diameter: None,
            },
            coarse_factor: coarse,
            step_fraction: step,
            filter_taps: taps,
            light_sweep: sweep,
            ..Default::default()
        };
        let source = CpuForwardScattering::new(model, tables.clone(), settings).expect("source");
        for &count in &[16usize, 50] {
            if coarse == 1 && !sweep && count == 50 {
                continue; // per-vertex marching of the dense grid is timed with 16 lights only
            }
            for srbf in [true, false] {
                let lights: Vec<EnvLight> = sphere_directions(count)
                    .into_iter()
                    .map(|d| {
                        if srbf {
                            EnvLight::srbf(d, 32.0, [1.0; 3])
                        } else {
                            EnvLight::directional(d, [1.0; 3])
                        }
                    })
                    .collect();
                let mut times = Vec::new();
                let reps = if coarse == 1 && !sweep { 1 } else { 3 };
                for _ in 0..reps {
                    let t = Instant::now();
                    let grid = source.grid(&lights).expect("grid");
                    times.push(t.elapsed().as_secs_f64() * 1e3);
                    assert!(grid.values.iter().all(|v| v.iter().all(|x| x.is_finite())));
                }
                let ms = median(times);
                let method = if sweep {
                    "light sweep".to_string()
                } else {
                    format!("march, {taps}³ taps")
                };
                println!(
                    "| {voxels} | {coarse} | {method} | {step} | {count} | {} | {} | {ms:.1} | {:.2} |",
                    if srbf { "SRBF λ=32" } else { "directional" },
                    source.sample_grid().vertex_count(),
                    ms / count as f64
                );
            }
        }
    }
}

/// Where a light's time goes: the per-voxel table lookups (LightMedium) vs the paths.
fn medium_times(model: &HairModel, tables: &ForwardScatteringTables) {
    println!("\n## Per-light table lookups (LightMedium::new, median of 5)");
    println!("| voxels | occupied | ms |");
    println!("|---|---|---|");
    for &voxels in &[64u32, 90] {
        let settings = VoxelSettings {
            voxels_longest_side: voxels,
            default_diameter: None,
        };
        let volume = HairVolume::build(model, &settings, 1.0).expect("voxelization");
        let light = EnvLight::srbf(Vec3::new(0.3, 0.5, 0.8), 32.0, [1.0; 3]);
        let times: Vec<f64> = (0..5)
            .map(|_| {
                let t = Instant::now();
                let m = LightMedium::new(&volume, tables, &light);
                std::hint::black_box(&m);
                t.elapsed().as_secs_f64() * 1e3
            })
            .collect();
        println!(
            "| {voxels} | {} | {:.1} |",
            volume.occupied_voxels(),
            median(times)
        );
    }
}

/// The march settings of a convergence row (marched per sample vertex, no light sweep).
fn march(voxels: u32, coarse: u32, step: f32, taps: u32) -> ForwardScatteringSettings {
    ForwardScatteringSettings {
        voxels: VoxelSettings {
            voxels_longest_side: voxels,
            default_diameter: None,
        },
        coarse_factor: coarse,
        step_fraction: step,
        filter_taps: taps,
        light_sweep: false,
        ..ForwardScatteringSettings::default()
    }
}

/// [`march`] with the light sweep.
fn swept(voxels: u32, coarse: u32, step: f32) -> ForwardScatteringSettings {
    ForwardScatteringSettings {
        light_sweep: true,
        ..march(voxels, coarse, step, 1)
    }
}

/// Fixed points on the hair and directional lights, where the convergence sections compare
/// sources.
struct Probe<'a> {
    model: &'a HairModel,
    tables: &'a ForwardScatteringTables,
    points: Vec<Vec3>,
    lights: Vec<EnvLight>,
}

impl Probe<'_> {
    fn source(&self, settings: ForwardScatteringSettings) -> CpuForwardScattering {
        CpuForwardScattering::new(self.model, self.tables.clone(), settings).expect("source")
    }

    /// `settings`' values evaluated at the points themselves.
    fn values(&self, settings: ForwardScatteringSettings) -> Vec<[f32; 4]> {
        let source = self.source(settings);
        (self.lights.iter())
            .flat_map(|l| source.values_at(l, &self.points))
            .collect()
    }

    /// The source's grid interpolated at the points.
    fn grid_values(&self, source: &CpuForwardScattering) -> Vec<[f32; 4]> {
        let grid = source.grid(&self.lights).expect("grid");
        (0..self.lights.len())
            .flat_map(|l| self.points.iter().map(move |&p| (l, p)))
            .map(|(l, p)| interpolate_grid(&grid, l, p).expect("light index within the batch"))
            .collect()
    }

    /// A table's rows: per setting, its values' differences from `reference`.
    fn rows<T: std::fmt::Display>(
        &self,
        settings: impl IntoIterator<Item = (T, ForwardScatteringSettings)>,
        reference: &[[f32; 4]],
    ) {
        for (name, settings) in settings {
            let (a, b, c, d) = differences(&self.values(settings), reference);
            println!("| {name} | {a:.4} | {b:.4} | {c:.4} | {d:.4} |");
        }
    }
}

/// Convergence at fixed points on the hair.
fn convergence(model: &HairModel, tables: &ForwardScatteringTables) {
    let probe = Probe {
        model,
        tables,
        points: probe_points(model, 1000),
        lights: sphere_directions(8)
            .into_iter()
            .map(|d| EnvLight::directional(d, [1.0; 3]))
            .collect(),
    };
    let exact = grid_densities(&probe);
    light_sweep_grids(&probe, &exact);
    step_sizes(&probe);
    voxel_resolutions(&probe);
    box_filters(&probe);
}

/// Grids of several densities against the march evaluated at each point itself (an infinitely
/// dense sample grid), which it returns.
fn grid_densities(probe: &Probe) -> Vec<[f32; 4]> {
    println!(
        "\n## Convergence vs sample-grid density ({} hair points × {} directional lights, 64 voxels, step 0.5, taps 2)",
        probe.points.len(),
        probe.lights.len()
    );
    println!(
        "Reference: the march evaluated at each point itself (an infinitely dense sample grid)."
    );
    let exact = probe.values(march(64, 4, 0.5, 2));
    let (mt, ms) = mean_t(&exact);
    println!("mean T_f at the probes {mt:.4}, mean σ̄_f {ms:.4} rad");
    println!("| coarse factor | vertices | RMS ΔT_f | max ΔT_f | RMS Δσ̄_f | max Δσ̄_f |");
    println!("|---|---|---|---|---|---|");
    for &coarse in &[8u32, 4, 2, 1] {
        let s = probe.source(march(64, coarse, 0.5, 2));
        let (a, b, c, d) = differences(&probe.grid_values(&s), &exact);
        println!(
            "| {coarse} | {} | {a:.4} | {b:.4} | {c:.4} | {d:.4} |",
            s.sample_grid().vertex_count()
        );
    }
    exact
}

fn light_sweep_grids(probe: &Probe, exact: &[[f32; 4]]) {
    println!("\n## Light-sweep grids vs the same per-point reference (64 voxels, step 0.5)");
    println!("| coarse factor | vertices | RMS ΔT_f | max ΔT_f | RMS Δσ̄_f | max Δσ̄_f |");
    println!("|---|---|---|---|---|---|");
    for &coarse in &[4u32, 2, 1] {
        let s = probe.source(swept(64, coarse, 0.5));
        let (a, b, c, d) = differences(&probe.grid_values(&s), exact);
        println!(
            "| {coarse} | {} | {a:.4} | {b:.4} | {c:.4} | {d:.4} |",
            s.sample_grid().vertex_count()
        );
    }
    println!("light sweep evaluated at the probes themselves (no grid):");
    let (a, b, c, d) = differences(&probe.values(swept(64, 4, 0.5)), exact);
    println!("| at probes | - | {a:.4} | {b:.4} | {c:.4} | {d:.4} |");
}

fn step_sizes(probe: &Probe) {
    println!(
        "\n## Convergence vs step size (values at the probes, 64 voxels, taps 2; reference step 1/16 voxel)"
    );
    let reference = probe.values(march(64, 4, 1.0 / 16.0, 2));
    println!("| step (voxels) | RMS ΔT_f | max ΔT_f | RMS Δσ̄_f | max Δσ̄_f |");
    println!("|---|---|---|---|---|");
    let steps = [1.0f32, 0.5, 0.25, 0.125].map(|step| (step, march(64, 4, step, 2)));
    probe.rows(steps, &reference);
}

fn voxel_resolutions(probe: &Probe) {
    println!(
        "\n## Convergence vs voxel resolution (values at the probes, step 0.25, taps 2; reference 128 voxels)"
    );
    let reference = probe.values(march(128, 4, 0.25, 2));
    println!("| voxels | RMS ΔT_f | max ΔT_f | RMS Δσ̄_f | max Δσ̄_f | mean T_f |");
    println!("|---|---|---|---|---|---|");
    for &voxels in &[32u32, 64, 90] {
        let v = probe.values(march(voxels, 4, 0.25, 2));
        let (a, b, c, d) = differences(&v, &reference);
        println!(
            "| {voxels} | {a:.4} | {b:.4} | {c:.4} | {d:.4} | {:.4} |",
            mean_t(&v).0
        );
    }
}

fn box_filters(probe: &Probe) {
    println!("\n## Box filter (values at the probes, 64 voxels, step 0.25): taps vs taps 4");
    let reference = probe.values(march(64, 4, 0.25, 4));
    println!("| taps per axis | RMS ΔT_f | max ΔT_f | RMS Δσ̄_f | max Δσ̄_f |");
    println!("|---|---|---|---|---|");
    let taps = [1u32, 2, 3].map(|taps| (taps, march(64, 4, 0.25, taps)));
    probe.rows(taps, &reference);
}
