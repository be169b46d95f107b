//! One env-lit frame (Ren 2010): per batch of lights of one kind, the light pass (DODM), the
//! summed-area tables, then the view pass whose images are summed on the GPU; one readback at
//! the end. [`EnvRenderer`] keeps the pipelines across frames; [`render_env_frame`] builds them
//! for one frame.

use strandlight_tables::table::Table;
use strandlight_tables::table_axes::{
    AXIS_COS_DPHI, AXIS_INV_LAMBDA, AXIS_SIGMA_F, AXIS_U_DOT_WO, AXIS_U_DOT_XI,
};

use crate::camera::{Camera, LightFootprint, LightFraming};
use crate::env_light::{EnvLight, ShadowGroup, shadow_groups};
use crate::gpu::limits::{GpuLimits, LimitError, fit_pixels, fit_within};
use crate::gpu::readback::{ReadbackError, read_buffer};
use crate::gpu::{AdapterReport, GpuContext};
use crate::hair::{Aabb, HairModel};
use crate::head::Head;
use crate::multiple::{ForwardScatteringGrid, ForwardScatteringSource};
use crate::passes::convolution_depth::{
    ConvolutionDepthPass, DodmBatch, DodmSettings, DodmSettingsError, SimplifiedSegments,
    check_kappa, simplification_order,
};
use crate::passes::env_view::{
    BatchBinding, EnvAccumulator, EnvViewPass, EnvViewTargets, FrameVisibility, TableBinding,
    ViewBinding, VolumeBuffers,
};
use crate::passes::frame_params::{FrameParams, KajiyaKay};
use crate::passes::head::{HeadDepthMaps, HeadGeometry};
use crate::passes::strand_geometry::{StrandGeometry, TooManyPoints};
use crate::passes::summed_area::{SummedAreaPass, SummedAreaTables};
pub use crate::passes::transmittance_filter::TransmittanceFilter;
use crate::passes::view_visibility::OccupancyMap;
pub use crate::passes::view_visibility::{FragmentCounts, OccupancyError, ViewTransparency};
use crate::render::PassTiming;
use crate::visibility::{
    LobeVisibility, VisibilityVolume, VisibilityVolumeError, VisibilityVolumeSettings,
};
use std::sync::{Arc, Mutex};

/// The tables a frame shades with. Each is an RGB [`Table`] with axes (u·ξ, u·ω_o, cos Δφ, w):
/// * `srbf`: the convolution table I (I_M, `marschner_full` or the artist I_A), w = 1/λ;
/// * `direct`: S(ω_i, ω_o)·cos θ_i for directional lights, w a one-node axis (any name);
/// * `multiple`: I_G, w = σ̄_f (used only with a [`ForwardScatteringSource`]).
#[derive(Clone, Debug, Default)]
pub struct EnvTables {
    pub srbf: Option<Arc<Table>>,
    pub direct: Option<Arc<Table>>,
    pub multiple: Option<Arc<Table>>,
}

#[derive(Debug, thiserror::Error, PartialEq)]
pub enum EnvTableError {
    #[error("env table `{table}` is needed ({needed_by}) but was not given")]
    Missing {
        table: &'static str,
        needed_by: &'static str,
    },
    #[error("env table `{table}`: {problem}")]
    Shape {
        table: &'static str,
        problem: String,
    },
}

/// Checks an env table's layout: 4 axes, the three direction axes by name, the fourth named
/// `fourth` (or any name with one node when `None`), 3 channels.
pub fn check_env_table(
    table_name: &'static str,
    table: &Table,
    fourth: Option<&str>,
) -> Result<(), EnvTableError> {
    let bad = |problem: String| EnvTableError::Shape {
        table: table_name,
        problem,
    };
    let axes = table.axes();
    if axes.len() != 4 {
        return Err(bad(format!("has {} axes, expected 4", axes.len())));
    }
    for (axis, name) in axes
        .iter()
        .zip([AXIS_U_DOT_XI, AXIS_U_DOT_WO, AXIS_COS_DPHI])
    {
        if axis.name != name {
            return Err(bad(format!(
                "axis `{}` where `{name}` was expected",
                axis.name
            )));
        }
    }
    match fourth {
        Some(name) if axes[3].name != name => {
            return Err(bad(format!(
                "fourth axis `{}` where `{name}` was expected",
                axes[3].name
            )));
        }
        None if axes[3].count != 1 => {
            return Err(bad(format!(
                "fourth axis `{}` has {} nodes; a direct table has one",
                axes[3].name, axes[3].count
            )));
        }
        _ => {}
    }
    if table.channels() != 3 {
        return Err(bad(format!(
            "has {} channels, expected 3 (RGB)",
            table.channels()
        )));
    }
    if u32::try_from(table.values().len()).is_err() {
        return Err(bad("holds more than 2^32 values".into()));
    }
    Ok(())
}

/// The default seed of the strand order behind stochastic simplification.
pub const DEFAULT_SIMPLIFICATION_SEED: u64 = 0x5eed;

/// Everything besides the scene that changes how a frame is rendered. Its `Debug` text is part
/// of the cached references' keys (`compare`): options added later print only when set, so
/// the references rendered before them keep their keys.
#[derive(Clone, Copy, PartialEq)]
pub struct EnvRenderOptions {
    /// Light-pass map resolution, first-layer depth and lights per batch.
    pub dodm: DodmSettings,
    /// Stochastic simplification (Ren §7): the light pass of SRBF lights draws this fraction of
    /// the strands (their width enlarged by 1/κ, τ scaled by 1/κ); 1 draws them all. Default
    /// 0.1. Directional lights (a sun taken out of the map) always draw every strand: one sharp
    /// shadow is what the simplification would blur.
    pub kappa: f32,
    /// Seed of the strand order behind κ (`simplification_order`'s scramble).
    pub simplification_seed: u64,
    /// What the view sees of each pixel's fibers: the nearest one (default) or all of them
    /// through the occupancy map (Ren §8).
    pub transparency: ViewTransparency,
    /// Count the fragments rasterized and shaded ([`EnvRenderStats::fragments`]; two extra
    /// passes over the hair, outside the timed passes).
    pub count_fragments: bool,
    /// `false`: no self-shadowing (T̃ = 1; for tests and for comparisons).
    pub shadowed: bool,
    /// The averaging box of the effective transmittance (default
    /// [`TransmittanceFilter::MatchedVariance`], the best measured: docs/BENCHMARKS.md).
    pub transmittance_filter: TransmittanceFilter,
    /// View pass only: every fiber this many pixels wide instead of its projected thickness (as
    /// `FrameParams::width_override_px`); the light pass always uses the file's thickness.
    pub width_override_px: Option<f32>,
    /// Where SRBF lobes' visibility comes from: their light maps (Ren's) or the groom's
    /// visibility volume integrated over each lobe.
    pub lobe_visibility: LobeVisibility,
}

