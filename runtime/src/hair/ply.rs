//! Hair strands in binary little-endian PLY, as hapPLY-based tools (e.g. hairutil) write them:
//! an element `vertex` with `x y z` (float or double) and optionally `red green blue`
//! (uchar 0–255 or float), and an element `strand` with a segment count `nsegs` per strand;
//! strand `s` owns the next `nsegs + 1` vertices. Other elements (such as `edge`) are read past,
//! and the elements together must fill the file exactly.
//! ASCII and big-endian PLY are refused with a clear error.

use std::path::Path;

use glam::Vec3;

use super::bytes::FileBytes;
use super::clean::{HairFormat, LoadedHair, RawHair, finish};
use super::{Attribute, HairError};

const FORMAT: &str = "PLY";
const HEADER_LIMIT: usize = 64 * 1024;

/// Reads a `.ply` file.
pub fn load_ply(path: &Path) -> Result<LoadedHair, HairError> {
    let data = super::read_file(path)?;
    parse_ply(&data, path)
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(name: &str) -> Option<Self> {
        Some(match name {
            "char" | "int8" => Self::I8,
            "uchar" | "uint8" => Self::U8,
            "short" | "int16" => Self::I16,
            "ushort" | "uint16" => Self::U16,
            "int" | "int32" => Self::I32,
            "uint" | "uint32" => Self::U32,
            "float" | "float32" => Self::F32,
            "double" | "float64" => Self::F64,
            _ => return None,
        })
    }

    fn size(self) -> u64 {
        match self {
            Self::I8 | Self::U8 => 1,
            Self::I16 | Self::U16 => 2,
            Self::I32 | Self::U32 | Self::F32 => 4,
            Self::F64 => 8,
        }
    }

    /// The value at the start of `b` (which holds at least `size()` bytes).
    fn read(self, b: &[u8]) -> f64 {
        match self {
            Self::I8 => b[0] as i8 as f64,
            Self::U8 => b[0] as f64,
            Self::I16 => i16::from_le_bytes([b[0], b[1]]) as f64,
            Self::U16 => u16::from_le_bytes([b[0], b[1]]) as f64,
            Self::I32 => i32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
            Self::U32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
            Self::F32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
            Self::F64 => f64::from_le_bytes(b[..8].try_into().unwrap()),
        }
    }
}

struct Property {
    name: String,
    kind: Scalar,
    /// For list properties, the type of the length prefix.
    list_count: Option<Scalar>,
}

struct Element {
    name: String,
    count: u64,
    properties: Vec<Property>,
}

impl Element {
    fn property(&self, name: &str) -> Option<usize> {
        self.properties.iter().position(|p| p.name == name)
    }

    /// The smallest possible size of one instance (lists counted as empty).
    fn min_bytes(&self) -> u64 {
        self.properties
            .iter()
            .map(|p| p.list_count.unwrap_or(p.kind).size())
            .sum()
    }
}

/// Decodes `.ply` bytes; `file` only names the source in errors.
pub fn parse_ply(data: &[u8], file: &Path) -> Result<LoadedHair, HairError> {
    let (elements, body_start) = parse_header(data, file)?;
    let bytes = FileBytes::new(data, file);
    let layout = HairLayout::locate(&elements, file)?;

    // Absurd counts: every element's instances must fit in what follows the header.
    let body = FileBytes::new(&data[body_start..], file);
    for e in &elements {
        body.check_count_fits(
            if e.name == "vertex" {
                "vertex"
            } else {
                "element"
            },
            e.count,
            e.min_bytes().max(1),
        )?;
    }

    let mut hair = HairData::default();
    let mut offset = body_start as u64;
    for (index, element) in elements.iter().enumerate() {
        let stride = element.min_bytes();
        let fixed = element.properties.iter().all(|p| p.list_count.is_none());
        if index == layout.vertex || index == layout.strand {
            let all = bytes.slice(offset, stride * element.count, || {
                format!("{} {} elements", element.count, element.name)
            })?;
            let rows = FixedRows::new(element, all);
            if index == layout.vertex {
                hair.read_vertices(&rows, &layout);
            } else {
                hair.read_segment_counts(&rows, layout.nsegs, file)?;
            }
            offset += stride * element.count;
        } else if fixed {
            offset = offset.saturating_add(stride * element.count);
        } else {
            offset = skip_with_lists(&bytes, element, offset)?;
        }
    }
    check_file_ends_at(offset, &bytes, elements.len(), file)?;
    let counted: u64 = hair.counts.iter().map(|&c| c as u64).sum();
    if counted != hair.points.len() as u64 {
        return Err(HairError::CountMismatch {
            file: file.into(),
            what: "vertices (sum of nsegs + 1 over strands)",
            declared: hair.points.len() as u64,
            actual: counted,
        });
    }
    let color = layout.rgb.map(|_| Attribute::PerPoint(hair.colors));
    finish(
        RawHair {
            points: hair.points,
            counts: hair.counts,
            thickness: None,
            transparency: None,
            color,
        },
        file,
        HairFormat::Ply,
        String::new(),
    )
}

