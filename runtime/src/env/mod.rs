//! Environment lighting (Ren et al. 2010): the env-lit renderer.
//!
//! One renderer serves three users: the SRBF path (lights with a bandwidth λ, shaded by the
//! convolution tables and shadowed by the convolution optical depth map), and the directional
//! reference and median-cut baseline (lights with no bandwidth, shaded by the fiber function
//! itself and shadowed by the same layered map sampled at one texel). A batch of lights is
//! always of one kind.
//!
//! A frame ([`EnvRenderer`], `renderer.rs`) checks its inputs (`checks.rs`), creates its
//! resources once (`frame_resources.rs`), draws the view's visibility once (`frame_visibility.rs`),
//! then per batch of lights (`light_kinds.rs`, `batch.rs`): the light maps, DODM and summed-area
//! tables (`light_maps.rs`), the view shading into two images (`view_shading.rs`, binding
//! groups 1–3 in `passes/convolution_transmittance.rs`, `table_binding.rs`, `view_binding.rs`),
//! added into the frame's running sums (`accumulate.rs`). One readback at the end, or none: a
//! progressive frame keeps its [`FrameSums`] and adds each part into it.

mod accumulate;
mod batch;
mod checks;
mod error;
mod frame_resources;
mod frame_visibility;
mod image;
mod light_kinds;
mod light_maps;
mod options;
mod renderer;
mod segment_light_visibility;
mod stats;
mod table_binding;
mod tables;
mod view_binding;
mod view_shading;
mod view_targets;
mod view_visibility;
mod volume;

pub use crate::passes::transmittance_filter::TransmittanceFilter;
pub use accumulate::FrameSums;
pub use error::EnvRenderError;
pub use image::{EncodedFrame, EnvImage};
pub use options::{DEFAULT_SIMPLIFICATION_SEED, EnvRenderOptions};
pub use renderer::{EnvRenderer, render_env_frame};
pub use stats::EnvRenderStats;
pub use tables::{EnvTableError, EnvTables, check_env_table};
pub use view_visibility::{FragmentCounts, OccupancyError, ViewTransparency};
