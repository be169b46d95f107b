//! The runtime's GPU tests in one binary: each file here was a test binary of its own, and
//! linking wgpu into seventeen of them cost CI minutes. `common` holds the shared scenes.

mod common;

mod abuffer;
mod deep_opacity;
mod env_render;
mod env_view_transparency;
mod exact_coverage;
mod fiber_models;
mod frame_cube_shadows;
mod frame_shadows;
mod gpu_limits;
mod hair_samples;
mod head_occlusion;
mod head_point_lights;
mod host_point_lights;
mod ktx2_strand;
mod pass_timing;
mod shadow_maps;
mod shadow_slots;
mod strand_render;
mod transparency_modes;
