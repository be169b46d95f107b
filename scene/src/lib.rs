//! The scene layer: what the `strandlight` command line, the viewer and `bench` share (the way
//! Filament's `libs/ibl` serves both `cmgen` and its runtime). It loads a scene's hair and
//! environment, fits and bakes with on-disk caches, renders an environment-lit frame through
//! the one GPU renderer of the process, measures images against a reference, and runs the
//! SRBF / reference / median-cut comparison of Ren 2010 §8.
//!
//! Dependencies point one way: `tables` ← `precompute`, `runtime` ← this crate ← the CLI.

pub mod baseline;
pub mod bench;
pub mod bench_plots;
pub mod bench_report;
pub mod camera_choice;
pub mod compare;
pub mod compare_table;
pub mod env_frame;
pub mod env_scene;
pub mod environment;
pub mod equal_time;
pub mod error_decomposition;
pub mod error_metric;
pub mod fit_cache;
pub mod frame_render;
pub mod frame_settings;
pub mod ground_truth;
pub mod hair_input;
pub mod hdr_flip;
pub mod image_metrics;
pub mod look;
pub mod point_shading;
pub mod reference_cache;
pub mod scene_tables;
pub mod sealed_file;
pub mod steps;
pub mod summary;
pub mod world_lights;
