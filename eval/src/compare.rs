//! The comparison behind `strandlight compare`: one hair, camera, fiber and environment rendered three ways (Ren 2010
//! §8): the SRBF path, the brute-force reference (6n² cube-texel directional lights, cached) and
//! the equal-time median-cut baseline; per scattering mode the frame times, the relative RMSE
//! against the reference over hair pixels, and the speed ratios; the images side by side.

use crate::baseline::Baseline;
use crate::equal_time::{EqualTimeSearch, equal_error_lights, equal_time_lights};
use crate::error_metric::ErrorMetric;
use crate::ground_truth::mitsuba_scene::MitsubaScene;
use crate::ground_truth::{GroundTruth, TruthInputs, TruthSettings, TruthUse, ground_truth};
use crate::hdr_flip::{HdrFlip, error_map_magma, hdr_flip};
use crate::reference_cache::{ReferenceCache, ReferenceRecord};
use anyhow::{Context, bail};
use serde::{Deserialize, Serialize};
use serde_json::{Value, json};
use std::path::PathBuf;
use strandlight_precompute::env_lights::{face_resolution_for, srbf_set_lights};
use strandlight_runtime::env::EnvRenderOptions;
use strandlight_runtime::env::ViewTransparency;
use strandlight_runtime::env_light::{EnvLight, shadow_groups};
use strandlight_runtime::hair::HairModel;
use strandlight_runtime::passes::convolution_depth::MAX_DODM_RESOLUTION;
use strandlight_scene::env_frame::{EnvFrame, FrameRole, fit_summary, forward_settings};
use strandlight_scene::env_light_sets::{frame_lights, reference_sources};
pub use strandlight_scene::env_lighting::ReferenceLighting;
use strandlight_scene::env_lighting::{EnvLightSet, EnvLighting};
use strandlight_scene::env_scene::{AlsoServe, PreparedEnv, prepare_env};
use strandlight_scene::frame_render::{
    FramePart, env_frame, env_look, load_settings_hair, settings_camera,
};
use strandlight_scene::frame_settings::{FrameSettings, Lighting};
use strandlight_scene::hair_input::fibers_for;
use strandlight_scene::head_input::load_head;
use strandlight_scene::image_metrics::{
    Image, ScaleErrors, error_legend, relative_rmse, write_side_by_side,
};
use strandlight_scene::look::EnvLook;
use strandlight_scene::rendered_frame::RenderedFrame;
use strandlight_scene::scene_tables::{EnvShading, ScatteringMode};
use strandlight_scene::steps::Steps;
use strandlight_tables::checksum::sha256_hex;
use strandlight_tables::image_out::{write_exr, write_png};

/// Everything one comparison is set by: the frame it measures (a [`FrameSettings`], exactly
/// what `render replay` draws) and what measuring adds. A plain value that the command line
/// builds, `bench` and the tests build directly, and every `compare --json` report records, so
/// `compare --settings REPORT.json` measures the same thing again. The reference and the
/// baseline are the same frame lit by their own light sets ([`EnvLightSet`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CompareSettings {
    /// The SRBF frame: hair, camera, fiber, map, rotation, head, look (its light set is the
    /// fit; its scattering is set per mode of `modes`).
    pub frame: FrameSettings,
    /// Print one JSON object on stdout (progress goes to stderr).
    pub json: bool,
    /// Lights of the brute-force reference, 6n² for n×n texels per cube face (6144 = the
    /// paper's 32×32×6; 1536, 384, 96 for quick runs). Default: converged, the first N of 96,
    /// 384, 1536, … whose image and that of 4N lights differ by at most
    /// `reference_tolerance`; the 4N image is the reference.
    pub reference_lights: Option<usize>,
    /// Relative RMSE between the N- and 4N-light references that counts as converged.
    pub reference_tolerance: f64,
    /// Most lights a converged reference may use (6n²); reached unconverged, the report says so.
    pub reference_max_lights: usize,
    /// The reference's shading cube, 6m² texels (m a multiple of every reference cube's n;
    /// 0, the default: every light shaded at its texel's centre, Ren 2010's brute force). The
    /// map is then shaded at this cube's texels, their visibility interpolated between the
    /// reference cube's shadow maps (precompute/src/env_lights.rs): the light passes stay the
    /// reference's, the shading costs more (docs/BENCHMARKS.md, "Shading the reference finer").
    pub reference_shading_lights: usize,
    /// Folder for the images.
    pub out: PathBuf,
    /// Cache folder (fits, tables, reference images).
    pub cache: PathBuf,
    /// Which modes to compare: single scattering, full (single + multiple), or both.
    pub modes: Vec<ScatteringMode>,
    /// Renders per timing (the median is reported).
    pub timing_runs: usize,
    /// Also search the fewest median-cut lights whose error is at most the SRBF frame's
    /// (Ren Fig. 6) and report the speed-up at equal error. Slow: it renders up to
    /// --reference-lights baseline lights.
    pub equal_error: bool,
    /// The directional-light baseline: median cut over the whole map (Debevec 2005, Ren's
    /// baseline), or the compact sources exactly and median cut over the rest.
    pub baseline: Baseline,
    /// The error --equal-error matches: relative RMSE, or HDR-FLIP over the hair.
    pub equal_error_metric: ErrorMetric,
    /// The path-traced ground truth (Mitsuba 3; the Chiang fiber only, which is Mitsuba's
    /// `hair`): `cached` measures every frame against it where `strandlight truth` or an
    /// earlier run rendered it, `render` renders what is missing (minutes), `off` never.
    pub ground_truth: TruthUse,
    /// Most samples per pixel of one ground-truth image (its ladder climbs ×4 from 1024, or from
    /// a quarter of this when that is less, until N and 4N agree within `reference_tolerance` or
    /// the next rung would pass this; at 640×480, 256 costs what 4096 costs at 160×120).
    pub truth_max_spp: u32,
}

impl Default for CompareSettings {
    /// The paper's comparison: 640×480, Marschner `brown`, a converged reference of up to
    /// 6144 lights, the default fit and look, the ground truth where it is cached.
    fn default() -> Self {
        let lighting = Lighting::Environment(EnvLighting::new(""));
        Self {
            frame: FrameSettings::new(lighting, [640, 480]),
            json: false,
            reference_lights: None,
            reference_tolerance: 0.01,
            reference_max_lights: 6144,
            reference_shading_lights: 0,
            out: PathBuf::from("out/compare"),
            cache: PathBuf::from("out/cache"),
            modes: vec![ScatteringMode::Single, ScatteringMode::Full],
            timing_runs: 3,
            equal_error: false,
            baseline: Baseline::MedianCut,
            equal_error_metric: ErrorMetric::RelativeRmse,
            ground_truth: TruthUse::Cached,
            truth_max_spp: TruthSettings::default().max_spp,
        }
    }
}

