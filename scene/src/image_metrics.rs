//! Comparing a rendering with the reference (Ren 2010 §8): relative RMSE in linear radiance over
//! the pixels the reference's hair covers, a false-colour error picture, and the side-by-side
//! PNG `compare` writes (SRBF | reference | baseline | error).

use std::path::Path;
use strandlight_tables::image_out::{
    ImageWriteError, PNG_TONEMAP, tonemap_channel, write_png_rgb8,
};
use thiserror::Error;

/// A linear RGBA float image, row-major from the top row (as the renderer returns it).
#[derive(Debug, Clone, PartialEq)]
pub struct Image {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<[f32; 4]>,
}

/// Pixels whose reference alpha (coverage) exceeds this count as hair.
pub const HAIR_ALPHA: f32 = 1e-3;

/// What the error panel shows, per pixel: max over RGB of |a − r| divided by the largest
/// reference value over the hair (one scale for the whole picture), through [`COLORMAP`] from 0
/// to this value (clamped above).
pub const ERROR_SCALE: f64 = 0.1;
pub const COLORMAP: &str = "viridis (matplotlib, 9-point piecewise-linear)";

/// Matplotlib's viridis at t = 0, 1/8, …, 1 (sRGB bytes).
const VIRIDIS: [[u8; 3]; 9] = [
    [68, 1, 84],
    [71, 44, 122],
    [59, 81, 139],
    [44, 113, 142],
    [33, 144, 141],
    [39, 173, 129],
    [92, 200, 99],
    [170, 220, 50],
    [253, 231, 37],
];

/// Height in pixels of the legend strip under the side-by-side picture.
const LEGEND_ROWS: u32 = 12;

#[derive(Debug, Error)]
pub enum CompareError {
    #[error("{what} is {w}x{h} but the reference is {rw}x{rh}")]
    SizeMismatch {
        what: String,
        w: u32,
        h: u32,
        rw: u32,
        rh: u32,
    },
    #[error("{what}: {count} pixel value(s) are NaN or infinite (first at pixel {first})")]
    NotFinite {
        what: String,
        count: usize,
        first: usize,
    },
    #[error("the reference covers no hair pixels (alpha > {HAIR_ALPHA}): nothing to compare")]
    NoHair,
    #[error("the reference is black over the hair (Σ|r|² = 0): relative error undefined")]
    BlackReference,
    #[error(
        "half the reference's hair pixels or more are black: HDR-FLIP's exposure range (up to the median luminance) is undefined"
    )]
    DarkMedian,
    #[error(transparent)]
    Write(#[from] ImageWriteError),
}

impl Image {
    /// `self − other` in RGB, `self`'s alpha kept (one part of an additive image: full minus
    /// single scattering). Sizes must match.
    pub fn minus(&self, other: &Image) -> Result<Image, CompareError> {
        other.check_against("the subtracted image", self)?;
        let pixels = self
            .pixels
            .iter()
            .zip(&other.pixels)
            .map(|(a, b)| [a[0] - b[0], a[1] - b[1], a[2] - b[2], a[3]])
            .collect();
        Ok(Image::new(self.width, self.height, pixels))
    }

    pub fn new(width: u32, height: u32, pixels: Vec<[f32; 4]>) -> Self {
        assert_eq!(
            pixels.len(),
            width as usize * height as usize,
            "pixel count must equal width × height"
        );
        Self {
            width,
            height,
            pixels,
        }
    }

    fn check_against(&self, what: &str, reference: &Image) -> Result<(), CompareError> {
        if (self.width, self.height) != (reference.width, reference.height) {
            return Err(CompareError::SizeMismatch {
                what: what.into(),
                w: self.width,
                h: self.height,
                rw: reference.width,
                rh: reference.height,
            });
        }
        check_finite(what, self)
    }
}

fn check_finite(what: &str, image: &Image) -> Result<(), CompareError> {
    let mut bad = image
        .pixels
        .iter()
        .enumerate()
        .filter(|(_, p)| p.iter().any(|c| !c.is_finite()));
    if let Some((first, _)) = bad.next() {
        return Err(CompareError::NotFinite {
            what: what.into(),
            count: 1 + bad.count(),
            first,
        });
    }
    Ok(())
}

fn is_hair(p: &[f32; 4]) -> bool {
    p[3] > HAIR_ALPHA
}

/// √(Σ‖a − r‖² / Σ‖r‖²) over RGB of the pixels where the reference has hair.
pub fn relative_rmse(approx: &Image, reference: &Image) -> Result<f64, CompareError> {
    relative_rmse_of_part(approx, reference, reference)
}

