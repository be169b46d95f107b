//! Cost of the env-lit single-scattering path (Ren 2010 §8): frame time vs the number of SRBF
//! lights (fixed image) and vs the image size (fixed lights), for the opaque and the occupancy
//! (transparent) view, on the procedural groom, with synthetic RGB tables of the convolution
//! tables' paper size (32³ × 64 nodes). Is the cost linear in the lights and in the fragments
//! shaded (counted by the renderer)?
//!
//! Each configuration renders once to warm up, then `TIMED_RUNS` times; the table gives medians
//! of the renderer's own per-pass wall-clock timings (summed over batches), pipelines built once
//! (`EnvRenderer`).
//!
//! Run: `cargo run --release -p strandlight-runtime --example env_bench [TIMED_RUNS]`

use glam::Vec3;
use strandlight_runtime::camera::Camera;
use strandlight_runtime::env::{EnvRenderOptions, EnvRenderer, EnvTables, ViewTransparency};
use strandlight_runtime::env_light::EnvLight;
use strandlight_runtime::gpu::GpuContext;
use strandlight_runtime::hair::groom::{GroomParams, generate_groom};
use strandlight_runtime::passes::convolution_depth::DodmSettings;
use strandlight_tables::hard_case_sweep::SweepRng;
use strandlight_tables::table::{Axis, Table};
use strandlight_tables::table_axes::{
    AXIS_COS_DPHI, AXIS_INV_LAMBDA, AXIS_U_DOT_WO, AXIS_U_DOT_XI,
};

type BoxError = Box<dyn std::error::Error>;

fn median(values: &mut [f64]) -> f64 {
    values.sort_by(f64::total_cmp);
    let n = values.len();
    if n % 2 == 1 {
        values[n / 2]
    } else {
        0.5 * (values[n / 2 - 1] + values[n / 2])
    }
}

fn table() -> Result<Table, BoxError> {
    let axes = vec![
        Axis::uniform(AXIS_U_DOT_XI, -1.0, 1.0, 32),
        Axis::uniform(AXIS_U_DOT_WO, -1.0, 1.0, 32),
        Axis::uniform(AXIS_COS_DPHI, -1.0, 1.0, 32),
        Axis::uniform(AXIS_INV_LAMBDA, 1.0 / 64.0, 1.0 / 16.0, 64),
    ];
    Ok(Table::from_fn(axes, 3, |x, out| {
        let v = (1.0 + x[0] * x[1]).abs() * (1.5 + x[2]) * (1.0 + 10.0 * x[3]);
        out.fill(v as f32);
    })?)
}

fn lights(n: usize) -> Vec<EnvLight> {
    let mut rng = SweepRng::new(5);
    (0..n)
        .map(|_| {
            let z = rng.range(-1.0, 1.0) as f32;
            let phi = rng.range(0.0, std::f64::consts::TAU) as f32;
            let r = (1.0 - z * z).sqrt();
            EnvLight::srbf(
                Vec3::new(r * phi.cos(), z, r * phi.sin()),
                rng.range(16.0, 64.0) as f32,
                [0.3; 3],
            )
        })
        .collect()
}

fn main() -> Result<(), BoxError> {
    let runs: usize = std::env::args()
        .nth(1)
        .map(|a| a.parse())
        .transpose()?
        .unwrap_or(3);
    let gpu = GpuContext::new_headless()?;
    let model = generate_groom(&GroomParams {
        strand_count: 2000,
        ..Default::default()
    })?;
    let tables = EnvTables {
        srbf: Some(table()?.into()),
        ..Default::default()
    };
    let renderer = EnvRenderer::new(&gpu);
    let base = EnvRenderOptions {
        dodm: DodmSettings {
            resolution: 256,
            first_layer: None,
            batch_size: 16,
        },
        count_fragments: true,
        ..Default::default()
    };
    println!("adapter: {}", gpu.report);
    println!(
        "model: {} strands, {} segments; DODM 256², batch 16, κ = {}",
        model.strand_count(),
        model.segment_count(),
        base.kappa
    );
    println!(
        "| view | lights | image | shaded fragments (per batch) | light pass ms | SAT ms | visibility ms | view ms | frame ms | frame ms / light | view µs / (light · 1k shaded fragments) |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    let mut configs: Vec<(usize, u32)> = [4, 8, 16, 32, 64].iter().map(|&n| (n, 256)).collect();
    configs.extend([(16, 128), (16, 512)]);
    for (name, transparency) in [
        ("opaque", ViewTransparency::Opaque),
        ("occupancy", ViewTransparency::occupancy()),
    ] {
        let options = EnvRenderOptions {
            transparency,
            ..base
        };
        for &(n, size) in &configs {
            let camera = Camera::framing(model.bounds(), 1.0, false);
            let ls = lights(n);
            let mut per_pass: Vec<(String, Vec<f64>)> = Vec::new();
            let mut shaded = 0;
            for run in 0..=runs {
                let frame = renderer.render(
                    &gpu, &model, &camera, size, size, &ls, &tables, &options, None,
                )?;
                shaded = frame.stats.fragments.map_or(0, |f| f.shaded);
                if run == 0 {
                    continue;
                }
                for t in frame.stats.timings {
                    match per_pass.iter_mut().find(|(p, _)| *p == t.pass) {
                        Some((_, v)) => v.push(t.milliseconds),
                        None => per_pass.push((t.pass, vec![t.milliseconds])),
                    }
                }
            }
            let mut ms = |name: &str| {
                per_pass
                    .iter_mut()
                    .find(|(p, _)| p == name)
                    .map_or(0.0, |(_, v)| median(v))
            };
            let (light, sat, visibility, view) = (
                ms("light pass"),
                ms("summed-area tables"),
                ms("view visibility"),
                ms("view"),
            );
            let frame = light + sat + visibility + view + ms("readback");
            println!(
                "| {name} | {n} | {size}² | {shaded} | {light:.1} | {sat:.1} | {visibility:.1} | {view:.1} | {frame:.1} | {:.2} | {:.2} |",
                frame / n as f64,
                view * 1e3 / (n as f64 * shaded as f64 / 1e3)
            );
        }
    }
    Ok(())
}
