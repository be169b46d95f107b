//! `strandlight image-error TEST.exr REFERENCE.exr`: the relative RMSE `compare` reports, between
//! any two of its EXR images — e.g. a 384-light reference against a 1536-light one, to show how
//! far a reduced reference is from converged.

use std::path::PathBuf;

use anyhow::Context;
use clap::Args;

use strandlight_scene::image_metrics::relative_rmse;
use strandlight_scene::reference_cache::read_rgba_exr;

#[derive(Args, Debug)]
pub struct ImageErrorArgs {
    /// The image to measure (RGBA EXR as `compare` and `render` write them).
    pub test: PathBuf,
    /// The reference (its alpha decides which pixels are hair).
    pub reference: PathBuf,
}

pub fn run(args: ImageErrorArgs) -> anyhow::Result<()> {
    let test =
        read_rgba_exr(&args.test).with_context(|| format!("reading {}", args.test.display()))?;
    let reference = read_rgba_exr(&args.reference)
        .with_context(|| format!("reading {}", args.reference.display()))?;
    let error = relative_rmse(&test, &reference).with_context(|| {
        format!(
            "{} against {}",
            args.test.display(),
            args.reference.display()
        )
    })?;
    println!(
        "relative RMSE {error:.4}  ({} against {}, over the reference's hair pixels)",
        args.test.display(),
        args.reference.display()
    );
    Ok(())
}
