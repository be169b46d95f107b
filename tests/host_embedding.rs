//! The runtime in someone else's renderer (issue 62): `runtime/examples/host.rs`, a wgpu
//! application with its own device, meshes (a ball and a floor), depth buffer and camera, draws
//! the hair of a frame's settings into its own render pass with the runtime's host API. Checked
//! against two independent references:
//! - the host's depth, computed on the CPU by casting each pixel's ray at the host's triangles:
//!   where the host's surface is nearer than the hair, the pixel is the host's alone; where the
//!   hair is nearer, it is the hair over the host's colour;
//! - `strandlight render replay` of the same settings: where nothing of the host is in front,
//!   the hair is that frame.
//!
//! The host's frame path (a new frame, every batch, its render pass) must make no GPU→CPU copy:
//! the runtime counts every one it makes. The same holds for a point-lit frame
//! (`HairRenderer::draw_point_lit`); with its fibers' front depth left undrawn, no hair pixel
//! reached the host's picture and the test failed.

#[path = "../runtime/examples/host.rs"]
#[allow(dead_code)]
mod host;

use glam::{Vec3, Vec4};
use std::path::Path;
use std::process::Command;
use strandlight_eval::reference_cache::read_rgba_exr;
use strandlight_scene::env_lighting::EnvLighting;
use strandlight_scene::frame_settings::{
    FrameSettings, Lighting, PointLighting, Shadows, Transparency,
};
use strandlight_scene::point_shading::Shading;
use strandlight_scene::scene_tables::ScatteringMode;

/// The host's target is f16 and the replay's EXR f32: the hair must agree to f16's rounding
/// (about 1e-3 relative), far below what a misplaced or re-exposed frame differs by.
const REPLAY_TOLERANCE: f64 = 4e-3;
/// Depths nearer than this to each other are a tie the test does not judge.
const DEPTH_TIE: f32 = 1e-5;

fn settings(dir: &Path) -> FrameSettings {
    let mut env = EnvLighting::new("procedural:sun_and_sky");
    env.scattering = ScatteringMode::Single;
    env.rotation_deg = 30.0;
    env.dodm_size = 128;
    env.table_resolution = Some(8);
    env.fit.max_lobes = 12;
    let settings = FrameSettings {
        shading: Some(Shading::Chiang),
        preset: "brown".into(),
        ..FrameSettings::new(Lighting::Environment(env), [160, 120])
    };
    std::fs::write(dir.join("settings.json"), settings.to_json()).unwrap();
    settings
}

fn render_replay(dir: &Path) -> Vec<[f32; 4]> {
    let out = Command::new(env!("CARGO_BIN_EXE_strandlight"))
        .current_dir(dir)
        .args(["render", "replay", "settings.json", "--out", "replay"])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "render replay: {}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    read_rgba_exr(&dir.join("replay.exr")).unwrap().pixels
}

/// The nearest of `triangles` through each pixel's centre, as wgpu's 0..1 depth of
/// `view_projection` (1 where none is hit): Möller–Trumbore on each pixel's ray.
fn cpu_depth(triangles: &[[Vec3; 3]], view_projection: glam::Mat4, [w, h]: [u32; 2]) -> Vec<f32> {
    let clip_to_world = view_projection.inverse();
    let unproject = |x: f32, y: f32, z: f32| {
        let p = clip_to_world * Vec4::new(x, y, z, 1.0);
        p.truncate() / p.w
    };
    let mut depths = Vec::with_capacity((w * h) as usize);
    for y in 0..h {
        for x in 0..w {
            let ndc = [
                2.0 * (x as f32 + 0.5) / w as f32 - 1.0,
                1.0 - 2.0 * (y as f32 + 0.5) / h as f32,
            ];
            let near = unproject(ndc[0], ndc[1], 0.0);
            let ray = unproject(ndc[0], ndc[1], 1.0) - near;
            let hit = triangles
                .iter()
                .filter_map(|t| ray_triangle(near, ray, t))
                .fold(f32::INFINITY, f32::min);
            depths.push(match hit.is_finite() {
                true => {
                    let clip = view_projection * (near + hit * ray).extend(1.0);
                    clip.z / clip.w
                }
                false => 1.0,
            });
        }
    }
    depths
}

/// Pixels on the mesh's outline: the mesh covers the pixel or one of its four neighbours, not
/// all five. A pixel centre a rounding away from an edge is the rasterizer's call, not the
/// test's (one such pixel of the ball, covered on the GPU and missed by the CPU ray, made the
/// clear pixels' error 0.2).
fn mesh_silhouette(mesh_depth: &[f32], [w, h]: [u32; 2]) -> Vec<bool> {
    let covered = |x: i64, y: i64| {
        let inside = (0..w as i64).contains(&x) && (0..h as i64).contains(&y);
        inside && mesh_depth[(y * w as i64 + x) as usize] < 1.0
    };
    (0..(w * h) as i64)
        .map(|p| {
            let (x, y) = (p % w as i64, p / w as i64);
            let here = covered(x, y);
            [(1, 0), (-1, 0), (0, 1), (0, -1)]
                .iter()
                .any(|(dx, dy)| covered(x + dx, y + dy) != here)
        })
        .collect()
}

