//! The textures one batch's view shading renders into, and what it reads of the frame's
//! visibility.

use super::view_visibility::ViewTransparency;
use crate::gpu::GpuContext;
use crate::gpu::texture::texture_2d;
use crate::passes::render_target::{DEPTH_FORMAT, NEAREST_SURFACE_FORMAT};

/// Two HDR targets (single, multiple) for one batch's view pass, and what the opaque view reads
/// of the frame's visibility: the depth prepass, the coverage (red: Σ −ln(1 − α) of a pixel's
/// fragments; the opaque view's alpha) and the nearest fiber's position (w: 1 on hair) and
/// tangent, f32 so that the deferred view shades the very point the rasterizer interpolated
/// (the three are 1×1 and unused for the transparent view).
#[derive(Clone)]
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
