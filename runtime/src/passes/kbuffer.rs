//! K-buffer transparency (Hunz §5.2; Vasilakis & Fudos' k+-buffer): only the k nearest fragments
//! of each pixel are stored and composited; the rest are dropped and counted. Without fragment
//! interlock the slots are filled in two passes over the strands (`kbuffer.wgsl`: the k nearest
//! depths by an atomicMin cascade, then the colours of those fragments), then a compute resolve
//! composites them front to back (`kbuffer_resolve.wgsl`).
//! Inputs: [`StrandGeometry`], [`FrameParams`], shadow maps, k. Output: [`KBufferFrame`].
//! Memory: k × (4 B depth + 8 B RGBA16F colour) per pixel, plus the resolved image.

use wgpu::util::DeviceExt;

use super::abuffer::every_fragment;
use super::attachments::cleared_depth;
use super::fiber_shading::ShadingModel;
use super::frame_params::FrameParams;
use super::render_target::RenderTarget;
use super::shadow_slots::{HeadInput, ShadowInput, TooManyShadowMaps, shadow_bind_group_for};
use super::strand_geometry::StrandGeometry;
use super::strand_quads::strand_bind_group;
use super::strands::{ShadedStrandLayouts, strand_shading_module};
use crate::gpu::bind_layout::{bind_group, pipeline_layout, storage_entry, uniform_entry};
use crate::gpu::pipeline::{StrandDraw, compute_pipeline, wgsl_module};
use crate::gpu::readback::{ReadbackError, read_buffer};
use crate::gpu::{GpuContext, GpuLimits, LimitError};
use crate::shaders::Wgsl;

/// Hunz §6 keeps 8 fragments per pixel.
pub const DEFAULT_K: u32 = 8;
/// Bounds each fragment's walk over its pixel's slots.
pub const MAX_K: u32 = 64;

#[derive(Debug, thiserror::Error)]
pub enum KBufferError {
    #[error("K-buffer k {0}: must be 1..={MAX_K}")]
    K(u32),
    #[error(transparent)]
    Limit(#[from] LimitError),
    #[error(transparent)]
    TooManyShadowMaps(#[from] TooManyShadowMaps),
    #[error(transparent)]
    Readback(#[from] ReadbackError),
}

/// A resolved frame and what the slots held.
pub struct KBufferFrame {
    /// Pre-multiplied RGBA, row-major from the top.
    pub pixels: Vec<[f32; 4]>,
    /// Fragments composited (at most k per pixel).
    pub fragments_kept: u64,
    /// Fragments beyond the k nearest of their pixel, left out.
    pub fragments_dropped: u64,
    pub memory_bytes: Vec<(String, u64)>,
}

/// A resolved frame still on the GPU ([`KBufferPass::submit`]).
pub struct KBufferOnGpu {
    /// Pre-multiplied RGBA f32 per pixel, row-major from the top.
    pub resolved: wgpu::Buffer,
    /// Fragments dropped, fragments kept.
    counters: wgpu::Buffer,
    pub memory_bytes: Vec<(String, u64)>,
}

impl KBufferOnGpu {
    /// The image and the fragment counts, read back (waits for the GPU).
    pub fn read(self, gpu: &GpuContext) -> Result<KBufferFrame, KBufferError> {
        let image = read_buffer(gpu, &self.resolved)?;
        let counts = read_buffer(gpu, &self.counters)?;
        let counts: &[u32] = bytemuck::cast_slice(&counts);
        Ok(KBufferFrame {
            pixels: bytemuck::cast_slice::<u8, [f32; 4]>(&image).to_vec(),
            fragments_dropped: u64::from(counts[0]),
            fragments_kept: u64::from(counts[1]),
            memory_bytes: self.memory_bytes,
        })
    }
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Params {
    width: u32,
    second: u32,
    third: u32,
    _pad: u32,
}

pub struct KBufferPass {
    depths: wgpu::RenderPipeline,
    colors: wgpu::RenderPipeline,
    resolve: wgpu::ComputePipeline,
    layouts: ShadedStrandLayouts,
    slots_layout: wgpu::BindGroupLayout,
    resolve_layout: wgpu::BindGroupLayout,
}

impl KBufferPass {
    pub fn with_model(gpu: &GpuContext, shading: &ShadingModel) -> Self {
        let device = &gpu.device;
        let fragment = wgpu::ShaderStages::FRAGMENT;
        let slots_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("kbuffer slots"),
            entries: &[
                storage_entry(0, fragment, false),
                storage_entry(1, fragment, false),
                storage_entry(2, fragment, false),
                uniform_entry(3, fragment),
            ],
        });
        let layouts = ShadedStrandLayouts::new(gpu, shading);
        let build_layout = layouts.pipeline_layout(device, "kbuffer build", Some(&slots_layout));
        let top = Wgsl {
            file: "kbuffer.wgsl",
            source: include_str!("kbuffer.wgsl"),
        };
        let shader = strand_shading_module(device, &top, shading);
        let build = |label, entry| {
            StrandDraw {
                label,
                layout: &build_layout,
                shader: &shader,
                vertex_entry: "vs_main",
                fragment: Some((entry, &[])),
                depth: Some(every_fragment()),
            }
            .build(device)
        };
        let compute = wgpu::ShaderStages::COMPUTE;
        let resolve_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("kbuffer resolve"),
            entries: &[
                storage_entry(0, compute, true),
                storage_entry(1, compute, true),
                storage_entry(2, compute, false),
                storage_entry(3, compute, false),
                uniform_entry(4, compute),
            ],
        });
        let resolve_shader = wgsl_module(
            device,
            "kbuffer_resolve.wgsl",
            include_str!("kbuffer_resolve.wgsl"),
        );
        let resolve = compute_pipeline(
            device,
            "kbuffer resolve",
            &pipeline_layout(device, "kbuffer resolve", &[Some(&resolve_layout)]),
            &resolve_shader,
            "resolve",
        );
        Self {
            depths: build("kbuffer depths", "fs_kbuffer_depths"),
            colors: build("kbuffer colours", "fs_kbuffer_colors"),
            resolve,
            layouts,
            slots_layout,
            resolve_layout,
        }
    }

