//! What the env view pass sees of each pixel's fibers (Ren 2010 §8, "Transparency"): built once
//! per frame, before the light batches, and read by every batch's view pass, so that the costly
//! per-fragment loop over lights runs only for fragments that reach the image.
//! * [`ViewTransparency::Opaque`]: a depth prepass that leaves each pixel's nearest fiber
//!   (position and tangent) in two textures, and a coverage pass (Σ −ln(1 − α) of each pixel's
//!   fragments); each batch's view pass then shades those fibers in one full-screen pass,
//!   weighting the nearest fiber's radiance by the coverage of all. The strands are rasterized
//!   twice per frame, not once per batch.
//! * [`ViewTransparency::Occupancy`]: the occupancy and slab maps of Sintorn & Assarsson 2009
//!   (`occupancy_map.wgsl`, `view_visibility.wgsl`): two passes record each pixel's depth range,
//!   which of its 128 depth slices hold fragments and the optical depth per slab of 32 slices,
//!   and a third sums the weights this gives the pixel's fragments; the view pass weighs every
//!   fragment by its coverage × exp(−optical depth in front), rescaled so that the pixel's
//!   weights add up to its coverage, and adds the results (order-independent), stopping before
//!   any light for fragments seen less than the cutoff (the paper's early opacity culling).
//!
//! * [`ViewTransparency::Layered`]: the occupancy map's three passes and a fourth that gathers
//!   the weighted fragments of each pixel into a few layers of equal coverage
//!   (`view_layers.wgsl`); each batch's view pass shades every layer once, in a full-screen
//!   pass, at its fibers' weighted mean depth and tangent.
//!
//! Inputs: the strands' bind group and the view group (group 3, holding the [`OccupancyMap`]).
//! Outputs: the view's depth, nearest-fiber and coverage textures (opaque) or the occupancy map
//! (occupancy).

use crate::gpu::GpuContext;
use crate::gpu::limits::{GpuLimits, LimitError, fit_pixels};
use crate::gpu::pipeline::{LazyPipeline, StrandDraw, build_both, depth_test};
use crate::gpu::readback::{ReadbackError, read_texture_rgba};
use crate::passes::attachments::{cleared_color, cleared_depth, prepassed_depth};
use crate::passes::render_target::{DEPTH_FORMAT, NEAREST_SURFACE_FORMAT, RenderTarget};

/// How the env view pass weighs the fragments of a pixel.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum ViewTransparency {
    /// Each pixel shows its nearest fiber's radiance, weighted by the coverage of all its
    /// fibers (1 − exp(−Σ τ)): one fragment shaded per pixel.
    #[default]
    Opaque,
    /// Every fiber in front weighs in by coverage × visibility; fragments seen less than
    /// `visibility_cutoff` (in [0, 1)) are not shaded.
    Occupancy { visibility_cutoff: f32 },
    /// The occupancy view's weights gathered into `VIEW_LAYERS` layers of equal coverage per
    /// pixel, each shaded once at its fibers' weighted mean depth and tangent
    /// (`view_layers.wgsl`): the occupancy view's weighting at a few shading loops per pixel.
    /// A compact source (a sun, a lamp) reads its layer's fibers' mean visibility, gathered per
    /// batch into the occupancy map (`OccupancyMap::layer_light_slots`).
    Layered { visibility_cutoff: f32 },
}

/// Layers per pixel of [`ViewTransparency::Layered`] (`OCC_LAYERS` in `view_layers.wgsl`).
pub const VIEW_LAYERS: u64 = 4;
/// u32 per layer (`OCC_LAYER_WORDS`): Σw, Σw·depth, Σw·tangent.
const LAYER_WORDS: u64 = 5;

impl ViewTransparency {
    /// Below 8-bit display precision: what is culled changes a pixel by at most 1/256 of the
    /// brightest fragment behind the cut.
    pub const DEFAULT_CUTOFF: f32 = 1.0 / 256.0;

    pub fn occupancy() -> Self {
        Self::Occupancy {
            visibility_cutoff: Self::DEFAULT_CUTOFF,
        }
    }

    pub fn layered() -> Self {
        Self::Layered {
            visibility_cutoff: Self::DEFAULT_CUTOFF,
        }
    }

    /// The cutoff the view pass applies (0 for opaque: nothing is culled by visibility).
    pub fn visibility_cutoff(&self) -> f32 {
        match self {
            Self::Opaque => 0.0,
            Self::Occupancy { visibility_cutoff } | Self::Layered { visibility_cutoff } => {
                *visibility_cutoff
            }
        }
    }

