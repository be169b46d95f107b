//! The running sums of a frame rendered in batches of lights, and the pass that adds a batch's
//! images into them (`accumulate.wgsl`). A progressive frame keeps one [`FrameSums`] and adds
//! each part of its lights into it ([`EnvRenderer::encode_part_into`]): pre-multiplied "over"
//! compositing is linear in colour for a fixed set of fragments, so the sum of the batches'
//! colours is the colour under all their lights.
//!
//! [`EnvRenderer::encode_part_into`]: super::EnvRenderer::encode_part_into

use super::frame_resources::{FrameView, ViewKey};
use super::view_targets::EnvViewTargets;
use crate::gpu::GpuContext;
use crate::gpu::bind_layout::{
    bind_group, float_texture_entry, pipeline_layout, storage_entry, uniform_entry,
};
use crate::gpu::buffer::init_buffer;
use crate::gpu::limits::{GpuLimits, LimitError, fit_pixels, fit_within};
use crate::gpu::pipeline::{compute_pipeline, wgsl_module};
use crate::gpu::texture::texture_2d;
use crate::passes::render_target::DEPTH_FORMAT;
use std::sync::{Arc, Mutex};

/// Pixels along each side of the accumulate pass's workgroups (`@workgroup_size(8, 8)`).
const WORKGROUP_SIDE: u32 = 8;

/// Bytes per pixel of the sums: an RGBA f32 for single, one for multiple scattering.
const BYTES_PER_PIXEL: u64 = 2 * 16;

#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct AccumulateParams {
    width: u32,
    height: u32,
    _pad: [u32; 2],
}

/// A frame's running sums on the GPU: `width·height` RGBA f32 of single scattering, then as many
/// of multiple scattering; linear, pre-multiplied, row-major from the top. Colour adds up over
/// the parts added into it; alpha (the coverage, the same under every light) is the latest
/// part's. Starts at zero. The frame's first part keeps its view here (the hair uploaded, the
/// visibility drawn), and the parts after it reuse that view: one frame's parts, one view.
pub struct FrameSums {
    buffer: wgpu::Buffer,
    params: wgpu::Buffer,
    width: u32,
    height: u32,
    /// The nearest of hair and head per pixel (wgpu's 0..1 depth, 1 where neither is), drawn
    /// with each part's visibility when asked for: what a host's depth test compares.
    front_depth: Option<wgpu::Texture>,
    /// The view the frame's parts share, with what it was drawn for.
    kept_view: Mutex<Option<(ViewKey, Arc<FrameView>)>>,
}

impl FrameSums {
    /// Zeroed sums of a `width`×`height` frame, checked against the adapter's limits.
    pub fn new(gpu: &GpuContext, width: u32, height: u32) -> Result<Self, LimitError> {
        GpuLimits::of(gpu).check_image(width, height)?;
        Self::check_limits(gpu, width, height)?;
        let buffer = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("env sums"),
            size: Self::bytes(width, height),
            // COPY_DST: a host's next frame zeroes the sums in place.
            usage: wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::COPY_SRC
                | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let params = AccumulateParams {
            width,
            height,
            _pad: [0; 2],
        };
        let params = init_buffer(
            &gpu.device,
            "env accumulate params",
            bytemuck::bytes_of(&params),
            wgpu::BufferUsages::UNIFORM,
        );
        Ok(Self {
            buffer,
            params,
            width,
            height,
            front_depth: None,
            kept_view: Mutex::new(None),
        })
    }

    /// [`Self::new`] with the frame's front depth kept beside the sums (a host depth-tests the
    /// hair with it; `TEXTURE_BINDING | COPY_SRC | COPY_DST`, [`DEPTH_FORMAT`]).
    pub fn with_front_depth(gpu: &GpuContext, width: u32, height: u32) -> Result<Self, LimitError> {
        // Checked (in `new`) before the texture is made: past a limit, wgpu would abort.
        let sums = Self::new(gpu, width, height)?;
        let depth = texture_2d(
            gpu,
            "env front depth",
            wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
            DEPTH_FORMAT,
            // COPY_DST: a point-lit frame's starts as a copy of the head's view depth.
            wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_SRC
                | wgpu::TextureUsages::COPY_DST,
        );
        Ok(Self {
            front_depth: Some(depth),
            ..sums
        })
    }

