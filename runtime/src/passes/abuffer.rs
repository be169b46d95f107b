//! Order-independent transparency with an A-buffer: per-pixel linked lists of shaded fragments
//! built with storage-buffer atomics (`abuffer.wgsl`), then sorted and composited front to back
//! by a compute resolve (`abuffer_resolve.wgsl`). Node-buffer overflow and resolve truncation
//! are counted and reported ([`ABufferFrame`]), never silent.
//! The DBK-buffer (depth-based K-buffer, Hunz 2016 §5.3) is the cheaper variant: a depth
//! prepass finds each pixel's nearest fiber, only fragments within a depth bucket of width Δ
//! behind it go into the lists, and the rest fall back to an opaque depth-tested target.
//! Fragments are shaded exactly as the opaque strand pass shades them: the same WGSL (any
//! [`ShadingModel`], group 2) and a deep opacity map for each of up to
//! [`MAX_SHADOWED_LIGHTS`](crate::passes::shadow_slots::MAX_SHADOWED_LIGHTS) lights (group 1).
//! Inputs: [`StrandGeometry`], [`FrameParams`], the shadow maps, the node capacity.
//! Output: [`ABufferFrame`].

use super::attachments::{cleared_color, cleared_depth};
use crate::gpu::texture::texture_2d;
use wgpu::util::DeviceExt;

use crate::gpu::GpuContext;
use crate::gpu::bind_layout::{
    bind_group, depth_texture_entry, float_texture_entry, pipeline_layout, storage_entry,
    uniform_entry,
};
use crate::gpu::limits::{GpuLimits, LimitError, fit_pixels, fit_within};
use crate::gpu::pipeline::{StrandDraw, color_target, compute_pipeline, depth_test, wgsl_module};
use crate::gpu::readback::{ReadbackError, read_buffer};
use crate::passes::fiber_shading::{ModelBinding, ShadingModel};
use crate::passes::frame_params::FrameParams;
use crate::passes::render_target::{DEPTH_FORMAT, RenderTarget};
use crate::passes::shadow_slots::{
    HeadInput, ShadowInput, TooManyShadowMaps, shadow_bind_group_for, shadow_bind_group_layout,
};
use crate::passes::strand_geometry::StrandGeometry;
use crate::passes::strand_quads::{strand_bind_group, strand_bind_group_layout};
use crate::passes::strands::strand_shading_module;
use crate::shaders::Wgsl;

#[derive(Debug, thiserror::Error)]
pub enum ABufferError {
    #[error(transparent)]
    TooManyShadowMaps(#[from] TooManyShadowMaps),
    #[error(transparent)]
    Readback(#[from] ReadbackError),
    #[error(transparent)]
    Limit(#[from] LimitError),
    #[error(
        "the frame is {frame_width}×{frame_height} but the A-buffer resources were made for \
         {width}×{height}"
    )]
    SizeMismatch {
        frame_width: u32,
        frame_height: u32,
        width: u32,
        height: u32,
    },
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

/// The view's depth range and Δ of the DBK-buffer (`DbkParams` in `abuffer.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct DbkUniform {
    near: f32,
    far: f32,
    delta: f32,
    /// 1: a perspective camera (view depth from the depth buffer's hyperbolic value).
    perspective: u32,
}

/// Which fragments go into the lists.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ListMode {
    /// Every fragment (A-buffer).
    All,
    /// DBK-buffer (depth-based K-buffer, Hunz 2016 §5.3): fragments within `delta` (view depth,
    /// world units) of the pixel's nearest fiber; the rest fall back to an opaque depth-tested
    /// target composited underneath.
    Dbk { delta: f32 },
}

/// The pipelines, built once per shading model.
pub struct ABufferPass {
    build: wgpu::RenderPipeline,
    dbk_build: wgpu::RenderPipeline,
    depth_prepass: wgpu::RenderPipeline,
    resolve: wgpu::ComputePipeline,
    layouts: ABufferLayouts,
    /// Group 2: the fiber model's constants and tables (none for Kajiya-Kay), as in
    /// [`StrandPass`](crate::passes::strands::StrandPass).
    model: Option<ModelBinding>,
}

