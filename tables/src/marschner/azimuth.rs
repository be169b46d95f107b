//! The azimuthal term N_p(θ_d, φ) of Marschner 2003 §4.3 (Hunz §3.3.2): scattering by the
//! circular cross section in the normal plane, with Bravais's indices η′, η″ standing in for
//! the 3D refraction, the cubic approximation of the exit angle φ(p, h), and Fresnel and
//! absorption attenuation A(p, h).
//!
//! Numerics: no quantity divides by cos θ_d. With `n = √(η² − sin²θ_d)` (≥ √(η² − 1) > 0),
//! `1/η′ = cos θ_d / n` and `η″ = η² cos θ_d / n`; every Fresnel factor below is written with
//! numerator and denominator multiplied through so that cos θ_d → 0 gives total reflection,
//! not 0/0. The Jacobian `|2 dφ/dh|⁻¹ = cos γ / (2 |dφ̂/dγ|)` has no `√(1 − h²)` division.

use crate::angles::wrap_angle;
use crate::scattering::Rgb;
use std::f64::consts::{FRAC_PI_2, PI};

const PI3: f64 = PI * PI * PI;

/// Floor of |dφ̂/dγ| where a fold (caustic) makes it vanish: the raw N_p has an integrable
/// 1/√|φ − φ_c| singularity there. The floor caps N_p at 5·10⁵·A within ~10⁻¹² rad of a fold
/// (|dφ̂/dγ| ≈ √(2|φ̂''| |φ − φ_c|)), which changes ∫N_p dφ by ~10⁻⁸ absolute, and keeps the
/// numerically ambiguous double root at the fold from returning 10¹⁰-sized spikes.
const MIN_SLOPE: f64 = 1e-6;

/// The per-θ_d quantities of the Bravais projection for a fiber of index η.
#[derive(Debug, Clone, Copy)]
pub struct Bravais {
    /// η²
    pub eta2: f64,
    /// cos θ_d ≥ 0
    pub cos_d: f64,
    /// n = √(η² − sin²θ_d)
    pub n: f64,
    /// 1/η′ = cos θ_d / n ∈ [0, 1)
    pub inv_eta_prime: f64,
    /// c = asin(1/η′), the constant of the cubic approximation of γ_t
    pub c: f64,
    /// cos θ_t of the refracted ray's inclination, sin θ_t = sin θ_d / η
    pub cos_theta_t: f64,
}

impl Bravais {
    pub fn new(eta: f64, theta_d: f64) -> Self {
        let (sin_d, cos_d) = theta_d.sin_cos();
        let cos_d = cos_d.max(0.0);
        let eta2 = eta * eta;
        let n = (eta2 - sin_d * sin_d).max(0.0).sqrt();
        let inv_eta_prime = (cos_d / n).clamp(0.0, 1.0);
        let c = inv_eta_prime.asin();
        let s_t = sin_d / eta;
        let cos_theta_t = (1.0 - s_t * s_t).max(0.0).sqrt();
        Self {
            eta2,
            cos_d,
            n,
            inv_eta_prime,
            c,
            cos_theta_t,
        }
    }

    /// η′ = n / cos θ_d (+∞ when cos θ_d = 0).
    pub fn eta_prime(&self) -> f64 {
        if self.cos_d > 0.0 {
            self.n / self.cos_d
        } else {
            f64::INFINITY
        }
    }

    /// Fresnel reflectance entering the fiber at offset h: the mean of the perpendicular
    /// component with index η′ and the parallel component with η″ (Marschner 2003 App. B).
    pub fn fresnel_entry(&self, h: f64) -> f64 {
        self.interfaces(h).entry
    }

    /// Fresnel reflectance from inside at the refracted angle γ_t (sin γ_t = h/η′), for both
    /// internal reflection and exit. The perpendicular part equals the entry one (Snell's law
    /// with the same η′ maps γ_t back to γ_i); the parallel part uses 1/η″ at angle γ_t.
    pub fn fresnel_internal(&self, h: f64) -> f64 {
        self.interfaces(h).internal
    }

