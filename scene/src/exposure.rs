//! Exposure of a displayed or written frame: metered on the subject's own pixels (the hair's and,
//! with a head, the skin's: every covered pixel), so the background (or the black around the
//! hair) never decides how bright the subject looks, and a check that what is written is neither
//! black nor clipped.

use crate::image_metrics::HAIR_ALPHA;
use std::fmt;
use std::str::FromStr;
use strandlight_tables::colour::luminance_f32;
use strandlight_tables::image_out::tonemap_channel;

/// Automatic exposure puts the hair's 90th-percentile radiance here: Reinhard's c/(1+c) maps it
/// to 2/3 of white, bright but with room for the highlights above it.
pub const AUTO_TARGET: f32 = 2.0;

/// The most automatic exposure may add or take away, so a frame of near-zero radiance stays
/// recognisably dark instead of being amplified into noise.
pub const AUTO_LIMIT_STOPS: f32 = 20.0;

/// Automatic exposure above this many stops means the hair is barely lit: say so.
pub const NEARLY_BLACK_STOPS: f32 = 12.0;

/// A picture whose hair clips in more than this share of its pixels is called saturated.
pub const SATURATED_SHARE: f64 = 0.2;

/// `auto` or a fixed number of stops (0: the radiance as is).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Exposure {
    #[default]
    Auto,
    Stops(f32),
}

impl FromStr for Exposure {
    type Err = String;
    fn from_str(text: &str) -> Result<Self, String> {
        if text.eq_ignore_ascii_case("auto") {
            return Ok(Self::Auto);
        }
        match text.parse::<f32>() {
            Ok(stops) if stops.is_finite() && stops.abs() <= 64.0 => Ok(Self::Stops(stops)),
            _ => Err(format!(
                "exposure {text:?}: expected `auto` or a number of stops in [-64, 64]"
            )),
        }
    }
}

impl fmt::Display for Exposure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Auto => write!(f, "auto"),
            Self::Stops(stops) => write!(f, "{stops}"),
        }
    }
}

/// Luminance of a hair pixel, un-premultiplied so a half-covered pixel meters like a covered one.
fn hair_luminance(p: &[f32; 4]) -> Option<f32> {
    let l = luminance_f32([p[0], p[1], p[2]]) / p[3];
    (p[3] > HAIR_ALPHA && l.is_finite() && l > 0.0).then_some(l)
}

/// Stops that bring the 90th percentile of the hair's luminance to [`AUTO_TARGET`]; None when no
/// hair pixel is lit.
pub fn metered_stops(pixels: &[[f32; 4]]) -> Option<f32> {
    let mut luminance: Vec<f32> = pixels.iter().filter_map(hair_luminance).collect();
    if luminance.is_empty() {
        return None;
    }
    let k = (luminance.len() * 9 / 10).min(luminance.len() - 1);
    let (_, p90, _) = luminance.select_nth_unstable_by(k, f32::total_cmp);
    Some(
        (AUTO_TARGET / *p90)
            .log2()
            .clamp(-AUTO_LIMIT_STOPS, AUTO_LIMIT_STOPS),
    )
}

impl Exposure {
    /// The stops applied to `pixels`: the metered ones for `Auto` (0 when no hair is lit).
    pub fn stops_for(self, pixels: &[[f32; 4]]) -> f32 {
        match self {
            Self::Auto => metered_stops(pixels).unwrap_or(0.0),
            Self::Stops(stops) => stops,
        }
    }
}

/// What is wrong with a written picture of hair.
#[derive(Clone, Debug, PartialEq)]
pub enum ExposureProblem {
    /// No pixel covers hair at all.
    NoHair,
    /// Hair is there but every covered pixel is black (or non-finite) in the linear frame.
    Unlit,
    /// Lit, but so faintly that automatic exposure needed this many stops.
    NearlyBlack { stops: f32 },
    /// At this exposure, the hair tonemaps to black (every channel under one 8-bit level).
    BlackAtExposure { stops: f32 },
    /// This share of the hair's pixels clip to white in some channel.
    Saturated { share: f64, stops: f32 },
}

impl fmt::Display for ExposureProblem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NoHair => write!(f, "no pixel covers hair: is the camera looking at it?"),
            Self::Unlit => write!(
                f,
                "the hair is black: no light reaches the hair's visible side (a light inside the \
                 hair or behind the head?)"
            ),
            Self::NearlyBlack { stops } => write!(
                f,
                "the hair is nearly black: automatic exposure needed {stops:+.1} stops (the \
                 linear EXR holds the radiance as rendered)"
            ),
            Self::BlackAtExposure { stops } => write!(
                f,
                "the hair is black at {stops:+.1} stops of exposure: try --exposure auto"
            ),
            Self::Saturated { share, stops } => write!(
                f,
                "{:.0}% of the hair's pixels clip to white at {stops:+.1} stops: try --exposure auto \
                 or fewer stops",
                100.0 * share
            ),
        }
    }
}

