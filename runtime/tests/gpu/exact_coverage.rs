//! The env view's coverage of fibers thinner than a pixel: each pixel is covered by the length
//! of the fiber's centre line inside its square times the fiber's width (the box filter the
//! path tracer integrates), in every view. The reference walks each polyline in steps of 10⁻³
//! pixel and bins the steps into pixels, here in f64: no clipping code is shared with the
//! shader. Within 2% of the width per pixel: a strand whose pieces in one pixel are more than
//! three (the last strand here) composes them from partial sums (strand_quads.wgsl,
//! `exact_fragment`), 1.5% off; with one-pixel quads the same pixels are off by up to 80%.

use crate::common::*;

use glam::{DVec2, Vec3};
use strandlight_runtime::env::{EnvRenderOptions, EnvTables, ViewTransparency, render_env_frame};
use strandlight_runtime::env_light::EnvLight;
use strandlight_runtime::hair::{Attribute, HairModel};
use strandlight_runtime::passes::convolution_depth::DodmSettings;
use strandlight_tables::table::{Axis, Table};
use strandlight_tables::table_axes::{AXIS_COS_DPHI, AXIS_U_DOT_WO, AXIS_U_DOT_XI};

/// World units per pixel of the orthographic test camera (RES pixels over 2 units).
const UNIT_PX: f64 = RES as f64 / 2.0;
/// The fibers' width, pixels.
const WIDTH_PX: f64 = 0.3;

/// Bent strands at odd angles and sub-pixel offsets, far enough apart that no pixel holds two.
fn strands() -> Vec<Vec<DVec2>> {
    let strand = |start: (f64, f64), turns: &[(f64, f64)]| {
        let mut p = DVec2::new(start.0, start.1);
        let mut points = vec![p];
        for &(degrees, length) in turns {
            let a = degrees.to_radians();
            p += DVec2::new(a.cos(), a.sin()) * length;
            points.push(p);
        }
        points
    };
    vec![
        strand(
            (4.3, 5.17),
            &[(7.0, 9.4), (31.0, 6.2), (58.0, 3.7), (80.0, 5.9)],
        ),
        strand((30.61, 6.08), &[(95.0, 12.3), (121.0, 0.8), (150.0, 7.7)]),
        strand(
            (8.2, 40.45),
            &[(-33.0, 11.1), (2.0, 2.6), (45.0, 8.3), (-71.0, 6.4)],
        ),
        strand(
            (40.9, 38.3),
            &[(180.0 + 12.0, 3.3), (250.0, 9.9), (300.0, 0.45)],
        ),
        strand((50.5, 50.5), &[(0.0, 7.0), (90.0, 6.0)]),
        // Pieces shorter than a pixel: a pixel holds up to four of one strand.
        strand((20.3, 50.2), &[(20.0, 0.31); 16]),
    ]
}

/// Pixel (x right, y down) to world: (0, 0) is the image's top-left corner.
fn world(p: DVec2) -> Vec3 {
    Vec3::new(
        (p.x / UNIT_PX - 1.0) as f32,
        (1.0 - p.y / UNIT_PX) as f32,
        0.0,
    )
}

fn model() -> HairModel {
    let mut points = Vec::new();
    let mut offsets = vec![0u32];
    for strand in strands() {
        points.extend(strand.iter().map(|&p| world(p)));
        offsets.push(points.len() as u32);
    }
    HairModel::new(
        points,
        offsets,
        Some(Attribute::Uniform((WIDTH_PX / UNIT_PX) as f32)),
        None,
        None,
    )
    .unwrap()
}

/// Each pixel's coverage by the strands' centre lines × their width, in f64.
fn binned_coverage() -> Vec<f64> {
    let mut coverage = vec![0.0; (RES * RES) as usize];
    const STEP: f64 = 1e-3;
    for strand in strands() {
        for pair in strand.windows(2) {
            let length = (pair[1] - pair[0]).length();
            let steps = (length / STEP).ceil() as usize;
            for k in 0..steps {
                let p = pair[0].lerp(pair[1], (k as f64 + 0.5) / steps as f64);
                let pixel = p.y.floor() as usize * RES as usize + p.x.floor() as usize;
                coverage[pixel] += length / steps as f64 * WIDTH_PX;
            }
        }
    }
    coverage
}

/// A table of one colour: only the coverage shows.
fn grey_table() -> Table {
    let axes = vec![
        Axis::uniform(AXIS_U_DOT_XI, -1.0, 1.0, 3),
        Axis::uniform(AXIS_U_DOT_WO, -1.0, 1.0, 3),
        Axis::uniform(AXIS_COS_DPHI, -1.0, 1.0, 3),
        Axis::uniform("w", 0.0, 0.0, 1),
    ];
    Table::from_fn(axes, 3, |_, out| out.fill(1.0)).unwrap()
}

fn alpha(transparency: ViewTransparency) -> Vec<f64> {
    let options = EnvRenderOptions {
        dodm: DodmSettings {
            resolution: 64,
            first_layer: None,
            batch_size: 4,
        },
        kappa: 1.0,
        shadowed: false,
        transparency,
        ..Default::default()
    };
    let tables = EnvTables {
        direct: Some(grey_table().into()),
        ..Default::default()
    };
    let lights = [EnvLight::directional(Vec3::X, [1.0; 3])];
    let frame = render_env_frame(
        &gpu(),
        &model(),
        &ortho_camera(),
        RES,
        RES,
        &lights,
        &tables,
        &options,
        None,
    )
    .unwrap();
    frame.pixels.iter().map(|p| p[3] as f64).collect()
}

#[test]
fn a_thin_fiber_covers_each_pixel_by_the_length_of_its_line_in_it() {
    let want = binned_coverage();
    let total: f64 = want.iter().sum();
    for transparency in [
        ViewTransparency::Opaque,
        ViewTransparency::Occupancy {
            visibility_cutoff: 0.0,
        },
        ViewTransparency::Layered {
            visibility_cutoff: 0.0,
        },
    ] {
        let got = alpha(transparency);
        let mut worst = (0.0, 0);
        for (i, (g, w)) in got.iter().zip(&want).enumerate() {
            let error = (g - w).abs();
            if error > worst.0 {
                worst = (error, i);
            }
        }
        let (error, i) = worst;
        assert!(
            error <= 0.02 * WIDTH_PX,
            "{transparency:?}: pixel ({}, {}) has coverage {:.5}, its line's length × width is \
             {:.5}",
            i % RES as usize,
            i / RES as usize,
            got[i],
            want[i]
        );
        let sum: f64 = got.iter().sum();
        assert!(
            (sum / total - 1.0).abs() < 0.002,
            "{transparency:?}: coverage sums to {sum:.4}, the lines' length × width to {total:.4}"
        );
    }
}
