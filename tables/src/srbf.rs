//! Spherical radial basis functions (Ren 2010 §3.1; Tsai & Shih 2006):
//! `G(ω; ξ, λ) = exp(λ(ω·ξ − 1))`, the paper's `e^{−λ} e^{λ ω·ξ}` written so it never overflows.

use glam::DVec3;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Ren 2010 §5: an SRBF is treated as zero where it falls below this value.
pub const SUPPORT_THRESHOLD: f64 = 1e-3;

/// One SRBF light: a lobe of bandwidth `lambda` around unit `center`, scaled per RGB channel.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SrbfLobe {
    pub center: [f64; 3],
    pub lambda: f64,
    pub amplitude: [f64; 3],
}

impl SrbfLobe {
    pub fn center(&self) -> DVec3 {
        DVec3::from_array(self.center)
    }

    /// Radiance this lobe sends from direction `w` (unit), per channel.
    pub fn radiance(&self, w: DVec3) -> [f64; 3] {
        let g = kernel(w.dot(self.center()), self.lambda);
        self.amplitude.map(|a| a * g)
    }
}

/// G as a function of cos γ = ω·ξ.
#[inline]
pub fn kernel(cos_gamma: f64, lambda: f64) -> f64 {
    (lambda * (cos_gamma.clamp(-1.0, 1.0) - 1.0)).exp()
}

/// ∫_{S²} G dω = 2π/λ · (1 − e^{−2λ}), via expm1 so small λ keeps its precision.
pub fn integral(lambda: f64) -> f64 {
    -2.0 * PI * (-2.0 * lambda).exp_m1() / lambda
}

/// ∫_{S²} G² dω: the squared norm of one lobe (G² is an SRBF of bandwidth 2λ).
pub fn squared_norm(lambda: f64) -> f64 {
    integral(2.0 * lambda)
}

/// ∫ G(ω; ξ₁, λ₁) G(ω; ξ₂, λ₂) dω in closed form: the product of two SRBFs is an SRBF of
/// bandwidth ‖λ₁ξ₁ + λ₂ξ₂‖ times a constant. Written in log space so λ up to 10⁴ is safe.
pub fn inner_product(xi1: DVec3, lambda1: f64, xi2: DVec3, lambda2: f64) -> f64 {
    let m = (xi1 * lambda1 + xi2 * lambda2).length();
    if m < 1e-300 {
        // Opposite lobes of equal width: the product is the constant e^{−2λ}.
        return 4.0 * PI * (-(lambda1 + lambda2)).exp();
    }
    // ∫ exp(m(ω·ξ) − λ₁ − λ₂) dω = e^{m − λ₁ − λ₂} · 2π/m · (1 − e^{−2m}).
    (m - lambda1 - lambda2).exp() * integral(m)
}

/// 1 − cos α of the angular support α, where G = [`SUPPORT_THRESHOLD`] (Ren 2010 eq. 11):
/// `ln(1000)/λ`, capped at 2 (the whole sphere) for very wide lobes.
pub fn support_one_minus_cos(lambda: f64) -> f64 {
    (-(SUPPORT_THRESHOLD.ln()) / lambda).min(2.0)
}

/// Angular support α in radians.
pub fn support_angle(lambda: f64) -> f64 {
    let omc = support_one_minus_cos(lambda);
    // acos(1 − x) = 2 asin(√(x/2)): accurate for the tiny x of narrow lobes.
    2.0 * (0.5 * omc).sqrt().min(1.0).asin()
}

/// cos γ of a direction drawn with density ∝ G, from a uniform `u` ∈ [0, 1):
/// inverts the CDF `(1 − e^{−λ(1−cos γ)}) / (1 − e^{−2λ})` without cancellation.
pub fn sample_cos_gamma(lambda: f64, u: f64) -> f64 {
    let one_minus_cos = -(u * (-2.0 * lambda).exp_m1()).ln_1p() / lambda;
    (1.0 - one_minus_cos).clamp(-1.0, 1.0)
}

