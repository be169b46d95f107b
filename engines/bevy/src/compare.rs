//! The comparison of the two frames, where both draw the same fiber.
//!
//! Coverage differs by construction: strandlight draws each segment as a screen-aligned
//! ribbon `fiber_width_px` wide and weights the pixel's nearest fiber by its exact area
//! coverage (a 1-px fiber covers 0.2–1 of the pixels it crosses), Bevy draws a 1-pixel line
//! (Vulkan's line rasterization: a pixel is drawn or not). So only the shaded radiance is
//! compared (strandlight's EXR holds radiance × coverage: divided by alpha), at the pixels
//! ("one-fiber pixels") that
//! - strandlight covers at least [`MIN_COVERAGE`] (the fiber's centre passes within about half a
//!   pixel of the pixel's centre) and that Bevy draws (alpha 1);
//! - lie within [`REACH_PX`] of one piece of one strand's projected centreline (computed here
//!   from the groom and the exact camera): where two strands, or two parts of one strand folded
//!   back on screen, come that close, which is nearest in a pixel depends on how each renderer
//!   rasterizes, and the frames may show different fibers there, which says nothing about the
//!   shading.
//!
//! The tolerance applies to the "straight" one-fiber pixels: those whose nearest segment turns
//! its tangent by less than [`STRAIGHT_DEG_PER_PX`] per pixel and that are more than
//! [`REACH_PX`] from a strand's end. Elsewhere the two rasterizers sample a pixel at slightly
//! different places along the fiber (a line's fragment takes its attributes at the pixel
//! centre's projection on the line, possibly past the segment's end; the ribbon's at the
//! centre inside the ribbon), and where the interpolated tangent turns fast that alone moves
//! the shading by several percent (README.md, "Figures"); those pixels are reported, not gated.

use crate::scene::{Hair, Settings};
use anyhow::Context;
use bevy::math::{Mat4, Vec2, Vec3, Vec4};
use std::path::Path;

/// Least strandlight coverage (alpha) of a compared pixel.
pub const MIN_COVERAGE: f32 = 0.5;
/// How close (pixels) a second fiber, or a strand's end, must come to disqualify a pixel.
pub const REACH_PX: f32 = 1.5;
/// Fastest turn of the tangent along the fiber (degrees per pixel) of a "straight" pixel.
pub const STRAIGHT_DEG_PER_PX: f32 = 1.0;

pub struct Image {
    pub width: usize,
    pub height: usize,
    /// RGBA, top row first.
    pub rgba: Vec<[f32; 4]>,
}

pub fn read_exr(path: &Path) -> anyhow::Result<Image> {
    let image = exr::prelude::read_first_rgba_layer_from_file(
        path,
        |resolution, _| Image {
            width: resolution.width(),
            height: resolution.height(),
            rgba: vec![[0.0; 4]; resolution.width() * resolution.height()],
        },
        |img: &mut Image, pos: exr::math::Vec2<usize>, (r, g, b, a): (f32, f32, f32, f32)| {
            img.rgba[pos.y() * img.width + pos.x()] = [r, g, b, a];
        },
    )
    .with_context(|| path.display().to_string())?;
    Ok(image.layer_data.channel_data.pixels)
}

pub fn write_exr(path: &Path, image: &Image) -> anyhow::Result<()> {
    exr::prelude::write_rgba_file(path, image.width, image.height, |x, y| {
        let p = image.rgba[y * image.width + x];
        (p[0], p[1], p[2], p[3])
    })
    .with_context(|| path.display().to_string())
}

/// What the groom puts at a pixel (from its projection, not from either image).
#[derive(Clone, Copy, Debug, Default)]
pub struct PixelGeometry {
    /// Pieces of fiber within [`REACH_PX`]: each strand that comes that close counts once, or
    /// twice where it folds back on itself on screen (the segments within reach lie more than
    /// 2 apart along the strand).
    pub pieces: u8,
    /// Distance to the nearest centreline, pixels.
    pub distance: f32,
    /// How fast the nearest segment turns its tangent: the angle between its two end tangents
    /// over its length on screen, degrees per pixel.
    pub turn_deg_per_px: f32,
    /// A strand's root or tip lies within [`REACH_PX`].
    pub near_end: bool,
}

