//! The precompute light sets ([`LightSpec`]s, in the environment map's frame) as the runtime's
//! [`EnvLight`]s in the hair's world frame.
//!
//! The map's frame (`precompute/src/envmap.rs`) has +Y up and its image center toward −Z. The
//! world is the hair file's: Y-up (front +z) or Z-up (front +y, Yuksel's models; see
//! `runtime/src/camera.rs`). The environment's up goes to the world's up, and its image center
//! goes behind the hair as the default front camera sees it (the picture's right half to the
//! camera's right), so a front view shows the map's center behind the hair in both worlds.

use glam::{DVec3, Vec3};
use strandlight_precompute::env_lights::LightSpec;
use strandlight_runtime::camera::UpAxis;
use strandlight_runtime::env_light::EnvLight;

/// A direction of the map's frame in the world of a hair file with `up`. A rotation
/// (determinant +1): the identity for Y-up; for Z-up (x, y, z) ↦ (−x, z, y).
pub fn env_to_world(d: DVec3, up: UpAxis) -> DVec3 {
    match up {
        UpAxis::Y => d,
        UpAxis::Z => DVec3::new(-d.x, d.z, d.y),
    }
}

/// The inverse of [`env_to_world`]: a world direction in the map's frame (what a background
/// seen along it shows).
pub fn world_to_env(w: DVec3, up: UpAxis) -> DVec3 {
    match up {
        UpAxis::Y => w,
        UpAxis::Z => DVec3::new(-w.x, w.z, w.y),
    }
}

/// The runtime lights of a set, with their directions in the world of `up`.
pub fn to_env_lights(specs: &[LightSpec], up: UpAxis) -> Vec<EnvLight> {
    specs
        .iter()
        .map(|s| {
            let direction: Vec3 = env_to_world(s.direction, up).as_vec3();
            let rgb = s.rgb.map(|c| c as f32);
            let light = match (s.lambda, s.shadowed_from) {
                (Some(lambda), _) => EnvLight::srbf(direction, lambda as f32, rgb),
                (None, None) => EnvLight::extended(direction, rgb, s.angular_variance as f32),
                (None, Some(from)) => EnvLight::directional_shadowed_from(
                    direction,
                    rgb,
                    env_to_world(from, up).as_vec3(),
                ),
            };
            EnvLight {
                stands_for_region: s.stands_for_region,
                ..light
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use strandlight_precompute::env_lights::{median_cut_lights, reference_lights, total_power};
    use strandlight_precompute::procedural_env;

    #[test]
    fn the_map_is_upright_and_its_center_is_behind_the_hair() {
        for up in [UpAxis::Y, UpAxis::Z] {
            let w = |d: DVec3| env_to_world(d, up).as_vec3();
            let world_up = up.vector();
            let front = up.toward_front();
            // The default camera looks from `front` toward the hair; its right is forward × up.
            let right = (-front).cross(world_up);
            assert_eq!(w(DVec3::Y), world_up, "{up:?}");
            assert_eq!(
                w(DVec3::NEG_Z),
                -front,
                "{up:?}: image center behind the hair"
            );
            assert_eq!(
                w(DVec3::X),
                right,
                "{up:?}: the image's right (u = ¾, +X) to the camera's right"
            );
            // A proper rotation: right-handed basis stays right-handed.
            let (x, y, z) = (
                env_to_world(DVec3::X, up),
                env_to_world(DVec3::Y, up),
                env_to_world(DVec3::Z, up),
            );
            assert!((x.cross(y).dot(z) - 1.0).abs() < 1e-12);
        }
    }

    #[test]
    fn world_to_env_undoes_env_to_world() {
        for up in [UpAxis::Y, UpAxis::Z] {
            for d in [
                DVec3::X,
                DVec3::Y,
                DVec3::Z,
                DVec3::new(0.3, -0.5, 0.81).normalize(),
            ] {
                assert!((world_to_env(env_to_world(d, up), up) - d).length() < 1e-12);
            }
        }
    }

    #[test]
    fn conversion_keeps_power_and_kind() {
        let map = procedural_env::by_name("studio", 256).unwrap();
        let reference = reference_lights(&map, 4, 0.0, &Default::default()).unwrap();
        let baseline = median_cut_lights(&map, 32, 0.0);
        for (specs, name) in [(&reference, "reference"), (&baseline, "median cut")] {
            let lights = to_env_lights(specs, UpAxis::Z);
            let want = total_power(specs);
            let got = lights.iter().fold([0.0f64; 3], |a, l| {
                let p = l.power();
                std::array::from_fn(|c| a[c] + p[c] as f64)
            });
            for c in 0..3 {
                // f32 rounding of each light's value: ≤ 2⁻²⁴ relative, summed.
                assert!(
                    (got[c] - want[c]).abs() <= 1e-6 * want[c],
                    "{name}: {got:?} vs {want:?}"
                );
            }
            assert!(lights.iter().all(|l| l.lambda.is_none()));
        }
        let srbf = [LightSpec {
            direction: DVec3::new(0.0, 0.6, 0.8),
            lambda: Some(32.0),
            rgb: [1.0, 2.0, 3.0],
            shadowed_from: None,
            angular_variance: 0.0,
            stands_for_region: false,
        }];
        let l = to_env_lights(&srbf, UpAxis::Y)[0];
        assert_eq!(l.lambda, Some(32.0));
        assert_eq!(l.rgb, [1.0, 2.0, 3.0]);
        // EnvLight::power and LightSpec::power agree on the SRBF integral 2π/λ(1 − e^{−2λ}).
        assert!((l.power()[2] as f64 - srbf[0].power()[2]).abs() < 1e-6);
    }
}
