//! The head in the point-lit frame (issue 40; `point_skin.wgsl`, `head.wgsl`): its depth drawn
//! into each shadowed light's faces (the strand passes' group 1 then blocks the light behind it)
//! and from the frame's camera (they drop the fibers behind it), and its skin shaded as a
//! Lambertian surface under the same lights and maps.
//! Inputs: a [`Head`], the frame, the lights' maps ([`ShadowInput`]). Outputs: [`PointHead`]
//! (bound as [`HeadInput`]) and the skin's pre-multiplied colour (alpha 1 on the head).

use wgpu::util::DeviceExt;

use super::fiber_shading::ShadingModel;
use super::frame_params::FrameParams;
use super::head::{HeadDepthMaps, HeadGeometry, HeadPass};
use super::render_target::NEAREST_SURFACE_FORMAT;
use super::render_target::{DEPTH_FORMAT, RenderTarget};
use super::shadow_slots::{
    HeadInput, ShadowInput, TooManyShadowMaps, shadow_bind_group_for, shadow_bind_group_layout,
};
use super::strand_geometry::StrandGeometry;
use super::strand_quads::{strand_bind_group, strand_bind_group_layout};
use super::strands::strand_shading_module;
use crate::camera::Camera;
use crate::gpu::GpuContext;
use crate::gpu::bind_layout::{bind_group, float_texture_entry, pipeline_layout, uniform_entry};
use crate::gpu::pipeline::color_target;
use crate::gpu::texture::texture_2d;
use crate::head::Head;
use crate::shaders::Wgsl;

/// One frame's head on the GPU: its triangles, its depth in the lights' faces and its view.
pub struct PointHead {
    geometry: HeadGeometry,
    /// The shadowed lights' faces in slot order ([`HeadInput::light_depth`]); none unshadowed.
    light_depth: Option<HeadDepthMaps>,
    view_depth: wgpu::Texture,
    /// World position (w = 1 on the head) and normal per pixel.
    surface: [wgpu::Texture; 2],
}

impl PointHead {
    /// What the strand passes bind.
    pub fn input(&self) -> HeadInput<'_> {
        HeadInput {
            light_depth: self.light_depth.as_ref(),
            view_depth: &self.view_depth,
        }
    }

    pub fn memory(&self) -> Vec<(String, u64)> {
        let view_bytes = self.view_depth.width() as u64 * self.view_depth.height() as u64;
        let mut memory = vec![
            ("head geometry".to_string(), self.geometry.bytes()),
            // Depth32Float and two Rgba32Float targets.
            ("head view".to_string(), view_bytes * (4 + 2 * 16)),
        ];
        if let Some(maps) = &self.light_depth {
            memory.push(("head light depth".to_string(), maps.memory()));
        }
        memory
    }
}

