//! Group 1 of the env view pass and of the transmittance probe (`convolution_transmittance.wgsl`):
//! a batch's lights (each with its light camera and its shading samples), the DODM's nearest
//! depths and the summed-area tables of its optical depths, and the head's depth from each light.

use super::convolution_depth::DodmBatch;
use super::head::HeadDepthMaps;
use super::summed_area::{MAX_BOX_HALF_SIZE, SummedAreaTables};
use super::transmittance_filter::TransmittanceFilter;
use crate::env_light::{EnvLight, ShadowGroup};
use crate::gpu::GpuContext;
use crate::gpu::bind_layout::{
    bind_group, float_array_texture_entry, storage_entry, uniform_entry,
};
use crate::gpu::buffer::init_buffer;
use glam::Vec3;

#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct EnvLightGpu {
    view_proj: [[f32; 4]; 4],
    direction: [f32; 4],
    /// xyz: the representative light's rgb (the view shades the samples); w: the box slope.
    rgb: [f32; 4],
    near: f32,
    far: f32,
    first_layer: f32,
    texels_per_unit: f32,
    /// The slot's lights in the batch's shading samples: `first_sample ..+ sample_count`.
    first_sample: u32,
    sample_count: u32,
    _pad: [u32; 2],
}

/// One light as the view pass shades it, with the visibility of its shadow group's slot.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct ShadingSampleGpu {
    /// xyz: unit vector toward the light; w: 1/λ (0 for a directional light).
    direction: [f32; 4],
    rgb: [f32; 4],
    power: [f32; 4],
}

impl ShadingSampleGpu {
    fn of(light: &EnvLight) -> Self {
        let inv_lambda = light.lambda.map_or(0.0, |l| 1.0 / l);
        let power = light.power();
        Self {
            direction: light.direction.normalize().extend(inv_lambda).into(),
            rgb: [light.rgb[0], light.rgb[1], light.rgb[2], 0.0],
            power: [power[0], power[1], power[2], 0.0],
        }
    }
}

#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct BatchUniform {
    light_count: u32,
    resolution: u32,
    max_half_size: u32,
    flags: u32,
}

const FLAG_UNSHADOWED: u32 = 1;
const FLAG_GRID: u32 = 2;
/// The batch binds the head's depth from each light (`HeadDepthMaps`).
const FLAG_HEAD: u32 = 4;

/// Group 1 of the view pass and the probe (`convolution_transmittance.wgsl`).
pub fn transmittance_bind_group_layout(
    device: &wgpu::Device,
    visibility: wgpu::ShaderStages,
) -> wgpu::BindGroupLayout {
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("convolution transmittance"),
        entries: &[
            uniform_entry(0, visibility),
            storage_entry(1, visibility, true),
            float_array_texture_entry(2, visibility),
            storage_entry(3, visibility, true),
            storage_entry(4, visibility, true),
            float_array_texture_entry(5, visibility),
        ],
    })
}

/// Group 1's resources for one batch: its lights, DODM and SATs.
pub struct BatchBinding {
    pub group: wgpu::BindGroup,
    /// Light slots bound (`batch.light_count` in the shaders).
    pub light_count: u32,
}

impl BatchBinding {
    /// `lights[slot]` must be the light of DODM slot `slot`; `shadowed = false` forces T̃ = 1.
    /// The default [`TransmittanceFilter`].
    pub fn new(
        gpu: &GpuContext,
        layout: &wgpu::BindGroupLayout,
        lights: &[EnvLight],
        dodm: &DodmBatch,
        sat: &SummedAreaTables,
        shadowed: bool,
        with_grid: bool,
    ) -> Self {
        Self::with_filter(
            gpu,
            layout,
            lights,
            dodm,
            sat,
            shadowed,
            with_grid,
            TransmittanceFilter::default(),
        )
    }

    /// [`Self::new`] with the averaging box of `filter`.
    #[allow(clippy::too_many_arguments)]
    pub fn with_filter(
        gpu: &GpuContext,
        layout: &wgpu::BindGroupLayout,
        lights: &[EnvLight],
        dodm: &DodmBatch,
        sat: &SummedAreaTables,
        shadowed: bool,
        with_grid: bool,
        filter: TransmittanceFilter,
    ) -> Self {
        let groups: Vec<_> = lights
            .chunks(1)
            .map(|one| ShadowGroup {
                direction: one[0].direction,
                lights: one,
            })
            .collect();
        Self::with_groups(
            gpu, layout, &groups, dodm, sat, shadowed, with_grid, filter, None,
        )
    }

