//! `strandlight compare`: SRBF lights vs the brute-force reference vs the equal-time median-cut
//! baseline ([`strandlight_eval::compare`]); prints the report as JSON with `--json`.
//!
//! The flags set the common fields of a [`CompareSettings`]; `--settings FILE` starts from a
//! whole settings value (a file of its own, or the `settings` member of a `compare --json`
//! report), and any flag given overrides the file.

use anyhow::Context;
use clap::Args;
use std::path::PathBuf;
use strandlight_eval::baseline::Baseline;
use strandlight_eval::compare::{CompareSettings, execute, prepare};
use strandlight_eval::ground_truth::TruthUse;
use strandlight_scene::env_frame::{env_adapter, render_lights};
use strandlight_scene::hair_input::parse_size;
use strandlight_scene::look::{EnvTransparency, ForwardDevice, LobeVisibilityArg};
use strandlight_scene::scene_tables::{EnvShading, ScatteringMode};
use strandlight_scene::steps::Steps;

#[derive(Args, Debug)]
pub struct CompareArgs {
    /// Start from this settings JSON (a `CompareSettings`, or a `compare --json` report, whose
    /// `settings` it reads); the flags below override it. The settings no flag names (the
    /// fit's knobs, the reference's convergence, timing runs, diagnostics) are set here.
    #[arg(long, value_name = "FILE")]
    settings: Option<PathBuf>,
    #[command(flatten)]
    scene: SceneFlags,
    #[command(flatten)]
    measure: MeasureFlags,
    #[command(flatten)]
    look: LookFlags,
}

#[derive(Args, Debug)]
#[command(next_help_heading = "Scene")]
struct SceneFlags {
    /// Hair file (.hair, .tfx, .data, .ply, USD .usda/.usdc/.usdz BasisCurves, Alembic .abc ICurves).
    #[arg(long)]
    hair: Option<PathBuf>,
    /// Environment: a Radiance .hdr / OpenEXR equirectangular map, or procedural:NAME.
    #[arg(long)]
    env: Option<String>,
    /// Turn the environment about its up axis, degrees (default 0).
    #[arg(long, allow_negative_numbers = true)]
    rotate: Option<f64>,
    /// Replace NaN/negative map values by 0 and +Inf by the largest finite value.
    #[arg(long)]
    sanitize: bool,
    /// Image size WxH (default: the paper's 640x480).
    #[arg(long)]
    size: Option<String>,
    /// Fiber model (default: marschner).
    #[arg(long, value_enum)]
    shading: Option<EnvShading>,
    /// Melanin preset of the fiber: white, blonde, red, auburn, brown, dark (default: brown).
    #[arg(long)]
    preset: Option<String>,
    /// The head in every frame (the SRBF path's, the reference's, the baseline's, the truth's):
    /// none, ellipsoid (fitted to the strand roots) or a mesh FILE (.obj, .glb, .gltf, .usd*;
    /// several, comma-separated, make one head) (default: none).
    #[arg(long, value_name = "none|ellipsoid|FILE[,FILE...]")]
    head: Option<strandlight_scene::head_input::HeadChoice>,
}

#[derive(Args, Debug)]
#[command(next_help_heading = "Measurement")]
struct MeasureFlags {
    /// Which modes to compare: single scattering, full (single + multiple), or both (default).
    #[arg(long, value_enum, value_delimiter = ',')]
    modes: Option<Vec<ScatteringMode>>,
    /// Lights of the brute-force reference, 6n² for n×n texels per cube face (6144 = the
    /// paper's 32×32×6; 1536, 384, 96 for quick runs). Default: converged, the first N of 96,
    /// 384, 1536, … whose image and that of 4N lights agree within the settings'
    /// `reference_tolerance` (1%); the 4N image is the reference.
    #[arg(long)]
    reference_lights: Option<usize>,
    /// The directional-light baseline: median cut over the whole map (Debevec 2005, Ren's
    /// baseline; the default), or the compact sources exactly and median cut over the rest.
    #[arg(long, value_enum)]
    baseline: Option<Baseline>,
    /// Also search the fewest median-cut lights whose error is at most the SRBF frame's
    /// (Ren Fig. 6) and report the speed-up at equal error. Slow: it renders up to
    /// --reference-lights baseline lights.
    #[arg(long)]
    equal_error: bool,
    /// The path-traced ground truth (Mitsuba 3; the Chiang fiber only, which is Mitsuba's
    /// `hair`): `cached` (the default) measures every frame against it where `strandlight
    /// truth` or an earlier run rendered it, `render` renders what is missing (minutes), `off`
    /// never.
    #[arg(long, value_enum)]
    ground_truth: Option<TruthUse>,
    /// Most samples per pixel of one ground-truth image (default 4096; its ladder climbs ×4
    /// from 1024, or from a quarter of this when that is less, until N and 4N agree; at
    /// 640×480, 256 costs what 4096 costs at 160×120).
    #[arg(long)]
    truth_max_spp: Option<u32>,
    /// Folder for the images (default: out/compare).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Cache folder of fits, tables, references and ground truths (default: out/cache).
    #[arg(long)]
    cache: Option<PathBuf>,
    /// Print one JSON object on stdout (progress goes to stderr); it records the settings.
    #[arg(long)]
    json: bool,
}

