//! `strandlight demo`: the procedural groom under the project's own sun-and-sky environment,
//! through fit → bake (cached) → environment-lit render with single and multiple scattering,
//! on a fresh machine with no files of the user's. Writes `out/demo.png` and `out/demo.exr`
//! and prints each step's time.

use anyhow::Context;
use std::path::Path;
use strandlight_precompute::bake_plan::{BakeResolution, FiberDescription};
use strandlight_runtime::camera::{Camera, UpAxis};
use strandlight_runtime::env::EnvRenderOptions;
use strandlight_runtime::hair::{GroomParams, generate_groom};
use strandlight_runtime::image_out::{PNG_TONEMAP, write_exr, write_png};
use strandlight_scene::env_frame::{
    EnvFrame, FrameRole, env_adapter, light_summary, render_lights,
};
use strandlight_scene::env_scene::{EnvSceneRequest, prepare_env_scene};
use strandlight_scene::environment::{ensure_procedural_envmap, load_env};
use strandlight_scene::look::{EnvTransparency, LookArgs};
use strandlight_scene::scene_tables::{EnvShading, ScatteringMode};
use strandlight_scene::steps::Steps;

/// The environment the demo renders under, and where it is written.
pub const DEMO_ENVIRONMENT: &str = "sun_and_sky";
pub const ENVMAP_DIR: &str = "envmaps";
/// Fiber preset (bright enough that multiple scattering is baked and rendered).
pub const DEMO_PRESET: &str = "blonde";
/// Nodes per direction axis of the demo's tables (1/λ gets twice as many): chosen so the bake
/// fits the two-minute budget on 2 cores (docs/BENCHMARKS.md has the timing and the accuracy).
pub const DEMO_TABLE_NODES: usize = 32;
pub const DEMO_SIZE: (u32, u32) = (640, 480);
pub const OUT_DIR: &str = "out";
pub const CACHE_DIR: &str = "out/cache";

#[derive(clap::Args, Debug)]
pub struct DemoArgs {
    /// The nearest fiber of each pixel (opaque, faster), or every fiber weighted by its
    /// visibility through an occupancy map (Ren §8).
    #[arg(long, value_enum, default_value = "occupancy")]
    pub transparency: EnvTransparency,
}

pub fn run(args: DemoArgs) -> anyhow::Result<()> {
    let look = LookArgs {
        transparency: args.transparency,
        ..Default::default()
    }
    .look()?;
    let mut steps = Steps::new(false);
    // Before minutes of fit and bake: a machine without a usable GPU device is told at once.
    steps.run("GPU", env_adapter, |adapter| adapter.clone())?;
    let env = steps
        .run(
            "environment",
            || {
                let (path, written) =
                    ensure_procedural_envmap(Path::new(ENVMAP_DIR), DEMO_ENVIRONMENT)?;
                Ok((load_env(&path.to_string_lossy(), false)?, path, written))
            },
            |(_, p, w)| {
                format!(
                    "{} ({}, read back)",
                    p.display(),
                    if *w {
                        "generated now by procedural_env"
                    } else {
                        "already there"
                    }
                )
            },
        )?
        .0;
    let hair = steps.run(
        "groom",
        || Ok(generate_groom(&GroomParams::default())?),
        |h| format!("procedural groom, {} strands", h.strand_count()),
    )?;
    let fiber = FiberDescription::preset(DEMO_PRESET)?;
    let shading = EnvShading::Marschner;
    let up = UpAxis::detect(&hair);
    let request = EnvSceneRequest {
        env: &env,
        fiber: &fiber,
        shading,
        scattering: ScatteringMode::Full,
        resolution: BakeResolution::reduced(DEMO_TABLE_NODES),
        cache_dir: Path::new(CACHE_DIR),
        table_set: "demo",
        up,
    };
    let scene = prepare_env_scene(&request, &mut steps)?;
    let (lights, mode) = (&scene.lights, scene.mode);
    let (width, height) = DEMO_SIZE;
    let camera = Camera::framing_front(hair.bounds(), width as f32 / height as f32, false, up);
    let frame = EnvFrame {
        hair: &hair,
        camera,
        width,
        height,
        lights,
        tables: &scene.tables,
        shading,
        mode,
        role: FrameRole::Interactive {
            kappa: EnvRenderOptions::default().kappa,
        },
        look,
    };
    let rendered = steps.run(
        "render",
        || render_lights(&frame),
        |r| {
            format!(
                "{:.1} ms/frame, {}, {} scattering, {:?} view",
                r.milliseconds,
                light_summary(lights),
                mode.name(),
                args.transparency
            )
        },
    )?;
    let out = Path::new(OUT_DIR);
    std::fs::create_dir_all(out).with_context(|| format!("cannot create {}", out.display()))?;
    let description = format!(
        "strandlight demo: procedural groom under procedural:{DEMO_ENVIRONMENT}, {}, Marschner ({DEMO_PRESET}), {} scattering",
        light_summary(lights),
        mode.name()
    );
    let (exr, png) = (out.join("demo.exr"), out.join("demo.png"));
    let image = &rendered.image;
    write_exr(&exr, image.width, image.height, &image.pixels, &description)?;
    write_png(&png, image.width, image.height, &image.pixels, &description)?;
    steps.say(format!(
        "wrote {} (linear) and {} ({PNG_TONEMAP}); total {:.1} s",
        exr.display(),
        png.display(),
        steps.total_seconds()
    ));
    Ok(())
}
