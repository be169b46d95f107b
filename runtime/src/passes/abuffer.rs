//! Order-independent transparency with an A-buffer: per-pixel linked lists of shaded fragments
//! built with storage-buffer atomics (`abuffer.wgsl`), then sorted and composited front to back
//! by a compute resolve (`abuffer_resolve.wgsl`). Node-buffer overflow and resolve truncation
//! are counted and reported, never silent.
//! Fragments are shaded exactly as the opaque strand pass shades them: the same WGSL (any
//! [`ShadingModel`], group 2) and a deep opacity map for each of up to
//! [`MAX_SHADOWED_LIGHTS`](crate::passes::shadow_slots::MAX_SHADOWED_LIGHTS) lights (group 1).
//! Inputs: [`StrandGeometry`], [`FrameParams`], the shadow maps, the node capacity.
//! Output: [`ABufferFrame`].

use super::attachments::{cleared_color, cleared_depth};
use wgpu::util::DeviceExt;

use crate::gpu::GpuContext;
use crate::gpu::bind_layout::{
    depth_texture_entry, float_texture_entry, storage_entry, uniform_entry,
};
use crate::gpu::readback::{ReadbackError, read_buffer};
use crate::passes::fiber_shading::{ModelBinding, ShadingModel};
use crate::passes::frame_params::FrameParams;
use crate::passes::render_target::{DEPTH_FORMAT, RenderTarget};
use crate::passes::shadow_slots::{
    ShadowInput, TooManyShadowMaps, shadow_bind_group_for, shadow_bind_group_layout,
};
use crate::passes::strand_geometry::StrandGeometry;
use crate::passes::strand_quads::{strand_bind_group, strand_bind_group_layout};
use crate::passes::strands::shading_source;

