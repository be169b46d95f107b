//! Scene pieces shared by the GPU tests: a device, the orthographic test camera, the slab of
//! parallel strands whose transmittance has a closed form, and a host application's targets.

use glam::{DVec3, Vec3};
use strandlight_runtime::camera::{Camera, Projection};
use strandlight_runtime::gpu::GpuContext;
use strandlight_runtime::gpu::texture::texture_2d;
use strandlight_runtime::hair::{Attribute, HairModel};

/// Texels of the slab's light maps (and pixels of the test images) across.
pub const RES: u32 = 64;
/// Light-map texels per world unit (2 units across 64 texels).
pub const PER_UNIT: f64 = 32.0;

/// ‖a − b‖ / ‖b‖ over the RGB of every pixel (alpha left out).
pub fn relative_rmse(a: &[[f32; 4]], b: &[[f32; 4]]) -> f64 {
    let (mut err, mut norm) = (0.0f64, 0.0f64);
    for (p, q) in a.iter().zip(b) {
        for k in 0..3 {
            err += (p[k] as f64 - q[k] as f64).powi(2);
            norm += (q[k] as f64).powi(2);
        }
    }
    (err / norm).sqrt()
}

/// The software or hardware device; a test fails (with the install hint) when there is none.
pub fn gpu() -> GpuContext {
    GpuContext::new_headless().unwrap_or_else(|e| panic!("{e}"))
}

/// Orthographic, looking down −z from +z, 2 world units tall: 32 pixels per unit for a 64-pixel
/// image, world x = 0 on the boundary between pixel columns 31 and 32.
pub fn ortho_camera() -> Camera {
    Camera {
        eye: Vec3::new(0.0, 0.0, 5.0),
        target: Vec3::ZERO,
        up: Vec3::Y,
        projection: Projection::Orthographic { half_height: 1.0 },
        near: 1.0,
        far: 10.0,
    }
}

/// `rows` rows at z = 0.3 − 0.1·r (lights at +z), one vertical fiber per texel column, each row
/// shifted by its own sub-texel offset: with fibers of diameter d spaced s = 1/PER_UNIT apart,
/// each row transmits (1 − d/s).
pub fn slab(rows: usize, thickness: f32) -> HairModel {
    slab_with_gap(rows, thickness, 0..0)
}

/// [`slab`] without the fibers of texel columns `gap` in every row: a slot the light falls
/// through, with the slab's shadow on both sides of it.
pub fn slab_with_gap(rows: usize, thickness: f32, gap: std::ops::Range<u32>) -> HairModel {
    let offsets = [0.17, -0.23, 0.05, 0.29, -0.11, -0.02];
    let mut points = Vec::new();
    let mut strand_offsets = vec![0u32];
    for r in 0..rows {
        let z = 0.3 - 0.1 * r as f32;
        for c in (0..RES).filter(|c| !gap.contains(c)) {
            let x = ((c as f64 + 0.5 + offsets[r % offsets.len()]) / PER_UNIT - 1.0) as f32;
            points.push(Vec3::new(x, -0.9, z));
            points.push(Vec3::new(x, 0.9, z));
            strand_offsets.push(points.len() as u32);
        }
    }
    HairModel::new(
        points,
        strand_offsets,
        Some(Attribute::Uniform(thickness)),
        None,
        None,
    )
    .unwrap()
}

/// The shortest distance between segments p0p1 and q0q1 (Ericson, Real-Time Collision
/// Detection §5.1.9; neither segment degenerate).
pub fn segment_distance(p0: DVec3, p1: DVec3, q0: DVec3, q1: DVec3) -> f64 {
    let (d1, d2, r) = (p1 - p0, q1 - q0, p0 - q0);
    let (a, e, f) = (d1.dot(d1), d2.dot(d2), d2.dot(r));
    let (b, c) = (d1.dot(d2), d1.dot(r));
    let denom = a * e - b * b;
    let mut s = if denom > 1e-12 {
        ((b * f - c * e) / denom).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let mut t = (b * s + f) / e;
    if t < 0.0 {
        t = 0.0;
        s = (-c / a).clamp(0.0, 1.0);
    } else if t > 1.0 {
        t = 1.0;
        s = ((b - c) / a).clamp(0.0, 1.0);
    }
    ((p0 + d1 * s) - (q0 + d2 * t)).length()
}

/// The head tests' scene (head_occlusion.rs, head_point_lights.rs): a sphere of radius
/// `HEAD_RADIUS` at the origin with skin `HEAD_SKIN`, and vertical fibers beside or behind it.
pub const HEAD_RADIUS: f32 = 0.4;
pub const HEAD_SKIN: [f32; 3] = [0.6, 0.4, 0.3];

pub fn sphere_head() -> strandlight_runtime::head::Head {
    strandlight_runtime::head::Head {
        albedo: HEAD_SKIN,
        ..strandlight_runtime::head::Head::ellipsoid(Vec3::ZERO, Vec3::splat(HEAD_RADIUS))
    }
}

/// A fiber along y from −0.9 to 0.9 at (x, z).
pub fn vertical_fiber(x: f32, z: f32) -> [Vec3; 2] {
    [Vec3::new(x, -0.9, z), Vec3::new(x, 0.9, z)]
}

/// One two-point strand per fiber, 3 pixels wide on screen (full coverage at its column).
pub fn two_point_hair(fibers: &[[Vec3; 2]]) -> HairModel {
    let points: Vec<Vec3> = fibers.iter().flatten().copied().collect();
    let offsets = (0..=fibers.len() as u32).map(|i| 2 * i).collect();
    HairModel::new(
        points,
        offsets,
        Some(Attribute::Uniform(3.0 / 32.0)),
        None,
        None,
    )
    .unwrap()
}

/// A host application's colour and depth targets (`RENDER_ATTACHMENT | COPY_SRC`), for tests
/// that draw the hair into a host's own pass.
pub struct HostTargets {
    pub colour: wgpu::Texture,
    pub depth: wgpu::Texture,
}

impl HostTargets {
    pub fn new(
        gpu: &GpuContext,
        [width, height]: [u32; 2],
        colour: wgpu::TextureFormat,
        depth: wgpu::TextureFormat,
    ) -> Self {
        let size = wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        };
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC;
        let target = |format, label| texture_2d(gpu, label, size, format, usage);
        Self {
            colour: target(colour, "host colour"),
            depth: target(depth, "host depth"),
        }
    }

    /// The host's own pass: colour cleared to `clear_colour` and depth to `clear_depth`, then
    /// `draw` recorded in it; submitted.
    pub fn draw(
        &self,
        gpu: &GpuContext,
        clear_colour: wgpu::Color,
        clear_depth: f32,
        draw: impl FnOnce(&mut wgpu::RenderPass<'_>),
    ) {
        let colour_view = self.colour.create_view(&Default::default());
        let depth_view = self.depth.create_view(&Default::default());
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("host"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &colour_view,
                    resolve_target: None,
                    depth_slice: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(clear_colour),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &depth_view,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(clear_depth),
                        store: wgpu::StoreOp::Store,
                    }),
                    stencil_ops: None,
                }),
                ..Default::default()
            });
            draw(&mut pass);
        }
        gpu.queue.submit([encoder.finish()]);
    }
}
