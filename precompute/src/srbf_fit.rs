//! Adaptive SRBF fitting of an environment map (Ren 2010 §3.1 and §7, after Tsai & Shih 2006).
//!
//! 1. The map is box-prefiltered onto a fit grid (default 256 × 128; [`EnvMap::downsampled`]
//!    preserves ∫L dω, so a small sun is spread, never aliased away).
//! 2. Initial lobes are placed greedily by importance: each goes where a lobe would remove the
//!    most residual energy (matching pursuit on a coarse copy of the residual).
//! 3. Centers and bandwidths are optimized by L-BFGS (argmin) on the variable-projection
//!    objective of [`crate::srbf_objective`]: the RGB amplitudes are the exact non-negative least
//!    squares solution for every trial, and the gradient is analytic. λ is kept inside
//!    [λ_min, λ_max] by a smooth (sigmoid) change of variable; centers move in the tangent
//!    plane and are renormalized.
//! 4. After each round (10 L-BFGS iterations by default; every later round keeps refining all
//!    lobes), lobes whose amplitude vanished are dropped and a new lobe is inserted where it
//!    removes the most residual energy — the paper's "at the location of the largest fitting
//!    error", scored by correlation with the residual on the full fit grid (the pixel of
//!    largest residual is always a candidate). This repeats until the relative MSE reaches the
//!    target (the paper's "mean squared error below 15%"), the lobe budget is spent, or four
//!    rounds in a row gain less than 10⁻⁶; a final 100-iteration polish ends the fit.
//!
//! The best state seen is returned; no NaN can escape (a non-finite evaluation ends the
//! round and the previous best is kept). Results do not depend on the thread count: all
//! parallel sums are reduced in a fixed order.

use crate::envmap::EnvMap;
use crate::srbf_objective::{FitGrid, evaluate, power_matched_amplitudes, relative_mse_of};
use argmin::core::{CostFunction, Error as ArgminError, Executor, Gradient};
use argmin::solver::linesearch::MoreThuenteLineSearch;
use argmin::solver::quasinewton::LBFGS;
use glam::DVec3;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::sync::Mutex;
use strandlight_tables::error::{ParamError, check};
use strandlight_tables::srbf::{self, SrbfLobe};

/// A round must lower the best relative MSE by this much (absolute: a part in 10⁶ of the map's
/// squared norm) to count as progress. Absolute, because on a map whose error is dominated by
/// a sun no lobe can resolve, the rest of the sky still improves by small absolute amounts ...
const STAGNATION_TOLERANCE: f64 = 1e-6;
/// ... and this many rounds in a row without progress end the fit.
const STAGNATION_ROUNDS: usize = 4;

/// The default largest bandwidth λ: the narrowest lobe, 1/√λ ≈ 3.6° rms. The paper's 64
/// (7.2° rms) leaves the detail between those widths to no lobe; the hair's R lobe (a few degrees)
/// sees it. Measured against the references of the eight shared maps (docs/BENCHMARKS.md,
/// "Narrower lobes"): 256 lowers the shadowed single-scattering error on six (quarry 0.056 →
/// 0.039, overcast 0.252 → 0.198, piz 0.344 → 0.287) and raises it on spruit and moonless
/// golf; 128 gains about half as much. The tables' 1/λ axis follows the lobes used, at the
/// same accuracy.
pub const DEFAULT_LAMBDA_MAX: f64 = 256.0;