/// Where the hair is among the file's elements: the element of the points and the one of the
/// per-strand segment counts, and the properties read from each. Everything else is read past.
struct HairLayout {
    vertex: usize,
    strand: usize,
    xyz: [usize; 3],
    /// `red green blue`, where the vertices have all three.
    rgb: Option<[usize; 3]>,
    nsegs: usize,
}

impl HairLayout {
    /// Finds the elements and properties, refusing a file without them or with list properties
    /// in them (which the fixed-row reader cannot walk).
    fn locate(elements: &[Element], file: &Path) -> Result<Self, HairError> {
        let unsupported = |why: String| HairError::Unsupported {
            file: file.into(),
            format: FORMAT,
            why,
        };
        let find = |name: &str| elements.iter().position(|e| e.name == name);
        let vertex_index =
            find("vertex").ok_or_else(|| unsupported("no `vertex` element".into()))?;
        let strand_index = find("strand")
            .ok_or_else(|| unsupported("no `strand` element (segment counts per strand)".into()))?;
        let vertex = &elements[vertex_index];
        let strand = &elements[strand_index];
        let xyz: Vec<usize> = ["x", "y", "z"]
            .iter()
            .filter_map(|n| vertex.property(n))
            .collect();
        if xyz.len() != 3 {
            return Err(unsupported("`vertex` lacks one of x, y, z".into()));
        }
        let rgb: Vec<usize> = ["red", "green", "blue"]
            .iter()
            .filter_map(|n| vertex.property(n))
            .collect();
        let nsegs = ["nsegs", "num_segments", "segments"]
            .iter()
            .find_map(|n| strand.property(n))
            .ok_or_else(|| unsupported("`strand` has no `nsegs` property".into()))?;
        if [vertex, strand]
            .iter()
            .any(|e| e.properties.iter().any(|p| p.list_count.is_some()))
        {
            return Err(unsupported(
                "list properties in `vertex` or `strand`".into(),
            ));
        }
        Ok(Self {
            vertex: vertex_index,
            strand: strand_index,
            xyz: [xyz[0], xyz[1], xyz[2]],
            rgb: (rgb.len() == 3).then(|| [rgb[0], rgb[1], rgb[2]]),
            nsegs,
        })
    }
}

/// The instances of an element without list properties: rows of one fixed size, each property
/// at a fixed offset in its row.
struct FixedRows<'a> {
    element: &'a Element,
    bytes: &'a [u8],
    field_offsets: Vec<usize>,
}

impl<'a> FixedRows<'a> {
    fn new(element: &'a Element, bytes: &'a [u8]) -> Self {
        let field_offsets = element
            .properties
            .iter()
            .scan(0usize, |at, p| {
                let here = *at;
                *at += p.kind.size() as usize;
                Some(here)
            })
            .collect();
        Self {
            element,
            bytes,
            field_offsets,
        }
    }

    fn rows(&self) -> std::slice::ChunksExact<'a, u8> {
        self.bytes.chunks_exact(self.element.min_bytes() as usize)
    }

    /// Property `p` of `row`, whatever its scalar type.
    fn value(&self, row: &[u8], p: usize) -> f64 {
        self.element.properties[p]
            .kind
            .read(&row[self.field_offsets[p]..])
    }
}