impl std::fmt::Debug for EnvRenderOptions {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mut s = f.debug_struct("EnvRenderOptions");
        s.field("dodm", &self.dodm)
            .field("kappa", &self.kappa)
            .field("simplification_seed", &self.simplification_seed)
            .field("transparency", &self.transparency)
            .field("count_fragments", &self.count_fragments)
            .field("shadowed", &self.shadowed)
            .field("transmittance_filter", &self.transmittance_filter)
            .field("width_override_px", &self.width_override_px);
        if self.lobe_visibility != LobeVisibility::LightMaps {
            s.field("lobe_visibility", &self.lobe_visibility);
        }
        s.finish()
    }
}

impl Default for EnvRenderOptions {
    fn default() -> Self {
        Self {
            dodm: DodmSettings::default(),
            kappa: 0.1,
            simplification_seed: DEFAULT_SIMPLIFICATION_SEED,
            transparency: ViewTransparency::Opaque,
            count_fragments: false,
            shadowed: true,
            transmittance_filter: TransmittanceFilter::default(),
            width_override_px: None,
            lobe_visibility: LobeVisibility::LightMaps,
        }
    }
}

#[derive(Debug, thiserror::Error)]
pub enum EnvRenderError {
    #[error("the environment has no lights")]
    NoLights,
    #[error("light {index}: {problem}")]
    BadLight { index: usize, problem: String },
    #[error(transparent)]
    Settings(#[from] DodmSettingsError),
    #[error(transparent)]
    Table(#[from] EnvTableError),
    #[error(transparent)]
    Limit(#[from] LimitError),
    #[error("forward-scattering grid: {0}")]
    Grid(String),
    #[error(transparent)]
    Transparency(#[from] OccupancyError),
    #[error(transparent)]
    TooManyPoints(#[from] TooManyPoints),
    #[error(transparent)]
    Readback(#[from] ReadbackError),
    #[error("the GPU reported an error: {0}")]
    Gpu(String),
    #[error(transparent)]
    VisibilityVolume(#[from] VisibilityVolumeError),
}

#[derive(Clone, Debug)]
pub struct EnvRenderStats {
    pub adapter: AdapterReport,
    /// Per pass, summed over batches: "upload", "pipelines", "view visibility", "light pass",
    /// "summed-area tables", "view", "multiple grid (CPU)" or "multiple grid (GPU)", "readback".
    pub timings: Vec<PassTiming>,
    /// GPU memory held while one batch renders (the frame's buffers included), per resource.
    pub memory_per_batch: Vec<(String, u64)>,
    pub batches: u32,
    pub lights: u32,
    pub segments: u32,
    /// Segments an SRBF batch's light pass draws (κ of the strands; directional batches draw all).
    pub light_pass_segments: u32,
    pub timing_method: &'static str,
    /// With [`EnvRenderOptions::count_fragments`]: the fragments of one batch's view pass.
    pub fragments: Option<FragmentCounts>,
}

/// A rendered frame: linear, pre-multiplied RGBA, row-major from the top.
#[derive(Clone, Debug)]
pub struct EnvFrame {
    pub width: u32,
    pub height: u32,
    /// single + multiple.
    pub pixels: Vec<[f32; 4]>,
    pub single_pixels: Vec<[f32; 4]>,
    /// `None` without a forward-scattering source.
    pub multiple_pixels: Option<Vec<[f32; 4]>>,
    pub stats: EnvRenderStats,
}

/// A frame whose passes are submitted and whose pixels are still on the GPU
/// ([`EnvRenderer::encode_part`]).
pub struct EncodedFrame {
    pub width: u32,
    pub height: u32,
    /// Linear, pre-multiplied RGBA f32, row-major from the top: single scattering for every
    /// pixel, then (`with_multiple`) multiple scattering for every pixel.
    pub sums: wgpu::Buffer,
    pub with_multiple: bool,
    pub stats: EnvRenderStats,
}

fn check_light(index: usize, light: &EnvLight) -> Result<(), EnvRenderError> {
    let bad = |problem: String| EnvRenderError::BadLight { index, problem };
    if !light.direction.is_finite() || light.direction.length() < 1e-6 {
        return Err(bad(format!(
            "direction {:?} is not a usable unit vector",
            light.direction
        )));
    }
    if let Some(lambda) = light.lambda
        && !(lambda.is_finite() && lambda > 0.0)
    {
        return Err(bad(format!(
            "SRBF bandwidth λ = {lambda} must be positive and finite"
        )));
    }
    if light.rgb.iter().any(|c| !c.is_finite()) {
        return Err(bad(format!("rgb {:?} is not finite", light.rgb)));
    }
    if !(light.angular_variance.is_finite() && light.angular_variance >= 0.0) {
        return Err(bad(format!(
            "angular variance {} must be finite and non-negative",
            light.angular_variance
        )));
    }
    if light.angular_variance > 0.0 && light.lambda.is_some() {
        return Err(bad(
            "angular_variance is for directional lights (an SRBF's spread is its λ)".into(),
        ));
    }
    if let Some(from) = light.shadowed_from {
        if light.lambda.is_some() {
            return Err(bad(
                "an SRBF light casts its own shadow map (shadowed_from is for directional lights)"
                    .into(),
            ));
        }
        if !from.is_finite() || from.length() < 1e-6 {
            return Err(bad(format!(
                "shadowed_from {from:?} is not a usable unit vector"
            )));
        }
    }
    Ok(())
}

fn check_grid(grid: &ForwardScatteringGrid, lights: usize) -> Result<(), EnvRenderError> {
    let vertices = grid.dims.iter().map(|&d| d as usize).product::<usize>();
    if vertices == 0 {
        return Err(EnvRenderError::Grid(format!(
            "dims {:?} has a zero",
            grid.dims
        )));
    }
    if grid.values.len() != vertices * lights {
        return Err(EnvRenderError::Grid(format!(
            "{} values for {lights} lights × {vertices} vertices",
            grid.values.len()
        )));
    }
    if !grid.origin.is_finite() || !grid.spacing.is_finite() || grid.spacing.min_element() <= 0.0 {
        return Err(EnvRenderError::Grid(format!(
            "origin {:?} / spacing {:?} must be finite, spacing positive",
            grid.origin, grid.spacing
        )));
    }
    if grid.values.iter().any(|v| v.iter().any(|c| !c.is_finite())) {
        return Err(EnvRenderError::Grid("holds non-finite values".into()));
    }
    Ok(())
}

/// Totals per pass name over the frame's batches.
struct Timings(Vec<PassTiming>);

impl Timings {
    fn time<T>(&mut self, gpu: &GpuContext, pass: &str, work: impl FnOnce() -> T) -> T {
        let (out, milliseconds, gpu_milliseconds) = gpu.time_passes(work);
        PassTiming {
            pass: pass.to_string(),
            milliseconds,
            gpu_milliseconds,
        }
        .add_to(&mut self.0);
        out
    }
}

/// The pipelines of the env-lit renderer, reusable across frames.
pub struct EnvRenderer {
    depth: ConvolutionDepthPass,
    sat: SummedAreaPass,
    view: EnvViewPass,
    /// The last groom's visibility volume on the GPU, kept while frames ask for the same hair
    /// and settings (a static groom pays its build once).
    volume: Mutex<Option<CachedVolume>>,
    /// The last frames' tables on the GPU, kept while frames bind the same tables (a
    /// progressive frame's steps, a viewer's frames): their upload was most of a step's CPU
    /// time in a web page (tens of MB a step).
    table_bindings: Mutex<Vec<CachedTables>>,
}

/// Tables uploaded and bound: the same tables are the same allocations (`Arc::ptr_eq`), which
/// the cache's own references keep from being reused by other tables.
struct CachedTables {
    single: Arc<Table>,
    multiple: Option<Arc<Table>>,
    binding: Arc<TableBinding>,
}

/// A frame binds at most two pairs of tables (SRBF and directional lights).
const CACHED_TABLE_BINDINGS: usize = 2;

/// A visibility volume uploaded for one groom and settings.
struct CachedVolume {
    key: (u64, VisibilityVolumeSettings),
    buffers: Arc<VolumeBuffers>,
}

/// A fingerprint of the hair a visibility volume was built from: its points, strands and
/// thicknesses (what the march sees).
fn hair_fingerprint(model: &HairModel) -> u64 {
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    model.points_bytes().hash(&mut h);
    model.strand_offsets_bytes().hash(&mut h);
    if let Some(t) = model.thickness() {
        t.per_point_values(model.point_count())
            .iter()
            .for_each(|v| v.to_bits().hash(&mut h));
    }
    h.finish()
}

/// A frame's lights split by kind, each batched apart: SRBFs and directional lights (each with
/// its own table), each drawing every strand into their maps or κ of them (one light-pass
/// geometry and one map size per batch). κ-thinned SRBFs are ranked by power, strongest first:
/// a thinned light's strand subset follows its place among them
/// ([`FrameResources::next_windows`]), so the frame must not depend on the order its caller
/// lists the lobes in (`compare` lists them in fit order, `bench` by power).
struct LightKinds {
    srbf_every_strand: Vec<EnvLight>,
    srbf: Vec<EnvLight>,
    directional: Vec<EnvLight>,
    directional_thinned: Vec<EnvLight>,
}

impl LightKinds {
    fn of(lights: &[EnvLight]) -> Self {
        let (srbf, directional): (Vec<EnvLight>, _) =
            lights.iter().partition(|l| l.lambda.is_some());
        let (srbf_every_strand, mut srbf): (_, Vec<EnvLight>) =
            srbf.into_iter().partition(|l| l.every_strand);
        // Stable, so lights of equal power keep the caller's order.
        srbf.sort_by(|a, b| b.luminous_power().total_cmp(&a.luminous_power()));
        let (directional, directional_thinned) =
            directional.into_iter().partition(|l| l.every_strand);
        Self {
            srbf_every_strand,
            srbf,
            directional,
            directional_thinned,
        }
    }

    fn has_srbf(&self) -> bool {
        !(self.srbf.is_empty() && self.srbf_every_strand.is_empty())
    }

    fn has_directional(&self) -> bool {
        !(self.directional.is_empty() && self.directional_thinned.is_empty())
    }

    /// Whether any light is a compact source, whose maps are fitted to the hair
    /// ([`LightFraming::Fitted`]).
    fn has_sharp_shadows(&self) -> bool {
        (self.directional.iter())
            .chain(&self.directional_thinned)
            .any(EnvLight::has_sharp_shadow)
    }

    /// The kinds whose maps κ thins.
    fn thinned(&self) -> [&Vec<EnvLight>; 2] {
        [&self.srbf, &self.directional_thinned]
    }

    fn has_thinned(&self) -> bool {
        self.thinned().iter().any(|k| !k.is_empty())
    }
}

/// The table a kind of light needs, checked for its layout.
fn required_table<'t>(
    table: &'t Option<Arc<Table>>,
    name: &'static str,
    needed_by: &'static str,
    fourth_axis: Option<&str>,
) -> Result<&'t Table, EnvTableError> {
    let t = table.as_deref().ok_or(EnvTableError::Missing {
        table: name,
        needed_by,
    })?;
    check_env_table(name, t, fourth_axis)?;
    Ok(t)
}

/// Everything the inputs must satisfy before anything is created on the GPU.
fn check_inputs(
    lights: &[EnvLight],
    kinds: &LightKinds,
    tables: &EnvTables,
    options: &EnvRenderOptions,
    with_multiple: bool,
) -> Result<(), EnvRenderError> {
    if lights.is_empty() {
        return Err(EnvRenderError::NoLights);
    }
    for (i, l) in lights.iter().enumerate() {
        check_light(i, l)?;
    }
    options.dodm.check()?;
    check_kappa(options.kappa)?;
    options.transparency.check()?;
    if let Some(volume) = options.lobe_visibility.volume() {
        volume.validate()?;
    }
    if kinds.has_srbf() {
        required_table(&tables.srbf, "srbf", "SRBF lights", Some(AXIS_INV_LAMBDA))?;
    }
    if kinds.has_directional() {
        required_table(&tables.direct, "direct", "directional lights", None)?;
    }
    if with_multiple {
        required_table(
            &tables.multiple,
            "multiple",
            "multiple scattering",
            Some(AXIS_SIGMA_F),
        )?;
    }
    Ok(())
}

/// A DODM batch (one array layer per light slot) against the adapter's limits; the image is
/// checked first, the SAT, the occupancy map and the sums when created.
fn check_light_map_limits(gpu: &GpuContext, resolution: u32, slots: u32) -> Result<(), LimitError> {
    let limits = GpuLimits::of(gpu);
    limits.check_texture_2d("DODM", resolution, resolution, |max| {
        format!("use a DODM resolution of at most {max}")
    })?;
    limits.check_texture_layers("DODM light batch", slots, |max| {
        format!("use a light batch size of at most {max}")
    })
}

/// The tables a frame binds whole, against the adapter's storage-binding limit: a table baked
/// with too many nodes (64 per direction axis is 400 MB) is refused by name, not by the driver.
fn check_table_limits(
    gpu: &GpuContext,
    tables: &EnvTables,
    kinds: &LightKinds,
    with_multiple: bool,
) -> Result<(), LimitError> {
    let limits = GpuLimits::of(gpu);
    let bound = [
        ("env table `srbf`", kinds.has_srbf(), &tables.srbf),
        (
            "env table `direct`",
            kinds.has_directional(),
            &tables.direct,
        ),
        ("env table `multiple`", with_multiple, &tables.multiple),
    ];
    for (what, needed, table) in bound {
        if let Some(t) = table.as_ref().filter(|_| needed) {
            limits.check_storage_buffer(what, t.as_bytes().len() as u64, |max| {
                format!("bake it with fewer nodes per axis, to at most {max} bytes")
            })?;
        }
    }
    Ok(())
}

/// The frame's running sums (two RGBA f32 images) and the pass that adds into them.
fn check_sums_limits(gpu: &GpuContext, width: u32, height: u32) -> Result<(), LimitError> {
    let limits = GpuLimits::of(gpu);
    let pixels_fitting = |bytes_per_pixel: u64| {
        move |max: u64| {
            let (w, h) = fit_pixels(width, height, max / bytes_per_pixel);
            format!("render at {w}x{h} or smaller")
        }
    };
    let sums = EnvViewPass::accumulator_bytes(width, height);
    limits.check_storage_buffer(
        "env sums",
        sums,
        pixels_fitting(sums / (width as u64 * height as u64)),
    )?;
    limits.check_workgroups(
        "env accumulate",
        [width.div_ceil(8), height.div_ceil(8), 1],
        |max| {
            let (w, h) = fit_within(width, height, max as u64 * 8);
            format!("render at {w}x{h} or smaller")
        },
    )
}

/// What one frame renders into, created once before its passes: the hair (all of it for the
/// view and directional lights, the κ-simplified order for SRBF light passes), the DODM batch
/// (DODM: the convolution optical depth map of Ren 2010 §5, one layer per light) and its
/// summed-area tables, the view's visibility, targets and running sums, and the tables bound
/// per light kind.
struct FrameResources {
    geometry: StrandGeometry,
    light_geometry: StrandGeometry,
    /// κ < 1: the strands in simplification order, whose windows the simplified light passes
    /// draw, and the next light's window.
    simplified: Option<SimplifiedSegments>,
    next_window: u32,
    footprint: LightFootprint,
    /// The light maps of every-strand SRBFs and directional lights, at the DODM resolution
    /// (None where the frame has only simplified SRBFs).
    full_maps: Option<LightMaps>,
    /// The light maps of κ-simplified SRBFs, at [`DodmSettings::simplified_resolution`]
    /// (None where that is the full resolution: they share `full_maps`).
    simplified_maps: Option<LightMaps>,
    occupancy: OccupancyMap,
    targets: EnvViewTargets,
    sums: EnvAccumulator,
    /// Group 0 of every view and visibility pass.
    strands: wgpu::BindGroup,
    coverage_view: wgpu::TextureView,
    /// [`EnvViewTargets::nearest_position`] and `nearest_tangent`.
    nearest_views: [wgpu::TextureView; 2],
    depth_view: wgpu::TextureView,
    /// The single-scattering tables of the SRBF and the directional lights (None: no such
    /// lights), each bound with the multiple-scattering table.
    srbf_tables: Option<Arc<TableBinding>>,
    directional_tables: Option<Arc<TableBinding>>,
    /// The groom's visibility volume (or its placeholder under Ren's light maps).
    volume: Arc<VolumeBuffers>,
    /// The head (issue 40), drawn into the view's depth and every light map.
    head: Option<HeadGeometry>,
    /// The view camera's world to clip space.
    view_proj: glam::Mat4,
    /// [`EnvViewTargets::head_position`] and `head_normal`.
    head_views: [wgpu::TextureView; 2],
}

/// Texels across the light maps bound, unread, by SRBF batches that read the visibility volume.
const PLACEHOLDER_MAP_RESOLUTION: u32 = 8;

/// One resolution's light maps: the batch's DODM and its summed-area tables.
struct LightMaps {
    dodm: DodmBatch,
    sat: SummedAreaTables,
    /// The head's depth from each slot's light, where the frame has a head.
    head: Option<HeadDepthMaps>,
}

impl LightMaps {
    fn new(
        gpu: &GpuContext,
        resolution: u32,
        slots: u32,
        first_layer: f32,
    ) -> Result<Self, EnvRenderError> {
        check_light_map_limits(gpu, resolution, slots)?;
        Ok(Self {
            sat: SummedAreaTables::new(gpu, resolution, slots)?,
            dodm: DodmBatch::new(gpu, resolution, slots, first_layer),
            head: None,
        })
    }

    /// A frame's full-resolution maps and its simplified ones (each None where no batch draws
    /// them), with as many slots as the most maps one batch of their kinds holds.
    fn for_frame(
        gpu: &GpuContext,
        options: &EnvRenderOptions,
        kinds: &LightKinds,
        first_layer: f32,
    ) -> Result<(Option<Self>, Option<Self>), EnvRenderError> {
        if options.shadowed && options.lobe_visibility.volume().is_some() && kinds.has_srbf() {
            // SRBF lobes read the visibility volume: only the compact sources draw maps, and
            // SRBF batches bind a small placeholder that nothing reads.
            let sources = LightKinds {
                srbf_every_strand: Vec::new(),
                srbf: Vec::new(),
                directional: kinds.directional.clone(),
                directional_thinned: kinds.directional_thinned.clone(),
            };
            let placeholder = || Self::new(gpu, PLACEHOLDER_MAP_RESOLUTION, 1, first_layer);
            if !sources.has_directional() {
                return Ok((Some(placeholder()?), None));
            }
            let (full, simplified) = Self::for_frame(gpu, options, &sources, first_layer)?;
            let full = match full {
                Some(maps) => maps,
                None => placeholder()?,
            };
            return Ok((Some(full), simplified));
        }
        let dodm = &options.dodm;
        let slots = |lights: &[&Vec<EnvLight>]| {
            let most = lights
                .iter()
                .map(|k| shadow_groups(k).len())
                .max()
                .unwrap_or(0);
            (dodm.batch_size as usize).min(most) as u32
        };
        let simplified_resolution = dodm.simplified_resolution(options.kappa);
        let full_kinds = [&kinds.srbf_every_strand, &kinds.directional];
        let thinned = kinds.thinned();
        if !kinds.has_thinned() || simplified_resolution == dodm.resolution {
            let all = slots(&[full_kinds[0], full_kinds[1], thinned[0], thinned[1]]);
            return Ok((
                Some(Self::new(gpu, dodm.resolution, all, first_layer)?),
                None,
            ));
        }
        let full = match slots(&full_kinds) {
            0 => None,
            n => Some(Self::new(gpu, dodm.resolution, n, first_layer)?),
        };
        let simplified = Self::new(gpu, simplified_resolution, slots(&thinned), first_layer)?;
        Ok((full, Some(simplified)))
    }

    /// GPU memory per resource, each name after `prefix`.
    fn memory(&self, prefix: &str) -> Vec<(String, u64)> {
        let named = |(name, bytes): (String, u64)| (format!("{prefix}{name}"), bytes);
        let mut memory: Vec<_> = self.dodm.memory().into_iter().map(named).collect();
        memory.extend(self.sat.memory().into_iter().map(named));
        if let Some(head) = &self.head {
            memory.push(named(("head light depth".into(), head.memory())));
        }
        memory
    }

    /// The maps a batch draws: the simplified ones for κ-thinned SRBFs where the frame has them.
    fn choose<'a>(
        simplified: bool,
        full: &'a mut Option<LightMaps>,
        simplified_maps: &'a mut Option<LightMaps>,
    ) -> &'a mut LightMaps {
        match (simplified, simplified_maps) {
            (true, Some(maps)) => maps,
            _ => full
                .as_mut()
                .expect("a frame holds full-resolution maps for every batch not simplified"),
        }
    }
}

impl FrameResources {
    /// The light maps a batch draws ([`LightMaps::choose`]).
    fn maps(&mut self, simplified: bool) -> &mut LightMaps {
        LightMaps::choose(simplified, &mut self.full_maps, &mut self.simplified_maps)
    }

    /// The visibility input of group 3 for this frame.
    fn visibility(&self, options: &EnvRenderOptions) -> FrameVisibility<'_> {
        FrameVisibility {
            volume: &self.volume,
            map: &self.occupancy,
            coverage: &self.coverage_view,
            nearest: [&self.nearest_views[0], &self.nearest_views[1]],
            transparency: options.transparency,
            width: self.sums.width,
            height: self.sums.height,
            head: [&self.head_views[0], &self.head_views[1]],
            skin: self.head.as_ref().map(|h| h.albedo),
            view_proj: self.view_proj,
        }
    }

    /// The strand windows of the next `lights` simplified light maps (the frame's κ-thinned
    /// SRBF lights, counted across batches): each light its own subset
    /// ([`SimplifiedSegments::window`]).
    fn next_windows(&mut self, lights: usize, kappa: f32) -> Vec<Vec<std::ops::Range<u32>>> {
        let Some(simplified) = &self.simplified else {
            return vec![vec![0..self.light_geometry.segment_count]; lights];
        };
        let first = self.next_window;
        self.next_window += lights as u32;
        (first..self.next_window)
            .map(|k| simplified.window(kappa, k))
            .collect()
    }

    /// GPU memory held while one batch renders, per resource (tables and grid added later).
    fn memory(&self) -> Vec<(String, u64)> {
        let mut memory = self.geometry.memory();
        if let Some(maps) = &self.full_maps {
            memory.extend(maps.memory(""));
        }
        if let Some(maps) = &self.simplified_maps {
            memory.extend(maps.memory("simplified "));
        }
        memory.extend(self.targets.memory());
        memory.push(self.occupancy.memory());
        memory.push(("env sums".into(), self.sums.sums.size()));
        memory.push(("visibility volume".into(), self.volume.bytes));
        if let Some(head) = &self.head {
            memory.push(("head geometry".into(), head.bytes()));
        }
        memory
    }
}

/// The geometry the SRBF light passes draw: when κ < 1, the strands in simplification order
/// (with that order, whose windows the passes draw); else all of them as they are.
fn light_pass_geometry(
    gpu: &GpuContext,
    model: &HairModel,
    geometry: &StrandGeometry,
    options: &EnvRenderOptions,
) -> (StrandGeometry, Option<SimplifiedSegments>) {
    if options.kappa >= 1.0 {
        return (geometry.clone(), None);
    }
    let order = simplification_order(model, options.simplification_seed);
    let simplified = SimplifiedSegments::in_order(gpu, model, &order);
    (
        simplified.geometry(geometry, options.kappa),
        Some(simplified),
    )
}

/// What one frame is asked for.
struct FrameRequest<'a> {
    model: &'a HairModel,
    camera: &'a Camera,
    width: u32,
    height: u32,
    tables: &'a EnvTables,
    options: &'a EnvRenderOptions,
    multiple: Option<&'a dyn ForwardScatteringSource>,
    head: Option<&'a Head>,
}

impl EnvRenderer {
    pub fn new(gpu: &GpuContext) -> Self {
        Self {
            depth: ConvolutionDepthPass::new(gpu),
            sat: SummedAreaPass::new(gpu),
            view: EnvViewPass::new(gpu),
            volume: Mutex::new(None),
            table_bindings: Mutex::new(Vec::new()),
        }
    }

