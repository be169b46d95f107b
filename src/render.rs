//! `strandlight render`: one headless frame of a hair model under point lights, written as a
//! linear EXR and a tonemapped PNG, with timings and GPU memory on request.

use anyhow::{Context, bail};
use clap::{Args, ValueEnum};
use std::path::{Path, PathBuf};
use strandlight_precompute::bake_plan::{BakeResolution, FiberDescription};
use strandlight_runtime::camera::UpAxis;
use strandlight_runtime::gpu::GpuContext;
use strandlight_runtime::image_out::{PNG_TONEMAP, write_exr, write_png};
use strandlight_runtime::lights::Light;
use strandlight_runtime::passes::deep_opacity::DomSettings;
use strandlight_runtime::passes::frame_params::{FrameParams, KajiyaKay};
use strandlight_runtime::render::{self, RenderOptions, render_frame_with_model};
use strandlight_scene::camera_choice::{CameraChoice, CameraKind, UpChoice};
use strandlight_scene::env_frame::{EnvFrame, FrameRole, light_summary, render_lights};
use strandlight_scene::env_scene::{EnvSceneRequest, prepare_env_scene};
use strandlight_scene::environment::load_env;
use strandlight_scene::hair_input::{load_hair, parse_size};
use strandlight_scene::look::{EnvLook, EnvTransparency, LookArgs};
use strandlight_scene::point_shading::{PointShadingRequest, Shading, point_shading_model};
use strandlight_scene::scene_tables::{EnvShading, ScatteringMode};
use strandlight_scene::steps::Steps;

#[derive(Clone, Copy, Debug, PartialEq, ValueEnum)]
pub enum Shadows {
    None,
    Dom,
}

#[derive(Clone, Copy, Debug, PartialEq, ValueEnum)]
pub enum Transparency {
    None,
    Abuffer,
    Dbk,
    /// With --env only: every fiber weighted by its visibility through an occupancy map.
    Occupancy,
}

/// The default light when none is given: from the upper right front.
const DEFAULT_LIGHT: &str = "directional:0.5,0.7,1:2";

