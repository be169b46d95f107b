//! Compact bright sources (a sun, a lamp) pulled out of an environment map as directional lights
//! before the SRBF fit.
//!
//! Why: an SRBF of the fit's widest allowed bandwidth (λ ≤ 64, ~7° half-width) cannot represent a
//! source half a degree wide. The L2 objective is then dominated by that source: the lobes
//! cluster on it, the rest of the sky is left unfitted (relative L2 errors of 0.99 on sun maps,
//! docs/BENCHMARKS.md), and the sun's shadows and highlights are blurred over the lobe. A source
//! that compact is exactly what a directional light with its own deep opacity map renders well,
//! so it is extracted, and the SRBFs fit what is left.
//!
//! A source is the disc of angular radius `radius` around the brightest pixel, less a
//! background: the per-channel median of the ring between `radius` and 2·`radius`. Its power
//! is Σ (L − background)⁺ dω over the disc, its direction the power-weighted mean direction; the
//! disc's pixels are set to the background (clamped to the pixel), so the residual map plus the
//! sources hold exactly the map's power. Sources are extracted, brightest first, while one
//! holds at least `min_norm_share` of what is left's squared norm Σ w‖L‖² (the quantity the
//! SRBF fit's L2 objective weighs): a source that dominates it is one the fit would chase.

use crate::envmap::EnvMap;
use glam::DVec3;
use serde::{Deserialize, Serialize};

/// A compact source as a directional light, in the map's own frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CompactSource {
    /// Unit vector toward the source.
    pub direction: [f64; 3],
    /// ∫ (L − background) dω over the source's disc, per channel (its irradiance at normal
    /// incidence as a directional light).
    pub power: [f64; 3],
    /// Share of the map's luminance power it holds.
    pub power_share: f64,
    /// Per-axis variance (rad²) of the directions its power arrives from about `direction`:
    /// half the power-weighted mean of |ω − (ω·d)d|² over the disc. ~0 for a sun a pixel or two
    /// wide, ~r²/4 for a uniform panel of angular radius r. A renderer that draws the source as
    /// one directional light softens its shadow by this much (`TransmittanceFilter`).
    pub angular_variance: f64,
}

/// What counts as a compact source.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SourceOptions {
    /// Most sources extracted (0: none, the paper's pure SRBF fit).
    pub max_sources: usize,
    /// Angular radius of a source's disc, degrees.
    pub radius_degrees: f64,
    /// Least share of the remaining map's squared norm Σ w‖L‖² a disc must hold above its
    /// background.
    pub min_norm_share: f64,
}

impl Default for SourceOptions {
    fn default() -> Self {
        Self {
            max_sources: 8,
            radius_degrees: 2.5,
            min_norm_share: 0.1,
        }
    }
}

impl SourceOptions {
    /// The paper's behaviour: no extraction.
    pub fn none() -> Self {
        Self {
            max_sources: 0,
            ..Self::default()
        }
    }
}

const LUMINANCE: [f64; 3] = strandlight_tables::colour::REC709_LUMINANCE;

fn luminance(p: [f32; 3]) -> f64 {
    (0..3).map(|c| LUMINANCE[c] * p[c] as f64).sum()
}

/// Fewest pixels in the ring around a candidate for its median to stand for the background;
/// a map too coarse for that (pixels wider than the disc) gets no sources.
const MIN_RING_PIXELS: usize = 8;

fn median(values: &mut [f64]) -> f64 {
    if values.is_empty() {
        return 0.0;
    }
    values.sort_by(f64::total_cmp);
    values[values.len() / 2]
}

/// Pixels (x, y) whose centre lies within `angle` radians of `direction`, with their cosine.
fn pixels_within(map: &EnvMap, direction: DVec3, angle: f64) -> Vec<(usize, usize, f64)> {
    let cos_limit = angle.cos();
    let mut out = Vec::new();
    for y in 0..map.height() {
        for x in 0..map.width() {
            let c = map.direction(x, y).dot(direction);
            if c >= cos_limit {
                out.push((x, y, c));
            }
        }
    }
    out
}

