//! `strandlight demo`: the procedural groom under the project's own sun-and-sky environment,
//! through fit → bake (cached) → environment-lit render with single and multiple scattering,
//! on a fresh machine with no files of the user's. Writes a first look from coarse tables
//! (`out/demo-preview.png`) within seconds, then `out/demo.png` and `out/demo.exr`, and prints
//! each step's time.

use anyhow::Context;
use std::path::Path;
use strandlight_runtime::hair::HairModel;
use strandlight_scene::env_frame::{env_adapter, light_summary};
use strandlight_scene::env_scene::{AlsoServe, prepare_env};
use strandlight_scene::environment::{ensure_procedural_envmap, load_env};
use strandlight_scene::exposure::{Exposure, exposure_problem};
use strandlight_scene::frame_render::{
    FrameDetails, FramePart, Prepared, coarse_preview_settings, first_look, load_settings_hair,
    render_frame,
};
use strandlight_scene::frame_settings::{EnvLighting, FrameSettings, Lighting};
use strandlight_scene::head_input::HeadChoice;
use strandlight_scene::look::EnvTransparency;
use strandlight_scene::point_shading::Shading;
use strandlight_scene::scene_tables::ScatteringMode;
use strandlight_scene::steps::Steps;
use strandlight_tables::image_out::{png_tonemap, write_exr, write_png_exposed};

/// The environment the demo renders under, and where it is written.
pub const DEMO_ENVIRONMENT: &str = "sun_and_sky";
pub const ENVMAP_DIR: &str = "envmaps";
/// Fiber preset (bright enough that multiple scattering is baked and rendered).
pub const DEMO_PRESET: &str = "blonde";
/// The demo's fiber: Chiang's, the model the path-traced truth renders, so the demo shows what
/// `bench --truth` measures (Marschner's has no path-traced twin).
pub const DEMO_SHADING: Shading = Shading::Chiang;
/// The demo's head: the ellipsoid the procedural groom grows from (fitted to its roots).
pub const DEMO_HEAD: HeadChoice = HeadChoice::Ellipsoid;
/// Nodes per direction axis of the demo's tables (1/λ gets twice as many): chosen so the bake
/// fits the two-minute budget on 2 cores (docs/BENCHMARKS.md has the timing and the accuracy).
pub const DEMO_TABLE_NODES: usize = 32;
pub const DEMO_SIZE: (u32, u32) = (640, 480);
pub const OUT_DIR: &str = "out";
pub const CACHE_DIR: &str = "out/cache";

#[derive(clap::Args, Debug)]
pub struct DemoArgs {
    /// Every fiber weighted by its visibility through an occupancy map (Ren §8), shaded in 4
    /// layers per pixel (layered) or one by one (occupancy), or the nearest fiber of each pixel
    /// (opaque, fastest).
    #[arg(long, value_enum, default_value = "layered")]
    pub transparency: EnvTransparency,
}

