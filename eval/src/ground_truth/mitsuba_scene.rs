//! A strandlight scene as the files Mitsuba 3 renders: the strands as a `bsplinecurve` text file
//! (one `x y z radius` control point per line, a blank line between strands), the environment map as a
//! linear EXR with the transform that puts it where strandlight's lights are, the camera, the
//! fiber (Mitsuba's `hair` BSDF, Chiang et al. 2016) and the integrator, all in one JSON file
//! that `mitsuba_render.py` reads.
//!
//! **Why B-splines.** Mitsuba's `hair` BSDF reads the fiber's tangent as its local y axis.
//! `bsplinecurve` builds that frame from the curve's tangent; `linearcurve` (3.9) does not: its
//! shading frame comes from the surface normal alone, whose y axis is the tangent only for a
//! fiber that happens to run along one particular direction (measured: a curve along +x gets
//! t = (0, 1, 0)). A B-spline does not pass through its control points, so each strand's
//! control points are solved for ([`interpolating_bspline`]) so that the curve passes through
//! every point of the polyline strandlight renders.
//!
//! **The map's frame.** strandlight's map frame (`precompute/src/envmap.rs`) puts texel column u
//! at azimuth 2π(u − ½) from −Z, Mitsuba's `envmap` at 2πu: the same picture half a turn apart
//! about +Y, so Mitsuba's local frame is strandlight's turned by π about +Y
//! ([`MITSUBA_MAP_FROM_OURS`]). Then the map is placed in the hair's world exactly as every
//! frame places it ([`strandlight_scene::env_orientation::EnvOrientation`]: up axis and
//! rotation).

use anyhow::Context;
use glam::{DMat3, DVec3};
use serde::Serialize;
use std::io::Write;
use std::path::{Path, PathBuf};
use strandlight_precompute::EnvMap;
use strandlight_runtime::camera::{Camera, Projection, UpAxis};
use strandlight_runtime::hair::HairModel;
use strandlight_runtime::head::Head;
use strandlight_runtime::passes::strand_geometry::default_thickness;
use strandlight_scene::env_orientation::EnvOrientation;
use strandlight_scene::frame_render::settings_camera;
use strandlight_scene::frame_settings::{FrameSettings, Lighting};
use strandlight_scene::head_input::write_obj;
use strandlight_tables::atomic_write::write_atomically;
use strandlight_tables::image_out::write_exr;

/// The script that renders a scene file (written beside it).
pub const RENDER_SCRIPT: &str = include_str!("mitsuba_render.py");
/// Its file name in a scene folder.
pub const RENDER_SCRIPT_NAME: &str = "mitsuba_render.py";

/// Mitsuba's map frame in terms of strandlight's: a half turn about +Y (x, z negated).
pub const MITSUBA_MAP_FROM_OURS: [[f64; 3]; 3] =
    [[-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, -1.0]];

/// Everything a path-traced image of a scene depends on.
#[derive(Clone, Copy)]
pub struct MitsubaScene<'a> {
    pub hair: &'a HairModel,
    /// Where the map sits in the hair's world (and the hair's up axis).
    pub orientation: EnvOrientation,
    pub camera: Camera,
    pub size: (u32, u32),
    /// The environment; None for a scene lit by `directional` lights only.
    pub map: Option<&'a EnvMap>,
    /// Directional lights in the world: (unit direction toward the light, RGB irradiance).
    pub directional: &'a [([f64; 3], [f64; 3])],
    /// Mitsuba's `hair` parameters under this project's names (`ChiangParams` serialized):
    /// `eumelanin`, `pheomelanin`, `sigma_a` (null for melanin), `longitudinal_roughness`,
    /// `azimuthal_roughness`, `ior`, `scale_tilt_degrees`.
    pub fiber: &'a serde_json::Value,
    /// The head (issue 40): an opaque Lambertian mesh (`diffuse` BSDF of the skin's albedo);
    /// an ellipsoid goes as its tessellation (Mitsuba's `sphere` takes no non-uniform scale).
    pub head: Option<&'a Head>,
}

/// What one render does: the path tracer's depth and samples.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct MitsubaRun {
    /// Mitsuba's `max_depth`: 2 is direct light only (single scattering).
    pub max_depth: u32,
    pub spp: u32,
    pub seed: u32,
}

