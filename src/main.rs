//! `strandlight`: the command-line front end. Parsing, progress and dispatch only; the work
//! lives in the library crates.

mod bench;
mod compare;
mod compare_table;
mod demo;
mod fit;
mod image_error;
mod render;
mod summary;
mod sweep_cmd;
mod tables_cmd;
mod truth;
mod view;

use clap::{Parser, Subcommand};

#[derive(Parser)]
#[command(
    name = "strandlight",
    version,
    about = "Strand hair under environment lighting (Ren et al. 2010)"
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand)]
enum Command {
    /// Print the fiber models, their default parameters and sample values (the default).
    Summary(summary::SummaryArgs),
    /// Fit SRBF lights to an environment map (Ren 2010 §3.1), or the median-cut baseline.
    Fit(fit::FitArgs),
    /// Hard-case sweep of every fiber model (NaN/Inf/negative counts), in parallel.
    Sweep(sweep_cmd::SweepArgs),
    /// Bake the convolution tables and point-light lookup textures for a fiber.
    Bake(tables_cmd::BakeArgs),
    /// Check baked tables against direct f64 integration at random off-grid points.
    CheckTables(tables_cmd::CheckArgs),
    /// Describe a baked table; optionally write its tiled slices as PNG and EXR.
    Inspect(tables_cmd::InspectArgs),
    /// Render a hair model headless under point lights to EXR (linear) and PNG (tonemapped).
    Render(render::RenderArgs),
    /// SRBF lights vs the brute-force cube-texel reference and the equal-time median-cut
    /// baseline (Ren 2010 §8): frame times, relative RMSE over hair pixels, images side by side.
    Compare(strandlight_eval::compare::CompareArgs),
    /// Speed against error on the shared data: fit, tables and env-lit frames against the
    /// converged reference, with plots; rewrites docs/BENCHMARKS.md's generated section.
    Bench(bench::BenchArgs),
    /// The path-traced ground truth of a scene (Mitsuba 3, the Chiang fiber), cached for
    /// `compare` and `bench`; `--export DIR` writes the scene's Mitsuba files instead.
    Truth(truth::TruthArgs),
    /// The markdown table of docs/BENCHMARKS.md from `compare --json` reports.
    CompareTable(compare_table::CompareTableArgs),
    /// Relative RMSE and HDR-FLIP between two EXR images over the reference's hair pixels.
    ImageError(image_error::ImageErrorArgs),
    /// The procedural groom under the project's sun-and-sky: fit → bake → env-lit render.
    Demo(demo::DemoArgs),
    /// Open a window on hair lit live: orbit, environment or lights, artist controls,
    /// progressive refinement, screenshots that `render --replay` reproduces.
    View(view::ViewArgs),
}

fn main() -> anyhow::Result<()> {
    let cli = Cli::parse();
    let default = Command::Summary(summary::SummaryArgs::default());
    match cli.command.unwrap_or(default) {
        Command::Summary(args) => summary::run(args),
        Command::Fit(args) => fit::run(args),
        Command::Sweep(args) => sweep_cmd::run(args),
        Command::Bake(args) => tables_cmd::bake(args),
        Command::CheckTables(args) => tables_cmd::check(args),
        Command::Inspect(args) => tables_cmd::inspect(args),
        Command::Render(args) => render::run(args),
        Command::Compare(args) => compare::run(args),
        Command::Bench(args) => bench::run(args),
        Command::CompareTable(args) => compare_table::run(args),
        Command::ImageError(args) => image_error::run(args),
        Command::Demo(args) => demo::run(args),
        Command::View(args) => view::run(args),
        Command::Truth(args) => truth::run(args),
    }
}
