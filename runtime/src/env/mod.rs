//! Environment lighting (Ren et al. 2010): the shared vocabulary of the env-lit renderer.
//!
//! One renderer serves three users: the SRBF path (lights with a bandwidth λ, shaded by the
//! convolution tables and shadowed by the convolution optical depth map), and the directional
//! reference and median-cut baseline (lights with no bandwidth, shaded by the fiber function
//! itself and shadowed by the same layered map sampled at one texel). A batch of lights is
//! always of one kind.

pub mod render;
pub use render::{
    DEFAULT_SIMPLIFICATION_SEED, EncodedFrame, EnvFrame, EnvRenderError, EnvRenderOptions,
    EnvRenderStats, EnvRenderer, EnvTableError, EnvTables, FragmentCounts, OccupancyError,
    TransmittanceFilter, ViewTransparency, render_env_frame,
};
