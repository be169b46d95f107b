//! Point lights (directional, point, spot) and their `--light` text form.

use glam::Vec3;

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Light {
    /// `direction` points toward the light; irradiance `intensity` (no falloff).
    Directional { direction: Vec3, intensity: f32 },
    /// Irradiance `intensity / d²` at distance d.
    Point { position: Vec3, intensity: f32 },
    /// A point light lit only inside the cone of half-angle `half_angle` (radians) around
    /// `direction` (the way the light shines); hard edge.
    Spot {
        position: Vec3,
        direction: Vec3,
        half_angle: f32,
        intensity: f32,
    },
}

#[derive(Debug, thiserror::Error, PartialEq)]
#[error(
    "light spec {spec:?}: {problem} (forms: directional:X,Y,Z[:INTENSITY], point:X,Y,Z[:INTENSITY], spot:X,Y,Z:DX,DY,DZ:ANGLE_DEGREES[:INTENSITY])"
)]
pub struct LightSpecError {
    pub spec: String,
    pub problem: String,
}

/// The layout of one light in the shaders' storage buffer (48 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct GpuLight {
    /// xyz: direction toward the light (directional) or position; w: kind (0, 1, 2).
    pub position_or_direction: [f32; 4],
    /// rgb: intensity (white light); w unused.
    pub intensity: [f32; 4],
    /// Spot: xyz the direction it shines, w the cosine of the half-angle.
    pub spot: [f32; 4],
}

impl Light {
    pub fn to_gpu(&self) -> GpuLight {
        match *self {
            Light::Directional {
                direction,
                intensity,
            } => GpuLight {
                position_or_direction: direction.normalize().extend(0.0).into(),
                intensity: [intensity; 4],
                spot: [0.0; 4],
            },
            Light::Point {
                position,
                intensity,
            } => GpuLight {
                position_or_direction: position.extend(1.0).into(),
                intensity: [intensity; 4],
                spot: [0.0; 4],
            },
            Light::Spot {
                position,
                direction,
                half_angle,
                intensity,
            } => GpuLight {
                position_or_direction: position.extend(2.0).into(),
                intensity: [intensity; 4],
                spot: direction.normalize().extend(half_angle.cos()).into(),
            },
        }
    }

    /// Parses `directional:X,Y,Z[:I]`, `point:X,Y,Z[:I]`, `spot:X,Y,Z:DX,DY,DZ:ANGLE[:I]`
    /// (ANGLE: the cone's half-angle in degrees).
    pub fn parse(spec: &str) -> Result<Self, LightSpecError> {
        let err = |problem: &str| LightSpecError {
            spec: spec.to_string(),
            problem: problem.to_string(),
        };
        let parts: Vec<&str> = spec.split(':').collect();
        let number = |s: &str, what: &str| -> Result<f32, LightSpecError> {
            let v: f32 = s
                .trim()
                .parse()
                .map_err(|_| err(&format!("{what} {s:?} is not a number")))?;
            if v.is_finite() {
                Ok(v)
            } else {
                Err(err(&format!("{what} {s:?} is not finite")))
            }
        };
        let vector = |s: &str, what: &str| -> Result<Vec3, LightSpecError> {
            let c: Vec<&str> = s.split(',').collect();
            if c.len() != 3 {
                return Err(err(&format!(
                    "{what} needs three comma-separated numbers, got {s:?}"
                )));
            }
            Ok(Vec3::new(
                number(c[0], what)?,
                number(c[1], what)?,
                number(c[2], what)?,
            ))
        };
        let unit = |s: &str, what: &str| -> Result<Vec3, LightSpecError> {
            let v = vector(s, what)?;
            if v.length() < 1e-12 {
                return Err(err(&format!("{what} must not be zero")));
            }
            Ok(v.normalize())
        };
        let intensity = |s: Option<&&str>| -> Result<f32, LightSpecError> {
            match s {
                None => Ok(1.0),
                Some(s) => {
                    let v = number(s, "intensity")?;
                    if v < 0.0 {
                        Err(err("intensity must not be negative"))
                    } else {
                        Ok(v)
                    }
                }
            }
        };
        match parts.first().copied() {
            Some("directional") if (2..=3).contains(&parts.len()) => Ok(Light::Directional {
                direction: unit(parts[1], "direction")?,
                intensity: intensity(parts.get(2))?,
            }),
            Some("point") if (2..=3).contains(&parts.len()) => Ok(Light::Point {
                position: vector(parts[1], "position")?,
                intensity: intensity(parts.get(2))?,
            }),
            Some("spot") if (4..=5).contains(&parts.len()) => {
                let angle = number(parts[3], "angle")?;
                if !(angle > 0.0 && angle <= 180.0) {
                    return Err(err("angle must be in (0, 180] degrees"));
                }
                Ok(Light::Spot {
                    position: vector(parts[1], "position")?,
                    direction: unit(parts[2], "spot direction")?,
                    half_angle: angle.to_radians(),
                    intensity: intensity(parts.get(4))?,
                })
            }
            Some("directional" | "point" | "spot") => {
                Err(err("wrong number of ':'-separated fields"))
            }
            _ => Err(err("unknown light kind")),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn specs_parse_and_bad_ones_name_the_problem() {
        assert_eq!(
            Light::parse("point:1,2,3:5").unwrap(),
            Light::Point {
                position: Vec3::new(1.0, 2.0, 3.0),
                intensity: 5.0
            }
        );
        match Light::parse("directional:0,0,2").unwrap() {
            Light::Directional {
                direction,
                intensity,
            } => {
                assert_eq!(direction, Vec3::Z);
                assert_eq!(intensity, 1.0);
            }
            other => panic!("{other:?}"),
        }
        match Light::parse("spot:0,0,5:0,0,-1:30:2").unwrap() {
            Light::Spot {
                half_angle,
                intensity,
                ..
            } => {
                assert!((half_angle - 30f32.to_radians()).abs() < 1e-7);
                assert_eq!(intensity, 2.0);
            }
            other => panic!("{other:?}"),
        }
        for bad in [
            "sun:0,0,1",
            "point:1,2",
            "directional:0,0,0",
            "point:1,2,3:-1",
            "spot:0,0,0:0,0,1",
            "point:1,2,nan",
        ] {
            let e = Light::parse(bad).unwrap_err();
            eprintln!("{e}");
            assert_eq!(e.spec, bad);
        }
    }
}

#[cfg(test)]
mod wgsl_layout {
    use super::*;
    use crate::shader_layout::{assert_same_layout, rust_layout};
    use crate::shaders::Wgsl;

    #[test]
    fn uploaded_structs_are_laid_out_as_the_wgsl_reads_them() {
        assert_same_layout(
            &Wgsl {
                file: "strand_quads.wgsl",
                source: include_str!("passes/strand_quads.wgsl"),
            },
            None,
            "Light",
            &rust_layout!(GpuLight {
                position_or_direction,
                intensity,
                spot
            }),
        );
    }
}
