//! Cem Yuksel's HAIR format (www.cemyuksel.com/research/hairmodels; cyHairFile.h).
//!
//! Little-endian. A 128-byte header:
//!
//! | offset | type | field |
//! |---:|---|---|
//! | 0 | `[u8; 4]` | `"HAIR"` |
//! | 4 | u32 | strand count |
//! | 8 | u32 | total point count |
//! | 12 | u32 | flags: bit 0 segments array, 1 points, 2 thickness, 3 transparency, 4 colour |
//! | 16 | u32 | default segments per strand (used when there is no segments array) |
//! | 20 | f32 | default thickness |
//! | 24 | f32 | default transparency |
//! | 28 | 3 × f32 | default colour |
//! | 40 | `[u8; 88]` | free text, NUL-padded |
//!
//! then the arrays present, in flag order: segments (**u16** per strand: points − 1), points
//! (3 × f32 per point), thickness (f32), transparency (f32), colour (3 × f32). The file ends
//! there. Note the segments array is 16-bit although the header default is 32-bit (checked against
//! Bangs_100.hair: 128 + 2·100 + 12·1165 = 14,308 bytes, its exact size).

use std::path::Path;

use glam::Vec3;

use super::bytes::{FileBytes, f32s};
use super::clean::{HairFormat, LoadedHair, RawHair, finish};
use super::{Attribute, HairError, HairModel, write_atomically};

pub const HEADER_BYTES: u64 = 128;
pub const INFO_BYTES: usize = 88;
const MAGIC: &[u8; 4] = b"HAIR";
const FORMAT: &str = "HAIR";

/// The flag bits of the header.
pub mod flags {
    pub const SEGMENTS: u32 = 1;
    pub const POINTS: u32 = 2;
    pub const THICKNESS: u32 = 4;
    pub const TRANSPARENCY: u32 = 8;
    pub const COLOR: u32 = 16;
}

/// Reads a `.hair` file.
pub fn load_hair(path: &Path) -> Result<LoadedHair, HairError> {
    let data = super::read_file(path)?;
    parse_hair(&data, path)
}

