//! The SRBF spread table of Ren 2010 §6: the longitudinal variance that an SRBF light of
//! bandwidth λ around ξ brings to the first forward-scattering event, i.e. the second moment
//! of the inclination offset θ(ω) − θ_ξ under the SRBF's angular distribution:
//! `σ²(θ_ξ, λ) = ∫ G(ω; ξ, λ) (θ(ω) − θ_ξ)² dω / ∫ G(ω; ξ, λ) dω`.
//! For ξ in the fiber's normal plane and large λ it tends to 1/λ (G ≈ a Gaussian of variance
//! 1/λ per tangent axis); at the fiber's poles the whole angular distance is an inclination
//! offset and it tends to 2/λ.

use glam::DVec3;
use std::f64::consts::{FRAC_PI_2, PI};
use strandlight_tables::angles::{direction, inclination};
use strandlight_tables::quadrature::GaussLegendre;
use strandlight_tables::srbf::kernel;
use strandlight_tables::table::{Axis, AxisMapping, Table, TableError};
use strandlight_tables::table_axes::{AXIS_ABS_U_DOT_XI, AXIS_LAMBDA};

/// σ² by quadrature in a frame centred on ξ (polar angle γ within G's 1e-12 support).
pub fn srbf_longitudinal_variance(sin_theta_xi: f64, lambda: f64) -> f64 {
    let theta_xi = sin_theta_xi.clamp(-1.0, 1.0).asin();
    let xi = direction(theta_xi, 0.0);
    let helper = if xi.z.abs() < 0.9 { DVec3::Z } else { DVec3::X };
    let t1 = helper.cross(xi).normalize();
    let t2 = xi.cross(t1);
    let gamma_max = (1.0 - (1e12_f64.ln() / lambda).min(2.0)).acos();
    let rule_g = GaussLegendre::composite(8, 24, 0.0, gamma_max);
    let rule_a = GaussLegendre::composite(8, 16, -PI, PI);
    let (mut num, mut den) = (0.0, 0.0);
    for (&g, &wg) in rule_g.nodes.iter().zip(&rule_g.weights) {
        let (sg, cg) = g.sin_cos();
        let w = kernel(cg, lambda) * sg * wg;
        for (&a, &wa) in rule_a.nodes.iter().zip(&rule_a.weights) {
            let wi = xi * cg + (t1 * a.cos() + t2 * a.sin()) * sg;
            let d = inclination(DVec3::Z, wi) - theta_xi;
            num += w * wa * d * d;
            den += w * wa;
        }
    }
    (num / den).clamp(0.0, FRAC_PI_2 * FRAC_PI_2)
}

/// The 2D table over (|u·ξ| ∈ [0, 1], λ ∈ [λ_min, λ_max]); the variance is even in u·ξ.
pub fn srbf_spread_table(
    xi_count: usize,
    lambda_count: usize,
    lambda_min: f64,
    lambda_max: f64,
) -> Result<Table, TableError> {
    let axes = vec![
        // Uniform in θ_ξ: the variance changes fastest near the pole (|u·ξ| → 1).
        Axis::with_mapping(AXIS_ABS_U_DOT_XI, 0.0, 1.0, xi_count, AxisMapping::Arcsine),
        Axis::uniform(AXIS_LAMBDA, lambda_min, lambda_max, lambda_count),
    ];
    Table::from_fn(axes, 1, |x, out| {
        out[0] = srbf_longitudinal_variance(x[0], x[1]) as f32
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn narrow_lobes_in_the_normal_plane_have_variance_one_over_lambda() {
        // G ≈ exp(−λγ²/2): per tangent axis a Gaussian of variance 1/λ, with O(1/λ²) corrections.
        for &lambda in &[64.0, 400.0, 1e4] {
            let v = srbf_longitudinal_variance(0.0, lambda);
            println!("λ={lambda}: σ² = {v:.6e}, 1/λ = {:.6e}", 1.0 / lambda);
            assert!((v * lambda - 1.0).abs() < 3.0 / lambda, "λ={lambda}: {v}");
        }
    }

    #[test]
    fn wide_lobe_at_the_equator_matches_a_one_dimensional_integral() {
        // At θ_ξ = 0 the moment factorizes: ∫∫ e^{λ(cos θ cos φ − 1)} θ² cos θ dθ dφ / (∫∫ …),
        // and the φ integral is 2π e^{−λ} I₀(λ cos θ) — a 1D integral in θ, independent of the
        // ξ-centred 2D quadrature above.
        let lambda: f64 = 16.0;
        let rule = GaussLegendre::composite(8, 64, -FRAC_PI_2, FRAC_PI_2);
        let weight = |t: f64| {
            let k = lambda * t.cos();
            strandlight_tables::special::scaled_bessel_i0(k) * (k - lambda).exp() * t.cos()
        };
        let num = rule.integrate(|t| weight(t) * t * t);
        let den = rule.integrate(weight);
        let v = srbf_longitudinal_variance(0.0, lambda);
        assert!((v - num / den).abs() < 1e-9, "{v} vs {}", num / den);
    }

    #[test]
    fn at_the_fiber_pole_the_offset_is_the_whole_angular_distance() {
        // ξ along the fiber: θ(ω) − θ_ξ = −γ, so σ² = E[γ²] under G, a 1D integral (≈ 2/λ).
        for &lambda in &[16.0f64, 64.0] {
            let rule = GaussLegendre::composite(8, 64, 0.0, PI);
            let w = |g: f64| (lambda * (g.cos() - 1.0)).exp() * g.sin();
            let want = rule.integrate(|g| w(g) * g * g) / rule.integrate(w);
            let got = srbf_longitudinal_variance(1.0, lambda);
            assert!(
                (got - want).abs() < 1e-9 * want,
                "λ={lambda}: {got} vs {want}"
            );
        }
        let t = srbf_spread_table(8, 8, 16.0, 64.0).unwrap();
        assert_eq!(t.stats().nan_count, 0);
    }
}
