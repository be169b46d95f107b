//! Render passes: small units with explicit inputs and outputs, each shader beside its pass.

pub mod abuffer;
pub mod attachments;
pub mod deep_opacity;
pub mod fiber_shading;
pub mod strands;
