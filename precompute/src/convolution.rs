//! The SRBF–fiber convolution `I(ω_o; ξ, λ) = ∫ G(ω_i; ξ, λ) S(ω_i, ω_o) cos θ_i dω_i`
//! (Ren 2010 eq. 8), evaluated for whole grids of (θ_ξ, θ_o, φ_o − φ_ξ, λ) at once.
//!
//! Why this is fast: in the fiber frame `G = e^{λ(cos(θ_i−θ_ξ)−1)} · e^{−κ} e^{κ cos(φ_i−φ_ξ)}`
//! with `κ = λ cos θ_i cos θ_ξ`, so the azimuthal integral is a circular convolution of S with a
//! von Mises kernel. Writing S(θ_i, θ_o, φ) = a₀/2 + Σ aₙ cos nφ (S is even in φ for round
//! fibers), the kernel's Fourier coefficients are the scaled Bessel functions Ĩₙ(κ) = e^{−κ}Iₙ(κ):
//!
//! `I = 2π ∫ cos²θ_i e^{λ(cos(θ_i−θ_ξ)−1)} Σₙ εₙ aₙ(θ_i, θ_o) Ĩₙ(κ) cos(nΔ) dθ_i`,  Δ = φ_o − φ_ξ,
//!
//! with ε₀ = ½, εₙ = 1. Ĩₙ(κ) decays like e^{−n²/2κ}, so a few dozen harmonics suffice for the
//! λ ≤ 64 of the paper; every grid entry is then a short 1D sum, and the spectra aₙ are shared
//! by every (ξ, λ, Δ). No exponential here can overflow: every exponent is ≤ 0.

use rayon::prelude::*;
use std::f64::consts::{FRAC_PI_2, PI};
use strandlight_tables::angles::FiberAngles;
use strandlight_tables::quadrature::GaussLegendre;
use strandlight_tables::scattering::Rgb;

/// Accuracy knobs of [`convolve_grid`]; the defaults keep the quadrature error far below
/// the interpolation error of a 32×32×32×64 table (measured by the tests and `check-tables`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ConvolutionSettings {
    /// 8-point Gauss–Legendre panels over θ_i ∈ [−π/2, π/2].
    pub theta_panels: usize,
    /// 8-point Gauss–Legendre panels over φ ∈ [0, π] for the cosine series of S.
    pub phi_panels: usize,
    /// Harmonics kept; `None` picks enough for the largest λ of the grid.
    pub max_harmonic: Option<usize>,
}

impl Default for ConvolutionSettings {
    fn default() -> Self {
        Self {
            theta_panels: 96,
            phi_panels: 32,
            max_harmonic: None,
        }
    }
}

/// The grid of a convolution table, in the table's own coordinates.
#[derive(Debug, Clone, PartialEq)]
pub struct ConvolutionGrid {
    /// u·ξ = sin θ_ξ.
    pub sin_theta_xi: Vec<f64>,
    /// u·ω_o = sin θ_o.
    pub sin_theta_o: Vec<f64>,
    /// cos(φ_ξ − φ_o).
    pub cos_delta_phi: Vec<f64>,
    /// SRBF bandwidths λ (the table axis is 1/λ; give the λ of each node).
    pub lambda: Vec<f64>,
}