    /// Whether the frame builds the occupancy map (every view but the opaque one).
    pub fn uses_occupancy_map(&self) -> bool {
        !matches!(self, Self::Opaque)
    }

    /// u32 per pixel of the `OccupancyMap` (`view.record_words`).
    pub fn record_words(&self) -> u64 {
        match self {
            Self::Opaque | Self::Occupancy { .. } => RECORD_WORDS,
            Self::Layered { .. } => RECORD_WORDS + VIEW_LAYERS * LAYER_WORDS,
        }
    }

    pub fn check(&self) -> Result<(), OccupancyError> {
        let cutoff = self.visibility_cutoff();
        if !(0.0..1.0).contains(&cutoff) {
            return Err(OccupancyError::Cutoff(cutoff));
        }
        Ok(())
    }
}

/// u32 per pixel (`OCC_RECORD`): depth range, 4 words of occupancy bits, 4 slab optical depths,
/// the sum of the weights the map gives the pixel's fragments (the layered view adds its layers).
pub const RECORD_WORDS: u64 = 11;

#[derive(Debug, thiserror::Error, PartialEq)]
pub enum OccupancyError {
    #[error("transparency visibility cutoff {0}: must be in [0, 1)")]
    Cutoff(f32),
    #[error(transparent)]
    TooLarge(#[from] LimitError),
}

/// Fragment counts of one batch's view pass (every batch draws the same fragments).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FragmentCounts {
    /// Fragments the hair rasterizes into.
    pub rasterized: u64,
    /// Fragments the view pass shades (runs the loop over lights for).
    pub shaded: u64,
}

/// The per-pixel records of the occupancy map (a 16-byte placeholder for
/// [`ViewTransparency::Opaque`], which reads none), followed in the layered view by the layers'
/// light visibility of a batch of compact sources.
///
/// A compact source's visibility (a sun, a lamp: a directional light not
/// [standing for a region](crate::env_light::EnvLight::stands_for_region)) is one deep opacity
/// texel per fiber, sharp at fiber scale: a layer's mean fiber reads the visibility of its mean
/// position, not its fibers' mean visibility (quarry at 160×120 against the truth: 0.338 read
/// at the mean position, 0.290 shaded per fragment, for ~3× the frame). So a batch of them
/// first gathers Σw·v per layer and light (its strands rasterized once, no light shaded), and
/// each layer is shaded once with Σw·v / Σw (`view_layers.wgsl`): quarry 0.2883 against 0.2876
/// per fragment, on five maps within +0.006 for 1.3–1.6× faster frames
/// (docs/history/benchmarks-2026-12-05-to-12-06.md, "Compact sources per layer"). SRBF lobes and the lights that stand for a region of the map (a
/// reference's cube texel, a median-cut region), whose true shadows are soft at fiber scale,
/// read theirs at the layer's mean position.
#[derive(Clone)]
pub struct OccupancyMap {
    pub buffer: wgpu::Buffer,
    /// The first u32 after every pixel's record: where the layers' light visibility starts.
    pub layer_lights_word: u64,
    /// Light slots per layer and pixel: the most lights a batch of compact sources holds
    /// (0: the frame has none, or is not layered).
    pub layer_light_slots: u32,
}

impl OccupancyMap {
    /// `compact_slots`: the most light slots a batch of compact sources would take (the batch
    /// size, or the frame's compact sources if fewer); fewer are kept where the adapter's
    /// storage binding limit leaves room for fewer, down to one.
    pub fn new(
        gpu: &GpuContext,
        transparency: ViewTransparency,
        (width, height): (u32, u32),
        compact_slots: u32,
    ) -> Result<Self, OccupancyError> {
        transparency.check()?;
        let pixels = width as u64 * height as u64;
        let layer_lights_word = match transparency {
            ViewTransparency::Opaque => 0,
            _ => pixels * transparency.record_words(),
        };
        let limits = GpuLimits::of(gpu);
        let slot_bytes = pixels * VIEW_LAYERS * 4;
        let layer_light_slots = match transparency {
            ViewTransparency::Layered { .. } if compact_slots > 0 => {
                let room = limits
                    .max_storage_bytes()
                    .saturating_sub(layer_lights_word * 4);
                (room / slot_bytes).clamp(1, compact_slots as u64) as u32
            }
            _ => 0,
        };
        let bytes = (layer_lights_word * 4 + layer_light_slots as u64 * slot_bytes).max(16);
        limits.check_storage_buffer("occupancy map", bytes, |max| {
            let per_pixel =
                transparency.record_words() * 4 + layer_light_slots.min(1) as u64 * VIEW_LAYERS * 4;
            let (w, h) = fit_pixels(width, height, max / per_pixel);
            format!("render at {w}x{h} or smaller, or use the opaque view")
        })?;
        let buffer = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("occupancy map"),
            size: bytes,
            // COPY_SRC: a later part of the frame that needs more light slots copies the
            // records into a larger map (`Self::grown`).
            usage: wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::COPY_DST
                | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        Ok(Self {
            buffer,
            layer_lights_word,
            layer_light_slots,
        })
    }

