//! Longitudinal scattering terms M_p: how a lobe spreads light away from the specular cone
//! θ_o = −θ_i.
//!
//! Two models:
//! - **Gaussian** (Marschner et al. 2003 §4.2; Hunz eq. 40): `M_p = g(β_p, θ_h − α_p)`, a
//!   unit-area Gaussian in the half angle θ_h. Note its area over θ_o at fixed θ_i is 2
//!   (dθ_o = 2 dθ_h), which is Marschner's normalization.
//! - **d'Eon** (d'Eon, Francois, Hill, Letteri, Aubry 2011, "An Energy-Conserving Hair
//!   Reflectance Model", eq. 7): the cone convolved with a spherical Gaussian of variance v,
//!   `M(v, θ_i, θ_o) = csch(1/v)/(2v) · exp(−sin θ_i sin θ_o / v) · I₀(cos θ_i cos θ_o / v)`,
//!   normalized so that `∫ M cos θ_o dθ_o = 1` over [−π/2, π/2] for every θ_i.
//!
//! The naive d'Eon form overflows for small v (I₀(1/v) and sinh(1/v) with 1/v ≈ 10⁴); here
//! it is evaluated in log space with the exponentially scaled I₀ and `ln csch` written with
//! `expm1`, so every factor stays bounded (see DESIGN.md, "Known traps").

use crate::special::{gaussian, scaled_bessel_i0};
use serde::{Deserialize, Serialize};
use std::f64::consts::{FRAC_PI_2, PI};

/// Which longitudinal term a lobe uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LongitudinalModel {
    /// Marschner 2003: unit-area Gaussian in θ_h.
    #[default]
    Gaussian,
    /// d'Eon et al. 2011, on Marschner's scale (see [`deon_on_marschner_scale`]).
    #[serde(rename = "deon")]
    DEon,
}

/// Marschner's longitudinal term `g(β, θ_h − α)`; `beta` is the standard deviation in θ_h.
pub fn gaussian_longitudinal(beta: f64, alpha: f64, theta_i: f64, theta_o: f64) -> f64 {
    let x = 0.5 * (theta_i + theta_o) - alpha;
    gaussian(beta * beta, x)
}

/// d'Eon 2011's longitudinal term for variance `v` without shift, in log space.
///
/// Inputs are inclinations in [−π/2, π/2] (so cosines are ≥ 0). Never overflows: the exponent
/// `(cos(θ_i+θ_o) − 1)/v ≤ 0` is computed as `−2 sin²((θ_i+θ_o)/2)/v`, the Bessel factor as
/// `e^{−a} I₀(a) ≤ 1`, and `ln csch(1/v) = ln 2 − 1/v − ln(1 − e^{−2/v})`.
pub fn deon_longitudinal(v: f64, theta_i: f64, theta_o: f64) -> f64 {
    let cos_i = theta_i.cos().max(0.0);
    let cos_o = theta_o.cos().max(0.0);
    let a = cos_i * cos_o / v;
    let s = (0.5 * (theta_i + theta_o)).sin();
    let exponent = -2.0 * s * s / v;
    let log_m = deon_log_prefactor(v) + exponent + scaled_bessel_i0(a).ln();
    log_m.exp()
}

/// `ln(csch(1/v) / (2v)) + 1/v = −ln v − ln(1 − e^{−2/v})`: the part of ln M that depends on v
/// only (the `−1/v` is folded into the exponent of [`deon_longitudinal`]).
pub fn deon_log_prefactor(v: f64) -> f64 {
    -v.ln() - (-(-2.0 / v).exp_m1()).ln()
}

/// The incidence inclination d'Eon's term is evaluated at for a lobe shifted by α:
/// θ_i − 2α (so the peak sits at θ_o = 2α − θ_i, i.e. θ_h = α as in Marschner), reflected
/// back into [−π/2, π/2] past the poles — the same as pbrt's rotation of sin θ_i with |cos|.
pub fn shifted_incidence(theta_i: f64, alpha: f64) -> f64 {
    let t = theta_i - 2.0 * alpha;
    if t > FRAC_PI_2 {
        PI - t
    } else if t < -FRAC_PI_2 {
        -PI - t
    } else {
        t
    }
}

/// The d'Eon variance whose lobe in θ_o has the width of Marschner's Gaussian of width β in
/// θ_h: a Gaussian of standard deviation β in θ_h = (θ_i+θ_o)/2 has 2β in θ_o, so v = 4β².
pub fn deon_variance_for_marschner_width(beta: f64) -> f64 {
    4.0 * beta * beta
}

/// d'Eon's term put on Marschner's scale, so the two models are interchangeable inside
/// `S = M N / cos²θ_d`: `2 cos θ_d · M_dEon(4β², θ_i − 2α, θ_o)`.
///
/// Why: for small variance d'Eon's term tends to `δ(θ_o + θ_i)/cos θ_o`, Marschner's Gaussian
/// to `δ(θ_h) = 2 δ(θ_o + θ_i)`, and on the cone cos θ_o = cos θ_d. The factor keeps
/// Marschner's overall scale (area 2 in θ_o) while taking d'Eon's shape, which is periodic on
/// the sphere and stays correct near grazing angles.
pub fn deon_on_marschner_scale(beta: f64, alpha: f64, theta_i: f64, theta_o: f64) -> f64 {
    let v = deon_variance_for_marschner_width(beta);
    let cos_d = (0.5 * (theta_o - theta_i)).cos().max(0.0);
    2.0 * cos_d * deon_longitudinal(v, shifted_incidence(theta_i, alpha), theta_o)
}

