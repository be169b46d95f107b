//! Before any error figure against the path-traced ground truth is trusted, the two renderers
//! must agree on what a scene is: the camera and the fibers' width (the silhouette), the
//! environment map's frame (which side a single bright texel lights), and the fiber frame and
//! units of the scattering function (one fiber under one directional light), and the map's
//! frame through the product's own path (a one-texel map fitted, turned, placed over a Y-up or
//! a Z-up groom and drawn by `render_frame`, against the Mitsuba scene written from the same
//! `FrameSettings`). Each test renders a small scene with strandlight's env-lit renderer and
//! with Mitsuba 3 (`eval/src/ground_truth.rs`), on the same Chiang fiber (Mitsuba's own `hair`
//! BSDF on its side).
//!
//! Mitsuba is installed by `.ci/run`; without it, or without a GPU device (not even lavapipe),
//! the tests print why and pass, unless `STRANDLIGHT_REQUIRE_TOOLS=1` (CI) makes either a
//! failure.

use glam::{DVec3, Vec3};
use std::path::{Path, PathBuf};
use strandlight_eval::ground_truth::mitsuba_scene::{MitsubaRun, MitsubaScene};
use strandlight_eval::ground_truth::{TruthInputs, TruthScene, render_cached};
use strandlight_eval::reference_cache::ReferenceCache;
use strandlight_precompute::EnvMap;
use strandlight_precompute::bake_plan::{BakeResolution, FiberDescription};
use strandlight_precompute::envmap::direction_to_uv;
use strandlight_runtime::camera::UpAxis;
use strandlight_runtime::env_light::EnvLight;
use strandlight_runtime::hair::{
    Attribute, GroomParams, HairModel, HairWriteOptions, generate_groom, write_hair,
};
use strandlight_scene::camera_choice::front_camera;
use strandlight_scene::env_frame::{EnvFrame, FrameRole, render_lights};
use strandlight_scene::env_lighting::EnvLighting;
use strandlight_scene::env_orientation::EnvOrientation;
use strandlight_scene::env_scene::{AlsoServe, prepare_env};
use strandlight_scene::environment::map_pixels_sha256;
use strandlight_scene::frame_render::{FramePart, Prepared, load_settings_hair, render_frame};
use strandlight_scene::frame_settings::{FrameSettings, Lighting};
use strandlight_scene::image_metrics::{HAIR_ALPHA, Image};
use strandlight_scene::look::{EnvLook, LookArgs};
use strandlight_scene::point_shading::Shading;
use strandlight_scene::scene_tables::{EnvShading, ScatteringMode, SceneTables, bake_scene_tables};
use strandlight_scene::steps::Steps;
use strandlight_tables::image_out::write_exr;

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("strandlight-truth-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// The brown Chiang fiber: its tables for directional lights (single scattering), and
/// Mitsuba's parameters.
fn chiang(dir: &Path) -> (SceneTables, serde_json::Value) {
    let fiber = FiberDescription::preset("brown").unwrap();
    let tables = bake_scene_tables(
        &fiber,
        EnvShading::Chiang,
        // 192 nodes per axis of the direct tables (the default is 128): with light from behind
        // the fiber, the TT lobe falls 100× along the fiber and bilinear interpolation of its
        // tail alone errs by up to 5% per row at 128 nodes (2.6% over the rows measured, 1.9% at
        // 192), which is the table's error, not a convention's.
        BakeResolution {
            direct_direction_nodes: 192,
            ..BakeResolution::default()
        },
        (16.0, 256.0),
        &[EnvShading::Chiang.direct_table(ScatteringMode::Single)],
        &dir.join("tables"),
        &mut |_| {},
    )
    .unwrap();
    (tables, serde_json::to_value(&fiber.chiang).unwrap())
}

/// strandlight's frame of `hair` under `lights`, single scattering, at the default front camera.
fn ours(
    hair: &HairModel,
    size: (u32, u32),
    lights: &[EnvLight],
    tables: &SceneTables,
    shadowed: bool,
) -> Image {
    let (_, camera) = front_camera(hair, size);
    let frame = EnvFrame {
        hair,
        camera,
        width: size.0,
        height: size.1,
        lights: lights.to_vec(),
        tables,
        shading: EnvShading::Chiang,
        mode: ScatteringMode::Single,
        role: FrameRole::Reference,
        look: EnvLook {
            shadowed,
            ..LookArgs::default().look().unwrap()
        },
        head: None,
    };
    render_lights(&frame).unwrap().image
}

/// The Mitsuba scene of `hair` at the default front camera, lit by `map` and `directional`.
fn mitsuba_scene<'a>(
    hair: &'a HairModel,
    size: (u32, u32),
    map: Option<&'a EnvMap>,
    directional: &'a [([f64; 3], [f64; 3])],
    fiber: &'a serde_json::Value,
) -> MitsubaScene<'a> {
    let (up, camera) = front_camera(hair, size);
    MitsubaScene {
        hair,
        orientation: EnvOrientation::upright(up),
        camera,
        size,
        map,
        directional,
        fiber,
        head: None,
    }
}