    /// The k nearest fragments of every pixel of `frame`, composited and read back.
    pub fn draw(
        &self,
        gpu: &GpuContext,
        geometry: &StrandGeometry,
        frame: &FrameParams,
        shadows: &[ShadowInput<'_>],
        head: Option<HeadInput<'_>>,
        k: u32,
    ) -> Result<KBufferFrame, KBufferError> {
        self.submit(gpu, geometry, frame, shadows, head, k)?
            .read(gpu)
    }

    /// [`Self::draw`] submitted without waiting: the resolved image stays on the GPU.
    pub fn submit(
        &self,
        gpu: &GpuContext,
        geometry: &StrandGeometry,
        frame: &FrameParams,
        shadows: &[ShadowInput<'_>],
        head: Option<HeadInput<'_>>,
        k: u32,
    ) -> Result<KBufferOnGpu, KBufferError> {
        if !(1..=MAX_K).contains(&k) {
            return Err(KBufferError::K(k));
        }
        let device = &gpu.device;
        let (width, height) = (frame.width, frame.height);
        let pixels = width as u64 * height as u64;
        let limits = GpuLimits::of(gpu);
        let fix = |max: u64| format!("use k ≤ {} at this image size", max / (pixels * 8));
        limits.check_storage_buffer("K-buffer colours", pixels * k as u64 * 8, fix)?;
        limits.check_storage_buffer("resolved image", pixels * 16, |_| {
            "render a smaller image".into()
        })?;
        let buffers = self.buffers(gpu, (width, height), k);
        let shadow_group = shadow_bind_group_for(gpu, &self.layouts.shadow, frame, shadows, head)?;
        let strands = strand_bind_group(gpu, &self.layouts.strand, geometry, frame);
        let mut encoder = device.create_command_encoder(&Default::default());
        self.encode(
            gpu,
            &mut encoder,
            geometry,
            [&strands, &shadow_group],
            &buffers,
            (width, height),
        );
        gpu.queue.submit([encoder.finish()]);
        let KBufferBuffers {
            depths,
            colors,
            counters,
            resolved,
            ..
        } = buffers;
        Ok(KBufferOnGpu {
            memory_bytes: vec![
                ("kbuffer depths".into(), depths.size()),
                ("kbuffer colours".into(), colors.size()),
                ("kbuffer resolved image".into(), resolved.size()),
                ("kbuffer pass depth".into(), pixels * 4),
            ],
            resolved,
            counters,
        })
    }

    /// A frame's slots (k per pixel), counters and resolved image, bound for the build and
    /// the resolve.
    fn buffers(&self, gpu: &GpuContext, (width, height): (u32, u32), k: u32) -> KBufferBuffers {
        let device = &gpu.device;
        let pixels = width as u64 * height as u64;
        let storage = |label, contents: &[u8]| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            })
        };
        let slots = (pixels * k as u64) as usize;
        let depths = storage("kbuffer depths", &vec![0xffu8; slots * 4]);
        let colors = storage("kbuffer colours", &vec![0u8; slots * 8]);
        let counters = storage("kbuffer counters", &[0u8; 8]);
        let resolved = storage("kbuffer resolved", &vec![0u8; pixels as usize * 16]);
        let uniform = |label, params: Params| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents: bytemuck::bytes_of(&params),
                usage: wgpu::BufferUsages::UNIFORM,
            })
        };
        let build_params = uniform(
            "kbuffer params",
            Params {
                width,
                second: k,
                third: 0,
                _pad: 0,
            },
        );
        let resolve_params = uniform(
            "kbuffer resolve params",
            Params {
                width,
                second: height,
                third: k,
                _pad: 0,
            },
        );
        let slots_group = bind_group(
            device,
            "kbuffer slots",
            &self.slots_layout,
            &[
                depths.as_entire_binding(),
                colors.as_entire_binding(),
                counters.as_entire_binding(),
                build_params.as_entire_binding(),
            ],
        );
        let resolve_group = bind_group(
            device,
            "kbuffer resolve",
            &self.resolve_layout,
            &[
                depths.as_entire_binding(),
                colors.as_entire_binding(),
                resolved.as_entire_binding(),
                counters.as_entire_binding(),
                resolve_params.as_entire_binding(),
            ],
        );
        KBufferBuffers {
            depths,
            colors,
            counters,
            resolved,
            slots_group,
            resolve_group,
        }
    }

    /// The two build passes over the strands (`groups`: strands, shadows), then the resolve.
    fn encode(
        &self,
        gpu: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        geometry: &StrandGeometry,
        [strands, shadow_group]: [&wgpu::BindGroup; 2],
        buffers: &KBufferBuffers,
        (width, height): (u32, u32),
    ) {
        // Only to give the build passes a size: every fragment passes its test.
        let target = RenderTarget::new(gpu, width, height);
        let depth_view = target.depth.create_view(&Default::default());
        for (label, pipeline) in [
            ("kbuffer depths", &self.depths),
            ("kbuffer colours", &self.colors),
        ] {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some(label),
                color_attachments: &[],
                depth_stencil_attachment: cleared_depth(&depth_view, false),
                timestamp_writes: gpu.render_timestamps(),
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, strands, &[]);
            pass.set_bind_group(1, shadow_group, &[]);
            if let Some(model) = &self.layouts.model {
                pass.set_bind_group(2, &model.group, &[]);
            }
            pass.set_bind_group(3, &buffers.slots_group, &[]);
            pass.draw(0..6, 0..geometry.segment_count);
        }
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("kbuffer resolve"),
            timestamp_writes: gpu.compute_timestamps(),
        });
        pass.set_pipeline(&self.resolve);
        pass.set_bind_group(0, &buffers.resolve_group, &[]);
        pass.dispatch_workgroups(width.div_ceil(8), height.div_ceil(8), 1);
    }
}

/// One frame's K-buffer on the GPU.
struct KBufferBuffers {
    depths: wgpu::Buffer,
    colors: wgpu::Buffer,
    counters: wgpu::Buffer,
    resolved: wgpu::Buffer,
    slots_group: wgpu::BindGroup,
    resolve_group: wgpu::BindGroup,
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
                file: "kbuffer.wgsl",
                source: include_str!("kbuffer.wgsl"),
            },
            Some(&KAJIYA_KAY),
            "KBufferParams",
            &rust_layout!(Params { width, second => "k" }),
        );
        assert_same_layout(
            &Wgsl {
                file: "kbuffer_resolve.wgsl",
                source: include_str!("kbuffer_resolve.wgsl"),
            },
            None,
            "ResolveParams",
            &rust_layout!(Params { width, second => "height", third => "k" }),
        );
    }
}
