//! Every transparency technique against the A-buffer on a small procedural groom, end to end
//! through `render_frame`: the A-buffer sorts every fragment of a pixel (none are left out on
//! this groom: its depth complexity stays under the resolve's 64), so it is the reference.
//! - K-buffer with k = 64 (beyond the depth complexity: nothing dropped) equals it up to its
//!   RGBA16F slots; with smaller k the error never grows as k grows.
//! - Bin-sorted blending is exact where the segments of one bin do not overlap in a pixel;
//!   with short segments and many bins it comes within a stated tolerance.
//! - One random subset is the opaque pass (up to its RGBA16F layer); more subsets come closer
//!   to the A-buffer.
//! - DBK with Δ covering the whole hair lists every fragment and equals it (also on three
//!   strands in `abuffer.rs`).

use crate::common::*;

use glam::Vec3;
use strandlight_runtime::camera::Camera;
use strandlight_runtime::hair::{GroomParams, HairModel, generate_groom};
use strandlight_runtime::lights::Light;
use strandlight_runtime::passes::frame_params::{FrameParams, KajiyaKay};
use strandlight_runtime::point_frame::{PointImage, RenderOptions, Transparency, render_frame};

const SIZE: u32 = 96;

fn groom() -> HairModel {
    generate_groom(&GroomParams {
        strand_count: 1000,
        points_per_strand: 24,
        clump_count: 40,
        thickness: 0.05,
        ..GroomParams::default()
    })
    .unwrap()
}

fn render(
    gpu: &strandlight_runtime::gpu::GpuContext,
    hair: &HairModel,
    t: Transparency,
) -> PointImage {
    let frame = FrameParams {
        camera: Camera::framing(hair.bounds(), 1.0, false),
        width: SIZE,
        height: SIZE,
        lights: vec![Light::Directional {
            direction: Vec3::new(0.4, 0.6, 1.0).normalize(),
            intensity: 2.0,
        }],
        shading: KajiyaKay::default(),
        width_override_px: None,
    };
    let options = RenderOptions {
        shadows: None,
        transparency: t,
        ..Default::default()
    };
    render_frame(gpu, hair, &frame, &options).unwrap_or_else(|e| panic!("{t:?}: {e}"))
}

/// [`relative_rmse`] of two frames.
fn frame_error(a: &PointImage, b: &PointImage) -> f64 {
    relative_rmse(&a.pixels, &b.pixels)
}

