//! `strandlight render env|lights|replay`: one headless frame of a hair model under an
//! environment map or point lights, written as a linear EXR and a tonemapped PNG, with timings
//! and GPU memory on request.

use anyhow::{Context, bail};
use clap::{Args, Subcommand};
use std::io::Write;
use std::path::{Path, PathBuf};
use strandlight_runtime::point_frame::PassTiming;
use strandlight_scene::camera_choice::{CameraChoice, CameraKind, UpChoice};
use strandlight_scene::env_frame::{env_adapter, light_summary};
use strandlight_scene::env_scene::{AlsoServe, prepare_env};
use strandlight_scene::exposure::{Exposure, ExposureProblem, exposure_problem};
use strandlight_scene::frame_render::{
    FrameDetails, FrameHair, FramePart, Prepared, RenderedFrame, load_settings_hair, prepare_point,
    render_frame,
};
use strandlight_scene::frame_settings::{
    CameraSettings, DEFAULT_LIGHT, EnvLighting, FrameSettings, Lighting, PointLighting, Shadows,
    Transparency,
};
use strandlight_scene::hair_input::parse_size;
use strandlight_scene::head_input::HeadChoice;
use strandlight_scene::look::LookArgs;
use strandlight_scene::point_shading::{Shading, read_artist_params};
use strandlight_scene::scene_tables::ScatteringMode;
use strandlight_scene::steps::Steps;
use strandlight_tables::atomic_write::write_atomically;
use strandlight_tables::image_out::{png_tonemap, write_exr, write_png_exposed};

/// `render env`, `render lights` or `render replay`: each lighting has its own flags, so no
/// flag belongs to two renderers.
#[derive(Args, Debug)]
pub struct RenderArgs {
    #[command(subcommand)]
    what: RenderWhat,
}

#[derive(Subcommand, Debug)]
enum RenderWhat {
    /// Under an environment map: SRBF fit and tables (both cached under out/cache), Ren 2010's
    /// env-lit frame.
    Env(EnvArgs),
    /// Under directional, point or spot lights, with the theses' shadow and transparency
    /// techniques.
    Lights(LightsArgs),
    /// Exactly the settings of a JSON file: the sidecar of a viewer screenshot.
    Replay(ReplayArgs),
}

/// What every frame needs: the hair, its fiber, the image and the camera.
#[derive(Args, Debug)]
#[command(next_help_heading = "Scene")]
struct SceneArgs {
    /// Hair file (.hair, .tfx, .data, .ply, USD .usda/.usdc/.usdz BasisCurves, Alembic .abc ICurves); the procedural groom when omitted.
    #[arg(long)]
    hair: Option<PathBuf>,
    /// Fiber model (default: kajiya-kay under lights, chiang under an environment).
    #[arg(long, value_enum)]
    shading: Option<Shading>,
    /// Melanin preset of the Marschner and Chiang fibers: dark, brown, blonde, ...
    #[arg(long, default_value = "brown")]
    preset: String,
    /// JSON file of artist-model controls (--shading artist; default: the built-in light brown).
    #[arg(long)]
    artist_params: Option<PathBuf>,
    /// Image size WxH in pixels.
    #[arg(long, default_value = "512x512")]
    size: String,
    /// The default camera frames the hair's bounds from the front (see --up and --eye).
    #[arg(long, value_enum, default_value = "perspective")]
    camera: CameraKind,
    /// The file's up axis; auto: Z when the strands hang along −z (Yuksel's .hair files), else Y.
    /// The front (face side) is +z for Y-up and +y for Z-up.
    #[arg(long, value_enum, default_value = "auto")]
    up: UpChoice,
    /// Camera position X,Y,Z looking at the hair's centre (default: in front, framing the hair).
    #[arg(long)]
    eye: Option<String>,
    /// Every fiber this many pixels wide (default: the file's thickness, projected).
    #[arg(long)]
    fiber_width_px: Option<f32>,
    /// The head the hair grows from: none, ellipsoid (fitted to the strand roots) or a mesh FILE:
    /// .obj (in the hair's units and frame), .glb/.gltf or .usd/.usda/.usdc/.usdz (every mesh in
    /// the scene, Y up in centimetres as USD grooms are); it hides the hair behind it, is drawn
    /// as diffuse skin and shadows every light. Several files, comma-separated, make one head
    /// (a character's skin, eyes and lashes).
    #[arg(
        long,
        default_value = "none",
        value_name = "none|ellipsoid|FILE[,FILE...]"
    )]
    head: HeadChoice,
}

