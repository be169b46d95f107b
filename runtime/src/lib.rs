//! The wgpu runtime: hair input, render passes, and the brute-force reference renderer.

pub mod gpu;
pub mod hair;
