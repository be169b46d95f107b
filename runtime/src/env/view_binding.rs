//! Group 3 of the view shading pass: one batch's forward-scattering grid (a placeholder without
//! multiple scattering) and the frame's visibility: the occupancy map, the nearest fibers and
//! their coverage, the visibility volume and the head seen from the view.

use super::view_visibility::{OccupancyMap, ViewTransparency};
use super::volume::VolumeBuffers;
use crate::gpu::GpuContext;
use crate::gpu::bind_layout::{float_texture_entry, storage_entry, uniform_entry};
use crate::gpu::buffer::init_buffer;
use crate::multiple::ForwardScatteringGrid;

#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct ViewUniform {
    origin: [f32; 4],
    spacing: [f32; 4],
    dims: [u32; 4],
    width: u32,
    height: u32,
    visibility_cutoff: f32,
    record_words: u32,
    /// rgb: the head's skin albedo; w: 1 where the frame has a head.
    skin: [f32; 4],
    /// Clip space to world (the layered view's layers on their pixels' rays).
    clip_to_world: [[f32; 4]; 4],
    /// The layers' light visibility: its first word, slots per layer, 1 when this batch reads
    /// it (`view_layers.wgsl`).
    layer_lights: [u32; 4],
}

/// Group 3: one batch's forward-scattering grid (a placeholder without multiple scattering) and
/// the frame's occupancy map.
pub struct ViewBinding {
    pub group: wgpu::BindGroup,
    /// Bytes of the grid.
    pub bytes: u64,
}

/// What group 3 is built from besides the grid.
pub struct FrameVisibility<'a> {
    /// SRBF lobes' visibility volume, or its placeholder.
    pub volume: &'a VolumeBuffers,
    pub map: &'a OccupancyMap,
    /// [`EnvViewTargets::coverage`](super::view_targets::EnvViewTargets::coverage).
    pub coverage: &'a wgpu::TextureView,
    /// [`EnvViewTargets::nearest_position`](super::view_targets::EnvViewTargets::nearest_position) and [`EnvViewTargets::nearest_tangent`](super::view_targets::EnvViewTargets::nearest_tangent).
    pub nearest: [&'a wgpu::TextureView; 2],
    pub transparency: ViewTransparency,
    pub width: u32,
    pub height: u32,
    /// [`EnvViewTargets::head_position`](super::view_targets::EnvViewTargets::head_position) and [`EnvViewTargets::head_normal`](super::view_targets::EnvViewTargets::head_normal).
    pub head: [&'a wgpu::TextureView; 2],
    /// The head's skin albedo; None: no head.
    pub skin: Option<[f32; 3]>,
    /// The view camera's world-to-clip matrix (the layered view inverts it).
    pub view_proj: glam::Mat4,
    /// This batch's layers read their fibers' mean light visibility (a batch of compact
    /// sources in the layered view, [`OccupancyMap`]).
    pub layer_lights: bool,
}

impl ViewBinding {
    /// `grid.values` must hold `lights × dims` entries (checked by the caller).
    pub fn new(
        gpu: &GpuContext,
        layout: &wgpu::BindGroupLayout,
        grid: Option<&ForwardScatteringGrid>,
        visibility: &FrameVisibility,
    ) -> Self {
        let device = &gpu.device;
        let mut uniform = ViewUniform {
            origin: [0.0; 4],
            spacing: [1.0; 4],
            dims: [1, 1, 1, 0],
            width: visibility.width,
            height: visibility.height,
            visibility_cutoff: visibility.transparency.visibility_cutoff(),
            record_words: visibility.transparency.record_words() as u32,
            skin: match visibility.skin {
                Some([r, g, b]) => [r, g, b, 1.0],
                None => [0.0; 4],
            },
            clip_to_world: visibility.view_proj.inverse().to_cols_array_2d(),
            layer_lights: [
                visibility.map.layer_lights_word as u32,
                visibility.map.layer_light_slots,
                visibility.layer_lights as u32,
                0,
            ],
        };
        let values = match grid {
            Some(g) => {
                uniform.origin = g.origin.extend(0.0).into();
                uniform.spacing = g.spacing.extend(0.0).into();
                uniform.dims = [g.dims[0], g.dims[1], g.dims[2], 0];
                init_buffer(
                    device,
                    "env forward-scattering grid",
                    bytemuck::cast_slice(&g.values),
                    wgpu::BufferUsages::STORAGE,
                )
            }
            None => init_buffer(
                device,
                "env forward-scattering grid",
                &[0u8; 16],
                wgpu::BufferUsages::STORAGE,
            ),
        };
        let params = init_buffer(
            device,
            "env view params",
            bytemuck::bytes_of(&uniform),
            wgpu::BufferUsages::UNIFORM,
        );
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("env view"),
            layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: params.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: values.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: visibility.map.buffer.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: wgpu::BindingResource::TextureView(visibility.coverage),
                },
                wgpu::BindGroupEntry {
                    binding: 4,
                    resource: wgpu::BindingResource::TextureView(visibility.nearest[0]),
                },
                wgpu::BindGroupEntry {
                    binding: 5,
                    resource: wgpu::BindingResource::TextureView(visibility.nearest[1]),
                },
                wgpu::BindGroupEntry {
                    binding: 6,
                    resource: visibility.volume.params.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 7,
                    resource: visibility.volume.coefficients.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 8,
                    resource: wgpu::BindingResource::TextureView(visibility.head[0]),
                },
                wgpu::BindGroupEntry {
                    binding: 9,
                    resource: wgpu::BindingResource::TextureView(visibility.head[1]),
                },
            ],
        });
        Self {
            group,
            bytes: grid.map_or(0, |_| values.size()),
        }
    }
}

/// Group 3's layout.
pub fn view_bind_group_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    let fragment = wgpu::ShaderStages::FRAGMENT;
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("env view"),
        entries: &[
            uniform_entry(0, fragment),
            storage_entry(1, fragment, true),
            storage_entry(2, fragment, false),
            float_texture_entry(3, fragment),
            float_texture_entry(4, fragment),
            float_texture_entry(5, fragment),
            uniform_entry(6, fragment),
            storage_entry(7, fragment, true),
            float_texture_entry(8, fragment),
            float_texture_entry(9, fragment),
        ],
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
                file: "view_binding.wgsl",
                source: include_str!("view_binding.wgsl"),
            },
            None,
            "ViewParams",
            &rust_layout!(ViewUniform {
                origin,
                spacing,
                dims,
                width,
                height,
                visibility_cutoff,
                record_words,
                skin,
                clip_to_world,
                layer_lights
            }),
        );
    }
}
