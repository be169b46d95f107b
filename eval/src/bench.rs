//! `strandlight bench`: speed against error for the environment-lit method, measured on the real
//! data in `../shared/data` and written as the generated section of docs/BENCHMARKS.md with its
//! plots (docs/bench/). Three sweeps:
//! - the SRBF fit per map: relative L2 error and seconds against the lobe count;
//! - the Marschner convolution table: error against resolution, bytes and bake seconds;
//! - the env-lit frame per map and mode: relative RMSE and HDR-FLIP against the converged
//!   reference, and milliseconds, for the SRBF path (lobe count, κ, light-map resolution varied
//!   one at a time around the defaults), the median-cut baseline at several light counts and
//!   the reference itself; with the equal-error speed-up of the SRBF default over median cut.
//!
//! Every render goes through [`compare`]'s scene, cache and converged reference, so `bench`
//! and `compare` measure the same thing.

use crate::baseline::Baseline;
use crate::compare::{self, CompareScene, CompareSettings};
use crate::error_decomposition::{
    self, DecompositionInputs, ErrorDecomposition, unshadowed_max_lights,
};
use crate::ground_truth::{GroundTruth, TruthUse};
use crate::hdr_flip::hdr_flip;
use anyhow::Context;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use strandlight_precompute::FitOptions;
use strandlight_precompute::bake::bake_job;
use strandlight_precompute::bake_plan::{BakeResolution, FiberDescription, Model, PlanOptions};
use strandlight_precompute::baked_tables_check::check_asset;
use strandlight_scene::env_frame::render_lights;
use strandlight_scene::env_lighting::{EnvLightSet, EnvLighting};
use strandlight_scene::environment::load_env;
use strandlight_scene::fit_cache::fit_cached;
use strandlight_scene::frame_settings::{FrameSettings, Lighting};
use strandlight_scene::head_input::HeadChoice;
use strandlight_scene::image_metrics::{Image, ScaleErrors, relative_rmse};
use strandlight_scene::look::{EnvTransparency, LobeVisibilityArg, ViewArgs};
use strandlight_scene::scene_tables::{EnvShading, ScatteringMode};
use strandlight_scene::steps::Steps;

/// What one run measures.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BenchPlan {
    pub name: String,
    pub maps: Vec<String>,
    pub size: (u32, u32),
    pub modes: Vec<ScatteringMode>,
    /// Fit sweep: most lobes.
    pub fit_lobes: Vec<usize>,
    /// Table sweep: nodes per direction axis of the Marschner table.
    pub table_nodes: Vec<usize>,
    pub table_check_points: usize,
    /// Env-lit sweep, one parameter at a time around the defaults (first of each list).
    pub lobes: Vec<usize>,
    pub kappas: Vec<f32>,
    pub dodm_sizes: Vec<u32>,
    pub baseline_lights: Vec<usize>,
    /// Which directional-light baseline (reports written before it existed: median cut).
    #[serde(default)]
    pub baseline: Baseline,
    pub reference_max_lights: usize,
    /// Timed runs per SRBF and median-cut frame, the median kept: one run of a sub-second frame
    /// varies by 15–35% on a shared machine, enough to move an equal-error ratio by as much.
    /// Reports written before it existed: 1.
    #[serde(default = "one_run")]
    pub timing_runs: usize,
    /// Measure only the error decomposition (`bench --decomposition-only`): no fit, table or
    /// env-lit sweep, so a page measured before the decomposition existed can gain it from a
    /// short run merged beside its own. Reports written before it existed: false.
    #[serde(default)]
    pub decomposition_only: bool,
    /// The fiber model of every frame (reports written before it existed: Marschner).
    #[serde(default = "marschner")]
    pub shading: EnvShading,
    /// Also measure every frame against the path-traced ground truth (Mitsuba 3; the Chiang
    /// fiber only), rendering what the cache lacks. Reports written before it existed: false.
    #[serde(default)]
    pub ground_truth: bool,
    /// Most samples per pixel of a ground-truth image, single and full scattering.
    #[serde(default = "truth_max_spp")]
    pub truth_max_spp: [u32; 2],
    /// Measure where each map's error comes from (against the DOM reference). Reports written
    /// before it existed: true.
    #[serde(default = "yes")]
    pub decomposition: bool,
    /// The head in every frame, the ground truth's too (issue 40). Reports written before it
    /// existed: none.
    #[serde(default, skip_serializing_if = "HeadChoice::is_none")]
    pub head: HeadChoice,
    /// The view of every frame, the DOM reference's and median cut's too. Reports written
    /// before it existed: opaque, the default then.
    #[serde(default = "opaque_view")]
    pub transparency: EnvTransparency,
    /// The fiber's melanin preset in every frame and truth (issue 65: every melanin measured).
    /// Reports written before it existed: brown.
    #[serde(default = "brown")]
    pub preset: String,
}

fn brown() -> String {
    "brown".into()
}

fn opaque_view() -> EnvTransparency {
    EnvTransparency::Opaque
}

fn one_run() -> usize {
    1
}

fn marschner() -> EnvShading {
    EnvShading::Marschner
}

fn truth_max_spp() -> [u32; 2] {
    [16384, 4096]
}

fn yes() -> bool {
    true
}

/// Timed runs per frame in both plans ([`BenchPlan::timing_runs`]).
const TIMING_RUNS: usize = 3;

/// Every shared map, in the order of docs/BENCHMARKS.md's comparison table.
const ALL_MAPS: [&str; 8] = [
    "hdr_overcast_soil_puresky_1k.hdr",
    "quarry_01_1k.hdr",
    "photo_studio_01_1k.hdr",
    "moonless_golf_1k.hdr",
    "royal_esplanade_1k.hdr",
    "spruit_sunrise_1k.hdr",
    "venice_sunset_1k.hdr",
    "piz_compressed.exr",
];

impl BenchPlan {
    /// The `bench` arguments that rerun this plan: its name and each flag whose value the run
    /// changed from that plan's.
    pub fn regenerate_args(&self) -> String {
        let plan = self;
        let base = plan.base();
        let list = |v: &[usize]| v.iter().map(usize::to_string).collect::<Vec<_>>().join(",");
        let mut args = String::from(match plan.name.as_str() {
            "quick" => " --quick",
            "truth" => " --truth",
            _ => "",
        });
        if plan.maps != base.maps {
            args += &format!(" --maps {}", plan.maps.join(","));
        }
        if plan.modes != base.modes {
            let modes: Vec<_> = plan.modes.iter().map(|m| m.name()).collect();
            args += &format!(" --modes {}", modes.join(","));
        }
        if plan.reference_max_lights != base.reference_max_lights {
            args += &format!(" --reference-max-lights {}", plan.reference_max_lights);
        }
        if plan.baseline_lights != base.baseline_lights {
            args += &format!(" --baseline-lights {}", list(&plan.baseline_lights));
        }
        if plan.baseline != base.baseline {
            let flag = serde_json::to_value(plan.baseline).expect("a unit enum serializes");
            args += &format!(" --baseline {}", flag.as_str().unwrap_or_default());
        }
        if plan.decomposition_only {
            args += " --decomposition-only";
        }
        if !plan.head.is_none() {
            args += &format!(" --head {}", plan.head);
        }
        if plan.preset != base.preset {
            args += &format!(" --preset {}", plan.preset);
        }
        args
    }