/// The ray parameter of `origin + t·direction` on triangle `t`, t in [0, 1].
fn ray_triangle(origin: Vec3, direction: Vec3, [a, b, c]: &[Vec3; 3]) -> Option<f32> {
    let (e1, e2) = (*b - *a, *c - *a);
    let p = direction.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-12 {
        return None;
    }
    let s = origin - *a;
    let u = s.dot(p) / det;
    let q = s.cross(e1);
    let v = direction.dot(q) / det;
    let t = e2.dot(q) / det;
    (u >= 0.0 && v >= 0.0 && u + v <= 1.0 && (0.0..=1.0).contains(&t)).then_some(t)
}

fn over(hair: [f32; 4], host: [f32; 4]) -> [f32; 4] {
    let under = 1.0 - hair[3];
    std::array::from_fn(|k| hair[k] + under * host[k])
}

/// √(Σ‖a − r‖² / Σ‖r‖²) over RGB.
fn relative_rmse(pairs: &[([f32; 4], [f32; 4])]) -> f64 {
    let (mut num, mut den) = (0.0f64, 0.0f64);
    for (a, r) in pairs {
        for k in 0..3 {
            num += ((a[k] - r[k]) as f64).powi(2);
            den += (r[k] as f64).powi(2);
        }
    }
    (num / den.max(1e-30)).sqrt()
}

#[test]
fn the_host_hides_the_hair_where_its_mesh_is_nearer_and_shows_the_replayed_frame_elsewhere() {
    let dir = std::env::temp_dir().join(format!("strandlight-host-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let settings = settings(&dir);
    host_matches_references(&dir, &settings);
}

/// The same for a frame of the thesis techniques: two lights with deep opacity maps, the
/// K-buffer's transparency, drawn whole by `HairRenderer::draw_point_lit`.
#[test]
fn a_point_lit_frame_in_the_host_is_hidden_by_its_mesh_and_is_the_replayed_frame_elsewhere() {
    let dir = std::env::temp_dir().join(format!("strandlight-host-points-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let point = PointLighting {
        lights: vec!["directional:0.4,1,0.6:2".into(), "point:1,0.5,1.5:3".into()],
        shadows: Shadows::Dom,
        transparency: Transparency::Kbuffer,
        ..PointLighting::default()
    };
    let settings = FrameSettings {
        shading: Some(Shading::Chiang),
        preset: "brown".into(),
        ..FrameSettings::new(Lighting::Lights(point), [160, 120])
    };
    std::fs::write(dir.join("settings.json"), settings.to_json()).unwrap();
    host_matches_references(&dir, &settings);
}

fn host_matches_references(dir: &Path, settings: &FrameSettings) {
    let dir = dir.to_path_buf();
    let settings = settings.clone();
    // One timed frame each way first: the checked picture is then a frame started again on
    // the same sums (each new frame must zero them).
    let (frame, times) = host::run(&settings, &dir.join("out/cache"), 1).unwrap();
    // The host's frame path (new frame, every batch, its render pass) copies nothing back.
    assert_eq!(
        times.readbacks_on_gpu, 0,
        "readbacks on the host's frame path"
    );
    let replay = render_replay(&dir);
    let mesh_depth = cpu_depth(
        &frame.triangles,
        frame.camera.view_projection(frame.size),
        frame.size,
    );

    let on_silhouette = mesh_silhouette(&mesh_depth, frame.size);
    let (mut hidden, mut hidden_wrong, mut in_front, mut clear) = (0, 0, Vec::new(), Vec::new());
    for p in 0..mesh_depth.len() {
        let (mesh, hair) = (mesh_depth[p], frame.hair_depth[p]);
        if hair >= 1.0 || (mesh - hair).abs() < DEPTH_TIE || on_silhouette[p] {
            continue;
        }
        if mesh < hair {
            hidden += 1;
            hidden_wrong += usize::from(frame.with_hair[p] != frame.host_only[p]);
        } else if mesh >= 1.0 {
            clear.push((frame.with_hair[p], replay[p]));
        } else {
            in_front.push((frame.with_hair[p], over(replay[p], frame.host_only[p])));
        }
    }
    eprintln!(
        "hair pixels: {hidden} behind the host's mesh ({hidden_wrong} not the host's alone), {} in \
         front of it, {} with nothing of the host in front",
        in_front.len(),
        clear.len()
    );
    assert!(
        hidden > 50 && in_front.len() > 50 && clear.len() > 500,
        "the scene must test all three cases"
    );
    assert_eq!(
        hidden_wrong, 0,
        "hair drawn where the host's mesh is nearer"
    );
    let (front_error, clear_error) = (relative_rmse(&in_front), relative_rmse(&clear));
    eprintln!("hair over the host's mesh vs replay over it: {front_error:.2e}");
    eprintln!("hair with nothing in front vs render replay: {clear_error:.2e}");
    assert!(front_error < REPLAY_TOLERANCE, "{front_error}");
    assert!(clear_error < REPLAY_TOLERANCE, "{clear_error}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// The README's embedding snippet is the example's code, line for line (comments aside).
#[test]
fn the_readme_shows_the_examples_own_lines() {
    let readme =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/README.md")).unwrap();
    let example = include_str!("../runtime/examples/host.rs");
    let section = readme
        .split("## Use the runtime in your renderer")
        .nth(1)
        .expect("the README's section");
    let block = section
        .split("```rust")
        .nth(1)
        .and_then(|b| b.split("```").next())
        .expect("its code block");
    let lines: Vec<&str> = block
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && !l.starts_with("//"))
        .collect();
    assert!(lines.len() >= 6, "{block}");
    for line in lines {
        assert!(example.contains(line), "README line not in host.rs: {line}");
    }
}