impl ConvolutionGrid {
    pub fn len(&self) -> usize {
        self.sin_theta_xi.len()
            * self.sin_theta_o.len()
            * self.cos_delta_phi.len()
            * self.lambda.len()
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Flat index of an entry: ξ slowest, then ω_o, Δφ, λ; RGB innermost in the output.
    pub fn index(&self, xi: usize, o: usize, d: usize, l: usize) -> usize {
        ((xi * self.sin_theta_o.len() + o) * self.cos_delta_phi.len() + d) * self.lambda.len() + l
    }
}

/// e^{−κ} Iₙ(κ) for n = 0..=n_max, by Miller's backward recurrence normalized with the
/// identity Ĩ₀ + 2 Σₙ Ĩₙ = 1 (the generating function at angle 0). Stable for every κ ≥ 0.
pub fn scaled_bessel_sequence(kappa: f64, n_max: usize) -> Vec<f64> {
    let mut out = vec![0.0; n_max + 1];
    if kappa < 1e-300 {
        out[0] = 1.0;
        return out;
    }
    // Start far enough above both n_max and the bulk of the sequence (width ~√κ).
    let start = n_max + 32 + (12.0 * kappa.sqrt()) as usize;
    let (mut above, mut here) = (0.0f64, 1e-280f64);
    let mut sum = 0.0; // Σ_{n≥1} Iₙ in the running scale
    for n in (1..=start).rev() {
        let below = here * (2.0 * n as f64 / kappa) + above;
        sum += here;
        if n <= n_max {
            out[n] = here;
        }
        (above, here) = (here, below);
        if here > 1e250 {
            // Rescale everything accumulated so far to stay in range.
            let s = 1e-250;
            above *= s;
            here *= s;
            sum *= s;
            out.iter_mut().for_each(|v| *v *= s);
        }
    }
    out[0] = here;
    let norm = here + 2.0 * sum;
    out.iter_mut().for_each(|v| *v /= norm);
    out
}

/// Cosine-series coefficients aₙ (n ≤ n_max) of an even 2π-periodic function, such that
/// f(φ) = a₀/2 + Σ aₙ cos nφ, from aₙ = (2/π) ∫₀^π f(φ) cos nφ dφ by composite Gauss–Legendre
/// on [0, π]. Kinks of even functions sit at 0 and π (e.g. |cos φ/2|, Marschner's N_R), which
/// are panel ends here, so they cost no accuracy; the trapezoid rule would alias them as 1/N².
pub fn cosine_coefficients(f: impl Fn(f64) -> f64, phi_panels: usize, n_max: usize) -> Vec<f64> {
    let basis = CosineBasis::new(phi_panels, n_max);
    let samples: Vec<f64> = basis.nodes.iter().map(|&p| f(p)).collect();
    basis.coefficients(&samples)
}

/// Cosine series of S(θ_i, θ_o, ·) per channel (symmetrized in φ, as [`convolve_grid`] does).
pub fn cosine_coefficients_many<F>(
    s: &F,
    theta_i: f64,
    theta_o: f64,
    phi_panels: usize,
    n_max: usize,
) -> Vec<Rgb>
where
    F: Fn(&FiberAngles) -> Rgb,
{
    let basis = CosineBasis::new(phi_panels, n_max);
    basis.spectrum(s, theta_i, theta_o)
}

/// Quadrature nodes φ_k on [0, π] and the weights (2/π) w_k cos(nφ_k), computed once per grid.
struct CosineBasis {
    nodes: Vec<f64>,
    /// `table[n * nodes.len() + k]`.
    table: Vec<f64>,
}

impl CosineBasis {
    fn new(phi_panels: usize, n_max: usize) -> Self {
        let rule = GaussLegendre::composite(8, phi_panels, 0.0, PI);
        let mut table = Vec::with_capacity((n_max + 1) * rule.nodes.len());
        for n in 0..=n_max {
            for (&p, &w) in rule.nodes.iter().zip(&rule.weights) {
                table.push(2.0 / PI * w * (n as f64 * p).cos());
            }
        }
        Self {
            nodes: rule.nodes,
            table,
        }
    }

    /// The cosine series of `s` at (θ_i, θ_o), per channel: `[n][c]`.
    fn spectrum<F: Fn(&FiberAngles) -> Rgb>(&self, s: &F, theta_i: f64, theta_o: f64) -> Vec<Rgb> {
        let mut channels = vec![vec![0.0; self.nodes.len()]; 3];
        for (k, &phi) in self.nodes.iter().enumerate() {
            let plus = s(&FiberAngles {
                theta_i,
                theta_o,
                phi,
            });
            let minus = s(&FiberAngles {
                theta_i,
                theta_o,
                phi: -phi,
            });
            for c in 0..3 {
                channels[c][k] = 0.5 * (plus[c] + minus[c]);
            }
        }
        let per_channel: Vec<Vec<f64>> = channels.iter().map(|ch| self.coefficients(ch)).collect();
        (0..per_channel[0].len())
            .map(|n| [per_channel[0][n], per_channel[1][n], per_channel[2][n]])
            .collect()
    }

