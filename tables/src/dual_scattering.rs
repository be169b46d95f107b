//! Dual-scattering fiber averages (Zinke et al. 2008; Ren 2010 §3.2, §6; Sadeghi 2010 §5).
//! (work in progress)

use crate::scattering::Rgb;

/// A fiber model written as a sum of lobes `S = Σ_p M_p(θ_h) N_p(θ_d, φ) / cos²θ_d`, where each
/// longitudinal term M_p is (close to) a unit-area Gaussian in θ_h with shift α_p and width β_p.
/// Marschner 2003 and the artist-friendly model both have this shape; the fiber averages of
/// dual scattering are computed from it.
pub trait LobeDecomposition: Send + Sync {
    /// Number of lobes (R, TT, TRT for Marschner).
    fn lobe_count(&self) -> usize;
    /// Longitudinal shift α_p and width β_p of lobe `p`, in radians.
    fn lobe_shift_width(&self, p: usize) -> (f64, f64);
    /// The azimuthal term N_p(θ_d, φ) per channel (units 1/rad), φ = φ_o − φ_i.
    fn lobe_azimuthal(&self, p: usize, theta_d: f64, phi: f64) -> Rgb;
}
