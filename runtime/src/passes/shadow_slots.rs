//! Group 1 of the shading passes (`strands.wgsl`): up to [`MAX_SHADOWED_LIGHTS`] light maps
//! (deep opacity, opacity shadow, shadow maps or ADSM), each shadowing one light of the frame, in fixed slots; unused slots hold 1×1
//! placeholders that shadow no light.

use wgpu::util::DeviceExt;

use super::deep_opacity::{DeepOpacityMap, DomSettings, ShadowLookup};
use super::frame_params::FrameParams;
use crate::gpu::GpuContext;
use crate::gpu::bind_layout::{depth_texture_entry, float_array_texture_entry, uniform_entry};

/// A deep opacity map that shadows light `light_index` of the frame.
#[derive(Clone, Copy)]
pub struct ShadowInput<'a> {
    pub map: &'a DeepOpacityMap,
    pub light_index: u32,
}

/// Directional lights the strand pass shadows at once (one deep opacity map each).
pub const MAX_SHADOWED_LIGHTS: usize = 4;

#[derive(Debug, thiserror::Error, PartialEq)]
#[error(
    "{maps} deep opacity maps given; the strand pass shadows at most {MAX_SHADOWED_LIGHTS} lights"
)]
pub struct TooManyShadowMaps {
    pub maps: usize,
}

#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct ShadowUniform {
    view_proj: [[f32; 4]; 4],
    near: f32,
    far: f32,
    spacing: f32,
    layers: u32,
    light_index: u32,
    resolution: f32,
    lookup: u32,
    perspective: u32,
    kernel: u32,
    bias: f32,
    adsm_alpha: f32,
    adsm_spacing: f32,
}

/// `ShadowParams.lookup` in `strands.wgsl`.
fn lookup_code(lookup: &ShadowLookup) -> u32 {
    match lookup {
        ShadowLookup::Layers { .. } => 0,
        ShadowLookup::Hard { .. } => 1,
        ShadowLookup::Adsm { .. } => 2,
    }
}

/// Group 1 of the shading passes: per slot (up to [`MAX_SHADOWED_LIGHTS`]) the nearest depth and
/// the layer array of a light's map (bindings 2k, 2k+1), then the uniform array of the slots'
/// parameters (binding 8).
pub fn shadow_bind_group_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    let fragment = wgpu::ShaderStages::FRAGMENT;
    let mut entries = Vec::new();
    for slot in 0..MAX_SHADOWED_LIGHTS as u32 {
        entries.push(depth_texture_entry(2 * slot, fragment));
        entries.push(float_array_texture_entry(2 * slot + 1, fragment));
    }
    entries.push(uniform_entry(2 * MAX_SHADOWED_LIGHTS as u32, fragment));
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("strand shadows"),
        entries: &entries,
    })
}

/// Group 1 of the shading passes with at most one shadowed light.
pub fn shadow_bind_group(
    gpu: &GpuContext,
    layout: &wgpu::BindGroupLayout,
    frame: &FrameParams,
    shadow: Option<ShadowInput<'_>>,
) -> wgpu::BindGroup {
    shadow_bind_group_for(gpu, layout, frame, shadow.as_slice())
        .expect("one shadow map is within the limit")
}

/// Group 1 of the shading passes: one slot per map, 1×1 placeholders (shadowing no light) in the
/// rest.
pub fn shadow_bind_group_for(
    gpu: &GpuContext,
    layout: &wgpu::BindGroupLayout,
    frame: &FrameParams,
    shadows: &[ShadowInput<'_>],
) -> Result<wgpu::BindGroup, TooManyShadowMaps> {
    if shadows.len() > MAX_SHADOWED_LIGHTS {
        return Err(TooManyShadowMaps {
            maps: shadows.len(),
        });
    }
    let device = &gpu.device;
    let placeholder = DeepOpacityMap::new(
        gpu,
        frame.camera,
        DomSettings {
            resolution: 1,
            layers: 1,
            spacing: 1.0,
        },
    );
    let slots: Vec<(&DeepOpacityMap, u32)> = (0..MAX_SHADOWED_LIGHTS)
        .map(|k| match shadows.get(k) {
            Some(s) => (s.map, s.light_index),
            None => (&placeholder, u32::MAX),
        })
        .collect();
    let uniforms: Vec<ShadowUniform> = slots
        .iter()
        .map(|&(map, light_index)| {
            let (kernel, bias, adsm_alpha, adsm_spacing) = match map.lookup {
                ShadowLookup::Layers { kernel } => (kernel, 0.0, 0.5, 1.0),
                ShadowLookup::Hard { kernel, bias } => (kernel, bias, 0.5, 1.0),
                ShadowLookup::Adsm {
                    kernel,
                    bias,
                    alpha,
                    spacing,
                } => (kernel, bias, alpha, spacing),
            };
            ShadowUniform {
                view_proj: (map.camera.projection_matrix(1.0) * map.camera.view())
                    .to_cols_array_2d(),
                near: map.camera.near,
                far: map.camera.far,
                spacing: map.settings.spacing,
                layers: map.settings.layers,
                light_index,
                resolution: map.settings.resolution as f32,
                lookup: lookup_code(&map.lookup),
                perspective: map.camera.is_perspective() as u32,
                kernel,
                bias,
                adsm_alpha,
                adsm_spacing,
            }
        })
        .collect();
    let shadow_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("strand shadow params"),
        contents: bytemuck::cast_slice(&uniforms),
        usage: wgpu::BufferUsages::UNIFORM,
    });
    let views: Vec<wgpu::TextureView> = slots
        .iter()
        .flat_map(|(map, _)| {
            [
                map.nearest_depth.create_view(&Default::default()),
                map.layers.create_view(&wgpu::TextureViewDescriptor {
                    dimension: Some(wgpu::TextureViewDimension::D2Array),
                    ..Default::default()
                }),
            ]
        })
        .collect();
    let mut entries: Vec<wgpu::BindGroupEntry> = views
        .iter()
        .enumerate()
        .map(|(i, view)| wgpu::BindGroupEntry {
            binding: i as u32,
            resource: wgpu::BindingResource::TextureView(view),
        })
        .collect();
    entries.push(wgpu::BindGroupEntry {
        binding: 2 * MAX_SHADOWED_LIGHTS as u32,
        resource: shadow_buffer.as_entire_binding(),
    });
    Ok(device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("strand shadows"),
        layout,
        entries: &entries,
    }))
}
