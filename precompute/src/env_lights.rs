//! The three light sets `strandlight compare` renders one environment with (Ren 2010 §8), as
//! plain descriptions the CLI turns into the runtime's `EnvLight`s (precompute does not link
//! the runtime): the fitted SRBFs, the brute-force cube-texel reference and the median-cut
//! baseline.
//!
//! Directions are in the map's own frame of [`crate::envmap`] (+Y up, image center toward −Z),
//! as [`crate::srbf_set::SrbfSet`] stores its lobes, so all three sets of one map agree. Where
//! the map sits in a hair's world, turned or not, is the frame's business
//! (`strandlight_scene::env_orientation`), applied to every set alike.

use crate::compact_sources::{self, SourceOptions};
use crate::cube_lights::{CubeLightsError, CubeTexel, cube_face_lights, texel_center_direction};
use crate::envmap::EnvMap;
use crate::median_cut::{DirectionalLight, median_cut};
use crate::srbf_set::{LightKind, SrbfSet};
use glam::DVec3;
use strandlight_tables::colour::luminance;
use strandlight_tables::srbf;

/// One light: an SRBF (`lambda` = Some, `rgb` its amplitude, radiance) or a directional light
/// (`lambda` = None, `rgb` its irradiance at normal incidence = ∫ L dω of the region it stands
/// for).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LightSpec {
    /// Unit vector toward the light.
    pub direction: DVec3,
    pub lambda: Option<f64>,
    pub rgb: [f64; 3],
    /// Directional lights only: the direction of the shadow map whose visibility this light
    /// takes (a reference sub-texel takes its cube texel's); `None`: its own direction.
    pub shadowed_from: Option<DVec3>,
    /// Directional lights only: per-axis variance (rad²) of the directions it stands for, which
    /// softens its shadow (a fitted set's compact source, [`CompactSource::angular_variance`]).
    /// 0: a point, as every reference and median-cut light is.
    ///
    /// [`CompactSource::angular_variance`]: crate::compact_sources::CompactSource::angular_variance
    pub angular_variance: f64,
    /// Directional lights only: the light stands for a region of the map (a reference's cube
    /// texel, a median-cut region), not a compact source taken out whole (a sun, a lamp). The
    /// region's own shadow is soft at fiber scale, so the layered view reads it at a layer's mean
    /// position, as it does SRBF lobes', and a compact source's as its fibers' mean visibility.
    pub stands_for_region: bool,
    /// A fitted set's compact source: the share of the map's power it holds
    /// ([`CompactSource::power_share`]); 0 for every other light.
    ///
    /// [`CompactSource::power_share`]: crate::compact_sources::CompactSource::power_share
    pub power_share: f64,
}

impl LightSpec {
    /// ∫ L dω it delivers per channel: amplitude · 2π/λ · (1 − e^{−2λ}) for an SRBF, the
    /// irradiance for a directional light.
    pub fn power(&self) -> [f64; 3] {
        match self.lambda {
            Some(l) => self.rgb.map(|a| a * srbf::integral(l)),
            None => self.rgb,
        }
    }
}

/// Σ power over a set, per channel.
pub fn total_power(lights: &[LightSpec]) -> [f64; 3] {
    lights.iter().fold([0.0; 3], |acc, l| {
        let p = l.power();
        std::array::from_fn(|c| acc[c] + p[c])
    })
}