#[derive(Args, Debug)]
#[command(next_help_heading = "The SRBF frame's look")]
struct LookFlags {
    /// Stochastic simplification of the SRBF light pass (Ren §7): the fraction of strands drawn
    /// into the light maps (default 0.1; 1 = all). The reference and the baseline draw all.
    #[arg(long)]
    kappa: Option<f32>,
    /// Side of every light map of all three renders, the reference's included, texels
    /// (default 512; docs/BENCHMARKS.md, "Light-map size").
    #[arg(long)]
    light_map_size: Option<u32>,
    /// Every fiber weighted by its visibility through an occupancy map (Ren §8), in 4 layers
    /// per pixel (layered, the default) or one by one (occupancy), or the nearest fiber of each
    /// pixel (opaque).
    #[arg(long, value_enum)]
    transparency: Option<EnvTransparency>,
    /// Where SRBF lobes' visibility comes from: the groom's visibility volume (the default) or
    /// each lobe's light map (Ren 2010).
    #[arg(long, value_enum)]
    lobe_visibility: Option<LobeVisibilityArg>,
    /// With layered or occupancy: fragments seen less than this fraction are not shaded.
    #[arg(long)]
    visibility_cutoff: Option<f32>,
    /// Where multiple scattering's shadow paths are marched (default: auto).
    #[arg(long, value_enum)]
    forward_scattering: Option<ForwardDevice>,
}

/// The settings `--settings` names, or the defaults.
fn base_settings(path: Option<&PathBuf>) -> anyhow::Result<CompareSettings> {
    let Some(path) = path else {
        return Ok(CompareSettings::default());
    };
    let text =
        std::fs::read_to_string(path).with_context(|| format!("--settings {}", path.display()))?;
    let value: serde_json::Value = serde_json::from_str(&text)
        .with_context(|| format!("--settings {}: not JSON", path.display()))?;
    let settings = value.get("settings").cloned().unwrap_or(value);
    CompareSettings::from_json(settings).with_context(|| {
        format!(
            "--settings {}: not compare settings (or a `compare --json` report holding them)",
            path.display()
        )
    })
}

/// Overwrites `target` with `flag`'s value where the flag was given.
fn set<T>(target: &mut T, flag: Option<T>) {
    if let Some(value) = flag {
        *target = value;
    }
}

impl CompareArgs {
    /// The settings these flags ask for.
    pub fn settings(self) -> anyhow::Result<CompareSettings> {
        let mut s = base_settings(self.settings.as_ref())?;
        let (scene, measure, look) = (self.scene, self.measure, self.look);
        let frame = &mut s.frame;
        if scene.hair.is_some() {
            frame.hair = scene.hair;
        }
        if let Some(size) = &scene.size {
            let (w, h) = parse_size(size)?;
            frame.size = [w, h];
        }
        set(&mut frame.shading, scene.shading.map(|s| Some(s.into())));
        set(&mut frame.preset, scene.preset);
        set(&mut frame.head, scene.head);
        let env = s.env_mut();
        set(&mut env.map, scene.env);
        set(&mut env.rotation_deg, scene.rotate.map(|r| r as f32));
        env.sanitize |= scene.sanitize;
        set(&mut env.kappa, look.kappa);
        set(&mut env.dodm_size, look.light_map_size);
        set(&mut env.transparency, look.transparency);
        set(&mut env.view.lobe_visibility, look.lobe_visibility);
        set(&mut env.view.visibility_cutoff, look.visibility_cutoff);
        set(&mut env.view.forward_scattering, look.forward_scattering);
        set(&mut s.modes, measure.modes);
        set(&mut s.reference_lights, measure.reference_lights.map(Some));
        set(&mut s.baseline, measure.baseline);
        s.equal_error |= measure.equal_error;
        set(&mut s.ground_truth, measure.ground_truth);
        set(&mut s.truth_max_spp, measure.truth_max_spp);
        set(&mut s.out, measure.out);
        set(&mut s.cache, measure.cache);
        s.json |= measure.json;
        Ok(s)
    }
}