/// The error of one additive part of an image relative to the whole:
/// √(Σ‖a − r‖² / Σ‖w‖²) over RGB of the pixels where `whole` has hair, `a` approximating the
/// part `r` of the reference `whole` (the multiple-scattering part of a full image: full
/// minus single scattering). The parts' errors add as vectors to the whole's. One pixel a block
/// of [`relative_rmse_of_part_over_blocks`].
pub fn relative_rmse_of_part(
    approx_part: &Image,
    reference_part: &Image,
    whole: &Image,
) -> Result<f64, CompareError> {
    relative_rmse_of_part_over_blocks(approx_part, reference_part, whole, 1)
}

/// Σa / Σr over RGB of the reference's hair pixels: how much brighter the image is on average.
/// Beside the relative RMSE it tells a bias (a ratio far from 1) from a pattern that moves
/// light between pixels while keeping the mean (a ratio near 1 with a large RMSE).
pub fn mean_ratio(approx: &Image, reference: &Image) -> Result<f64, CompareError> {
    check_finite("the reference", reference)?;
    approx.check_against("the image", reference)?;
    let (mut sum_a, mut sum_r, mut hair) = (0.0f64, 0.0f64, 0usize);
    for (a, r) in approx.pixels.iter().zip(&reference.pixels) {
        if is_hair(r) {
            hair += 1;
            sum_a += (0..3).map(|c| a[c] as f64).sum::<f64>();
            sum_r += (0..3).map(|c| r[c] as f64).sum::<f64>();
        }
    }
    if hair == 0 {
        return Err(CompareError::NoHair);
    }
    if sum_r == 0.0 {
        return Err(CompareError::BlackReference);
    }
    Ok(sum_a / sum_r)
}

/// The block sizes an image's error is reported at: the pixel, and boxes of 2, 4 and 16 pixels
/// a side. A path tracer's noise averages away over a box, a bias does not; a pattern at fiber
/// scale (which fibers a pixel's centre sees) fades by 4×4.
pub const ERROR_SCALES: [u32; 4] = [1, 2, 4, 16];

/// An image's error against a reference at every scale of [`ERROR_SCALES`], beside the error of
/// its coverage and its mean ratio: what `image-error`, `compare` and `bench` report.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ScaleErrors {
    /// [`relative_rmse_over_blocks`] at each of [`ERROR_SCALES`] (the first is
    /// [`relative_rmse`]).
    pub blocks: [f64; 4],
    /// [`coverage_error`].
    pub coverage: f64,
    /// [`mean_ratio`].
    pub mean_ratio: f64,
}

impl ScaleErrors {
    pub fn of(approx: &Image, reference: &Image) -> Result<Self, CompareError> {
        let mut blocks = [0.0; 4];
        for (e, n) in blocks.iter_mut().zip(ERROR_SCALES) {
            *e = relative_rmse_over_blocks(approx, reference, n)?;
        }
        Ok(Self {
            blocks,
            coverage: coverage_error(approx, reference)?,
            mean_ratio: mean_ratio(approx, reference)?,
        })
    }

    /// One line: the error at each scale, the coverage error and the mean ratio.
    pub fn line(&self) -> String {
        let scales: Vec<String> = ERROR_SCALES
            .iter()
            .zip(self.blocks)
            .map(|(n, e)| format!("{n}×{n} {e:.4}"))
            .collect();
        format!(
            "relative RMSE over blocks {}; coverage {:.4}; mean {:.4}×",
            scales.join(", "),
            self.coverage,
            self.mean_ratio
        )
    }
}

/// The relative RMSE of both images box-filtered over `n`×`n` blocks (the last row and column
/// of blocks hold what is left of the image): √(Σ count·‖ā − r̄‖² / Σ count·‖r̄‖²) over RGB of
/// the blocks that hold any of the reference's hair, ā and r̄ the blocks' mean pre-multiplied
/// colours. At n = 1 it is [`relative_rmse`].
pub fn relative_rmse_over_blocks(
    approx: &Image,
    reference: &Image,
    n: u32,
) -> Result<f64, CompareError> {
    relative_rmse_of_part_over_blocks(approx, reference, reference, n)
}

