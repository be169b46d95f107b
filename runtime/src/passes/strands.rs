//! The strand pass: every hair segment drawn as a camera-facing quad, shaded under several
//! lights with a [`ShadingModel`] (Kajiya-Kay, Marschner through lookup tables, artist-friendly), blended with pre-multiplied alpha into an HDR float target with a
//! depth test. Inputs: [`StrandGeometry`] (the hair on the GPU), [`FrameParams`] (camera,
//! shading constants, lights). Output: the colour texture of a [`RenderTarget`].

use super::attachments::{cleared_color, cleared_depth};
use glam::{Mat4, Vec3};
use wgpu::util::DeviceExt;

use crate::camera::Camera;
use crate::gpu::GpuContext;
use crate::hair::HairModel;
use crate::lights::{GpuLight, Light};
use crate::passes::deep_opacity::{DeepOpacityMap, DomSettings};
use crate::passes::fiber_shading::{ModelBinding, ShadingModel};

/// Hair colour where the file has none (linear RGB, a mid brown).
pub const DEFAULT_HAIR_COLOR: [f32; 3] = [0.35, 0.22, 0.12];

/// The hair's arrays on the GPU, laid out as `strands.wgsl` reads them.
pub struct StrandGeometry {
    pub points: wgpu::Buffer,
    pub segments: wgpu::Buffer,
    pub attributes: wgpu::Buffer,
    pub segment_count: u32,
    /// The thickness used where the file gives none (world units).
    pub default_thickness: f32,
}

/// Per-point attributes (32 bytes): colour, diameter, opacity.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct PointAttributes {
    color: [f32; 3],
    thickness: f32,
    opacity: f32,
    _pad: [f32; 3],
}

const FIRST_SEGMENT_BIT: u32 = 1 << 30;
const LAST_SEGMENT_BIT: u32 = 1 << 31;

/// Where a model has no thickness: a thousandth of its bounding-box diagonal (sub-pixel for a
/// framed head at ordinary image sizes, which is what real fibers are).
pub fn default_thickness(model: &HairModel) -> f32 {
    model.bounds().diagonal() * 1e-3
}

/// One entry per segment: the index of its first point, flagged at strand ends.
pub fn segment_table(model: &HairModel) -> Vec<u32> {
    let mut table = Vec::with_capacity(model.segment_count());
    for w in model.strand_offsets().windows(2) {
        let (start, end) = (w[0], w[1]);
        for i in start..end - 1 {
            let mut entry = i;
            if i == start {
                entry |= FIRST_SEGMENT_BIT;
            }
            if i == end - 2 {
                entry |= LAST_SEGMENT_BIT;
            }
            table.push(entry);
        }
    }
    table
}

#[derive(Debug, thiserror::Error)]
#[error("the hair has {points} points; the strand pass indexes at most 2^30")]
pub struct TooManyPoints {
    pub points: usize,
}

impl StrandGeometry {
    pub fn upload(gpu: &GpuContext, model: &HairModel) -> Result<Self, TooManyPoints> {
        let n = model.point_count();
        if n >= FIRST_SEGMENT_BIT as usize {
            return Err(TooManyPoints { points: n });
        }
        let default_thickness = default_thickness(model);
        let thickness = model
            .thickness()
            .map(|a| a.per_point_values(n).into_owned())
            .unwrap_or_else(|| vec![default_thickness; n]);
        let transparency = model
            .transparency()
            .map(|a| a.per_point_values(n).into_owned())
            .unwrap_or_else(|| vec![0.0; n]);
        let color = model
            .color()
            .map(|a| a.per_point_values(n).into_owned())
            .unwrap_or_else(|| vec![Vec3::from(DEFAULT_HAIR_COLOR); n]);
        let attributes: Vec<PointAttributes> = (0..n)
            .map(|i| PointAttributes {
                color: color[i].into(),
                thickness: thickness[i],
                opacity: 1.0 - transparency[i],
                _pad: [0.0; 3],
            })
            .collect();
        let segments = segment_table(model);
        let storage = |label, contents: &[u8]| {
            gpu.device
                .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some(label),
                    contents,
                    usage: wgpu::BufferUsages::STORAGE,
                })
        };
        Ok(Self {
            points: storage("hair points", model.points_bytes()),
            segments: storage("hair segments", bytemuck::cast_slice(&segments)),
            attributes: storage("hair point attributes", bytemuck::cast_slice(&attributes)),
            segment_count: segments.len() as u32,
            default_thickness,
        })
    }

    /// Bytes held per buffer, for reports.
    pub fn memory(&self) -> Vec<(String, u64)> {
        [&self.points, &self.segments, &self.attributes]
            .iter()
            .zip(["hair points", "hair segments", "hair point attributes"])
            .map(|(b, name)| (name.to_string(), b.size()))
            .collect()
    }
}

