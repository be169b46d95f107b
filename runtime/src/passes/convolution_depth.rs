//! The light pass of the convolution optical depth map (Ren 2010 §5): for a batch of lights, per
//! light an orthographic camera along its direction around the hair ([`light_camera`](crate::camera::light_camera)), the
//! nearest fiber z₀ per texel (one `R32Float` array layer per light slot), then the cumulative
//! optical depths at the boundaries z_k = k(k+1)d/2, k = 1..3, behind z₀ and everything in the
//! fourth channel (an `Rgba32Float` array layer). The strands' quads are rasterized in compute
//! (`convolution_depth.wgsl`): one invocation per segment visits the texel centres its two
//! triangles cover. All lights of a batch are encoded into one command encoder.
//! Inputs: [`StrandGeometry`] (possibly the simplified segment order of
//! [`SimplifiedSegments`]), light directions, hair bounds, [`DodmSettings`].
//! Output: [`DodmBatch`] (textures + the lights' cameras), read by `summed_area` and the view pass.

use glam::Vec3;
use std::ops::Range;
use strandlight_tables::hard_case_sweep::SweepRng;
use wgpu::util::DeviceExt;

use super::frame_params::{FrameParams, KajiyaKay, QuadStyle};
use super::strand_geometry::{StrandGeometry, segment_table};
use super::strand_quads::{strand_bind_group_layout_for, strand_bind_group_styled};
use crate::camera::{Camera, LightFraming, Projection};
use crate::gpu::GpuContext;
use crate::gpu::bind_layout::{
    bind_group, pipeline_layout, storage_entry, storage_texture_entry, uniform_entry,
};
use crate::gpu::pipeline::compute_pipeline;
use crate::gpu::texture::texture_2d;
use crate::hair::{Aabb, HairModel};
use crate::shaders::{Wgsl, shader_module};

/// The largest DODM side the SAT's u32 fixed point is specified for (see `summed_area`).
pub const MAX_DODM_RESOLUTION: u32 = 2048;

/// Boundaries z_k (k = 1..4, the fourth standing for ∞ when accumulating) in units of d.
pub const LAYER_BOUNDARIES: [f32; 4] = [1.0, 3.0, 6.0, 10.0];

/// The light pass's settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DodmSettings {
    /// Texels across each light's map (default 512, at most [`MAX_DODM_RESOLUTION`]).
    pub resolution: u32,
    /// d, the first layer's depth in world units; `None`: [`default_first_layer`] of the hair.
    pub first_layer: Option<f32>,
    /// Lights per batch (one map each, drawn in one submit; default 16).
    pub batch_size: u32,
}

impl Default for DodmSettings {
    fn default() -> Self {
        Self {
            resolution: 512,
            first_layer: None,
            batch_size: 16,
        }
    }
}

#[derive(Debug, thiserror::Error, PartialEq)]
pub enum DodmSettingsError {
    #[error("DODM resolution {0}: must be 1..={MAX_DODM_RESOLUTION}")]
    Resolution(u32),
    #[error("DODM first layer depth {0}: must be positive and finite")]
    FirstLayer(f32),
    #[error("light batch size 0: must be at least 1")]
    BatchSize,
    #[error("stochastic simplification fraction κ = {0}: must be in (0, 1]")]
    Kappa(f32),
}

impl DodmSettings {
    /// Texels across the maps of κ-simplified lights: `resolution` × √κ (at least 16, at most
    /// `resolution`). A simplified map holds κ of the strands, each widened to cover the ones
    /// left out, so it carries about κ of a full map's detail: √κ per side keeps the texels per
    /// drawn strand, and the light pass's fill (the light pass's largest cost) falls with κ
    /// (docs/BENCHMARKS.md, "Simplified light maps at √κ resolution").
    pub fn simplified_resolution(&self, kappa: f32) -> u32 {
        let scaled = (self.resolution as f32 * kappa.clamp(0.0, 1.0).sqrt()).round() as u32;
        scaled.clamp(16.min(self.resolution), self.resolution)
    }

