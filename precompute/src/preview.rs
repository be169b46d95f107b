//! A picture of what the fit lost: original | reconstruction | error, side by side, as one PNG.
//!
//! Tonemapping (named here and printed by the CLI): radiance × exposure, where exposure puts
//! the original's solid-angle-weighted mean luminance at 0.18, then Reinhard `x / (1 + x)`
//! per channel, then the sRGB transfer curve. The error panel shows |fit − original| with the
//! same exposure, so equal brightness means equal radiance in all three panels.

use crate::envmap::EnvMap;
use std::path::Path;
use strandlight_tables::colour::{luminance, srgb_encode};
use strandlight_tables::image_out::{ImageWriteError, write_png_rgb8_with_text};
use strandlight_tables::srbf::SrbfLobe;

pub const TONEMAP: &str = "exposure to mean luminance 0.18, Reinhard x/(1+x), sRGB";

#[derive(Debug, thiserror::Error)]
pub enum PreviewError {
    #[error("cannot write the preview: {0}")]
    Write(#[from] ImageWriteError),
}

/// Writes the three panels at `panel_width × panel_width/2` each, `map` being the original.
/// `lobes` are in the map's own frame, as every fit is.
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
    let total_w = 3 * w + 2 * gap;
    let mut bytes = vec![0u8; total_w * h * 3];
    for y in 0..h {
        for x in 0..w {
            let o = original.pixel(x, y);
            let f = fit.pixel(x, y);
            let e: [f32; 3] = std::array::from_fn(|c| (f[c] - o[c]).abs());
            for (panel, p) in [o, f, e].into_iter().enumerate() {
                let at = 3 * (y * total_w + panel * (w + gap) + x);
                bytes[at..at + 3].copy_from_slice(&p.map(|v| encode(v as f64 * exposure)));
            }
        }
    }
    Ok(write_png_rgb8_with_text(
        path,
        total_w as u32,
        h as u32,
        &bytes,
        &[
            ("Description", "environment map | SRBF fit | |fit − map|"),
            ("Tonemap", TONEMAP),
        ],
    )?)
}

fn encode(x: f64) -> u8 {
    let t = if x.is_finite() && x > 0.0 {
        x / (1.0 + x)
    } else {
        0.0
    };
    (srgb_encode(t) * 255.0 + 0.5).clamp(0.0, 255.0) as u8
}
