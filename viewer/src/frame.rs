//! A rendered frame as the window shows it: the image on the GPU, how far its refinement is and
//! what it cost. The render thread produces it, progressive refinement scales it, the window's
//! display pass (`gpu_display`) draws it where it is, and only a screenshot reads it back.

use anyhow::Context;
use strandlight_runtime::env::FrameSums;
use strandlight_runtime::gpu::{GpuContext, read_buffer};
use strandlight_runtime::point_frame::PassTiming;
use strandlight_scene::image_metrics::Image;

/// How far the shown image is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Stage {
    Preview,
    /// `done` of `total` light batches summed.
    Refining {
        done: usize,
        total: usize,
    },
    Converged,
}

/// What the overlay reports of the shown image.
#[derive(Clone, Debug, Default)]
pub struct FrameStats {
    /// Time per pass, summed over the batches so far.
    pub passes: Vec<PassTiming>,
    /// GPU memory per resource while one batch renders, bytes.
    pub memory: Vec<(String, u64)>,
    /// Lights drawn (SRBF lobes and directional sources, or point lights).
    pub lights: usize,
    /// Render calls (light batches) so far.
    pub batches: usize,
    pub adapter: String,
    pub timing_method: String,
}

/// An image on the renderer's device, never written again once made: a frame's sums
/// ([`FrameSums`]' layout: linear pre-multiplied RGBA f32 of single scattering, then as many of
/// multiple scattering), and the scale its colour is shown at.
pub struct GpuImage {
    pub buffer: wgpu::Buffer,
    pub size: [u32; 2],
    /// The second half holds multiple scattering to add.
    pub with_multiple: bool,
    /// Colour scale: a running sum over the share of the lights' power it holds (1 when whole).
    pub scale: f32,
    /// The buffer's bytes, read back for a window on a device of its own
    /// ([`crate::WindowDevice::Own`]); None where the window shares the renderer's device.
    pub read_back: Option<Vec<u8>>,
}

impl GpuImage {
    /// `sums` themselves, when nothing adds into them any more (a preview, a point-lit frame).
    pub fn of_finished(sums: FrameSums, with_multiple: bool) -> Self {
        let size = sums.size();
        Self {
            buffer: sums.into_buffer(),
            size,
            with_multiple,
            scale: 1.0,
            read_back: None,
        }
    }

    /// The image with its bytes read back (waits for the GPU): what a window on its own
    /// device uploads.
    pub fn with_read_back(self, gpu: &GpuContext) -> anyhow::Result<Self> {
        let bytes = read_buffer(gpu, &self.buffer).context("reading the frame back")?;
        Ok(Self {
            read_back: Some(bytes),
            ..self
        })
    }

    /// A copy of `sums` on the GPU, taken after the work submitted so far: the running sum goes
    /// on adding batches while the window shows this one.
    pub fn copy_of(gpu: &GpuContext, sums: &FrameSums, with_multiple: bool) -> Self {
        let source = sums.buffer();
        let buffer = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("viewer: shown sums"),
            size: source.size(),
            usage: wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::COPY_SRC
                | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        encoder.copy_buffer_to_buffer(source, 0, &buffer, 0, source.size());
        gpu.queue.submit([encoder.finish()]);
        Self {
            buffer,
            size: sums.size(),
            with_multiple,
            scale: 1.0,
            read_back: None,
        }
    }

    /// The image as linear pre-multiplied RGBA at its scale (single and multiple scattering
    /// added): a screenshot's one readback (none when the bytes were read back already). Waits
    /// for the GPU.
    pub fn read(&self, gpu: &GpuContext) -> anyhow::Result<Image> {
        let bytes = match &self.read_back {
            Some(bytes) => std::borrow::Cow::Borrowed(bytes),
            None => std::borrow::Cow::Owned(
                read_buffer(gpu, &self.buffer).context("reading the shown frame back")?,
            ),
        };
        let sums: &[[f32; 4]] = bytemuck::cast_slice(&bytes);
        let (single, multiple) = sums.split_at(sums.len() / 2);
        let pixels = single
            .iter()
            .zip(multiple)
            .map(|(s, m)| {
                let m = if self.with_multiple { *m } else { [0.0; 4] };
                let c = |k: usize| self.scale * (s[k] + m[k]);
                [c(0), c(1), c(2), s[3]]
            })
            .collect();
        Ok(Image {
            width: self.size[0],
            height: self.size[1],
            pixels,
        })
    }
}