    /// The whole report: every map, both modes, the issue's sweeps.
    pub fn full() -> Self {
        Self {
            name: "full".into(),
            maps: ALL_MAPS.iter().map(|m| m.to_string()).collect(),
            // Every env-lit figure in docs/BENCHMARKS.md is at this size: on lavapipe on two
            // cores a 1536-light single-scattering reference takes 3-4 min at it, four times
            // that at 320×240, and the whole plan would not fit a working day.
            size: (160, 120),
            modes: vec![ScatteringMode::Single, ScatteringMode::Full],
            fit_lobes: vec![8, 16, 32, 49, 64],
            table_nodes: vec![8, 16, 24, 32],
            table_check_points: 500,
            lobes: vec![64, 8, 16, 32, 49],
            kappas: vec![0.1, 0.3, 1.0],
            dodm_sizes: vec![512, 256, 1024],
            baseline_lights: vec![4, 8, 16, 32, 64, 128],
            baseline: Baseline::MedianCut,
            reference_max_lights: 1536,
            timing_runs: TIMING_RUNS,
            decomposition_only: false,
            shading: EnvShading::Marschner,
            ground_truth: false,
            truth_max_spp: truth_max_spp(),
            decomposition: true,
            head: HeadChoice::None,
            transparency: EnvTransparency::default(),
            preset: brown(),
        }
    }

    /// Every map in both modes against the path-traced ground truth with the Chiang fiber (the
    /// model Mitsuba, pbrt and Cycles render): the SRBF default, the median-cut front and the
    /// DOM reference, each measured against both yardsticks. No parameter sweep, fit or table
    /// study, no decomposition: what the page opens with.
    pub fn truth() -> Self {
        Self {
            name: "truth".into(),
            fit_lobes: Vec::new(),
            table_nodes: Vec::new(),
            table_check_points: 0,
            lobes: vec![64],
            kappas: vec![0.1],
            dodm_sizes: vec![512],
            shading: EnvShading::Chiang,
            ground_truth: true,
            // The truth's noise at 4096 (the kept image holds 5120 spp) is ~3% relative RMSE,
            // a tenth of the errors it measures; removed in quadrature on the page.
            truth_max_spp: [4096, 4096],
            decomposition: false,
            ..Self::full()
        }
    }

    /// Whether this is the ground-truth plan (its page section opens docs/BENCHMARKS.md).
    pub fn is_truth(&self) -> bool {
        self.name == "truth"
    }

    /// Most samples per pixel of `mode`'s ground truth.
    pub fn truth_max_spp_of(&self, mode: ScatteringMode) -> u32 {
        match mode {
            ScatteringMode::Single => self.truth_max_spp[0],
            ScatteringMode::Full => self.truth_max_spp[1],
        }
    }

    /// Whether this is the `--quick` plan (its report goes to a scratch page, not docs/).
    pub fn is_quick(&self) -> bool {
        self.name == "quick"
    }

    /// A few minutes: the smooth overcast map, single scattering, 160×120, a reference of
    /// at most 384 lights.
    pub fn quick() -> Self {
        Self {
            name: "quick".into(),
            maps: vec![ALL_MAPS[0].to_string()],
            size: (160, 120),
            modes: vec![ScatteringMode::Single],
            fit_lobes: vec![8, 32, 64],
            table_nodes: vec![8, 16],
            table_check_points: 100,
            lobes: vec![64, 8, 32],
            kappas: vec![0.1, 1.0],
            dodm_sizes: vec![512, 256],
            baseline_lights: vec![4, 16, 64],
            baseline: Baseline::MedianCut,
            reference_max_lights: 384,
            timing_runs: TIMING_RUNS,
            decomposition_only: false,
            shading: EnvShading::Marschner,
            ground_truth: false,
            truth_max_spp: truth_max_spp(),
            decomposition: true,
            head: HeadChoice::None,
            transparency: EnvTransparency::default(),
            preset: brown(),
        }
    }
}

/// What a run changes of its base plan (`bench --maps --modes --reference-max-lights
/// --baseline-lights --baseline --head`): a subset, or a longer ladder, more baseline points or the
/// other baseline where one map needs them, without editing the plan.
#[derive(Debug, Clone, Default)]
pub struct PlanChanges {
    pub maps: Vec<String>,
    pub modes: Vec<ScatteringMode>,
    pub reference_max_lights: Option<usize>,
    pub baseline_lights: Vec<usize>,
    pub baseline: Option<Baseline>,
    pub decomposition_only: bool,
    pub head: Option<HeadChoice>,
    pub preset: Option<String>,
}

/// The most median-cut lights a bench frame may ask for (a light map each; the largest
/// reference rung the paper uses).
const MOST_BASELINE_LIGHTS: usize = 6144;

impl BenchPlan {
    /// The plan this one was changed from: the quick or the full one.
    pub fn base(&self) -> Self {
        match self.name.as_str() {
            "quick" => Self::quick(),
            "truth" => Self::truth(),
            _ => Self::full(),
        }
    }

    /// This plan with `changes` applied, checked: every mode once, median-cut light counts in
    /// 1..=6144 (sorted, each once), the reference budget one `compare` accepts.
    pub fn changed(mut self, changes: &PlanChanges) -> anyhow::Result<Self> {
        if !changes.maps.is_empty() {
            self.maps = changes.maps.clone();
        }
        if !changes.modes.is_empty() {
            self.modes.clear();
            for &mode in &changes.modes {
                if !self.modes.contains(&mode) {
                    self.modes.push(mode);
                }
            }
        }
        if let Some(most) = changes.reference_max_lights {
            self.reference_max_lights = most;
        }
        if !changes.baseline_lights.is_empty() {
            if let Some(n) = changes
                .baseline_lights
                .iter()
                .find(|&&n| !(1..=MOST_BASELINE_LIGHTS).contains(&n))
            {
                anyhow::bail!("--baseline-lights {n}: use 1 to {MOST_BASELINE_LIGHTS} lights");
            }
            self.baseline_lights = changes.baseline_lights.clone();
            self.baseline_lights.sort_unstable();
            self.baseline_lights.dedup();
        }
        if let Some(baseline) = changes.baseline {
            self.baseline = baseline;
        }
        self.decomposition_only |= changes.decomposition_only;
        if let Some(head) = &changes.head {
            self.head = head.clone();
        }
        if let Some(preset) = &changes.preset {
            FiberDescription::preset(preset).with_context(|| format!("--preset {preset}"))?;
            self.preset = preset.clone();
        }
        let probe = compare_args(
            &self,
            (Path::new(BENCH_HAIR), Path::new("map")),
            Path::new("cache"),
            Path::new("out"),
        );
        // The cause names the comparison's setting; the context, the bench flags that set it.
        compare::check_args(&probe).with_context(|| format!("bench{}", self.regenerate_args()))?;
        Ok(self)
    }
}

