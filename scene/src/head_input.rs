//! The head of a scene (issue 40): none, an ellipsoid fitted to the strand roots, or a mesh
//! read from a file: Wavefront OBJ (`tobj`, in the hair's units and frame), glTF 2.0
//! ([`crate::head_gltf`]) or USD `Mesh` prims (the runtime's USD reader); the last two in
//! strandlight's world, as their grooms are (Y up, centimetres). The setting is
//! [`HeadChoice`]; [`load_head`] turns it into the runtime's [`Head`] for a given groom.
//!
//! The ellipsoid fit: a groom's roots sit on the scalp, which is usually only the top of the
//! head (a cap), where a free ellipsoid fit is poorly conditioned (on straight.hair the
//! six-parameter least-squares fit comes out squashed to half the head's height, with roots
//! at 0.52…2.1 of its implicit function). So:
//! 1. a least-squares sphere through the roots gives the centre (linear, well posed on a cap);
//! 2. the full axis-aligned ellipsoid (6 parameters, linear least squares) is kept when every
//!    root lies within 2 % of its surface (a groom grown from an ellipsoid, like the procedural
//!    one), else the radii are fitted with the sphere's centre fixed (3 parameters);
//! 3. the radii are then scaled down together until every root lies on or outside the surface
//!    (a bounding fit from inside: no root, and so no strand's first point, is swallowed).

use anyhow::{Context, bail};
use glam::{DVec3, Vec3};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use strandlight_runtime::hair::HairModel;
use strandlight_runtime::head::{DEFAULT_SKIN_ALBEDO, Head, HeadSurface, TriangleMesh};
use strandlight_tables::atomic_write::write_atomically;

/// Which head a scene has.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum HeadChoice {
    /// Nothing but the hair blocks light or view (every render before issue 40).
    #[default]
    None,
    /// An ellipsoid fitted to the strand roots (see the module's documentation).
    Ellipsoid,
    /// Triangle meshes from one or more files ([`MESH_EXTENSIONS`]): every mesh in each,
    /// merged (a character's skin, eyes and lashes often come as separate files).
    Mesh(MeshFiles),
}

/// The files of a mesh head, at least one; written as one path, or as a list when several
/// (settings written before several were taken hold one path and read the same).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "MeshFilesForm", into = "MeshFilesForm")]
pub struct MeshFiles(Vec<PathBuf>);

#[derive(Serialize, Deserialize)]
#[serde(untagged)]
enum MeshFilesForm {
    One(PathBuf),
    Several(Vec<PathBuf>),
}

impl TryFrom<MeshFilesForm> for MeshFiles {
    type Error = &'static str;
    fn try_from(form: MeshFilesForm) -> Result<Self, Self::Error> {
        match form {
            MeshFilesForm::One(path) => Ok(Self(vec![path])),
            MeshFilesForm::Several(paths) if paths.is_empty() => {
                Err("a mesh head names no file (give one or more mesh files)")
            }
            MeshFilesForm::Several(paths) => Ok(Self(paths)),
        }
    }
}

impl From<MeshFiles> for MeshFilesForm {
    fn from(files: MeshFiles) -> Self {
        match <[PathBuf; 1]>::try_from(files.0) {
            Ok([path]) => Self::One(path),
            Err(paths) => Self::Several(paths),
        }
    }
}

impl MeshFiles {
    pub fn paths(&self) -> &[PathBuf] {
        &self.0
    }
}

impl From<PathBuf> for MeshFiles {
    fn from(path: PathBuf) -> Self {
        Self(vec![path])
    }
}

impl HeadChoice {
    /// The head in the mesh file at `path`.
    pub fn mesh(path: impl Into<PathBuf>) -> Self {
        Self::Mesh(MeshFiles::from(path.into()))
    }
}

impl HeadChoice {
    pub fn is_none(&self) -> bool {
        *self == HeadChoice::None
    }

