//! `strandlight sweep`: the benchmark-mode hard-case sweep of every fiber model. Each model's
//! `hard_case_sweep(samples, seed)` is split into chunks run in parallel (rayon) and merged in
//! chunk order, so the counts depend on `--samples` and `--seed` only, not on the thread count.

use serde::Serialize;
use std::io::IsTerminal;
use std::time::Instant;
use strandlight_tables::hard_case_sweep::{SweepReport, chunked_sweep};
use strandlight_tables::model_sweeps::{ModelSweep, SWEEPS};

#[derive(clap::Args)]
pub struct SweepArgs {
    /// Samples requested per model (benchmark mode: 10⁸, minutes on a few cores).
    #[arg(long, default_value_t = 100_000_000)]
    samples: u64,
    /// Seed of the sweep; chunk k of a model draws from a seed derived from it and k.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Print one JSON object instead of the table.
    #[arg(long)]
    json: bool,
}

#[derive(Serialize)]
struct ModelResult {
    name: &'static str,
    unit: &'static str,
    requested: u64,
    values_checked: u64,
    nan: u64,
    inf: u64,
    negative: u64,
    max_finite: f64,
    rejected_parameter_sets: u64,
    seconds: f64,
    requested_per_second: f64,
}

impl ModelResult {
    fn new(sweep: &ModelSweep, requested: u64, r: &SweepReport, seconds: f64) -> Self {
        Self {
            name: sweep.name,
            unit: sweep.unit,
            requested,
            values_checked: r.samples,
            nan: r.nan,
            inf: r.infinite,
            negative: r.negative,
            max_finite: r.max_finite,
            rejected_parameter_sets: r.rejected,
            seconds,
            requested_per_second: requested as f64 / seconds.max(1e-9),
        }
    }

    fn is_clean(&self) -> bool {
        self.nan == 0 && self.inf == 0 && self.negative == 0
    }
}

#[derive(Serialize)]
struct SweepSummary {
    samples_per_model: u64,
    seed: u64,
    threads: usize,
    clean: bool,
    models: Vec<ModelResult>,
}

pub fn run(args: SweepArgs) -> anyhow::Result<()> {
    let bar = progress_bar(!args.json, args.samples * SWEEPS.len() as u64);
    let models: Vec<ModelResult> = SWEEPS
        .iter()
        .map(|s| run_one(s, args.samples, args.seed, &bar))
        .collect();
    bar.finish_and_clear();
    let summary = SweepSummary {
        samples_per_model: args.samples,
        seed: args.seed,
        threads: rayon::current_num_threads(),
        clean: models.iter().all(ModelResult::is_clean),
        models,
    };
    if args.json {
        println!("{}", serde_json::to_string_pretty(&summary)?);
    } else {
        print_table(&summary);
    }
    anyhow::ensure!(
        summary.clean,
        "the hard-case sweep found NaN, Inf or negative values"
    );
    Ok(())
}

fn run_one(
    sweep: &ModelSweep,
    samples: u64,
    seed: u64,
    bar: &indicatif::ProgressBar,
) -> ModelResult {
    bar.set_message(sweep.name);
    let start = Instant::now();
    let report = chunked_sweep(sweep.name, samples, seed, sweep.chunk, sweep.run, |n| {
        bar.inc(n)
    });
    ModelResult::new(sweep, samples, &report, start.elapsed().as_secs_f64())
}

/// A bar on stderr when it is a terminal (and the output is not JSON); hidden otherwise.
fn progress_bar(wanted: bool, total: u64) -> indicatif::ProgressBar {
    if !wanted || !std::io::stderr().is_terminal() {
        return indicatif::ProgressBar::hidden();
    }
    let bar = indicatif::ProgressBar::new(total);
    if let Ok(style) = indicatif::ProgressStyle::with_template(
        "{msg:>16} [{bar:40}] {human_pos}/{human_len} samples, eta {eta}",
    ) {
        bar.set_style(style.progress_chars("=> "));
    }
    bar
}

fn print_table(s: &SweepSummary) {
    println!(
        "hard-case sweep: {} samples per model, seed {}, {} threads",
        s.samples_per_model, s.seed, s.threads
    );
    println!(
        "{:<16} {:>12} {:>14} {:>5} {:>5} {:>5} {:>11} {:>9} {:>9} {:>12}",
        "model",
        "samples",
        "values",
        "NaN",
        "Inf",
        "neg",
        "max finite",
        "rejected",
        "seconds",
        "samples/s"
    );
    for m in &s.models {
        println!(
            "{:<16} {:>12} {:>14} {:>5} {:>5} {:>5} {:>11.3e} {:>9} {:>9.2} {:>12.3e}",
            m.name,
            m.requested,
            m.values_checked,
            m.nan,
            m.inf,
            m.negative,
            m.max_finite,
            m.rejected_parameter_sets,
            m.seconds,
            m.requested_per_second
        );
    }
    println!("a sample is: {}", sample_units());
    println!(
        "{}",
        if s.clean {
            "clean: no NaN, Inf or negative value"
        } else {
            "NOT CLEAN"
        }
    );
}

fn sample_units() -> String {
    SWEEPS
        .iter()
        .map(|s| format!("{} = {}", s.name, s.unit))
        .collect::<Vec<_>>()
        .join("; ")
}