impl LongitudinalModel {
    /// M_p(θ_i, θ_o) for a lobe of shift `alpha` and width `beta` (radians).
    pub fn eval(self, beta: f64, alpha: f64, theta_i: f64, theta_o: f64) -> f64 {
        match self {
            Self::Gaussian => gaussian_longitudinal(beta, alpha, theta_i, theta_o),
            Self::DEon => deon_on_marschner_scale(beta, alpha, theta_i, theta_o),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::quadrature::GaussLegendre;

    /// ∫ M cos θ_o dθ_o over [−π/2, π/2], with panels fine enough for the narrowest lobe.
    fn deon_area(v: f64, theta_i: f64) -> f64 {
        let sigma = v.sqrt();
        let panels = ((PI / sigma) * 4.0).ceil().clamp(64.0, 40_000.0) as usize;
        let rule = GaussLegendre::composite(8, panels, -FRAC_PI_2, FRAC_PI_2);
        rule.integrate(|t| deon_longitudinal(v, theta_i, t) * t.cos())
    }

    #[test]
    fn deon_integrates_to_one_with_cos_measure() {
        let mut worst: f64 = 0.0;
        for &v in &[1e-6, 7.6e-5, 1e-3, 0.02, 0.3, 1.0, 10.0] {
            for &ti in &[0.0, 0.4, -1.0, 1.4, 1.55, FRAC_PI_2] {
                let area = deon_area(v, ti);
                eprintln!("d'Eon area v={v:e} θ_i={ti:.3}: {area:.12}");
                worst = worst.max((area - 1.0).abs());
                assert!((area - 1.0).abs() < 1e-8, "v={v} θ_i={ti}: {area}");
            }
        }
        eprintln!("d'Eon normalization: max |area − 1| = {worst:e}");
    }

    #[test]
    fn deon_is_finite_for_tiny_variance_and_at_poles() {
        let near = FRAC_PI_2 - 1e-4;
        let angles = [-FRAC_PI_2, -near, -1.0, 0.0, 1e-9, 1.0, near, FRAC_PI_2];
        for &v in &[1e-12, 1e-8, 7.6e-5, 1.0, 1e6] {
            for &ti in &angles {
                for &to in &angles {
                    let m = deon_longitudinal(v, ti, to);
                    assert!(m.is_finite() && m >= 0.0, "v={v} {ti} {to}: {m}");
                    let ms = deon_on_marschner_scale(0.5f64.to_radians(), -0.1, ti, to);
                    assert!(ms.is_finite() && ms >= 0.0);
                }
            }
        }
        // The peak at the poles: θ_i = −π/2, θ_o = π/2 lies on the cone; M = 1/(v(1−e^{−2/v})).
        let v = 7.6e-5;
        let m = deon_longitudinal(v, -FRAC_PI_2, FRAC_PI_2);
        assert!((m * v - 1.0).abs() < 1e-9, "{m}");
    }

    /// For small variance the two models agree: Marschner's g(β, θ_h − α) against d'Eon on
    /// Marschner's scale with v = 4β², over θ_h − α ∈ [−4β, 4β], deviation relative to the
    /// Gaussian's peak. Unshifted, the difference is O(β²) (I₀'s asymptotic 1/(8a), sin θ_h vs
    /// θ_h). Shifted, d'Eon's peak height carries 1/√(cos(θ_i − 2α) cos θ_o) where the
    /// Marschner-scale factor has cos θ_d = cos(θ_i − α): a relative O(|α| tan θ_i) difference.
    #[test]
    fn gaussian_and_deon_agree_for_small_variance() {
        let thetas = [0.0f64, 0.3, -0.7, 1.0];
        let tan_max = 1f64.tan();
        for &beta_deg in &[0.5f64, 1.0, 2.0, 5.0] {
            let beta = beta_deg.to_radians();
            let peak = gaussian(beta * beta, 0.0);
            for alpha in [0.0, -0.5 * beta] {
                let mut worst: f64 = 0.0;
                for &ti in &thetas {
                    for k in -80..=80 {
                        let x = k as f64 * 0.05 * beta;
                        let to = 2.0 * (alpha + x) - ti;
                        let g = gaussian_longitudinal(beta, alpha, ti, to);
                        let d = deon_on_marschner_scale(beta, alpha, ti, to);
                        worst = worst.max((g - d).abs() / peak);
                    }
                }
                let bound = 4.0 * beta * beta + 1.2 * alpha.abs() * tan_max;
                eprintln!(
                    "β={beta_deg}°, α={:.3}°: max |M_gauss − M_dEon| / peak = {worst:.3e} (bound {bound:.3e})",
                    alpha.to_degrees()
                );
                assert!(worst < bound, "β={beta_deg} α={alpha}: {worst}");
            }
        }
    }

    #[test]
    fn shift_moves_the_peak_to_theta_h_equal_alpha() {
        let (beta, alpha) = (2f64.to_radians(), -5f64.to_radians());
        let ti = 0.3;
        // Locate the maximum over θ_o by dense sampling; it must sit at θ_o = 2α − θ_i.
        let (mut best, mut best_to) = (0.0, 0.0);
        for k in 0..=20000 {
            let to = -FRAC_PI_2 + PI * k as f64 / 20000.0;
            let m = deon_on_marschner_scale(beta, alpha, ti, to);
            if m > best {
                best = m;
                best_to = to;
            }
        }
        assert!((best_to - (2.0 * alpha - ti)).abs() < 2e-3, "{best_to}");
    }

    #[test]
    fn model_enum_round_trips_through_json() {
        for m in [LongitudinalModel::Gaussian, LongitudinalModel::DEon] {
            let s = serde_json::to_string(&m).unwrap();
            assert_eq!(serde_json::from_str::<LongitudinalModel>(&s).unwrap(), m);
        }
        assert_eq!(
            serde_json::to_string(&LongitudinalModel::DEon).unwrap(),
            "\"deon\""
        );
    }
}