/// Where the frame goes.
#[derive(Args, Debug)]
#[command(next_help_heading = "Output")]
struct OutputArgs {
    /// Output stem: writes STEM.exr (linear), STEM.png (tonemapped) and STEM.json (the
    /// settings, for `render replay`).
    #[arg(long, default_value = "render")]
    out: PathBuf,
    /// Print adapter, per-pass milliseconds and GPU memory as JSON.
    #[arg(long)]
    json: bool,
    /// The PNG's exposure: auto (metered on the hair's pixels) or stops (0: the radiance as is);
    /// the EXR is always the linear radiance.
    #[arg(long, default_value = "auto")]
    exposure: Exposure,
}

#[derive(Args, Debug)]
struct EnvArgs {
    /// A .hdr/.exr map or procedural:NAME, fitted with SRBFs (cached).
    #[arg(long, value_name = "MAP")]
    env: String,
    /// Single scattering, or full (single + multiple; skipped for dark hair).
    #[arg(long, value_enum, default_value = "full")]
    scattering: ScatteringMode,
    /// Fraction of the strands drawn into the light maps (Ren §7; 1 = all).
    #[arg(long, default_value_t = 0.1)]
    kappa: f32,
    /// Only the N most powerful SRBF lobes (a fit's compact sources are kept); default: all.
    #[arg(long, value_name = "N")]
    strongest_lobes: Option<usize>,
    /// The environment turned about the hair's up axis, degrees: map azimuth φ moves to φ + DEG
    /// (scene/src/env_orientation.rs; the fitted lobes are turned exactly, nothing is refitted).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    rotate: f32,
    /// Side of each light's convolution optical depth map, texels; a compact source holding
    /// at least a quarter of the map's power draws its map at four times the side (at most
    /// 2048; docs/history/benchmarks-2026-12-05-to-12-06.md, "Fine maps for dominant suns").
    #[arg(long, default_value_t = 512)]
    light_map_size: u32,
    /// The head's skin: diffuse albedo, linear R,G,B each in [0, 1].
    #[arg(long, value_name = "R,G,B")]
    skin: Option<String>,
    #[command(flatten)]
    look: LookArgs,
    #[command(flatten)]
    scene: SceneArgs,
    #[command(flatten)]
    output: OutputArgs,
}

#[derive(Args, Debug)]
struct LightsArgs {
    /// Repeatable: directional:X,Y,Z[:I] (toward the light), point:X,Y,Z[:I],
    /// spot:X,Y,Z:DX,DY,DZ:HALF_ANGLE_DEGREES[:I].
    #[arg(long = "light", default_value = DEFAULT_LIGHT)]
    lights: Vec<String>,
    #[command(flatten)]
    shadows: ShadowArgs,
    #[command(flatten)]
    transparency: TransparencyArgs,
    #[command(flatten)]
    scene: SceneArgs,
    #[command(flatten)]
    output: OutputArgs,
}