    /// Both Fresnel factors and cos γ_t at offset h, sharing their square roots.
    fn interfaces(&self, h: f64) -> Interfaces {
        let cos_i = (1.0 - h * h).max(0.0).sqrt();
        let cd = self.cos_d;
        let s_t = h * self.inv_eta_prime;
        let cos_t = (1.0 - s_t * s_t).max(0.0).sqrt();
        // r_s = (cos γ_i − η′ cos γ_t)/(cos γ_i + η′ cos γ_t), times cos θ_d; by Snell's law
        // with η′ the internal r_s at γ_t is the same number.
        let rs = ratio_squared(cd * cos_i - self.n * cos_t, cd * cos_i + self.n * cos_t);
        // Entry r_p = (η″ cos γ_i − cos γ″_t)/(η″ cos γ_i + cos γ″_t), times n·η²cos θ_d, with
        // cos γ″_t = √q/(η² cos θ_d), q = η⁴cos²θ_d − h²n²; q ≤ 0 is total reflection.
        let e4c2 = self.eta2 * self.eta2 * cd * cd;
        let q = e4c2 - h * h * self.n * self.n;
        let rp_entry = if q <= 0.0 {
            1.0
        } else {
            let sq = self.n * q.sqrt();
            ratio_squared(e4c2 * cos_i - sq, e4c2 * cos_i + sq)
        };
        // Internal r_p with 1/η″ at γ_t: η″ sin γ_t = η² cos²θ_d h / n² ≤ h (η″ ≤ η′), so
        // there is no total internal reflection.
        let eta_pp = self.eta2 * cd / self.n;
        let s_out = (eta_pp * s_t).min(1.0);
        let cos_out = (1.0 - s_out * s_out).max(0.0).sqrt();
        let rp_internal = ratio_squared(cos_t - eta_pp * cos_out, cos_t + eta_pp * cos_out);
        Interfaces {
            entry: 0.5 * (rs + rp_entry),
            internal: 0.5 * (rs + rp_internal),
            cos_gamma_t: cos_t,
        }
    }

    /// Length of one internal chord at offset h in fiber radii: 2 cos γ_t / cos θ_t (the chord
    /// of the unit circle is 2 cos γ_t; dividing by cos θ_t turns the projected length into
    /// the 3D path length, which Hunz eq. 52 omits). cos θ_t ≥ √(1 − 1/η²) > 0.
    fn chord_length(&self, cos_gamma_t: f64) -> f64 {
        2.0 * cos_gamma_t / self.cos_theta_t
    }

    /// Transmittance of one internal chord at offset h: exp(−σ_a · 2 cos γ_t / cos θ_t), σ_a
    /// per unit fiber radius. σ_a = +∞ (or overflowing) gives 0: the chord is > 0 for |h| < 1.
    pub fn transmittance(&self, h: f64, sigma_a: &Rgb) -> Rgb {
        let length = self.chord_length(self.interfaces(h).cos_gamma_t);
        sigma_a.map(|s| (-(s * length)).exp())
    }

    /// The attenuation A(p, h) of Marschner 2003 eq. 9 / Hunz eq. 54, per channel.
    pub fn attenuation(&self, p: usize, h: f64, sigma_a: &Rgb) -> Rgb {
        let f = self.interfaces(h);
        if p == 0 {
            return [f.entry; 3];
        }
        // Through the fiber: enter, (p − 1) internal reflections, exit; p chords.
        let fresnel = (1.0 - f.entry) * (1.0 - f.internal) * f.internal.powi(p as i32 - 1);
        if fresnel == 0.0 {
            return [0.0; 3];
        }
        let path = p as f64 * self.chord_length(f.cos_gamma_t);
        sigma_a.map(|s| fresnel * (-(s * path)).exp())
    }
}

struct Interfaces {
    entry: f64,
    internal: f64,
    cos_gamma_t: f64,
}

fn ratio_squared(num: f64, den: f64) -> f64 {
    if den > 0.0 {
        let r = num / den;
        (r * r).min(1.0)
    } else {
        1.0
    }
}

/// The cubic exit-angle map of Marschner 2003 eq. 10 (Hunz eq. 46):
/// `φ̂(p, γ) = (6pc/π − 2) γ − (8pc/π³) γ³ + pπ`, written `a1 γ − a3 γ³ + pπ`.
#[derive(Debug, Clone, Copy)]
pub struct CubicExitMap {
    pub p: usize,
    pub a1: f64,
    pub a3: f64,
}

