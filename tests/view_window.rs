//! The viewer as a person uses it: the real window under Xvfb on whatever Vulkan device there
//! is (lavapipe in CI), driven by a script of mouse drags, key presses and an artist-control
//! change that needs a table rebake, ending in a screenshot. Checks that can fail:
//! - the window kept presenting frames while the rebake ran (no gap near the bake's length);
//! - the screenshot is not blank, and its sidecar holds the orbited camera and the new control;
//! - the capture of the whole window shows the screenshot's picture where the image sits;
//! - `render replay` of the sidecar reproduces the screenshot's linear EXR, also after the
//!   panel turns the map;
//! - switched to point lights (DOM shadows, sorted transparency) as the panel's radio button
//!   does, and orbited again, the window converges to another picture whose screenshot
//!   `render replay` also reproduces.
//!
//! And on the renderer's device (`--window-device shared`), the window draws each frame where it
//! is: the process reads back nothing but its screenshot, and the window shows that picture.

use serde_json::{Value, json};
use std::path::Path;
use std::process::Command;
use strandlight_eval::reference_cache::read_rgba_exr;
use strandlight_scene::frame_settings::{PointLighting, Shadows, Transparency};
use strandlight_scene::image_metrics::{Image, relative_rmse};
use strandlight_tables::artist::ArtistParams;
use strandlight_tables::outside_tools::{missing_tool, program_exists};

fn xvfb_run() -> Option<&'static str> {
    program_exists("xvfb-run").then_some("xvfb-run")
}

fn strandlight(dir: &Path) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_strandlight"));
    c.current_dir(dir);
    c
}

/// An 8-bit PNG as (width, height, RGB pixels).
fn read_rgb8(path: &Path) -> (u32, u32, Vec<[u8; 3]>) {
    let file = std::fs::File::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let decoder = png::Decoder::new(std::io::BufReader::new(file));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    let channels = info.color_type.samples();
    let pixels = buf[..info.buffer_size()]
        .chunks(channels)
        .map(|p| [p[0], p[1], p[2]])
        .collect();
    (info.width, info.height, pixels)
}

/// Share of pixels that are not black in an 8-bit PNG.
fn lit_share(path: &Path) -> f64 {
    let (_, _, pixels) = read_rgb8(path);
    let lit = pixels.iter().filter(|p| p.iter().any(|&c| c > 8)).count();
    lit as f64 / pixels.len() as f64
}

/// Mean absolute difference (8-bit levels) between the screenshot and the window capture
/// sampled at the centre of each screenshot pixel's footprint in `rect` (physical pixels),
/// where the window's bilinear magnification reproduces the texel.
fn window_against_screenshot(window: &Path, shot: &Path, rect: [f64; 4]) -> f64 {
    let (ww, wh, win) = read_rgb8(window);
    let (sw, sh, shot) = read_rgb8(shot);
    let (sx, sy) = (
        (rect[2] - rect[0]) / sw as f64,
        (rect[3] - rect[1]) / sh as f64,
    );
    let mut sum = 0.0;
    for y in 0..sh {
        for x in 0..sw {
            let wx = (rect[0] + (x as f64 + 0.5) * sx).floor() as u32;
            let wy = (rect[1] + (y as f64 + 0.5) * sy).floor() as u32;
            assert!(
                wx < ww && wy < wh,
                "image rect {rect:?} outside the {ww}x{wh} window"
            );
            let a = shot[(y * sw + x) as usize];
            let b = win[(wy * ww + wx) as usize];
            sum += (0..3)
                .map(|c| (a[c] as f64 - b[c] as f64).abs())
                .sum::<f64>()
                / 3.0;
        }
    }
    sum / (sw * sh) as f64
}

