//! Bin-sorted back-to-front blending (Kim 2003, Svoboda §2.5): a compute counting sort orders the
//! segments by the view depth of their farther endpoint in `bins` equal bins
//! (`sorted_blend.wgsl`), then the segments are drawn in that order with pre-multiplied "over"
//! and no depth test (`sorted_blend_draw.wgsl`). Exact where no two segments of one bin overlap
//! in a pixel; otherwise their order within the bin is arbitrary.
//! Inputs: [`StrandGeometry`], [`FrameParams`], the hair's bounds, shadow maps. Output: the
//! colour texture of a [`RenderTarget`].

use wgpu::util::DeviceExt;

use super::attachments::cleared_color;
use super::fiber_shading::ShadingModel;
use super::frame_params::FrameParams;
use super::render_target::RenderTarget;
use super::shadow_slots::{HeadInput, ShadowInput, TooManyShadowMaps, shadow_bind_group_for};
use super::strand_geometry::StrandGeometry;
use super::strand_quads::strand_bind_group;
use super::strands::{ShadedStrandLayouts, strand_shading_module};
use crate::gpu::GpuContext;
use crate::gpu::bind_layout::{bind_group, pipeline_layout, storage_entry, uniform_entry};
use crate::gpu::pipeline::{
    PREMULTIPLIED_OVER, StrandDraw, color_target, compute_pipeline, wgsl_module,
};
use crate::hair::Aabb;
use crate::shaders::Wgsl;

/// Kim 2003 and Hunz use a few hundred depth bins.
pub const DEFAULT_SORT_BINS: u32 = 256;
pub const MAX_SORT_BINS: u32 = 65536;

const SORT_GROUP: u32 = 256;
const MAX_GROUPS_PER_DIMENSION: u32 = 65535;

#[derive(Debug, thiserror::Error, PartialEq)]
#[error("sort bins {0}: must be 1..={MAX_SORT_BINS}")]
pub struct BadSortBins(pub u32);

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct SortUniform {
    eye: [f32; 4],
    forward: [f32; 4],
    nearest: f32,
    farthest: f32,
    bins: u32,
    segment_count: u32,
}

/// The segments in back-to-front draw order, on the GPU.
pub struct SegmentOrder {
    order: wgpu::Buffer,
    bins: wgpu::Buffer,
}

impl SegmentOrder {
    pub fn memory(&self) -> Vec<(String, u64)> {
        vec![
            ("sorted segment order".into(), self.order.size()),
            ("sort bins".into(), self.bins.size()),
        ]
    }
}

pub struct SortedBlendPass {
    histogram: wgpu::ComputePipeline,
    scan: wgpu::ComputePipeline,
    scatter: wgpu::ComputePipeline,
    sort_layout: wgpu::BindGroupLayout,
    draw: IndexedStrandDraw,
}

impl SortedBlendPass {
    pub fn with_model(gpu: &GpuContext, shading: &ShadingModel) -> Self {
        let device = &gpu.device;
        let compute = wgpu::ShaderStages::COMPUTE;
        let sort_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("segment sort"),
            entries: &[
                uniform_entry(0, compute),
                storage_entry(1, compute, true),
                storage_entry(2, compute, true),
                storage_entry(3, compute, false),
                storage_entry(4, compute, false),
            ],
        });
        let sort_shader = wgsl_module(
            device,
            "sorted_blend.wgsl",
            include_str!("sorted_blend.wgsl"),
        );
        let sort_pipeline_layout = pipeline_layout(device, "segment sort", &[Some(&sort_layout)]);
        let stage =
            |entry| compute_pipeline(device, entry, &sort_pipeline_layout, &sort_shader, entry);
        let (histogram, scan, scatter) = (stage("histogram"), stage("scan"), stage("scatter"));

        let draw = IndexedStrandDraw::new(gpu, shading, "sorted blend", gpu.hdr_format(), None);
        Self {
            histogram,
            scan,
            scatter,
            sort_layout,
            draw,
        }
    }

    /// The segments of `geometry` ordered back to front for `frame`'s camera, in `bins` equal
    /// depth bins spanning `bounds` along the view axis.
    pub fn sort(
        &self,
        gpu: &GpuContext,
        geometry: &StrandGeometry,
        frame: &FrameParams,
        bounds: Aabb,
        bins: u32,
    ) -> Result<SegmentOrder, BadSortBins> {
        if !(1..=MAX_SORT_BINS).contains(&bins) {
            return Err(BadSortBins(bins));
        }
        let device = &gpu.device;
        let camera = &frame.camera;
        let forward = (camera.target - camera.eye).normalize();
        let depths = bounds.corners().map(|c| (c - camera.eye).dot(forward));
        let uniform = SortUniform {
            eye: camera.eye.extend(0.0).into(),
            forward: forward.extend(0.0).into(),
            nearest: depths.iter().copied().fold(f32::INFINITY, f32::min),
            farthest: depths.iter().copied().fold(f32::NEG_INFINITY, f32::max),
            bins,
            segment_count: geometry.segment_count,
        };
        let params = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("segment sort params"),
            contents: bytemuck::bytes_of(&uniform),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let bin_counts = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("sort bins"),
            contents: &vec![0u8; bins as usize * 4],
            usage: wgpu::BufferUsages::STORAGE,
        });
        let order = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("sorted segment order"),
            size: geometry.segment_count.max(1) as u64 * 4,
            usage: wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        });
        let group = bind_group(
            device,
            "segment sort",
            &self.sort_layout,
            &[
                params.as_entire_binding(),
                geometry.points.as_entire_binding(),
                geometry.segments.as_entire_binding(),
                bin_counts.as_entire_binding(),
                order.as_entire_binding(),
            ],
        );
        let groups = geometry.segment_count.div_ceil(SORT_GROUP);
        let (gx, gy) = (
            groups.clamp(1, MAX_GROUPS_PER_DIMENSION),
            groups.div_ceil(MAX_GROUPS_PER_DIMENSION).max(1),
        );
        let mut encoder = device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("segment sort"),
                timestamp_writes: gpu.compute_timestamps(),
            });
            pass.set_bind_group(0, &group, &[]);
            pass.set_pipeline(&self.histogram);
            pass.dispatch_workgroups(gx, gy, 1);
            pass.set_pipeline(&self.scan);
            pass.dispatch_workgroups(1, 1, 1);
            pass.set_pipeline(&self.scatter);
            pass.dispatch_workgroups(gx, gy, 1);
        }
        gpu.queue.submit([encoder.finish()]);
        Ok(SegmentOrder {
            order,
            bins: bin_counts,
        })
    }

    /// Clears `target` and blends every segment over it in `order`.
    #[allow(clippy::too_many_arguments)]
    pub fn draw(
        &self,
        gpu: &GpuContext,
        geometry: &StrandGeometry,
        frame: &FrameParams,
        shadows: &[ShadowInput<'_>],
        head: Option<HeadInput<'_>>,
        order: &SegmentOrder,
        target: &RenderTarget,
    ) -> Result<(), TooManyShadowMaps> {
        let groups = self
            .draw
            .groups(gpu, geometry, frame, shadows, head, &order.order)?;
        let color_view = target.color.create_view(&Default::default());
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("sorted blend"),
                color_attachments: &[cleared_color(&color_view)],
                depth_stencil_attachment: None,
                timestamp_writes: gpu.render_timestamps(),
                occlusion_query_set: None,
                multiview_mask: None,
            });
            self.draw
                .record(&mut pass, &groups, 0..geometry.segment_count);
        }
        gpu.queue.submit([encoder.finish()]);
        Ok(())
    }
}