    /// Texels across the map of a compact source that holds much of the environment's power
    /// ([`EnvLight::has_fine_map`](crate::env_light::EnvLight::has_fine_map)): four times the
    /// side, at most [`MAX_DODM_RESOLUTION`]. Its shadow is sharp at fiber scale and decides a
    /// large share of the frame, so a fiber's shadow should be resolved, not averaged over a
    /// texel several fibers wide.
    pub fn fine_resolution(&self) -> u32 {
        self.resolution.saturating_mul(4).min(MAX_DODM_RESOLUTION)
    }

    /// The fiber enlargement of a simplified light map at [`Self::simplified_resolution`]: 1/κ
    /// of a full-resolution texel (Ren 2010 §7, the drawn fibers cover those left out), so the
    /// same world width whatever the map's texels; a quad is never narrower than its texel.
    pub fn simplified_enlargement(&self, kappa: f32) -> f32 {
        let texel_ratio = self.simplified_resolution(kappa) as f32 / self.resolution as f32;
        (texel_ratio / kappa).max(1.0)
    }

    pub fn check(&self) -> Result<(), DodmSettingsError> {
        if !(1..=MAX_DODM_RESOLUTION).contains(&self.resolution) {
            return Err(DodmSettingsError::Resolution(self.resolution));
        }
        if let Some(d) = self.first_layer
            && !(d.is_finite() && d > 0.0)
        {
            return Err(DodmSettingsError::FirstLayer(d));
        }
        if self.batch_size == 0 {
            return Err(DodmSettingsError::BatchSize);
        }
        Ok(())
    }

    /// d for `bounds`: the setting, else [`default_first_layer`].
    pub fn first_layer_for(&self, bounds: Aabb) -> f32 {
        self.first_layer
            .unwrap_or_else(|| default_first_layer(bounds))
    }
}

/// 1% of the bounds' diagonal. The boundaries then lie at 1, 3, 6 and 10% of the diagonal
/// behind the first fiber: a scalp's hair layer is a few percent of the head's diagonal thick,
/// and light is mostly gone a few layers in, so the resolution goes where the optical depth
/// still changes the transmittance (the triangular spacing of eq. 10 coarsens with depth).
pub fn default_first_layer(bounds: Aabb) -> f32 {
    (bounds.diagonal() * 0.01).max(1e-6)
}

/// Checks κ ∈ (0, 1].
pub fn check_kappa(kappa: f32) -> Result<(), DodmSettingsError> {
    if kappa > 0.0 && kappa <= 1.0 {
        Ok(())
    } else {
        Err(DodmSettingsError::Kappa(kappa))
    }
}

/// Stochastic simplification (Ren 2010 §7): the segment table with whole strands in the
/// seeded [`simplification_order`], so the light pass may draw only the segments of a window
/// of κ·strands consecutive strands (enlarged by 1/κ, `ConvolutionDepthPass::encode`).
pub struct SimplifiedSegments {
    pub segments: wgpu::Buffer,
    /// `segments_before[s]`: segments of the first s strands in that order (strand_count + 1
    /// entries).
    pub segments_before: Vec<u32>,
}

/// The order whose consecutive runs are the strand subsets κ draws: a permutation of
/// 0..strand_count. Strands are sorted along a Morton curve through their roots and visited in
/// bit-reversed order, scrambled by a seeded digital shift. Every run of consecutive entries
/// is then spread evenly over the scalp (a run of 2^q aligned entries holds exactly one strand
/// of each 2^q-th of the sorted strands), so a light map drawing one run thins the hair
/// evenly instead of leaving the random clumps and gaps of a shuffled subset, whose shadow
/// noise κ's 1/κ opacity then magnifies (docs/BENCHMARKS.md, "Stratified subsets").
pub fn simplification_order(model: &HairModel, seed: u64) -> Vec<u32> {
    let strands = model.strand_count();
    if strands == 0 {
        return Vec::new();
    }
    let along_curve = strands_along_morton_curve(model);
    let bits = usize::BITS - (strands - 1).leading_zeros();
    let shift = SweepRng::new(seed).next_u64() & ((1u64 << bits) - 1);
    (0..1u64 << bits)
        .map(|i| bit_reversed(i, bits) ^ shift)
        .filter(|&r| (r as usize) < strands)
        .map(|r| along_curve[r as usize])
        .collect()
}

