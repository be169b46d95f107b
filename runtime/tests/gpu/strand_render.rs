//! The strand pass against independent CPU computations: Kajiya-Kay shading of a single straight
//! strand at sampled pixels (f64, several lights of every kind), and the coverage alpha of
//! sub-pixel strands summed across the strand against their width in pixels.

use crate::common::*;

use glam::Vec3;
use strandlight_runtime::camera::{Camera, Projection};
use strandlight_runtime::hair::{Attribute, HairModel};
use strandlight_runtime::lights::Light;
use strandlight_runtime::passes::frame_params::{FrameParams, KajiyaKay};
use strandlight_runtime::point_frame::{RenderOptions, render_frame};

const SIZE: u32 = 64;

fn straight_strand(
    from: Vec3,
    to: Vec3,
    points: usize,
    thickness: Option<f32>,
    color: Vec3,
) -> HairModel {
    let pts = (0..points)
        .map(|i| from.lerp(to, i as f32 / (points - 1) as f32))
        .collect();
    HairModel::new(
        pts,
        vec![0, points as u32],
        thickness.map(Attribute::Uniform),
        None,
        Some(Attribute::Uniform(color)),
    )
    .unwrap()
}

fn pixel(frame: &strandlight_runtime::point_frame::PointImage, x: u32, y: u32) -> [f32; 4] {
    frame.pixels[(y * frame.width + x) as usize]
}

/// Kajiya-Kay in f64, written from the textbook form: diffuse kd·c·sin(t,l); specular
/// ks·cos(angle between e and the cone of mirror directions around t)^p.
fn kajiya_kay_f64(
    t: [f64; 3],
    l: [f64; 3],
    e: [f64; 3],
    c: [f64; 3],
    kd: f64,
    ks: f64,
    p: f64,
) -> [f64; 3] {
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let theta_l = dot(t, l).clamp(-1.0, 1.0).acos();
    let theta_e = dot(t, e).clamp(-1.0, 1.0).acos();
    // The mirror cone makes angle π − θ_l with t; e makes θ_e.
    let cone = (theta_e - (std::f64::consts::PI - theta_l)).cos().max(0.0);
    let spec = ks * cone.powf(p);
    [0, 1, 2].map(|k| kd * c[k] * theta_l.sin() + spec)
}

fn normalize(v: [f64; 3]) -> [f64; 3] {
    let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    v.map(|x| x / n)
}

/// The strand's colour and the Kajiya-Kay constants of the three-light test.
const STRAND_COLOR: [f64; 3] = [0.5, 0.3, 0.2];
const THREE_LIGHT_SHADING: KajiyaKay = KajiyaKay {
    kd: 0.6,
    ks: 0.4,
    shininess: 20.0,
};
/// The spot light of the three-light test: position, axis and half-angle in degrees.
const SPOT_POSITION: [f64; 3] = [-1.0, 0.0, 2.0];
const SPOT_AXIS: [f64; 3] = [1.0, 0.0, -2.0];
const SPOT_HALF_ANGLE_DEGREES: f64 = 12.0;

/// A directional, a point and a spot light; the spot lights part of the strand.
fn three_lights() -> Vec<Light> {
    let [x, y, z] = SPOT_POSITION.map(|c| c as f32);
    let [ax, ay, az] = SPOT_AXIS.map(|c| c as f32);
    vec![
        Light::Directional {
            direction: Vec3::new(1.0, 0.5, 1.0).normalize(),
            intensity: 1.0,
        },
        Light::Point {
            position: Vec3::new(1.5, 1.0, 2.0),
            intensity: 6.0,
        },
        Light::Spot {
            position: Vec3::new(x, y, z),
            direction: Vec3::new(ax, ay, az).normalize(),
            half_angle: SPOT_HALF_ANGLE_DEGREES.to_radians() as f32,
            intensity: 4.0,
        },
    ]
}