/// One measured frame.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Point {
    /// "srbf", "reference" or the baseline's name ([`Baseline::name`]).
    pub family: String,
    /// What was varied ("lobes", "kappa", "dodm", "lights") and its value.
    pub label: String,
    pub lights: usize,
    pub ms: f64,
    pub relative_rmse: f64,
    pub hdr_flip: f64,
    /// The same frame against the path-traced ground truth, where the plan has one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub truth: Option<TruthError>,
}

/// A frame's error against the path-traced ground truth.
#[derive(Debug, Clone, Copy, Serialize, Deserialize)]
pub struct TruthError {
    pub relative_rmse: f64,
    /// With the ground truth's own noise removed in quadrature.
    pub relative_rmse_noise_corrected: f64,
    pub hdr_flip: f64,
    /// The error over blocks, the coverage's and the mean ratio (absent in runs before them).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scales: Option<ScaleErrors>,
}

/// How one map and mode's ground truth was made.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct TruthSummary {
    pub renderer: String,
    pub spp: u32,
    pub max_depth: u32,
    /// Mitsuba's time for the kept image (its two renders), seconds.
    pub seconds: f64,
    pub converged: bool,
    /// Relative RMSE of the kept image's noise (from its last N-vs-4N rung).
    pub noise: f64,
    /// (spp N, relative RMSE of N against 4N).
    pub ladder: Vec<(u32, f64)>,
    /// (depth D, relative RMSE of D against 2D), full scattering.
    pub depth_ladder: Vec<(u32, f64)>,
}

impl Point {
    /// A frame of the directional-light baseline (whichever the plan chose).
    pub fn is_baseline(&self) -> bool {
        self.family != "srbf" && self.family != "reference"
    }
}

/// One map and mode of the env-lit sweep.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct EnvLitResult {
    pub map: String,
    pub mode: String,
    pub reference_lights: usize,
    pub reference_ms: f64,
    pub reference_converged: Option<bool>,
    /// (N, relative RMSE of N against 4N lights).
    pub reference_ladder: Vec<(usize, f64)>,
    pub points: Vec<Point>,
    /// The SRBF default's speed-up over median cut at equal relative RMSE / HDR-FLIP, from the
    /// median-cut curve interpolated log-log (None where the curve never gets that accurate).
    pub speedup_equal_rmse: Option<f64>,
    pub speedup_equal_flip: Option<f64>,
    /// The path-traced ground truth, where the plan has one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub truth: Option<TruthSummary>,
    /// The equal-error speed-ups over median cut, both measured against the ground truth.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub speedup_equal_rmse_truth: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub speedup_equal_flip_truth: Option<f64>,
}

