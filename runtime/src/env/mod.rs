//! Environment lighting (Ren et al. 2010): the shared vocabulary of the env-lit renderer.
//!
//! One renderer serves three users: the SRBF path (lights with a bandwidth λ, shaded by the
//! convolution tables and shadowed by the convolution optical depth map), and the directional
//! reference and median-cut baseline (lights with no bandwidth, shaded by the fiber function
//! itself and shadowed by the same layered map sampled at one texel). A batch of lights is
//! always of one kind.

use glam::Vec3;

/// One light of an environment.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EnvLight {
    /// Unit vector toward the light (the SRBF centre ξ).
    pub direction: Vec3,
    /// SRBF bandwidth λ; `None` for a directional light.
    pub lambda: Option<f32>,
    /// SRBF amplitude L_j (radiance) for an SRBF; for a directional light its irradiance at
    /// normal incidence (the radiance it stands for × the solid angle it covers).
    pub rgb: [f32; 3],
}

impl EnvLight {
    pub fn srbf(direction: Vec3, lambda: f32, amplitude: [f32; 3]) -> Self {
        Self {
            direction: direction.normalize(),
            lambda: Some(lambda),
            rgb: amplitude,
        }
    }

    pub fn directional(direction: Vec3, irradiance: [f32; 3]) -> Self {
        Self {
            direction: direction.normalize(),
            lambda: None,
            rgb: irradiance,
        }
    }

    /// What the light delivers to a fiber facing it, before shadowing: for an SRBF its
    /// amplitude × ∫G dω = L_j · 2π/λ · (1 − e^{−2λ}); for a directional light its irradiance.
    /// The multiple-scattering term (normalized spread function ψ_f) is weighted by this.
    pub fn power(&self) -> [f32; 3] {
        match self.lambda {
            None => self.rgb,
            Some(lambda) => {
                let l = lambda as f64;
                let integral = 2.0 * std::f64::consts::PI / l * -(-2.0 * l).exp_m1();
                self.rgb.map(|c| (c as f64 * integral) as f32)
            }
        }
    }
}

/// The forward-scattering attenuation T_f (RGB) and spread σ̄_f (radians, the standard
/// deviation of the incident inclination) of Ren §6, sampled on a regular grid over the hair
/// per light, as the view pass reads them: `values[light][z][y][x] = [T_r, T_g, T_b, σ̄_f]`,
/// trilinearly interpolated between grid vertices, clamped at the border.
#[derive(Clone, Debug, PartialEq)]
pub struct ForwardScatteringGrid {
    /// World position of vertex (0, 0, 0).
    pub origin: Vec3,
    /// World distance between neighbouring vertices along x, y, z.
    pub spacing: Vec3,
    /// Vertices along x, y, z.
    pub dims: [u32; 3],
    /// One block of dims.x·dims.y·dims.z values per light, in the order of the lights asked for.
    pub values: Vec<[f32; 4]>,
}

/// Computes [`ForwardScatteringGrid`]s for batches of lights (the multiple-scattering module
/// implements it on the CPU and on the GPU; a frame asks once per batch).
pub trait ForwardScatteringSource {
    /// The grid (with values for every light in `lights`, in order).
    fn grid(&self, lights: &[EnvLight]) -> Result<ForwardScatteringGrid, ForwardScatteringError>;

    /// Where the march runs ("CPU", "GPU"): names the pass in the frame's timings.
    fn device(&self) -> &'static str;
}

use crate::multiple::ForwardScatteringError;

pub mod render;
pub use render::{
    BoxAverage, EnvFrame, EnvRenderError, EnvRenderOptions, EnvRenderStats, EnvRenderer,
    EnvTableError, EnvTables, FragmentCounts, OccupancyError, TransmittanceFilter,
    ViewTransparency, render_env_frame,
};