/// The CPU's radiance of [`three_lights`] at `world` on a strand of tangent `dir` seen along
/// +z, and whether the spot lights it; None on the spot cone's hard edge, where either answer
/// is right.
fn three_light_radiance(dir: [f64; 3], world: [f64; 3]) -> Option<([f64; 3], bool)> {
    let e = [0.0, 0.0, 1.0];
    let KajiyaKay { kd, ks, shininess } = THREE_LIGHT_SHADING;
    let (kd, ks, p) = (kd as f64, ks as f64, shininess as f64);
    let kk = |l: [f64; 3]| kajiya_kay_f64(dir, l, e, STRAND_COLOR, kd, ks, p);
    let mut expected = kk(normalize([1.0, 0.5, 1.0]));
    let point_to = [1.5 - world[0], 1.0 - world[1], 2.0 - world[2]];
    let d2 = point_to.iter().map(|x| x * x).sum::<f64>();
    let point = kk(normalize(point_to));
    for k in 0..3 {
        expected[k] += 6.0 / d2 * point[k];
    }
    let spot_to: [f64; 3] = std::array::from_fn(|k| SPOT_POSITION[k] - world[k]);
    let s2 = spot_to.iter().map(|x| x * x).sum::<f64>();
    let l = normalize(spot_to);
    let axis = normalize(SPOT_AXIS);
    let cos_off_axis = -(l[0] * axis[0] + l[1] * axis[1] + l[2] * axis[2]);
    let cos_half_angle = SPOT_HALF_ANGLE_DEGREES.to_radians().cos();
    if (cos_off_axis - cos_half_angle).abs() < 2e-3 {
        return None;
    }
    let spot_lit = cos_off_axis >= cos_half_angle;
    if spot_lit {
        let spot = kk(l);
        for k in 0..3 {
            expected[k] += 4.0 / s2 * spot[k];
        }
    }
    Some((expected, spot_lit))
}

#[test]
fn a_single_strand_matches_cpu_kajiya_kay_under_three_lights() {
    let gpu = gpu();
    // Tilted 30° toward the camera in the y–z plane so that (t·l)(t·e) ≠ 0; it still projects
    // onto the image column x = 0.
    let tilt = 30f64.to_radians();
    let dir = [0.0, tilt.cos(), tilt.sin()];
    let half_len = 0.8;
    let a = Vec3::new(
        0.0,
        -(half_len * dir[1]) as f32,
        -(half_len * dir[2]) as f32,
    );
    let b = -a;
    let [r, g, b_] = STRAND_COLOR.map(|c| c as f32);
    let model = straight_strand(a, b, 9, None, Vec3::new(r, g, b_));
    let frame = FrameParams {
        camera: ortho_camera(),
        width: SIZE,
        height: SIZE,
        lights: three_lights(),
        shading: THREE_LIGHT_SHADING,
        width_override_px: Some(4.0),
    };
    let out = render_frame(&gpu, &model, &frame, &RenderOptions::default()).unwrap();
    let mut worst = 0.0f64;
    let mut compared = 0;
    let mut spot_lit_rows = 0;
    for row in 12..52u32 {
        // Pixel centre's world y, and the strand point there.
        let y = 1.0 - (row as f64 + 0.5) / 32.0;
        let s = y / dir[1];
        let Some((expected, spot_lit)) = three_light_radiance(dir, [0.0, y, s * dir[2]]) else {
            continue;
        };
        spot_lit_rows += spot_lit as usize;
        for column in [31u32, 32] {
            let got = pixel(&out, column, row);
            assert!(
                (got[3] - 1.0).abs() < 1e-6,
                "row {row} col {column}: alpha {}",
                got[3]
            );
            for k in 0..3 {
                let err = (got[k] as f64 - expected[k]).abs() / expected[k].abs().max(1e-3);
                worst = worst.max(err);
                compared += 1;
                assert!(
                    err < 3e-3,
                    "row {row} col {column} channel {k}: GPU {} CPU {}",
                    got[k],
                    expected[k]
                );
            }
        }
    }
    eprintln!(
        "Kajiya-Kay: {compared} channel samples, worst relative error {worst:.2e}; spot lit {spot_lit_rows} of the rows; adapter {}",
        out.stats.adapter
    );
    assert!(
        spot_lit_rows > 5 && spot_lit_rows < 35,
        "the spot cone should light only part of the strand"
    );
    // Nothing outside the 4-pixel quad.
    for row in 0..SIZE {
        for column in (0..28).chain(36..SIZE) {
            assert_eq!(
                pixel(&out, column, row),
                [0.0; 4],
                "pixel ({column}, {row})"
            );
        }
    }
}