impl EnvLitResult {
    /// Where the median-cut curve never gets as accurate as the SRBF default, its equal-error
    /// speed-up is at least the costliest median-cut frame's time over the default's: that
    /// frame's light count and the ratio.
    pub fn speedup_lower_bound(&self) -> Option<(usize, f64)> {
        let default = self.points.first()?;
        self.points
            .iter()
            .filter(|p| p.is_baseline())
            .max_by(|a, b| a.ms.total_cmp(&b.ms))
            .map(|p| (p.lights, p.ms / default.ms))
    }
}

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct FitPoint {
    pub map: String,
    pub max_lobes: usize,
    pub lobes: usize,
    pub sources: usize,
    pub relative_l2_error: f64,
    pub seconds: f64,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct TablePoint {
    pub nodes: usize,
    pub bytes: u64,
    pub bake_seconds: f64,
    pub max_error: f64,
    pub rms_error: f64,
    pub off_axis_max_error: f64,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct BenchReport {
    pub plan: BenchPlan,
    pub machine: String,
    pub adapter: String,
    pub date: String,
    pub git_revision: String,
    pub seconds: f64,
    pub fits: Vec<FitPoint>,
    pub tables: Vec<TablePoint>,
    pub env_lit: Vec<EnvLitResult>,
    /// Per map and mode, where the SRBF default's error comes from. Reports written before it
    /// existed: none.
    #[serde(default)]
    pub decompositions: Vec<ErrorDecomposition>,
    /// Maps the plan named that were not found, with why.
    pub skipped: Vec<String>,
    /// Where this report merges several runs ([`BenchReport::merged`]): each run's `bench`
    /// arguments, to say how to measure it again, and its machine. Empty for one run.
    #[serde(default)]
    pub runs: Vec<BenchRun>,
}

/// One run of a merged report. Its frames were timed against each other on one machine, so
/// every speed-up a map's section gives is that run's; runs on different machines can share a
/// page as long as each names its own.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(from = "RecordedRun")]
pub struct BenchRun {
    /// The `bench` arguments that measure it again.
    pub args: String,
    pub machine: String,
    pub adapter: String,
}

/// A run as reports store it: reports merged before runs named their machine hold only the
/// arguments (their runs all shared the report's machine, which merging then required).
#[derive(Deserialize)]
#[serde(untagged)]
enum RecordedRun {
    Args(String),
    Run {
        args: String,
        machine: String,
        adapter: String,
    },
}

impl From<RecordedRun> for BenchRun {
    fn from(recorded: RecordedRun) -> Self {
        match recorded {
            RecordedRun::Args(args) => BenchRun {
                args,
                machine: String::new(),
                adapter: String::new(),
            },
            RecordedRun::Run {
                args,
                machine,
                adapter,
            } => BenchRun {
                args,
                machine,
                adapter,
            },
        }
    }
}

impl BenchReport {
    /// One report of runs that measured the same plan on different maps or modes, each with
    /// the reference budget its maps need (a long sweep split into runs: a cached 6144-light
    /// reference for one map, 1536 for the rest). Maps, modes, fits and env-lit results in the
    /// order given (a map's fit sweep from its first run), the first run's table sweep, the
    /// largest reference budget, the runs' dates, revisions and arguments named, their seconds
    /// summed.
    pub fn merged(reports: Vec<BenchReport>) -> anyhow::Result<BenchReport> {
        let mut reports = reports.into_iter();
        let mut merged = reports.next().context("no report to merge")?;
        // Dates are "YYYY-MM-DD HH:MM UTC": their order as text is their order in time.
        let (mut first_date, mut last_date) = date_range(&merged.date);
        let mut revisions = vec![merged.git_revision.clone()];
        merged.runs = runs_of(&merged);
        // What a run may change of the plan it shares with the others.
        let shared_part = |p: &BenchPlan| BenchPlan {
            maps: Vec::new(),
            modes: Vec::new(),
            reference_max_lights: 0,
            decomposition_only: false,
            ..p.clone()
        };
        for report in reports {
            if shared_part(&report.plan) != shared_part(&merged.plan) {
                anyhow::bail!(
                    "the reports measured different plans (apart from maps, modes and reference budget): {:?} and {:?}",
                    shared_part(&merged.plan),
                    shared_part(&report.plan)
                );
            }
            let env_lit_key = |r: &EnvLitResult| (r.map.clone(), r.mode.clone());
            if let Some((map, mode)) = repeated_key(&merged.env_lit, &report.env_lit, env_lit_key) {
                anyhow::bail!("{map} ({mode} scattering) is in more than one report");
            }
            let decomposition_key = |d: &ErrorDecomposition| {
                let against = if d.against_truth {
                    ", against the truth"
                } else {
                    ""
                };
                (d.map.clone(), format!("{}{against}", d.mode))
            };
            if let Some((map, mode)) = repeated_key(
                &merged.decompositions,
                &report.decompositions,
                decomposition_key,
            ) {
                anyhow::bail!(
                    "the error decomposition of {map} ({mode} scattering) is in more than one report"
                );
            }
            merged.runs.extend(runs_of(&report));
            let had_fits = |map: &String| merged.fits.iter().any(|f| &f.map == map);
            let new_fits: Vec<FitPoint> = report
                .fits
                .into_iter()
                .filter(|f| !had_fits(&f.map))
                .collect();
            merged.fits.extend(new_fits);
            for map in report.plan.maps {
                if !merged.plan.maps.contains(&map) {
                    merged.plan.maps.push(map);
                }
            }
            for mode in report.plan.modes {
                if !merged.plan.modes.contains(&mode) {
                    merged.plan.modes.push(mode);
                }
            }
            merged.plan.reference_max_lights = merged
                .plan
                .reference_max_lights
                .max(report.plan.reference_max_lights);
            merged.env_lit.extend(report.env_lit);
            merged.decompositions.extend(report.decompositions);
            merged.plan.decomposition_only &= report.plan.decomposition_only;
            merged.skipped.extend(report.skipped);
            merged.seconds += report.seconds;
            if !revisions.contains(&report.git_revision) {
                revisions.push(report.git_revision);
            }
            let (first, last) = date_range(&report.date);
            first_date = first_date.min(first);
            last_date = last_date.max(last);
        }
        merged.machine = distinct_joined(merged.runs.iter().map(|r| &r.machine));
        merged.adapter = distinct_joined(merged.runs.iter().map(|r| &r.adapter));
        if merged.runs.len() == 1 {
            merged.runs.clear();
        }
        if last_date != first_date {
            merged.date = format!("{first_date} to {last_date}");
        }
        merged.git_revision = revisions.join(", ");
        Ok(merged)
    }

    /// Whether its runs were measured on more than one machine or adapter.
    pub fn spans_machines(&self) -> bool {
        self.runs
            .windows(2)
            .any(|w| (&w[0].machine, &w[0].adapter) != (&w[1].machine, &w[1].adapter))
    }
}

/// The first (map, mode) of `new` that `merged` already holds.
fn repeated_key<T>(
    merged: &[T],
    new: &[T],
    key: impl Fn(&T) -> (String, String),
) -> Option<(String, String)> {
    new.iter()
        .map(&key)
        .find(|k| merged.iter().any(|m| &key(m) == k))
}

/// The runs `report` holds: itself, or those it was merged from.
fn runs_of(report: &BenchReport) -> Vec<BenchRun> {
    let this_run = || BenchRun {
        args: report.plan.regenerate_args(),
        machine: report.machine.clone(),
        adapter: report.adapter.clone(),
    };
    match report.runs.is_empty() {
        true => vec![this_run()],
        false => report
            .runs
            .iter()
            .map(|run| BenchRun {
                args: run.args.clone(),
                machine: or_else(&run.machine, &report.machine),
                adapter: or_else(&run.adapter, &report.adapter),
            })
            .collect(),
    }
}

fn or_else(recorded: &str, fallback: &str) -> String {
    match recorded.is_empty() {
        true => fallback.to_string(),
        false => recorded.to_string(),
    }
}

/// A report's first and last date: a merged report's are "FIRST to LAST".
fn date_range(date: &str) -> (String, String) {
    match date.split_once(" to ") {
        Some((first, last)) => (first.to_string(), last.to_string()),
        None => (date.to_string(), date.to_string()),
    }
}

/// The runs' values, each once, in the runs' order: one machine, or "A and B".
fn distinct_joined<'a>(values: impl Iterator<Item = &'a String>) -> String {
    let mut distinct: Vec<&str> = Vec::new();
    for value in values {
        if !distinct.contains(&value.as_str()) {
            distinct.push(value);
        }
    }
    distinct.join(" and ")
}

/// The hair every bench frame draws, under the shared data folder.
pub const BENCH_HAIR: &str = "hair/straight.hair";

/// The compare settings a bench scene of `map` is built with.
fn compare_args(
    plan: &BenchPlan,
    (hair, map): (&Path, &Path),
    cache: &Path,
    out: &Path,
) -> CompareSettings {
    let mut env = EnvLighting::new(map.display().to_string());
    env.fit.max_lobes = plan.lobes[0];
    env.kappa = plan.kappas[0];
    env.dodm_size = plan.dodm_sizes[0];
    env.transparency = plan.transparency;
    env.view = ViewArgs {
        // Every SRBF frame of the sweep sets its own ([`srbf_configs`]); the error
        // decomposition against the DOM reference takes Ren's light maps apart (one
        // visibility per lobe, κ), so they are what these arguments leave in place.
        lobe_visibility: LobeVisibilityArg::LightMaps,
        ..ViewArgs::default()
    };
    let frame = FrameSettings {
        hair: Some(hair.to_path_buf()),
        shading: Some(plan.shading.into()),
        preset: plan.preset.clone(),
        head: plan.head.clone(),
        ..FrameSettings::new(Lighting::Environment(env), [plan.size.0, plan.size.1])
    };
    CompareSettings {
        frame,
        json: true,
        reference_max_lights: plan.reference_max_lights,
        out: out.to_path_buf(),
        cache: cache.to_path_buf(),
        // The tables every mode measured needs, and single scattering's for full scattering's
        // decomposition, which compares the single-scattering parts.
        modes: [ScatteringMode::Single, ScatteringMode::Full]
            .into_iter()
            .filter(|m| *m == ScatteringMode::Single || plan.modes.contains(m))
            .collect(),
        timing_runs: plan.timing_runs,
        baseline: plan.baseline,
        ground_truth: match plan.ground_truth {
            true => TruthUse::Render,
            false => TruthUse::Off,
        },
        truth_max_spp: plan.truth_max_spp[0],
        ..CompareSettings::default()
    }
}

/// The yardsticks a frame is measured against: the DOM reference, and the ground truth where
/// the plan has one.
#[derive(Clone, Copy)]
struct Yardsticks<'a> {
    reference: &'a Image,
    truth: Option<&'a GroundTruth>,
}

fn measure(
    family: &str,
    label: String,
    lights: usize,
    ms: f64,
    image: &Image,
    against: Yardsticks,
) -> anyhow::Result<Point> {
    Ok(Point {
        family: family.into(),
        label,
        lights,
        ms,
        relative_rmse: relative_rmse(image, against.reference)?,
        hdr_flip: hdr_flip(image, against.reference)?.mean_over_hair,
        truth: against.truth.map(|t| truth_error(image, t)).transpose()?,
    })
}

fn truth_error(image: &Image, truth: &GroundTruth) -> anyhow::Result<TruthError> {
    let e = relative_rmse(image, &truth.image)?;
    Ok(TruthError {
        relative_rmse: e,
        relative_rmse_noise_corrected: truth.noise_corrected(e),
        hdr_flip: hdr_flip(image, &truth.image)?.mean_over_hair,
        scales: Some(ScaleErrors::of(image, &truth.image)?),
    })
}

