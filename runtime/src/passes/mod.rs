//! Render passes: small units with explicit inputs and outputs, each shader beside its pass.

pub mod abuffer;
pub mod attachments;
pub mod convolution_depth;
pub mod convolution_transmittance;
pub mod deep_opacity;
pub mod fiber_shading;
pub mod frame_params;
pub mod head;
pub mod kbuffer;
pub mod point_skin;
pub mod random_subsets;
pub mod render_target;
pub mod shadow_slots;
pub mod sorted_blend;
pub mod strand_geometry;
pub mod strand_quads;
pub mod strands;
pub mod summed_area;
pub mod transmittance_filter;
pub mod transmittance_probe;
