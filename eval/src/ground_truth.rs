//! The path-traced ground truth: the scene rendered by a renderer nobody here wrote, Mitsuba 3,
//! with its `hair` BSDF (Chiang et al. 2016, as in pbrt-v4 and Cycles), its `envmap` emitter and
//! its `path` integrator. Fibers are opaque tubes (`bsplinecurve` through the strand's points) of the file's width: light
//! passes a fiber only by scattering through it, whatever transparency the file asks for.
//!
//! Single scattering is `max_depth` 2 (direct light through opaque fibers). Full scattering is
//! traced to the first depth D (of 8, 16, 32, …) whose image moves by less than the tolerance
//! when the depth doubles, both rendered with the same seed so that the difference is the deeper
//! bounces, not noise. Samples follow the rule of the other references: N samples per pixel
//! are converged when independent N and 4N images differ by at most the tolerance (relative RMSE
//! over the hair); the kept image averages the two (5N samples), and the ladder stops at a
//! budget, where the image is reported as not converged with its noise estimated from the last
//! difference. Every image is cached by content like the DOM reference.

pub mod mitsuba_scene;

use crate::reference_cache::{CachedRecord, ReferenceCache, read_rgba_exr};
use anyhow::{Context, bail};
use mitsuba_scene::{MitsubaRun, MitsubaScene, write_scene};
use serde::{Deserialize, Serialize};
use serde_json::{Value, json};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};
use strandlight_precompute::bake_plan::FiberDescription;
use strandlight_runtime::camera::UpAxis;
use strandlight_runtime::head::Head;
use strandlight_scene::environment::{LoadedEnv, load_env};
use strandlight_scene::frame_render::{FrameHair, load_settings_hair};
use strandlight_scene::frame_settings::{FrameSettings, Lighting, up_choice};
use strandlight_scene::head_input::load_head;
use strandlight_scene::image_metrics::{Image, relative_rmse};
use strandlight_scene::scene_tables::{EnvShading, ScatteringMode};
use strandlight_scene::steps::Steps;
use strandlight_tables::checksum::sha256_hex;
use strandlight_tables::outside_tools::{PYTHON_VAR, python};

/// What to install when Mitsuba is missing.
pub const INSTALL_HINT: &str =
    "pip install mitsuba, or set STRANDLIGHT_PYTHON to a Python that has it";

/// The exit status of `mitsuba_render.py` when `import mitsuba` fails.
const NO_MITSUBA_STATUS: i32 = 3;

/// How hard the ground truth works (see the module documentation).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct TruthSettings {
    /// Samples per pixel of the first rung.
    pub first_spp: u32,
    /// Most samples per pixel of one image (the ladder stops there).
    pub max_spp: u32,
    /// Relative RMSE between N and 4N (and between depths D and 2D) that counts as converged.
    pub tolerance: f64,
    /// First depth tried for full scattering, and the most.
    pub first_depth: u32,
    pub most_depth: u32,
    /// Samples per pixel of the depth search.
    pub depth_spp: u32,
}

impl Default for TruthSettings {
    fn default() -> Self {
        Self {
            first_spp: 1024,
            max_spp: 16384,
            tolerance: 0.01,
            first_depth: 8,
            most_depth: 64,
            depth_spp: 256,
        }
    }
}

impl TruthSettings {
    /// The default ladder under a budget of `max_spp` samples per pixel: its first rung and the
    /// depth search are at most a quarter of the budget, so that even a small budget (a large
    /// image's) renders an N and 4N pair and so measures its own noise.
    pub fn with_budget(max_spp: u32, tolerance: f64) -> Self {
        let default = Self::default();
        Self {
            first_spp: default.first_spp.min(max_spp / 4),
            depth_spp: default.depth_spp.min(max_spp / 4).max(1),
            max_spp,
            tolerance,
            ..default
        }
    }
}

/// What is stored beside a ground-truth image.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TruthRecord {
    /// Everything the image depends on.
    pub inputs: Value,
    /// Mitsuba's render time, seconds (scene loading excluded).
    pub seconds: f64,
    /// `mitsuba.__version__`.
    pub mitsuba: String,
}

