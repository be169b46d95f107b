//! The whole window (panel, image and overlay) as a PNG: egui's frame drawn a second time into
//! an offscreen texture of the surface's format and read back. Reading the presented surface
//! itself is not portable (many surfaces lack `COPY_SRC`), and a screen grab of an X server
//! misses what Vulkan presents directly.

use anyhow::{Context, bail};
use std::path::Path;
use strandlight_tables::image_out::write_png_rgb8;

/// The target a capture is drawn into, and the buffer it is read back through.
pub struct CaptureTarget {
    texture: wgpu::Texture,
    buffer: wgpu::Buffer,
    padded_row_bytes: u32,
    width: u32,
    height: u32,
    format: wgpu::TextureFormat,
}

impl CaptureTarget {
    /// A target for a `width` × `height` window drawn in `format` (8-bit RGBA or BGRA only).
    pub fn new(
        device: &wgpu::Device,
        width: u32,
        height: u32,
        format: wgpu::TextureFormat,
    ) -> anyhow::Result<Self> {
        if channel_order(format).is_none() {
            bail!("cannot capture a window drawn in {format:?} (8-bit RGBA or BGRA only)");
        }
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("window capture"),
            size: wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let padded_row_bytes = (width * 4).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("window capture readback"),
            size: u64::from(padded_row_bytes) * u64::from(height),
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        Ok(Self {
            texture,
            buffer,
            padded_row_bytes,
            width,
            height,
            format,
        })
    }

    pub fn view(&self) -> wgpu::TextureView {
        self.texture.create_view(&Default::default())
    }

    /// Records the copy of the drawn target into the readback buffer.
    pub fn encode_copy(&self, encoder: &mut wgpu::CommandEncoder) {
        encoder.copy_texture_to_buffer(
            self.texture.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &self.buffer,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(self.padded_row_bytes),
                    rows_per_image: None,
                },
            },
            self.texture.size(),
        );
    }

    /// After the copy was submitted: the window's pixels as tightly packed 8-bit RGB.
    pub fn read_rgb(&self, device: &wgpu::Device) -> anyhow::Result<Vec<u8>> {
        let slice = self.buffer.slice(..);
        let (sender, receiver) = std::sync::mpsc::channel();
        slice.map_async(wgpu::MapMode::Read, move |r| {
            let _ = sender.send(r);
        });
        device
            .poll(wgpu::PollType::wait_indefinitely())
            .context("waiting for the window capture")?;
        receiver
            .recv()
            .context("the window capture's readback was dropped")?
            .context("mapping the window capture")?;
        let bgra = channel_order(self.format) == Some(ChannelOrder::Bgra);
        let mapped = slice
            .get_mapped_range()
            .context("reading the window capture")?;
        let mut rgb = Vec::with_capacity((self.width * self.height * 3) as usize);
        for row in mapped.chunks(self.padded_row_bytes as usize) {
            for px in row[..(self.width * 4) as usize].chunks_exact(4) {
                let (r, b) = if bgra { (px[2], px[0]) } else { (px[0], px[2]) };
                rgb.extend_from_slice(&[r, px[1], b]);
            }
        }
        drop(mapped);
        self.buffer.unmap();
        Ok(rgb)
    }

    /// Writes `rgb` (from [`read_rgb`](Self::read_rgb)) as a PNG, atomically.
    pub fn write_png(&self, path: &Path, rgb: &[u8]) -> anyhow::Result<()> {
        write_png_rgb8(
            path,
            self.width,
            self.height,
            rgb,
            "strandlight view: the whole window",
        )
        .context("writing the window capture")
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum ChannelOrder {
    Rgba,
    Bgra,
}

/// Byte order of the 8-bit formats a surface offers; `None` for anything else.
fn channel_order(format: wgpu::TextureFormat) -> Option<ChannelOrder> {
    use wgpu::TextureFormat as F;
    match format {
        F::Rgba8Unorm | F::Rgba8UnormSrgb => Some(ChannelOrder::Rgba),
        F::Bgra8Unorm | F::Bgra8UnormSrgb => Some(ChannelOrder::Bgra),
        _ => None,
    }
}