/// Kajiya-Kay constants: `L = E·(kd·color·sin(t,l) + ks·max(0, sin(t,l)sin(t,e) − (t·l)(t·e))^p)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KajiyaKay {
    pub kd: f32,
    pub ks: f32,
    pub shininess: f32,
}

impl Default for KajiyaKay {
    fn default() -> Self {
        Self {
            kd: 0.6,
            ks: 0.25,
            shininess: 40.0,
        }
    }
}

/// What the pass needs besides the geometry.
#[derive(Clone, Debug)]
pub struct FrameParams {
    pub camera: Camera,
    pub width: u32,
    pub height: u32,
    pub lights: Vec<Light>,
    pub shading: KajiyaKay,
    /// Every fiber this many pixels wide instead of its projected thickness.
    pub width_override_px: Option<f32>,
}

#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct FrameUniform {
    view_proj: [[f32; 4]; 4],
    eye: [f32; 4],
    toward_eye: [f32; 4],
    viewport: [f32; 2],
    focal_px: f32,
    width_override_px: f32,
    kd: f32,
    ks: f32,
    shininess: f32,
    light_count: u32,
    /// Fiber width multiplier (the light pass's stochastic simplification enlarges fibers by
    /// 1/κ); 1 elsewhere.
    width_scale: f32,
    _pad: [f32; 3],
}

impl FrameParams {
    fn uniform(&self, width_scale: f32) -> FrameUniform {
        let aspect = self.width as f32 / self.height as f32;
        let proj = self.camera.projection_matrix(aspect);
        let view_proj: Mat4 = proj * self.camera.view();
        FrameUniform {
            view_proj: view_proj.to_cols_array_2d(),
            eye: self
                .camera
                .eye
                .extend(if self.camera.is_perspective() {
                    1.0
                } else {
                    0.0
                })
                .into(),
            toward_eye: self.camera.toward_eye().extend(0.0).into(),
            viewport: [self.width as f32, self.height as f32],
            focal_px: proj.y_axis.y * self.height as f32 * 0.5,
            width_override_px: self.width_override_px.unwrap_or(0.0),
            kd: self.shading.kd,
            ks: self.shading.ks,
            shininess: self.shading.shininess,
            light_count: self.lights.len() as u32,
            width_scale,
            _pad: [0.0; 3],
        }
    }
}

/// An HDR colour texture and its depth buffer.
pub struct RenderTarget {
    pub color: wgpu::Texture,
    pub depth: wgpu::Texture,
}

pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

impl RenderTarget {
    pub fn new(gpu: &GpuContext, width: u32, height: u32) -> Self {
        let size = wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        };
        let texture = |label, format, usage| {
            gpu.device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size,
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage,
                view_formats: &[],
            })
        };
        Self {
            color: texture(
                "hdr colour",
                gpu.hdr_format(),
                wgpu::TextureUsages::RENDER_ATTACHMENT
                    | wgpu::TextureUsages::COPY_SRC
                    | wgpu::TextureUsages::TEXTURE_BINDING,
            ),
            depth: texture(
                "depth",
                DEPTH_FORMAT,
                wgpu::TextureUsages::RENDER_ATTACHMENT,
            ),
        }
    }

    /// Bytes held per texture, for reports.
    pub fn memory(&self) -> Vec<(String, u64)> {
        let bytes = |t: &wgpu::Texture| {
            let texel = t.format().block_copy_size(None).unwrap_or(4) as u64;
            t.width() as u64 * t.height() as u64 * texel
        };
        vec![
            ("hdr colour".to_string(), bytes(&self.color)),
            ("depth".to_string(), bytes(&self.depth)),
        ]
    }
}

/// The compiled pipeline; reusable across frames and models.
pub struct StrandPass {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    shadow_layout: wgpu::BindGroupLayout,
    /// Group 2: the fiber model's constants and tables (none for Kajiya-Kay).
    model: Option<ModelBinding>,
}

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
    _pad: [f32; 2],
}

