//! Special functions whose naive forms overflow where hair models need them: the modified
//! Bessel function I₀ of large arguments (d'Eon's longitudinal term, the von Mises azimuthal
//! factor of an SRBF) and normalized Gaussians.

use std::f64::consts::PI;

/// Below this argument the power series is summed directly (its terms stay below e^{SERIES_MAX}).
const SERIES_MAX: f64 = 30.0;

/// e^{−|x|} I₀(x): bounded by 1 for every x, so it never overflows.
pub fn scaled_bessel_i0(x: f64) -> f64 {
    let x = x.abs();
    if x.is_nan() {
        return f64::NAN;
    }
    if x <= SERIES_MAX {
        bessel_i0_series(x) * (-x).exp()
    } else {
        bessel_i0_asymptotic_scaled(x)
    }
}

/// ln I₀(x), finite for every finite x (I₀ itself overflows past x ≈ 713).
pub fn log_bessel_i0(x: f64) -> f64 {
    let x = x.abs();
    x + scaled_bessel_i0(x).ln()
}

/// I₀(x) = Σ_k (x²/4)^k / (k!)², summed until the terms stop mattering.
fn bessel_i0_series(x: f64) -> f64 {
    let q = 0.25 * x * x;
    let mut term = 1.0;
    let mut sum = 1.0;
    let mut k = 1.0;
    while term > 1e-17 * sum {
        term *= q / (k * k);
        sum += term;
        k += 1.0;
    }
    sum
}

/// e^{−x} I₀(x) ≈ (2πx)^{−1/2} Σ_k ((2k−1)!!)² / (k! (8x)^k) for large x, truncated at its
/// smallest term (the series is asymptotic, not convergent).
fn bessel_i0_asymptotic_scaled(x: f64) -> f64 {
    let mut term = 1.0;
    let mut sum = 1.0;
    for k in 1..40 {
        let kf = k as f64;
        let next = term * (2.0 * kf - 1.0).powi(2) / (kf * 8.0 * x);
        if next.abs() >= term.abs() {
            break;
        }
        term = next;
        sum += term;
        if term < 1e-17 * sum {
            break;
        }
    }
    sum / (2.0 * PI * x).sqrt()
}

/// Unit-area Gaussian with variance `variance`, evaluated at `x`.
pub fn gaussian(variance: f64, x: f64) -> f64 {
    (-x * x / (2.0 * variance)).exp() / (2.0 * PI * variance).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// I₀(x) = (1/π) ∫₀^π e^{x cos t} dt, integrated in scaled form by the composite
    /// trapezoid rule, which converges geometrically for periodic integrands.
    fn scaled_i0_by_quadrature(x: f64) -> f64 {
        let n = 4000;
        let h = PI / n as f64;
        let mut s = 0.0;
        for i in 0..=n {
            let t = i as f64 * h;
            let w = if i == 0 || i == n { 0.5 } else { 1.0 };
            s += w * (x * (t.cos() - 1.0)).exp();
        }
        s * h / PI
    }

    #[test]
    fn scaled_i0_matches_quadrature_across_both_branches() {
        // The trapezoid reference resolves the integrand's width 1/√x only up to x ≈ 1e4.
        for &x in &[0.0, 1e-8, 0.5, 3.0, 10.0, 29.9, 30.1, 80.0, 700.0, 1e4] {
            let want = scaled_i0_by_quadrature(x);
            let got = scaled_bessel_i0(x);
            assert!(
                (got - want).abs() <= 1e-12 * want.max(1e-300) + 1e-15,
                "x={x}: {got} vs {want}"
            );
        }
    }

    #[test]
    fn huge_arguments_follow_the_asymptotic_series() {
        // Three terms of the asymptotic series, written out independently.
        for &x in &[1e5, 1e6, 1e9] {
            let want = (1.0 + 1.0 / (8.0 * x) + 9.0 / (128.0 * x * x)) / (2.0 * PI * x).sqrt();
            assert!((scaled_bessel_i0(x) - want).abs() < 1e-14 * want, "x={x}");
        }
    }

    #[test]
    fn known_values() {
        // I₀(1) = 1.2660658777520082 (Abramowitz & Stegun table 9.8).
        assert!((scaled_bessel_i0(1.0) * 1f64.exp() - 1.2660658777520082).abs() < 1e-14);
        assert!(log_bessel_i0(1e5).is_finite());
        assert!(scaled_bessel_i0(f64::NAN).is_nan());
    }
}