fn truth_summary(t: &GroundTruth) -> TruthSummary {
    TruthSummary {
        renderer: format!("Mitsuba {} (scalar_rgb, path, hair BSDF)", t.mitsuba),
        spp: t.spp,
        max_depth: t.max_depth,
        seconds: t.seconds,
        converged: t.converged,
        noise: t.noise,
        ladder: t
            .ladder
            .iter()
            .map(|r| (r.spp, r.difference_to_4x))
            .collect(),
        depth_ladder: t.depth_ladder.clone(),
    }
}

/// One SRBF frame of the sweep: the defaults with one setting changed.
#[derive(Clone)]
struct SrbfConfig {
    label: String,
    lobes: usize,
    kappa: f32,
    dodm: u32,
    lobe_visibility: LobeVisibilityArg,
}

/// The label of Ren 2010's frame: lobes shadowed by their own light maps at the plan's first κ
/// and size, the base of the κ and light-map-size series.
fn light_maps_label(kappa: f32, dodm: u32) -> String {
    format!("light maps (κ {kappa}, {dodm}²)")
}

/// The SRBF frames of `plan`: the product's default (lobes shadowed by the visibility volume),
/// with the lobe count varied; then Ren 2010's light maps, with κ and the light-map size
/// varied one at a time (κ thins only light maps, so it has no frame of the volume's). Compact
/// sources draw maps of the plan's first size in every frame.
fn srbf_configs(plan: &BenchPlan) -> Vec<SrbfConfig> {
    let (lobes, kappa, dodm) = (plan.lobes[0], plan.kappas[0], plan.dodm_sizes[0]);
    let default = SrbfConfig {
        label: format!("default ({lobes} lobes, visibility volume; light maps under a head)"),
        lobes,
        kappa,
        dodm,
        lobe_visibility: LobeVisibilityArg::Auto,
    };
    let light_maps = SrbfConfig {
        label: light_maps_label(kappa, dodm),
        lobe_visibility: LobeVisibilityArg::LightMaps,
        ..default.clone()
    };
    let mut configs = vec![default.clone()];
    for &n in &plan.lobes[1..] {
        configs.push(SrbfConfig {
            label: format!("{n} lobes"),
            lobes: n,
            ..default.clone()
        });
    }
    configs.push(light_maps.clone());
    for &k in &plan.kappas[1..] {
        configs.push(SrbfConfig {
            label: format!("light maps, κ {k}"),
            kappa: k,
            ..light_maps.clone()
        });
    }
    for &d in &plan.dodm_sizes[1..] {
        configs.push(SrbfConfig {
            label: format!("light maps {d}²"),
            dodm: d,
            ..light_maps.clone()
        });
    }
    configs
}

/// The SRBF frames of one map and mode ([`srbf_configs`]).
fn srbf_points(
    plan: &BenchPlan,
    scene: &CompareScene,
    args: &CompareSettings,
    mode: ScatteringMode,
    against: Yardsticks,
    steps: &mut Steps,
) -> anyhow::Result<Vec<Point>> {
    let mut points = Vec::new();
    for config in srbf_configs(plan) {
        let mut settings = args.frame_of(mode, EnvLightSet::Fit);
        if let Lighting::Environment(env) = &mut settings.lighting {
            env.lobes = Some(config.lobes);
            env.kappa = config.kappa;
            env.dodm_size = config.dodm;
            env.view.lobe_visibility = config.lobe_visibility;
        }
        let frame = compare::frame(scene, &settings)?;
        let lights = frame.lights.len();
        let r = steps.run(
            &format!("{}: SRBF {}", mode.name(), config.label),
            || compare::timed_render(&render_lights, &frame, args.timing_runs),
            |r| format!("{:.0} ms", r.milliseconds),
        )?;
        points.push(measure(
            "srbf",
            config.label,
            lights,
            r.milliseconds,
            &r.image,
            against,
        )?);
    }
    Ok(points)
}

/// ms of the median-cut curve at `error` (log-log interpolation between the two measured
/// counts around it), None when no measured count is that accurate.
fn curve_ms_at(points: &[&Point], error: f64, metric: &dyn Fn(&Point) -> f64) -> Option<f64> {
    let mut curve: Vec<(f64, f64)> = points.iter().map(|p| (metric(p), p.ms)).collect();
    curve.sort_by(|a, b| b.0.total_cmp(&a.0)); // error falling
    if curve.first().is_some_and(|c| c.0 <= error) {
        return Some(curve[0].1);
    }
    curve.windows(2).find_map(|w| {
        let ((e0, t0), (e1, t1)) = (w[0], w[1]);
        (e1 <= error && error <= e0 && e0 > 0.0 && e1 > 0.0).then(|| {
            let f = (error.ln() - e0.ln()) / (e1.ln() - e0.ln());
            (t0.ln() + f * (t1.ln() - t0.ln())).exp()
        })
    })
}

/// One map's env-lit results and error decompositions (each mode).
struct MapResults {
    env_lit: Vec<EnvLitResult>,
    decompositions: Vec<ErrorDecomposition>,
}

fn env_lit(
    plan: &BenchPlan,
    map: &Path,
    hair: &(PathBuf, strandlight_runtime::hair::HairModel, String),
    cache: &Path,
    scratch: &Path,
    steps: &mut Steps,
) -> anyhow::Result<MapResults> {
    let args = compare_args(plan, (&hair.0, map), cache, scratch);
    let scene = compare::prepare_with_hair(&args, hair.1.clone(), hair.2.clone(), steps)?;
    // The first frame compiles the driver's shader variants: not a frame's cost.
    render_lights(&compare::frame(
        &scene,
        &args.frame_of(plan.modes[0], EnvLightSet::Fit),
    )?)?;
    let name = map_stem(map);
    let mut out = Vec::new();
    let mut decompositions = Vec::new();
    let mut unshadowed_args = CompareSettings {
        reference_max_lights: unshadowed_max_lights(plan.reference_max_lights),
        ..compare_args(plan, (&hair.0, map), cache, scratch)
    };
    unshadowed_args.env_mut().shadowed = false;
    let inputs = DecompositionInputs {
        render: &render_lights,
        scene: &scene,
        args: &args,
        unshadowed_args: &unshadowed_args,
        lobes: plan.lobes[0],
        kappa: plan.kappas[0],
    };
    let mut single_truth = None;
    for &mode in &plan.modes {
        let reference = compare::reference(&render_lights, &scene, &args, mode, steps)?;
        if plan.decomposition {
            decompositions.push(decomposition(&name, mode, &inputs, &reference, steps)?);
        }
        if plan.decomposition_only {
            continue;
        }
        let truth_args = CompareSettings {
            truth_max_spp: plan.truth_max_spp_of(mode),
            ..compare_args(plan, (&hair.0, map), cache, scratch)
        };
        let truth = compare::truth_of(&scene, &truth_args, mode, steps)?;
        if let Some(truth) = &truth {
            decompositions.push(against_truth(
                &name,
                mode,
                &inputs,
                &reference,
                truth,
                &mut single_truth,
                steps,
            )?);
        }
        let image = &reference.chosen.image;
        let against = Yardsticks {
            reference: image,
            truth: truth.as_ref(),
        };
        let mut points = srbf_points(plan, &scene, &args, mode, against, steps)?;
        let family = plan.baseline.name();
        for &n in &plan.baseline_lights {
            let r = steps.run(
                &format!("{}: {family} {n}", mode.name()),
                || compare::render_baseline(&render_lights, &scene, &args, mode, n),
                |r| format!("{:.0} ms", r.milliseconds),
            )?;
            let count = compare::baseline_set(&scene, &args, n)?.len();
            points.push(measure(
                family,
                format!("{count} lights"),
                count,
                r.milliseconds,
                &r.image,
                against,
            )?);
        }
        let record = &reference.chosen.record;
        points.push(Point {
            family: "reference".into(),
            label: format!("{} lights", record.lights),
            lights: record.lights,
            ms: record.milliseconds,
            relative_rmse: 0.0,
            hdr_flip: 0.0,
            truth: truth.as_ref().map(|t| truth_error(image, t)).transpose()?,
        });
        out.push(env_lit_result(
            &name,
            mode,
            &reference,
            truth.as_ref(),
            points,
        ));
    }
    Ok(MapResults {
        env_lit: out,
        decompositions,
    })
}