    /// `single` bound with `multiple` (see [`TableBinding`]), uploaded unless a recent frame
    /// bound the same tables.
    fn table_binding(
        &self,
        gpu: &GpuContext,
        single: &Arc<Table>,
        multiple: Option<&Arc<Table>>,
    ) -> Arc<TableBinding> {
        let mut cache = self.table_bindings.lock().expect("table cache lock");
        let same = |c: &CachedTables| {
            Arc::ptr_eq(&c.single, single)
                && match (&c.multiple, multiple) {
                    (Some(a), Some(b)) => Arc::ptr_eq(a, b),
                    (None, None) => true,
                    _ => false,
                }
        };
        if let Some(cached) = cache.iter().find(|c| same(c)) {
            return cached.binding.clone();
        }
        let binding = Arc::new(TableBinding::new(
            gpu,
            &self.view.table_layout,
            single,
            multiple.map(|m| &**m),
        ));
        if cache.len() == CACHED_TABLE_BINDINGS {
            cache.remove(0);
        }
        cache.push(CachedTables {
            single: single.clone(),
            multiple: multiple.cloned(),
            binding: binding.clone(),
        });
        binding
    }

    /// Makes `volume` the visibility volume of `model` under `settings` (instead of building
    /// it): a volume computed elsewhere, or a hand-made one in tests.
    pub fn use_visibility_volume(
        &self,
        gpu: &GpuContext,
        model: &HairModel,
        settings: VisibilityVolumeSettings,
        volume: &VisibilityVolume,
    ) {
        *self.volume.lock().unwrap_or_else(|e| e.into_inner()) = Some(CachedVolume {
            key: (hair_fingerprint(model), settings),
            buffers: Arc::new(VolumeBuffers::new(gpu, Some(volume))),
        });
    }

