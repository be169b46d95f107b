//! The env-lit view pass (Ren 2010 §3.1, §5–6): each fiber the frame's visibility lets through
//! ([`ViewTransparency`], built once per frame by [`ViewVisibilityPass`]: the nearest fiber of
//! each pixel, shaded by a full-screen pass, or every fragment of the strands rasterized again
//! through the occupancy map) loops over a batch's lights and sums
//! T̃ × table lookup × light weight (single scattering) and, with a forward-scattering grid,
//! power × T_f × I_G (multiple scattering) into two targets (`env_view.wgsl`). A small compute
//! pass adds each batch's images into running float sums (`env_accumulate.wgsl`).
//! Inputs: [`StrandGeometry`], [`FrameParams`] (camera), [`BatchBinding`] (lights + DODM + SAT),
//! [`TableBinding`] (the tables), [`ViewBinding`] (the batch's grid and the frame's occupancy
//! map). Output: the sums buffer of [`EnvAccumulator`].

use glam::Vec3;
use strandlight_tables::table::{AxisGpu, Table};
use wgpu::util::DeviceExt;

use super::attachments::cleared_color;
use super::convolution_depth::DodmBatch;
use super::frame_params::FrameParams;
use super::head::{HeadDepthMaps, HeadPass};
use super::render_target::DEPTH_FORMAT;
use super::strand_geometry::StrandGeometry;
use super::strand_quads::{strand_bind_group, strand_bind_group_layout_vertex_storage};
use super::summed_area::{MAX_BOX_HALF_SIZE, SummedAreaTables};
use super::transmittance_filter::TransmittanceFilter;
use super::view_visibility::{
    NEAREST_SURFACE_FORMAT, OccupancyMap, ViewTransparency, ViewVisibilityPass,
};
use crate::env_light::{EnvLight, ShadowGroup};
use crate::gpu::GpuContext;
use crate::gpu::bind_layout::{
    float_array_texture_entry, float_texture_entry, pipeline_layout, storage_entry, uniform_entry,
};
use crate::gpu::pipeline::{ADDITIVE, StrandDraw, color_target, compute_pipeline, wgsl_module};
use crate::gpu::texture::texture_2d;
use crate::multiple::ForwardScatteringGrid;
use crate::visibility::VisibilityVolume;

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
        let device = &gpu.device;
        let placeholder;
        let head_maps = match head {
            Some(maps) => maps,
            None => {
                placeholder = HeadDepthMaps::placeholder(gpu);
                &placeholder
            }
        };
        let head_view = head_maps.array_view();
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
        let flags = if shadowed { 0 } else { FLAG_UNSHADOWED }
            | if with_grid { FLAG_GRID } else { 0 }
            | if head.is_some() && shadowed {
                FLAG_HEAD
            } else {
                0
            };
        let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("env batch"),
            contents: bytemuck::bytes_of(&BatchUniform {
                light_count: groups.len() as u32,
                resolution: dodm.resolution,
                max_half_size: MAX_BOX_HALF_SIZE,
                flags,
            }),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let light_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("env lights"),
            contents: bytemuck::cast_slice(&gpu_lights),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let sample_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("env shading samples"),
            contents: bytemuck::cast_slice(&samples),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let depth_view = DodmBatch::array_view(&dodm.nearest_depth);
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("env batch"),
            layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: uniform.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: light_buffer.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: wgpu::BindingResource::TextureView(&depth_view),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: sat.buffer.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 4,
                    resource: sample_buffer.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 5,
                    resource: wgpu::BindingResource::TextureView(&head_view),
                },
            ],
        });
        Self { group }
    }
}

#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct TableLayoutUniform {
    axes: [AxisGpu; 4],
    strides: [u32; 4],
}

