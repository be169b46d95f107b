//! The shared core of strandlight: fiber scattering functions, SRBF math, the lookup-table
//! type with its asset format, and the f64 reference integrators everything else is checked
//! against.
//!
//! Conventions (see DESIGN.md): the fiber frame has tangent `u` from root to tip; a direction's
//! inclination θ ∈ [−π/2, π/2] is measured from the normal plane (`sin θ = u·ω`) and φ is its
//! azimuth in the normal plane. Radiance leaving a fiber is `L_o = D ∫ S(ω_i, ω_o) L_i cos θ_i dω_i`
//! (Marschner 2003; Ren 2010 eq. 1), so every [`ScatteringFunction`] returns that `S`.

pub mod absorption;
pub mod angles;
pub mod artist;
pub mod asset;
pub mod atomic_write;
pub mod checksum;
pub mod chiang;
pub mod colour;
pub mod dual_scattering;
pub mod dual_scattering_hard_cases;
pub mod error;
pub mod hard_case_sweep;
pub mod image_out;
pub mod kajiya_kay;
pub mod ktx2_writer;
pub mod longitudinal;
pub mod lut_export;
pub mod lut_layout;
pub mod lut_sidecar;
pub mod marschner;
pub mod model_sweeps;
pub mod outside_tools;
pub mod quadrature;
pub mod scattering;
pub mod shared_data;
pub mod slices;
pub mod special;
pub mod split_mix;
pub mod srbf;
pub mod table;
pub mod table_axes;

pub use angles::FiberAngles;
pub use error::ParamError;
pub use scattering::{Rgb, ScatteringFunction};
