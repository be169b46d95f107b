//! The window's picture on the CPU: the backdrop drawn behind the hair (uploaded to the GPU's
//! display pass, `gpu_display`), and the composite and tonemap a screenshot's PNG is made with
//! (exposure is `strandlight_scene::exposure`'s, metered on the hair; the curve is
//! [`PNG_TONEMAP`](strandlight_tables::image_out::PNG_TONEMAP)), so the window and a screenshot
//! show the same thing. The display pass is tested against [`composite`] and [`to_rgba8`].

use crate::recompute::Backdrop;
use glam::{DVec3, Vec4};
use strandlight_precompute::envmap::EnvMap;
use strandlight_runtime::camera::{Camera, UpAxis};
use strandlight_scene::env_orientation::EnvOrientation;
use strandlight_scene::image_metrics::Image;
use strandlight_tables::image_out::tonemap_channel;

/// The world direction through each pixel of `camera` at `size`, in the map's frame (the map
/// turned `rotation_deg` about `up`, as the lights are).
fn pixel_directions(
    camera: &Camera,
    size: [u32; 2],
    up: UpAxis,
    rotation_deg: f32,
) -> impl Iterator<Item = DVec3> {
    let [w, h] = size;
    let clip_to_world = (camera.projection_matrix(w as f32 / h as f32) * camera.view()).inverse();
    let orientation = EnvOrientation::new(up, rotation_deg as f64);
    (0..h).flat_map(move |y| {
        (0..w).map(move |x| {
            let ndc_x = 2.0 * (x as f32 + 0.5) / w as f32 - 1.0;
            let ndc_y = 1.0 - 2.0 * (y as f32 + 0.5) / h as f32;
            let far = clip_to_world * Vec4::new(ndc_x, ndc_y, 1.0, 1.0);
            let near = clip_to_world * Vec4::new(ndc_x, ndc_y, 0.0, 1.0);
            let ray = far.truncate() / far.w - near.truncate() / near.w;
            orientation.to_env(ray.normalize_or_zero().as_dvec3())
        })
    })
}

/// Radiance of the environment seen through every pixel of `camera` at `size`.
pub fn background(
    map: &EnvMap,
    camera: &Camera,
    size: [u32; 2],
    up: UpAxis,
    rotation_deg: f32,
) -> Vec<[f32; 3]> {
    pixel_directions(camera, size, up, rotation_deg)
        .map(|d| map.radiance(d))
        .collect()
}

/// The soft backdrop sits this many stops under the hair's exposure.
pub const SOFT_BACKDROP_STOPS: f32 = -2.0;

/// The soft backdrop's prefiltered map: 64 × 32 pixels, about 6° each, so the sky's gradients
/// stay and its detail (trees, windows, a sun's disc) does not compete with the fibers.
const SOFT_BACKDROP_MAP: [usize; 2] = [64, 32];

/// The map the soft backdrop samples. Computed on a pool of its own: the window's thread must
/// not wait for the global rayon pool while a bake fills it (that stalled the window 4.8 s).
pub fn soft_backdrop_map(map: &EnvMap) -> EnvMap {
    let [w, h] = SOFT_BACKDROP_MAP;
    match rayon::ThreadPoolBuilder::new().num_threads(1).build() {
        Ok(pool) => pool.install(|| map.downsampled(w, h)),
        Err(_) => map.downsampled(w, h),
    }
}

/// What `backdrop` draws behind the hair at the hair's exposure: None for black. `blurred` is
/// [`soft_backdrop_map`] of `map`.
pub fn backdrop_pixels(
    backdrop: Backdrop,
    map: &EnvMap,
    blurred: &EnvMap,
    camera: &Camera,
    size: [u32; 2],
    up: UpAxis,
    rotation_deg: f32,
) -> Option<Vec<[f32; 3]>> {
    match backdrop {
        Backdrop::Black => None,
        Backdrop::Environment => Some(background(map, camera, size, up, rotation_deg)),
        Backdrop::Soft => {
            let dim = SOFT_BACKDROP_STOPS.exp2();
            Some(
                pixel_directions(camera, size, up, rotation_deg)
                    .map(|d| blurred.radiance_bilinear(d).map(|c| dim * c))
                    .collect(),
            )
        }
    }
}

