//! THE convention that puts an environment map in a hair's world, written once: every light set
//! of every frame (the fit's, the reference's, the median-cut baseline's), the viewer's backdrop
//! and the path tracer's map are placed by [`EnvOrientation`], so no two of them can turn the
//! map opposite ways.
//!
//! The map's frame (`precompute/src/envmap.rs`) has +Y up and its image center toward −Z;
//! precompute keeps everything it makes of a map in that frame. The world is the hair file's:
//! Y-up (front +z) or Z-up (front +y, Yuksel's models; see `runtime/src/camera.rs`). The
//! environment's up goes to the world's up, and its image center goes behind the hair as the
//! default front camera sees it (the picture's right half to the camera's right), so a front
//! view shows the map's center behind the hair in both worlds.
//!
//! **Rotation** (`--rotate DEG`, the viewer's and the page's "rotate map"): the map is turned
//! about its up axis so that what it shows at azimuth φ appears at φ + DEG, φ being the map's
//! azimuth `2π(u − ½)` from its image center (`precompute/src/envmap.rs`): +90° takes the
//! image center (u = ½, −Z) to where the image's right quarter (u = ¾, +X) was. Seen from above
//! (looking down the up axis) that is a clockwise turn, a rotation by −DEG in the right-handed
//! sense about the up axis.

use glam::{DVec3, Vec3};
use strandlight_precompute::env_lights::LightSpec;
use strandlight_runtime::camera::UpAxis;
use strandlight_runtime::env_light::EnvLight;

/// Where an environment map sits in a hair's world.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EnvOrientation {
    /// The hair's up axis, onto which the map's +Y goes.
    pub up: UpAxis,
    /// The map turned about the up axis, degrees (module documentation).
    pub rotation_deg: f64,
}

impl EnvOrientation {
    pub fn new(up: UpAxis, rotation_deg: f64) -> Self {
        Self { up, rotation_deg }
    }

    /// The map upright over a hair with `up`, not turned.
    pub fn upright(up: UpAxis) -> Self {
        Self::new(up, 0.0)
    }

    /// A direction of the map's frame in the hair's world.
    pub fn to_world(&self, d: DVec3) -> DVec3 {
        axes_to_world(turn_about_up(d, self.rotation_deg), self.up)
    }

    /// The inverse of [`Self::to_world`]: a world direction in the map's frame (what a
    /// background seen along it shows).
    pub fn to_env(&self, w: DVec3) -> DVec3 {
        turn_about_up(world_to_axes(w, self.up), -self.rotation_deg)
    }

    /// The runtime lights of a set, with their directions in the hair's world.
    pub fn lights(&self, specs: &[LightSpec]) -> Vec<EnvLight> {
        specs.iter().map(|s| self.light(s)).collect()
    }

    fn light(&self, spec: &LightSpec) -> EnvLight {
        let direction: Vec3 = self.to_world(spec.direction).as_vec3();
        let rgb = spec.rgb.map(|c| c as f32);
        let light = match (spec.lambda, spec.shadowed_from) {
            (Some(lambda), _) => EnvLight::srbf(direction, lambda as f32, rgb),
            (None, None) => EnvLight::extended(direction, rgb, spec.angular_variance as f32),
            (None, Some(from)) => {
                EnvLight::directional_shadowed_from(direction, rgb, self.to_world(from).as_vec3())
            }
        };
        EnvLight {
            stands_for_region: spec.stands_for_region,
            power_share: spec.power_share as f32,
            ..light
        }
    }
}

/// THE rotation: the map's azimuth φ becomes φ + `degrees` (module documentation), about the
/// map's +Y.
fn turn_about_up(w: DVec3, degrees: f64) -> DVec3 {
    let (s, c) = degrees.to_radians().sin_cos();
    DVec3::new(w.x * c - w.z * s, w.y, w.z * c + w.x * s)
}

/// The map's axes in the world of a hair file with `up`. A rotation (determinant +1): the
/// identity for Y-up; for Z-up (x, y, z) ↦ (−x, z, y).
fn axes_to_world(d: DVec3, up: UpAxis) -> DVec3 {
    match up {
        UpAxis::Y => d,
        UpAxis::Z => DVec3::new(-d.x, d.z, d.y),
    }
}

