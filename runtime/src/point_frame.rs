//! One headless frame end to end: upload, strand pass, readback, with per-pass timings and the
//! GPU memory each buffer and texture holds.

use crate::gpu::readback::ReadbackError;
use crate::gpu::{AdapterReport, GpuContext, GpuLimits, LimitError, read_texture_rgba};
use crate::hair::HairModel;
use crate::head::Head;
use crate::passes::abuffer::{ABufferError, ABufferPass, ABufferResources, ListMode};
use crate::passes::attachments::cleared_depth;
use crate::passes::deep_opacity::{
    DeepOpacityMap, DeepOpacityPass, DomSettings, DomSettingsError, ShadowLookup, ShadowMapError,
    array_layers_for,
};
use crate::passes::fiber_shading::ShadingModel;
use crate::passes::frame_params::FrameParams;
use crate::passes::kbuffer::{KBufferError, KBufferOnGpu, KBufferPass};
use crate::passes::point_skin::{PointHead, PointSkinPass, composite_over};
use crate::passes::random_subsets::{RandomSubsetsPass, SubsetsError, SubsetsOnGpu};
use crate::passes::render_target::RenderTarget;
use crate::passes::shadow_slots::{HeadInput, MAX_SHADOWED_LIGHTS, ShadowInput, TooManyShadowMaps};
use crate::passes::sorted_blend::{BadSortBins, SortedBlendPass};
use crate::passes::strand_geometry::{StrandGeometry, TooManyPoints};
use crate::passes::strands::{StrandDepthPass, StrandPass};
use crate::shadow_layout::{PointLayoutChoice, ShadowLayout};

