//! Marschner, Jensen, Cammarano, Worley, Hanrahan 2003, "Light Scattering from Human Hair
//! Fibers", as presented in Hunz 2016 §3.3: three lobes R, TT, TRT,
//!
//! `S(ω_i, ω_o) = Σ_p M_p(θ_i, θ_o) N_p(θ_d, φ) / cos²θ_d`,
//!
//! with M_p the longitudinal term ([`crate::longitudinal`]) and N_p the azimuthal term of the
//! circular cross section ([`azimuth`]), whose TRT caustics are replaced by glints (Hunz
//! Algorithm 1). S follows the crate convention `L_o = D ∫ S L_i cos θ_i dω_i`.
//!
//! **Normalization, stated once.** Marschner's M_p is a unit-area Gaussian in θ_h, so at fixed
//! θ_i its area over θ_o is 2 (dθ_o = 2 dθ_h), and `∫ S_p cos θ_o dω_o ≈ 2 · ½∫A_p(h) dh` —
//! twice the energy fraction the azimuthal analysis gives the lobe. This is the published
//! model (it is one of the reasons d'Eon et al. 2011 renormalized it); the energy test beside
//! the code measures it. [`LongitudinalModel::DEon`] keeps the same scale (see
//! [`crate::longitudinal::deon_on_marschner_scale`]).
//!
//! **Eccentricity.** Marschner §4.4 replaces η by η*(φ_h) for the TRT lobe, where φ_h is the
//! half azimuth from the fiber's major axis. [`ScatteringFunction::eval`] knows only
//! φ = φ_o − φ_i, i.e. fibers of random orientation about their axis, and uses the mean index
//! ½(η₁* + η₂*); [`Marschner::eval_oriented`] takes φ_h explicitly.
//!
//! **Grazing angles.** cos²θ_d is floored at [`MIN_COS2_THETA_D`] (θ_d within ~0.006° of ±90°,
//! a set of measure zero where the specular cone degenerates), so S stays finite everywhere.

pub mod azimuth;
mod hard_cases;
pub mod params;
#[cfg(test)]
mod tests;

pub use hard_cases::{SweepReport, hard_case_sweep};
pub use params::{MarschnerParams, elliptical_index, elliptical_indices};

use crate::angles::FiberAngles;
use crate::dual_scattering::LobeDecomposition;
use crate::error::ParamError;
use crate::longitudinal::LongitudinalModel;
use crate::scattering::{Rgb, ScatteringFunction};
use azimuth::{Bravais, CausticParams, azimuthal_raw, azimuthal_trt_smoothed};
use serde::{Deserialize, Serialize};

/// Floor on cos²θ_d in the 1/cos²θ_d factor of S.
pub const MIN_COS2_THETA_D: f64 = 1e-8;

/// The three scattering paths: reflection, transmission–transmission, and one internal
/// reflection.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Lobe {
    R,
    TT,
    TRT,
}

impl Lobe {
    pub const ALL: [Lobe; 3] = [Lobe::R, Lobe::TT, Lobe::TRT];

    /// p, the number of internal path segments.
    pub fn index(self) -> usize {
        match self {
            Lobe::R => 0,
            Lobe::TT => 1,
            Lobe::TRT => 2,
        }
    }

    pub fn from_index(p: usize) -> Option<Lobe> {
        Self::ALL.get(p).copied()
    }
}

/// A validated Marschner fiber with its per-parameter constants precomputed.
#[derive(Debug, Clone)]
pub struct Marschner {
    params: MarschnerParams,
    alpha: [f64; 3],
    beta: [f64; 3],
    /// η of the TRT lobe for randomly oriented fibers: ½(η₁* + η₂*) (= η when a = 1).
    eta_trt_mean: f64,
    caustic: CausticParams,
}

impl Marschner {
    pub fn new(params: MarschnerParams) -> Result<Self, ParamError> {
        params.validate()?;
        let (e1, e2) = elliptical_indices(params.eta, params.eccentricity);
        Ok(Self {
            alpha: params.alpha_deg.map(f64::to_radians),
            beta: params.beta_deg.map(f64::to_radians),
            eta_trt_mean: if params.eccentricity == 1.0 {
                params.eta
            } else {
                0.5 * (e1 + e2)
            },
            caustic: CausticParams {
                width: params.caustic_width_deg.to_radians(),
                glint_scale: params.glint_scale,
                fade_range: params.caustic_fade_range,
                intensity_limit: params.caustic_intensity_limit,
            },
            params,
        })
    }

    pub fn params(&self) -> &MarschnerParams {
        &self.params
    }

    /// Longitudinal shift α_p and width β_p of a lobe, radians.
    pub fn shift_width(&self, lobe: Lobe) -> (f64, f64) {
        (self.alpha[lobe.index()], self.beta[lobe.index()])
    }

