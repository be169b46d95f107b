//! The head's passes in the env-lit frame (`head.wgsl`): the view pass writes its depth into the
//! frame's depth (before the hair's prepass, which then keeps only fibers in front of it) and
//! its world position and normal into two textures the deferred view pass shades as skin; the
//! light pass draws it into one depth map per light slot with the slot's light-map camera.
//! Inputs: [`HeadGeometry`] (uploaded once per frame), a camera. Outputs: the view's head
//! textures, [`HeadDepthMaps`].

use glam::Mat4;
use wgpu::util::DeviceExt;

use super::attachments::cleared_depth;
use super::render_target::DEPTH_FORMAT;
use super::render_target::NEAREST_SURFACE_FORMAT;
use crate::camera::Camera;
use crate::gpu::GpuContext;
use crate::gpu::bind_layout::{pipeline_layout, uniform_entry};
use crate::gpu::pipeline::{color_target, depth_test, wgsl_module};
use crate::gpu::texture::texture_2d;
use crate::head::Head;

/// The light-map format of the head's depth (the DODM's nearest depth is the same).
pub const HEAD_DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;

/// The head's triangles on the GPU: interleaved position and normal, and a u32 index list.
#[derive(Clone)]
pub struct HeadGeometry {
    vertices: wgpu::Buffer,
    indices: wgpu::Buffer,
    index_count: u32,
    /// Linear RGB skin albedo.
    pub albedo: [f32; 3],
}

impl HeadGeometry {
    pub fn upload(gpu: &GpuContext, head: &Head) -> Self {
        let mesh = head.triangles();
        let interleaved: Vec<[f32; 6]> = mesh
            .positions
            .iter()
            .zip(&mesh.normals)
            .map(|(p, n)| [p.x, p.y, p.z, n.x, n.y, n.z])
            .collect();
        let buffer = |label, contents: &[u8], usage| {
            gpu.device
                .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some(label),
                    contents,
                    usage,
                })
        };
        Self {
            vertices: buffer(
                "head vertices",
                bytemuck::cast_slice(&interleaved),
                wgpu::BufferUsages::VERTEX,
            ),
            indices: buffer(
                "head indices",
                bytemuck::cast_slice(&mesh.indices),
                wgpu::BufferUsages::INDEX,
            ),
            index_count: mesh.indices.len() as u32,
            albedo: head.albedo,
        }
    }

    pub fn bytes(&self) -> u64 {
        self.vertices.size() + self.indices.size()
    }

    fn draw(&self, pass: &mut wgpu::RenderPass<'_>) {
        pass.set_vertex_buffer(0, self.vertices.slice(..));
        pass.set_index_buffer(self.indices.slice(..), wgpu::IndexFormat::Uint32);
        pass.draw_indexed(0..self.index_count, 0, 0..1);
    }
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct HeadCameraUniform {
    view_proj: [[f32; 4]; 4],
    eye: [f32; 4],
    toward_eye: [f32; 4],
}

impl HeadCameraUniform {
    fn of(camera: &Camera, aspect: f32) -> Self {
        let view_proj: Mat4 = camera.projection_matrix(aspect) * camera.view();
        Self {
            view_proj: view_proj.to_cols_array_2d(),
            eye: camera
                .eye
                .extend(if camera.is_perspective() { 1.0 } else { 0.0 })
                .into(),
            toward_eye: camera.toward_eye().extend(0.0).into(),
        }
    }
}

/// One light batch's head depth: an `R32Float` array (one layer per slot, 1 where the head is
/// not drawn) and the depth attachment its draws test against.
pub struct HeadDepthMaps {
    pub depth: wgpu::Texture,
    scratch: wgpu::Texture,
}

impl HeadDepthMaps {
    pub fn new(gpu: &GpuContext, resolution: u32, slots: u32) -> Self {
        let size = |layers| wgpu::Extent3d {
            width: resolution,
            height: resolution,
            depth_or_array_layers: layers,
        };
        Self {
            depth: texture_2d(
                gpu,
                "head light depth",
                size(slots),
                HEAD_DEPTH_FORMAT,
                wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            ),
            scratch: texture_2d(
                gpu,
                "head light depth test",
                size(1),
                DEPTH_FORMAT,
                wgpu::TextureUsages::RENDER_ATTACHMENT,
            ),
        }
    }

    /// A 1×1 single-layer map for frames without a head (bound, never read).
    pub fn placeholder(gpu: &GpuContext) -> Self {
        Self::new(gpu, 1, 1)
    }

    pub fn array_view(&self) -> wgpu::TextureView {
        self.depth.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        })
    }

    pub fn memory(&self) -> u64 {
        let texels = |t: &wgpu::Texture| {
            t.width() as u64 * t.height() as u64 * t.depth_or_array_layers() as u64 * 4
        };
        texels(&self.depth) + texels(&self.scratch)
    }
}

/// The two head pipelines.
pub struct HeadPass {
    surface: wgpu::RenderPipeline,
    light_depth: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
}