/// A four-axis RGB table's uniform: axes and element strides (row-major, channels innermost).
fn table_layout(table: &Table) -> TableLayoutUniform {
    let axes = table.gpu_axes();
    let shape = table.shape();
    let c = table.channels();
    TableLayoutUniform {
        axes: [axes[0], axes[1], axes[2], axes[3]],
        strides: [
            (shape[1] * shape[2] * shape[3] * c) as u32,
            (shape[2] * shape[3] * c) as u32,
            (shape[3] * c) as u32,
            c as u32,
        ],
    }
}

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
}

/// Group 2: the single-scattering table (the SRBF convolution table, or the direct table for
/// directional lights) and the multiple-scattering table (a 1-element placeholder where absent).
/// Built once per light kind per frame.
pub struct TableBinding {
    pub group: wgpu::BindGroup,
    pub bytes: u64,
}

fn bind_buffers(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::BindGroupLayout,
    buffers: &[&wgpu::Buffer],
) -> (wgpu::BindGroup, u64) {
    let entries: Vec<_> = buffers
        .iter()
        .enumerate()
        .map(|(i, b)| wgpu::BindGroupEntry {
            binding: i as u32,
            resource: b.as_entire_binding(),
        })
        .collect();
    let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout,
        entries: &entries,
    });
    (group, buffers.iter().map(|b| b.size()).sum())
}

fn init_buffer(
    device: &wgpu::Device,
    label: &str,
    contents: &[u8],
    usage: wgpu::BufferUsages,
) -> wgpu::Buffer {
    device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(label),
        contents,
        usage,
    })
}

impl TableBinding {
    /// Tables must have 4 axes and 3 channels (checked by the caller).
    pub fn new(
        gpu: &GpuContext,
        layout: &wgpu::BindGroupLayout,
        single: &Table,
        multiple: Option<&Table>,
    ) -> Self {
        let device = &gpu.device;
        let storage = wgpu::BufferUsages::STORAGE;
        let uniform = wgpu::BufferUsages::UNIFORM;
        let single_layout = init_buffer(
            device,
            "env single layout",
            bytemuck::bytes_of(&table_layout(single)),
            uniform,
        );
        let single_values = init_buffer(device, "env single table", single.as_bytes(), storage);
        let multiple_table = multiple.unwrap_or(single);
        let multiple_layout = init_buffer(
            device,
            "env multiple layout",
            bytemuck::bytes_of(&table_layout(multiple_table)),
            uniform,
        );
        let multiple_values = match multiple {
            Some(t) => init_buffer(device, "env multiple table", t.as_bytes(), storage),
            None => init_buffer(device, "env multiple table", &[0u8; 16], storage),
        };
        let (group, bytes) = bind_buffers(
            device,
            "env tables",
            layout,
            &[
                &single_layout,
                &single_values,
                &multiple_layout,
                &multiple_values,
            ],
        );
        Self { group, bytes }
    }
}

/// Group 3: one batch's forward-scattering grid (a placeholder without multiple scattering) and
/// the frame's occupancy map.
pub struct ViewBinding {
    pub group: wgpu::BindGroup,
    /// Bytes of the grid.
    pub bytes: u64,
}

/// The visibility volume as group 3 reads it (bindings 6 and 7, `visibility_volume.wgsl`): the
/// SH coefficients of T(ω) at a grid's vertices, or a placeholder that leaves SRBF lobes to
/// their light maps. Uploaded once per groom.
pub struct VolumeBuffers {
    params: wgpu::Buffer,
    coefficients: wgpu::Buffer,
    /// Bytes of the coefficients (0 for the placeholder).
    pub bytes: u64,
}

#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct VolumeUniform {
    origin: [f32; 4],
    dims: [u32; 4],
    spacing: [f32; 4],
}

