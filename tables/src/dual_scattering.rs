//! Dual-scattering fiber averages (Zinke, Yuksel, Weber, Keyser 2008, "Dual Scattering
//! Approximation for Fast Multiple Scattering in Hair"; used by Ren 2010 §3.2/§6 and Sadeghi
//! 2010 §5.2).
//!
//! Everything here is computed from any fiber model written as lobes ([`LobeDecomposition`]),
//! per RGB channel, as functions of the inclination θ of the light arriving at a fiber:
//!
//! * **Average attenuations** (Zinke eqs. 6 and 12):
//!   `ā_{f|b}(θ) = (1/π) ∫_{Ω_{f|b}} ∫_{−π/2}^{π/2} S((θ, φ_i), ω) cos θ dφ_i dω`.
//!   S depends only on φ = φ_o − φ_i and the hemispheres are taken relative to the incident
//!   azimuth (forward: |φ| > π/2, where TT lives — Zinke §3.1; this matches his `s̃_f`, "1/π for
//!   forward scattering directions"), so the average over φ_i is trivial and
//!   `ā_{f|b}(θ) = cos θ ∫_{Ω_{f|b}} S(θ, θ_o, φ) dω_o`. Their sum is the total energy
//!   `cos θ ∫_{S²} S dω_o` (tested against brute-force sphere quadrature).
//! * **Average shifts and widths** α_{f|b}, β²_{f|b}: Zinke takes them "directly from the BCSDF"
//!   without an equation. Here they are the lobe shifts α_p and variances β_p² weighted by each
//!   lobe's share of ā_{f|b} (per channel). Where a hemisphere receives nothing (θ = ±90°, a
//!   black channel), the plain mean over lobes is used so the moments stay finite.
//! * **Multiple backscattering** (Zinke §3.2): paths with one and three backward events,
//!   `Ā_1 = ā_b Σ_{i≥1} ā_f^{2i} = ā_b ā_f²/(1−ā_f²)` (eq. 11) and
//!   `Ā_3 = ā_b³ Σ_{i≥1} Σ_{j=0}^{i−1} Σ_{k≥j+1} ā_f^{2(i−j−1+k)} = ā_b³ ā_f²/(1−ā_f²)³` (eq. 13),
//!   `Ā_b = Ā_1 + Ā_3` (eq. 14). A path's longitudinal offset is Gaussian in θ_h with mean the
//!   sum of its events' shifts and variance the sum of their variances (shifts add because every
//!   event, forward or backward, maps θ_o = 2α − θ_i and the next fiber sees −θ_o). Δ̄_b and σ̄_b²
//!   are the mean and variance of that path mixture, summed in closed form
//!   ([`MomentsForm::PathSeries`], the default; tested against brute-force path sums). Zinke's
//!   printed fits (eqs. 16, 17) are available as [`MomentsForm::ZinkeFit`]; they agree with the
//!   series to first order in ā_b² for the α_f term, but eq. 16's α_b term carries the opposite
//!   sign of the series' first-order term (1 − 2ā_b²/… vs 1 + 2ā_b²/…), see the tests.
//! * **Backward scattering function** (Zinke eqs. 10, 15):
//!   `S_back = 2 Ā_b(θ) g(θ_h − Δ̄_b(θ), σ̄_b²(θ)) / (π cos²θ_d)` for backward φ, 0 forward, with
//!   the averages read at θ = (θ_i − θ_o)/2 (equal to θ_i on the specular cone, where the
//!   averages are defined; Ren writes this θ_d).
//! * **Forward scattering** along a shadow path (Zinke eqs. 5, 7, 8; Ren §3.2):
//!   `T_f = d_f ∏_k ā_f(θ_k)` (1 when the point is lit directly), `σ̄_f² = Σ_k β̄_f²(θ_k)`, and
//!   the spread `ψ_f = s̃_f(φ) g(θ_i − θ_ξ, 4σ̄_f²)/cos θ_ξ`, s̃_f = 1/π forward (the 4: σ̄_f² is
//!   in θ_h, the spread is in θ_i; see [`forward_spread`]).
//!
//! **Units of M.** The trait's M_p is a unit-area Gaussian in θ_h (Marschner 2003), so
//! `∫ M_p dθ_o = 2`; a lobe whose N_p integrates to E over φ contributes about 2E to ā_f + ā_b.
//! Zinke writes his longitudinal term as a unit-area Gaussian in θ_i + θ_o, which integrates to 1
//! over θ_o. The averages here integrate whatever S the model defines; if ā_f reaches 1 the
//! backscattering series diverges and construction fails with a typed error.
//!
//! **Numerics.** The φ-integrals of each N_p over the two hemispheres are tabulated once on a
//! fine θ_d grid (cubic interpolation); the θ_o integrals use Gauss–Legendre pieces placed around
//! each lobe's peak θ_o = 2α_p − θ (any width down to a fraction of a degree); results are
//! tabulated on a fine θ grid and linearly interpolated. [`fiber_averages_direct`] computes the
//! same quantities without either table, which the tests use to measure interpolation error.

