//! Kajiya-Kay in the form Ren et al. 2010 §4 tabulate:
//! `S(ω_i, ω_o) = K_d + K_s · cos^p(θ_i + θ_o) / cos θ_i`.
//!
//! **Sign convention.** Both directions point away from the fiber and `sin θ = u·ω`. Light
//! travelling along −ω_i that reflects off the cylinder keeps its tangential component, so it
//! leaves with `u·ω_o = −u·ω_i`, i.e. on the specular cone `θ_o = −θ_i`. There `θ_i + θ_o = 0`
//! and the lobe `cos^p(θ_i + θ_o)` peaks, so Ren's `+` is right for our convention.
//!
//! **Clamping.** `θ_i + θ_o ∈ [−π, π]`, so the cosine goes negative when the pair is more than
//! 90° off the cone; the lobe is clamped to 0 there (a negative base with a fractional `p`
//! would otherwise be NaN, and an odd integer `p` would give negative radiance).
//!
//! **Grazing guard.** `1/cos θ_i` is unbounded as θ_i → ±90°. In `L_o = D ∫ S L_i cos θ_i dω_i`
//! it only cancels the `cos θ_i` of the measure — which is why Ren's specular table
//! `I_s = ∫ G cos^p(θ_i+θ_o) dω_i` has neither. [`specular_term`](KajiyaKay::specular_term)
//! divides by `max(cos θ_i, MIN_COS_THETA_I)` with `MIN_COS_THETA_I = 1e-4`: S stays finite
//! (≤ 10⁴ K_s) and `S cos θ_i` differs from the lobe only within 0.0057° of the poles, a solid
//! angle of ~6e-4 sr·1e-4 that no quadrature or table resolves. Tables that want the exact
//! integrand use [`specular_lobe`](KajiyaKay::specular_lobe), which has no division at all.

use crate::angles::FiberAngles;
use crate::error::{ParamError, check, check_non_negative};
use crate::hard_case_sweep::{SweepReport, SweepRng};
use crate::scattering::{Rgb, ScatteringFunction};
use serde::{Deserialize, Serialize};

/// Below this `cos θ_i` the specular term divides by this value instead (see module docs).
pub const MIN_COS_THETA_I: f64 = 1e-4;

/// Largest accepted specular exponent; beyond it the lobe is narrower than f64 angles resolve
/// near the cone (cos^p(ε) ≈ exp(−pε²/2) needs ε ~ 1/√p ≫ 1e-8).
pub const MAX_EXPONENT: f64 = 1e5;

/// Parameters of the Kajiya-Kay model. `diffuse` (K_d) and `specular` (K_s) are RGB
/// multipliers applied at run time; the tables hold the monochrome terms.
///
/// Scale: a fiber under uniform unit radiance returns `∫ S_d cos θ_i dω_i = K_d π²` from the
/// diffuse part, so `K_d = albedo / π²` reflects `albedo` of uniform light.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct KajiyaKayParams {
    pub diffuse: [f64; 3],
    pub specular: [f64; 3],
    /// The specular exponent p (> 0).
    pub exponent: f64,
}

impl Default for KajiyaKayParams {
    /// A brown fiber: diffuse albedo (0.30, 0.20, 0.12) under uniform light, a white highlight.
    fn default() -> Self {
        let pi2 = std::f64::consts::PI * std::f64::consts::PI;
        Self {
            diffuse: [0.30 / pi2, 0.20 / pi2, 0.12 / pi2],
            specular: [0.05; 3],
            exponent: 40.0,
        }
    }
}