/// [`relative_rmse_of_part`] over `n`×`n` blocks: the part's block means against the
/// reference part's, over the norm of the `whole` reference's block means, on the blocks that
/// hold any of the whole's hair. The parts' block errors add as vectors to the whole's, as
/// the pixels' do.
pub fn relative_rmse_of_part_over_blocks(
    approx_part: &Image,
    reference_part: &Image,
    whole: &Image,
    n: u32,
) -> Result<f64, CompareError> {
    check_finite("the reference", whole)?;
    check_finite("the reference's part", reference_part)?;
    reference_part.check_against("the reference's part", whole)?;
    approx_part.check_against("the image", whole)?;
    let n = n.max(1);
    let (w, h) = (whole.width, whole.height);
    let (mut num, mut den, mut hair) = (0.0f64, 0.0f64, 0usize);
    for by in (0..h).step_by(n as usize) {
        for bx in (0..w).step_by(n as usize) {
            let mut sums = [[0.0f64; 3]; 3];
            let (mut count, mut has_hair) = (0.0, false);
            for y in by..(by + n).min(h) {
                for x in bx..(bx + n).min(w) {
                    let i = (y * w + x) as usize;
                    has_hair |= is_hair(&whole.pixels[i]);
                    let pixels = [approx_part, reference_part, whole].map(|im| im.pixels[i]);
                    for (sum, p) in sums.iter_mut().zip(pixels) {
                        for c in 0..3 {
                            sum[c] += p[c] as f64;
                        }
                    }
                    count += 1.0;
                }
            }
            if !has_hair {
                continue;
            }
            hair += 1;
            let [a, r, whole] = sums;
            for c in 0..3 {
                let (a, r, whole) = (a[c] / count, r[c] / count, whole[c] / count);
                num += count * (a - r) * (a - r);
                den += count * whole * whole;
            }
        }
    }
    if hair == 0 {
        return Err(CompareError::NoHair);
    }
    if den == 0.0 {
        return Err(CompareError::BlackReference);
    }
    Ok((num / den).sqrt())
}

/// The error of the image's coverage: √(Σ(α_a − α_r)² / Σα_r²) over the pixels where either
/// image has hair. Coverage is the same under every light, so this is the view's error alone
/// (each fiber's polyline and its box-filtered coverage, against the true curve's footprint).
pub fn coverage_error(approx: &Image, reference: &Image) -> Result<f64, CompareError> {
    check_finite("the reference", reference)?;
    approx.check_against("the image", reference)?;
    let (mut num, mut den) = (0.0f64, 0.0f64);
    for (a, r) in approx.pixels.iter().zip(&reference.pixels) {
        if is_hair(a) || is_hair(r) {
            let (a, r) = (a[3] as f64, r[3] as f64);
            num += (a - r) * (a - r);
            den += r * r;
        }
    }
    if den == 0.0 {
        return Err(CompareError::NoHair);
    }
    Ok((num / den).sqrt())
}

/// How an image's error over the hair splits between a brightness bias and a pattern, and
/// where the bias sits: a bias is a modelling error a correction can target, a pattern is
/// per-pixel scatter (shadow detail placed differently, noise).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ErrorSplit {
    /// The one factor s that brings the image closest to the reference: the s minimizing
    /// Σ‖s·a − r‖², s = Σ a·r / Σ a·a over RGB of the hair pixels.
    pub best_scale: f64,
    /// The relative RMSE of s·a: the error no brightness correction removes.
    pub relative_rmse_after_scale: f64,
    /// Σa / Σr over the brightest tenth of the reference's hair pixels (by their RGB sum; at
    /// least one pixel): the lit fibers, which weigh most in a relative RMSE.
    pub brightest_tenth_ratio: f64,
    /// That tenth's share of Σ‖a − r‖² (0 when the images agree).
    pub brightest_tenth_share: f64,
}

/// The [`ErrorSplit`] of `approx` against `reference` over the reference's hair pixels.
pub fn error_split(approx: &Image, reference: &Image) -> Result<ErrorSplit, CompareError> {
    check_finite("the reference", reference)?;
    approx.check_against("the image", reference)?;
    let mut hair: Vec<(&[f32; 4], &[f32; 4])> = approx
        .pixels
        .iter()
        .zip(&reference.pixels)
        .filter(|(_, r)| is_hair(r))
        .collect();
    if hair.is_empty() {
        return Err(CompareError::NoHair);
    }
    let rgb_sum = |p: &[f32; 4]| (0..3).map(|c| p[c] as f64).sum::<f64>();
    let (mut ar, mut aa, mut rr) = (0.0f64, 0.0f64, 0.0f64);
    for (a, r) in &hair {
        for c in 0..3 {
            let (a, r) = (a[c] as f64, r[c] as f64);
            ar += a * r;
            aa += a * a;
            rr += r * r;
        }
    }
    if rr == 0.0 {
        return Err(CompareError::BlackReference);
    }
    // A black image has no brightness to correct: its best scale is taken as 1.
    let s = if aa > 0.0 { ar / aa } else { 1.0 };
    // Σ‖s·a − r‖² = s²·Σa² − 2s·Σa·r + Σr² (s = 1: the error itself), never below 0 but for
    // rounding.
    let squared_error_at = |s: f64| (s * s * aa - 2.0 * s * ar + rr).max(0.0);
    let after = (squared_error_at(s) / rr).sqrt();
    let total_error = squared_error_at(1.0);
    hair.sort_by(|x, y| rgb_sum(y.1).total_cmp(&rgb_sum(x.1)));
    let tenth = &hair[..hair.len().div_ceil(10)];
    let tenth_sums = tenth
        .iter()
        .fold((0.0, 0.0), |(a, r), p| (a + rgb_sum(p.0), r + rgb_sum(p.1)));
    let tenth_error: f64 = tenth
        .iter()
        .flat_map(|(a, r)| (0..3).map(move |c| (a[c] as f64 - r[c] as f64).powi(2)))
        .sum();
    Ok(ErrorSplit {
        best_scale: s,
        relative_rmse_after_scale: after,
        brightest_tenth_ratio: match tenth_sums.1 {
            0.0 => 1.0,
            r => tenth_sums.0 / r,
        },
        brightest_tenth_share: match total_error {
            0.0 => 0.0,
            e => tenth_error / e,
        },
    })
}

