//! What `compare` and `demo` share up to the GPU: the environment (file or procedural), the
//! SRBF fit with its cache, the tables baked for the fitted λ range (cached by the bake), and
//! the ONE call into the environment-lit renderer ([`render_lights`]).

use crate::image_compare::Image;
use anyhow::{bail, Context};
use serde_json::{json, Value};
use sha2::{Digest, Sha256};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use strandlight_precompute::bake::{bake_job, BakedTable};
use strandlight_precompute::bake_plan::{plan, BakeResolution, FiberDescription, Model, PlanOptions, DEFAULT_MULTIPLE_THRESHOLD};
use strandlight_precompute::envmap::BadPixelCounts;
use strandlight_precompute::envmap_io::{self, LoadOptions};
use strandlight_precompute::srbf_set::{Source, SrbfSet};
use strandlight_precompute::{procedural_env, EnvMap, FitOptions};
use strandlight_runtime::camera::Camera;
use std::sync::OnceLock;
use strandlight_runtime::multiple::{CpuForwardScattering, ForwardScatteringSettings, ForwardScatteringTables, GpuForwardScattering};
use strandlight_runtime::env::{ForwardScatteringSource, EnvLight, EnvRenderOptions, EnvRenderStats, EnvRenderer, EnvTables, FragmentCounts, ViewTransparency, BoxAverage};
use strandlight_runtime::gpu::GpuContext;
use strandlight_runtime::hair::HairModel;
use strandlight_tables::checksum::sha256_hex;
use strandlight_tables::asset::{expect_parameters, read_asset, Storage, TableAsset};

/// Width at which procedural environments are generated (as `fit` does).
pub const PROCEDURAL_WIDTH: usize = 1024;

/// SHA-256 of a map's size and pixel values (little-endian f32): identifies a procedural map
/// by what it is, so a change to its generator invalidates every cache keyed by it.
pub fn map_pixels_sha256(map: &EnvMap) -> String {
    let mut h = Sha256::new();
    h.update((map.width() as u64).to_le_bytes());
    h.update((map.height() as u64).to_le_bytes());
    for p in map.pixels() {
        for c in p {
            h.update(c.to_le_bytes());
        }
    }
    h.finalize().iter().map(|b| format!("{b:02x}")).collect()
}

/// An environment ready to fit: the map, its name for reports and its content hash.
pub struct LoadedEnv {
    pub map: EnvMap,
    /// File name (no directories) or `procedural:NAME`.
    pub name: String,
    /// SHA-256 of the file's bytes, or of a procedural map's pixels.
    pub sha256: String,
    pub sanitized: BadPixelCounts,
}

impl LoadedEnv {
    pub fn source(&self) -> Source<'_> {
        Source { map: &self.map, name: self.name.clone(), sha256: self.sha256.clone(), sanitized: self.sanitized }
    }
}

/// `procedural:NAME` or a Radiance/OpenEXR file.
pub fn load_env(spec: &str, sanitize: bool) -> anyhow::Result<LoadedEnv> {
    if let Some(name) = spec.strip_prefix("procedural:") {
        let Some(map) = procedural_env::by_name(name, PROCEDURAL_WIDTH) else {
            bail!("unknown procedural environment {name:?} (known: {})", procedural_env::NAMES.join(", "));
        };
        let sha256 = map_pixels_sha256(&map);
        return Ok(LoadedEnv { map, name: spec.to_string(), sha256, sanitized: BadPixelCounts::default() });
    }
    let path = Path::new(spec);
    let loaded = envmap_io::load(path, LoadOptions { sanitize })?;
    if loaded.sanitized.total() > 0 {
        eprintln!("{}: sanitized {}", path.display(), loaded.sanitized);
    }
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    Ok(LoadedEnv { map: loaded.map, name, sha256: loaded.sha256, sanitized: loaded.sanitized })
}

/// A fitted set and whether it came from the cache.
pub struct FitOutcome {
    pub set: SrbfSet,
    pub cached: bool,
    pub path: PathBuf,
}

/// The cache key of a fit: the map's content and every fit option.
pub fn fit_key(env: &LoadedEnv, options: &FitOptions) -> String {
    sha256_hex(json!({ "map_sha256": env.sha256, "options": options, "generator": env!("CARGO_PKG_VERSION") }).to_string().as_bytes())
}

