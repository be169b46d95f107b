//! Group 1 of the shading passes (`strand_shading.wgsl`): up to [`MAX_SHADOWED_LIGHTS`] light maps
//! (deep opacity, opacity shadow, shadow maps or ADSM), each shadowing one light of the frame, in
//! fixed slots; unused slots hold 1×1 placeholders that shadow no light. A slot holds one light's
//! maps whatever their [`ShadowLayout`]: a frustum's one face or a cube's six, as array layers,
//! with one view-projection per face. Beside them the group binds the head (issue 40), opaque to
//! every light and to the view: its depth in every slot's faces and from the frame's camera
//! ([`HeadInput`]), 1×1 placeholders without one.
//!
//! [`ShadowLayout`]: crate::shadow_layout::ShadowLayout

use wgpu::util::DeviceExt;

use super::deep_opacity::{DeepOpacityMap, DomSettings, ShadowLookup};
use super::frame_params::FrameParams;
use super::head::HeadDepthMaps;
use super::render_target::DEPTH_FORMAT;
use crate::gpu::GpuContext;
use crate::gpu::bind_layout::{
    depth_array_texture_entry, depth_texture_entry, float_array_texture_entry, uniform_entry,
};
use crate::gpu::texture::texture_2d;
use crate::shadow_layout::{CUBE_FACES, ShadowLayout};

/// A deep opacity map that shadows light `light_index` of the frame.
#[derive(Clone, Copy)]
pub struct ShadowInput<'a> {
    pub map: &'a DeepOpacityMap,
    pub light_index: u32,
}

/// The head as the strand passes see it: opaque in the light maps and in the view.
#[derive(Clone, Copy)]
pub struct HeadInput<'a> {
    /// The head's depth in every slot's faces: the slots' faces in slot order, one array layer
    /// each (slot k's first layer is the faces of the slots before it); `None` without maps.
    pub light_depth: Option<&'a HeadDepthMaps>,
    /// The head's depth from the frame's camera ([`DEPTH_FORMAT`], the frame's size): fibers
    /// behind it are not drawn.
    pub view_depth: &'a wgpu::Texture,
}

/// `NO_HEAD_LAYER` in `strand_shading.wgsl`: a slot whose maps hold no head.
const NO_HEAD_LAYER: u32 = u32::MAX;

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
    /// Face f's view-projection (a frustum: face 0 only).
    view_proj: [[[f32; 4]; 4]; CUBE_FACES],
    /// xyz: a cube's light position; w: faces (1 or 6).
    cube: [f32; 4],
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
    /// Array layers of the layer texture per face.
    face_array_layers: u32,
    /// First layer of the slot's faces in the head's light depth ([`NO_HEAD_LAYER`]: none).
    head_layer: u32,
    /// World size of one map texel: at unit depth along the light for a perspective camera
    /// (it grows with depth), anywhere for an orthographic one.
    texel_world: f32,
    _pad: u32,
}

/// Binding 11: whether the view has a head to hide fibers behind.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct HeadViewUniform {
    in_view: u32,
    _pad: [u32; 3],
}

/// Bindings of group 1 after the slots' textures.
const SHADOW_PARAMS_BINDING: u32 = 2 * MAX_SHADOWED_LIGHTS as u32;
const HEAD_LIGHT_DEPTH_BINDING: u32 = SHADOW_PARAMS_BINDING + 1;
const HEAD_VIEW_DEPTH_BINDING: u32 = SHADOW_PARAMS_BINDING + 2;
const HEAD_VIEW_BINDING: u32 = SHADOW_PARAMS_BINDING + 3;

/// `ShadowParams.lookup` in `strand_shading.wgsl`.
fn lookup_code(lookup: &ShadowLookup) -> u32 {
    match lookup {
        ShadowLookup::Layers { .. } => 0,
        ShadowLookup::Hard { .. } => 1,
        ShadowLookup::Adsm { .. } => 2,
    }
}

/// Group 1 of the shading passes: per slot (up to [`MAX_SHADOWED_LIGHTS`]) the nearest depth and
/// the layer array of a light's map (bindings 2k, 2k+1), then the uniform array of the slots'
/// parameters (binding 8), the head's light depth array (9), its view depth (10) and whether the
/// view has one (11).
pub fn shadow_bind_group_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    let fragment = wgpu::ShaderStages::FRAGMENT;
    let mut entries = Vec::new();
    for slot in 0..MAX_SHADOWED_LIGHTS as u32 {
        entries.push(depth_array_texture_entry(2 * slot, fragment));
        entries.push(float_array_texture_entry(2 * slot + 1, fragment));
    }
    entries.push(uniform_entry(SHADOW_PARAMS_BINDING, fragment));
    entries.push(float_array_texture_entry(
        HEAD_LIGHT_DEPTH_BINDING,
        fragment,
    ));
    entries.push(depth_texture_entry(HEAD_VIEW_DEPTH_BINDING, fragment));
    entries.push(uniform_entry(HEAD_VIEW_BINDING, fragment));
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
    shadow_bind_group_for(gpu, layout, frame, shadow.as_slice(), None)
        .expect("one shadow map is within the limit")
}

