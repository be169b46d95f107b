//! Deep opacity maps: a light-space depth prepass (nearest fiber per texel), then additive
//! passes that sort every fragment's optical depth into K layers of configurable spacing, the
//! last layer taking what lies beyond (`deep_opacity.wgsl`); one pass fills
//! [`LAYERS_PER_PASS`] layers.
//! Shadow maps and ADSM (Hunz §4) use only the depth prepass: the lookup compares against the
//! nearest fiber ([`ShadowLookup`]). Point and spot lights use a perspective light camera
//! ([`point_light_camera`]); depths are linearized wherever layers are measured.
//! Opacity shadow maps (Kim & Neumann 2001, Kim 2003) are the same layers started at one depth
//! for every texel, the hair's nearest extent, and spaced to span its whole depth range
//! ([`DeepOpacityMap::opacity_slices`]): no prepass, so the slices do not follow the hair's
//! surface and need more of them for the same accuracy.
//!
//! A point or spot light that no frustum holds gets a cube of six faces ([`ShadowLayout`]): every
//! texture holds one group of array layers per face, each face drawn from its own camera.
//!
//! [`point_light_camera`]: crate::camera::point_light_camera
//!
//! Inputs: [`StrandGeometry`], the light's camera, the hair's bounds, [`DomSettings`].
//! Output: [`DeepOpacityMap`] (layer textures + nearest-depth texture + the light's camera).
//! The pipelines are built once and the per-light targets can be reused, so the pass repeats
//! cheaply for many lights.

use wgpu::util::DeviceExt;

use super::attachments::{cleared_color, cleared_depth};
use super::frame_params::{FrameParams, KajiyaKay};
use super::render_target::DEPTH_FORMAT;
use super::strand_geometry::StrandGeometry;
use super::strand_quads::{strand_bind_group, strand_bind_group_layout};
use crate::gpu::GpuContext;
use crate::gpu::bind_layout::{bind_group, depth_texture_entry, uniform_entry};
use crate::gpu::pipeline::{ADDITIVE, StrandDraw, color_target, depth_test};
use crate::gpu::readback::{ReadbackError, read_texture_layer_rgba};
use crate::gpu::texture::texture_2d;
use crate::hair::Aabb;
use crate::shaders::{Wgsl, shader_module};
use crate::shadow_layout::{CUBE_FACES, ShadowLayout};

/// At most this many layers (eight RGBA array layers; the layer pass fills them
/// [`LAYERS_PER_PASS`] at a time).
pub const MAX_LAYERS: u32 = 32;

/// Layers one rasterization of the hair fills: two RGBA32F targets are the 32 bytes per sample
/// that WebGPU's default limits allow every adapter, so 16 layers take two passes, 32 four.
pub const LAYERS_PER_PASS: u32 = 8;
const TARGETS_PER_PASS: u32 = LAYERS_PER_PASS / 4;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DomSettings {
    pub resolution: u32,
    pub layers: u32,
    /// Layer thickness along the light direction, world units.
    pub spacing: f32,
}

#[derive(Debug, thiserror::Error, PartialEq)]
pub enum DomSettingsError {
    #[error("deep opacity map layers {0}: must be 1..={MAX_LAYERS}")]
    Layers(u32),
    #[error("deep opacity map layer spacing {0}: must be positive and finite")]
    Spacing(f32),
    #[error("deep opacity map resolution {0}: must be 1..=8192")]
    Resolution(u32),
}

impl DomSettings {
    pub fn check(&self) -> Result<(), DomSettingsError> {
        if !(1..=MAX_LAYERS).contains(&self.layers) {
            return Err(DomSettingsError::Layers(self.layers));
        }
        if !(self.spacing.is_finite() && self.spacing > 0.0) {
            return Err(DomSettingsError::Spacing(self.spacing));
        }
        if !(1..=8192).contains(&self.resolution) {
            return Err(DomSettingsError::Resolution(self.resolution));
        }
        Ok(())
    }
}

#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct DomUniform {
    near: f32,
    far: f32,
    spacing: f32,
    layers: u32,
    perspective: u32,
    /// The first layer this pass writes (a multiple of [`LAYERS_PER_PASS`]).
    first_layer: u32,
    _pad: [u32; 2],
}

/// Where a map's first layer begins.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LayerStart {
    /// At each texel's nearest fiber, found by a depth prepass (deep opacity maps).
    NearestFiber,
    /// At one depth for every texel of a face, normalized between the light camera's near (0)
    /// and far (1) planes, per face (index 0 for a frustum; opacity shadow maps).
    Fixed([f32; CUBE_FACES]),
}