/// The shadow technique of `render lights` and its parameters.
#[derive(Args, Debug)]
#[command(next_help_heading = "Shadows")]
struct ShadowArgs {
    #[arg(long, value_enum, default_value = "none")]
    shadows: Shadows,
    /// Side of every shadow technique's light map, texels.
    #[arg(long, default_value_t = 512)]
    light_map_size: u32,
    /// Percentage-closer filter of every light map, texels per side (odd, 1..=9).
    #[arg(long, default_value_t = strandlight_scene::frame_settings::DEFAULT_PCF_KERNEL)]
    pcf: u32,
    /// Depth layers of the layered light maps: deep opacity map layers with --shadows dom
    /// (1..=32, default 4), opacity shadow map slices with --shadows osm (1..=32, default 16).
    #[arg(long, value_name = "N")]
    layers: Option<u32>,
    /// World units between depth layers along the light: deep opacity map layers with --shadows
    /// dom, ADSM's assumed fibers with --shadows adsm (default: 1% of the hair's bounding-box
    /// diagonal).
    #[arg(long)]
    layer_spacing: Option<f32>,
    /// Shadow map and ADSM depth bias along the light, world units (default: two map texels).
    #[arg(long)]
    shadow_bias: Option<f32>,
    /// ADSM: opacity of one fiber, in (0, 1).
    #[arg(long, default_value_t = strandlight_scene::frame_settings::DEFAULT_ADSM_ALPHA)]
    adsm_alpha: f32,
}

/// The transparency technique of `render lights` and its parameters. Its finer settings (the
/// sorted blend's depth bins, the A-buffer's node pool, sized exactly by default) are read from
/// a settings file: `render replay`.
#[derive(Args, Debug)]
#[command(next_help_heading = "Transparency")]
struct TransparencyArgs {
    #[arg(long, value_enum, default_value = "none")]
    transparency: Transparency,
    /// K-buffer (--transparency kbuffer): fragments kept per pixel, nearest first.
    #[arg(long, default_value_t = strandlight_scene::frame_settings::DEFAULT_KBUFFER_K)]
    kbuffer_k: u32,
    /// Random subsets (--transparency subsets): how many (1..=16).
    #[arg(long, default_value_t = strandlight_runtime::passes::random_subsets::DEFAULT_SUBSETS)]
    subsets: u32,
    /// DBK layer depth Δ in world units (default: 5% of the hair's bounding-box diagonal).
    #[arg(long)]
    dbk_delta: Option<f32>,
}

#[derive(Args, Debug)]
struct ReplayArgs {
    /// The settings JSON (a viewer screenshot's sidecar, or one written by hand).
    #[arg(value_name = "SETTINGS_JSON")]
    settings: PathBuf,
    #[command(flatten)]
    output: OutputArgs,
}

/// Before the render, not after it: a missing folder is made, and one that cannot be is
/// reported before minutes of work are spent.
fn create_output_dir(out: &Path) -> anyhow::Result<()> {
    match out.parent().filter(|p| !p.as_os_str().is_empty()) {
        Some(dir) => std::fs::create_dir_all(dir)
            .with_context(|| format!("creating the output folder {}", dir.display())),
        None => Ok(()),
    }
}

/// `render.exr` → `render`: the stem may be given with either extension.
fn output_stem(out: &Path) -> PathBuf {
    match out.extension().and_then(|e| e.to_str()) {
        Some("exr" | "png") => out.with_extension(""),
        _ => out.to_path_buf(),
    }
}

fn parse_vec3(flag: &str, text: &str) -> anyhow::Result<[f32; 3]> {
    let values = text
        .split(',')
        .map(|s| s.trim().parse::<f32>().ok().filter(|v| v.is_finite()))
        .collect::<Option<Vec<f32>>>();
    match values.as_deref() {
        Some(&[x, y, z]) => Ok([x, y, z]),
        _ => bail!("{flag} {text:?}: expected three finite numbers X,Y,Z"),
    }
}

/// The camera `--camera`, `--up` and `--eye` ask for.
fn camera_choice(scene: &SceneArgs) -> anyhow::Result<CameraChoice> {
    let eye = scene
        .eye
        .as_deref()
        .map(|text| parse_vec3("--eye", text))
        .transpose()?;
    Ok(CameraChoice {
        kind: scene.camera,
        up: scene.up,
        eye,
    })
}

/// The frame `scene`'s flags describe, lit by `lighting`.
fn frame_settings(scene: &SceneArgs, lighting: Lighting) -> anyhow::Result<FrameSettings> {
    let (width, height) = parse_size(&scene.size)?;
    Ok(FrameSettings {
        hair: scene.hair.clone(),
        size: [width, height],
        camera: CameraSettings::Framed(camera_choice(scene)?),
        shading: scene.shading,
        preset: scene.preset.clone(),
        artist: scene
            .artist_params
            .as_deref()
            .map(read_artist_params)
            .transpose()?,
        fiber_width_px: scene.fiber_width_px,
        lighting,
        head: scene.head.clone(),
        skin_albedo: strandlight_scene::head_input::default_skin_albedo(),
    })
}