#[test]
fn every_technique_approaches_the_abuffer() {
    let gpu = gpu();
    let hair = groom();
    let reference = render(
        &gpu,
        &hair,
        Transparency::ABuffer {
            nodes_per_pixel: None,
        },
    );
    let counts = reference.stats.fragments.unwrap();
    assert_eq!(
        (counts.dropped, counts.truncated),
        (0, 0),
        "the reference must composite every fragment"
    );
    assert!(
        counts.stored > 20_000,
        "a thin scene: {} fragments",
        counts.stored
    );

    let full = render(&gpu, &hair, Transparency::KBuffer { k: 64 });
    let full_counts = full.stats.fragments.unwrap();
    assert_eq!(full_counts.dropped, 0);
    assert_eq!(
        full_counts.stored, counts.stored,
        "k = 64 keeps every fragment"
    );
    let full_error = frame_error(&full, &reference);
    eprintln!("K-buffer k = 64: relative RMSE {full_error:.2e} against the A-buffer");
    assert!(full_error < 2e-3, "k = 64: {full_error}");

    // DBK with Δ across the whole hair lists every fragment: the A-buffer's image.
    let whole = render(
        &gpu,
        &hair,
        Transparency::Dbk {
            nodes_per_pixel: None,
            delta: 2.0 * hair.bounds().diagonal(),
        },
    );
    let whole_counts = whole.stats.fragments.unwrap();
    assert_eq!(
        (whole_counts.stored, whole_counts.dropped),
        (counts.stored, 0),
        "DBK with Δ over the whole hair keeps every fragment"
    );
    let dbk_error = frame_error(&whole, &reference);
    eprintln!("DBK, Δ = twice the diagonal: relative RMSE {dbk_error:.2e} against the A-buffer");
    assert!(dbk_error < 2e-3, "DBK over the whole volume: {dbk_error}");

    let mut previous = f64::INFINITY;
    let mut errors = Vec::new();
    for k in [1, 2, 4, 8, 16, 32] {
        let frame = render(&gpu, &hair, Transparency::KBuffer { k });
        let c = frame.stats.fragments.unwrap();
        assert_eq!(
            c.stored + c.dropped,
            counts.stored,
            "k = {k}: every fragment kept or counted"
        );
        let error = frame_error(&frame, &reference);
        errors.push((k, error, c.dropped));
        assert!(
            error <= previous + 1e-4,
            "k = {k}: error {error} grew from {previous}"
        );
        previous = error;
    }
    eprintln!("K-buffer (k, relative RMSE, fragments dropped): {errors:?}");
    assert!(
        errors[0].1 > 10.0 * errors[5].1,
        "k = 1 should be far worse than k = 32"
    );

    let mut sorted = Vec::new();
    for bins in [16, 256, 4096] {
        let frame = render(&gpu, &hair, Transparency::Sorted { bins });
        sorted.push((bins, frame_error(&frame, &reference)));
    }
    let opaque_frame = render(&gpu, &hair, Transparency::Opaque);
    let opaque = frame_error(&opaque_frame, &reference);
    eprintln!("sorted blending (bins, relative RMSE): {sorted:?}; opaque: {opaque:.4}");

    // One subset is the opaque pass (same segments, same order); more approach the A-buffer.
    let one = render(&gpu, &hair, Transparency::RandomSubsets { subsets: 1 });
    // Same segments in the same order; only the subset layer's half floats differ.
    let one_error = frame_error(&one, &opaque_frame);
    eprintln!("one random subset against the opaque pass: relative RMSE {one_error:.2e}");
    assert!(
        one_error < 2e-3,
        "one random subset must be the opaque pass: {one_error}"
    );
    let subsets: Vec<(u32, f64)> = [2, 4, 8, 16]
        .into_iter()
        .map(|n| {
            let frame = render(&gpu, &hair, Transparency::RandomSubsets { subsets: n });
            (n, frame_error(&frame, &reference))
        })
        .collect();
    eprintln!("random subsets (k, relative RMSE): {subsets:?}");
    assert!(
        subsets.windows(2).all(|w| w[1].1 < w[0].1),
        "more subsets must come closer"
    );
    assert!(subsets[0].1 < opaque);
    assert!(sorted[2].1 < 0.02, "4096 bins: {}", sorted[2].1);
    assert!(
        sorted[1].1 < opaque,
        "256 bins must beat unsorted opaque blending"
    );
}

#[test]
fn bad_counts_are_refused() {
    let gpu = gpu();
    let hair = groom();
    let frame = FrameParams {
        camera: Camera::framing(hair.bounds(), 1.0, false),
        width: 16,
        height: 16,
        lights: vec![Light::Directional {
            direction: Vec3::Z,
            intensity: 1.0,
        }],
        shading: KajiyaKay::default(),
        width_override_px: None,
    };
    for t in [
        Transparency::KBuffer { k: 0 },
        Transparency::KBuffer { k: 65 },
        Transparency::Sorted { bins: 0 },
        Transparency::Sorted { bins: 1 << 20 },
        Transparency::RandomSubsets { subsets: 0 },
        Transparency::RandomSubsets { subsets: 17 },
    ] {
        let options = RenderOptions {
            shadows: None,
            transparency: t,
            ..Default::default()
        };
        let error = render_frame(&gpu, &hair, &frame, &options).err();
        assert!(error.is_some(), "{t:?} was accepted");
        eprintln!("{t:?}: {}", error.unwrap());
    }
}
