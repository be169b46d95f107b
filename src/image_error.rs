//! `strandlight image-error TEST.exr REF.exr`: the errors `compare` reports (relative RMSE and
//! HDR-FLIP over the reference's hair pixels), between any two of its EXR images — e.g. a
//! 384-light reference against a 1536-light one, to show how far a reduced reference is from
//! converged. A second line gives the error over blocks of 1, 2, 4 and 16 pixels a side, the
//! coverage's error and the mean ratio (`ScaleErrors`); a third splits the error into what one
//! brightness scale removes (a bias) and what it leaves (a pattern), and says how the brightest
//! tenth of the hair compares. Given the single-scattering images of the same two frames
//! (`--single`), it splits a full frame's error into its single- and multiple-scattering parts
//! at every scale (issue 65: each term against the truth on its own).

use std::path::PathBuf;

use anyhow::Context;
use clap::Args;

use strandlight_eval::ground_truth::{read_truth_sidecar, without_noise};
use strandlight_eval::hdr_flip::{error_map_magma, hdr_flip};
use strandlight_eval::reference_cache::read_rgba_exr;
use strandlight_scene::image_metrics::{
    ERROR_SCALES, Image, ScaleErrors, error_split, mean_ratio, relative_rmse,
    relative_rmse_of_part_over_blocks,
};

#[derive(Args, Debug)]
pub struct ImageErrorArgs {
    /// The image to measure (RGBA EXR as `compare` and `render` write them).
    pub test: PathBuf,
    /// The reference (its alpha decides which pixels are hair).
    pub reference: PathBuf,
    /// Also write HDR-FLIP's error map here (PNG, magma colour map from 0 to 1).
    #[arg(long, value_name = "PNG")]
    pub flip_map: Option<PathBuf>,
    /// The single-scattering images of the same frames, the test's then the reference's, when
    /// TEST and REFERENCE are full scattering: reports each part (single, and full less single)
    /// against the reference's, over the full reference's norm at every scale, and its light.
    #[arg(long, num_args = 2, value_names = ["TEST_SINGLE", "REFERENCE_SINGLE"])]
    pub single: Option<Vec<PathBuf>>,
}

fn read(path: &std::path::Path) -> anyhow::Result<Image> {
    read_rgba_exr(path).with_context(|| format!("reading {}", path.display()))
}

/// One line per part: its light against the reference part's and its error at every scale,
/// each over the full reference's norm (the parts add as vectors to the full frame's error).
fn print_parts(
    test: &Image,
    reference: &Image,
    [test_single, reference_single]: [&std::path::Path; 2],
) -> anyhow::Result<()> {
    let (ts, rs) = (read(test_single)?, read(reference_single)?);
    let single_pair = || {
        format!(
            "{} against {}",
            test_single.display(),
            reference_single.display()
        )
    };
    let test_multiple = test.minus(&ts).with_context(single_pair)?;
    let reference_multiple = reference.minus(&rs).with_context(single_pair)?;
    for (name, a, r) in [
        ("single-scattering part", &ts, &rs),
        (
            "multiple-scattering part (full less single)",
            &test_multiple,
            &reference_multiple,
        ),
    ] {
        let light = mean_ratio(a, r).with_context(single_pair)?;
        let scales = ERROR_SCALES
            .iter()
            .map(|&n| {
                let e = relative_rmse_of_part_over_blocks(a, r, reference, n)?;
                Ok(format!("{n}×{n} {e:.4}"))
            })
            .collect::<Result<Vec<_>, strandlight_scene::image_metrics::CompareError>>()
            .with_context(single_pair)?;
        println!(
            "{name}: {light:.4}× the reference's light; error over the full reference's norm {}",
            scales.join(", ")
        );
    }
    Ok(())
}

pub fn run(args: ImageErrorArgs) -> anyhow::Result<()> {
    let test = read(&args.test)?;
    let reference = read(&args.reference)?;
    let pair = || {
        format!(
            "{} against {}",
            args.test.display(),
            args.reference.display()
        )
    };
    let error = relative_rmse(&test, &reference).with_context(pair)?;
    let flip = hdr_flip(&test, &reference).with_context(pair)?;
    let mean = mean_ratio(&test, &reference).with_context(pair)?;
    println!(
        "relative RMSE {error:.4}, HDR-FLIP {:.4} ({} exposures {:+.2} to {:+.2}), mean {mean:.4}× the reference's  ({}, over the reference's hair pixels)",
        flip.mean_over_hair,
        flip.exposures,
        flip.start_exposure,
        flip.stop_exposure,
        pair()
    );
    let scales = ScaleErrors::of(&test, &reference).with_context(pair)?;
    println!("at every scale: {}", scales.line());
    let split = error_split(&test, &reference).with_context(pair)?;
    println!(
        "bias and pattern: the best single scale {:.4} leaves relative RMSE {:.4}; the brightest tenth of the hair is {:.4}× the reference's and holds {:.0}% of the squared error",
        split.best_scale,
        split.relative_rmse_after_scale,
        split.brightest_tenth_ratio,
        100.0 * split.brightest_tenth_share
    );
    if let Some(truth) = read_truth_sidecar(&args.reference) {
        println!(
            "the reference is a path-traced ground truth ({}, {} spp, depth {}{}) with noise {:.4}: without it, relative RMSE {:.4}",
            truth.renderer,
            truth.spp,
            truth.max_depth,
            if truth.converged {
                ""
            } else {
                ", not converged"
            },
            truth.noise,
            without_noise(error, truth.noise)
        );
    }
    if let Some(single) = &args.single {
        print_parts(&test, &reference, [&single[0], &single[1]])?;
    }
    if let Some(path) = &args.flip_map {
        let (w, h) = (reference.width, reference.height);
        strandlight_tables::image_out::write_png_rgb8(
            path,
            w,
            h,
            &error_map_magma(&flip, w, h),
            &format!("HDR-FLIP error map (magma, 0 → 1): {}", pair()),
        )?;
        println!("wrote {}", path.display());
    }
    Ok(())
}
