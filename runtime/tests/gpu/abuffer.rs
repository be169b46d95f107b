//! The A-buffer against independent expectations: a single strand resolves to what the
//! hardware-blended pass draws; two overlapping sub-pixel strands composite as
//! front + (1 − α_front)·back whatever their draw order; fragment counts match the number of
//! pixel centres the strands cover, and a small node buffer drops exactly the excess; with
//! Marschner-LUT and artist shading and several shadow maps, a single strand through the A-buffer
//! and DBK equals the opaque pass.

use crate::common::*;

use glam::Vec3;
use strandlight_precompute::point_light_luts::{LutResolution, bake_lut_m, bake_lut_n};
use strandlight_runtime::camera::{Camera, Projection};
use strandlight_runtime::gpu::{GpuContext, read_texture_rgba};
use strandlight_runtime::hair::{Attribute, HairModel};
use strandlight_runtime::lights::Light;
use strandlight_runtime::passes::abuffer::{ABufferPass, ListMode};
use strandlight_runtime::passes::deep_opacity::{DeepOpacityMap, DeepOpacityPass, DomSettings};
use strandlight_runtime::passes::fiber_shading::{MarschnerLuts, ShadingModel};
use strandlight_runtime::passes::frame_params::{FrameParams, KajiyaKay};
use strandlight_runtime::passes::render_target::RenderTarget;
use strandlight_runtime::passes::shadow_slots::ShadowInput;
use strandlight_runtime::passes::strand_geometry::StrandGeometry;
use strandlight_runtime::passes::strands::StrandPass;
use strandlight_tables::artist::{ArtistModel, ArtistParams};
use strandlight_tables::marschner::{Marschner, MarschnerParams};

const SIZE: u32 = 64;

/// Vertical strands at x = 0.3 px right of column 32's left edge, y ∈ [−0.8, 0.8], one per
/// (z, colour), in the given order.
fn strands(list: &[(f32, Vec3)]) -> HairModel {
    let x = 0.3 / 32.0;
    let mut points = Vec::new();
    let mut colors = Vec::new();
    let mut offsets = vec![0u32];
    for &(z, c) in list {
        points.extend([Vec3::new(x, -0.8, z), Vec3::new(x, 0.8, z)]);
        colors.extend([c, c]);
        offsets.push(points.len() as u32);
    }
    HairModel::new(
        points,
        offsets,
        None,
        None,
        Some(Attribute::PerPoint(colors)),
    )
    .unwrap()
}

fn frame() -> FrameParams {
    FrameParams {
        camera: ortho_camera(),
        width: SIZE,
        height: SIZE,
        lights: vec![
            Light::Directional {
                direction: Vec3::new(0.3, 0.4, 1.0).normalize(),
                intensity: 1.5,
            },
            Light::Point {
                position: Vec3::new(-1.0, 1.0, 2.0),
                intensity: 3.0,
            },
        ],
        shading: KajiyaKay::default(),
        width_override_px: Some(0.6),
    }
}

/// Rows whose pixel centre lies inside y ∈ (−0.8, 0.8): j + 0.5 ∈ (6.4, 57.6), j = 6..=57.
const COVERED_ROWS: u64 = 52;