/// The sources of `map` and the map without them.
pub fn extract(map: &EnvMap, options: &SourceOptions) -> (Vec<CompactSource>, EnvMap) {
    let mut pixels = map.pixels().to_vec();
    let (width, height) = (map.width(), map.height());
    let total: f64 = map
        .integral()
        .iter()
        .zip(LUMINANCE)
        .map(|(p, w)| p * w)
        .sum();
    let radius = options.radius_degrees.to_radians();
    let mut sources = Vec::new();
    if !(total > 0.0) {
        return (sources, map.clone());
    }
    let squared_norm = |pixels: &[[f32; 3]]| -> f64 {
        (0..height)
            .map(|y| {
                let w = map.row_solid_angle(y);
                pixels[y * width..(y + 1) * width]
                    .iter()
                    .map(|p| w * p.iter().map(|&c| (c as f64).powi(2)).sum::<f64>())
                    .sum::<f64>()
            })
            .sum()
    };
    while sources.len() < options.max_sources {
        let residual = EnvMap::from_pixels(width, height, pixels.clone());
        let brightest = (0..pixels.len())
            .max_by(|&a, &b| luminance(pixels[a]).total_cmp(&luminance(pixels[b])))
            .expect("a map has pixels");
        let centre = residual.direction(brightest % width, brightest / width);
        let ring: Vec<_> = pixels_within(&residual, centre, 2.0 * radius)
            .into_iter()
            .filter(|&(_, _, c)| c < radius.cos())
            .collect();
        if ring.len() < MIN_RING_PIXELS {
            break; // pixels as wide as the disc: no background to tell a source from
        }
        let background: [f64; 3] = std::array::from_fn(|ch| {
            let mut v: Vec<f64> = ring
                .iter()
                .map(|&(x, y, _)| pixels[y * width + x][ch] as f64)
                .collect();
            median(&mut v)
        });
        let disc = pixels_within(&residual, centre, radius);
        let mut power = [0.0; 3];
        let mut norm = 0.0;
        let mut weighted = DVec3::ZERO;
        for &(x, y, _) in &disc {
            let w = residual.row_solid_angle(y);
            let p = pixels[y * width + x];
            let excess: [f64; 3] = std::array::from_fn(|c| (p[c] as f64 - background[c]).max(0.0));
            for c in 0..3 {
                power[c] += excess[c] * w;
                norm += excess[c] * excess[c] * w;
            }
            let lum: f64 = (0..3).map(|c| LUMINANCE[c] * excess[c]).sum();
            weighted += residual.direction(x, y) * lum * w;
        }
        let share = (0..3).map(|c| LUMINANCE[c] * power[c]).sum::<f64>() / total;
        if !(norm >= options.min_norm_share * squared_norm(&pixels)) || weighted.length() == 0.0 {
            break;
        }
        let direction = weighted.normalize();
        let spread = angular_variance(&residual, &disc, background, direction);
        for &(x, y, _) in &disc {
            let p = &mut pixels[y * width + x];
            for c in 0..3 {
                p[c] = p[c].min(background[c] as f32);
            }
        }
        sources.push(CompactSource {
            direction: direction.to_array(),
            power,
            power_share: share,
            angular_variance: spread,
        });
    }
    (sources, EnvMap::from_pixels(width, height, pixels))
}

/// [`CompactSource::angular_variance`] of the excess over `background` on `disc` (pixels of
/// `map`) about `direction`.
fn angular_variance(
    map: &EnvMap,
    disc: &[(usize, usize, f64)],
    background: [f64; 3],
    direction: DVec3,
) -> f64 {
    let (mut sum, mut weight) = (0.0, 0.0);
    for &(x, y, _) in disc {
        let p = map.pixels()[y * map.width() + x];
        let excess: [f64; 3] = std::array::from_fn(|c| (p[c] as f64 - background[c]).max(0.0));
        let w = (0..3).map(|c| LUMINANCE[c] * excess[c]).sum::<f64>() * map.row_solid_angle(y);
        let d = map.direction(x, y);
        sum += w * (d - d.dot(direction) * direction).length_squared();
        weight += w;
    }
    if weight > 0.0 {
        0.5 * sum / weight
    } else {
        0.0
    }
}

/// The wider disc radius (degrees) the fit tries by default ([`extract_widening`]): a studio's
/// softboxes and a sun 6° wide widen, the shared maps' suns and lamps do not
/// (docs/BENCHMARKS.md, "Wider compact sources").
pub const DEFAULT_WIDER_RADIUS_DEGREES: f64 = 5.0;

/// `degrees` as a wider radius, 0 meaning none (how the command lines switch widening off).
pub fn wider_radius(degrees: f64) -> Option<f64> {
    (degrees != 0.0).then_some(degrees)
}

/// How much more of the map's power (luminance share) the sources at the wider radius must
/// hold before [`extract_widening`] takes them: a sun's glow adds a few points, a softbox whose
/// light spills past the narrow disc adds tens.
pub const WIDENING_GAIN: f64 = 0.10;