#[derive(Args, Debug)]
pub struct RenderArgs {
    /// Hair file (.hair, .tfx, .data, .ply); the procedural groom when omitted.
    #[arg(long)]
    hair: Option<PathBuf>,
    /// Repeatable: directional:X,Y,Z[:I] (toward the light), point:X,Y,Z[:I],
    /// spot:X,Y,Z:DX,DY,DZ:HALF_ANGLE_DEGREES[:I].
    #[arg(long = "light", default_value = DEFAULT_LIGHT)]
    lights: Vec<String>,
    /// Fiber model (default: kajiya-kay for point lights, marschner with --env).
    #[arg(long, value_enum)]
    shading: Option<Shading>,
    /// Light the hair with an environment instead: a .hdr/.exr map or procedural:NAME, fitted
    /// with SRBFs (cached) and rendered by Ren 2010's method (marschner or artist shading).
    #[arg(long, value_name = "MAP")]
    pub env: Option<String>,
    /// With --env: single scattering, or full (single + multiple; skipped for dark hair).
    #[arg(long, value_enum, default_value = "full")]
    pub scattering: ScatteringMode,
    /// With --env: fraction of the strands drawn into the light maps (Ren §7; 1 = all).
    #[arg(long, default_value_t = 0.1)]
    pub kappa: f32,
    /// Melanin preset of the Marschner fiber (--shading marschner): dark, brown, blonde, ...
    #[arg(long, default_value = "brown")]
    preset: String,
    /// Nodes per axis of the Marschner lookup tables, baked at startup.
    #[arg(long, default_value_t = 128)]
    lut_size: usize,
    /// JSON file of artist-model controls (--shading artist; default: the built-in light brown).
    #[arg(long)]
    artist_params: Option<PathBuf>,
    #[arg(long, value_enum, default_value = "none")]
    shadows: Shadows,
    #[arg(long, value_enum, default_value = "none")]
    transparency: Transparency,
    /// With --env: the env-lit renderer's view choices.
    #[command(flatten)]
    env_view: strandlight_scene::look::ViewArgs,
    /// Deep opacity map layers (1..=8), with --shadows dom.
    #[arg(long, default_value_t = 4)]
    dom_layers: u32,
    /// Layer spacing in world units (default: 1% of the hair's bounding-box diagonal).
    #[arg(long)]
    dom_spacing: Option<f32>,
    /// Deep opacity map resolution (square).
    #[arg(long, default_value_t = 512)]
    dom_size: u32,
    /// A-buffer node buffer size, in nodes per pixel (clamped to the adapter's limit).
    #[arg(long, default_value_t = 16)]
    abuffer_nodes_per_pixel: u32,
    /// DBK layer depth Δ in world units (default: 5% of the hair's bounding-box diagonal).
    #[arg(long)]
    dbk_delta: Option<f32>,
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
    /// Output stem: writes STEM.exr (linear) and STEM.png (tonemapped).
    #[arg(long, default_value = "render")]
    out: PathBuf,
    /// Print adapter, per-pass milliseconds and GPU memory as JSON.
    #[arg(long)]
    json: bool,
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
fn camera_choice(args: &RenderArgs) -> anyhow::Result<CameraChoice> {
    let eye = args
        .eye
        .as_deref()
        .map(|text| parse_vec3("--eye", text))
        .transpose()?;
    Ok(CameraChoice {
        kind: args.camera,
        up: args.up,
        eye,
    })
}

pub fn run(args: RenderArgs) -> anyhow::Result<()> {
    if let Some(env) = args.env.clone() {
        return run_env(&args, &env);
    }
    let (shading, shading_description) = point_shading_model(&PointShadingRequest {
        shading: args.shading.unwrap_or(Shading::KajiyaKay),
        preset: &args.preset,
        lut_size: args.lut_size,
        artist_params: args.artist_params.as_deref(),
    })?;
    let transparency = match args.transparency {
        Transparency::None => render::Transparency::Opaque,
        Transparency::Abuffer => render::Transparency::ABuffer {
            nodes_per_pixel: args.abuffer_nodes_per_pixel,
        },
        Transparency::Dbk => render::Transparency::Dbk {
            nodes_per_pixel: args.abuffer_nodes_per_pixel,
            delta: args.dbk_delta.unwrap_or(0.0),
        },
        Transparency::Occupancy => bail!(
            "--transparency occupancy is the view of --env (environment lighting); with point lights use none, abuffer or dbk"
        ),
    };
    let (width, height) = parse_size(&args.size)?;
    if let Some(w) = args.fiber_width_px
        && !(w.is_finite() && w > 0.0)
    {
        bail!("--fiber-width-px {w}: must be a positive number of pixels");
    }
    let lights = args
        .lights
        .iter()
        .map(|s| Light::parse(s))
        .collect::<Result<Vec<_>, _>>()?;
    if let Some(d) = args.dbk_delta
        && !(d.is_finite() && d >= 0.0)
    {
        bail!("--dbk-delta {d}: must be a non-negative number of world units");
    }
    let (model, source) = load_hair(args.hair.as_deref())?;
    let transparency = match transparency {
        render::Transparency::Dbk {
            nodes_per_pixel, ..
        } => render::Transparency::Dbk {
            nodes_per_pixel,
            delta: args.dbk_delta.unwrap_or(model.bounds().diagonal() * 0.05),
        },
        other => other,
    };
    let gpu = GpuContext::new_headless()?;
    let camera = camera_choice(&args)?.camera(&model, width as f32 / height as f32)?;
    let frame = FrameParams {
        camera,
        width,
        height,
        lights,
        shading: KajiyaKay::default(),
        width_override_px: args.fiber_width_px,
    };
    let shadows = match args.shadows {
        Shadows::None => None,
        Shadows::Dom => Some(DomSettings {
            resolution: args.dom_size,
            layers: args.dom_layers,
            spacing: args.dom_spacing.unwrap_or(model.bounds().diagonal() * 0.01),
        }),
    };
    let rendered = render_frame_with_model(
        &gpu,
        &model,
        &frame,
        &RenderOptions {
            shadows,
            transparency,
        },
        &shading,
    )?;
    let stem = output_stem(&args.out);
    let exr_path = stem.with_extension("exr");
    let png_path = stem.with_extension("png");
    let description = format!(
        "{source}; {width}x{height}; {shading_description}; shadows {shadows:?}; lights {}; camera {:?}",
        args.lights.join(" "),
        args.camera
    );
    write_exr(&exr_path, width, height, &rendered.pixels, &description)?;
    write_png(&png_path, width, height, &rendered.pixels, &description)?;
    let covered = rendered.pixels.iter().filter(|p| p[3] > 0.0).count();
    let stats = &rendered.stats;
    if args.json {
        let report = serde_json::json!({
            "hair": source,
            "strands": model.strand_count(),
            "segments": stats.segments,
            "size": [width, height],
            "shading": shading_description,
            "adapter": {
                "name": stats.adapter.name,
                "backend": stats.adapter.backend,
                "device_type": stats.adapter.device_type,
                "driver": stats.adapter.driver,
            },
            "timing_method": stats.timing_method,
            "pass_ms": stats.timings.iter().map(|t| (t.pass.clone(), serde_json::json!(t.milliseconds))).collect::<serde_json::Map<_, _>>(),
            "gpu_memory_bytes": stats.memory_bytes.iter().map(|(n, b)| (n.clone(), serde_json::json!(b))).collect::<serde_json::Map<_, _>>(),
            "covered_pixels": covered,
            "fragments_stored": stats.fragments.map(|f| f.stored),
            "fragments_dropped": stats.fragments.map(|f| f.dropped),
            "fragments_truncated_at_resolve": stats.fragments.map(|f| f.truncated),
            "abuffer_node_capacity": stats.fragments.map(|f| f.capacity),
            "outputs": { "exr": exr_path, "png": png_path, "png_tonemap": PNG_TONEMAP },
        });
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        println!("adapter: {}", stats.adapter);
        println!("shading: {shading_description}");
        println!(
            "hair: {source}, {} strands, {} segments",
            model.strand_count(),
            stats.segments
        );
        for t in &stats.timings {
            println!("  {:<10} {:>9.2} ms", t.pass, t.milliseconds);
        }
        if let Some(f) = stats.fragments {
            println!(
                "A-buffer: {} fragments stored, {} dropped (node buffer holds {}), {} truncated at resolve (over 64 in a pixel)",
                f.stored, f.dropped, f.capacity, f.truncated
            );
        }
        println!(
            "wrote {} and {} ({covered} pixels covered)",
            exr_path.display(),
            png_path.display()
        );
    }
    Ok(())
}

/// `render --env MAP`: the SRBF path alone (fit and tables cached under out/cache).
fn run_env(args: &RenderArgs, env_spec: &str) -> anyhow::Result<()> {
    let shading = match args.shading.unwrap_or(Shading::Marschner) {
        Shading::Marschner => EnvShading::Marschner,
        Shading::Artist => EnvShading::Artist,
        Shading::KajiyaKay => bail!(
            "--shading kajiya-kay with --env: the env renderer reads one RGB 4D table (Marschner I_M or the artist I_A); use --shading marschner or artist"
        ),
    };
    if matches!(args.transparency, Transparency::Abuffer | Transparency::Dbk)
        || args.shadows != Shadows::None
    {
        bail!(
            "--env shadows every SRBF light with its convolution optical depth map and renders opaque (none) or through an occupancy map (occupancy); --shadows, --transparency abuffer/dbk apply to point lights only"
        );
    }
    let look_args = LookArgs {
        transparency: if args.transparency == Transparency::Occupancy {
            EnvTransparency::Occupancy
        } else {
            EnvTransparency::Opaque
        },
        view: args.env_view,
    };
    let look = EnvLook {
        count_fragments: args.json,
        ..look_args.look()?
    };
    let (width, height) = parse_size(&args.size)?;
    let mut steps = Steps::new(args.json);
    let (model, source) = steps.run(
        "hair",
        || load_hair(args.hair.as_deref()),
        |(m, s)| format!("{s} ({} strands)", m.strand_count()),
    )?;
    let env = steps.run(
        "environment",
        || load_env(env_spec, false),
        |e| format!("{} {}x{}", e.name, e.map.width(), e.map.height()),
    )?;
    let fiber = FiberDescription::preset(&args.preset)
        .with_context(|| format!("--preset {:?}", args.preset))?;
    let table_set = format!("{}-{:?}", args.preset, shading).to_lowercase();
    let request = EnvSceneRequest {
        env: &env,
        fiber: &fiber,
        shading,
        scattering: args.scattering,
        resolution: BakeResolution::default(),
        cache_dir: Path::new("out/cache"),
        table_set: &table_set,
        up: UpAxis::detect(&model),
    };
    let scene = prepare_env_scene(&request, &mut steps)?;
    let (lights, mode) = (&scene.lights, scene.mode);
    let camera = camera_choice(args)?.camera(&model, width as f32 / height as f32)?;
    let frame = EnvFrame {
        hair: &model,
        camera,
        width,
        height,
        lights,
        tables: &scene.tables,
        shading,
        mode,
        role: FrameRole::Interactive { kappa: args.kappa },
        look,
    };
    let rendered = steps.run(
        "render",
        || render_lights(&frame),
        |r| {
            format!(
                "{:.1} ms/frame, {}, {} scattering",
                r.milliseconds,
                light_summary(lights),
                mode.name()
            )
        },
    )?;
    let stem = output_stem(&args.out);
    let (exr_path, png_path) = (stem.with_extension("exr"), stem.with_extension("png"));
    let description = format!(
        "{source}; {width}x{height}; env {env_spec}, {}; {shading:?} ({}), {} scattering",
        light_summary(lights),
        args.preset,
        mode.name()
    );
    let image = &rendered.image;
    write_exr(&exr_path, width, height, &image.pixels, &description)?;
    write_png(&png_path, width, height, &image.pixels, &description)?;
    if args.json {
        let report = serde_json::json!({
            "hair": source,
            "env": env_spec,
            "srbf_lights": lights.iter().filter(|l| l.lambda.is_some()).count(),
            "directional_lights": lights.iter().filter(|l| l.lambda.is_none()).count(),
            "size": [width, height],
            "mode": mode.name(),
            "frame_ms": rendered.milliseconds,
            "transparency": look_args.transparency,
            "box_average": look_args.view.box_average,
            "forward_scattering": look_args.view.forward_scattering,
            "visibility_cutoff": look_args.view.visibility_cutoff,
            "memory_per_batch_bytes": rendered.memory_per_batch.iter().map(|(n, b)| (n.clone(), serde_json::json!(b))).collect::<serde_json::Map<_, _>>(),
            "memory_per_batch_total_bytes": rendered.memory_per_batch.iter().map(|(_, b)| b).sum::<u64>(),
            "fragments": rendered.fragments.map(|f| serde_json::json!({ "rasterized": f.rasterized, "shaded": f.shaded, "note": "per batch (each batch draws the same fragments)" })),
            "pass_ms": rendered.passes.iter().map(|(n, ms)| (n.clone(), serde_json::json!(ms))).collect::<serde_json::Map<_, _>>(),
            "timing_method": "CPU wall clock around submit + wait for idle, summed over batches",
            "exr": exr_path,
            "png": png_path,
        });
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        let memory: u64 = rendered.memory_per_batch.iter().map(|(_, b)| b).sum();
        steps.say(format!(
            "GPU memory per batch of {} lights: {:.1} MB (--json lists it per resource)",
            strandlight_runtime::passes::convolution_depth::DodmSettings::default().batch_size,
            memory as f64 / 1e6
        ));
        steps.say(format!(
            "wrote {} and {}",
            exr_path.display(),
            png_path.display()
        ));
    }
    Ok(())
}