#[test]
fn abuffer_composites_in_depth_order_and_counts_fragments() {
    let gpu = GpuContext::new_headless().unwrap_or_else(|e| panic!("{e}"));
    let pass = ABufferPass::new(&gpu);
    let frame = frame();
    let capacity = ABufferPass::max_capacity(&gpu, 1 << 16);
    let front = (0.2f32, Vec3::new(0.8, 0.2, 0.1));
    let back = (-0.2f32, Vec3::new(0.1, 0.3, 0.9));
    let run = |list: &[(f32, Vec3)], capacity| {
        let geometry = StrandGeometry::upload(&gpu, &strands(list)).unwrap();
        pass.draw(&gpu, &geometry, &frame, None, capacity, ListMode::All)
            .unwrap()
    };

    // One strand: the resolve equals hardware "over" onto black.
    let alone_front = run(&[front], capacity);
    let alone_back = run(&[back], capacity);
    let geometry = StrandGeometry::upload(&gpu, &strands(&[front])).unwrap();
    let target = RenderTarget::new(&gpu, SIZE, SIZE);
    StrandPass::new(&gpu).draw(&gpu, &geometry, &frame, &target, None);
    let blended = read_texture_rgba(&gpu, &target.color).unwrap();
    let mut worst_single = 0.0f32;
    for (a, b) in alone_front.pixels.iter().zip(&blended) {
        for k in 0..4 {
            worst_single = worst_single.max((a[k] - b[k]).abs());
        }
    }
    assert!(
        worst_single < 1e-5,
        "single strand: A-buffer vs blended pass differ by {worst_single}"
    );
    assert_eq!(alone_front.fragments_stored, COVERED_ROWS);

    // Two strands, both orders.
    let mut worst_pair = 0.0f32;
    for (order, list) in [
        ("front first", [front, back]),
        ("back first", [back, front]),
    ] {
        let both = run(&list, capacity);
        assert_eq!(both.fragments_stored, 2 * COVERED_ROWS, "{order}");
        assert_eq!(
            (both.fragments_dropped, both.fragments_truncated),
            (0, 0),
            "{order}"
        );
        for ((p, f), b) in both
            .pixels
            .iter()
            .zip(&alone_front.pixels)
            .zip(&alone_back.pixels)
        {
            for k in 0..4 {
                let expected = f[k] + (1.0 - f[3]) * b[k];
                worst_pair = worst_pair.max((p[k] - expected).abs());
            }
        }
    }
    let centre = alone_front.pixels[(32 * SIZE + 32) as usize];
    eprintln!(
        "A-buffer: single strand vs hardware blend max |Δ| {worst_single:.2e}; two strands vs front + (1 − α)·back max |Δ| {worst_pair:.2e} (front pixel {centre:?})"
    );
    assert!(worst_pair < 1e-5);
    assert!(
        (centre[3] - 0.6).abs() < 1e-6,
        "coverage alpha 0.6, got {}",
        centre[3]
    );

    // Overflow: a 10-node buffer keeps 10 fragments and reports the rest as dropped.
    let small = run(&[front, back], 10);
    eprintln!(
        "capacity 10: stored {}, dropped {} (of {} fragments)",
        small.fragments_stored,
        small.fragments_dropped,
        2 * COVERED_ROWS
    );
    assert_eq!(small.fragments_stored, 10);
    assert_eq!(small.fragments_dropped, 2 * COVERED_ROWS - 10);
}

/// DBK with Δ covering the whole volume equals the A-buffer pixel for pixel; with Δ smaller
/// than the gap between two strands, the front one is listed, the back one falls back to the
/// opaque target, and the composite is still front + (1 − α_front)·back.
#[test]
fn dbk_agrees_with_the_abuffer() {
    let gpu = GpuContext::new_headless().unwrap_or_else(|e| panic!("{e}"));
    let pass = ABufferPass::new(&gpu);
    let capacity = ABufferPass::max_capacity(&gpu, 1 << 16);
    let front = (0.2f32, Vec3::new(0.8, 0.2, 0.1));
    let back = (-0.2f32, Vec3::new(0.1, 0.3, 0.9));
    let middle = (0.0f32, Vec3::new(0.2, 0.9, 0.2));
    for (name, frame) in [
        ("orthographic", frame()),
        (
            "perspective",
            FrameParams {
                camera: Camera {
                    projection: Projection::Perspective { fov_y: 0.5 },
                    ..ortho_camera()
                },
                ..frame()
            },
        ),
    ] {
        let geometry = StrandGeometry::upload(&gpu, &strands(&[back, front, middle])).unwrap();
        let reference = pass
            .draw(&gpu, &geometry, &frame, None, capacity, ListMode::All)
            .unwrap();
        let whole = pass
            .draw(
                &gpu,
                &geometry,
                &frame,
                None,
                capacity,
                ListMode::Dbk { delta: 100.0 },
            )
            .unwrap();
        let max_diff = |a: &[[f32; 4]], b: &[[f32; 4]]| {
            a.iter()
                .zip(b)
                .flat_map(|(p, q)| (0..4).map(move |k| (p[k] - q[k]).abs()))
                .fold(0.0f32, f32::max)
        };
        let whole_diff = max_diff(&whole.pixels, &reference.pixels);
        assert_eq!(whole.fragments_stored, reference.fragments_stored, "{name}");
        assert!(
            whole_diff < 1e-6,
            "{name}: DBK(Δ = all) vs A-buffer differ by {whole_diff}"
        );

        // Two strands 0.4 apart, Δ = 0.1: one listed fragment per row, the other in the fallback.
        let pair = StrandGeometry::upload(&gpu, &strands(&[back, front])).unwrap();
        let reference = pass
            .draw(&gpu, &pair, &frame, None, capacity, ListMode::All)
            .unwrap();
        let thin = pass
            .draw(
                &gpu,
                &pair,
                &frame,
                None,
                capacity,
                ListMode::Dbk { delta: 0.1 },
            )
            .unwrap();
        let thin_diff = max_diff(&thin.pixels, &reference.pixels);
        eprintln!(
            "{name}: DBK(Δ = all) vs A-buffer max |Δ| {whole_diff:.2e} ({} fragments); DBK(Δ = 0.1) vs A-buffer on two strands max |Δ| {thin_diff:.2e}, {} listed of {}",
            whole.fragments_stored, thin.fragments_stored, reference.fragments_stored
        );
        let front_alone = StrandGeometry::upload(&gpu, &strands(&[front])).unwrap();
        let front_fragments = pass
            .draw(&gpu, &front_alone, &frame, None, capacity, ListMode::All)
            .unwrap()
            .fragments_stored;
        assert_eq!(
            thin.fragments_stored, front_fragments,
            "{name}: only the front strand is listed"
        );
        assert!(thin_diff < 1e-6, "{name}");
    }
}