/// How the shading passes read a light's map.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ShadowLookup {
    /// Optical depth layers (deep opacity and opacity shadow maps): the transmittance averaged
    /// over `kernel`×`kernel` texels (PCF; 1: the texel alone).
    Layers { kernel: u32 },
    /// A shadow map: lit where the fragment lies no more than `bias` (world units along the
    /// light) behind the nearest fiber, averaged over `kernel`×`kernel` texels (PCF).
    Hard { kernel: u32, bias: f32 },
    /// Approximate deep shadow maps (TressFX; Hunz §4): behind the nearest fiber by b (beyond
    /// `bias`), the light passes (1 − `alpha`)^(1 + b / `spacing`), i.e. one fiber of opacity
    /// `alpha` every `spacing` world units; PCF as for [`ShadowLookup::Hard`].
    Adsm {
        kernel: u32,
        bias: f32,
        alpha: f32,
        spacing: f32,
    },
}

/// The largest PCF kernel (texels per side).
pub const MAX_PCF_KERNEL: u32 = 9;

#[derive(Debug, thiserror::Error, PartialEq)]
pub enum ShadowLookupError {
    #[error("PCF kernel {0}: must be odd and 1..={MAX_PCF_KERNEL}")]
    Kernel(u32),
    #[error("shadow bias {0}: must be finite and ≥ 0 (world units)")]
    Bias(f32),
    #[error("ADSM fiber opacity {0}: must be in (0, 1)")]
    Alpha(f32),
    #[error("ADSM fiber spacing {0}: must be positive and finite (world units)")]
    Spacing(f32),
}

impl ShadowLookup {
    pub fn check(&self) -> Result<(), ShadowLookupError> {
        let (kernel, bias) = match *self {
            ShadowLookup::Layers { kernel } => (kernel, 0.0),
            ShadowLookup::Hard { kernel, bias } => (kernel, bias),
            ShadowLookup::Adsm {
                kernel,
                bias,
                alpha,
                spacing,
            } => {
                if !(alpha > 0.0 && alpha < 1.0) {
                    return Err(ShadowLookupError::Alpha(alpha));
                }
                if !(spacing > 0.0 && spacing.is_finite()) {
                    return Err(ShadowLookupError::Spacing(spacing));
                }
                (kernel, bias)
            }
        };
        if kernel % 2 == 0 || !(1..=MAX_PCF_KERNEL).contains(&kernel) {
            return Err(ShadowLookupError::Kernel(kernel));
        }
        if !(bias >= 0.0 && bias.is_finite()) {
            return Err(ShadowLookupError::Bias(bias));
        }
        Ok(())
    }

    /// Whether the map needs its optical depth layers (else only the nearest depth).
    pub fn uses_layers(&self) -> bool {
        matches!(self, ShadowLookup::Layers { .. })
    }
}

/// One light's maps.
pub struct DeepOpacityMap {
    /// One frustum, or a cube's six faces.
    pub layout: ShadowLayout,
    pub settings: DomSettings,
    pub layer_start: LayerStart,
    pub lookup: ShadowLookup,
    /// Array layer f: face f's nearest depth.
    pub nearest_depth: wgpu::Texture,
    /// Face f's layer k in channel k % 4 of array layer f · [`Self::face_array_layers`] + k / 4
    /// (rounded up to whole passes).
    pub layers: wgpu::Texture,
}

/// Array layers holding `layers` optical depth layers: whole passes of `TARGETS_PER_PASS`.
pub fn array_layers_for(layers: u32) -> u32 {
    layers.max(1).div_ceil(LAYERS_PER_PASS) * TARGETS_PER_PASS
}

impl DeepOpacityMap {
    /// Empty maps for `layout` (a [`crate::camera::Camera`] converts to one frustum).
    pub fn new(gpu: &GpuContext, layout: impl Into<ShadowLayout>, settings: DomSettings) -> Self {
        let layout = layout.into();
        let faces = layout.face_count();
        let size = wgpu::Extent3d {
            width: settings.resolution,
            height: settings.resolution,
            depth_or_array_layers: faces,
        };
        let texture = |label, format, usage| texture_2d(gpu, label, size, format, usage);
        let layer_usage = wgpu::TextureUsages::RENDER_ATTACHMENT
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_SRC;
        Self {
            layout,
            settings,
            layer_start: LayerStart::NearestFiber,
            lookup: ShadowLookup::Layers { kernel: 1 },
            nearest_depth: texture(
                "dom nearest depth",
                DEPTH_FORMAT,
                wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            ),
            layers: texture_2d(
                gpu,
                "dom layers",
                wgpu::Extent3d {
                    depth_or_array_layers: faces * array_layers_for(settings.layers),
                    ..size
                },
                gpu.hdr_format(),
                layer_usage,
            ),
        }
    }