/// The lights of a fitted set. A set of kind `directional` (the median-cut baseline saved by
/// `fit --directional`, stored as very narrow lobes) becomes directional lights carrying each
/// lobe's power.
/// The set's compact sources follow as directional lights carrying their power.
pub fn srbf_set_lights(set: &SrbfSet) -> Vec<LightSpec> {
    let lobes = set.lobes.iter().map(|l| match set.kind {
        LightKind::Srbf => LightSpec {
            direction: l.center().normalize(),
            lambda: Some(l.lambda),
            rgb: l.amplitude,
            shadowed_from: None,
            angular_variance: 0.0,
            stands_for_region: false,
            power_share: 0.0,
        },
        LightKind::Directional => LightSpec {
            direction: l.center().normalize(),
            lambda: None,
            rgb: crate::srbf_set::power(l),
            shadowed_from: None,
            angular_variance: 0.0,
            stands_for_region: true,
            power_share: 0.0,
        },
    });
    let sources = set.sources.iter().map(|s| LightSpec {
        direction: DVec3::from(s.direction).normalize(),
        lambda: None,
        rgb: s.power,
        shadowed_from: None,
        angular_variance: s.angular_variance,
        stands_for_region: false,
        power_share: s.power_share,
    });
    lobes.chain(sources).collect()
}

/// Point lights along `lights`' directions; `stands_for_region`: each stands for a region of
/// the map ([`LightSpec::stands_for_region`]), not a compact source.
fn directional(lights: Vec<DirectionalLight>, stands_for_region: bool) -> Vec<LightSpec> {
    lights
        .into_iter()
        .map(|l| LightSpec {
            direction: l.direction.normalize(),
            lambda: None,
            rgb: l.power,
            shadowed_from: None,
            angular_variance: 0.0,
            stands_for_region,
            power_share: 0.0,
        })
        .collect()
}

/// The brute-force reference: the compact sources of `map` that `sources` picks (a sun, a lamp:
/// [`compact_sources::extract`], as the fit takes them out), each an exact directional light at
/// its power-weighted direction, then what is left of the map as `6 · face_resolution²`
/// directional lights, one per cube texel (32 → the paper's 6144), each carrying its texel's
/// ∫ L dω ([`cube_face_lights`]). The sets hold the map's power exactly. A sun left among the
/// texel lights would sit at its texel's centre, up to half a texel (5.6° at 8 × 8 per face)
/// from where it is, moving every highlight it casts (docs/BENCHMARKS.md: quarry's 384-light
/// reference was 34% off its 1536-light one).
pub fn reference_lights(
    map: &EnvMap,
    face_resolution: usize,
    sources: &SourceOptions,
) -> Result<Vec<LightSpec>, CubeLightsError> {
    reference_lights_shaded(map, face_resolution, face_resolution, sources)
}

/// [`reference_lights`] with each cube texel's light shaded over finer sub-texels: the map
/// left after the compact sources becomes one light per texel of a `shading_face_resolution`
/// cube (a multiple of `face_resolution`), whose visibility is interpolated between the shadow
/// maps of the `face_resolution` cube's texel centres: each coarse texel's map
/// ([`LightSpec::shadowed_from`]) shades the sub-texels around it weighted by a bilinear tent
/// ([`tent_samples`]). A sub-texel thus appears under up to four maps, its power split by the
/// weights. Lights are listed map by map; sub-texels with no luminance are left out.
///
/// Why: a texel light point-samples the fiber's response, whose R lobe is a few degrees wide,
/// so a coarse cube moves highlights by up to half a texel, while visibility through the hair
/// varies more slowly with the light's direction. Shading at the fine cube and interpolating
/// visibility from the coarse one costs the coarse cube's light passes (the dominant cost) and
/// converges at the rate of the interpolated visibility (docs/BENCHMARKS.md, "A converged
/// reference").
pub fn reference_lights_shaded(
    map: &EnvMap,
    face_resolution: usize,
    shading_face_resolution: usize,
    sources: &SourceOptions,
) -> Result<Vec<LightSpec>, CubeLightsError> {
    let (n, fine) = (face_resolution, shading_face_resolution);
    if n == 0 || fine == 0 {
        return Err(CubeLightsError::ZeroFaceResolution);
    }
    if !fine.is_multiple_of(n) {
        return Err(CubeLightsError::ShadingNotAMultiple {
            face: n,
            shading: fine,
        });
    }
    let (found, residual) = compact_sources::extract(map, sources);
    let source_lights = found.iter().map(|s| DirectionalLight {
        direction: DVec3::from(s.direction),
        power: s.power,
    });
    let mut lights = directional(source_lights.collect(), false);
    let texel_lights = cube_face_lights(&residual, fine)?;
    if fine == n {
        lights.extend(directional(texel_lights, true));
        return Ok(lights);
    }
    let m = fine / n;
    for face in 0..6 {
        for (j, i) in (0..n).flat_map(|j| (0..n).map(move |i| (j, i))) {
            let texel = CubeTexel { face, i, j };
            let shadow = texel_center_direction(texel, n);
            let shadowed_from = Some(shadow.normalize());
            let samples = tent_samples(texel, n, m).filter_map(|(t, w)| {
                let l = &texel_lights[t.index(fine)];
                (luminance(l.power) > 0.0).then(|| LightSpec {
                    direction: l.direction.normalize(),
                    lambda: None,
                    rgb: l.power.map(|p| p * w),
                    shadowed_from,
                    angular_variance: 0.0,
                    stands_for_region: true,
                    power_share: 0.0,
                })
            });
            lights.extend(samples);
        }
    }
    Ok(lights)
}