/// `rows` rows of thick vertical fibers at z = 0.5 − 0.1·r, one per map texel column: an
/// occluder drawn only into a deep opacity map (never into the picture), so the picture still
/// holds a single strand.
fn occluder(rows: usize) -> HairModel {
    let mut points = Vec::new();
    let mut offsets = vec![0u32];
    for r in 0..rows {
        let z = 0.5 - 0.1 * r as f32;
        for c in 0..MAP_RES {
            let x = (c as f32 + 0.5 + 0.13 * r as f32) / (MAP_RES as f32 / 2.0) - 1.0;
            points.extend([Vec3::new(x, -0.9, z), Vec3::new(x, 0.9, z)]);
            offsets.push(points.len() as u32);
        }
    }
    // Half a texel wide: each row lets through about half the light.
    let thickness = 0.5 * 2.0 / MAP_RES as f32;
    HairModel::new(
        points,
        offsets,
        Some(Attribute::Uniform(thickness)),
        None,
        None,
    )
    .unwrap()
}

const MAP_RES: u32 = 64;

fn occluder_map(gpu: &GpuContext, rows: usize) -> DeepOpacityMap {
    let geometry = StrandGeometry::upload(gpu, &occluder(rows)).unwrap();
    let map = DeepOpacityMap::new(
        gpu,
        ortho_camera(),
        DomSettings {
            resolution: MAP_RES,
            layers: 4,
            spacing: 0.08,
        },
    );
    DeepOpacityPass::new(gpu).draw(gpu, &geometry, &map);
    map
}

fn max_abs_diff(a: &[[f32; 4]], b: &[[f32; 4]]) -> f32 {
    a.iter()
        .zip(b)
        .flat_map(|(p, q)| (0..4).map(move |k| (p[k] - q[k]).abs()))
        .fold(0.0f32, f32::max)
}

/// Marschner (lookup tables) and artist shading with two shadowed directional lights and a point
/// light: a single strand through the A-buffer equals the opaque pass (one fragment per pixel,
/// nothing to sort), DBK with Δ covering the volume equals the A-buffer, and the second light's
/// map visibly darkens the A-buffer picture (so every map is in play, not only the first).
#[test]
fn abuffer_and_dbk_shade_like_the_opaque_pass_for_every_model() {
    let gpu = GpuContext::new_headless().unwrap_or_else(|e| panic!("{e}"));
    let marschner = Marschner::new(MarschnerParams::with_preset("brown").unwrap()).unwrap();
    let resolution = LutResolution::square(32);
    let luts = MarschnerLuts::new(
        bake_lut_m(&marschner, &resolution).unwrap(),
        bake_lut_n(&marschner, &resolution).unwrap(),
    )
    .unwrap();
    let models = [
        ("marschner-lut", ShadingModel::MarschnerLut(luts)),
        (
            "artist",
            ShadingModel::Artist(ArtistModel::new(ArtistParams::default()).unwrap()),
        ),
    ];
    let frame = FrameParams {
        lights: vec![
            Light::Directional {
                direction: Vec3::new(0.3, 0.4, 1.0).normalize(),
                intensity: 1.5,
            },
            Light::Directional {
                direction: Vec3::new(-0.4, 0.1, 1.0).normalize(),
                intensity: 2.0,
            },
            Light::Point {
                position: Vec3::new(-1.0, 1.0, 2.0),
                intensity: 3.0,
            },
        ],
        ..frame()
    };
    // Light 0 behind one occluding row, light 1 behind two; the strand lies behind both.
    let (map0, map1) = (occluder_map(&gpu, 1), occluder_map(&gpu, 2));
    let shadows = [
        ShadowInput {
            map: &map0,
            light_index: 0,
        },
        ShadowInput {
            map: &map1,
            light_index: 1,
        },
    ];
    let geometry =
        StrandGeometry::upload(&gpu, &strands(&[(-0.2, Vec3::new(0.8, 0.5, 0.3))])).unwrap();
    let capacity = ABufferPass::max_capacity(&gpu, 1 << 16);
    for (name, model) in &models {
        let target = RenderTarget::new(&gpu, SIZE, SIZE);
        StrandPass::with_model(&gpu, model)
            .draw_shadowed(&gpu, &geometry, &frame, &target, &shadows, None)
            .unwrap();
        let opaque = read_texture_rgba(&gpu, &target.color).unwrap();
        let pass = ABufferPass::with_model(&gpu, model);
        let draw = |shadows: &[ShadowInput], mode| {
            pass.draw_shadowed(&gpu, &geometry, &frame, shadows, None, capacity, mode)
                .unwrap_or_else(|e| panic!("{e}"))
        };
        let abuffer = draw(&shadows, ListMode::All);
        let dbk = draw(&shadows, ListMode::Dbk { delta: 100.0 });
        let first_map_only = draw(&shadows[..1], ListMode::All);
        let peak = opaque
            .iter()
            .map(|p| p[0].max(p[1]).max(p[2]))
            .fold(0.0f32, f32::max);
        let abuffer_diff = max_abs_diff(&abuffer.pixels, &opaque);
        let dbk_diff = max_abs_diff(&dbk.pixels, &abuffer.pixels);
        let second_map_effect = max_abs_diff(&first_map_only.pixels, &abuffer.pixels);
        eprintln!(
            "{name}: peak radiance {peak:.4}; A-buffer vs opaque max |Δ| {abuffer_diff:.2e}; DBK(Δ = all) vs A-buffer max |Δ| {dbk_diff:.2e}; light 1's map changes the A-buffer by up to {second_map_effect:.4}; {} fragments",
            abuffer.fragments_stored
        );
        assert!(peak > 1e-3, "{name}: the strand is lit");
        assert_eq!(abuffer.fragments_stored, COVERED_ROWS, "{name}");
        assert_eq!(dbk.fragments_stored, COVERED_ROWS, "{name}");
        assert!(
            abuffer_diff <= 1e-6 * peak.max(1.0),
            "{name}: A-buffer vs opaque differ by {abuffer_diff}"
        );
        assert!(
            dbk_diff <= 1e-6 * peak.max(1.0),
            "{name}: DBK(Δ = all) vs A-buffer differ by {dbk_diff}"
        );
        assert!(
            second_map_effect > 0.05 * peak,
            "{name}: light 1's deep opacity map barely changes the A-buffer ({second_map_effect})"
        );
    }
}

