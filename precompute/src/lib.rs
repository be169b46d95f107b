//! Offline precompute: environment maps to SRBF lights, and the convolution tables.
pub mod convolution;
pub mod convolution_table;
pub mod table_check;