#[derive(Debug, thiserror::Error)]
pub enum ABufferError {
    #[error(transparent)]
    TooManyShadowMaps(#[from] TooManyShadowMaps),
    #[error(transparent)]
    Readback(#[from] ReadbackError),
}

/// Bytes per list node (colour, depth, next, padding).
pub const NODE_BYTES: u64 = 32;
/// Fragments one pixel can sort at resolve; more are counted as truncated.
pub const MAX_SORTED_PER_PIXEL: u32 = 64;

pub struct ABufferFrame {
    /// Linear pre-multiplied RGBA, row-major from the top.
    pub pixels: Vec<[f32; 4]>,
    /// Fragments that found a node.
    pub fragments_stored: u64,
    /// Fragments dropped because the node buffer was full.
    pub fragments_dropped: u64,
    /// Fragments beyond [`MAX_SORTED_PER_PIXEL`] in a pixel, left out at resolve.
    pub fragments_truncated: u64,
    pub memory_bytes: Vec<(String, u64)>,
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Params {
    a: u32,
    b: u32,
    _pad: [u32; 2],
}

/// Which fragments go into the lists.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ListMode {
    /// Every fragment (A-buffer).
    All,
    /// DBK-buffer: fragments within `delta` (view depth, world units) of the pixel's nearest
    /// fiber; the rest fall back to an opaque depth-tested target composited underneath.
    Dbk { delta: f32 },
}

pub struct ABufferPass {
    build: wgpu::RenderPipeline,
    dbk_build: wgpu::RenderPipeline,
    depth_prepass: wgpu::RenderPipeline,
    resolve: wgpu::ComputePipeline,
    strand_layout: wgpu::BindGroupLayout,
    shadow_layout: wgpu::BindGroupLayout,
    /// Group 3 of the A-buffer build: heads, nodes, counters, parameters.
    lists_layout: wgpu::BindGroupLayout,
    /// Group 3 of the DBK build: the lists' bindings, then the nearest depth and DBK parameters.
    dbk_lists_layout: wgpu::BindGroupLayout,
    /// Group 2: the fiber model's constants and tables (none for Kajiya-Kay), as in
    /// [`StrandPass`](crate::passes::strands::StrandPass).
    model: Option<ModelBinding>,
}

impl ABufferPass {
    /// Kajiya-Kay shading with the constants of [`FrameParams::shading`].
    pub fn new(gpu: &GpuContext) -> Self {
        Self::with_model(gpu, &ShadingModel::KajiyaKay)
    }

    /// Fragments shaded with `model`; its tables and constants are uploaded once, here.
    pub fn with_model(gpu: &GpuContext, shading: &ShadingModel) -> Self {
        let device = &gpu.device;
        let build_shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("abuffer.wgsl"),
            source: wgpu::ShaderSource::Wgsl(
                shading_source(shading, include_str!("abuffer.wgsl")).into(),
            ),
        });
        let model = ModelBinding::new(gpu, shading);
        let resolve_shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("abuffer_resolve.wgsl"),
            source: wgpu::ShaderSource::Wgsl(include_str!("abuffer_resolve.wgsl").into()),
        });
        let strand_layout = strand_bind_group_layout(device);
        let shadow_layout = shadow_bind_group_layout(device);
        let frag = wgpu::ShaderStages::FRAGMENT;
        let list_entries = [
            storage_entry(0, frag, false),
            storage_entry(1, frag, false),
            storage_entry(2, frag, false),
            uniform_entry(3, frag),
        ];
        let lists_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("abuffer lists"),
            entries: &list_entries,
        });
        let model_layout = model.as_ref().map(|m| &m.layout);
        let build_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("abuffer build"),
            bind_group_layouts: &[
                Some(&strand_layout),
                Some(&shadow_layout),
                model_layout,
                Some(&lists_layout),
            ],
            immediate_size: 0,
        });
        let build = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("abuffer build"),
            layout: Some(&build_layout),
            vertex: wgpu::VertexState {
                module: &build_shader,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            fragment: Some(wgpu::FragmentState {
                module: &build_shader,
                entry_point: Some("fs_abuffer"),
                compilation_options: Default::default(),
                targets: &[],
            }),
            primitive: wgpu::PrimitiveState {
                topology: wgpu::PrimitiveTopology::TriangleList,
                cull_mode: None,
                ..Default::default()
            },
            // A depth attachment only to give the pass a size; every fragment passes.
            depth_stencil: Some(wgpu::DepthStencilState {
                format: DEPTH_FORMAT,
                depth_write_enabled: Some(false),
                depth_compare: Some(wgpu::CompareFunction::Always),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            multiview_mask: None,
            cache: None,
        });
        let compute = wgpu::ShaderStages::COMPUTE;
        let resolve_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("abuffer resolve"),
            entries: &[
                storage_entry(0, compute, true),
                storage_entry(1, compute, true),
                storage_entry(2, compute, false),
                storage_entry(3, compute, false),
                uniform_entry(4, compute),
                float_texture_entry(5, compute),
            ],
        });
        let resolve_pipeline_layout =
            device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("abuffer resolve"),
                bind_group_layouts: &[Some(&resolve_layout)],
                immediate_size: 0,
            });
        let resolve = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("abuffer resolve"),
            layout: Some(&resolve_pipeline_layout),
            module: &resolve_shader,
            entry_point: Some("resolve"),
            compilation_options: Default::default(),
            cache: None,
        });
        let dbk_lists_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("dbk lists"),
            entries: &[
                list_entries[0],
                list_entries[1],
                list_entries[2],
                list_entries[3],
                depth_texture_entry(4, frag),
                uniform_entry(5, frag),
            ],
        });
        let depth_tested = wgpu::DepthStencilState {
            format: DEPTH_FORMAT,
            depth_write_enabled: Some(true),
            depth_compare: Some(wgpu::CompareFunction::Less),
            stencil: Default::default(),
            bias: Default::default(),
        };
        let primitive = wgpu::PrimitiveState {
            topology: wgpu::PrimitiveTopology::TriangleList,
            cull_mode: None,
            ..Default::default()
        };
        let vertex = wgpu::VertexState {
            module: &build_shader,
            entry_point: Some("vs_main"),
            compilation_options: Default::default(),
            buffers: &[],
        };
        let prepass_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("dbk depth prepass"),
            bind_group_layouts: &[Some(&strand_layout)],
            immediate_size: 0,
        });
        let depth_prepass = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("dbk depth prepass"),
            layout: Some(&prepass_layout),
            vertex: vertex.clone(),
            fragment: None,
            primitive,
            depth_stencil: Some(depth_tested.clone()),
            multisample: Default::default(),
            multiview_mask: None,
            cache: None,
        });
        let dbk_pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("dbk build"),
            bind_group_layouts: &[
                Some(&strand_layout),
                Some(&shadow_layout),
                model_layout,
                Some(&dbk_lists_layout),
            ],
            immediate_size: 0,
        });
        let dbk_build = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("dbk build"),
            layout: Some(&dbk_pipeline_layout),
            vertex,
            fragment: Some(wgpu::FragmentState {
                module: &build_shader,
                entry_point: Some("fs_dbk"),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState {
                    format: gpu.hdr_format(),
                    blend: None,
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            primitive,
            depth_stencil: Some(depth_tested),
            multisample: Default::default(),
            multiview_mask: None,
            cache: None,
        });
        Self {
            build,
            dbk_build,
            depth_prepass,
            resolve,
            strand_layout,
            shadow_layout,
            lists_layout,
            dbk_lists_layout,
            model,
        }
    }

    /// DBK: the nearest-depth prepass, then the build that sorts fragments into the lists or
    /// the depth-tested fallback.
    fn encode_dbk(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        geometry: &StrandGeometry,
        nearest_view: &wgpu::TextureView,
        target: &RenderTarget,
        [strands, shadows, lists]: [&wgpu::BindGroup; 3],
    ) {
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("dbk depth prepass"),
                color_attachments: &[],
                depth_stencil_attachment: cleared_depth(&nearest_view, true),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&self.depth_prepass);
            pass.set_bind_group(0, strands, &[]);
            pass.draw(0..6, 0..geometry.segment_count);
        }
        let color_view = target.color.create_view(&Default::default());
        let depth_view = target.depth.create_view(&Default::default());
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("dbk build"),
            color_attachments: &[cleared_color(&color_view)],
            depth_stencil_attachment: cleared_depth(&depth_view, false),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.dbk_build);
        pass.set_bind_group(0, strands, &[]);
        pass.set_bind_group(1, shadows, &[]);
        if let Some(model) = &self.model {
            pass.set_bind_group(2, &model.group, &[]);
        }
        pass.set_bind_group(3, lists, &[]);
        pass.draw(0..6, 0..geometry.segment_count);
    }

    /// The node capacity the adapter's storage-binding limit allows, at most `wanted`.
    pub fn max_capacity(gpu: &GpuContext, wanted: u64) -> u32 {
        let limit = gpu.device.limits().max_storage_buffer_binding_size / NODE_BYTES;
        wanted.min(limit).min(u32::MAX as u64 - 1) as u32
    }

    /// Builds the lists and resolves them; `capacity` nodes (see [`Self::max_capacity`]).
    pub fn draw(
        &self,
        gpu: &GpuContext,
        geometry: &StrandGeometry,
        frame: &FrameParams,
        shadow: Option<ShadowInput<'_>>,
        capacity: u32,
        mode: ListMode,
    ) -> Result<ABufferFrame, ReadbackError> {
        match self.draw_shadowed(gpu, geometry, frame, shadow.as_slice(), capacity, mode) {
            Ok(out) => Ok(out),
            Err(ABufferError::Readback(e)) => Err(e),
            Err(ABufferError::TooManyShadowMaps(_)) => {
                unreachable!("one shadow map is within the limit")
            }
        }
    }

    /// [`Self::draw`] with a deep opacity map for each of up to
    /// [`MAX_SHADOWED_LIGHTS`](crate::passes::shadow_slots::MAX_SHADOWED_LIGHTS) lights.
    pub fn draw_shadowed(
        &self,
        gpu: &GpuContext,
        geometry: &StrandGeometry,
        frame: &FrameParams,
        shadows: &[ShadowInput<'_>],
        capacity: u32,
        mode: ListMode,
    ) -> Result<ABufferFrame, ABufferError> {
        let shadow_group = shadow_bind_group_for(gpu, &self.shadow_layout, frame, shadows)?;
        let device = &gpu.device;
        let (width, height) = (frame.width, frame.height);
        let pixels = width as u64 * height as u64;
        let storage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC;
        let heads = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("abuffer heads"),
            contents: bytemuck::cast_slice(&vec![u32::MAX; pixels as usize]),
            usage: storage,
        });
        let nodes = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("abuffer nodes"),
            size: capacity.max(1) as u64 * NODE_BYTES,
            usage: storage,
            mapped_at_creation: false,
        });
        let counters = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("abuffer counters"),
            contents: bytemuck::cast_slice(&[0u32; 2]),
            usage: storage,
        });
        let truncated = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("abuffer truncated"),
            contents: bytemuck::cast_slice(&[0u32; 1]),
            usage: storage,
        });
        let resolved = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("abuffer resolved"),
            size: pixels * 16,
            usage: storage,
            mapped_at_creation: false,
        });
        let uniform = |label, params: Params| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents: bytemuck::bytes_of(&params),
                usage: wgpu::BufferUsages::UNIFORM,
            })
        };
        let build_params = uniform(
            "abuffer params",
            Params {
                a: width,
                b: capacity,
                _pad: [0; 2],
            },
        );
        let is_dbk = matches!(mode, ListMode::Dbk { .. });
        let resolve_params = uniform(
            "abuffer resolve params",
            Params {
                a: width,
                b: height,
                _pad: [is_dbk as u32, 0],
            },
        );
        let target = RenderTarget::new(gpu, width, height);
        let nearest = RenderTarget::new(gpu, 1, 1);
        let nearest_depth = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("dbk nearest depth"),
            size: target.depth.size(),
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: DEPTH_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        // The A-buffer binds a 1×1 fallback it never reads.
        let fallback = if is_dbk {
            &target.color
        } else {
            &nearest.color
        };
        let fallback_view = fallback.create_view(&Default::default());
        let strands = strand_bind_group(gpu, &self.strand_layout, geometry, frame);
        let nearest_view = nearest_depth.create_view(&Default::default());
        let camera = &frame.camera;
        let delta = match mode {
            ListMode::Dbk { delta } => delta,
            ListMode::All => 0.0,
        };
        let dbk_params = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("dbk params"),
            contents: bytemuck::cast_slice(&[
                camera.near,
                camera.far,
                delta,
                f32::from_bits(camera.is_perspective() as u32),
            ]),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let mut list_entries = vec![
            wgpu::BindGroupEntry {
                binding: 0,
                resource: heads.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: nodes.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 2,
                resource: counters.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 3,
                resource: build_params.as_entire_binding(),
            },
        ];
        let lists_layout = if is_dbk {
            list_entries.push(wgpu::BindGroupEntry {
                binding: 4,
                resource: wgpu::BindingResource::TextureView(&nearest_view),
            });
            list_entries.push(wgpu::BindGroupEntry {
                binding: 5,
                resource: dbk_params.as_entire_binding(),
            });
            &self.dbk_lists_layout
        } else {
            &self.lists_layout
        };
        let lists = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("abuffer lists"),
            layout: lists_layout,
            entries: &list_entries,
        });
        let resolve_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("abuffer resolve"),
            layout: &self.resolve.get_bind_group_layout(0),
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: heads.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: nodes.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: resolved.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: truncated.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 4,
                    resource: resolve_params.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 5,
                    resource: wgpu::BindingResource::TextureView(&fallback_view),
                },
            ],
        });
        let depth_view = target.depth.create_view(&Default::default());
        let mut encoder = device.create_command_encoder(&Default::default());
        if is_dbk {
            self.encode_dbk(
                &mut encoder,
                geometry,
                &nearest_view,
                &target,
                [&strands, &shadow_group, &lists],
            );
        } else {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("abuffer build"),
                color_attachments: &[],
                depth_stencil_attachment: cleared_depth(&depth_view, false),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&self.build);
            pass.set_bind_group(0, &strands, &[]);
            pass.set_bind_group(1, &shadow_group, &[]);
            if let Some(model) = &self.model {
                pass.set_bind_group(2, &model.group, &[]);
            }
            pass.set_bind_group(3, &lists, &[]);
            pass.draw(0..6, 0..geometry.segment_count);
        }
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            pass.set_pipeline(&self.resolve);
            pass.set_bind_group(0, &resolve_group, &[]);
            pass.dispatch_workgroups(width.div_ceil(8), height.div_ceil(8), 1);
        }
        gpu.queue.submit([encoder.finish()]);
        let colour_bytes = read_buffer(gpu, &resolved)?;
        let counter_bytes = read_buffer(gpu, &counters)?;
        let truncated_bytes = read_buffer(gpu, &truncated)?;
        let floats: &[f32] = bytemuck::cast_slice(&colour_bytes);
        let counts: &[u32] = bytemuck::cast_slice(&counter_bytes);
        let requested = counts[0] as u64;
        let dropped = counts[1] as u64;
        Ok(ABufferFrame {
            pixels: floats
                .chunks_exact(4)
                .map(|c| [c[0], c[1], c[2], c[3]])
                .collect(),
            fragments_stored: requested - dropped,
            fragments_dropped: dropped,
            fragments_truncated: bytemuck::cast_slice::<u8, u32>(&truncated_bytes)[0] as u64,
            memory_bytes: vec![
                ("abuffer heads".into(), heads.size()),
                ("abuffer nodes".into(), nodes.size()),
                ("abuffer resolved".into(), resolved.size()),
                ("depth".into(), pixels * 4),
            ]
            .into_iter()
            .chain(
                is_dbk
                    .then(|| {
                        vec![
                            ("dbk nearest depth".to_string(), pixels * 4),
                            (
                                "dbk fallback colour".to_string(),
                                pixels
                                    * target.color.format().block_copy_size(None).unwrap_or(16)
                                        as u64,
                            ),
                        ]
                    })
                    .into_iter()
                    .flatten(),
            )
            .collect(),
        })
    }
}