/// [`extract`] at `options.radius_degrees`, or at `wider_degrees` where the sources found there
/// hold at least [`WIDENING_GAIN`] more of the map's power: extended lamps (studio softboxes),
/// whose light the narrow disc leaves to lobes too wide for it (λ ≤ 64). A sun keeps the narrow
/// disc: collapsing a wider one into a point sharpens the glow's shadows (docs/BENCHMARKS.md,
/// "Wider compact sources"). Returns the radius used beside the sources and the residual.
pub fn extract_widening(
    map: &EnvMap,
    options: &SourceOptions,
    wider_degrees: Option<f64>,
) -> (Vec<CompactSource>, EnvMap, f64) {
    let narrow = extract(map, options);
    let Some(wider) = wider_degrees.filter(|&w| w > options.radius_degrees) else {
        return (narrow.0, narrow.1, options.radius_degrees);
    };
    let wide_options = SourceOptions {
        radius_degrees: wider,
        ..*options
    };
    let wide = extract(map, &wide_options);
    let held = |sources: &[CompactSource]| sources.iter().map(|s| s.power_share).sum::<f64>();
    match held(&wide.0) >= held(&narrow.0) + WIDENING_GAIN {
        true => (wide.0, wide.1, wider),
        false => (narrow.0, narrow.1, options.radius_degrees),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::envmap::row_solid_angle;

    /// A sky of constant radiance `sky` with a disc of radius `sun_radius` (radians) around
    /// `sun` at radiance `sun_radiance` (on top of the sky).
    fn sky_with_sun(sky: f32, sun: DVec3, sun_radius: f64, sun_radiance: f32) -> EnvMap {
        EnvMap::from_fn(1024, 512, |w| {
            let s = if w.dot(sun) >= sun_radius.cos() {
                sun_radiance
            } else {
                0.0
            };
            [(sky + s) as f64; 3]
        })
    }

    #[test]
    fn a_sun_is_extracted_with_its_power_direction_and_the_sky_left_behind() {
        let sun = DVec3::new(0.3, 0.8, -0.52).normalize();
        let map = sky_with_sun(0.5, sun, 0.6f64.to_radians(), 20000.0);
        let (sources, residual) = extract(&map, &SourceOptions::default());
        assert_eq!(sources.len(), 1, "{sources:?}");
        let s = sources[0];
        // The disc's excess power, summed independently over the pixels whose centres are in it.
        let mut expected = 0.0;
        for y in 0..map.height() {
            for x in 0..map.width() {
                if map.direction(x, y).dot(sun) >= 0.6f64.to_radians().cos() {
                    expected += 20000.0 * row_solid_angle(y, map.width(), map.height());
                }
            }
        }
        for c in 0..3 {
            assert!(
                (s.power[c] - expected).abs() < 1e-9 * expected,
                "{} vs {expected}",
                s.power[c]
            );
        }
        let angle = DVec3::from(s.direction)
            .dot(sun)
            .clamp(-1.0, 1.0)
            .acos()
            .to_degrees();
        assert!(angle < 0.1, "direction off by {angle}°");
        // What is left is the sky alone, and the power adds up.
        assert!(residual.pixels().iter().all(|p| (p[0] - 0.5).abs() < 1e-6));
        let (m, r) = (map.integral(), residual.integral());
        for c in 0..3 {
            assert!((r[c] + s.power[c] - m[c]).abs() < 1e-9 * m[c]);
        }
    }

    #[test]
    fn smooth_skies_and_disabled_options_extract_nothing() {
        // A bright but broad gradient: no 2.5° disc holds 10% of the squared norm above its ring.
        let map = EnvMap::from_fn(512, 256, |w| [(1.0 + 3.0 * w.y.max(0.0)).powi(2); 3]);
        assert!(extract(&map, &SourceOptions::default()).0.is_empty());
        let sun = sky_with_sun(0.5, DVec3::Y, 0.01, 1e6);
        let (none, residual) = extract(&sun, &SourceOptions::none());
        assert!(none.is_empty());
        assert_eq!(residual, sun);
        // A black map has nothing to extract.
        let black = EnvMap::from_pixels(8, 4, vec![[0.0; 3]; 32]);
        assert!(extract(&black, &SourceOptions::default()).0.is_empty());
        // Pixels (11° at 32 × 16) wider than the 2.5° disc: no ring to measure a background
        // against, so a bright pixel of a coarse map is left to the fit.
        let mut coarse = vec![[0.2f32; 3]; 32 * 16];
        coarse[5 * 32 + 7] = [500.0; 3];
        let coarse = EnvMap::from_pixels(32, 16, coarse);
        let (found, residual) = extract(&coarse, &SourceOptions::default());
        assert!(found.is_empty(), "{found:?}");
        assert_eq!(residual, coarse);
    }

    /// A softbox: a disc `radius` wide of near-uniform radiance `level` (5% brighter at its
    /// centre, so the brightest pixel is there), on a sky.
    fn sky_with_softbox(sky: f32, lamp: DVec3, radius: f64, level: f32) -> EnvMap {
        EnvMap::from_fn(1024, 512, |w| {
            let t = w.dot(lamp).clamp(-1.0, 1.0).acos() / radius;
            let l = if t <= 1.0 {
                level * (1.0 + 0.05 * (1.0 - t * t) as f32)
            } else {
                0.0
            };
            [(sky + l) as f64; 3]
        })
    }

    #[test]
    fn an_extended_lamp_widens_the_disc_and_a_sun_keeps_it() {
        let options = SourceOptions::default();
        let held = |s: &[CompactSource]| s.iter().map(|s| s.power_share).sum::<f64>();
        let toward = DVec3::new(0.3, 0.8, -0.52).normalize();
        let lamp = sky_with_softbox(0.5, toward, 6f64.to_radians(), 200.0);
        let narrow = extract(&lamp, &options).0;
        // Within 2.5° of the centre the softbox's own radiance is the background.
        let (wide, residual, radius) = extract_widening(&lamp, &options, Some(5.0));
        assert_eq!(radius, 5.0, "{narrow:?} vs {wide:?}");
        assert!(
            held(&wide) >= held(&narrow) + WIDENING_GAIN,
            "{narrow:?} vs {wide:?}"
        );
        let (m, r) = (lamp.integral(), residual.integral());
        let power: f64 = wide.iter().map(|s| s.power[0]).sum();
        assert!((r[0] + power - m[0]).abs() < 1e-9 * m[0]);
        // A sun half a degree wide: the wider disc adds only sky, so the narrow one stays.
        let sun = sky_with_sun(0.5, toward, 0.25f64.to_radians(), 20000.0);
        let (kept, _, radius) = extract_widening(&sun, &options, Some(5.0));
        assert_eq!(radius, options.radius_degrees);
        assert_eq!(kept, extract(&sun, &options).0);
        // No wider radius, or one no wider: the narrow extraction as is.
        assert_eq!(extract_widening(&lamp, &options, None).2, 2.5);
        assert_eq!(extract_widening(&lamp, &options, Some(2.0)).2, 2.5);
    }

    /// Per-axis variance of directions within `disc` radians of a softbox's centre, weighted by
    /// its excess radiance (`sky_with_softbox`'s profile over `lamp` radians; the ring's median
    /// is the sky, so the excess is the profile) and solid angle: ½ E[sin²γ] by Gauss–Legendre
    /// over γ.
    fn softbox_variance_by_quadrature(lamp: f64, disc: f64) -> f64 {
        use strandlight_tables::quadrature::GaussLegendre;
        let rule = GaussLegendre::composite(16, 64, 0.0, disc);
        let weight = |g: f64| (1.0 + 0.05 * (1.0 - (g / lamp).powi(2))) * g.sin();
        0.5 * rule.integrate(|g| weight(g) * g.sin().powi(2)) / rule.integrate(weight)
    }

    #[test]
    fn a_source_carries_the_spread_of_its_disc() {
        let options = SourceOptions::default();
        let toward = DVec3::new(0.3, 0.8, -0.52).normalize();
        // A softbox 6° across taken at 5°: its excess fills the whole disc.
        let lamp = sky_with_softbox(0.5, toward, 6f64.to_radians(), 200.0);
        let (wide, _, radius) = extract_widening(&lamp, &options, Some(5.0));
        assert_eq!(radius, 5.0);
        let expected = softbox_variance_by_quadrature(6f64.to_radians(), 5f64.to_radians());
        let got = wide[0].angular_variance;
        println!("softbox: angular variance {got:.4e}, quadrature {expected:.4e}");
        // Pixels of 0.35° on a 5° disc: its rim is a staircase.
        assert!((got / expected - 1.0).abs() < 0.03, "{got} vs {expected}");
        // A sun a pixel or two wide carries (almost) no spread.
        let sun = sky_with_sun(0.5, toward, 0.25f64.to_radians(), 20000.0);
        let spread = extract(&sun, &options).0[0].angular_variance;
        println!("0.25° sun: angular variance {spread:.4e}");
        assert!(spread < 0.01 * expected, "{spread}");
    }

    #[test]
    fn two_suns_come_out_brightest_first() {
        let a = DVec3::new(0.0, 0.5, -1.0).normalize();
        let b = DVec3::new(-1.0, 0.2, 0.3).normalize();
        let map = EnvMap::from_fn(1024, 512, |w| {
            let mut v = 0.2;
            if w.dot(a) >= 0.5f64.to_radians().cos() {
                v += 5e4;
            }
            if w.dot(b) >= 0.7f64.to_radians().cos() {
                v += 1e4;
            }
            [v; 3]
        });
        let (sources, _) = extract(&map, &SourceOptions::default());
        assert_eq!(sources.len(), 2, "{sources:?}");
        assert!(DVec3::from(sources[0].direction).dot(a) > 0.9999);
        assert!(DVec3::from(sources[1].direction).dot(b) > 0.9999);
        assert!(sources[0].power_share > sources[1].power_share);
    }
}