/// Checks the hair of `pixels` as it will look at `stops` through the PNG tonemap.
pub fn exposure_problem(
    pixels: &[[f32; 4]],
    exposure: Exposure,
    stops: f32,
) -> Option<ExposureProblem> {
    let hair: Vec<&[f32; 4]> = pixels.iter().filter(|p| p[3] > HAIR_ALPHA).collect();
    if hair.is_empty() {
        return Some(ExposureProblem::NoHair);
    }
    if !hair.iter().any(|p| hair_luminance(p).is_some()) {
        return Some(ExposureProblem::Unlit);
    }
    if exposure == Exposure::Auto && stops > NEARLY_BLACK_STOPS {
        return Some(ExposureProblem::NearlyBlack { stops });
    }
    let scale = stops.exp2();
    let levels = |p: &[f32; 4]| [0, 1, 2].map(|k| tonemap_channel(scale * p[k]));
    if hair.iter().all(|p| levels(p).iter().all(|&v| v == 0)) {
        return Some(ExposureProblem::BlackAtExposure { stops });
    }
    let clipped = hair.iter().filter(|p| levels(p).contains(&255)).count();
    let share = clipped as f64 / hair.len() as f64;
    (share > SATURATED_SHARE).then_some(ExposureProblem::Saturated { share, stops })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A frame with `n` hair pixels of luminance 1..=n (grey, fully covered) and background.
    fn ramp(n: usize) -> Vec<[f32; 4]> {
        let mut pixels: Vec<[f32; 4]> = (1..=n)
            .map(|i| {
                let c = i as f32;
                [c, c, c, 1.0]
            })
            .collect();
        pixels.extend(std::iter::repeat_n([1e3, 1e3, 1e3, 0.0], n));
        pixels
    }

    #[test]
    fn auto_exposure_meters_the_hair_not_the_background() {
        // Luminance of grey is the grey value (the Rec. 709 weights sum to 1); the 90th
        // percentile of 1..=100 at index 90 is 91. A bright background (alpha 0) must not count.
        let stops = metered_stops(&ramp(100)).unwrap();
        assert!(
            (stops - (AUTO_TARGET / 91.0).log2()).abs() < 1e-5,
            "{stops}"
        );
        assert_eq!(metered_stops(&[[5.0, 5.0, 5.0, 0.0]]), None);
    }

    #[test]
    fn half_covered_pixels_meter_like_covered_ones() {
        let covered = metered_stops(&[[4.0, 4.0, 4.0, 1.0]]).unwrap();
        let half = metered_stops(&[[2.0, 2.0, 2.0, 0.5]]).unwrap();
        assert!((covered - half).abs() < 1e-6);
        assert!((covered - (AUTO_TARGET / 4.0).log2()).abs() < 1e-6);
    }

    #[test]
    fn parses_auto_and_stops_and_refuses_the_rest() {
        assert_eq!("auto".parse::<Exposure>(), Ok(Exposure::Auto));
        assert_eq!("-1.5".parse::<Exposure>(), Ok(Exposure::Stops(-1.5)));
        for bad in ["", "bright", "nan", "inf", "100"] {
            let err = bad.parse::<Exposure>().unwrap_err();
            assert!(err.contains("expected `auto`"), "{bad}: {err}");
        }
    }

    #[test]
    fn black_unlit_faint_and_clipped_hair_are_each_named() {
        let unlit = [[0.0, 0.0, 0.0, 1.0]; 4];
        assert_eq!(
            exposure_problem(&unlit, Exposure::Auto, 0.0),
            Some(ExposureProblem::Unlit)
        );
        assert_eq!(
            exposure_problem(&[[1.0, 1.0, 1.0, 0.0]], Exposure::Auto, 0.0),
            Some(ExposureProblem::NoHair)
        );
        // The curly groom behind a point light: radiance 1e-6 needs about +21 stops.
        let faint = [[1e-6, 1e-6, 1e-6, 1.0]; 4];
        let stops = Exposure::Auto.stops_for(&faint);
        assert!(matches!(
            exposure_problem(&faint, Exposure::Auto, stops),
            Some(ExposureProblem::NearlyBlack { .. })
        ));
        // The same frame at a fixed exposure of 0 tonemaps every channel to level 0.
        assert!(matches!(
            exposure_problem(&faint, Exposure::Stops(0.0), 0.0),
            Some(ExposureProblem::BlackAtExposure { .. })
        ));
        // c/(1+c) ≥ 254.5/255 in sRGB needs c in the hundreds: +10 stops on radiance 1 clips.
        let lit = [[1.0, 1.0, 1.0, 1.0]; 4];
        assert!(matches!(
            exposure_problem(&lit, Exposure::Stops(10.0), 10.0),
            Some(ExposureProblem::Saturated { share, .. }) if share == 1.0
        ));
        let stops = Exposure::Auto.stops_for(&lit);
        assert_eq!(exposure_problem(&lit, Exposure::Auto, stops), None);
    }
}