use crate::angles::FiberAngles;
use crate::error::{ParamError, check};
use crate::quadrature::GaussLegendre;
use crate::scattering::{Rgb, ScatteringFunction};
use crate::special::gaussian;
use serde::{Deserialize, Serialize};
use std::f64::consts::{FRAC_PI_2, PI};

/// Below this `cos θ_d`, `1/cos²θ_d` is evaluated as `1/MIN_COS_THETA_D²` (= 10⁸). cos θ_d
/// vanishes only when one direction is along +u and the other along −u, a set of measure zero.
pub const MIN_COS_THETA_D: f64 = 1e-4;

/// Smallest variance handed to a Gaussian (rad²); a (0.0006°)² lobe is a delta for any table.
pub const MIN_VARIANCE: f64 = 1e-12;

/// Zinke's density factors; "between 0.6 and 0.8 give realistic results" (§3.1), 0.7 used.
pub const DEFAULT_DENSITY_FACTOR: f64 = 0.7;

/// `1/cos²θ_d`, bounded (see [`MIN_COS_THETA_D`]).
#[inline]
pub fn inverse_cos2_guarded(theta_d: f64) -> f64 {
    1.0 / theta_d.cos().abs().max(MIN_COS_THETA_D).powi(2)
}

/// A fiber model written as a sum of lobes `S = Σ_p M_p(θ_h) N_p(θ_d, φ) / cos²θ_d`, where each
/// longitudinal term M_p is (close to) a unit-area Gaussian in θ_h with shift α_p and width β_p.
/// Marschner 2003 and the artist-friendly model both have this shape; the fiber averages of
/// dual scattering are computed from it.
pub trait LobeDecomposition: Send + Sync {
    /// Number of lobes (R, TT, TRT for Marschner).
    fn lobe_count(&self) -> usize;
    /// Longitudinal shift α_p and width β_p of lobe `p`, in radians.
    fn lobe_shift_width(&self, p: usize) -> (f64, f64);
    /// The azimuthal term N_p(θ_d, φ) per channel (units 1/rad), φ = φ_o − φ_i.
    fn lobe_azimuthal(&self, p: usize, theta_d: f64, phi: f64) -> Rgb;

    /// The longitudinal term M_p(θ_h). Default: the unit-area Gaussian g(β_p², θ_h − α_p).
    fn lobe_longitudinal(&self, p: usize, theta_h: f64) -> f64 {
        let (alpha, beta) = self.lobe_shift_width(p);
        gaussian((beta * beta).max(MIN_VARIANCE), theta_h - alpha)
    }

    /// Azimuths (center, width) in radians where N_p(θ_d, ·) has peaks narrower than a few
    /// degrees, so integrators can put nodes there. Default: none (N_p is smooth).
    fn lobe_azimuthal_peaks(&self, _p: usize, _theta_d: f64) -> Vec<(f64, f64)> {
        Vec::new()
    }

    /// S reassembled from the lobes, with the guarded `1/cos²θ_d`.
    fn eval_lobes(&self, angles: &FiberAngles) -> Rgb {
        let (theta_h, theta_d) = (angles.theta_h(), angles.theta_d());
        let inv = inverse_cos2_guarded(theta_d);
        let mut s = [0.0; 3];
        for p in 0..self.lobe_count() {
            let m = self.lobe_longitudinal(p, theta_h);
            let n = self.lobe_azimuthal(p, theta_d, angles.phi);
            for c in 0..3 {
                s[c] += m * n[c] * inv;
            }
        }
        s
    }
}

// ---------------------------------------------------------------------------------------------
// Quadrature for peaked integrands.

