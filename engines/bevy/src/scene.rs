//! The scene both renderers draw: the groom (a Yuksel `.hair` file, loaded and cleaned as
//! strandlight's loader does), the camera (strandlight's front framing, written out exactly so
//! that neither side recomputes it) and the SRBF lights of strandlight's fit, placed in the
//! hair's world by strandlight's convention (`scene/src/env_orientation.rs`).

use anyhow::{Context, bail};
use bevy::math::{DVec3, Vec3};
use serde_json::{Value, json};
use std::path::{Path, PathBuf};

/// A groom: points and, per strand, its range of points.
pub struct Hair {
    pub points: Vec<Vec3>,
    /// Strand s is `points[offsets[s]..offsets[s + 1]]`.
    pub offsets: Vec<usize>,
}

impl Hair {
    /// Reads Cem Yuksel's `.hair` (header of 128 bytes; segments as u16 per strand when flag
    /// bit 0 is set; points as 3 × f32), then merges zero-length segments and drops strands
    /// left with fewer than two points, exactly as `runtime/src/hair/clean.rs` does.
    pub fn read_yuksel(path: &Path) -> anyhow::Result<Self> {
        let bytes = std::fs::read(path).with_context(|| path.display().to_string())?;
        if bytes.len() < 128 || &bytes[0..4] != b"HAIR" {
            bail!("{}: not a .hair file", path.display());
        }
        let u32_at = |o: usize| u32::from_le_bytes(bytes[o..o + 4].try_into().unwrap());
        let (strands, points, flags, default_segments) = (
            u32_at(4) as usize,
            u32_at(8) as usize,
            u32_at(12),
            u32_at(16),
        );
        if flags & 2 == 0 {
            bail!("{}: no points array", path.display());
        }
        let mut offset = 128;
        let counts: Vec<usize> = if flags & 1 != 0 {
            let c = (0..strands)
                .map(|s| {
                    u16::from_le_bytes([bytes[offset + 2 * s], bytes[offset + 2 * s + 1]]) as usize
                        + 1
                })
                .collect();
            offset += 2 * strands;
            c
        } else {
            vec![default_segments as usize + 1; strands]
        };
        if counts.iter().sum::<usize>() != points || bytes.len() < offset + 12 * points {
            bail!("{}: point count does not match its strands", path.display());
        }
        let f = |o: usize| f32::from_le_bytes(bytes[o..o + 4].try_into().unwrap());
        let raw: Vec<Vec3> = (0..points)
            .map(|i| {
                let o = offset + 12 * i;
                Vec3::new(f(o), f(o + 4), f(o + 8))
            })
            .collect();
        let degenerate = |a: Vec3, b: Vec3| {
            let scale = a.abs().max(b.abs()).max_element();
            (b - a).length() <= 4.0 * f32::EPSILON * scale
        };
        let mut hair = Hair {
            points: Vec::with_capacity(points),
            offsets: vec![0],
        };
        let mut read = 0;
        for count in counts {
            let start = hair.points.len();
            for _ in 0..count {
                let p = raw[read];
                read += 1;
                if hair.points.len() == start || !degenerate(*hair.points.last().unwrap(), p) {
                    hair.points.push(p);
                }
            }
            if hair.points.len() - start < 2 {
                hair.points.truncate(start);
            } else {
                hair.offsets.push(hair.points.len());
            }
        }
        if hair.offsets.len() < 2 {
            bail!("{}: no strands", path.display());
        }
        Ok(hair)
    }

    pub fn strands(&self) -> impl Iterator<Item = &[Vec3]> {
        self.offsets.windows(2).map(|w| &self.points[w[0]..w[1]])
    }