/// What the fit may do. The defaults are the paper's, but for [`DEFAULT_LAMBDA_MAX`] and the
/// compact sources.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FitOptions {
    /// Lobes placed before the first optimization (paper: 30).
    pub initial_lobes: usize,
    /// The lobe budget (paper: 30–60 were needed; default 64).
    pub max_lobes: usize,
    /// Stop once the relative MSE Σw‖fit−map‖²/Σw‖map‖² is at or below this (paper: 0.15).
    pub target_relative_mse: f64,
    pub lambda_min: f64,
    /// The narrowest lobe allowed (default [`DEFAULT_LAMBDA_MAX`]; the paper's 64 is
    /// `--lambda-max 64`).
    pub lambda_max: f64,
    /// Width of the prefiltered fit grid (its height is half of it).
    pub grid_width: usize,
    /// L-BFGS iterations after each insertion (few: the next rounds keep refining every lobe).
    pub iterations_per_round: u64,
    /// L-BFGS iterations of the final polish of the best state.
    pub final_iterations: u64,
    /// Re-solve the final amplitudes so the lobes carry exactly the map's power per channel
    /// (see [`crate::srbf_objective::power_matched_amplitudes`]). On by default: rendering
    /// integrates light, so power matters more than the last digits of the L2 error.
    #[serde(default = "default_true")]
    pub preserve_power: bool,
    /// Compact bright sources (suns, lamps) taken out as directional lights before the fit
    /// ([`crate::compact_sources`]); `max_sources = 0` is the paper's pure SRBF fit. Applied by
    /// [`crate::SrbfSet::fit`]; [`fit`] fits the map it is given. Options saved without the
    /// field predate extraction: none.
    #[serde(default = "crate::compact_sources::SourceOptions::none")]
    pub sources: crate::compact_sources::SourceOptions,
    /// A wider disc radius (degrees) the sources take instead where it holds markedly more of
    /// the map's power ([`crate::compact_sources::extract_widening`]: extended lamps, a wide
    /// sun). Default [`crate::compact_sources::DEFAULT_WIDER_RADIUS_DEGREES`]: of the shared
    /// maps only the photo studio widens, and with the demo's procedural 6° sun both are
    /// closer to their references (docs/BENCHMARKS.md). Options saved without the field
    /// predate it: none.
    #[serde(default)]
    pub wider_source_radius: Option<f64>,
}

fn default_true() -> bool {
    true
}

impl Default for FitOptions {
    fn default() -> Self {
        Self {
            initial_lobes: 30,
            max_lobes: 64,
            target_relative_mse: 0.15,
            lambda_min: 16.0,
            lambda_max: DEFAULT_LAMBDA_MAX,
            grid_width: 256,
            iterations_per_round: 10,
            final_iterations: 100,
            preserve_power: true,
            sources: Default::default(),
            wider_source_radius: Some(crate::compact_sources::DEFAULT_WIDER_RADIUS_DEGREES),
        }
    }
}

impl FitOptions {
    pub fn validate(&self) -> Result<(), ParamError> {
        check(
            "initial_lobes",
            self.initial_lobes as f64,
            |v| v >= 1.0,
            "must be ≥ 1",
        )?;
        check(
            "max_lobes",
            self.max_lobes as f64,
            |v| (1.0..=4096.0).contains(&v),
            "must be in [1, 4096]",
        )?;
        check(
            "target_error",
            self.target_relative_mse,
            |v| v >= 0.0,
            "must be ≥ 0",
        )?;
        check("lambda_min", self.lambda_min, |v| v > 0.0, "must be > 0")?;
        check(
            "lambda_max",
            self.lambda_max,
            |v| v >= self.lambda_min && v <= 1e5,
            "must be in [lambda_min, 1e5]",
        )?;
        check(
            "grid_width",
            self.grid_width as f64,
            |v| v >= 8.0,
            "must be ≥ 8",
        )?;
        // The Gram matrix is exact (closed form) while ⟨G, L⟩ is a sum over grid pixels; that
        // sum is accurate only while G² spans about a pixel or more: λ ≤ W²/64.
        check(
            "lambda_max",
            self.lambda_max,
            |v| v <= (self.grid_width * self.grid_width) as f64 / 64.0,
            "must be ≤ grid_width²/64 (a narrower lobe falls between the fit grid's pixels; raise the grid width)",
        )?;
        check(
            "max_sources",
            self.sources.max_sources as f64,
            |v| v <= 64.0,
            "must be in [0, 64]",
        )?;
        check(
            "source_radius_degrees",
            self.sources.radius_degrees,
            |v| v > 0.0 && v <= 20.0,
            "must be in (0, 20]",
        )?;
        check(
            "source_min_norm_share",
            self.sources.min_norm_share,
            |v| v > 0.0 && v <= 1.0,
            "must be in (0, 1]",
        )?;
        if let Some(wider) = self.wider_source_radius {
            let narrow = self.sources.radius_degrees;
            check(
                "wider_source_radius",
                wider,
                |v| v > narrow && v <= 20.0,
                "must be wider than source_radius_degrees and at most 20",
            )?;
        }
        Ok(())
    }
}

/// The state after one round (optimization that follows an insertion).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RoundRecord {
    /// Lobes with non-zero amplitude.
    pub lobes: usize,
    /// The objective's relative MSE on the fit grid.
    pub relative_mse: f64,
    /// Objective evaluations so far.
    pub evaluations: usize,
}

