//! AMD TressFX 4 `.tfx` files (TressFXFileFormat.h, `TressFXTFXFileHeader`). Little-endian, a
//! 160-byte header:
//!
//! | offset | type | field |
//! |---:|---|---|
//! | 0 | f32 | version (4.0 for TressFX 4) |
//! | 4 | u32 | strand count |
//! | 8 | u32 | vertices per strand (the same for every strand) |
//! | 12 | u32 | byte offset of positions: float4 (x, y, z, inverse mass) per vertex |
//! | 16 | u32 | byte offset of per-strand UVs (float2), 0 = none |
//! | 20 | u32 | byte offset of per-vertex UVs (float2), 0 = none |
//! | 24 | u32 | byte offset of per-strand thickness (f32), 0 = none |
//! | 28 | u32 | byte offset of per-vertex colours (float4), 0 = none |
//! | 32 | 32 × u32 | reserved |
//!
//! UVs are read past (checked to lie in the file, not kept); thickness becomes per-point
//! thickness and colour's rgb per-point colour. Offsets may leave gaps, so trailing bytes are
//! not an error here, but every array must lie inside the file.

use std::path::Path;

use glam::Vec3;

use super::bytes::{FileBytes, f32s};
use super::clean::{HairFormat, LoadedHair, RawHair, finish};
use super::{Attribute, HairError};

pub const HEADER_BYTES: u64 = 160;
const FORMAT: &str = "TressFX";

/// Reads a `.tfx` file.
pub fn load_tfx(path: &Path) -> Result<LoadedHair, HairError> {
    let data = super::read_file(path)?;
    parse_tfx(&data, path)
}

/// Decodes `.tfx` bytes; `file` only names the source in errors.
pub fn parse_tfx(data: &[u8], file: &Path) -> Result<LoadedHair, HairError> {
    let bytes = FileBytes::new(data, file);
    bytes.slice(0, HEADER_BYTES, || "the 160-byte TressFX header".into())?;
    let version = bytes.f32_at(0, "version")?;
    // Older TressFX versions used other layouts; a non-float here means this is no .tfx at all.
    if !(version.is_finite() && (4.0..5.0).contains(&version)) {
        return Err(HairError::Unsupported {
            file: file.into(),
            format: FORMAT,
            why: format!("version {version} (only 4.x is known)"),
        });
    }
    let strands = bytes.u32_at(4, "strand count")? as u64;
    let per_strand = bytes.u32_at(8, "vertices per strand")? as u64;
    let field = |i: u64, name: &str| bytes.u32_at(12 + 4 * i, name).map(u64::from);
    let (positions_at, strand_uv_at, vertex_uv_at, thickness_at, color_at) = (
        field(0, "position offset")?,
        field(1, "strand UV offset")?,
        field(2, "vertex UV offset")?,
        field(3, "thickness offset")?,
        field(4, "color offset")?,
    );
    if per_strand < 2 {
        return Err(HairError::BadValue {
            file: file.into(),
            what: "vertices per strand".into(),
            value: per_strand.to_string(),
            why: "a strand needs at least 2",
        });
    }
    bytes.check_count_fits("strand", strands, 16 * per_strand)?;
    let vertices = strands * per_strand;

    let array = |at: u64, bytes_each: u64, count: u64, what: &str| {
        bytes.slice(at, bytes_each * count, || format!("{what} at offset {at}"))
    };
    let positions = array(positions_at, 16, vertices, "positions")?;
    if strand_uv_at != 0 {
        array(strand_uv_at, 8, strands, "strand UVs")?;
    }
    if vertex_uv_at != 0 {
        array(vertex_uv_at, 8, vertices, "vertex UVs")?;
    }
    let thickness = match thickness_at {
        0 => None,
        at => {
            let per_strand_values: Vec<f32> =
                f32s(array(at, 4, strands, "strand thickness")?).collect();
            Some(Attribute::PerPoint(
                per_strand_values
                    .iter()
                    .flat_map(|&t| std::iter::repeat_n(t, per_strand as usize))
                    .collect(),
            ))
        }
    };
    let color = match color_at {
        0 => None,
        at => Some(Attribute::PerPoint(rgb_of_float4(array(
            at,
            16,
            vertices,
            "vertex colors",
        )?))),
    };
    let raw = RawHair {
        points: rgb_of_float4(positions),
        counts: vec![per_strand as u32; strands as usize],
        thickness,
        transparency: None,
        color,
    };
    finish(raw, file, HairFormat::TressFx, String::new())
}

