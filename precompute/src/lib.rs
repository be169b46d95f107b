//! Offline precompute: environment maps to SRBF lights, and the convolution tables.
pub mod convolution;
pub mod convolution_table;
pub mod table_check;
pub mod attenuation_ratio;
pub mod srbf_spread;
pub mod multiple_scattering_table;
pub mod bake;
