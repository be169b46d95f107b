//! A point-lit frame gathered into the sums the host's composite draws (`point_gather.wgsl`).
//!
//! Inputs: the frame a point-light technique left on the GPU (its colour in a target or a
//! buffer, the head's skin). Output: the [`FrameSums`]' single-scattering half holds the hair
//! over the skin, the multiple-scattering half zero, so one composite serves both lightings.

use crate::env::FrameSums;
use crate::gpu::GpuContext;
use crate::gpu::bind_layout::{
    bind_group, float_texture_entry, pipeline_layout, storage_entry, uniform_entry,
};
use crate::gpu::buffer::init_buffer;
use crate::gpu::pipeline::{compute_pipeline, wgsl_module};
use crate::gpu::texture::texture_2d;
use crate::point_frame::{ColourOnGpu, PointFrameOnGpu};

#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct GatherParams {
    width: u32,
    height: u32,
    hair_in_buffer: u32,
    has_skin: u32,
}

/// The gather pipeline, with what stands in for a binding the frame lacks.
pub(super) struct PointGatherPass {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    /// Bound where the hair is in a texture.
    no_buffer: wgpu::Buffer,
    /// Bound where the hair is in a buffer, or there is no skin.
    no_texture: wgpu::Texture,
}

impl PointGatherPass {
    pub(super) fn new(gpu: &GpuContext) -> Self {
        let device = &gpu.device;
        let compute = wgpu::ShaderStages::COMPUTE;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("point gather"),
            entries: &[
                storage_entry(0, compute, false),
                storage_entry(1, compute, true),
                float_texture_entry(2, compute),
                float_texture_entry(3, compute),
                uniform_entry(4, compute),
            ],
        });
        let shader = wgsl_module(
            device,
            "point_gather.wgsl",
            include_str!("point_gather.wgsl"),
        );
        let pipeline = compute_pipeline(
            device,
            "point gather",
            &pipeline_layout(device, "point gather", &[Some(&layout)]),
            &shader,
            "gather",
        );
        let no_buffer = init_buffer(
            device,
            "point gather: no hair buffer",
            &[0u8; 16],
            wgpu::BufferUsages::STORAGE,
        );
        let one = wgpu::Extent3d {
            width: 1,
            height: 1,
            depth_or_array_layers: 1,
        };
        let no_texture = texture_2d(
            gpu,
            "point gather: no texture",
            one,
            wgpu::TextureFormat::Rgba16Float,
            wgpu::TextureUsages::TEXTURE_BINDING,
        );
        Self {
            pipeline,
            layout,
            no_buffer,
            no_texture,
        }
    }

    /// Records the gather of `frame` into `sums` (the frame's size).
    pub(super) fn encode(
        &self,
        gpu: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        frame: &PointFrameOnGpu,
        sums: &FrameSums,
    ) {
        let [width, height] = sums.size();
        let (hair_buffer, hair_texture) = match frame.hair.on_gpu() {
            ColourOnGpu::Buffer(buffer) => (buffer, &self.no_texture),
            ColourOnGpu::Texture(texture) => (&self.no_buffer, texture),
        };
        let skin = frame.skin.as_ref().map_or(&self.no_texture, |s| &s.color);
        let params = GatherParams {
            width,
            height,
            hair_in_buffer: matches!(frame.hair.on_gpu(), ColourOnGpu::Buffer(_)) as u32,
            has_skin: frame.skin.is_some() as u32,
        };
        let params = init_buffer(
            &gpu.device,
            "point gather params",
            bytemuck::bytes_of(&params),
            wgpu::BufferUsages::UNIFORM,
        );
        let hair_view = hair_texture.create_view(&Default::default());
        let skin_view = skin.create_view(&Default::default());
        let group = bind_group(
            &gpu.device,
            "point gather",
            &self.layout,
            &[
                sums.buffer().as_entire_binding(),
                hair_buffer.as_entire_binding(),
                wgpu::BindingResource::TextureView(&hair_view),
                wgpu::BindingResource::TextureView(&skin_view),
                params.as_entire_binding(),
            ],
        );
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("point gather"),
            timestamp_writes: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &group, &[]);
        pass.dispatch_workgroups(width.div_ceil(8), height.div_ceil(8), 1);
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
                file: "point_gather.wgsl",
                source: include_str!("point_gather.wgsl"),
            },
            None,
            "GatherParams",
            &rust_layout!(GatherParams {
                width,
                height,
                hair_in_buffer,
                has_skin
            }),
        );
    }
}