/// Group 1 of the shading passes: one slot per map, 1×1 placeholders (shadowing no light) in the
/// rest, and `head` (placeholders hiding and shadowing nothing without one).
pub fn shadow_bind_group_for(
    gpu: &GpuContext,
    layout: &wgpu::BindGroupLayout,
    frame: &FrameParams,
    shadows: &[ShadowInput<'_>],
    head: Option<HeadInput<'_>>,
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
    let head_layers = head_layers(&slots, head.and_then(|h| h.light_depth).is_some());
    let uniforms: Vec<ShadowUniform> = slots
        .iter()
        .zip(head_layers)
        .map(|(&(map, light_index), head_layer)| {
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
            let faces = map.layout.faces();
            let camera = faces[0];
            ShadowUniform {
                view_proj: std::array::from_fn(|f| {
                    let c = faces.get(f).unwrap_or(&camera);
                    (c.projection_matrix(1.0) * c.view()).to_cols_array_2d()
                }),
                cube: match map.layout {
                    ShadowLayout::Cube(cube) => cube.position.extend(CUBE_FACES as f32).into(),
                    ShadowLayout::Frustum(_) => [0.0, 0.0, 0.0, 1.0],
                },
                near: camera.near,
                far: camera.far,
                spacing: map.settings.spacing,
                layers: map.settings.layers,
                light_index,
                resolution: map.settings.resolution as f32,
                lookup: lookup_code(&map.lookup),
                perspective: camera.is_perspective() as u32,
                kernel,
                bias,
                adsm_alpha,
                adsm_spacing,
                face_array_layers: map.face_array_layers(),
                head_layer,
                texel_world: 2.0
                    / (camera.projection_matrix(1.0).y_axis.y * map.settings.resolution as f32),
                _pad: 0,
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
                map.nearest_depth.create_view(&wgpu::TextureViewDescriptor {
                    dimension: Some(wgpu::TextureViewDimension::D2Array),
                    ..Default::default()
                }),
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
        binding: SHADOW_PARAMS_BINDING,
        resource: shadow_buffer.as_entire_binding(),
    });
    let head_views = HeadViews::of(gpu, head);
    entries.extend(head_views.entries());
    Ok(device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("strand shadows"),
        layout,
        entries: &entries,
    }))
}

/// Each slot's first layer in the head's light depth: the faces of the slots before it, in slot
/// order ([`HeadInput::light_depth`]); [`NO_HEAD_LAYER`] without the head's maps and in unused
/// slots.
fn head_layers(slots: &[(&DeepOpacityMap, u32)], with_head: bool) -> Vec<u32> {
    let mut next = 0;
    slots
        .iter()
        .map(|&(map, light_index)| {
            if !with_head || light_index == u32::MAX {
                return NO_HEAD_LAYER;
            }
            let first = next;
            next += map.layout.face_count();
            first
        })
        .collect()
}

/// The head's bindings of group 1: its views, or 1×1 placeholders (never read: no slot has a
/// head layer and the view flag is off).
struct HeadViews {
    light_depth: wgpu::TextureView,
    view_depth: wgpu::TextureView,
    params: wgpu::Buffer,
}

impl HeadViews {
    fn of(gpu: &GpuContext, head: Option<HeadInput<'_>>) -> Self {
        let light_depth = match head.and_then(|h| h.light_depth) {
            Some(maps) => maps.array_view(),
            None => HeadDepthMaps::placeholder(gpu).array_view(),
        };
        let view_depth = match head {
            Some(h) => h.view_depth.create_view(&Default::default()),
            None => texture_2d(
                gpu,
                "no head view depth",
                wgpu::Extent3d {
                    width: 1,
                    height: 1,
                    depth_or_array_layers: 1,
                },
                DEPTH_FORMAT,
                wgpu::TextureUsages::TEXTURE_BINDING,
            )
            .create_view(&Default::default()),
        };
        let params = gpu
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("strand head view"),
                contents: bytemuck::bytes_of(&HeadViewUniform {
                    in_view: head.is_some() as u32,
                    _pad: [0; 3],
                }),
                usage: wgpu::BufferUsages::UNIFORM,
            });
        Self {
            light_depth,
            view_depth,
            params,
        }
    }

    fn entries(&self) -> [wgpu::BindGroupEntry<'_>; 3] {
        [
            wgpu::BindGroupEntry {
                binding: HEAD_LIGHT_DEPTH_BINDING,
                resource: wgpu::BindingResource::TextureView(&self.light_depth),
            },
            wgpu::BindGroupEntry {
                binding: HEAD_VIEW_DEPTH_BINDING,
                resource: wgpu::BindingResource::TextureView(&self.view_depth),
            },
            wgpu::BindGroupEntry {
                binding: HEAD_VIEW_BINDING,
                resource: self.params.as_entire_binding(),
            },
        ]
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
                file: "strand_shading.wgsl",
                source: include_str!("strand_shading.wgsl"),
            },
            Some(&KAJIYA_KAY),
            "ShadowParams",
            &rust_layout!(ShadowUniform {
                view_proj,
                cube,
                near,
                far,
                spacing,
                layers,
                light_index,
                resolution,
                lookup,
                perspective,
                kernel,
                bias,
                adsm_alpha,
                adsm_spacing,
                face_array_layers,
                head_layer,
                texel_world
            }),
        );
        assert_same_layout(
            &Wgsl {
                file: "strand_shading.wgsl",
                source: include_str!("strand_shading.wgsl"),
            },
            Some(&KAJIYA_KAY),
            "HeadView",
            &rust_layout!(HeadViewUniform { in_view }),
        );
    }
}