    /// The frame's volume buffers: the cached volume where the hair and settings match, else
    /// built (timed as "visibility volume", a static groom's setup), or the placeholder.
    fn volume_buffers(
        &self,
        gpu: &GpuContext,
        model: &HairModel,
        head: Option<&Head>,
        options: &EnvRenderOptions,
        timings: &mut Timings,
    ) -> Result<Arc<VolumeBuffers>, EnvRenderError> {
        let Some(settings) = options
            .lobe_visibility
            .volume()
            .filter(|_| options.shadowed)
        else {
            return Ok(Arc::new(VolumeBuffers::new(gpu, None)));
        };
        // The head is in the volume (its marches stop at it): another head, another volume.
        let scene = hair_fingerprint(model) ^ head.map_or(0, |h| h.fingerprint().rotate_left(17));
        let key = (scene, *settings);
        let mut cache = self.volume.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(cached) = cache.as_ref().filter(|c| c.key == key) {
            return Ok(cached.buffers.clone());
        }
        let volume = timings.time(gpu, "visibility volume", || {
            VisibilityVolume::build_with_head(model, settings, head)
        })?;
        GpuLimits::of(gpu).check_storage_buffer(
            "visibility volume",
            volume.bytes().len() as u64,
            |max| format!("use fewer voxels along the longest side (at most {max} bytes)"),
        )?;
        let buffers = Arc::new(VolumeBuffers::new(gpu, Some(&volume)));
        *cache = Some(CachedVolume {
            key,
            buffers: buffers.clone(),
        });
        Ok(buffers)
    }