/// A Gauss–Legendre rule on [a, b] with extra breakpoints around each peak (center, width):
/// the interval is cut at c, c ± 2w, c ± 6w, c ± 12w (clipped) and at `splits`, and every piece
/// gets `panels` 8-point panels. Integrands that are Gaussians of any width w ≥ 1e-6·(b−a)
/// are integrated to ~1e-13; beyond 12w a Gaussian is below e⁻⁷².
pub fn peaked_rule(
    a: f64,
    b: f64,
    peaks: &[(f64, f64)],
    splits: &[f64],
    panels: usize,
) -> GaussLegendre {
    let mut cuts = vec![a, b];
    cuts.extend(splits.iter().copied());
    for &(c, w) in peaks {
        let w = w.abs().max(1e-9);
        for k in [0.0, 2.0, 6.0, 12.0] {
            cuts.push(c - k * w);
            cuts.push(c + k * w);
        }
    }
    let mut cuts: Vec<f64> = cuts
        .into_iter()
        .filter(|x| x.is_finite() && *x >= a && *x <= b)
        .collect();
    cuts.sort_by(|x, y| x.total_cmp(y));
    cuts.dedup_by(|x, y| (*x - *y).abs() < 1e-13);
    let mut nodes = Vec::new();
    let mut weights = Vec::new();
    for w in cuts.windows(2) {
        let r = GaussLegendre::composite(8, panels.max(1), w[0], w[1]);
        nodes.extend(r.nodes);
        weights.extend(r.weights);
    }
    GaussLegendre { nodes, weights }
}

/// Peaks of lobe `p` listed for the whole circle, with their 2π images inside (−π, π].
fn azimuthal_peaks_on_circle(
    model: &dyn LobeDecomposition,
    p: usize,
    theta_d: f64,
) -> Vec<(f64, f64)> {
    let mut peaks = Vec::new();
    for (c, w) in model.lobe_azimuthal_peaks(p, theta_d) {
        for shift in [-2.0 * PI, 0.0, 2.0 * PI] {
            peaks.push((c + shift, w));
        }
    }
    peaks
}

/// `[∫_{|φ|>π/2} N_p dφ, ∫_{|φ|≤π/2} N_p dφ]` per channel at one θ_d: forward and backward.
pub fn azimuthal_hemisphere_integrals(
    model: &dyn LobeDecomposition,
    p: usize,
    theta_d: f64,
) -> [Rgb; 2] {
    let peaks = azimuthal_peaks_on_circle(model, p, theta_d);
    let splits = [-FRAC_PI_2, 0.0, FRAC_PI_2];
    let mut out = [[0.0; 3]; 2];
    for (hemi, ranges) in [
        (0, &[(-PI, -FRAC_PI_2), (FRAC_PI_2, PI)][..]),
        (1, &[(-FRAC_PI_2, FRAC_PI_2)][..]),
    ] {
        for &(a, b) in ranges {
            let rule = peaked_rule(a, b, &peaks, &splits, 4);
            for (&phi, &w) in rule.nodes.iter().zip(&rule.weights) {
                let n = model.lobe_azimuthal(p, theta_d, phi);
                for c in 0..3 {
                    out[hemi][c] += w * n[c];
                }
            }
        }
    }
    out
}

// ---------------------------------------------------------------------------------------------
// Per-inclination averages.

/// Zinke's per-event fiber averages at one inclination, per channel.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct FiberAverages {
    /// ā_f: fraction scattered into the forward hemisphere (Zinke eq. 6).
    pub a_f: Rgb,
    /// ā_b: fraction scattered into the backward hemisphere (Zinke eq. 12).
    pub a_b: Rgb,
    /// ᾱ_f, ᾱ_b: attenuation-weighted mean longitudinal shift (radians, in θ_h).
    pub alpha_f: Rgb,
    pub alpha_b: Rgb,
    /// β̄_f², β̄_b²: attenuation-weighted mean longitudinal variance (rad², in θ_h).
    pub beta2_f: Rgb,
    pub beta2_b: Rgb,
}

impl FiberAverages {
    fn lerp(&self, other: &Self, t: f64) -> Self {
        let l = |a: &Rgb, b: &Rgb| -> Rgb { std::array::from_fn(|c| a[c] + t * (b[c] - a[c])) };
        Self {
            a_f: l(&self.a_f, &other.a_f),
            a_b: l(&self.a_b, &other.a_b),
            alpha_f: l(&self.alpha_f, &other.alpha_f),
            alpha_b: l(&self.alpha_b, &other.alpha_b),
            beta2_f: l(&self.beta2_f, &other.beta2_f),
            beta2_b: l(&self.beta2_b, &other.beta2_b),
        }
    }
}