impl KajiyaKayParams {
    pub fn validate(&self) -> Result<(), ParamError> {
        const DIFFUSE: [&str; 3] = [
            "kajiya_kay.diffuse[0]",
            "kajiya_kay.diffuse[1]",
            "kajiya_kay.diffuse[2]",
        ];
        const SPECULAR: [&str; 3] = [
            "kajiya_kay.specular[0]",
            "kajiya_kay.specular[1]",
            "kajiya_kay.specular[2]",
        ];
        for c in 0..3 {
            check_non_negative(DIFFUSE[c], self.diffuse[c])?;
            check_non_negative(SPECULAR[c], self.specular[c])?;
        }
        check(
            "kajiya_kay.exponent",
            self.exponent,
            |p| p > 0.0 && p <= MAX_EXPONENT,
            "must be in (0, 1e5]",
        )?;
        Ok(())
    }
}

/// The Kajiya-Kay scattering function with validated parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KajiyaKay {
    params: KajiyaKayParams,
}

impl KajiyaKay {
    pub fn new(params: KajiyaKayParams) -> Result<Self, ParamError> {
        params.validate()?;
        Ok(Self { params })
    }

    pub fn params(&self) -> &KajiyaKayParams {
        &self.params
    }

    /// The monochrome diffuse term (K_d is applied by the caller): a constant 1.
    pub fn diffuse_term(&self, _angles: &FiberAngles) -> f64 {
        1.0
    }

    /// `max(cos(θ_i + θ_o), 0)^p` — the specular lobe without the `1/cos θ_i`, i.e. the
    /// integrand of Ren's `I_s` table.
    pub fn specular_lobe(&self, angles: &FiberAngles) -> f64 {
        specular_lobe(self.params.exponent, angles.theta_i + angles.theta_o)
    }

    /// The monochrome specular term `max(cos(θ_i+θ_o), 0)^p / max(cos θ_i, 1e-4)`.
    pub fn specular_term(&self, angles: &FiberAngles) -> f64 {
        self.specular_lobe(angles) / angles.theta_i.cos().max(MIN_COS_THETA_I)
    }
}

fn specular_lobe(exponent: f64, theta_sum: f64) -> f64 {
    let c = theta_sum.cos();
    if c <= 0.0 { 0.0 } else { c.powf(exponent) }
}

impl ScatteringFunction for KajiyaKay {
    fn name(&self) -> &'static str {
        "kajiya-kay"
    }

    fn eval(&self, angles: &FiberAngles) -> Rgb {
        let d = self.diffuse_term(angles);
        let s = self.specular_term(angles);
        std::array::from_fn(|c| self.params.diffuse[c] * d + self.params.specular[c] * s)
    }
}