/// Group 1 of the shading passes: per slot (up to [`MAX_SHADOWED_LIGHTS`]) the nearest depth and
/// the two layer textures of a deep opacity map (bindings 3k, 3k+1, 3k+2), then the uniform array
/// of the slots' parameters (binding 12).
pub fn shadow_bind_group_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    let texture = |binding, sample_type| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Texture {
            sample_type,
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: false,
        },
        count: None,
    };
    let mut entries = Vec::new();
    for slot in 0..MAX_SHADOWED_LIGHTS as u32 {
        entries.push(texture(3 * slot, wgpu::TextureSampleType::Depth));
        for layer in 1..3 {
            entries.push(texture(
                3 * slot + layer,
                wgpu::TextureSampleType::Float { filterable: false },
            ));
        }
    }
    entries.push(wgpu::BindGroupLayoutEntry {
        binding: 3 * MAX_SHADOWED_LIGHTS as u32,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    });
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("strand shadows"),
        entries: &entries,
    })
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
                timestamp_writes: None,
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

/// Group 0 of every pass that draws strand quads (`strand_quads.wgsl`): frame uniform, points,
/// segments, point attributes, lights.
pub fn strand_bind_group_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    let storage = |binding| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only: true },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    };

    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("strands"),
        entries: &[
            wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            },
            storage(1),
            storage(2),
            storage(3),
            storage(4),
        ],
    })
}

/// Group 0's resources for `geometry` seen through `frame`.
pub fn strand_bind_group(
    gpu: &GpuContext,
    layout: &wgpu::BindGroupLayout,
    geometry: &StrandGeometry,
    frame: &FrameParams,
) -> wgpu::BindGroup {
    strand_bind_group_scaled(gpu, layout, geometry, frame, 1.0)
}

/// [`strand_bind_group`] with every fiber `width_scale` times wider, its optical depth summed
/// across kept (`strand_quads.wgsl`): the light pass's enlargement by 1/κ (Ren 2010 §7).
pub fn strand_bind_group_scaled(
    gpu: &GpuContext,
    layout: &wgpu::BindGroupLayout,
    geometry: &StrandGeometry,
    frame: &FrameParams,
    width_scale: f32,
) -> wgpu::BindGroup {
    let device = &gpu.device;
    let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("strand frame"),
        contents: bytemuck::bytes_of(&frame.uniform(width_scale)),
        usage: wgpu::BufferUsages::UNIFORM,
    });
    // A storage binding may not be empty: pad with one unused light.
    let mut lights: Vec<GpuLight> = frame.lights.iter().map(Light::to_gpu).collect();
    if lights.is_empty() {
        lights.push(bytemuck::Zeroable::zeroed());
    }
    let lights = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("lights"),
        contents: bytemuck::cast_slice(&lights),
        usage: wgpu::BufferUsages::STORAGE,
    });

    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("strands"),
        layout,
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: uniform.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: geometry.points.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 2,
                resource: geometry.segments.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 3,
                resource: geometry.attributes.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 4,
                resource: lights.as_entire_binding(),
            },
        ],
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
        .map(|&(map, light_index)| ShadowUniform {
            view_proj: (map.camera.projection_matrix(1.0) * map.camera.view()).to_cols_array_2d(),
            near: map.camera.near,
            far: map.camera.far,
            spacing: map.settings.spacing,
            layers: map.settings.layers,
            light_index,
            resolution: map.settings.resolution as f32,
            _pad: [0.0; 2],
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
                map.layers[0].create_view(&Default::default()),
                map.layers[1].create_view(&Default::default()),
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
        binding: 3 * MAX_SHADOWED_LIGHTS as u32,
        resource: shadow_buffer.as_entire_binding(),
    });
    Ok(device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("strand shadows"),
        layout,
        entries: &entries,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn segment_table_flags_strand_ends() {
        let points = (0..5).map(|i| Vec3::new(i as f32, 0.0, 0.0)).collect();
        let model = HairModel::new(points, vec![0, 3, 5], None, None, None).unwrap();
        let t = segment_table(&model);
        assert_eq!(
            t,
            vec![
                FIRST_SEGMENT_BIT,
                1 | LAST_SEGMENT_BIT,
                3 | FIRST_SEGMENT_BIT | LAST_SEGMENT_BIT
            ]
        );
    }
}
