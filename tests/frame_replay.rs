//! One frame, one truth (issue 61): the same [`FrameSettings`] drawn by every front end that
//! draws env-lit frames is the same picture. For settings drawn at random (the map turned by
//! an angle in (0°, 360°), a Y-up or a Z-up groom, a head or none), three real paths:
//! - `strandlight render replay SETTINGS.json` (the CLI's frame);
//! - `strandlight compare --settings` of those settings (its SRBF frame, written as
//!   `single-srbf.exr`);
//! - the web page's own stepping ([`Session`], preview then batches summed on the GPU) over the
//!   bundle `strandlight web --replay SETTINGS.json` writes, run natively on lavapipe.
//!
//! `render replay` and `compare` read the same tables and must agree to 1e-3 (relative RMSE
//! over the hair); the page reads the bundle's half-float tables (see [`PAGE_TOLERANCE`]). A
//! map turned one way by one front end and the other way by another differs by far more (2.7
//! at 211° on a Z-up groom before the one orientation, issue 61).
//!
//! The Z-up groom is the Y-up groom turned onto Z-up (a proper rotation taking +y to +z and the
//! Y-up front +z to the Z-up front +y): at the same settings both frames must also show the same
//! picture over blocks of pixels, which checks the map's placement in both worlds against each
//! other.

use glam::Vec3;
use std::path::{Path, PathBuf};
use std::process::Command;
use strandlight_eval::reference_cache::read_rgba_exr;
use strandlight_runtime::hair::{
    GroomParams, HairModel, HairWriteOptions, generate_groom, write_hair,
};
use strandlight_scene::env_lighting::EnvLighting;
use strandlight_scene::frame_settings::{FrameSettings, Lighting};
use strandlight_scene::head_input::HeadChoice;
use strandlight_scene::image_metrics::{Image, relative_rmse};
use strandlight_scene::point_shading::Shading;
use strandlight_scene::scene_tables::ScatteringMode;
use strandlight_tables::outside_tools::missing_tool;
use strandlight_tables::split_mix::SplitMix64;

mod page_session;
use page_session::{blocks, native_session, total};

/// `render replay` against `compare`'s SRBF frame: the same tables, the same frame builder.
const CLI_TOLERANCE: f64 = 1e-3;
/// The page's batches against `render replay`'s one call on lavapipe, with the bundle's
/// half-float tables (tests/web_page.rs measured 4.6e-5 on the demo's scene).
const PAGE_TOLERANCE: f64 = 5e-3;
/// Light maps of the Y-up and Z-up twins: each world frames its lights' maps about its own up
/// axis, so their texels fall differently across the hair and single pixels' shadows differ
/// (measured 2.8e-2 per pixel at 512², 3.2e-2 at 128², the coverage identical); over 4×4 blocks
/// that falls to 1.0e-2 and the totals agree to 1.2e-4. A map turned or mirrored differently in
/// one world moves the light itself: blocks and totals.
const TWIN_DODM_SIZE: u32 = 512;
const TWIN_BLOCK_TOLERANCE: f64 = 0.02;

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn strandlight(dir: &Path, args: &[&str]) {
    let out = Command::new(env!("CARGO_BIN_EXE_strandlight"))
        .current_dir(dir)
        .args(args)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "strandlight {}: {}{}",
        args.join(" "),
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}