pub fn run(args: DemoArgs) -> anyhow::Result<()> {
    let mut steps = Steps::new(false);
    // Before minutes of fit and bake: a machine without a usable GPU device is told at once.
    steps.run("GPU", env_adapter, |adapter| adapter.clone())?;
    let env_path = steps
        .run(
            "environment",
            || {
                let (path, written) =
                    ensure_procedural_envmap(Path::new(ENVMAP_DIR), DEMO_ENVIRONMENT)?;
                // Read back here, so that a map that did not write is told before the groom.
                load_env(&path.to_string_lossy(), false)?;
                Ok((path, written))
            },
            |(p, w)| {
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
        )
        .map(|(path, _)| path)?;
    let settings = demo_settings(&env_path.to_string_lossy(), args.transparency);
    let hair = steps.run(
        "groom",
        || load_settings_hair(&settings),
        |h| format!("{}, {} strands", h.source, h.model.strand_count()),
    )?;
    let out = Path::new(OUT_DIR);
    std::fs::create_dir_all(out).with_context(|| format!("cannot create {}", out.display()))?;
    write_first_look(&settings, &hair.model, &mut steps)?;
    let prepared = prepare_env(
        &settings,
        &hair.model,
        Path::new(CACHE_DIR),
        AlsoServe::default(),
        &mut steps,
        &mut |_| {},
    )?;
    let rendered = steps.run(
        "render",
        || {
            render_frame(
                &settings,
                &hair.model,
                Prepared::Env(&prepared),
                FramePart::Whole,
                false,
            )
        },
        |r| {
            format!(
                "{:.1} ms/frame, {:?} view",
                r.milliseconds, args.transparency
            )
        },
    )?;
    let FrameDetails::Env { lights, mode, .. } = &rendered.details else {
        anyhow::bail!("the demo is env-lit");
    };
    let description = format!(
        "strandlight demo: {} under procedural:{DEMO_ENVIRONMENT}, {}, {DEMO_SHADING:?} ({DEMO_PRESET}), {} scattering",
        hair.source,
        light_summary(lights),
        mode.name()
    );
    let (exr, png) = (out.join("demo.exr"), out.join("demo.png"));
    let image = &rendered.image;
    write_exr(&exr, image.width, image.height, &image.pixels, &description)?;
    // Metered on the hair and skin, as the viewer and `render` do: the sun and sky would wash
    // them out.
    let stops = Exposure::Auto.stops_for(&image.pixels);
    write_png_exposed(
        &png,
        image.width,
        image.height,
        &image.pixels,
        stops,
        &description,
    )?;
    if let Some(problem) = exposure_problem(&image.pixels, Exposure::Auto, stops) {
        eprintln!("warning: {}: {problem}", png.display());
    }
    steps.say(format!(
        "{}, {} scattering; wrote {} (linear) and {} ({}); total {:.1} s",
        light_summary(lights),
        mode.name(),
        exr.display(),
        png.display(),
        png_tonemap(stops),
        steps.total_seconds()
    ));
    Ok(())
}

/// Where the first look is written.
pub const FIRST_LOOK_PNG: &str = "out/demo-preview.png";

/// A first look before the full tables bake: the demo's frame as the viewer and the page
/// preview it ([`first_look`]: half size, the strongest lights, single scattering, the nearest
/// fiber of a thinned groom) from coarse tables, which bake in seconds on a cold cache. The
/// full frame follows in `out/demo.png`.
fn write_first_look(
    settings: &FrameSettings,
    hair: &HairModel,
    steps: &mut Steps,
) -> anyhow::Result<()> {
    let coarse = coarse_preview_settings(settings);
    let prepared = prepare_env(
        &coarse,
        hair,
        Path::new(CACHE_DIR),
        AlsoServe::default(),
        steps,
        &mut |_| {},
    )?;
    // The viewer's and the page's first look: a thinned groom seen by the whole groom's camera.
    let (look, look_hair) = first_look(&coarse, hair)?;
    let preview = steps.run(
        "first look",
        || {
            render_frame(
                &look,
                &look_hair,
                Prepared::Env(&prepared),
                FramePart::Preview,
                false,
            )
        },
        |r| format!("{:.1} ms/frame", r.milliseconds),
    )?;
    let (image, path) = (&preview.image, Path::new(FIRST_LOOK_PNG));
    let stops = Exposure::Auto.stops_for(&image.pixels);
    let description = "strandlight demo, first look: coarse tables, single scattering";
    write_png_exposed(
        path,
        image.width,
        image.height,
        &image.pixels,
        stops,
        description,
    )?;
    steps.say(format!(
        "wrote {} ({}x{}, coarse tables) {:.1} s after the start; the full frame follows",
        path.display(),
        image.width,
        image.height,
        steps.total_seconds()
    ));
    Ok(())
}

/// The demo as frame settings: the procedural groom's default style on its head, framed from
/// the front, `DEMO_SHADING` `DEMO_PRESET` fibers, single and multiple scattering under the map
/// at `map`.
fn demo_settings(map: &str, transparency: EnvTransparency) -> FrameSettings {
    let lighting = EnvLighting {
        scattering: ScatteringMode::Full,
        transparency,
        table_resolution: Some(DEMO_TABLE_NODES),
        ..EnvLighting::new(map)
    };
    FrameSettings {
        shading: Some(DEMO_SHADING),
        preset: DEMO_PRESET.into(),
        head: DEMO_HEAD,
        ..FrameSettings::new(Lighting::Environment(lighting), [DEMO_SIZE.0, DEMO_SIZE.1])
    }
}