#[test]
fn scripted_window_keeps_presenting_through_a_rebake_and_its_screenshot_replays() {
    let Some(xvfb) = xvfb_run() else {
        missing_tool("xvfb-run", "apt-get install -y xvfb");
        return;
    };
    let started = std::time::Instant::now();
    let phase = |what: &str| eprintln!("[{:6.1} s] {what}", started.elapsed().as_secs_f64());
    let dir = std::env::temp_dir().join(format!("strandlight-view-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let report = run_scripted_window(xvfb, &dir);
    phase("the scripted window exited");

    assert_bakes_ran_while_the_window_presented(&report);
    assert_lit_before_the_tables_were_baked(&report);
    assert_rebake_starts_with_a_first_look(&report);
    assert_previews_from_the_first_look_tables(&report);
    assert!(lit_share(&dir.join("shot.png")) > 0.02, "blank screenshot");
    assert_readout_beside_the_image(&report);
    assert_window_captures_show_the_screenshots(&report, &dir);

    let sidecar: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("shot.json")).unwrap()).unwrap();
    assert!(
        sidecar["camera"]["exact"].is_object(),
        "the drag orbited: {sidecar}"
    );
    assert_eq!(sidecar["artist"]["r"]["intensity"], json!(1.5));

    let shot = read_rgba_exr(&dir.join("shot.exr")).unwrap();
    let error = replay_error(&dir, "shot");
    println!("screenshot against its replay: relative RMSE {error:.2e}");
    // The viewer adds its light batches into one running sum, `render` draws them at once, both
    // on the GPU: rounding only.
    assert!(error < 1e-4, "replay differs: relative RMSE {error}");
    phase("the screenshot replayed");

    assert_rotated_screenshot_changed_and_replays(&dir, &shot);
    phase("the rotated screenshot replayed");

    assert_point_lit_screenshot_changed_and_replays(&dir, &shot);
    phase("the point-lit screenshot replayed");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn on_the_renderers_device_the_window_reads_back_nothing_but_its_screenshot() {
    let Some(xvfb) = xvfb_run() else {
        missing_tool("xvfb-run", "apt-get install -y xvfb");
        return;
    };
    let dir = std::env::temp_dir().join(format!("strandlight-view-shared-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let out = Command::new(xvfb)
        .current_dir(&dir)
        .args(["-a", "-s", "-screen 0 1280x800x24"])
        .args([
            env!("CARGO_BIN_EXE_strandlight"),
            "view",
            "--size",
            "160x120",
        ])
        // Single scattering: on a hardware adapter the forward-scattering march of multiple
        // scattering reads its grid (not the frame) back once per batch, the runtime's one
        // documented exception; the display of the multiple-scattering half is unit-tested.
        .args(["--scattering", "single", "--window-device", "shared"])
        .args(["--screenshot", "shot", "--report", "report.json"])
        .output()
        .expect("xvfb-run runs");
    let report = view_report(&out, &dir);
    assert_eq!(report["window_device"], json!("shared"));
    let presented = report["frames_presented"].as_u64().unwrap();
    assert!(presented >= 3, "{report}");
    // The preview, each batch and the converged frame reached the window without a copy to
    // the CPU; the screenshot's one readback is all.
    assert_eq!(report["screenshot_readbacks"], json!(1), "{report}");
    assert_eq!(
        report["data_readbacks"],
        json!(1),
        "GPU→CPU copies besides the screenshot over {presented} presented frames"
    );
    assert!(lit_share(&dir.join("shot.png")) > 0.02, "blank screenshot");
    let difference = window_against_screenshot(
        &dir.join("shot-window.png"),
        &dir.join("shot.png"),
        capture_rect(&report, 0),
    );
    println!("window capture against the screenshot: mean |Δ| {difference:.2} levels");
    assert!(
        difference < 2.0,
        "the window shows another picture: {difference} levels"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The map's turn the script sets in the panel, away from 0 and 180 so that a turn the wrong
/// way draws another frame.
const ROTATION_DEG: f32 = 211.0;

/// The script of the test: orbit, toggle the overlay keys, change an artist control (which
/// rebakes a table: a brighter, wider primary highlight, the artist table holding the colours),
/// screenshot `shot`; turn the map by [`ROTATION_DEG`], screenshot `rotated`; then switch to [`point_lighting`], orbit again and screenshot `points`.
fn viewer_script() -> Value {
    let mut artist = ArtistParams::default();
    artist.r.intensity = 1.5;
    artist.r.width_deg = 8.0;
    json!([
        {"wait": "converged"},
        {"drag": [[0.5, 0.5], [0.62, 0.42]]},
        {"wait": "converged"},
        {"key": "B"},
        {"frames": 3},
        {"key": "B"},
        {"frames": 3},
        {"key": "B"},
        {"settings": {"artist": artist}},
        {"frames": 20},
        {"wait": "converged"},
        {"key": "O"},
        {"frames": 2},
        {"key": "O"},
        {"frames": 2},
        {"screenshot": "shot"},
        {"settings": {"lighting": {"environment": {"rotation_deg": ROTATION_DEG}}}},
        {"wait": "converged"},
        {"screenshot": "rotated"},
        {"settings": {"lighting": {"environment": null, "lights": point_lighting()}}},
        {"wait": "converged"},
        {"drag": [[0.5, 0.5], [0.4, 0.55]]},
        {"wait": "converged"},
        {"frames": 2},
        {"screenshot": "points"}
    ])
}

/// Runs `strandlight view` on [`viewer_script`] in `dir` under `xvfb`; it must exit cleanly.
/// Returns (and prints) the viewer's report.
fn run_scripted_window(xvfb: &str, dir: &Path) -> Value {
    std::fs::write(dir.join("script.json"), viewer_script().to_string()).unwrap();
    let out = Command::new(xvfb)
        .current_dir(dir)
        .args([
            "-a",
            "-s",
            "-screen 0 1280x800x24",
            env!("CARGO_BIN_EXE_strandlight"),
        ])
        .args([
            "view",
            "--size",
            "160x120",
            "--shading",
            "artist",
            "--scattering",
            "single",
        ])
        .args([
            "--script",
            "script.json",
            "--report",
            "report.json",
            "--timeout-s",
            "600",
        ])
        .output()
        .expect("xvfb-run runs");
    view_report(&out, dir)
}

/// The report `view --report report.json` wrote in `dir`, printed; the run must have exited
/// cleanly.
fn view_report(out: &std::process::Output, dir: &Path) -> Value {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "view failed:\n{stderr}");
    let report: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("report.json")).unwrap()).unwrap();
    println!("{}", serde_json::to_string_pretty(&report).unwrap());
    report
}

/// Where the image sat in window capture `i`, physical pixels: [x0, y0, x1, y1].
fn capture_rect(report: &Value, i: usize) -> [f64; 4] {
    let rect: Vec<f64> = report["window_capture_image_rects_px"][i]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    rect.try_into().unwrap()
}

/// The first bake and the rebake both ran while the window presented frames, with no gap near
/// a bake's length.
fn assert_bakes_ran_while_the_window_presented(report: &Value) {
    assert!(report["bakes_seen"].as_u64().unwrap() >= 2, "{report}");
    assert!(
        report["frames_presented_during_bakes"].as_u64().unwrap() >= 20,
        "{report}"
    );
    let gap = report["longest_frame_gap_during_bakes_ms"]
        .as_f64()
        .unwrap();
    assert!(gap < 1500.0, "the window stalled {gap} ms during a bake");
}

/// On its empty cache the window showed a lit frame drawn with the first look's coarse tables,
/// before the full ones were baked (how soon is a benchmark figure: scripts/first-minute.sh).
fn assert_lit_before_the_tables_were_baked(report: &Value) {
    assert_eq!(report["first_lit_coarse_tables"], json!(true), "{report}");
    let seconds = report["first_lit_seconds"].as_f64().unwrap();
    println!("first lit frame {seconds:.2} s after the start, from the coarse tables");
}

/// The artist change's rebake showed a first look of the new colours from coarse tables, never
/// the old colours' tables drawn with the new settings.
fn assert_rebake_starts_with_a_first_look(report: &Value) {
    assert_eq!(
        report["pictures_from_previous_tables"],
        json!(0),
        "{report}"
    );
    let coarse = report["coarse_pictures"].as_u64().unwrap();
    assert!(
        coarse >= 2,
        "a coarse first look at the start and at the rebake: {coarse}"
    );
}

/// Every env-lit preview (the start, the drags, the rebake, the map's turn) came from the first
/// look's fit and tables, also once the full ones were baked.
fn assert_previews_from_the_first_look_tables(report: &Value) {
    let previews = report["env_previews"].as_u64().unwrap();
    assert!(previews >= 3, "{report}");
    assert_eq!(
        report["env_previews_from_first_look_tables"]
            .as_u64()
            .unwrap(),
        previews,
        "{report}"
    );
}

/// The timing readout sits beside the image, so it never covers the hair.
fn assert_readout_beside_the_image(report: &Value) {
    let rect_of = |v: &Value| -> [f64; 4] {
        let r: Vec<f64> = v
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect();
        r.try_into().unwrap()
    };
    let image = rect_of(&report["image_rect_px"]);
    let readout = rect_of(&report["readout_rect_px"]);
    let overlap_x = image[2].min(readout[2]) - image[0].max(readout[0]);
    let overlap_y = image[3].min(readout[3]) - image[1].max(readout[1]);
    assert!(
        overlap_x <= 0.0 || overlap_y <= 0.0,
        "the readout {readout:?} covers the image {image:?}"
    );
}

/// The whole window, panel included: larger than the frame, and showing the same picture where
/// the frame sits, for every screenshot.
fn assert_window_captures_show_the_screenshots(report: &Value, dir: &Path) {
    assert_eq!(
        report["window_captures"],
        json!(["shot-window.png", "rotated-window.png", "points-window.png"])
    );
    for (i, stem) in ["shot", "rotated", "points"].into_iter().enumerate() {
        let window = dir.join(format!("{stem}-window.png"));
        let (ww, wh, _) = read_rgb8(&window);
        assert!(ww > 160 + 300 && wh > 120, "window capture {ww}x{wh}");
        let difference = window_against_screenshot(
            &window,
            &dir.join(format!("{stem}.png")),
            capture_rect(report, i),
        );
        println!(
            "{stem}: window capture against the screenshot in the image rect: mean |Δ| {difference:.2} levels"
        );
        // Both are the same 8-bit tonemap; the window adds an sRGB texture round trip.
        assert!(
            difference < 2.0,
            "{stem}: the window shows another picture: {difference} levels"
        );
    }
}

/// Point lights: the sidecar holds them, the picture changed from the environment-lit `shot`,
/// and it replays.
fn assert_point_lit_screenshot_changed_and_replays(dir: &Path, shot: &Image) {
    let sidecar: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("points.json")).unwrap()).unwrap();
    assert_eq!(
        sidecar["lighting"]["lights"]["shadows"],
        json!("dom"),
        "{sidecar}"
    );
    assert!(
        lit_share(&dir.join("points.png")) > 0.02,
        "blank point-lit screenshot"
    );
    let points = read_rgba_exr(&dir.join("points.exr")).unwrap();
    let change = relative_rmse(&points, shot).unwrap();
    assert!(
        change > 0.1,
        "the point lights did not change the picture: {change}"
    );
    let error = replay_error(dir, "points");
    println!("point-lit screenshot against its replay: relative RMSE {error:.2e}");
    // The same frame function on the same device, but sorted transparency bins its segments with
    // atomics and blends each bin in whatever order they give (sorted_blend.wgsl), so two runs of
    // one frame differ where fragments of one bin overlap: 1.4e-4 measured, 1e-3 allowed, a hundredth
    // of what the switch to point lights moved the picture (above).
    assert!(
        error < 1e-3,
        "point-lit replay differs: relative RMSE {error}"
    );
}