    fn coefficients(&self, samples: &[f64]) -> Vec<f64> {
        self.table
            .chunks_exact(self.nodes.len())
            .map(|row| row.iter().zip(samples).map(|(c, s)| c * s).sum::<f64>())
            .collect()
    }
}

/// Harmonics needed so that the von Mises factor Ĩₙ(κ)/Ĩ₀(κ) ≈ e^{−n²/2κ} of the widest
/// kernel (κ = λ_max) has dropped below 1e-12 of its peak.
pub fn harmonics_for(lambda_max: f64) -> usize {
    (7.5 * lambda_max.max(0.0).sqrt()).ceil() as usize + 8
}

/// The convolution of `s` with an SRBF at every node of `grid`, as RGB (layout: see
/// [`ConvolutionGrid::index`], three values per entry).
pub fn convolve_grid<F>(s: &F, grid: &ConvolutionGrid, settings: &ConvolutionSettings) -> Vec<Rgb>
where
    F: Fn(&FiberAngles) -> Rgb + Sync,
{
    let lambda_max = grid.lambda.iter().cloned().fold(0.0, f64::max);
    let n_max = settings
        .max_harmonic
        .unwrap_or_else(|| harmonics_for(lambda_max))
        .min(8 * settings.phi_panels / 2);
    let theta_rule = GaussLegendre::composite(8, settings.theta_panels, -FRAC_PI_2, FRAC_PI_2);
    let spectra = azimuthal_spectra(
        s,
        &theta_rule.nodes,
        &grid.sin_theta_o,
        settings.phi_panels,
        n_max,
    );

    let n_o = grid.sin_theta_o.len();
    let delta_cosines: Vec<Vec<f64>> = grid
        .cos_delta_phi
        .iter()
        .map(|&cd| {
            let delta = cd.clamp(-1.0, 1.0).acos();
            (0..=n_max).map(|n| (n as f64 * delta).cos()).collect()
        })
        .collect();
    let mut out = vec![[0.0; 3]; grid.len()];
    let block = n_o * grid.cos_delta_phi.len() * grid.lambda.len();
    out.par_chunks_mut(block)
        .enumerate()
        .for_each(|(xi_index, chunk)| {
            let theta_xi = grid.sin_theta_xi[xi_index].clamp(-1.0, 1.0).asin();
            for (l, &lambda) in grid.lambda.iter().enumerate() {
                // κ ≤ λ cos θ_ξ: lobes near the fiber's poles need few harmonics.
                let n_used = n_max.min(harmonics_for(lambda * theta_xi.cos()));
                let kernel = ThetaKernel::new(&theta_rule, theta_xi, lambda, n_used);
                for o in 0..n_o {
                    let harmonics = kernel.harmonic_sums(&spectra[o], n_used);
                    for (d, cosines) in delta_cosines.iter().enumerate() {
                        let value = cosine_series(&harmonics, cosines).map(|v| 2.0 * PI * v);
                        chunk[(o * grid.cos_delta_phi.len() + d) * grid.lambda.len() + l] = value;
                    }
                }
            }
        });
    out
}

/// aₙ(θ_i, θ_o) per channel: `spectra[o][i][n]`. S is symmetrized in φ (exact for round
/// fibers; for eccentric ones the table holds the orientation average of ±φ, which is what a
/// table indexed by cos Δφ can hold).
fn azimuthal_spectra<F>(
    s: &F,
    theta_i: &[f64],
    sin_theta_o: &[f64],
    phi_panels: usize,
    n_max: usize,
) -> Vec<Vec<Vec<Rgb>>>
where
    F: Fn(&FiberAngles) -> Rgb + Sync,
{
    let basis = CosineBasis::new(phi_panels, n_max);
    sin_theta_o
        .par_iter()
        .map(|&so| {
            let theta_o = so.clamp(-1.0, 1.0).asin();
            theta_i
                .iter()
                .map(|&ti| basis.spectrum(s, ti, theta_o))
                .collect()
        })
        .collect()
}

/// The θ_i-dependent part of the integrand for one (θ_ξ, λ): quadrature weight × cos²θ_i ×
/// longitudinal SRBF factor, and the von Mises harmonics, restricted to nodes that matter.
struct ThetaKernel {
    /// (θ_i node index, W_i εₙ Ĩₙ(κ_i) for n = 0..=n_max).
    nodes: Vec<(usize, Vec<f64>)>,
}

impl ThetaKernel {
    fn new(rule: &GaussLegendre, theta_xi: f64, lambda: f64, n_max: usize) -> Self {
        let weights: Vec<f64> = rule
            .nodes
            .iter()
            .zip(&rule.weights)
            .map(|(&t, &w)| w * t.cos().powi(2) * (lambda * ((t - theta_xi).cos() - 1.0)).exp())
            .collect();
        let peak = weights.iter().cloned().fold(0.0, f64::max);
        let nodes = weights
            .iter()
            .enumerate()
            .filter(|&(_, &w)| w > 1e-16 * peak)
            .map(|(i, &w)| {
                let kappa = lambda * rule.nodes[i].cos() * theta_xi.cos();
                let mut bessel = scaled_bessel_sequence(kappa.max(0.0), n_max);
                bessel[0] *= 0.5; // ε₀
                bessel.iter_mut().for_each(|b| *b *= w);
                (i, bessel)
            })
            .collect();
        Self { nodes }
    }

