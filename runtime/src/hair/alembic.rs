//! Alembic archives (`.abc`, Ogawa back end) through the `ogawa-rs` crate: every `ICurves`
//! object (schema `AbcGeom_Curve_v2`) is a batch of strands. Read from each: `P`, `nVertices`,
//! `curveBasisAndType` (linear, or cubic Bézier / B-spline / Catmull-Rom, evaluated at segment
//! ends as in `hair::curves`) and `width` (con, uni, vtx or var scope). Points are taken
//! through the `IXform` parents' ops (translate, rotate about an axis, rotate x/y/z, scale,
//! matrix; `inherits` off stops the chain), composed as AbcGeom's `XformSample::getMatrix`.
//!
//! Alembic states no units and is Y up by convention: points keep the file's units. Not read:
//! normals, UVs, velocities, `w` weights, variable-order (NURBS) curves, indexed widths,
//! arbitrary geometry parameters, and time: the first sample of everything.
//!
//! The container is checked first (`hair::ogawa`) and `ogawa-rs` runs under
//! `catch_unwind`, so that a damaged archive is refused with a message.

use std::io::{Cursor, Read, Seek, SeekFrom};
use std::path::Path;

use glam::{DMat4, DVec3, Vec3};
use ogawa_rs::{
    Archive, ArchiveReader, BasisType, CurvePeriodicity, CurveType, CurvesSchema, ObjectReader,
    PodArray, PropertyReader, U8_TYPE,
};

use super::HairError;
use super::clean::{HairFormat, LoadedHair, finish};
use super::curves::{Basis, CurveBatch, Interpolation, Shape, Values, Wrap, assemble};
use super::guard::without_panics;

const FORMAT: &str = "Alembic";
const CURVES_SCHEMA: &str = "AbcGeom_Curve_v2";
const XFORM_SCHEMA: &str = "AbcGeom_Xform_v3";

/// Reads the `ICurves` of an Alembic archive.
pub fn load_alembic(path: &Path) -> Result<LoadedHair, HairError> {
    let data = super::read_file(path)?;
    parse_alembic(&data, path)
}

/// Decodes Alembic bytes; `file` only names the source in errors.
pub fn parse_alembic(data: &[u8], file: &Path) -> Result<LoadedHair, HairError> {
    super::ogawa::check_container(data, file)?;
    let batches = without_panics(file, FORMAT, || read_archive(data, file))?;
    let names: Vec<_> = batches.iter().map(|b| b.name.clone()).collect();
    let (raw, notes) = assemble(batches, file)?;
    let mut info = vec![format!(
        "Alembic: {} ICurves object(s) ({}); no units in Alembic, the file's kept",
        names.len(),
        super::usd::printable(&names.join(", "))
    )];
    info.extend(notes);
    finish(raw, file, HairFormat::Alembic, info.join("; "))
}

/// The bytes as `ogawa-rs` reads them.
struct Bytes<'a>(Cursor<&'a [u8]>);

impl Read for Bytes<'_> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        self.0.read(buf)
    }
}

impl Seek for Bytes<'_> {
    fn seek(&mut self, pos: SeekFrom) -> std::io::Result<u64> {
        self.0.seek(pos)
    }
}

impl ArchiveReader for Bytes<'_> {
    fn size(&self) -> u64 {
        self.0.get_ref().len() as u64
    }
}

struct Reader<'a> {
    bytes: Bytes<'a>,
    archive: Archive,
    file: &'a Path,
}

impl Reader<'_> {
    fn decode(&self, why: impl std::fmt::Display) -> HairError {
        decode_error(self.file, why)
    }
}

fn decode_error(file: &Path, why: impl std::fmt::Display) -> HairError {
    HairError::Decode {
        file: file.into(),
        format: FORMAT,
        why: why.to_string(),
    }
}

fn read_archive(data: &[u8], file: &Path) -> Result<Vec<CurveBatch>, HairError> {
    let mut bytes = Bytes(Cursor::new(data));
    let archive = Archive::new(&mut bytes).map_err(|e| decode_error(file, e))?;
    let mut r = Reader {
        bytes,
        archive,
        file,
    };
    let root = r
        .archive
        .load_root_object(&mut r.bytes)
        .map_err(|e| r.decode(e))?;
    let mut batches = Vec::new();
    // Depth-first over objects, each with its parent's world transform.
    let mut stack = vec![(root, DMat4::IDENTITY)];
    while let Some((object, parent)) = stack.pop() {
        let world = match schema(&mut r, &object)?.as_deref() {
            Some(XFORM_SCHEMA) => xform(&mut r, &object, parent)?,
            Some(CURVES_SCHEMA) => {
                batches.push(curves(&mut r, &object, parent)?);
                parent
            }
            _ => parent,
        };
        for i in (0..object.child_count()).rev() {
            let child = object
                .load_child(
                    i,
                    &mut r.bytes,
                    &r.archive.indexed_meta_data,
                    &r.archive.time_samplings,
                )
                .map_err(|e| r.decode(e))?;
            stack.push((child, world));
        }
    }
    if batches.is_empty() {
        return Err(HairError::NoCurves {
            file: file.into(),
            format: FORMAT,
            looked_for: "ICurves object",
        });
    }
    Ok(batches)
}

