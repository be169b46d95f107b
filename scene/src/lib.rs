//! The scene layer: what the `strandlight` command line, the viewer and the evaluation share
//! (the way Filament's `libs/ibl` serves both `cmgen` and its runtime). It loads a scene's hair
//! and environment, holds the frame's settings, fits and bakes with on-disk caches, and renders
//! an environment-lit frame through the one GPU renderer of the process.
//!
//! Dependencies point one way: `tables` ← `precompute`, `runtime` ← this crate ← `eval`, the
//! viewer and the CLI. How the product measures itself (compare, bench, the ground truth) lives
//! in `strandlight-eval`, so the viewer does not link it.

pub mod camera_choice;
pub mod env_frame;
pub mod env_light_sets;
pub mod env_lighting;
pub mod env_orientation;
pub mod env_scene;
pub mod environment;
pub mod exposure;
pub mod fit_cache;
pub mod frame_render;
pub mod frame_settings;
pub mod hair_input;
#[cfg(feature = "scene-files")]
pub mod head_gltf;
pub mod head_input;
pub mod image_metrics;
pub mod look;
pub mod orbit;
pub mod point_shading;
pub mod progressive;
pub mod rendered_frame;
pub mod scene_tables;
pub mod sealed_file;
pub mod steps;
pub mod web_bundle;