impl CompareSettings {
    /// The frame's environment lighting (`validate` refuses point-lit frames).
    pub fn env(&self) -> &EnvLighting {
        match &self.frame.lighting {
            Lighting::Environment(env) => env,
            Lighting::Lights(_) => panic!("compare settings are validated to be env-lit"),
        }
    }

    pub fn env_mut(&mut self) -> &mut EnvLighting {
        match &mut self.frame.lighting {
            Lighting::Environment(env) => env,
            Lighting::Lights(_) => panic!("compare settings are validated to be env-lit"),
        }
    }

    /// The fiber model of every frame.
    pub fn shading(&self) -> EnvShading {
        self.frame
            .env_shading()
            .expect("compare settings are validated to have an env fiber")
    }

    /// The frame of `mode` lit by `light_set`: what `render replay` of its JSON draws.
    pub fn frame_of(&self, mode: ScatteringMode, light_set: EnvLightSet) -> FrameSettings {
        let mut frame = self.frame.clone();
        if let Lighting::Environment(env) = &mut frame.lighting {
            env.scattering = mode;
            env.light_set = light_set;
        }
        frame
    }

    /// Reads settings JSON: the current form, or the flat one `compare --json` reports
    /// recorded before the frame was a [`FrameSettings`] (5 Dec 2026).
    pub fn from_json(value: Value) -> anyhow::Result<Self> {
        match serde_json::from_value::<Self>(value.clone()) {
            Ok(settings) => Ok(settings),
            Err(current) => crate::compare_settings_legacy::read(value)
                .map_err(|legacy| anyhow::anyhow!("{current} (nor the older form: {legacy})")),
        }
    }
}

/// The settings checked together, before any work (for callers that build them).
pub(crate) fn check_args(args: &CompareSettings) -> anyhow::Result<()> {
    validate(args).map(drop)
}

fn validate(args: &CompareSettings) -> anyhow::Result<ReferenceChoice> {
    let Lighting::Environment(env) = &args.frame.lighting else {
        bail!("compare measures env-lit frames: the settings' lighting must be an environment");
    };
    if env.map.is_empty() {
        bail!("--env: no environment given (on the command line or in --settings)");
    }
    if !env.light_set.is_fit() {
        bail!("the compared frame is the SRBF fit's (its light set must be `fit`)");
    }
    if args.timing_runs == 0 {
        bail!("timing_runs 0: at least one render per timing");
    }
    if !(1..=MAX_DODM_RESOLUTION).contains(&env.dodm_size) {
        bail!(
            "--light-map-size {}: texels across a light map, 1 to {MAX_DODM_RESOLUTION}",
            env.dodm_size
        );
    }
    args.frame.check()?;
    if !(args.reference_tolerance > 0.0 && args.reference_tolerance < 1.0) {
        bail!(
            "reference_tolerance {}: must be in (0, 1)",
            args.reference_tolerance
        );
    }
    crate::ground_truth::validate(&truth_settings(args))
        .map_err(|e| anyhow::anyhow!("--truth-max-spp {}: {e}", args.truth_max_spp))?;
    let check = |flag: &str, count: usize| {
        face_resolution_for(count).with_context(|| {
            format!("{flag} {count}: must be 6n² for a cube of n×n texels per face (e.g. 6, 24, 96, 384, 1536, 6144)")
        })
    };
    let most = check("reference_max_lights", args.reference_max_lights)?;
    if most < 2 * FIRST_CONVERGENCE_FACE {
        bail!(
            "reference_max_lights {}: a converged reference compares N with 4N lights from {} up; allow at least {}",
            args.reference_max_lights,
            6 * FIRST_CONVERGENCE_FACE * FIRST_CONVERGENCE_FACE,
            24 * FIRST_CONVERGENCE_FACE * FIRST_CONVERGENCE_FACE
        );
    }
    let choice = match args.reference_lights {
        Some(count) => ReferenceChoice::Fixed(check("--reference-lights", count)?),
        None => ReferenceChoice::Converged { most_face: most },
    };
    if let Some(m) = shading_face(args)? {
        let finest = choice.finest_face();
        if m < finest || !m.is_multiple_of(finest) {
            bail!(
                "reference_shading_lights {}: its {m}² texels per face must split every reference texel, up to the finest cube's {finest}²: use 6m² with m a multiple of {finest}",
                args.reference_shading_lights
            );
        }
    }
    Ok(choice)
}

/// The reference's shading cube's face resolution m (None: shaded at the texel lights).
fn shading_face(args: &CompareSettings) -> anyhow::Result<Option<usize>> {
    match args.reference_shading_lights {
        0 => Ok(None),
        count => face_resolution_for(count).map(Some).with_context(|| {
            format!("reference_shading_lights {count}: must be 0 or 6m² (e.g. 24576 = 6·64², 98304 = 6·128²)")
        }),
    }
}

/// The smallest cube a converged reference starts from (n = 4: 96 lights).
const FIRST_CONVERGENCE_FACE: usize = 4;

/// Which reference `compare` renders.
#[derive(Debug, Clone, Copy, PartialEq)]
enum ReferenceChoice {
    /// 6n² lights for n texels per face side.
    Fixed(usize),
    /// N = 6n², then 4N, … up to 6·most_face² lights, until N and 4N agree.
    Converged { most_face: usize },
}

impl ReferenceChoice {
    /// The face resolution of the finest cube it may render.
    fn finest_face(&self) -> usize {
        match *self {
            Self::Fixed(n) => n,
            Self::Converged { most_face } => {
                let mut face = FIRST_CONVERGENCE_FACE;
                while 2 * face <= most_face {
                    face *= 2;
                }
                face
            }
        }
    }
}

/// Everything fixed before the first render: the hair and the prepared environment (fit,
/// tables, map) every frame of the comparison is built from.
pub struct CompareScene {
    pub hair: HairModel,
    /// Identifies the hair in the reference and truth caches.
    pub hair_sha256: String,
    pub prepared: PreparedEnv,
}

impl CompareScene {
    /// The map's content hash.
    pub fn map_sha256(&self) -> &str {
        &self
            .prepared
            .map()
            .expect("compare prepares the map")
            .sha256
    }

    /// The map.
    pub fn map(&self) -> &strandlight_precompute::EnvMap {
        &self.prepared.map().expect("compare prepares the map").map
    }
}

/// Loads the hair (the settings' file, or the procedural groom), fits, bakes and builds the
/// light sets (every step timed into `steps`).
pub fn prepare(args: &CompareSettings, steps: &mut Steps) -> anyhow::Result<CompareScene> {
    validate(args)?;
    let hair = steps.run(
        "hair",
        || load_settings_hair(&args.frame),
        |h| format!("{} ({} strands)", h.source, h.model.strand_count()),
    )?;
    prepare_with_hair(args, hair.model, hair.identity, steps)
}