/// The object's schema: in its header, or (for xforms) on its first compound property.
fn schema(r: &mut Reader, object: &ObjectReader) -> Result<Option<String>, HairError> {
    if let Some(s) = object.header.meta_data.tokens.get("schema") {
        return Ok(Some(s.clone()));
    }
    match first_compound(r, object)? {
        Some(c) => Ok(compound_meta(&c, "schema")),
        None => Ok(None),
    }
}

fn first_compound(
    r: &mut Reader,
    object: &ObjectReader,
) -> Result<Option<PropertyReader>, HairError> {
    let Some(properties) = object.properties() else {
        return Ok(None);
    };
    if properties.sub_property_count() == 0 {
        return Ok(None);
    }
    let first = properties
        .load_sub_property(0, &mut r.bytes, &r.archive)
        .map_err(|e| r.decode(e))?;
    Ok(matches!(first, PropertyReader::Compound(_)).then_some(first))
}

fn compound_meta(p: &PropertyReader, key: &str) -> Option<String> {
    match p {
        PropertyReader::Compound(c) => c.header.meta_data.tokens.get(key).cloned(),
        _ => None,
    }
}

/// The xform's world transform: `parent` times its ops, or its ops alone when it does not
/// inherit.
fn xform(r: &mut Reader, object: &ObjectReader, parent: DMat4) -> Result<DMat4, HairError> {
    let Some(PropertyReader::Compound(xform)) = first_compound(r, object)? else {
        return Ok(parent);
    };
    let file = r.file;
    let mut sub = |name: &str| {
        xform
            .load_sub_property_by_name(name, &mut r.bytes, &r.archive)
            .map_err(|e| decode_error(file, e))
    };
    let (ops, vals, inherits) = (sub(".ops")?, sub(".vals")?, sub(".inherits")?);
    let ops = match ops {
        Some(p) => match first_sample(r, &p)? {
            PodArray::U8(ops) => ops,
            _ => {
                return Err(r.decode(format!(
                    "{}: .ops is not a byte array",
                    object.header.full_name
                )));
            }
        },
        None => Vec::new(),
    };
    let vals = match vals {
        Some(p) => match first_sample(r, &p)? {
            PodArray::F64(v) => v,
            PodArray::F32(v) => v.into_iter().map(f64::from).collect(),
            _ => return Err(r.decode(format!("{}: .vals are not floats", object.header.full_name))),
        },
        None => Vec::new(),
    };
    let local = xform_matrix(&ops, &vals).map_err(|why| HairError::BadCurves {
        file: r.file.into(),
        at: object.header.full_name.clone(),
        problem: why,
    })?;
    // ogawa-rs cannot decode a bool sample (todo!()); a bool is one byte after the 16-byte key.
    let inherits = match inherits {
        Some(PropertyReader::Scalar(s)) => {
            let chunk = s
                .group
                .load_data(&mut r.bytes, 0)
                .map_err(|e| r.decode(e))?;
            match chunk.read_pod_array(&U8_TYPE, &mut r.bytes) {
                Ok(PodArray::U8(b)) => b.first().is_none_or(|&b| b != 0),
                _ => true,
            }
        }
        _ => true,
    };
    Ok(if inherits { parent * local } else { local })
}

/// AbcGeom's op codes (`XformOperationType`, the high nibble of each `.ops` byte) and their
/// channels: scale 3, translate 3, rotate 4 (axis, degrees), matrix 16, rotate x/y/z 1.
fn xform_matrix(ops: &[u8], vals: &[f64]) -> Result<DMat4, String> {
    let mut m = DMat4::IDENTITY;
    let mut at = 0usize;
    for &op in ops {
        let kind = op >> 4;
        let channels = match kind {
            0 | 1 => 3,
            2 => 4,
            3 => 16,
            4..=6 => 1,
            _ => return Err(format!("unknown xform op {kind}")),
        };
        let v = vals.get(at..at + channels).ok_or_else(|| {
            format!(
                "the xform ops need more than the {} values given",
                vals.len()
            )
        })?;
        at += channels;
        let v3 = || DVec3::new(v[0], v[1], v[2]);
        let op_matrix = match kind {
            0 => DMat4::from_scale(v3()),
            1 => DMat4::from_translation(v3()),
            2 => DMat4::from_axis_angle(v3().normalize_or_zero(), v[3].to_radians()),
            // Imath's row-major, row-vector matrix read column-major is the column-vector one.
            3 => DMat4::from_cols_slice(v),
            4 => DMat4::from_rotation_x(v[0].to_radians()),
            5 => DMat4::from_rotation_y(v[0].to_radians()),
            _ => DMat4::from_rotation_z(v[0].to_radians()),
        };
        // The first op is outermost, as in getMatrix().
        m *= op_matrix;
    }
    Ok(m)
}