/// The hair scaled by `2^stops` over the (equally exposed) background, as linear RGB + alpha 1
/// where there is a background.
pub fn composite(image: &Image, stops: f32, background: Option<&[[f32; 3]]>) -> Vec<[f32; 4]> {
    let scale = stops.exp2();
    image
        .pixels
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let behind = background.map_or([0.0; 3], |b| b[i]);
            let uncovered = 1.0 - p[3].clamp(0.0, 1.0);
            let c = |k: usize| scale * (p[k] + uncovered * behind[k]);
            [c(0), c(1), c(2), 1.0]
        })
        .collect()
}

/// 8-bit sRGB RGBA through the PNG's tonemap.
pub fn to_rgba8(pixels: &[[f32; 4]]) -> Vec<u8> {
    pixels
        .iter()
        .flat_map(|p| {
            [
                tonemap_channel(p[0]),
                tonemap_channel(p[1]),
                tonemap_channel(p[2]),
                255,
            ]
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;
    use strandlight_runtime::camera::Projection;

    #[test]
    fn the_background_through_the_centre_pixel_is_what_lies_behind_the_target() {
        // A map that is bright only around the map's −Z (its image centre, behind the hair).
        let map = EnvMap::from_fn(64, 32, |d| {
            if d.dot(DVec3::NEG_Z) > 0.99 {
                [5.0; 3]
            } else {
                [0.0; 3]
            }
        });
        let camera = Camera {
            eye: Vec3::new(0.0, 0.0, 3.0),
            target: Vec3::ZERO,
            up: Vec3::Y,
            projection: Projection::Perspective { fov_y: 0.3 },
            near: 0.1,
            far: 10.0,
        };
        let bg = background(&map, &camera, [9, 9], UpAxis::Y, 0.0);
        assert_eq!(bg[4 * 9 + 4], [5.0; 3], "centre sees the map's centre");
        assert_eq!(bg[0], [0.0; 3]);
        // Turned half way round, the bright spot is behind the camera.
        let turned = background(&map, &camera, [9, 9], UpAxis::Y, 180.0);
        assert_eq!(turned[4 * 9 + 4], [0.0; 3]);
    }

    #[test]
    fn the_soft_backdrop_is_the_map_blurred_and_two_stops_darker() {
        let camera = Camera {
            eye: Vec3::new(0.0, 0.0, 3.0),
            target: Vec3::ZERO,
            up: Vec3::Y,
            projection: Projection::Perspective { fov_y: 1.0 },
            near: 0.1,
            far: 10.0,
        };
        let soft = |map: &EnvMap, size: [u32; 2]| {
            let blurred = soft_backdrop_map(map);
            backdrop_pixels(Backdrop::Soft, map, &blurred, &camera, size, UpAxis::Y, 0.0).unwrap()
        };
        // A uniform sky stays uniform, a quarter as bright.
        let uniform = EnvMap::from_fn(256, 128, |_| [3.0, 2.0, 1.0]);
        for p in soft(&uniform, [16, 16]) {
            assert!(
                (p[0] - 0.75).abs() < 1e-5 && (p[2] - 0.25).abs() < 1e-5,
                "{p:?}"
            );
        }
        // A small sun (2.6° wide) straight behind the hair is spread over the blurred map's 5.6°
        // pixels and dimmed two stops: ten times dimmer at the centre or more, but not gone.
        let sun = EnvMap::from_fn(256, 128, |d| {
            if d.dot(DVec3::NEG_Z) > 0.999 {
                [1e4; 3]
            } else {
                [0.0; 3]
            }
        });
        let sharp = background(&sun, &camera, [17, 17], UpAxis::Y, 0.0)[8 * 17 + 8][0];
        let blurred = soft(&sun, [17, 17]);
        let centre = blurred[8 * 17 + 8][0];
        assert_eq!(sharp, 1e4);
        assert!(centre > 0.0 && centre < 0.1 * sharp, "{centre}");
        assert!(
            backdrop_pixels(Backdrop::Black, &sun, &sun, &camera, [4, 4], UpAxis::Y, 0.0).is_none()
        );
    }

    #[test]
    fn composite_puts_the_hair_over_the_background_with_one_exposure() {
        let image = Image {
            width: 2,
            height: 1,
            pixels: vec![[0.5, 0.5, 0.5, 0.5], [0.0; 4]],
        };
        let out = composite(&image, 1.0, Some(&[[1.0; 3], [3.0; 3]]));
        assert_eq!(out, vec![[2.0, 2.0, 2.0, 1.0], [6.0, 6.0, 6.0, 1.0]]);
        assert_eq!(composite(&image, 0.0, None)[1], [0.0, 0.0, 0.0, 1.0]);
    }
}
