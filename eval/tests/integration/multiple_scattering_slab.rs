//! Multiple scattering on a slab of parallel fibers whose density is known, against Mitsuba's
//! path tracer (issue 65).
//!
//! A slab of straight vertical fibers, placed at random (x, z) in a box, is lit by one
//! directional light from the camera's side and from behind. Both renderers draw the slab with
//! single scattering and with full scattering; the multiple-scattering part is the full image
//! less the single one, in each renderer. Its total over the frame, per channel, is the figure
//! dual scattering is judged by: the forward-scattering attenuation and spread along the
//! shadow paths (T_f, σ̄_f) and the local backscatter (d_b·S_back) decide it, and the slab's
//! density and the fiber's colour are all it depends on.
//!
//! Measured (6 Dec 2026, 6,000 fibers of 80 µm, σ_t⊥ 8/cm, 1 cm deep, 256 spp; ours with the
//! dense reference grid, d_f = d_b = 0.7), the multiple-scattering part ours / the path
//! tracer's, RGB: white 1.32 lit from the front, 0.55 from behind; blonde 1.27/1.22/1.10 and
//! 0.71/0.68/0.60; brown 1.02/0.78/0.55 and 0.59/0.56/0.58. Light from the front, the local
//! backscatter d_b·S_back alone is 0.85 of the truth's multiple scattering for white: Zinke's
//! Ā_b sums an endless stack of fibers behind the point, and this slab (like a groom) ends.
//! Light from behind, the forward paths carry too little: d_f = 1 (the grid's density is
//! measured, not guessed) gives 0.79 (white), 1.01/0.98/0.86 (blonde), 0.85/0.81/0.83 (brown).
//! Since 7 Dec a compact source's paths take d_f = 1 (`compact_density_forward`), and this
//! slab's light is one: blonde 1.45/1.39/1.25 from the front and 1.01/0.97/0.84 from behind,
//! brown 1.16/0.92/0.70 and 0.82/0.78/0.79 (the front's excess is the local backscatter's).
//! Dark hair bakes no multiple-scattering table; the truth's share of it is 5% (front) and 13%
//! (behind) of the slab's light. Issue 65 has the rest of the story.

use glam::{DVec3, Vec3};
use std::path::{Path, PathBuf};
use strandlight_eval::ground_truth::mitsuba_scene::{MitsubaRun, MitsubaScene};
use strandlight_eval::ground_truth::{TruthInputs, render_cached};
use strandlight_eval::reference_cache::ReferenceCache;
use strandlight_precompute::bake_plan::{BakeResolution, FiberDescription};
use strandlight_runtime::env_light::EnvLight;
use strandlight_runtime::hair::{Attribute, HairModel};
use strandlight_scene::camera_choice::front_camera;
use strandlight_scene::env_frame::{EnvFrame, FrameRole, render_lights};
use strandlight_scene::env_orientation::EnvOrientation;
use strandlight_scene::image_metrics::Image;
use strandlight_scene::look::LookArgs;
use strandlight_scene::scene_tables::{
    EnvShading, ScatteringMode, SceneTables, bake_scene_tables, wanted_tables,
};
use strandlight_tables::split_mix::SplitMix64;

/// A slab of `per_cm2` straight vertical fibers per cm² of its (x, z) cross-section, each of
/// `diameter` cm, `width` × `height` × `depth` cm, centred on the origin.
struct Slab {
    per_cm2: f64,
    diameter: f32,
    width: f32,
    height: f32,
    depth: f32,
}

impl Slab {
    fn model(&self, seed: u64) -> HairModel {
        let count = (self.per_cm2 * (self.width * self.depth) as f64).round() as usize;
        let mut rng = SplitMix64::new(seed);
        let (mut points, mut offsets) = (Vec::new(), vec![0u32]);
        const POINTS: usize = 6;
        for _ in 0..count {
            let x = (rng.unit_f32() - 0.5) * self.width;
            let z = (rng.unit_f32() - 0.5) * self.depth;
            for k in 0..POINTS {
                let y = self.height * (0.5 - k as f32 / (POINTS - 1) as f32);
                points.push(Vec3::new(x, y, z));
            }
            offsets.push(points.len() as u32);
        }
        HairModel::new(
            points,
            offsets,
            Some(Attribute::Uniform(self.diameter)),
            None,
            None,
        )
        .unwrap()
    }