fn groom() -> HairModel {
    generate_groom(&GroomParams {
        strand_count: 400,
        points_per_strand: 12,
        clump_count: 20,
        thickness: 0.5,
        ..GroomParams::default()
    })
    .unwrap()
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

/// One random frame: its settings and a name for the messages.
struct Case {
    name: String,
    settings: FrameSettings,
}

/// The first case on the other groom: the Z-up world must show the Y-up world's picture.
fn z_up_twin(first: &Case, dir: &Path) -> FrameSettings {
    FrameSettings {
        hair: Some(dir.join("groom-z-up.hair")),
        ..first.settings.clone()
    }
}

fn cases(dir: &Path) -> Vec<Case> {
    let y_up = dir.join("groom-y-up.hair");
    let z_up_path = dir.join("groom-z-up.hair");
    let model = groom();
    write_hair(&model, &y_up, &HairWriteOptions::default()).unwrap();
    write_hair(&z_up(&model), &z_up_path, &HairWriteOptions::default()).unwrap();
    let mut rng = SplitMix64::new(61);
    let mut cases = Vec::new();
    for k in 0..3 {
        // (0°, 360°), never 0 itself: a sign error is invisible at 0.
        let rotation = (1.0 + 358.0 * rng.uniform()) as f32;
        let hair = if k % 2 == 0 { &y_up } else { &z_up_path };
        // A head in two of the three: a random draw could leave it out of every case.
        let head = if k == 0 {
            HeadChoice::None
        } else {
            HeadChoice::Ellipsoid
        };
        let mut env = EnvLighting::new("procedural:sun_and_sky");
        env.scattering = ScatteringMode::Single;
        env.rotation_deg = rotation;
        // The first case has a Z-up twin ([`z_up_twin`]), compared with fine maps.
        env.dodm_size = if k == 0 { TWIN_DODM_SIZE } else { 128 };
        env.table_resolution = Some(8);
        env.fit.max_lobes = 12;
        let settings = FrameSettings {
            hair: Some(hair.clone()),
            shading: Some(Shading::Chiang),
            preset: "brown".into(),
            head: head.clone(),
            ..FrameSettings::new(Lighting::Environment(env), [64, 48])
        };
        cases.push(Case {
            name: format!(
                "{} turned {rotation:.1}°, head {head:?}",
                hair.file_name().unwrap().to_string_lossy()
            ),
            settings,
        });
    }
    cases
}

fn render_replay(dir: &Path, settings: &Path, stem: &str) -> Image {
    let stem = dir.join(stem);
    strandlight(
        dir,
        &[
            "render",
            "replay",
            settings.to_str().unwrap(),
            "--out",
            stem.to_str().unwrap(),
        ],
    );
    read_rgba_exr(&stem.with_extension("exr")).unwrap()
}

fn compare_srbf(dir: &Path, settings: &FrameSettings, name: &str) -> Image {
    let out = dir.join(format!("compare-{name}"));
    let compare = serde_json::json!({
        "frame": settings,
        "modes": ["single"],
        "reference_lights": 6,
        "reference_max_lights": 384,
        "timing_runs": 1,
        "ground_truth": "off",
        "out": out,
        "cache": "out/cache",
    });
    let file = dir.join(format!("compare-{name}.json"));
    std::fs::write(&file, compare.to_string()).unwrap();
    strandlight(dir, &["compare", "--settings", file.to_str().unwrap()]);
    read_rgba_exr(&out.join("single-srbf.exr")).unwrap()
}

/// The page's frame: the bundle written by `strandlight web --replay`, stepped by the page's
/// own session natively.
fn page_frame(dir: &Path, settings: &Path, name: &str, preset: &str) -> Image {
    let site = dir.join(format!("site-{name}"));
    let page = repo().join("target/web/pkg");
    strandlight(
        dir,
        &[
            "web",
            "--replay",
            settings.to_str().unwrap(),
            "--out",
            site.to_str().unwrap(),
            "--preset",
            preset,
            "--page",
            page.to_str().unwrap(),
        ],
    );
    native_session(&site.join("bundle"))
}

#[test]
fn render_replay_compare_and_the_page_draw_the_same_frame_of_the_same_settings() {
    if !repo()
        .join("target/web/pkg/strandlight_web_bg.wasm")
        .is_file()
    {
        missing_tool(
            "the built web page (target/web/pkg)",
            "scripts/web.sh --page-only",
        );
        return;
    }
    let dir = std::env::temp_dir().join(format!("strandlight-replay-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let mut replays = Vec::new();
    let cases = cases(&dir);
    for (k, case) in cases.iter().enumerate() {
        let name = format!("case{k}");
        let file = dir.join(format!("{name}.json"));
        std::fs::write(&file, case.settings.to_json()).unwrap();
        let replay = render_replay(&dir, &file, &name);
        let compared = compare_srbf(&dir, &case.settings, &name);
        let page = page_frame(&dir, &file, &name, &case.settings.preset);
        let cli = relative_rmse(&compared, &replay).unwrap();
        let browser = relative_rmse(&page, &replay).unwrap();
        eprintln!(
            "{}: compare's SRBF frame vs render replay {cli:.2e}, the page's vs render replay {browser:.2e}",
            case.name
        );
        assert!(cli <= CLI_TOLERANCE, "{}: compare {cli}", case.name);
        assert!(browser <= PAGE_TOLERANCE, "{}: page {browser}", case.name);
        replays.push(replay);
    }
    let twin = dir.join("twin.json");
    std::fs::write(&twin, z_up_twin(&cases[0], &dir).to_json()).unwrap();
    let (y, z) = (&replays[0], &render_replay(&dir, &twin, "twin"));
    let (pixels, blocks) = (
        relative_rmse(z, y).unwrap(),
        relative_rmse(&blocks(z, 4), &blocks(y, 4)).unwrap(),
    );
    let totals = total(z) / total(y);
    eprintln!(
        "the same frame on the Y-up and the Z-up groom: {pixels:.2e} per pixel, {blocks:.2e} over \
         4×4 blocks, totals' ratio {totals:.5}"
    );
    assert!(
        blocks <= TWIN_BLOCK_TOLERANCE,
        "Y-up against Z-up: {blocks}"
    );
    assert!(
        (totals - 1.0).abs() <= 2e-3,
        "Y-up against Z-up totals: {totals}"
    );
    std::fs::remove_dir_all(&dir).ok();
}
