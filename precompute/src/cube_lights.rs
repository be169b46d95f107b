//! The brute-force directional reference of Ren et al. 2010 §8: the environment map sampled as
//! `6 · n²` directional lights, one per cube-map texel (n = 32 gives the paper's 6144), each
//! placed at its texel center's direction and carrying the texel's ∫ L dω.
//!
//! # Cube convention
//!
//! Faces in the order +X, −X, +Y, −Y, +Z, −Z (world axes of [`crate::envmap`]: +Y up). Each face
//! uses the OpenGL cube-map axes: for a direction ω whose largest component (by magnitude) is the
//! face's `major` axis, the face coordinates are `a = ω·s_axis / ω·major`,
//! `b = ω·t_axis / ω·major` in [−1, 1], and texel `(i, j)` covers
//! `a ∈ [2i/n − 1, 2(i+1)/n − 1]`, `b ∈ [2j/n − 1, 2(j+1)/n − 1]`. Light index =
//! `face · n² + j · n + i`. Ties on a face edge go to the first face in the order above, so
//! every direction belongs to exactly one texel.
//!
//! # How a texel's power is integrated
//!
//! The equirectangular map is piecewise constant over its pixels. Each pixel is cut into
//! `s × s` sub-pixels (equal in azimuth, equal in polar angle), each sub-pixel's EXACT solid
//! angle `Δφ (cos θ₀ − cos θ₁)` is given to the texel containing the sub-pixel's center, with
//! the pixel's radiance. Every bit of solid angle is assigned exactly once, so the sum of all
//! powers equals [`EnvMap::integral`] up to rounding. The only error is binning: a sub-pixel
//! straddling a texel edge goes wholly to one side. The azimuth slices are also cut at the
//! meridians that are texel edges of the side faces, so those edges (aligned with the pixel
//! columns, hence the worst aliasing) are exact. Measured against the closed-form texel solid
//! angle ([`cube_texel_solid_angle`]) for a constant 1024×512 map at n = 32, max (rms) relative
//! error per texel: s = 1 9.3 % (2.0 %), s = 2 4.7 % (0.75 %), s = 4 1.6 % (0.26 %),
//! s = 8 0.78 % (0.086 %), i.e. ≈ 1/s. The default `s` ([`default_subsamples`]) is picked so
//! that a texel spans at least [`SUBPIXELS_PER_TEXEL`] sub-pixels across (s = 8 there).
//!
//! Sums run in fixed row bands, reduced in order: results are bitwise deterministic whatever
//! the thread count.

use crate::envmap::{BadPixelCounts, EnvMap};
use crate::median_cut::DirectionalLight;
use glam::DVec3;
use rayon::prelude::*;
use std::f64::consts::PI;
use thiserror::Error;

/// The cube faces: (major axis, s axis, t axis), OpenGL cube-map layout.
const FACES: [(DVec3, DVec3, DVec3); 6] = [
    (DVec3::X, DVec3::NEG_Z, DVec3::NEG_Y),
    (DVec3::NEG_X, DVec3::Z, DVec3::NEG_Y),
    (DVec3::Y, DVec3::X, DVec3::Z),
    (DVec3::NEG_Y, DVec3::X, DVec3::NEG_Z),
    (DVec3::Z, DVec3::X, DVec3::NEG_Y),
    (DVec3::NEG_Z, DVec3::NEG_X, DVec3::NEG_Y),
];

/// The default sub-pixel count aims for at least this many sub-pixels across a texel's
/// narrowest extent at the equator (where equirect pixels are largest).
pub const SUBPIXELS_PER_TEXEL: usize = 64;

/// The most sub-pixels per pixel side the default picks (the work grows as s²).
const MAX_DEFAULT_SUBSAMPLES: usize = 8;

/// Rows per band of the parallel sum (fixed, so the reduction order never changes).
const ROWS_PER_BAND: usize = 8;