/// A finished fit.
#[derive(Debug, Clone)]
pub struct SrbfFit {
    /// In radiance units, centers in the map's own frame.
    pub lobes: Vec<SrbfLobe>,
    /// The objective (closed-form Gram, grid projections) at the returned lobes.
    pub objective_relative_mse: f64,
    pub history: Vec<RoundRecord>,
    /// The prefiltered map the fit saw.
    pub grid_map: EnvMap,
}

#[derive(Debug, thiserror::Error)]
pub enum FitError {
    /// Names the option (e.g. `lambda_max` for `--lambda-max`) and what it must satisfy.
    #[error(transparent)]
    Option(#[from] ParamError),
    #[error("the environment map is black (zero everywhere): there is nothing to fit")]
    BlackMap,
}

/// Fits SRBF lights to `map`. `progress` is called after every round.
pub fn fit(
    map: &EnvMap,
    options: &FitOptions,
    progress: &mut dyn FnMut(&RoundRecord),
) -> Result<SrbfFit, FitError> {
    options.validate()?;
    let grid_map = map.downsampled(options.grid_width, options.grid_width / 2);
    let grid = FitGrid::new(&grid_map);
    if grid.radiance.iter().all(|p| p.iter().all(|&v| v == 0.0)) {
        return Err(FitError::BlackMap);
    }
    let coarse = CoarseResidual::new(&grid_map);
    let bounds = (options.lambda_min, options.lambda_max);

    let mut lobes: Vec<(DVec3, f64)> = Vec::new();
    let initial = options.initial_lobes.min(options.max_lobes);
    coarse.place_greedily(&grid, &mut lobes, initial, bounds);

    let mut log = RoundLog {
        history: Vec::new(),
        evaluations: 0,
        progress,
    };
    let (best_mse, best_lobes) =
        optimize_and_insert(&grid, &coarse, lobes, bounds, options, &mut log);
    let best_lobes = polish(&grid, best_lobes, best_mse, bounds, options, &mut log);
    let (lobes, objective_relative_mse) =
        radiance_lobes(&grid, &grid_map, &best_lobes, options.preserve_power);
    Ok(SrbfFit {
        lobes,
        objective_relative_mse,
        history: log.history,
        grid_map,
    })
}

/// The rounds' history as it grows, with the evaluation count it records and the caller's
/// progress callback, which hears of every round as it is recorded.
struct RoundLog<'a> {
    history: Vec<RoundRecord>,
    evaluations: usize,
    progress: &'a mut dyn FnMut(&RoundRecord),
}

impl RoundLog<'_> {
    fn record(&mut self, lobes: usize, relative_mse: f64) {
        let record = RoundRecord {
            lobes,
            relative_mse,
            evaluations: self.evaluations,
        };
        self.history.push(record);
        (self.progress)(&record);
    }
}

