//! A stress test of the Marschner model over the inputs where naive implementations produce
//! NaN or Inf: grazing inclinations (θ → ±90°, exactly and nearly), φ at 0 and ±π, narrow
//! lobes (β_R down to 0.5°), absorption from 0 to 10⁴ and beyond, indices for which η′ ≥ 2
//! (η = 1.55 at steep θ_d, η up to 3) and near 1 (TT fold), eccentric fibers, both
//! longitudinal models, caustic smoothing on and off.
//!
//! Public so that a benchmark mode can run it with 10⁸ samples; the unit test runs 10⁶.

use super::{Lobe, Marschner, MarschnerParams};
use crate::angles::FiberAngles;
use crate::hard_case_sweep::SweepRng;
use crate::longitudinal::LongitudinalModel;
use crate::scattering::ScatteringFunction;
use std::f64::consts::{FRAC_PI_2, PI};

/// What the sweep found. Every sample evaluates S, each lobe's M_p and N_p, and S for an
/// oriented fiber; a value counts once per output channel.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SweepReport {
    pub samples: u64,
    pub configurations: usize,
    pub values_checked: u64,
    pub nan: u64,
    pub inf: u64,
    pub negative: u64,
    /// Samples whose TRT lobe took the η′ ≥ 2 branch of Hunz Algorithm 1.
    pub eta_prime_at_least_2: u64,
    /// Samples with at least one inclination exactly ±90°.
    pub exact_pole: u64,
    pub max_s: f64,
}

impl SweepReport {
    pub fn is_clean(&self) -> bool {
        self.nan == 0 && self.inf == 0 && self.negative == 0
    }

    fn record(&mut self, v: f64) {
        self.values_checked += 1;
        if v.is_nan() {
            self.nan += 1;
        } else if v.is_infinite() {
            self.inf += 1;
        } else if v < 0.0 {
            self.negative += 1;
        }
    }
}

/// The parameter sets the sweep cycles through (all valid).
pub fn sweep_configurations() -> Vec<MarschnerParams> {
    let mut out = vec![];
    for &eta in &[1.01, 1.2, 1.55, 2.0, 3.0] {
        for &beta_r in &[0.5, 7.5, 30.0] {
            for sigma in [[0.0; 3], [0.5447, 0.9061, 1.781], [1e4; 3], [1e300; 3]] {
                for &ecc in &[0.72, 0.85, 1.0] {
                    for model in [LongitudinalModel::Gaussian, LongitudinalModel::DEon] {
                        for smooth in [true, false] {
                            let (alpha_deg, beta_deg) = MarschnerParams::lobes_from_r(-5.0, beta_r);
                            out.push(MarschnerParams {
                                eta,
                                sigma_a: sigma,
                                alpha_deg,
                                beta_deg,
                                longitudinal_model: model,
                                smooth_caustics: smooth,
                                eccentricity: ecc,
                                ..MarschnerParams::default()
                            });
                        }
                    }
                }
            }
        }
    }
    out
}

/// An inclination biased toward the hard places: exactly ±90°, within 10⁻¹²…10⁻¹ of them,
/// exactly 0, or uniform.
fn hard_theta(rng: &mut SweepRng) -> f64 {
    let sign = if rng.uniform() < 0.5 { -1.0 } else { 1.0 };
    match rng.next_u64() % 8 {
        0 => sign * FRAC_PI_2,
        1 | 2 => sign * (FRAC_PI_2 - 10f64.powf(-1.0 - 11.0 * rng.uniform())),
        3 => 0.0,
        _ => (rng.uniform() - 0.5) * PI,
    }
}

/// A relative azimuth biased toward 0, ±π and tiny offsets from them.
fn hard_phi(rng: &mut SweepRng) -> f64 {
    let sign = if rng.uniform() < 0.5 { -1.0 } else { 1.0 };
    match rng.next_u64() % 8 {
        0 => 0.0,
        1 => PI,
        2 => sign * 10f64.powf(-12.0 * rng.uniform()),
        3 => sign * (PI - 10f64.powf(-1.0 - 11.0 * rng.uniform())),
        _ => (2.0 * rng.uniform() - 1.0) * PI,
    }
}

/// Evaluates `samples` hard inputs (spread over [`sweep_configurations`]) and counts NaN, Inf
/// and negative values. Deterministic for a given seed.
pub fn hard_case_sweep(samples: u64, seed: u64) -> SweepReport {
    let models: Vec<Marschner> = sweep_configurations()
        .into_iter()
        .map(|p| Marschner::new(p).expect("sweep configurations are valid"))
        .collect();
    let mut rng = SweepRng::new(seed);
    let mut report = SweepReport {
        configurations: models.len(),
        ..SweepReport::default()
    };
    for _ in 0..samples {
        let model = &models[(rng.next_u64() % models.len() as u64) as usize];
        let (ti, to) = (hard_theta(&mut rng), hard_theta(&mut rng));
        let angles = FiberAngles::new(ti, to, hard_phi(&mut rng));
        report.samples += 1;
        if ti.abs() == FRAC_PI_2 || to.abs() == FRAC_PI_2 {
            report.exact_pole += 1;
        }
        if model.trt_bravais_index(angles.theta_d()) >= 2.0 {
            report.eta_prime_at_least_2 += 1;
        }
        let s = model.eval(&angles);
        for v in s {
            report.record(v);
            if v.is_finite() {
                report.max_s = report.max_s.max(v);
            }
        }
        for lobe in Lobe::ALL {
            report.record(model.longitudinal(lobe, ti, to));
            for v in model.azimuthal(lobe, angles.theta_d(), angles.phi) {
                report.record(v);
            }
        }
        let phi_h = (2.0 * rng.uniform() - 1.0) * PI;
        for v in model.eval_oriented(&angles, phi_h) {
            report.record(v);
        }
    }
    report
}