/// The error decomposition of `reference`'s mode against the DOM reference (full scattering's
/// needs the single-scattering reference too).
fn decomposition(
    name: &str,
    mode: ScatteringMode,
    inputs: &DecompositionInputs,
    reference: &compare::Reference,
    steps: &mut Steps,
) -> anyhow::Result<ErrorDecomposition> {
    match mode {
        ScatteringMode::Single => {
            error_decomposition::single_scattering(name, inputs, reference, steps)
        }
        ScatteringMode::Full => {
            let single = compare::reference(
                &render_lights,
                inputs.scene,
                inputs.args,
                ScatteringMode::Single,
                steps,
            )?;
            error_decomposition::full_scattering(name, inputs, &single, reference, steps)
        }
    }
}

/// One mode's points with the speedups at the default's errors read off the baseline's curve.
fn env_lit_result(
    name: &str,
    mode: ScatteringMode,
    reference: &compare::Reference,
    truth: Option<&GroundTruth>,
    points: Vec<Point>,
) -> EnvLitResult {
    let record = &reference.chosen.record;
    let default = points[0].clone();
    let baseline: Vec<&Point> = points.iter().filter(|p| p.is_baseline()).collect();
    let speedup = |metric: &dyn Fn(&Point) -> f64| {
        curve_ms_at(&baseline, metric(&default), metric).map(|ms| ms / default.ms)
    };
    let truth_metric =
        |f: fn(&TruthError) -> f64| move |p: &Point| p.truth.as_ref().map_or(f64::NAN, f);
    let (truth_rmse, truth_flip) = match truth {
        Some(_) => (
            speedup(&truth_metric(|t| t.relative_rmse)),
            speedup(&truth_metric(|t| t.hdr_flip)),
        ),
        None => (None, None),
    };
    EnvLitResult {
        map: name.into(),
        mode: mode.name().into(),
        reference_lights: record.lights,
        reference_ms: record.milliseconds,
        reference_converged: reference.converged,
        reference_ladder: reference.ladder.iter().map(|&(n, _, d)| (n, d)).collect(),
        speedup_equal_rmse: speedup(&|p| p.relative_rmse),
        speedup_equal_flip: speedup(&|p| p.hdr_flip),
        truth: truth.map(truth_summary),
        speedup_equal_rmse_truth: truth_rmse,
        speedup_equal_flip_truth: truth_flip,
        points,
    }
}

/// The decomposition of `reference`'s mode against its ground truth `truth`. Full scattering's
/// needs the single-scattering truth too: `single_truth` holds it once measured (rendered
/// here when the plan has no single-scattering mode before full).
fn against_truth(
    name: &str,
    mode: ScatteringMode,
    inputs: &DecompositionInputs,
    reference: &compare::Reference,
    truth: &GroundTruth,
    single_truth: &mut Option<GroundTruth>,
    steps: &mut Steps,
) -> anyhow::Result<ErrorDecomposition> {
    if mode == ScatteringMode::Single {
        *single_truth = Some(truth.clone());
        return error_decomposition::single_scattering_against_truth(
            name, inputs, reference, truth, steps,
        );
    }
    if single_truth.is_none() {
        // The plan's single-scattering budget: `compare_args` sets it.
        *single_truth =
            compare::truth_of(inputs.scene, inputs.args, ScatteringMode::Single, steps)?;
    }
    let single = single_truth.as_ref().context(
        "the single-scattering ground truth, which full scattering's decomposition needs",
    )?;
    error_decomposition::full_scattering_against_truth(
        name, inputs, reference, single, truth, steps,
    )
}

/// A map's file name without its extension, as the report names it.
fn map_stem(map: &Path) -> String {
    map.file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default()
}

fn fits(
    plan: &BenchPlan,
    map: &Path,
    cache: &Path,
    steps: &mut Steps,
) -> anyhow::Result<Vec<FitPoint>> {
    let env = load_env(&map.display().to_string(), false)?;
    let mut out = Vec::new();
    for &max_lobes in &plan.fit_lobes {
        let options = FitOptions {
            max_lobes,
            initial_lobes: max_lobes.min(FitOptions::default().initial_lobes),
            ..FitOptions::default()
        };
        let fit = steps.run(
            &format!("fit {} ≤ {max_lobes} lobes", env.name),
            || fit_cached(&env, &options, cache),
            |f| {
                format!(
                    "{} lobes, {:.3}",
                    f.set.lobes.len(),
                    f.set.relative_l2_error
                )
            },
        )?;
        out.push(FitPoint {
            map: map_stem(map),
            max_lobes,
            lobes: fit.set.lobes.len(),
            sources: fit.set.sources.len(),
            relative_l2_error: fit.set.relative_l2_error,
            seconds: fit.set.seconds,
        });
    }
    Ok(out)
}

fn tables(plan: &BenchPlan, scratch: &Path, steps: &mut Steps) -> anyhow::Result<Vec<TablePoint>> {
    let fiber = FiberDescription::preset(&plan.preset)
        .with_context(|| format!("the {} preset", plan.preset))?;
    let mut out = Vec::new();
    for &nodes in &plan.table_nodes {
        let dir = scratch.join(format!("tables-{nodes}"));
        // A fresh folder: the bake is timed, never served from a cache.
        let _ = std::fs::remove_dir_all(&dir);
        let options = PlanOptions {
            models: vec![Model::Marschner],
            resolution: BakeResolution::reduced(nodes),
            ..Default::default()
        };
        let job = strandlight_precompute::bake_plan::plan(&fiber, &options)?
            .jobs
            .into_iter()
            .find(|j| j.name == "marschner")
            .context("the Marschner convolution table is planned")?;
        let point = steps.run(
            &format!("table marschner {nodes}³×{}", 2 * nodes),
            || -> anyhow::Result<TablePoint> {
                let baked = bake_job(job, &dir, strandlight_tables::asset::Storage::F32)?;
                let asset = strandlight_tables::asset::read_asset(&baked.path)?;
                let acc = check_asset(&asset, plan.table_check_points, 11)?;
                Ok(TablePoint {
                    nodes,
                    bytes: baked.bytes,
                    bake_seconds: baked.seconds,
                    max_error: acc.max_abs_error,
                    rms_error: acc.rms_abs_error,
                    off_axis_max_error: acc.off_axis_max_abs_error,
                })
            },
            |t| format!("{:.2}% max, {:.1} s", 100.0 * t.max_error, t.bake_seconds),
        )?;
        out.push(point);
        let _ = std::fs::remove_dir_all(&dir);
    }
    Ok(out)
}

