//! HDR-FLIP (Andersson, Nilsson, Shirley and Akenine-Möller 2021, "Visualizing Errors in Rendered
//! High Dynamic Range Images"): the perceptual difference a viewer sees between a linear test
//! image and its reference, as LDR-FLIP (Andersson et al. 2020) taken over a bracket of
//! exposures, per pixel the largest. Relative RMSE weighs every radiance difference alike; FLIP
//! weighs what the eye picks out (edges, highlights moved, colour shifts) and ignores what it
//! cannot see, which is how an image that is "nearly as accurate" by RMSE can still look wrong.
//!
//! LDR-FLIP itself is NVIDIA's C++ implementation through the `nv-flip` crate. The exposure
//! bracket follows NVIDIA's HDR-FLIP code (`computeExposures`, FLIP v1.2–1.7): with the ACES
//! tone mapper t(x) = (a x² + b x + c)/(d x² + e x + f) (0.6 pre-exposure cancelled into the
//! coefficients), the start exposure maps the reference's largest luminance to t = 0.85, the
//! stop exposure its median; ⌈stop − start⌉ exposures (at least 2) evenly between them. Each
//! exposure is tone mapped, clamped to [0, 1] and sRGB encoded for LDR-FLIP.
//!
//! Two deliberate differences, both documented where the value is reported:
//! - The luminance statistics are taken over the hair pixels only. The renders have a black
//!   background covering most of the frame, whose median luminance 0 would put the stop
//!   exposure at infinity.
//! - `nv-flip` takes 8-bit sRGB, so each tone-mapped exposure is quantized to 8 bits before
//!   LDR-FLIP (NVIDIA's HDR path stays in float).
//!   `eval/tests/integration/hdr_flip_vs_nvidia.rs` measures what that costs against NVIDIA's
//!   own HDR-FLIP (the `flip-evaluator` package).

use strandlight_scene::image_metrics::{CompareError, HAIR_ALPHA, Image};
use strandlight_tables::colour::{luminance_f32, srgb_encode_f32};

/// Pixels per degree of visual angle: FLIP's default, a 0.7 m wide 4K monitor seen from 0.7 m.
pub const PIXELS_PER_DEGREE: f32 = nv_flip::DEFAULT_PIXELS_PER_DEGREE;

/// ACES (Narkowicz 2015) with FLIP's 0.6 pre-exposure cancellation, as in FLIP's tensor.h.
const ACES: [f32; 6] = [
    0.6 * 0.6 * 2.51,
    0.6 * 0.03,
    0.0,
    0.6 * 0.6 * 2.43,
    0.6 * 0.59,
    0.14,
];

/// HDR-FLIP of one image pair.
#[derive(Debug, Clone)]
pub struct HdrFlip {
    /// Mean of the error map over the reference's hair pixels (alpha > [`HAIR_ALPHA`]).
    pub mean_over_hair: f64,
    /// Per pixel, the largest LDR-FLIP error over the exposures (0 = invisible, 1 = the most
    /// visible), row-major from the top.
    pub error_map: Vec<f32>,
    pub start_exposure: f32,
    pub stop_exposure: f32,
    pub exposures: usize,
}

fn luminance(p: &[f32; 4]) -> f32 {
    luminance_f32([p[0], p[1], p[2]])
}

fn aces(x: f32) -> f32 {
    let [a, b, c, d, e, f] = ACES;
    ((x * x * a + x * b + c) / (x * x * d + x * e + f)).clamp(0.0, 1.0)
}

/// The exposure bracket (start, stop) of NVIDIA's `computeExposures` for the luminances given.
fn exposure_range(mut luminances: Vec<f32>) -> (f32, f32) {
    // The larger root of (a − t d) x² + (b − t e) x + (c − t f) = 0: where ACES reaches t.
    let t = 0.85;
    let [a, b, c, d, e, f] = ACES;
    let (qa, qb, qc) = (a - t * d, b - t * e, c - t * f);
    let root = (qb * qb - 4.0 * qa * qc).sqrt();
    let x_max = ((-qb - root) / (2.0 * qa)).max((-qb + root) / (2.0 * qa));
    luminances.sort_by(f32::total_cmp);
    let n = luminances.len();
    let median = if n >= 2 {
        0.5 * (luminances[n / 2 - 1] + luminances[n / 2])
    } else {
        luminances[0]
    };
    let largest = luminances[n - 1];
    ((x_max / largest).log2(), (x_max / median).log2())
}

/// The image exposed by 2^`exposure`, tone mapped, clamped and sRGB encoded to bytes.
fn exposed_srgb8(image: &Image, exposure: f32) -> Vec<u8> {
    let scale = exposure.exp2();
    image
        .pixels
        .iter()
        .flat_map(|p| {
            [p[0], p[1], p[2]].map(|c| {
                let v = srgb_encode_f32(aces(c.max(0.0) * scale));
                (v * 255.0 + 0.5) as u8
            })
        })
        .collect()
}