fn first_sample(r: &mut Reader, p: &PropertyReader) -> Result<PodArray, HairError> {
    let sample = match p {
        PropertyReader::Scalar(s) => s.load_sample(0, &mut r.bytes),
        PropertyReader::Array(a) => a.load_sample(0, &mut r.bytes),
        PropertyReader::Compound(_) => {
            return Err(r.decode("a compound where a value was expected"));
        }
    };
    sample.map_err(|e| r.decode(e))
}

fn curves(r: &mut Reader, object: &ObjectReader, to_world: DMat4) -> Result<CurveBatch, HairError> {
    let name = object.header.full_name.clone();
    let at = |e: ogawa_rs::OgawaError| HairError::Decode {
        file: r.file.into(),
        format: FORMAT,
        why: format!("{name}: {e}"),
    };
    let schema = CurvesSchema::new_from_object_reader(object, &mut r.bytes, &r.archive)
        .map_err(|e| r.decode(format!("{name}: {e}")))?;
    let bytes = &mut r.bytes;
    let points = schema.load_positions_sample(0, bytes).map_err(at)?;
    let counts = schema.load_n_vertices_sample(0, bytes).map_err(at)?;
    let (kind, periodicity, basis) = schema.load_curve_type_sample(0, bytes).map_err(at)?;
    let widths = schema.load_widths_sample(0, bytes).map_err(at)?;
    let bad = |problem: String| HairError::BadCurves {
        file: r.file.into(),
        at: name.clone(),
        problem,
    };
    let shape = match (kind, basis) {
        (CurveType::Linear, _) => Shape::Linear,
        (CurveType::Cubic, BasisType::Bezier) => Shape::Cubic(Basis::Bezier),
        (CurveType::Cubic, BasisType::Bspline) => Shape::Cubic(Basis::Bspline),
        (CurveType::Cubic, BasisType::Catmullrom) => Shape::Cubic(Basis::CatmullRom),
        (CurveType::Cubic, other) => return Err(bad(format!("unsupported cubic basis {other:?}"))),
        (CurveType::VariableOrder, _) => {
            return Err(bad("variable-order (NURBS) curves are not supported".into()));
        }
    };
    let wrap = match periodicity {
        CurvePeriodicity::NonPeriodic => Wrap::Open,
        CurvePeriodicity::Periodic => Wrap::Periodic,
    };
    let scope = width_scope(r, object)?;
    Ok(CurveBatch {
        name,
        points: points.into_iter().map(Vec3::from_array).collect(),
        counts: counts.into_iter().map(i64::from).collect(),
        shape,
        wrap,
        to_world,
        widths: widths.map(|values| Values {
            values,
            declared: scope,
        }),
        colors: None,
    })
}

/// The `geoScope` of the curves' `width` parameter.
fn width_scope(r: &mut Reader, object: &ObjectReader) -> Result<Option<Interpolation>, HairError> {
    let Some(PropertyReader::Compound(geom)) = first_compound(r, object)? else {
        return Ok(None);
    };
    let width = geom
        .load_sub_property_by_name("width", &mut r.bytes, &r.archive)
        .map_err(|e| r.decode(e))?;
    let scope = match &width {
        Some(PropertyReader::Array(a)) => a.header.meta_data.tokens.get("geoScope").cloned(),
        _ => None,
    };
    Ok(match scope.as_deref() {
        Some("con") => Some(Interpolation::Constant),
        Some("uni") => Some(Interpolation::Uniform),
        Some("vtx") => Some(Interpolation::Vertex),
        Some("var") => Some(Interpolation::Varying),
        _ => None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ops_compose_outermost_first() {
        // translate (1, 0, 0) then scale 2: a point at x = 1 goes to 2, then to 3.
        let m = xform_matrix(&[0x10, 0x00], &[1.0, 0.0, 0.0, 2.0, 2.0, 2.0]).unwrap();
        assert_eq!(m.transform_point3(DVec3::X), DVec3::new(3.0, 0.0, 0.0));
        // rotate 90° about z (axis-angle), as Imath: +x to +y.
        let m = xform_matrix(&[0x20], &[0.0, 0.0, 1.0, 90.0]).unwrap();
        assert!((m.transform_point3(DVec3::X) - DVec3::Y).length() < 1e-12);
        assert!(xform_matrix(&[0x10], &[1.0]).is_err());
        assert!(xform_matrix(&[0x70], &[1.0]).is_err());
    }
}
