//! Splitting an SRBF light into narrower sub-lobes, so that its shadowing is sampled in several
//! directions instead of one.
//!
//! Ren 2010 renders one convolution optical depth map per SRBF and applies one filtered
//! transmittance to the whole lobe, T̃_j·(L_j G_j ⊛ S). On dense hair the transmittance varies
//! across a wide lobe and is correlated with the fiber response inside it, which that product
//! cannot represent (docs/BENCHMARKS.md: the shadowing is most of the SRBF frame's error). A
//! lobe G(ω; ξ, λ) written as a centre sub-lobe plus a ring of `ring` sub-lobes at angle ρ
//! around ξ, all of bandwidth c·λ, Σ_k a_k G(ω; ξ_k, cλ) ≈ G(ω; ξ, λ), is rendered as `ring + 1`
//! SRBF lights: each has its own map and its own narrower filter, and its weight in the pixel
//! is its own convolution with the fiber, (a_k G_k ⊛ S), read from the same table. That is the
//! lobe's visibility split into sub-directions weighted by the lobe times the fiber response.
//! The shape (ρ√λ, c) is chosen per lobe by a small search and the amplitudes by non-negative
//! least squares with the closed-form SRBF inner products, so the split's own L2 error is known.

use glam::DVec3;
use nalgebra::{DMatrix, DVector};
use strandlight_tables::srbf::{SrbfLobe, inner_product, integral, squared_norm};

/// How one lobe was split.
#[derive(Debug, Clone, PartialEq)]
pub struct LobeSplit {
    pub lobes: Vec<SrbfLobe>,
    /// ‖G − Σ a_k G_k‖ / ‖G‖ over the sphere.
    pub relative_l2_error: f64,
}

/// A unit vector perpendicular to `v` (unit).
fn perpendicular(v: DVec3) -> DVec3 {
    let helper = if v.x.abs() < 0.9 { DVec3::X } else { DVec3::Y };
    v.cross(helper).normalize()
}

/// The centre and `ring` directions at angle `rho` around unit `xi`.
fn directions(xi: DVec3, ring: usize, rho: f64) -> Vec<DVec3> {
    let u = perpendicular(xi);
    let v = xi.cross(u);
    let mut out = vec![xi];
    out.extend((0..ring).map(|k| {
        let phi = 2.0 * std::f64::consts::PI * k as f64 / ring as f64;
        (xi * rho.cos() + (u * phi.cos() + v * phi.sin()) * rho.sin()).normalize()
    }));
    out
}

/// Unit-amplitude sub-lobe weights a ≥ 0 and the relative L2 error for one shape. The L2 fit
/// is rescaled to carry the lobe's power exactly: a light that loses power darkens the image
/// everywhere, which costs more than the slightly larger L2 error.
fn fit_shape(xi: DVec3, lambda: f64, ring: usize, rho: f64, c: f64) -> (Vec<DVec3>, Vec<f64>, f64) {
    let dirs = directions(xi, ring, rho);
    let sub = c * lambda;
    let n = dirs.len();
    let gram = DMatrix::from_fn(n, n, |i, j| inner_product(dirs[i], sub, dirs[j], sub));
    let rhs = DVector::from_iterator(n, dirs.iter().map(|d| inner_product(*d, sub, xi, lambda)));
    let fitted = crate::nnls::solve(&gram, &rhs);
    let power = fitted.sum() * integral(sub);
    let a = if power > 0.0 {
        fitted * (integral(lambda) / power)
    } else {
        fitted
    };
    // ‖G − Σ a G_k‖² = ‖G‖² − 2 aᵀb + aᵀ A a.
    let norm2 = squared_norm(lambda);
    let err2 = (norm2 - 2.0 * a.dot(&rhs) + a.dot(&(&gram * &a))).max(0.0);
    (dirs, a.iter().copied().collect(), (err2 / norm2).sqrt())
}

