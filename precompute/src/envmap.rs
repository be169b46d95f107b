//! The in-memory environment map and THE direction convention of strandlight.
//!
//! # Convention (the runtime renders with exactly this; do not restate it elsewhere)
//!
//! World space is right-handed with **+Y up**. An environment map is equirectangular
//! (latitude–longitude), `width = 2 · height`, stored row-major from the **top row** (y = 0,
//! looking straight up) to the bottom row (looking straight down), each row from left (x = 0)
//! to right. For the pixel-continuous coordinates `u = x / width ∈ [0, 1)` and
//! `v = y / height ∈ [0, 1]` (pixel centers at `x + ½`, `y + ½`):
//!
//! * polar angle from +Y: `θ = π v` (θ = 0 is up, θ = π is down);
//! * azimuth: `φ = 2π (u − ½)`, so the **image center column looks toward −Z**;
//! * direction `ω = (sin θ sin φ, cos θ, −sin θ cos φ)`.
//!
//! So u = ½ is −Z, u = ¾ is +X, u = 0 (the left/right seam) is +Z and u = ¼ is −X: a person
//! standing at the origin facing −Z sees the image as printed, the right half to their right.
//!
//! Everything precompute makes of a map (fits, reference and median-cut light sets) stays in
//! this frame. Where the map sits in a hair's world (the hair's up axis, and `--rotate`) is
//! written once, in `strandlight_scene::env_orientation`.

use glam::DVec3;
use std::f64::consts::PI;

/// Linear RGB radiance, scene-referred.
pub type Rgb32 = [f32; 3];

/// An equirectangular environment map in the convention above.
#[derive(Debug, Clone, PartialEq)]
pub struct EnvMap {
    width: usize,
    height: usize,
    pixels: Vec<Rgb32>,
}

/// Non-finite or negative pixel values found in a map.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct BadPixelCounts {
    pub nan: usize,
    pub positive_infinity: usize,
    pub negative_infinity: usize,
    pub negative: usize,
}

impl BadPixelCounts {
    pub fn total(&self) -> usize {
        self.nan + self.positive_infinity + self.negative_infinity + self.negative
    }
}

impl std::fmt::Display for BadPixelCounts {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} NaN, {} +Inf, {} -Inf, {} negative channel values",
            self.nan, self.positive_infinity, self.negative_infinity, self.negative
        )
    }
}

impl EnvMap {
    /// A map from row-major pixels (top row first). The caller guarantees the size matches;
    /// the 2:1 aspect is checked by the loaders, which know the file name to report.
    pub fn from_pixels(width: usize, height: usize, pixels: Vec<Rgb32>) -> Self {
        assert_eq!(
            pixels.len(),
            width * height,
            "pixel count must equal width × height"
        );
        Self {
            width,
            height,
            pixels,
        }
    }

    /// A map whose radiance is `f(ω)` at every pixel center.
    pub fn from_fn(width: usize, height: usize, f: impl Fn(DVec3) -> [f64; 3] + Sync) -> Self {
        use rayon::prelude::*;
        let pixels = (0..width * height)
            .into_par_iter()
            .map(|i| {
                let c = f(pixel_direction(i % width, i / width, width, height));
                c.map(|v| v as f32)
            })
            .collect();
        Self {
            width,
            height,
            pixels,
        }
    }

    pub fn width(&self) -> usize {
        self.width
    }
    pub fn height(&self) -> usize {
        self.height
    }
    pub fn pixels(&self) -> &[Rgb32] {
        &self.pixels
    }
    pub fn pixel(&self, x: usize, y: usize) -> Rgb32 {
        self.pixels[y * self.width + x]
    }

    /// Direction of the center of pixel (x, y).
    pub fn direction(&self, x: usize, y: usize) -> DVec3 {
        pixel_direction(x, y, self.width, self.height)
    }

    /// Solid angle of one pixel of row y (all pixels of a row are equal): the exact area
    /// `Δφ (cos θ_top − cos θ_bottom)`, so the weights of a map sum to 4π.
    pub fn row_solid_angle(&self, y: usize) -> f64 {
        row_solid_angle(y, self.width, self.height)
    }

    /// Nearest-pixel radiance seen in direction `w` (unit).
    pub fn radiance(&self, w: DVec3) -> Rgb32 {
        let (u, v) = direction_to_uv(w);
        let x = ((u * self.width as f64) as usize).min(self.width - 1);
        let y = ((v * self.height as f64) as usize).min(self.height - 1);
        self.pixel(x, y)
    }