/// Steps 3 and 4 of the module docs: optimize, drop dead lobes, insert one where it removes the
/// most residual, until the target error, the lobe budget or stagnation. Returns the best
/// state seen (its relative MSE and its live lobes), not the last.
fn optimize_and_insert(
    grid: &FitGrid,
    coarse: &CoarseResidual,
    mut lobes: Vec<(DVec3, f64)>,
    bounds: (f64, f64),
    options: &FitOptions,
    log: &mut RoundLog,
) -> (f64, Vec<(DVec3, f64)>) {
    let mut best: Option<(f64, Vec<(DVec3, f64)>)> = None;
    let mut stalled_rounds = 0;
    // Where inserted lobes died (NNLS gave them zero): not tried again.
    let mut tabu: Vec<DVec3> = Vec::new();
    let mut inserted: Option<DVec3> = None;
    for _round in 0..3 * options.max_lobes + 3 {
        let round = optimize_round(grid, &lobes, bounds, options, &mut log.evaluations);
        lobes = round.lobes;
        let ev = evaluate(grid, &centers(&lobes), &lambdas(&lobes));
        // Dead lobes (zero amplitude in every channel) are free slots for insertion.
        let alive: Vec<(DVec3, f64)> = lobes
            .iter()
            .zip(&ev.amplitudes)
            .filter(|(_, a)| a.iter().any(|&v| v > 0.0))
            .map(|(l, _)| *l)
            .collect();
        if let Some(xi) = inserted.take()
            && !alive.iter().any(|(c, _)| c.dot(xi) > 0.999)
        {
            tabu.push(xi);
        }
        log.record(alive.len(), ev.relative_mse);
        if best.as_ref().is_none_or(|(e, _)| ev.relative_mse < *e) {
            best = Some((ev.relative_mse, alive.clone()));
        }
        if ev.relative_mse <= options.target_relative_mse || alive.len() >= options.max_lobes {
            break;
        }
        // Stagnation: insertions keep dying or no longer reduce the error (e.g. a sun narrower
        // than λ_max allows dominates the residual). More rounds would only burn time.
        let history = &log.history;
        let improved = history.len() < 2 || {
            let previous_best = history[..history.len() - 1]
                .iter()
                .map(|r| r.relative_mse)
                .fold(f64::INFINITY, f64::min);
            ev.relative_mse < previous_best - STAGNATION_TOLERANCE
        };
        stalled_rounds = if improved { 0 } else { stalled_rounds + 1 };
        if stalled_rounds >= STAGNATION_ROUNDS {
            break;
        }
        lobes = alive;
        // Amplitudes re-solved for the surviving lobes.
        let amplitudes = evaluate(grid, &centers(&lobes), &lambdas(&lobes)).amplitudes;
        let new_lobe = coarse.best_insertion(grid, &lobes, &amplitudes, bounds, &tabu);
        lobes.push(new_lobe);
        inserted = Some(new_lobe.0);
    }
    best.expect("at least one round ran")
}

/// The final polish: `final_iterations` of L-BFGS from the best state, kept (and recorded as a
/// round) only if it lowers the error.
fn polish(
    grid: &FitGrid,
    best_lobes: Vec<(DVec3, f64)>,
    best_mse: f64,
    bounds: (f64, f64),
    options: &FitOptions,
    log: &mut RoundLog,
) -> Vec<(DVec3, f64)> {
    if options.final_iterations == 0 {
        return best_lobes;
    }
    let polish = FitOptions {
        iterations_per_round: options.final_iterations,
        ..options.clone()
    };
    let polished = optimize_round(grid, &best_lobes, bounds, &polish, &mut log.evaluations).lobes;
    let ev = evaluate(grid, &centers(&polished), &lambdas(&polished));
    if ev.relative_mse < best_mse {
        let alive = ev
            .amplitudes
            .iter()
            .filter(|a| a.iter().any(|&v| v > 0.0))
            .count();
        log.record(alive, ev.relative_mse);
        polished
    } else {
        best_lobes
    }
}

/// The fitted lobes in radiance units with their amplitudes solved once more (power-matched if
/// `preserve_power`), dead ones dropped, and the objective's relative MSE at those amplitudes.
fn radiance_lobes(
    grid: &FitGrid,
    grid_map: &EnvMap,
    lobes: &[(DVec3, f64)],
    preserve_power: bool,
) -> (Vec<SrbfLobe>, f64) {
    let mut ev = evaluate(grid, &centers(lobes), &lambdas(lobes));
    if preserve_power {
        let power = grid_map.integral().map(|p| p / grid.scale);
        ev.amplitudes = power_matched_amplitudes(grid, &centers(lobes), &lambdas(lobes), power);
        ev.relative_mse = relative_mse_of(grid, &centers(lobes), &lambdas(lobes), &ev.amplitudes);
    }
    let fitted = lobes
        .iter()
        .zip(&ev.amplitudes)
        .filter(|(_, a)| a.iter().any(|&v| v > 0.0))
        .map(|((xi, lambda), a)| SrbfLobe {
            center: xi.to_array(),
            lambda: *lambda,
            amplitude: a.map(|v| v * grid.scale),
        })
        .collect();
    (fitted, ev.relative_mse)
}

fn centers(lobes: &[(DVec3, f64)]) -> Vec<DVec3> {
    lobes.iter().map(|l| l.0).collect()
}
fn lambdas(lobes: &[(DVec3, f64)]) -> Vec<f64> {
    lobes.iter().map(|l| l.1).collect()
}

// ---------------------------------------------------------------------------------------------
// Placement by importance.

/// The residual on a coarse grid (32 × 16) and candidate centers on a finer one (64 × 32):
/// enough to choose where a lobe goes; the optimizer refines it.
struct CoarseResidual {
    width: usize,
    height: usize,
    candidates: Vec<DVec3>,
}