    /// Renders `model` seen by `camera` into `width`×`height` under `lights` (SRBFs shaded with
    /// `tables.srbf`, directional lights with `tables.direct`), with multiple scattering from
    /// `multiple` (and `tables.multiple`) when given.
    #[allow(clippy::too_many_arguments)]
    pub fn render(
        &self,
        gpu: &GpuContext,
        model: &HairModel,
        camera: &Camera,
        width: u32,
        height: u32,
        lights: &[EnvLight],
        tables: &EnvTables,
        options: &EnvRenderOptions,
        multiple: Option<&dyn ForwardScatteringSource>,
    ) -> Result<EnvFrame, EnvRenderError> {
        let part = (lights, 0);
        self.render_part(
            gpu, model, camera, width, height, part, tables, options, multiple, None,
        )
    }

    /// [`Self::render`] for `lights` that continue a frame rendered in parts (the viewer's
    /// progressive batches): its simplified lights draw the strand windows from `first_window`
    /// on, the number of simplified lights in the parts before, so the parts sum to the frame
    /// rendered at once ([`SimplifiedSegments::window`]). With `head`, the head hides the fibers
    /// behind it, is drawn as skin and is opaque in every light's visibility.
    #[allow(clippy::too_many_arguments)]
    pub fn render_part(
        &self,
        gpu: &GpuContext,
        model: &HairModel,
        camera: &Camera,
        width: u32,
        height: u32,
        part: (&[EnvLight], u32),
        tables: &EnvTables,
        options: &EnvRenderOptions,
        multiple: Option<&dyn ForwardScatteringSource>,
        head: Option<&Head>,
    ) -> Result<EnvFrame, EnvRenderError> {
        let scope = gpu.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let encoded = self.encode_part(
            gpu, model, camera, width, height, part, tables, options, multiple, head,
        )?;
        let mut timings = Timings(encoded.stats.timings.clone());
        let bytes = timings.time(gpu, "readback", || read_buffer(gpu, &encoded.sums))?;
        if let Some(error) = pollster::block_on(scope.pop()) {
            return Err(EnvRenderError::Gpu(error.to_string()));
        }
        let (pixels, single_pixels, multiple_pixels) =
            split_sums(&bytes, width, height, encoded.with_multiple);
        Ok(EnvFrame {
            width,
            height,
            pixels,
            single_pixels,
            multiple_pixels,
            stats: EnvRenderStats {
                timings: timings.0,
                ..encoded.stats
            },
        })
    }

