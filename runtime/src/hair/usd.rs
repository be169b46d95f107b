//! USD stages (`.usda`, `.usdc`, `.usdz`, `.usd`) through the pure-Rust `openusd` crate: every
//! `BasisCurves` prim that renders (active, defined, not invisible, not a guide or proxy) is a
//! batch of strands. Read from each prim: `points`, `curveVertexCounts`, `type`, `basis` and
//! `wrap` (cubic curves are evaluated at their segment ends, see `hair::curves`), `widths`
//! (the fiber diameter) and `primvars:displayColor` (linear RGB), each constant, uniform (per
//! curve), vertex or varying. Points are taken through the prim's and its ancestors' xform ops
//! (`!resetXformStack!` honoured), then to strandlight's world: Y up (a Z-up stage is turned so
//! that its front, −y, faces +z) and centimetres (`metersPerUnit`, USD's fallback 0.01).
//! Widths scale with the transform.
//!
//! The same stages' `Mesh` prims make a head ([`load_usd_mesh`]), in the same world.
//!
//! Not read: normals, `st`/UVs, `displayOpacity` and every other primvar, velocities, and time:
//! an animated attribute gives its earliest sample. Which prims were read and what was changed
//! or dropped is in [`LoadReport::info`](super::LoadReport::info).
//!
//! `openusd` is young; it is run under `catch_unwind` so that a file it panics on is refused
//! with the panic's message instead of ending the process.

use std::path::Path;

use glam::{DMat4, Vec3};
use openusd::schemas::geom::{Imageable, Xformable};
use openusd::sdf::{self, Value};
use openusd::usd::{Prim, PrimPredicate, SchemaBase, SchemaKind, Stage, TimeCode};

use super::HairError;
use super::clean::{HairFormat, LoadedHair, finish};
use super::curves::{
    Basis, CurveBatch, Interpolation, Shape, Values, Wrap, assemble, scene_to_world,
};
use super::guard::without_panics;
use crate::head::TriangleMesh;

const FORMAT: &str = "USD";

/// USD's fallback when a stage states no `metersPerUnit`: centimetres.
const DEFAULT_METERS_PER_UNIT: f64 = 0.01;

/// Reads the `BasisCurves` prims of a USD stage.
pub fn load_usd(path: &Path) -> Result<LoadedHair, HairError> {
    let (batches, mut info) = read_usd(path, read_stage)?;
    let (raw, notes) = assemble(batches, path)?;
    info.extend(notes);
    finish(raw, path, HairFormat::Usd, info.join("; "))
}

/// The `Mesh` prims of a USD stage that a renderer draws (as for curves: active, defined, not
/// invisible, not a guide or proxy), as one triangle mesh in strandlight's world (Y up,
/// centimetres), for a head. Read: `points`, `faceVertexCounts`, `faceVertexIndices` (polygons
/// fanned into triangles) and `orientation`; normals are computed from the faces, wound
/// outward (a `leftHanded` prim or a mirroring transform turns its faces). Not read: `normals`,
/// subdivision (the cage is drawn), `holeIndices`, UVs and every other primitive variable.
pub fn load_usd_mesh(path: &Path) -> Result<TriangleMesh, HairError> {
    read_usd(path, read_mesh_stage)
}

/// Opens the stage at `path` and runs `read` on it, with the reader's failures (and panics)
/// as errors naming the file.
fn read_usd<T>(
    path: &Path,
    read: impl FnOnce(&Stage, &Path) -> Result<T, Read>,
) -> Result<T, HairError> {
    // openusd reports a missing file as an anyhow error; the project's Io error names the
    // problem the same way for every format.
    std::fs::metadata(path).map_err(|source| HairError::Io {
        file: path.into(),
        action: "read",
        source,
    })?;
    let decode = |why: String| HairError::Decode {
        file: path.into(),
        format: FORMAT,
        why,
    };
    let text = path
        .to_str()
        .ok_or_else(|| decode("the path is not UTF-8".into()))?;
    check_text_prim_names(path)?;
    without_panics(path, FORMAT, || {
        let stage = Stage::open(text).map_err(|e| decode(format!("{e:#}")))?;
        read(&stage, path).map_err(|e| match e {
            Read::Hair(e) => e,
            Read::Usd(e) => decode(format!("{e:#}")),
        })
    })
}

