//! The colour and depth textures a strand pass draws into.

use crate::gpu::GpuContext;
use crate::gpu::texture::texture_2d;

/// An HDR colour texture and its depth buffer.
pub struct RenderTarget {
    pub color: wgpu::Texture,
    pub depth: wgpu::Texture,
}

pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// The format of the view's nearest-surface targets (the env view's nearest fiber, the head
/// seen from the view): f32, so that a deferred pass shades the very point the rasterizer
/// interpolated.
pub const NEAREST_SURFACE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;

impl RenderTarget {
    pub fn new(gpu: &GpuContext, width: u32, height: u32) -> Self {
        let size = wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        };
        let texture = |label, format, usage| texture_2d(gpu, label, size, format, usage);
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