#[derive(Debug, Error, Clone, PartialEq)]
pub enum CubeLightsError {
    #[error("cube face resolution must be ≥ 1 (got 0)")]
    ZeroFaceResolution,
    #[error("sub-samples per pixel side must be ≥ 1 (got 0)")]
    ZeroSubsamples,
    #[error(
        "a shading cube of {shading}² texels per face does not divide into the {face}² texels of the visibility cube: use a multiple of {face}"
    )]
    ShadingNotAMultiple { face: usize, shading: usize },
    #[error("environment map has bad pixels ({0}); sanitize it first")]
    BadPixels(BadPixelCounts),
}

/// Which cube texel a direction falls in: (face, i, j), and its light index.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CubeTexel {
    pub face: usize,
    pub i: usize,
    pub j: usize,
}

impl CubeTexel {
    /// The index of this texel's light in [`cube_face_lights`]'s output.
    pub fn index(&self, face_resolution: usize) -> usize {
        (self.face * face_resolution + self.j) * face_resolution + self.i
    }
}

/// The texel of an `n × n`-per-face cube containing direction `w` (need not be unit length,
/// must be non-zero).
pub fn cube_texel(w: DVec3, n: usize) -> CubeTexel {
    let abs = w.abs();
    let face = if abs.x >= abs.y && abs.x >= abs.z {
        if w.x >= 0.0 { 0 } else { 1 }
    } else if abs.y >= abs.z {
        if w.y >= 0.0 { 2 } else { 3 }
    } else if w.z >= 0.0 {
        4
    } else {
        5
    };
    let (major, s_axis, t_axis) = FACES[face];
    let m = w.dot(major);
    let cell = |c: f64| (((c / m + 1.0) * 0.5 * n as f64) as usize).min(n - 1);
    CubeTexel {
        face,
        i: cell(w.dot(s_axis)),
        j: cell(w.dot(t_axis)),
    }
}

/// The (non-normalized) direction of face point (a, b) ∈ [−1, 1]².
fn face_point(face: usize, a: f64, b: f64) -> DVec3 {
    let (major, s_axis, t_axis) = FACES[face];
    major + a * s_axis + b * t_axis
}

/// Unit direction of the center of texel `t`.
pub fn texel_center_direction(t: CubeTexel, n: usize) -> DVec3 {
    let c = |k: usize| 2.0 * (k as f64 + 0.5) / n as f64 - 1.0;
    face_point(t.face, c(t.i), c(t.j)).normalize()
}

/// The four corner directions of texel `t` (unit), in order around the texel.
pub fn texel_corner_directions(t: CubeTexel, n: usize) -> [DVec3; 4] {
    let e = |k: usize| 2.0 * k as f64 / n as f64 - 1.0;
    let (a0, a1, b0, b1) = (e(t.i), e(t.i + 1), e(t.j), e(t.j + 1));
    [(a0, b0), (a1, b0), (a1, b1), (a0, b1)].map(|(a, b)| face_point(t.face, a, b).normalize())
}

/// `6 n²` lights, one per cube texel (index order of [`CubeTexel::index`]), with the default
/// sub-sampling ([`default_subsamples`]).
pub fn cube_face_lights(
    map: &EnvMap,
    face_resolution: usize,
) -> Result<Vec<DirectionalLight>, CubeLightsError> {
    if face_resolution == 0 {
        return Err(CubeLightsError::ZeroFaceResolution);
    }
    let s = default_subsamples(map.width(), face_resolution);
    cube_face_lights_subsampled(map, face_resolution, s)
}

/// Sub-pixels per pixel side so that a texel spans ≥ [`SUBPIXELS_PER_TEXEL`] sub-pixels at the
/// equator (texel ≈ (π/2)/n wide, pixel 2π/width wide), clamped to 1..=8.
pub fn default_subsamples(map_width: usize, face_resolution: usize) -> usize {
    let pixels_per_texel = map_width as f64 / (4.0 * face_resolution.max(1) as f64);
    ((SUBPIXELS_PER_TEXEL as f64 / pixels_per_texel).ceil() as usize)
        .clamp(1, MAX_DEFAULT_SUBSAMPLES)
}

