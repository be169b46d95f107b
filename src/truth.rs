//! `strandlight truth`: the path-traced ground truth of a scene (Mitsuba 3 with its `hair` BSDF,
//! the Chiang fiber), rendered and cached where `compare --ground-truth cached` and `bench` find
//! it; `--export DIR` writes the scene's Mitsuba files instead, for a user's own offline render.

use anyhow::Context;
use clap::Args;
use std::path::PathBuf;
use strandlight_eval::ground_truth::mitsuba_scene::MitsubaRun;
use strandlight_eval::ground_truth::{
    TruthRequest, TruthScene, TruthSettings, TruthUse, export, ground_truth, write_truth_image,
};
use strandlight_scene::hair_input::parse_size;
use strandlight_scene::scene_tables::ScatteringMode;
use strandlight_scene::steps::Steps;

#[derive(Args, Debug)]
pub struct TruthArgs {
    /// Hair file (.hair, .tfx, .data, .ply, USD .usda/.usdc/.usdz BasisCurves, Alembic .abc ICurves); rendered with opaque fibers of the file's width.
    #[arg(long)]
    pub hair: PathBuf,
    /// Environment map (.hdr, .exr) or procedural:NAME.
    #[arg(long)]
    pub env: String,
    /// Image size WxH (as `compare --size`).
    #[arg(long, default_value = "640x480")]
    pub size: String,
    /// Turn the map about the hair's up axis, degrees (as `compare --rotate`).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub rotate: f64,
    /// Melanin preset of the fiber: white, blonde, red, auburn, brown, dark.
    #[arg(long, default_value = "brown")]
    pub preset: String,
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

pub fn run(args: TruthArgs) -> anyhow::Result<()> {
    let size = parse_size(&args.size)?;
    let request = TruthRequest {
        hair: args.hair.clone(),
        env: args.env.clone(),
        sanitize: args.sanitize,
        size,
        rotate_degrees: args.rotate,
        preset: args.preset.clone(),
        modes: args.modes.clone(),
        // As `compare` and `bench` ask for it, so a budget under 4096 (640×480) is cached once.
        settings: TruthSettings::with_budget(args.truth_max_spp, args.reference_tolerance),
        cache: args.cache.clone(),
    };
    let mut steps = Steps::new(false);
    let scene = steps.run(
        "scene",
        || TruthScene::load(&request),
        |s| format!("{} strands, map {}", s.hair.strand_count(), args.env),
    )?;
    let inputs = scene.inputs(size, args.rotate);
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
            &request.settings,
            TruthUse::Render,
            &request.cache,
            &mut steps,
        )?
        .expect("TruthUse::Render always renders");
        let stem = args.out.join(format!("{}-truth", mode.name()));
        let description = format!(
            "strandlight truth: {} under {}, {} scattering, Mitsuba {} {} spp depth {}",
            args.hair.display(),
            args.env,
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
