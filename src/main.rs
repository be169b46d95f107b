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
mod web;

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
    /// Render one frame headless to EXR (linear) and PNG (tonemapped): `render env` under an
    /// environment map, `render lights` under point lights, `render replay` from a settings file.
    Render(render::RenderArgs),
    /// SRBF lights vs the brute-force cube-texel reference and the equal-time median-cut
    /// baseline (Ren 2010 §8): frame times, relative RMSE over hair pixels, images side by side.
    Compare(compare::CompareArgs),
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
    /// progressive refinement, screenshots that `render replay` reproduces.
    View(view::ViewArgs),
    /// A static site that renders the scene in a browser (WebGPU): the page and its bundle.
    Web(web::WebArgs),
    /// Serve a folder (the site of `web`) on localhost.
    Serve(web::ServeArgs),
}

fn main() -> anyhow::Result<()> {
    quiet_on_closed_pipe();
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
        Command::Web(args) => web::run(args),
        Command::Serve(args) => web::serve(args),
    }
}

/// Rust ignores SIGPIPE, so printing into a pipe its reader closed (`strandlight … | head`)
/// panics; a command-line tool should stop quietly, as `cat` does.
fn quiet_on_closed_pipe() {
    #[cfg(unix)]
    // SAFETY: called first in main, before any other thread exists; SIG_DFL is a valid handler.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

#[cfg(test)]
mod glossary {
    //! docs/GLOSSARY.md against the flags clap actually accepts, both ways.

    use super::Cli;
    use clap::CommandFactory;
    use std::collections::{BTreeMap, BTreeSet};

    /// (flag, subcommand path) for every long flag of every leaf subcommand.
    fn flags_in_code() -> BTreeSet<(String, String)> {
        fn walk(cmd: &clap::Command, path: &str, out: &mut BTreeSet<(String, String)>) {
            let leaves: Vec<_> = cmd
                .get_subcommands()
                .filter(|s| s.get_name() != "help")
                .collect();
            if leaves.is_empty() {
                for arg in cmd.get_arguments() {
                    if let Some(long) = arg.get_long()
                        && !matches!(long, "help" | "version")
                    {
                        out.insert((long.to_string(), path.to_string()));
                    }
                }
            }
            for sub in leaves {
                let name = match path {
                    "" => sub.get_name().to_string(),
                    _ => format!("{path} {}", sub.get_name()),
                };
                walk(sub, &name, out);
            }
        }
        let mut out = BTreeSet::new();
        walk(&Cli::command(), "", &mut out);
        out
    }

    /// The glossary's rows: flag → subcommands.
    fn flags_in_glossary(text: &str) -> BTreeMap<String, Vec<String>> {
        let mut rows = BTreeMap::new();
        for line in text.lines().filter(|l| l.starts_with("| `--")) {
            let cells: Vec<&str> = line.split(" | ").collect();
            let flag = cells[0].trim_start_matches("| `--").trim_end_matches('`');
            let subcommands = cells
                .last()
                .expect("a row has cells")
                .trim_end_matches(" |")
                .split(", ")
                .map(|s| s.trim_matches('`').to_string())
                .collect();
            let earlier = rows.insert(flag.to_string(), subcommands);
            assert!(
                earlier.is_none(),
                "--{flag} has two rows in docs/GLOSSARY.md"
            );
        }
        rows
    }

    #[test]
    fn glossary_names_every_flag_of_every_subcommand_and_nothing_else() {
        let text =
            std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/docs/GLOSSARY.md"))
                .expect("docs/GLOSSARY.md");
        let glossary: BTreeSet<(String, String)> = flags_in_glossary(&text)
            .into_iter()
            .flat_map(|(flag, subs)| subs.into_iter().map(move |s| (flag.clone(), s)))
            .collect();
        let code = flags_in_code();
        assert!(
            code.len() > 100,
            "only {} flags found: the walk is broken",
            code.len()
        );
        let missing: Vec<_> = code.difference(&glossary).collect();
        let stale: Vec<_> = glossary.difference(&code).collect();
        assert!(
            missing.is_empty() && stale.is_empty(),
            "docs/GLOSSARY.md is out of date.\n(flag, subcommand) the CLI has and the glossary lacks: {missing:?}\nrows the CLI no longer has: {stale:?}"
        );
    }

    #[test]
    fn every_subcommand_takes_at_most_25_flags() {
        let mut per_subcommand = BTreeMap::<String, usize>::new();
        for (_, sub) in flags_in_code() {
            *per_subcommand.entry(sub).or_default() += 1;
        }
        let over: Vec<_> = per_subcommand.iter().filter(|(_, n)| **n > 25).collect();
        assert!(over.is_empty(), "subcommands over 25 flags: {over:?}");
    }
}