/// Mean over interior rows of the alpha summed along each row.
fn mean_row_alpha(
    out: &strandlight_runtime::point_frame::PointImage,
    rows: std::ops::Range<u32>,
) -> (f64, f64) {
    let sums: Vec<f64> = rows
        .map(|row| (0..out.width).map(|x| pixel(out, x, row)[3] as f64).sum())
        .collect();
    let mean = sums.iter().sum::<f64>() / sums.len() as f64;
    let spread = sums.iter().map(|s| (s - mean).abs()).fold(0.0, f64::max);
    (mean, spread)
}

#[test]
fn coverage_alpha_of_sub_pixel_strands_integrates_to_their_width() {
    let gpu = gpu();
    let white = Vec3::ONE;
    let lights = vec![Light::Directional {
        direction: Vec3::Z,
        intensity: 1.0,
    }];
    let params = |camera, width_override_px| FrameParams {
        camera,
        width: SIZE,
        height: SIZE,
        lights: lights.clone(),
        shading: KajiyaKay::default(),
        width_override_px,
    };
    // 0.3 px right of a column boundary, so the one-pixel quad covers exactly one pixel centre.
    let x = 0.3 / 32.0;
    let vertical = straight_strand(
        Vec3::new(x, -0.8, 0.0),
        Vec3::new(x, 0.8, 0.0),
        5,
        Some(0.02),
        white,
    );

    // The user's width.
    let out = render_frame(
        &gpu,
        &vertical,
        &params(ortho_camera(), Some(0.37)),
        &RenderOptions::default(),
    )
    .unwrap();
    let (mean, spread) = mean_row_alpha(&out, 12..52);
    eprintln!("user width 0.37 px: row alpha sum mean {mean:.6}, max deviation {spread:.2e}");
    assert!((mean - 0.37).abs() < 1e-4 && spread < 1e-4);

    // The file's thickness 0.02 at 32 px per unit: 0.64 px.
    let out = render_frame(
        &gpu,
        &vertical,
        &params(ortho_camera(), None),
        &RenderOptions::default(),
    )
    .unwrap();
    let (mean, spread) = mean_row_alpha(&out, 12..52);
    eprintln!(
        "thickness 0.02 orthographic (0.64 px): row alpha sum mean {mean:.6}, max deviation {spread:.2e}"
    );
    assert!((mean - 0.64).abs() < 1e-4 && spread < 1e-4);

    // Perspective: 0.02 at depth 5 with a 30° field of view over 64 rows.
    let fov: f64 = 30f64.to_radians();
    let perspective = Camera {
        projection: Projection::Perspective { fov_y: fov as f32 },
        ..ortho_camera()
    };
    let expected = 0.02 * (SIZE as f64 / 2.0) / (5.0 * (fov / 2.0).tan());
    let xp = Vec3::new((0.3 / 32.0 * 5.0 * (fov / 2.0).tan()) as f32, 0.0, 0.0);
    let strand = straight_strand(xp - Vec3::Y, xp + Vec3::Y, 5, Some(0.02), white);
    let out = render_frame(
        &gpu,
        &strand,
        &params(perspective, None),
        &RenderOptions::default(),
    )
    .unwrap();
    let (mean, spread) = mean_row_alpha(&out, 12..52);
    eprintln!(
        "thickness 0.02 perspective ({expected:.4} px): row alpha sum mean {mean:.6}, max deviation {spread:.2e}"
    );
    assert!((mean - expected).abs() < 1e-3 * expected && spread < 1e-3);

    // A strand 30° from vertical in the image plane: each row crosses 1/cos 30° of its width.
    let angle = 30f64.to_radians();
    let half = Vec3::new(angle.sin() as f32, angle.cos() as f32, 0.0) * 0.9;
    let slanted = straight_strand(-half, half, 7, None, white);
    let out = render_frame(
        &gpu,
        &slanted,
        &params(ortho_camera(), Some(0.5)),
        &RenderOptions::default(),
    )
    .unwrap();
    let (mean, spread) = mean_row_alpha(&out, 12..52);
    let expected = 0.5 / angle.cos();
    eprintln!(
        "slanted 30°, 0.5 px: row alpha sum mean {mean:.5} (expected {expected:.5}), max row deviation {spread:.3}"
    );
    assert!((mean - expected).abs() < 0.02 * expected);
}