impl CachedRecord for TruthRecord {
    fn inputs(&self) -> &Value {
        &self.inputs
    }
    fn description() -> &'static str {
        "strandlight path-traced ground truth (Mitsuba 3)"
    }
}

/// (depth D, relative RMSE of the image at D against 2D) per step of the depth search.
pub type DepthLadder = Vec<(u32, f64)>;

/// One rung of the sample ladder.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SampleRung {
    pub spp: u32,
    pub seconds: f64,
    /// Relative RMSE against the independent image of 4× the samples.
    pub difference_to_4x: f64,
}

/// The ground truth of one scene and mode.
#[derive(Debug, Clone)]
pub struct GroundTruth {
    pub image: Image,
    /// Samples per pixel of the kept image (N + 4N of the last rung).
    pub spp: u32,
    pub max_depth: u32,
    /// Mitsuba's time for the kept image's two renders, seconds.
    pub seconds: f64,
    pub ladder: Vec<SampleRung>,
    /// The depth search (empty for single scattering).
    pub depth_ladder: DepthLadder,
    pub converged: bool,
    /// The kept image's noise, relative RMSE against the noiseless image: the last rung's
    /// difference d between independent N and 4N images is √(σ²_N + σ²_N/4) = σ_N·√1.25, and
    /// their average holds 5N samples: σ_N/√5 = d/2.5.
    pub noise: f64,
    pub mitsuba: String,
}

impl GroundTruth {
    /// The error of `image` against the noiseless truth, estimated by removing this image's
    /// noise in quadrature (their errors are independent): √max(0, e² − noise²).
    pub fn noise_corrected(&self, measured: f64) -> f64 {
        without_noise(measured, self.noise)
    }
}

/// A relative RMSE measured against a noisy yardstick, with the yardstick's own noise (relative
/// RMSE) removed in quadrature: the two errors are independent, so their squares add.
pub fn without_noise(measured: f64, noise: f64) -> f64 {
    (measured * measured - noise * noise).max(0.0).sqrt()
}

/// The scene and what identifies it in the cache.
pub struct TruthInputs<'a> {
    pub scene: MitsubaScene<'a>,
    pub hair_sha256: &'a str,
    pub map_sha256: &'a str,
}

/// Bumped by hand when a change outside the writer's own code (mitsuba_scene.rs, hashed below,
/// and mitsuba_render.py, hashed whole) changes the files Mitsuba reads for the same inputs: how
/// an EXR is written, the head's tessellation, the fibers' default thickness.
pub const SCENE_WRITER_VERSION: u32 = 1;

/// The writer's source, for [`scene_writer`].
const SCENE_WRITER_SOURCE: &str = include_str!("ground_truth/mitsuba_scene.rs");

/// The scene writer as a truth's cache key names it: its version and a hash of its code (the
/// source up to its tests, each line trimmed, without comment and blank lines). A hash cannot be
/// forgotten the way a hand-bumped number can, so a fix to the writer never serves a truth
/// rendered from the old scene files (issue 61); comments and tests stay out of it because a
/// truth costs minutes to hours of Mitsuba. Any other edit of the writer's code renders its
/// truths again, whether or not the files it writes changed: stale by design, as are the truths
/// cached before the writer was part of the key.
fn scene_writer(version: u32, source: &str) -> Value {
    let code = source.split("\n#[cfg(test)]").next().unwrap_or(source);
    let lines: Vec<&str> = code
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && !l.starts_with("//"))
        .collect();
    json!({ "version": version, "code_sha256": sha256_hex(lines.join("\n").as_bytes()) })
}