    /// Extinction of light crossing the fibers at right angles, per cm: the projected width of
    /// the fibers per unit area of the cross-section.
    fn sigma_t(&self) -> f64 {
        self.per_cm2 * self.diameter as f64
    }
}

fn tables(preset: &str, dir: &Path) -> (SceneTables, serde_json::Value) {
    let fiber = FiberDescription::preset(preset).unwrap();
    let names = wanted_tables(
        EnvShading::Chiang,
        &[ScatteringMode::Single, ScatteringMode::Full],
        false,
        true,
    );
    let tables = bake_scene_tables(
        &fiber,
        EnvShading::Chiang,
        BakeResolution::default(),
        (16.0, 256.0),
        &names,
        &dir.join(format!("tables-{preset}")),
        &mut |_| {},
    )
    .unwrap();
    (tables, serde_json::to_value(&fiber.chiang).unwrap())
}

fn ours(
    hair: &HairModel,
    size: (u32, u32),
    light: &EnvLight,
    tables: &SceneTables,
    mode: ScatteringMode,
) -> Image {
    let (_, camera) = front_camera(hair, size);
    let frame = EnvFrame {
        hair,
        camera,
        width: size.0,
        height: size.1,
        lights: vec![*light],
        tables,
        shading: EnvShading::Chiang,
        mode,
        role: FrameRole::Reference,
        look: LookArgs::default().look().unwrap(),
        head: None,
    };
    render_lights(&frame).unwrap().image
}

#[allow(clippy::too_many_arguments)]
fn theirs(
    hair: &HairModel,
    size: (u32, u32),
    toward: DVec3,
    irradiance: f64,
    fiber: &serde_json::Value,
    max_depth: u32,
    spp: u32,
    dir: &Path,
) -> Image {
    let (up, camera) = front_camera(hair, size);
    let directional = [(toward.to_array(), [irradiance; 3])];
    let scene = MitsubaScene {
        hair,
        orientation: EnvOrientation::upright(up),
        camera,
        size,
        map: None,
        directional: &directional,
        fiber,
        head: None,
    };
    let hair_key = format!("slab {} fibers", hair.strand_count());
    let inputs = TruthInputs {
        scene,
        hair_sha256: &hair_key,
        map_sha256: "no map",
    };
    let run = MitsubaRun {
        max_depth,
        spp,
        seed: 1,
    };
    let cache = ReferenceCache::new(dir.join("cache"));
    render_cached(&inputs, run, &cache, &dir.join("work"), true)
        .unwrap()
        .expect("rendering is allowed")
        .0
}

/// Mean over the middle half of the (x, y) columns of Σ σ_t⊥ h along z.
fn grid_optical_depth_across(volume: &strandlight_runtime::multiple::HairVolume) -> f64 {
    let [nx, ny, nz] = volume.grid.dims;
    let h = volume.grid.voxel_size as f64;
    let (mut sum, mut columns) = (0.0, 0);
    for x in nx / 4..3 * nx / 4 {
        for y in ny / 4..3 * ny / 4 {
            let column: f64 = (0..nz)
                .map(|z| volume.sigma_perp[volume.grid.linear_index([x, y, z])] as f64 * h)
                .sum();
            sum += column;
            columns += 1;
        }
    }
    sum / columns as f64
}

/// Σ over the frame per channel.
fn totals(image: &Image) -> [f64; 3] {
    let mut sum = [0.0; 3];
    for p in &image.pixels {
        for c in 0..3 {
            sum[c] += p[c] as f64;
        }
    }
    sum
}

fn minus(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn ratio(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] / b[0], a[1] / b[1], a[2] / b[2]]
}