/// [`prepare`] for a hair already loaded (`hair_sha256` identifies it in the reference cache).
pub fn prepare_with_hair(
    args: &CompareSettings,
    hair: HairModel,
    hair_sha256: String,
    steps: &mut Steps,
) -> anyhow::Result<CompareScene> {
    validate(args)?;
    let (hair, hair_sha256) = fibers_for(args.shading(), hair, hair_sha256);
    let also = AlsoServe {
        full_scattering: args.modes.contains(&ScatteringMode::Full),
        directional_sets: true,
    };
    let prepared = prepare_env(&args.frame, &hair, &args.cache, also, steps, &mut |_| {})?;
    steps.say(fit_summary(&prepared.scene.fit));
    Ok(CompareScene {
        hair,
        hair_sha256,
        prepared,
    })
}

/// The function that renders a frame: [`render_lights`] in the program, a stand-in in tests.
pub type Renderer<'r> = &'r dyn Fn(&EnvFrame) -> anyhow::Result<RenderedFrame>;

/// Renders `runs` times and keeps the last image with the median time.
pub fn timed_render(
    render: Renderer,
    frame: &EnvFrame,
    runs: usize,
) -> anyhow::Result<RenderedFrame> {
    let mut times = Vec::with_capacity(runs);
    let mut last = None;
    for _ in 0..runs {
        let r = render(frame)?;
        times.push(r.milliseconds);
        last = Some(r);
    }
    times.sort_by(f64::total_cmp);
    let mut r = last.expect("runs ≥ 1");
    r.milliseconds = times[times.len() / 2];
    Ok(r)
}

/// One reference image, rendered or from the cache.
pub struct ReferenceImage {
    pub image: Image,
    pub record: ReferenceRecord,
    pub cached: bool,
}

/// The reference a mode is measured against, and how it was reached.
pub struct Reference {
    pub chosen: ReferenceImage,
    /// Per rung of a converged reference: N lights, their ms, and the relative RMSE of the
    /// N-light image against the 4N-light one.
    pub ladder: Vec<(usize, f64, f64)>,
    /// Converged references: whether the last rung met the tolerance.
    pub converged: Option<bool>,
}

/// One mode's results.
struct ModeResult {
    srbf: RenderedFrame,
    srbf_lights: usize,
    srbf_flip: HdrFlip,
    baseline_flip: HdrFlip,
    reference: Reference,
    baseline: RenderedFrame,
    baseline_lights: usize,
    baseline_search: Vec<(usize, f64)>,
    equal_error: Option<EqualErrorResult>,
    /// The path-traced ground truth, where the fiber has one and it is cached or rendered.
    truth: Option<GroundTruth>,
}

/// The equal-error baseline: the count found and (lights, ms, relative RMSE) of every render.
struct EqualErrorResult {
    lights: usize,
    at_bound: bool,
    renders: Vec<(usize, f64, f64)>,
}

impl EqualErrorResult {
    fn chosen(&self) -> (usize, f64, f64) {
        *self
            .renders
            .iter()
            .find(|r| r.0 == self.lights)
            .expect("the chosen count was rendered")
    }
}

/// The baseline's (`--baseline`) lights for a budget of `count`: exactly `count`, except that
/// median cut with exact sources keeps every source and at least one light for the rest.
pub fn baseline_set(
    scene: &CompareScene,
    args: &CompareSettings,
    count: usize,
) -> anyhow::Result<Vec<EnvLight>> {
    let settings = args.frame_of(ScatteringMode::Single, args.baseline.light_set(count));
    let Lighting::Environment(env) = &settings.lighting else {
        unreachable!("compare frames are env-lit")
    };
    frame_lights(&scene.prepared, env)
}

/// The baseline (`--baseline`) with a budget of `lights` directional lights ([`baseline_set`]).
pub fn render_baseline(
    render: Renderer,
    scene: &CompareScene,
    args: &CompareSettings,
    mode: ScatteringMode,
    lights: usize,
) -> anyhow::Result<RenderedFrame> {
    let settings = args.frame_of(mode, args.baseline.light_set(lights));
    timed_render(render, &frame(scene, &settings)?, args.timing_runs)
}

/// Median-cut baselines of growing size (up to `most` lights) until one is as accurate as
/// `target_error` against `yardstick` (the ground truth where there is one, else the reference).
#[allow(clippy::too_many_arguments)]
fn equal_error_baseline(
    render: Renderer,
    scene: &CompareScene,
    args: &CompareSettings,
    mode: ScatteringMode,
    yardstick: &Image,
    most: usize,
    target_error: f64,
    start: usize,
) -> anyhow::Result<EqualErrorResult> {
    let mut renders = Vec::new();
    let found = equal_error_lights(target_error, start, most.max(16), 0.1, 10, |n| {
        let r = render_baseline(render, scene, args, mode, n)?;
        let error = args.equal_error_metric.measure(&r.image, yardstick)?;
        // A search near the reference's light count renders for many minutes: say each step
        // (stderr, so `--json` keeps stdout for the JSON).
        eprintln!(
            "  equal-error search: {n} lights of {} → {} {error:.4} (target {target_error:.4}), {:.0} ms/frame",
            args.baseline.name(),
            args.equal_error_metric.name(),
            r.milliseconds
        );
        renders.push((n, r.milliseconds, error));
        Ok::<f64, anyhow::Error>(error)
    })?;
    Ok(EqualErrorResult {
        lights: found.lights,
        at_bound: found.at_bound,
        renders,
    })
}

/// The ground-truth settings of `args`.
pub fn truth_settings(args: &CompareSettings) -> TruthSettings {
    TruthSettings::with_budget(args.truth_max_spp, args.reference_tolerance)
}

/// Mitsuba's `hair` parameters of the scene's fiber, where the shading model is the one the
/// path tracer has (Chiang et al. 2016); None for the others, which the DOM reference measures.
pub fn truth_fiber(scene: &CompareScene, args: &CompareSettings) -> Option<Value> {
    (args.shading() == EnvShading::Chiang).then(|| {
        serde_json::to_value(&scene.prepared.fiber.chiang).expect("fiber parameters serialize")
    })
}

/// The path-traced ground truth of `mode` (cached, rendered or none: `--ground-truth`): the
/// scene `truth --export` writes for the same frame settings.
pub fn truth_of(
    scene: &CompareScene,
    args: &CompareSettings,
    mode: ScatteringMode,
    steps: &mut Steps,
) -> anyhow::Result<Option<GroundTruth>> {
    let Some(fiber) = truth_fiber(scene, args) else {
        return Ok(None);
    };
    let head = load_head(&args.frame.head, &scene.hair, args.frame.skin_albedo)?;
    let inputs = TruthInputs {
        scene: MitsubaScene::of_frame(
            &args.frame,
            &scene.hair,
            (scene.map(), scene.prepared.up),
            &fiber,
            head.as_ref(),
        )?,
        hair_sha256: &scene.hair_sha256,
        map_sha256: scene.map_sha256(),
    };
    ground_truth(
        &inputs,
        mode,
        &truth_settings(args),
        args.ground_truth,
        &args.cache,
        steps,
    )
}