impl VolumeBuffers {
    pub fn new(gpu: &GpuContext, volume: Option<&VisibilityVolume>) -> Self {
        let device = &gpu.device;
        let (uniform, coefficients, bytes) = match volume {
            Some(v) => (
                VolumeUniform {
                    origin: v.origin.extend(1.0).into(),
                    dims: [v.dims[0], v.dims[1], v.dims[2], 0],
                    spacing: [v.spacing, 0.0, 0.0, 0.0],
                },
                v.bytes(),
                v.bytes().len() as u64,
            ),
            None => (
                VolumeUniform {
                    origin: [0.0; 4],
                    dims: [1, 1, 1, 0],
                    spacing: [1.0, 0.0, 0.0, 0.0],
                },
                &[0u8; 64][..],
                0,
            ),
        };
        Self {
            params: init_buffer(
                device,
                "visibility volume params",
                bytemuck::bytes_of(&uniform),
                wgpu::BufferUsages::UNIFORM,
            ),
            coefficients: init_buffer(
                device,
                "visibility volume",
                coefficients,
                wgpu::BufferUsages::STORAGE,
            ),
            bytes,
        }
    }
}

/// What group 3 is built from besides the grid.
pub struct FrameVisibility<'a> {
    /// SRBF lobes' visibility volume, or its placeholder.
    pub volume: &'a VolumeBuffers,
    pub map: &'a OccupancyMap,
    /// [`EnvViewTargets::coverage`].
    pub coverage: &'a wgpu::TextureView,
    /// [`EnvViewTargets::nearest_position`] and [`EnvViewTargets::nearest_tangent`].
    pub nearest: [&'a wgpu::TextureView; 2],
    pub transparency: ViewTransparency,
    pub width: u32,
    pub height: u32,
    /// [`EnvViewTargets::head_position`] and [`EnvViewTargets::head_normal`].
    pub head: [&'a wgpu::TextureView; 2],
    /// The head's skin albedo; None: no head.
    pub skin: Option<[f32; 3]>,
    /// The view camera's world-to-clip matrix (the layered view inverts it).
    pub view_proj: glam::Mat4,
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

/// Two HDR targets (single, multiple) for one batch's view pass, and what the opaque view reads
/// of the frame's visibility: the depth prepass, the coverage (red: Σ −ln(1 − α) of a pixel's
/// fragments; the opaque view's alpha) and the nearest fiber's position (w: 1 on hair) and
/// tangent, f32 so that the deferred view shades the very point the rasterizer interpolated
/// (the three are 1×1 and unused for the transparent view).
pub struct EnvViewTargets {
    pub single: wgpu::Texture,
    pub multiple: wgpu::Texture,
    pub depth: wgpu::Texture,
    pub coverage: wgpu::Texture,
    pub nearest_position: wgpu::Texture,
    pub nearest_tangent: wgpu::Texture,
    /// The head seen from the view (`head.wgsl`): world position (w: 1 on the head) and normal;
    /// 1×1 without a head.
    pub head_position: wgpu::Texture,
    pub head_normal: wgpu::Texture,
}

impl EnvViewTargets {
    pub fn new(
        gpu: &GpuContext,
        width: u32,
        height: u32,
        transparency: ViewTransparency,
        with_head: bool,
    ) -> Self {
        let size = wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        };
        let texture = |label, format, usage| texture_2d(gpu, label, size, format, usage);
        let color = wgpu::TextureUsages::RENDER_ATTACHMENT
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_SRC;
        let opaque_only = match transparency {
            ViewTransparency::Opaque => size,
            _ => wgpu::Extent3d {
                width: 1,
                height: 1,
                depth_or_array_layers: 1,
            },
        };
        let read_by_view =
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING;
        let visibility = |label, format| texture_2d(gpu, label, opaque_only, format, read_by_view);
        let head_size = match with_head {
            true => size,
            false => wgpu::Extent3d {
                width: 1,
                height: 1,
                depth_or_array_layers: 1,
            },
        };
        let head = |label| texture_2d(gpu, label, head_size, NEAREST_SURFACE_FORMAT, read_by_view);
        Self {
            single: texture("env single", gpu.hdr_format(), color),
            multiple: texture("env multiple", gpu.hdr_format(), color),
            depth: texture(
                "env depth",
                DEPTH_FORMAT,
                wgpu::TextureUsages::RENDER_ATTACHMENT,
            ),
            coverage: visibility("env coverage", gpu.hdr_format()),
            nearest_position: visibility("env nearest position", NEAREST_SURFACE_FORMAT),
            nearest_tangent: visibility("env nearest tangent", NEAREST_SURFACE_FORMAT),
            head_position: head("env head position"),
            head_normal: head("env head normal"),
        }
    }

    pub fn memory(&self) -> Vec<(String, u64)> {
        let bytes = |t: &wgpu::Texture| {
            t.width() as u64
                * t.height() as u64
                * t.format().block_copy_size(None).unwrap_or(4) as u64
        };
        vec![
            ("env single target".into(), bytes(&self.single)),
            ("env multiple target".into(), bytes(&self.multiple)),
            ("env depth".into(), bytes(&self.depth)),
            ("env coverage".into(), bytes(&self.coverage)),
            ("env nearest position".into(), bytes(&self.nearest_position)),
            ("env nearest tangent".into(), bytes(&self.nearest_tangent)),
            ("env head position".into(), bytes(&self.head_position)),
            ("env head normal".into(), bytes(&self.head_normal)),
        ]
    }
}

/// Running sums over batches: `2·width·height` RGBA f32 (single, then multiple).
pub struct EnvAccumulator {
    pub sums: wgpu::Buffer,
    pub width: u32,
    pub height: u32,
    group: wgpu::BindGroup,
}

#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct AccumulateUniform {
    width: u32,
    height: u32,
    _pad: [u32; 2],
}

