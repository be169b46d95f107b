//! The wgpu runtime: hair input, render passes, and the brute-force reference renderer.
//!
//! # Use the runtime in your renderer
//!
//! [`host::HairRenderer`] draws env-lit hair into an application's own render pass, on the
//! application's device, depth-tested against what it drew, with no readback and no wait on the
//! frame's path. The scene layer (`strandlight-scene`) turns a frame's settings into the groom,
//! lights and baked tables it draws; the runtime takes them from anywhere.
//!
//! ```ignore
//! // Once: the hair renderer on the host's device, drawing into the host's targets.
//! let mut hair_renderer = HairRenderer::new(&device, &queue, HairTargets {
//!     color: wgpu::TextureFormat::Rgba16Float,
//!     depth: Some(wgpu::TextureFormat::Depth32Float),
//!     sample_count: 1,
//! });
//! // Per view: start the frame, then add batches of lights when there is time.
//! hair_renderer.prepare(&hair_frame)?;
//! while !hair_renderer.encode_next_batch(&hair_frame)?.converged() {}
//! // In the host's own render pass, after its meshes:
//! hair_renderer.render(&mut pass);
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