    /// Per point, the tangent strandlight's strand quads give it (`strand_quads.wgsl`): the
    /// central difference p_{i+1} − p_{i−1}, one-sided at a strand's ends, normalized.
    pub fn tangents(&self) -> Vec<Vec3> {
        let mut out = Vec::with_capacity(self.points.len());
        for strand in self.strands() {
            let n = strand.len();
            for i in 0..n {
                let before = strand[i.saturating_sub(1)];
                let after = strand[(i + 1).min(n - 1)];
                out.push((after - before).normalize());
            }
        }
        out
    }

    pub fn bounds(&self) -> (Vec3, Vec3) {
        self.points.iter().fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), p| (lo.min(*p), hi.max(*p)),
        )
    }

    /// `UpAxis::detect`: Z when the summed root→tip vector points more along −z than −y.
    pub fn z_up(&self) -> bool {
        let hang = self
            .strands()
            .map(|s| s[s.len() - 1] - s[0])
            .fold(Vec3::ZERO, |a, b| a + b);
        -hang.z > -hang.y && hang.z < 0.0
    }
}

/// A camera written out in full (strandlight's `ExactCamera`, perspective).
#[derive(Clone, Copy, Debug)]
pub struct Camera {
    pub eye: Vec3,
    pub target: Vec3,
    pub up: Vec3,
    pub fov_y_deg: f32,
    pub near: f32,
    pub far: f32,
}

impl Camera {
    /// `Camera::framing_front` of `runtime/src/camera.rs`: the bounding sphere fits the narrower
    /// field of view at 30° vertical, seen from the front (+y for Z-up hair, +z for Y-up).
    pub fn framing_front(hair: &Hair, aspect: f32) -> Self {
        let (lo, hi) = hair.bounds();
        let center = (lo + hi) * 0.5;
        let radius = ((hi - lo).length() * 0.5).max(1e-6);
        let (toward_eye, up) = if hair.z_up() {
            (Vec3::Y, Vec3::Z)
        } else {
            (Vec3::Z, Vec3::Y)
        };
        let fov_y = 30f32.to_radians();
        let half_x = ((fov_y * 0.5).tan() * aspect).atan();
        let half_min = (fov_y * 0.5).min(half_x);
        let distance = radius / half_min.sin();
        Self {
            eye: center + toward_eye * distance,
            target: center,
            up,
            fov_y_deg: 30.0,
            near: (distance - radius) * 0.5,
            far: distance + radius * 2.0,
        }
    }
}

/// What `strandlight render replay` reads (scene/src/frame_settings.rs), and this example too.
pub struct Settings {
    pub hair: PathBuf,
    pub size: [u32; 2],
    pub camera: Camera,
    pub rotation_deg: f64,
}

/// The frame: `hair` under `map`'s SRBF fit, single scattering of the Chiang fiber (brown, the
/// env frame's default), no shadows (`shadowed: false`), the nearest fiber of each pixel
/// (`opaque`), every fiber `fiber_width_px` wide, seen by the exact camera.
pub fn settings_json(
    hair_path: &Path,
    hair: &Hair,
    map: &str,
    size: [u32; 2],
    fiber_width_px: f32,
) -> Value {
    let c = Camera::framing_front(hair, size[0] as f32 / size[1] as f32);
    json!({
        "hair": hair_path,
        "size": size,
        "camera": { "exact": {
            "eye": c.eye.to_array(),
            "target": c.target.to_array(),
            "up": c.up.to_array(),
            "fov_y_deg": c.fov_y_deg,
            "half_height": null,
            "near": c.near,
            "far": c.far,
        }},
        "shading": null,
        "preset": "brown",
        "artist": null,
        "fiber_width_px": fiber_width_px,
        "lighting": { "environment": {
            "map": map,
            "scattering": "single",
            "kappa": 1.0,
            "lobes": null,
            "rotation_deg": 0.0,
            "dodm_size": 512,
            "transparency": "opaque",
            "view": {
                "lobe_visibility": "auto",
                "visibility_cutoff": 0.00390625,
                "forward_scattering": "auto",
                "simplification_seed": 24301
            },
            "shadowed": false
        }}
    })
}

