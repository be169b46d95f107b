//! Multiple scattering in hair under environment lighting (Ren 2010 §3.2 and §6, after Zinke
//! 2008's dual scattering): the forward-scattering attenuation T_f and spread σ̄_f along shadow
//! paths, sampled on a coarse grid per light, marched on the CPU with rayon or on the GPU.
//!
//! * [`hair_volume`]: voxelization (ω̄, ν, σ_t⊥ per voxel);
//! * [`direction_deviation`]: ν in the meaning of the attenuation-ratio table;
//! * [`fiber_tables`]: checked accessors for the baked `fiber_averages`, `attenuation_ratio`
//!   and `srbf_spread` tables;
//! * [`shadow_paths`]: the expected-value shadow-path march;
//! * [`light_sweep`]: the same paths for a whole volume at once (dense sampling);
//! * [`forward_scattering`]: [`CpuForwardScattering`], the `ForwardScatteringSource` on the CPU;
//! * [`gpu_shadow_paths`]: [`GpuForwardScattering`], the same march as a compute shader.

pub mod direction_deviation;
pub mod fiber_tables;
pub mod forward_scattering;
pub mod gpu_shadow_paths;
pub mod hair_volume;
pub mod light_sweep;
pub mod shadow_paths;

#[cfg(test)]
mod tests;

pub use fiber_tables::{ForwardScatteringError, ForwardScatteringTables};
pub use forward_scattering::{
    CpuForwardScattering, ForwardScatteringGrid, ForwardScatteringSettings,
    ForwardScatteringSource, SampleGrid, interpolate_grid,
};
pub use gpu_shadow_paths::{GpuForwardScattering, MarchedForwardScattering};
pub use hair_volume::{HairVolume, VoxelGrid, VoxelSettings};