    /// `none`, `ellipsoid`, or mesh files (each one of [`MESH_EXTENSIONS`]) separated by
    /// commas: `sintel.obj,sintel-eyes.obj`. The path of an existing mesh file is taken whole,
    /// commas and all.
    pub fn parse(text: &str) -> Result<Self, String> {
        let refused = |what: &str| {
            format!(
                "`{what}`: give none, ellipsoid or mesh files ending in {} (several separated by commas)",
                MESH_EXTENSIONS.map(|e| format!(".{e}")).join(", ")
            )
        };
        match text {
            "none" => Ok(Self::None),
            "ellipsoid" => Ok(Self::Ellipsoid),
            path if is_mesh_file(Path::new(path)) && Path::new(path).exists() => {
                Ok(Self::mesh(path))
            }
            list => {
                let paths: Vec<PathBuf> = list.split(',').map(PathBuf::from).collect();
                match paths.iter().find(|p| !is_mesh_file(p)) {
                    Some(bad) => Err(refused(&bad.display().to_string())),
                    None => Ok(Self::Mesh(MeshFiles(paths))),
                }
            }
        }
    }
}

impl std::fmt::Display for HeadChoice {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::None => write!(f, "none"),
            Self::Ellipsoid => write!(f, "ellipsoid"),
            Self::Mesh(files) => {
                let paths: Vec<String> = files.0.iter().map(|p| p.display().to_string()).collect();
                write!(f, "{}", paths.join(","))
            }
        }
    }
}

impl std::str::FromStr for HeadChoice {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Self::parse(s)
    }
}

/// The extensions of the head mesh files read (the format follows the extension).
pub const MESH_EXTENSIONS: [&str; 7] = ["obj", "glb", "gltf", "usd", "usda", "usdc", "usdz"];

/// Whether `path` names a head mesh file by its extension.
pub fn is_mesh_file(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| MESH_EXTENSIONS.contains(&e.to_ascii_lowercase().as_str()))
}

/// The head `choice` asks for, around `hair`, with skin of `albedo`.
pub fn load_head(
    choice: &HeadChoice,
    hair: &HairModel,
    albedo: [f32; 3],
) -> anyhow::Result<Option<Head>> {
    let surface = match choice {
        HeadChoice::None => return Ok(None),
        HeadChoice::Ellipsoid => {
            let roots: Vec<Vec3> = hair.strands().filter_map(|s| s.first().copied()).collect();
            let fit = fit_root_ellipsoid(&roots)?;
            HeadSurface::Ellipsoid {
                center: fit.center,
                radii: fit.radii,
            }
        }
        HeadChoice::Mesh(files) => HeadSurface::Mesh(TriangleMesh::merged(
            files
                .paths()
                .iter()
                .map(|p| load_mesh(p))
                .collect::<anyhow::Result<Vec<_>>>()?,
        )),
    };
    if albedo.iter().any(|a| !(0.0..=1.0).contains(a)) {
        bail!("skin albedo {albedo:?}: each channel must be in [0, 1]");
    }
    Ok(Some(Head { surface, albedo }))
}

/// The default skin albedo (linear RGB).
pub fn default_skin_albedo() -> [f32; 3] {
    DEFAULT_SKIN_ALBEDO
}

/// The head mesh in the file at `path`, read as its extension says.
pub fn load_mesh(path: &Path) -> anyhow::Result<TriangleMesh> {
    let extension = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    match extension.as_str() {
        "obj" => load_obj(path),
        #[cfg(feature = "scene-files")]
        "glb" | "gltf" => crate::head_gltf::load_gltf(path),
        #[cfg(feature = "scene-files")]
        "usd" | "usda" | "usdc" | "usdz" => {
            Ok(strandlight_runtime::hair::usd::load_usd_mesh(path)?)
        }
        _ if is_mesh_file(path) => bail!(
            "{}: this build reads only OBJ heads (glTF and USD come with the scene-files feature)",
            path.display()
        ),
        _ => bail!(
            "{}: not a head mesh file (give one ending in {})",
            path.display(),
            MESH_EXTENSIONS.map(|e| format!(".{e}")).join(", ")
        ),
    }
}