/// The SRBF fit of `env`, served from `cache_dir/fits/KEY.srbf.json` when the map and options
/// are unchanged, else computed and stored there.
pub fn fit_cached(env: &LoadedEnv, options: &FitOptions, cache_dir: &Path) -> anyhow::Result<FitOutcome> {
    let dir = cache_dir.join("fits");
    std::fs::create_dir_all(&dir).with_context(|| format!("cannot create the cache folder {}", dir.display()))?;
    let path = dir.join(format!("{}.srbf.json", &fit_key(env, options)[..32]));
    if let Ok(set) = SrbfSet::load(&path) {
        let same_options = serde_json::to_value(&set.options).ok() == serde_json::to_value(options).ok();
        if set.source_sha256 == env.sha256 && same_options {
            return Ok(FitOutcome { set, cached: true, path });
        }
    }
    let set = SrbfSet::fit(&env.source(), options, &mut |_| {}).with_context(|| format!("fitting SRBFs to {}", env.name))?;
    set.save(&path)?;
    Ok(FitOutcome { set, cached: false, path })
}

/// The fiber model whose tables shade the hair.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum EnvShading {
    Marschner,
    Artist,
}

/// What the view shows of each pixel's fibers (Ren §8).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum EnvTransparency {
    /// The nearest fiber, weighted by its coverage.
    Opaque,
    /// Every fiber, weighted by coverage × its visibility through the occupancy map.
    Occupancy,
}

/// Where the forward-scattering shadow paths are marched (Ren §6).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum ForwardDevice {
    /// The GPU on a hardware adapter, rayon on a software one (lavapipe runs compute shaders on
    /// the same CPU cores, where rayon measured 4–9% faster at the interactive grid:
    /// docs/BENCHMARKS.md, "CPU vs GPU march").
    Auto,
    Cpu,
    Gpu,
}

/// What the effective transmittance's box averages (the CLI's names for [`BoxAverage`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum BoxAverageArg {
    /// Ren 2010: exp(−mean optical depth).
    OpticalDepth,
    /// The mean of exp(−optical depth).
    Transmittance,
}

/// The renderer choices of the env-lit commands.
#[derive(clap::Args, Debug, Clone, Copy)]
pub struct LookArgs {
    /// The nearest fiber of each pixel (opaque), or every fiber weighted by its visibility
    /// through an occupancy map (Ren §8; order-independent transparency; costs about as many
    /// times the view pass as the hair has fragments per pixel).
    #[arg(long, value_enum, default_value = "opaque")]
    pub transparency: EnvTransparency,
    #[command(flatten)]
    pub view: ViewArgs,
}

/// The env-lit renderer's choices besides the transparency (which `render` names its own way,
/// sharing `--transparency` with the point-light renderer).
#[derive(clap::Args, Debug, Clone, Copy)]
pub struct ViewArgs {
    /// With occupancy: fragments seen less than this fraction are not shaded (early termination).
    #[arg(long, default_value_t = ViewTransparency::DEFAULT_CUTOFF)]
    pub visibility_cutoff: f32,
    /// What the SRBF transmittance's box averages over the convolution optical depth map.
    #[arg(long, value_enum, default_value = "optical-depth")]
    pub box_average: BoxAverageArg,
    /// Where multiple scattering's shadow paths are marched (the brute-force reference's dense
    /// grid always uses the CPU light sweep).
    #[arg(long, value_enum, default_value = "auto")]
    pub forward_scattering: ForwardDevice,
}

impl Default for ViewArgs {
    fn default() -> Self {
        Self { visibility_cutoff: ViewTransparency::DEFAULT_CUTOFF, box_average: BoxAverageArg::OpticalDepth, forward_scattering: ForwardDevice::Auto }
    }
}

impl Default for LookArgs {
    fn default() -> Self {
        Self { transparency: EnvTransparency::Opaque, view: ViewArgs::default() }
    }
}

impl LookArgs {
    /// The look these arguments ask for (`shadowed` and no fragment counts).
    pub fn look(&self) -> anyhow::Result<EnvLook> {
        let view = &self.view;
        let transparency = match self.transparency {
            EnvTransparency::Opaque => ViewTransparency::Opaque,
            EnvTransparency::Occupancy => ViewTransparency::Occupancy { visibility_cutoff: view.visibility_cutoff },
        };
        transparency.check().with_context(|| format!("--visibility-cutoff {}", view.visibility_cutoff))?;
        let box_average = match view.box_average {
            BoxAverageArg::OpticalDepth => BoxAverage::OpticalDepth,
            BoxAverageArg::Transmittance => BoxAverage::Transmittance,
        };
        Ok(EnvLook { shadowed: true, transparency, box_average, count_fragments: false, forward_scattering: view.forward_scattering })
    }
}