/// Where things are and go.
pub struct BenchPaths {
    /// `../shared/data` (hair/straight.hair, envmaps/…).
    pub data: PathBuf,
    pub cache: PathBuf,
    /// Scratch images and tables.
    pub scratch: PathBuf,
}

/// Runs `plan`. Maps absent from `paths.data` are skipped and listed.
pub fn run(plan: &BenchPlan, paths: &BenchPaths, steps: &mut Steps) -> anyhow::Result<BenchReport> {
    let start = std::time::Instant::now();
    let hair_path = paths.data.join(BENCH_HAIR);
    let bytes =
        std::fs::read(&hair_path).with_context(|| format!("reading {}", hair_path.display()))?;
    let (model, _) = strandlight_scene::hair_input::load_hair(Some(&hair_path))?;
    let hair = (
        hair_path.clone(),
        model,
        strandlight_tables::checksum::sha256_hex(&bytes),
    );
    let mut report = BenchReport {
        plan: plan.clone(),
        machine: machine(),
        adapter: strandlight_scene::env_frame::env_adapter()?,
        date: command_output("date", &["-u", "+%Y-%m-%d %H:%M UTC"]),
        // "-dirty" when the tree has uncommitted changes: the revision alone would not say
        // what was measured.
        git_revision: command_output("git", &["describe", "--always", "--dirty", "--abbrev=7"]),
        seconds: 0.0,
        fits: Vec::new(),
        tables: match plan.decomposition_only {
            true => Vec::new(),
            false => tables(plan, &paths.scratch, steps)?,
        },
        env_lit: Vec::new(),
        decompositions: Vec::new(),
        skipped: Vec::new(),
        runs: Vec::new(),
    };
    for map in &plan.maps {
        let path = paths.data.join("envmaps").join(map);
        if !path.is_file() {
            report.skipped.push(format!("{}: absent", path.display()));
            continue;
        }
        if !plan.decomposition_only {
            report.fits.extend(fits(plan, &path, &paths.cache, steps)?);
        }
        let scratch = paths.scratch.join(map);
        let results = env_lit(plan, &path, &hair, &paths.cache, &scratch, steps)?;
        report.env_lit.extend(results.env_lit);
        report.decompositions.extend(results.decompositions);
    }
    report.seconds = start.elapsed().as_secs_f64();
    Ok(report)
}

fn command_output(program: &str, args: &[&str]) -> String {
    std::process::Command::new(program)
        .args(args)
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
        .unwrap_or_else(|| "unknown".into())
}