    /// Radiance in direction `w` (unit) interpolated between the four nearest pixel centres:
    /// wrapping around in longitude, clamped at the poles. For a small (prefiltered) map drawn
    /// large, where the nearest pixel would show its blocks.
    pub fn radiance_bilinear(&self, w: DVec3) -> Rgb32 {
        let (u, v) = direction_to_uv(w);
        let fx = u * self.width as f64 - 0.5;
        let fy = (v * self.height as f64 - 0.5).clamp(0.0, (self.height - 1) as f64);
        let (x0, y0) = (fx.floor(), fy.floor());
        let (tx, ty) = ((fx - x0) as f32, (fy - y0) as f32);
        let column = |x: f64| (x as i64).rem_euclid(self.width as i64) as usize;
        let (xa, xb) = (column(x0), column(x0 + 1.0));
        let (ya, yb) = (y0 as usize, (y0 as usize + 1).min(self.height - 1));
        let mix = |a: Rgb32, b: Rgb32, t: f32| [0, 1, 2].map(|k| a[k] + t * (b[k] - a[k]));
        let top = mix(self.pixel(xa, ya), self.pixel(xb, ya), tx);
        let bottom = mix(self.pixel(xa, yb), self.pixel(xb, yb), tx);
        mix(top, bottom, ty)
    }

    /// Counts NaN, ±Inf and negative channel values.
    pub fn bad_pixels(&self) -> BadPixelCounts {
        let mut c = BadPixelCounts::default();
        for v in self.pixels.iter().flatten() {
            if v.is_nan() {
                c.nan += 1;
            } else if *v == f32::INFINITY {
                c.positive_infinity += 1;
            } else if *v == f32::NEG_INFINITY {
                c.negative_infinity += 1;
            } else if *v < 0.0 {
                c.negative += 1;
            }
        }
        c
    }

    /// Replaces bad values: negative and −Inf → 0, NaN → 0, +Inf → the largest finite value
    /// in the map (0 if there is none). Returns what was replaced.
    pub fn sanitize(&mut self) -> BadPixelCounts {
        let counts = self.bad_pixels();
        let largest = self
            .pixels
            .iter()
            .flatten()
            .filter(|v| v.is_finite())
            .fold(0.0f32, |m, &v| m.max(v));
        for v in self.pixels.iter_mut().flatten() {
            *v = if v.is_nan() || *v < 0.0 {
                0.0
            } else if v.is_infinite() {
                largest
            } else {
                *v
            };
        }
        counts
    }

    /// ∫ L dω per channel (f64 sums; the pixel solid angles are exact).
    pub fn integral(&self) -> [f64; 3] {
        let mut s = [0.0; 3];
        for y in 0..self.height {
            let w = self.row_solid_angle(y);
            for p in &self.pixels[y * self.width..(y + 1) * self.width] {
                for c in 0..3 {
                    s[c] += w * p[c] as f64;
                }
            }
        }
        s
    }

    /// An area-weighted (box) prefiltered copy at `width × height`: each target pixel is the
    /// solid-angle-weighted mean of the source area it covers, so ∫ L dω is preserved and a small
    /// bright source (a sun) is spread, never skipped. Sizes larger than the source are clamped
    /// to the source (no upsampling).
    pub fn downsampled(&self, width: usize, height: usize) -> EnvMap {
        let (width, height) = (width.min(self.width).max(1), height.min(self.height).max(1));
        if width == self.width && height == self.height {
            return self.clone();
        }
        let cols = overlap_weights(self.width, width, |a, b| b - a);
        // Rows are weighted by their solid angle: the measure of [v0, v1] is cos πv0 − cos πv1.
        let rows = overlap_weights(self.height, height, |a, b| (PI * a).cos() - (PI * b).cos());
        use rayon::prelude::*;
        let pixels = (0..width * height)
            .into_par_iter()
            .map(|i| {
                let (tx, ty) = (i % width, i / width);
                let mut sum = [0.0f64; 3];
                let mut wsum = 0.0;
                for &(sy, wy) in &rows[ty] {
                    for &(sx, wx) in &cols[tx] {
                        let w = wx * wy;
                        let p = self.pixel(sx, sy);
                        for c in 0..3 {
                            sum[c] += w * p[c] as f64;
                        }
                        wsum += w;
                    }
                }
                sum.map(|s| (s / wsum) as f32)
            })
            .collect();
        EnvMap {
            width,
            height,
            pixels,
        }
    }
}

/// For each of `dst` target cells over [0, 1], the source cells it overlaps and the measure
/// `measure(a, b)` of each overlap (a, b in the unit interval).
fn overlap_weights(
    src: usize,
    dst: usize,
    measure: impl Fn(f64, f64) -> f64,
) -> Vec<Vec<(usize, f64)>> {
    (0..dst)
        .map(|t| {
            let (t0, t1) = (t as f64 / dst as f64, (t + 1) as f64 / dst as f64);
            let first = ((t0 * src as f64).floor() as usize).min(src - 1);
            let last = (((t1 * src as f64).ceil() as usize).max(first + 1)).min(src);
            (first..last)
                .filter_map(|s| {
                    let a = (s as f64 / src as f64).max(t0);
                    let b = ((s + 1) as f64 / src as f64).min(t1);
                    let m = measure(a, b);
                    (b > a && m > 0.0).then_some((s, m))
                })
                .collect()
        })
        .collect()
}

/// Direction of the center of pixel (x, y) in a `width × height` map.
pub fn pixel_direction(x: usize, y: usize, width: usize, height: usize) -> DVec3 {
    uv_to_direction(
        (x as f64 + 0.5) / width as f64,
        (y as f64 + 0.5) / height as f64,
    )
}