/// The bind group layouts of the build and resolve passes.
struct ABufferLayouts {
    strand: wgpu::BindGroupLayout,
    shadow: wgpu::BindGroupLayout,
    /// Group 3 of the A-buffer build: heads, nodes, counters, parameters.
    lists: wgpu::BindGroupLayout,
    /// Group 3 of the DBK build: the lists' bindings, then the nearest depth and DBK parameters.
    dbk_lists: wgpu::BindGroupLayout,
    /// The resolve: heads, nodes, resolved colours, truncation counter, parameters, fallback.
    resolve: wgpu::BindGroupLayout,
}

impl ABufferLayouts {
    fn new(device: &wgpu::Device) -> Self {
        let frag = wgpu::ShaderStages::FRAGMENT;
        let compute = wgpu::ShaderStages::COMPUTE;
        let list_entries = [
            storage_entry(0, frag, false),
            storage_entry(1, frag, false),
            storage_entry(2, frag, false),
            uniform_entry(3, frag),
        ];
        let mut dbk_entries = list_entries.to_vec();
        dbk_entries.extend([depth_texture_entry(4, frag), uniform_entry(5, frag)]);
        let layout = |label, entries: &[wgpu::BindGroupLayoutEntry]| {
            device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some(label),
                entries,
            })
        };
        Self {
            strand: strand_bind_group_layout(device),
            shadow: shadow_bind_group_layout(device),
            lists: layout("abuffer lists", &list_entries),
            dbk_lists: layout("dbk lists", &dbk_entries),
            resolve: layout(
                "abuffer resolve",
                &[
                    storage_entry(0, compute, true),
                    storage_entry(1, compute, true),
                    storage_entry(2, compute, false),
                    storage_entry(3, compute, false),
                    uniform_entry(4, compute),
                    float_texture_entry(5, compute),
                ],
            ),
        }
    }
}

/// Depth-tested and written: the DBK prepass and its opaque fallback.
fn depth_tested() -> wgpu::DepthStencilState {
    depth_test(DEPTH_FORMAT, true, wgpu::CompareFunction::Less)
}

/// A depth attachment only to give the A-buffer build a size; every fragment passes.
pub(crate) fn every_fragment() -> wgpu::DepthStencilState {
    depth_test(DEPTH_FORMAT, false, wgpu::CompareFunction::Always)
}

fn resolve_pipeline(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
) -> wgpu::ComputePipeline {
    let shader = wgsl_module(
        device,
        "abuffer_resolve.wgsl",
        include_str!("abuffer_resolve.wgsl"),
    );
    compute_pipeline(
        device,
        "abuffer resolve",
        &pipeline_layout(device, "abuffer resolve", &[Some(layout)]),
        &shader,
        "resolve",
    )
}

/// Bytes of the per-pixel list heads, resolved colours and nodes of a `width`×`height` frame
/// with `capacity` nodes: `(heads, resolved, nodes)`.
fn list_bytes(width: u32, height: u32, capacity: u32) -> (u64, u64, u64) {
    let pixels = width as u64 * height as u64;
    (pixels * 4, pixels * 16, capacity.max(1) as u64 * NODE_BYTES)
}

