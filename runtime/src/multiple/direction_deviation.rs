//! The direction deviation ν of a voxel's fibers, in the meaning the `attenuation_ratio` table
//! gives it: fiber directions t are the mean direction ū moved by a tangent-plane offset
//! (x, y) with x, y ~ N(0, ν²), through the sphere's exponential map (so the angle r between t
//! and ū has the Rayleigh density r/ν² e^{−r²/2ν²}, cut at min(8ν, π) as that table does).
//!
//! The voxelization measures the length-weighted structure tensor M = E[t tᵀ]; its largest
//! eigenvalue is E[(t·ū)²] = E[cos² r], so `1 − λ_max = E[sin² r] =: f(ν)`. f is computed once
//! by quadrature on a ν grid and inverted by bisection on that grid (f is increasing there; the
//! grid stops at the first maximum). For small ν, f(ν) ≈ 2ν². A voxel more disordered than the
//! largest tabulated ν clamps to it (the α table clamps there anyway).

use strandlight_tables::quadrature::GaussLegendre;

/// f(ν) = E[sin² r] under the cut Rayleigh density of the attenuation-ratio model.
pub fn mean_sin2_offset(nu: f64) -> f64 {
    if nu <= 1e-9 {
        return 0.0;
    }
    let r_max = (8.0 * nu).min(std::f64::consts::PI);
    let rule = GaussLegendre::composite(8, 16, 0.0, r_max);
    let density = |r: f64| r * (-0.5 * r * r / (nu * nu)).exp();
    let den = rule.integrate(density);
    rule.integrate(|r| density(r) * r.sin().powi(2)) / den
}

/// f tabulated on [0, ν_max] for inversion.
#[derive(Clone, Debug)]
pub struct DirectionDeviation {
    nus: Vec<f64>,
    f: Vec<f64>,
}

impl DirectionDeviation {
    /// Tabulates f on `nodes` points of [0, ν_max] (ν_max > 0), cut at f's first maximum.
    pub fn new(nu_max: f64, nodes: usize) -> Self {
        let nu_max = if nu_max.is_finite() && nu_max > 0.0 {
            nu_max
        } else {
            1.0
        };
        let n = nodes.max(3);
        let mut nus = Vec::with_capacity(n);
        let mut f: Vec<f64> = Vec::with_capacity(n);
        for k in 0..n {
            let nu = nu_max * k as f64 / (n - 1) as f64;
            let v = mean_sin2_offset(nu);
            if let Some(&last) = f.last()
                && v <= last
            {
                break;
            }
            nus.push(nu);
            f.push(v);
        }
        Self { nus, f }
    }

    /// ν with f(ν) = `mean_sin2` (piecewise-linear inverse; clamped to [0, ν_max]).
    pub fn nu_from_mean_sin2(&self, mean_sin2: f64) -> f64 {
        let y = if mean_sin2.is_nan() { 0.0 } else { mean_sin2 };
        let last = self.f.len() - 1;
        if y <= 0.0 {
            return 0.0;
        }
        if y >= self.f[last] {
            return self.nus[last];
        }
        let i = self.f.partition_point(|&v| v <= y).clamp(1, last);
        let (f0, f1) = (self.f[i - 1], self.f[i]);
        let t = (y - f0) / (f1 - f0);
        self.nus[i - 1] + t * (self.nus[i] - self.nus[i - 1])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn small_deviation_follows_the_two_dimensional_gaussian() {
        // For small ν, sin² r ≈ r² and E[r²] = 2ν² (two tangent axes of variance ν²).
        for &nu in &[0.01, 0.05] {
            let f = mean_sin2_offset(nu);
            println!("ν={nu}: f={f:.6e}, 2ν²={:.6e}", 2.0 * nu * nu);
            assert!((f / (2.0 * nu * nu) - 1.0).abs() < 2.0 * nu * nu + 1e-9);
        }
    }

    #[test]
    fn inversion_recovers_nu() {
        let d = DirectionDeviation::new(1.0, 257);
        for &nu in &[0.0, 0.02, 0.2, 0.5, 0.9] {
            let back = d.nu_from_mean_sin2(mean_sin2_offset(nu));
            println!("ν={nu}: recovered {back:.5}");
            assert!((back - nu).abs() < 2e-3, "{nu} → {back}");
        }
        // Isotropic fibers (E[sin² r] = 2/3) are beyond the model: clamped to the largest ν.
        assert!(d.nu_from_mean_sin2(2.0 / 3.0) > 0.9);
        assert_eq!(d.nu_from_mean_sin2(f64::NAN), 0.0);
    }
}