    /// [`Self::render_part`] up to the pixels: every pass submitted, the sums left on the GPU
    /// (a web page cannot wait for a readback; it draws them or maps them later). The caller
    /// owns the error scope.
    #[allow(clippy::too_many_arguments)]
    pub fn encode_part(
        &self,
        gpu: &GpuContext,
        model: &HairModel,
        camera: &Camera,
        width: u32,
        height: u32,
        (lights, first_window): (&[EnvLight], u32),
        tables: &EnvTables,
        options: &EnvRenderOptions,
        multiple: Option<&dyn ForwardScatteringSource>,
        head: Option<&Head>,
    ) -> Result<EncodedFrame, EnvRenderError> {
        let request = FrameRequest {
            model,
            camera,
            width,
            height,
            tables,
            options,
            multiple,
            head,
        };
        let mut timings = Timings(Vec::new());
        let kinds = LightKinds::of(lights);
        check_inputs(lights, &kinds, tables, options, multiple.is_some())?;
        let mut frame = self.frame_resources(gpu, &request, &kinds, &mut timings)?;
        frame.next_window = first_window;
        let mut memory = frame.memory();
        self.encode_visibility(gpu, &frame, options, camera, &mut timings);
        let fragments = match options.count_fragments {
            true => Some(self.count_fragments(gpu, &frame, options)?),
            false => None,
        };
        let mut usage = BatchUsage::default();
        let (srbf_tables, directional_tables) =
            (frame.srbf_tables.take(), frame.directional_tables.take());
        usage.table_bytes = [&srbf_tables, &directional_tables]
            .iter()
            .filter_map(|t| t.as_ref().map(|t| t.bytes))
            .sum();
        let kind_tables = [
            (&kinds.srbf_every_strand, srbf_tables.as_ref()),
            (&kinds.srbf, srbf_tables.as_ref()),
            (&kinds.directional, directional_tables.as_ref()),
            (&kinds.directional_thinned, directional_tables.as_ref()),
        ];
        for (kind_lights, binding) in kind_tables {
            let Some(binding) = binding else { continue };
            let groups = shadow_groups(kind_lights);
            // A batch is shaded in one view: compact sources and region lights apart.
            let sharp = |g: &ShadowGroup| g.lights[0].has_sharp_shadow();
            for run in groups.chunk_by(|a, b| sharp(a) == sharp(b)) {
                for chunk in run.chunks(options.dodm.batch_size as usize) {
                    let batch = LightBatch {
                        groups: chunk,
                        tables: binding,
                    };
                    self.render_batch(gpu, &mut frame, &batch, &request, &mut timings, &mut usage)?;
                }
            }
        }
        memory.push(("env tables".into(), usage.table_bytes));
        memory.push(("forward-scattering grid".into(), usage.grid_bytes));
        Ok(EncodedFrame {
            width,
            height,
            sums: frame.sums.sums,
            with_multiple: multiple.is_some(),
            stats: EnvRenderStats {
                adapter: gpu.report.clone(),
                timings: timings.0,
                memory_per_batch: memory,
                batches: usage.batches,
                lights: lights.len() as u32,
                segments: frame.geometry.segment_count,
                light_pass_segments: frame.light_geometry.segment_count,
                timing_method: crate::render::TIMING_METHOD,
                fragments,
            },
        })
    }

