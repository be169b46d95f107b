//! The multiple-scattering table I_G(u·ξ, u·ω_o, cos(φ_ξ − φ_o), σ̄_f) of Ren 2010 eq. 11: the
//! convolution of the forward-scattering spread function ψ_f with the BCSDF S^D = S + d_b·S_back.
//!
//! ψ_f(ξ, ω_i, σ̄_f) = s̄_f(φ_i − φ_ξ) · g(θ_i − θ_ξ, σ̄_f²) / N: 1/π on the half of the azimuths
//! facing ξ (the forward-scattered light still travels roughly along −ξ), and a unit Gaussian in
//! inclination. The paper normalizes with N = cos θ_ξ, which is the small-σ̄_f limit of
//! N = ∫ g(θ − θ_ξ, σ̄_f²) cos θ dθ, the value that makes ψ_f integrate to one over the sphere; we
//! use the latter, which stays finite for ξ along the fiber (u·ξ = ±1).
//!
//! The azimuthal box does not depend on θ_i, so
//! `I_G = ∫ g(θ_i − θ_ξ, σ̄_f²) H(θ_i; θ_o, Δ) dθ_i / N` with `H = cos²θ_i Σ εₙ aₙ(θ_i, θ_o) Kₙ cos nΔ`,
//! where aₙ is S^D's cosine series in φ and Kₙ = ∫ s̄_f(ψ) cos nψ dψ = sinc-like box harmonics.
//! H is computed once on a fine uniform θ_i grid and integrated against the Gaussian with
//! product-integration weights that are exact for piecewise-linear H — so σ̄_f → 0 gives H's
//! interpolant at θ_ξ instead of an unresolved spike.

use crate::convolution::cosine_coefficients_many;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::f64::consts::{FRAC_PI_2, PI};
use strandlight_tables::angles::FiberAngles;
use strandlight_tables::scattering::Rgb;
use strandlight_tables::table::{Axis, Table, TableError};
use strandlight_tables::table_axes::AXIS_SIGMA_F;

#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MultipleScatteringResolution {
    pub u_dot_xi: usize,
    pub u_dot_wo: usize,
    pub cos_dphi: usize,
    pub sigma_f: usize,
    /// Largest forward-scattering spread tabulated (radians); lookups beyond clamp to it.
    pub sigma_f_max: f64,
    pub axes: crate::convolution_table::DirectionAxes,
    /// Nodes of the uniform θ_i grid on which H is sampled.
    pub theta_nodes: usize,
    /// Gauss–Legendre panels over φ ∈ [0, π] for the cosine series, and harmonics kept.
    pub phi_panels: usize,
    pub harmonics: usize,
}

impl Default for MultipleScatteringResolution {
    fn default() -> Self {
        Self {
            u_dot_xi: 32,
            u_dot_wo: 32,
            cos_dphi: 32,
            sigma_f: 64,
            sigma_f_max: 1.0,
            axes: Default::default(),
            theta_nodes: 1025,
            phi_panels: 32,
            harmonics: 127,
        }
    }
}

impl MultipleScatteringResolution {
    pub fn axes(&self) -> Vec<Axis> {
        let [xi, wo, cos_dphi] = self.axes.build(self.u_dot_xi, self.u_dot_wo, self.cos_dphi);
        vec![
            xi,
            wo,
            cos_dphi,
            Axis::uniform(AXIS_SIGMA_F, 0.0, self.sigma_f_max, self.sigma_f),
        ]
    }
}

/// Kₙ = ∫ s̄_f(ψ) cos nψ dψ for the box s̄_f = 1/π on |ψ| < π/2: 1 for n = 0, else
/// 2 sin(nπ/2)/(nπ).
fn box_harmonic(n: usize) -> f64 {
    if n == 0 {
        1.0
    } else {
        2.0 * (n as f64 * FRAC_PI_2).sin() / (n as f64 * PI)
    }
}