/// CPU model and logical CPU count.
fn machine() -> String {
    let cpuinfo = std::fs::read_to_string("/proc/cpuinfo").unwrap_or_default();
    let model = cpuinfo
        .lines()
        .find_map(|l| l.strip_prefix("model name"))
        .map(|l| l.trim_start_matches([' ', '\t', ':']).to_string())
        .unwrap_or_else(|| std::env::consts::ARCH.to_string());
    let cpus = std::thread::available_parallelism().map_or(0, |n| n.get());
    format!("{model}, {cpus} logical CPUs, {}", std::env::consts::OS)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(family: &str, ms: f64, error: f64) -> Point {
        Point {
            family: family.into(),
            label: String::new(),
            lights: 0,
            ms,
            relative_rmse: error,
            hdr_flip: error,
            truth: None,
        }
    }

    fn report(map: &str, date: &str, revision: &str) -> BenchReport {
        let mut plan = BenchPlan::quick();
        plan.maps = vec![map.into()];
        BenchReport {
            env_lit: vec![result(map, "single")],
            fits: vec![fit(map, 8)],
            plan,
            machine: "m".into(),
            adapter: "a".into(),
            date: date.into(),
            git_revision: revision.into(),
            seconds: 10.0,
            tables: Vec::new(),
            decompositions: Vec::new(),
            skipped: Vec::new(),
            runs: Vec::new(),
        }
    }

    fn decomposition(map: &str, mode: &str) -> ErrorDecomposition {
        ErrorDecomposition {
            map: map.into(),
            mode: mode.into(),
            reference_lights: 1536,
            reference_converged: Some(false),
            unshadowed_reference_lights: None,
            unshadowed_converged: None,
            against_truth: false,
            steps: Vec::new(),
        }
    }

    /// A short run that measured only the error decomposition of a map the sweeps measured.
    fn decomposition_run(map: &str) -> BenchReport {
        let mut run = report(map, "d9", "r9");
        run.plan.decomposition_only = true;
        run.plan.modes = vec![ScatteringMode::Single, ScatteringMode::Full];
        run.env_lit = Vec::new();
        run.fits = Vec::new();
        run.decompositions = vec![decomposition(map, "single"), decomposition(map, "full")];
        run
    }

    fn result(map: &str, mode: &str) -> EnvLitResult {
        EnvLitResult {
            map: map.into(),
            mode: mode.into(),
            reference_lights: 96,
            reference_ms: 1.0,
            reference_converged: Some(true),
            reference_ladder: Vec::new(),
            points: Vec::new(),
            speedup_equal_rmse: None,
            speedup_equal_flip: None,
            truth: None,
            speedup_equal_rmse_truth: None,
            speedup_equal_flip_truth: None,
        }
    }

    fn fit(map: &str, max_lobes: usize) -> FitPoint {
        FitPoint {
            map: map.into(),
            max_lobes,
            lobes: max_lobes,
            sources: 0,
            relative_l2_error: 0.1,
            seconds: 1.0,
        }
    }

    /// The same map measured in full scattering by a run with its own reference budget.
    fn full_scattering_run(map: &str, reference_max_lights: usize) -> BenchReport {
        let mut run = report(map, "d4", "r3");
        run.plan.modes = vec![ScatteringMode::Full];
        run.plan.reference_max_lights = reference_max_lights;
        run.env_lit = vec![result(map, "full")];
        run.fits = vec![fit(map, 8), fit(map, 32)];
        run
    }

    #[test]
    fn reports_of_one_plan_on_different_maps_merge() {
        let merged = BenchReport::merged(vec![
            report("a.hdr", "d1", "r1"),
            report("b.hdr", "d3", "r1"),
            report("c.hdr", "d2", "r2"),
        ])
        .unwrap();
        assert_eq!(merged.plan.maps, ["a.hdr", "b.hdr", "c.hdr"]);
        assert_eq!(merged.date, "d1 to d3");
        assert_eq!(merged.git_revision, "r1, r2");
        assert_eq!(merged.seconds, 30.0);
        assert_eq!(merged.runs.len(), 3);
        assert!(
            merged
                .runs
                .iter()
                .all(|r| r.args.starts_with(" --quick --maps "))
        );
    }

    #[test]
    fn a_run_of_another_mode_and_reference_budget_joins_its_map() {
        let merged = BenchReport::merged(vec![
            report("a.hdr", "d1", "r1"),
            full_scattering_run("a.hdr", 6144),
        ])
        .unwrap();
        assert_eq!(merged.plan.maps, ["a.hdr"]);
        assert_eq!(
            merged.plan.modes,
            [ScatteringMode::Single, ScatteringMode::Full]
        );
        assert_eq!(merged.plan.reference_max_lights, 6144);
        let modes: Vec<&str> = merged.env_lit.iter().map(|r| r.mode.as_str()).collect();
        assert_eq!(modes, ["single", "full"]);
        // The map's fit sweep once, from its first run.
        assert_eq!(merged.fits.len(), 1);
        assert!(
            merged.runs[1]
                .args
                .contains("--modes full --reference-max-lights 6144")
        );
        // Merged again with a third run, the first two runs are still named.
        let again = BenchReport::merged(vec![merged, report("b.hdr", "d5", "r3")]).unwrap();
        assert_eq!(again.runs.len(), 3);
        assert_eq!(again.date, "d1 to d5", "a merged report's range, widened");
    }

    #[test]
    fn a_decomposition_only_run_joins_the_sweeps_of_its_map_once() {
        let merged = BenchReport::merged(vec![
            report("a.hdr", "d1", "r1"),
            full_scattering_run("a.hdr", 1536),
            decomposition_run("a.hdr"),
        ])
        .unwrap();
        let modes: Vec<&str> = merged.env_lit.iter().map(|r| r.mode.as_str()).collect();
        assert_eq!(modes, ["single", "full"], "the sweeps are kept");
        assert_eq!(merged.decompositions.len(), 2);
        assert!(!merged.plan.decomposition_only, "the page holds sweeps");
        assert!(
            merged.runs[2].args.ends_with("--decomposition-only"),
            "{:?}",
            merged.runs
        );
        let error = BenchReport::merged(vec![merged, decomposition_run("a.hdr")]).unwrap_err();
        assert!(
            error.to_string().contains("error decomposition of a.hdr"),
            "{error}"
        );
    }

    #[test]
    fn reports_of_different_plans_or_the_same_map_and_mode_do_not_merge() {
        let mut other_plan = report("b.hdr", "d", "r");
        other_plan.plan.size = (320, 240);
        let mut other_view = report("b.hdr", "d", "r");
        other_view.plan.transparency = EnvTransparency::Occupancy;
        for (second, says) in [
            (other_plan, "different plans"),
            (other_view, "different plans"),
            (report("a.hdr", "d", "r"), "more than one report"),
        ] {
            let error = BenchReport::merged(vec![report("a.hdr", "d", "r"), second]).unwrap_err();
            assert!(error.to_string().contains(says), "{error}");
        }
        let none = BenchReport::merged(Vec::new()).unwrap_err().to_string();
        assert!(none.contains("no report to merge"), "{none}");
    }

    #[test]
    fn runs_on_different_machines_merge_and_each_names_its_own() {
        let mut elsewhere = report("b.hdr", "d2", "r");
        elsewhere.machine = "n".into();
        let merged = BenchReport::merged(vec![report("a.hdr", "d1", "r"), elsewhere]).unwrap();
        let machines: Vec<&str> = merged.runs.iter().map(|r| r.machine.as_str()).collect();
        assert_eq!(machines, ["m", "n"]);
        assert_eq!(merged.machine, "m and n");
        assert_eq!(merged.adapter, "a");
        assert!(merged.spans_machines());
        let page = crate::bench_report::section(&merged, "bench");
        assert!(page.contains("(on n; a)"), "{page}");
        assert!(page.contains("each run's machine and adapter"), "{page}");
    }

    #[test]
    fn a_merged_report_whose_runs_hold_only_arguments_reads_them_as_its_machines() {
        let mut old = serde_json::to_value(report("a.hdr", "d", "r")).unwrap();
        old["runs"] = serde_json::json!([" --maps a.hdr", " --maps b.hdr"]);
        let old: BenchReport = serde_json::from_value(old).unwrap();
        let again = BenchReport::merged(vec![old]).unwrap();
        assert_eq!(again.runs.len(), 2);
        assert!(
            again
                .runs
                .iter()
                .all(|r| (r.machine.as_str(), r.adapter.as_str()) == ("m", "a"))
        );
        assert_eq!(again.runs[1].args, " --maps b.hdr");
        assert!(!again.spans_machines());
    }

    #[test]
    fn a_report_written_before_the_view_was_recorded_reads_as_the_opaque_view() {
        let mut plan = serde_json::to_value(BenchPlan::truth()).unwrap();
        plan.as_object_mut().unwrap().remove("transparency");
        let old: BenchPlan = serde_json::from_value(plan).unwrap();
        assert_eq!(old.transparency, EnvTransparency::Opaque);
        assert_eq!(BenchPlan::truth().transparency, EnvTransparency::Layered);
    }

    #[test]
    fn each_srbf_frame_changes_one_setting_of_the_default() {
        for plan in [BenchPlan::quick(), BenchPlan::full()] {
            let configs = srbf_configs(&plan);
            let default = &configs[0];
            assert!(default.label.starts_with("default"));
            assert_eq!(default.lobe_visibility, LobeVisibilityArg::default());
            let expected = plan.lobes.len() + plan.kappas.len() + plan.dodm_sizes.len() - 2;
            assert_eq!(configs.len(), 1 + expected, "{}", plan.name);
            let light_maps = configs
                .iter()
                .find(|c| c.label == light_maps_label(plan.kappas[0], plan.dodm_sizes[0]))
                .expect("Ren's light-map frame");
            let changed = |c: &SrbfConfig, base: &SrbfConfig| {
                [
                    c.lobes != base.lobes,
                    c.kappa != base.kappa,
                    c.dodm != base.dodm,
                    c.lobe_visibility != base.lobe_visibility,
                ]
                .iter()
                .filter(|&&x| x)
                .count()
            };
            assert_eq!(changed(light_maps, default), 1);
            for c in &configs[1..] {
                let base = match c.lobe_visibility {
                    LobeVisibilityArg::Auto | LobeVisibilityArg::Volume => default,
                    LobeVisibilityArg::LightMaps if c.label == light_maps.label => default,
                    LobeVisibilityArg::LightMaps => light_maps,
                };
                assert_eq!(changed(c, base), 1, "{}: one setting changed", c.label);
            }
        }
    }

    #[test]
    fn the_median_cut_curve_is_interpolated_log_log_at_an_error() {
        let curve = [
            point("m", 10.0, 0.4),
            point("m", 40.0, 0.1),
            point("m", 160.0, 0.025),
        ];
        let refs: Vec<&Point> = curve.iter().collect();
        let err = |p: &Point| p.relative_rmse;
        // Error ∝ 1/ms here: 0.2 lies halfway (in log) between 10 and 40 ms.
        assert!((curve_ms_at(&refs, 0.2, &err).unwrap() - 20.0).abs() < 1e-9);
        assert_eq!(curve_ms_at(&refs, 0.5, &err), Some(10.0));
        assert_eq!(curve_ms_at(&refs, 0.01, &err), None);
    }
}