pub fn run(args: CompareArgs) -> anyhow::Result<()> {
    let settings = args.settings()?;
    let mut steps = Steps::new(settings.json);
    // Before the fit, bake and references: a machine without a usable GPU device is told at once.
    steps.run("GPU", env_adapter, |adapter| adapter.clone())?;
    let scene = prepare(&settings, &mut steps)?;
    let report = execute(&settings, &scene, &mut steps, &render_lights)?;
    if settings.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        args: CompareArgs,
    }

    fn settings(line: &[&str]) -> anyhow::Result<CompareSettings> {
        Cli::try_parse_from(std::iter::once("compare").chain(line.iter().copied()))?
            .args
            .settings()
    }

    #[test]
    fn no_flag_leaves_the_default_and_each_flag_sets_its_field() {
        assert_eq!(settings(&[]).unwrap(), CompareSettings::default());
        let s = settings(&[
            "--hair",
            "h.hair",
            "--env",
            "e.hdr",
            "--size",
            "64x48",
            "--modes",
            "single",
            "--kappa",
            "0.5",
            "--lobe-visibility",
            "light-maps",
            "--reference-lights",
            "96",
            "--json",
        ])
        .unwrap();
        let mut expected = CompareSettings {
            modes: vec![ScatteringMode::Single],
            reference_lights: Some(96),
            json: true,
            ..CompareSettings::default()
        };
        expected.frame.hair = Some("h.hair".into());
        expected.frame.size = [64, 48];
        let env = expected.env_mut();
        env.map = "e.hdr".into();
        env.kappa = 0.5;
        env.view.lobe_visibility = LobeVisibilityArg::LightMaps;
        assert_eq!(s, expected);
    }

    #[test]
    fn a_settings_file_or_report_is_the_base_and_flags_override_it() {
        let dir = std::env::temp_dir().join(format!("strandlight-compare-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let mut file = CompareSettings {
            reference_max_lights: 1536,
            timing_runs: 1,
            ..CompareSettings::default()
        };
        file.env_mut().map = "from-file.hdr".into();
        file.env_mut().fit.max_lobes = 8;
        let plain = dir.join("settings.json");
        std::fs::write(&plain, serde_json::to_string(&file).unwrap()).unwrap();
        let report = dir.join("report.json");
        let wrapped = serde_json::json!({ "settings": file, "single": { "srbf": {} } });
        std::fs::write(&report, wrapped.to_string()).unwrap();
        for path in [&plain, &report] {
            let s = settings(&["--settings", path.to_str().unwrap(), "--env", "flag.hdr"]).unwrap();
            assert_eq!(
                (s.env().fit.max_lobes, s.reference_max_lights, s.timing_runs),
                (8, 1536, 1)
            );
            assert_eq!(s.env().map, "flag.hdr", "the flag overrides the file");
        }
        std::fs::write(&plain, r#"{"timing_runs": 8, "no_such_field": 1}"#).unwrap();
        let e = format!(
            "{:#}",
            settings(&["--settings", plain.to_str().unwrap()]).unwrap_err()
        );
        assert!(
            e.contains("not compare settings") && e.contains("no_such_field"),
            "{e}"
        );
        let e = format!(
            "{:#}",
            settings(&["--settings", "/no/such.json"]).unwrap_err()
        );
        assert!(e.contains("--settings /no/such.json"), "{e}");
        std::fs::remove_dir_all(&dir).ok();
    }
}