fn scratch() -> PathBuf {
    let dir = std::env::temp_dir().join(format!("strandlight-slab-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The multiple-scattering part of ours over the path tracer's may not leave this range, in
/// any channel of blonde or brown, lit from the front or behind: the model's own error on this
/// slab is 0.55–1.27 (see the module notes), so this catches a part that vanishes, doubles or
/// lands in the wrong channel, not the 20% the targets ask for. The grid's density, which
/// decides the forward paths, is held to its closed form within [`DENSITY_TOLERANCE`].
const MULTIPLE_RANGE: (f64, f64) = (0.45, 1.6);

/// The grid's optical depth across the slab against σ_t⊥·depth (the fibers' projected width
/// per unit area times the depth): voxelization conserves fiber length, so only the slab's
/// ragged faces and the Poisson scatter of 6,000 fibers move it.
const DENSITY_TOLERANCE: f64 = 0.05;

#[test]
fn a_slab_of_fibers_scatters_as_the_path_tracer_says() {
    if !crate::mitsuba_and_gpu() {
        return;
    }
    let dir = scratch();
    let slab = Slab {
        per_cm2: 1000.0,
        diameter: 0.008,
        width: 6.0,
        height: 6.0,
        depth: 1.0,
    };
    let hair = slab.model(7);
    println!(
        "slab: {} fibers, σ_t⊥ {:.2}/cm, optical depth {:.2} across",
        hair.strand_count(),
        slab.sigma_t(),
        slab.sigma_t() * slab.depth as f64
    );
    let volume = strandlight_runtime::multiple::HairVolume::build(
        &hair,
        &strandlight_runtime::multiple::VoxelSettings::default(),
        1.0,
    )
    .unwrap();
    let depth = grid_optical_depth_across(&volume);
    let closed_form = slab.sigma_t() * slab.depth as f64;
    println!("the grid's optical depth across the slab: {depth:.3} (closed form {closed_form:.3})");
    assert!(
        (depth / closed_form - 1.0).abs() < DENSITY_TOLERANCE,
        "the grid holds optical depth {depth:.3} across the slab, not {closed_form:.3}"
    );
    let mut failures = Vec::new();
    let size = (96, 72);
    for preset in ["blonde", "brown", "dark"] {
        let (tables, fiber) = tables(preset, &dir);
        for (name, toward) in [
            ("front", DVec3::new(0.3, 0.5, 1.0).normalize()),
            ("back", DVec3::new(0.2, 0.4, -1.0).normalize()),
        ] {
            let light = EnvLight::directional(toward.as_vec3(), [1.0; 3]);
            let os = totals(&ours(&hair, size, &light, &tables, ScatteringMode::Single));
            let multiple = tables.assets.contains_key("multiple");
            let of = match multiple {
                true => totals(&ours(&hair, size, &light, &tables, ScatteringMode::Full)),
                false => os,
            };
            // Single scattering with d_b·S_back on the directly lit fibers: the local part.
            let local = {
                let mut assets = tables.assets.clone();
                let full_direct = assets["chiang_full_direct"].clone();
                assets.insert("chiang_direct".into(), full_direct);
                let with_back = SceneTables {
                    assets,
                    baked: Vec::new(),
                    skipped: Vec::new(),
                };
                minus(
                    totals(&ours(
                        &hair,
                        size,
                        &light,
                        &with_back,
                        ScatteringMode::Single,
                    )),
                    os,
                )
            };
            let ts = totals(&theirs(&hair, size, toward, 1.0, &fiber, 2, 256, &dir));
            let tf = totals(&theirs(&hair, size, toward, 1.0, &fiber, 200, 256, &dir));
            let (om, tm) = (minus(of, os), minus(tf, ts));
            match multiple {
                true => println!(
                    "{preset} {name}: single ours/truth {:.3?}; multiple ours/truth {:.3?} (local backscatter {:.3?}, global {:.3?}); truth multiple/full {:.3?}",
                    ratio(os, ts),
                    ratio(om, tm),
                    ratio(local, tm),
                    ratio(minus(om, local), tm),
                    ratio(tm, tf)
                ),
                false => println!(
                    "{preset} {name}: single ours/truth {:.3?}; no multiple-scattering table (the plan skips it); truth multiple/full {:.3?}",
                    ratio(os, ts),
                    ratio(tm, tf)
                ),
            }
            if multiple {
                let off = ratio(om, tm)
                    .into_iter()
                    .any(|r| !(MULTIPLE_RANGE.0..=MULTIPLE_RANGE.1).contains(&r));
                if off {
                    failures.push(format!(
                        "{preset} lit from the {name}: multiple scattering {:.3?} of the truth's",
                        ratio(om, tm)
                    ));
                }
            }
        }
    }
    std::fs::remove_dir_all(&dir).ok();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