/// The head's pipelines: its depth and surface (`head.wgsl`) and the skin's shading.
pub struct PointSkinPass {
    head: HeadPass,
    skin: wgpu::RenderPipeline,
    strand_layout: wgpu::BindGroupLayout,
    shadow_layout: wgpu::BindGroupLayout,
    surface_layout: wgpu::BindGroupLayout,
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct SkinUniform {
    albedo: [f32; 4],
}

impl PointSkinPass {
    pub fn new(gpu: &GpuContext) -> Self {
        let device = &gpu.device;
        // The skin reads the lights and maps as the fibers do; the module needs some fiber model
        // to compile `shade`, and Kajiya-Kay binds nothing (group 2 stays empty).
        let top = Wgsl {
            file: "point_skin.wgsl",
            source: include_str!("point_skin.wgsl"),
        };
        let shader = strand_shading_module(device, &top, &ShadingModel::KajiyaKay);
        let strand_layout = strand_bind_group_layout(device);
        let shadow_layout = shadow_bind_group_layout(device);
        let fragment = wgpu::ShaderStages::FRAGMENT;
        let surface_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("skin surface"),
            entries: &[
                float_texture_entry(0, fragment),
                float_texture_entry(1, fragment),
                uniform_entry(2, fragment),
            ],
        });
        let layout = pipeline_layout(
            device,
            "skin",
            &[
                Some(&strand_layout),
                Some(&shadow_layout),
                None,
                Some(&surface_layout),
            ],
        );
        let skin = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("skin"),
            layout: Some(&layout),
            vertex: wgpu::VertexState {
                module: &shader,
                entry_point: Some("vs_skin"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            fragment: Some(wgpu::FragmentState {
                module: &shader,
                entry_point: Some("fs_skin"),
                compilation_options: Default::default(),
                targets: &[color_target(gpu.hdr_format(), None)],
            }),
            primitive: Default::default(),
            depth_stencil: None,
            multisample: Default::default(),
            multiview_mask: None,
            cache: None,
        });
        Self {
            head: HeadPass::new(gpu),
            skin,
            strand_layout,
            shadow_layout,
            surface_layout,
        }
    }

    /// Uploads `head` and draws its depth into every face of `shadows`' maps (in slot order)
    /// and from `frame`'s camera.
    pub fn prepare(
        &self,
        gpu: &GpuContext,
        head: &Head,
        frame: &FrameParams,
        shadows: &[ShadowInput<'_>],
    ) -> PointHead {
        let geometry = HeadGeometry::upload(gpu, head);
        let faces: Vec<Camera> = shadows.iter().flat_map(|s| s.map.layout.faces()).collect();
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        let light_depth = shadows.first().map(|first| {
            let maps = HeadDepthMaps::new(gpu, first.map.settings.resolution, faces.len() as u32);
            self.head
                .encode_light_depths(gpu, &mut encoder, &geometry, &faces, &maps);
            maps
        });
        let size = wgpu::Extent3d {
            width: frame.width,
            height: frame.height,
            depth_or_array_layers: 1,
        };
        let read = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING;
        // COPY_SRC: a host's front depth starts from it (`point_frame::submit_frame`).
        let view_depth = texture_2d(
            gpu,
            "head view depth",
            size,
            DEPTH_FORMAT,
            read | wgpu::TextureUsages::COPY_SRC,
        );
        let surface = ["head view position", "head view normal"]
            .map(|label| texture_2d(gpu, label, size, NEAREST_SURFACE_FORMAT, read));
        let views = surface
            .each_ref()
            .map(|t| t.create_view(&Default::default()));
        self.head.encode_view(
            gpu,
            &mut encoder,
            Some(&geometry),
            &frame.camera,
            (frame.width, frame.height),
            &view_depth.create_view(&Default::default()),
            [&views[0], &views[1]],
        );
        gpu.queue.submit([encoder.finish()]);
        PointHead {
            geometry,
            light_depth,
            view_depth,
            surface,
        }
    }

    /// The skin of `head` under `frame`'s lights into a fresh target: pre-multiplied, alpha 1
    /// on the head and 0 elsewhere.
    pub fn shade(
        &self,
        gpu: &GpuContext,
        strands: &StrandGeometry,
        frame: &FrameParams,
        shadows: &[ShadowInput<'_>],
        head: &PointHead,
    ) -> Result<RenderTarget, TooManyShadowMaps> {
        let device = &gpu.device;
        let shadow_group =
            shadow_bind_group_for(gpu, &self.shadow_layout, frame, shadows, Some(head.input()))?;
        let strand_group = strand_bind_group(gpu, &self.strand_layout, strands, frame);
        let albedo = head.geometry.albedo;
        let params = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("skin params"),
            contents: bytemuck::bytes_of(&SkinUniform {
                albedo: [albedo[0], albedo[1], albedo[2], 0.0],
            }),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let surface_views = head
            .surface
            .each_ref()
            .map(|t| t.create_view(&Default::default()));
        let surface_group = bind_group(
            device,
            "skin surface",
            &self.surface_layout,
            &[
                wgpu::BindingResource::TextureView(&surface_views[0]),
                wgpu::BindingResource::TextureView(&surface_views[1]),
                params.as_entire_binding(),
            ],
        );
        let target = RenderTarget::new(gpu, frame.width, frame.height);
        let color_view = target.color.create_view(&Default::default());
        let mut encoder = device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("skin"),
                color_attachments: &[super::attachments::cleared_color(&color_view)],
                depth_stencil_attachment: None,
                timestamp_writes: gpu.render_timestamps(),
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&self.skin);
            pass.set_bind_group(0, &strand_group, &[]);
            pass.set_bind_group(1, &shadow_group, &[]);
            pass.set_bind_group(3, &surface_group, &[]);
            pass.draw(0..3, 0..1);
        }
        gpu.queue.submit([encoder.finish()]);
        Ok(target)
    }
}

/// Pre-multiplied `hair` over `skin`, pixel by pixel: the fibers left in front of the head
/// composite over it (where there is no head the skin is transparent and the hair stays).
pub fn composite_over(hair: &mut [[f32; 4]], skin: &[[f32; 4]]) {
    for (h, s) in hair.iter_mut().zip(skin) {
        let behind = 1.0 - h[3];
        for k in 0..4 {
            h[k] += behind * s[k];
        }
    }
}

#[cfg(test)]
mod wgsl_layout {
    use super::*;
    use crate::shader_layout::{assert_same_layout, rust_layout};
    use crate::shaders::Wgsl;

    /// Any fiber model composes the strand shading module; Kajiya-Kay binds nothing.
    const KAJIYA_KAY: Wgsl = Wgsl {
        file: "fiber_kajiya_kay.wgsl",
        source: include_str!("fiber_kajiya_kay.wgsl"),
    };

    #[test]
    fn uploaded_structs_are_laid_out_as_the_wgsl_reads_them() {
        assert_same_layout(
            &Wgsl {
                file: "point_skin.wgsl",
                source: include_str!("point_skin.wgsl"),
            },
            Some(&KAJIYA_KAY),
            "SkinParams",
            &rust_layout!(SkinUniform { albedo }),
        );
    }
}