impl CoarseResidual {
    fn new(grid_map: &EnvMap) -> Self {
        let width = grid_map.width().min(32);
        let height = (width / 2).max(1);
        let cw = grid_map.width().min(64);
        let ch = (cw / 2).max(1);
        let candidates = (0..cw * ch)
            .map(|i| crate::envmap::pixel_direction(i % cw, i / cw, cw, ch))
            .collect();
        Self {
            width,
            height,
            candidates,
        }
    }

    /// The lobe to insert after a round: like matching pursuit, but scored against the residual
    /// on the full fit grid, where it is (nearly) orthogonal to the current lobes, so a spot
    /// the current lobes already fit as well as they can (a sun narrower than λ_max allows)
    /// scores low instead of attracting lobes that NNLS would zero. Candidates: a 32 × 16 grid
    /// of centers plus the pixel of largest residual; λ among a few values in the bounds.
    fn best_insertion(
        &self,
        grid: &FitGrid,
        lobes: &[(DVec3, f64)],
        amplitudes: &[[f64; 3]],
        (lo, hi): (f64, f64),
        tabu: &[DVec3],
    ) -> (DVec3, f64) {
        let residual: Vec<[f64; 3]> = (0..grid.dirs.len())
            .into_par_iter()
            .map(|i| {
                let d = grid.dirs[i];
                let mut r = grid.radiance[i];
                for ((xi, lambda), a) in lobes.iter().zip(amplitudes) {
                    let g = srbf::kernel(d.dot(*xi), *lambda);
                    (0..3).for_each(|c| r[c] -= a[c] * g);
                }
                r
            })
            .collect();
        let largest = (0..residual.len())
            .max_by(|&a, &b| {
                let s =
                    |i: usize| residual[i].iter().sum::<f64>() * grid.row_weight[i / grid.width];
                s(a).total_cmp(&s(b)).then(b.cmp(&a))
            })
            .unwrap_or(0);
        let (cw, ch) = (grid.width.min(32), (grid.width.min(32) / 2).max(1));
        let mut candidates: Vec<DVec3> = (0..cw * ch)
            .map(|i| crate::envmap::pixel_direction(i % cw, i / cw, cw, ch))
            .collect();
        candidates.push(grid.dirs[largest]);
        let tabu_cos = (std::f64::consts::TAU / 64.0).cos();
        let trial_lambdas = [lo, (lo * hi).sqrt(), hi];
        let scored: Vec<(f64, DVec3, f64)> = candidates
            .par_iter()
            .map(|&xi| {
                let mut best = (f64::NEG_INFINITY, xi, lo);
                if tabu.iter().any(|t| t.dot(xi) > tabu_cos) {
                    return best;
                }
                for &lambda in &trial_lambdas {
                    let proj = grid.correlate(xi, lambda, &residual);
                    let score = proj.iter().map(|p| p.max(0.0).powi(2)).sum::<f64>()
                        / srbf::squared_norm(lambda);
                    if score > best.0 {
                        best = (score, xi, lambda);
                    }
                }
                best
            })
            .collect();
        let best = scored
            .into_iter()
            .fold((f64::NEG_INFINITY, candidates[0], lo), |b, s| {
                if s.0 > b.0 { s } else { b }
            });
        (best.1, best.2)
    }

    fn place_greedily(
        &self,
        grid: &FitGrid,
        lobes: &mut Vec<(DVec3, f64)>,
        count: usize,
        bounds: (f64, f64),
    ) {
        let pixels = grid.radiance.iter().map(|p| p.map(|v| v as f32)).collect();
        let residual = EnvMap::from_pixels(grid.width, grid.height, pixels)
            .downsampled(self.width, self.height);
        self.place_greedily_from(residual, lobes, count, bounds);
    }

