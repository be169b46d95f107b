//! Real spherical harmonics of bands 0–3 (16 coefficients) and the SRBF's zonal convolution.
//!
//! The basis is the usual orthonormal real one (Sloan, "Stupid SH tricks"), in the project's
//! world axes; `visibility_volume.wgsl` evaluates the same polynomials in the same order.
//!
//! An SRBF G(ω; ξ, λ) = exp(λ(ω·ξ − 1)) is zonal about ξ, so by Funk–Hecke
//! ∫ G(ω) Y_lm(ω) dω = 2π ∫₋₁¹ G(t) P_l(t) dt · Y_lm(ξ). Divided by ∫ G dω that is
//! i_l(λ)/i_0(λ) · Y_lm(ξ), with i_l the modified spherical Bessel functions of the first kind:
//! the lobe-weighted mean of a function with coefficients c_lm is Σ c_lm (i_l/i_0)(λ) Y_lm(ξ).

use glam::Vec3;

/// Coefficients of bands 0–3.
pub const SH_COEFFICIENTS: usize = 16;

/// The 16 basis functions at the unit vector `d`.
pub fn sh_basis(d: Vec3) -> [f32; SH_COEFFICIENTS] {
    let (x, y, z) = (d.x, d.y, d.z);
    let (x2, y2, z2) = (x * x, y * y, z * z);
    [
        0.282_094_8,
        0.488_602_5 * y,
        0.488_602_5 * z,
        0.488_602_5 * x,
        1.092_548_5 * x * y,
        1.092_548_5 * y * z,
        0.315_391_6 * (3.0 * z2 - 1.0),
        1.092_548_5 * x * z,
        0.546_274_2 * (x2 - y2),
        0.590_043_6 * y * (3.0 * x2 - y2),
        2.890_611_4 * x * y * z,
        0.457_045_8 * y * (5.0 * z2 - 1.0),
        0.373_176_3 * z * (5.0 * z2 - 3.0),
        0.457_045_8 * x * (5.0 * z2 - 1.0),
        1.445_305_7 * z * (x2 - y2),
        0.590_043_6 * x * (x2 - 3.0 * y2),
    ]
}

/// The band of each coefficient.
const BAND: [usize; SH_COEFFICIENTS] = [0, 1, 1, 1, 2, 2, 2, 2, 2, 3, 3, 3, 3, 3, 3, 3];

/// (i_l/i_0)(λ) for l = 0..3: how much of band l survives the convolution with an SRBF of
/// bandwidth λ. Below λ = ½ the recurrence cancels catastrophically, so the Taylor series
/// is used there; above 20, coth λ = 1 in f32 (and `tanh` of large arguments is not
/// trusted on every GPU). The shader computes the same.
pub fn srbf_band_ratios(lambda: f32) -> [f32; 4] {
    let l = lambda.max(0.0);
    if l < 0.5 {
        let l2 = l * l;
        return [
            1.0,
            l / 3.0 * (1.0 - l2 / 15.0 + 2.0 * l2 * l2 / 315.0),
            l2 / 15.0 * (1.0 - 2.0 * l2 / 21.0 + l2 * l2 / 105.0),
            l2 * l / 105.0 * (1.0 - l2 / 9.0),
        ];
    }
    let coth = if l > 20.0 { 1.0 } else { 1.0 / l.tanh() };
    let r1 = coth - 1.0 / l;
    let r2 = 1.0 - 3.0 * r1 / l;
    let r3 = r1 - 5.0 * r2 / l;
    [1.0, r1, r2, r3]
}

/// Lanczos σ factors sinc(l / 4) of bands 0–3. A band-limited step rings: the hemisphere of
/// sky above a fiber on the hair's surface reconstructs to 0.81 at its pole from bands 0–3, so
/// the fibers a lobe lights most would read a fifth too dark. Damping the higher bands by these
/// factors brings the pole to 1.04 (clamped to 1) at the price of a slightly softer horizon.
pub const RINGING_WINDOW: [f32; 4] = [1.0, 0.900_316_3, std::f32::consts::FRAC_2_PI, 0.300_105_1];

/// `c` with each band scaled by [`RINGING_WINDOW`].
pub fn windowed(c: &[f32; SH_COEFFICIENTS]) -> [f32; SH_COEFFICIENTS] {
    std::array::from_fn(|i| c[i] * RINGING_WINDOW[BAND[i]])
}

/// The mean of the function with SH coefficients `c` over the SRBF of centre `xi` and
/// bandwidth `lambda`, weighted by the lobe, clamped to [0, 1] (a visibility; the band limit
/// rings a little below 0 and above 1 near sharp edges).
pub fn lobe_visibility(c: &[f32; SH_COEFFICIENTS], xi: Vec3, lambda: f32) -> f32 {
    let ratios = srbf_band_ratios(lambda);
    let y = sh_basis(xi.normalize());
    let v: f32 = (0..SH_COEFFICIENTS)
        .map(|i| c[i] * ratios[BAND[i]] * y[i])
        .sum();
    v.clamp(0.0, 1.0)
}

/// `count` unit vectors spread evenly over the sphere (a spherical Fibonacci lattice): equal
/// solid angle 4π/count each.
pub fn fibonacci_directions(count: usize) -> Vec<Vec3> {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..count)
        .map(|i| {
            let z = 1.0 - (2.0 * i as f64 + 1.0) / count as f64;
            let r = (1.0 - z * z).max(0.0).sqrt();
            let phi = golden * i as f64;
            Vec3::new((r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32)
        })
        .collect()
}