    /// Aₙ = Σ_i W_i εₙ Ĩₙ(κ_i) aₙ(θ_i, θ_o) per channel.
    fn harmonic_sums(&self, spectra_o: &[Vec<Rgb>], n_max: usize) -> Vec<Rgb> {
        let mut acc = vec![[0.0; 3]; n_max + 1];
        for (i, weighted_bessel) in &self.nodes {
            let a = &spectra_o[*i];
            for ((acc_n, a_n), f) in acc.iter_mut().zip(a).zip(weighted_bessel) {
                for c in 0..3 {
                    acc_n[c] += f * a_n[c];
                }
            }
        }
        acc
    }
}

/// Σₙ hₙ cos(nΔ), given cos(nΔ) for every n.
fn cosine_series(harmonics: &[Rgb], cosines: &[f64]) -> Rgb {
    let mut v = [0.0; 3];
    for (h, &c) in harmonics.iter().zip(cosines) {
        for k in 0..3 {
            v[k] += h[k] * c;
        }
    }
    v
}

/// Brute-force reference: eq. 8 integrated directly in the fiber frame, θ_i by composite
/// Gauss–Legendre over the inclinations where G exceeds 1e-12, and for each θ_i node φ_i over
/// the azimuths where it does. Independent of every shortcut above (no series, no separation),
/// and the fiber frame keeps the poles θ_i = ±π/2 at the ends of the θ_i range, where the
/// integrand's cos θ_i factor is smooth.
pub fn convolve_reference<F>(
    s: &F,
    theta_xi: f64,
    theta_o: f64,
    delta_phi: f64,
    lambda: f64,
    panels: usize,
) -> Rgb
where
    F: Fn(&FiberAngles) -> Rgb,
{
    // Beyond this angular distance from ξ, G < 1e-12.
    let cos_gamma_min = 1.0 - (1e12_f64.ln() / lambda).min(2.0);
    let gamma_max = cos_gamma_min.acos();
    let lo = (theta_xi - gamma_max).max(-FRAC_PI_2);
    let hi = (theta_xi + gamma_max).min(FRAC_PI_2);
    let rule_t = GaussLegendre::composite(8, panels, lo, hi);
    let (s_xi, c_xi) = theta_xi.sin_cos();
    let mut acc = [0.0; 3];
    for (&t, &wt) in rule_t.nodes.iter().zip(&rule_t.weights) {
        let (st, ct) = t.sin_cos();
        // cos γ = sin θ sin θ_ξ + cos θ cos θ_ξ cos ψ ≥ cos γ_min  ⇔  cos ψ ≥ bound.
        let denom = ct * c_xi;
        let half_width = if denom <= 1e-300 {
            PI
        } else {
            ((cos_gamma_min - st * s_xi) / denom)
                .clamp(-1.0, 1.0)
                .acos()
        };
        if half_width <= 0.0 {
            continue;
        }
        let rule_p = GaussLegendre::composite(8, panels, -half_width, half_width);
        for (&psi, &wp) in rule_p.nodes.iter().zip(&rule_p.weights) {
            // ω_i at azimuth φ_ξ + ψ with φ_ξ = 0; φ = φ_o − φ_i = Δ − ψ.
            let g = (lambda * (st * s_xi + ct * c_xi * psi.cos() - 1.0)).exp();
            let v = s(&FiberAngles::new(t, theta_o, delta_phi - psi));
            let f = wt * wp * g * ct * ct;
            for c in 0..3 {
                acc[c] += f * v[c];
            }
        }
    }
    acc
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A smooth, coloured, φ-even test function with longitudinal structure.
    fn smooth_s(a: &FiberAngles) -> Rgb {
        let th = a.theta_h();
        let base = (-(th - 0.1).powi(2) / 0.08).exp() / (1.0 + a.theta_d().powi(2));
        [
            base * (1.0 + 0.5 * a.phi.cos()),
            base * (1.2 + 0.3 * (3.0 * a.phi).cos()),
            (1.0 + a.theta_i.sin() * a.theta_o.sin()) * (0.5 - 0.4 * (a.phi / 2.0).cos().powi(2)),
        ]
    }

    #[test]
    fn scaled_bessel_matches_the_series_and_quadrature() {
        for &kappa in &[0.0, 1e-6, 0.3, 5.0, 64.0, 400.0, 1e4] {
            let seq = scaled_bessel_sequence(kappa, 40);
            // Independent: Ĩₙ(κ) = (1/π) ∫₀^π e^{κ(cos t − 1)} cos(nt) dt by a fine trapezoid rule.
            for n in [0usize, 1, 7, 40] {
                let m = 20000;
                let mut q = 0.0;
                for k in 0..=m {
                    let t = PI * k as f64 / m as f64;
                    let w = if k == 0 || k == m { 0.5 } else { 1.0 };
                    q += w * (kappa * (t.cos() - 1.0)).exp() * (n as f64 * t).cos();
                }
                q /= m as f64;
                assert!(
                    (seq[n] - q).abs() < 1e-13 + 1e-10 * q.abs(),
                    "κ={kappa} n={n}: {} vs {q}",
                    seq[n]
                );
            }
            assert!((seq[0] - strandlight_tables::special::scaled_bessel_i0(kappa)).abs() < 1e-13);
        }
    }

    #[test]
    fn cosine_coefficients_match_closed_forms() {
        // A trigonometric polynomial, and |cos φ/2| whose kink at π the trapezoid rule would
        // alias: its coefficients are aₙ = (4/π)(−1)^{n+1}/(4n² − 1).
        let a = cosine_coefficients(|p| 3.0 + 2.0 * p.cos() - 0.5 * (5.0 * p).cos(), 8, 8);
        let want = [6.0, 2.0, 0.0, 0.0, 0.0, -0.5, 0.0, 0.0, 0.0];
        for (g, w) in a.iter().zip(want) {
            assert!((g - w).abs() < 1e-13, "{a:?}");
        }
        let k = cosine_coefficients(|p| (p / 2.0).cos().abs(), 32, 40);
        for (n, g) in k.iter().enumerate() {
            let n = n as f64;
            let w = 4.0 / PI * (-1f64).powf(n + 1.0) / (4.0 * n * n - 1.0);
            assert!((g - w).abs() < 1e-12, "n={n}: {g} vs {w}");
        }
    }

    #[test]
    fn grid_matches_brute_force_integration() {
        let grid = ConvolutionGrid {
            sin_theta_xi: vec![-0.95, -0.3, 0.0, 0.6, 1.0],
            sin_theta_o: vec![-0.99, 0.2, 0.8],
            cos_delta_phi: vec![-1.0, -0.2, 0.5, 1.0],
            lambda: vec![16.0, 40.0, 64.0],
        };
        let settings = ConvolutionSettings {
            theta_panels: 48,
            phi_panels: 16,
            max_harmonic: None,
        };
        let fast = convolve_grid(&smooth_s, &grid, &settings);
        let mut worst: f64 = 0.0;
        let mut peak: f64 = 0.0;
        for (xi, &sx) in grid.sin_theta_xi.iter().enumerate() {
            for (o, &so) in grid.sin_theta_o.iter().enumerate() {
                for (d, &cd) in grid.cos_delta_phi.iter().enumerate() {
                    for (l, &lambda) in grid.lambda.iter().enumerate() {
                        let r = convolve_reference(
                            &smooth_s,
                            sx.asin(),
                            so.asin(),
                            cd.acos(),
                            lambda,
                            48,
                        );
                        let f = fast[grid.index(xi, o, d, l)];
                        for c in 0..3 {
                            worst = worst.max((f[c] - r[c]).abs());
                            peak = peak.max(r[c].abs());
                        }
                    }
                }
            }
        }
        println!(
            "harmonic convolution vs brute force: max |Δ| = {worst:.3e} (peak value {peak:.3e})"
        );
        // Two independent quadratures of a smooth integrand: both converge spectrally.
        assert!(worst < 1e-10 * peak, "max deviation {worst} of peak {peak}");
    }

    #[test]
    fn constant_scattering_gives_the_cosine_weighted_srbf_integral() {
        // S = 1: I = ∫ G cos θ_i dω. At ξ on the fiber's normal plane and λ large this tends
        // to ∫G dω = 2π/λ(1 − e^{−2λ}) up to the cos θ_i ≈ 1 − γ²/2 factor: check the exact
        // value against the ξ-centred brute force instead, plus the ω_o- and Δ-independence.
        let one = |_: &FiberAngles| [1.0, 1.0, 1.0];
        let grid = ConvolutionGrid {
            sin_theta_xi: vec![0.0, 0.7],
            sin_theta_o: vec![-0.5, 0.9],
            cos_delta_phi: vec![-1.0, 1.0],
            lambda: vec![16.0, 64.0],
        };
        let v = convolve_grid(&one, &grid, &ConvolutionSettings::default());
        for xi in 0..2 {
            for l in 0..2 {
                let r = convolve_reference(
                    &one,
                    grid.sin_theta_xi[xi].asin(),
                    0.0,
                    0.0,
                    grid.lambda[l],
                    64,
                )[0];
                for o in 0..2 {
                    for d in 0..2 {
                        let f = v[grid.index(xi, o, d, l)][0];
                        assert!((f - r).abs() < 1e-7 * r, "{f} vs {r}");
                    }
                }
            }
        }
        let at_pole = convolve_reference(&one, FRAC_PI_2, 0.0, 0.0, 64.0, 64)[0];
        let flat = convolve_reference(&one, 0.0, 0.0, 0.0, 64.0, 64)[0];
        // With ξ along the fiber, cos θ_i = sin γ: a 1D integral 2π ∫ e^{λ(cos γ−1)} sin²γ dγ.
        let pole_1d = 2.0
            * PI
            * GaussLegendre::composite(8, 64, 0.0, PI)
                .integrate(|g| (64.0 * (g.cos() - 1.0)).exp() * g.sin().powi(2));
        assert!(
            (at_pole - pole_1d).abs() < 1e-7 * pole_1d,
            "{at_pole} vs {pole_1d}"
        );
        let integral = strandlight_tables::srbf::integral(64.0);
        assert!((flat - integral).abs() < 0.02 * integral);
    }
}