/// `i`'s lowest `bits` bits in reverse order.
fn bit_reversed(i: u64, bits: u32) -> u64 {
    match bits {
        0 => 0,
        _ => i.reverse_bits() >> (64 - bits),
    }
}

/// Strand indices sorted by the Morton code of their roots on a 1024³ grid over the bounds,
/// so strands near each other on the curve grow near each other.
fn strands_along_morton_curve(model: &HairModel) -> Vec<u32> {
    let bounds = model.bounds();
    let extent = (bounds.max - bounds.min).max(Vec3::splat(1e-20));
    let mut keyed: Vec<(u64, u32)> = model
        .strands()
        .enumerate()
        .map(|(s, points)| {
            let root = points.first().copied().unwrap_or(bounds.min);
            let cell =
                ((root - bounds.min) / extent * 1023.0).clamp(Vec3::ZERO, Vec3::splat(1023.0));
            (morton_code(cell.as_uvec3()), s as u32)
        })
        .collect();
    keyed.sort_unstable();
    keyed.into_iter().map(|(_, s)| s).collect()
}

/// The 30-bit Morton code of a cell of a 1024³ grid (x, y and z bits interleaved).
fn morton_code(cell: glam::UVec3) -> u64 {
    fn spread(v: u32) -> u64 {
        let mut v = v as u64 & 0x3ff;
        v = (v | v << 16) & 0x0300_00ff;
        v = (v | v << 8) & 0x0300_f00f;
        v = (v | v << 4) & 0x030c_30c3;
        (v | v << 2) & 0x0924_9249
    }
    spread(cell.x) | spread(cell.y) << 1 | spread(cell.z) << 2
}

/// Light `k`'s strands under simplification κ, as ranges of segments in the
/// [`simplification_order`] (`segments_before[s]`: segments of its first s strands): the
/// ⌈κ·S⌉ strands from strand (k·⌈κ·S⌉) mod S on, wrapping round. Consecutive lights thus draw
/// disjoint subsets (⌈1/κ⌉ lights draw every strand), so the simplification's noise differs
/// between lights and averages out over a frame's lobes, instead of one subset's pattern
/// repeating in every lobe's shadow (docs/BENCHMARKS.md, "One subset per light").
pub fn strand_window(segments_before: &[u32], kappa: f32, k: u32) -> Vec<Range<u32>> {
    let strands = segments_before.len().saturating_sub(1);
    if strands == 0 {
        return Vec::new();
    }
    let drawn = ((kappa as f64 * strands as f64).ceil() as usize).clamp(1, strands);
    let start = (k as usize % strands) * drawn % strands;
    let end = start + drawn;
    let mut ranges = Vec::with_capacity(2);
    ranges.push(segments_before[start]..segments_before[end.min(strands)]);
    if end > strands {
        ranges.push(0..segments_before[end - strands]);
    }
    ranges.retain(|r| !r.is_empty());
    ranges
}

impl SimplifiedSegments {
    pub fn new(gpu: &GpuContext, model: &HairModel, seed: u64) -> Self {
        Self::in_order(gpu, model, &simplification_order(model, seed))
    }