/// How a frame is rendered besides its scene and lights.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EnvLook {
    /// False sets every single-scattering transmittance to 1 (a diagnostic: what is left is
    /// the lighting and table error alone).
    pub shadowed: bool,
    pub transparency: ViewTransparency,
    pub box_average: BoxAverage,
    /// Count the fragments rasterized and shaded (two extra passes, outside the frame time).
    pub count_fragments: bool,
    pub forward_scattering: ForwardDevice,
}

/// Single scattering only, or with multiple scattering (Ren §3.2).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, clap::ValueEnum)]
#[serde(rename_all = "kebab-case")]
pub enum ScatteringMode {
    Single,
    Full,
}

impl ScatteringMode {
    pub fn name(self) -> &'static str {
        match self {
            ScatteringMode::Single => "single",
            ScatteringMode::Full => "full",
        }
    }
}

impl EnvShading {
    fn model(self) -> Model {
        match self {
            EnvShading::Marschner => Model::Marschner,
            EnvShading::Artist => Model::Artist,
        }
    }

    /// The convolution table of SRBF lights in `mode` (the artist model has no d_b·S_back
    /// variant: its full mode adds only I_G).
    pub fn srbf_table(self, mode: ScatteringMode) -> &'static str {
        match (self, mode) {
            (EnvShading::Marschner, ScatteringMode::Single) => "marschner",
            (EnvShading::Marschner, ScatteringMode::Full) => "marschner_full",
            (EnvShading::Artist, _) => "artist",
        }
    }

    /// The direct table of directional lights in `mode`.
    pub fn direct_table(self, mode: ScatteringMode) -> &'static str {
        match (self, mode) {
            (EnvShading::Marschner, ScatteringMode::Single) => "marschner_direct",
            (EnvShading::Marschner, ScatteringMode::Full) => "marschner_full_direct",
            (EnvShading::Artist, _) => "artist_direct",
        }
    }
}

/// The tables multiple scattering reads (the first is absent for hair too dark to need it).
pub const MULTIPLE_TABLES: [&str; 4] = ["multiple", "fiber_averages", "attenuation_ratio", "srbf_spread"];

/// The tables a frame in any of `modes` may read: the multiple-scattering tables, the SRBF
/// tables and, with `directional` lights (baselines, references, a fit's compact sources), the
/// direct tables.
pub fn wanted_tables(shading: EnvShading, modes: &[ScatteringMode], srbf: bool, directional: bool) -> Vec<&'static str> {
    let mut wanted: Vec<&str> = MULTIPLE_TABLES.to_vec();
    for &mode in modes {
        if srbf {
            wanted.push(shading.srbf_table(mode));
        }
        if directional {
            wanted.push(shading.direct_table(mode));
        }
    }
    wanted.dedup();
    wanted
}

/// "N SRBF lights" or "N SRBF lights + k directional" for a frame's lights.
pub fn light_summary(lights: &[EnvLight]) -> String {
    let srbf = lights.iter().filter(|l| l.lambda.is_some()).count();
    match lights.len() - srbf {
        0 => format!("{srbf} SRBF lights"),
        k => format!("{srbf} SRBF lights + {k} directional"),
    }
}

/// "N SRBFs + k compact sources (x% of the power), relative L2 error e" for a fitted set.
pub fn fit_summary(set: &SrbfSet) -> String {
    let sources = match set.sources.len() {
        0 => String::new(),
        n => format!(
            " + {n} compact source{} as directional light{} ({:.0}% of the power)",
            if n == 1 { "" } else { "s" },
            if n == 1 { "" } else { "s" },
            100.0 * set.sources.iter().map(|s| s.power_share).sum::<f64>()
        ),
    };
    let without = if set.sources.is_empty() { "" } else { " (of the rest)" };
    format!("{} SRBFs{sources}, relative L2 error {:.3}{without}", set.lobes.len(), set.relative_l2_error)
}

/// Loaded tables by name, each checked against the fiber parameters it was asked for.
pub struct SceneTables {
    pub assets: BTreeMap<String, TableAsset>,
    pub baked: Vec<BakedTable>,
    /// Tables the plan skipped, with the reason (e.g. `multiple` for dark hair).
    pub skipped: Vec<(String, String)>,
}