/// Refuses a text layer whose `def`/`over`/`class` line names a prim with other characters than
/// an identifier's: openusd 0.6 recurses until the stack overflows (an abort, which no catch
/// stops) when composing such a prim (the fuzzer found `def BasisCurves "Curl}"`). Only text
/// layers can be checked here; the reader itself sees binary ones.
fn check_text_prim_names(path: &Path) -> Result<(), HairError> {
    let Ok(data) = std::fs::read(path) else {
        return Ok(()); // openusd reports it
    };
    if !data.starts_with(b"#usda") {
        return Ok(());
    }
    let text = String::from_utf8_lossy(&data);
    for (n, line) in text.lines().enumerate() {
        let line = line.trim_start();
        if !["def ", "over ", "class "]
            .iter()
            .any(|k| line.starts_with(k))
        {
            continue;
        }
        let Some(name) = line.split('"').nth(1) else {
            continue;
        };
        let mut chars = name.chars();
        let identifier = chars
            .next()
            .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
            && chars.all(|c| c.is_ascii_alphanumeric() || c == '_');
        if !identifier {
            return Err(HairError::Decode {
                file: path.into(),
                format: FORMAT,
                why: format!(
                    "line {}: prim name \"{}\" is not an identifier",
                    n + 1,
                    name.escape_debug()
                ),
            });
        }
    }
    Ok(())
}

enum Read {
    Hair(HairError),
    Usd(anyhow::Error),
}

impl From<anyhow::Error> for Read {
    fn from(e: anyhow::Error) -> Self {
        Read::Usd(e)
    }
}

impl From<HairError> for Read {
    fn from(e: HairError) -> Self {
        Read::Hair(e)
    }
}

/// The stage's units and up axis: (to strandlight's world, metersPerUnit, Z up).
fn stage_to_world(stage: &Stage, file: &Path) -> Result<(DMat4, f64, bool), Read> {
    let meters_per_unit = match stage.stage_metadata("metersPerUnit")? {
        Some(Value::Double(m)) => m,
        Some(Value::Float(m)) => m as f64,
        _ => DEFAULT_METERS_PER_UNIT,
    };
    let z_up =
        matches!(stage.stage_metadata("upAxis")?, Some(Value::Token(t)) if t.as_str() == "Z");
    if !(meters_per_unit.is_finite() && meters_per_unit > 0.0) {
        return Err(HairError::BadValue {
            file: file.into(),
            what: "metersPerUnit".into(),
            value: meters_per_unit.to_string(),
            why: "must be a positive number",
        }
        .into());
    }
    Ok((scene_to_world(z_up, meters_per_unit), meters_per_unit, z_up))
}

/// Every rendered `BasisCurves` prim as a batch in strandlight's world, and notes for the report.
fn read_stage(stage: &Stage, file: &Path) -> Result<(Vec<CurveBatch>, Vec<String>), Read> {
    let (to_world, meters_per_unit, z_up) = stage_to_world(stage, file)?;
    let mut paths = Vec::new();
    stage.traverse(PrimPredicate::default(), |p| paths.push(p.clone()))?;
    let mut batches = Vec::new();
    let mut skipped = Vec::new();
    for path in paths {
        let prim = stage.prim(path.clone());
        if prim.type_name()?.as_ref().map(|t| t.as_str()) != Some("BasisCurves") {
            continue;
        }
        if let Some(why) = not_rendered(&prim)? {
            skipped.push(format!("{} ({why})", path.as_str()));
            continue;
        }
        let local_to_world = world_transform(&prim)?;
        batches.push(read_prim(&prim, to_world * local_to_world, file)?);
    }
    if batches.is_empty() {
        return Err(HairError::NoCurves {
            file: file.into(),
            format: FORMAT,
            looked_for: "rendered BasisCurves prim",
        }
        .into());
    }
    let mut info = vec![format!(
        "USD: {} BasisCurves prim(s) ({}); upAxis {}, metersPerUnit {meters_per_unit} (to Y up, centimetres)",
        batches.len(),
        batches
            .iter()
            .map(|b| b.name.as_str())
            .collect::<Vec<_>>()
            .join(", "),
        if z_up { "Z" } else { "Y" },
    )];
    if !skipped.is_empty() {
        info.push(format!("not drawn: {}", printable(&skipped.join(", "))));
    }
    Ok((batches, info))
}