/// The map turned in the viewer draws what `render` draws at that turn: the sidecar names it,
/// the picture changed, and `render replay` of the sidecar reproduces it.
fn assert_rotated_screenshot_changed_and_replays(dir: &Path, shot: &Image) {
    let sidecar: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("rotated.json")).unwrap()).unwrap();
    assert_eq!(
        sidecar["lighting"]["environment"]["rotation_deg"],
        json!(ROTATION_DEG),
        "{sidecar}"
    );
    let rotated = read_rgba_exr(&dir.join("rotated.exr")).unwrap();
    let change = relative_rmse(&rotated, shot).unwrap();
    assert!(
        change > 0.1,
        "turning the map did not change the picture: {change}"
    );
    let error = replay_error(dir, "rotated");
    println!("rotated screenshot against its replay: relative RMSE {error:.2e}");
    assert!(
        error < 1e-4,
        "rotated replay differs: relative RMSE {error}"
    );
}

/// The point lights the script switches to: the default light, shadowed by deep opacity maps,
/// drawn with sorted transparency.
fn point_lighting() -> Value {
    serde_json::to_value(PointLighting {
        shadows: Shadows::Dom,
        transparency: Transparency::Sorted,
        ..PointLighting::default()
    })
    .unwrap()
}

/// Relative RMSE between the screenshot `STEM.exr` and `render replay STEM.json`'s frame.
fn replay_error(dir: &Path, stem: &str) -> f64 {
    let out = format!("{stem}-replay");
    let replay = strandlight(dir)
        .args(["render", "replay", &format!("{stem}.json"), "--out", &out])
        .output()
        .unwrap();
    assert!(
        replay.status.success(),
        "{}",
        String::from_utf8_lossy(&replay.stderr)
    );
    let shot = read_rgba_exr(&dir.join(format!("{stem}.exr"))).unwrap();
    let replayed = read_rgba_exr(&dir.join(format!("{out}.exr"))).unwrap();
    relative_rmse(&shot, &replayed).unwrap()
}
