//! Offline precompute: environment maps to SRBF lights, and the convolution tables.
//!
//! Environment input: [`envmap`] (the in-memory map and THE direction convention),
//! [`envmap_io`] (files), [`radiance_hdr`], [`procedural_env`]. Lights: [`srbf_fit`] (the
//! adaptive SRBF fit), [`median_cut`] (the directional baseline), [`srbf_set`] (the file the
//! runtime reads), [`preview`] (a picture of what the fit lost). Tables:
//! [`point_light_luts`] (Hunz Algorithm 2).

pub mod atomic;
pub mod envmap;
pub mod envmap_error;
pub mod envmap_io;
pub mod median_cut;
pub mod nnls;
pub mod point_light_luts;
pub mod preview;
pub mod procedural_env;
pub mod radiance_hdr;
pub mod srbf_fit;
pub mod srbf_objective;
pub mod srbf_set;

pub use envmap::EnvMap;
pub use envmap_error::EnvMapError;
pub use srbf_fit::{FitOptions, fit};
pub use srbf_set::SrbfSet;