    /// Matching pursuit: the lobe (center among the candidates, λ among a few values in the
    /// bounds) that maximizes Σ_c max(0, ⟨G, R_c⟩)² / ‖G‖², the energy it would remove; then
    /// its share is subtracted from the residual and the next lobe is chosen.
    fn place_greedily_from(
        &self,
        mut residual: EnvMap,
        lobes: &mut Vec<(DVec3, f64)>,
        count: usize,
        (lo, hi): (f64, f64),
    ) {
        let trial_lambdas = [lo, (lo * hi).sqrt(), hi];
        let (w, h) = (residual.width(), residual.height());
        let weights: Vec<f64> = (0..h).map(|y| residual.row_solid_angle(y)).collect();
        let dirs: Vec<DVec3> = (0..w * h)
            .map(|i| residual.direction(i % w, i / w))
            .collect();
        for _ in 0..count {
            let res = residual.pixels();
            let scored: Vec<(f64, usize, f64, [f64; 3])> = self
                .candidates
                .par_iter()
                .enumerate()
                .map(|(ci, &xi)| {
                    let mut best = (f64::NEG_INFINITY, ci, lo, [0.0; 3]);
                    for &lambda in &trial_lambdas {
                        let mut proj = [0.0; 3];
                        for (i, d) in dirs.iter().enumerate() {
                            let g = weights[i / w] * srbf::kernel(d.dot(xi), lambda);
                            (0..3).for_each(|c| proj[c] += g * res[i][c] as f64);
                        }
                        let norm2 = srbf::squared_norm(lambda);
                        let score: f64 =
                            proj.iter().map(|p| p.max(0.0).powi(2)).sum::<f64>() / norm2;
                        if score > best.0 {
                            best = (score, ci, lambda, proj.map(|p| p.max(0.0) / norm2));
                        }
                    }
                    best
                })
                .collect();
            // First maximum in candidate order: deterministic.
            let (score, ci, lambda, amp) =
                scored
                    .into_iter()
                    .fold((f64::NEG_INFINITY, 0, lo, [0.0; 3]), |b, s| {
                        if s.0 > b.0 { s } else { b }
                    });
            let xi = self.candidates[ci];
            let _ = score;
            lobes.push((xi, lambda));
            let mut px = residual.pixels().to_vec();
            for (i, d) in dirs.iter().enumerate() {
                let g = srbf::kernel(d.dot(xi), lambda);
                (0..3).for_each(|c| px[i][c] -= (amp[c] * g) as f32);
            }
            residual = EnvMap::from_pixels(w, h, px);
        }
    }
}

// ---------------------------------------------------------------------------------------------
// One L-BFGS round.

struct RoundResult {
    lobes: Vec<(DVec3, f64)>,
}

/// The parametrization of one round: each lobe moves in the tangent plane at its starting
/// center (u, v) and λ = lo + (hi − lo)·σ(t).
struct RoundProblem<'a> {
    grid: &'a FitGrid,
    origin: Vec<(DVec3, DVec3, DVec3)>,
    bounds: (f64, f64),
    /// The best (cost, params) seen, and the evaluation count.
    best: &'a Mutex<(f64, Vec<f64>, usize)>,
    /// Cost and gradient of the last parameter vector (argmin asks for them separately).
    cache: &'a Mutex<Option<CachedEvaluation>>,
}

/// Parameters, cost and gradient of the last evaluation.
type CachedEvaluation = (Vec<f64>, f64, Vec<f64>);

fn sigmoid(t: f64) -> f64 {
    1.0 / (1.0 + (-t).exp())
}

impl RoundProblem<'_> {
    fn cost_and_gradient(&self, p: &[f64]) -> (f64, Vec<f64>) {
        if let Some((q, c, g)) = self.cache.lock().unwrap().as_ref()
            && q.as_slice() == p
        {
            return (*c, g.clone());
        }
        let lobes = problem_lobes(&self.origin, self.bounds, p);
        let ev = evaluate(self.grid, &centers(&lobes), &lambdas(&lobes));
        let (lo, hi) = self.bounds;
        let mut grad = vec![0.0; p.len()];
        for (k, (xi0, e1, e2)) in self.origin.iter().enumerate() {
            let n = *xi0 + *e1 * p[3 * k] + *e2 * p[3 * k + 1];
            let len = n.length();
            let xi = n / len;
            let dxi = |e: DVec3| (e - xi * xi.dot(e)) / len;
            grad[3 * k] = ev.grad_center[k].dot(dxi(*e1));
            grad[3 * k + 1] = ev.grad_center[k].dot(dxi(*e2));
            let s = sigmoid(p[3 * k + 2]);
            grad[3 * k + 2] = ev.grad_lambda[k] * (hi - lo) * s * (1.0 - s);
        }
        let cost = ev.relative_mse;
        let finite = cost.is_finite() && grad.iter().all(|g| g.is_finite());
        let (cost, grad) = if finite {
            (cost, grad)
        } else {
            (f64::INFINITY, vec![0.0; p.len()])
        };
        {
            let mut best = self.best.lock().unwrap();
            best.2 += 1;
            if cost < best.0 {
                best.0 = cost;
                best.1 = p.to_vec();
            }
        }
        *self.cache.lock().unwrap() = Some((p.to_vec(), cost, grad.clone()));
        (cost, grad)
    }
}