impl SceneTables {
    pub fn get(&self, name: &str) -> anyhow::Result<&TableAsset> {
        self.assets.get(name).with_context(|| format!("table `{name}` was not baked (known: {:?})", self.assets.keys().collect::<Vec<_>>()))
    }
}

/// Bakes (or finds in `dir`'s cache) the tables named in `wanted` for `shading`, with the 1/λ
/// axis spanning only `lambda_range`, and loads them with a parameter check. `report` sees
/// each table as it is done.
pub fn bake_scene_tables(
    fiber: &FiberDescription,
    shading: EnvShading,
    resolution: BakeResolution,
    lambda_range: (f64, f64),
    wanted: &[&str],
    dir: &Path,
    report: &mut dyn FnMut(&BakedTable),
) -> anyhow::Result<SceneTables> {
    let options = PlanOptions {
        models: vec![shading.model()],
        resolution: resolution.with_lambda_range(lambda_range.0, lambda_range.1),
        force_multiple: false,
        multiple_threshold: DEFAULT_MULTIPLE_THRESHOLD,
    };
    let plan = plan(fiber, &options)?;
    let skipped = plan.skipped.iter().map(|s| (s.name.clone(), s.reason.clone())).collect();
    let mut expected: BTreeMap<String, Value> = BTreeMap::new();
    let mut baked = Vec::new();
    for job in plan.jobs.into_iter().filter(|j| wanted.contains(&j.name)) {
        expected.insert(job.name.to_string(), job.fiber_parameters.clone());
        let t = bake_job(job, dir, Storage::F32)?;
        report(&t);
        baked.push(t);
    }
    let mut assets = BTreeMap::new();
    for t in &baked {
        let asset = read_asset(&t.path)?;
        expect_parameters(&asset, &expected[&t.name])?;
        assets.insert(t.name.clone(), asset);
    }
    Ok(SceneTables { assets, baked, skipped })
}

/// One frame for the environment-lit renderer: a hair, a camera and one set of lights (all
/// SRBFs, directional lights, or SRBFs with a fit's compact sources as directional lights), shaded in `mode` with `tables`.
pub struct EnvFrame<'a> {
    pub hair: &'a HairModel,
    pub camera: Camera,
    pub width: u32,
    pub height: u32,
    pub lights: &'a [EnvLight],
    pub tables: &'a SceneTables,
    pub shading: EnvShading,
    pub mode: ScatteringMode,
    pub role: FrameRole,
    pub look: EnvLook,
}

/// A rendered frame and its GPU time.
pub struct RenderedEnv {
    pub image: Image,
    pub milliseconds: f64,
    /// Per pass (summed over batches), milliseconds; empty for stand-in renderers.
    pub passes: Vec<(String, f64)>,
    /// With [`EnvLook::count_fragments`].
    pub fragments: Option<FragmentCounts>,
    /// GPU memory held while one batch renders, per resource (bytes); empty for stand-ins.
    pub memory_per_batch: Vec<(String, u64)>,
}

/// The GPU device and the renderer's pipelines, created on first use and kept for every frame
/// of the run (pipeline creation is a one-time cost, not part of a frame).
struct GpuRenderer {
    gpu: GpuContext,
    renderer: EnvRenderer,
}

fn gpu_renderer() -> anyhow::Result<&'static GpuRenderer> {
    static RENDERER: OnceLock<Result<GpuRenderer, String>> = OnceLock::new();
    RENDERER
        .get_or_init(|| {
            let gpu = GpuContext::new_headless().map_err(|e| e.to_string())?;
            let renderer = EnvRenderer::new(&gpu);
            Ok(GpuRenderer { gpu, renderer })
        })
        .as_ref()
        .map_err(|e| anyhow::anyhow!("no GPU device for the environment-lit renderer: {e}"))
}

/// Passes an application pays once (device, pipelines, uploads of hair and tables), not per
/// frame; everything else the renderer times is the frame.
const SETUP_PASSES: [&str; 3] = ["pipelines", "upload", "table upload"];

/// Milliseconds of one frame: the renderer's passes without the one-time setup.
pub fn frame_milliseconds(stats: &EnvRenderStats) -> f64 {
    stats.timings.iter().filter(|t| !SETUP_PASSES.contains(&t.pass.as_str())).map(|t| t.milliseconds).sum()
}