/// The first three of every four floats (positions drop the inverse mass, colours the alpha).
fn rgb_of_float4(bytes: &[u8]) -> Vec<Vec3> {
    bytes
        .chunks_exact(16)
        .map(|c| {
            let f =
                |i: usize| f32::from_le_bytes([c[4 * i], c[4 * i + 1], c[4 * i + 2], c[4 * i + 3]]);
            Vec3::new(f(0), f(1), f(2))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A `.tfx` with the given strands (each `per_strand` points), and optionally thickness and colours.
    fn file(strands: &[Vec<[f32; 3]>], thickness: Option<&[f32]>, colors: bool) -> Vec<u8> {
        let per_strand = strands[0].len() as u32;
        let vertices = strands.len() as u32 * per_strand;
        let positions_at = 160u32;
        let thickness_at = if thickness.is_some() {
            positions_at + 16 * vertices
        } else {
            0
        };
        let color_at = if colors {
            positions_at
                + 16 * vertices
                + if thickness.is_some() {
                    4 * strands.len() as u32
                } else {
                    0
                }
        } else {
            0
        };
        let mut out = 4.0f32.to_le_bytes().to_vec();
        for v in [
            strands.len() as u32,
            per_strand,
            positions_at,
            0,
            0,
            thickness_at,
            color_at,
        ] {
            out.extend_from_slice(&v.to_le_bytes());
        }
        out.resize(160, 0);
        for p in strands.iter().flatten() {
            out.extend(p.iter().chain(&[1.0]).flat_map(|v| v.to_le_bytes()));
        }
        for t in thickness.unwrap_or(&[]) {
            out.extend_from_slice(&t.to_le_bytes());
        }
        if colors {
            for p in strands.iter().flatten() {
                out.extend(
                    [p[0] * 0.5, 0.25, 0.125, 1.0]
                        .iter()
                        .flat_map(|v| v.to_le_bytes()),
                );
            }
        }
        out
    }

    fn parse(bytes: &[u8]) -> Result<LoadedHair, HairError> {
        parse_tfx(bytes, Path::new("crafted.tfx"))
    }

    fn two_strands() -> Vec<Vec<[f32; 3]>> {
        vec![
            vec![[0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 2.0, 0.0]],
            vec![[1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [1.0, 2.0, 0.0]],
        ]
    }

    #[test]
    fn reads_positions_thickness_and_colors() {
        let loaded = parse(&file(&two_strands(), Some(&[0.5, 0.25]), true)).unwrap();
        let m = &loaded.model;
        assert_eq!(m.strand_offsets(), &[0, 3, 6]);
        assert_eq!(m.strand(1)[2], Vec3::new(1.0, 2.0, 0.0));
        assert_eq!(
            m.thickness(),
            Some(&Attribute::PerPoint(vec![0.5, 0.5, 0.5, 0.25, 0.25, 0.25]))
        );
        assert_eq!(m.color().unwrap().at(4), Vec3::new(0.5, 0.25, 0.125));
    }

    #[test]
    fn crafted_bad_files_give_their_own_errors() {
        let good = file(&two_strands(), None, false);
        assert!(parse(&good).is_ok());
        assert!(matches!(
            parse(&good[..100]),
            Err(HairError::Truncated { .. })
        ));
        assert!(matches!(
            parse(&good[..good.len() - 1]),
            Err(HairError::Truncated { .. })
        ));
        let mut v3 = good.clone();
        v3[0..4].copy_from_slice(&3.0f32.to_le_bytes());
        assert!(matches!(parse(&v3), Err(HairError::Unsupported { .. })));
        let mut absurd = good.clone();
        absurd[4..8].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(matches!(parse(&absurd), Err(HairError::AbsurdCount { .. })));
        let mut one = good.clone();
        one[8..12].copy_from_slice(&1u32.to_le_bytes());
        assert!(matches!(parse(&one), Err(HairError::BadValue { .. })));
        let mut far = good.clone();
        far[12..16].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(matches!(parse(&far), Err(HairError::Truncated { .. })));
        let mut uv = good.clone();
        uv[16..20].copy_from_slice(&(good.len() as u32 - 8).to_le_bytes());
        assert!(matches!(parse(&uv), Err(HairError::Truncated { .. })));
        let mut nan = two_strands();
        nan[1][1][2] = f32::NAN;
        assert!(matches!(
            parse(&file(&nan, None, false)),
            Err(HairError::NonFinite {
                strand: 1,
                point: 1,
                ..
            })
        ));
        assert!(matches!(
            parse(&file(&two_strands(), Some(&[0.5, f32::NAN]), false)),
            Err(HairError::NonFinite { .. })
        ));
    }

    /// 10⁶ strands of 10⁶ vertices (10¹² points), or the largest u32 counts, claimed by a file
    /// of a few hundred bytes: refused against the file's length before any allocation.
    #[test]
    fn absurd_counts_are_refused_before_allocation() {
        let good = file(&two_strands(), None, false);
        for (strands, per_strand) in [
            (1_000_000u32, 1_000_000u32),
            (u32::MAX, 3),
            (2, u32::MAX),
            (u32::MAX, u32::MAX),
        ] {
            let mut f = good.clone();
            f[4..8].copy_from_slice(&strands.to_le_bytes());
            f[8..12].copy_from_slice(&per_strand.to_le_bytes());
            let start = std::time::Instant::now();
            let e = parse(&f).unwrap_err();
            assert!(start.elapsed() < std::time::Duration::from_secs(1), "{e}");
            assert!(matches!(e, HairError::AbsurdCount { .. }), "{e}");
            assert!(e.to_string().contains("crafted.tfx"), "{e}");
        }
    }
}