/// Everything one A-buffer or DBK frame of a given size, node capacity and list mode draws
/// into, created once and reused by every [`ABufferPass::draw_into`].
pub struct ABufferResources {
    width: u32,
    height: u32,
    capacity: u32,
    mode: ListMode,
    /// Per pixel, the index of its list's first node (`u32::MAX`: empty).
    heads: wgpu::Buffer,
    nodes: wgpu::Buffer,
    /// Fragments that asked for a node, fragments dropped for a full node buffer.
    counters: wgpu::Buffer,
    /// Fragments left out at resolve (beyond [`MAX_SORTED_PER_PIXEL`] in a pixel).
    truncated: wgpu::Buffer,
    /// The composited colour per pixel.
    resolved: wgpu::Buffer,
    /// The camera's near and far planes, Δ and the projection kind, rewritten per draw.
    dbk_params: wgpu::Buffer,
    /// The build's depth attachment; for DBK also the opaque fallback's colour.
    target: RenderTarget,
    /// DBK only: each pixel's nearest fiber depth.
    nearest_depth: Option<wgpu::Texture>,
    lists: wgpu::BindGroup,
    resolve: wgpu::BindGroup,
}

impl ABufferResources {
    /// Resources for `width`×`height` frames with `capacity` nodes (see
    /// [`ABufferPass::max_capacity`]), checked against the adapter's limits first.
    pub fn new(
        gpu: &GpuContext,
        pass: &ABufferPass,
        (width, height): (u32, u32),
        capacity: u32,
        mode: ListMode,
    ) -> Result<Self, LimitError> {
        check_abuffer_limits(gpu, width, height, capacity)?;
        let device = &gpu.device;
        let (heads_bytes, resolved_bytes, node_bytes) = list_bytes(width, height, capacity);
        let storage = |label, size| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage: wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_SRC
                    | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        let uniform = |label, contents: &[u8]| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            })
        };
        let is_dbk = matches!(mode, ListMode::Dbk { .. });
        let heads = storage("abuffer heads", heads_bytes);
        let nodes = storage("abuffer nodes", node_bytes);
        let counters = storage("abuffer counters", 8);
        let truncated = storage("abuffer truncated", 4);
        let resolved = storage("abuffer resolved", resolved_bytes);
        let build_params = uniform(
            "abuffer params",
            bytemuck::bytes_of(&Params {
                a: width,
                b: capacity,
                _pad: [0; 2],
            }),
        );
        let resolve_params = uniform(
            "abuffer resolve params",
            bytemuck::bytes_of(&Params {
                a: width,
                b: height,
                _pad: [is_dbk as u32, 0],
            }),
        );
        let dbk_params = uniform("dbk params", &[0u8; 16]);
        let target = RenderTarget::new(gpu, width, height);
        let nearest_depth = is_dbk.then(|| nearest_depth_texture(gpu, target.depth.size()));
        let nearest_view = nearest_depth
            .as_ref()
            .map(|t| t.create_view(&Default::default()));
        let mut list_resources = vec![
            heads.as_entire_binding(),
            nodes.as_entire_binding(),
            counters.as_entire_binding(),
            build_params.as_entire_binding(),
        ];
        let lists_layout = match &nearest_view {
            Some(view) => {
                list_resources.push(wgpu::BindingResource::TextureView(view));
                list_resources.push(dbk_params.as_entire_binding());
                &pass.layouts.dbk_lists
            }
            None => &pass.layouts.lists,
        };
        let lists = bind_group(device, "abuffer lists", lists_layout, &list_resources);
        // The A-buffer binds a 1×1 fallback it never reads.
        let placeholder = (!is_dbk).then(|| RenderTarget::new(gpu, 1, 1));
        let fallback = placeholder.as_ref().unwrap_or(&target);
        let fallback_view = fallback.color.create_view(&Default::default());
        let resolve = bind_group(
            device,
            "abuffer resolve",
            &pass.layouts.resolve,
            &[
                heads.as_entire_binding(),
                nodes.as_entire_binding(),
                resolved.as_entire_binding(),
                truncated.as_entire_binding(),
                resolve_params.as_entire_binding(),
                wgpu::BindingResource::TextureView(&fallback_view),
            ],
        );
        Ok(Self {
            width,
            height,
            capacity,
            mode,
            heads,
            nodes,
            counters,
            truncated,
            resolved,
            dbk_params,
            target,
            nearest_depth,
            lists,
            resolve,
        })
    }

    pub fn capacity(&self) -> u32 {
        self.capacity
    }

    /// Bytes held per resource, for reports.
    pub fn memory(&self) -> Vec<(String, u64)> {
        let pixels = self.width as u64 * self.height as u64;
        let mut memory = vec![
            ("abuffer heads".to_string(), self.heads.size()),
            ("abuffer nodes".to_string(), self.nodes.size()),
            ("abuffer resolved".to_string(), self.resolved.size()),
            ("depth".to_string(), pixels * 4),
        ];
        if self.nearest_depth.is_some() {
            let texel = self
                .target
                .color
                .format()
                .block_copy_size(None)
                .unwrap_or(16) as u64;
            memory.push(("dbk nearest depth".to_string(), pixels * 4));
            memory.push(("dbk fallback colour".to_string(), pixels * texel));
        }
        memory
    }

    /// Empties the lists and counters and sets the camera's DBK parameters for the next draw.
    fn reset(&self, gpu: &GpuContext, encoder: &mut wgpu::CommandEncoder, frame: &FrameParams) {
        let empty_heads = vec![0xffu8; self.heads.size() as usize];
        gpu.queue.write_buffer(&self.heads, 0, &empty_heads);
        let camera = &frame.camera;
        let delta = match self.mode {
            ListMode::Dbk { delta } => delta,
            ListMode::All => 0.0,
        };
        let dbk = DbkUniform {
            near: camera.near,
            far: camera.far,
            delta,
            perspective: camera.is_perspective() as u32,
        };
        gpu.queue
            .write_buffer(&self.dbk_params, 0, bytemuck::bytes_of(&dbk));
        encoder.clear_buffer(&self.counters, 0, None);
        encoder.clear_buffer(&self.truncated, 0, None);
        encoder.clear_buffer(&self.resolved, 0, None);
    }

    /// The composited colour per pixel (pre-multiplied RGBA f32, row-major from the top),
    /// on the GPU.
    pub fn resolved(&self) -> &wgpu::Buffer {
        &self.resolved
    }

    /// The resolved image and the fragment counts, read back (waits for the GPU).
    pub fn read(&self, gpu: &GpuContext) -> Result<ABufferFrame, ReadbackError> {
        let colour_bytes = read_buffer(gpu, &self.resolved)?;
        let counter_bytes = read_buffer(gpu, &self.counters)?;
        let truncated_bytes = read_buffer(gpu, &self.truncated)?;
        let floats: &[f32] = bytemuck::cast_slice(&colour_bytes);
        let counts: &[u32] = bytemuck::cast_slice(&counter_bytes);
        let truncated: &[u32] = bytemuck::cast_slice(&truncated_bytes);
        let (requested, dropped) = (counts[0] as u64, counts[1] as u64);
        Ok(ABufferFrame {
            pixels: floats
                .chunks_exact(4)
                .map(|c| [c[0], c[1], c[2], c[3]])
                .collect(),
            fragments_stored: requested.saturating_sub(dropped),
            fragments_dropped: dropped,
            fragments_truncated: truncated[0] as u64,
            memory_bytes: self.memory(),
        })
    }
}