/// The frame of `settings` (one of `args.frame_of`'s) over the comparison's scene: built by the
/// one env-lit frame builder, as `render replay` of the same settings builds it.
pub fn frame<'a>(
    scene: &'a CompareScene,
    settings: &FrameSettings,
) -> anyhow::Result<EnvFrame<'a>> {
    env_frame(
        settings,
        &scene.hair,
        &scene.prepared,
        FramePart::Whole,
        false,
    )
}

/// The look of every frame of `args` (checked by `validate`).
fn look(args: &CompareSettings) -> EnvLook {
    env_look(args.env()).expect("checked by validate")
}

/// The multiple-scattering tables a directional reference reads (`srbf_spread` serves SRBF
/// lights only; it follows the fit's λ range, which must not invalidate a reference).
const REFERENCE_MULTIPLE_TABLES: [&str; 3] = ["multiple", "fiber_averages", "attenuation_ratio"];

/// What identifies a reference image: everything its render reads, nothing else.
fn reference_inputs(
    scene: &CompareScene,
    args: &CompareSettings,
    face: usize,
    lights: usize,
    mode: ScatteringMode,
    lighting: ReferenceLighting,
) -> anyhow::Result<Value> {
    let prepared = &scene.prepared;
    let tables = &prepared.scene.tables;
    let direct = tables.get(args.shading().direct_table(mode))?;
    let env = args.env();
    let [width, height] = args.frame.size;
    let mut inputs = json!({
        "hair_sha256": scene.hair_sha256,
        "camera": format!("{:?}", settings_camera(&args.frame, &scene.hair)?),
        "size": [width, height],
        "map_sha256": scene.map_sha256(),
        "rotate": env.rotation_deg as f64,
        "reference_lights": lights,
        "reference_placement": "compact sources exact, texel lights at texel centres",
        "reference_sources": reference_sources(),
        "mode": mode.name(),
        "shading": args.shading(),
        "fiber": prepared.fiber,
        "direct_table_inputs": direct.metadata.description.inputs_key,
        "multiple_tables_inputs": REFERENCE_MULTIPLE_TABLES.iter().filter(|_| mode == ScatteringMode::Full).filter_map(|n| tables.assets.get(*n)).map(|a| a.metadata.description.inputs_key.clone()).collect::<Vec<_>>(),
        "generator": env!("CARGO_PKG_VERSION"),
        "renderer": format!("{:?} / {:?}", EnvRenderOptions { kappa: 1.0, shadowed: env.shadowed, transparency: look(args).transparency, dodm: look(args).dodm, ..EnvRenderOptions::default() }, forward_settings(FrameRole::Reference)),
    });
    // Occupancy references rendered before the view's weights were rescaled to each pixel's
    // coverage are not this renderer's: the key tells them apart (opaque ones keep theirs).
    if look(args).transparency.uses_occupancy_map() {
        inputs["view_weights"] = json!("rescaled to each pixel's coverage");
    }
    // Layered references rendered before their texel lights were shaded per layer (as lights
    // standing for regions, 2 Dec 2026) shaded them per fragment, and before 6 Dec 2026 their
    // compact sources too: not this renderer's.
    if matches!(look(args).transparency, ViewTransparency::Layered { .. }) {
        inputs["region_lights"] =
            json!("per layer; compact sources per layer at their fibers' mean visibility");
    }
    // Only the fit's lighting adds a key, so the map's references keep their cache entries.
    // Only with a head: the references rendered before it keep their keys.
    if let Some(head) = load_head(&args.frame.head, &scene.hair, args.frame.skin_albedo)? {
        inputs["head"] = json!(format!("{:016x}", head.fingerprint()));
    }
    if lighting == ReferenceLighting::Fit {
        let fit_lights = srbf_set_lights(&prepared.scene.fit);
        inputs["reference_lighting"] = json!({
            "fit_lights": sha256_hex(format!("{fit_lights:?}").as_bytes()),
            "placement": "fit's sources exact, its lobes' radiance sampled on the map's grid, texel lights at texel centres",
        });
    }
    // Only a finer shading cube adds a key, so brute-force references keep their cache entries.
    if let Some(m) = shading_face(args)?.filter(|&m| m > face) {
        inputs["reference_shading"] = json!(format!(
            "{m}² texels per face, visibility interpolated between the {face}² texels' maps"
        ));
    }
    Ok(inputs)
}

fn run_mode(
    render: Renderer,
    scene: &CompareScene,
    args: &CompareSettings,
    mode: ScatteringMode,
    steps: &mut Steps,
) -> anyhow::Result<ModeResult> {
    let m = mode.name();
    let srbf_frame = frame(scene, &args.frame_of(mode, EnvLightSet::Fit))?;
    let srbf_lights = srbf_frame.lights.len();
    let srbf = steps.run(
        &format!("{m}: SRBF"),
        || timed_render(render, &srbf_frame, args.timing_runs),
        |r| format!("{:.2} ms/frame, {srbf_lights} lights", r.milliseconds),
    )?;
    let reference = reference(render, scene, args, mode, steps)?;
    let truth = truth_of(scene, args, mode, steps)?;
    let reference_lights = reference.chosen.record.lights;
    let search = EqualTimeSearch {
        max_lights: reference_lights.max(16),
        ..EqualTimeSearch::new(srbf.milliseconds)
    };
    // Every image the search renders is kept, so the chosen count need not be rendered again.
    let mut searched: std::collections::HashMap<usize, RenderedFrame> =
        std::collections::HashMap::new();
    let found = steps.run(
        &format!("{m}: baseline"),
        || {
            equal_time_lights(&search, |n| {
                let r = render_baseline(render, scene, args, mode, n)?;
                let ms = r.milliseconds;
                searched.insert(n, r);
                Ok::<f64, anyhow::Error>(ms)
            })
        },
        |f| {
            format!(
                "{} lights of {} at {:.2} ms/frame ({} searches{})",
                f.lights,
                args.baseline.name(),
                f.milliseconds,
                f.measurements.len(),
                if f.at_bound {
                    ", at the search bound"
                } else {
                    ""
                }
            )
        },
    )?;
    let baseline = match searched.remove(&found.lights) {
        Some(r) => r,
        None => render_baseline(render, scene, args, mode, found.lights)?,
    };
    // The equal-error search measures against the best yardstick there is.
    let yardstick = truth.as_ref().map_or(&reference.chosen.image, |t| &t.image);
    let equal_error = if args.equal_error {
        let metric = args.equal_error_metric;
        let target = metric.measure(&srbf.image, yardstick)?;
        Some(steps.run(
            &format!("{m}: equal-error baseline"),
            || {
                equal_error_baseline(
                    render,
                    scene,
                    args,
                    mode,
                    yardstick,
                    reference_lights,
                    target,
                    found.lights,
                )
            },
            |e: &EqualErrorResult| {
                let (n, ms, err) = e.chosen();
                if e.at_bound {
                    format!("NOT reached: {n} lights of {}, the search bound, give {} {err:.4} > {target:.4} at {ms:.2} ms/frame ({} renders)", args.baseline.name(), metric.name(), e.renders.len())
                } else {
                    format!("{n} lights of {} reach {} {err:.4} ≤ {target:.4} at {ms:.2} ms/frame ({} renders)", args.baseline.name(), metric.name(), e.renders.len())
                }
            },
        )?)
    } else {
        None
    };
    let srbf_flip = hdr_flip(&srbf.image, &reference.chosen.image)?;
    let baseline_flip = hdr_flip(&baseline.image, &reference.chosen.image)?;
    Ok(ModeResult {
        srbf,
        srbf_flip,
        baseline_flip,
        reference,
        baseline,
        srbf_lights,
        baseline_lights: baseline_set(scene, args, found.lights)?.len(),
        baseline_search: found.measurements,
        equal_error,
        truth,
    })
}