/// [`VIRIDIS`] at t ∈ [0, 1] (clamped), linearly interpolated between its samples.
pub fn colormap(t: f64) -> [u8; 3] {
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        1.0
    };
    let x = t * (VIRIDIS.len() - 1) as f64;
    let i = (x.floor() as usize).min(VIRIDIS.len() - 2);
    let f = x - i as f64;
    std::array::from_fn(|c| {
        ((1.0 - f) * VIRIDIS[i][c] as f64 + f * VIRIDIS[i + 1][c] as f64).round() as u8
    })
}

/// The false-colour error panel (sRGB bytes, row-major): hair pixels coloured by
/// max_c |a − r| / max(reference over the hair) on [0, [`ERROR_SCALE`]], others black.
/// Also returns the largest normalized error found.
pub fn error_panel(approx: &Image, reference: &Image) -> Result<(Vec<[u8; 3]>, f64), CompareError> {
    check_finite("the reference", reference)?;
    approx.check_against("the image", reference)?;
    let peak = reference
        .pixels
        .iter()
        .filter(|p| is_hair(p))
        .flat_map(|p| p[..3].iter().map(|c| *c as f64))
        .fold(0.0f64, f64::max);
    if reference.pixels.iter().all(|p| !is_hair(p)) {
        return Err(CompareError::NoHair);
    }
    if peak <= 0.0 {
        return Err(CompareError::BlackReference);
    }
    let mut worst = 0.0f64;
    let panel = approx
        .pixels
        .iter()
        .zip(&reference.pixels)
        .map(|(a, r)| {
            if !is_hair(r) {
                return [0, 0, 0];
            }
            let e = (0..3)
                .map(|c| (a[c] as f64 - r[c] as f64).abs())
                .fold(0.0, f64::max)
                / peak;
            worst = worst.max(e);
            colormap(e / ERROR_SCALE)
        })
        .collect();
    Ok((panel, worst))
}

/// A line for the log saying how to read the error panel.
pub fn error_legend() -> String {
    format!(
        "error panel: max over RGB of |image − reference| / (largest reference value over the hair), {COLORMAP}: 0 → dark violet, {ERROR_SCALE} and above → yellow; the strip under it is the scale; non-hair pixels black"
    )
}

/// One tonemapped panel ([`PNG_TONEMAP`]).
fn tonemapped(image: &Image) -> Vec<[u8; 3]> {
    image
        .pixels
        .iter()
        .map(|p| {
            [
                tonemap_channel(p[0]),
                tonemap_channel(p[1]),
                tonemap_channel(p[2]),
            ]
        })
        .collect()
}

