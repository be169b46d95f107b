//! The strand pass: every hair segment drawn as a camera-facing quad, shaded under several
//! lights with a [`ShadingModel`] (Kajiya-Kay, Marschner through lookup tables, artist-friendly),
//! blended with pre-multiplied alpha into an HDR float target with a depth test.
//! Inputs: [`StrandGeometry`] (the hair on the GPU), [`FrameParams`] (camera, shading constants,
//! lights), the shadow maps ([`ShadowInput`]). Output: the colour texture of a [`RenderTarget`].

use super::attachments::{cleared_color, cleared_depth};
use super::fiber_shading::{ModelBinding, ShadingModel};
use super::frame_params::FrameParams;
use super::render_target::{DEPTH_FORMAT, RenderTarget};
use super::shadow_slots::{
    HeadInput, ShadowInput, TooManyShadowMaps, shadow_bind_group_for, shadow_bind_group_layout,
};
use super::strand_geometry::StrandGeometry;
use super::strand_quads::{strand_bind_group, strand_bind_group_layout};
use crate::gpu::GpuContext;
use crate::gpu::bind_layout::pipeline_layout;
use crate::gpu::pipeline::{PREMULTIPLIED_OVER, StrandDraw, color_target, depth_test};
use crate::shaders::{Wgsl, shader_module};

/// The compiled pipeline; reusable across frames and models.
pub struct StrandPass {
    pipeline: wgpu::RenderPipeline,
    layouts: ShadedStrandLayouts,
}

impl StrandPass {
    /// Kajiya-Kay shading with the constants of [`FrameParams::shading`].
    pub fn new(gpu: &GpuContext) -> Self {
        Self::with_model(gpu, &ShadingModel::KajiyaKay)
    }

    /// Shading with `model`; its tables and constants are uploaded once, here.
    pub fn with_model(gpu: &GpuContext, model: &ShadingModel) -> Self {
        let targets = [color_target(gpu.hdr_format(), Some(PREMULTIPLIED_OVER))];
        let (pipeline, layouts) = strand_quads_pipeline(gpu, model, "strands", Some(&targets));
        Self { pipeline, layouts }
    }

    /// Clears the target to transparent black and draws every segment.
    pub fn draw(
        &self,
        gpu: &GpuContext,
        geometry: &StrandGeometry,
        frame: &FrameParams,
        target: &RenderTarget,
        shadow: Option<ShadowInput<'_>>,
    ) {
        self.draw_shadowed(gpu, geometry, frame, target, shadow.as_slice(), None)
            .expect("one shadow map is within the limit");
    }

    /// [`StrandPass::draw`] with a deep opacity map for each of up to [`MAX_SHADOWED_LIGHTS`](super::shadow_slots::MAX_SHADOWED_LIGHTS)
    /// lights, and the head hiding and shadowing fibers.
    pub fn draw_shadowed(
        &self,
        gpu: &GpuContext,
        geometry: &StrandGeometry,
        frame: &FrameParams,
        target: &RenderTarget,
        shadows: &[ShadowInput<'_>],
        head: Option<HeadInput<'_>>,
    ) -> Result<(), TooManyShadowMaps> {
        let device = &gpu.device;
        let shadow_group = shadow_bind_group_for(gpu, &self.layouts.shadow, frame, shadows, head)?;
        let bind_group = strand_bind_group(gpu, &self.layouts.strand, geometry, frame);
        let color_view = target.color.create_view(&Default::default());
        let depth_view = target.depth.create_view(&Default::default());
        let mut encoder = device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("strands"),
                color_attachments: &[cleared_color(&color_view)],
                depth_stencil_attachment: cleared_depth(&depth_view, true),
                timestamp_writes: gpu.render_timestamps(),
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &bind_group, &[]);
            pass.set_bind_group(1, &shadow_group, &[]);
            if let Some(model) = &self.layouts.model {
                pass.set_bind_group(2, &model.group, &[]);
            }
            pass.draw(0..6, 0..geometry.segment_count);
        }
        gpu.queue.submit([encoder.finish()]);
        Ok(())
    }
}

/// The strands' depth alone, the nearest fiber per pixel, tested and written into a depth the
/// caller keeps: a host depth-tests a point-lit frame against it whichever technique drew the
/// colour (the transparency techniques keep no depth of their own). The same quads as
/// [`StrandPass`], so the depth is the one the opaque frame's colour was drawn at.
pub struct StrandDepthPass {
    pipeline: wgpu::RenderPipeline,
    layouts: ShadedStrandLayouts,
}

