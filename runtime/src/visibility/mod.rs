//! Lobe visibility integrated over the lobe, for a groom that does not move: the transmittance
//! toward every direction, marched once through the voxelized hair from the vertices of a grid
//! around it and kept as low-order spherical harmonics ([`VisibilityVolume`]). A lobe's
//! visibility is then the SH visibility convolved with the SRBF in closed form
//! (Funk–Hecke: [`spherical_harmonics::srbf_band_ratios`]), so its cost does not grow with a
//! light pass per lobe, and the map can rotate without rebuilding anything.
//!
//! Ren 2010 reads one direction per lobe from the lobe's own deep opacity map and box-filters
//! it; this integrates T over the lobe's solid angle, weighted by the lobe, at the price of the
//! volume's resolution (fiber-scale detail is averaged over a voxel) and of the SH band limit.

pub mod spherical_harmonics;
pub mod volume;

pub use spherical_harmonics::{SH_COEFFICIENTS, lobe_visibility, srbf_band_ratios};
pub use volume::{VisibilityVolume, VisibilityVolumeError, VisibilityVolumeSettings};

/// Where an SRBF lobe's visibility comes from. The runtime defaults to Ren's light maps, the
/// method as published; the product's settings (`scene::look`, so the CLI and the viewer) default
/// to the volume, which measured faster at the same error (docs/BENCHMARKS.md, "Lobe visibility").
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum LobeVisibility {
    /// Ren 2010: each lobe's own convolution optical depth map, read at the lobe's centre and
    /// box-filtered (one light pass per lobe).
    #[default]
    LightMaps,
    /// The groom's [`VisibilityVolume`], integrated over each lobe (no light pass for SRBF
    /// lobes; built once per groom and kept while the hair does not move).
    Volume(VisibilityVolumeSettings),
}

impl LobeVisibility {
    pub fn volume(&self) -> Option<&VisibilityVolumeSettings> {
        match self {
            Self::LightMaps => None,
            Self::Volume(settings) => Some(settings),
        }
    }
}