    /// Creates the frame's resources, after checking them against the adapter's limits.
    fn frame_resources(
        &self,
        gpu: &GpuContext,
        request: &FrameRequest<'_>,
        kinds: &LightKinds,
        timings: &mut Timings,
    ) -> Result<FrameResources, EnvRenderError> {
        let FrameRequest {
            model,
            camera,
            width,
            height,
            tables,
            options,
            multiple,
            head,
        } = *request;
        GpuLimits::of(gpu).check_image(width, height)?;
        let occupancy = OccupancyMap::new(gpu, options.transparency, width, height)?;
        check_sums_limits(gpu, width, height)?;
        let geometry = timings.time(gpu, "upload", || StrandGeometry::upload(gpu, model))?;
        // Per hair and settings, not per light or view: setup, as the upload is.
        let (light_geometry, simplified) = timings.time(gpu, "upload", || {
            light_pass_geometry(gpu, model, &geometry, options)
        });
        let bounds = model.bounds();
        let first_layer = options.dodm.first_layer_for(bounds);
        let (mut full_maps, mut simplified_maps) =
            LightMaps::for_frame(gpu, options, kinds, first_layer)?;
        let head_geometry =
            head.map(|h| timings.time(gpu, "upload", || HeadGeometry::upload(gpu, h)));
        if head_geometry.is_some() {
            for maps in [&mut full_maps, &mut simplified_maps].into_iter().flatten() {
                maps.head = Some(HeadDepthMaps::new(
                    gpu,
                    maps.dodm.resolution,
                    maps.dodm.slots,
                ));
            }
        }
        let targets = EnvViewTargets::new(
            gpu,
            width,
            height,
            options.transparency,
            head_geometry.is_some(),
        );
        let sums = self.view.accumulator(gpu, &targets);
        let view_params = FrameParams {
            camera: *camera,
            width,
            height,
            lights: Vec::new(),
            shading: KajiyaKay::default(),
            width_override_px: options.width_override_px,
        };
        check_table_limits(gpu, tables, kinds, multiple.is_some())?;
        let volume = self.volume_buffers(gpu, model, head, options, timings)?;
        let (srbf_tables, directional_tables) = timings.time(gpu, "table upload", || {
            let multiple_table = multiple.and(tables.multiple.as_ref());
            let bind = |needed: bool, t: &Option<Arc<Table>>| {
                t.as_ref()
                    .filter(|_| needed)
                    .map(|t| self.table_binding(gpu, t, multiple_table))
            };
            (
                bind(kinds.has_srbf(), &tables.srbf),
                bind(kinds.has_directional(), &tables.direct),
            )
        });
        let head_views = [&targets.head_position, &targets.head_normal]
            .map(|t| t.create_view(&Default::default()));
        Ok(FrameResources {
            strands: self.view.strands(gpu, &geometry, &view_params),
            view_proj: view_params.view_proj(),
            coverage_view: targets.coverage.create_view(&Default::default()),
            nearest_views: [&targets.nearest_position, &targets.nearest_tangent]
                .map(|t| t.create_view(&Default::default())),
            depth_view: targets.depth.create_view(&Default::default()),
            geometry,
            light_geometry,
            simplified,
            next_window: 0,
            footprint: light_footprint(model, head, bounds, kinds.has_sharp_shadows()),
            full_maps,
            simplified_maps,
            occupancy,
            targets,
            sums,
            srbf_tables,
            directional_tables,
            volume,
            head_views,
            head: head_geometry,
        })
    }

    /// The frame's visibility (depth prepass and coverage, or the occupancy map), once.
    fn encode_visibility(
        &self,
        gpu: &GpuContext,
        frame: &FrameResources,
        options: &EnvRenderOptions,
        camera: &Camera,
        timings: &mut Timings,
    ) {
        timings.time(gpu, "view visibility", || {
            let visibility = frame.visibility(options);
            let view = ViewBinding::new(gpu, &self.view.view_layout, None, &visibility);
            let mut encoder = gpu.device.create_command_encoder(&Default::default());
            // The head first: its depth bounds the hair's passes (and clears the depth).
            self.view.head.encode_view(
                gpu,
                &mut encoder,
                frame.head.as_ref(),
                camera,
                (frame.sums.width, frame.sums.height),
                &frame.depth_view,
                [&frame.head_views[0], &frame.head_views[1]],
            );
            self.view.visibility.encode(
                gpu,
                &mut encoder,
                options.transparency,
                &frame.strands,
                &view.group,
                &frame.depth_view,
                &frame.coverage_view,
                [&frame.nearest_views[0], &frame.nearest_views[1]],
                &frame.occupancy,
                frame.geometry.segment_count,
            );
            gpu.queue.submit([encoder.finish()]);
        });
    }

    /// The fragments one batch's view pass rasterizes and shades (benchmarks).
    fn count_fragments(
        &self,
        gpu: &GpuContext,
        frame: &FrameResources,
        options: &EnvRenderOptions,
    ) -> Result<FragmentCounts, ReadbackError> {
        let visibility = frame.visibility(options);
        let view = ViewBinding::new(gpu, &self.view.view_layout, None, &visibility);
        self.view.visibility.count_fragments(
            gpu,
            options.transparency,
            &frame.strands,
            &view.group,
            &frame.depth_view,
            (frame.sums.width, frame.sums.height),
            frame.geometry.segment_count,
        )
    }

    /// One batch of lights of one kind: its forward-scattering grid, the light pass into the
    /// DODM, the SATs, then the view pass added into the frame's sums.
    fn render_batch(
        &self,
        gpu: &GpuContext,
        frame: &mut FrameResources,
        batch: &LightBatch<'_>,
        request: &FrameRequest<'_>,
        timings: &mut Timings,
        usage: &mut BatchUsage,
    ) -> Result<(), EnvRenderError> {
        let options = request.options;
        usage.batches += 1;
        let grid = match request.multiple {
            Some(source) => {
                let representatives: Vec<_> =
                    batch.groups.iter().map(|g| g.representative()).collect();
                Some(batch_grid(gpu, source, &representatives, timings)?)
            }
            None => None,
        };
        // Unshadowed frames never read the light maps, nor do SRBF lobes that read the
        // visibility volume: skip drawing them.
        let srbf_from_volume = options.lobe_visibility.volume().is_some()
            && batch.first_light().is_some_and(|l| l.lambda.is_some());
        if options.shadowed && !srbf_from_volume {
            self.encode_light_maps(gpu, frame, batch, options, timings);
        }
        let simplified = batch.is_simplified();
        timings.time(gpu, "view", || {
            let maps = frame.maps(simplified);
            let lights = BatchBinding::with_groups(
                gpu,
                &self.view.batch_layout,
                batch.groups,
                &maps.dodm,
                &maps.sat,
                options.shadowed,
                grid.is_some(),
                options.transmittance_filter,
                maps.head.as_ref().filter(|_| !srbf_from_volume),
            );
            let visibility = frame.visibility(options);
            let view = ViewBinding::new(gpu, &self.view.view_layout, grid.as_ref(), &visibility);
            usage.grid_bytes = usage.grid_bytes.max(view.bytes);
            let mut encoder = gpu.device.create_command_encoder(&Default::default());
            let transparency = options.transparency.for_batch(batch.has_sharp_shadows());
            self.view.encode(
                gpu,
                &mut encoder,
                &frame.geometry,
                &frame.strands,
                transparency,
                &lights,
                batch.tables,
                &view,
                &frame.targets,
                &frame.sums,
                frame.head.is_some(),
            );
            gpu.queue.submit([encoder.finish()]);
        });
        Ok(())
    }