/// Decodes `.hair` bytes; `file` only names the source in errors.
pub fn parse_hair(data: &[u8], file: &Path) -> Result<LoadedHair, HairError> {
    let bytes = FileBytes::new(data, file);
    let header = bytes.slice(0, HEADER_BYTES, || "the 128-byte HAIR header".into())?;
    if &header[0..4] != MAGIC {
        return Err(HairError::BadMagic {
            file: file.into(),
            format: FORMAT,
            found: header[0..4].escape_ascii().to_string(),
        });
    }
    let strands = bytes.u32_at(4, "strand count")? as u64;
    let points = bytes.u32_at(8, "point count")? as u64;
    let flag_bits = bytes.u32_at(12, "flags")?;
    let default_segments = bytes.u32_at(16, "default segments")? as u64;
    let default_thickness = bytes.f32_at(20, "default thickness")?;
    let default_transparency = bytes.f32_at(24, "default transparency")?;
    let default_color = Vec3::new(
        bytes.f32_at(28, "")?,
        bytes.f32_at(32, "")?,
        bytes.f32_at(36, "")?,
    );
    let info = info_text(&header[40..128]);
    let has = |bit: u32| flag_bits & bit != 0;

    if !has(flags::POINTS) {
        return Err(HairError::Unsupported {
            file: file.into(),
            format: FORMAT,
            why: format!("flags {flag_bits:#07b} have no points array (bit 1)"),
        });
    }
    // Bits above 4 mean nothing in the format; cyHairFile ignores them and so does this reader
    // (the exact-size check below still catches a file whose layout they would change).
    // Refuse absurd counts before anything is sized by them.
    let segment_bytes = if has(flags::SEGMENTS) { 2 } else { 0 };
    bytes.check_count_fits("strand", strands, segment_bytes.max(1))?;
    bytes.check_count_fits("point", points, 12)?;
    let per_point = 12
        + if has(flags::THICKNESS) { 4 } else { 0 }
        + if has(flags::TRANSPARENCY) { 4 } else { 0 }
        + if has(flags::COLOR) { 12 } else { 0 };
    let expected = HEADER_BYTES + segment_bytes * strands + per_point * points; // both counts < 2^32: no overflow
    if expected > bytes.len() {
        return Err(HairError::Truncated {
            file: file.into(),
            what: format!("{strands} strands and {points} points with flags {flag_bits:#07b}"),
            needed: expected,
            actual: bytes.len(),
        });
    }
    if expected < bytes.len() {
        return Err(HairError::SizeMismatch {
            file: file.into(),
            expected,
            actual: bytes.len(),
        });
    }

    let mut offset = HEADER_BYTES;
    let counts: Vec<u32> = if has(flags::SEGMENTS) {
        let seg = bytes.slice(offset, 2 * strands, || "segments array".into())?;
        offset += 2 * strands;
        seg.chunks_exact(2)
            .map(|c| u16::from_le_bytes([c[0], c[1]]) as u32 + 1)
            .collect()
    } else {
        if default_segments >= u32::MAX as u64 || strands * (default_segments + 1) != points {
            return Err(HairError::CountMismatch {
                file: file.into(),
                what: "points (strands × (default segments + 1), no segments array)",
                declared: points,
                actual: strands.saturating_mul(default_segments + 1),
            });
        }
        vec![default_segments as u32 + 1; strands as usize]
    };
    let counted: u64 = counts.iter().map(|&c| c as u64).sum();
    if counted != points {
        return Err(HairError::CountMismatch {
            file: file.into(),
            what: "points (sum of segments + 1 over strands)",
            declared: points,
            actual: counted,
        });
    }

    let mut take = |len: u64, what: &str| {
        let s = bytes.slice(offset, len, || what.to_string());
        offset += len;
        s
    };
    let point_values = take(12 * points, "points array")?;
    let points_vec = vec3s(point_values);
    let thickness = if has(flags::THICKNESS) {
        Attribute::PerPoint(f32s(take(4 * points, "thickness array")?).collect())
    } else {
        Attribute::Uniform(default_thickness)
    };
    let transparency = if has(flags::TRANSPARENCY) {
        Attribute::PerPoint(f32s(take(4 * points, "transparency array")?).collect())
    } else {
        Attribute::Uniform(default_transparency)
    };
    let color = if has(flags::COLOR) {
        Attribute::PerPoint(vec3s(take(12 * points, "color array")?))
    } else {
        Attribute::Uniform(default_color)
    };
    let raw = RawHair {
        points: points_vec,
        counts,
        thickness: Some(thickness),
        transparency: Some(transparency),
        color: Some(color),
    };
    finish(raw, file, HairFormat::Yuksel, info)
}

pub(crate) fn vec3s(bytes: &[u8]) -> Vec<Vec3> {
    let mut values = f32s(bytes);
    let mut out = Vec::with_capacity(bytes.len() / 12);
    while let (Some(x), Some(y), Some(z)) = (values.next(), values.next(), values.next()) {
        out.push(Vec3::new(x, y, z));
    }
    out
}

fn info_text(field: &[u8]) -> String {
    let end = field.iter().position(|&b| b == 0).unwrap_or(field.len());
    String::from_utf8_lossy(&field[..end]).into_owned()
}

/// Choices for writing a `.hair` file.
#[derive(Clone, Debug, Default)]
pub struct HairWriteOptions {
    /// Write the per-strand segments array. Without it every strand must have the same number
    /// of points (the header's default segment count).
    pub segments_array: bool,
    /// Free text for the header (at most 87 bytes, so that it stays NUL-terminated).
    pub info: String,
}