fn env_lighting(args: &EnvArgs) -> Lighting {
    Lighting::Environment(EnvLighting {
        scattering: args.scattering,
        kappa: args.kappa,
        lobes: args.strongest_lobes,
        rotation_deg: args.rotate,
        dodm_size: args.light_map_size,
        transparency: args.look.transparency,
        view: args.look.view,
        ..EnvLighting::new(args.env.clone())
    })
}

fn point_lighting(args: &LightsArgs) -> Lighting {
    let (shadows, transparency) = (&args.shadows, &args.transparency);
    let defaults = PointLighting::default();
    Lighting::Lights(PointLighting {
        lights: args.lights.clone(),
        shadows: shadows.shadows,
        transparency: transparency.transparency,
        dom_layers: shadows.layers.unwrap_or(defaults.dom_layers),
        osm_slices: shadows.layers.unwrap_or(defaults.osm_slices),
        pcf_kernel: shadows.pcf,
        kbuffer_k: transparency.kbuffer_k,
        subsets: transparency.subsets,
        shadow_bias: shadows.shadow_bias,
        adsm_alpha: shadows.adsm_alpha,
        // One flag for both: only one technique runs (as --layers for DOM layers and OSM slices).
        adsm_spacing: shadows.layer_spacing,
        dom_spacing: shadows.layer_spacing,
        dom_size: shadows.light_map_size,
        dbk_delta: transparency.dbk_delta,
        ..defaults
    })
}

pub fn run(args: RenderArgs) -> anyhow::Result<()> {
    let (settings, output) = match &args.what {
        RenderWhat::Env(env) => {
            let mut settings = frame_settings(&env.scene, env_lighting(env))?;
            if let Some(skin) = &env.skin {
                settings.skin_albedo = parse_vec3("--skin", skin)?;
            }
            (settings, &env.output)
        }
        RenderWhat::Lights(lights) => (
            frame_settings(&lights.scene, point_lighting(lights))?,
            &lights.output,
        ),
        RenderWhat::Replay(replay) => (FrameSettings::read(&replay.settings)?, &replay.output),
    };
    settings.check()?;
    create_output_dir(&output.out)?;
    let mut steps = Steps::new(output.json);
    // Before the fit and bake: a machine without a usable GPU device is told at once.
    steps.run("GPU", env_adapter, |adapter| adapter.clone())?;
    let hair = steps.run(
        "hair",
        || load_settings_hair(&settings),
        |h| format!("{} ({} strands)", h.source, h.model.strand_count()),
    )?;
    let (point, env);
    let prepared = match &settings.lighting {
        Lighting::Lights(lights) => {
            point = steps.run(
                "fiber",
                || prepare_point(&settings, lights),
                |p| p.description.clone(),
            )?;
            Prepared::Point(&point)
        }
        Lighting::Environment(_) => {
            env = prepare_env(
                &settings,
                &hair.model,
                Path::new("out/cache"),
                AlsoServe::default(),
                &mut steps,
                &mut |_| {},
            )?;
            Prepared::Env(&env)
        }
    };
    let rendered = steps.run(
        "render",
        || {
            render_frame(
                &settings,
                &hair.model,
                prepared,
                FramePart::Whole,
                output.json,
            )
        },
        |r| format!("{:.1} ms/frame, {}", r.milliseconds, what_was_drawn(r)),
    )?;
    let written = write_outputs(output, &settings, &hair, prepared, &rendered)?;
    if let Some(problem) = &written.problem {
        eprintln!("warning: {}: {problem}", written.png.display());
    }
    if output.json {
        let report = json_report(&settings, &hair, &rendered, &written)?;
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        for line in text_report(&settings, &hair, &rendered) {
            steps.say(line);
        }
        steps.say(format!(
            "wrote {}, {} (exposure {:+.2} stops, {}) and {} (the settings, for `render replay`)",
            written.exr.display(),
            written.png.display(),
            written.exposure_stops,
            output.exposure,
            written.settings.display()
        ));
    }
    Ok(())
}