    /// The segments of `model` with its strands in `order` (a permutation of its strands; a
    /// coarser model of the same strands takes its original's order, so that both draw the
    /// same strands per window).
    pub fn in_order(gpu: &GpuContext, model: &HairModel, order: &[u32]) -> Self {
        let table = segment_table(model);
        // Segment range of each strand in the original table.
        let mut first = Vec::with_capacity(model.strand_count() + 1);
        first.push(0usize);
        for w in model.strand_offsets().windows(2) {
            first.push(first.last().unwrap() + (w[1] - w[0]).saturating_sub(1) as usize);
        }
        let mut ordered = Vec::with_capacity(table.len());
        let mut segments_before = vec![0u32];
        for &s in order {
            ordered.extend_from_slice(&table[first[s as usize]..first[s as usize + 1]]);
            segments_before.push(ordered.len() as u32);
        }
        // A storage binding may not be empty.
        if ordered.is_empty() {
            ordered.push(0);
        }
        let segments = gpu
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("hair segments (simplification order)"),
                contents: bytemuck::cast_slice(&ordered),
                usage: wgpu::BufferUsages::STORAGE,
            });
        Self {
            segments,
            segments_before,
        }
    }

    /// Segments to draw for fraction κ: those of the first ⌈κ·strands⌉ strands in order.
    pub fn segment_count(&self, kappa: f32) -> u32 {
        let strands = self.segments_before.len() - 1;
        let drawn = ((kappa as f64 * strands as f64).ceil() as usize).min(strands);
        self.segments_before[drawn]
    }

    /// Light `k`'s window of the simplification order for fraction κ, as segment ranges
    /// ([`strand_window`]).
    pub fn window(&self, kappa: f32, k: u32) -> Vec<Range<u32>> {
        strand_window(&self.segments_before, kappa, k)
    }

    /// `geometry` drawing the first κ fraction of strands in simplification order.
    pub fn geometry(&self, geometry: &StrandGeometry, kappa: f32) -> StrandGeometry {
        StrandGeometry {
            segments: self.segments.clone(),
            segment_count: self.segment_count(kappa),
            ..geometry.clone()
        }
    }
}

#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct DodmUniform {
    near: f32,
    far: f32,
    first_layer: f32,
    tau_scale: f32,
    resolution: u32,
    segment_count: u32,
    window_count: u32,
    row_length: u32,
}

/// The maps of one batch: layer `slot` of each array belongs to light `slot`.
pub struct DodmBatch {
    pub resolution: u32,
    pub slots: u32,
    pub first_layer: f32,
    pub cameras: Vec<Camera>,
    /// Nearest fiber depth z₀ (0..1 between the camera's near and far planes; 1 where nothing
    /// is drawn), `R32Float`.
    pub nearest_depth: wgpu::Texture,
    /// Cumulative optical depths at the four boundaries, `Rgba32Float`.
    pub optical_depth: wgpu::Texture,
}

/// The formats of [`DodmBatch`]'s maps: written by the light pass's compute resolve, so
/// storage formats of every WebGPU adapter.
pub const NEAREST_DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;
pub const OPTICAL_DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;

impl DodmBatch {
    pub fn new(gpu: &GpuContext, resolution: u32, slots: u32, first_layer: f32) -> Self {
        let size = wgpu::Extent3d {
            width: resolution,
            height: resolution,
            depth_or_array_layers: slots.max(1),
        };
        let texture = |label, format| {
            // COPY_SRC: tests read the maps back; COPY_DST: tests write optical depths.
            let usage = wgpu::TextureUsages::STORAGE_BINDING
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_SRC
                | wgpu::TextureUsages::COPY_DST;
            texture_2d(gpu, label, size, format, usage)
        };
        Self {
            resolution,
            slots,
            first_layer,
            cameras: Vec::new(),
            nearest_depth: texture("dodm nearest depth", NEAREST_DEPTH_FORMAT),
            optical_depth: texture("dodm optical depth", OPTICAL_DEPTH_FORMAT),
        }
    }

    /// One array layer as a 2D view.
    pub fn layer_view(texture: &wgpu::Texture, slot: u32) -> wgpu::TextureView {
        texture.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2),
            base_array_layer: slot,
            array_layer_count: Some(1),
            ..Default::default()
        })
    }

    /// The whole array as a 2D-array view.
    pub fn array_view(texture: &wgpu::Texture) -> wgpu::TextureView {
        texture.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        })
    }

    /// Texels per world unit of slot `slot`'s map.
    pub fn texels_per_unit(&self, slot: usize) -> f32 {
        match self.cameras[slot].projection {
            Projection::Orthographic { half_height } => {
                self.resolution as f32 / (2.0 * half_height)
            }
            Projection::Perspective { .. } => 0.0,
        }
    }

    /// The maps, and the light pass's scratch of one slot (4 + 16 bytes a texel).
    pub fn memory(&self) -> Vec<(String, u64)> {
        let map = self.resolution as u64 * self.resolution as u64;
        let texels = map * self.slots.max(1) as u64;
        vec![
            ("dodm nearest depth".into(), texels * 4),
            ("dodm optical depth".into(), texels * 16),
            (
                "dodm light-pass scratch".into(),
                map * SCRATCH_BYTES_PER_TEXEL,
            ),
        ]
    }
}