/// Evaluates random valid models (K_d, K_s from 1e-9 to 1e3 or exactly 0, p from 0.01 to 1e5)
/// at angles concentrated near the poles; `samples` scalar values in total.
pub fn hard_case_sweep(samples: u64, seed: u64) -> SweepReport {
    let mut report = SweepReport::new("kajiya-kay");
    let mut rng = SweepRng::new(seed);
    let per_model = 1000u64;
    while report.samples < samples {
        let scale = |rng: &mut SweepRng| {
            if rng.uniform() < 0.1 {
                0.0
            } else {
                rng.log_range(1e-9, 1e3)
            }
        };
        let params = KajiyaKayParams {
            diffuse: [scale(&mut rng), scale(&mut rng), scale(&mut rng)],
            specular: [scale(&mut rng), scale(&mut rng), scale(&mut rng)],
            exponent: rng.log_range(1e-2, MAX_EXPONENT),
        };
        let model = KajiyaKay::new(params).expect("sweep parameters are valid by construction");
        for _ in 0..per_model.min(samples.div_ceil(5)) {
            let a = FiberAngles::new(
                rng.hard_inclination(),
                rng.hard_inclination(),
                rng.hard_azimuth(),
            );
            report.record_rgb(model.eval(&a));
            report.record(model.specular_term(&a));
            report.record(model.specular_lobe(&a));
        }
    }
    report
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::quadrature::{GaussLegendre, integrate_sphere};
    use std::f64::consts::{FRAC_PI_2, PI};

    /// C_n(a, b) = ∫_a^b cos^n t dt by the reduction formula
    /// C_n = [cos^{n−1} t sin t]_a^b / n + (n−1)/n · C_{n−2}.
    fn cos_power_integral(n: u32, a: f64, b: f64) -> f64 {
        match n {
            0 => b - a,
            1 => b.sin() - a.sin(),
            _ => {
                let nf = n as f64;
                let edge = |t: f64| t.cos().powi(n as i32 - 1) * t.sin();
                (edge(b) - edge(a)) / nf + (nf - 1.0) / nf * cos_power_integral(n - 2, a, b)
            }
        }
    }

    /// ∫_{S²} max(cos(θ_i+θ_o),0)^p dω_i in closed form for integer p: with t = θ_i + θ_o on
    /// the range where the cosine is positive, cos θ_i = cos t cos θ_o + sin t sin θ_o, so the
    /// integral is 2π [cos θ_o C_{p+1}(a,b) + sin θ_o (cos^{p+1} a − cos^{p+1} b)/(p+1)].
    fn specular_energy_closed_form(p: u32, theta_o: f64) -> f64 {
        let a = (theta_o - FRAC_PI_2).max(-FRAC_PI_2);
        let b = (theta_o + FRAC_PI_2).min(FRAC_PI_2);
        let q = p as f64 + 1.0;
        let sin_part = (a.cos().powf(q) - b.cos().powf(q)) / q;
        2.0 * PI * (theta_o.cos() * cos_power_integral(p + 1, a, b) + theta_o.sin() * sin_part)
    }

    #[test]
    fn diffuse_energy_is_kd_pi_squared() {
        // ∫ K_d cos θ_i dω_i = K_d · 2π ∫ cos²θ dθ = K_d π².
        let m = KajiyaKay::new(KajiyaKayParams::default()).unwrap();
        let a = FiberAngles::new(0.0, 0.3, 0.0);
        // integrate_sphere supplies the measure's cos θ; the integrand supplies the cos θ_i.
        let got = integrate_sphere(16, 4, |t, p| {
            m.diffuse_term(&FiberAngles::new(t, a.theta_o, p)) * t.cos()
        });
        let want = PI * PI;
        println!("diffuse ∫ cos θ_i dω_i: quadrature {got:.15}, closed form π² = {want:.15}");
        assert!((got - want).abs() < 1e-12);
    }

    #[test]
    fn specular_energy_matches_closed_form() {
        let mut worst: f64 = 0.0;
        for p in [1u32, 2, 5, 10, 40, 200] {
            let params = KajiyaKayParams {
                exponent: p as f64,
                ..Default::default()
            };
            let m = KajiyaKay::new(params).unwrap();
            for theta_o in [0.0, 0.3, -0.7, 1.2, -1.5] {
                // S does not depend on φ, so the φ integral is 2π; S cos θ_i (through the
                // guarded specular_term that eval uses) times the measure's cos θ_i.
                // The clamp puts a kink at θ_i + θ_o = ±π/2; split the rule there so a low p
                // (a kink in the first derivative) still converges fast.
                let kink = if theta_o >= 0.0 {
                    FRAC_PI_2 - theta_o
                } else {
                    -FRAC_PI_2 - theta_o
                };
                let quad: f64 = [(-FRAC_PI_2, kink), (kink, FRAC_PI_2)]
                    .iter()
                    .filter(|(a, b)| b > a)
                    .map(|&(a, b)| {
                        GaussLegendre::composite(8, 128, a, b).integrate(|t| {
                            let ang = FiberAngles::new(t, theta_o, 0.0);
                            m.specular_term(&ang) * t.cos() * t.cos()
                        })
                    })
                    .sum::<f64>()
                    * 2.0
                    * PI;
                let exact = specular_energy_closed_form(p, theta_o);
                let rel = (quad - exact).abs() / exact;
                worst = worst.max(rel);
                println!(
                    "p={p:4} θ_o={theta_o:+.2}: quadrature {quad:.12e}, closed form {exact:.12e}, rel {rel:.2e}"
                );
                assert!(rel < 1e-12, "p={p} θ_o={theta_o}");
            }
        }
        println!("worst relative error {worst:.2e}");
    }

    #[test]
    fn highlight_lies_on_the_specular_cone() {
        let m = KajiyaKay::new(KajiyaKayParams {
            exponent: 100.0,
            ..Default::default()
        })
        .unwrap();
        for theta_i in [-1.2, -0.4, 0.0, 0.5, 1.3] {
            let n = 20_001;
            let (best, _) = (0..n)
                .map(|k| -FRAC_PI_2 + PI * k as f64 / (n - 1) as f64)
                .map(|to| (to, m.specular_term(&FiberAngles::new(theta_i, to, 0.3))))
                .fold((0.0, -1.0), |acc, x| if x.1 > acc.1 { x } else { acc });
            println!(
                "θ_i={theta_i:+.2}: highlight at θ_o={best:+.5} (cone: {:+.5})",
                -theta_i
            );
            assert!((best + theta_i).abs() <= PI / (n - 1) as f64);
        }
    }

    #[test]
    fn clamped_lobe_and_grazing_guard_stay_finite() {
        let m = KajiyaKay::new(KajiyaKayParams {
            exponent: 2.5,
            ..Default::default()
        })
        .unwrap();
        // More than 90° off the cone: clamped to zero, not NaN from a negative base.
        assert_eq!(m.specular_lobe(&FiberAngles::new(1.2, 0.9, 0.0)), 0.0);
        // Exactly grazing incidence on the cone: bounded by 1/MIN_COS_THETA_I.
        let s = m.specular_term(&FiberAngles::new(FRAC_PI_2, -FRAC_PI_2, 0.0));
        assert_eq!(s, 1.0 / MIN_COS_THETA_I);
    }

    #[test]
    fn symmetric_in_azimuth() {
        let m = KajiyaKay::new(KajiyaKayParams::default()).unwrap();
        let mut rng = SweepRng::new(3);
        for _ in 0..10_000 {
            let (ti, to, phi) = (
                rng.hard_inclination(),
                rng.hard_inclination(),
                rng.range(-PI, PI),
            );
            let a = m.eval(&FiberAngles::new(ti, to, phi));
            let b = m.eval(&FiberAngles::new(ti, to, -phi));
            assert_eq!(a, b);
        }
    }

    #[test]
    fn validation_names_the_parameter() {
        let bad = KajiyaKayParams {
            exponent: 0.0,
            ..Default::default()
        };
        let e = KajiyaKay::new(bad).unwrap_err();
        assert!(e.to_string().contains("kajiya_kay.exponent"), "{e}");
        let mut bad = KajiyaKayParams::default();
        bad.specular[1] = f64::NAN;
        assert!(matches!(
            KajiyaKay::new(bad),
            Err(ParamError::NotFinite {
                name: "kajiya_kay.specular[1]",
                ..
            })
        ));
        let mut bad = KajiyaKayParams::default();
        bad.diffuse[2] = -0.1;
        assert!(matches!(
            KajiyaKay::new(bad),
            Err(ParamError::OutOfRange { .. })
        ));
        let json = serde_json::to_string(&KajiyaKayParams::default()).unwrap();
        let back: KajiyaKayParams = serde_json::from_str(&json).unwrap();
        assert_eq!(back, KajiyaKayParams::default());
        assert!(
            serde_json::from_str::<KajiyaKayParams>(
                r#"{"diffuse":[0,0,0],"specular":[0,0,0],"exponent":1,"p":2}"#
            )
            .is_err()
        );
    }

    #[test]
    fn hard_cases_never_produce_nan_or_inf() {
        let r = hard_case_sweep(400_000, 11);
        println!("{r}");
        assert!(r.samples >= 400_000);
        assert!(r.is_clean(), "{r}");
    }
}