impl TruthInputs<'_> {
    fn key(&self, run: MitsubaRun) -> Value {
        self.key_with_writer(run, scene_writer(SCENE_WRITER_VERSION, SCENE_WRITER_SOURCE))
    }

    fn key_with_writer(&self, run: MitsubaRun, writer: Value) -> Value {
        // The map's transform as the writer computes it, not only the rotation it is computed
        // from: a change to the rotation convention (scene/src/env_orientation.rs) moves Mitsuba's map
        // without touching the writer's code. Rounded so that the last bits of a sine do not
        // split the cache.
        let map_to_world = mitsuba_scene::map_to_world(self.scene.orientation)
            .map(|row| row.map(|v| (v * 1e9).round() / 1e9));
        let mut key = json!({
            "renderer": "mitsuba3 scalar_rgb path, hair BSDF, bsplinecurve through the strand points, envmap (hidden from the camera), box filter",
            "hair_sha256": self.hair_sha256,
            "map_sha256": self.map_sha256,
            "rotate": self.scene.orientation.rotation_deg,
            "directional": self.scene.directional,
            "up": format!("{:?}", self.scene.orientation.up),
            "camera": format!("{:?}", self.scene.camera),
            "size": [self.scene.size.0, self.scene.size.1],
            "fiber": self.scene.fiber,
            "run": run,
            "script_sha256": sha256_hex(mitsuba_scene::RENDER_SCRIPT.as_bytes()),
            "scene_writer": writer,
            "map_to_world": map_to_world,
        });
        // Only with a head, so that truths rendered before it keep their keys.
        if let Some(head) = self.scene.head {
            key["head"] = json!(format!("{:016x}", head.fingerprint()));
        }
        key
    }
}

/// Whether a ground truth may be rendered or only read from the cache.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(any(feature = "cli", test), derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum TruthUse {
    /// Never: the DOM reference is the only yardstick.
    Off,
    /// Where an earlier run cached every image it needs (`strandlight truth` renders them).
    Cached,
    /// Render what the cache lacks (minutes per image).
    Render,
}

/// One image from `cache`, or rendered by Mitsuba in a fresh folder under `work` when `render`
/// allows (None when it does not and the cache lacks it). The bool says it was cached.
pub fn render_cached(
    inputs: &TruthInputs,
    run: MitsubaRun,
    cache: &ReferenceCache,
    work: &Path,
    render: bool,
) -> anyhow::Result<Option<(Image, TruthRecord, bool)>> {
    let key = inputs.key(run);
    if let Some((image, record)) = cache.load::<TruthRecord>(&key) {
        return Ok(Some((image, record, true)));
    }
    if !render {
        return Ok(None);
    }
    let dir = work.join(format!("mitsuba-{}", &ReferenceCache::key(&key)[..16]));
    let output = dir.join("render.exr");
    let scene_json = write_scene(&inputs.scene, run, &dir, &output)?;
    let (seconds, mitsuba) = run_mitsuba(&scene_json, run)?;
    let image = read_rgba_exr(&output)?;
    let record = TruthRecord {
        inputs: key,
        seconds,
        mitsuba,
    };
    cache.store(&image, &record)?;
    std::fs::remove_dir_all(&dir).ok();
    Ok(Some((image, record, false)))
}

/// Runs `mitsuba_render.py` on a scene file with `$STRANDLIGHT_PYTHON` (or `python3`),
/// printing a progress line every 10 s while it works (a first ground truth takes minutes).
/// Returns (render seconds, Mitsuba's version).
pub fn run_mitsuba(scene_json: &Path, run: MitsubaRun) -> anyhow::Result<(f64, String)> {
    run_mitsuba_with(&python(), scene_json, run)
}