pub fn read_settings(path: &Path) -> anyhow::Result<Settings> {
    let text = std::fs::read_to_string(path).with_context(|| path.display().to_string())?;
    let json: Value = serde_json::from_str(&text).with_context(|| path.display().to_string())?;
    let v3 = |v: &Value| -> anyhow::Result<Vec3> {
        let a = v.as_array().context("a 3-vector")?;
        Ok(Vec3::new(
            a[0].as_f64().context("x")? as f32,
            a[1].as_f64().context("y")? as f32,
            a[2].as_f64().context("z")? as f32,
        ))
    };
    let exact = &json["camera"]["exact"];
    if exact.is_null() {
        bail!("{}: this example needs an exact camera", path.display());
    }
    let f = |v: &Value| v.as_f64().map(|x| x as f32).context("a number");
    let camera = Camera {
        eye: v3(&exact["eye"])?,
        target: v3(&exact["target"])?,
        up: v3(&exact["up"])?,
        fov_y_deg: f(&exact["fov_y_deg"])?,
        near: f(&exact["near"])?,
        far: f(&exact["far"])?,
    };
    let size = [
        json["size"][0].as_u64().context("size")? as u32,
        json["size"][1].as_u64().context("size")? as u32,
    ];
    let env = &json["lighting"]["environment"];
    Ok(Settings {
        hair: PathBuf::from(json["hair"].as_str().context("hair")?),
        size,
        camera,
        rotation_deg: env["rotation_deg"].as_f64().unwrap_or(0.0),
    })
}

/// One SRBF light in the hair's world: toward its centre (unit), 1/λ, amplitude.
#[derive(Clone, Copy, Debug)]
pub struct Lobe {
    pub direction: Vec3,
    pub inv_lambda: f32,
    pub rgb: [f32; 3],
}

/// The lobes of a `strandlight fit` set (`precompute/src/srbf_set.rs`, format
/// `strandlight-srbf-set`) in the world of a hair with the given up axis, the map turned by
/// `rotation_deg` (`EnvOrientation::to_world`).
pub fn read_fit(path: &Path, z_up: bool, rotation_deg: f64) -> anyhow::Result<Vec<Lobe>> {
    let text = std::fs::read_to_string(path).with_context(|| path.display().to_string())?;
    let json: Value = serde_json::from_str(&text).with_context(|| path.display().to_string())?;
    if json["format"] != "strandlight-srbf-set" || json["kind"] != "srbf" {
        bail!("{}: not an SRBF set of `strandlight fit`", path.display());
    }
    if json["sources"].as_array().is_some_and(|s| !s.is_empty()) {
        bail!(
            "{}: the fit took out compact sources (directional lights, shaded with the `*_direct` table); this example shades SRBF lobes only: use a map without (venice_sunset_1k.hdr) or fit with --sources 0",
            path.display()
        );
    }
    let (s, c) = rotation_deg.to_radians().sin_cos();
    let mut lobes = Vec::new();
    for l in json["lobes"].as_array().context("lobes")? {
        let a = l["center"].as_array().context("center")?;
        let d = DVec3::new(
            a[0].as_f64().context("x")?,
            a[1].as_f64().context("y")?,
            a[2].as_f64().context("z")?,
        )
        .normalize();
        let turned = DVec3::new(d.x * c - d.z * s, d.y, d.z * c + d.x * s);
        let world = if z_up {
            DVec3::new(-turned.x, turned.z, turned.y)
        } else {
            turned
        };
        let amp = l["amplitude"].as_array().context("amplitude")?;
        lobes.push(Lobe {
            direction: world.as_vec3().normalize(),
            inv_lambda: (1.0 / l["lambda"].as_f64().context("lambda")?) as f32,
            rgb: [0, 1, 2].map(|k| amp[k].as_f64().unwrap_or(0.0) as f32),
        });
    }
    Ok(lobes)
}