/// Every triangle of every model in an OBJ file, merged into one mesh (triangulated, one index
/// per vertex; normals from the file where it has them for every vertex, else computed).
pub fn load_obj(path: &Path) -> anyhow::Result<TriangleMesh> {
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ignore_points: true,
        ignore_lines: true,
    };
    let (models, _materials) = tobj::load_obj(path, &options).with_context(|| {
        format!(
            "{}: not a readable OBJ mesh (the head must be a Wavefront .obj file with faces)",
            path.display()
        )
    })?;
    let mut positions = Vec::new();
    let mut normals = Vec::new();
    let mut indices = Vec::new();
    let mut every_normal = true;
    for model in &models {
        let mesh = &model.mesh;
        let base = positions.len() as u32;
        let count = mesh.positions.len() / 3;
        positions.extend(
            mesh.positions
                .chunks_exact(3)
                .map(|p| Vec3::new(p[0], p[1], p[2])),
        );
        if mesh.normals.len() == mesh.positions.len() {
            normals.extend(
                mesh.normals
                    .chunks_exact(3)
                    .map(|n| unit(Vec3::new(n[0], n[1], n[2]))),
            );
        } else {
            every_normal = false;
        }
        for &i in &mesh.indices {
            if i as usize >= count {
                bail!("{}: a face refers to vertex {i} of {count}", path.display());
            }
            indices.push(base + i);
        }
    }
    if indices.is_empty() {
        bail!(
            "{}: the OBJ file has no faces (a head mesh needs triangles or polygons)",
            path.display()
        );
    }
    if positions.iter().any(|p| !p.is_finite()) {
        bail!("{}: a vertex position is not finite", path.display());
    }
    Ok(match every_normal {
        true => TriangleMesh::new(positions, normals, indices),
        false => TriangleMesh::with_computed_normals(positions, indices),
    })
}

/// `mesh` as a Wavefront OBJ with per-vertex normals, which [`load_obj`] reads back exactly
/// (floats in their shortest exact form). Written whole or not at all.
pub fn write_obj(mesh: &TriangleMesh, path: &Path) -> anyhow::Result<()> {
    use std::io::Write;
    write_atomically(path, |out| {
        for p in &mesh.positions {
            writeln!(out, "v {} {} {}", p.x, p.y, p.z)?;
        }
        for n in &mesh.normals {
            writeln!(out, "vn {} {} {}", n.x, n.y, n.z)?;
        }
        for t in mesh.indices.chunks_exact(3) {
            let [a, b, c] = [t[0] + 1, t[1] + 1, t[2] + 1];
            writeln!(out, "f {a}//{a} {b}//{b} {c}//{c}")?;
        }
        Ok::<(), std::io::Error>(())
    })
    .with_context(|| format!("cannot write the head {}", path.display()))
}

/// `n` made unit length; a normal already unit to f32's rounding is kept as it is, so a mesh
/// written by [`write_obj`] reads back bit for bit.
fn unit(n: Vec3) -> Vec3 {
    if (n.length_squared() - 1.0).abs() <= 4.0 * f32::EPSILON {
        n
    } else {
        n.normalize_or(Vec3::Y)
    }
}

/// An axis-aligned ellipsoid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EllipsoidFit {
    pub center: Vec3,
    pub radii: Vec3,
    /// Whether the free six-parameter fit was kept (every root within 2 % of its surface).
    pub free_fit: bool,
}

/// Roots within this much of the free fit's implicit value 1 keep it.
const FREE_FIT_TOLERANCE: f64 = 0.02;

/// The head fitted to the strand roots (module documentation); every root ends on or outside it.
pub fn fit_root_ellipsoid(roots: &[Vec3]) -> anyhow::Result<EllipsoidFit> {
    let roots: Vec<DVec3> = roots
        .iter()
        .filter(|p| p.is_finite())
        .map(|p| p.as_dvec3())
        .collect();
    if roots.len() < 9 {
        bail!(
            "fitting a head to the strand roots needs at least 9 strands, the hair has {}",
            roots.len()
        );
    }
    let center = fit_sphere_center(&roots)
        .context("the strand roots are degenerate (all on a plane or a line): give --head FILE (a mesh) or --head none")?;
    let free = fit_free_ellipsoid(&roots).filter(|(c, r)| {
        roots.iter().all(|p| {
            ((*p - *c) / *r).length_squared().sqrt() - 1.0 < FREE_FIT_TOLERANCE
                && 1.0 - ((*p - *c) / *r).length_squared().sqrt() < FREE_FIT_TOLERANCE
        })
    });
    let (center, radii, free_fit) = match free {
        Some((c, r)) => (c, r, true),
        None => {
            let r = fit_radii_about(&roots, center)
                .context("the strand roots do not bound an ellipsoid about their centre: give --head FILE (a mesh) or --head none")?;
            (center, r, false)
        }
    };
    // Scale until the innermost root lies on the surface.
    let innermost = roots
        .iter()
        .map(|p| ((*p - center) / radii).length())
        .fold(f64::INFINITY, f64::min);
    let radii = radii * innermost.min(1.0);
    Ok(EllipsoidFit {
        center: center.as_vec3(),
        radii: radii.as_vec3(),
        free_fit,
    })
}