/// The fiber averages at inclination θ, given the hemisphere φ-integrals of each lobe as a
/// function of θ_d (`phi_integrals(p, θ_d) -> [forward, backward]`).
pub(crate) fn fiber_averages_with(
    model: &dyn LobeDecomposition,
    theta: f64,
    mut phi_integrals: impl FnMut(usize, f64) -> [Rgb; 2],
) -> FiberAverages {
    let lobes = model.lobe_count();
    let cos_theta = theta.cos().max(0.0);
    // Per lobe, per hemisphere, per channel: cos θ ∫ cos θ_o M_p N̄_p / cos²θ_d dθ_o.
    let mut share = vec![[[0.0; 3]; 2]; lobes];
    for (p, share_p) in share.iter_mut().enumerate() {
        let (alpha, beta) = model.lobe_shift_width(p);
        // Near grazing incidence (θ → ∓π/2) cos θ_o / cos²θ_d ≈ 4ε/(ε + δ)² at θ_o = ±(π/2 − ε),
        // δ = π/2 − |θ| (capped at 2·MIN_COS_THETA_D by the guard): a boundary layer with a
        // 1/ε tail. Grade the rule geometrically toward that pole as well as around the lobe.
        let layer = (FRAC_PI_2 - theta.abs()).max(2.0 * MIN_COS_THETA_D);
        let toward = if theta <= 0.0 { 1.0 } else { -1.0 };
        let splits: Vec<f64> = (0..12)
            .map(|k| toward * (FRAC_PI_2 - layer * 4f64.powi(k)))
            .collect();
        let rule = peaked_rule(
            -FRAC_PI_2,
            FRAC_PI_2,
            &[(2.0 * alpha - theta, 2.0 * beta)],
            &splits,
            4,
        );
        for (&theta_o, &w) in rule.nodes.iter().zip(&rule.weights) {
            let theta_d = 0.5 * (theta_o - theta);
            let m = model.lobe_longitudinal(p, 0.5 * (theta + theta_o));
            if m == 0.0 {
                continue;
            }
            let k = w * cos_theta * theta_o.cos() * m * inverse_cos2_guarded(theta_d);
            let n = phi_integrals(p, theta_d);
            for h in 0..2 {
                for c in 0..3 {
                    share_p[h][c] += k * n[h][c];
                }
            }
        }
    }
    let shapes: Vec<(f64, f64)> = (0..lobes)
        .map(|p| {
            let (a, b) = model.lobe_shift_width(p);
            (a, b * b)
        })
        .collect();
    let mut out = FiberAverages::default();
    for h in 0..2 {
        for c in 0..3 {
            let total: f64 = share.iter().map(|s| s[h][c]).sum();
            let (mut alpha, mut beta2) = (0.0, 0.0);
            if total > 0.0 && total.is_finite() {
                for (p, &(a, b2)) in shapes.iter().enumerate() {
                    let w = share[p][h][c] / total;
                    alpha += w * a;
                    beta2 += w * b2;
                }
            } else if lobes > 0 {
                alpha = shapes.iter().map(|s| s.0).sum::<f64>() / lobes as f64;
                beta2 = shapes.iter().map(|s| s.1).sum::<f64>() / lobes as f64;
            }
            let total = if total.is_finite() {
                total.max(0.0)
            } else {
                total
            };
            if h == 0 {
                (out.a_f[c], out.alpha_f[c], out.beta2_f[c]) = (total, alpha, beta2);
            } else {
                (out.a_b[c], out.alpha_b[c], out.beta2_b[c]) = (total, alpha, beta2);
            }
        }
    }
    out
}

/// The fiber averages at θ computed on demand, without any table (slow; a reference).
pub fn fiber_averages_direct(model: &dyn LobeDecomposition, theta: f64) -> FiberAverages {
    fiber_averages_with(model, theta, |p, theta_d| {
        azimuthal_hemisphere_integrals(model, p, theta_d)
    })
}

/// Hemisphere φ-integrals of every lobe on a uniform θ_d grid over [−π/2, π/2].
struct AzimuthalTable {
    samples: usize,
    /// `[lobe][node] -> [forward, backward]`.
    values: Vec<Vec<[Rgb; 2]>>,
}

impl AzimuthalTable {
    fn new(model: &dyn LobeDecomposition, samples: usize) -> Self {
        let values = (0..model.lobe_count())
            .map(|p| {
                (0..samples)
                    .map(|k| azimuthal_hemisphere_integrals(model, p, grid_value(k, samples)))
                    .collect()
            })
            .collect();
        Self { samples, values }
    }