/// Every rendered `Mesh` prim's faces, fanned into triangles, in strandlight's world.
fn read_mesh_stage(stage: &Stage, file: &Path) -> Result<TriangleMesh, Read> {
    let (to_world, _, _) = stage_to_world(stage, file)?;
    let mut paths = Vec::new();
    stage.traverse(PrimPredicate::default(), |p| paths.push(p.clone()))?;
    let (mut positions, mut indices) = (Vec::new(), Vec::new());
    for path in paths {
        let prim = stage.prim(path.clone());
        if prim.type_name()?.as_ref().map(|t| t.as_str()) != Some("Mesh")
            || not_rendered(&prim)?.is_some()
        {
            continue;
        }
        let to_world = to_world * world_transform(&prim)?;
        let base = positions.len() as u32;
        let (points, triangles) = read_mesh_prim(&prim, to_world, file)?;
        positions.extend(points);
        indices.extend(triangles.into_iter().map(|i| base + i));
    }
    if indices.is_empty() {
        return Err(HairError::Decode {
            file: file.into(),
            format: FORMAT,
            why: "no rendered Mesh prim with faces, so there is no head to draw".into(),
        }
        .into());
    }
    Ok(TriangleMesh::with_computed_normals(positions, indices))
}

/// One `Mesh` prim's points (in the world `to_world` takes them to) and triangles (indices into
/// those points), wound counter-clockwise seen from outside.
fn read_mesh_prim(
    prim: &Prim,
    to_world: DMat4,
    file: &Path,
) -> Result<(Vec<Vec3>, Vec<u32>), Read> {
    let name = printable(prim.path().as_str());
    let bad = |problem: String| HairError::BadCurves {
        file: file.into(),
        at: name.clone(),
        problem,
    };
    let points = points(prim, &bad)?;
    let counts = int_array(prim, "faceVertexCounts", &bad)?;
    let corners = int_array(prim, "faceVertexIndices", &bad)?;
    let mirrored = (token(prim, "orientation")?.as_deref() == Some("leftHanded"))
        != (to_world.determinant() < 0.0);
    let mut triangles = Vec::new();
    let mut at = 0usize;
    for (face, &count) in counts.iter().enumerate() {
        let Some(face_corners) = usize::try_from(count)
            .ok()
            .filter(|&n| n >= 3)
            .and_then(|n| corners.get(at..at.checked_add(n)?))
        else {
            return Err(bad(format!(
                "face {face} has {count} corners where faceVertexIndices has {} left (a face needs at least 3)",
                corners.len().saturating_sub(at)
            ))
            .into());
        };
        at += face_corners.len();
        let corner = |i: i64| {
            u32::try_from(i)
                .ok()
                .filter(|&i| (i as usize) < points.len())
                .ok_or_else(|| bad(format!("face {face} names point {i} of {}", points.len())))
        };
        let first = corner(face_corners[0])?;
        for pair in face_corners[1..].windows(2) {
            let (b, c) = (corner(pair[0])?, corner(pair[1])?);
            triangles.extend(if mirrored {
                [first, c, b]
            } else {
                [first, b, c]
            });
        }
    }
    if at != corners.len() {
        return Err(bad(format!(
            "faceVertexCounts add up to {at} corners but faceVertexIndices has {}",
            corners.len()
        ))
        .into());
    }
    let world: Vec<Vec3> = points
        .iter()
        .map(|p| to_world.transform_point3(p.as_dvec3()).as_vec3())
        .collect();
    if let Some(p) = world.iter().find(|p| !p.is_finite()) {
        return Err(bad(format!("a point is not finite in the world ({p})")).into());
    }
    Ok((world, triangles))
}

/// A name for the report: control characters (which a damaged file can put in names) escaped.
pub(crate) fn printable(name: &str) -> String {
    name.chars()
        .flat_map(|c| {
            let escaped: Vec<char> = if c.is_control() {
                c.escape_default().collect()
            } else {
                vec![c]
            };
            escaped
        })
        .collect()
}

/// Why a prim is not drawn by a renderer: hidden by itself or an ancestor, or a guide/proxy.
fn not_rendered(prim: &Prim) -> anyhow::Result<Option<&'static str>> {
    let mut at = Some(prim.path().clone());
    while let Some(path) = at {
        if path == sdf::Path::abs_root() {
            break;
        }
        let p = prim.stage().prim(path.clone());
        if token(&p, "visibility")?.as_deref() == Some("invisible") {
            return Ok(Some("invisible"));
        }
        match token(&p, "purpose")?.as_deref() {
            Some("guide") => return Ok(Some("purpose guide")),
            Some("proxy") => return Ok(Some("purpose proxy")),
            _ => {}
        }
        at = path.parent();
    }
    Ok(None)
}