    /// An opacity shadow map: `slices` layers of equal thickness from the nearest to the
    /// farthest extent of `bounds` along the light camera's axis. A cube's faces each start at
    /// their own nearest extent (no nearer than their near plane) and share the widest face's
    /// spacing, so that one spacing serves the lookup.
    pub fn opacity_slices(
        gpu: &GpuContext,
        layout: impl Into<ShadowLayout>,
        bounds: Aabb,
        resolution: u32,
        slices: u32,
    ) -> Result<Self, DomSettingsError> {
        let layout = layout.into();
        let faces = layout.faces();
        let ranges: Vec<(f32, f32)> = faces.iter().map(|c| depth_extent(c, bounds)).collect();
        let widest = ranges
            .iter()
            .map(|(nearest, farthest)| farthest - nearest)
            .fold(0.0f32, f32::max);
        // A flat hair (all corners at one depth) still gets a usable, positive spacing.
        let camera = faces[0];
        let range = widest.max(1e-6 * (camera.far - camera.near));
        let settings = DomSettings {
            resolution,
            layers: slices,
            spacing: range / slices as f32,
        };
        settings.check()?;
        let mut start = [0.0; CUBE_FACES];
        for ((face, camera), (nearest, _)) in start.iter_mut().zip(&faces).zip(&ranges) {
            *face = camera.depth_buffer_value(*nearest).clamp(0.0, 1.0);
        }
        Ok(Self {
            layer_start: LayerStart::Fixed(start),
            ..Self::new(gpu, layout, settings)
        })
    }

    /// Array layers of [`Self::layers`] per face.
    pub fn face_array_layers(&self) -> u32 {
        self.layers.depth_or_array_layers() / self.layout.face_count()
    }

    /// The same map read through `kernel`×`kernel` PCF (layer lookups only).
    pub fn with_layer_pcf(mut self, kernel: u32) -> Result<Self, ShadowLookupError> {
        let lookup = ShadowLookup::Layers { kernel };
        lookup.check()?;
        self.lookup = lookup;
        Ok(self)
    }

    /// A shadow map (or ADSM) of `resolution`²: the nearest depth only, with 1×1 layer
    /// placeholders for the shading passes' bindings.
    pub fn depth_only(
        gpu: &GpuContext,
        layout: impl Into<ShadowLayout>,
        resolution: u32,
        lookup: ShadowLookup,
    ) -> Result<Self, ShadowMapError> {
        let layout = layout.into();
        lookup.check()?;
        let settings = DomSettings {
            resolution,
            layers: 1,
            spacing: 1.0,
        };
        settings.check()?;
        let mut map = Self::new(gpu, layout, settings);
        let placeholder = Self::new(
            gpu,
            layout,
            DomSettings {
                resolution: 1,
                ..settings
            },
        );
        map.layers = placeholder.layers;
        map.lookup = lookup;
        Ok(map)
    }

    /// Per texel, the K layers' optical depths (row-major from the top), of the first face.
    pub fn read_layers(&self, gpu: &GpuContext) -> Result<Vec<Vec<f32>>, ReadbackError> {
        self.read_face_layers(gpu, 0)
    }

    /// [`Self::read_layers`] of face `face`.
    pub fn read_face_layers(
        &self,
        gpu: &GpuContext,
        face: u32,
    ) -> Result<Vec<Vec<f32>>, ReadbackError> {
        let k = self.settings.layers as usize;
        let first = face * self.face_array_layers();
        let groups = (0..k.div_ceil(4) as u32)
            .map(|g| read_texture_layer_rgba(gpu, &self.layers, first + g))
            .collect::<Result<Vec<_>, _>>()?;
        let texels = groups[0].len();
        Ok((0..texels)
            .map(|t| groups.iter().flat_map(|g| g[t]).take(k).collect())
            .collect())
    }