/// Mitsuba's image of the same scene (direct light only).
fn theirs(scene: MitsubaScene, spp: u32, dir: &Path) -> Image {
    // Each test's cache is its own scratch folder; the map (or its absence) must be in the key.
    let map_sha256 = scene.map.map_or("no map".into(), map_pixels_sha256);
    let inputs = TruthInputs {
        scene,
        hair_sha256: "a test's hair",
        map_sha256: &map_sha256,
    };
    let run = MitsubaRun {
        max_depth: 2,
        spp,
        seed: 1,
    };
    let cache = ReferenceCache::new(dir.join("cache"));
    render_cached(&inputs, run, &cache, &dir.join("work"), true)
        .unwrap()
        .expect("rendering is allowed")
        .0
}

fn small_groom() -> HairModel {
    generate_groom(&GroomParams {
        strand_count: 300,
        clump_count: 12,
        // Fibers about three pixels wide at 64×48, so that coverage is a matter of geometry more
        // than of how each renderer samples a pixel.
        thickness: 2.5,
        ..GroomParams::default()
    })
    .unwrap()
}

/// A letter F of dense strands: no symmetry, so a mirrored or upside-down camera shows.
fn letter_f() -> HairModel {
    let mut points = Vec::new();
    let mut offsets = vec![0u32];
    let mut strand = |from: Vec3, to: Vec3| {
        for k in 0..=10 {
            points.push(from.lerp(to, k as f32 / 10.0));
        }
        offsets.push(points.len() as u32);
    };
    for k in 0..18 {
        let x = 0.2 * k as f32;
        strand(Vec3::new(x, 20.0, 0.0), Vec3::new(x, 0.0, 0.0));
    }
    for (y, length) in [(16.5, 12.0), (8.0, 8.0)] {
        for k in 0..18 {
            let y = y + 0.2 * k as f32;
            strand(Vec3::new(0.0, y, 0.1), Vec3::new(length, y, 0.1));
        }
    }
    HairModel::new(points, offsets, Some(Attribute::Uniform(0.3)), None, None).unwrap()
}

/// IoU of the pixels two images cover more than half (strandlight samples coverage at the
/// pixel centre with quads at least a pixel wide, Mitsuba integrates it over the pixel: they
/// differ by design in the faint fringe, so the silhouette is where a pixel is mostly hair).
fn silhouette_iou(a: &Image, b: &Image, flip_x: bool, flip_y: bool) -> (f64, usize) {
    let (w, h) = (a.width as usize, a.height as usize);
    let (mut both, mut either) = (0, 0);
    for y in 0..h {
        for x in 0..w {
            let bx = if flip_x { w - 1 - x } else { x };
            let by = if flip_y { h - 1 - y } else { y };
            let (p, q) = (a.pixels[y * w + x][3] > 0.5, b.pixels[by * w + bx][3] > 0.5);
            both += usize::from(p && q);
            either += usize::from(p || q);
        }
    }
    (both as f64 / either as f64, either)
}