impl CubicExitMap {
    pub fn new(p: usize, c: f64) -> Self {
        let pc = p as f64 * c;
        Self {
            p,
            a1: 6.0 * pc / PI - 2.0,
            a3: 8.0 * pc / PI3,
        }
    }

    /// φ̂(p, γ) (not wrapped).
    pub fn phi(&self, gamma: f64) -> f64 {
        self.a1 * gamma - self.a3 * gamma * gamma * gamma + self.p as f64 * PI
    }

    /// dφ̂/dγ.
    pub fn slope(&self, gamma: f64) -> f64 {
        self.a1 - 3.0 * self.a3 * gamma * gamma
    }

    /// Every γ ∈ [−π/2, π/2] with φ̂(p, γ) ≡ φ (mod 2π); calls `visit` for each.
    pub fn for_each_root(&self, phi: f64, mut visit: impl FnMut(f64)) {
        // |φ̂ − pπ| is bounded by this over [−π/2, π/2]; try every 2π-image of φ inside it.
        let reach = self.a1.abs() * FRAC_PI_2 + self.a3 * PI3 / 8.0 + 1e-9;
        let base = self.p as f64 * PI - phi;
        let k_lo = ((base - reach) / (2.0 * PI)).ceil() as i64;
        let k_hi = ((base + reach) / (2.0 * PI)).floor() as i64;
        for k in k_lo..=k_hi {
            let target = phi + 2.0 * PI * k as f64 - self.p as f64 * PI;
            solve_odd_cubic(self.a1, self.a3, target, |g| {
                if g.abs() <= FRAC_PI_2 + 1e-9 {
                    visit(g.clamp(-FRAC_PI_2, FRAC_PI_2));
                }
            });
        }
    }
}

/// Real roots of `a1 γ − a3 γ³ = t` with a3 ≥ 0, by the trigonometric/hyperbolic forms that
/// stay accurate as a3 → 0 (where the cubic becomes linear) and never divide by zero.
fn solve_odd_cubic(a1: f64, a3: f64, t: f64, mut visit: impl FnMut(f64)) {
    if a3 <= 1e-6 * a1.abs() {
        // Nearly linear: γ = t/a1 and two Newton steps on the cubic term.
        if a1 == 0.0 {
            return;
        }
        let mut g = t / a1;
        for _ in 0..2 {
            let f = a1 * g - a3 * g * g * g - t;
            g -= f / (a1 - 3.0 * a3 * g * g);
        }
        visit(g);
        return;
    }
    // γ³ + Pγ + Q = 0 with P = −a1/a3, Q = t/a3.
    let p = -a1 / a3;
    let q = t / a3;
    if p > 0.0 {
        let r = 1.5 * q / p * (3.0 / p).sqrt();
        visit(-2.0 * (p / 3.0).sqrt() * (r.asinh() / 3.0).sinh());
    } else if p == 0.0 {
        visit((-q).cbrt());
    } else {
        let m = (-p / 3.0).sqrt();
        let r = 1.5 * q / p * (-3.0 / p).sqrt();
        if r.abs() <= 1.0 {
            let base = r.acos() / 3.0;
            for k in 0..3 {
                visit(2.0 * m * (base - 2.0 * PI * k as f64 / 3.0).cos());
            }
        } else {
            visit(-2.0 * q.signum() * m * (r.abs().acosh() / 3.0).cosh());
        }
    }
}

/// The raw azimuthal term `N_p = Σ_roots A(p, h) |2 dφ/dh|⁻¹` (Hunz eq. 55) with
/// `|2 dφ/dh|⁻¹ = cos γ / (2 |dφ̂/dγ|)`.
pub fn azimuthal_raw(b: &Bravais, p: usize, phi: f64, sigma_a: &Rgb) -> Rgb {
    let map = CubicExitMap::new(p, b.c);
    let mut sum = [0.0; 3];
    map.for_each_root(phi, |gamma| {
        let weight = gamma.cos() / (2.0 * map.slope(gamma).abs().max(MIN_SLOPE));
        if weight > 0.0 {
            let a = b.attenuation(p, gamma.sin(), sigma_a);
            for c in 0..3 {
                sum[c] += a[c] * weight;
            }
        }
    });
    sum
}