/// [`run_mitsuba`] with the interpreter named.
pub fn run_mitsuba_with(
    interpreter: &str,
    scene_json: &Path,
    run: MitsubaRun,
) -> anyhow::Result<(f64, String)> {
    let dir = scene_json.parent().unwrap_or(Path::new("."));
    let script = dir.join(mitsuba_scene::RENDER_SCRIPT_NAME);
    let mut child = Command::new(interpreter)
        .arg(&script)
        .arg(scene_json)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .with_context(|| {
            format!("cannot start {interpreter}, the Python that runs Mitsuba 3 (${PYTHON_VAR}, default python3): {INSTALL_HINT}")
        })?;
    // Drained while the child runs: a full pipe would stall it.
    let drain = |pipe: Option<Box<dyn std::io::Read + Send>>| {
        std::thread::spawn(move || {
            let mut text = String::new();
            if let Some(mut pipe) = pipe {
                let _ = pipe.read_to_string(&mut text);
            }
            text
        })
    };
    let stdout = drain(child.stdout.take().map(|p| Box::new(p) as _));
    let stderr = drain(child.stderr.take().map(|p| Box::new(p) as _));
    let start = Instant::now();
    let mut last_said = start;
    let status = loop {
        if let Some(status) = child.try_wait()? {
            break status;
        }
        std::thread::sleep(Duration::from_millis(200));
        if last_said.elapsed() >= Duration::from_secs(10) {
            eprintln!(
                "  ground truth: Mitsuba renders {} spp at depth {}, {:.0} s so far",
                run.spp,
                run.max_depth,
                start.elapsed().as_secs_f64()
            );
            last_said = Instant::now();
        }
    };
    let stdout = stdout.join().unwrap_or_default();
    let stderr = stderr.join().unwrap_or_default();
    if status.code() == Some(NO_MITSUBA_STATUS) {
        bail!("Mitsuba 3 is not installed for {interpreter}: {INSTALL_HINT}");
    }
    if !status.success() {
        bail!(
            "Mitsuba failed on {} ({status}):\n{}",
            scene_json.display(),
            stderr.trim()
        );
    }
    let line = stdout.lines().last().unwrap_or_default();
    let report: Value = serde_json::from_str(line)
        .with_context(|| format!("Mitsuba's report on {}: {line:?}", scene_json.display()))?;
    Ok((
        report["seconds"].as_f64().unwrap_or(f64::NAN),
        report["mitsuba"].as_str().unwrap_or("?").to_string(),
    ))
}

/// The ground truth of `mode`: the depth search (full scattering), then the sample ladder.
/// None when `truth` is [`TruthUse::Cached`] and the cache lacks the first N-against-4N pair;
/// with the first pair cached, the last cached pair below the budget.
pub fn ground_truth(
    inputs: &TruthInputs,
    mode: ScatteringMode,
    settings: &TruthSettings,
    truth: TruthUse,
    cache_dir: &Path,
    steps: &mut Steps,
) -> anyhow::Result<Option<GroundTruth>> {
    validate(settings)?;
    if truth == TruthUse::Off {
        return Ok(None);
    }
    let may_render = truth == TruthUse::Render;
    let cache = ReferenceCache::new(cache_dir.join("truth"));
    let work = cache_dir.join("truth-work");
    let m = mode.name();
    let (max_depth, depth_ladder) = match mode {
        ScatteringMode::Single => (2, Vec::new()),
        ScatteringMode::Full => {
            let found = steps.run(
                &format!("{m}: truth depth"),
                || depth_search(inputs, settings, &cache, &work, may_render),
                |found: &Option<(u32, DepthLadder)>| match found {
                    None => "not cached".into(),
                    Some((d, ladder)) => {
                        let moves: Vec<String> = ladder
                            .iter()
                            .map(|(d, e)| format!("{d}→{}: {e:.4}", 2 * d))
                            .collect();
                        format!("max_depth {d} ({})", moves.join(", "))
                    }
                },
            )?;
            match found {
                Some(found) => found,
                None => return Ok(None),
            }
        }
    };
    let mut ladder = Vec::new();
    let mut spp = settings.first_spp;
    let render = |spp: u32, steps: &mut Steps| {
        // Each rung its own seed (its sample count), so that every image is independent of
        // the others: N against 4N then measures noise, not a shared sample sequence.
        let run = MitsubaRun {
            max_depth,
            spp,
            seed: spp,
        };
        steps.run(
            &format!("{m}: truth {spp} spp"),
            || render_cached(inputs, run, &cache, &work, may_render),
            |r: &Option<(Image, TruthRecord, bool)>| match r {
                None => "not cached".into(),
                Some((_, r, cached)) => format!(
                    "Mitsuba {:.1} s{}",
                    r.seconds,
                    if *cached { " (cached)" } else { "" }
                ),
            },
        )
    };
    let Some(mut coarse) = render(spp, steps)? else {
        return Ok(None);
    };
    // With the cache only, the last pair it holds is the truth: a finer rung that a run with a
    // larger budget would render does not hide what a smaller budget already measured.
    let mut last_pair = None;
    loop {
        let Some(fine) = render(4 * spp, steps)? else {
            if last_pair.is_some() {
                steps.say(format!(
                    "{m}: the cache holds no {} spp image: the truth is its {} against {spp} spp pair",
                    4 * spp,
                    spp / 4
                ));
            }
            return Ok(last_pair);
        };
        let difference = relative_rmse(&coarse.0, &fine.0)?;
        ladder.push(SampleRung {
            spp,
            seconds: coarse.1.seconds,
            difference_to_4x: difference,
        });
        steps.say(format!(
            "{m}: ground truth {spp} against {} spp: relative RMSE {difference:.4} (tolerance {})",
            4 * spp,
            settings.tolerance
        ));
        let converged = difference <= settings.tolerance;
        let truth = GroundTruth {
            image: average(&coarse.0, 1.0, &fine.0, 4.0),
            spp: 5 * spp,
            max_depth,
            seconds: coarse.1.seconds + fine.1.seconds,
            ladder: ladder.clone(),
            depth_ladder: depth_ladder.clone(),
            converged,
            noise: difference / 2.5,
            mitsuba: fine.1.mitsuba.clone(),
        };
        if converged || 16 * spp > settings.max_spp {
            return Ok(Some(truth));
        }
        last_pair = Some(truth);
        spp *= 4;
        coarse = fine;
    }
}