    /// The front depth, when the sums keep one ([`Self::with_front_depth`]).
    pub fn front_depth(&self) -> Option<&wgpu::Texture> {
        self.front_depth.as_ref()
    }

    /// The view an earlier part of this frame kept, if it was drawn for `key`.
    pub(super) fn kept_view(&self, key: &ViewKey) -> Option<Arc<FrameView>> {
        let kept = self.kept_view.lock().unwrap_or_else(|e| e.into_inner());
        kept.as_ref()
            .filter(|(kept, _)| kept == key)
            .map(|(_, view)| view.clone())
    }

    /// Keeps `view`, drawn for `key`, for the parts of the frame that follow.
    pub(super) fn keep_view(&self, key: ViewKey, view: Arc<FrameView>) {
        *self.kept_view.lock().unwrap_or_else(|e| e.into_inner()) = Some((key, view));
    }

    /// Drops the kept view: the next part draws its own (a host's next frame, whose hair may
    /// have moved).
    pub(crate) fn forget_view(&self) {
        *self.kept_view.lock().unwrap_or_else(|e| e.into_inner()) = None;
    }

    /// Bytes of the sums of a `width`×`height` frame.
    pub fn bytes(width: u32, height: u32) -> u64 {
        width as u64 * height as u64 * BYTES_PER_PIXEL
    }

    /// The sums' buffer (STORAGE | COPY_SRC): single scattering, then multiple.
    pub fn buffer(&self) -> &wgpu::Buffer {
        &self.buffer
    }

    pub fn into_buffer(self) -> wgpu::Buffer {
        self.buffer
    }

    /// `[width, height]`.
    pub fn size(&self) -> [u32; 2] {
        [self.width, self.height]
    }

    /// The sums' buffer and the accumulate pass's workgroups against the adapter's limits.
    pub(super) fn check_limits(
        gpu: &GpuContext,
        width: u32,
        height: u32,
    ) -> Result<(), LimitError> {
        let limits = GpuLimits::of(gpu);
        limits.check_storage_buffer("env sums", Self::bytes(width, height), |max| {
            let (w, h) = fit_pixels(width, height, max / BYTES_PER_PIXEL);
            format!("render at {w}x{h} or smaller")
        })?;
        let groups = [
            width.div_ceil(WORKGROUP_SIDE),
            height.div_ceil(WORKGROUP_SIDE),
            1,
        ];
        limits.check_workgroups("env accumulate", groups, |max| {
            let (w, h) = fit_within(width, height, max as u64 * WORKGROUP_SIDE as u64);
            format!("render at {w}x{h} or smaller")
        })
    }
}

/// Adds a batch's two images (single, multiple) into a frame's [`FrameSums`].
pub(super) struct AccumulatePass {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
}

impl AccumulatePass {
    pub(super) fn new(device: &wgpu::Device) -> Self {
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
        let shader = wgsl_module(device, "accumulate.wgsl", include_str!("accumulate.wgsl"));
        let pipeline = compute_pipeline(
            device,
            "env accumulate",
            &pipeline_layout(device, "env accumulate", &[Some(&layout)]),
            &shader,
            "accumulate",
        );
        Self { pipeline, layout }
    }

    /// Records `sums += targets` (colour; alpha replaced). `targets` must be the sums' size.
    pub(super) fn encode(
        &self,
        gpu: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        targets: &EnvViewTargets,
        sums: &FrameSums,
    ) {
        let single = targets.single.create_view(&Default::default());
        let multiple = targets.multiple.create_view(&Default::default());
        let group = bind_group(
            &gpu.device,
            "env accumulate",
            &self.layout,
            &[
                wgpu::BindingResource::TextureView(&single),
                wgpu::BindingResource::TextureView(&multiple),
                sums.buffer.as_entire_binding(),
                sums.params.as_entire_binding(),
            ],
        );
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("env accumulate"),
            timestamp_writes: gpu.compute_timestamps(),
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &group, &[]);
        pass.dispatch_workgroups(
            sums.width.div_ceil(WORKGROUP_SIDE),
            sums.height.div_ceil(WORKGROUP_SIDE),
            1,
        );
    }
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
                file: "accumulate.wgsl",
                source: include_str!("accumulate.wgsl"),
            },
            None,
            "AccumulateParams",
            &rust_layout!(AccumulateParams { width, height }),
        );
    }
}