/// [`PixelGeometry`] of every pixel of the frame of `settings`.
pub fn pixel_geometry(hair: &Hair, settings: &Settings) -> Vec<PixelGeometry> {
    let [w, h] = settings.size;
    let c = settings.camera;
    let view = Mat4::look_at_rh(c.eye, c.target, c.up);
    let proj = Mat4::perspective_rh(c.fov_y_deg.to_radians(), w as f32 / h as f32, c.near, c.far);
    let view_proj = proj * view;
    let to_px = |p: Vec3| -> Option<Vec2> {
        let clip: Vec4 = view_proj * p.extend(1.0);
        (clip.w > 0.0).then(|| {
            let ndc = clip.truncate() / clip.w;
            Vec2::new(
                (0.5 + 0.5 * ndc.x) * w as f32,
                (0.5 - 0.5 * ndc.y) * h as f32,
            )
        })
    };
    let tangents = hair.tangents();
    let n = (w * h) as usize;
    let mut out = vec![
        PixelGeometry {
            distance: f32::INFINITY,
            ..Default::default()
        };
        n
    ];
    // Per pixel, the first and last segment of the current strand that came within reach.
    let mut span: Vec<Option<(usize, usize)>> = vec![None; n];
    for (s, strand) in hair.strands().enumerate() {
        let first_point = hair.offsets[s];
        let mut touched = Vec::new();
        let px: Vec<Option<Vec2>> = strand.iter().map(|p| to_px(*p)).collect();
        for (k, seg) in px.windows(2).enumerate() {
            let (Some(a), Some(b)) = (seg[0], seg[1]) else {
                continue;
            };
            let d = b - a;
            let (t0, t1) = (tangents[first_point + k], tangents[first_point + k + 1]);
            let turn = t0.dot(t1).clamp(-1.0, 1.0).acos().to_degrees() / d.length().max(1e-3);
            let lo = a.min(b) - Vec2::splat(REACH_PX + 1.0);
            let hi = a.max(b) + Vec2::splat(REACH_PX + 1.0);
            let (x0, y0) = (lo.x.floor().max(0.0) as u32, lo.y.floor().max(0.0) as u32);
            let (x1, y1) = (
                hi.x.ceil().min(w as f32 - 1.0),
                hi.y.ceil().min(h as f32 - 1.0),
            );
            if x1 < 0.0 || y1 < 0.0 {
                continue;
            }
            let ends = [(k == 0).then_some(a), (k + 2 == strand.len()).then_some(b)];
            for y in y0..=y1 as u32 {
                for x in x0..=x1 as u32 {
                    let p = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                    let t = if d.length_squared() > 0.0 {
                        ((p - a).dot(d) / d.length_squared()).clamp(0.0, 1.0)
                    } else {
                        0.0
                    };
                    let distance = (a + t * d - p).length();
                    if distance > REACH_PX {
                        continue;
                    }
                    let i = (y * w + x) as usize;
                    let g = &mut out[i];
                    if distance < g.distance {
                        g.distance = distance;
                        g.turn_deg_per_px = turn;
                    }
                    g.near_end |= ends.iter().flatten().any(|e| (*e - p).length() <= REACH_PX);
                    span[i] = Some(match span[i] {
                        None => {
                            touched.push(i);
                            (k, k)
                        }
                        Some((first, _)) => (first, k),
                    });
                }
            }
        }
        for i in touched {
            let (first, last) = span[i].take().unwrap();
            let pieces = if last - first > 2 { 2 } else { 1 };
            out[i].pieces = out[i].pieces.saturating_add(pieces);
        }
    }
    out
}

/// Errors over one set of pixels. The per-pixel error is max_c |b − s| / max_c s: relative
/// to the pixel's brightest channel.
#[derive(Clone, Copy, Debug)]
pub struct Errors {
    pub pixels: usize,
    /// sqrt(Σ|b − s|²) / sqrt(Σ|s|²) over the pixels' RGB.
    pub relative_rmse: f64,
    pub p50: f64,
    pub p99: f64,
    pub max: f64,
    /// Where the largest per-pixel error is (x, y).
    pub worst_at: (usize, usize),
    /// Σb / Σs (a brightness or exposure slip shows here).
    pub mean_ratio: f64,
}

fn radiance(p: [f32; 4]) -> [f64; 3] {
    let a = p[3] as f64;
    [p[0] as f64 / a, p[1] as f64 / a, p[2] as f64 / a]
}

fn errors(strandlight: &Image, bevy: &Image, pixels: &[usize]) -> Errors {
    let (mut num, mut den, mut sum_b, mut sum_s) = (0.0, 0.0, 0.0, 0.0);
    let mut per_pixel: Vec<(f64, usize)> = Vec::with_capacity(pixels.len());
    for &i in pixels {
        let (s, b) = (radiance(strandlight.rgba[i]), radiance(bevy.rgba[i]));
        let mut largest_error = 0.0f64;
        for c in 0..3 {
            let e = b[c] - s[c];
            num += e * e;
            den += s[c] * s[c];
            sum_b += b[c];
            sum_s += s[c];
            largest_error = largest_error.max(e.abs());
        }
        per_pixel.push((largest_error / s[0].max(s[1]).max(s[2]).max(1e-30), i));
    }
    per_pixel.sort_by(|a, b| a.0.total_cmp(&b.0));
    let quantile = |q: f64| {
        per_pixel
            .get(((per_pixel.len() as f64 * q) as usize).min(per_pixel.len().saturating_sub(1)))
            .map_or(f64::NAN, |p| p.0)
    };
    let worst = per_pixel.last().map_or(0, |p| p.1);
    Errors {
        pixels: pixels.len(),
        relative_rmse: (num / den).sqrt(),
        p50: quantile(0.5),
        p99: quantile(0.99),
        max: per_pixel.last().map_or(f64::NAN, |p| p.0),
        worst_at: (worst % strandlight.width, worst / strandlight.width),
        mean_ratio: sum_b / sum_s,
    }
}