const VERTEX_ATTRIBUTES: [wgpu::VertexAttribute; 2] =
    wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3];

impl HeadPass {
    pub fn new(gpu: &GpuContext) -> Self {
        let device = &gpu.device;
        let shader = wgsl_module(device, "head.wgsl", include_str!("head.wgsl"));
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("head camera"),
            entries: &[uniform_entry(
                0,
                wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT,
            )],
        });
        let pipeline_layout = pipeline_layout(device, "head", &[Some(&layout)]);
        let pipeline = |label, entry, targets: &[Option<wgpu::ColorTargetState>]| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(label),
                layout: Some(&pipeline_layout),
                vertex: wgpu::VertexState {
                    module: &shader,
                    entry_point: Some("vs_head"),
                    compilation_options: Default::default(),
                    buffers: &[Some(wgpu::VertexBufferLayout {
                        array_stride: 24,
                        step_mode: wgpu::VertexStepMode::Vertex,
                        attributes: &VERTEX_ATTRIBUTES,
                    })],
                },
                fragment: Some(wgpu::FragmentState {
                    module: &shader,
                    entry_point: Some(entry),
                    compilation_options: Default::default(),
                    targets,
                }),
                primitive: wgpu::PrimitiveState {
                    topology: wgpu::PrimitiveTopology::TriangleList,
                    // A mesh's winding is unknown: both faces are opaque.
                    cull_mode: None,
                    ..Default::default()
                },
                depth_stencil: Some(depth_test(DEPTH_FORMAT, true, wgpu::CompareFunction::Less)),
                multisample: Default::default(),
                multiview_mask: None,
                cache: None,
            })
        };
        let surface_target = color_target(NEAREST_SURFACE_FORMAT, None);
        Self {
            surface: pipeline(
                "head view",
                "fs_head_surface",
                &[surface_target.clone(), surface_target],
            ),
            light_depth: pipeline(
                "head light depth",
                "fs_head_depth",
                &[color_target(HEAD_DEPTH_FORMAT, None)],
            ),
            layout,
        }
    }

    fn camera_group(&self, gpu: &GpuContext, camera: &Camera, aspect: f32) -> wgpu::BindGroup {
        let buffer = gpu
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("head camera"),
                contents: bytemuck::bytes_of(&HeadCameraUniform::of(camera, aspect)),
                usage: wgpu::BufferUsages::UNIFORM,
            });
        gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("head camera"),
            layout: &self.layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: buffer.as_entire_binding(),
            }],
        })
    }

    /// The view: `depth` cleared and written with the head's, `surface` (position, normal)
    /// cleared to zero (w = 0: no head) and written where the head is seen. With no head only
    /// the depth is cleared.
    #[allow(clippy::too_many_arguments)]
    pub fn encode_view(
        &self,
        gpu: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        head: Option<&HeadGeometry>,
        camera: &Camera,
        (width, height): (u32, u32),
        depth: &wgpu::TextureView,
        surface: [&wgpu::TextureView; 2],
    ) {
        let group = self.camera_group(gpu, camera, width as f32 / height as f32);
        // Without a head the surface targets are 1×1 placeholders (unread): the depth alone.
        let colors: Vec<_> = match head {
            Some(_) => surface.map(super::attachments::cleared_color).to_vec(),
            None => Vec::new(),
        };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("head view"),
            color_attachments: &colors,
            depth_stencil_attachment: cleared_depth(depth, true),
            timestamp_writes: gpu.render_timestamps(),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        if let Some(head) = head {
            pass.set_pipeline(&self.surface);
            pass.set_bind_group(0, &group, &[]);
            head.draw(&mut pass);
        }
    }

    /// The head's depth into layer `slot` of `maps` for each of the batch's light-map cameras.
    pub fn encode_light_depths(
        &self,
        gpu: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        head: &HeadGeometry,
        cameras: &[Camera],
        maps: &HeadDepthMaps,
    ) {
        let scratch = maps.scratch.create_view(&Default::default());
        for (slot, camera) in cameras.iter().enumerate() {
            let group = self.camera_group(gpu, camera, 1.0);
            let layer = maps.depth.create_view(&wgpu::TextureViewDescriptor {
                dimension: Some(wgpu::TextureViewDimension::D2),
                base_array_layer: slot as u32,
                array_layer_count: Some(1),
                ..Default::default()
            });
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("head light depth"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &layer,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        // 1: the far plane, nothing drawn.
                        load: wgpu::LoadOp::Clear(wgpu::Color {
                            r: 1.0,
                            g: 0.0,
                            b: 0.0,
                            a: 0.0,
                        }),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: cleared_depth(&scratch, false),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&self.light_depth);
            pass.set_bind_group(0, &group, &[]);
            head.draw(&mut pass);
        }
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
                file: "head.wgsl",
                source: include_str!("head.wgsl"),
            },
            None,
            "HeadCamera",
            &rust_layout!(HeadCameraUniform {
                view_proj,
                eye,
                toward_eye
            }),
        );
    }
}