    /// Catmull–Rom interpolation in θ_d (clamped at the ends, and at 0 from below: the
    /// integrals are non-negative).
    fn at(&self, p: usize, theta_d: f64) -> [Rgb; 2] {
        let v = &self.values[p];
        let (i, t) = grid_position(theta_d, self.samples);
        let at = |k: isize| v[k.clamp(0, self.samples as isize - 1) as usize];
        let (p0, p1, p2, p3) = (
            at(i as isize - 1),
            at(i as isize),
            at(i as isize + 1),
            at(i as isize + 2),
        );
        let mut out = [[0.0; 3]; 2];
        for h in 0..2 {
            for c in 0..3 {
                let (a, b, cc, d) = (p0[h][c], p1[h][c], p2[h][c], p3[h][c]);
                let y = b + 0.5
                    * t
                    * (cc - a
                        + t * (2.0 * a - 5.0 * b + 4.0 * cc - d + t * (3.0 * (b - cc) + d - a)));
                out[h][c] = y.max(0.0);
            }
        }
        out
    }
}

/// k-th node of a uniform grid of `n` nodes on [−π/2, π/2].
fn grid_value(k: usize, n: usize) -> f64 {
    -FRAC_PI_2 + PI * k as f64 / (n - 1) as f64
}

/// Cell index and fraction of `x` on that grid (x clamped to the grid).
fn grid_position(x: f64, n: usize) -> (usize, f64) {
    let u = ((x + FRAC_PI_2) / PI).clamp(0.0, 1.0) * (n - 1) as f64;
    let i = (u.floor() as usize).min(n - 2);
    (i, u - i as f64)
}

/// k-th node of the inclination grid θ = (π/2) sin(πs/2), s uniform on [−1, 1]: spacing
/// (π²/4)(2/(n−1)) at θ = 0, shrinking quadratically toward ±90° where the averages vary on
/// the scale π/2 − |θ| (grazing boundary layers).
fn inclination_grid_value(k: usize, n: usize) -> f64 {
    let s = -1.0 + 2.0 * k as f64 / (n - 1) as f64;
    FRAC_PI_2 * (FRAC_PI_2 * s).sin()
}

/// Cell index and fraction of θ on the inclination grid (θ clamped to [−π/2, π/2]).
fn inclination_grid_position(theta: f64, n: usize) -> (usize, f64) {
    let s = (theta / FRAC_PI_2).clamp(-1.0, 1.0).asin() / FRAC_PI_2;
    let u = 0.5 * (s + 1.0) * (n - 1) as f64;
    let i = (u.floor() as usize).min(n - 2);
    (i, u - i as f64)
}

// ---------------------------------------------------------------------------------------------
// Multiple backscattering.

/// Which formulas give Δ̄_b and σ̄_b².
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum MomentsForm {
    /// Mean and variance of the one- and three-backscatter path series, in closed form.
    #[default]
    PathSeries,
    /// Zinke 2008 eqs. 16 and 17 as printed (numerical fits).
    ZinkeFit,
}

/// Ā_b, Δ̄_b, σ̄_b² at one inclination, per channel.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct BackscatterMoments {
    /// Ā_b: total attenuation of multiple backscattering (Zinke eq. 14).
    pub attenuation: Rgb,
    /// Δ̄_b: mean longitudinal shift, radians in θ_h.
    pub shift: Rgb,
    /// σ̄_b²: longitudinal variance, rad² in θ_h.
    pub variance: Rgb,
}

/// One channel's (Ā_b, Δ̄_b, σ̄_b²) from the path series. `a_f` must be in [0, 1).
///
/// One-backscatter paths: 2i forward events (i ≥ 1), weight ā_b x^i with x = ā_f², offset mean
/// α_b + 2iα_f, variance β_b² + 2iβ_f²; i is geometric: E[i] = 1/(1−x), Var[i] = x/(1−x)².
/// Three-backscatter paths: 2N forward events, N − 1 a sum of three independent geometric counts
/// (Zinke's indices i−j−1, k−j−1, j), so E[N] = (1+2x)/(1−x), Var[N] = 3x/(1−x)²; weight ratio
/// Ā_3/Ā_1 = ā_b²/(1−x)². The mixture's variance is the law of total variance.
pub fn backscatter_series(
    a_f: f64,
    a_b: f64,
    alpha_f: f64,
    alpha_b: f64,
    beta2_f: f64,
    beta2_b: f64,
) -> (f64, f64, f64) {
    let x = a_f * a_f;
    let q = 1.0 - x;
    let a1 = a_b * x / q;
    let r = a_b * a_b / (q * q);
    let attenuation = a1 * (1.0 + r);

    let mean_i = 1.0 / q;
    let var_i = x / (q * q);
    let mean_n = (1.0 + 2.0 * x) / q;
    let var_n = 3.0 * x / (q * q);

    let s1 = alpha_b + 2.0 * alpha_f * mean_i;
    let s3 = 3.0 * alpha_b + 2.0 * alpha_f * mean_n;
    let within1 = beta2_b + 2.0 * beta2_f * mean_i + 4.0 * alpha_f * alpha_f * var_i;
    let within3 = 3.0 * beta2_b + 2.0 * beta2_f * mean_n + 4.0 * alpha_f * alpha_f * var_n;

    let shift = (s1 + r * s3) / (1.0 + r);
    let variance = (within1 + r * within3) / (1.0 + r) + r * (s3 - s1).powi(2) / (1.0 + r).powi(2);
    (attenuation, shift, variance.max(MIN_VARIANCE))
}

