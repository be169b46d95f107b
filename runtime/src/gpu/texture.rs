//! Texture creation shared by the passes: every target and map here is a single-mip,
//! single-sample 2D texture (or 2D array, through `size.depth_or_array_layers`).

use crate::gpu::GpuContext;

/// A `size` 2D texture (array) of `format` with `usage`.
pub fn texture_2d(
    gpu: &GpuContext,
    label: &str,
    size: wgpu::Extent3d,
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> wgpu::Texture {
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
}