/// What the vertex and strand elements hold, as [`RawHair`] wants it.
#[derive(Default)]
struct HairData {
    points: Vec<Vec3>,
    colors: Vec<Vec3>,
    counts: Vec<u32>,
}

impl HairData {
    /// Points, and colours where the vertices have them (uchar channels scaled from 0–255).
    fn read_vertices(&mut self, rows: &FixedRows, layout: &HairLayout) {
        let xyz = layout.xyz;
        for row in rows.rows() {
            self.points.push(Vec3::new(
                rows.value(row, xyz[0]) as f32,
                rows.value(row, xyz[1]) as f32,
                rows.value(row, xyz[2]) as f32,
            ));
            if let Some(rgb) = layout.rgb {
                let scale = |p: usize| {
                    if rows.element.properties[p].kind == Scalar::U8 {
                        1.0 / 255.0
                    } else {
                        1.0
                    }
                };
                let c = |i: usize| (rows.value(row, rgb[i]) * scale(rgb[i])) as f32;
                self.colors.push(Vec3::new(c(0), c(1), c(2)));
            }
        }
    }

    /// Points per strand (`nsegs + 1`); a count that is negative, NaN or beyond u32 is a typed
    /// error naming the strand.
    fn read_segment_counts(
        &mut self,
        rows: &FixedRows,
        nsegs: usize,
        file: &Path,
    ) -> Result<(), HairError> {
        for row in rows.rows() {
            let n = rows.value(row, nsegs);
            if !(0.0..u32::MAX as f64).contains(&n) {
                return Err(HairError::BadValue {
                    file: file.into(),
                    what: format!("nsegs of strand {}", self.counts.len()),
                    value: n.to_string(),
                    why: "must be a count ≥ 0",
                });
            }
            self.counts.push(n as u32 + 1);
        }
        Ok(())
    }
}

/// Every element was walked up to `offset`, so the file must end exactly there: shorter is
/// truncated, longer has bytes no element accounts for.
fn check_file_ends_at(
    offset: u64,
    bytes: &FileBytes,
    element_count: usize,
    file: &Path,
) -> Result<(), HairError> {
    if offset == bytes.len() {
        return Ok(());
    }
    let what = format!("{element_count} elements after the header");
    Err(if offset > bytes.len() {
        HairError::Truncated {
            file: file.into(),
            what,
            needed: offset,
            actual: bytes.len(),
        }
    } else {
        HairError::SizeMismatch {
            file: file.into(),
            expected: offset,
            actual: bytes.len(),
        }
    })
}

/// Reads past an element that has list properties, one instance at a time.
fn skip_with_lists(
    bytes: &FileBytes,
    element: &Element,
    mut offset: u64,
) -> Result<u64, HairError> {
    for i in 0..element.count {
        for p in &element.properties {
            let what = || format!("{} {} property {}", element.name, i, p.name);
            match p.list_count {
                None => offset = offset.saturating_add(p.kind.size()),
                Some(count_kind) => {
                    let n = count_kind.read(bytes.slice(offset, count_kind.size(), what)?);
                    // A float list count can be 1e308: saturate, and the check below refuses
                    // it as truncated (a plain `+` overflowed here).
                    offset = offset
                        .saturating_add(count_kind.size())
                        .saturating_add((n.max(0.0) as u64).saturating_mul(p.kind.size()));
                }
            }
        }
        bytes.slice(offset, 0, || format!("{} {}", element.name, i))?;
    }
    Ok(offset)
}