    /// This map with light slots for `compact_slots` compact sources a batch, for a later part
    /// of the same frame: `None` when it has as many already (or the adapter's storage limit
    /// leaves room for no more); else a larger map holding this one's records, copied on the
    /// GPU, so that the frame's visibility is not drawn again.
    pub fn grown(
        &self,
        gpu: &GpuContext,
        transparency: ViewTransparency,
        size: (u32, u32),
        compact_slots: u32,
    ) -> Result<Option<Self>, OccupancyError> {
        if compact_slots <= self.layer_light_slots || self.layer_lights_word == 0 {
            return Ok(None);
        }
        let grown = Self::new(gpu, transparency, size, compact_slots)?;
        if grown.layer_light_slots <= self.layer_light_slots {
            return Ok(None);
        }
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        let records = self.layer_lights_word * 4;
        encoder.copy_buffer_to_buffer(&self.buffer, 0, &grown.buffer, 0, records);
        gpu.queue.submit([encoder.finish()]);
        Ok(Some(grown))
    }

    /// The layers' light visibility: zeroed before each batch of compact sources gathers it.
    pub fn clear_layer_lights(&self, encoder: &mut wgpu::CommandEncoder) {
        encoder.clear_buffer(&self.buffer, self.layer_lights_word * 4, None);
    }

    pub fn memory(&self) -> (String, u64) {
        ("occupancy map".into(), self.buffer.size())
    }
}

/// The build pipelines, made from the env view module so that they rasterize exactly the
/// fragments the view pass shades (the depth prepass's Equal test needs bit-identical depths).
pub struct ViewVisibilityPass {
    depth_prepass: LazyPipeline,
    front_depth: LazyPipeline,
    coverage: LazyPipeline,
    range: LazyPipeline,
    slices: LazyPipeline,
    weights: LazyPipeline,
    layers: LazyPipeline,
    count_rasterized: LazyPipeline,
    count_nearest: LazyPipeline,
    count_visible: LazyPipeline,
    count_layers: LazyPipeline,
}

/// What the visibility pipelines are built from (each when a frame first draws with it).
struct VisibilityShader {
    device: wgpu::Device,
    module: wgpu::ShaderModule,
    layout: wgpu::PipelineLayout,
    strands_only: wgpu::PipelineLayout,
    float_format: wgpu::TextureFormat,
}

impl VisibilityShader {
    /// A fragment entry point writes the additive float target (or the nearest surface);
    /// `depth`: the depth test and whether it writes, None without a depth attachment.
    fn pipeline(
        &self,
        label: &str,
        strands_only: bool,
        fragment: Option<&str>,
        depth: Option<(wgpu::CompareFunction, bool)>,
    ) -> wgpu::RenderPipeline {
        let additive = wgpu::BlendComponent {
            src_factor: wgpu::BlendFactor::One,
            dst_factor: wgpu::BlendFactor::One,
            operation: wgpu::BlendOperation::Add,
        };
        let float_target = [Some(wgpu::ColorTargetState {
            format: self.float_format,
            blend: Some(wgpu::BlendState {
                color: additive,
                alpha: additive,
            }),
            write_mask: wgpu::ColorWrites::ALL,
        })];
        // Replaced, not blended: with the depth test Less the last write is the nearest.
        let nearest_target = Some(wgpu::ColorTargetState {
            format: NEAREST_SURFACE_FORMAT,
            blend: None,
            write_mask: wgpu::ColorWrites::ALL,
        });
        let nearest_targets = [nearest_target.clone(), nearest_target];
        // The layer count is a full-screen pass; every other pass draws the strands.
        let vertex_entry = match fragment {
            Some("fs_count_layers") => "vs_fullscreen",
            _ => "vs_main",
        };
        let targets: &[Option<wgpu::ColorTargetState>] = match fragment {
            Some(f) if f.starts_with("fs_count") || f == "fs_coverage" => &float_target,
            Some("fs_nearest_surface") => &nearest_targets,
            _ => &[],
        };
        StrandDraw {
            label,
            layout: match strands_only {
                true => &self.strands_only,
                false => &self.layout,
            },
            shader: &self.module,
            vertex_entry,
            fragment: fragment.map(|entry| (entry, targets)),
            depth: depth.map(|(compare, write)| depth_test(DEPTH_FORMAT, write, compare)),
        }
        .build(&self.device)
    }
}

