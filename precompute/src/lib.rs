//! Offline precompute: environment maps to SRBF lights, and the convolution tables.
pub mod convolution;
