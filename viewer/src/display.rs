//! From a linear frame to the window's pixels: exposure (automatic by default, so a first image is
//! never black), the environment drawn behind the hair, and the PNG's tonemap curve
//! ([`PNG_TONEMAP`](strandlight_tables::image_out::PNG_TONEMAP)) so the window and a screenshot
//! show the same thing.

use crate::frame::LinearImage;
use glam::{Quat, Vec4};
use strandlight_precompute::envmap::EnvMap;
use strandlight_runtime::camera::{Camera, UpAxis};
use strandlight_scene::image_metrics::HAIR_ALPHA;
use strandlight_scene::world_lights::world_to_env;
use strandlight_tables::colour::luminance_f32;
use strandlight_tables::image_out::tonemap_channel;

/// Automatic exposure puts the hair's 90th-percentile radiance here (Reinhard: 2/3 of white).
const AUTO_TARGET: f32 = 2.0;

/// Stops that bring the 90th percentile of the hair's (un-premultiplied) luminance to
/// [`AUTO_TARGET`]; 0 for an image without lit hair.
pub fn auto_exposure_stops(image: &LinearImage) -> f32 {
    let mut luminance: Vec<f32> = image
        .pixels
        .iter()
        .filter(|p| p[3] > HAIR_ALPHA)
        .map(|p| luminance_f32([p[0], p[1], p[2]]) / p[3])
        .filter(|l| l.is_finite() && *l > 0.0)
        .collect();
    if luminance.is_empty() {
        return 0.0;
    }
    let k = (luminance.len() * 9 / 10).min(luminance.len() - 1);
    let (_, p90, _) = luminance.select_nth_unstable_by(k, f32::total_cmp);
    (AUTO_TARGET / *p90).log2().clamp(-20.0, 20.0)
}

/// Radiance of the environment seen through every pixel of `camera` at `size` (the map turned
/// `rotation_deg` about `up`, as the lights are).
pub fn background(
    map: &EnvMap,
    camera: &Camera,
    size: [u32; 2],
    up: UpAxis,
    rotation_deg: f32,
) -> Vec<[f32; 3]> {
    let [w, h] = size;
    let clip_to_world = (camera.projection_matrix(w as f32 / h as f32) * camera.view()).inverse();
    let unturn = Quat::from_axis_angle(up.vector(), -rotation_deg.to_radians());
    let mut out = Vec::with_capacity(w as usize * h as usize);
    for y in 0..h {
        for x in 0..w {
            let ndc_x = 2.0 * (x as f32 + 0.5) / w as f32 - 1.0;
            let ndc_y = 1.0 - 2.0 * (y as f32 + 0.5) / h as f32;
            let far = clip_to_world * Vec4::new(ndc_x, ndc_y, 1.0, 1.0);
            let near = clip_to_world * Vec4::new(ndc_x, ndc_y, 0.0, 1.0);
            let ray = far.truncate() / far.w - near.truncate() / near.w;
            let world = unturn * ray.normalize_or_zero();
            out.push(map.radiance(world_to_env(world.as_dvec3(), up)));
        }
    }
    out
}

/// The hair scaled by `2^stops` over the (equally exposed) background, as linear RGB + alpha 1
/// where there is a background.
pub fn composite(
    image: &LinearImage,
    stops: f32,
    background: Option<&[[f32; 3]]>,
) -> Vec<[f32; 4]> {
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
    use glam::{DVec3, Vec3};
    use strandlight_runtime::camera::Projection;

    #[test]
    fn auto_exposure_lands_the_bright_hair_mid_curve_and_leaves_empty_images_alone() {
        let mut pixels = vec![[0.0; 4]; 100];
        for (i, p) in pixels.iter_mut().enumerate().take(50) {
            let v = 0.001 * (i + 1) as f32;
            *p = [0.5 * v, 0.5 * v, 0.5 * v, 0.5];
        }
        let image = LinearImage {
            width: 10,
            height: 10,
            pixels,
        };
        let stops = auto_exposure_stops(&image);
        // 90th percentile of the 50 lit pixels is the 46th: radiance 0.046.
        assert!((stops - (2.0f32 / 0.046).log2()).abs() < 1e-4, "{stops}");
        let empty = LinearImage {
            width: 1,
            height: 1,
            pixels: vec![[0.0; 4]],
        };
        assert_eq!(auto_exposure_stops(&empty), 0.0);
    }

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
    fn composite_puts_the_hair_over_the_background_with_one_exposure() {
        let image = LinearImage {
            width: 2,
            height: 1,
            pixels: vec![[0.5, 0.5, 0.5, 0.5], [0.0; 4]],
        };
        let out = composite(&image, 1.0, Some(&[[1.0; 3], [3.0; 3]]));
        assert_eq!(out, vec![[2.0, 2.0, 2.0, 1.0], [6.0, 6.0, 6.0, 1.0]]);
        assert_eq!(composite(&image, 0.0, None)[1], [0.0, 0.0, 0.0, 1.0]);
    }
}