/// Zinke 2008 eqs. 16 and 17 as printed: (Δ̄_b, σ̄_b²). Eq. 17 gives σ̄_b; it is squared here.
pub fn backscatter_zinke_fit(
    a_f: f64,
    a_b: f64,
    alpha_f: f64,
    alpha_b: f64,
    beta2_f: f64,
    beta2_b: f64,
) -> (f64, f64) {
    let x = a_f * a_f;
    let q = 1.0 - x;
    let y = a_b * a_b;
    let shift =
        alpha_b * (1.0 - 2.0 * y / (q * q)) + alpha_f * (2.0 * q * q + 4.0 * x * y) / (q * q * q);
    let (bf, bb) = (beta2_f.max(0.0).sqrt(), beta2_b.max(0.0).sqrt());
    // Divide eq. 17's numerator and denominator by ā_b so ā_b → 0 has its finite limit.
    let num = (2.0 * beta2_f + beta2_b).sqrt() + y * (2.0 * beta2_f + 3.0 * beta2_b).sqrt();
    let den = 1.0 + y * (2.0 * bf + 3.0 * bb);
    let sigma = (1.0 + 0.7 * x) * num / den;
    (shift, (sigma * sigma).max(MIN_VARIANCE))
}

/// The backscatter moments of `avg` computed on demand (what the tabulated averages store),
/// by the path series or Zinke's fit.
pub fn moments_from(avg: &FiberAverages, form: MomentsForm) -> BackscatterMoments {
    let mut m = BackscatterMoments::default();
    for c in 0..3 {
        let args = (
            avg.a_f[c],
            avg.a_b[c],
            avg.alpha_f[c],
            avg.alpha_b[c],
            avg.beta2_f[c],
            avg.beta2_b[c],
        );
        let (att, shift, var) = backscatter_series(args.0, args.1, args.2, args.3, args.4, args.5);
        m.attenuation[c] = att;
        (m.shift[c], m.variance[c]) = match form {
            MomentsForm::PathSeries => (shift, var),
            MomentsForm::ZinkeFit => {
                backscatter_zinke_fit(args.0, args.1, args.2, args.3, args.4, args.5)
            }
        };
    }
    m
}

// ---------------------------------------------------------------------------------------------
// The precomputed averages.

/// Settings of the dual-scattering averages.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DualScatteringConfig {
    /// d_f: scales the forward-scattering transmittance T_f (Zinke eq. 5).
    pub density_forward: f64,
    /// d_b: scales S_back in S^D = S + d_b S_back (Zinke; Ren §3.2).
    pub density_backward: f64,
    /// Nodes of the θ grid on [−90°, 90°] the averages are tabulated on (≥ 3), spaced as
    /// θ = 90° sin(90° s) for uniform s (denser toward ±90°).
    pub theta_samples: usize,
    /// Nodes of the θ_d grid the azimuthal hemisphere integrals are tabulated on (≥ 4).
    pub theta_d_samples: usize,
    pub moments: MomentsForm,
}

impl Default for DualScatteringConfig {
    fn default() -> Self {
        Self {
            density_forward: DEFAULT_DENSITY_FACTOR,
            density_backward: DEFAULT_DENSITY_FACTOR,
            theta_samples: 513,
            theta_d_samples: 361,
            moments: MomentsForm::PathSeries,
        }
    }
}

impl DualScatteringConfig {
    pub fn validate(&self) -> Result<(), ParamError> {
        check(
            "dual_scattering.density_forward",
            self.density_forward,
            |d| (0.0..=1.0).contains(&d),
            "must be in [0, 1]",
        )?;
        check(
            "dual_scattering.density_backward",
            self.density_backward,
            |d| (0.0..=1.0).contains(&d),
            "must be in [0, 1]",
        )?;
        check(
            "dual_scattering.theta_samples",
            self.theta_samples as f64,
            |n| (3.0..=1e5).contains(&n),
            "must be in [3, 100000]",
        )?;
        check(
            "dual_scattering.theta_d_samples",
            self.theta_d_samples as f64,
            |n| (4.0..=1e5).contains(&n),
            "must be in [4, 100000]",
        )?;
        Ok(())
    }
}