fn nearest_depth_texture(gpu: &GpuContext, size: wgpu::Extent3d) -> wgpu::Texture {
    texture_2d(
        gpu,
        "dbk nearest depth",
        size,
        DEPTH_FORMAT,
        wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
    )
}

/// The image's textures, the three per-pixel/per-node storage buffers and the resolve's
/// 8×8 workgroups, against the adapter's limits.
fn check_abuffer_limits(
    gpu: &GpuContext,
    width: u32,
    height: u32,
    capacity: u32,
) -> Result<(), LimitError> {
    let limits = GpuLimits::of(gpu);
    limits.check_image(width, height)?;
    let (heads, resolved, nodes) = list_bytes(width, height, capacity);
    let smaller_image = |bytes_per_pixel: u64| {
        move |max: u64| {
            let (w, h) = fit_pixels(width, height, max / bytes_per_pixel);
            format!("render at {w}x{h} or smaller")
        }
    };
    limits.check_storage_buffer("A-buffer list heads", heads, smaller_image(4))?;
    limits.check_storage_buffer("A-buffer resolved colours", resolved, smaller_image(16))?;
    let pixels = width as u64 * height as u64;
    limits.check_storage_buffer("A-buffer node pool", nodes, |max| {
        let fits = max / NODE_BYTES;
        format!(
            "use at most {fits} nodes ({} per pixel at this size; ABufferPass::max_capacity \
             gives the largest pool that fits)",
            fits / pixels.max(1)
        )
    })?;
    limits.check_workgroups(
        "A-buffer resolve",
        [width.div_ceil(8), height.div_ceil(8), 1],
        |max| {
            let (w, h) = fit_within(width, height, max as u64 * 8);
            format!("render at {w}x{h} or smaller")
        },
    )
}