/// In the fiber frame, with ω = (θ, φ) and ξ = (θ_ξ, φ_ξ),
/// `ω·ξ = sin θ sin θ_ξ + cos θ cos θ_ξ cos(φ − φ_ξ)`, so G separates into a longitudinal factor
/// and a von Mises kernel in φ − φ_ξ with this concentration. Tabulation exploits that split.
pub fn azimuthal_concentration(lambda: f64, theta: f64, theta_xi: f64) -> f64 {
    lambda * theta.cos() * theta_xi.cos()
}

/// The longitudinal factor `exp(λ(sin θ sin θ_ξ − 1))` that multiplies the von Mises kernel
/// `exp(κ cos(φ − φ_ξ))`; their product is G.
pub fn longitudinal_factor(lambda: f64, theta: f64, theta_xi: f64) -> f64 {
    (lambda * (theta.sin() * theta_xi.sin() - 1.0)).exp()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::angles::direction;
    use crate::quadrature::integrate_sphere;

    fn lobe_integral_by_quadrature(lambda: f64, xi: DVec3) -> f64 {
        // Panels scale with the lobe width so narrow lobes are resolved.
        let panels = ((lambda.sqrt() * 4.0) as usize).clamp(8, 800);
        integrate_sphere(panels, panels, |t, p| {
            kernel(direction(t, p).dot(xi), lambda)
        })
    }

    #[test]
    fn closed_form_integral_matches_quadrature() {
        let xi = direction(0.4, 1.1);
        for &lambda in &[0.01, 1.0, 16.0, 64.0, 1000.0] {
            let q = lobe_integral_by_quadrature(lambda, xi);
            let c = integral(lambda);
            assert!((q - c).abs() < 1e-9 * c, "λ={lambda}: {q} vs {c}");
        }
    }

    #[test]
    fn inner_product_matches_quadrature() {
        let (a, b) = (direction(0.2, 0.3), direction(-0.1, 0.9));
        let q = integrate_sphere(60, 60, |t, p| {
            let w = direction(t, p);
            kernel(w.dot(a), 20.0) * kernel(w.dot(b), 45.0)
        });
        let c = inner_product(a, 20.0, b, 45.0);
        assert!((q - c).abs() < 1e-9 * c, "{q} vs {c}");
        assert!((inner_product(a, 30.0, a, 30.0) - squared_norm(30.0)).abs() < 1e-12);
    }

    #[test]
    fn huge_bandwidth_stays_finite() {
        assert!((integral(1e4) - 2.0 * PI / 1e4).abs() < 1e-15);
        assert!(inner_product(DVec3::Z, 1e4, DVec3::X, 1e4).is_finite());
        assert_eq!(kernel(1.0, 1e4), 1.0);
        assert!(sample_cos_gamma(1e4, 0.999_999).is_finite());
    }

    #[test]
    fn support_is_where_the_kernel_reaches_the_threshold() {
        for &lambda in &[16.0, 64.0, 1e4] {
            let g = kernel(support_angle(lambda).cos(), lambda);
            assert!((g - SUPPORT_THRESHOLD).abs() < 1e-9, "λ={lambda}: {g}");
        }
        assert!((support_angle(1.0) - PI).abs() < 1e-12);
    }

    #[test]
    fn sampling_inverts_the_cdf() {
        let lambda = 40.0;
        for i in 1..10 {
            let u = i as f64 / 10.0;
            let c = sample_cos_gamma(lambda, u);
            let cdf = (-lambda * (1.0 - c)).exp_m1() / (-2.0 * lambda).exp_m1();
            assert!((cdf - u).abs() < 1e-12);
        }
    }

    #[test]
    fn separable_form_equals_kernel() {
        let (t, p, txi, pxi, lambda) = (0.3, 2.0, -0.7, -1.0, 33.0);
        let direct = kernel(direction(t, p).dot(direction(txi, pxi)), lambda);
        let split = longitudinal_factor(lambda, t, txi)
            * (azimuthal_concentration(lambda, t, txi) * (p - pxi).cos()).exp();
        assert!((direct - split).abs() < 1e-14);
    }
}