impl StrandDepthPass {
    /// The quads of [`StrandPass::with_model`], whose module `model` completes.
    pub fn with_model(gpu: &GpuContext, model: &ShadingModel) -> Self {
        let (pipeline, layouts) = strand_quads_pipeline(gpu, model, "strand depth", None);
        Self { pipeline, layouts }
    }

    /// Draws every segment's depth into `depth` (a [`DEPTH_FORMAT`] view), over what it holds.
    #[allow(clippy::too_many_arguments)]
    pub fn encode(
        &self,
        gpu: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        geometry: &StrandGeometry,
        frame: &FrameParams,
        shadows: &[ShadowInput<'_>],
        head: Option<HeadInput<'_>>,
        depth: &wgpu::TextureView,
    ) -> Result<(), TooManyShadowMaps> {
        let shadow_group = shadow_bind_group_for(gpu, &self.layouts.shadow, frame, shadows, head)?;
        let bind_group = strand_bind_group(gpu, &self.layouts.strand, geometry, frame);
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("strand depth"),
            color_attachments: &[],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: depth,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Load,
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &bind_group, &[]);
        pass.set_bind_group(1, &shadow_group, &[]);
        if let Some(model) = &self.layouts.model {
            pass.set_bind_group(2, &model.group, &[]);
        }
        pass.draw(0..6, 0..geometry.segment_count);
        Ok(())
    }
}

/// The strand quads of `strands.wgsl` (its module completed by `model`), depth-tested and
/// written, into `targets` with `fs_main`, or depth alone without targets.
fn strand_quads_pipeline(
    gpu: &GpuContext,
    model: &ShadingModel,
    label: &str,
    targets: Option<&[Option<wgpu::ColorTargetState>]>,
) -> (wgpu::RenderPipeline, ShadedStrandLayouts) {
    let device = &gpu.device;
    let top = Wgsl {
        file: "strands.wgsl",
        source: include_str!("strands.wgsl"),
    };
    let shader = strand_shading_module(device, &top, model);
    let layouts = ShadedStrandLayouts::new(gpu, model);
    let pipeline_layout = layouts.pipeline_layout(device, label, None);
    let pipeline = StrandDraw {
        label,
        layout: &pipeline_layout,
        shader: &shader,
        vertex_entry: "vs_main",
        fragment: targets.map(|targets| ("fs_main", targets)),
        depth: Some(depth_test(DEPTH_FORMAT, true, wgpu::CompareFunction::Less)),
    }
    .build(device);
    (pipeline, layouts)
}

/// The bind group layouts of a pass that shades strand quads under point lights: the strands
/// (group 0), their shadow maps (1), the fiber model's constants and tables (2; none for
/// Kajiya-Kay), then what the pass adds (3).
pub(crate) struct ShadedStrandLayouts {
    pub strand: wgpu::BindGroupLayout,
    pub shadow: wgpu::BindGroupLayout,
    pub model: Option<ModelBinding>,
}

impl ShadedStrandLayouts {
    /// The layouts for `shading`, its tables and constants uploaded once, here.
    pub fn new(gpu: &GpuContext, shading: &ShadingModel) -> Self {
        Self {
            strand: strand_bind_group_layout(&gpu.device),
            shadow: shadow_bind_group_layout(&gpu.device),
            model: ModelBinding::new(gpu, shading),
        }
    }

    /// The pipeline layout of groups 0–2 and the pass's own group 3, if it has one.
    pub fn pipeline_layout(
        &self,
        device: &wgpu::Device,
        label: &str,
        own: Option<&wgpu::BindGroupLayout>,
    ) -> wgpu::PipelineLayout {
        let mut groups = vec![
            Some(&self.strand),
            Some(&self.shadow),
            self.model.as_ref().map(|m| &m.layout),
            own,
        ];
        while groups.last() == Some(&None) {
            groups.pop();
        }
        pipeline_layout(device, label, &groups)
    }
}

/// The shader of a pass that shades strand quads with `model`: `top` (the pass's own entry
/// points) composed with `strand_shading.wgsl`'s `shade` and its shadow group 1, and the model's
/// `fiber_radiance` (group 2).
pub(crate) fn strand_shading_module(
    device: &wgpu::Device,
    top: &Wgsl,
    model: &ShadingModel,
) -> wgpu::ShaderModule {
    shader_module(device, top, Some(&model.wgsl()))
}
