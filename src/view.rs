//! `strandlight view`: the window. Flags choose the first frame; everything else is live in the
//! panel. `--script`, `--screenshot`, `--frames` and `--report` drive and measure it unattended.

use clap::Args;
use std::path::PathBuf;
use std::time::{Duration, Instant};
use strandlight_scene::frame_settings::{EnvLighting, FrameSettings, Lighting, PointLighting};
use strandlight_scene::hair_input::parse_size;
use strandlight_scene::head_input::HeadChoice;
use strandlight_scene::point_shading::Shading;
use strandlight_scene::scene_tables::ScatteringMode;

use crate::demo::{DEMO_ENVIRONMENT, DEMO_PRESET};

#[derive(Args, Debug)]
pub struct ViewArgs {
    /// Hair file (.hair, .tfx, .data, .ply, USD .usda/.usdc/.usdz BasisCurves, Alembic .abc ICurves) or procedural:STYLE (straight-long, wavy-bob, curly); the procedural groom's straight-long when omitted.
    #[arg(long)]
    hair: Option<PathBuf>,
    /// Environment map (.hdr/.exr or procedural:NAME); the demo's sun and sky by default.
    #[arg(long, value_name = "MAP")]
    env: Option<String>,
    /// Point-light mode instead: repeatable, as `render lights --light`.
    #[arg(long = "light")]
    lights: Vec<String>,
    /// Fiber model (default: chiang under an environment, kajiya-kay under lights).
    #[arg(long, value_enum)]
    shading: Option<Shading>,
    #[arg(long, default_value = DEMO_PRESET)]
    preset: String,
    #[arg(long, value_enum, default_value = "full")]
    scattering: ScatteringMode,
    /// The head the hair grows from: none, ellipsoid (fitted to the strand roots) or a mesh
    /// FILE (.obj, .glb, .gltf, .usd, .usda, .usdc, .usdz); several files, comma-separated,
    /// make one head (skin, eyes, lashes).
    #[arg(
        long,
        default_value = "ellipsoid",
        value_name = "none|ellipsoid|FILE[,FILE...]"
    )]
    head: HeadChoice,
    /// Image size WxH in pixels (the window shows it scaled to fit).
    #[arg(long, default_value = "640x480")]
    size: String,
    /// Open on the settings of this JSON file (a screenshot's sidecar) instead of the flags.
    #[arg(long, value_name = "SETTINGS_JSON")]
    replay: Option<PathBuf>,
    /// Fit and table cache (shared with `render`).
    #[arg(long, default_value = "out/cache")]
    cache: PathBuf,
    /// Drive the window with this JSON list of steps (see viewer/src/script.rs), then exit.
    #[arg(long)]
    script: Option<PathBuf>,
    /// Save a screenshot here (STEM.png, STEM.exr, STEM.json) once converged, then exit.
    #[arg(long, value_name = "STEM")]
    screenshot: Option<PathBuf>,
    /// Exit after this many presented frames.
    #[arg(long)]
    frames: Option<u64>,
    /// Write frame counts and preview/converged times as JSON here at exit.
    #[arg(long)]
    report: Option<PathBuf>,
    /// A scripted run that takes longer than this fails.
    #[arg(long, default_value_t = 900)]
    timeout_s: u64,
    /// Whether the window presents on the renderer's device (shared: frames never leave the
    /// GPU) or on its own (own: each new image is read back once and uploaded; on a software
    /// adapter's single queue the window would otherwise wait for every pass). auto: shared on
    /// a hardware GPU, own on a software one.
    #[arg(long, value_enum, default_value = "auto")]
    window_device: strandlight_viewer::WindowDevice,
}

fn settings(args: &ViewArgs) -> anyhow::Result<FrameSettings> {
    if let Some(path) = &args.replay {
        return FrameSettings::read(path);
    }
    let (w, h) = parse_size(&args.size)?;
    let lighting = if args.lights.is_empty() {
        let map = args
            .env
            .clone()
            .unwrap_or_else(|| format!("procedural:{DEMO_ENVIRONMENT}"));
        Lighting::Environment(EnvLighting {
            scattering: args.scattering,
            ..EnvLighting::new(map)
        })
    } else {
        if args.env.is_some() {
            anyhow::bail!(
                "--env and --light: choose an environment or lights (the panel switches)"
            );
        }
        Lighting::Lights(PointLighting {
            lights: args.lights.clone(),
            ..PointLighting::default()
        })
    };
    let mut settings = FrameSettings::new(lighting, [w, h]);
    settings.hair = args.hair.clone();
    settings.shading = args.shading;
    settings.preset = args.preset.clone();
    settings.head = args.head.clone();
    Ok(settings)
}

pub fn run(args: ViewArgs) -> anyhow::Result<()> {
    let started = Instant::now();
    strandlight_viewer::run(strandlight_viewer::ViewOptions {
        started,
        settings: settings(&args)?,
        cache_dir: args.cache,
        script: args.script,
        screenshot: args.screenshot,
        frames: args.frames,
        report: args.report,
        timeout: Duration::from_secs(args.timeout_s),
        window_device: args.window_device,
    })
}