/// Any prim seen as xformable, so that the crate's xform-op evaluation applies to ancestors of
/// every type (Xform, Scope-like groups, SkelRoot, a Mesh with hair below it).
struct AnyXformable(Prim);

impl SchemaBase for AnyXformable {
    const KIND: SchemaKind = SchemaKind::ConcreteTyped;
    fn prim(&self) -> &Prim {
        &self.0
    }
}
impl Imageable for AnyXformable {}
impl Xformable for AnyXformable {}

/// The prim's local-to-world transform (column vectors), its ancestors' ops included until one
/// resets the stack.
fn world_transform(prim: &Prim) -> anyhow::Result<DMat4> {
    let mut m = DMat4::IDENTITY;
    let mut at = Some(prim.path().clone());
    while let Some(path) = at {
        if path == sdf::Path::abs_root() {
            break;
        }
        let x = AnyXformable(prim.stage().prim(path.clone()));
        check_op_names(&x)?;
        // openusd's matrices are USD's row-vector ones; read column-major they are the
        // column-vector matrix glam applies.
        let local = x.local_to_parent_transform(TimeCode::EARLIEST)?;
        m = DMat4::from_cols_array(&local.0) * m;
        if x.resets_xform_stack()? {
            break;
        }
        at = path.parent();
    }
    Ok(m)
}

/// Refuses an `xformOpOrder` entry that is no attribute name: openusd 0.6 never returns when
/// asked for such an op's value (the fuzzer found one with a string spanning lines).
fn check_op_names(x: &AnyXformable) -> anyhow::Result<()> {
    let valid = |op: &str| {
        let name = op.strip_prefix("!invert!").unwrap_or(op);
        op == "!resetXformStack!"
            || (name.starts_with("xformOp:")
                && name
                    .chars()
                    .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == ':'))
    };
    for op in x.xform_op_order()?.unwrap_or_default() {
        if !valid(&op) {
            anyhow::bail!(
                "{}: xformOpOrder names {:?}, which is not an xformOp attribute",
                x.0.path().as_str(),
                op.escape_debug().to_string()
            );
        }
    }
    Ok(())
}

fn read_prim(prim: &Prim, to_world: DMat4, file: &Path) -> Result<CurveBatch, Read> {
    let name = prim.path().as_str().to_string();
    let bad = |problem: String| HairError::BadCurves {
        file: file.into(),
        at: name.clone(),
        problem,
    };
    let points = points(prim, &bad)?;
    let counts = int_array(prim, "curveVertexCounts", &bad)?;
    let shape = match token(prim, "type")?.as_deref() {
        None | Some("cubic") => Shape::Cubic(match token(prim, "basis")?.as_deref() {
            None | Some("bezier") => Basis::Bezier,
            Some("bspline") => Basis::Bspline,
            Some("catmullRom") => Basis::CatmullRom,
            Some(other) => return Err(bad(format!("unsupported cubic basis {other:?}")).into()),
        }),
        Some("linear") => Shape::Linear,
        Some(other) => return Err(bad(format!("unknown curve type {other:?}")).into()),
    };
    let wrap = match token(prim, "wrap")?.as_deref() {
        None | Some("nonperiodic") => Wrap::Open,
        Some("periodic") => Wrap::Periodic,
        Some("pinned") => Wrap::Pinned,
        Some(other) => return Err(bad(format!("unknown wrap {other:?}")).into()),
    };
    let widths = match value(prim, "widths")? {
        Some(v) => Some(Values {
            values: floats(v).ok_or_else(|| bad("widths are not a float array".into()))?,
            declared: interpolation(prim, "widths")?,
        }),
        None => None,
    };
    let colors = match value(prim, "primvars:displayColor")? {
        Some(v) => Some(Values {
            values: vec3s(v).ok_or_else(|| bad("displayColor is not a color3 array".into()))?,
            declared: interpolation(prim, "primvars:displayColor")?,
        }),
        None => None,
    };
    Ok(CurveBatch {
        name,
        points,
        counts,
        shape,
        wrap,
        to_world,
        widths,
        colors,
    })
}

/// A prim's `points`; `bad` says what is wrong with them.
fn points(prim: &Prim, bad: &impl Fn(String) -> HairError) -> Result<Vec<Vec3>, Read> {
    Ok(value(prim, "points")?
        .map(vec3s)
        .ok_or_else(|| bad("no points".into()))?
        .ok_or_else(|| bad("points are not an array of 3-vectors".into()))?)
}

