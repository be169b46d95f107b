//! The wgpu runtime: hair input, render passes, and the brute-force reference renderer.
//!
//! # Use the runtime in your renderer
//!
//! [`host::HairRenderer`] draws env-lit hair into an application's own render pass, on the
//! application's device, depth-tested against what it drew, with no readback and no wait on the
//! frame's path. The scene layer (`strandlight-scene`) turns a frame's settings into the groom,
//! lights and baked tables it draws; the runtime takes them from anywhere. The thesis
//! techniques (point and directional lights with shadow or deep opacity maps, and every
//! transparency technique) go the same way: [`host::HairRenderer::draw_point_lit`] draws such a
//! frame whole, and `render` draws it into the host's pass as below.
//!
//! ```
//! # use strandlight_runtime::camera::Camera;
//! # use strandlight_runtime::env::{EnvRenderOptions, EnvTables};
//! # use strandlight_runtime::env_light::EnvLight;
//! # use strandlight_runtime::gpu::GpuContext;
//! # use strandlight_runtime::hair::groom::{GroomParams, generate_groom};
//! # use strandlight_runtime::host::{HairFrame, HairRenderer, HairTargets};
//! # use strandlight_precompute::convolution_table::DirectionAxes;
//! # use strandlight_precompute::direct_table::{DirectResolution, bake_direct_table};
//! # use strandlight_tables::chiang::Chiang;
//! # use strandlight_tables::scattering::ScatteringFunction;
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! # // The host's device, targets and scene (an application has its own).
//! # let host = GpuContext::new_headless()?;
//! # let (device, queue) = (&host.device, &host.queue);
//! # let size = [64, 48];
//! # let target = |format: wgpu::TextureFormat| device.create_texture(&wgpu::TextureDescriptor {
//! #     label: None,
//! #     size: wgpu::Extent3d { width: size[0], height: size[1], depth_or_array_layers: 1 },
//! #     mip_level_count: 1,
//! #     sample_count: 1,
//! #     dimension: wgpu::TextureDimension::D2,
//! #     format,
//! #     usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
//! #     view_formats: &[],
//! # }).create_view(&Default::default());
//! # let (color, depth) = (target(wgpu::TextureFormat::Rgba16Float), target(wgpu::TextureFormat::Depth32Float));
//! # let model = generate_groom(&GroomParams { strand_count: 300, ..Default::default() })?;
//! # let camera = Camera::framing(model.bounds(), size[0] as f32 / size[1] as f32, false);
//! # let fiber = Chiang::new(Default::default())?;
//! # let table = bake_direct_table(&|a| fiber.eval(a), &DirectResolution::cube(6, DirectionAxes::Uniform))?;
//! # let tables = EnvTables { direct: Some(table.into()), ..Default::default() };
//! # let sun = [EnvLight::directional(glam::Vec3::new(0.3, 1.0, 0.5), [3.0, 2.8, 2.5])];
//! # let options = EnvRenderOptions::default();
//! let hair_frame = HairFrame {
//!     model: &model,
//!     camera: &camera,
//!     size,
//!     lights: &sun,
//!     tables: &tables,
//!     options: &options,
//!     multiple: None,
//!     head: None,
//! };
//! // Once: the hair renderer on the host's device, drawing into the host's targets.
//! let mut hair_renderer = HairRenderer::new(device, queue, HairTargets {
//!     color: wgpu::TextureFormat::Rgba16Float,
//!     depth: Some(wgpu::TextureFormat::Depth32Float),
//!     sample_count: 1,
//! });
//! // Per view: start the frame, then add batches of lights when there is time.
//! hair_renderer.prepare(&hair_frame)?;
//! while !hair_renderer.encode_next_batch(&hair_frame)?.converged() {}
//! // In the host's own render pass, after its meshes:
//! let mut encoder = device.create_command_encoder(&Default::default());
//! let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
//!     color_attachments: &[Some(wgpu::RenderPassColorAttachment {
//!         view: &color,
//!         depth_slice: None,
//!         resolve_target: None,
//!         ops: wgpu::Operations { load: wgpu::LoadOp::Clear(wgpu::Color::BLACK), store: wgpu::StoreOp::Store },
//!     })],
//!     depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
//!         view: &depth,
//!         depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(1.0), store: wgpu::StoreOp::Store }),
//!         stencil_ops: None,
//!     }),
//!     ..Default::default()
//! });
//! hair_renderer.render(&mut pass);
//! drop(pass);
//! queue.submit([encoder.finish()]);
//! # assert!(hair_renderer.progress().unwrap().converged());
//! # Ok(())
//! # }
//! ```
//!
//! The whole program, with its own device, meshes, depth buffer and camera, is
//! `runtime/examples/host.rs` (`cargo run --release -p strandlight-runtime --example host`);
//! `tests/host_embedding.rs` runs it and checks its picture against a CPU depth reference and
//! against `strandlight render replay`.

pub mod camera;
pub mod env;
pub mod env_light;
pub mod gpu;
pub mod hair;
pub mod head;
pub mod host;
pub mod lights;
pub mod multiple;
pub mod passes;
pub mod point_frame;
#[cfg(test)]
mod shader_layout;
pub mod shaders;
pub mod shadow_layout;
pub mod visibility;