impl ViewVisibilityPass {
    /// `layout` binds the strands at group 0 and the view group at group 3, `strands_only` the
    /// strands alone; `float_format` is the (blendable) format of the coverage and count targets.
    pub fn new(
        device: &wgpu::Device,
        module: &wgpu::ShaderModule,
        layout: &wgpu::PipelineLayout,
        strands_only: &wgpu::PipelineLayout,
        float_format: wgpu::TextureFormat,
    ) -> Self {
        let shader = std::sync::Arc::new(VisibilityShader {
            device: device.clone(),
            module: module.clone(),
            layout: layout.clone(),
            strands_only: strands_only.clone(),
            float_format,
        });
        let lazy = |label: &'static str,
                    strands_only: bool,
                    fragment: Option<&'static str>,
                    depth: Option<(wgpu::CompareFunction, bool)>| {
            let shader = shader.clone();
            LazyPipeline::new(move || shader.pipeline(label, strands_only, fragment, depth))
        };
        use wgpu::CompareFunction::{Always, Equal, Less};
        let reading =
            |label, entry, compare| lazy(label, false, Some(entry), Some((compare, false)));
        Self {
            depth_prepass: lazy(
                "view depth prepass",
                true,
                Some("fs_nearest_surface"),
                Some((Less, true)),
            ),
            front_depth: lazy(
                "view front depth",
                true,
                Some("fs_front_depth"),
                Some((Less, true)),
            ),
            // Against the head's depth alone (the head pass wrote it; the prepass runs after):
            // fibers behind the head add no coverage.
            coverage: lazy(
                "view coverage",
                true,
                Some("fs_coverage"),
                Some((Less, false)),
            ),
            range: reading("occupancy depth range", "fs_occupancy_range", Always),
            slices: reading("occupancy slices", "fs_occupancy_slices", Always),
            weights: reading("occupancy weights", "fs_occupancy_weights", Always),
            layers: reading("view layers", "fs_view_layers", Always),
            count_rasterized: reading("count rasterized", "fs_count_rasterized", Always),
            count_nearest: reading("count nearest", "fs_count_nearest", Equal),
            count_visible: reading("count visible", "fs_count_visible", Always),
            count_layers: reading("count layers", "fs_count_layers", Always),
        }
    }

    /// Compiles the pipelines that build a frame's visibility in `transparency`, side by side
    /// ([`build_both`]), before its first frame needs them.
    pub fn compile(&self, transparency: ViewTransparency) {
        match transparency {
            ViewTransparency::Opaque => {
                build_both(|| self.coverage.get(), || self.depth_prepass.get());
            }
            ViewTransparency::Occupancy { .. } => {
                build_both(
                    || build_both(|| self.range.get(), || self.slices.get()),
                    || self.weights.get(),
                );
            }
            ViewTransparency::Layered { .. } => {
                build_both(
                    || build_both(|| self.range.get(), || self.slices.get()),
                    || build_both(|| self.weights.get(), || self.layers.get()),
                );
            }
        }
    }