/// ∫ g(θ − μ, σ²) ℓ(θ) dθ over [a, b] for the two linear pieces ℓ = (b − θ)/(b − a) and
/// (θ − a)/(b − a): the product-integration weights of one grid cell. σ = 0 gives the hat
/// functions' values at μ.
fn cell_weights(a: f64, b: f64, mu: f64, sigma: f64) -> (f64, f64) {
    let h = b - a;
    if sigma <= 0.0 {
        if mu < a || mu > b {
            return (0.0, 0.0);
        }
        // Half weight on each side of a shared node, so a node is not counted twice.
        let t = (mu - a) / h;
        let edge = if mu == a || mu == b { 0.5 } else { 1.0 };
        return (edge * (1.0 - t), edge * t);
    }
    let s2 = std::f64::consts::SQRT_2 * sigma;
    let (za, zb) = ((a - mu) / s2, (b - mu) / s2);
    let mass = 0.5 * (libm::erf(zb) - libm::erf(za));
    // ∫ g(θ−μ) (θ − μ) dθ = σ²(g(a−μ) − g(b−μ)).
    let g = |x: f64| (-(x * x) / (2.0 * sigma * sigma)).exp() / ((2.0 * PI).sqrt() * sigma);
    let first = sigma * sigma * (g(a - mu) - g(b - mu));
    let mean_offset = first + (mu - a) * mass; // ∫ g (θ − a)
    let w_b = mean_offset / h;
    (mass - w_b, w_b)
}

/// Product-integration weights of the Gaussian g(θ − μ, σ²) on the uniform grid `nodes`.
fn gaussian_weights(nodes: &[f64], mu: f64, sigma: f64) -> Vec<f64> {
    let mut w = vec![0.0; nodes.len()];
    for j in 0..nodes.len() - 1 {
        let (wa, wb) = cell_weights(nodes[j], nodes[j + 1], mu, sigma);
        w[j] += wa;
        w[j + 1] += wb;
    }
    w
}

/// Tabulates I_G for the BCSDF `s_d` (S + d_b·S_back, per RGB channel).
pub fn bake_multiple_scattering_table<F>(
    s_d: &F,
    res: &MultipleScatteringResolution,
) -> Result<Table, TableError>
where
    F: Fn(&FiberAngles) -> Rgb + Sync,
{
    let axes = res.axes();
    let nodes = |a: &Axis| (0..a.count).map(|i| a.node(i)).collect::<Vec<f64>>();
    let (xis, wos, cds, sigmas) = (
        nodes(&axes[0]),
        nodes(&axes[1]),
        nodes(&axes[2]),
        nodes(&axes[3]),
    );
    let theta: Vec<f64> = (0..res.theta_nodes)
        .map(|j| -FRAC_PI_2 + PI * j as f64 / (res.theta_nodes - 1) as f64)
        .collect();
    let box_k: Vec<f64> = (0..=res.harmonics)
        .map(|n| box_harmonic(n) * if n == 0 { 0.5 } else { 1.0 })
        .collect();
    let cos_n_delta: Vec<Vec<f64>> = cds
        .iter()
        .map(|&c| {
            let d = c.clamp(-1.0, 1.0).acos();
            (0..=res.harmonics).map(|n| (n as f64 * d).cos()).collect()
        })
        .collect();

    // h[o][d][j] = H(θ_j; θ_o, Δ_d) per channel.
    let h: Vec<Vec<Vec<Rgb>>> = wos
        .par_iter()
        .map(|&so| {
            let theta_o = so.clamp(-1.0, 1.0).asin();
            let spectra: Vec<Vec<Rgb>> = theta
                .iter()
                .map(|&ti| {
                    cosine_coefficients_many(s_d, ti, theta_o, res.phi_panels, res.harmonics)
                })
                .collect();
            cos_n_delta
                .iter()
                .map(|cn| {
                    theta
                        .iter()
                        .zip(&spectra)
                        .map(|(&ti, a)| {
                            let mut v = [0.0; 3];
                            for n in 0..=res.harmonics {
                                let f = box_k[n] * cn[n];
                                for c in 0..3 {
                                    v[c] += f * a[n][c];
                                }
                            }
                            let c2 = ti.cos().powi(2);
                            v.map(|x| x * c2)
                        })
                        .collect()
                })
                .collect()
        })
        .collect();

    let (n_o, n_d, n_s) = (wos.len(), cds.len(), sigmas.len());
    // H as a matrix: rows θ_j, columns (o, d, c). For each ξ, all σ̄_f at once are one matrix
    // product W·H (W: σ̄_f × θ_j weights), which streams H through the cache once per ξ
    // instead of once per (ξ, σ̄_f).
    let n_j = theta.len();
    let h_matrix = nalgebra::DMatrix::from_fn(n_j, n_o * n_d * 3, |j, col| {
        let (od, c) = (col / 3, col % 3);
        h[od / n_d][od % n_d][j][c]
    });
    let mut values = vec![0f32; xis.len() * n_o * n_d * n_s * 3];
    values
        .par_chunks_mut(n_o * n_d * n_s * 3)
        .zip(&xis)
        .for_each(|(chunk, &sx)| {
            let theta_xi = sx.clamp(-1.0, 1.0).asin();
            let mut w = nalgebra::DMatrix::<f64>::zeros(n_s, n_j);
            let mut inv_norm = vec![0.0; n_s];
            for (k, &sigma) in sigmas.iter().enumerate() {
                let weights = gaussian_weights(&theta, theta_xi, sigma);
                let norm: f64 = weights.iter().zip(&theta).map(|(w, t)| w * t.cos()).sum();
                // Exactly along the fiber with σ̄_f = 0 no light reaches the fiber's cross-section.
                inv_norm[k] = if norm > 1e-12 { 1.0 / norm } else { 0.0 };
                for (j, wj) in weights.into_iter().enumerate() {
                    w[(k, j)] = wj;
                }
            }
            let product = w * &h_matrix; // n_s × (o, d, c)
            for k in 0..n_s {
                for od in 0..n_o * n_d {
                    for c in 0..3 {
                        chunk[(od * n_s + k) * 3 + c] =
                            (product[(k, od * 3 + c)] * inv_norm[k]) as f32;
                    }
                }
            }
        });
    Table::new(axes, 3, values)
}

