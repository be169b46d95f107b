//! The attenuation ratio α(ν, θ) of Ren 2010 §6: how much more or less a voxel of fibers with
//! mean direction ū and direction deviation ν attenuates light arriving at inclination θ than
//! its perpendicular attenuation σ_t⊥.
//!
//! A fiber with direction t shadows light travelling along ω with a cross-section ∝ |t × ω| =
//! √(1 − (t·ω)²), so σ_t(ω) = σ_t⊥ · E_t[√(1 − (t·ω)²)]. We model the fiber directions as a
//! Gaussian around ū: t is ū moved along a tangent-plane offset (x, y), x, y ~ N(0, ν²), through
//! the exponential map of the sphere. Then α(ν, θ) = E[√(1 − (t·ω)²)] with ū·ω = sin θ;
//! α(0, θ) = cos θ exactly.

use std::f64::consts::PI;
use strandlight_tables::quadrature::GaussLegendre;
use strandlight_tables::table::{Axis, AxisMapping, Table, TableError};
use strandlight_tables::table_axes::{AXIS_ABS_SIN_THETA, AXIS_NU};

/// α(ν, θ) by quadrature over the offset's polar radius r (Rayleigh density) and angle ψ.
pub fn attenuation_ratio(nu: f64, sin_theta: f64) -> f64 {
    let s = sin_theta.clamp(-1.0, 1.0);
    let c = (1.0 - s * s).sqrt();
    if nu <= 1e-9 {
        return c;
    }
    // r beyond 8ν carries < e^{-32} of the mass; beyond π the exponential map wraps.
    let r_max = (8.0 * nu).min(PI);
    let rule_r = GaussLegendre::composite(8, 16, 0.0, r_max);
    let rule_psi = GaussLegendre::composite(8, 8, 0.0, PI); // symmetric in ψ → [0, π]
    let mut num = 0.0;
    let mut den = 0.0;
    for (&r, &wr) in rule_r.nodes.iter().zip(&rule_r.weights) {
        let density = r / (nu * nu) * (-0.5 * r * r / (nu * nu)).exp() * wr;
        let (sr, cr) = r.sin_cos();
        for (&psi, &wp) in rule_psi.nodes.iter().zip(&rule_psi.weights) {
            let t_dot_w = c * sr * psi.cos() + s * cr;
            num += density * wp * (1.0 - t_dot_w * t_dot_w).max(0.0).sqrt();
            den += density * wp;
        }
    }
    num / den
}

/// The 2D table over (ν ∈ [0, ν_max], |sin θ| ∈ [0, 1]); α is even in θ.
pub fn attenuation_ratio_table(
    nu_count: usize,
    sin_count: usize,
    nu_max: f64,
) -> Result<Table, TableError> {
    // Uniform in θ: α = cos θ for aligned fibers has an infinite slope in sin θ at the pole.
    let axes = vec![
        Axis::uniform(AXIS_NU, 0.0, nu_max, nu_count),
        Axis::with_mapping(
            AXIS_ABS_SIN_THETA,
            0.0,
            1.0,
            sin_count,
            AxisMapping::Arcsine,
        ),
    ];
    Table::from_fn(axes, 1, |x, out| {
        out[0] = attenuation_ratio(x[0], x[1]) as f32
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn aligned_fibers_give_the_cosine() {
        for &s in &[0.0, 0.3, 0.9, 1.0] {
            assert!((attenuation_ratio(0.0, s) - (1.0 - s * s).sqrt()).abs() < 1e-15);
            // A tiny deviation is a tiny perturbation.
            assert!((attenuation_ratio(1e-4, s) - (1.0 - s * s).sqrt()).abs() < 2e-4);
        }
    }

    #[test]
    fn matches_monte_carlo_of_the_same_fiber_distribution() {
        // Independent estimate: sample offsets with Box–Muller and map them to directions.
        let mut state = 0x1234_5678_9abc_def0u64;
        let mut unit = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for &(nu, s) in &[(0.3, 0.0), (0.5, 0.7), (0.8, 1.0)] {
            let c = (1.0f64 - s * s).sqrt();
            let n = 400_000;
            let mut sum = 0.0;
            for _ in 0..n {
                let (u1, u2): (f64, f64) = (unit().max(1e-300), unit());
                let rad = (-2.0 * u1.ln()).sqrt();
                let (x, y) = (
                    nu * rad * (2.0 * PI * u2).cos(),
                    nu * rad * (2.0 * PI * u2).sin(),
                );
                let r = (x * x + y * y).sqrt();
                let (sr, cr) = r.sin_cos();
                let t = if r > 0.0 {
                    [sr * x / r, sr * y / r, cr]
                } else {
                    [0.0, 0.0, 1.0]
                };
                let d = t[0] * c + t[2] * s;
                sum += (1.0 - d * d).max(0.0).sqrt();
            }
            let mc = sum / n as f64;
            let q = attenuation_ratio(nu, s);
            println!("α(ν={nu}, sin θ={s}): quadrature {q:.5}, Monte Carlo {mc:.5}");
            assert!((q - mc).abs() < 3e-3, "{q} vs {mc}");
        }
    }

    #[test]
    fn light_along_a_disordered_voxel_is_still_attenuated() {
        // Aligned fibers are invisible along their own direction; disorder makes them visible.
        assert_eq!(attenuation_ratio(0.0, 1.0), 0.0);
        assert!(attenuation_ratio(0.5, 1.0) > 0.3);
        let t = attenuation_ratio_table(16, 16, 1.0).unwrap();
        assert_eq!(t.stats().nan_count, 0);
    }
}