    /// Bytes per texture (a cube's six faces included).
    pub fn memory(&self) -> Vec<(String, u64)> {
        let face_texels = self.settings.resolution as u64 * self.settings.resolution as u64;
        let depth_bytes = face_texels * self.layout.face_count() as u64 * 4;
        if !self.lookup.uses_layers() {
            return vec![("shadow map depth".into(), depth_bytes)];
        }
        let layer_texel = self.layers.format().block_copy_size(None).unwrap_or(16) as u64;
        // Every face's array layers: the texture's whole depth.
        let array_layers = self.layers.depth_or_array_layers() as u64;
        vec![
            ("dom nearest depth".into(), depth_bytes),
            (
                "dom layers".into(),
                array_layers * face_texels * layer_texel,
            ),
        ]
    }
}

/// A light's map could not be made.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum ShadowMapError {
    #[error(transparent)]
    Settings(#[from] DomSettingsError),
    #[error(transparent)]
    Lookup(#[from] ShadowLookupError),
    #[error(transparent)]
    LightInsideHair(#[from] crate::camera::LightInsideHair),
    #[error(transparent)]
    LightNotFinite(#[from] crate::shadow_layout::LightNotFinite),
}

/// The nearest and farthest depth of `bounds`' corners along `camera`'s axis (view-space depth:
/// for a perspective camera too, the quantity the layer pass linearizes to), no nearer than its
/// near plane.
fn depth_extent(camera: &crate::camera::Camera, bounds: Aabb) -> (f32, f32) {
    let forward = (camera.target - camera.eye).normalize();
    let depths = bounds.corners().map(|c| (c - camera.eye).dot(forward));
    let nearest = depths.iter().copied().fold(f32::INFINITY, f32::min);
    let farthest = depths.iter().copied().fold(f32::NEG_INFINITY, f32::max);
    let nearest = nearest.max(camera.near);
    (nearest, farthest.max(nearest))
}

/// Transmittance in front of layer `k` from one texel's layers: exp(−Σ_{j<k} layer_j).
pub fn transmittance_before_layer(layers: &[f32], k: usize) -> f64 {
    (-layers[..k.min(layers.len())]
        .iter()
        .map(|&t| t as f64)
        .sum::<f64>())
    .exp()
}

/// The two pipelines, built once.
pub struct DeepOpacityPass {
    depth_pipeline: wgpu::RenderPipeline,
    layer_pipeline: wgpu::RenderPipeline,
    strand_layout: wgpu::BindGroupLayout,
    dom_layout: wgpu::BindGroupLayout,
}

impl DeepOpacityPass {
    pub fn new(gpu: &GpuContext) -> Self {
        let device = &gpu.device;
        let top = Wgsl {
            file: "deep_opacity.wgsl",
            source: include_str!("deep_opacity.wgsl"),
        };
        let shader = shader_module(device, &top, None);
        let strand_layout = strand_bind_group_layout(device);
        let dom_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("dom"),
            entries: &[
                depth_texture_entry(0, wgpu::ShaderStages::FRAGMENT),
                uniform_entry(1, wgpu::ShaderStages::FRAGMENT),
            ],
        });
        let depth_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("dom depth"),
            bind_group_layouts: &[Some(&strand_layout)],
            immediate_size: 0,
        });
        let layer_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("dom layers"),
            bind_group_layouts: &[Some(&strand_layout), Some(&dom_layout)],
            immediate_size: 0,
        });
        let depth_pipeline = StrandDraw {
            label: "dom depth",
            layout: &depth_layout,
            shader: &shader,
            vertex_entry: "vs_main",
            fragment: None,
            depth: Some(depth_test(DEPTH_FORMAT, true, wgpu::CompareFunction::Less)),
        }
        .build(device);
        let targets =
            vec![color_target(gpu.hdr_format(), Some(ADDITIVE)); TARGETS_PER_PASS as usize];
        let layer_pipeline = StrandDraw {
            label: "dom layers",
            layout: &layer_layout,
            shader: &shader,
            vertex_entry: "vs_main",
            fragment: Some(("fs_layers", &targets)),
            depth: None,
        }
        .build(device);
        Self {
            depth_pipeline,
            layer_pipeline,
            strand_layout,
            dom_layout,
        }
    }

    /// Fills `map` from `geometry` as seen from its light camera (each face of a cube from its
    /// own; a face that cannot see the hair is cleared, not drawn).
    pub fn draw(&self, gpu: &GpuContext, geometry: &StrandGeometry, map: &DeepOpacityMap) {
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        for face in 0..map.layout.face_count() {
            self.draw_face(gpu, geometry, map, face, &mut encoder);
        }
        gpu.queue.submit([encoder.finish()]);
    }

    /// Records the passes of face `face`: the nearest depth (or the fixed start), then the
    /// layers; without `drawn`, the same clears with nothing drawn.
    fn draw_face(
        &self,
        gpu: &GpuContext,
        geometry: &StrandGeometry,
        map: &DeepOpacityMap,
        face: u32,
        encoder: &mut wgpu::CommandEncoder,
    ) {
        let camera = map.layout.faces()[face as usize];
        let drawn = map.layout.face_drawn(face as usize);
        let res = map.settings.resolution;
        let frame = FrameParams {
            camera,
            width: res,
            height: res,
            lights: Vec::new(),
            shading: KajiyaKay::default(),
            width_override_px: None,
        };
        let strands = strand_bind_group(gpu, &self.strand_layout, geometry, &frame);
        let depth_view = array_layer_view(&map.nearest_depth, face);
        let segments = if drawn { geometry.segment_count } else { 0 };
        match map.layer_start {
            LayerStart::NearestFiber => {
                let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("dom depth"),
                    color_attachments: &[],
                    depth_stencil_attachment: cleared_depth(&depth_view, true),
                    timestamp_writes: gpu.render_timestamps(),
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
                pass.set_pipeline(&self.depth_pipeline);
                pass.set_bind_group(0, &strands, &[]);
                pass.draw(0..6, 0..segments);
            }
            LayerStart::Fixed(start) => {
                // The layer pass and the lookup read the start from the depth texture either way.
                encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("osm start depth"),
                    depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                        view: &depth_view,
                        depth_ops: Some(wgpu::Operations {
                            load: wgpu::LoadOp::Clear(start[face as usize]),
                            store: wgpu::StoreOp::Store,
                        }),
                        stencil_ops: None,
                    }),
                    ..Default::default()
                });
            }
        }
        if !map.lookup.uses_layers() {
            return;
        }
        let first_array_layer = face * map.face_array_layers();
        for first_layer in (0..map.settings.layers).step_by(LAYERS_PER_PASS as usize) {
            let dom_group = self.layer_group(gpu, map, &camera, &depth_view, first_layer);
            let views: Vec<_> = (0..TARGETS_PER_PASS)
                .map(|t| array_layer_view(&map.layers, first_array_layer + first_layer / 4 + t))
                .collect();
            let attachments: Vec<_> = views.iter().map(cleared_color).collect();
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("dom layers"),
                color_attachments: &attachments,
                depth_stencil_attachment: None,
                timestamp_writes: gpu.render_timestamps(),
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&self.layer_pipeline);
            pass.set_bind_group(0, &strands, &[]);
            pass.set_bind_group(1, &dom_group, &[]);
            pass.draw(0..6, 0..segments);
        }
    }

    /// Group 1 of the layer pass that fills layers `first_layer..first_layer + LAYERS_PER_PASS`.
    fn layer_group(
        &self,
        gpu: &GpuContext,
        map: &DeepOpacityMap,
        camera: &crate::camera::Camera,
        depth_view: &wgpu::TextureView,
        first_layer: u32,
    ) -> wgpu::BindGroup {
        let uniform = gpu
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("dom params"),
                contents: bytemuck::bytes_of(&DomUniform {
                    near: camera.near,
                    far: camera.far,
                    spacing: map.settings.spacing,
                    layers: map.settings.layers,
                    perspective: camera.is_perspective() as u32,
                    first_layer,
                    _pad: [0; 2],
                }),
                usage: wgpu::BufferUsages::UNIFORM,
            });
        bind_group(
            &gpu.device,
            "dom",
            &self.dom_layout,
            &[
                wgpu::BindingResource::TextureView(depth_view),
                uniform.as_entire_binding(),
            ],
        )
    }
}

/// A 2D view of one array layer, to render into.
fn array_layer_view(texture: &wgpu::Texture, layer: u32) -> wgpu::TextureView {
    texture.create_view(&wgpu::TextureViewDescriptor {
        dimension: Some(wgpu::TextureViewDimension::D2),
        base_array_layer: layer,
        array_layer_count: Some(1),
        ..Default::default()
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
                file: "deep_opacity.wgsl",
                source: include_str!("deep_opacity.wgsl"),
            },
            None,
            "DomParams",
            &rust_layout!(DomUniform {
                near,
                far,
                spacing,
                layers,
                perspective,
                first_layer
            }),
        );
    }
}