/// HDR-FLIP of `test` against `reference` (linear radiance, same size), its exposures chosen
/// from the reference's hair pixels.
pub fn hdr_flip(test: &Image, reference: &Image) -> Result<HdrFlip, CompareError> {
    // The same checks (size, finite values, some hair, not black) as the relative RMSE.
    strandlight_scene::image_metrics::relative_rmse(test, reference)?;
    let hair: Vec<bool> = reference.pixels.iter().map(|p| p[3] > HAIR_ALPHA).collect();
    let luminances: Vec<f32> = reference
        .pixels
        .iter()
        .zip(&hair)
        .filter(|(_, h)| **h)
        .map(|(p, _)| luminance(p).max(0.0))
        .collect();
    let (start, stop) = exposure_range(luminances);
    if !(start.is_finite() && stop.is_finite()) {
        return Err(CompareError::DarkMedian);
    }
    let exposures = ((stop - start).ceil() as usize).max(2);
    let step = (stop - start) / (exposures - 1) as f32;
    let (w, h) = (reference.width, reference.height);
    let mut error_map = vec![0.0f32; hair.len()];
    for k in 0..exposures {
        let exposure = start + k as f32 * step;
        let r = nv_flip::FlipImageRgb8::with_data(w, h, &exposed_srgb8(reference, exposure));
        let t = nv_flip::FlipImageRgb8::with_data(w, h, &exposed_srgb8(test, exposure));
        let errors = nv_flip::flip(r, t, PIXELS_PER_DEGREE).to_vec();
        for (e, x) in error_map.iter_mut().zip(errors) {
            *e = e.max(x);
        }
    }
    let (sum, count) = error_map
        .iter()
        .zip(&hair)
        .filter(|(_, h)| **h)
        .fold((0.0f64, 0usize), |(s, n), (e, _)| (s + *e as f64, n + 1));
    Ok(HdrFlip {
        mean_over_hair: sum / count as f64,
        error_map,
        start_exposure: start,
        stop_exposure: stop,
        exposures,
    })
}

/// The error map through FLIP's magma colour map, as sRGB bytes (3 per pixel).
pub fn error_map_magma(flip: &HdrFlip, width: u32, height: u32) -> Vec<u8> {
    nv_flip::FlipImageFloat::with_data(width, height, &flip.error_map)
        .apply_color_lut(&nv_flip::magma_lut())
        .to_vec()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(w: u32, h: u32, f: impl Fn(u32, u32) -> [f32; 4]) -> Image {
        Image::new(w, h, (0..w * h).map(|i| f(i % w, i / w)).collect())
    }

    /// A striped hair-like patch on black, bright and dark fibers over three decades.
    fn hair_patch(gain: f32) -> Image {
        image(64, 48, |x, y| {
            if (8..56).contains(&x) && (8..40).contains(&y) {
                let v = gain * if x % 4 < 2 { 4.0 } else { 0.05 } * (1.0 + y as f32 / 48.0);
                [v, 0.8 * v, 0.6 * v, 1.0]
            } else {
                [0.0; 4]
            }
        })
    }

    #[test]
    fn the_exposure_bracket_is_nvidias() {
        // ACES reaches 0.85 at x where (a − 0.85 d) x² + (b − 0.85 e) x − 0.85 f = 0; check t there.
        let (start, stop) = exposure_range(vec![0.5, 1.0, 2.0, 8.0]);
        let x_max = 8.0 * start.exp2();
        assert!((aces(x_max) - 0.85).abs() < 1e-5, "{}", aces(x_max));
        // Median of four: the mean of the middle two (NVIDIA's), 1.5.
        assert!((1.5 * stop.exp2() - x_max).abs() < 1e-4 * x_max);
    }

    #[test]
    fn identical_images_show_no_error_and_differences_grow_it() {
        let reference = hair_patch(1.0);
        let same = hdr_flip(&reference, &reference).unwrap();
        assert_eq!(same.mean_over_hair, 0.0);
        assert!(same.exposures >= 2);
        let mut last = 0.0;
        for gain in [1.05, 1.3, 2.0] {
            let e = hdr_flip(&hair_patch(gain), &reference)
                .unwrap()
                .mean_over_hair;
            eprintln!("gain {gain}: HDR-FLIP {e:.4}");
            assert!(e > last, "gain {gain}: {e} after {last}");
            last = e;
        }
        assert!(last < 1.0);
    }

    #[test]
    fn bad_pairs_are_refused_like_the_relative_rmse() {
        let reference = hair_patch(1.0);
        let small = image(8, 8, |_, _| [1.0; 4]);
        assert!(matches!(
            hdr_flip(&small, &reference),
            Err(CompareError::SizeMismatch { .. })
        ));
        let black = image(64, 48, |_, _| [0.0, 0.0, 0.0, 1.0]);
        assert!(matches!(
            hdr_flip(&reference, &black),
            Err(CompareError::BlackReference)
        ));
        let mut nan = reference.clone();
        nan.pixels[100][1] = f32::NAN;
        assert!(matches!(
            hdr_flip(&nan, &reference),
            Err(CompareError::NotFinite { .. })
        ));
    }
}