impl CostFunction for RoundProblem<'_> {
    type Param = Vec<f64>;
    type Output = f64;
    fn cost(&self, p: &Vec<f64>) -> Result<f64, ArgminError> {
        Ok(self.cost_and_gradient(p).0)
    }
}

impl Gradient for RoundProblem<'_> {
    type Param = Vec<f64>;
    type Gradient = Vec<f64>;
    fn gradient(&self, p: &Vec<f64>) -> Result<Vec<f64>, ArgminError> {
        Ok(self.cost_and_gradient(p).1)
    }
}

fn tangent_basis(xi: DVec3) -> (DVec3, DVec3) {
    let helper = if xi.y.abs() < 0.9 { DVec3::Y } else { DVec3::X };
    let e1 = xi.cross(helper).normalize();
    (e1, xi.cross(e1))
}

fn optimize_round(
    grid: &FitGrid,
    lobes: &[(DVec3, f64)],
    (lo, hi): (f64, f64),
    options: &FitOptions,
    evaluations: &mut usize,
) -> RoundResult {
    let origin: Vec<_> = lobes
        .iter()
        .map(|(xi, _)| {
            let (e1, e2) = tangent_basis(*xi);
            (*xi, e1, e2)
        })
        .collect();
    let mut init = Vec::with_capacity(3 * lobes.len());
    for (_, lambda) in lobes {
        let s = if hi > lo {
            ((lambda - lo) / (hi - lo)).clamp(0.02, 0.98)
        } else {
            0.5
        };
        init.extend_from_slice(&[0.0, 0.0, (s / (1.0 - s)).ln()]);
    }
    let best = Mutex::new((f64::INFINITY, init.clone(), 0));
    let cache = Mutex::new(None);
    let problem = RoundProblem {
        grid,
        origin: origin.clone(),
        bounds: (lo, hi),
        best: &best,
        cache: &cache,
    };
    let (start_cost, _) = problem.cost_and_gradient(&init);
    if options.iterations_per_round > 0 && start_cost.is_finite() {
        let solver = LBFGS::new(MoreThuenteLineSearch::new(), 8)
            .with_tolerance_cost(1e-12 * start_cost.max(1e-12))
            .and_then(|s| s.with_tolerance_grad(1e-9));
        if let Ok(solver) = solver {
            // A line-search failure ends the round early; the best point seen is kept below.
            let r = Executor::new(problem, solver)
                .configure(|state| {
                    state
                        .param(init.clone())
                        .max_iters(options.iterations_per_round)
                })
                .run();
            if std::env::var_os("STRANDLIGHT_FIT_DEBUG").is_some() {
                match r {
                    Ok(r) => eprintln!(
                        "round: iters {} cost {} status {:?}",
                        r.state.iter, r.state.best_cost, r.state.termination_status
                    ),
                    Err(e) => eprintln!("round error: {e}"),
                }
            }
        }
    }
    let (best_cost, best_params, count) = best.into_inner().unwrap();
    *evaluations += count + 1;
    // The sigmoid start point moves a λ that sat exactly on a bound a little; never let that
    // make a round worse than the state it started from.
    let incoming = evaluate(grid, &centers(lobes), &lambdas(lobes)).relative_mse;
    if incoming <= best_cost {
        return RoundResult {
            lobes: lobes.to_vec(),
        };
    }
    RoundResult {
        lobes: problem_lobes(&origin, (lo, hi), &best_params),
    }
}

fn problem_lobes(
    origin: &[(DVec3, DVec3, DVec3)],
    (lo, hi): (f64, f64),
    p: &[f64],
) -> Vec<(DVec3, f64)> {
    origin
        .iter()
        .enumerate()
        .map(|(k, (xi0, e1, e2))| {
            let n = *xi0 + *e1 * p[3 * k] + *e2 * p[3 * k + 1];
            (n.normalize(), lo + (hi - lo) * sigmoid(p[3 * k + 2]))
        })
        .collect()
}
