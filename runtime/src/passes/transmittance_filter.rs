//! The averaging box of the effective transmittance (Ren 2010 §5): the convolution optical depth
//! map averages the optical depth over a square on the effective occlusion plane (δ/2 in front
//! of the shaded point) whose half-width is R = (δ/2)·s. This file picks the slope s per light.
//! The box is continuous in R: the view pass interpolates between the two nearest texel boxes
//! (`convolution_transmittance.wgsl`).

use strandlight_tables::srbf::support_angle;

use crate::env_light::EnvLight;

/// The largest slope used, for every filter (an SRBF wider than ~89°, λ < ~7, is limited by the
/// box size anyway).
const MAX_SLOPE: f32 = 64.0;

/// How wide the averaging box of an SRBF light is.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TransmittanceFilter {
    /// The paper's R = (δ/2)·tan α with α the SRBF support where G = 10⁻³ (the box reaches the
    /// cone's edge, so its variance is ~2× the G-weighted cone's at λ = 16..64).
    PaperSupport,
    /// The box's per-axis variance R²/3 equals the variance of the G-distributed direction's
    /// transverse component projected at δ/2: R = (δ/2)·√(3σ²), σ² = (coth λ − 1/λ)/λ
    /// (≈ 1/λ, the variance of sin γ cos φ under G exactly). Measured best on the slab test and
    /// on the Fig. 5 comparison (docs/BENCHMARKS.md), hence the default.
    #[default]
    MatchedVariance,
    /// R = 0: the single texel on the SRBF's centre direction (a plain deep opacity map), the
    /// baseline the paper improves on.
    Centre,
}

impl TransmittanceFilter {
    /// s with R = (δ/2)·s for `light`. A directional light's box matches its
    /// [`EnvLight::angular_variance`] under both SRBF filters (0 for a point: one texel).
    pub fn slope(self, light: &EnvLight) -> f32 {
        let Some(lambda) = light.lambda else {
            return match self {
                Self::Centre => 0.0,
                _ => matched_slope(light.angular_variance as f64),
            };
        };
        match self {
            Self::PaperSupport => tan_support(light),
            Self::MatchedVariance => matched_slope(transverse_variance(lambda as f64)),
            Self::Centre => 0.0,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Self::PaperSupport => "paper support (G = 1e-3)",
            Self::MatchedVariance => "matched variance",
            Self::Centre => "centre texel",
        }
    }
}

/// The slope whose box (per-axis variance R²/3) has the variance of directions spread by
/// `variance` per axis, projected at δ/2.
fn matched_slope(variance: f64) -> f32 {
    ((3.0 * variance.max(0.0)).sqrt() as f32).min(MAX_SLOPE)
}

/// tan α of light `light`'s support (G = 10⁻³), 0 for a directional light: the slope of
/// [`TransmittanceFilter::PaperSupport`].
pub fn tan_support(light: &EnvLight) -> f32 {
    match light.lambda {
        None => 0.0,
        Some(lambda) => {
            let alpha = support_angle(lambda as f64);
            if alpha >= std::f64::consts::FRAC_PI_2 {
                MAX_SLOPE
            } else {
                (alpha.tan() as f32).min(MAX_SLOPE)
            }
        }
    }
}

/// Variance of one transverse component (sin γ cos φ) of a direction drawn from the SRBF
/// G(γ) = exp(λ(cos γ − 1)): with μ = cos γ ∝ e^{λμ} on [−1, 1], E\[μ\] = coth λ − 1/λ and
/// E\[sin²γ\] = 2E\[μ\]/λ, halved between the two axes.
pub fn transverse_variance(lambda: f64) -> f64 {
    if lambda < 1e-3 {
        // Nearly uniform: E[sin²γ] = 2/3.
        return 1.0 / 3.0;
    }
    (1.0 / lambda.tanh() - 1.0 / lambda) / lambda
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;
    use strandlight_tables::quadrature::GaussLegendre;

    /// E[sin²γ cos²φ] under G by Gauss–Legendre over μ = cos γ (φ averages cos² to 1/2).
    fn transverse_variance_by_quadrature(lambda: f64) -> f64 {
        let rule = GaussLegendre::composite(16, 400, -1.0, 1.0);
        let g = |x: f64| (lambda * (x - 1.0)).exp();
        rule.integrate(|x| g(x) * (1.0 - x * x) * 0.5) / rule.integrate(g)
    }

    #[test]
    fn transverse_variance_matches_quadrature_and_small_angle_limit() {
        for lambda in [0.5, 4.0, 16.0, 32.0, 64.0, 300.0] {
            let closed = transverse_variance(lambda);
            let quad = transverse_variance_by_quadrature(lambda);
            println!(
                "λ = {lambda}: σ² closed form {closed:.6e}, quadrature {quad:.6e}, 1/λ {:.6e}",
                1.0 / lambda
            );
            assert!(
                (closed - quad).abs() < 1e-9 * quad.max(1e-3),
                "λ = {lambda}"
            );
        }
        assert!((transverse_variance(300.0) * 300.0 - 1.0).abs() < 0.01);
    }

    #[test]
    fn slopes_order_and_directional_lights_read_one_texel() {
        let srbf = EnvLight::srbf(Vec3::Z, 32.0, [1.0; 3]);
        let paper = TransmittanceFilter::PaperSupport.slope(&srbf);
        let matched = TransmittanceFilter::MatchedVariance.slope(&srbf);
        // tan α at λ = 32: 1 − cos α = ln(1000)/32.
        let alpha = (1.0 - (1000f64).ln() / 32.0).acos();
        assert!((paper as f64 - alpha.tan()).abs() < 1e-5, "{paper}");
        assert!((matched as f64 - (3.0 * transverse_variance(32.0)).sqrt()).abs() < 1e-6);
        assert!(matched < paper, "{matched} vs {paper}");
        assert_eq!(TransmittanceFilter::Centre.slope(&srbf), 0.0);
        // An extended source's box has its variance: a 5° panel (σ² = r²/4 for small r).
        let r = 5f32.to_radians();
        let panel = EnvLight::extended(Vec3::Z, [1.0; 3], r * r / 4.0);
        for f in [
            TransmittanceFilter::PaperSupport,
            TransmittanceFilter::MatchedVariance,
        ] {
            let s = f.slope(&panel);
            assert!(
                (s * s / 3.0 - r * r / 4.0).abs() < 1e-6 * r * r,
                "{f:?}: {s}"
            );
        }
        assert_eq!(TransmittanceFilter::Centre.slope(&panel), 0.0);
        let directional = EnvLight::directional(Vec3::Z, [1.0; 3]);
        for f in [
            TransmittanceFilter::PaperSupport,
            TransmittanceFilter::MatchedVariance,
            TransmittanceFilter::Centre,
        ] {
            assert_eq!(f.slope(&directional), 0.0);
        }
    }
}