/// The camera and the fibers' width: the pixels each renderer covers mostly with hair overlap,
/// for a groom and for an asymmetric letter F (which a mirrored or upside-down picture would
/// not match).
#[test]
fn the_silhouettes_match() {
    if !crate::mitsuba_and_gpu() {
        return;
    }
    let dir = scratch("silhouette");
    let (tables, fiber) = chiang(&dir);
    let size = (64, 48);
    for (name, hair) in [("groom", small_groom()), ("letter F", letter_f())] {
        let (up, _) = front_camera(&hair, size);
        let toward = (up.toward_front().as_dvec3() + up.vector().as_dvec3()).normalize();
        let light = EnvLight::directional(toward.as_vec3(), [3.0; 3]);
        let a = ours(&hair, size, &[light], &tables, true);
        let b = theirs(
            mitsuba_scene(&hair, size, None, &[(toward.to_array(), [3.0; 3])], &fiber),
            64,
            &dir,
        );
        let (iou, pixels) = silhouette_iou(&a, &b, false, false);
        let (mirrored, _) = silhouette_iou(&a, &b, true, false);
        let (upside_down, _) = silhouette_iou(&a, &b, false, true);
        let fringe = {
            let hair = |p: &[f32; 4]| p[3] > HAIR_ALPHA;
            let both = a
                .pixels
                .iter()
                .zip(&b.pixels)
                .filter(|(p, q)| hair(p) && hair(q))
                .count();
            let either = a
                .pixels
                .iter()
                .zip(&b.pixels)
                .filter(|(p, q)| hair(p) || hair(q))
                .count();
            both as f64 / either as f64
        };
        println!(
            "{name}: silhouette IoU {iou:.4} over {pixels} pixels (against Mitsuba's picture mirrored {mirrored:.4}, upside down {upside_down:.4}); IoU of every pixel with coverage > {HAIR_ALPHA}: {fringe:.4}"
        );
        assert!(pixels > 150, "{name} covers too little of the frame");
        assert!(iou >= 0.95, "{name}: silhouette IoU {iou:.4} < 0.95");
        if name == "letter F" {
            assert!(
                mirrored < 0.8 && upside_down < 0.8,
                "{name}: the test cannot tell a mirrored or flipped picture"
            );
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// Luminance-weighted centroid of the hair minus its coverage centroid, in pixels.
fn lit_side(image: &Image) -> (f64, f64) {
    let w = image.width as usize;
    let (mut lum, mut lx, mut ly, mut cov, mut cx, mut cy) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    for (i, p) in image.pixels.iter().enumerate() {
        let (x, y) = ((i % w) as f64, (i / w) as f64);
        let l = (0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]) as f64;
        lum += l;
        lx += l * x;
        ly += l * y;
        cov += p[3] as f64;
        cx += p[3] as f64 * x;
        cy += p[3] as f64 * y;
    }
    (lx / lum - cx / cov, ly / lum - cy / cov)
}

/// A map black but for one bright texel at (x, y), written as an EXR the product reads like any
/// user's map.
fn one_texel_map(dir: &Path, (x, y): (usize, usize), (w, h): (usize, usize)) -> PathBuf {
    let mut pixels = vec![[0f32; 4]; w * h];
    pixels[y * w + x] = [4000.0, 4000.0, 4000.0, 1.0];
    let path = dir.join(format!("one-texel-{x}-{y}.exr"));
    write_exr(&path, w as u32, h as u32, &pixels, "one bright texel").unwrap();
    path
}

/// The texel of a `w`×`h` map that a frame turned by `orientation` shows along `world`.
fn texel_toward(
    orientation: EnvOrientation,
    world: DVec3,
    (w, h): (usize, usize),
) -> (usize, usize) {
    let (u, v) = direction_to_uv(orientation.to_env(world.normalize()));
    let x = ((u * w as f64) as usize).min(w - 1);
    let y = ((v * h as f64) as usize).min(h - 1);
    (x, y)
}

/// A groom of realistic fibers (0.3 mm, a tenth of a pixel at 64×48): the light maps' shadows
/// and the path tracer's agree in total there, where a few thick fibers shadow themselves in a
/// light map (measured: 0.56 of Mitsuba's light with 2.5 cm tubes, 0.96 with these).
fn fine_groom() -> HairModel {
    generate_groom(&GroomParams {
        strand_count: 3000,
        points_per_strand: 16,
        clump_count: 60,
        thickness: 0.03,
        ..GroomParams::default()
    })
    .unwrap()
}

/// The map's frame, through the product's own path: a map black but for one bright texel is
/// fitted (as SRBF lobes, and as a compact source: the two ways a fit lights a frame), turned
/// by the frame's rotation, placed over a Y-up or a Z-up groom, and rendered by `render_frame`;
/// Mitsuba renders the scene [`TruthScene`] writes for the same settings. The texel is the one
/// the frame shows along a chosen world direction (left of the camera, or above), so its lit
/// side is known: both renderers must light that side of the groom (the lit side: the luminance
/// centroid less the coverage centroid), agree on it, and carry the same light.
#[test]
fn one_bright_texel_lights_the_same_side_through_the_fit_at_any_rotation_and_up_axis() {
    if !crate::mitsuba_and_gpu() {
        return;
    }
    let dir = scratch("texel");
    std::fs::create_dir_all(&dir).unwrap();
    let y_up = fine_groom();
    let hair_files = [("Y-up", &y_up), ("Z-up", &z_up(&y_up))].map(|(name, model)| {
        let path = dir.join(format!("{name}.hair"));
        write_hair(model, &path, &HairWriteOptions::default()).unwrap();
        (name, path)
    });
    let size = [64, 48];
    let map_size = (128, 64);
    let mut failures = Vec::new();
    let (mut worst_cosine, mut worst_energy) = (1.0f64, 0.0f64);
    // Turned, never at 0 (a sign error is invisible there; the other tests here hold 0).
    for (hair, rotation) in [(0, 211.0), (1, 149.0)] {
        let (up_name, hair_path) = &hair_files[hair];
        let up = if hair == 0 { UpAxis::Y } else { UpAxis::Z };
        let orientation = EnvOrientation::new(up, rotation as f64);
        let (front, world_up) = (up.toward_front().as_dvec3(), up.vector().as_dvec3());
        // The camera looks along −front; its right is (−front) × up.
        let right = (-front).cross(world_up);
        for (texel, toward, screen) in [
            (
                "left of the camera",
                -right + 0.4 * world_up + 0.3 * front,
                (-1.0, -0.4),
            ),
            ("above", world_up + 0.4 * front, (0.0, -1.0)),
        ] {
            let at = texel_toward(orientation, toward, map_size);
            let map = one_texel_map(&dir, at, map_size);
            let settings = |sources: usize| {
                let mut env = EnvLighting::new(map.to_string_lossy());
                env.scattering = ScatteringMode::Single;
                env.rotation_deg = rotation;
                env.fit.sources = sources;
                FrameSettings {
                    hair: Some(hair_path.clone()),
                    shading: Some(Shading::Chiang),
                    ..FrameSettings::new(Lighting::Environment(env), size)
                }
            };
            let theirs = truth_of(&settings(0), &dir);
            for (fit, sources) in [("SRBF lobes", 0), ("a compact source", 1)] {
                let ours = render_settings(&settings(sources), &dir);
                let (sa, sb) = (lit_side(&ours), lit_side(&theirs));
                let cosine = cosine_2d(sa, sb);
                let toward_light = cosine_2d(sb, screen);
                let energy = total(&ours) / total(&theirs);
                let case = format!(
                    "{up_name} groom, map turned {rotation}°, texel {at:?} {texel} as {fit}"
                );
                println!(
                    "{case}: lit side ours {sa:.2?} Mitsuba {sb:.2?} px, cosine {cosine:.4}, toward the light {toward_light:.2}; light ours / Mitsuba {energy:.4}"
                );
                if cosine <= 0.98 {
                    failures.push(format!(
                        "{case}: the lit sides disagree (cosine {cosine:.4})"
                    ));
                }
                if toward_light <= 0.7 {
                    failures.push(format!(
                        "{case}: the lit side is not toward the light (cosine {toward_light:.2})"
                    ));
                }
                if (energy - 1.0).abs() >= ENERGY_TOLERANCE {
                    failures.push(format!(
                        "{case}: ours carries {energy:.4} of Mitsuba's light"
                    ));
                }
                worst_cosine = worst_cosine.min(cosine);
                worst_energy = worst_energy.max((energy - 1.0).abs());
            }
        }
    }
    println!("worst cosine {worst_cosine:.4}, worst light ratio off by {worst_energy:.4}");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    std::fs::remove_dir_all(&dir).ok();
}

fn cosine_2d(a: (f64, f64), b: (f64, f64)) -> f64 {
    (a.0 * b.0 + a.1 * b.1) / (a.0.hypot(a.1) * b.0.hypot(b.1))
}

/// How far the light one bright texel puts on the groom may be from Mitsuba's: the frame's
/// shadows come from light maps where Mitsuba traces each fiber, a fit's lobes spread the
/// texel's light over a few degrees, and coverage is sampled at pixel centres (issue 64's
/// terms). Measured on this groom (5 Dec 2026): 0.90–0.99 as a compact source, 0.995–1.11 as
/// SRBF lobes, the same at every rotation and on both axes.
const ENERGY_TOLERANCE: f64 = 0.13;

/// Σ RGB over the frame.
fn total(image: &Image) -> f64 {
    image
        .pixels
        .iter()
        .map(|p| (p[0] + p[1] + p[2]) as f64)
        .sum()
}

/// `model` turned onto Z-up: (x, y, z) ↦ (−x, z, y), the map's own placement in a Z-up world.
fn z_up(model: &HairModel) -> HairModel {
    let points = model
        .points()
        .iter()
        .map(|p| Vec3::new(-p.x, p.z, p.y))
        .collect();
    HairModel::new(
        points,
        model.strand_offsets().to_vec(),
        model.thickness().cloned(),
        None,
        None,
    )
    .unwrap()
}

/// The frame of `settings` as `render` draws it (fit and tables cached under `dir`).
fn render_settings(settings: &FrameSettings, dir: &Path) -> Image {
    let hair = load_settings_hair(settings).unwrap();
    let prepared = prepare_env(
        settings,
        &hair.model,
        &dir.join("cache"),
        AlsoServe::default(),
        &mut Steps::new(true),
        &mut |_| {},
    )
    .unwrap();
    render_frame(
        settings,
        &hair.model,
        Prepared::Env(&prepared),
        FramePart::Whole,
        false,
    )
    .unwrap()
    .image
}

/// Mitsuba's direct-light image of the scene `strandlight truth` writes for `settings`.
fn truth_of(settings: &FrameSettings, dir: &Path) -> Image {
    let scene = TruthScene::load(settings).unwrap();
    let run = MitsubaRun {
        max_depth: 2,
        spp: 256,
        seed: 1,
    };
    let cache = ReferenceCache::new(dir.join("truth"));
    render_cached(
        &scene.inputs().unwrap(),
        run,
        &cache,
        &dir.join("work"),
        true,
    )
    .unwrap()
    .expect("rendering is allowed")
    .0
}

/// The fiber frame and units: one straight fiber, several pixels wide, under one directional
/// light. Summed across the fiber, each row of the picture integrates the near-field model over
/// the fiber's width, which is the far-field function strandlight tabulates: per unit of
/// coverage (Σ RGB / Σ alpha over the rows) the two must agree. Coverage itself differs by
/// design (strandlight samples it at pixel centres: a 2.9-pixel fiber on a pixel edge covers
/// 2 pixels or 4), which the silhouette test measures. Unshadowed on our side: a lone fiber has nothing to shadow it, and Mitsuba's curves
/// do not occlude rays leaving their own inside.
#[test]
fn one_fiber_under_one_directional_light() {
    if !crate::mitsuba_and_gpu() {
        return;
    }
    let dir = scratch("fiber");
    let (tables, fiber) = chiang(&dir);
    let points: Vec<Vec3> = (0..9)
        .map(|i| Vec3::new(0.0, 4.0 - i as f32, 0.0))
        .collect();
    let hair = HairModel::new(
        points,
        vec![0, 9],
        Some(Attribute::Uniform(0.5)),
        None,
        None,
    )
    .unwrap();
    let size = (64, 48);
    assert_eq!(front_camera(&hair, size).0, UpAxis::Y);
    let mut worst: f64 = 0.0;
    for toward in [
        DVec3::new(0.4, 0.3, 1.0),
        DVec3::new(-0.8, -0.5, 0.4),
        DVec3::new(0.3, 0.6, -1.0),
    ] {
        let toward = toward.normalize();
        let light = EnvLight::directional(toward.as_vec3(), [2.0, 1.5, 1.0]);
        let a = ours(&hair, size, &[light], &tables, false);
        let b = theirs(
            mitsuba_scene(
                &hair,
                size,
                None,
                &[(toward.to_array(), [2.0, 1.5, 1.0])],
                &fiber,
            ),
            8192,
            &dir,
        );
        // Rows well inside the fiber's length (its ends are capped differently).
        let rows = 14..34;
        let w = size.0 as usize;
        let sum = |i: &Image, c: usize| -> f64 {
            rows.clone()
                .flat_map(|y| (0..w).map(move |x| y * w + x))
                .map(|k| i.pixels[k][c] as f64)
                .sum()
        };
        for c in 0..3 {
            let sa = sum(&a, c) / sum(&a, 3);
            let sb = sum(&b, c) / sum(&b, 3);
            let relative = (sa - sb).abs() / sb;
            worst = worst.max(relative);
            println!(
                "light toward {toward:.2}, channel {c}: radiance per coverage ours {sa:.6} Mitsuba {sb:.6}, relative difference {relative:.4}"
            );
        }
    }
    assert!(
        worst <= 0.02,
        "a fiber's radiance differs by {worst:.4} > 2%"
    );
    std::fs::remove_dir_all(&dir).ok();
}