    /// `groups[slot]` shaded with the visibility of DODM slot `slot`; `shadowed = false`
    /// forces T̃ = 1. SRBF lights take the box of `filter`. `head`: the head's depth from each
    /// slot's light (layer `slot`), opaque in every lobe's visibility.
    #[allow(clippy::too_many_arguments)]
    pub fn with_groups(
        gpu: &GpuContext,
        layout: &wgpu::BindGroupLayout,
        groups: &[ShadowGroup<'_>],
        dodm: &DodmBatch,
        sat: &SummedAreaTables,
        shadowed: bool,
        with_grid: bool,
        filter: TransmittanceFilter,
        head: Option<&HeadDepthMaps>,
    ) -> Self {
        let placeholder;
        let head_maps = match head {
            Some(maps) => maps,
            None => {
                placeholder = HeadDepthMaps::placeholder(gpu);
                &placeholder
            }
        };
        let (gpu_lights, samples) = slot_lights(groups, dodm, shadowed, filter);
        let flags = if shadowed { 0 } else { FLAG_UNSHADOWED }
            | if with_grid { FLAG_GRID } else { 0 }
            | if head.is_some() && shadowed {
                FLAG_HEAD
            } else {
                0
            };
        let params = BatchUniform {
            light_count: groups.len() as u32,
            resolution: dodm.resolution,
            max_half_size: MAX_BOX_HALF_SIZE,
            flags,
        };
        let device = &gpu.device;
        let (uniform, storage) = (wgpu::BufferUsages::UNIFORM, wgpu::BufferUsages::STORAGE);
        let uniform = init_buffer(device, "env batch", bytemuck::bytes_of(&params), uniform);
        let light_buffer = init_buffer(
            device,
            "env lights",
            bytemuck::cast_slice(&gpu_lights),
            storage,
        );
        let sample_buffer = init_buffer(
            device,
            "env shading samples",
            bytemuck::cast_slice(&samples),
            storage,
        );
        let depth_view = DodmBatch::array_view(&dodm.nearest_depth);
        let head_view = head_maps.array_view();
        let resources = [
            uniform.as_entire_binding(),
            light_buffer.as_entire_binding(),
            wgpu::BindingResource::TextureView(&depth_view),
            sat.buffer.as_entire_binding(),
            sample_buffer.as_entire_binding(),
            wgpu::BindingResource::TextureView(&head_view),
        ];
        Self {
            group: bind_group(device, "env batch", layout, &resources),
            light_count: params.light_count,
        }
    }
}

/// Each slot's light (its shadow group's representative, with its light camera) and the
/// shading samples of all slots (each group's lights), never empty: storage buffers hold at
/// least one element.
fn slot_lights(
    groups: &[ShadowGroup<'_>],
    dodm: &DodmBatch,
    shadowed: bool,
    filter: TransmittanceFilter,
) -> (Vec<EnvLightGpu>, Vec<ShadingSampleGpu>) {
    let mut samples: Vec<ShadingSampleGpu> = Vec::new();
    let mut gpu_lights: Vec<EnvLightGpu> = groups
        .iter()
        .enumerate()
        .map(|(slot, group)| {
            // An unshadowed frame, or SRBF lobes that read the visibility volume, drew no
            // light maps, so there is no camera to read.
            let map = dodm.cameras.get(slot).filter(|_| shadowed).map(|&camera| {
                let view_proj = camera.projection_matrix(1.0) * camera.view();
                (
                    view_proj,
                    camera.near,
                    camera.far,
                    dodm.texels_per_unit(slot),
                )
            });
            let (view_proj, near, far, texels_per_unit) =
                map.unwrap_or((glam::Mat4::IDENTITY, 0.0, 1.0, 0.0));
            let light = group.representative();
            let inv_lambda = light.lambda.map_or(0.0, |l| 1.0 / l);
            let first_sample = samples.len() as u32;
            samples.extend(group.lights.iter().map(ShadingSampleGpu::of));
            EnvLightGpu {
                view_proj: view_proj.to_cols_array_2d(),
                direction: light.direction.normalize().extend(inv_lambda).into(),
                rgb: Vec3::from(light.rgb).extend(filter.slope(&light)).into(),
                near,
                far,
                first_layer: dodm.first_layer,
                texels_per_unit,
                first_sample,
                sample_count: group.lights.len() as u32,
                _pad: [0; 2],
            }
        })
        .collect();
    if samples.is_empty() {
        samples.push(bytemuck::Zeroable::zeroed());
    }
    if gpu_lights.is_empty() {
        gpu_lights.push(bytemuck::Zeroable::zeroed());
    }
    (gpu_lights, samples)
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
                file: "convolution_transmittance.wgsl",
                source: include_str!("convolution_transmittance.wgsl"),
            },
            None,
            "EnvLightGpu",
            &rust_layout!(EnvLightGpu {
                view_proj,
                direction,
                rgb,
                near,
                far,
                first_layer,
                texels_per_unit,
                first_sample,
                sample_count
            }),
        );
        assert_same_layout(
            &Wgsl {
                file: "convolution_transmittance.wgsl",
                source: include_str!("convolution_transmittance.wgsl"),
            },
            None,
            "ShadingSample",
            &rust_layout!(ShadingSampleGpu {
                direction,
                rgb,
                power
            }),
        );
        assert_same_layout(
            &Wgsl {
                file: "convolution_transmittance.wgsl",
                source: include_str!("convolution_transmittance.wgsl"),
            },
            None,
            "BatchParams",
            &rust_layout!(BatchUniform {
                light_count,
                resolution,
                max_half_size,
                flags
            }),
        );
    }
}