/// The first depth D whose image, rendered again at 2D with the same seed, moves by at most
/// the tolerance; the most depth if none does. None: not cached and not allowed to render.
fn depth_search(
    inputs: &TruthInputs,
    settings: &TruthSettings,
    cache: &ReferenceCache,
    work: &Path,
    may_render: bool,
) -> anyhow::Result<Option<(u32, DepthLadder)>> {
    let image = |max_depth| {
        let run = MitsubaRun {
            max_depth,
            spp: settings.depth_spp,
            seed: 7,
        };
        render_cached(inputs, run, cache, work, may_render).map(|r| r.map(|r| r.0))
    };
    let mut ladder = Vec::new();
    let mut depth = settings.first_depth;
    let Some(mut shallow) = image(depth)? else {
        return Ok(None);
    };
    while depth < settings.most_depth {
        let Some(deep) = image(2 * depth)? else {
            return Ok(None);
        };
        let moved = relative_rmse(&shallow, &deep)?;
        ladder.push((depth, moved));
        if moved <= settings.tolerance {
            return Ok(Some((depth, ladder)));
        }
        depth *= 2;
        shallow = deep;
    }
    Ok(Some((settings.most_depth, ladder)))
}

pub(crate) fn validate(s: &TruthSettings) -> anyhow::Result<()> {
    if s.max_spp < 4 {
        bail!(
            "ground-truth budget {} samples per pixel: its noise is measured from an N and 4N pair, so use at least 4",
            s.max_spp
        );
    }
    if s.first_spp == 0 || s.max_spp < s.first_spp || s.depth_spp == 0 {
        bail!(
            "ground-truth samples: first {} and most {} per pixel must be ≥ 1 and ordered",
            s.first_spp,
            s.max_spp
        );
    }
    if !(s.tolerance > 0.0 && s.tolerance < 1.0) {
        bail!(
            "ground-truth tolerance {}: use a relative RMSE in (0, 1)",
            s.tolerance
        );
    }
    if s.first_depth < 3 || s.most_depth < s.first_depth {
        bail!(
            "ground-truth depths: first {} (≥ 3: more than direct light) and most {} must be ordered",
            s.first_depth,
            s.most_depth
        );
    }
    Ok(())
}

/// The weighted mean of two images (weights by their sample counts); alpha likewise.
fn average(a: &Image, wa: f32, b: &Image, wb: f32) -> Image {
    let w = wa + wb;
    let pixels = a
        .pixels
        .iter()
        .zip(&b.pixels)
        .map(|(p, q)| std::array::from_fn(|c| (wa * p[c] + wb * q[c]) / w))
        .collect();
    Image::new(a.width, a.height, pixels)
}

/// Writes a scene's Mitsuba files to `dir` (curves, map, script, `scene.json` for `run`) for
/// a user who wants the offline render: `python3 DIR/mitsuba_render.py DIR/scene.json`.
pub fn export(inputs: &TruthInputs, run: MitsubaRun, dir: &Path) -> anyhow::Result<PathBuf> {
    write_scene(&inputs.scene, run, dir, &dir.join("render.exr"))
}