/// With no nodes-per-pixel given, `render_frame` sizes the pool to exactly the fragments each
/// technique stores: three strands through the A-buffer need one node per covered pixel centre
/// each; DBK with Δ = 0.1 over two strands 0.4 apart lists only the front one. The pictures equal
/// those from a generous fixed pool.
#[test]
fn an_unsized_pool_holds_exactly_what_each_technique_stores() {
    use strandlight_runtime::point_frame::{RenderOptions, Transparency, render_frame};
    let gpu = GpuContext::new_headless().unwrap_or_else(|e| panic!("{e}"));
    let front = (0.2f32, Vec3::new(0.8, 0.2, 0.1));
    let back = (-0.2f32, Vec3::new(0.1, 0.3, 0.9));
    let middle = (0.0f32, Vec3::new(0.2, 0.9, 0.2));
    let cases = [
        (
            "A-buffer, three strands",
            strands(&[back, front, middle]),
            Transparency::ABuffer {
                nodes_per_pixel: None,
            },
            Transparency::ABuffer {
                nodes_per_pixel: Some(16),
            },
            3 * COVERED_ROWS,
        ),
        (
            "DBK Δ = 0.1, two strands",
            strands(&[back, front]),
            Transparency::Dbk {
                nodes_per_pixel: None,
                delta: 0.1,
            },
            Transparency::Dbk {
                nodes_per_pixel: Some(16),
                delta: 0.1,
            },
            COVERED_ROWS,
        ),
    ];
    for (name, model, sized, fixed, expected_nodes) in cases {
        let render = |transparency| {
            let options = RenderOptions {
                transparency,
                ..Default::default()
            };
            render_frame(&gpu, &model, &frame(), &options).unwrap()
        };
        let (sized, fixed) = (render(sized), render(fixed));
        let counts = sized.stats.fragments.unwrap();
        eprintln!("{name}: {counts:?}");
        assert_eq!(counts.capacity, expected_nodes, "{name}");
        assert_eq!(counts.stored, expected_nodes, "{name}");
        assert_eq!(counts.dropped, 0, "{name}");
        assert_eq!(
            fixed.stats.fragments.unwrap().capacity,
            16 * (SIZE * SIZE) as u64
        );
        let diff = max_abs_diff(&sized.pixels, &fixed.pixels);
        assert!(diff < 1e-6, "{name}: sized vs fixed pool differ by {diff}");
    }
    let zero = RenderOptions {
        transparency: Transparency::ABuffer {
            nodes_per_pixel: Some(0),
        },
        ..Default::default()
    };
    let Err(e) = render_frame(&gpu, &strands(&[front]), &frame(), &zero) else {
        panic!("a zero-node pool rendered");
    };
    assert!(e.to_string().contains("nodes per pixel 0"), "{e}");
}
