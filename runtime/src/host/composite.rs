//! The pass that draws a frame's sums into a host's render pass (`composite.wgsl`).
//!
//! Inputs: a [`FrameSums`] with its front depth, the radiance scale. Output: one full-screen
//! triangle in the host's pass, pre-multiplied "over" its colour, depth-tested against its depth
//! at the frame's front depth (and writing it, so what the host draws later is hidden behind the
//! hair too).

use super::HairTargets;
use crate::env::FrameSums;
use crate::gpu::bind_layout::{
    bind_group, depth_texture_entry, pipeline_layout, storage_entry, uniform_entry,
};
use crate::gpu::buffer::init_buffer;
use crate::gpu::pipeline::{PREMULTIPLIED_OVER, color_target, depth_test, wgsl_module};

#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct CompositeParams {
    width: u32,
    height: u32,
    scale: f32,
    _pad: u32,
}

/// The composite pipeline for one set of host targets.
pub(super) struct CompositePass {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
}

/// What one frame's composite binds: its sums, front depth and scale.
pub(super) struct CompositeBinding {
    group: wgpu::BindGroup,
    params: wgpu::Buffer,
    size: [u32; 2],
}

impl CompositePass {
    pub(super) fn new(device: &wgpu::Device, targets: &HairTargets) -> Self {
        let fragment = wgpu::ShaderStages::FRAGMENT;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("hair composite"),
            entries: &[
                storage_entry(0, fragment, true),
                depth_texture_entry(1, fragment),
                uniform_entry(2, fragment),
            ],
        });
        let shader = wgsl_module(device, "composite.wgsl", include_str!("composite.wgsl"));
        let (entry, depth_stencil) = match targets.depth {
            Some(format) => (
                "fs_depth_tested",
                Some(depth_test(format, true, wgpu::CompareFunction::Less)),
            ),
            None => ("fs_over", None),
        };
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("hair composite"),
            layout: Some(&pipeline_layout(device, "hair composite", &[Some(&layout)])),
            vertex: wgpu::VertexState {
                module: &shader,
                entry_point: Some("vs_fullscreen"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            fragment: Some(wgpu::FragmentState {
                module: &shader,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                targets: &[color_target(targets.color, Some(PREMULTIPLIED_OVER))],
            }),
            primitive: Default::default(),
            depth_stencil,
            multisample: wgpu::MultisampleState {
                count: targets.sample_count,
                ..Default::default()
            },
            multiview_mask: None,
            cache: None,
        });
        Self { pipeline, layout }
    }

    /// The binding of `sums`, whose front depth it reads.
    pub(super) fn bind(&self, device: &wgpu::Device, sums: &FrameSums) -> CompositeBinding {
        let [width, height] = sums.size();
        let params = CompositeParams {
            width,
            height,
            scale: 1.0,
            _pad: 0,
        };
        let params = init_buffer(
            device,
            "hair composite params",
            bytemuck::bytes_of(&params),
            wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        );
        let depth = sums
            .front_depth()
            .expect("the host's sums keep a front depth")
            .create_view(&Default::default());
        let group = bind_group(
            device,
            "hair composite",
            &self.layout,
            &[
                sums.buffer().as_entire_binding(),
                wgpu::BindingResource::TextureView(&depth),
                params.as_entire_binding(),
            ],
        );
        CompositeBinding {
            group,
            params,
            size: [width, height],
        }
    }

    /// Draws `binding`'s frame into `pass` (one triangle over the whole target).
    pub(super) fn draw(&self, pass: &mut wgpu::RenderPass<'_>, binding: &CompositeBinding) {
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &binding.group, &[]);
        pass.draw(0..3, 0..1);
    }
}

impl CompositeBinding {
    /// Radiance is multiplied by `scale` as it is drawn (an exposure; a progressive frame's
    /// share of the power drawn so far).
    pub(super) fn set_scale(&self, queue: &wgpu::Queue, scale: f32) {
        let [width, height] = self.size;
        let params = CompositeParams {
            width,
            height,
            scale,
            _pad: 0,
        };
        queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&params));
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
                file: "composite.wgsl",
                source: include_str!("composite.wgsl"),
            },
            None,
            "CompositeParams",
            &rust_layout!(CompositeParams {
                width,
                height,
                scale
            }),
        );
    }
}