#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    #[error(transparent)]
    Limit(#[from] LimitError),
    #[error(transparent)]
    TooManyPoints(#[from] TooManyPoints),
    #[error(transparent)]
    DomSettings(#[from] DomSettingsError),
    #[error(transparent)]
    ShadowMap(#[from] ShadowMapError),
    #[error("shadows were asked for but the frame has no light")]
    NoLight,
    #[error(transparent)]
    TooManyShadowMaps(#[from] TooManyShadowMaps),
    #[error(transparent)]
    Readback(#[from] ReadbackError),
    #[error("the GPU reported an error: {0}")]
    Gpu(String),
    #[error(transparent)]
    SortBins(#[from] BadSortBins),
    #[error("{0}")]
    Settings(String),
    #[error("A-buffer nodes per pixel 0: must be at least 1 (or left unset to size the pool)")]
    NoListNodes,
    #[error("a {}x{} frame cannot be drawn into sums of {}x{}", frame[0], frame[1], sums[0], sums[1])]
    SumsSize { sums: [u32; 2], frame: [u32; 2] },
}

/// The time one pass took.
#[derive(Clone, Debug, PartialEq)]
pub struct PassTiming {
    pub pass: String,
    /// Wall clock around recording, submit and wait-for-idle.
    pub milliseconds: f64,
    /// The GPU's own time for the pass's render and compute passes, from timestamp queries;
    /// `None` where the adapter lacks them or the pass recorded none (CPU-only work).
    pub gpu_milliseconds: Option<f64>,
}

impl PassTiming {
    /// Adds `self` to the entry of the same pass in `totals` (appending a new one). A GPU
    /// total stays known only while every addend had one: a partial sum would understate.
    pub fn add_to(self, totals: &mut Vec<PassTiming>) {
        match totals.iter_mut().find(|t| t.pass == self.pass) {
            Some(t) => {
                t.milliseconds += self.milliseconds;
                t.gpu_milliseconds = t
                    .gpu_milliseconds
                    .zip(self.gpu_milliseconds)
                    .map(|(a, b)| a + b);
            }
            None => totals.push(self),
        }
    }
}

/// How [`PassTiming`]s are measured, for reports.
pub const TIMING_METHOD: &str = "wall clock around submit + wait for idle; GPU time from \
                                 timestamp queries where the adapter has them";

#[derive(Clone, Debug)]
pub struct RenderStats {
    pub adapter: AdapterReport,
    pub timings: Vec<PassTiming>,
    pub memory_bytes: Vec<(String, u64)>,
    pub segments: u32,
    pub timing_method: &'static str,
    /// A-buffer only: fragments stored, dropped for a full node buffer, truncated at resolve.
    pub fragments: Option<FragmentCounts>,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FragmentCounts {
    pub stored: u64,
    /// Fragments that found the node pool full (overflow): missing from the image.
    pub dropped: u64,
    pub truncated: u64,
    /// Nodes in the pool: the requested count clamped to the adapter's storage limits.
    pub capacity: u64,
    /// Nodes asked for (`nodes_per_pixel` × pixels).
    pub requested_capacity: u64,
}

impl From<KBufferError> for RenderError {
    fn from(e: KBufferError) -> Self {
        match e {
            KBufferError::TooManyShadowMaps(e) => Self::TooManyShadowMaps(e),
            KBufferError::Readback(e) => Self::Readback(e),
            KBufferError::Limit(e) => Self::Limit(e),
            KBufferError::K(_) => Self::Settings(e.to_string()),
        }
    }
}

impl From<SubsetsError> for RenderError {
    fn from(e: SubsetsError) -> Self {
        match e {
            SubsetsError::TooManyShadowMaps(e) => Self::TooManyShadowMaps(e),
            SubsetsError::Readback(e) => Self::Readback(e),
            SubsetsError::Limit(e) => Self::Limit(e),
            SubsetsError::Count(_) => Self::Settings(e.to_string()),
        }
    }
}

impl From<ABufferError> for RenderError {
    fn from(e: ABufferError) -> Self {
        match e {
            ABufferError::TooManyShadowMaps(e) => Self::TooManyShadowMaps(e),
            ABufferError::Readback(e) => Self::Readback(e),
            ABufferError::Limit(e) => Self::Limit(e),
            ABufferError::SizeMismatch { .. } => Self::Gpu(e.to_string()),
        }
    }
}

/// The image and the deep opacity maps against the adapter's limits, before anything is
/// created (the A-buffer checks its own buffers: [`ABufferResources`]).
///
/// [`ABufferResources`]: crate::passes::abuffer::ABufferResources
fn check_frame_limits(
    gpu: &GpuContext,
    frame: &FrameParams,
    shadowed_lights: &[ShadowedLight],
) -> Result<(), LimitError> {
    let limits = GpuLimits::of(gpu);
    limits.check_image(frame.width, frame.height)?;
    // Every light's map has the same settings.
    if let Some(first) = shadowed_lights.first() {
        let res = first.maps.resolution();
        limits.check_texture_2d("light map", res, res, |max| {
            format!("use a shadow map resolution of at most {max}")
        })?;
    }
    for light in shadowed_lights {
        check_layout_layers(&limits, &light.maps, &light.layout)?;
    }
    Ok(())
}

/// A light's layer texture holds its faces' layers in one array: a cube's six faces of deep
/// opacity layers (or opacity slices) may pass the adapter's `max_texture_array_layers`.
pub fn check_layout_layers(
    limits: &GpuLimits,
    maps: &ShadowMaps,
    layout: &ShadowLayout,
) -> Result<(), LimitError> {
    let layers = maps.layers();
    let faces = layout.face_count();
    limits.check_texture_layers(
        "light map layers",
        faces * array_layers_for(layers),
        |max| {
            let per_face = max / faces / 2 * LAYERS_PER_ARRAY_PAIR;
            let what = if faces > 1 {
                format!("a cube's {faces} faces of")
            } else {
                "the".to_string()
            };
            format!(
                "{what} {layers} layers do not fit: use at most {per_face} DOM layers or OSM \
                 slices (array layers hold 4 each, in pairs), or a light farther from the hair"
            )
        },
    )
}

/// Optical depth layers in the two RGBA array layers one layer pass fills.
const LAYERS_PER_ARRAY_PAIR: u32 = 8;

/// A light that gets maps: its maps' settings, its index in the frame, and where they look from.
struct ShadowedLight {
    maps: ShadowMaps,
    index: u32,
    layout: ShadowLayout,
}

/// How overlapping fibers combine.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Transparency {
    /// Depth-tested, coverage blended in draw order (plain opaque rendering).
    #[default]
    Opaque,
    /// Segments bin-sorted back to front by a compute counting sort into `bins` depth bins,
    /// then blended in that order without a depth test.
    Sorted { bins: u32 },
    /// The `k` nearest fragments per pixel composited; the rest dropped and counted.
    KBuffer { k: u32 },
    /// Strands split at random into `subsets` subsets, each drawn depth-tested into its own
    /// layer; per pixel the layers' fragments sorted and composited.
    RandomSubsets { subsets: u32 },
    /// Per-pixel linked lists sorted at resolve. The node pool holds `nodes_per_pixel` ×
    /// pixels nodes, or with `None` exactly the fragments stored (counted by a first build);
    /// either way clamped to the adapter's storage-binding limit, with overflow counted.
    ABuffer { nodes_per_pixel: Option<u32> },
    /// DBK-buffer: lists for fragments within `delta` (world units of view depth) behind each
    /// pixel's nearest fiber, an opaque fallback for the rest. Pool as for the A-buffer.
    Dbk {
        nodes_per_pixel: Option<u32>,
        delta: f32,
    },
}

/// How lights are shadowed. Deep opacity and opacity shadow maps are layers of optical depth
/// along the light, looked up the same way, differing in where the layers start; shadow maps
/// and ADSM keep only the nearest fiber's depth. Directional lights get an orthographic map,
/// point and spot lights a perspective one, or a cube of six where one cannot hold the hair
/// ([`ShadowLayout`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ShadowMaps {
    /// Deep opacity maps (Yuksel & Keyser 2008): layers from each texel's nearest fiber, read
    /// through `pcf`×`pcf` PCF.
    Deep { settings: DomSettings, pcf: u32 },
    /// Opacity shadow maps (Kim & Neumann 2001): `slices` equal slices spanning the hair's
    /// depth range along the light, the same for every texel, read through `pcf`×`pcf` PCF.
    OpacitySlices {
        resolution: u32,
        slices: u32,
        pcf: u32,
    },
    /// Shadow maps with PCF or ADSM ([`ShadowLookup::Hard`], [`ShadowLookup::Adsm`]).
    Depth {
        resolution: u32,
        lookup: ShadowLookup,
    },
}

impl ShadowMaps {
    pub fn resolution(&self) -> u32 {
        match *self {
            ShadowMaps::Deep { settings, .. } => settings.resolution,
            ShadowMaps::OpacitySlices { resolution, .. } => resolution,
            ShadowMaps::Depth { resolution, .. } => resolution,
        }
    }

    fn check(&self) -> Result<(), ShadowMapError> {
        match *self {
            ShadowMaps::Deep { settings, pcf } => {
                settings.check()?;
                ShadowLookup::Layers { kernel: pcf }.check()?;
            }
            ShadowMaps::OpacitySlices {
                resolution,
                slices,
                pcf,
            } => {
                DomSettings {
                    resolution,
                    layers: slices,
                    spacing: 1.0,
                }
                .check()?;
                ShadowLookup::Layers { kernel: pcf }.check()?;
            }
            ShadowMaps::Depth { resolution, lookup } => {
                DomSettings {
                    resolution,
                    layers: 1,
                    spacing: 1.0,
                }
                .check()?;
                lookup.check()?;
            }
        }
        Ok(())
    }

    /// The name of the pass that draws one light's map, in timings.
    pub fn pass_name(&self) -> &'static str {
        match self {
            ShadowMaps::Deep { .. } => "deep opacity",
            ShadowMaps::OpacitySlices { .. } => "opacity shadow",
            ShadowMaps::Depth {
                lookup: ShadowLookup::Adsm { .. },
                ..
            } => "adsm depth",
            ShadowMaps::Depth { .. } => "shadow map",
        }
    }

    /// Optical depth layers per face (1 for depth-only maps, whose layer texture is a
    /// placeholder).
    pub fn layers(&self) -> u32 {
        match *self {
            ShadowMaps::Deep { settings, .. } => settings.layers,
            ShadowMaps::OpacitySlices { slices, .. } => slices,
            ShadowMaps::Depth { .. } => 1,
        }
    }

    /// The map of a light shining onto hair within `bounds`, seen through `layout`.
    fn map_for(
        &self,
        gpu: &GpuContext,
        layout: ShadowLayout,
        bounds: crate::hair::Aabb,
    ) -> Result<DeepOpacityMap, ShadowMapError> {
        Ok(match *self {
            ShadowMaps::Deep { settings, pcf } => {
                DeepOpacityMap::new(gpu, layout, settings).with_layer_pcf(pcf)?
            }
            ShadowMaps::OpacitySlices {
                resolution,
                slices,
                pcf,
            } => DeepOpacityMap::opacity_slices(gpu, layout, bounds, resolution, slices)?
                .with_layer_pcf(pcf)?,
            ShadowMaps::Depth { resolution, lookup } => {
                DeepOpacityMap::depth_only(gpu, layout, resolution, lookup)?
            }
        })
    }
}

/// Everything besides the frame that changes how it is rendered.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RenderOptions {
    /// Light maps for every light (at most [`MAX_SHADOWED_LIGHTS`]), used by every
    /// transparency mode.
    pub shadows: Option<ShadowMaps>,
    pub transparency: Transparency,
    /// Point and spot lights: one frustum where it holds the hair (the default), or always a
    /// cube ([`ShadowLayout`]).
    pub point_layout: PointLayoutChoice,
}

/// A point-lit frame: linear, pre-multiplied RGBA, row-major from the top, and its stats (the
/// env-lit frame's is [`crate::env::EnvImage`]).
pub struct PointImage {
    pub width: u32,
    pub height: u32,
    /// Linear, pre-multiplied RGBA, row-major from the top.
    pub pixels: Vec<[f32; 4]>,
    pub stats: RenderStats,
}

fn timed<T>(
    timings: &mut Vec<PassTiming>,
    gpu: &GpuContext,
    pass: &str,
    work: impl FnOnce() -> T,
) -> T {
    let (out, milliseconds, gpu_milliseconds) = gpu.time_passes(work);
    timings.push(PassTiming {
        pass: pass.to_string(),
        milliseconds,
        gpu_milliseconds,
    });
    out
}

/// Renders `model` with `frame` and reads the picture back. With `shadows`, every light is
/// shadowed through its own map.
pub fn render_frame(
    gpu: &GpuContext,
    model: &HairModel,
    frame: &FrameParams,
    options: &RenderOptions,
) -> Result<PointImage, RenderError> {
    render_frame_with_model(gpu, model, frame, options, &ShadingModel::KajiyaKay)
}

/// [`render_frame`] shading the fibers with `shading` (Kajiya-Kay takes its constants from
/// `frame.shading`), in any [`Transparency`] mode.
pub fn render_frame_with_model(
    gpu: &GpuContext,
    model: &HairModel,
    frame: &FrameParams,
    options: &RenderOptions,
    shading: &ShadingModel,
) -> Result<PointImage, RenderError> {
    render_frame_with_head(gpu, model, frame, options, shading, None)
}

/// [`render_frame_with_model`] with the head the hair grows from (issue 40): opaque in every
/// light's maps and in the view, where it hides the fibers behind it, and drawn as Lambertian
/// skin of the head's albedo under the same lights, the remaining fibers composited over it.
pub fn render_frame_with_head(
    gpu: &GpuContext,
    model: &HairModel,
    frame: &FrameParams,
    options: &RenderOptions,
    shading: &ShadingModel,
    head: Option<&Head>,
) -> Result<PointImage, RenderError> {
    let scope = gpu.device.push_error_scope(wgpu::ErrorFilter::Validation);
    let drawn = submit_frame(gpu, model, frame, options, shading, head, None);
    let read = drawn.and_then(|drawn| drawn.read(gpu, frame));
    if let Some(error) = pollster::block_on(scope.pop()) {
        return Err(RenderError::Gpu(error.to_string()));
    }
    read
}

/// A point-lit frame drawn and left on the GPU ([`submit_frame`]): the hair composited by its
/// technique, the skin under it, and what the frame cost so far.
pub(crate) struct PointFrameOnGpu {
    pub hair: HairColour,
    /// The head's skin, pre-multiplied, alpha 1 on the head (the hair composites over it).
    pub skin: Option<RenderTarget>,
    costs: Costs,
    segments: u32,
}

/// Where a technique left the hair's composited colour (pre-multiplied RGBA, row-major from
/// the top): a target's texture or a storage buffer of f32 RGBA per pixel.
pub(crate) enum HairColour {
    /// The opaque and sorted techniques' target.
    Target(RenderTarget),
    KBuffer {
        out: KBufferOnGpu,
        slots: u64,
    },
    Subsets(SubsetsOnGpu),
    /// The A-buffer's and DBK's lists, with the node pool's size and the nodes asked for.
    Lists {
        resources: Box<ABufferResources>,
        capacity: u32,
        wanted: u64,
    },
}

/// The hair's colour on the GPU, as [`HairColour`] holds it.
pub(crate) enum ColourOnGpu<'a> {
    Texture(&'a wgpu::Texture),
    Buffer(&'a wgpu::Buffer),
}

impl HairColour {
    pub fn on_gpu(&self) -> ColourOnGpu<'_> {
        match self {
            HairColour::Target(target) => ColourOnGpu::Texture(&target.color),
            HairColour::KBuffer { out, .. } => ColourOnGpu::Buffer(&out.resolved),
            HairColour::Subsets(out) => ColourOnGpu::Buffer(&out.resolved),
            HairColour::Lists { resources, .. } => ColourOnGpu::Buffer(resources.resolved()),
        }
    }

    /// The pixels and, for the techniques that count them, the fragments kept and dropped.
    fn read(
        self,
        gpu: &GpuContext,
    ) -> Result<(Vec<[f32; 4]>, Option<FragmentCounts>), RenderError> {
        Ok(match self {
            HairColour::Target(target) => (read_texture_rgba(gpu, &target.color)?, None),
            HairColour::KBuffer { out, slots } => {
                let out = out.read(gpu)?;
                let counts = FragmentCounts {
                    stored: out.fragments_kept,
                    dropped: out.fragments_dropped,
                    truncated: 0,
                    capacity: slots,
                    requested_capacity: slots,
                };
                (out.pixels, Some(counts))
            }
            HairColour::Subsets(out) => (out.read(gpu)?.pixels, None),
            HairColour::Lists {
                resources,
                capacity,
                wanted,
            } => {
                let out = resources.read(gpu)?;
                let counts = FragmentCounts {
                    stored: out.fragments_stored,
                    dropped: out.fragments_dropped,
                    truncated: out.fragments_truncated,
                    capacity: capacity as u64,
                    requested_capacity: wanted,
                };
                (out.pixels, Some(counts))
            }
        })
    }
}

impl PointFrameOnGpu {
    /// The frame's costs so far, without reading it back (no fragment counts).
    pub(crate) fn stats(&self, gpu: &GpuContext) -> RenderStats {
        RenderStats {
            adapter: gpu.report.clone(),
            timings: self.costs.timings.clone(),
            memory_bytes: self.costs.memory_bytes.clone(),
            segments: self.segments,
            timing_method: TIMING_METHOD,
            fragments: None,
        }
    }

    /// The frame read back: the hair over the skin, with its costs (waits for the GPU).
    fn read(self, gpu: &GpuContext, frame: &FrameParams) -> Result<PointImage, RenderError> {
        let mut costs = self.costs;
        let (mut pixels, fragments) =
            timed(&mut costs.timings, gpu, "readback", || self.hair.read(gpu))?;
        if let Some(skin) = &self.skin {
            let skin = timed(&mut costs.timings, gpu, "skin readback", || {
                read_texture_rgba(gpu, &skin.color)
            })?;
            composite_over(&mut pixels, &skin);
        }
        Ok(PointImage {
            width: frame.width,
            height: frame.height,
            pixels,
            stats: RenderStats {
                adapter: gpu.report.clone(),
                timings: costs.timings,
                memory_bytes: costs.memory_bytes,
                segments: self.segments,
                timing_method: TIMING_METHOD,
                fragments,
            },
        })
    }
}

/// Draws the point-lit frame and submits it without reading anything back: the light maps, the
/// head's depth and skin, and the hair by its technique. With `front_depth` (a
/// [`DEPTH_FORMAT`](crate::passes::render_target::DEPTH_FORMAT) texture of the frame's size)
/// it also draws there the nearest of head and fiber per pixel, what a host's depth test
/// compares. One exception to "nothing read back": the A-buffer and DBK without a node count
/// count their fragments first, to size the pool.
pub(crate) fn submit_frame(
    gpu: &GpuContext,
    model: &HairModel,
    frame: &FrameParams,
    options: &RenderOptions,
    shading: &ShadingModel,
    head: Option<&Head>,
    front_depth: Option<&wgpu::Texture>,
) -> Result<PointFrameOnGpu, RenderError> {
    let shadowed_lights = shadowed_lights(model, frame, options, head)?;
    check_frame_limits(gpu, frame, &shadowed_lights)?;
    let mut costs = Costs::default();
    let geometry = timed(&mut costs.timings, gpu, "upload", || {
        StrandGeometry::upload(gpu, model)
    })?;
    costs.memory_bytes = geometry.memory();
    let shadow_maps = draw_light_maps(gpu, model, &geometry, &shadowed_lights, &mut costs)?;
    let shadows: Vec<ShadowInput> = shadow_maps
        .iter()
        .map(|(map, light_index)| ShadowInput {
            map,
            light_index: *light_index,
        })
        .collect();
    let head = head.map(|head| {
        let Costs {
            timings,
            memory_bytes,
        } = &mut costs;
        prepare_head(gpu, head, frame, &shadows, timings, memory_bytes)
    });
    let hair = HairDraw {
        gpu,
        model,
        geometry: &geometry,
        frame,
        shading,
        shadows: &shadows,
        head: head.as_ref().map(|(_, head)| head.input()),
    };
    let colour = hair.draw(options.transparency, &mut costs)?;
    if let Some(depth) = front_depth {
        let timings = &mut costs.timings;
        timed(timings, gpu, "front depth", || hair.front_depth(depth))?;
    }
    let skin = match &head {
        Some((pass, head)) => Some(timed(&mut costs.timings, gpu, "skin", || {
            pass.shade(gpu, &geometry, frame, &shadows, head)
        })?),
        None => None,
    };
    Ok(PointFrameOnGpu {
        hair: colour,
        skin,
        costs,
        segments: geometry.segment_count,
    })
}

/// Every light with its map's layout (every pass shadows them all), checked; none without
/// shadows.
fn shadowed_lights(
    model: &HairModel,
    frame: &FrameParams,
    options: &RenderOptions,
    head: Option<&Head>,
) -> Result<Vec<ShadowedLight>, RenderError> {
    let Some(settings) = options.shadows else {
        return Ok(Vec::new());
    };
    settings.check()?;
    if frame.lights.is_empty() {
        return Err(RenderError::NoLight);
    }
    if frame.lights.len() > MAX_SHADOWED_LIGHTS {
        return Err(RenderError::TooManyShadowMaps(TooManyShadowMaps {
            maps: frame.lights.len(),
        }));
    }
    let bounds = caster_bounds(model, head);
    (0..)
        .zip(&frame.lights)
        .map(|(index, light)| {
            let layout = ShadowLayout::for_light(light, bounds, options.point_layout)
                .map_err(ShadowMapError::from)?;
            Ok(ShadowedLight {
                maps: settings,
                index,
                layout,
            })
        })
        .collect()
}

/// Each shadowed light's map, drawn, with its light's index.
fn draw_light_maps(
    gpu: &GpuContext,
    model: &HairModel,
    geometry: &StrandGeometry,
    shadowed_lights: &[ShadowedLight],
    costs: &mut Costs,
) -> Result<Vec<(DeepOpacityMap, u32)>, RenderError> {
    if shadowed_lights.is_empty() {
        return Ok(Vec::new());
    }
    let dom_pass = timed(&mut costs.timings, gpu, "light map pipeline", || {
        DeepOpacityPass::new(gpu)
    });
    let mut shadow_maps = Vec::new();
    for &ShadowedLight {
        maps,
        index,
        layout,
    } in shadowed_lights
    {
        let map = maps.map_for(gpu, layout, model.bounds())?;
        // One entry per light, so that reports keyed by pass name keep them all; a cube's
        // says so, since it costs up to six maps.
        let cube = if layout.is_cube() { ", cube" } else { "" };
        let label = format!("{} (light {index}{cube})", maps.pass_name());
        timed(&mut costs.timings, gpu, &label, || {
            dom_pass.draw(gpu, geometry, &map)
        });
        costs.memory_bytes.extend(map.memory());
        shadow_maps.push((map, index));
    }
    Ok(shadow_maps)
}

/// Time per pass and memory per resource, gathered over a frame's passes.
#[derive(Default)]
struct Costs {
    timings: Vec<PassTiming>,
    memory_bytes: Vec<(String, u64)>,
}

/// What every transparency mode draws the hair with.
struct HairDraw<'a> {
    gpu: &'a GpuContext,
    model: &'a HairModel,
    geometry: &'a StrandGeometry,
    frame: &'a FrameParams,
    shading: &'a ShadingModel,
    shadows: &'a [ShadowInput<'a>],
    head: Option<HeadInput<'a>>,
}

impl HairDraw<'_> {
    /// The hair under `transparency`, submitted: its colour stays where the technique left it.
    fn draw(
        &self,
        transparency: Transparency,
        costs: &mut Costs,
    ) -> Result<HairColour, RenderError> {
        match transparency {
            Transparency::Opaque => self.opaque(costs),
            Transparency::Sorted { bins } => self.sorted(bins, costs),
            Transparency::KBuffer { k } => self.kbuffer(k, costs),
            Transparency::RandomSubsets { subsets } => self.subsets(subsets, costs),
            Transparency::ABuffer { nodes_per_pixel } => {
                self.lists(nodes_per_pixel, ListMode::All, costs)
            }
            Transparency::Dbk {
                nodes_per_pixel,
                delta,
            } => self.lists(nodes_per_pixel, ListMode::Dbk { delta }, costs),
        }
    }

    /// The nearest of the head (its view depth) and the fibers per pixel, into `depth`.
    fn front_depth(&self, depth: &wgpu::Texture) -> Result<(), RenderError> {
        let gpu = self.gpu;
        let pass = StrandDepthPass::with_model(gpu, self.shading);
        let view = depth.create_view(&Default::default());
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        match &self.head {
            Some(head) => encoder.copy_texture_to_texture(
                head.view_depth.as_image_copy(),
                depth.as_image_copy(),
                depth.size(),
            ),
            None => {
                encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("front depth cleared"),
                    depth_stencil_attachment: cleared_depth(&view, true),
                    ..Default::default()
                });
            }
        }
        pass.encode(
            gpu,
            &mut encoder,
            self.geometry,
            self.frame,
            self.shadows,
            self.head,
            &view,
        )?;
        gpu.queue.submit([encoder.finish()]);
        Ok(())
    }

    fn opaque(&self, costs: &mut Costs) -> Result<HairColour, RenderError> {
        let (gpu, frame, timings) = (self.gpu, self.frame, &mut costs.timings);
        let pass = timed(timings, gpu, "strand pipeline", || {
            StrandPass::with_model(gpu, self.shading)
        });
        let target = RenderTarget::new(gpu, frame.width, frame.height);
        timed(timings, gpu, "strands", || {
            pass.draw_shadowed(gpu, self.geometry, frame, &target, self.shadows, self.head)
        })?;
        costs.memory_bytes.extend(target.memory());
        Ok(HairColour::Target(target))
    }

    fn sorted(&self, bins: u32, costs: &mut Costs) -> Result<HairColour, RenderError> {
        let (gpu, frame, geometry, timings) =
            (self.gpu, self.frame, self.geometry, &mut costs.timings);
        let pass = timed(timings, gpu, "sorted blend pipeline", || {
            SortedBlendPass::with_model(gpu, self.shading)
        });
        let order = timed(timings, gpu, "segment sort", || {
            pass.sort(gpu, geometry, frame, self.model.bounds(), bins)
        })?;
        let target = RenderTarget::new(gpu, frame.width, frame.height);
        timed(timings, gpu, "sorted blend", || {
            pass.draw(
                gpu,
                geometry,
                frame,
                self.shadows,
                self.head,
                &order,
                &target,
            )
        })?;
        costs.memory_bytes.extend(order.memory());
        costs.memory_bytes.extend(target.memory());
        Ok(HairColour::Target(target))
    }

    fn kbuffer(&self, k: u32, costs: &mut Costs) -> Result<HairColour, RenderError> {
        let (gpu, frame, timings) = (self.gpu, self.frame, &mut costs.timings);
        let pass = timed(timings, gpu, "kbuffer pipeline", || {
            KBufferPass::with_model(gpu, self.shading)
        });
        let out = timed(timings, gpu, "kbuffer build + resolve", || {
            pass.submit(gpu, self.geometry, frame, self.shadows, self.head, k)
        })?;
        costs.memory_bytes.extend(out.memory_bytes.iter().cloned());
        let slots = frame.width as u64 * frame.height as u64 * k as u64;
        Ok(HairColour::KBuffer { out, slots })
    }

    fn subsets(&self, subsets: u32, costs: &mut Costs) -> Result<HairColour, RenderError> {
        let (gpu, timings) = (self.gpu, &mut costs.timings);
        let pass = timed(timings, gpu, "random subsets pipeline", || {
            RandomSubsetsPass::with_model(gpu, self.shading)
        });
        let out = timed(timings, gpu, "random subsets + resolve", || {
            let (model, geometry, frame) = (self.model, self.geometry, self.frame);
            pass.submit(
                gpu,
                model,
                geometry,
                frame,
                self.shadows,
                self.head,
                subsets,
            )
        })?;
        costs.memory_bytes.extend(out.memory_bytes.iter().cloned());
        Ok(HairColour::Subsets(out))
    }

    /// The A-buffer's or the DBK-buffer's per-pixel lists.
    fn lists(
        &self,
        nodes_per_pixel: Option<u32>,
        list_mode: ListMode,
        costs: &mut Costs,
    ) -> Result<HairColour, RenderError> {
        let (gpu, frame, geometry, timings) =
            (self.gpu, self.frame, self.geometry, &mut costs.timings);
        let (shadows, head) = (self.shadows, self.head);
        let abuffer = timed(timings, gpu, "abuffer pipeline", || {
            ABufferPass::with_model(gpu, self.shading)
        });
        let wanted = match nodes_per_pixel {
            Some(0) => return Err(RenderError::NoListNodes),
            Some(n) => frame.width as u64 * frame.height as u64 * n as u64,
            None => timed(timings, gpu, "abuffer count", || {
                abuffer.count_fragments(gpu, geometry, frame, shadows, head, list_mode)
            })?
            .max(1),
        };
        let capacity = ABufferPass::max_capacity(gpu, wanted);
        let resources = timed(timings, gpu, "abuffer build + resolve", || {
            let size = (frame.width, frame.height);
            let resources = ABufferResources::new(gpu, &abuffer, size, capacity, list_mode)?;
            abuffer.submit_into(gpu, &resources, geometry, frame, shadows, head)?;
            Ok::<_, ABufferError>(resources)
        })?;
        costs.memory_bytes.extend(resources.memory());
        Ok(HairColour::Lists {
            resources: Box::new(resources),
            capacity,
            wanted,
        })
    }
}