    /// M_p(θ_i, θ_o) as it enters S (units 1/rad), including the energy normalization
    /// (see [`MarschnerParams::energy_conserving`]).
    pub fn longitudinal(&self, lobe: Lobe, theta_i: f64, theta_o: f64) -> f64 {
        let p = lobe.index();
        self.energy_scale()
            * self
                .params
                .longitudinal_model
                .eval(self.beta[p], self.alpha[p], theta_i, theta_o)
    }

    /// ½ for the energy-conserving normalization of M_p, 1 for Marschner's published one.
    pub fn energy_scale(&self) -> f64 {
        if self.params.energy_conserving {
            0.5
        } else {
            1.0
        }
    }

    /// N_p(θ_d, φ) per channel (units 1/rad), fibers of random orientation.
    pub fn azimuthal(&self, lobe: Lobe, theta_d: f64, phi: f64) -> Rgb {
        let eta = if lobe == Lobe::TRT {
            self.eta_trt_mean
        } else {
            self.params.eta
        };
        self.azimuthal_with_index(lobe, &Bravais::new(eta, theta_d), phi)
    }

    /// The η′ the TRT lobe sees at θ_d (may be +∞ at θ_d = ±90°); ≥ 2 selects the merged-
    /// caustic branch of Hunz Algorithm 1.
    pub fn trt_bravais_index(&self, theta_d: f64) -> f64 {
        Bravais::new(self.eta_trt_mean, theta_d).eta_prime()
    }

    fn azimuthal_with_index(&self, lobe: Lobe, b: &Bravais, phi: f64) -> Rgb {
        let sigma_a = &self.params.sigma_a;
        if lobe == Lobe::TRT && self.params.smooth_caustics {
            azimuthal_trt_smoothed(b, phi, sigma_a, &self.caustic)
        } else {
            azimuthal_raw(b, lobe.index(), phi, sigma_a)
        }
    }

    /// One lobe of S: M_p N_p / cos²θ_d.
    pub fn eval_lobe(&self, lobe: Lobe, angles: &FiberAngles) -> Rgb {
        let m = self.longitudinal(lobe, angles.theta_i, angles.theta_o);
        if m == 0.0 {
            return [0.0; 3];
        }
        let theta_d = angles.theta_d();
        let n = self.azimuthal(lobe, theta_d, angles.phi);
        let scale = m / cos2_floored(theta_d);
        n.map(|v| v * scale)
    }

    /// S for a fiber whose major axis makes half azimuth `phi_h` = (φ_i + φ_o)/2 with the
    /// half vector (Marschner 2003 §4.4): the TRT lobe uses η*(φ_h).
    pub fn eval_oriented(&self, angles: &FiberAngles, phi_h: f64) -> Rgb {
        let eta_trt = elliptical_index(self.params.eta, self.params.eccentricity, phi_h);
        self.eval_with_trt_index(angles, eta_trt)
    }

    fn eval_with_trt_index(&self, angles: &FiberAngles, eta_trt: f64) -> Rgb {
        let theta_d = angles.theta_d();
        let inv_cos2 = 1.0 / cos2_floored(theta_d);
        let b = Bravais::new(self.params.eta, theta_d);
        let b_trt = if eta_trt == self.params.eta {
            b
        } else {
            Bravais::new(eta_trt, theta_d)
        };
        let mut s = [0.0; 3];
        for lobe in Lobe::ALL {
            let m = self.longitudinal(lobe, angles.theta_i, angles.theta_o);
            if m == 0.0 {
                continue;
            }
            let bravais = if lobe == Lobe::TRT { &b_trt } else { &b };
            let n = self.azimuthal_with_index(lobe, bravais, angles.phi);
            for c in 0..3 {
                s[c] += m * n[c] * inv_cos2;
            }
        }
        s
    }
}

fn cos2_floored(theta_d: f64) -> f64 {
    let c = theta_d.cos();
    (c * c).max(MIN_COS2_THETA_D)
}

impl ScatteringFunction for Marschner {
    fn name(&self) -> &'static str {
        "marschner"
    }

    fn eval(&self, angles: &FiberAngles) -> Rgb {
        self.eval_with_trt_index(angles, self.eta_trt_mean)
    }
}

impl LobeDecomposition for Marschner {
    fn lobe_count(&self) -> usize {
        3
    }

    /// (α_p, β_p) in radians; a lobe index ≥ 3 has no width: (0, 0).
    fn lobe_shift_width(&self, p: usize) -> (f64, f64) {
        Lobe::from_index(p).map_or((0.0, 0.0), |l| self.shift_width(l))
    }

    /// N_p, times the energy normalization because the trait's M_p is the unit-area Gaussian
    /// in θ_h; a lobe index ≥ 3 scatters nothing.
    fn lobe_azimuthal(&self, p: usize, theta_d: f64, phi: f64) -> Rgb {
        let k = self.energy_scale();
        Lobe::from_index(p).map_or([0.0; 3], |l| self.azimuthal(l, theta_d, phi).map(|v| k * v))
    }
}

/// Convenience for callers that only have the enum: the longitudinal model in use.
impl Marschner {
    pub fn longitudinal_model(&self) -> LongitudinalModel {
        self.params.longitudinal_model
    }
}