/// The sub-texels of the `n·m` cube whose visibility the map of coarse `texel` contributes to,
/// with their weights: the bilinear tent over the face between neighbouring coarse texel
/// centres (constant beyond the outermost centres of the face; cube edges are not crossed).
/// Over the coarse texels of a face the weights of every sub-texel sum to 1, so the map's
/// power is kept and visibility is interpolated linearly between shadow maps instead of being
/// piecewise constant (one order more accurate where it varies smoothly).
fn tent_samples(texel: CubeTexel, n: usize, m: usize) -> impl Iterator<Item = (CubeTexel, f64)> {
    // Sub-texel index k (0..n·m) in coarse texel units, centres at (k + ½)/m − ½.
    let weight = move |coarse: usize, k: usize| {
        let u = ((k as f64 + 0.5) / m as f64 - 0.5).clamp(0.0, (n - 1) as f64);
        (1.0 - (u - coarse as f64).abs()).max(0.0)
    };
    let span = move |coarse: usize| {
        let lo = coarse.saturating_sub(1) * m;
        let hi = ((coarse + 2) * m).min(n * m);
        (lo..hi).filter_map(move |k| {
            let w = weight(coarse, k);
            (w > 0.0).then_some((k, w))
        })
    };
    span(texel.j).flat_map(move |(jj, wj)| {
        span(texel.i).map(move |(ii, wi)| {
            let t = CubeTexel {
                face: texel.face,
                i: ii,
                j: jj,
            };
            (t, wi * wj)
        })
    })
}

/// The brute-force reference of a fitted set's own lighting, `fit` being
/// [`srbf_set_lights`]'s lights: its compact sources as exact point lights (no softened
/// shadow: the map's reference takes its sources as points too), then its lobes' radiance,
/// sampled on a `width × height` equirectangular map, one light per texel of a
/// `face_resolution` cube ([`cube_face_lights`]).
///
/// Why: rendered against the map's reference ([`reference_lights`]) at the same cube, it
/// measures what the fit alone changes in the image, and the SRBF frame against it what the
/// convolution tables and the renderer change: `strandlight bench`'s error decomposition.
pub fn fitted_reference_lights(
    fit: &[LightSpec],
    width: usize,
    height: usize,
    face_resolution: usize,
) -> Result<Vec<LightSpec>, CubeLightsError> {
    let lobes: Vec<(DVec3, f64, [f64; 3])> = fit
        .iter()
        .filter_map(|l| {
            l.lambda
                .map(|lambda| (l.direction.normalize(), lambda, l.rgb))
        })
        .collect();
    let radiance = EnvMap::from_fn(width, height, |w| {
        lobes
            .iter()
            .fold([0.0; 3], |sum, &(center, lambda, amplitude)| {
                let g = srbf::kernel(w.dot(center), lambda);
                std::array::from_fn(|c| sum[c] + amplitude[c] * g)
            })
    });
    let sources = fit
        .iter()
        .filter(|l| l.lambda.is_none())
        .map(|l| LightSpec {
            shadowed_from: None,
            angular_variance: 0.0,
            stands_for_region: false,
            // The reference draws every map at one resolution (its cached images stay valid);
            // the fine maps of dominant sources are the method's, measured against the truth.
            power_share: 0.0,
            ..*l
        });
    let mut lights: Vec<LightSpec> = sources.collect();
    lights.extend(directional(
        cube_face_lights(&radiance, face_resolution)?,
        true,
    ));
    Ok(lights)
}