/// The view, visibility and accumulate pipelines, built once.
pub struct EnvViewPass {
    opaque: wgpu::RenderPipeline,
    transparent: wgpu::RenderPipeline,
    layered: wgpu::RenderPipeline,
    /// Occupancy and layered views: the skin behind the pixel's fibers (`skin.wgsl`), added after them.
    skin_behind_hair: wgpu::RenderPipeline,
    pub head: HeadPass,
    pub visibility: ViewVisibilityPass,
    accumulate: wgpu::ComputePipeline,
    accumulate_layout: wgpu::BindGroupLayout,
    pub strand_layout: wgpu::BindGroupLayout,
    pub batch_layout: wgpu::BindGroupLayout,
    pub table_layout: wgpu::BindGroupLayout,
    pub view_layout: wgpu::BindGroupLayout,
}

/// The bind group layouts of the view pass: strands (0), the batch's lights, DODM and SATs (1),
/// the tables (2), the grid and the frame's visibility (3).
struct EnvViewLayouts {
    strand: wgpu::BindGroupLayout,
    batch: wgpu::BindGroupLayout,
    table: wgpu::BindGroupLayout,
    view: wgpu::BindGroupLayout,
}

impl EnvViewLayouts {
    fn new(device: &wgpu::Device) -> Self {
        let fragment = wgpu::ShaderStages::FRAGMENT;
        let layout = |label, entries: &[wgpu::BindGroupLayoutEntry]| {
            device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some(label),
                entries,
            })
        };
        Self {
            strand: strand_bind_group_layout_vertex_storage(device),
            batch: transmittance_bind_group_layout(device, fragment),
            table: layout(
                "env tables",
                &[
                    uniform_entry(0, fragment),
                    storage_entry(1, fragment, true),
                    uniform_entry(2, fragment),
                    storage_entry(3, fragment, true),
                ],
            ),
            view: layout(
                "env view",
                &[
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
            ),
        }
    }
}