/// Dual-scattering fiber averages of one fiber model, tabulated on a uniform θ grid.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DualScatteringAverages {
    config: DualScatteringConfig,
    averages: Vec<FiberAverages>,
    moments: Vec<BackscatterMoments>,
}

impl DualScatteringAverages {
    /// Integrates the model's lobes (f64) and tabulates every average. Fails if the
    /// configuration is invalid, a lobe is malformed, or ā_f ≥ 1 anywhere (the backscattering
    /// series would diverge: the model scatters more than it receives forward).
    pub fn new(
        model: &dyn LobeDecomposition,
        config: DualScatteringConfig,
    ) -> Result<Self, ParamError> {
        config.validate()?;
        for p in 0..model.lobe_count() {
            let (alpha, beta) = model.lobe_shift_width(p);
            check(
                "lobe shift α_p",
                alpha,
                |a| a.abs() < FRAC_PI_2,
                "must be in (−π/2, π/2) radians",
            )?;
            check(
                "lobe width β_p",
                beta,
                |b| b > 0.0 && b < PI,
                "must be in (0, π) radians",
            )?;
        }
        let table = AzimuthalTable::new(model, config.theta_d_samples);
        let n = config.theta_samples;
        let mut averages = Vec::with_capacity(n);
        let mut moments = Vec::with_capacity(n);
        for k in 0..n {
            let theta = inclination_grid_value(k, n);
            let avg = fiber_averages_with(model, theta, |p, theta_d| table.at(p, theta_d));
            for c in 0..3 {
                let name = "dual_scattering.average_forward_attenuation";
                check(
                    name,
                    avg.a_f[c],
                    |a| (0.0..1.0).contains(&a),
                    "must be in [0, 1) at every inclination; ā_f ≥ 1 makes the backscattering series diverge (normalize the fiber model, Sadeghi 2010 eq. 13)",
                )?;
                check(
                    "dual_scattering.average_backward_attenuation",
                    avg.a_b[c],
                    |a| a >= 0.0,
                    "must be ≥ 0",
                )?;
            }
            moments.push(moments_from(&avg, config.moments));
            averages.push(avg);
        }
        Ok(Self {
            config,
            averages,
            moments,
        })
    }

    pub fn config(&self) -> &DualScatteringConfig {
        &self.config
    }

    /// The tabulated fiber averages at inclination θ (linear interpolation).
    pub fn averages_at(&self, theta: f64) -> FiberAverages {
        let (i, t) = inclination_grid_position(theta, self.averages.len());
        self.averages[i].lerp(&self.averages[i + 1], t)
    }

    /// Ā_b, Δ̄_b, σ̄_b² at inclination θ (linear interpolation of the tabulated moments).
    pub fn moments_at(&self, theta: f64) -> BackscatterMoments {
        let (i, t) = inclination_grid_position(theta, self.moments.len());
        let (a, b) = (&self.moments[i], &self.moments[i + 1]);
        let l = |x: &Rgb, y: &Rgb| -> Rgb { std::array::from_fn(|c| x[c] + t * (y[c] - x[c])) };
        BackscatterMoments {
            attenuation: l(&a.attenuation, &b.attenuation),
            shift: l(&a.shift, &b.shift),
            variance: l(&a.variance, &b.variance),
        }
    }

    /// Zinke's f_back for direct light: `2 Ā_b g(θ_h − Δ̄_b, σ̄_b²)/(π cos²θ_d)` for backward
    /// φ (|φ| ≤ π/2), 0 otherwise. Not scaled by d_b.
    pub fn backward_scattering(&self, angles: &FiberAngles) -> Rgb {
        self.backward_scattering_spread(angles, [0.0; 3])
    }

    /// f_back for light that was already spread by forward scattering: the variance
    /// `forward_variance` (σ̄_f², rad² in θ_h) is added to σ̄_b² (Sadeghi 2010's f_back^scatter).
    pub fn backward_scattering_spread(&self, angles: &FiberAngles, forward_variance: Rgb) -> Rgb {
        if crate::angles::wrap_angle(angles.phi).abs() > FRAC_PI_2 {
            return [0.0; 3];
        }
        let theta = 0.5 * (angles.theta_i - angles.theta_o);
        let m = self.moments_at(theta);
        let k = 2.0 / PI * inverse_cos2_guarded(angles.theta_d());
        std::array::from_fn(|c| {
            let var = (m.variance[c] + forward_variance[c].max(0.0)).max(MIN_VARIANCE);
            k * m.attenuation[c] * gaussian(var, angles.theta_h() - m.shift[c])
        })
    }