/// The best split of `lobe` into a centre and `ring` sub-lobes (ring ≥ 3), searched over ring
/// radii ρ√λ ∈ [0.2, 2.5] and bandwidth ratios c ∈ [1.5, 6]. Below that c the sub-lobes are
/// hardly narrower; the wider the ratio, the better the shadows are resolved but the more the
/// ring must cover, which is what the error measures.
pub fn split_lobe(lobe: &SrbfLobe, ring: usize, c: f64) -> LobeSplit {
    let xi = lobe.center().normalize();
    let lambda = lobe.lambda;
    let mut best: Option<(Vec<DVec3>, Vec<f64>, f64)> = None;
    for k in 0..=46 {
        let rho = (0.2 + 0.05 * k as f64) / lambda.sqrt();
        if rho >= 1.2 {
            break;
        }
        let candidate = fit_shape(xi, lambda, ring, rho, c);
        if best.as_ref().is_none_or(|b| candidate.2 < b.2) {
            best = Some(candidate);
        }
    }
    let (dirs, weights, error) = best.expect("at least one ring radius is tried");
    LobeSplit {
        lobes: dirs
            .into_iter()
            .zip(weights)
            .filter(|(_, a)| *a > 0.0)
            .map(|(d, a)| SrbfLobe {
                center: d.to_array(),
                lambda: c * lambda,
                amplitude: lobe.amplitude.map(|x| x * a),
            })
            .collect(),
        relative_l2_error: error,
    }
}

/// `set` with every lobe split into a centre and `ring` sub-lobes of bandwidth `c`·λ; returns
/// the new set and the largest relative L2 error of a split. `ring` 0 returns the set as it is.
pub fn split_set(set: &crate::SrbfSet, ring: usize, c: f64) -> (crate::SrbfSet, f64) {
    if ring == 0 {
        return (set.clone(), 0.0);
    }
    let mut worst = 0.0f64;
    let mut lobes = Vec::new();
    for lobe in &set.lobes {
        let split = split_lobe(lobe, ring, c);
        worst = worst.max(split.relative_l2_error);
        lobes.extend(split.lobes);
    }
    (
        crate::SrbfSet {
            lobes,
            ..set.clone()
        },
        worst,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    fn lobe(lambda: f64) -> SrbfLobe {
        SrbfLobe {
            center: DVec3::new(0.3, 0.8, -0.52).normalize().to_array(),
            lambda,
            amplitude: [1.0, 2.0, 0.5],
        }
    }

    /// The split's L2 error by brute force on a fine sphere grid, independent of the closed
    /// form the fit uses.
    fn brute_force_error(original: &SrbfLobe, parts: &[SrbfLobe]) -> f64 {
        let (n_t, n_p) = (800, 1600);
        let (mut num, mut den) = (0.0, 0.0);
        for i in 0..n_t {
            let t = PI * (i as f64 + 0.5) / n_t as f64;
            let w = t.sin() * (PI / n_t as f64) * (2.0 * PI / n_p as f64);
            for j in 0..n_p {
                let p = 2.0 * PI * (j as f64 + 0.5) / n_p as f64;
                let d = DVec3::new(t.sin() * p.cos(), t.cos(), t.sin() * p.sin());
                let g = original.radiance(d)[0];
                let s: f64 = parts.iter().map(|l| l.radiance(d)[0]).sum();
                num += w * (g - s).powi(2);
                den += w * g * g;
            }
        }
        (num / den).sqrt()
    }

    #[test]
    fn a_split_reproduces_the_lobe_and_its_error_is_measured() {
        for lambda in [16.0, 64.0] {
            for (ring, c) in [(4, 2.0), (6, 3.0)] {
                let original = lobe(lambda);
                let split = split_lobe(&original, ring, c);
                let brute = brute_force_error(&original, &split.lobes);
                eprintln!(
                    "λ = {lambda}, ring {ring}, c = {c}: {} sub-lobes, relative L2 error {:.4} (brute force {brute:.4})",
                    split.lobes.len(),
                    split.relative_l2_error
                );
                assert!((brute - split.relative_l2_error).abs() < 2e-3, "{brute}");
                assert!(split.relative_l2_error < 0.1);
                assert!(split.lobes.iter().all(|l| l.lambda == c * lambda));
                // Power is kept exactly.
                let power: f64 = split
                    .lobes
                    .iter()
                    .map(|l| l.amplitude[1] * integral(l.lambda))
                    .sum();
                let want = 2.0 * integral(lambda);
                assert!((power / want - 1.0).abs() < 1e-12, "{power} vs {want}");
            }
        }
    }
}