/// Constants of Hunz's Algorithm 1 (Marschner 2003 §4.3 caustic smoothing).
#[derive(Debug, Clone, Copy)]
pub struct CausticParams {
    /// azimuthal width w_c (radians)
    pub width: f64,
    /// glint scale k_G
    pub glint_scale: f64,
    /// fade range Δη′
    pub fade_range: f64,
    /// intensity limit Δh_M
    pub intensity_limit: f64,
}

/// Where the TRT caustic sits for a given θ_d and how strongly it is replaced.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CausticPlacement {
    /// φ_c ∈ [0, π]
    pub phi_c: f64,
    /// h_c = sin γ_c (0 in the merged branch η′ ≥ 2)
    pub h_c: f64,
    /// Δh
    pub delta_h: f64,
    /// blend t ∈ [0, 1]
    pub t: f64,
}

/// Lines 2–11 of Hunz Algorithm 1. The fold of the cubic (dφ̂/dγ = 0) exists only while
/// a1 = 12c/π − 2 > 0, i.e. η′ < 2 (c > π/6); beyond that the two caustics have merged at
/// φ = 0 and their glint fades out over η′ ∈ [2, 2 + Δη′].
pub fn caustic_placement(b: &Bravais, cp: &CausticParams) -> CausticPlacement {
    let map = CubicExitMap::new(2, b.c);
    if map.a1 > 0.0 {
        // Hunz eq. 57: γ_c = √((12c/π − 2) / (48c/π³)).
        let gamma_c = (map.a1 / (3.0 * map.a3)).sqrt();
        let cos_c = gamma_c.cos();
        // d²φ/dh² at the fold = φ̂''(γ_c) / cos²γ_c (the φ̂' term vanishes there).
        let curvature = (6.0 * map.a3 * gamma_c) / (cos_c * cos_c);
        let delta_h = if curvature > 0.0 {
            cp.intensity_limit
                .min(2.0 * (2.0 * cp.width / curvature).sqrt())
        } else {
            cp.intensity_limit
        };
        CausticPlacement {
            phi_c: wrap_angle(map.phi(gamma_c)).abs(),
            h_c: gamma_c.sin(),
            delta_h,
            t: 1.0,
        }
    } else {
        let eta_prime = b.eta_prime();
        CausticPlacement {
            phi_c: 0.0,
            h_c: 0.0,
            delta_h: cp.intensity_limit,
            t: 1.0 - smoothstep(2.0, 2.0 + cp.fade_range, eta_prime),
        }
    }
}

/// N_TRT with the caustic replaced by glints (lines 12–15 of Hunz Algorithm 1).
pub fn azimuthal_trt_smoothed(b: &Bravais, phi: f64, sigma_a: &Rgb, cp: &CausticParams) -> Rgb {
    let raw = azimuthal_raw(b, 2, phi, sigma_a);
    let pl = caustic_placement(b, cp);
    if pl.t <= 0.0 {
        return raw;
    }
    let inv_2w2 = 0.5 / (cp.width * cp.width);
    let norm = 1.0 / (cp.width * (2.0 * PI).sqrt());
    let dm = wrap_angle(phi - pl.phi_c);
    let dp = wrap_angle(phi + pl.phi_c);
    // g(x)/g(0) for the removal, g(x) for the glints.
    let em = (-dm * dm * inv_2w2).exp();
    let ep = (-dp * dp * inv_2w2).exp();
    let keep = (1.0 - pl.t * em) * (1.0 - pl.t * ep);
    let a_c = b.attenuation(2, pl.h_c, sigma_a);
    let glint = pl.t * cp.glint_scale * pl.delta_h * norm * (em + ep);
    std::array::from_fn(|c| raw[c] * keep + a_c[c] * glint)
}