/// Solves the normal equations AᵀA x = Aᵀb of rows `a` (Gaussian elimination, partial pivot).
fn least_squares<const N: usize>(rows: impl Iterator<Item = ([f64; N], f64)>) -> Option<[f64; N]> {
    let mut m = [[0.0f64; N]; N];
    let mut v = [0.0f64; N];
    for (a, b) in rows {
        for i in 0..N {
            v[i] += a[i] * b;
            for j in 0..N {
                m[i][j] += a[i] * a[j];
            }
        }
    }
    let scale = (0..N).map(|i| m[i][i].abs()).fold(0.0, f64::max);
    for col in 0..N {
        let pivot = (col..N).max_by(|&a, &b| m[a][col].abs().total_cmp(&m[b][col].abs()))?;
        if m[pivot][col].abs() <= 1e-12 * scale {
            return None;
        }
        m.swap(col, pivot);
        v.swap(col, pivot);
        for row in 0..N {
            if row != col {
                let f = m[row][col] / m[col][col];
                let pivot_row = m[col];
                for (a, p) in m[row].iter_mut().zip(pivot_row) {
                    *a -= f * p;
                }
                v[row] -= f * v[col];
            }
        }
    }
    Some(std::array::from_fn(|i| v[i] / m[i][i]))
}

/// |p|² = 2c·p + k, linear in (c, k), centred on the roots' mean for conditioning.
fn fit_sphere_center(roots: &[DVec3]) -> Option<DVec3> {
    let mean = roots.iter().copied().sum::<DVec3>() / roots.len() as f64;
    let x = least_squares::<4>(roots.iter().map(|p| {
        let q = *p - mean;
        ([2.0 * q.x, 2.0 * q.y, 2.0 * q.z, 1.0], q.length_squared())
    }))?;
    Some(mean + DVec3::new(x[0], x[1], x[2]))
}

/// a x² + b y² + c z² + d x + e y + f z = 1 about the roots' mean.
fn fit_free_ellipsoid(roots: &[DVec3]) -> Option<(DVec3, DVec3)> {
    let mean = roots.iter().copied().sum::<DVec3>() / roots.len() as f64;
    let s = roots
        .iter()
        .map(|p| (*p - mean).length())
        .fold(0.0, f64::max)
        .max(1e-30);
    let x = least_squares::<6>(roots.iter().map(|p| {
        let q = (*p - mean) / s;
        ([q.x * q.x, q.y * q.y, q.z * q.z, q.x, q.y, q.z], 1.0)
    }))?;
    let quad = DVec3::new(x[0], x[1], x[2]);
    if quad.min_element() <= 0.0 {
        return None;
    }
    let lin = DVec3::new(x[3], x[4], x[5]);
    let c = -lin / (2.0 * quad);
    let g = 1.0 + (quad * c * c).element_sum();
    if g <= 0.0 {
        return None;
    }
    let radii = (DVec3::splat(g) / quad).map(f64::sqrt);
    Some((mean + c * s, radii * s))
}