/// "N SRBF lights …, full scattering" or "3 point lights, shadows Dom".
fn what_was_drawn(rendered: &RenderedFrame) -> String {
    match &rendered.details {
        FrameDetails::Env { lights, mode, .. } => {
            format!("{}, {} scattering", light_summary(lights), mode.name())
        }
        FrameDetails::Point(stats) => format!("{} segments", stats.segments),
    }
}

struct Written {
    exr: PathBuf,
    png: PathBuf,
    settings: PathBuf,
    covered_pixels: usize,
    exposure_stops: f32,
    /// What a person would not see in the PNG: black or clipped hair.
    problem: Option<ExposureProblem>,
}

/// STEM.exr (linear), STEM.png (tonemapped) and STEM.json (the settings), each with a line
/// describing the frame.
fn write_outputs(
    output: &OutputArgs,
    settings: &FrameSettings,
    hair: &FrameHair,
    prepared: Prepared,
    rendered: &RenderedFrame,
) -> anyhow::Result<Written> {
    let stem = output_stem(&output.out);
    let [width, height] = settings.size;
    let lighting = match (&settings.lighting, prepared, &rendered.details) {
        (Lighting::Lights(point), Prepared::Point(p), _) => format!(
            "{}; shadows {:?}; lights {}",
            p.description,
            point.shadows,
            point.lights.join(" ")
        ),
        (Lighting::Environment(env), Prepared::Env(p), FrameDetails::Env { lights, mode, .. }) => {
            format!(
                "env {}, {}; {:?} ({}), {} scattering",
                env.map,
                light_summary(lights),
                p.shading,
                settings.preset,
                mode.name()
            )
        }
        _ => bail!("the frame's lighting was prepared for other settings"),
    };
    let description = format!(
        "{}; {width}x{height}; {lighting}; camera {:?}",
        hair.source, settings.camera
    );
    let exposure_stops = output.exposure.stops_for(&rendered.image.pixels);
    let written = Written {
        exr: stem.with_extension("exr"),
        png: stem.with_extension("png"),
        settings: stem.with_extension("json"),
        covered_pixels: rendered.image.pixels.iter().filter(|p| p[3] > 0.0).count(),
        exposure_stops,
        problem: exposure_problem(&rendered.image.pixels, output.exposure, exposure_stops),
    };
    let image = &rendered.image;
    write_exr(&written.exr, width, height, &image.pixels, &description)?;
    write_png_exposed(
        &written.png,
        width,
        height,
        &image.pixels,
        exposure_stops,
        &description,
    )?;
    write_atomically::<anyhow::Error, _>(&written.settings, |w| {
        Ok(w.write_all(settings.to_json().as_bytes())?)
    })
    .with_context(|| format!("writing {}", written.settings.display()))?;
    Ok(written)
}

