//! Render passes: small units with explicit inputs and outputs, each shader beside its pass.

pub mod abuffer;
pub mod deep_opacity;
pub mod strands;