/// The light pass's scratch per texel: the nearest depth and four optical depths, u32 each.
const SCRATCH_BYTES_PER_TEXEL: u64 = 4 + 16;

/// Workgroups of the splat kernels (`@workgroup_size(64)`) in x before a row wraps to y: within
/// every adapter's 65535 workgroups per dimension.
const SPLAT_ROW_WORKGROUPS: u32 = 32768;

/// The light pass's three kernels and their layouts, built once.
pub struct ConvolutionDepthPass {
    nearest: wgpu::ComputePipeline,
    layers: wgpu::ComputePipeline,
    resolve: wgpu::ComputePipeline,
    strand_layout: wgpu::BindGroupLayout,
    splat_layout: wgpu::BindGroupLayout,
    output_layout: wgpu::BindGroupLayout,
}

impl ConvolutionDepthPass {
    pub fn new(gpu: &GpuContext) -> Self {
        let device = &gpu.device;
        let top = Wgsl {
            file: "convolution_depth.wgsl",
            source: include_str!("convolution_depth.wgsl"),
        };
        let shader = shader_module(device, &top, None);
        let compute = wgpu::ShaderStages::COMPUTE;
        let strand_layout = strand_bind_group_layout_for(device, compute);
        let splat_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("dodm splat"),
            entries: &[
                uniform_entry(0, compute),
                storage_entry(1, compute, true),
                storage_entry(2, compute, false),
                storage_entry(3, compute, false),
            ],
        });
        let output_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("dodm maps"),
            entries: &[
                storage_texture_entry(0, compute, NEAREST_DEPTH_FORMAT),
                storage_texture_entry(1, compute, OPTICAL_DEPTH_FORMAT),
            ],
        });
        let layout = pipeline_layout(
            device,
            "dodm light pass",
            &[
                Some(&strand_layout),
                Some(&splat_layout),
                Some(&output_layout),
            ],
        );
        let kernel = |entry: &str| compute_pipeline(device, entry, &layout, &shader, entry);
        Self {
            nearest: kernel("splat_nearest"),
            layers: kernel("splat_layers"),
            resolve: kernel("resolve"),
            strand_layout,
            splat_layout,
            output_layout,
        }
    }

    /// Encodes the maps of `toward_lights` (one slot each, at most `batch.slots`) into `encoder`;
    /// for a simplified `geometry`, `tau_scale` = 1/κ and `width_scale` = 1/κ (Ren 2010 §7: the
    /// drawn fibers enlarged, so the map keeps the coverage of the fibers left out; 1 keeps the
    /// file's width). Sets `batch.cameras`.
    #[allow(clippy::too_many_arguments)]
    pub fn encode(
        &self,
        gpu: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        geometry: &StrandGeometry,
        toward_lights: &[Vec3],
        framing: LightFraming<'_>,
        tau_scale: f32,
        width_scale: f32,
        batch: &mut DodmBatch,
    ) {
        let everything = std::iter::once(0..geometry.segment_count).collect::<Vec<_>>();
        let windows = vec![everything; toward_lights.len()];
        self.encode_windows(
            gpu,
            encoder,
            geometry,
            toward_lights,
            &windows,
            framing,
            [tau_scale, width_scale],
            batch,
        );
    }

    /// [`Self::encode`] drawing, for light `i`, only the segments in `windows[i]` (ranges of
    /// `geometry`'s segment table: [`SimplifiedSegments::window`]); `scales` = [τ, width].
    /// Per light: the nearest depths, then the optical depths, splatted into a scratch shared by
    /// the batch's lights, then resolved into the light's layer of the maps.
    #[allow(clippy::too_many_arguments)]
    pub fn encode_windows(
        &self,
        gpu: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        geometry: &StrandGeometry,
        toward_lights: &[Vec3],
        windows: &[Vec<Range<u32>>],
        framing: LightFraming<'_>,
        [tau_scale, width_scale]: [f32; 2],
        batch: &mut DodmBatch,
    ) {
        assert_eq!(windows.len(), toward_lights.len(), "one window per light");
        let device = &gpu.device;
        let res = batch.resolution;
        batch.cameras = toward_lights
            .iter()
            .map(|&l| framing.light_camera(l))
            .collect();
        let scratch = LightPassScratch::new(gpu, res);
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("dodm light pass"),
            timestamp_writes: gpu.compute_timestamps(),
        });
        for (slot, camera) in batch.cameras.iter().enumerate() {
            let frame = FrameParams {
                camera: *camera,
                width: res,
                height: res,
                lights: Vec::new(),
                shading: KajiyaKay::default(),
                width_override_px: None,
            };
            let strands = strand_bind_group_styled(
                gpu,
                &self.strand_layout,
                geometry,
                &frame,
                QuadStyle::Widened(width_scale),
            );
            let ranges: Vec<[u32; 2]> = windows[slot]
                .iter()
                .filter(|r| !r.is_empty())
                .map(|r| [r.start, r.end - r.start])
                .collect();
            let segment_count: u32 = ranges.iter().map(|r| r[1]).sum();
            let workgroups = segment_count.div_ceil(64);
            let grid = [
                workgroups.min(SPLAT_ROW_WORKGROUPS),
                workgroups.div_ceil(SPLAT_ROW_WORKGROUPS),
            ];
            let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("dodm params"),
                contents: bytemuck::bytes_of(&DodmUniform {
                    near: camera.near,
                    far: camera.far,
                    first_layer: batch.first_layer,
                    tau_scale,
                    resolution: res,
                    segment_count,
                    window_count: ranges.len() as u32,
                    row_length: grid[0] * 64,
                }),
                usage: wgpu::BufferUsages::UNIFORM,
            });
            // A storage binding may not be empty.
            let window_list: &[[u32; 2]] = if ranges.is_empty() {
                &[[0, 0]]
            } else {
                &ranges
            };
            let window_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("dodm windows"),
                contents: bytemuck::cast_slice(window_list),
                usage: wgpu::BufferUsages::STORAGE,
            });
            let splat = bind_group(
                device,
                "dodm splat",
                &self.splat_layout,
                &[
                    uniform.as_entire_binding(),
                    window_buffer.as_entire_binding(),
                    scratch.nearest.as_entire_binding(),
                    scratch.layers.as_entire_binding(),
                ],
            );
            let nearest_view = DodmBatch::layer_view(&batch.nearest_depth, slot as u32);
            let optical_view = DodmBatch::layer_view(&batch.optical_depth, slot as u32);
            let output = bind_group(
                device,
                "dodm maps",
                &self.output_layout,
                &[
                    wgpu::BindingResource::TextureView(&nearest_view),
                    wgpu::BindingResource::TextureView(&optical_view),
                ],
            );
            pass.set_bind_group(0, &strands, &[]);
            pass.set_bind_group(1, &splat, &[]);
            pass.set_bind_group(2, &output, &[]);
            if segment_count > 0 {
                for kernel in [&self.nearest, &self.layers] {
                    pass.set_pipeline(kernel);
                    pass.dispatch_workgroups(grid[0], grid[1], 1);
                }
            }
            pass.set_pipeline(&self.resolve);
            pass.dispatch_workgroups(res.div_ceil(8), res.div_ceil(8), 1);
        }
    }
}