/// As [`cube_face_lights`] with `subsamples × subsamples` sub-pixels per map pixel.
pub fn cube_face_lights_subsampled(
    map: &EnvMap,
    face_resolution: usize,
    subsamples: usize,
) -> Result<Vec<DirectionalLight>, CubeLightsError> {
    let n = face_resolution;
    if n == 0 {
        return Err(CubeLightsError::ZeroFaceResolution);
    }
    if subsamples == 0 {
        return Err(CubeLightsError::ZeroSubsamples);
    }
    let bad = map.bad_pixels();
    if bad.total() > 0 {
        return Err(CubeLightsError::BadPixels(bad));
    }
    let power = texel_powers(map, n, subsamples);
    Ok(power
        .into_iter()
        .enumerate()
        .map(|(k, power)| {
            let (face, rest) = (k / (n * n), k % (n * n));
            let t = CubeTexel {
                face,
                i: rest % n,
                j: rest / n,
            };
            DirectionalLight {
                direction: texel_center_direction(t, n),
                power,
            }
        })
        .collect())
}

/// One azimuth slice of the map: its center's (sin φ, cos φ), width Δφ and pixel column.
struct ColumnSegment {
    sin_phi: f64,
    cos_phi: f64,
    dphi: f64,
    pixel: usize,
}

/// The map's azimuth range cut at every sub-pixel column edge AND at every meridian that is a
/// texel edge of a side face (±X, ±Z: the edges `a = const` there are meridians). Binning by
/// slice centers then never straddles those texel edges, which would otherwise alias with
/// the pixel columns (a systematic error of up to half a column per texel edge).
fn column_segments(width: usize, s: usize, n: usize) -> Vec<ColumnSegment> {
    let sub_w = width * s;
    let mut edges: Vec<f64> = (0..=sub_w).map(|k| k as f64 / sub_w as f64).collect();
    for face in [0, 1, 4, 5] {
        for i in 0..=n {
            let a = 2.0 * i as f64 / n as f64 - 1.0;
            edges.push(crate::envmap::direction_to_uv(face_point(face, a, 0.0)).0);
        }
    }
    edges.sort_by(f64::total_cmp);
    edges.dedup_by(|b, a| *b - *a < 1e-14);
    edges
        .windows(2)
        .map(|e| {
            let mid = 0.5 * (e[0] + e[1]);
            let (sin_phi, cos_phi) = (2.0 * PI * (mid - 0.5)).sin_cos();
            ColumnSegment {
                sin_phi,
                cos_phi,
                dphi: 2.0 * PI * (e[1] - e[0]),
                pixel: ((mid * width as f64) as usize).min(width - 1),
            }
        })
        .collect()
}

/// ∫ L dω per texel: every sub-pixel's exact solid angle, times its pixel's radiance, binned.
fn texel_powers(map: &EnvMap, n: usize, s: usize) -> Vec<[f64; 3]> {
    let (w, h) = (map.width(), map.height());
    let texels = 6 * n * n;
    if w == 0 || h == 0 {
        return vec![[0.0; 3]; texels];
    }
    let sub_h = h * s;
    let columns = column_segments(w, s, n);
    let bands: Vec<Vec<[f64; 3]>> = (0..h.div_ceil(ROWS_PER_BAND))
        .into_par_iter()
        .map(|band| {
            let mut acc = vec![[0.0f64; 3]; texels];
            let rows = band * ROWS_PER_BAND..((band + 1) * ROWS_PER_BAND).min(h);
            for y in rows {
                let row = &map.pixels()[y * w..(y + 1) * w];
                for sy in y * s..(y + 1) * s {
                    let (t0, t1) = (
                        PI * sy as f64 / sub_h as f64,
                        PI * (sy + 1) as f64 / sub_h as f64,
                    );
                    // cos t0 − cos t1 without cancellation (as envmap::row_solid_angle).
                    let dcos = 2.0 * (0.5 * (t0 + t1)).sin() * (0.5 * (t1 - t0)).sin();
                    let (st, ct) = (0.5 * (t0 + t1)).sin_cos();
                    for col in &columns {
                        let p = row[col.pixel];
                        let dir = DVec3::new(st * col.sin_phi, ct, -st * col.cos_phi);
                        let da = col.dphi * dcos;
                        let a = &mut acc[cube_texel(dir, n).index(n)];
                        for c in 0..3 {
                            a[c] += da * p[c] as f64;
                        }
                    }
                }
            }
            acc
        })
        .collect();
    let mut total = vec![[0.0f64; 3]; texels];
    for band in &bands {
        for (t, b) in total.iter_mut().zip(band) {
            for c in 0..3 {
                t[c] += b[c];
            }
        }
    }
    total
}

