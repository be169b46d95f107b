//! A study input, not a product path: every N-th strand of a hair file, written as `.hair`
//! (scripts/fiber-scale-error.sh; docs/BENCHMARKS.md, "Fiber scale"). A sparse groom has little
//! self-shadowing and few fibers per pixel. Its transparency and colour are dropped (the Chiang
//! fiber ignores both); its thickness is kept.
//!
//! `cargo run --release -p strandlight-eval --example thin_groom -- IN OUT.hair N`

use anyhow::{Context, bail};
use std::path::PathBuf;
use strandlight_runtime::hair::{self, Attribute, HairModel, HairWriteOptions};

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [input, output, every] = args.as_slice() else {
        bail!("usage: thin_groom IN OUT.hair N (keeps every N-th strand)");
    };
    let every: usize = every
        .parse()
        .ok()
        .filter(|&n| n >= 1)
        .with_context(|| format!("N {every:?}: not a whole number ≥ 1"))?;
    let (input, output) = (PathBuf::from(input), PathBuf::from(output));
    let full = hair::load(&input)?.model;
    let thin = every_nth_strand(&full, every)?;
    let info = format!("every {every}th strand of {}", input.display());
    let options = HairWriteOptions {
        segments_array: true,
        info: info.chars().take(80).collect(),
    };
    hair::write_hair(&thin, &output, &options)?;
    println!(
        "wrote {}: {} of {} strands, {} points",
        output.display(),
        thin.strand_count(),
        full.strand_count(),
        thin.point_count()
    );
    Ok(())
}

fn every_nth_strand(model: &HairModel, every: usize) -> anyhow::Result<HairModel> {
    let offsets = model.strand_offsets();
    let widths = model
        .thickness()
        .map(|t| t.per_point_values(model.point_count()));
    let (mut points, mut kept_offsets, mut kept_widths) = (Vec::new(), vec![0u32], Vec::new());
    for strand in (0..model.strand_count()).step_by(every) {
        let range = offsets[strand] as usize..offsets[strand + 1] as usize;
        points.extend_from_slice(&model.points()[range.clone()]);
        if let Some(w) = &widths {
            kept_widths.extend_from_slice(&w[range]);
        }
        kept_offsets.push(points.len() as u32);
    }
    let thickness = model.thickness().map(|t| match t {
        Attribute::Uniform(w) => Attribute::Uniform(*w),
        Attribute::PerPoint(_) => Attribute::PerPoint(kept_widths),
    });
    Ok(HairModel::new(points, kept_offsets, thickness, None, None)?)
}
