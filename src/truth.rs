//! `strandlight truth`: the path-traced ground truth of a scene (Mitsuba 3 with its `hair` BSDF,
//! the Chiang fiber), rendered and cached where `compare --ground-truth cached` and `bench` find
//! it; `--export DIR` writes the scene's Mitsuba files instead, for a user's own offline render.

use anyhow::Context;
use clap::Args;
use std::path::PathBuf;
use strandlight_eval::ground_truth::mitsuba_scene::MitsubaRun;
use strandlight_eval::ground_truth::{
    TruthScene, TruthSettings, TruthUse, export, ground_truth, write_truth_image,
};
use strandlight_scene::env_lighting::EnvLighting;
use strandlight_scene::frame_settings::{FrameSettings, Lighting};
use strandlight_scene::hair_input::parse_size;
use strandlight_scene::head_input::HeadChoice;
use strandlight_scene::point_shading::Shading;
use strandlight_scene::scene_tables::ScatteringMode;
use strandlight_scene::steps::Steps;

#[derive(Args, Debug)]
pub struct TruthArgs {
    /// The frame's settings (a `render` or viewer screenshot's STEM.json, a page's
    /// settings.json): its hair, camera, map, rotation and head, with the Chiang fiber. The
    /// scene flags below are then not taken.
    #[arg(long, value_name = "SETTINGS_JSON", conflicts_with_all = ["hair", "env", "size", "rotate", "preset", "head"])]
    pub settings: Option<PathBuf>,
    /// Hair file (.hair, .tfx, .data, .ply, USD .usda/.usdc/.usdz BasisCurves, Alembic .abc ICurves); rendered with opaque fibers of the file's width. The procedural groom when omitted.
    #[arg(long)]
    pub hair: Option<PathBuf>,
    /// Environment map (.hdr, .exr) or procedural:NAME.
    #[arg(long, required_unless_present = "settings")]
    pub env: Option<String>,
    /// Image size WxH (as `compare --size`).
    #[arg(long, default_value = "640x480")]
    pub size: String,
    /// Turn the map about the hair's up axis, degrees (as `render --rotate` and
    /// `compare --rotate`).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub rotate: f64,
    /// Melanin preset of the fiber: white, blonde, red, auburn, brown, dark.
    #[arg(long, default_value = "brown")]
    pub preset: String,
    /// The head under the hair: none, ellipsoid (fitted to the strand roots) or a mesh
    /// FILE (.obj, .glb, .gltf, .usd, .usda, .usdc, .usdz); several files, comma-separated,
    /// make one head.
    #[arg(
        long,
        default_value = "none",
        value_name = "none|ellipsoid|FILE[,FILE...]"
    )]
    pub head: HeadChoice,
    /// Scattering modes: single (direct light, max_depth 2) and full (path traced).
    #[arg(long, value_enum, value_delimiter = ',', default_value = "single,full")]
    pub modes: Vec<ScatteringMode>,
    /// Most samples per pixel of one image (the ladder climbs ×4 from 1024, or from a quarter of
    /// this when that is less).
    #[arg(long, default_value_t = TruthSettings::default().max_spp)]
    pub truth_max_spp: u32,
    /// N and 4N samples (and depths D and 2D) within this relative RMSE are converged.
    #[arg(long, default_value_t = TruthSettings::default().tolerance)]
    pub reference_tolerance: f64,
    /// Replace NaN/negative map pixels by 0 instead of refusing the map.
    #[arg(long)]
    pub sanitize: bool,
    /// Cache folder, shared with `compare` and `bench`.
    #[arg(long, default_value = "out/cache")]
    pub cache: PathBuf,
    /// Where each mode's image goes (`MODE-truth.exr` and `.png`).
    #[arg(long, default_value = "out/truth")]
    pub out: PathBuf,
    /// Write the scene's Mitsuba files to DIR instead of rendering: the curves, the map, the
    /// scene JSON and the script (`python3 DIR/mitsuba_render.py DIR/scene.json`).
    #[arg(long, value_name = "DIR")]
    pub export: Option<PathBuf>,
    /// With --export: samples per pixel of the exported scene.
    #[arg(long, default_value_t = 1024)]
    pub spp: u32,
}

/// The frame the flags (or the settings file) describe: what `compare` measures with the same
/// flags, so both find the same cached truths.
fn frame_settings(args: &TruthArgs) -> anyhow::Result<FrameSettings> {
    if let Some(path) = &args.settings {
        let mut frame = FrameSettings::read(path)?;
        if let Lighting::Environment(env) = &mut frame.lighting {
            env.sanitize |= args.sanitize;
        }
        return Ok(frame);
    }
    let (width, height) = parse_size(&args.size)?;
    let mut env = EnvLighting::new(args.env.clone().unwrap_or_default());
    env.rotation_deg = args.rotate as f32;
    env.sanitize = args.sanitize;
    Ok(FrameSettings {
        hair: args.hair.clone(),
        shading: Some(Shading::Chiang),
        preset: args.preset.clone(),
        head: args.head.clone(),
        ..FrameSettings::new(Lighting::Environment(env), [width, height])
    })
}

pub fn run(args: TruthArgs) -> anyhow::Result<()> {
    let frame = frame_settings(&args)?;
    // As `compare` and `bench` ask for it, so a budget under 4096 (640×480) is cached once.
    let settings = TruthSettings::with_budget(args.truth_max_spp, args.reference_tolerance);
    let mut steps = Steps::new(false);
    let scene = steps.run(
        "scene",
        || TruthScene::load(&frame),
        |s| {
            format!(
                "{} ({} strands), map {}",
                s.hair.source,
                s.hair.model.strand_count(),
                s.map.name
            )
        },
    )?;
    let inputs = scene.inputs()?;
    if let Some(dir) = &args.export {
        for &mode in &args.modes {
            let run = MitsubaRun {
                max_depth: match mode {
                    ScatteringMode::Single => 2,
                    ScatteringMode::Full => TruthSettings::default().most_depth,
                },
                spp: args.spp,
                seed: 0,
            };
            let mode_dir = dir.join(mode.name());
            let json = export(&inputs, run, &mode_dir)?;
            println!(
                "{}: python3 {} {}",
                mode.name(),
                mode_dir.join("mitsuba_render.py").display(),
                json.display()
            );
        }
        return Ok(());
    }
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create {}", args.out.display()))?;
    for &mode in &args.modes {
        let truth = ground_truth(
            &inputs,
            mode,
            &settings,
            TruthUse::Render,
            &args.cache,
            &mut steps,
        )?
        .expect("TruthUse::Render always renders");
        let stem = args.out.join(format!("{}-truth", mode.name()));
        let description = format!(
            "strandlight truth: {} under {}, {} scattering, Mitsuba {} {} spp depth {}",
            scene.hair.source,
            scene.map.name,
            mode.name(),
            truth.mitsuba,
            truth.spp,
            truth.max_depth
        );
        let exr = write_truth_image(&truth, &stem, &description)?;
        steps.say(format!(
            "{:<6} ground truth: {} spp, depth {}, {}, noise {:.4} (relative RMSE), Mitsuba {:.1} s → {}",
            mode.name(),
            truth.spp,
            truth.max_depth,
            if truth.converged { "converged" } else { "NOT converged (the budget came first)" },
            truth.noise,
            truth.seconds,
            exr.display()
        ));
    }
    Ok(())
}