/// What the steps call a reference of `lighting` under `args`.
fn reference_name(lighting: ReferenceLighting, args: &CompareSettings) -> &'static str {
    match (lighting, !args.env().shadowed) {
        (ReferenceLighting::Map, false) => "reference",
        (ReferenceLighting::Map, true) => "unshadowed reference",
        (ReferenceLighting::Fit, false) => "reference of the fit",
        (ReferenceLighting::Fit, true) => "unshadowed reference of the fit",
    }
}

/// The reference of `mode` with 6·face² lights, from the cache or rendered (and cached).
fn reference_with_face(
    render: Renderer,
    scene: &CompareScene,
    args: &CompareSettings,
    mode: ScatteringMode,
    face: usize,
    lighting: ReferenceLighting,
    steps: &mut Steps,
) -> anyhow::Result<ReferenceImage> {
    let light_set = EnvLightSet::Reference {
        face,
        shading_face: shading_face(args)?,
        lighting,
    };
    let reference_frame = frame(scene, &args.frame_of(mode, light_set))?;
    // What a reference costs is its shadow maps: one per compact source and per texel.
    let maps = shadow_groups(&reference_frame.lights).len();
    let cache = ReferenceCache::new(args.cache.join("reference"));
    let inputs = reference_inputs(scene, args, face, maps, mode, lighting)?;
    let what = reference_name(lighting, args);
    steps.run(
        &format!("{}: {what}, {maps} lights", mode.name()),
        || match cache.load(&inputs) {
            Some((image, record)) => Ok(ReferenceImage {
                image,
                record,
                cached: true,
            }),
            None => {
                let r = render(&reference_frame)?;
                let record = ReferenceRecord {
                    inputs: inputs.clone(),
                    lights: maps,
                    milliseconds: r.milliseconds,
                };
                cache.store(&r.image, &record)?;
                Ok(ReferenceImage {
                    image: r.image,
                    record,
                    cached: false,
                })
            }
        },
        |r: &ReferenceImage| {
            format!(
                "{:.1} ms/frame{}",
                r.record.milliseconds,
                if r.cached { " (cached)" } else { "" }
            )
        },
    )
}

/// The reference of `mode`: the fixed light count asked for, or the converged one (N and 4N
/// lights within the tolerance, the 4N image kept).
pub fn reference(
    render: Renderer,
    scene: &CompareScene,
    args: &CompareSettings,
    mode: ScatteringMode,
    steps: &mut Steps,
) -> anyhow::Result<Reference> {
    reference_of(render, scene, args, mode, ReferenceLighting::Map, steps)
}

/// [`reference`] lit by `lighting`.
pub fn reference_of(
    render: Renderer,
    scene: &CompareScene,
    args: &CompareSettings,
    mode: ScatteringMode,
    lighting: ReferenceLighting,
    steps: &mut Steps,
) -> anyhow::Result<Reference> {
    let most_face = match validate(args)? {
        ReferenceChoice::Fixed(face) => {
            return Ok(Reference {
                chosen: reference_with_face(render, scene, args, mode, face, lighting, steps)?,
                ladder: Vec::new(),
                converged: None,
            });
        }
        ReferenceChoice::Converged { most_face } => most_face,
    };
    let mut face = FIRST_CONVERGENCE_FACE;
    let mut coarse = reference_with_face(render, scene, args, mode, face, lighting, steps)?;
    let mut ladder = Vec::new();
    loop {
        let fine = reference_with_face(render, scene, args, mode, 2 * face, lighting, steps)?;
        let difference = relative_rmse(&coarse.image, &fine.image)?;
        ladder.push((coarse.record.lights, coarse.record.milliseconds, difference));
        steps.say(format!(
            "{}: {} with {} lights against {}: relative RMSE {difference:.4} (tolerance {})",
            mode.name(),
            reference_name(lighting, args),
            coarse.record.lights,
            fine.record.lights,
            args.reference_tolerance
        ));
        let converged = difference <= args.reference_tolerance;
        if converged || 4 * face > most_face {
            return Ok(Reference {
                chosen: fine,
                ladder,
                converged: Some(converged),
            });
        }
        face *= 2;
        coarse = fine;
    }
}

fn write_mode_images(
    args: &CompareSettings,
    mode: ScatteringMode,
    r: &ModeResult,
    description: &str,
) -> anyhow::Result<Vec<PathBuf>> {
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create {}", args.out.display()))?;
    let mut written = Vec::new();
    for (name, image) in [
        ("srbf", &r.srbf.image),
        ("reference", &r.reference.chosen.image),
        ("baseline", &r.baseline.image),
    ] {
        let stem = args.out.join(format!("{}-{name}", mode.name()));
        write_exr(
            &stem.with_extension("exr"),
            image.width,
            image.height,
            &image.pixels,
            description,
        )?;
        write_png(
            &stem.with_extension("png"),
            image.width,
            image.height,
            &image.pixels,
            description,
        )?;
        written.push(stem.with_extension("png"));
    }
    for (name, flip) in [("srbf", &r.srbf_flip), ("baseline", &r.baseline_flip)] {
        let path = args.out.join(format!("{}-{name}-flip.png", mode.name()));
        let (w, h) = (
            r.reference.chosen.image.width,
            r.reference.chosen.image.height,
        );
        strandlight_tables::image_out::write_png_rgb8(
            &path,
            w,
            h,
            &error_map_magma(flip, w, h),
            &format!("HDR-FLIP error map (magma, 0 → 1) of the {name} frame: {description}"),
        )?;
        written.push(path);
    }
    let side = args.out.join(format!("{}-compare.png", mode.name()));
    write_side_by_side(
        &side,
        &r.srbf.image,
        &r.reference.chosen.image,
        &r.baseline.image,
        description,
    )?;
    written.push(side);
    Ok(written)
}