    /// Starts a shadow path for the forward-scattering transmittance and spread.
    pub fn forward_path(&self) -> ForwardScatteringPath {
        ForwardScatteringPath {
            product: [1.0; 3],
            variance: [0.0; 3],
            shift: [0.0; 3],
            events: 0,
        }
    }
}

impl ScatteringFunction for DualScatteringAverages {
    fn name(&self) -> &'static str {
        "dual-scattering-back"
    }

    /// S_back (without d_b), so the backscattering lobe can be tabulated like any other S.
    fn eval(&self, angles: &FiberAngles) -> Rgb {
        self.backward_scattering(angles)
    }
}

/// Ren 2010 §3.2's BCSDF for multiple scattering, `S^D = S + d_b S_back`: the function the
/// multiple-scattering table I_G convolves with the forward spread ψ_f. For the artist model,
/// `single` is the normalized copy (Sadeghi eq. 13) the averages were computed from.
#[derive(Debug, Clone)]
pub struct DualScatteringBcsdf<S> {
    pub single: S,
    pub averages: DualScatteringAverages,
}

impl<S: ScatteringFunction> ScatteringFunction for DualScatteringBcsdf<S> {
    fn name(&self) -> &'static str {
        "dual-scattering-bcsdf"
    }

    fn eval(&self, angles: &FiberAngles) -> Rgb {
        let s = self.single.eval(angles);
        let back = self.averages.backward_scattering(angles);
        let d_b = self.averages.config().density_backward;
        std::array::from_fn(|c| s[c] + d_b * back[c])
    }
}

/// Accumulates forward-scattering events along a shadow path (Zinke eqs. 5 and 8).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ForwardScatteringPath {
    product: Rgb,
    variance: Rgb,
    shift: Rgb,
    events: u32,
}

impl ForwardScatteringPath {
    /// One fiber crossed, with the light at inclination θ in that fiber's frame.
    pub fn add_event(&mut self, averages: &DualScatteringAverages, theta: f64) {
        let a = averages.averages_at(theta);
        for c in 0..3 {
            self.product[c] *= a.a_f[c];
            self.variance[c] += a.beta2_f[c];
            self.shift[c] += a.alpha_f[c];
        }
        self.events += 1;
    }

    pub fn events(&self) -> u32 {
        self.events
    }

    /// T_f = d_f ∏ ā_f, or 1 when no fiber was crossed (direct illumination).
    pub fn transmittance(&self, density_forward: f64) -> Rgb {
        if self.events == 0 {
            [1.0; 3]
        } else {
            self.product.map(|p| density_forward * p)
        }
    }

    /// σ̄_f² = Σ β̄_f² (rad², in θ_h), 0 for direct illumination.
    pub fn variance(&self) -> Rgb {
        self.variance
    }

    /// Σ ᾱ_f (radians, in θ_h). Each event maps the incident inclination θ to θ − 2α, so the
    /// light reaches the shading point at θ_ξ − 2Σᾱ_f on average; Zinke and Ren drop this
    /// drift (their spread is centred on θ_ξ), it is exposed for callers that want it.
    pub fn shift(&self) -> Rgb {
        self.shift
    }
}

/// Zinke's spread of forward-scattered light (eq. 7; Ren §3.2's ψ_f):
/// `s̃_f(φ) g(θ_i − θ_ξ, 4σ̄_f²)/cos θ_ξ`, s̃_f = 1/π for forward azimuths (|φ| > π/2, φ between
/// the light's azimuth and the incident one), 0 otherwise.
///
/// `forward_variance` is σ̄_f² as [`ForwardScatteringPath::variance`] accumulates it: a sum of
/// lobe variances in θ_h. Each event maps θ_o = 2θ_h − θ_i, so in the incident inclination the
/// spread is 4σ̄_f² (Zinke's g is written in θ_i + θ_o = 2θ_h, where the same spread reads
/// σ̄_f²). It is clamped to [`MIN_VARIANCE`] (variance 0 is the delta of direct light, which
/// the caller handles), and cos θ_ξ to [`MIN_COS_THETA_D`].
pub fn forward_spread(theta_light: f64, theta_i: f64, phi: f64, forward_variance: f64) -> f64 {
    if crate::angles::wrap_angle(phi).abs() <= FRAC_PI_2 {
        return 0.0;
    }
    gaussian(
        (4.0 * forward_variance).max(MIN_VARIANCE),
        theta_i - theta_light,
    ) / (PI * theta_light.cos().max(MIN_COS_THETA_D))
}
