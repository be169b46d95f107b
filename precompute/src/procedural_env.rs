//! Procedural environments, made by the project's own code: an analytic sun-and-sky and a
//! three-light studio (the defaults a person gets without a real map), and a map built from
//! known SRBF lobes (for tests that must recover them). All return the same [`EnvMap`] as the
//! loaders, in [`crate::envmap`]'s convention (+Y up, image center toward −Z).

use crate::envmap::{EnvMap, uv_to_direction};
use glam::DVec3;
use strandlight_tables::srbf::SrbfLobe;

/// A disk light of angular radius `radius` (radians) around `center`, with a smooth edge of
/// a tenth of the radius so the map has no aliasing step.
fn disk(w: DVec3, center: DVec3, radius: f64) -> f64 {
    let angle = w.dot(center).clamp(-1.0, 1.0).acos();
    let edge = 0.1 * radius;
    ((radius + edge - angle) / (2.0 * edge)).clamp(0.0, 1.0)
}

/// Sun and sky: a clear-sky gradient (blue zenith, pale horizon), a warm sun of angular radius
/// 6° at 35° elevation toward azimuth u = 0.6 (front right), and a grey-brown ground.
/// The sun is much wider than the real one (0.27°): a lobe with λ ≤ 64 is ~7° wide, and a
/// real sun would dominate the squared error beyond what any such lobe can fit (see
/// docs/BENCHMARKS.md on quarry_01). It carries about a third of the light.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SunSky {
    pub sun_direction: DVec3,
    pub sun_angular_radius: f64,
    pub sun_radiance: [f64; 3],
    pub zenith: [f64; 3],
    pub horizon: [f64; 3],
    pub ground: [f64; 3],
}

impl Default for SunSky {
    fn default() -> Self {
        Self {
            sun_direction: uv_to_direction(0.6, 0.5 - 35.0 / 180.0),
            sun_angular_radius: 6f64.to_radians(),
            sun_radiance: [60.0, 54.0, 44.0],
            zenith: [0.25, 0.45, 0.9],
            horizon: [0.9, 0.95, 1.0],
            ground: [0.18, 0.15, 0.12],
        }
    }
}

impl SunSky {
    pub fn radiance(&self, w: DVec3) -> [f64; 3] {
        let mut c = if w.y >= 0.0 {
            // Horizon → zenith blend with a gently saturating elevation profile.
            let t = w.y.sqrt();
            std::array::from_fn(|i| self.horizon[i] * (1.0 - t) + self.zenith[i] * t)
        } else {
            self.ground
        };
        let s = disk(w, self.sun_direction, self.sun_angular_radius);
        (0..3).for_each(|i| c[i] += s * self.sun_radiance[i]);
        c
    }

    pub fn to_map(&self, width: usize) -> EnvMap {
        EnvMap::from_fn(width, width / 2, |w| self.radiance(w))
    }
}

/// A photo studio: a large soft key light (front left, above), a dimmer fill (front right,
/// low) and a small bright rim light behind, over a dim grey cyclorama that darkens downward.
pub fn three_light_studio(width: usize) -> EnvMap {
    let key = (
        uv_to_direction(0.4, 0.3),
        12f64.to_radians(),
        [40.0, 38.0, 35.0],
    );
    let fill = (
        uv_to_direction(0.62, 0.45),
        18f64.to_radians(),
        [8.0, 8.5, 9.0],
    );
    let rim = (
        uv_to_direction(0.05, 0.35),
        6f64.to_radians(),
        [60.0, 60.0, 60.0],
    );
    EnvMap::from_fn(width, width / 2, |w| {
        let base = 0.05 + 0.1 * (0.5 + 0.5 * w.y);
        let mut c = [base; 3];
        for (center, radius, rgb) in [key, fill, rim] {
            let s = disk(w, center, radius);
            (0..3).for_each(|i| c[i] += s * rgb[i]);
        }
        c
    })
}

/// The map whose radiance is exactly the sum of `lobes` (sampled at pixel centers).
pub fn from_srbf_lobes(width: usize, lobes: &[SrbfLobe]) -> EnvMap {
    EnvMap::from_fn(width, width / 2, |w| {
        let mut c = [0.0; 3];
        for lobe in lobes {
            let r = lobe.radiance(w);
            (0..3).for_each(|i| c[i] += r[i]);
        }
        c
    })
}

/// The names accepted by the CLI as `procedural:NAME`.
pub const NAMES: [&str; 2] = ["sun_and_sky", "studio"];

/// A named procedural environment at `width × width/2`, or `None` for an unknown name.
pub fn by_name(name: &str, width: usize) -> Option<EnvMap> {
    match name {
        "sun_and_sky" => Some(SunSky::default().to_map(width)),
        "studio" => Some(three_light_studio(width)),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn sun_power_matches_its_disk() {
        // The sun's contribution integrates to radiance × solid angle of its (soft) disk.
        let sky = SunSky::default();
        let no_sun = SunSky {
            sun_radiance: [0.0; 3],
            ..sky
        };
        let (a, b) = (sky.to_map(2048).integral(), no_sun.to_map(2048).integral());
        let solid_angle = 2.0 * PI * (1.0 - sky.sun_angular_radius.cos());
        let expected = sky.sun_radiance[0] * solid_angle;
        eprintln!("sun power {:.4} vs disk {expected:.4}", a[0] - b[0]);
        assert!(((a[0] - b[0]) - expected).abs() < 0.03 * expected);
    }

    #[test]
    fn maps_are_finite_non_negative_and_two_to_one() {
        for name in NAMES {
            let m = by_name(name, 64).unwrap();
            assert_eq!((m.width(), m.height()), (64, 32));
            assert_eq!(m.bad_pixels().total(), 0, "{name}");
        }
        assert!(by_name("nope", 64).is_none());
    }
}