fn parse_header(data: &[u8], file: &Path) -> Result<(Vec<Element>, usize), HairError> {
    let unsupported = |why: String| HairError::Unsupported {
        file: file.into(),
        format: FORMAT,
        why,
    };
    if !data.starts_with(b"ply\n") && !data.starts_with(b"ply\r\n") {
        return Err(HairError::BadMagic {
            file: file.into(),
            format: FORMAT,
            found: data[..data.len().min(4)].escape_ascii().to_string(),
        });
    }
    const END: &[u8] = b"end_header\n";
    let head = &data[..data.len().min(HEADER_LIMIT)];
    let end = head
        .windows(END.len())
        .position(|w| w == END)
        .ok_or_else(|| HairError::Truncated {
            file: file.into(),
            what: format!("a PLY header ending in `end_header` within {HEADER_LIMIT} bytes"),
            needed: data.len() as u64 + 1,
            actual: data.len() as u64,
        })?;
    let text = String::from_utf8_lossy(&head[..end]);
    let mut elements: Vec<Element> = Vec::new();
    let mut format_ok = false;
    for line in text.lines().skip(1) {
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.as_slice() {
            ["format", "binary_little_endian", _] => format_ok = true,
            ["format", other, ..] => {
                return Err(unsupported(format!(
                    "format {other} (only binary_little_endian)"
                )));
            }
            ["element", name, count] => {
                let count = count
                    .parse()
                    .map_err(|_| unsupported(format!("element count `{count}`")))?;
                elements.push(Element {
                    name: name.to_string(),
                    count,
                    properties: Vec::new(),
                });
            }
            ["property", "list", count_kind, kind, name] => {
                let (Some(c), Some(k)) = (Scalar::parse(count_kind), Scalar::parse(kind)) else {
                    return Err(unsupported(format!("property line `{line}`")));
                };
                let e = elements
                    .last_mut()
                    .ok_or_else(|| unsupported("property before any element".into()))?;
                e.properties.push(Property {
                    name: name.to_string(),
                    kind: k,
                    list_count: Some(c),
                });
            }
            ["property", kind, name] => {
                let k = Scalar::parse(kind)
                    .ok_or_else(|| unsupported(format!("property type `{kind}`")))?;
                let e = elements
                    .last_mut()
                    .ok_or_else(|| unsupported("property before any element".into()))?;
                e.properties.push(Property {
                    name: name.to_string(),
                    kind: k,
                    list_count: None,
                });
            }
            ["comment", ..] | ["obj_info", ..] | [] => {}
            _ => return Err(unsupported(format!("header line `{line}`"))),
        }
    }
    if !format_ok {
        return Err(unsupported("no `format` line".into()));
    }
    Ok((elements, end + END.len()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn file(points: &[[f32; 3]], nsegs: &[u16], trailing_edges: bool) -> Vec<u8> {
        let mut out = format!(
            "ply\nformat binary_little_endian 1.0\ncomment test\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nelement strand {}\nproperty ushort nsegs\n{}end_header\n",
            points.len(),
            nsegs.len(),
            if trailing_edges { "element edge 1\nproperty int vertex1\nproperty int vertex2\n" } else { "" }
        )
        .into_bytes();
        for p in points {
            out.extend(p.iter().flat_map(|v| v.to_le_bytes()));
            out.extend_from_slice(&[255, 0, 51]);
        }
        for n in nsegs {
            out.extend_from_slice(&n.to_le_bytes());
        }
        if trailing_edges {
            out.extend_from_slice(&[0; 8]);
        }
        out
    }

    fn parse(b: &[u8]) -> Result<LoadedHair, HairError> {
        parse_ply(b, Path::new("crafted.ply"))
    }

    #[test]
    fn reads_strands_and_colors() {
        let pts = [
            [0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [2.0, 0.0, 0.0],
            [2.0, 1.0, 0.0],
            [2.0, 2.0, 0.0],
        ];
        let m = parse(&file(&pts, &[1, 2], true)).unwrap().model;
        assert_eq!(m.strand_offsets(), &[0, 2, 5]);
        assert_eq!(m.strand(1)[2], Vec3::new(2.0, 2.0, 0.0));
        assert_eq!(m.color().unwrap().at(3), Vec3::new(1.0, 0.0, 0.2));
    }

    #[test]
    fn crafted_bad_files_give_their_own_errors() {
        let pts = [
            [0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [2.0, 0.0, 0.0],
            [2.0, 1.0, 0.0],
        ];
        let good = file(&pts, &[1, 1], false);
        assert!(parse(&good).is_ok());
        assert!(matches!(
            parse(&file(&pts, &[1, 2], false)),
            Err(HairError::CountMismatch { .. })
        ));
        assert!(matches!(
            parse(&file(&pts, &[1, 0], false)),
            Err(HairError::CountMismatch { .. })
        ));
        assert!(matches!(
            parse(&good[..good.len() - 1]),
            Err(HairError::Truncated { .. })
        ));
        assert!(matches!(parse(b"plx\n"), Err(HairError::BadMagic { .. })));
        assert!(matches!(
            parse(b"ply\nformat ascii 1.0\nend_header\n"),
            Err(HairError::Unsupported { .. })
        ));
        let absurd =
            String::from_utf8_lossy(&good).replace("element vertex 4", "element vertex 400000000");
        assert!(matches!(
            parse(absurd.as_bytes()),
            Err(HairError::AbsurdCount { .. })
        ));
    }

    /// Swaps the header line `from` for `to` and keeps the body.
    fn with_header_line(file: &[u8], from: &str, to: &str) -> Vec<u8> {
        let end = file.windows(11).position(|w| w == b"end_header\n").unwrap() + 11;
        let header = String::from_utf8(file[..end].to_vec()).unwrap();
        assert!(header.contains(from), "{header}");
        let mut out = header.replace(from, to).into_bytes();
        out.extend_from_slice(&file[end..]);
        out
    }

    /// Counts of 10¹² vertices, strands or other elements are refused from the header against
    /// the bytes that follow it, before anything is allocated (and at once).
    #[test]
    fn absurd_element_counts_are_refused_before_allocation() {
        let pts = [[0.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let good = file(&pts, &[1], true);
        for (from, to) in [
            ("element vertex 2", "element vertex 1000000000000"),
            ("element strand 1", "element strand 1000000000000"),
            ("element edge 1", "element edge 1000000000000"),
            ("element vertex 2", "element vertex 18446744073709551615"),
        ] {
            let start = std::time::Instant::now();
            let e = parse(&with_header_line(&good, from, to)).unwrap_err();
            assert!(start.elapsed() < std::time::Duration::from_secs(1));
            assert!(
                matches!(e, HairError::AbsurdCount { count, .. } if count >= 1_000_000_000_000),
                "{to}: {e}"
            );
            assert!(e.to_string().contains("crafted.ply"), "{e}");
        }
        // Beyond u64: not a count at all.
        let e = parse(&with_header_line(
            &good,
            "element vertex 2",
            "element vertex 99999999999999999999999",
        ))
        .unwrap_err();
        assert!(matches!(e, HairError::Unsupported { .. }), "{e}");
    }

    /// Review finding: a list property whose length prefix is a `double` read as 1e308
    /// overflowed the running offset (a panic in debug builds, a wrapped offset in release).
    /// It is now refused as truncated.
    #[test]
    fn a_huge_float_list_length_is_refused() {
        let pts = [[0.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let mut f = with_header_line(
            &file(&pts, &[1], false),
            "end_header",
            "element face 1\nproperty list double int vertex_indices\nend_header",
        );
        f.extend_from_slice(&1e308f64.to_le_bytes());
        f.extend_from_slice(&[0; 8]);
        let e = parse(&f).unwrap_err();
        assert!(matches!(e, HairError::Truncated { .. }), "{e}");
        assert!(e.to_string().contains("crafted.ply"), "{e}");
    }

    /// NaN and ±Inf coordinates (and doubles too large for f32) are refused naming the file,
    /// the strand and the point; NaN colours likewise.
    #[test]
    fn non_finite_points_are_refused_with_their_place() {
        for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
            let pts = [
                [0.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [1.0, 0.0, 0.0],
                [1.0, bad, 0.0],
            ];
            let e = parse(&file(&pts, &[1, 1], false)).unwrap_err();
            assert!(
                matches!(
                    e,
                    HairError::NonFinite {
                        strand: 1,
                        point: 1,
                        ..
                    }
                ),
                "{bad}: {e}"
            );
            assert!(e.to_string().contains("crafted.ply"), "{e}");
        }
        let mut doubles = b"ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty double x\nproperty double y\nproperty double z\nelement strand 1\nproperty uchar nsegs\nend_header\n".to_vec();
        for v in [0.0f64, 0.0, 0.0, 0.0, 1e300, 0.0] {
            doubles.extend_from_slice(&v.to_le_bytes());
        }
        doubles.push(1);
        let e = parse(&doubles).unwrap_err();
        assert!(
            matches!(
                e,
                HairError::NonFinite {
                    strand: 0,
                    point: 1,
                    ..
                }
            ),
            "{e}"
        );
    }
}
