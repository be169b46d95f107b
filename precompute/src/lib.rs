//! Offline precompute: environment maps to SRBF lights, and the convolution tables.
//!
//! Environment input: [`envmap`] (the in-memory map and THE direction convention),
//! [`envmap_io`] (files), [`radiance_hdr`], [`procedural_env`]. Lights: [`srbf_fit`] (the
//! adaptive SRBF fit), [`median_cut`] (the directional baseline), [`srbf_set`] (the file the
//! runtime reads), [`preview`] (a picture of what the fit lost), [`cube_lights`] (the
//! brute-force reference's texel lights), [`env_lights`] (the three light sets of `compare`).
//!
//! Tables: [`convolution`] (the SRBF–fiber convolution engine and its brute-force reference),
//! [`convolution_table`] (I_M, I_A, I_d, I_s as tables), [`direct_table`] (S·cos θ_i for
//! directional lights, on the same axes), [`multiple_scattering_table`] (I_G),
//! [`attenuation_ratio`], [`srbf_spread`], [`point_light_luts`] (Hunz Algorithm 2),
//! [`chiang_luts`] (the same for the Chiang fiber),
//! [`bake_plan`] (which tables a fiber needs), [`bake`] (assets and the cache),
//! [`table_accuracy`] (the accuracy measure: stratified off-grid points against f64 integration) and [`baked_tables_check`] (every baked asset against its f64 reference).

pub mod attenuation_ratio;
pub mod bake;
pub mod bake_plan;
pub mod baked_tables_check;
pub mod chiang_luts;
pub mod compact_sources;
pub mod convolution;
pub mod convolution_table;
pub mod cube_lights;
pub mod direct_table;
pub mod env_lights;
pub mod envmap;
pub mod envmap_error;
pub mod envmap_io;
pub mod median_cut;
pub mod multiple_scattering_table;
pub mod nnls;
pub mod point_light_luts;
pub mod preview;
pub mod procedural_env;
pub mod radiance_hdr;
pub mod srbf_fit;
pub mod srbf_objective;
pub mod srbf_set;
pub mod srbf_spread;
pub mod table_accuracy;

pub use envmap::EnvMap;
pub use envmap_error::EnvMapError;
pub use srbf_fit::{FitOptions, fit};
pub use srbf_set::SrbfSet;