pub struct Figures {
    pub strandlight_hair_pixels: usize,
    pub bevy_hair_pixels: usize,
    /// Every one-fiber pixel.
    pub one_fiber: Errors,
    /// The straight one-fiber pixels away from strand ends: what the tolerance applies to.
    pub straight: Errors,
}

/// Compares the shaded radiance at the one-fiber pixels (module documentation); returns the
/// figures and the mask of one-fiber pixels.
pub fn compare(
    strandlight: &Image,
    bevy: &Image,
    geometry: &[PixelGeometry],
) -> (Figures, Vec<bool>) {
    let n = strandlight.rgba.len();
    let mask: Vec<bool> = (0..n)
        .map(|i| {
            strandlight.rgba[i][3] >= MIN_COVERAGE
                && bevy.rgba[i][3] > 0.5
                && geometry[i].pieces == 1
        })
        .collect();
    let one_fiber: Vec<usize> = (0..n).filter(|&i| mask[i]).collect();
    let straight: Vec<usize> = one_fiber
        .iter()
        .copied()
        .filter(|&i| geometry[i].turn_deg_per_px < STRAIGHT_DEG_PER_PX && !geometry[i].near_end)
        .collect();
    if let Some(path) = std::env::var_os("STRANDLIGHT_BEVY_DUMP") {
        // x y alpha s_rgb b_rgb turn near_end: for studying where the frames differ.
        let text: String = one_fiber
            .iter()
            .map(|&i| {
                let (s, b, g) = (
                    radiance(strandlight.rgba[i]),
                    radiance(bevy.rgba[i]),
                    geometry[i],
                );
                format!(
                    "{} {} {} {} {} {} {} {} {} {} {}\n",
                    i % strandlight.width,
                    i / strandlight.width,
                    strandlight.rgba[i][3],
                    s[0],
                    s[1],
                    s[2],
                    b[0],
                    b[1],
                    b[2],
                    g.turn_deg_per_px,
                    g.near_end as u8
                )
            })
            .collect();
        let _ = std::fs::write(path, text);
    }
    let figures = Figures {
        strandlight_hair_pixels: strandlight.rgba.iter().filter(|p| p[3] > 0.0).count(),
        bevy_hair_pixels: bevy.rgba.iter().filter(|p| p[3] > 0.5).count(),
        one_fiber: errors(strandlight, bevy, &one_fiber),
        straight: errors(strandlight, bevy, &straight),
    };
    (figures, mask)
}

fn srgb(x: f64) -> u8 {
    let x = x.clamp(0.0, 1.0);
    let y = if x <= 0.0031308 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    };
    (y * 255.0 + 0.5) as u8
}

/// strandlight | Bevy | |difference| × 10 on the compared pixels (others dimmed grey where
/// either draws hair), one exposure for all three (the 99th percentile of strandlight's hair
/// radiance at 0.8), sRGB.
pub fn write_side_by_side(
    path: &Path,
    strandlight: &Image,
    bevy: &Image,
    mask: &[bool],
) -> anyhow::Result<()> {
    let (w, h) = (strandlight.width, strandlight.height);
    let mut lum: Vec<f64> = strandlight
        .rgba
        .iter()
        .filter(|p| p[3] > 0.0)
        .map(|p| p[0].max(p[1]).max(p[2]) as f64)
        .collect();
    lum.sort_by(f64::total_cmp);
    let top = lum
        .get(lum.len() * 99 / 100)
        .copied()
        .unwrap_or(1.0)
        .max(1e-12);
    let scale = 0.8 / top;
    let gap = 4;
    let out_w = 3 * w + 2 * gap;
    let mut rgb = vec![255u8; out_w * h * 3];
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            let s = strandlight.rgba[i];
            let b = bevy.rgba[i];
            let panels = [
                [s[0], s[1], s[2]].map(|v| srgb(v as f64 * scale)),
                [b[0], b[1], b[2]].map(|v| srgb(v as f64 * scale * b[3].min(1.0) as f64)),
                if mask[i] {
                    let a = s[3].max(1e-6) as f64;
                    [0, 1, 2].map(|c| srgb(10.0 * scale * (b[c] as f64 - s[c] as f64 / a).abs()))
                } else if s[3] > 0.0 || b[3] > 0.5 {
                    [40, 40, 40]
                } else {
                    [0, 0, 0]
                },
            ];
            for (k, p) in panels.iter().enumerate() {
                let o = (y * out_w + k * (w + gap) + x) * 3;
                rgb[o..o + 3].copy_from_slice(p);
            }
        }
    }
    let file = std::fs::File::create(path).with_context(|| path.display().to_string())?;
    let mut encoder = png::Encoder::new(std::io::BufWriter::new(file), out_w as u32, h as u32);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.write_header()?.write_image_data(&rgb)?;
    Ok(())
}