/// The bytes of a `.hair` file for `model`. Per-point attributes become arrays (and flags);
/// uniform ones become the header defaults; absent ones are written as cyHairFile's defaults
/// (thickness 1, transparency 0, colour white), so they read back as uniform values.
pub fn encode_hair(
    model: &HairModel,
    options: &HairWriteOptions,
    file: &Path,
) -> Result<Vec<u8>, HairError> {
    let not_representable = |why: String| HairError::NotRepresentable {
        file: file.into(),
        format: FORMAT,
        why,
    };
    let counts: Vec<u32> = model
        .strand_offsets()
        .windows(2)
        .map(|w| w[1] - w[0])
        .collect();
    if let Some(&c) = counts.iter().find(|&&c| c - 1 > u16::MAX as u32) {
        return Err(not_representable(format!(
            "a strand has {c} points; segment counts are 16-bit"
        )));
    }
    if !options.segments_array && counts.iter().any(|&c| c != counts[0]) {
        return Err(not_representable(
            "strands differ in point count, so a segments array is required".into(),
        ));
    }
    if options.info.len() >= INFO_BYTES {
        return Err(not_representable(format!(
            "info text is {} bytes, at most {} fit",
            options.info.len(),
            INFO_BYTES - 1
        )));
    }
    let mut flag_bits = flags::POINTS;
    let per_point_f32 = |a: Option<&Attribute<f32>>, default: f32| match a {
        Some(Attribute::PerPoint(v)) => (default, Some(v.clone())),
        Some(Attribute::Uniform(u)) => (*u, None),
        None => (default, None),
    };
    let (thickness, thickness_array) = per_point_f32(model.thickness(), 1.0);
    let (transparency, transparency_array) = per_point_f32(model.transparency(), 0.0);
    let (color, color_array) = match model.color() {
        Some(Attribute::PerPoint(v)) => (Vec3::ONE, Some(v.clone())),
        Some(Attribute::Uniform(c)) => (*c, None),
        None => (Vec3::ONE, None),
    };
    if options.segments_array {
        flag_bits |= flags::SEGMENTS;
    }
    flag_bits |= if thickness_array.is_some() {
        flags::THICKNESS
    } else {
        0
    };
    flag_bits |= if transparency_array.is_some() {
        flags::TRANSPARENCY
    } else {
        0
    };
    flag_bits |= if color_array.is_some() {
        flags::COLOR
    } else {
        0
    };

    let mut out =
        Vec::with_capacity(HEADER_BYTES as usize + 2 * counts.len() + 32 * model.point_count());
    out.extend_from_slice(MAGIC);
    // With a segments array the default count is unused; 0 is what Yuksel's own files hold there.
    let default_segments = if options.segments_array {
        0
    } else {
        counts[0] - 1
    };
    for v in [
        counts.len() as u32,
        model.point_count() as u32,
        flag_bits,
        default_segments,
    ] {
        out.extend_from_slice(&v.to_le_bytes());
    }
    for v in [thickness, transparency, color.x, color.y, color.z] {
        out.extend_from_slice(&v.to_le_bytes());
    }
    let mut info = [0u8; INFO_BYTES];
    info[..options.info.len()].copy_from_slice(options.info.as_bytes());
    out.extend_from_slice(&info);
    if options.segments_array {
        for &c in &counts {
            out.extend_from_slice(&((c - 1) as u16).to_le_bytes());
        }
    }
    out.extend_from_slice(model.points_bytes());
    for array in [thickness_array, transparency_array].into_iter().flatten() {
        out.extend_from_slice(bytemuck::cast_slice(&array));
    }
    if let Some(c) = color_array {
        out.extend_from_slice(bytemuck::cast_slice(&c));
    }
    Ok(out)
}

