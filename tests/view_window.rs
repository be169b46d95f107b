//! The viewer as a person uses it: the real window under Xvfb on whatever Vulkan device there
//! is (lavapipe in CI), driven by a script of mouse drags, key presses and an artist-control
//! change that needs a table rebake, ending in a screenshot. Checks that can fail:
//! - the window kept presenting frames while the rebake ran (no gap near the bake's length);
//! - the screenshot is not blank, and its sidecar holds the orbited camera and the new control;
//! - `render --replay` of the sidecar reproduces the screenshot's linear EXR.

use serde_json::{Value, json};
use std::path::Path;
use std::process::Command;
use strandlight_scene::image_metrics::relative_rmse;
use strandlight_scene::reference_cache::read_rgba_exr;
use strandlight_tables::artist::ArtistParams;

fn xvfb_run() -> Option<&'static str> {
    let found = Command::new("xvfb-run").arg("--help").output().is_ok();
    found.then_some("xvfb-run")
}

fn strandlight(dir: &Path) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_strandlight"));
    c.current_dir(dir);
    c
}

/// Share of pixels that are not black in an 8-bit RGB PNG.
fn lit_share(path: &Path) -> f64 {
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    let channels = info.color_type.samples();
    let pixels = buf[..info.buffer_size()].chunks(channels);
    let n = (info.width * info.height) as f64;
    pixels.filter(|p| p[..3].iter().any(|&c| c > 8)).count() as f64 / n
}

#[test]
fn scripted_window_keeps_presenting_through_a_rebake_and_its_screenshot_replays() {
    let Some(xvfb) = xvfb_run() else {
        println!("skipped: xvfb-run is not installed (apt-get install -y xvfb)");
        return;
    };
    let dir = std::env::temp_dir().join(format!("strandlight-view-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    // The rebake: a brighter, wider primary highlight (the artist table holds the colours).
    let mut artist = ArtistParams::default();
    artist.r.intensity = 1.5;
    artist.r.width_deg = 8.0;
    let script = json!([
        {"wait": "converged"},
        {"drag": [[0.5, 0.5], [0.62, 0.42]]},
        {"wait": "converged"},
        {"key": "B"},
        {"frames": 3},
        {"key": "B"},
        {"settings": {"artist": artist}},
        {"frames": 20},
        {"wait": "converged"},
        {"screenshot": "shot"}
    ]);
    std::fs::write(dir.join("script.json"), script.to_string()).unwrap();
    let out = Command::new(xvfb)
        .current_dir(&dir)
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
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "view failed:\n{stderr}");
    let report: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("report.json")).unwrap()).unwrap();
    println!("{}", serde_json::to_string_pretty(&report).unwrap());

    // The first bake and the rebake both ran while the window presented frames.
    assert!(report["bakes_seen"].as_u64().unwrap() >= 2, "{report}");
    assert!(
        report["frames_presented_during_bakes"].as_u64().unwrap() >= 20,
        "{report}"
    );
    let gap = report["longest_frame_gap_during_bakes_ms"]
        .as_f64()
        .unwrap();
    assert!(gap < 1500.0, "the window stalled {gap} ms during a bake");

    assert!(lit_share(&dir.join("shot.png")) > 0.02, "blank screenshot");
    let sidecar: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("shot.json")).unwrap()).unwrap();
    assert!(
        sidecar["camera"]["exact"].is_object(),
        "the drag orbited: {sidecar}"
    );
    assert_eq!(sidecar["artist"]["r"]["intensity"], json!(1.5));

    let replay = strandlight(&dir)
        .args(["render", "--replay", "shot.json", "--out", "replay"])
        .output()
        .unwrap();
    assert!(
        replay.status.success(),
        "{}",
        String::from_utf8_lossy(&replay.stderr)
    );
    let shot = read_rgba_exr(&dir.join("shot.exr")).unwrap();
    let replayed = read_rgba_exr(&dir.join("replay.exr")).unwrap();
    let error = relative_rmse(&shot, &replayed).unwrap();
    println!("screenshot against its replay: relative RMSE {error:.2e}");
    // The viewer sums its light batches on the CPU, `render` on the GPU: rounding only.
    assert!(error < 1e-4, "replay differs: relative RMSE {error}");
    std::fs::remove_dir_all(&dir).unwrap();
}