    /// The batch's light maps: the light pass into the DODM, then its summed-area tables.
    fn encode_light_maps(
        &self,
        gpu: &GpuContext,
        frame: &mut FrameResources,
        batch: &LightBatch<'_>,
        options: &EnvRenderOptions,
        timings: &mut Timings,
    ) {
        let simplified = batch.is_simplified();
        let directions: Vec<_> = batch.groups.iter().map(|g| g.direction).collect();
        let windows = match simplified {
            true => frame.next_windows(directions.len(), options.kappa),
            false => vec![vec![0..frame.geometry.segment_count]; directions.len()],
        };
        // A simplified map draws 1/κ-times the optical depth of each drawn fiber, enlarged to
        // the same world width at whatever resolution its maps have.
        let (tau_scale, enlargement) = match simplified {
            true => (
                1.0 / options.kappa,
                options.dodm.simplified_enlargement(options.kappa),
            ),
            false => (1.0, 1.0),
        };
        let FrameResources {
            geometry,
            light_geometry,
            footprint,
            full_maps,
            simplified_maps,
            head,
            ..
        } = frame;
        let geometry = if simplified { light_geometry } else { geometry };
        let maps = LightMaps::choose(simplified, full_maps, simplified_maps);
        let framing = match batch.has_sharp_shadows() {
            true => LightFraming::Fitted(footprint),
            false => LightFraming::Sphere(footprint.bounds),
        };
        timings.time(gpu, "light pass", || {
            let mut encoder = gpu.device.create_command_encoder(&Default::default());
            self.depth.encode_windows(
                gpu,
                &mut encoder,
                geometry,
                &directions,
                &windows,
                framing,
                [tau_scale, enlargement],
                &mut maps.dodm,
            );
            if let (Some(head), Some(head_maps)) = (head.as_ref(), maps.head.as_ref()) {
                self.view.head.encode_light_depths(
                    gpu,
                    &mut encoder,
                    head,
                    &maps.dodm.cameras,
                    head_maps,
                );
            }
            gpu.queue.submit([encoder.finish()]);
        });
        timings.time(gpu, "summed-area tables", || {
            let mut encoder = gpu.device.create_command_encoder(&Default::default());
            self.sat
                .encode(gpu, &mut encoder, &maps.dodm.optical_depth, &maps.sat);
            gpu.queue.submit([encoder.finish()]);
        });
    }
}

/// What a compact source's map must hold: the hair, and the head whose skin it shadows and
/// which shadows the hair (outside a map a point reads as lit). Without compact sources no map
/// is fitted, and the points are not copied.
fn light_footprint(
    model: &HairModel,
    head: Option<&Head>,
    bounds: Aabb,
    has_compact_sources: bool,
) -> LightFootprint {
    if !has_compact_sources {
        return LightFootprint::new(bounds, Vec::new().into());
    }
    let mut points = model.points().to_vec();
    if let Some(head) = head {
        points.extend_from_slice(&head.triangles().positions);
    }
    LightFootprint::new(bounds, points.into())
}

/// One batch: lights of one kind (at most the batch size of shadow groups) and their kind's
/// tables.
struct LightBatch<'a> {
    groups: &'a [ShadowGroup<'a>],
    tables: &'a TableBinding,
}

impl LightBatch<'_> {
    /// A batch holds one kind of light: its first tells the kind.
    fn first_light(&self) -> Option<&EnvLight> {
        self.groups.first().map(|g| &g.lights[0])
    }

    /// Whether this batch's lights are compact sources, whose shadows are sharp at fiber scale
    /// (a batch holds lights of one view: [`EnvLight::has_sharp_shadow`]).
    fn has_sharp_shadows(&self) -> bool {
        self.first_light().is_some_and(EnvLight::has_sharp_shadow)
    }

    /// Whether stochastic simplification thins this batch's maps.
    fn is_simplified(&self) -> bool {
        self.first_light().is_some_and(|l| l.is_simplified())
    }
}

/// Counts over the batches, for the stats.
#[derive(Default)]
struct BatchUsage {
    batches: u32,
    table_bytes: u64,
    grid_bytes: u64,
}

/// The forward-scattering grid of one batch, checked.
fn batch_grid(
    gpu: &GpuContext,
    source: &dyn ForwardScatteringSource,
    lights: &[EnvLight],
    timings: &mut Timings,
) -> Result<ForwardScatteringGrid, EnvRenderError> {
    let pass = format!("multiple grid ({})", source.device());
    let grid = timings
        .time(gpu, &pass, || source.grid(lights))
        .map_err(|e| EnvRenderError::Grid(e.to_string()))?;
    check_grid(&grid, lights.len())?;
    Ok(grid)
}

/// The readback of the sums split into (single + multiple, single, multiple).
#[allow(clippy::type_complexity)]
fn split_sums(
    bytes: &[u8],
    width: u32,
    height: u32,
    with_multiple: bool,
) -> (Vec<[f32; 4]>, Vec<[f32; 4]>, Option<Vec<[f32; 4]>>) {
    let all: &[[f32; 4]] = bytemuck::cast_slice(bytes);
    let n = width as usize * height as usize;
    let single_pixels = all[..n].to_vec();
    let multiple_pixels = with_multiple.then(|| all[n..2 * n].to_vec());
    let pixels = match &multiple_pixels {
        None => single_pixels.clone(),
        Some(m) => single_pixels
            .iter()
            .zip(m)
            .map(|(s, m)| [s[0] + m[0], s[1] + m[1], s[2] + m[2], s[3]])
            .collect(),
    };
    (pixels, single_pixels, multiple_pixels)
}

/// [`EnvRenderer::render`] with pipelines built for this one frame.
#[allow(clippy::too_many_arguments)]
pub fn render_env_frame(
    gpu: &GpuContext,
    model: &HairModel,
    camera: &Camera,
    width: u32,
    height: u32,
    lights: &[EnvLight],
    tables: &EnvTables,
    options: &EnvRenderOptions,
    multiple: Option<&dyn ForwardScatteringSource>,
) -> Result<EnvFrame, EnvRenderError> {
    let mut timings = Timings(Vec::new());
    let renderer = timings.time(gpu, "pipelines", || EnvRenderer::new(gpu));
    let mut frame = renderer.render(
        gpu, model, camera, width, height, lights, tables, options, multiple,
    )?;
    frame.stats.timings.splice(0..0, timings.0);
    Ok(frame)
}