/// What `strandlight truth` renders (or exports): the frame of a [`FrameSettings`] exactly as
/// `compare` sets it up for the same settings, so that `compare`, `image-error` and `bench` find
/// the cached images, and a viewer screenshot's settings export the scene the viewer showed.
pub struct TruthScene {
    pub hair: FrameHair,
    pub map: LoadedEnv,
    pub up: UpAxis,
    /// The fiber's Chiang parameters (Mitsuba's `hair`).
    pub fiber: Value,
    pub head: Option<Head>,
    pub frame: FrameSettings,
}

impl TruthScene {
    /// The scene of `frame`, an env-lit frame of the Chiang fiber (the path tracer's).
    pub fn load(frame: &FrameSettings) -> anyhow::Result<Self> {
        frame.check()?;
        let Lighting::Environment(env) = &frame.lighting else {
            bail!("the path-traced truth is of env-lit frames: give an environment");
        };
        if frame.env_shading()? != EnvShading::Chiang {
            bail!(
                "the path-traced truth renders the Chiang fiber (Mitsuba's `hair`): use --shading chiang"
            );
        }
        let hair = load_settings_hair(frame)?;
        let map = load_env(&env.map, env.sanitize)?;
        let fiber = FiberDescription::preset(&frame.preset)
            .with_context(|| format!("--preset {:?}", frame.preset))?;
        let head = load_head(&frame.head, &hair.model, frame.skin_albedo)?;
        Ok(Self {
            up: up_choice(frame).axis(&hair.model),
            hair,
            map,
            fiber: serde_json::to_value(&fiber.chiang)?,
            head,
            frame: frame.clone(),
        })
    }

    pub fn inputs(&self) -> anyhow::Result<TruthInputs<'_>> {
        Ok(TruthInputs {
            scene: MitsubaScene::of_frame(
                &self.frame,
                &self.hair.model,
                (&self.map.map, self.up),
                &self.fiber,
                self.head.as_ref(),
            )?,
            hair_sha256: &self.hair.identity,
            map_sha256: &self.map.sha256,
        })
    }
}

/// What is written beside a ground-truth image (`STEM.json` beside `STEM.exr`), so that a tool
/// reading the image later (`image-error`) knows its noise.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TruthSidecar {
    pub renderer: String,
    pub spp: u32,
    pub max_depth: u32,
    pub converged: bool,
    /// Relative RMSE of the image's own noise.
    pub noise: f64,
    pub seconds: f64,
}

/// Writes `STEM.exr` (linear), `STEM.png` and the sidecar `STEM.json`; returns the EXR's path.
pub fn write_truth_image(
    truth: &GroundTruth,
    stem: &Path,
    description: &str,
) -> anyhow::Result<PathBuf> {
    use strandlight_tables::image_out::{write_exr, write_png};
    let (w, h) = (truth.image.width, truth.image.height);
    let exr = stem.with_extension("exr");
    write_exr(&exr, w, h, &truth.image.pixels, description)?;
    write_png(
        &stem.with_extension("png"),
        w,
        h,
        &truth.image.pixels,
        description,
    )?;
    let sidecar = TruthSidecar {
        renderer: format!("Mitsuba {} (scalar_rgb, path, hair BSDF)", truth.mitsuba),
        spp: truth.spp,
        max_depth: truth.max_depth,
        converged: truth.converged,
        noise: truth.noise,
        seconds: truth.seconds,
    };
    let json = stem.with_extension("json");
    strandlight_tables::atomic_write::write_atomically(&json, |out| {
        std::io::Write::write_all(out, serde_json::to_string_pretty(&sidecar)?.as_bytes())
    })
    .with_context(|| format!("cannot write {}", json.display()))?;
    Ok(exr)
}

/// The sidecar of a ground-truth EXR, None when the image has none (it is not a ground truth).
pub fn read_truth_sidecar(exr: &Path) -> Option<TruthSidecar> {
    let text = std::fs::read_to_string(exr.with_extension("json")).ok()?;
    serde_json::from_str(&text).ok()
}

#[cfg(test)]
mod tests {
    use super::*;
    use strandlight_runtime::hair::{GroomParams, generate_groom};
    use strandlight_scene::camera_choice::front_camera;
    use strandlight_scene::env_orientation::EnvOrientation;