/// The draw that sorted blending and random subsets share (`sorted_blend_draw.wgsl`): strand
/// quads whose segments come from an index list (group 3) rather than the instance index, shaded
/// with the pass's fiber model and blended pre-multiplied "over". The passes differ only in the
/// target's format, the depth test and which indices they draw.
pub(crate) struct IndexedStrandDraw {
    pipeline: wgpu::RenderPipeline,
    layouts: ShadedStrandLayouts,
    order_layout: wgpu::BindGroupLayout,
}

/// One frame's bind groups for an [`IndexedStrandDraw`].
pub(crate) struct IndexedStrandGroups {
    strands: wgpu::BindGroup,
    shadows: wgpu::BindGroup,
    order: wgpu::BindGroup,
}

impl IndexedStrandDraw {
    pub fn new(
        gpu: &GpuContext,
        shading: &ShadingModel,
        label: &str,
        format: wgpu::TextureFormat,
        depth: Option<wgpu::DepthStencilState>,
    ) -> Self {
        let device = &gpu.device;
        let layouts = ShadedStrandLayouts::new(gpu, shading);
        let order_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("segment order"),
            entries: &[storage_entry(0, wgpu::ShaderStages::VERTEX, true)],
        });
        let layout = layouts.pipeline_layout(device, label, Some(&order_layout));
        let top = Wgsl {
            file: "sorted_blend_draw.wgsl",
            source: include_str!("sorted_blend_draw.wgsl"),
        };
        let shader = strand_shading_module(device, &top, shading);
        let pipeline = StrandDraw {
            label,
            layout: &layout,
            shader: &shader,
            vertex_entry: "vs_sorted",
            fragment: Some(("fs_main", &[color_target(format, Some(PREMULTIPLIED_OVER))])),
            depth,
        }
        .build(device);
        Self {
            pipeline,
            layouts,
            order_layout,
        }
    }

    /// The groups that draw `geometry` in `frame`, segment `order[i]` as instance i.
    pub fn groups(
        &self,
        gpu: &GpuContext,
        geometry: &StrandGeometry,
        frame: &FrameParams,
        shadows: &[ShadowInput<'_>],
        head: Option<HeadInput<'_>>,
        order: &wgpu::Buffer,
    ) -> Result<IndexedStrandGroups, TooManyShadowMaps> {
        Ok(IndexedStrandGroups {
            strands: strand_bind_group(gpu, &self.layouts.strand, geometry, frame),
            shadows: shadow_bind_group_for(gpu, &self.layouts.shadow, frame, shadows, head)?,
            order: bind_group(
                &gpu.device,
                "segment order",
                &self.order_layout,
                &[order.as_entire_binding()],
            ),
        })
    }

    /// Draws the segments listed at `positions` of the order into `pass`.
    pub fn record(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        groups: &IndexedStrandGroups,
        positions: std::ops::Range<u32>,
    ) {
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &groups.strands, &[]);
        pass.set_bind_group(1, &groups.shadows, &[]);
        if let Some(model) = &self.layouts.model {
            pass.set_bind_group(2, &model.group, &[]);
        }
        pass.set_bind_group(3, &groups.order, &[]);
        pass.draw(0..6, positions);
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
                file: "sorted_blend.wgsl",
                source: include_str!("sorted_blend.wgsl"),
            },
            None,
            "SortParams",
            &rust_layout!(SortUniform {
                eye,
                forward,
                nearest,
                farthest,
                bins,
                segment_count
            }),
        );
    }
}