/// SH coefficients of the function sampled as `values` at `directions` (equal solid angles).
pub fn project(directions: &[Vec3], values: impl Iterator<Item = f32>) -> [f32; SH_COEFFICIENTS] {
    let mut c = [0.0f64; SH_COEFFICIENTS];
    for (d, v) in directions.iter().zip(values) {
        for (ci, yi) in c.iter_mut().zip(sh_basis(*d)) {
            *ci += v as f64 * yi as f64;
        }
    }
    let weight = 4.0 * std::f64::consts::PI / directions.len() as f64;
    c.map(|ci| (ci * weight) as f32)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// ∫₋₁¹ e^{λ(t−1)} P_l(t) dt by composite Simpson in f64 (the kernel is smooth; 20 000
    /// intervals resolve λ = 2000's width of 1/λ near t = 1).
    fn band_integral(lambda: f64, l: usize) -> f64 {
        let legendre = |t: f64| match l {
            0 => 1.0,
            1 => t,
            2 => 0.5 * (3.0 * t * t - 1.0),
            _ => 0.5 * (5.0 * t * t * t - 3.0 * t),
        };
        let n = 20_000;
        let h = 2.0 / n as f64;
        let f = |k: usize| {
            let t = -1.0 + k as f64 * h;
            (lambda * (t - 1.0)).exp() * legendre(t)
        };
        let inner: f64 = (1..n)
            .map(|k| if k % 2 == 1 { 4.0 } else { 2.0 } * f(k))
            .sum();
        h / 3.0 * (f(0) + inner + f(n))
    }

    #[test]
    fn band_ratios_match_f64_integration_from_wide_to_narrow_lobes() {
        for lambda in [
            0.01, 0.3, 0.499, 0.5, 0.999, 1.0, 2.5, 10.0, 19.9, 20.1, 150.0, 2000.0,
        ] {
            let exact: Vec<f64> = (0..4)
                .map(|l| band_integral(lambda, l) / band_integral(lambda, 0))
                .collect();
            let ratios = srbf_band_ratios(lambda as f32);
            for l in 0..4 {
                let err = (ratios[l] as f64 - exact[l]).abs();
                assert!(
                    err < 2e-4 + 1e-3 * exact[l].abs(),
                    "λ {lambda} band {l}: {} vs {}",
                    ratios[l],
                    exact[l]
                );
            }
        }
    }

    #[test]
    fn the_basis_is_orthonormal_under_the_lattice_quadrature() {
        let dirs = fibonacci_directions(40_000);
        for i in 0..SH_COEFFICIENTS {
            let c = project(&dirs, dirs.iter().map(|d| sh_basis(*d)[i]));
            for (j, cj) in c.iter().enumerate() {
                let expected = if i == j { 1.0 } else { 0.0 };
                assert!((cj - expected).abs() < 2e-3, "<Y{i}, Y{j}> = {cj}");
            }
        }
    }

    #[test]
    fn lobe_visibility_is_the_lobe_weighted_mean_of_a_band_limited_function() {
        // V(ω) = 0.5 + 0.3 z + 0.4 x y − 0.2 z (5z² − 3)/2: bands 0–3, inside [0, 1].
        let v = |d: Vec3| 0.5 + 0.3 * d.z + 0.4 * d.x * d.y - 0.1 * d.z * (5.0 * d.z * d.z - 3.0);
        let dirs = fibonacci_directions(200_000);
        let c = project(&dirs, dirs.iter().map(|d| v(*d)));
        for (xi, lambda) in [
            (Vec3::new(0.3, -0.5, 0.8), 0.5f32),
            (Vec3::new(-0.7, 0.1, 0.2), 4.0),
            (Vec3::new(0.1, 0.9, -0.4), 40.0),
        ] {
            let xi = xi.normalize();
            // Brute force: Σ G V / Σ G over the lattice, in f64.
            let (mut num, mut den) = (0.0f64, 0.0f64);
            for d in &dirs {
                let g = ((lambda * (d.dot(xi) - 1.0)) as f64).exp();
                num += g * v(*d) as f64;
                den += g;
            }
            let brute = num / den;
            let sh = lobe_visibility(&c, xi, lambda) as f64;
            assert!(
                (sh - brute).abs() < 2e-3,
                "ξ {xi} λ {lambda}: {sh} vs {brute}"
            );
        }
    }

    #[test]
    fn the_window_lifts_a_hemisphere_step_at_its_pole_to_one() {
        let dirs = fibonacci_directions(100_000);
        let step = project(
            &dirs,
            dirs.iter().map(|d| if d.z > 0.0 { 1.0 } else { 0.0 }),
        );
        let at_pole = |c: &[f32; SH_COEFFICIENTS]| -> f32 {
            c.iter().zip(sh_basis(Vec3::Z)).map(|(c, y)| c * y).sum()
        };
        // The truncated series: 1/2 + 3/4 − 7/16 = 0.8125.
        assert!((at_pole(&step) - 0.8125).abs() < 2e-3, "{}", at_pole(&step));
        let w = at_pole(&windowed(&step));
        assert!((1.0..1.06).contains(&w), "windowed pole {w}");
        // The horizon stays at one half, the nadir near 0.
        let at = |c: &[f32; SH_COEFFICIENTS], d: Vec3| -> f32 {
            c.iter().zip(sh_basis(d)).map(|(c, y)| c * y).sum()
        };
        assert!((at(&windowed(&step), Vec3::X) - 0.5).abs() < 2e-3);
        assert!(at(&windowed(&step), -Vec3::Z) < 0.0);
    }

    #[test]
    fn a_visibility_is_clamped_to_zero_and_one() {
        let mut c = [0.0; SH_COEFFICIENTS];
        c[0] = 3.0 / 0.282_094_8;
        assert_eq!(lobe_visibility(&c, Vec3::Z, 10.0), 1.0);
        c[0] = -1.0;
        assert_eq!(lobe_visibility(&c, Vec3::Z, 10.0), 0.0);
    }
}