    fn scratch(name: &str) -> PathBuf {
        let dir =
            std::env::temp_dir().join(format!("strandlight-gt-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    fn run() -> MitsubaRun {
        MitsubaRun {
            max_depth: 2,
            spp: 1,
            seed: 0,
        }
    }

    /// The runner reports a missing interpreter, a Python without Mitsuba (the script's exit
    /// status 3) and a failed render with what the child printed, never a silent result.
    #[test]
    fn a_missing_python_mitsuba_or_failed_render_is_a_clear_error() {
        let dir = scratch("runner");
        let scene = dir.join("scene.json");
        std::fs::write(&scene, "{}").unwrap();
        let e = run_mitsuba_with("/nonexistent/python3", &scene, run()).unwrap_err();
        assert!(format!("{e:#}").contains("pip install mitsuba"), "{e:#}");
        if !strandlight_tables::outside_tools::program_exists(&python()) {
            strandlight_tables::outside_tools::missing_tool(&python(), "install Python 3");
            return;
        }
        let script = dir.join(mitsuba_scene::RENDER_SCRIPT_NAME);
        std::fs::write(&script, "import sys\nsys.exit(3)\n").unwrap();
        let e = run_mitsuba_with(&python(), &scene, run()).unwrap_err();
        assert!(
            format!("{e:#}").contains("not installed")
                && format!("{e:#}").contains("pip install mitsuba"),
            "{e:#}"
        );
        std::fs::write(
            &script,
            "import sys\nsys.stderr.write('bad curve file\\n')\nsys.exit(1)\n",
        )
        .unwrap();
        let e = format!(
            "{:#}",
            run_mitsuba_with(&python(), &scene, run()).unwrap_err()
        );
        assert!(
            e.contains("Mitsuba failed on") && e.contains("bad curve file"),
            "{e}"
        );
        std::fs::write(&script, "print('not json')\n").unwrap();
        let e = format!(
            "{:#}",
            run_mitsuba_with(&python(), &scene, run()).unwrap_err()
        );
        assert!(e.contains("Mitsuba's report"), "{e}");
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn a_change_to_the_scene_writer_changes_the_truths_key() {
        let hair = generate_groom(&GroomParams {
            strand_count: 4,
            clump_count: 1,
            ..GroomParams::default()
        })
        .unwrap();
        let (up, camera) = front_camera(&hair, (8, 6));
        let fiber = serde_json::json!({ "eumelanin": 1.3 });
        let inputs = TruthInputs {
            scene: MitsubaScene {
                hair: &hair,
                orientation: EnvOrientation::upright(up),
                camera,
                size: (8, 6),
                map: None,
                directional: &[],
                fiber: &fiber,
                head: None,
            },
            hair_sha256: "h",
            map_sha256: "m",
        };
        let source = "pub fn write() {\n    write_map(1);\n}\n";
        let key = |version, source| inputs.key_with_writer(run(), scene_writer(version, source));
        let base = key(SCENE_WRITER_VERSION, source);
        assert_ne!(
            base,
            key(SCENE_WRITER_VERSION + 1, source),
            "a bumped version"
        );
        let fixed = source.replace("write_map(1)", "write_map(2)");
        assert_ne!(base, key(SCENE_WRITER_VERSION, &fixed), "a fix to the code");
        // What cannot change the files Mitsuba reads keeps the cached truths.
        let commented = format!(
            "//! The writer.\n\n{}",
            source.replace("{\n", "{\n    // why\n")
        );
        let tested = format!("{source}\n#[cfg(test)]\nmod tests {{ fn t() {{}} }}\n");
        assert_eq!(base, key(SCENE_WRITER_VERSION, &commented), "a comment");
        assert_eq!(base, key(SCENE_WRITER_VERSION, &tested), "a test");
        // The key in use names this build's writer.
        assert_eq!(
            inputs.key(run())["scene_writer"],
            scene_writer(SCENE_WRITER_VERSION, SCENE_WRITER_SOURCE)
        );
        assert!(SCENE_WRITER_SOURCE.contains("pub fn write_scene("));
    }

    /// The sample ladder against a cache filled with images whose error is known: an image of
    /// N spp is 1 + 8/N everywhere, so N and 4N differ by 6/(N + 2) relative.
    #[test]
    fn the_ladder_stops_at_the_first_converged_rung_or_the_budget() {
        let dir = scratch("ladder");
        let hair = generate_groom(&GroomParams {
            strand_count: 20,
            clump_count: 4,
            ..GroomParams::default()
        })
        .unwrap();
        let (up, camera) = front_camera(&hair, (8, 6));
        let fiber = serde_json::json!({ "eumelanin": 1.3 });
        let inputs = TruthInputs {
            scene: MitsubaScene {
                hair: &hair,
                orientation: EnvOrientation::upright(up),
                camera,
                size: (8, 6),
                map: None,
                directional: &[],
                fiber: &fiber,
                head: None,
            },
            hair_sha256: "h",
            map_sha256: "m",
        };
        let cache = ReferenceCache::new(dir.join("truth"));
        let value = |spp: u32| 1.0 + 8.0 / spp as f32;
        let store = |spp: u32| {
            let run = MitsubaRun {
                max_depth: 2,
                spp,
                seed: spp,
            };
            let image = Image::new(8, 6, vec![[value(spp), value(spp), value(spp), 1.0]; 48]);
            let record = TruthRecord {
                inputs: inputs.key(run),
                seconds: spp as f64 / 1000.0,
                mitsuba: "test".into(),
            };
            cache.store(&image, &record).unwrap();
        };
        let settings = |tolerance| TruthSettings {
            tolerance,
            max_spp: 16384,
            ..TruthSettings::default()
        };
        let truth = |tolerance, using| {
            ground_truth(
                &inputs,
                ScatteringMode::Single,
                &settings(tolerance),
                using,
                &dir,
                &mut Steps::new(true),
            )
            .unwrap()
        };
        store(1024);
        assert!(
            truth(0.01, TruthUse::Cached).is_none(),
            "the 4096 rung is missing"
        );
        assert!(truth(0.01, TruthUse::Off).is_none());
        store(4096);
        // The cache holds 1024 and 4096 only: at 0.1% the pair it holds is the truth, not
        // converged.
        let t = truth(0.001, TruthUse::Cached).unwrap();
        assert!(!t.converged && t.spp == 5 * 1024 && t.ladder.len() == 1);
        store(16384);
        let d = |n: f64| (8.0 / n - 2.0 / n) / (1.0 + 2.0 / n);
        // 1024 against 4096 differ by 0.0058: converged at 1%.
        let t = truth(0.01, TruthUse::Cached).unwrap();
        assert!(t.converged && t.spp == 5 * 1024 && t.max_depth == 2);
        assert!((t.noise - d(1024.0) / 2.5).abs() < 1e-6, "{}", t.noise);
        let mean = (value(1024) + 4.0 * value(4096)) / 5.0;
        assert!((t.image.pixels[0][0] - mean).abs() < 1e-6);
        // At 0.1% the ladder climbs to 4096 against 16384 (0.0015), and the budget stops it.
        let t = truth(0.001, TruthUse::Cached).unwrap();
        assert!(
            !t.converged && t.spp == 5 * 4096,
            "{} {}",
            t.converged,
            t.spp
        );
        assert_eq!(t.ladder.len(), 2);
        assert!((t.ladder[1].difference_to_4x - d(4096.0)).abs() < 1e-6);
        // A budget of 1024 (a large image's) still renders a pair: 256 against 1024.
        store(256);
        let small = TruthSettings::with_budget(1024, 0.001);
        let t = ground_truth(
            &inputs,
            ScatteringMode::Single,
            &small,
            TruthUse::Cached,
            &dir,
            &mut Steps::new(true),
        )
        .unwrap()
        .unwrap();
        assert!(!t.converged && t.spp == 5 * 256 && t.ladder.len() == 1);
        assert!((t.noise - d(256.0) / 2.5).abs() < 1e-6, "{}", t.noise);
        let e = validate(&TruthSettings::with_budget(3, 0.01)).unwrap_err();
        assert!(format!("{e}").contains("at least 4"), "{e}");
        std::fs::remove_dir_all(&dir).ok();
    }
}
