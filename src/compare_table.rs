//! `strandlight compare-table`: the markdown table of docs/BENCHMARKS.md from `compare --json`
//! reports (built by `strandlight_eval::compare_table`).

use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct CompareTableArgs {
    /// `compare --json` reports (one per map).
    #[arg(required = true)]
    pub reports: Vec<PathBuf>,
}

pub fn run(args: CompareTableArgs) -> anyhow::Result<()> {
    println!(
        "{}",
        strandlight_eval::compare_table::markdown_table(&args.reports)?
    );
    Ok(())
}