/// a x² + b y² + c z² = 1 with the centre fixed.
fn fit_radii_about(roots: &[DVec3], center: DVec3) -> Option<DVec3> {
    let x = least_squares::<3>(roots.iter().map(|p| {
        let q = *p - center;
        ([q.x * q.x, q.y * q.y, q.z * q.z], 1.0)
    }))?;
    let quad = DVec3::from_array(x);
    (quad.min_element() > 0.0).then(|| quad.map(|v| 1.0 / v.sqrt()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use strandlight_runtime::hair::GroomParams;

    /// Roots over the top cap (polar angle ≤ 105°) of a known ellipsoid recover it exactly.
    #[test]
    fn roots_on_a_known_ellipsoid_cap_recover_it() {
        let (c, r) = (Vec3::new(1.0, -2.0, 3.0), Vec3::new(7.8, 9.5, 9.8));
        let mut roots = Vec::new();
        for i in 0..40 {
            for j in 0..40 {
                let polar = 105f32.to_radians() * (i as f32 + 0.5) / 40.0;
                let azimuth = std::f32::consts::TAU * j as f32 / 40.0;
                let unit = Vec3::new(
                    polar.sin() * azimuth.cos(),
                    polar.cos(),
                    polar.sin() * azimuth.sin(),
                );
                roots.push(c + unit * r);
            }
        }
        let fit = fit_root_ellipsoid(&roots).unwrap();
        assert!(fit.free_fit);
        assert!((fit.center - c).abs().max_element() < 1e-3, "{fit:?}");
        assert!((fit.radii - r).abs().max_element() < 1e-3, "{fit:?}");
    }

    /// The procedural groom grows from its scalp ellipsoid: the fit finds that scalp, and no
    /// root ends inside.
    #[test]
    fn the_procedural_groom_gives_back_its_scalp() {
        let params = GroomParams {
            strand_count: 800,
            ..GroomParams::default()
        };
        let model = strandlight_runtime::hair::generate_groom(&params).unwrap();
        let roots: Vec<Vec3> = model.strands().map(|s| s[0]).collect();
        let fit = fit_root_ellipsoid(&roots).unwrap();
        let scalp = &params.scalp;
        assert!(
            (fit.center - scalp.center).abs().max_element() < 0.05,
            "{fit:?}"
        );
        assert!(
            (fit.radii - scalp.radii).abs().max_element() < 0.05,
            "{fit:?}"
        );
        let inside = roots
            .iter()
            .map(|p| ((*p - fit.center) / fit.radii).length_squared())
            .fold(f32::INFINITY, f32::min);
        assert!(inside >= 1.0 - 1e-4, "a root inside the head: {inside}");
    }

    /// Roots on a cap with noise: the free fit is refused, the bounding fit keeps every root on
    /// or outside and touches the innermost.
    #[test]
    fn noisy_cap_roots_all_stay_outside_the_fitted_head() {
        let mut rng = strandlight_tables::split_mix::SplitMix64::new(3);
        let (c, r) = (Vec3::new(0.0, 0.0, 40.0), Vec3::new(20.0, 21.0, 20.0));
        let roots: Vec<Vec3> = (0..2000)
            .map(|_| {
                let polar = rng.range_f32(0.0, 1.2);
                let azimuth = rng.range_f32(0.0, std::f32::consts::TAU);
                let unit = Vec3::new(
                    polar.sin() * azimuth.cos(),
                    polar.sin() * azimuth.sin(),
                    polar.cos(),
                );
                c + unit * r * rng.range_f32(0.9, 1.2)
            })
            .collect();
        let fit = fit_root_ellipsoid(&roots).unwrap();
        assert!(!fit.free_fit);
        let q: Vec<f32> = roots
            .iter()
            .map(|p| ((*p - fit.center) / fit.radii).length())
            .collect();
        let min = q.iter().copied().fold(f32::INFINITY, f32::min);
        assert!((min - 1.0).abs() < 1e-4, "innermost root at {min}");
        // A head, not a sliver: each radius within 25 % of the true one scaled by 0.9.
        for a in 0..3 {
            let ratio = fit.radii[a] / (0.9 * r[a]);
            assert!((0.75..1.25).contains(&ratio), "{fit:?}");
        }
    }

    #[test]
    fn a_bad_obj_is_refused_naming_the_file() {
        let dir = std::env::temp_dir().join(format!("strandlight-head-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("broken.obj");
        std::fs::write(&path, "v 0 0 0\nv 1 0 0\nf 1 2 7\n").unwrap();
        let error = format!("{:#}", load_obj(&path).unwrap_err());
        assert!(error.contains("broken.obj"), "{error}");
        let empty = dir.join("points.obj");
        std::fs::write(&empty, "v 0 0 0\nv 1 0 0\n").unwrap();
        let error = format!("{:#}", load_obj(&empty).unwrap_err());
        assert!(
            error.contains("points.obj") && error.contains("no faces"),
            "{error}"
        );
        let missing = dir.join("missing.obj");
        let error = format!("{:#}", load_obj(&missing).unwrap_err());
        assert!(error.contains("missing.obj"), "{error}");
    }

    #[test]
    fn an_obj_quad_loads_as_two_triangles_with_normals() {
        let dir = std::env::temp_dir().join(format!("strandlight-head-q{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("quad.obj");
        std::fs::write(&path, "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n").unwrap();
        let mesh = load_obj(&path).unwrap();
        assert_eq!(mesh.triangle_count(), 2);
        assert!(mesh.normals.iter().all(|n| (*n - Vec3::Z).length() < 1e-6));
    }

    #[test]
    fn the_head_choice_parses_and_refuses_by_name() {
        assert_eq!(HeadChoice::parse("none"), Ok(HeadChoice::None));
        assert_eq!(HeadChoice::parse("ellipsoid"), Ok(HeadChoice::Ellipsoid));
        assert_eq!(
            HeadChoice::parse("a/head.OBJ"),
            Ok(HeadChoice::mesh("a/head.OBJ"))
        );
        assert!(
            HeadChoice::parse("head.ply")
                .unwrap_err()
                .contains("head.ply")
        );
        let several = HeadChoice::parse("a/skin.obj,b/eyes.glb").unwrap();
        assert_eq!(
            several,
            HeadChoice::Mesh(MeshFiles(vec!["a/skin.obj".into(), "b/eyes.glb".into()]))
        );
        assert_eq!(several.to_string(), "a/skin.obj,b/eyes.glb");
        let error = HeadChoice::parse("skin.obj,eyes.png").unwrap_err();
        assert!(error.contains("`eyes.png`"), "{error}");
    }

    /// One file is written as the path alone, as every settings file before several were
    /// taken; several as a list; both read back.
    #[test]
    fn mesh_files_are_written_as_one_path_or_a_list() {
        let one = HeadChoice::mesh("a.obj");
        assert_eq!(serde_json::to_string(&one).unwrap(), r#"{"mesh":"a.obj"}"#);
        let several = HeadChoice::parse("a.obj,b.obj").unwrap();
        let json = serde_json::to_string(&several).unwrap();
        assert_eq!(json, r#"{"mesh":["a.obj","b.obj"]}"#);
        for (json, choice) in [(r#"{"mesh":"a.obj"}"#, one), (json.as_str(), several)] {
            assert_eq!(serde_json::from_str::<HeadChoice>(json).unwrap(), choice);
        }
        let empty = serde_json::from_str::<HeadChoice>(r#"{"mesh":[]}"#).unwrap_err();
        assert!(empty.to_string().contains("names no file"), "{empty}");
    }

    /// A head from two OBJ files has both files' triangles; a missing second file is named.
    #[test]
    fn a_head_from_several_files_holds_every_files_triangles() {
        let dir = std::env::temp_dir().join(format!("strandlight-head-m{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let (quad, triangle) = (dir.join("quad.obj"), dir.join("tri.obj"));
        std::fs::write(&quad, "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n").unwrap();
        std::fs::write(&triangle, "v 0 0 2\nv 1 0 2\nv 0 1 2\nf 1 2 3\n").unwrap();
        let hair = HairModel::new(vec![Vec3::ZERO, Vec3::Y], vec![0, 2], None, None, None).unwrap();
        let list = format!("{},{}", quad.display(), triangle.display());
        let head = load_head(&HeadChoice::parse(&list).unwrap(), &hair, [0.5; 3])
            .unwrap()
            .unwrap();
        let HeadSurface::Mesh(mesh) = head.surface else {
            panic!("a mesh head")
        };
        assert_eq!(mesh.triangle_count(), 3);
        assert_eq!(mesh.positions[4].z, 2.0);
        let missing = format!("{},{}", quad.display(), dir.join("gone.obj").display());
        let error = format!(
            "{:#}",
            load_head(&HeadChoice::parse(&missing).unwrap(), &hair, [0.5; 3]).unwrap_err()
        );
        assert!(error.contains("gone.obj"), "{error}");
    }
}
