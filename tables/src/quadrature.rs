//! Reference integrators in f64: Gauss–Legendre rules and sphere integration in the fiber
//! frame. Tables and fits are checked against these, never against themselves.

use std::f64::consts::{FRAC_PI_2, PI};

/// An n-point Gauss–Legendre rule on [a, b].
#[derive(Debug, Clone)]
pub struct GaussLegendre {
    pub nodes: Vec<f64>,
    pub weights: Vec<f64>,
}

impl GaussLegendre {
    /// Nodes by Newton iteration on P_n from the Chebyshev guess; accurate to ~1e-15 for any n.
    pub fn new(n: usize, a: f64, b: f64) -> Self {
        assert!(n > 0, "a quadrature rule needs at least one node");
        let mut nodes = vec![0.0; n];
        let mut weights = vec![0.0; n];
        let (mid, half) = (0.5 * (a + b), 0.5 * (b - a));
        for i in 0..n.div_ceil(2) {
            let mut x = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut dp = 1.0;
            for _ in 0..100 {
                let (p, d) = legendre_and_derivative(n, x);
                dp = d;
                let dx = p / d;
                x -= dx;
                if dx.abs() < 1e-16 {
                    break;
                }
            }
            let (_, d) = legendre_and_derivative(n, x);
            dp = if d != 0.0 { d } else { dp };
            let w = 2.0 / ((1.0 - x * x) * dp * dp);
            nodes[i] = mid - half * x;
            nodes[n - 1 - i] = mid + half * x;
            weights[i] = half * w;
            weights[n - 1 - i] = half * w;
        }
        Self { nodes, weights }
    }

    pub fn integrate(&self, mut f: impl FnMut(f64) -> f64) -> f64 {
        self.nodes
            .iter()
            .zip(&self.weights)
            .map(|(&x, &w)| w * f(x))
            .sum()
    }

    /// The same rule repeated on `panels` equal sub-intervals: robust for peaked integrands.
    pub fn composite(n: usize, panels: usize, a: f64, b: f64) -> Self {
        let h = (b - a) / panels as f64;
        let mut nodes = Vec::with_capacity(n * panels);
        let mut weights = Vec::with_capacity(n * panels);
        for p in 0..panels {
            let r = Self::new(n, a + p as f64 * h, a + (p + 1) as f64 * h);
            nodes.extend(r.nodes);
            weights.extend(r.weights);
        }
        Self { nodes, weights }
    }
}

fn legendre_and_derivative(n: usize, x: f64) -> (f64, f64) {
    let (mut p0, mut p1) = (1.0, x);
    for k in 2..=n {
        let kf = k as f64;
        let p2 = ((2.0 * kf - 1.0) * x * p1 - (kf - 1.0) * p0) / kf;
        p0 = p1;
        p1 = p2;
    }
    if n == 0 {
        return (1.0, 0.0);
    }
    let d = n as f64 * (x * p1 - p0) / (x * x - 1.0);
    (p1, d)
}

/// ∫ f(θ, φ) dω over the sphere in fiber coordinates (dω = cos θ dθ dφ), with `n_theta`
/// composite Gauss–Legendre nodes in θ ∈ [−π/2, π/2] and `n_phi` in φ ∈ (−π, π].
pub fn integrate_sphere(
    n_theta_panels: usize,
    n_phi_panels: usize,
    mut f: impl FnMut(f64, f64) -> f64,
) -> f64 {
    let rt = GaussLegendre::composite(8, n_theta_panels, -FRAC_PI_2, FRAC_PI_2);
    let rp = GaussLegendre::composite(8, n_phi_panels, -PI, PI);
    let mut total = 0.0;
    for (&t, &wt) in rt.nodes.iter().zip(&rt.weights) {
        let c = t.cos();
        let mut row = 0.0;
        for (&p, &wp) in rp.nodes.iter().zip(&rp.weights) {
            row += wp * f(t, p);
        }
        total += wt * c * row;
    }
    total
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn polynomials_are_exact() {
        let r = GaussLegendre::new(5, -1.0, 2.0);
        // Exact for degree ≤ 9: ∫_{-1}^{2} x^9 dx = (2^10 − 1)/10.
        let got = r.integrate(|x| x.powi(9));
        assert!((got - 102.3).abs() < 1e-11, "{got}");
        let w: f64 = GaussLegendre::new(64, 0.0, 1.0).weights.iter().sum();
        assert!((w - 1.0).abs() < 1e-14);
    }

    #[test]
    fn sphere_area_is_four_pi() {
        let a = integrate_sphere(4, 4, |_, _| 1.0);
        assert!((a - 4.0 * PI).abs() < 1e-12);
    }
}