/// The equal-cost baseline: `count` median-cut directional lights (Debevec 2005).
pub fn median_cut_lights(map: &EnvMap, count: usize) -> Vec<LightSpec> {
    directional(median_cut(map, count.max(1)), true)
}

/// The median-cut baseline given the same exact compact sources as the reference and the SRBF
/// frame: each source of `map` that `sources` picks is one directional light at its
/// power-weighted direction ([`compact_sources::extract`]), and median cut splits what is left
/// into the rest of the `count` lights (at least one). Why: plain median cut lights a sun that
/// holds half a map's power from the centroids of the regions it is cut into, so its error
/// stops falling at a few percent however many lights it gets; with the sun exact, the
/// comparison measures the SRBF's treatment of the rest of the map, not a handicap of the
/// baseline's.
pub fn median_cut_lights_with_sources(
    map: &EnvMap,
    count: usize,
    sources: &SourceOptions,
) -> Vec<LightSpec> {
    let (found, residual) = compact_sources::extract(map, sources);
    let exact = found.iter().map(|s| DirectionalLight {
        direction: DVec3::from(s.direction),
        power: s.power,
    });
    let rest = median_cut(&residual, count.saturating_sub(found.len()).max(1));
    let mut lights = directional(exact.collect(), false);
    lights.extend(directional(rest, true));
    lights
}

