//! What an env-lit frame gives back: its pixels read back, or its sums left on the GPU.

use super::EnvRenderStats;

/// A rendered frame: linear, pre-multiplied RGBA, row-major from the top.
#[derive(Clone, Debug)]
pub struct EnvImage {
    pub width: u32,
    pub height: u32,
    /// single + multiple.
    pub pixels: Vec<[f32; 4]>,
    pub single_pixels: Vec<[f32; 4]>,
    /// `None` without a forward-scattering source.
    pub multiple_pixels: Option<Vec<[f32; 4]>>,
    pub stats: EnvRenderStats,
}

/// A frame whose passes are submitted and whose pixels are still on the GPU
/// ([`EnvRenderer::encode_part`](super::EnvRenderer::encode_part)).
pub struct EncodedFrame {
    pub width: u32,
    pub height: u32,
    /// Linear, pre-multiplied RGBA f32, row-major from the top: single scattering for every
    /// pixel, then (`with_multiple`) multiple scattering for every pixel.
    pub sums: wgpu::Buffer,
    pub with_multiple: bool,
    pub stats: EnvRenderStats,
}

/// The readback of the sums split into (single + multiple, single, multiple).
#[allow(clippy::type_complexity)]
pub(super) fn split_sums(
    bytes: &[u8],
    width: u32,
    height: u32,
    with_multiple: bool,
) -> (Vec<[f32; 4]>, Vec<[f32; 4]>, Option<Vec<[f32; 4]>>) {
    let all: &[[f32; 4]] = bytemuck::cast_slice(bytes);
    let n = width as usize * height as usize;
    let single_pixels = all[..n].to_vec();
    let multiple_pixels = with_multiple.then(|| all[n..2 * n].to_vec());
    let pixels = match &multiple_pixels {
        None => single_pixels.clone(),
        Some(m) => single_pixels
            .iter()
            .zip(m)
            .map(|(s, m)| [s[0] + m[0], s[1] + m[1], s[2] + m[2], s[3]])
            .collect(),
    };
    (pixels, single_pixels, multiple_pixels)
}
