//! Random subsets (Hunz §5.4): the strands are split at random into k subsets; each is drawn
//! depth-tested into its own layer (its nearest fiber per pixel, coverage-blended as the opaque
//! pass blends), and a compute resolve sorts the k layers of each pixel by depth and composites
//! them front to back (`random_subsets_resolve.wgsl`). No per-pixel lists: memory is k colour
//! and depth layers, and a pixel composites at most k fragments.
//! Inputs: [`StrandGeometry`], the hair (its strands), [`FrameParams`], shadow maps, k.
//! Output: the resolved image.

use wgpu::util::DeviceExt;

use super::attachments::{cleared_color, cleared_depth};
use super::fiber_shading::ShadingModel;
use super::frame_params::FrameParams;
use super::render_target::DEPTH_FORMAT;
use super::shadow_slots::{HeadInput, ShadowInput, TooManyShadowMaps};
use super::sorted_blend::{IndexedStrandDraw, IndexedStrandGroups};
use super::strand_geometry::StrandGeometry;
use crate::gpu::bind_layout::{
    bind_group, pipeline_layout, storage_entry, texture_entry, uniform_entry,
};
use crate::gpu::pipeline::{compute_pipeline, depth_test, wgsl_module};
use crate::gpu::readback::{ReadbackError, read_buffer};
use crate::gpu::texture::texture_2d;
use crate::gpu::{GpuContext, GpuLimits, LimitError};
use crate::hair::HairModel;

/// Each subset's colour layer: half floats, as Hunz's RGBA16 layers (and blendable everywhere).
const SUBSET_COLOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

/// Hunz §6 renders 8 subsets.
pub const DEFAULT_SUBSETS: u32 = 8;
/// The resolve sorts a pixel's layers in registers.
pub const MAX_SUBSETS: u32 = 16;