impl<'a> MitsubaScene<'a> {
    /// The path-traced scene of the env-lit frame `settings` describe over `hair` (loaded from
    /// them): its camera and size, `map` placed as the frame places it over a hair with `up`,
    /// its head, and `fiber` (its Chiang parameters, [`Self::fiber`]).
    pub fn of_frame(
        settings: &FrameSettings,
        hair: &'a HairModel,
        (map, up): (&'a EnvMap, UpAxis),
        fiber: &'a serde_json::Value,
        head: Option<&'a Head>,
    ) -> anyhow::Result<Self> {
        let Lighting::Environment(env) = &settings.lighting else {
            anyhow::bail!("the path-traced truth is of env-lit frames");
        };
        let [width, height] = settings.size;
        Ok(Self {
            hair,
            orientation: EnvOrientation::new(up, env.rotation_deg as f64),
            camera: settings_camera(settings, hair)?,
            size: (width, height),
            map: Some(map),
            directional: &[],
            fiber,
            head,
        })
    }
}

/// The matrix (rows) that takes Mitsuba's map frame into the hair's world.
pub fn map_to_world(orientation: EnvOrientation) -> [[f64; 3]; 3] {
    let ours_from_mitsuba = DMat3::from_cols_array_2d(&MITSUBA_MAP_FROM_OURS).transpose();
    let column = |axis: DVec3| orientation.to_world(ours_from_mitsuba * axis);
    let (x, y, z) = (column(DVec3::X), column(DVec3::Y), column(DVec3::Z));
    [[x.x, y.x, z.x], [x.y, y.y, z.y], [x.z, y.z, z.z]]
}

/// The files of a scene in `dir`: curves, map, the render script, and the scene JSON for one
/// run writing `output`; returns the JSON's path.
pub fn write_scene(
    scene: &MitsubaScene,
    run: MitsubaRun,
    dir: &Path,
    output: &Path,
) -> anyhow::Result<PathBuf> {
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let curves = dir.join("hair.txt");
    write_curves(scene.hair, &curves)?;
    let map = dir.join("environment.exr");
    if let Some(environment) = scene.map {
        write_map(environment, &map)?;
    }
    let head_obj = dir.join("head.obj");
    if let Some(head) = scene.head {
        // Mitsuba's `obj` shape reads it.
        write_obj(&head.triangles(), &head_obj)?;
    }
    let script = dir.join(RENDER_SCRIPT_NAME);
    std::fs::write(&script, RENDER_SCRIPT)
        .with_context(|| format!("cannot write {}", script.display()))?;
    let json = dir.join("scene.json");
    let mut description = scene_json(scene, run, &curves, &map, output)?;
    if let Some(head) = scene.head {
        description["head"] = serde_json::json!({
            "obj": absolute(&head_obj)?,
            "albedo": head.albedo,
        });
    }
    write_atomically(&json, |out| {
        out.write_all(serde_json::to_string_pretty(&description)?.as_bytes())
    })
    .with_context(|| format!("cannot write {}", json.display()))?;
    Ok(json)
}

/// The scene JSON (see `mitsuba_render.py` for how each field is used).
pub fn scene_json(
    scene: &MitsubaScene,
    run: MitsubaRun,
    curves: &Path,
    map: &Path,
    output: &Path,
) -> anyhow::Result<serde_json::Value> {
    let camera = &scene.camera;
    let Projection::Perspective { fov_y } = camera.projection else {
        anyhow::bail!("the path-traced ground truth needs a perspective camera");
    };
    Ok(serde_json::json!({
        "camera": {
            "width": scene.size.0,
            "height": scene.size.1,
            "fov_y_degrees": fov_y.to_degrees(),
            "near": camera.near,
            "far": camera.far,
            "eye": camera.eye.to_array(),
            "target": camera.target.to_array(),
            "up": camera.up.to_array(),
        },
        "fiber": scene.fiber,
        "environment": match scene.map {
            Some(_) => serde_json::json!({
                "map": absolute(map)?,
                "to_world": map_to_world(scene.orientation),
            }),
            None => serde_json::Value::Null,
        },
        "directional": scene.directional.iter().map(|(toward, irradiance)| serde_json::json!({
            "toward_light": toward,
            "irradiance": irradiance,
        })).collect::<Vec<_>>(),
        "curves": [absolute(curves)?],
        "max_depth": run.max_depth,
        "spp": run.spp,
        "seed": run.seed,
        "output": absolute(output)?,
    }))
}

fn absolute(path: &Path) -> anyhow::Result<String> {
    let p = std::path::absolute(path).with_context(|| path.display().to_string())?;
    Ok(p.to_string_lossy().into_owned())
}

/// The strands as Mitsuba's `bsplinecurve` text: per strand the control points of the uniform
/// cubic B-spline through its points, with radii (half the file's thickness, or half the
/// renderer's default thickness where the file has none) solved for the same way.
pub fn write_curves(hair: &HairModel, path: &Path) -> anyhow::Result<()> {
    let fallback = default_thickness(hair);
    let thickness = |i: usize| hair.thickness().map_or(fallback, |t| t.at(i));
    write_atomically(path, |out| {
        let mut first = 0;
        for strand in hair.strands() {
            let points: Vec<[f64; 4]> = strand
                .iter()
                .enumerate()
                .map(|(k, p)| {
                    let r = 0.5 * thickness(first + k);
                    [p.x as f64, p.y as f64, p.z as f64, r as f64]
                })
                .collect();
            first += strand.len();
            for c in interpolating_bspline(&points) {
                // A radius can dip below 0 between points whose radii change abruptly.
                writeln!(out, "{} {} {} {}", c[0], c[1], c[2], c[3].max(1e-7))?;
            }
            writeln!(out)?;
        }
        Ok::<(), std::io::Error>(())
    })
    .with_context(|| format!("cannot write the curves {}", path.display()))
}

/// The control points C_0..C_{m+2} of the uniform cubic B-spline whose segment joints are the
/// points P_0..P_m (joint k = (C_k + 4C_{k+1} + C_{k+2})/6), with zero second derivative at both
/// ends (C_0 = 2C_1 − C_2, which makes C_1 = P_0; likewise C_{m+1} = P_m). The interior
/// C_2..C_m solve a diagonally dominant tridiagonal system (Thomas algorithm, stable here).
/// Works on any number of components (position and radius).
pub fn interpolating_bspline<const N: usize>(points: &[[f64; N]]) -> Vec<[f64; N]> {
    let m = points.len().saturating_sub(1);
    if points.len() < 2 {
        return points.to_vec();
    }
    let add =
        |a: [f64; N], b: [f64; N], s: f64| -> [f64; N] { std::array::from_fn(|c| a[c] + s * b[c]) };
    // Unknowns x_j = C_{j+2}, j = 0..m-1 (C_2..C_m): for joints k = 1..m-1,
    // C_k + 4C_{k+1} + C_{k+2} = 6P_k with C_1 = P_0 and C_{m+1} = P_m known.
    let n = m - 1;
    let mut c = vec![[0.0; N]; m + 3];
    c[1] = points[0];
    c[m + 1] = points[m];
    if n > 0 {
        let mut diag = vec![4.0; n];
        let mut rhs: Vec<[f64; N]> = (1..m).map(|k| points[k].map(|v| 6.0 * v)).collect();
        rhs[0] = add(rhs[0], points[0], -1.0);
        rhs[n - 1] = add(rhs[n - 1], points[m], -1.0);
        for j in 1..n {
            let w = 1.0 / diag[j - 1];
            diag[j] -= w;
            rhs[j] = add(rhs[j], rhs[j - 1], -w);
        }
        let mut x = vec![[0.0; N]; n];
        x[n - 1] = rhs[n - 1].map(|v| v / diag[n - 1]);
        for j in (0..n - 1).rev() {
            x[j] = add(rhs[j], x[j + 1], -1.0).map(|v| v / diag[j]);
        }
        for (j, v) in x.into_iter().enumerate() {
            c[j + 2] = v;
        }
    }
    c[0] = add(c[1].map(|v| 2.0 * v), c[2], -1.0);
    c[m + 2] = add(c[m + 1].map(|v| 2.0 * v), c[m], -1.0);
    c
}

/// The map's pixels as a linear RGB(A) EXR, exactly as strandlight loaded them.
pub fn write_map(map: &EnvMap, path: &Path) -> anyhow::Result<()> {
    let pixels: Vec<[f32; 4]> = map
        .pixels()
        .iter()
        .map(|p| [p[0], p[1], p[2], 1.0])
        .collect();
    write_exr(
        path,
        map.width() as u32,
        map.height() as u32,
        &pixels,
        "strandlight environment for Mitsuba",
    )
    .with_context(|| format!("cannot write the map {}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use strandlight_precompute::envmap::uv_to_direction;

    /// Mitsuba's `envmap` (src/emitters/envmap.cpp) looks a local direction d up at
    /// u = atan2(d.x, −d.z)/2π, v = acos(d.y)/π.
    fn mitsuba_uv(d: DVec3) -> (f64, f64) {
        let u = (d.x.atan2(-d.z) / (2.0 * std::f64::consts::PI)).rem_euclid(1.0);
        (u, d.y.clamp(-1.0, 1.0).acos() / std::f64::consts::PI)
    }

    /// The uniform cubic B-spline of four control points at t ∈ [0, 1].
    fn bspline(c: &[[f64; 3]], t: f64) -> [f64; 3] {
        let b = [
            (1.0 - t).powi(3) / 6.0,
            (3.0 * t.powi(3) - 6.0 * t * t + 4.0) / 6.0,
            (-3.0 * t.powi(3) + 3.0 * t * t + 3.0 * t + 1.0) / 6.0,
            t.powi(3) / 6.0,
        ];
        std::array::from_fn(|k| (0..4).map(|i| b[i] * c[i][k]).sum())
    }

    #[test]
    fn the_bspline_passes_through_every_point_of_the_strand() {
        for points in [
            vec![[0.0, 0.0, 0.0], [1.0, 2.0, 0.5]],
            vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0]],
            (0..16)
                .map(|k| {
                    let t = k as f64 * 0.7;
                    [t.cos(), t.sin(), 0.3 * t]
                })
                .collect(),
        ] {
            let c = interpolating_bspline(&points);
            assert_eq!(c.len(), points.len() + 2);
            // Segment k (control points k..k+3) starts at point k; the last one ends at the last.
            for (k, p) in points.iter().enumerate() {
                let (segment, t) = if k + 3 < c.len() {
                    (k, 0.0)
                } else {
                    (k - 1, 1.0)
                };
                let q = bspline(&c[segment..segment + 4], t);
                for i in 0..3 {
                    assert!((q[i] - p[i]).abs() < 1e-12, "point {k}: {q:?} vs {p:?}");
                }
            }
            // A straight strand stays straight between its points.
            if points.len() == 2 {
                let mid = bspline(&c[0..4], 0.5);
                for i in 0..3 {
                    assert!((mid[i] - 0.5 * (points[0][i] + points[1][i])).abs() < 1e-12);
                }
            }
        }
    }

    #[test]
    fn a_texel_lands_where_strandlight_puts_it() {
        for up in [UpAxis::Y, UpAxis::Z] {
            for rotate in [0.0, 37.0, -120.0] {
                let orientation = EnvOrientation::new(up, rotate);
                let m = DMat3::from_cols_array_2d(&map_to_world(orientation)).transpose();
                for &(u, v) in &[(0.1, 0.3), (0.5, 0.5), (0.93, 0.71), (0.26, 0.05)] {
                    // Where strandlight puts texel (u, v) in the world ...
                    let world = orientation.to_world(uv_to_direction(u, v));
                    // ... Mitsuba must look up the same texel.
                    let local = m.transpose() * world;
                    let (mu, mv) = mitsuba_uv(local);
                    let du = (mu - u).abs().min(1.0 - (mu - u).abs());
                    assert!(
                        du < 1e-9 && (mv - v).abs() < 1e-9,
                        "{up:?} {rotate}: ({u}, {v}) → ({mu}, {mv})"
                    );
                }
                // A rotation: orthonormal with determinant +1.
                assert!((m.determinant() - 1.0).abs() < 1e-12);
            }
        }
    }
}