/// Renders both modes three ways with `render`, writes the images and returns the report
/// (`{"single": {...}, "full": {...}, "steps": [...]}`; the shape of the issue's JSON).
pub fn execute(
    args: &CompareSettings,
    scene: &CompareScene,
    steps: &mut Steps,
    render: Renderer,
) -> anyhow::Result<Value> {
    let mut report = serde_json::Map::new();
    // What `compare --settings REPORT.json` reads back to measure the same thing again.
    report.insert("settings".into(), serde_json::to_value(args)?);
    let env = args.env();
    let hair_name = hair_name(&args.frame);
    let description = format!(
        "strandlight compare: {hair_name} under {} ({:?}, preset {})",
        env.map,
        args.shading(),
        args.frame.preset
    );
    if let Some(&first) = args.modes.first() {
        // Drivers compile shader variants at their first draw (lavapipe: seconds): not a frame's cost.
        let warm_up = frame(scene, &args.frame_of(first, EnvLightSet::Fit))?;
        steps.run(
            "warm-up",
            || render(&warm_up),
            |r| format!("{:.0} ms, untimed", r.milliseconds),
        )?;
    }
    for &mode in &args.modes {
        let r = run_mode(render, scene, args, mode, steps)?;
        let reference = &r.reference.chosen;
        let srbf_error = relative_rmse(&r.srbf.image, &reference.image)?;
        let baseline_error = relative_rmse(&r.baseline.image, &reference.image)?;
        let written = write_mode_images(args, mode, &r, &description)?;
        let reference_ms = reference.record.milliseconds;
        let ladder: Vec<Value> = r
            .reference
            .ladder
            .iter()
            .map(|&(lights, ms, d)| json!({"lights": lights, "ms": ms, "relative_rmse_vs_4x": d}))
            .collect();
        let mut entry = json!({
                "srbf": { "lights": r.srbf_lights, "ms": r.srbf.milliseconds, "relative_rmse": srbf_error, "hdr_flip": r.srbf_flip.mean_over_hair },
                "baseline": { "lights": r.baseline_lights, "ms": r.baseline.milliseconds, "relative_rmse": baseline_error, "hdr_flip": r.baseline_flip.mean_over_hair, "search": r.baseline_search },
                "hdr_flip_exposures": { "start": r.srbf_flip.start_exposure, "stop": r.srbf_flip.stop_exposure, "count": r.srbf_flip.exposures },
                "reference": { "lights": reference.record.lights, "ms": reference_ms, "cached": reference.cached, "converged": r.reference.converged, "convergence": ladder },
                "speedup_vs_reference": reference_ms / r.srbf.milliseconds,
                "images": written,
        });
        if let Some(truth) = &r.truth {
            let stem = args.out.join(format!("{}-truth", mode.name()));
            crate::ground_truth::write_truth_image(truth, &stem, &description)?;
            entry["ground_truth"] = truth_json(
                truth,
                &[
                    ("srbf", &r.srbf.image),
                    ("baseline", &r.baseline.image),
                    ("reference", &reference.image),
                ],
            )?;
            steps.say(truth_line(mode, truth, &entry["ground_truth"]));
        }
        if let Some(e) = &r.equal_error {
            let (lights, ms, error) = e.chosen();
            entry["baseline_equal_error"] = json!({ "lights": lights, "ms": ms, "metric": args.equal_error_metric, "yardstick": if r.truth.is_some() { "ground truth" } else { "reference" }, "error": error, "at_bound": e.at_bound, "renders": e.renders });
            entry["speedup_at_equal_error"] = json!(ms / r.srbf.milliseconds);
        }
        report.insert(mode.name().into(), entry);
        steps.say(format!(
            "{:<6} SRBF {:>8.2} ms rel. RMSE {:.4} HDR-FLIP {:.4} | baseline {} lights {:>8.2} ms rel. RMSE {:.4} HDR-FLIP {:.4} | reference {} lights {:>10.1} ms | speed-up vs reference {:.0}×",
            mode.name(), r.srbf.milliseconds, srbf_error, r.srbf_flip.mean_over_hair, r.baseline_lights, r.baseline.milliseconds, baseline_error, r.baseline_flip.mean_over_hair, reference.record.lights, reference_ms, reference_ms / r.srbf.milliseconds
        ));
    }
    steps.say(error_legend());
    report.insert(
        "scene".into(),
        json!({
            "hair": hair_name, "env": env.map, "size": args.frame.size, "shading": args.shading(),
            "preset": args.frame.preset, "baseline": args.baseline, "lambda_max": env.fit.lambda_max, "sources": env.fit.sources, "source_radius": env.fit.source_radius, "source_min_share": env.fit.source_min_share, "wider_source_radius": env.fit.wider_source_radius, "light_map_size": env.dodm_size, "kappa": env.kappa, "timing_runs": args.timing_runs, "unshadowed": !env.shadowed,
            "rotate": env.rotation_deg, "head": args.frame.head,
            "transparency": env.transparency, "visibility_cutoff": env.view.visibility_cutoff, "lobe_visibility": env.view.lobe_visibility, "forward_scattering": env.view.forward_scattering,
            "fit_relative_l2_error": scene.prepared.scene.fit.relative_l2_error,
            "compact_sources": scene.prepared.scene.fit.sources,
        }),
    );
    report.insert(
        "steps".into(),
        json!(
            steps
                .done
                .iter()
                .map(|(n, s, note)| json!({"step": n, "seconds": s, "note": note}))
                .collect::<Vec<_>>()
        ),
    );
    Ok(Value::Object(report))
}

/// The hair file's name, or the procedural groom's.
pub fn hair_name(frame: &FrameSettings) -> String {
    match &frame.hair {
        Some(path) => path.display().to_string(),
        None => "the procedural groom".into(),
    }
}