/// What the light maps must hold: the hair, and the head, which casts too (a frustum fitted to
/// the hair alone would clip a head reaching past it, and nothing would stop the light there).
fn caster_bounds(model: &HairModel, head: Option<&Head>) -> crate::hair::Aabb {
    let hair = model.bounds();
    match head {
        Some(head) => {
            let head = head.bounds();
            crate::hair::Aabb {
                min: hair.min.min(head.min),
                max: hair.max.max(head.max),
            }
        }
        None => hair,
    }
}

/// The head's pipelines, its upload and its depth in every light face and in the view.
fn prepare_head(
    gpu: &GpuContext,
    head: &Head,
    frame: &FrameParams,
    shadows: &[ShadowInput<'_>],
    timings: &mut Vec<PassTiming>,
    memory_bytes: &mut Vec<(String, u64)>,
) -> (PointSkinPass, PointHead) {
    let pass = timed(timings, gpu, "head pipelines", || PointSkinPass::new(gpu));
    let prepared = timed(timings, gpu, "head depth (lights + view)", || {
        pass.prepare(gpu, head, frame, shadows)
    });
    memory_bytes.extend(prepared.memory());
    (pass, prepared)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shadow_layout::CubeLight;
    use glam::Vec3;

    fn deep(layers: u32) -> ShadowMaps {
        ShadowMaps::Deep {
            settings: DomSettings {
                resolution: 64,
                layers,
                spacing: 0.1,
            },
            pcf: 1,
        }
    }

    /// A cube's six faces of layers must fit the adapter's array limit: refused with the
    /// limit named and a layer count that fits, where one frustum of the same layers passes.
    #[test]
    fn a_cube_of_layers_past_the_array_limit_is_refused_naming_it() {
        let limits = GpuLimits::from_limits(wgpu::Limits {
            max_texture_array_layers: 16,
            ..wgpu::Limits::downlevel_defaults()
        });
        let bounds = crate::hair::Aabb {
            min: Vec3::splat(-1.0),
            max: Vec3::splat(1.0),
        };
        let cube = ShadowLayout::Cube(CubeLight::around(Vec3::ZERO, bounds));
        let frustum = ShadowLayout::Frustum(crate::camera::light_camera(Vec3::Z, bounds));
        // 16 layers: 4 array layers per face; 24 for the cube.
        assert!(check_layout_layers(&limits, &deep(16), &frustum).is_ok());
        let e = check_layout_layers(&limits, &deep(16), &cube).unwrap_err();
        let message = e.to_string();
        assert!(
            message.contains("max_texture_array_layers 16") && message.contains("24 array layers"),
            "{message}"
        );
        // 16 / 6 faces: 2 array layers, 8 optical depth layers per face.
        assert!(message.contains("at most 8 DOM layers"), "{message}");
        assert!(check_layout_layers(&limits, &deep(8), &cube).is_ok());
        // Depth-only maps keep a placeholder of 2 array layers per face: 12 fit.
        let hard = ShadowMaps::Depth {
            resolution: 64,
            lookup: ShadowLookup::Hard {
                kernel: 1,
                bias: 0.0,
            },
        };
        assert!(check_layout_layers(&limits, &hard, &cube).is_ok());
    }
}
