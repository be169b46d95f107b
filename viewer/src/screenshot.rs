//! A screenshot: the window's picture as PNG, the linear frame as EXR (what `render` writes), and
//! the frame's settings as a JSON sidecar that `strandlight render replay` renders again. The
//! settings also go into both images' metadata. The whole window, panel included, is captured
//! beside them when the window next paints (`window_capture`).

use crate::recompute::Display;
use anyhow::Context;
use std::path::{Path, PathBuf};
use strandlight_scene::frame_settings::FrameSettings;
use strandlight_scene::image_metrics::Image;
use strandlight_tables::atomic_write::write_atomically;
use strandlight_tables::image_out::{write_exr, write_png};

/// The files of a screenshot at `stem`.
pub struct ScreenshotFiles {
    pub png: PathBuf,
    pub exr: PathBuf,
    pub sidecar: PathBuf,
    /// `STEM-window.png`: the whole window.
    pub window: PathBuf,
}

impl ScreenshotFiles {
    pub fn at(stem: &Path) -> Self {
        let stem = match stem.extension().and_then(|e| e.to_str()) {
            Some("png" | "exr" | "json") => stem.with_extension(""),
            _ => stem.to_path_buf(),
        };
        let mut window = stem.clone().into_os_string();
        window.push("-window.png");
        Self {
            window: window.into(),
            png: stem.with_extension("png"),
            exr: stem.with_extension("exr"),
            sidecar: stem.with_extension("json"),
        }
    }
}

/// Writes the screenshot; `shown` is the window's picture (exposed, over the background).
pub fn save(
    stem: &Path,
    settings: &FrameSettings,
    display: &Display,
    exposure_stops: f32,
    frame: &Image,
    shown: &[[f32; 4]],
) -> anyhow::Result<ScreenshotFiles> {
    let files = ScreenshotFiles::at(stem);
    if let Some(dir) = files.png.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("screenshot folder {}", dir.display()))?;
    }
    let json = settings.to_json();
    let compact = serde_json::to_string(settings)?;
    let look = format!(
        "strandlight view screenshot; exposure {exposure_stops:+.2} stops ({}), backdrop {}; \
         replay: strandlight render replay {}; settings {compact}",
        if display.exposure_stops.is_none() {
            "auto"
        } else {
            "manual"
        },
        display.backdrop.name(),
        files.sidecar.display()
    );
    let (w, h) = (frame.width, frame.height);
    write_atomically::<std::io::Error, _>(&files.sidecar, |out| {
        use std::io::Write;
        out.write_all(json.as_bytes())
    })
    .with_context(|| format!("writing {}", files.sidecar.display()))?;
    write_exr(&files.exr, w, h, &frame.pixels, &look)?;
    write_png(&files.png, w, h, shown, &look)?;
    Ok(files)
}