/// Writes `srbf | reference | baseline | error` side by side as one 8-bit PNG, atomically, with
/// a legend strip under the error panel (the colormap from 0 to [`ERROR_SCALE`]).
pub fn write_side_by_side(
    path: &Path,
    srbf: &Image,
    reference: &Image,
    baseline: &Image,
    description: &str,
) -> Result<(), CompareError> {
    srbf.check_against("the SRBF image", reference)?;
    baseline.check_against("the baseline image", reference)?;
    let (error, _) = error_panel(srbf, reference)?;
    let panels = [
        tonemapped(srbf),
        tonemapped(reference),
        tonemapped(baseline),
        error,
    ];
    let (w, h) = (reference.width as usize, reference.height as usize);
    let total_w = 4 * w;
    let total_h = h + LEGEND_ROWS as usize;
    let mut bytes = vec![0u8; total_w * total_h * 3];
    for (k, panel) in panels.iter().enumerate() {
        for y in 0..h {
            for x in 0..w {
                let o = (y * total_w + k * w + x) * 3;
                bytes[o..o + 3].copy_from_slice(&panel[y * w + x]);
            }
        }
    }
    for y in h..total_h {
        for x in 0..w {
            let c = colormap(x as f64 / (w.max(2) - 1) as f64);
            let o = (y * total_w + 3 * w + x) * 3;
            bytes[o..o + 3].copy_from_slice(&c);
        }
    }
    let legend = format!(
        "{description}; panels: SRBF | reference | baseline | error; images: {PNG_TONEMAP}; {}",
        error_legend()
    );
    Ok(write_png_rgb8(
        path,
        total_w as u32,
        total_h as u32,
        &bytes,
        &legend,
    )?)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(pixels: Vec<[f32; 4]>) -> Image {
        Image::new(pixels.len() as u32, 1, pixels)
    }

    /// (image, reference): hair pixels r = (1,0,0), (0,2,0) with errors 0.1 and 0.2; the third
    /// pixel has no hair in the reference and a huge difference that must not count.
    fn worked_pair() -> (Image, Image) {
        let reference = image(vec![[1.0, 0.0, 0.0, 1.0], [0.0, 2.0, 0.0, 0.5], [0.0; 4]]);
        let approx = image(vec![
            [1.1, 0.0, 0.0, 1.0],
            [0.0, 2.0, 0.2, 0.5],
            [50.0, 50.0, 50.0, 1.0],
        ]);
        (approx, reference)
    }

    /// A full image split into single and multiple scattering: each part's error is measured
    /// over the whole's norm and hair, and the parts' errors add as vectors to the whole's.
    #[test]
    fn the_parts_errors_are_relative_to_the_whole_and_add_up_to_it() {
        let (approx, reference) = worked_pair();
        // The reference's single-scattering part; the rest of it is multiple scattering.
        let single_reference = image(vec![[0.5, 0.0, 0.0, 1.0], [0.0, 1.0, 0.0, 0.5], [0.0; 4]]);
        // The image's single part is off by 0.1 in pixel 0 only, so its multiple part carries
        // the rest of its error: 0.2 in pixel 1 (and pixel 2, which has no hair).
        let single_approx = image(vec![[0.6, 0.0, 0.0, 1.0], [0.0, 1.0, 0.0, 0.5], [9.0; 4]]);
        let single = relative_rmse_of_part(&single_approx, &single_reference, &reference).unwrap();
        // √(0.01 / 5)
        assert!((single - (0.01f64 / 5.0).sqrt()).abs() < 1e-7, "{single}");
        let multiple_approx = approx.minus(&single_approx).unwrap();
        let multiple_reference = reference.minus(&single_reference).unwrap();
        let multiple =
            relative_rmse_of_part(&multiple_approx, &multiple_reference, &reference).unwrap();
        // √(0.04 / 5)
        assert!(
            (multiple - (0.04f64 / 5.0).sqrt()).abs() < 1e-7,
            "{multiple}"
        );
        let whole = relative_rmse(&approx, &reference).unwrap();
        assert!(
            (single.hypot(multiple) - whole).abs() < 1e-7,
            "{single} ⊕ {multiple} ≠ {whole}"
        );
        assert!(
            approx.minus(&image(vec![[0.0; 4]])).is_err(),
            "sizes must match"
        );
    }

    /// Over blocks, a part's error is its block means' against the reference part's, over the
    /// whole's block means: worked by hand on the 8×8 patch (colour (1, 2, 3)), whose reference
    /// part is half the whole and whose approximated part is 0.6 of it left of x = 5 and 0.4
    /// from there: every hair pixel is 0.1 of the whole off, and a block straddling x = 5
    /// cancels.
    #[test]
    fn a_parts_error_over_blocks_is_its_block_means_against_the_references() {
        let whole = patch(|_, _, p| p);
        let half = patch(|_, _, p| [0.5 * p[0], 0.5 * p[1], 0.5 * p[2], p[3]]);
        let skewed = patch(|x, _, p| {
            let k = if x < 5 { 0.6 } else { 0.4 };
            [k * p[0], k * p[1], k * p[2], p[3]]
        });
        // Per pixel: every hair pixel is off by 0.1 of its colour, the whole is 1: 0.1.
        let pixels = relative_rmse_of_part_over_blocks(&skewed, &half, &whole, 1).unwrap();
        assert!((pixels - 0.1).abs() < 1e-7, "{pixels}");
        // Over 2×2 blocks, a block of k hair pixels that deviate alike has squared error
        // 4·(0.1·k·c/4)² against the whole's 4·(k·c/4)²; the blocks at x 4–5 cancel. k is the
        // block's hair columns times its hair rows, so the rows cancel from the ratio, and the
        // hair columns per block column (x 0–1, 2–3, 4–5, 6–7, 8–9) are 1, 2, 2, 2, 1: squared
        // 1 + 4 + 4 + 1 = 10 deviate of 1 + 4 + 4 + 4 + 1 = 14.
        let two = relative_rmse_of_part_over_blocks(&skewed, &half, &whole, 2).unwrap();
        let expected = (0.01f64 * 10.0 / 14.0).sqrt();
        assert!((two - expected).abs() < 1e-7, "{two} vs {expected}");
        // The reference part itself is exact at every scale.
        for n in ERROR_SCALES {
            let e = relative_rmse_of_part_over_blocks(&half, &half, &whole, n).unwrap();
            assert_eq!(e, 0.0);
        }
        // A part of another size is refused.
        let small = image(vec![[0.0; 4]]);
        assert!(relative_rmse_of_part_over_blocks(&small, &half, &whole, 4).is_err());
    }

    /// An 8×8 hair patch of colour (1, 2, 3), alpha 1, inside a 10×10 image; `at(x, y)` the
    /// image's pixels there.
    fn patch(at: impl Fn(u32, u32, [f32; 4]) -> [f32; 4]) -> Image {
        let pixels = (0..100)
            .map(|i| {
                let (x, y) = (i % 10, i / 10);
                let hair = (1..9).contains(&x) && (1..9).contains(&y);
                let p = if hair { [1.0, 2.0, 3.0, 1.0] } else { [0.0; 4] };
                at(x, y, p)
            })
            .collect();
        Image::new(10, 10, pixels)
    }

    /// A checkerboard of ±10% averages out over every 2×2 block inside the patch (which starts
    /// at an odd pixel, so the blocks on its edge hold one or two of its pixels and keep a
    /// residue), a 10% bias stays 10% at every scale, and at 1×1 the block error is the
    /// relative RMSE.
    #[test]
    fn a_pattern_averages_out_over_blocks_and_a_bias_does_not() {
        let reference = patch(|_, _, p| p);
        let checker = patch(|x, y, p| {
            let s = if (x + y) % 2 == 0 { 1.1 } else { 0.9 };
            [p[0] * s, p[1] * s, p[2] * s, p[3]]
        });
        let errors = ScaleErrors::of(&checker, &reference).unwrap();
        assert!((errors.blocks[0] - 0.1).abs() < 1e-6, "{errors:?}");
        // The patch's edge blocks hold 1, 2 or 4 of its pixels: only blocks of an odd count
        // keep a residue, and over 4×4 the blocks hold 9, 12 or 16.
        let by_hand_2 = relative_rmse_over_blocks(&checker, &reference, 2).unwrap();
        assert_eq!(errors.blocks[1], by_hand_2);
        assert!(errors.blocks[1] < 0.06, "{errors:?}");
        assert!(errors.blocks[2] < errors.blocks[0] / 3.0, "{errors:?}");
        assert_eq!(
            errors.blocks[0],
            relative_rmse(&checker, &reference).unwrap()
        );
        assert_eq!(errors.coverage, 0.0);
        assert!((errors.mean_ratio - 1.0).abs() < 1e-6);

        let biased = patch(|_, _, p| [p[0] * 1.1, p[1] * 1.1, p[2] * 1.1, p[3]]);
        let errors = ScaleErrors::of(&biased, &reference).unwrap();
        for e in errors.blocks {
            assert!((e - 0.1).abs() < 1e-6, "{errors:?}");
        }
        assert!((errors.mean_ratio - 1.1).abs() < 1e-6);
    }

    /// A block's colour is its pixels' mean: a patch aligned to 2×2 blocks whose pixels swap
    /// light within each block has no error at 2×2; the same swap across blocks keeps it.
    #[test]
    fn light_moved_within_a_block_is_no_error_at_that_block_size() {
        let reference = Image::new(4, 2, vec![[1.0, 1.0, 1.0, 1.0]; 8]);
        let within = Image::new(
            4,
            2,
            (0..8)
                .map(|i| {
                    if i % 2 == 0 {
                        [1.5, 1.5, 1.5, 1.0]
                    } else {
                        [0.5, 0.5, 0.5, 1.0]
                    }
                })
                .collect(),
        );
        let across = Image::new(
            4,
            2,
            (0..8)
                .map(|i| {
                    if i % 4 < 2 {
                        [1.5, 1.5, 1.5, 1.0]
                    } else {
                        [0.5, 0.5, 0.5, 1.0]
                    }
                })
                .collect(),
        );
        assert_eq!(
            relative_rmse_over_blocks(&within, &reference, 2).unwrap(),
            0.0
        );
        let kept = relative_rmse_over_blocks(&across, &reference, 2).unwrap();
        assert!((kept - 0.5).abs() < 1e-9, "{kept}");
        assert!((relative_rmse_over_blocks(&across, &reference, 4).unwrap()).abs() < 1e-9);
    }

    /// Coverage: half the alpha on every hair pixel is an error of 0.5; alpha where the
    /// reference has none counts, whatever the colour.
    #[test]
    fn the_coverage_error_is_the_alphas_relative_rmse() {
        let reference = patch(|_, _, p| p);
        let half = patch(|_, _, p| [p[0], p[1], p[2], p[3] * 0.5]);
        let e = coverage_error(&half, &reference).unwrap();
        assert!((e - 0.5).abs() < 1e-9, "{e}");
        let extra = patch(|x, y, p| {
            if (x, y) == (0, 0) {
                [0.0, 0.0, 0.0, 1.0]
            } else {
                p
            }
        });
        let e = coverage_error(&extra, &reference).unwrap();
        assert!((e - (1.0f64 / 64.0).sqrt()).abs() < 1e-9, "{e}");
    }

    #[test]
    fn relative_rmse_by_hand() {
        // Σ|a−r|² = 0.01 + 0.04 = 0.05, Σ|r|² = 1 + 4 = 5, √(0.05/5) = 0.1.
        let (approx, reference) = worked_pair();
        let e = relative_rmse(&approx, &reference).unwrap();
        assert!((e - 0.1).abs() < 1e-7, "{e}");
        assert_eq!(relative_rmse(&reference, &reference).unwrap(), 0.0);
    }

    #[test]
    fn mean_ratio_by_hand() {
        // Hair RGB sums 1 and 2 in the reference, 1.1 and 2.2 in the image: 3.3 / 3 = 1.1; the
        // non-hair pixel does not count. Swapping the two hair pixels' light keeps the mean.
        let (approx, reference) = worked_pair();
        let r = mean_ratio(&approx, &reference).unwrap();
        assert!((r - 1.1).abs() < 1e-7, "{r}");
        let swapped = image(vec![[0.0, 2.0, 0.0, 1.0], [1.0, 0.0, 0.0, 0.5], [0.0; 4]]);
        assert!((mean_ratio(&swapped, &reference).unwrap() - 1.0).abs() < 1e-12);
        assert!(relative_rmse(&swapped, &reference).unwrap() > 1.0);
        let black = image(vec![[0.0, 0.0, 0.0, 1.0]; 3]);
        assert!(matches!(
            mean_ratio(&black, &black),
            Err(CompareError::BlackReference)
        ));
    }

    #[test]
    fn error_split_by_hand() {
        // Worked pair: Σa·r = 1.1 + 4 = 5.1, Σa² = 1.21 + 4 + 0.04 = 5.25, s = 5.1/5.25;
        // Σ‖s·a − r‖² = s²·5.25 − 2s·5.1 + 5 = 5 − 5.1²/5.25.
        let (approx, reference) = worked_pair();
        let split = error_split(&approx, &reference).unwrap();
        let s = 5.1 / 5.25;
        assert!((split.best_scale - s).abs() < 1e-6, "{split:?}");
        let after = ((5.0 - 5.1 * 5.1 / 5.25) / 5.0f64).sqrt();
        assert!(
            (split.relative_rmse_after_scale - after).abs() < 1e-6,
            "{split:?}"
        );
        // Two hair pixels: the brightest tenth is the one pixel of RGB sum 2, measured 2.2; its
        // error 0.2² (the blue) is 0.04 of Σ‖a − r‖² = 0.01 + 0.04.
        assert!(
            (split.brightest_tenth_ratio - 1.1).abs() < 1e-6,
            "{split:?}"
        );
        assert!(
            (split.brightest_tenth_share - 0.8).abs() < 1e-6,
            "{split:?}"
        );

        // A pure bias (the image twice the reference) is all scale: nothing left after it.
        let doubled = image(
            reference
                .pixels
                .iter()
                .map(|p| [2.0 * p[0], 2.0 * p[1], 2.0 * p[2], p[3]])
                .collect(),
        );
        let split = error_split(&doubled, &reference).unwrap();
        assert!((split.best_scale - 0.5).abs() < 1e-12);
        assert!(split.relative_rmse_after_scale < 1e-7, "{split:?}");
        assert!((split.brightest_tenth_ratio - 2.0).abs() < 1e-12);

        // A pure pattern (the two hair pixels' light swapped) keeps the mean; the scale does
        // not remove it.
        let swapped = image(vec![[0.0, 2.0, 0.0, 1.0], [1.0, 0.0, 0.0, 0.5], [0.0; 4]]);
        let split = error_split(&swapped, &reference).unwrap();
        assert!(split.relative_rmse_after_scale > 0.99, "{split:?}");
        assert_eq!(split.brightest_tenth_ratio, 0.5);
        assert_eq!(
            error_split(&reference, &reference)
                .unwrap()
                .brightest_tenth_share,
            0.0
        );
        let black = image(vec![[0.0, 0.0, 0.0, 1.0]; 3]);
        assert!(matches!(
            error_split(&black, &black),
            Err(CompareError::BlackReference)
        ));
    }

    #[test]
    fn bad_inputs_are_named() {
        let reference = image(vec![[1.0, 0.0, 0.0, 1.0], [0.0; 4]]);
        let short = image(vec![[1.0, 0.0, 0.0, 1.0]]);
        assert!(matches!(
            relative_rmse(&short, &reference),
            Err(CompareError::SizeMismatch { w: 1, rw: 2, .. })
        ));
        let nan = image(vec![[1.0, 0.0, 0.0, 1.0], [f32::NAN, 0.0, 0.0, 0.0]]);
        let e = relative_rmse(&nan, &reference).unwrap_err();
        assert!(
            matches!(
                e,
                CompareError::NotFinite {
                    count: 1,
                    first: 1,
                    ..
                }
            ),
            "{e}"
        );
        let empty = image(vec![[1.0, 0.0, 0.0, 0.0], [0.0; 4]]);
        assert!(matches!(
            relative_rmse(&reference, &empty),
            Err(CompareError::NoHair)
        ));
        let black = image(vec![[0.0, 0.0, 0.0, 1.0], [0.0; 4]]);
        assert!(matches!(
            relative_rmse(&reference, &black),
            Err(CompareError::BlackReference)
        ));
    }

    #[test]
    fn colormap_hits_its_samples_and_interpolates() {
        assert_eq!(colormap(0.0), [68, 1, 84]);
        assert_eq!(colormap(1.0), [253, 231, 37]);
        assert_eq!(colormap(0.5), [33, 144, 141]);
        assert_eq!(colormap(7.0), [253, 231, 37]);
        assert_eq!(colormap(-1.0), [68, 1, 84]);
        // Halfway between t = 0 and 1/8: the rounded mean of (68,1,84) and (71,44,122).
        assert_eq!(colormap(1.0 / 16.0), [70, 23, 103]);
    }

    #[test]
    fn error_panel_by_hand() {
        // Peak reference value over the hair = 2 (pixel 1's green). Pixel 0: max|Δ| = 0.1 →
        // 0.05 → t = 0.5 at scale 0.1; pixel 1: exact → t = 0; pixel 2: not hair → black.
        let reference = image(vec![
            [1.0, 0.0, 0.0, 1.0],
            [0.0, 2.0, 0.0, 1.0],
            [9.0, 9.0, 9.0, 0.0],
        ]);
        let approx = image(vec![
            [1.1, 0.05, 0.0, 1.0],
            [0.0, 2.0, 0.0, 1.0],
            [0.0, 0.0, 0.0, 1.0],
        ]);
        let (panel, worst) = error_panel(&approx, &reference).unwrap();
        assert!((worst - 0.05).abs() < 1e-6, "{worst}");
        assert_eq!(panel, vec![colormap(0.5), colormap(0.0), [0, 0, 0]]);
    }

    #[test]
    fn side_by_side_png_has_four_panels_and_a_legend() {
        let reference = Image::new(2, 1, vec![[1.0, 0.0, 0.0, 1.0], [0.0, 0.0, 0.0, 0.0]]);
        let srbf = Image::new(2, 1, vec![[1.1, 0.0, 0.0, 1.0], [0.0, 0.0, 0.0, 0.0]]);
        let baseline = Image::new(2, 1, vec![[3.0, 0.0, 0.0, 1.0], [0.0, 0.0, 0.0, 0.0]]);
        let dir = std::env::temp_dir().join(format!("strandlight-sbs-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("side.png");
        write_side_by_side(&path, &srbf, &reference, &baseline, "test").unwrap();
        let decoder =
            png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&path).unwrap()));
        let mut reader = decoder.read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut buf).unwrap();
        assert_eq!((info.width, info.height), (8, 1 + LEGEND_ROWS));
        let px = |x: usize, y: usize| {
            [
                buf[(y * 8 + x) * 3],
                buf[(y * 8 + x) * 3 + 1],
                buf[(y * 8 + x) * 3 + 2],
            ]
        };
        // Reinhard 1.0 → 0.5 → sRGB 0.7354 → 188; 3.0 → 0.75 → 225 (by hand from the sRGB curve).
        assert_eq!(px(2, 0), [188, 0, 0]);
        assert_eq!(px(4, 0), [225, 0, 0]);
        // Error: |1.1 − 1| / 1 = 0.1 → the top of the scale.
        assert_eq!(px(6, 0), colormap(1.0));
        assert_eq!(px(7, 0), [0, 0, 0]);
        // Legend strip: the colormap's two ends under the error panel.
        assert_eq!(px(6, 5), colormap(0.0));
        assert_eq!(px(7, 5), colormap(1.0));
        assert!(
            std::fs::read_dir(&dir).unwrap().count() == 1,
            "no temporary file left behind"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