/// The view and visibility passes share one module, so that they rasterize bit-identical
/// depths (the fragment count's Equal depth test after the prepass relies on it).
fn env_view_shader(device: &wgpu::Device) -> wgpu::ShaderModule {
    let source = [
        include_str!("strand_quads.wgsl"),
        include_str!("fiber_frame.wgsl"),
        include_str!("convolution_transmittance.wgsl"),
        include_str!("occupancy_map.wgsl"),
        include_str!("table_axis.wgsl"),
        include_str!("env_view.wgsl"),
        include_str!("visibility_volume.wgsl"),
        include_str!("view_visibility.wgsl"),
        include_str!("view_layers.wgsl"),
        include_str!("skin.wgsl"),
    ]
    .concat();
    wgsl_module(device, "env_view.wgsl", &source)
}

/// A view pipeline writing the single and multiple targets from vertex entry `vertex` and
/// fragment entry `entry`.
fn view_pipeline(
    gpu: &GpuContext,
    layout: &wgpu::PipelineLayout,
    shader: &wgpu::ShaderModule,
    (label, vertex, entry): (&str, &str, &str),
    blend: Option<wgpu::BlendState>,
) -> wgpu::RenderPipeline {
    let target = color_target(gpu.hdr_format(), blend);
    StrandDraw {
        label,
        layout,
        shader,
        vertex_entry: vertex,
        fragment: Some((entry, &[target.clone(), target])),
        depth: None,
    }
    .build(&gpu.device)
}

/// The compute pass adding a batch's two images into the sums, and its layout.
fn accumulate_pipeline(device: &wgpu::Device) -> (wgpu::ComputePipeline, wgpu::BindGroupLayout) {
    let compute = wgpu::ShaderStages::COMPUTE;
    let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("env accumulate"),
        entries: &[
            float_texture_entry(0, compute),
            float_texture_entry(1, compute),
            storage_entry(2, compute, false),
            uniform_entry(3, compute),
        ],
    });
    let shader = wgsl_module(
        device,
        "env_accumulate.wgsl",
        include_str!("env_accumulate.wgsl"),
    );
    let pipeline = compute_pipeline(
        device,
        "env accumulate",
        &pipeline_layout(device, "env accumulate", &[Some(&layout)]),
        &shader,
        "accumulate",
    );
    (pipeline, layout)
}

impl EnvViewPass {
    pub fn new(gpu: &GpuContext) -> Self {
        let device = &gpu.device;
        let shader = env_view_shader(device);
        let layouts = EnvViewLayouts::new(device);
        let layout = pipeline_layout(
            device,
            "env view",
            &[
                Some(&layouts.strand),
                Some(&layouts.batch),
                Some(&layouts.table),
                Some(&layouts.view),
            ],
        );
        let visibility_layout = pipeline_layout(
            device,
            "view visibility",
            &[Some(&layouts.strand), None, None, Some(&layouts.view)],
        );
        // The coverage pass writes the texture group 3 reads: it binds the strands alone.
        let strands_only = pipeline_layout(device, "view coverage", &[Some(&layouts.strand)]);
        let visibility = ViewVisibilityPass::new(
            device,
            &shader,
            &visibility_layout,
            &strands_only,
            gpu.hdr_format(),
        );
        // The depth prepass left each pixel's nearest fiber in two textures: the opaque view
        // shades those pixels, rasterizing no strand per batch.
        let opaque = view_pipeline(
            gpu,
            &layout,
            &shader,
            ("env view (opaque)", "vs_fullscreen", "fs_env_deferred"),
            None,
        );
        let transparent = view_pipeline(
            gpu,
            &layout,
            &shader,
            ("env view (occupancy)", "vs_main", "fs_env_transparent"),
            Some(ADDITIVE),
        );
        // The layers the frame's visibility gathered: a full-screen pass, added to by the skin.
        let layered = view_pipeline(
            gpu,
            &layout,
            &shader,
            ("env view (layered)", "vs_fullscreen", "fs_env_layered"),
            Some(ADDITIVE),
        );
        let skin_behind_hair = view_pipeline(
            gpu,
            &layout,
            &shader,
            (
                "env view (skin behind hair)",
                "vs_fullscreen",
                "fs_env_skin",
            ),
            Some(ADDITIVE),
        );
        let (accumulate, accumulate_layout) = accumulate_pipeline(device);
        Self {
            opaque,
            transparent,
            layered,
            skin_behind_hair,
            head: HeadPass::new(gpu),
            visibility,
            accumulate,
            accumulate_layout,
            strand_layout: layouts.strand,
            batch_layout: layouts.batch,
            table_layout: layouts.table,
            view_layout: layouts.view,
        }
    }