/// One map's splat targets, zeroed at creation and by each resolve.
struct LightPassScratch {
    nearest: wgpu::Buffer,
    layers: wgpu::Buffer,
}

impl LightPassScratch {
    fn new(gpu: &GpuContext, resolution: u32) -> Self {
        let texels = resolution as u64 * resolution as u64;
        let buffer = |label, bytes| {
            gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: bytes,
                usage: wgpu::BufferUsages::STORAGE,
                mapped_at_creation: false,
            })
        };
        Self {
            nearest: buffer("dodm nearest scratch", texels * 4),
            layers: buffer("dodm layers scratch", texels * 16),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn simplified_maps_shrink_with_the_root_of_kappa_and_keep_the_world_width() {
        let settings = DodmSettings::default();
        assert_eq!(settings.simplified_resolution(1.0), settings.resolution);
        assert_eq!(settings.simplified_enlargement(1.0), 1.0);
        for kappa in [0.5f32, 0.25, 0.1, 0.05] {
            let r = settings.simplified_resolution(kappa);
            let expected = settings.resolution as f32 * kappa.sqrt();
            assert!((r as f32 - expected).abs() <= 0.5, "κ {kappa}: {r}");
            // The enlarged quad spans 1/κ full-resolution texels in the world.
            let world = settings.simplified_enlargement(kappa) / r as f32;
            let wanted = 1.0 / (kappa * settings.resolution as f32);
            assert!(
                (world / wanted - 1.0).abs() < 1e-5,
                "κ {kappa}: {world} vs {wanted}"
            );
        }
        // Tiny maps stop at 16 texels (or the map's own size), and quads at one texel.
        let small = DodmSettings::at_resolution(32);
        assert_eq!(small.simplified_resolution(0.01), 16);
        assert!((small.simplified_enlargement(0.01) - 50.0).abs() < 1e-3);
        let tiny = DodmSettings::at_resolution(8);
        assert_eq!(tiny.simplified_resolution(0.1), 8);
        assert!((tiny.simplified_enlargement(0.9) - 1.0 / 0.9).abs() < 1e-6);
    }

    #[test]
    fn kappa_and_settings_are_checked() {
        assert!(check_kappa(0.1).is_ok());
        assert!(check_kappa(1.0).is_ok());
        for bad in [0.0, -0.5, 1.5, f32::NAN] {
            let e = check_kappa(bad).unwrap_err();
            assert!(matches!(e, DodmSettingsError::Kappa(_)), "{bad}");
            assert!(e.to_string().contains("κ"), "{e}");
        }
        let ok = DodmSettings::default();
        assert!(ok.check().is_ok());
        let e = DodmSettings {
            resolution: 4096,
            ..ok
        }
        .check()
        .unwrap_err();
        assert!(e.to_string().contains("4096"), "{e}");
        assert_eq!(
            DodmSettings {
                batch_size: 0,
                ..ok
            }
            .check(),
            Err(DodmSettingsError::BatchSize)
        );
        assert!(
            DodmSettings {
                first_layer: Some(-1.0),
                ..ok
            }
            .check()
            .is_err()
        );
    }

    /// Strands rooted along a line in a scrambled file order.
    fn strands_on_a_line(count: u32) -> HairModel {
        let mut points = Vec::new();
        for s in 0..count {
            let x = ((s as u64 * 7919) % count as u64) as f32;
            points.extend([Vec3::new(x, 0.0, 0.0), Vec3::new(x, -1.0, 0.0)]);
        }
        let offsets = (0..=count).map(|s| 2 * s).collect();
        HairModel::new(points, offsets, None, None, None).unwrap()
    }

    fn root_x(model: &HairModel, s: u32) -> usize {
        model.strand(s as usize)[0].x as usize
    }

    #[test]
    fn simplification_order_is_a_seeded_permutation() {
        for count in [1, 2, 10, 1000] {
            let model = strands_on_a_line(count);
            let a = simplification_order(&model, 7);
            let mut sorted = a.clone();
            sorted.sort();
            assert_eq!(sorted, (0..count).collect::<Vec<_>>(), "{count} strands");
            assert_eq!(a, simplification_order(&model, 7));
        }
        let model = strands_on_a_line(1000);
        let seeds: std::collections::HashSet<_> = (0..8)
            .map(|seed| simplification_order(&model, seed))
            .collect();
        assert!(seeds.len() >= 6, "8 seeds gave {} orders", seeds.len());
    }

    /// 256 strands, windows of 2^q aligned entries: each window holds one strand from each
    /// 2^q-th of the line, whatever the seed; a shuffle would clump.
    #[test]
    fn aligned_windows_hold_one_strand_per_stratum() {
        let model = strands_on_a_line(256);
        for seed in [0, 1, 24301] {
            let order = simplification_order(&model, seed);
            for window in [4usize, 16, 64] {
                let stratum = 256 / window;
                for run in order.chunks(window) {
                    let mut strata: Vec<_> =
                        run.iter().map(|&s| root_x(&model, s) / stratum).collect();
                    strata.sort();
                    assert_eq!(strata, (0..window).collect::<Vec<_>>(), "seed {seed}");
                }
            }
        }
    }

    /// 10,000 strands (not a power of two) and κ = 1/8, windows at every light's offset: no gap
    /// along the line between a window's strands reaches 3× their mean spacing (8), where a
    /// random subset's largest gap is about ln(window) ≈ 7× it (measured here: 18).
    #[test]
    fn every_window_spreads_over_the_line() {
        let model = strands_on_a_line(10_000);
        let order = simplification_order(&model, 24301);
        let mut before = vec![0u32];
        for s in &order {
            before.push(before.last().unwrap() + model.strand(*s as usize).len() as u32 - 1);
        }
        let w = 1250usize;
        let bound = 3 * 10_000 / w;
        for k in 0..25u32 {
            let mut xs: Vec<usize> = strand_window(&before, 0.125, k)
                .into_iter()
                .flat_map(|r| r.start as usize..r.end as usize)
                .map(|segment| root_x(&model, order[segment]))
                .collect();
            assert_eq!(xs.len(), w);
            xs.sort();
            let gap = xs
                .windows(2)
                .map(|p| p[1] - p[0])
                .chain([xs[0], 10_000 - xs[w - 1]]);
            assert!(
                gap.clone().max().unwrap() < bound,
                "light {k}: gap {:?} ≥ {bound}",
                gap.max()
            );
        }
    }

    /// Strands of uneven length (1, 2, 3, 1, 2, 3, … segments), κ = 1/4 of 12 strands: each
    /// window holds 3 strands, consecutive windows follow one another round the order (the
    /// fifth wraps to the start), and 1/κ of them draw every segment once (counted here strand
    /// by strand, not from the ranges' lengths).
    #[test]
    fn consecutive_windows_are_disjoint_and_cover_every_strand() {
        let lengths: Vec<u32> = (0..12).map(|s| 1 + s % 3).collect();
        let mut before = vec![0u32];
        for l in &lengths {
            before.push(before.last().unwrap() + l);
        }
        let total = *before.last().unwrap();
        let mut drawn = vec![0u32; total as usize];
        for k in 0..5 {
            let ranges = strand_window(&before, 0.25, k);
            let strands: std::collections::BTreeSet<usize> = ranges
                .iter()
                .flat_map(|r| r.clone())
                .map(|seg| before.partition_point(|&b| b <= seg) - 1)
                .collect();
            assert_eq!(strands.len(), 3, "window {k}: {ranges:?}");
            let first = (3 * k as usize) % 12;
            let expected: std::collections::BTreeSet<usize> =
                (first..first + 3).map(|s| s % 12).collect();
            assert_eq!(strands, expected, "window {k}");
            for seg in ranges.iter().flat_map(|r| r.clone()) {
                drawn[seg as usize] += 1;
            }
        }
        // Windows 0..4 cover strands 0..15: every segment once, strands 0..3 twice.
        for (seg, &n) in drawn.iter().enumerate() {
            let strand = before.partition_point(|&b| b <= seg as u32) - 1;
            let want = if strand < 3 { 2 } else { 1 };
            assert_eq!(n, want, "segment {seg} of strand {strand}");
        }
        // κ = 1: every window is the whole order; no strands: nothing.
        assert_eq!(strand_window(&before, 1.0, 5), vec![0..total]);
        assert!(strand_window(&[0], 0.5, 0).is_empty());
    }
}

#[cfg(test)]
mod wgsl_layout {
    use super::*;
    use crate::shader_layout::{assert_same_layout, rust_layout};
    use crate::shaders::Wgsl;

    #[test]
    fn uploaded_structs_are_laid_out_as_the_wgsl_reads_them() {
        assert_same_layout(
            &Wgsl {
                file: "convolution_depth.wgsl",
                source: include_str!("convolution_depth.wgsl"),
            },
            None,
            "DodmParams",
            &rust_layout!(DodmUniform {
                near,
                far,
                first_layer,
                tau_scale,
                resolution,
                segment_count,
                window_count,
                row_length
            }),
        );
    }
}
