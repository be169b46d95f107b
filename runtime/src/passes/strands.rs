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
    ShadowInput, TooManyShadowMaps, shadow_bind_group_for, shadow_bind_group_layout,
};
use super::strand_geometry::StrandGeometry;
use super::strand_quads::{strand_bind_group, strand_bind_group_layout};
use crate::gpu::GpuContext;

/// The compiled pipeline; reusable across frames and models.
pub struct StrandPass {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    shadow_layout: wgpu::BindGroupLayout,
    /// Group 2: the fiber model's constants and tables (none for Kajiya-Kay).
    model: Option<ModelBinding>,
}

impl StrandPass {
    /// Kajiya-Kay shading with the constants of [`FrameParams::shading`].
    pub fn new(gpu: &GpuContext) -> Self {
        Self::with_model(gpu, &ShadingModel::KajiyaKay)
    }

    /// Shading with `model`; its tables and constants are uploaded once, here.
    pub fn with_model(gpu: &GpuContext, model: &ShadingModel) -> Self {
        let device = &gpu.device;
        let source = shading_source(model, "");
        let shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("strands.wgsl"),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
        let layout = strand_bind_group_layout(device);
        let shadow_layout = shadow_bind_group_layout(device);
        let model = ModelBinding::new(gpu, model);
        let mut group_layouts = vec![Some(&layout), Some(&shadow_layout)];
        if let Some(m) = &model {
            group_layouts.push(Some(&m.layout));
        }
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("strands"),
            bind_group_layouts: &group_layouts,
            immediate_size: 0,
        });
        let premultiplied_over = wgpu::BlendComponent {
            src_factor: wgpu::BlendFactor::One,
            dst_factor: wgpu::BlendFactor::OneMinusSrcAlpha,
            operation: wgpu::BlendOperation::Add,
        };
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("strands"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &shader,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            fragment: Some(wgpu::FragmentState {
                module: &shader,
                entry_point: Some("fs_main"),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState {
                    format: gpu.hdr_format(),
                    blend: Some(wgpu::BlendState {
                        color: premultiplied_over,
                        alpha: premultiplied_over,
                    }),
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            primitive: wgpu::PrimitiveState {
                topology: wgpu::PrimitiveTopology::TriangleList,
                cull_mode: None,
                ..Default::default()
            },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: DEPTH_FORMAT,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Less),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            multiview_mask: None,
            cache: None,
        });
        Self {
            pipeline,
            layout,
            shadow_layout,
            model,
        }
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
        self.draw_shadowed(gpu, geometry, frame, target, shadow.as_slice())
            .expect("one shadow map is within the limit");
    }

    /// [`StrandPass::draw`] with a deep opacity map for each of up to [`MAX_SHADOWED_LIGHTS`]
    /// lights.
    pub fn draw_shadowed(
        &self,
        gpu: &GpuContext,
        geometry: &StrandGeometry,
        frame: &FrameParams,
        target: &RenderTarget,
        shadows: &[ShadowInput<'_>],
    ) -> Result<(), TooManyShadowMaps> {
        let device = &gpu.device;
        let shadow_group = shadow_bind_group_for(gpu, &self.shadow_layout, frame, shadows)?;
        let bind_group = strand_bind_group(gpu, &self.layout, geometry, frame);
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
            if let Some(model) = &self.model {
                pass.set_bind_group(2, &model.group, &[]);
            }
            pass.draw(0..6, 0..geometry.segment_count);
        }
        gpu.queue.submit([encoder.finish()]);
        Ok(())
    }
}

/// The WGSL of a pass that shades strand quads with `model`: the quads, `shade` with its shadow
/// group 1, the model's `fiber_radiance` (group 2), then `tail` (the pass's own entry points).
pub(crate) fn shading_source(model: &ShadingModel, tail: &str) -> String {
    [
        include_str!("strand_quads.wgsl"),
        include_str!("strands.wgsl"),
        model.wgsl(),
        tail,
    ]
    .concat()
}
