//! Cube against frustum for the same far point light on straight.hair: each shadow technique
//! with the CLI's default settings (`point_render_options`), its maps once in the one frustum
//! that holds the hair (what `render lights` uses for this light) and once forced into the cube
//! layout. Configurations are interleaved round by round (load from others on a shared machine
//! falls on all alike); the table gives medians of the frame (passes without pipeline creation
//! and upload) and of the light-map pass, and the cube/frustum ratios of the same run.
//!
//! Run: `cargo run --release -p strandlight-scene --example shadow_layout_bench [ROUNDS]`
//! (`cargo build --release -p strandlight -p strandlight-scene --example shadow_layout_bench`
//! shares the CLI's wgpu build instead of compiling one with the scene crate's features alone).
//! The image is 256² to keep the strand pass, which both layouts share, from drowning the maps.

use glam::Vec3;
use strandlight_runtime::camera::Camera;
use strandlight_runtime::gpu::GpuContext;
use strandlight_runtime::hair;
use strandlight_runtime::lights::Light;
use strandlight_runtime::passes::frame_params::{FrameParams, KajiyaKay};
use strandlight_runtime::point_frame::{RenderOptions, render_frame};
use strandlight_runtime::shadow_layout::{PointLayoutChoice, ShadowLayout};
use strandlight_scene::frame_render::point_render_options;
use strandlight_scene::frame_settings::{PointLighting, Shadows};

const SIZE: u32 = 256;

fn median(values: &mut [f64]) -> f64 {
    values.sort_by(f64::total_cmp);
    let n = values.len();
    if n % 2 == 1 {
        values[n / 2]
    } else {
        0.5 * (values[n / 2 - 1] + values[n / 2])
    }
}

struct Config {
    name: String,
    options: RenderOptions,
    frame_ms: Vec<f64>,
    map_ms: Vec<f64>,
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let rounds: usize = std::env::args()
        .nth(1)
        .map(|s| s.parse())
        .transpose()?
        .unwrap_or(5);
    let Some(path) = strandlight_tables::shared_data::shared_file("hair/straight.hair") else {
        println!("shadow_layout_bench: skipped (hair/straight.hair is not in the shared data)");
        return Ok(());
    };
    let model = hair::load(&path)?.model;
    let bounds = model.bounds();
    // Far in front and above: the box fills a ~22° cone, which one frustum holds.
    let position = bounds.center() + Vec3::new(0.0, 2.0, 1.0) * bounds.diagonal() * 1.2;
    let light = Light::Point {
        position,
        intensity: 2.0 * position.distance_squared(bounds.center()),
    };
    let auto = ShadowLayout::for_light(&light, bounds, PointLayoutChoice::Auto)?;
    assert!(
        !auto.is_cube(),
        "the far light must fit one frustum: {auto:?}"
    );
    let gpu = GpuContext::new_headless()?;
    let frame = FrameParams {
        camera: Camera::framing_from_eye(
            bounds,
            1.0,
            false,
            bounds.center() + Vec3::new(0.0, 3.0, 0.5) * bounds.diagonal(),
            Vec3::Z,
        )?,
        width: SIZE,
        height: SIZE,
        lights: vec![light],
        shading: KajiyaKay::default(),
        width_override_px: None,
    };
    let mut configs = Vec::new();
    for shadows in [Shadows::Dom, Shadows::Osm, Shadows::Sm, Shadows::Adsm] {
        let point = PointLighting {
            shadows,
            ..PointLighting::default()
        };
        for layout in [PointLayoutChoice::Auto, PointLayoutChoice::Cube] {
            let options = RenderOptions {
                point_layout: layout,
                ..point_render_options(&point, &model)
            };
            configs.push(Config {
                name: format!("{shadows:?} {layout:?}"),
                options,
                frame_ms: Vec::new(),
                map_ms: Vec::new(),
            });
        }
    }
    println!(
        "straight.hair, {SIZE}x{SIZE}, light at {position} (far: one frustum holds the hair), \
         {rounds} rounds, adapter {}",
        gpu.report
    );
    for c in &configs {
        render_frame(&gpu, &model, &frame, &c.options)?;
    }
    for round in 0..rounds {
        eprintln!("round {} of {rounds} ...", round + 1);
        for c in &mut configs {
            let out = render_frame(&gpu, &model, &frame, &c.options)?;
            let timings = &out.stats.timings;
            let setup = |p: &str| p.contains("pipeline") || p == "upload";
            c.frame_ms.push(
                timings
                    .iter()
                    .filter(|t| !setup(&t.pass))
                    .map(|t| t.milliseconds)
                    .sum(),
            );
            c.map_ms.push(
                timings
                    .iter()
                    .filter(|t| t.pass.contains("(light "))
                    .map(|t| t.milliseconds)
                    .sum(),
            );
        }
    }
    println!(
        "| technique | layout | frame ms (median) | light map ms (median) | frame cube/frustum |"
    );
    println!("| --- | --- | ---: | ---: | ---: |");
    let medians: Vec<(f64, f64)> = configs
        .iter_mut()
        .map(|c| (median(&mut c.frame_ms), median(&mut c.map_ms)))
        .collect();
    for (i, c) in configs.iter().enumerate() {
        let (frame_ms, map_ms) = medians[i];
        let ratio = if i % 2 == 1 {
            format!("{:.2}", frame_ms / medians[i - 1].0)
        } else {
            String::new()
        };
        let (technique, layout) = c.name.split_once(' ').unwrap_or((&c.name, ""));
        println!("| {technique} | {layout} | {frame_ms:.1} | {map_ms:.1} | {ratio} |");
    }
    Ok(())
}