/// An int or int64 array attribute; `bad` says it is missing or of another type.
fn int_array(
    prim: &Prim,
    attribute: &str,
    bad: &impl Fn(String) -> HairError,
) -> Result<Vec<i64>, Read> {
    match value(prim, attribute)? {
        Some(Value::IntVec(v)) => Ok(v.into_iter().map(i64::from).collect()),
        Some(Value::Int64Vec(v)) => Ok(v),
        Some(_) => Err(bad(format!("{attribute} is not an int array")).into()),
        None => Err(bad(format!("no {attribute}")).into()),
    }
}

/// The attribute's earliest time sample, or its default value.
fn value(prim: &Prim, name: &str) -> anyhow::Result<Option<Value>> {
    let attribute = prim.attribute(name);
    match attribute.get_at::<Value>(TimeCode::EARLIEST)? {
        Some(v) => Ok(Some(v)),
        None => attribute.get::<Value>(),
    }
}

fn token(prim: &Prim, name: &str) -> anyhow::Result<Option<String>> {
    Ok(match value(prim, name)? {
        Some(Value::Token(t)) => Some(t.as_str().to_string()),
        Some(Value::String(s)) => Some(s),
        _ => None,
    })
}

fn interpolation(prim: &Prim, name: &str) -> anyhow::Result<Option<Interpolation>> {
    let declared = prim
        .attribute(name)
        .get_metadata::<Value>("interpolation")?;
    Ok(match declared {
        Some(Value::Token(t)) => match t.as_str() {
            "constant" => Some(Interpolation::Constant),
            "uniform" => Some(Interpolation::Uniform),
            "vertex" => Some(Interpolation::Vertex),
            "varying" => Some(Interpolation::Varying),
            _ => None,
        },
        _ => None,
    })
}

fn vec3s(v: Value) -> Option<Vec<Vec3>> {
    Some(match v {
        Value::Vec3fVec(v) => v.into_iter().map(|p| Vec3::new(p.x, p.y, p.z)).collect(),
        Value::Vec3dVec(v) => v
            .into_iter()
            .map(|p| Vec3::new(p.x as f32, p.y as f32, p.z as f32))
            .collect(),
        Value::Vec3hVec(v) => v
            .into_iter()
            .map(|p| Vec3::new(p.x.to_f32(), p.y.to_f32(), p.z.to_f32()))
            .collect(),
        _ => return None,
    })
}