/// Brute-force reference of eq. 11: 2D quadrature over θ_i (fine composite Gauss–Legendre
/// around θ_ξ) and φ_i over the forward half only, with the same normalization N.
pub fn multiple_scattering_reference<F>(
    s_d: &F,
    theta_xi: f64,
    theta_o: f64,
    delta: f64,
    sigma: f64,
    panels: usize,
) -> Rgb
where
    F: Fn(&FiberAngles) -> Rgb,
{
    use strandlight_tables::quadrature::GaussLegendre;
    let (lo, hi) = (
        (theta_xi - 9.0 * sigma).max(-FRAC_PI_2),
        (theta_xi + 9.0 * sigma).min(FRAC_PI_2),
    );
    let rule_t = GaussLegendre::composite(8, panels, lo, hi);
    let rule_p = GaussLegendre::composite(8, panels, -FRAC_PI_2, FRAC_PI_2);
    let g = |x: f64| (-(x * x) / (2.0 * sigma * sigma)).exp() / ((2.0 * PI).sqrt() * sigma);
    let norm: f64 = rule_t.integrate(|t| g(t - theta_xi) * t.cos());
    let mut acc = [0.0; 3];
    for (&t, &wt) in rule_t.nodes.iter().zip(&rule_t.weights) {
        let radial = wt * g(t - theta_xi) * t.cos() * t.cos() / PI;
        for (&psi, &wp) in rule_p.nodes.iter().zip(&rule_p.weights) {
            // φ_i = φ_ξ + ψ with φ_ξ = 0; φ = φ_o − φ_i = Δ − ψ.
            let v = s_d(&FiberAngles::new(t, theta_o, delta - psi));
            for c in 0..3 {
                acc[c] += radial * wp * v[c];
            }
        }
    }
    acc.map(|v| v / norm)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bcsdf(a: &FiberAngles) -> Rgb {
        let m = (-(a.theta_h() - 0.08).powi(2) / (2.0 * 0.12f64.powi(2))).exp();
        let n_r = (a.phi / 2.0).cos().abs();
        let n_tt = (-(PI - a.phi.abs()).powi(2) / (2.0 * 0.4f64.powi(2))).exp();
        let d = a.theta_d().cos().powi(2) + 0.05;
        [m * n_r / d, m * (0.3 * n_r + n_tt) / d, 0.2 + m * n_tt / d]
    }

    #[test]
    fn product_weights_integrate_linear_functions_exactly() {
        let nodes: Vec<f64> = (0..41).map(|j| -1.0 + j as f64 * 0.05).collect();
        for &(mu, sigma) in &[(0.1, 0.14), (-0.33, 0.01), (0.4, 0.0), (0.0, 1e-9)] {
            let w = gaussian_weights(&nodes, mu, sigma);
            // ∫ g (2 + 3θ) dθ over ℝ = 2 + 3μ; the mass beyond ±1 is < 1e-10 here (≥ 6σ away).
            let got: f64 = w.iter().zip(&nodes).map(|(w, t)| w * (2.0 + 3.0 * t)).sum();
            assert!(
                (got - (2.0 + 3.0 * mu)).abs() < 1e-9,
                "μ={mu} σ={sigma}: {got}"
            );
        }
    }

    #[test]
    fn table_nodes_match_the_brute_force_integral() {
        let res = MultipleScatteringResolution {
            u_dot_xi: 5,
            u_dot_wo: 4,
            cos_dphi: 5,
            sigma_f: 4,
            theta_nodes: 2049,
            ..Default::default()
        };
        let table = bake_multiple_scattering_table(&bcsdf, &res).unwrap();
        let axes = res.axes();
        let mut worst: f64 = 0.0;
        let peak = table.stats().max as f64;
        for i in [1usize, 2, 3] {
            for o in [0usize, 2] {
                for d in [0usize, 2, 4] {
                    for k in [1usize, 3] {
                        let x = [
                            axes[0].node(i),
                            axes[1].node(o),
                            axes[2].node(d),
                            axes[3].node(k),
                        ];
                        let r = multiple_scattering_reference(
                            &bcsdf,
                            x[0].asin(),
                            x[1].asin(),
                            x[2].acos(),
                            x[3],
                            24,
                        );
                        let t = table.lookup_rgb(&x).unwrap();
                        for c in 0..3 {
                            worst = worst.max((t[c] as f64 - r[c]).abs());
                        }
                    }
                }
            }
        }
        println!(
            "I_G at nodes vs brute force: max |Δ| = {:.3e} of the table maximum",
            worst / peak
        );
        // Residual (measured 2e-7): the piecewise-linear H (h = π/2048) and the 127 box
        // harmonics of a function with a kink at φ = π (aₙ ~ 1/n², Kₙ ~ 1/n).
        assert!(worst < 1e-5 * peak, "{worst} of {peak}");
    }

    #[test]
    fn vanishing_spread_is_finite_and_continuous() {
        let res = MultipleScatteringResolution {
            u_dot_xi: 9,
            u_dot_wo: 3,
            cos_dphi: 3,
            sigma_f: 9,
            sigma_f_max: 0.08,
            ..Default::default()
        };
        let table = bake_multiple_scattering_table(&bcsdf, &res).unwrap();
        let s = table.stats();
        assert_eq!(s.nan_count + s.infinite_count, 0);
        // σ̄_f = 0 and the next node (0.01 rad) differ by little: the spike is resolved.
        let x0 = table.lookup_rgb(&[0.3, 0.0, -1.0, 0.0]).unwrap();
        let x1 = table.lookup_rgb(&[0.3, 0.0, -1.0, 0.01]).unwrap();
        for c in 0..3 {
            assert!(
                (x0[c] - x1[c]).abs() < 0.02 * x0[c].abs().max(1e-3),
                "{x0:?} vs {x1:?}"
            );
        }
    }
}