/// `(u, v) ∈ [0,1]²` to the unit direction (see the module documentation).
pub fn uv_to_direction(u: f64, v: f64) -> DVec3 {
    let theta = PI * v;
    let phi = 2.0 * PI * (u - 0.5);
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = phi.sin_cos();
    DVec3::new(st * sp, ct, -st * cp)
}

/// The inverse of [`uv_to_direction`]: `u ∈ [0, 1)`, `v ∈ [0, 1]`.
pub fn direction_to_uv(w: DVec3) -> (f64, f64) {
    let theta = w.y.clamp(-1.0, 1.0).acos();
    let phi = w.x.atan2(-w.z);
    let u = (phi / (2.0 * PI) + 0.5).rem_euclid(1.0);
    (u, theta / PI)
}

/// Solid angle of a pixel in row y of a `width × height` map.
pub fn row_solid_angle(y: usize, width: usize, height: usize) -> f64 {
    let t0 = PI * y as f64 / height as f64;
    let t1 = PI * (y + 1) as f64 / height as f64;
    // cos t0 − cos t1 = 2 sin((t0+t1)/2) sin((t1−t0)/2): no cancellation near the poles.
    2.0 * PI / width as f64 * 2.0 * (0.5 * (t0 + t1)).sin() * (0.5 * (t1 - t0)).sin()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn named_directions_land_where_documented() {
        let close = |a: DVec3, b: DVec3| (a - b).length() < 1e-12;
        assert!(close(uv_to_direction(0.5, 0.5), DVec3::NEG_Z));
        assert!(close(uv_to_direction(0.75, 0.5), DVec3::X));
        assert!(close(uv_to_direction(0.25, 0.5), DVec3::NEG_X));
        assert!(close(uv_to_direction(0.0, 0.5), DVec3::Z));
        assert!(close(uv_to_direction(0.3, 0.0), DVec3::Y));
        assert!(close(uv_to_direction(0.3, 1.0), DVec3::NEG_Y));
    }

    #[test]
    fn bilinear_radiance_hits_pixel_centres_and_blends_between_them_across_the_seam() {
        // Pixel value = column index, so the interpolant in x is linear in u.
        let (w, h) = (8usize, 4usize);
        let map = EnvMap::from_pixels(
            w,
            h,
            (0..w * h)
                .map(|i| [(i % w) as f32, (i / w) as f32, 1.0])
                .collect(),
        );
        let at = |u: f64, v: f64| map.radiance_bilinear(uv_to_direction(u, v));
        let centre =
            |x: usize, y: usize| ((x as f64 + 0.5) / w as f64, (y as f64 + 0.5) / h as f64);
        for (x, y) in [(0, 0), (3, 1), (7, 3)] {
            let (u, v) = centre(x, y);
            let got = at(u, v);
            assert!(
                (got[0] - x as f32).abs() < 1e-4 && (got[1] - y as f32).abs() < 1e-4,
                "{x},{y}: {got:?}"
            );
        }
        // Half way between columns 2 and 3, and between rows 1 and 2.
        let got = at(3.0 / w as f64, 2.0 / h as f64);
        assert!(
            (got[0] - 2.5).abs() < 1e-4 && (got[1] - 1.5).abs() < 1e-4,
            "{got:?}"
        );
        // Across the seam: half way between the last column (7) and the first (0).
        let got = at(1e-9, 0.5);
        assert!((got[0] - 3.5).abs() < 1e-3, "{got:?}");
        // Above the first row's centre the poles clamp to it.
        assert!((at(0.3, 0.0)[1] - 0.0).abs() < 1e-6);
        assert!((at(0.3, 1.0)[1] - 3.0).abs() < 1e-6);
    }

    #[test]
    fn uv_round_trips() {
        for &(u, v) in &[(0.1, 0.2), (0.6, 0.9), (0.999, 0.5), (0.25, 0.01)] {
            let (u2, v2) = direction_to_uv(uv_to_direction(u, v));
            assert!(
                (u - u2).abs() < 1e-12 && (v - v2).abs() < 1e-12,
                "{u},{v} → {u2},{v2}"
            );
        }
    }

    #[test]
    fn pixel_solid_angles_sum_to_four_pi() {
        let (w, h) = (64, 32);
        let total: f64 = (0..h).map(|y| w as f64 * row_solid_angle(y, w, h)).sum();
        eprintln!("Σ pixel solid angles = {total} (4π = {})", 4.0 * PI);
        assert!((total - 4.0 * PI).abs() < 1e-12);
    }

    #[test]
    fn downsampling_preserves_the_integral_of_a_one_pixel_sun() {
        let mut px = vec![[0.1f32; 3]; 256 * 128];
        px[37 * 256 + 201] = [5e4, 4e4, 3e4];
        let map = EnvMap::from_pixels(256, 128, px);
        let small = map.downsampled(48, 24); // not an integer factor on purpose
        let (a, b) = (map.integral(), small.integral());
        eprintln!("integral full {a:?} vs 48×24 {b:?}");
        for c in 0..3 {
            assert!((a[c] - b[c]).abs() < 1e-5 * a[c], "channel {c}");
        }
    }
}