impl ABufferPass {
    /// Kajiya-Kay shading with the constants of [`FrameParams::shading`].
    pub fn new(gpu: &GpuContext) -> Self {
        Self::with_model(gpu, &ShadingModel::KajiyaKay)
    }

    /// Fragments shaded with `model`; its tables and constants are uploaded once, here.
    pub fn with_model(gpu: &GpuContext, shading: &ShadingModel) -> Self {
        let device = &gpu.device;
        let top = Wgsl {
            file: "abuffer.wgsl",
            source: include_str!("abuffer.wgsl"),
        };
        let shader = strand_shading_module(device, &top, shading);
        let model = ModelBinding::new(gpu, shading);
        let layouts = ABufferLayouts::new(device);
        let model_layout = model.as_ref().map(|m| &m.layout);
        let shading_groups = |lists| {
            [
                Some(&layouts.strand),
                Some(&layouts.shadow),
                model_layout,
                Some(lists),
            ]
        };
        let build_layout =
            pipeline_layout(device, "abuffer build", &shading_groups(&layouts.lists));
        let dbk_layout = pipeline_layout(device, "dbk build", &shading_groups(&layouts.dbk_lists));
        let prepass_layout = pipeline_layout(device, "dbk depth prepass", &[Some(&layouts.strand)]);
        let fallback_target = [color_target(gpu.hdr_format(), None)];
        let quads = |label, layout, fragment, depth| {
            StrandDraw {
                label,
                layout,
                shader: &shader,
                vertex_entry: "vs_main",
                fragment,
                depth: Some(depth),
            }
            .build(device)
        };
        Self {
            build: quads(
                "abuffer build",
                &build_layout,
                Some(("fs_abuffer", &[])),
                every_fragment(),
            ),
            dbk_build: quads(
                "dbk build",
                &dbk_layout,
                Some(("fs_dbk", &fallback_target)),
                depth_tested(),
            ),
            depth_prepass: quads("dbk depth prepass", &prepass_layout, None, depth_tested()),
            resolve: resolve_pipeline(device, &layouts.resolve),
            layouts,
            model,
        }
    }

    /// The node capacity the adapter's storage-binding and buffer-size limits allow, at most
    /// `wanted`.
    pub fn max_capacity(gpu: &GpuContext, wanted: u64) -> u32 {
        let limits = gpu.device.limits();
        let bytes = limits
            .max_storage_buffer_binding_size
            .min(limits.max_buffer_size);
        wanted.min(bytes / NODE_BYTES).min(u32::MAX as u64 - 1) as u32
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
    ) -> Result<ABufferFrame, ABufferError> {
        self.draw_shadowed(
            gpu,
            geometry,
            frame,
            shadow.as_slice(),
            None,
            capacity,
            mode,
        )
    }