/// Writes `model` as a `.hair` file (through a temporary file, so a failure leaves no partial file).
pub fn write_hair(
    model: &HairModel,
    path: &Path,
    options: &HairWriteOptions,
) -> Result<(), HairError> {
    let bytes = encode_hair(model, options, path)?;
    write_atomically(path, &bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A model whose strands differ in length when `ragged`, with every attribute per point.
    fn model(ragged: bool) -> HairModel {
        let counts: Vec<u32> = if ragged { vec![2, 5, 3, 4] } else { vec![4; 4] };
        let mut points = Vec::new();
        let mut offsets = vec![0u32];
        for (s, &c) in counts.iter().enumerate() {
            for i in 0..c {
                points.push(Vec3::new(
                    s as f32 * 1.5 - 0.25,
                    i as f32 * 0.75,
                    (s * i as usize) as f32 * -0.125,
                ));
            }
            offsets.push(points.len() as u32);
        }
        let n = points.len();
        HairModel::new(
            points,
            offsets,
            Some(Attribute::PerPoint(
                (0..n).map(|i| 0.01 * (i + 1) as f32).collect(),
            )),
            Some(Attribute::PerPoint(
                (0..n).map(|i| i as f32 / n as f32).collect(),
            )),
            Some(Attribute::PerPoint(
                (0..n)
                    .map(|i| Vec3::new(i as f32, 0.5, 1.0 / (i + 1) as f32))
                    .collect(),
            )),
        )
        .unwrap()
    }

    /// `model` with each attribute kept per point or replaced by a uniform value, by `mask` bits.
    fn with_attributes(m: &HairModel, mask: u32) -> HairModel {
        let pick_f32 = |a: Option<&Attribute<f32>>, keep: bool, u: f32| {
            if keep {
                a.cloned()
            } else {
                Some(Attribute::Uniform(u))
            }
        };
        HairModel::new(
            m.points().to_vec(),
            m.strand_offsets().to_vec(),
            pick_f32(m.thickness(), mask & flags::THICKNESS != 0, 0.25),
            pick_f32(m.transparency(), mask & flags::TRANSPARENCY != 0, 0.75),
            if mask & flags::COLOR != 0 {
                m.color().cloned()
            } else {
                Some(Attribute::Uniform(Vec3::new(0.1, 0.2, 0.3)))
            },
        )
        .unwrap()
    }

    #[test]
    fn every_flag_combination_round_trips_exactly() {
        for segments_array in [false, true] {
            for mask in 0..8u32 {
                let mask = mask << 2; // thickness, transparency, colour bits
                let original = with_attributes(&model(segments_array), mask);
                let options = HairWriteOptions {
                    segments_array,
                    info: format!("mask {mask}"),
                };
                let bytes = encode_hair(&original, &options, Path::new("mem.hair")).unwrap();
                // The size follows from the format description, independently of the encoder.
                let n = original.point_count();
                let expected =
                    128 + if segments_array {
                        2 * original.strand_count()
                    } else {
                        0
                    } + 12 * n
                        + if mask & flags::THICKNESS != 0 {
                            4 * n
                        } else {
                            0
                        }
                        + if mask & flags::TRANSPARENCY != 0 {
                            4 * n
                        } else {
                            0
                        }
                        + if mask & flags::COLOR != 0 { 12 * n } else { 0 };
                assert_eq!(bytes.len(), expected);
                let flag_bits = u32::from_le_bytes(bytes[12..16].try_into().unwrap());
                assert_eq!(
                    flag_bits,
                    flags::POINTS | mask | if segments_array { flags::SEGMENTS } else { 0 }
                );
                let loaded = parse_hair(&bytes, Path::new("mem.hair")).unwrap();
                assert_eq!(loaded.model, original, "flags {flag_bits:#07b}");
                assert_eq!(loaded.report.info, options.info);
                assert_eq!(
                    loaded.report.degenerate_segments_merged + loaded.report.short_strands_dropped,
                    0
                );
            }
        }
    }

    #[test]
    fn writer_refuses_what_the_format_cannot_hold() {
        let ragged = model(true);
        let e = encode_hair(&ragged, &HairWriteOptions::default(), Path::new("x.hair"));
        assert!(matches!(e, Err(HairError::NotRepresentable { .. })));
        let long_info = HairWriteOptions {
            segments_array: true,
            info: "x".repeat(88),
        };
        assert!(matches!(
            encode_hair(&ragged, &long_info, Path::new("x.hair")),
            Err(HairError::NotRepresentable { .. })
        ));
    }

    #[test]
    fn write_hair_writes_a_file_that_loads() {
        let dir = std::env::temp_dir().join(format!("strandlight-hair-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("model.hair");
        let m = model(true);
        write_hair(
            &m,
            &path,
            &HairWriteOptions {
                segments_array: true,
                info: String::new(),
            },
        )
        .unwrap();
        assert_eq!(load_hair(&path).unwrap().model, m);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// A hand-built header for the bad-file tests.
    fn header(strands: u32, points: u32, flag_bits: u32, default_segments: u32) -> Vec<u8> {
        let mut h = b"HAIR".to_vec();
        for v in [strands, points, flag_bits, default_segments] {
            h.extend_from_slice(&v.to_le_bytes());
        }
        for v in [0.1f32, 0.0, 1.0, 1.0, 1.0] {
            h.extend_from_slice(&v.to_le_bytes());
        }
        h.resize(128, 0);
        h
    }

    fn points_bytes(points: &[[f32; 3]]) -> Vec<u8> {
        points
            .iter()
            .flatten()
            .flat_map(|v| v.to_le_bytes())
            .collect()
    }

    fn parse(bytes: &[u8]) -> Result<LoadedHair, HairError> {
        parse_hair(bytes, Path::new("crafted.hair"))
    }

    #[test]
    fn crafted_bad_files_give_their_own_errors() {
        let good_points = points_bytes(&[
            [0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
        ]);
        let mut good = header(2, 4, flags::POINTS, 1);
        good.extend_from_slice(&good_points);
        let m = parse(&good).unwrap().model;
        assert_eq!((m.strand_count(), m.point_count()), (2, 4));
        assert_eq!(m.thickness(), Some(&Attribute::Uniform(0.1)));

        // Header cut short.
        assert!(matches!(
            parse(&good[..100]),
            Err(HairError::Truncated { needed: 128, .. })
        ));
        // Wrong magic.
        let mut bad = good.clone();
        bad[0] = b'X';
        assert!(matches!(parse(&bad), Err(HairError::BadMagic { .. })));
        // Data cut short.
        assert!(matches!(
            parse(&good[..good.len() - 1]),
            Err(HairError::Truncated { .. })
        ));
        // Trailing bytes.
        let mut long = good.clone();
        long.extend_from_slice(&[0; 4]);
        assert!(matches!(
            parse(&long),
            Err(HairError::SizeMismatch {
                expected: 176,
                actual: 180,
                ..
            })
        ));
        // Absurd point count: refused before allocating 4 G points.
        let mut absurd = header(2, u32::MAX, flags::POINTS, 1);
        absurd.extend_from_slice(&good_points);
        assert!(matches!(
            parse(&absurd),
            Err(HairError::AbsurdCount { what: "point", .. })
        ));
        let mut absurd = header(u32::MAX, 4, flags::POINTS | flags::SEGMENTS, 1);
        absurd.extend_from_slice(&good_points);
        assert!(matches!(
            parse(&absurd),
            Err(HairError::AbsurdCount { what: "strand", .. })
        ));
        // Default segments that disagree with the point count.
        let mut mismatch = header(2, 4, flags::POINTS, 2);
        mismatch.extend_from_slice(&good_points);
        assert!(matches!(
            parse(&mismatch),
            Err(HairError::CountMismatch { .. })
        ));
        let mut mismatch = header(2, 4, flags::POINTS, u32::MAX);
        mismatch.extend_from_slice(&good_points);
        assert!(matches!(
            parse(&mismatch),
            Err(HairError::CountMismatch { .. })
        ));
        // A segments array that disagrees with the point count.
        let mut seg = header(2, 4, flags::POINTS | flags::SEGMENTS, 0);
        seg.extend_from_slice(&[1, 0, 2, 0]);
        seg.extend_from_slice(&good_points);
        assert!(matches!(
            parse(&seg),
            Err(HairError::CountMismatch {
                declared: 4,
                actual: 5,
                ..
            })
        ));
        // No points array.
        assert!(matches!(
            parse(&header(0, 0, 0, 0)),
            Err(HairError::Unsupported { .. })
        ));
        // A NaN point, named by strand and point.
        let mut nan = header(2, 4, flags::POINTS, 1);
        nan.extend_from_slice(&points_bytes(&[
            [0.0; 3],
            [0.0, 1.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, f32::NAN, 0.0],
        ]));
        assert!(matches!(
            parse(&nan),
            Err(HairError::NonFinite {
                strand: 1,
                point: 1,
                ..
            })
        ));
        // A negative default thickness.
        let mut neg = good.clone();
        neg[20..24].copy_from_slice(&(-1.0f32).to_le_bytes());
        assert!(matches!(parse(&neg), Err(HairError::BadValue { .. })));
        // Zero strands.
        assert!(matches!(
            parse(&header(0, 0, flags::POINTS, 0)),
            Err(HairError::NoStrands { .. })
        ));
    }

    /// The header's counts are u32, so "10¹² strands" reads as the largest count it can hold
    /// (and 10¹² mod 2³² where a writer truncated it): all are refused against the file's
    /// length before anything is allocated, and at once.
    #[test]
    fn absurd_counts_are_refused_before_allocation() {
        let truncated_10_12 = (1_000_000_000_000u64 % (1 << 32)) as u32;
        let points = points_bytes(&[[0.0; 3], [0.0, 1.0, 0.0]]);
        for (strands, points_count, flag_bits, what) in [
            (1, u32::MAX, flags::POINTS, "point"),
            (1, truncated_10_12, flags::POINTS | flags::COLOR, "point"),
            (u32::MAX, 2, flags::POINTS | flags::SEGMENTS, "strand"),
            (
                truncated_10_12,
                2,
                flags::POINTS | flags::SEGMENTS,
                "strand",
            ),
        ] {
            let mut f = header(strands, points_count, flag_bits, 1);
            f.extend_from_slice(&points);
            let start = std::time::Instant::now();
            let e = parse(&f).unwrap_err();
            assert!(start.elapsed() < std::time::Duration::from_secs(1), "{e}");
            assert!(
                matches!(e, HairError::AbsurdCount { what: w, .. } if w == what),
                "{e}"
            );
            assert!(e.to_string().contains("crafted.hair"), "{e}");
        }
        // Without a segments array a strand costs no bytes of its own, but still at least a
        // byte's worth of the file: a huge strand count is refused all the same.
        let mut f = header(u32::MAX, 2, flags::POINTS, 1);
        f.extend_from_slice(&points);
        assert!(matches!(
            parse(&f),
            Err(HairError::AbsurdCount { what: "strand", .. })
        ));
    }

    /// Inf points (and NaN per-point thickness and colour) are refused naming the file, strand
    /// and point, like the NaN point of `crafted_bad_files_give_their_own_errors`.
    #[test]
    fn non_finite_points_and_attributes_are_refused() {
        let pts = [[0.0; 3], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0]];
        for bad in [f32::INFINITY, f32::NEG_INFINITY] {
            let mut p = pts;
            p[2][0] = bad;
            let mut f = header(2, 4, flags::POINTS, 1);
            f.extend_from_slice(&points_bytes(&p));
            let e = parse(&f).unwrap_err();
            assert!(
                matches!(
                    e,
                    HairError::NonFinite {
                        strand: 1,
                        point: 0,
                        ..
                    }
                ),
                "{e}"
            );
            assert!(e.to_string().contains("crafted.hair"), "{e}");
        }
        for flag in [flags::THICKNESS, flags::COLOR] {
            let mut f = header(2, 4, flags::POINTS | flag, 1);
            f.extend_from_slice(&points_bytes(&pts));
            let per_point = if flag == flags::COLOR { 3 } else { 1 };
            let mut values = vec![0.5f32; 4 * per_point];
            values[per_point] = f32::NAN;
            f.extend(values.iter().flat_map(|v| v.to_le_bytes()));
            let e = parse(&f).unwrap_err();
            assert!(
                matches!(
                    e,
                    HairError::NonFinite {
                        strand: 0,
                        point: 1,
                        ..
                    } | HairError::BadValue { .. }
                ),
                "{e}"
            );
            assert!(e.to_string().contains("crafted.hair"), "{e}");
        }
    }

    #[test]
    fn degenerate_segments_in_a_file_are_merged_and_counted() {
        // Strand 0 repeats its middle point twice; strand 1 is a single repeated point.
        let mut f = header(2, 6, flags::POINTS | flags::SEGMENTS, 0);
        f.extend_from_slice(&[3, 0, 1, 0]);
        f.extend_from_slice(&points_bytes(&[
            [0.0; 3],
            [0.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 2.0, 0.0],
            [5.0; 3],
            [5.0; 3],
        ]));
        let loaded = parse(&f).unwrap();
        eprintln!("report: {:?}", loaded.report);
        assert_eq!(loaded.report.degenerate_segments_merged, 2);
        assert_eq!(loaded.report.short_strands_dropped, 1);
        assert_eq!(loaded.model.strand_count(), 1);
        assert_eq!(
            loaded.model.strand(0),
            &[Vec3::ZERO, Vec3::Y, 2.0 * Vec3::Y]
        );
    }
}