#[derive(Debug, thiserror::Error)]
pub enum SubsetsError {
    #[error("random subsets {0}: must be 1..={MAX_SUBSETS}")]
    Count(u32),
    #[error(transparent)]
    Limit(#[from] LimitError),
    #[error(transparent)]
    TooManyShadowMaps(#[from] TooManyShadowMaps),
    #[error(transparent)]
    Readback(#[from] ReadbackError),
}

pub struct SubsetsFrame {
    pub pixels: Vec<[f32; 4]>,
    pub memory_bytes: Vec<(String, u64)>,
}

/// A resolved frame still on the GPU ([`RandomSubsetsPass::submit`]).
pub struct SubsetsOnGpu {
    /// Pre-multiplied RGBA f32 per pixel, row-major from the top.
    pub resolved: wgpu::Buffer,
    pub memory_bytes: Vec<(String, u64)>,
}

impl SubsetsOnGpu {
    /// The image, read back (waits for the GPU).
    pub fn read(self, gpu: &GpuContext) -> Result<SubsetsFrame, SubsetsError> {
        let image = read_buffer(gpu, &self.resolved)?;
        Ok(SubsetsFrame {
            pixels: bytemuck::cast_slice::<u8, [f32; 4]>(&image).to_vec(),
            memory_bytes: self.memory_bytes,
        })
    }
}

/// Strand `strand`'s subset among `subsets`: a fixed hash, so frames are repeatable.
pub fn subset_of(strand: usize, subsets: u32) -> u32 {
    // SplitMix64's finalizer.
    let mut z = (strand as u64).wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce5_e4b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    ((z ^ (z >> 31)) % subsets as u64) as u32
}

/// The segments grouped by subset, and where each subset's run starts (k + 1 bounds).
fn segments_by_subset(model: &HairModel, subsets: u32) -> (Vec<u32>, Vec<u32>) {
    let mut runs = vec![Vec::new(); subsets as usize];
    let mut segment = 0u32;
    for (strand, w) in model.strand_offsets().windows(2).enumerate() {
        let segments = w[1] - w[0] - 1;
        runs[subset_of(strand, subsets) as usize].extend(segment..segment + segments);
        segment += segments;
    }
    let mut bounds = vec![0u32];
    for run in &runs {
        bounds.push(bounds.last().unwrap() + run.len() as u32);
    }
    (runs.concat(), bounds)
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct ResolveParams {
    width: u32,
    height: u32,
    subsets: u32,
    _pad: u32,
}

pub struct RandomSubsetsPass {
    draw: IndexedStrandDraw,
    resolve: wgpu::ComputePipeline,
    resolve_layout: wgpu::BindGroupLayout,
}

impl RandomSubsetsPass {
    pub fn with_model(gpu: &GpuContext, shading: &ShadingModel) -> Self {
        let device = &gpu.device;
        // The sorted pass's draw reads segments through an index list: here, a subset's.
        let draw = IndexedStrandDraw::new(
            gpu,
            shading,
            "random subsets",
            SUBSET_COLOR_FORMAT,
            Some(depth_test(DEPTH_FORMAT, true, wgpu::CompareFunction::Less)),
        );
        let compute = wgpu::ShaderStages::COMPUTE;
        let resolve_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("random subsets resolve"),
            entries: &[
                texture_entry(
                    0,
                    compute,
                    wgpu::TextureSampleType::Float { filterable: false },
                    wgpu::TextureViewDimension::D2Array,
                ),
                texture_entry(
                    1,
                    compute,
                    wgpu::TextureSampleType::Depth,
                    wgpu::TextureViewDimension::D2Array,
                ),
                storage_entry(2, compute, false),
                uniform_entry(3, compute),
            ],
        });
        let resolve_shader = wgsl_module(
            device,
            "random_subsets_resolve.wgsl",
            include_str!("random_subsets_resolve.wgsl"),
        );
        let resolve = compute_pipeline(
            device,
            "random subsets resolve",
            &pipeline_layout(device, "random subsets resolve", &[Some(&resolve_layout)]),
            &resolve_shader,
            "resolve",
        );
        Self {
            draw,
            resolve,
            resolve_layout,
        }
    }

    /// `model`'s strands (uploaded as `geometry`) in `subsets` random subsets, composited and
    /// read back.
    #[allow(clippy::too_many_arguments)]
    pub fn draw(
        &self,
        gpu: &GpuContext,
        model: &HairModel,
        geometry: &StrandGeometry,
        frame: &FrameParams,
        shadows: &[ShadowInput<'_>],
        head: Option<HeadInput<'_>>,
        subsets: u32,
    ) -> Result<SubsetsFrame, SubsetsError> {
        self.submit(gpu, model, geometry, frame, shadows, head, subsets)?
            .read(gpu)
    }

    /// [`Self::draw`] submitted without waiting: the resolved image stays on the GPU.
    #[allow(clippy::too_many_arguments)]
    pub fn submit(
        &self,
        gpu: &GpuContext,
        model: &HairModel,
        geometry: &StrandGeometry,
        frame: &FrameParams,
        shadows: &[ShadowInput<'_>],
        head: Option<HeadInput<'_>>,
        subsets: u32,
    ) -> Result<SubsetsOnGpu, SubsetsError> {
        if !(1..=MAX_SUBSETS).contains(&subsets) {
            return Err(SubsetsError::Count(subsets));
        }
        let device = &gpu.device;
        let (width, height) = (frame.width, frame.height);
        let limits = GpuLimits::of(gpu);
        limits.check_texture_layers("random subset layers", subsets, |max| {
            format!("use at most {max} subsets")
        })?;
        let pixels = width as u64 * height as u64;
        limits.check_storage_buffer("resolved image", pixels * 16, |_| {
            "render a smaller image".into()
        })?;
        let (order, bounds) = segments_by_subset(model, subsets);
        let order = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("subset segments"),
            contents: bytemuck::cast_slice(if order.is_empty() { &[0u32] } else { &order }),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let layers = SubsetLayers::new(gpu, (width, height), subsets);
        let resolved = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("random subsets resolved"),
            size: pixels * 16,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let groups = self
            .draw
            .groups(gpu, geometry, frame, shadows, head, &order)?;
        let mut encoder = device.create_command_encoder(&Default::default());
        for subset in 0..subsets as usize {
            let segments = bounds[subset]..bounds[subset + 1];
            self.encode_subset(gpu, &mut encoder, &groups, &layers, subset as u32, segments);
        }
        self.encode_resolve(gpu, &mut encoder, &layers, &resolved);
        gpu.queue.submit([encoder.finish()]);
        let texel = SUBSET_COLOR_FORMAT.block_copy_size(None).unwrap_or(8) as u64;
        Ok(SubsetsOnGpu {
            memory_bytes: vec![
                ("subset colours".into(), pixels * subsets as u64 * texel),
                ("subset depths".into(), pixels * subsets as u64 * 4),
                ("subset segment lists".into(), order.size()),
                ("random subsets resolved image".into(), resolved.size()),
            ],
            resolved,
        })
    }

    /// Subset `subset` (its segments `segments` of the subset order) drawn depth-tested into
    /// its layer.
    fn encode_subset(
        &self,
        gpu: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        groups: &IndexedStrandGroups,
        layers: &SubsetLayers,
        subset: u32,
        segments: std::ops::Range<u32>,
    ) {
        let color_view = layer_view(&layers.colors, subset);
        let depth_view = layer_view(&layers.depths, subset);
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("random subset"),
            color_attachments: &[cleared_color(&color_view)],
            depth_stencil_attachment: cleared_depth(&depth_view, true),
            timestamp_writes: gpu.render_timestamps(),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        self.draw.record(&mut pass, groups, segments);
    }

    /// Every pixel's fragments of all the layers, sorted and composited into `resolved`.
    fn encode_resolve(
        &self,
        gpu: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        layers: &SubsetLayers,
        resolved: &wgpu::Buffer,
    ) {
        let device = &gpu.device;
        let (width, height) = (layers.colors.width(), layers.colors.height());
        let params = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("random subsets params"),
            contents: bytemuck::bytes_of(&ResolveParams {
                width,
                height,
                subsets: layers.colors.depth_or_array_layers(),
                _pad: 0,
            }),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let array_view = |texture: &wgpu::Texture| {
            texture.create_view(&wgpu::TextureViewDescriptor {
                dimension: Some(wgpu::TextureViewDimension::D2Array),
                ..Default::default()
            })
        };
        let (color_array, depth_array) = (array_view(&layers.colors), array_view(&layers.depths));
        let resolve_group = bind_group(
            device,
            "random subsets resolve",
            &self.resolve_layout,
            &[
                wgpu::BindingResource::TextureView(&color_array),
                wgpu::BindingResource::TextureView(&depth_array),
                resolved.as_entire_binding(),
                params.as_entire_binding(),
            ],
        );
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("random subsets resolve"),
            timestamp_writes: gpu.compute_timestamps(),
        });
        pass.set_pipeline(&self.resolve);
        pass.set_bind_group(0, &resolve_group, &[]);
        pass.dispatch_workgroups(width.div_ceil(8), height.div_ceil(8), 1);
    }
}

/// One colour and one depth layer per subset.
struct SubsetLayers {
    colors: wgpu::Texture,
    depths: wgpu::Texture,
}

impl SubsetLayers {
    fn new(gpu: &GpuContext, (width, height): (u32, u32), subsets: u32) -> Self {
        let size = wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: subsets,
        };
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING;
        Self {
            colors: texture_2d(gpu, "subset colours", size, SUBSET_COLOR_FORMAT, usage),
            depths: texture_2d(gpu, "subset depths", size, DEPTH_FORMAT, usage),
        }
    }
}

/// Layer `layer` of an array texture as a 2D attachment.
fn layer_view(texture: &wgpu::Texture, layer: u32) -> wgpu::TextureView {
    texture.create_view(&wgpu::TextureViewDescriptor {
        dimension: Some(wgpu::TextureViewDimension::D2),
        base_array_layer: layer,
        array_layer_count: Some(1),
        ..Default::default()
    })
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
                file: "random_subsets_resolve.wgsl",
                source: include_str!("random_subsets_resolve.wgsl"),
            },
            None,
            "ResolveParams",
            &rust_layout!(ResolveParams {
                width,
                height,
                subsets
            }),
        );
    }
}