    /// [`Self::draw`] with a deep opacity map for each of up to
    /// [`MAX_SHADOWED_LIGHTS`](crate::passes::shadow_slots::MAX_SHADOWED_LIGHTS) lights, into
    /// resources made for this one frame.
    #[allow(clippy::too_many_arguments)]
    pub fn draw_shadowed(
        &self,
        gpu: &GpuContext,
        geometry: &StrandGeometry,
        frame: &FrameParams,
        shadows: &[ShadowInput<'_>],
        head: Option<HeadInput<'_>>,
        capacity: u32,
        mode: ListMode,
    ) -> Result<ABufferFrame, ABufferError> {
        let resources =
            ABufferResources::new(gpu, self, (frame.width, frame.height), capacity, mode)?;
        self.draw_into(gpu, &resources, geometry, frame, shadows, head)
    }

    /// Builds and resolves one frame in `resources` (whose size must be the frame's), and
    /// reads it back.
    pub fn draw_into(
        &self,
        gpu: &GpuContext,
        resources: &ABufferResources,
        geometry: &StrandGeometry,
        frame: &FrameParams,
        shadows: &[ShadowInput<'_>],
        head: Option<HeadInput<'_>>,
    ) -> Result<ABufferFrame, ABufferError> {
        self.submit_into(gpu, resources, geometry, frame, shadows, head)?;
        Ok(resources.read(gpu)?)
    }

    /// [`Self::draw_into`] submitted without waiting: the resolved image stays in
    /// `resources` ([`ABufferResources::resolved`]).
    pub fn submit_into(
        &self,
        gpu: &GpuContext,
        resources: &ABufferResources,
        geometry: &StrandGeometry,
        frame: &FrameParams,
        shadows: &[ShadowInput<'_>],
        head: Option<HeadInput<'_>>,
    ) -> Result<(), ABufferError> {
        if (frame.width, frame.height) != (resources.width, resources.height) {
            return Err(ABufferError::SizeMismatch {
                frame_width: frame.width,
                frame_height: frame.height,
                width: resources.width,
                height: resources.height,
            });
        }
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        self.encode_build(gpu, &mut encoder, resources, geometry, frame, shadows, head)?;
        self.encode_resolve(gpu, &mut encoder, resources);
        gpu.queue.submit([encoder.finish()]);
        Ok(())
    }

    /// The nodes a frame's lists need in `mode`: the build run into a one-node pool, whose
    /// request counter still counts every fragment the technique would store. A pool sized
    /// from it costs each technique only what it keeps (DBK far less than the A-buffer).
    pub fn count_fragments(
        &self,
        gpu: &GpuContext,
        geometry: &StrandGeometry,
        frame: &FrameParams,
        shadows: &[ShadowInput<'_>],
        head: Option<HeadInput<'_>>,
        mode: ListMode,
    ) -> Result<u64, ABufferError> {
        let resources = ABufferResources::new(gpu, self, (frame.width, frame.height), 1, mode)?;
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        self.encode_build(
            gpu,
            &mut encoder,
            &resources,
            geometry,
            frame,
            shadows,
            head,
        )?;
        gpu.queue.submit([encoder.finish()]);
        let counters = read_buffer(gpu, &resources.counters)?;
        let counts: &[u32] = bytemuck::cast_slice(&counters);
        Ok(u64::from(counts[0]))
    }

    /// Empties `resources` and records the list build of `frame`.
    #[allow(clippy::too_many_arguments)]
    fn encode_build(
        &self,
        gpu: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        resources: &ABufferResources,
        geometry: &StrandGeometry,
        frame: &FrameParams,
        shadows: &[ShadowInput<'_>],
        head: Option<HeadInput<'_>>,
    ) -> Result<(), ABufferError> {
        let shadow_group = shadow_bind_group_for(gpu, &self.layouts.shadow, frame, shadows, head)?;
        let strands = strand_bind_group(gpu, &self.layouts.strand, geometry, frame);
        let groups = [&strands, &shadow_group, &resources.lists];
        resources.reset(gpu, encoder, frame);
        match &resources.nearest_depth {
            Some(nearest) => self.encode_dbk(gpu, encoder, geometry, nearest, resources, groups),
            None => self.encode_abuffer(gpu, encoder, geometry, resources, groups),
        }
        Ok(())
    }

    /// Groups 0–3 of the build passes.
    fn bind_shading_groups(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        [strands, shadows, lists]: [&wgpu::BindGroup; 3],
    ) {
        pass.set_bind_group(0, strands, &[]);
        pass.set_bind_group(1, shadows, &[]);
        if let Some(model) = &self.model {
            pass.set_bind_group(2, &model.group, &[]);
        }
        pass.set_bind_group(3, lists, &[]);
    }

    /// A-buffer: every fragment into the lists.
    fn encode_abuffer(
        &self,
        gpu: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        geometry: &StrandGeometry,
        resources: &ABufferResources,
        groups: [&wgpu::BindGroup; 3],
    ) {
        let depth_view = resources.target.depth.create_view(&Default::default());
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("abuffer build"),
            color_attachments: &[],
            depth_stencil_attachment: cleared_depth(&depth_view, false),
            timestamp_writes: gpu.render_timestamps(),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.build);
        self.bind_shading_groups(&mut pass, groups);
        pass.draw(0..6, 0..geometry.segment_count);
    }

    /// DBK: the nearest-depth prepass, then the build that sorts fragments into the lists or
    /// the depth-tested fallback.
    fn encode_dbk(
        &self,
        gpu: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        geometry: &StrandGeometry,
        nearest_depth: &wgpu::Texture,
        resources: &ABufferResources,
        groups: [&wgpu::BindGroup; 3],
    ) {
        let nearest_view = nearest_depth.create_view(&Default::default());
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("dbk depth prepass"),
                color_attachments: &[],
                depth_stencil_attachment: cleared_depth(&nearest_view, true),
                timestamp_writes: gpu.render_timestamps(),
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&self.depth_prepass);
            pass.set_bind_group(0, groups[0], &[]);
            pass.draw(0..6, 0..geometry.segment_count);
        }
        let color_view = resources.target.color.create_view(&Default::default());
        let depth_view = resources.target.depth.create_view(&Default::default());
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("dbk build"),
            color_attachments: &[cleared_color(&color_view)],
            depth_stencil_attachment: cleared_depth(&depth_view, false),
            timestamp_writes: gpu.render_timestamps(),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.dbk_build);
        self.bind_shading_groups(&mut pass, groups);
        pass.draw(0..6, 0..geometry.segment_count);
    }

    /// Sorts and composites every pixel's list (8×8 pixels a workgroup).
    fn encode_resolve(
        &self,
        gpu: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        resources: &ABufferResources,
    ) {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("abuffer resolve"),
            timestamp_writes: gpu.compute_timestamps(),
        });
        pass.set_pipeline(&self.resolve);
        pass.set_bind_group(0, &resources.resolve, &[]);
        pass.dispatch_workgroups(resources.width.div_ceil(8), resources.height.div_ceil(8), 1);
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
                file: "abuffer.wgsl",
                source: include_str!("abuffer.wgsl"),
            },
            Some(&KAJIYA_KAY),
            "ABufferParams",
            &rust_layout!(Params { a => "width", b => "capacity" }),
        );
        assert_same_layout(
            &Wgsl {
                file: "abuffer.wgsl",
                source: include_str!("abuffer.wgsl"),
            },
            Some(&KAJIYA_KAY),
            "DbkParams",
            &rust_layout!(DbkUniform {
                near,
                far,
                delta,
                perspective
            }),
        );
        assert_same_layout(
            &Wgsl {
                file: "abuffer_resolve.wgsl",
                source: include_str!("abuffer_resolve.wgsl"),
            },
            None,
            "ResolveParams",
            &rust_layout!(Params { a => "width", b => "height" }),
        );
    }
}
