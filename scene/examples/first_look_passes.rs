//! What the viewer's and the page's first look costs, pass by pass (docs/BENCHMARKS.md, "The
//! viewer's first look"): the default scene's first look at 800×600 (its preview at 400×300) from
//! the coarse tables in CACHE, drawn three times on the process's device. The first draw pays
//! for the renderer's pipelines and the driver's shader compiling; the others are the frame.
//! Any Vulkan driver: SwiftShader, as headless Chromium's WebGPU draws the page, through
//! `VK_ICD_FILENAMES=/usr/lib/chromium/vk_swiftshader_icd.json`.
//!
//!   cargo run --release -p strandlight-scene --example first_look_passes -- [MAP] [CACHE] [WxH]

use anyhow::Context;
use std::path::PathBuf;
use std::time::Instant;
use strandlight_scene::env_frame::frame_sums;
use strandlight_scene::env_lighting::EnvLighting;
use strandlight_scene::env_scene::{AlsoServe, prepare_env};
use strandlight_scene::frame_render::{
    FramePart, Prepared, coarse_preview_settings, first_look, load_settings_hair, submit_frame_into,
};
use strandlight_scene::frame_settings::{FrameSettings, Lighting};
use strandlight_scene::head_input::HeadChoice;
use strandlight_scene::steps::Steps;

fn main() -> anyhow::Result<()> {
    let mut args = std::env::args().skip(1);
    let map = args.next().unwrap_or("procedural:sun_and_sky".into());
    let cache = PathBuf::from(args.next().unwrap_or("out/cache".into()));
    let size = match args.next() {
        Some(text) => {
            let (w, h) = (text.split_once('x'))
                .with_context(|| format!("size {text:?}: expected WxH, e.g. 800x600"))?;
            [w.parse()?, h.parse()?]
        }
        None => [800, 600],
    };
    let mut settings = FrameSettings::new(Lighting::Environment(EnvLighting::new(&map)), size);
    settings.preset = "blonde".into();
    settings.head = HeadChoice::Ellipsoid;
    let hair = load_settings_hair(&settings)?;
    let coarse = coarse_preview_settings(&settings);
    let mut steps = Steps::new(true);
    let prepared = prepare_env(
        &coarse,
        &hair.model,
        &cache,
        AlsoServe::default(),
        &mut steps,
        &mut |_| {},
    )?;
    let (look, look_hair) = first_look(&coarse, &hair.model)?;
    let [width, height] = FramePart::Preview.size(look.size);
    for draw in 1..=3 {
        let started = Instant::now();
        let sums = frame_sums(width, height)?;
        let frame = submit_frame_into(
            &look,
            &look_hair,
            Prepared::Env(&prepared),
            FramePart::Preview,
            &sums,
        )?;
        let wall = started.elapsed().as_secs_f64();
        println!(
            "draw {draw} at {width}x{height} on {}: {wall:.3} s",
            frame.adapter
        );
        for pass in &frame.passes {
            let gpu = pass.gpu_milliseconds.map(|ms| format!(" (GPU {ms:.1} ms)"));
            println!(
                "  {:24} {:8.1} ms{}",
                pass.pass,
                pass.milliseconds,
                gpu.unwrap_or_default()
            );
        }
    }
    Ok(())
}