fn json_report(
    settings: &FrameSettings,
    hair: &FrameHair,
    rendered: &RenderedFrame,
    written: &Written,
) -> anyhow::Result<serde_json::Value> {
    let mut report = serde_json::json!({
        "hair": hair.source,
        "strands": hair.model.strand_count(),
        "size": settings.size,
        "frame_ms": rendered.milliseconds,
        "adapter": rendered.adapter,
        "timing_method": rendered.timing_method,
        "pass_ms": pass_ms(&rendered.passes),
        "pass_gpu_ms": pass_gpu_ms(&rendered.passes),
        "gpu_memory_bytes": rendered.memory.iter().map(|(n, b)| (n.clone(), serde_json::json!(b))).collect::<serde_json::Map<_, _>>(),
        "gpu_memory_total_bytes": rendered.memory.iter().map(|(_, b)| b).sum::<u64>(),
        "covered_pixels": written.covered_pixels,
        "outputs": { "exr": written.exr, "png": written.png, "png_tonemap": png_tonemap(written.exposure_stops), "settings": written.settings },
        "exposure_stops": written.exposure_stops,
        "exposure_warning": written.problem.as_ref().map(|p| p.to_string()),
        "settings": serde_json::to_value(settings)?,
    });
    let extra = match &rendered.details {
        FrameDetails::Point(stats) => serde_json::json!({
            "segments": stats.segments,
            "adapter_device_type": stats.adapter.device_type,
            "adapter_backend": stats.adapter.backend,
            "adapter_driver": stats.adapter.driver,
            "fragments_stored": stats.fragments.map(|f| f.stored),
            "fragments_dropped": stats.fragments.map(|f| f.dropped),
            "fragments_truncated_at_resolve": stats.fragments.map(|f| f.truncated),
            "abuffer_node_capacity": stats.fragments.map(|f| f.capacity),
        }),
        FrameDetails::Env {
            lights,
            mode,
            fragments,
        } => serde_json::json!({
            "srbf_lights": lights.iter().filter(|l| l.lambda.is_some()).count(),
            "directional_lights": lights.iter().filter(|l| l.lambda.is_none()).count(),
            "mode": mode.name(),
            "gpu_memory_note": "per batch of lights (each batch reuses the same resources)",
            "fragments": fragments.map(|f| serde_json::json!({ "rasterized": f.rasterized, "shaded": f.shaded, "note": "per batch (each batch draws the same fragments)" })),
        }),
    };
    if let (Some(report), serde_json::Value::Object(extra)) = (report.as_object_mut(), extra) {
        report.extend(extra);
    }
    Ok(report)
}

fn text_report(
    settings: &FrameSettings,
    hair: &FrameHair,
    rendered: &RenderedFrame,
) -> Vec<String> {
    let mut lines = vec![format!("adapter: {}", rendered.adapter)];
    match &rendered.details {
        FrameDetails::Point(stats) => {
            lines.push(format!(
                "hair: {}, {} strands, {} segments",
                hair.source,
                hair.model.strand_count(),
                stats.segments
            ));
            for t in &stats.timings {
                lines.push(format!("  {:<28} {:>9.2} ms", t.pass, t.milliseconds));
            }
            if let Some(f) = stats.fragments {
                let technique = match &settings.lighting {
                    Lighting::Lights(point) => point.transparency,
                    Lighting::Environment(_) => Transparency::None,
                };
                lines.push(match technique {
                    Transparency::Kbuffer => format!(
                        "K-buffer: {} fragments kept, {} dropped beyond the k nearest ({} slots)",
                        f.stored, f.dropped, f.capacity
                    ),
                    Transparency::Dbk => format!(
                        "DBK: {} fragments stored, {} dropped (node buffer holds {}), {} truncated at resolve (over 64 in a pixel)",
                        f.stored, f.dropped, f.capacity, f.truncated
                    ),
                    _ => format!(
                        "A-buffer: {} fragments stored, {} dropped (node buffer holds {}), {} truncated at resolve (over 64 in a pixel)",
                        f.stored, f.dropped, f.capacity, f.truncated
                    ),
                });
            }
        }
        FrameDetails::Env { .. } => {
            let memory: u64 = rendered.memory.iter().map(|(_, b)| b).sum();
            lines.push(format!(
                "GPU memory per batch of {} lights: {:.1} MB (--json lists it per resource)",
                strandlight_runtime::passes::convolution_depth::DodmSettings::default().batch_size,
                memory as f64 / 1e6
            ));
        }
    }
    lines
}

/// Wall-clock milliseconds per pass, for the JSON report.
fn pass_ms(passes: &[PassTiming]) -> serde_json::Map<String, serde_json::Value> {
    passes
        .iter()
        .map(|t| (t.pass.clone(), serde_json::json!(t.milliseconds)))
        .collect()
}

/// GPU milliseconds per pass from timestamp queries (null where unmeasured).
fn pass_gpu_ms(passes: &[PassTiming]) -> serde_json::Map<String, serde_json::Value> {
    passes
        .iter()
        .map(|t| (t.pass.clone(), serde_json::json!(t.gpu_milliseconds)))
        .collect()
}