    /// Encodes the frame's build: the coverage into `coverage`, then the depth prepass into
    /// `depth` with each pixel's nearest fiber into `nearest` (position, tangent) (opaque, all
    /// kept for the view passes; both test against the head's depth, which `depth` holds on
    /// entry), or the occupancy map zeroed and its three passes (which test against the head in
    /// the shader). `view` must bind `map`.
    #[allow(clippy::too_many_arguments)]
    pub fn encode(
        &self,
        gpu: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        transparency: ViewTransparency,
        strands: &wgpu::BindGroup,
        view: &wgpu::BindGroup,
        depth: &wgpu::TextureView,
        coverage: &wgpu::TextureView,
        nearest: [&wgpu::TextureView; 2],
        map: &OccupancyMap,
        segments: u32,
    ) {
        // (label, colour targets, with the depth attachment, pipeline, binds group 3).
        let passes: Vec<(
            &str,
            Vec<&wgpu::TextureView>,
            bool,
            &wgpu::RenderPipeline,
            bool,
        )> = match transparency {
            ViewTransparency::Opaque => vec![
                (
                    "view coverage",
                    vec![coverage],
                    true,
                    self.coverage.get(),
                    false,
                ),
                (
                    "view depth prepass",
                    nearest.to_vec(),
                    true,
                    self.depth_prepass.get(),
                    false,
                ),
            ],
            ViewTransparency::Occupancy { .. } | ViewTransparency::Layered { .. } => {
                encoder.clear_buffer(&map.buffer, 0, None);
                let mut passes = vec![
                    (
                        "occupancy depth range",
                        vec![],
                        true,
                        self.range.get(),
                        true,
                    ),
                    ("occupancy slices", vec![], true, self.slices.get(), true),
                    ("occupancy weights", vec![], true, self.weights.get(), true),
                ];
                if let ViewTransparency::Layered { .. } = transparency {
                    passes.push(("view layers", vec![], true, self.layers.get(), true));
                }
                passes
            }
        };
        for (label, colors, with_depth, pipeline, bind_view) in passes {
            let color_attachments: Vec<_> = colors.into_iter().map(cleared_color).collect();
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some(label),
                color_attachments: &color_attachments,
                // The opaque view's passes keep the head's depth; the occupancy passes test
                // Always (against the head in the shader).
                depth_stencil_attachment: match (with_depth, transparency) {
                    (false, _) => None,
                    (true, ViewTransparency::Opaque) => prepassed_depth(depth),
                    (true, _) => cleared_depth(depth, true),
                },
                timestamp_writes: gpu.render_timestamps(),
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, strands, &[]);
            if bind_view {
                pass.set_bind_group(3, view, &[]);
            }
            pass.draw(0..6 * segments, 0..1);
        }
    }

    /// The strands' depth, nearest kept, into `depth` (which holds the head's on entry): the
    /// frame's front depth that a host's depth test compares with its own scene. The strands
    /// are the view's quads, so a pixel has a depth exactly where it has coverage.
    pub fn encode_front_depth(
        &self,
        gpu: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        strands: &wgpu::BindGroup,
        depth: &wgpu::TextureView,
        segments: u32,
    ) {
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("view front depth"),
            color_attachments: &[],
            depth_stencil_attachment: prepassed_depth(depth),
            timestamp_writes: gpu.render_timestamps(),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(self.front_depth.get());
        pass.set_bind_group(0, strands, &[]);
        pass.draw(0..6 * segments, 0..1);
    }

    /// Benchmarks: the fragments one batch's view pass rasterizes and shades, counted into a
    /// float target (red rasterized, green shaded per pixel) after [`Self::encode`] built the
    /// frame's visibility (its depth is read, not changed), then summed on the CPU.
    #[allow(clippy::too_many_arguments)]
    pub fn count_fragments(
        &self,
        gpu: &GpuContext,
        transparency: ViewTransparency,
        strands: &wgpu::BindGroup,
        view: &wgpu::BindGroup,
        depth: &wgpu::TextureView,
        (width, height): (u32, u32),
        segments: u32,
    ) -> Result<FragmentCounts, ReadbackError> {
        let counts = RenderTarget::new(gpu, width, height);
        let (shaded, shaded_vertices) = match transparency {
            ViewTransparency::Opaque => (self.count_nearest.get(), 6 * segments),
            ViewTransparency::Occupancy { .. } => (self.count_visible.get(), 6 * segments),
            ViewTransparency::Layered { .. } => (self.count_layers.get(), 3),
        };
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        {
            let target = counts.color.create_view(&Default::default());
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("count fragments"),
                color_attachments: &[cleared_color(&target)],
                depth_stencil_attachment: prepassed_depth(depth),
                timestamp_writes: gpu.render_timestamps(),
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_bind_group(0, strands, &[]);
            pass.set_bind_group(3, view, &[]);
            for (pipeline, vertices) in [
                (self.count_rasterized.get(), 6 * segments),
                (shaded, shaded_vertices),
            ] {
                pass.set_pipeline(pipeline);
                pass.draw(0..vertices, 0..1);
            }
        }
        gpu.queue.submit([encoder.finish()]);
        Ok(sum_counts(&read_texture_rgba(gpu, &counts.color)?))
    }
}

/// Sums the per-pixel counts of [`ViewVisibilityPass::count_fragments`] (RGBA f32 texels).
fn sum_counts(texels: &[[f32; 4]]) -> FragmentCounts {
    let (rasterized, shaded) = texels.iter().fold((0.0f64, 0.0f64), |(r, s), t| {
        (r + t[0] as f64, s + t[1] as f64)
    });
    FragmentCounts {
        rasterized: rasterized.round() as u64,
        shaded: shaded.round() as u64,
    }
}