fn world_to_axes(w: DVec3, up: UpAxis) -> DVec3 {
    match up {
        UpAxis::Y => w,
        UpAxis::Z => DVec3::new(-w.x, w.z, w.y),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use strandlight_precompute::env_lights::{median_cut_lights, reference_lights, total_power};
    use strandlight_precompute::envmap::{direction_to_uv, uv_to_direction};
    use strandlight_precompute::procedural_env;

    const UPS: [UpAxis; 2] = [UpAxis::Y, UpAxis::Z];

    #[test]
    fn the_map_is_upright_and_its_center_is_behind_the_hair() {
        for up in UPS {
            let w = |d: DVec3| EnvOrientation::upright(up).to_world(d).as_vec3();
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
            let (x, y, z) = (w(DVec3::X), w(DVec3::Y), w(DVec3::Z));
            assert!((x.cross(y).dot(z) - 1.0).abs() < 1e-6);
        }
    }

    /// The documented convention, checked through the map's own pixel coordinates: turned by
    /// DEG, the world direction that showed the map at azimuth φ + DEG now shows what was at φ.
    #[test]
    fn a_turn_moves_the_maps_azimuth_by_the_angle_in_both_worlds() {
        for up in UPS {
            for degrees in [90.0, 149.0, 211.0, -30.0] {
                let turned = EnvOrientation::new(up, degrees);
                let upright = EnvOrientation::upright(up);
                for (u, v) in [(0.5, 0.4), (0.1, 0.7), (0.93, 0.2)] {
                    let seen = turned.to_world(uv_to_direction(u, v));
                    let shifted = (u + degrees / 360.0).rem_euclid(1.0);
                    let want = upright.to_world(uv_to_direction(shifted, v));
                    assert!(
                        (seen - want).length() < 1e-12,
                        "{up:?} {degrees}°: ({u}, {v}) appears at {seen:?}, not {want:?}"
                    );
                }
            }
            // +90° puts the image center where the image's right quarter was.
            let center = EnvOrientation::new(up, 90.0)
                .to_env(EnvOrientation::upright(up).to_world(DVec3::X));
            let (u, _) = direction_to_uv(center);
            assert!((u - 0.5).abs() < 1e-12, "{up:?}: {u}");
        }
    }

    #[test]
    fn to_env_undoes_to_world_at_any_rotation() {
        for up in UPS {
            for degrees in [0.0, 37.0, -211.0] {
                let o = EnvOrientation::new(up, degrees);
                for d in [
                    DVec3::X,
                    DVec3::Y,
                    DVec3::Z,
                    DVec3::new(0.3, -0.5, 0.81).normalize(),
                ] {
                    assert!((o.to_env(o.to_world(d)) - d).length() < 1e-12);
                    assert!((o.to_world(o.to_env(d)) - d).length() < 1e-12);
                }
            }
        }
    }

    #[test]
    fn conversion_keeps_power_and_kind() {
        let map = procedural_env::by_name("studio", 256).unwrap();
        let reference = reference_lights(&map, 4, &Default::default()).unwrap();
        let baseline = median_cut_lights(&map, 32);
        let orientation = EnvOrientation::new(UpAxis::Z, 30.0);
        for (specs, name) in [(&reference, "reference"), (&baseline, "median cut")] {
            let lights = orientation.lights(specs);
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
            for (light, spec) in lights.iter().zip(specs.iter()) {
                let want = orientation.to_world(spec.direction).as_vec3();
                assert!((light.direction - want).length() < 1e-6);
            }
        }
        let srbf = [LightSpec {
            direction: DVec3::new(0.0, 0.6, 0.8),
            lambda: Some(32.0),
            rgb: [1.0, 2.0, 3.0],
            shadowed_from: None,
            angular_variance: 0.0,
            stands_for_region: false,
            power_share: 0.0,
        }];
        let l = EnvOrientation::upright(UpAxis::Y).lights(&srbf)[0];
        assert_eq!(l.lambda, Some(32.0));
        assert_eq!(l.rgb, [1.0, 2.0, 3.0]);
        // EnvLight::power and LightSpec::power agree on the SRBF integral 2π/λ(1 − e^{−2λ}).
        assert!((l.power()[2] as f64 - srbf[0].power()[2]).abs() < 1e-6);
    }
}