/// Which renderer settings a frame uses.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FrameRole {
    /// The interactive method: SRBF lights (or the equal-cost directional baseline) with the
    /// paper's sparse forward-scattering grid and, for SRBFs, stochastic simplification κ.
    Interactive { kappa: f32 },
    /// The brute-force reference: every fiber in every light's map (κ = 1) and the forward
    /// scattering from the dense grid ([`ForwardScatteringSettings::dense_reference`]).
    Reference,
}

fn render_options(frame: &EnvFrame) -> EnvRenderOptions {
    // κ thins the SRBF lights' light passes (the runtime never thins a directional light's).
    let srbf = frame.lights.iter().any(|l| l.lambda.is_some());
    let kappa = match frame.role {
        FrameRole::Interactive { kappa } if srbf => kappa,
        _ => 1.0,
    };
    let look = frame.look;
    EnvRenderOptions { kappa, shadowed: look.shadowed, transparency: look.transparency, box_average: look.box_average, count_fragments: look.count_fragments, ..EnvRenderOptions::default() }
}

/// Forward-scattering settings of `role`.
pub fn forward_settings(role: FrameRole) -> ForwardScatteringSettings {
    match role {
        FrameRole::Interactive { .. } => ForwardScatteringSettings::default(),
        FrameRole::Reference => ForwardScatteringSettings::dense_reference(),
    }
}

/// The forward-scattering source of Ren §6 for `frame` on the device its look asks for
/// (voxelization included: a static hair pays it once, outside the frame time; dynamic hair per
/// frame — see docs/BENCHMARKS.md). The reference's light sweep runs on the CPU only.
fn forward_scattering<'g>(frame: &EnvFrame, gpu: &'g GpuContext) -> anyhow::Result<Box<dyn ForwardScatteringSource + 'g>> {
    let tables = ForwardScatteringTables::from_tables(&frame.tables.get("fiber_averages")?.table, &frame.tables.get("attenuation_ratio")?.table, &frame.tables.get("srbf_spread")?.table)?;
    let cpu = CpuForwardScattering::new(frame.hair, tables, forward_settings(frame.role))?;
    Ok(match frame.look.forward_scattering {
        _ if frame.role == FrameRole::Reference => Box::new(cpu),
        ForwardDevice::Cpu => Box::new(cpu),
        ForwardDevice::Gpu => Box::new(GpuForwardScattering::new(gpu, cpu).context("--forward-scattering gpu")?),
        ForwardDevice::Auto if gpu.report.is_software => Box::new(cpu),
        // A volume beyond the adapter's limits is still rendered, by rayon.
        ForwardDevice::Auto => match GpuForwardScattering::new(gpu, cpu.clone()) {
            Ok(on_gpu) => Box::new(on_gpu),
            Err(_) => Box::new(cpu),
        },
    })
}

/// The runtime's tables for `frame`: the SRBF table of its mode for SRBF lights, the direct
/// table for directional ones (the baselines, the reference, a fit's compact sources), and in
/// full mode I_G.
fn env_tables(frame: &EnvFrame) -> anyhow::Result<EnvTables> {
    let mut tables = EnvTables::default();
    if frame.lights.iter().any(|l| l.lambda.is_some()) {
        tables.srbf = Some(frame.tables.get(frame.shading.srbf_table(frame.mode))?.table.clone());
    }
    if frame.lights.iter().any(|l| l.lambda.is_none()) {
        tables.direct = Some(frame.tables.get(frame.shading.direct_table(frame.mode))?.table.clone());
    }
    if frame.mode == ScatteringMode::Full {
        tables.multiple = Some(frame.tables.get("multiple")?.table.clone());
    }
    Ok(tables)
}