/// Face resolution n of a reference with `count` = 6n² lights, or None when `count` is not of
/// that form.
pub fn face_resolution_for(count: usize) -> Option<usize> {
    if count == 0 || !count.is_multiple_of(6) {
        return None;
    }
    let n = ((count / 6) as f64).sqrt().round() as usize;
    (6 * n * n == count).then_some(n)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::procedural_env;
    use crate::srbf_fit::FitOptions;
    use crate::srbf_set::{FORMAT, FORMAT_VERSION, Source};
    use std::f64::consts::PI;
    use strandlight_tables::srbf::SrbfLobe;

    /// ∫ L dω by the definition, written out here: Σ pixel radiance × pixel solid angle, the
    /// solid angle of a row of an equirectangular map being (2π/W)(cos θ_top − cos θ_bottom).
    fn pixel_sum_integral(map: &EnvMap) -> [f64; 3] {
        let (w, h) = (map.width(), map.height());
        let mut sum = [0.0f64; 3];
        for y in 0..h {
            let (t0, t1) = (PI * y as f64 / h as f64, PI * (y + 1) as f64 / h as f64);
            let d_omega = 2.0 * PI / w as f64 * (t0.cos() - t1.cos());
            for x in 0..w {
                let p = map.pixel(x, y);
                for c in 0..3 {
                    sum[c] += p[c] as f64 * d_omega;
                }
            }
        }
        sum
    }

    /// The fitted set's reference holds what the set delivers: each lobe's closed-form
    /// ∫ G dω times its amplitude plus each source's power, the sources kept exactly where
    /// they are and as points.
    #[test]
    fn the_fitted_reference_holds_the_fits_power_and_its_sources_exactly() {
        let lobe = |d: DVec3, lambda: f64, rgb: [f64; 3]| LightSpec {
            direction: d.normalize(),
            lambda: Some(lambda),
            rgb,
            shadowed_from: None,
            angular_variance: 0.0,
            stands_for_region: false,
            power_share: 0.0,
        };
        let sun = LightSpec {
            direction: DVec3::new(0.3, 0.8, -0.2).normalize(),
            lambda: None,
            rgb: [5.0, 4.0, 3.0],
            shadowed_from: None,
            angular_variance: 1e-3,
            stands_for_region: false,
            power_share: 0.0,
        };
        let fit = [
            lobe(DVec3::new(0.0, 1.0, 0.0), 3.0, [1.0, 1.5, 2.0]),
            lobe(DVec3::new(1.0, -0.2, 0.4), 120.0, [8.0, 6.0, 1.0]),
            sun,
        ];
        let lights = fitted_reference_lights(&fit, 1024, 512, 16).unwrap();
        assert_eq!(lights.len(), 1 + 6 * 16 * 16);
        assert_eq!(lights[0].direction, sun.direction);
        assert_eq!(lights[0].rgb, sun.rgb);
        assert_eq!(
            lights[0].angular_variance, 0.0,
            "the reference's sources are points"
        );
        assert!(!lights[0].stands_for_region, "the sun is a compact source");
        assert!(
            lights[1..].iter().all(|l| l.stands_for_region),
            "every cube texel's light stands for its texel"
        );
        let want: [f64; 3] = std::array::from_fn(|c| {
            sun.rgb[c]
                + [1.0, 1.5, 2.0][c] * srbf::integral(3.0)
                + [8.0, 6.0, 1.0][c] * srbf::integral(120.0)
        });
        let gap = relative_gap(total_power(&lights), want);
        assert!(
            gap < 2e-3,
            "power {:?} against {want:?}: {gap}",
            total_power(&lights)
        );
    }

    fn relative_gap(a: [f64; 3], b: [f64; 3]) -> f64 {
        (0..3)
            .map(|c| ((a[c] - b[c]) / b[c]).abs())
            .fold(0.0, f64::max)
    }

    /// A sky brighter overhead with a sun disc of `radius_deg` holding most of the power.
    fn sun_and_sky(width: usize, height: usize, radius_deg: f64) -> EnvMap {
        let sun = DVec3::new(0.4, 0.6, -0.69).normalize();
        let inside = radius_deg.to_radians().cos();
        EnvMap::from_fn(width, height, |w| {
            let sky = 0.5 + 0.3 * w.y.max(0.0);
            let disc = if w.dot(sun) > inside { 2e5 } else { 0.0 };
            [sky + disc, sky + 0.9 * disc, sky + 0.7 * disc]
        })
    }

    #[test]
    fn reference_and_median_cut_carry_the_whole_map() {
        // A sky with a sun 0.5° across holding most of the power: a compact source.
        let map = sun_and_sky(1024, 512, 0.25);
        let truth = pixel_sum_integral(&map);
        // Both partition the map's solid angle (every sub-pixel / pixel goes to exactly one
        // light), so only f64 summation order separates them from the pixel sum: 1e-9.
        for n in [4, 8] {
            let sources = SourceOptions::default();
            let (found, _) = compact_sources::extract(&map, &sources);
            assert_eq!(found.len(), 1, "the procedural sun is taken out");
            let lights = reference_lights(&map, n, &sources).unwrap();
            assert_eq!(lights.len(), 1 + 6 * n * n);
            let gap = relative_gap(total_power(&lights), truth);
            println!(
                "cube reference n = {n}: {} lights, relative power gap {gap:.2e}",
                lights.len()
            );
            assert!(gap < 1e-9, "{gap}");
        }
        for count in [1, 17, 64] {
            let lights = median_cut_lights(&map, count);
            assert_eq!(lights.len(), count);
            let gap = relative_gap(total_power(&lights), truth);
            println!("median cut {count}: relative power gap {gap:.2e}");
            assert!(gap < 1e-9, "{gap}");
            assert!(
                lights
                    .iter()
                    .all(|l| (l.direction.length() - 1.0).abs() < 1e-12 && l.lambda.is_none())
            );
        }
    }

    #[test]
    fn median_cut_with_sources_keeps_the_sun_exact_and_the_whole_map() {
        let map = sun_and_sky(1024, 512, 0.25);
        let truth = pixel_sum_integral(&map);
        let sources = SourceOptions::default();
        let (found, _) = compact_sources::extract(&map, &sources);
        let sun = DVec3::from(found[0].direction).normalize();
        for count in [1, 2, 16, 64] {
            let lights = median_cut_lights_with_sources(&map, count, &sources);
            // One light for the sun plus at least one for the sky.
            assert_eq!(lights.len(), count.max(2));
            let gap = relative_gap(total_power(&lights), truth);
            assert!(gap < 1e-9, "median cut + sources {count}: power gap {gap}");
            // The sun is one light, where the source is, with the source's power; plain
            // median cut spreads it over the centroids of the regions it is cut into.
            assert!((lights[0].direction - sun).length() < 1e-12);
            assert_eq!(lights[0].rgb, found[0].power);
        }
    }

    fn set_of(kind: LightKind, lobes: Vec<SrbfLobe>, map: &EnvMap) -> SrbfSet {
        let mut set = SrbfSet::directional(
            &Source {
                map,
                name: "test".into(),
                sha256: String::new(),
                sanitized: Default::default(),
            },
            1,
            &FitOptions::default(),
        );
        set.format = FORMAT.into();
        set.version = FORMAT_VERSION;
        set.kind = kind;
        set.lobes = lobes;
        set
    }

    #[test]
    fn srbf_lights_carry_the_power_of_the_map_they_describe() {
        // A map made of known lobes: its pixel-sum integral is an independent estimate of the
        // lobes' ∫ L dω. The midpoint rule on 1024×512 pixels (0.35°) against lobes ≥ 7° wide
        // (λ ≤ 64) errs by O((pixel/width)²) ≲ 2.5e-3 · (curvature terms that largely cancel
        // over a smooth lobe); measured 1.9e-6, bound 1e-4. A wrong λ, a missing 2π or a lost
        // lobe is off by far more.
        let lobes = vec![
            SrbfLobe {
                center: DVec3::new(0.3, 0.8, -0.5).normalize().to_array(),
                lambda: 64.0,
                amplitude: [2.0, 1.5, 1.0],
            },
            SrbfLobe {
                center: DVec3::new(-0.9, 0.1, 0.2).normalize().to_array(),
                lambda: 16.0,
                amplitude: [0.2, 0.3, 0.5],
            },
            SrbfLobe {
                center: DVec3::new(0.0, -1.0, 0.0).to_array(),
                lambda: 30.0,
                amplitude: [0.1, 0.1, 0.05],
            },
        ];
        let map = procedural_env::from_srbf_lobes(1024, &lobes);
        let set = set_of(LightKind::Srbf, lobes.clone(), &map);
        let lights = srbf_set_lights(&set);
        let gap = relative_gap(total_power(&lights), pixel_sum_integral(&map));
        println!("SRBF set vs pixel-sum integral of its own map: relative gap {gap:.2e}");
        assert!(gap < 1e-4, "{gap}");
        for (l, lobe) in lights.iter().zip(&lobes) {
            assert_eq!(l.lambda, Some(lobe.lambda));
            assert_eq!(l.rgb, lobe.amplitude);
            assert!((l.direction - lobe.center()).length() < 1e-12);
        }
        // A directional set (narrow stand-in lobes) becomes directional lights of equal power.
        let dir = set_of(
            LightKind::Directional,
            vec![SrbfLobe {
                center: [0.0, 1.0, 0.0],
                lambda: 1e4,
                amplitude: [3.0, 2.0, 1.0],
            }],
            &map,
        );
        let d = srbf_set_lights(&dir);
        let want = 2.0 * PI / 1e4 * (1.0 - (-2e4f64).exp());
        assert!(d[0].lambda.is_none() && (d[0].rgb[0] - 3.0 * want).abs() < 1e-15);
    }

    #[test]
    fn reference_counts_are_six_squares() {
        assert_eq!(face_resolution_for(6144), Some(32));
        assert_eq!(face_resolution_for(6), Some(1));
        assert_eq!(face_resolution_for(600), Some(10));
        assert_eq!(face_resolution_for(100), None);
        assert_eq!(face_resolution_for(0), None);
        assert_eq!(face_resolution_for(12), None);
    }

    /// The shaded reference keeps the map's power (the tent weights of every sub-texel sum to
    /// 1), keeps the compact sources as they are, shares one map per texel, and refuses a
    /// shading cube that does not divide into the visibility cube.
    #[test]
    fn shaded_reference_carries_the_whole_map_in_runs_sharing_a_map() {
        let map = sun_and_sky(512, 256, 0.5);
        let truth = pixel_sum_integral(&map);
        let sources = SourceOptions::default();
        for (n, fine) in [(2, 8), (4, 8), (4, 4)] {
            let lights = reference_lights_shaded(&map, n, fine, &sources).unwrap();
            let gap = relative_gap(total_power(&lights), truth);
            let maps = lights
                .chunk_by(|a, b| a.shadowed_from.is_some() && a.shadowed_from == b.shadowed_from)
                .count();
            println!(
                "n = {n}, shading {fine}: {} lights, {maps} maps, power gap {gap:.2e}",
                lights.len()
            );
            assert!(gap < 1e-9, "{gap}");
            assert_eq!(maps, 1 + 6 * n * n, "the sun, then one map per texel");
            assert!(
                lights[0].shadowed_from.is_none(),
                "the sun casts its own map"
            );
            match fine == n {
                true => assert!(lights.iter().all(|l| l.shadowed_from.is_none())),
                false => assert!(lights[1..].iter().all(|l| l.shadowed_from.is_some())),
            }
        }
        let e = reference_lights_shaded(&map, 4, 6, &sources).unwrap_err();
        assert!(e.to_string().contains("multiple of 4"), "{e}");
    }

    /// Visibility bilinear in a face's coordinates is reproduced exactly by the tent weights
    /// between the coarse texel centres (what makes the interpolation one order more accurate
    /// than one map per texel); beyond the outermost centres it is held constant.
    #[test]
    fn tent_weights_interpolate_bilinear_visibility_exactly() {
        let (n, m) = (4usize, 4usize);
        let centre = |k: usize, res: usize| 2.0 * (k as f64 + 0.5) / res as f64 - 1.0;
        let visibility = |a: f64, b: f64| 1.0 + 0.3 * a - 0.2 * b + 0.1 * a * b;
        let mut interpolated = vec![0.0f64; n * m * n * m];
        let mut weight_sum = vec![0.0f64; n * m * n * m];
        for (j, i) in (0..n).flat_map(|j| (0..n).map(move |i| (j, i))) {
            let v = visibility(centre(i, n), centre(j, n));
            for (t, w) in tent_samples(CubeTexel { face: 2, i, j }, n, m) {
                assert_eq!(t.face, 2);
                interpolated[t.j * n * m + t.i] += w * v;
                weight_sum[t.j * n * m + t.i] += w;
            }
        }
        let (lo, hi) = (centre(0, n), centre(n - 1, n));
        let mut checked = 0;
        for (jj, ii) in (0..n * m).flat_map(|j| (0..n * m).map(move |i| (j, i))) {
            let k = jj * n * m + ii;
            assert!(
                (weight_sum[k] - 1.0).abs() < 1e-12,
                "{ii},{jj}: {}",
                weight_sum[k]
            );
            let (a, b) = (centre(ii, n * m), centre(jj, n * m));
            let clamped = visibility(a.clamp(lo, hi), b.clamp(lo, hi));
            assert!(
                (interpolated[k] - clamped).abs() < 1e-12,
                "{ii},{jj}: {} vs {clamped}",
                interpolated[k]
            );
            checked += 1;
        }
        assert_eq!(checked, 256);
    }
}
