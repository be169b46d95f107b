//! A picture of what the fit lost: original | reconstruction | error, side by side, as one PNG.
//!
//! Tonemapping (named here and printed by the CLI): radiance × exposure, where exposure puts
//! the original's solid-angle-weighted mean luminance at 0.18, then Reinhard `x / (1 + x)`
//! per channel, then the sRGB transfer curve. The error panel shows |fit − original| with the
//! same exposure, so equal brightness means equal radiance in all three panels.

use crate::envmap::EnvMap;
use std::path::Path;
use strandlight_tables::atomic_write::write_atomically;
use strandlight_tables::colour::{luminance, srgb_encode};
use strandlight_tables::srbf::SrbfLobe;

pub const TONEMAP: &str = "exposure to mean luminance 0.18, Reinhard x/(1+x), sRGB";

#[derive(Debug, thiserror::Error)]
pub enum PreviewError {
    #[error("{path}: cannot write the preview: {message}")]
    Write {
        path: std::path::PathBuf,
        message: String,
    },
}

/// Writes the three panels at `panel_width × panel_width/2` each, `map` being the original.
/// `lobes` are in the map's own frame (undo any rotation before calling).
pub fn write_preview(
    map: &EnvMap,
    lobes: &[SrbfLobe],
    panel_width: usize,
    path: &Path,
) -> Result<(), PreviewError> {
    let original = map.downsampled(panel_width, panel_width / 2);
    let (w, h) = (original.width(), original.height());
    let fit = crate::procedural_env::from_srbf_lobes(w, lobes);
    let lum = |p: [f32; 3]| luminance(p.map(f64::from));
    let mean: f64 = (0..h)
        .map(|y| {
            original.row_solid_angle(y) * (0..w).map(|x| lum(original.pixel(x, y))).sum::<f64>()
        })
        .sum::<f64>()
        / (4.0 * std::f64::consts::PI);
    let exposure = if mean > 0.0 { 0.18 / mean } else { 1.0 };
    let gap = 4;
    let mut img = image::RgbImage::new((3 * w + 2 * gap) as u32, h as u32);
    for y in 0..h {
        for x in 0..w {
            let o = original.pixel(x, y);
            let f = fit.pixel(x, y);
            let e: [f32; 3] = std::array::from_fn(|c| (f[c] - o[c]).abs());
            for (panel, p) in [o, f, e].into_iter().enumerate() {
                let px = image::Rgb(p.map(|v| encode(v as f64 * exposure)));
                img.put_pixel((panel * (w + gap) + x) as u32, y as u32, px);
            }
        }
    }
    let mut bytes = Vec::new();
    let write_err = |message: String| PreviewError::Write {
        path: path.into(),
        message,
    };
    img.write_to(
        &mut std::io::Cursor::new(&mut bytes),
        image::ImageFormat::Png,
    )
    .map_err(|e| write_err(e.to_string()))?;
    write_atomically(path, |out| std::io::Write::write_all(out, &bytes))
        .map_err(|e: std::io::Error| write_err(e.to_string()))
}

fn encode(x: f64) -> u8 {
    let t = if x.is_finite() && x > 0.0 {
        x / (1.0 + x)
    } else {
        0.0
    };
    (srgb_encode(t) * 255.0 + 0.5).clamp(0.0, 255.0) as u8
}