fn floats(v: Value) -> Option<Vec<f32>> {
    Some(match v {
        Value::FloatVec(v) => v,
        Value::DoubleVec(v) => v.into_iter().map(|w| w as f32).collect(),
        Value::HalfVec(v) => v.into_iter().map(|w| w.to_f32()).collect(),
        Value::Float(w) => vec![w],
        Value::Double(w) => vec![w as f32],
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Writes `body` (prims) under a usda header into a temp file named `name` and loads it.
    fn load_usda(name: &str, header: &str, body: &str) -> Result<LoadedHair, HairError> {
        let dir = std::env::temp_dir().join(format!("strandlight-usd-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join(name);
        std::fs::write(&file, format!("#usda 1.0\n(\n{header}\n)\n\n{body}\n")).unwrap();
        load_usd(&file)
    }

    const TWO_CURVES: &str = r#"
def Xform "Groom" (
) {
    double3 xformOp:translate = (10, 0, 0)
    uniform token[] xformOpOrder = ["xformOp:translate"]
    def BasisCurves "Hair" {
        uniform token type = "linear"
        int[] curveVertexCounts = [2, 3]
        point3f[] points = [(0, 0, 0), (0, 0, 1), (1, 0, 0), (1, 0, 1), (1, 0, 2)]
        float[] widths = [0.5] (interpolation = "constant")
    }
}
"#;

    #[test]
    fn units_up_axis_and_xforms_reach_the_points() {
        let loaded = load_usda("two.usda", "upAxis = \"Z\"\nmetersPerUnit = 1", TWO_CURVES)
            .unwrap_or_else(|e| panic!("{e}"));
        let m = &loaded.model;
        assert_eq!(m.strand_offsets(), &[0, 2, 5]);
        // Translated by 10 along x, Z up turned to Y up, metres to centimetres.
        assert_eq!(
            m.strand(0),
            &[Vec3::new(1000.0, 0.0, 0.0), Vec3::new(1000.0, 100.0, 0.0)]
        );
        assert_eq!(m.strand(1)[2], Vec3::new(1100.0, 200.0, 0.0));
        assert_eq!(m.thickness(), Some(&super::super::Attribute::Uniform(50.0)));
        // USD's fallbacks: Y up, centimetres.
        let m = load_usda("plain.usda", "", TWO_CURVES).unwrap().model;
        assert_eq!(m.strand(1)[2], Vec3::new(11.0, 0.0, 2.0));
    }

    #[test]
    fn a_reset_xform_stack_drops_the_parents_transform() {
        let body = TWO_CURVES.replace(
            "uniform token type",
            "uniform token[] xformOpOrder = [\"!resetXformStack!\"]\n        uniform token type",
        );
        let m = load_usda("reset.usda", "", &body).unwrap().model;
        assert_eq!(m.strand(1)[2], Vec3::new(1.0, 0.0, 2.0));
    }

    #[test]
    fn cubic_bspline_curves_are_drawn_through_their_segment_ends() {
        // Four collinear control points at x = 0, 6, 12, 18: one segment from x = 6 to 12.
        let body = r#"
def BasisCurves "Hair" {
    uniform token type = "cubic"
    uniform token basis = "bspline"
    int[] curveVertexCounts = [4]
    point3f[] points = [(0, 0, 0), (6, 0, 0), (12, 0, 0), (18, 0, 0)]
}
"#;
        let m = load_usda("bspline.usda", "", body).unwrap().model;
        assert_eq!(
            m.strand(0),
            &[Vec3::new(6.0, 0.0, 0.0), Vec3::new(12.0, 0.0, 0.0)]
        );
        // Pinned: the curve reaches the end points, one segment per gap.
        let pinned = body.replace(
            "\"bspline\"",
            "\"bspline\"\n    uniform token wrap = \"pinned\"",
        );
        let m = load_usda("pinned.usda", "", &pinned).unwrap().model;
        let xs: Vec<f32> = m.strand(0).iter().map(|p| p.x).collect();
        assert_eq!(xs, [0.0, 6.0, 12.0, 18.0]);
    }

    #[test]
    fn bad_stages_give_errors_that_name_the_file_and_the_problem() {
        let check = |name: &str, body: &str, kind: &str, says: &str| {
            let e = load_usda(name, "", body).unwrap_err();
            let text = e.to_string();
            assert!(format!("{e:?}").starts_with(kind), "{name}: {e:?}");
            assert!(text.contains(name) && text.contains(says), "{name}: {text}");
        };
        check(
            "counts.usda",
            &TWO_CURVES.replace("[2, 3]", "[2, 4]"),
            "BadCurves",
            "sum to 6, but it has 5 points",
        );
        check(
            "negative.usda",
            &TWO_CURVES.replace("[2, 3]", "[-1, 6]"),
            "BadCurves",
            "negative vertex count",
        );
        check(
            "nan.usda",
            &TWO_CURVES.replace("(1, 0, 1)", "(1, nan, 1)"),
            "NonFinite",
            "strand 1, point 1",
        );
        check(
            "none.usda",
            "def Xform \"Empty\" {\n}\n",
            "NoCurves",
            "no rendered BasisCurves prim",
        );
        check(
            "hidden.usda",
            &TWO_CURVES.replace(
                "uniform token type",
                "token visibility = \"invisible\"\n        uniform token type",
            ),
            "NoCurves",
            "BasisCurves",
        );
        check(
            "garbage.usda",
            "this is { not usda",
            "Decode",
            "cannot read as USD",
        );
        check(
            "name.usda",
            &TWO_CURVES.replace("\"Hair\"", "\"Ha}r\""),
            "Decode",
            "prim name \"Ha}r\" is not an identifier",
        );
        check(
            "short.usda",
            &TWO_CURVES
                .replace("\"cubic\"", "")
                .replace("\"linear\"", "\"cubic\""),
            "BadCurves",
            "do not make whole Bezier segments",
        );
    }

    #[test]
    fn widths_of_no_fitting_count_are_dropped_with_a_note() {
        let body = TWO_CURVES.replace("float[] widths = [0.5]", "float[] widths = [0.5, 0.5, 0.5]");
        let loaded = load_usda("widths.usda", "", &body).unwrap();
        assert_eq!(loaded.model.thickness(), None);
        assert!(
            loaded.report.info.contains("3 values fit no interpolation"),
            "{}",
            loaded.report.info
        );
    }
}