/// Closed-form solid angle of texel `t`: the area on the unit sphere of the face rectangle
/// `[a0, a1] × [b0, b1]` at distance 1 is `F(a1,b1) − F(a0,b1) − F(a1,b0) + F(a0,b0)` with
/// `F(a, b) = atan2(a b, √(a² + b² + 1))`.
pub fn cube_texel_solid_angle(t: CubeTexel, n: usize) -> f64 {
    let e = |k: usize| 2.0 * k as f64 / n as f64 - 1.0;
    let f = |a: f64, b: f64| (a * b).atan2((a * a + b * b + 1.0).sqrt());
    let (a0, a1, b0, b1) = (e(t.i), e(t.i + 1), e(t.j), e(t.j + 1));
    f(a1, b1) - f(a0, b1) - f(a1, b0) + f(a0, b0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::envmap::{direction_to_uv, pixel_direction};

    /// A deterministic pseudo-random unit direction (uniform on the sphere), no crate needed.
    fn random_direction(k: u64) -> DVec3 {
        let hash = |x: u64| {
            let mut z = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
        };
        let (u, v) = (hash(2 * k), hash(2 * k + 1));
        let y = 1.0 - 2.0 * u;
        let r = (1.0 - y * y).max(0.0).sqrt();
        let (sp, cp) = (2.0 * PI * v).sin_cos();
        DVec3::new(r * cp, y, r * sp)
    }

    fn all_texels(n: usize) -> impl Iterator<Item = CubeTexel> {
        (0..6).flat_map(move |face| {
            (0..n).flat_map(move |j| (0..n).map(move |i| CubeTexel { face, i, j }))
        })
    }

    /// Independent containment test: `w` is inside the spherical quad of the texel's corner
    /// directions iff it is on the inner side of all four great-circle edges (`margin` > 0
    /// demands clearance, < 0 tolerates points on an edge).
    fn quad_contains(t: CubeTexel, n: usize, w: DVec3, margin: f64) -> bool {
        let c = texel_corner_directions(t, n);
        let center = c.iter().copied().sum::<DVec3>();
        (0..4).all(|k| {
            let normal = c[k].cross(c[(k + 1) % 4]).normalize();
            let side = normal.dot(center).signum();
            side * normal.dot(w) > margin
        })
    }

    /// A smooth sky with a sun, so every channel and texel gets something different.
    fn test_sky(width: usize) -> EnvMap {
        let sun = DVec3::new(0.3, 0.8, -0.5).normalize();
        let mut map = EnvMap::from_fn(width, width / 2, |w| {
            let sky = 0.5 + 0.4 * w.y + 0.1 * w.x * w.z;
            let glow = 20.0 * (-40.0 * (1.0 - w.dot(sun))).exp();
            [sky + glow, 0.8 * sky + 0.5 * glow, 1.2 * sky]
        });
        // One very bright pixel on top.
        let mut px = map.pixels().to_vec();
        px[(width / 7) * width + width * 4 / 5] = [5e4, 4e4, 3e4];
        map = EnvMap::from_pixels(width, width / 2, px);
        map
    }

    #[test]
    fn total_power_equals_the_map_integral() {
        let map = test_sky(256);
        let want = map.integral();
        for (n, s) in [(32, 1), (32, 3), (5, 1), (7, 4), (1, 2)] {
            let lights = cube_face_lights_subsampled(&map, n, s).unwrap();
            assert_eq!(lights.len(), 6 * n * n);
            let total: [f64; 3] = std::array::from_fn(|c| lights.iter().map(|l| l.power[c]).sum());
            let rel = (0..3)
                .map(|c| ((total[c] - want[c]) / want[c]).abs())
                .fold(0.0, f64::max);
            eprintln!("n={n} s={s}: Σ power {total:?} vs ∫L dω {want:?}, max rel diff {rel:.2e}");
            assert!(rel < 1e-12, "n={n} s={s}: {rel}");
        }
    }

    #[test]
    fn closed_form_texel_solid_angles_sum_to_four_pi() {
        for n in [1, 3, 32] {
            let total: f64 = all_texels(n).map(|t| cube_texel_solid_angle(t, n)).sum();
            eprintln!(
                "n={n}: Σ closed-form texel solid angles = {total:.15} (4π = {:.15})",
                4.0 * PI
            );
            assert!((total - 4.0 * PI).abs() < 1e-12);
        }
        // One face texel at n = 1 is a sixth of the sphere; a far-from-center texel is smaller.
        let face = cube_texel_solid_angle(
            CubeTexel {
                face: 2,
                i: 0,
                j: 0,
            },
            1,
        );
        assert!((face - 4.0 * PI / 6.0).abs() < 1e-14);
        let center = cube_texel_solid_angle(
            CubeTexel {
                face: 0,
                i: 16,
                j: 16,
            },
            32,
        );
        let corner = cube_texel_solid_angle(
            CubeTexel {
                face: 0,
                i: 0,
                j: 0,
            },
            32,
        );
        eprintln!("n=32 texel solid angle: center {center:.4e}, corner {corner:.4e} sr");
        // Small-texel limit: dA cos³ at distance 1 = (2/32)² at the center, (2/32)²/3^{3/2} at a corner.
        assert!((center / (2.0f64 / 32.0).powi(2) - 1.0).abs() < 0.01);
        assert!((corner / ((2.0f64 / 32.0).powi(2) / 3f64.powf(1.5)) - 1.0).abs() < 0.1);
    }

    /// Binning error: a constant map's per-texel power / L against the closed-form solid angle.
    #[test]
    fn constant_map_texels_match_the_closed_form_solid_angle() {
        let (width, n) = (1024, 32);
        let map = EnvMap::from_pixels(width, width / 2, vec![[1.0; 3]; width * width / 2]);
        let exact: Vec<f64> = all_texels(n)
            .map(|t| cube_texel_solid_angle(t, n))
            .collect();
        let default_s = default_subsamples(width, n);
        eprintln!("1024×512 map, n = {n}: default subsamples = {default_s}");
        let mut previous = f64::INFINITY;
        for s in [1, 2, 4, 8] {
            let lights = cube_face_lights_subsampled(&map, n, s).unwrap();
            let (mut max_rel, mut sq, mut worst) = (0.0f64, 0.0, 0);
            for (k, (l, &e)) in lights.iter().zip(&exact).enumerate() {
                let rel = (l.power[0] - e) / e;
                if rel.abs() > max_rel {
                    (max_rel, worst) = (rel.abs(), k);
                }
                sq += rel * rel;
            }
            let rms = (sq / exact.len() as f64).sqrt();
            let t = all_texels(n).nth(worst).unwrap();
            eprintln!(
                "  s = {s} ({}×{} sub-pixels): texel solid angle max rel err {max_rel:.3e} (at {t:?}), rms {rms:.3e}",
                width * s,
                width * s / 2
            );
            // Binning error shrinks with the sub-pixel size (≈ 1/s).
            assert!(max_rel < 0.25 / s as f64, "s={s}: {max_rel}");
            assert!(max_rel < previous);
            previous = max_rel;
        }
        // The default (what cube_face_lights uses) keeps every texel within 1 %.
        let lights = cube_face_lights(&map, n).unwrap();
        let max_rel = lights
            .iter()
            .zip(&exact)
            .map(|(l, &e)| ((l.power[0] - e) / e).abs())
            .fold(0.0, f64::max);
        eprintln!("  default: max rel err {max_rel:.3e}");
        assert!(max_rel < 0.01);
    }

    #[test]
    fn a_one_pixel_sun_lands_in_the_texel_containing_it() {
        let (width, height, n) = (1024, 512, 32);
        // Suns at a few texel centers (pixel well inside its texel) on different faces.
        for (k, t) in [
            CubeTexel {
                face: 0,
                i: 3,
                j: 17,
            },
            CubeTexel {
                face: 2,
                i: 16,
                j: 16,
            },
            CubeTexel {
                face: 3,
                i: 30,
                j: 1,
            },
            CubeTexel {
                face: 5,
                i: 9,
                j: 22,
            },
        ]
        .into_iter()
        .enumerate()
        {
            let (u, v) = direction_to_uv(texel_center_direction(t, n));
            let (x, y) = ((u * width as f64) as usize, (v * height as f64) as usize);
            let sun = pixel_direction(x, y, width, height);
            // The texel found by the independent great-circle test, among all 6144.
            let containing: Vec<usize> = all_texels(n)
                .filter(|&c| quad_contains(c, n, sun, 0.0))
                .map(|c| c.index(n))
                .collect();
            assert_eq!(containing.len(), 1, "sun {k}");
            let mut px = vec![[0.0f32; 3]; width * height];
            px[y * width + x] = [1e5, 2e5, 3e5];
            let map = EnvMap::from_pixels(width, height, px);
            let want = map.integral();
            let lights = cube_face_lights(&map, n).unwrap();
            let lit: Vec<usize> = (0..lights.len())
                .filter(|&i| lights[i].power[0] > 0.0)
                .collect();
            let got = lights[containing[0]].power;
            eprintln!(
                "sun {k} at pixel ({x},{y}): lit texels {lit:?}, containing {containing:?}, power {got:?} vs {want:?}"
            );
            assert_eq!(lit, containing);
            for c in 0..3 {
                assert!((got[c] - want[c]).abs() <= 1e-12 * want[c]);
            }
        }
    }

    #[test]
    fn a_sun_pixel_on_a_texel_corner_splits_among_its_neighbours() {
        let (width, height, n) = (1024, 512, 32);
        // The pixel holding a corner shared by 4 texels of face +X (texels i 4|5, j 10|11),
        // a corner that is not on a pixel edge.
        let e = |k: usize| 2.0 * k as f64 / n as f64 - 1.0;
        let corner = face_point(0, e(5), e(11)).normalize();
        let (u, v) = direction_to_uv(corner);
        let (x, y) = ((u * width as f64) as usize, (v * height as f64) as usize);
        let mut px = vec![[0.0f32; 3]; width * height];
        px[y * width + x] = [1.0, 1.0, 1.0];
        let map = EnvMap::from_pixels(width, height, px);
        let lights = cube_face_lights_subsampled(&map, n, 8).unwrap();
        let lit: Vec<(usize, f64)> = (0..lights.len())
            .filter(|&i| lights[i].power[0] > 0.0)
            .map(|i| (i, lights[i].power[0] / map.integral()[0]))
            .collect();
        eprintln!("corner pixel ({x},{y}) split (texel, fraction): {lit:?}");
        let e = |k: usize| k as f64;
        let expected: Vec<usize> = [(4, 10), (5, 10), (4, 11), (5, 11)]
            .map(|(i, j)| CubeTexel { face: 0, i, j }.index(n))
            .to_vec();
        assert!(lit.iter().all(|l| expected.contains(&l.0)), "{expected:?}");
        let got: Vec<usize> = lit.iter().map(|l| l.0).collect();
        assert_eq!(got, expected);
        // Independent fractions: a fine area-uniform grid over the pixel (uniform in φ and in
        // cos θ), each point classified by the great-circle test.
        let grid = 400;
        let mut counts = [0usize; 4];
        for gy in 0..grid {
            let (c0, c1) = (
                (PI * e(y) / height as f64).cos(),
                (PI * (e(y) + 1.0) / height as f64).cos(),
            );
            let cos_theta = c0 + (c1 - c0) * (gy as f64 + 0.5) / grid as f64;
            let v = cos_theta.acos() / PI;
            for gx in 0..grid {
                let u = (e(x) + (gx as f64 + 0.5) / grid as f64) / width as f64;
                let p = crate::envmap::uv_to_direction(u, v);
                let inside: Vec<usize> = (0..4)
                    .filter(|&k| quad_contains(all_texels(n).nth(expected[k]).unwrap(), n, p, 0.0))
                    .collect();
                assert_eq!(inside.len(), 1);
                counts[inside[0]] += 1;
            }
        }
        for k in 0..4 {
            let reference = counts[k] as f64 / (grid * grid) as f64;
            eprintln!(
                "  texel {}: fraction {:.4} vs fine-grid {reference:.4}",
                lit[k].0, lit[k].1
            );
            assert!((lit[k].1 - reference).abs() < 0.03);
        }
        let sum: f64 = lit.iter().map(|l| l.1).sum();
        assert!((sum - 1.0).abs() < 1e-12);
    }

    #[test]
    fn every_direction_is_in_exactly_one_texel() {
        for n in [1, 4, 32] {
            let count = if n == 32 { 500 } else { 5000 };
            for k in 0..count {
                let w = random_direction(k);
                let containing: Vec<CubeTexel> = all_texels(n)
                    .filter(|&t| quad_contains(t, n, w, 0.0))
                    .collect();
                assert_eq!(containing.len(), 1, "n={n}, {w}");
                assert_eq!(cube_texel(w, n), containing[0], "n={n}, {w}");
                assert_eq!(cube_texel(w * 7.5, n), containing[0], "scale invariance");
            }
            eprintln!(
                "n={n}: {count} random directions, each inside exactly one texel quad = cube_texel"
            );
        }
        // Edges and corners of the cube: one texel, whose quad holds the direction (on its edge).
        for w in [
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::ONE,
            DVec3::new(-1.0, 0.0, 1.0),
            DVec3::NEG_Y,
        ] {
            let t = cube_texel(w, 4);
            assert!(t.i < 4 && t.j < 4);
            assert!(quad_contains(t, 4, w.normalize(), -1e-12), "{w} → {t:?}");
        }
    }

    #[test]
    fn light_directions_are_unit_texel_centers() {
        let n = 32;
        let map = test_sky(64);
        let lights = cube_face_lights(&map, n).unwrap();
        let mut max_len_err = 0.0f64;
        for (k, l) in lights.iter().enumerate() {
            max_len_err = max_len_err.max((l.direction.length() - 1.0).abs());
            assert_eq!(cube_texel(l.direction, n).index(n), k);
        }
        eprintln!("6144 light directions: max | |ω| − 1 | = {max_len_err:.2e}");
        assert!(max_len_err < 1e-15);
    }

    #[test]
    fn deterministic_across_thread_counts_and_timed() {
        let map = test_sky(1024);
        let start = std::time::Instant::now();
        let a = cube_face_lights(&map, 32).unwrap();
        let ms = start.elapsed().as_secs_f64() * 1e3;
        eprintln!(
            "1024×512 → 6144 cube lights (s = {}): {ms:.1} ms ({} rayon threads, test profile)",
            default_subsamples(1024, 32),
            rayon::current_num_threads()
        );
        let b = cube_face_lights(&map, 32).unwrap();
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        let c = pool.install(|| cube_face_lights(&map, 32).unwrap());
        assert_eq!(a, b);
        assert_eq!(a, c);
    }

    #[test]
    fn bad_input_is_a_typed_error() {
        let map = test_sky(64);
        assert_eq!(
            cube_face_lights(&map, 0),
            Err(CubeLightsError::ZeroFaceResolution)
        );
        assert_eq!(
            cube_face_lights_subsampled(&map, 4, 0),
            Err(CubeLightsError::ZeroSubsamples)
        );
        let mut px = map.pixels().to_vec();
        px[5][1] = f32::NAN;
        let bad = EnvMap::from_pixels(64, 32, px);
        assert!(
            matches!(cube_face_lights(&bad, 4), Err(CubeLightsError::BadPixels(c)) if c.nan == 1)
        );
    }
}