    /// Bytes of the sums of a `width`×`height` frame: RGBA f32 per pixel, single then multiple.
    pub fn accumulator_bytes(width: u32, height: u32) -> u64 {
        2 * width as u64 * height as u64 * 16
    }

    /// Zeroed sums for a `width`×`height` frame, bound to `targets`.
    pub fn accumulator(&self, gpu: &GpuContext, targets: &EnvViewTargets) -> EnvAccumulator {
        let device = &gpu.device;
        let (width, height) = (targets.single.width(), targets.single.height());
        let sums = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("env sums"),
            size: Self::accumulator_bytes(width, height),
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("env accumulate params"),
            contents: bytemuck::bytes_of(&AccumulateUniform {
                width,
                height,
                _pad: [0; 2],
            }),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let single = targets.single.create_view(&Default::default());
        let multiple = targets.multiple.create_view(&Default::default());
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("env accumulate"),
            layout: &self.accumulate_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(&single),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(&multiple),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: sums.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: uniform.as_entire_binding(),
                },
            ],
        });
        EnvAccumulator {
            sums,
            width,
            height,
            group,
        }
    }

    /// The strands' bind group of the view (group 0 of every view and visibility pass).
    pub fn strands(
        &self,
        gpu: &GpuContext,
        geometry: &StrandGeometry,
        frame: &FrameParams,
    ) -> wgpu::BindGroup {
        strand_bind_group(gpu, &self.strand_layout, geometry, frame)
    }

    /// Encodes one batch: the view pass into `targets` (opaque: a full-screen pass over the
    /// nearest fibers the frame's depth prepass left; occupancy: the strands rasterized again),
    /// then its addition into `sums`.
    #[allow(clippy::too_many_arguments)]
    pub fn encode(
        &self,
        gpu: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        geometry: &StrandGeometry,
        strands: &wgpu::BindGroup,
        transparency: ViewTransparency,
        batch: &BatchBinding,
        tables: &TableBinding,
        view: &ViewBinding,
        targets: &EnvViewTargets,
        sums: &EnvAccumulator,
        with_head: bool,
    ) {
        let single = targets.single.create_view(&Default::default());
        let multiple = targets.multiple.create_view(&Default::default());
        let (pipeline, vertices, instances) = match transparency {
            ViewTransparency::Opaque => (&self.opaque, 3, 1),
            ViewTransparency::Occupancy { .. } => (&self.transparent, 6, geometry.segment_count),
            ViewTransparency::Layered { .. } => (&self.layered, 3, 1),
        };
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("env view"),
                color_attachments: &[cleared_color(&single), cleared_color(&multiple)],
                depth_stencil_attachment: None,
                timestamp_writes: gpu.render_timestamps(),
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, strands, &[]);
            pass.set_bind_group(1, &batch.group, &[]);
            pass.set_bind_group(2, &tables.group, &[]);
            pass.set_bind_group(3, &view.group, &[]);
            pass.draw(0..vertices, 0..instances);
            if transparency.uses_occupancy_map() && with_head {
                pass.set_pipeline(&self.skin_behind_hair);
                pass.draw(0..3, 0..1);
            }
        }
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("env accumulate"),
            timestamp_writes: gpu.compute_timestamps(),
        });
        pass.set_pipeline(&self.accumulate);
        pass.set_bind_group(0, &sums.group, &[]);
        pass.dispatch_workgroups(sums.width.div_ceil(8), sums.height.div_ceil(8), 1);
    }
}