/// The ground truth's record and each frame's error against it (raw, and with the truth's
/// own noise removed in quadrature).
fn truth_json(truth: &GroundTruth, frames: &[(&str, &Image)]) -> anyhow::Result<Value> {
    let mut v = json!({
        "renderer": format!("Mitsuba {} (scalar_rgb, path, hair BSDF)", truth.mitsuba),
        "spp": truth.spp,
        "max_depth": truth.max_depth,
        "seconds": truth.seconds,
        "converged": truth.converged,
        "noise": truth.noise,
        "ladder": truth.ladder,
        "depth_ladder": truth.depth_ladder,
        "fibers": "opaque cylinders of the file's width (its transparency field ignored)",
    });
    for (name, image) in frames {
        let e = relative_rmse(image, &truth.image)?;
        v[*name] = json!({
            "relative_rmse": e,
            "relative_rmse_noise_corrected": truth.noise_corrected(e),
            "hdr_flip": hdr_flip(image, &truth.image)?.mean_over_hair,
            "scales": ScaleErrors::of(image, &truth.image)?,
        });
    }
    Ok(v)
}

fn truth_line(mode: ScatteringMode, truth: &GroundTruth, figures: &Value) -> String {
    let part = |name: &str| {
        let scales = serde_json::from_value::<ScaleErrors>(figures[name]["scales"].clone())
            .map_or_else(|_| String::new(), |s| format!(", {}", s.line()));
        format!(
            "{name} rel. RMSE {:.4} ({:.4} without the truth's noise) HDR-FLIP {:.4}{scales}",
            figures[name]["relative_rmse"].as_f64().unwrap_or(f64::NAN),
            figures[name]["relative_rmse_noise_corrected"]
                .as_f64()
                .unwrap_or(f64::NAN),
            figures[name]["hdr_flip"].as_f64().unwrap_or(f64::NAN),
        )
    };
    format!(
        "{:<6} against the path-traced ground truth ({} spp, depth {}, noise {:.4}{}, Mitsuba {:.1} s): {} | {} | {}",
        mode.name(),
        truth.spp,
        truth.max_depth,
        truth.noise,
        if truth.converged {
            ""
        } else {
            ", not converged"
        },
        truth.seconds,
        part("srbf"),
        part("baseline"),
        part("reference")
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use strandlight_scene::environment::load_env;
    use strandlight_scene::fit_cache::fit_cached;
    use strandlight_scene::point_shading::Shading;
    use strandlight_scene::rendered_frame::FrameDetails;

    /// Settings for hair `h` under map `e`, changed by `change`.
    fn settings(change: impl FnOnce(&mut CompareSettings)) -> CompareSettings {
        let mut s = CompareSettings::default();
        s.frame.hair = Some("h".into());
        s.env_mut().map = "e".into();
        change(&mut s);
        s
    }

    #[test]
    fn settings_default_to_the_issue_and_bad_values_are_named() {
        let a = settings(|_| {});
        assert_eq!(
            (
                a.env().fit.max_lobes,
                a.frame.size,
                a.reference_lights,
                a.shading()
            ),
            (64, [640, 480], None, EnvShading::Chiang)
        );
        assert_eq!(
            validate(&a).unwrap(),
            ReferenceChoice::Converged { most_face: 32 }
        );
        type Change = Box<dyn Fn(&mut CompareSettings)>;
        let cases: Vec<(&str, &str, Change)> = vec![
            (
                "reference_shading_lights 100",
                "6m²",
                Box::new(|s| s.reference_shading_lights = 100),
            ),
            (
                "reference_shading_lights 1536",
                "multiple of 32",
                Box::new(|s| s.reference_shading_lights = 1536),
            ),
            (
                "reference_max_lights 100",
                "6n²",
                Box::new(|s| s.reference_max_lights = 100),
            ),
            (
                "reference_max_lights 96",
                "allow at least 384",
                Box::new(|s| s.reference_max_lights = 96),
            ),
            (
                "reference_tolerance 0",
                "(0, 1)",
                Box::new(|s| s.reference_tolerance = 0.0),
            ),
            (
                "--light-map-size 0",
                "1 to 2048",
                Box::new(|s| s.env_mut().dodm_size = 0),
            ),
            (
                "--light-map-size 4096",
                "1 to 2048",
                Box::new(|s| s.env_mut().dodm_size = 4096),
            ),
            (
                "--truth-max-spp 3",
                "at least 4",
                Box::new(|s| s.truth_max_spp = 3),
            ),
            (
                "max_lobes 0",
                "at least one",
                Box::new(|s| s.env_mut().fit.max_lobes = 0),
            ),
            (
                "--reference-lights 100",
                "6n²",
                Box::new(|s| s.reference_lights = Some(100)),
            ),
            (
                "--env",
                "no environment",
                Box::new(|s| s.env_mut().map.clear()),
            ),
        ];
        for (named, wanted, change) in cases {
            let e = validate(&settings(change)).unwrap_err().to_string();
            assert!(e.contains(named) && e.contains(wanted), "{named}: {e}");
        }
        let a = settings(|s| {
            s.frame.shading = Some(Shading::Artist);
            s.reference_lights = Some(96);
        });
        assert_eq!(validate(&a).unwrap(), ReferenceChoice::Fixed(4));
        let a = settings(|s| s.reference_shading_lights = 24576);
        assert_eq!(
            validate(&a).unwrap(),
            ReferenceChoice::Converged { most_face: 32 }
        );
        let point_lit = settings(|s| {
            s.frame.lighting = Lighting::Lights(Default::default());
        });
        let e = validate(&point_lit).unwrap_err().to_string();
        assert!(e.contains("env-lit"), "{e}");
    }

    #[test]
    fn a_missing_hair_file_is_named_before_any_work() {
        let a = settings(|s| {
            s.frame.hair = Some("/nonexistent/straight.hair".into());
            s.env_mut().map = "procedural:studio".into();
            s.reference_lights = Some(96);
        });
        let e = prepare(&a, &mut Steps::new(true)).err().expect("must fail");
        assert!(
            format!("{e:#}").contains("/nonexistent/straight.hair"),
            "{e:#}"
        );
    }

    /// The procedural studio at `size` over a hair of the caller's, with a fit of 8 lobes and
    /// tables of 4 nodes an axis: quick to prepare.
    fn small_frame(size: [u32; 2]) -> FrameSettings {
        let mut env = EnvLighting::new("procedural:studio");
        env.fit.max_lobes = 8;
        env.table_resolution = Some(4);
        FrameSettings::new(Lighting::Environment(env), size)
    }

    /// A stand-in renderer whose picture is known without a GPU: every pixel of a central
    /// block (alpha 1) holds the set's total power Σ power() per channel, the rest is empty;
    /// a frame costs 1 ms + 0.01 ms per light.
    fn power_renderer(frame: &EnvFrame) -> anyhow::Result<RenderedFrame> {
        let total = frame.lights.iter().fold([0f32; 3], |a, l| {
            let p = l.power();
            [a[0] + p[0], a[1] + p[1], a[2] + p[2]]
        });
        let (w, h) = (frame.width, frame.height);
        let pixels = (0..w * h)
            .map(|i| {
                let (x, y) = (i % w, i / w);
                if (w / 4..3 * w / 4).contains(&x) && (h / 4..3 * h / 4).contains(&y) {
                    [total[0], total[1], total[2], 1.0]
                } else {
                    [0.0; 4]
                }
            })
            .collect();
        Ok(RenderedFrame {
            image: Image::new(w, h, pixels),
            milliseconds: 1.0 + 0.01 * frame.lights.len() as f64,
            passes: Vec::new(),
            memory: Vec::new(),
            adapter: "a stand-in".into(),
            timing_method: "a stand-in's cost model".into(),
            details: FrameDetails::Env {
                lights: frame.lights.clone(),
                mode: frame.mode,
                fragments: None,
            },
        })
    }

    /// [`power_renderer`] whose reference frames carry a discretization error of 1/N for N
    /// lights: the N- and 4N-light references differ by (3/4N)/(1 + 1/4N).
    fn converging_renderer(frame: &EnvFrame) -> anyhow::Result<RenderedFrame> {
        let mut r = power_renderer(frame)?;
        if frame.role == FrameRole::Reference {
            let scale = 1.0 + 1.0 / frame.lights.len() as f32;
            for p in &mut r.image.pixels {
                for c in &mut p[..3] {
                    *c *= scale;
                }
            }
        }
        Ok(r)
    }

    /// The converged reference climbs 96 → 384 → 1536 → 6144 lights until N and 4N agree
    /// within the tolerance, keeps the 4N image and says when the bound came first.
    #[test]
    fn a_converged_reference_stops_at_the_first_n_that_agrees_with_4n() {
        let dir = std::env::temp_dir().join(format!(
            "strandlight-compare-converged-{}",
            std::process::id()
        ));
        let _ = std::fs::remove_dir_all(&dir);
        let groom =
            strandlight_runtime::hair::generate_groom(&strandlight_runtime::hair::GroomParams {
                strand_count: 40,
                clump_count: 8,
                ..Default::default()
            })
            .unwrap();
        let expected = |n: f64| (0.75 / n) / (1.0 + 0.25 / n);
        for (tolerance, lights, rungs, converged) in [
            ("0.01", 384, 1, true),
            ("0.001", 6144, 3, true),
            ("0.0001", 6144, 3, false),
        ] {
            let (out, cache) = (
                dir.join("out").display().to_string(),
                dir.join("cache").display().to_string(),
            );
            let a = CompareSettings {
                frame: small_frame([16, 12]),
                reference_tolerance: tolerance.parse().unwrap(),
                timing_runs: 1,
                modes: vec![ScatteringMode::Single],
                out: (&out).into(),
                cache: (&cache).into(),
                ..CompareSettings::default()
            };
            let mut steps = Steps::new(true);
            let scene = prepare_with_hair(&a, groom.clone(), "groom".into(), &mut steps).unwrap();
            let report = execute(&a, &scene, &mut steps, &converging_renderer).unwrap();
            let r = &report["single"]["reference"];
            assert_eq!(r["lights"], lights, "tolerance {tolerance}: {r}");
            assert_eq!(r["converged"], converged, "tolerance {tolerance}: {r}");
            let ladder = r["convergence"].as_array().unwrap();
            assert_eq!(ladder.len(), rungs, "tolerance {tolerance}: {r}");
            for (k, rung) in ladder.iter().enumerate() {
                let n = 96.0 * 4f64.powi(k as i32);
                assert_eq!(rung["lights"].as_f64().unwrap(), n);
                let d = rung["relative_rmse_vs_4x"].as_f64().unwrap();
                assert!(
                    (d - expected(n)).abs() < 1e-5,
                    "{n}: {d} vs {}",
                    expected(n)
                );
            }
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn the_whole_comparison_runs_with_a_stand_in_renderer() {
        let dir =
            std::env::temp_dir().join(format!("strandlight-compare-e2e-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let (out, cache) = (
            dir.join("out").display().to_string(),
            dir.join("cache").display().to_string(),
        );
        let a = CompareSettings {
            frame: small_frame([32, 24]),
            reference_lights: Some(96),
            timing_runs: 1,
            out: (&out).into(),
            cache: (&cache).into(),
            json: true,
            ..CompareSettings::default()
        };
        let groom =
            strandlight_runtime::hair::generate_groom(&strandlight_runtime::hair::GroomParams {
                strand_count: 40,
                clump_count: 8,
                ..Default::default()
            })
            .unwrap();
        let mut steps = Steps::new(true);
        let scene = prepare_with_hair(&a, groom.clone(), "groom".into(), &mut steps).unwrap();
        let report = execute(&a, &scene, &mut steps, &power_renderer).unwrap();
        println!("{}", serde_json::to_string_pretty(&report).unwrap());
        // Independent expectations: the reference and the median cut both carry the map's
        // integral exactly, the SRBFs carry it times the fit's own measured power ratio.
        let fit = fit_cached(
            &load_env("procedural:studio", false).unwrap(),
            &a.env().fit.options(),
            &dir.join("cache"),
        )
        .unwrap();
        assert!(fit.cached, "compare stored its fit in the cache");
        let integral = scene.map().integral();
        let num: f64 = (0..3)
            .map(|c| ((fit.set.power_ratio[c] - 1.0) * integral[c]).powi(2))
            .sum();
        let den: f64 = integral.iter().map(|v| v * v).sum();
        let want_srbf = (num / den).sqrt();
        let n_srbf = frame(&scene, &a.frame).unwrap().lights.len();
        for mode in ["single", "full"] {
            let m = &report[mode];
            let srbf = m["srbf"]["relative_rmse"].as_f64().unwrap();
            assert!(
                (srbf - want_srbf).abs() < 1e-5,
                "{mode}: {srbf} vs {want_srbf}"
            );
            assert!(
                m["baseline"]["relative_rmse"].as_f64().unwrap() < 1e-5,
                "{mode}: median cut carries the whole map"
            );
            let lights = m["baseline"]["lights"].as_u64().unwrap() as usize;
            assert!(
                lights.abs_diff(n_srbf) <= 1,
                "{mode}: equal time ⇔ equal light count here ({lights} vs {n_srbf})"
            );
            assert_eq!(m["reference"]["lights"], 96);
            assert!(
                (m["speedup_vs_reference"].as_f64().unwrap()
                    - (1.96 / (1.0 + 0.01 * n_srbf as f64)))
                    .abs()
                    < 1e-9
            );
            assert_eq!(m["reference"]["cached"], false);
            for image in m["images"].as_array().unwrap() {
                assert!(
                    std::path::Path::new(image.as_str().unwrap()).is_file(),
                    "{image}"
                );
            }
        }
        // Again: the reference comes from its cache.
        let report = execute(&a, &scene, &mut Steps::new(true), &power_renderer).unwrap();
        assert_eq!(report["single"]["reference"]["cached"], true);
        assert_eq!(report["full"]["reference"]["cached"], true);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
