//! The wgpu runtime: hair input, render passes, and the brute-force reference renderer.

pub mod camera;
pub mod env;
pub mod env_light;
pub mod gpu;
pub mod hair;
pub mod head;
pub mod lights;
pub mod multiple;
pub mod passes;
pub mod point_frame;
#[cfg(test)]
mod shader_layout;
pub mod shaders;
pub mod shadow_layout;
pub mod visibility;