/// THE call into the environment-lit renderer. The SRBF path reads
/// `tables.get(shading.srbf_table(mode))`, directional lights `tables.get(shading.direct_table(mode))`
/// (4 axes, the 1/λ axis a single node), and the full mode also [`MULTIPLE_TABLES`].
pub fn render_lights(frame: &EnvFrame) -> anyhow::Result<RenderedEnv> {
    let r = gpu_renderer()?;
    let tables = env_tables(frame)?;
    let source = match frame.mode {
        ScatteringMode::Single => None,
        ScatteringMode::Full => Some(forward_scattering(frame, &r.gpu)?),
    };
    let multiple = source.as_deref();
    let out = r
        .renderer
        .render(&r.gpu, frame.hair, &frame.camera, frame.width, frame.height, frame.lights, &tables, &render_options(frame), multiple)
        .with_context(|| format!("rendering {} lights ({} scattering)", frame.lights.len(), frame.mode.name()))?;
    Ok(RenderedEnv {
        milliseconds: frame_milliseconds(&out.stats),
        passes: out.stats.timings.iter().map(|t| (t.pass.clone(), t.milliseconds)).collect(),
        fragments: out.stats.fragments,
        memory_per_batch: out.stats.memory_per_batch.clone(),
        image: Image { width: out.width, height: out.height, pixels: out.pixels },
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn map_hash_sees_every_pixel_and_the_size() {
        let a = EnvMap::from_pixels(4, 2, vec![[1.0, 2.0, 3.0]; 8]);
        let mut pixels = vec![[1.0, 2.0, 3.0]; 8];
        pixels[7][2] = 3.0000002;
        let b = EnvMap::from_pixels(4, 2, pixels);
        let c = EnvMap::from_pixels(8, 1, vec![[1.0, 2.0, 3.0]; 8]);
        let (ha, hb, hc) = (map_pixels_sha256(&a), map_pixels_sha256(&b), map_pixels_sha256(&c));
        assert_eq!(ha.len(), 64);
        assert!(ha != hb && ha != hc && hb != hc);
        assert_eq!(ha, map_pixels_sha256(&a.clone()));
    }

    #[test]
    fn fits_are_cached_by_map_and_options() {
        let dir = std::env::temp_dir().join(format!("strandlight-fitcache-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        // A map made of one known lobe: a tiny fit converges in a fraction of a second.
        let lobe = strandlight_tables::srbf::SrbfLobe { center: [0.0, 1.0, 0.0], lambda: 20.0, amplitude: [1.0, 0.5, 0.25] };
        let map = procedural_env::from_srbf_lobes(64, &[lobe]);
        let env = LoadedEnv { sha256: map_pixels_sha256(&map), map, name: "one-lobe".into(), sanitized: Default::default() };
        let options = FitOptions { initial_lobes: 1, max_lobes: 2, grid_width: 64, iterations_per_round: 20, final_iterations: 20, ..FitOptions::default() };
        let first = fit_cached(&env, &options, &dir).unwrap();
        assert!(!first.cached);
        let again = fit_cached(&env, &options, &dir).unwrap();
        assert!(again.cached);
        assert_eq!(again.set.lobes, first.set.lobes);
        let other = fit_cached(&env, &FitOptions { max_lobes: 1, ..options.clone() }, &dir).unwrap();
        assert!(!other.cached, "other options must refit");
        assert!(!first.set.lobes.is_empty());
        // A changed map (one pixel) refits too.
        let mut pixels = env.map.pixels().to_vec();
        pixels[0][0] += 1.0;
        let map2 = EnvMap::from_pixels(env.map.width(), env.map.height(), pixels);
        let env2 = LoadedEnv { sha256: map_pixels_sha256(&map2), map: map2, name: "one-lobe".into(), sanitized: Default::default() };
        assert!(!fit_cached(&env2, &options, &dir).unwrap().cached, "a changed map must refit");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn tables_for_each_mode_exist_in_the_plan() {
        let dir = std::env::temp_dir().join(format!("strandlight-scene-tables-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let fiber = FiberDescription::preset("blonde").unwrap();
        for shading in [EnvShading::Marschner, EnvShading::Artist] {
            let mut wanted: Vec<&str> = MULTIPLE_TABLES.to_vec();
            for mode in [ScatteringMode::Single, ScatteringMode::Full] {
                wanted.push(shading.srbf_table(mode));
                wanted.push(shading.direct_table(mode));
            }
            let tables = bake_scene_tables(&fiber, shading, BakeResolution::reduced(4), (20.0, 40.0), &wanted, &dir.join(format!("{shading:?}")), &mut |_| {}).unwrap();
            for name in &wanted {
                let t = tables.get(name).unwrap();
                if !["fiber_averages", "attenuation_ratio", "srbf_spread"].contains(name) {
                    assert_eq!(t.table.axes().len(), 4, "{name}: the renderer's 4-axis lookup");
                }
            }
            // The 1/λ axis spans the requested range, not the global bounds.
            let conv = tables.get(shading.srbf_table(ScatteringMode::Single)).unwrap();
            let inv = &conv.table.axes()[3];
            assert!((inv.min - 1.0 / 40.0).abs() < 1e-12 && (inv.max - 1.0 / 20.0).abs() < 1e-12, "{inv:?}");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
