//! Offline precompute: environment maps to SRBF lights, and the convolution tables.
pub mod attenuation_ratio;
pub mod bake;
pub mod convolution;
pub mod convolution_table;
pub mod multiple_scattering_table;
pub mod point_light_luts;
pub mod srbf_spread;
pub mod table_check;
pub mod bake_plan;
pub mod check_tables;