/// Cubic Hermite step from 0 at `a` to 1 at `b` (GLSL smoothstep); +∞ gives 1.
fn smoothstep(a: f64, b: f64, x: f64) -> f64 {
    let t = ((x - a) / (b - a)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The real roots of a1 γ − a3 γ³ = t found by dense bracketing and bisection.
    fn brute_roots(a1: f64, a3: f64, t: f64) -> Vec<f64> {
        let f = |g: f64| a1 * g - a3 * g * g * g - t;
        let n = 20000;
        let (lo, hi) = (-4.0, 4.0);
        let mut roots = vec![];
        for i in 0..n {
            let (mut x0, mut x1) = (
                lo + (hi - lo) * i as f64 / n as f64,
                lo + (hi - lo) * (i + 1) as f64 / n as f64,
            );
            if f(x0) == 0.0 {
                roots.push(x0);
                continue;
            }
            if f(x0) * f(x1) < 0.0 {
                for _ in 0..200 {
                    let m = 0.5 * (x0 + x1);
                    if f(m).signum() == f(x0).signum() {
                        x0 = m
                    } else {
                        x1 = m
                    }
                }
                roots.push(0.5 * (x0 + x1));
            }
        }
        roots
    }

    #[test]
    fn cubic_roots_match_bisection() {
        let cases = [
            (-2.0, 0.0, 1.3),
            (-0.66, 0.09, 0.4),
            (1.0, 0.2, 0.3),
            (1.0, 0.2, -1.2),
            (0.5, 0.3, 0.0),
            (-1.9, 1e-8, 2.0),
            (0.0, 0.25, 0.7),
            (2.3, 0.25, 2.0),
        ];
        for (a1, a3, t) in cases {
            let mut got = vec![];
            solve_odd_cubic(a1, a3, t, |g| got.push(g));
            got.retain(|g| g.abs() < 4.0);
            got.sort_by(f64::total_cmp);
            let want = brute_roots(a1, a3, t);
            assert_eq!(
                got.len(),
                want.len(),
                "a1={a1} a3={a3} t={t}: {got:?} vs {want:?}"
            );
            for (g, w) in got.iter().zip(&want) {
                assert!((g - w).abs() < 1e-9, "a1={a1} a3={a3} t={t}: {g} vs {w}");
            }
        }
    }

    /// Fresnel at normal incidence and θ_d = 0: ((η − 1)/(η + 1))² for both components.
    #[test]
    fn fresnel_limits() {
        let eta = 1.55;
        let b = Bravais::new(eta, 0.0);
        let r0 = ((eta - 1.0) / (eta + 1.0)) * ((eta - 1.0) / (eta + 1.0));
        assert!((b.fresnel_entry(0.0) - r0).abs() < 1e-15);
        assert!((b.fresnel_internal(0.0) - r0).abs() < 1e-15);
        // Grazing offset: total reflection at the entry.
        assert!((b.fresnel_entry(1.0) - 1.0).abs() < 1e-12);
        // θ_d → 90°: η′ → ∞, η″ → 0: everything reflects, no NaN.
        let g = Bravais::new(eta, FRAC_PI_2);
        for &h in &[0.0, 0.3, 1.0] {
            assert!(g.fresnel_entry(h) > 1.0 - 1e-12);
            assert!(g.fresnel_internal(h).is_finite());
        }
        // Against the textbook form with η′ and η″ computed by division (fine at θ_d = 0.6).
        let td: f64 = 0.6;
        let b = Bravais::new(eta, td);
        let ep = (eta * eta - td.sin().powi(2)).sqrt() / td.cos();
        let epp = eta * eta / ep;
        for &h in &[0.0f64, 0.2, 0.5, 0.8, 0.95] {
            let ci: f64 = (1.0 - h * h).sqrt();
            let ct_s = (1.0 - (h / ep).powi(2)).sqrt();
            let rs = ((ci - ep * ct_s) / (ci + ep * ct_s)).powi(2);
            let st_p: f64 = h / epp;
            let rp = if st_p >= 1.0 {
                1.0
            } else {
                let ct_p = (1.0 - st_p * st_p).sqrt();
                ((epp * ci - ct_p) / (epp * ci + ct_p)).powi(2)
            };
            let want = 0.5 * (rs + rp);
            assert!((b.fresnel_entry(h) - want).abs() < 1e-13, "h={h}");
        }
    }

    #[test]
    fn transmittance_goes_to_zero_not_nan() {
        let b = Bravais::new(1.55, 1.2);
        let t = b.transmittance(0.3, &[0.0, 1e4, 1e300]);
        assert_eq!(t[0], 1.0);
        assert_eq!(t[1], 0.0);
        assert_eq!(t[2], 0.0);
        let t = b.transmittance(0.3, &[f64::INFINITY; 3]);
        assert_eq!(t, [0.0; 3]);
    }
}
