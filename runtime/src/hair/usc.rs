//! USC-HairSalon `.data` strands (Hu et al. 2015): little-endian i32 strand count, then for
//! each strand an i32 point count followed by that many 3 × f32 points. Nothing else; the
//! file ends after the last strand. Hair-Salon scalps store bald scalp samples as one-point
//! strands, which loading drops (and counts).

use std::path::Path;

use super::bytes::FileBytes;
use super::clean::{HairFormat, LoadedHair, RawHair, finish};
use super::yuksel::vec3s;
use super::{HairError, HairModel, write_atomically};

/// Reads a `.data` file.
pub fn load_usc(path: &Path) -> Result<LoadedHair, HairError> {
    let data = super::read_file(path)?;
    parse_usc(&data, path)
}

/// Decodes `.data` bytes; `file` only names the source in errors.
pub fn parse_usc(data: &[u8], file: &Path) -> Result<LoadedHair, HairError> {
    let bytes = FileBytes::new(data, file);
    let strands = bytes.i32_at(0, "strand count")?;
    if strands < 0 {
        return Err(negative(file, "strand count", strands));
    }
    // Each strand costs at least its 4-byte count.
    bytes.check_count_fits("strand", strands as u64, 4)?;

    // First pass: the counts only, so the points can be allocated once and exactly.
    let mut counts = Vec::with_capacity(strands as usize);
    let mut offset = 4u64;
    for s in 0..strands as usize {
        let count = bytes.i32_at(offset, &format!("point count of strand {s}"))?;
        if count < 0 {
            return Err(negative(file, &format!("point count of strand {s}"), count));
        }
        let point_bytes = 12 * count as u64;
        bytes.slice(offset + 4, point_bytes, || {
            format!("{count} points of strand {s}")
        })?;
        counts.push(count as u32);
        offset += 4 + point_bytes;
    }
    if offset != bytes.len() {
        return Err(HairError::SizeMismatch {
            file: file.into(),
            expected: offset,
            actual: bytes.len(),
        });
    }

    let total: usize = counts.iter().map(|&c| c as usize).sum();
    let mut points = Vec::with_capacity(total);
    let mut offset = 4usize;
    for &c in &counts {
        let end = offset + 4 + 12 * c as usize;
        points.extend(vec3s(&data[offset + 4..end]));
        offset = end;
    }
    let raw = RawHair {
        points,
        counts,
        thickness: None,
        transparency: None,
        color: None,
    };
    finish(raw, file, HairFormat::UscHairSalon, String::new())
}

fn negative(file: &Path, what: &str, value: i32) -> HairError {
    HairError::BadValue {
        file: file.into(),
        what: what.to_string(),
        value: value.to_string(),
        why: "negative",
    }
}

/// The bytes of a `.data` file for `model` (positions only; the format has nothing else).
pub fn encode_usc(model: &HairModel) -> Vec<u8> {
    let mut out = Vec::with_capacity(4 + 4 * model.strand_count() + 12 * model.point_count());
    out.extend_from_slice(&(model.strand_count() as i32).to_le_bytes());
    for strand in model.strands() {
        out.extend_from_slice(&(strand.len() as i32).to_le_bytes());
        out.extend_from_slice(bytemuck::cast_slice(strand));
    }
    out
}

/// Writes `model` as a `.data` file (through a temporary file).
pub fn write_usc(model: &HairModel, path: &Path) -> Result<(), HairError> {
    write_atomically(path, &encode_usc(model))
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;

    fn file(strands: &[&[[f32; 3]]]) -> Vec<u8> {
        let mut out = (strands.len() as i32).to_le_bytes().to_vec();
        for s in strands {
            out.extend_from_slice(&(s.len() as i32).to_le_bytes());
            out.extend(s.iter().flatten().flat_map(|v| v.to_le_bytes()));
        }
        out
    }

    fn parse(bytes: &[u8]) -> Result<LoadedHair, HairError> {
        parse_usc(bytes, Path::new("crafted.data"))
    }

    #[test]
    fn reads_strands_and_drops_bald_scalp_points() {
        let f = file(&[
            &[[0.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            &[[9.0, 9.0, 9.0]],
            &[],
            &[[1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [1.0, 2.0, 0.5]],
        ]);
        let loaded = parse(&f).unwrap();
        assert_eq!(loaded.report.short_strands_dropped, 2);
        assert_eq!(
            (loaded.report.source_strands, loaded.report.source_points),
            (4, 6)
        );
        assert_eq!(loaded.model.strand_offsets(), &[0, 2, 5]);
        assert_eq!(loaded.model.strand(1)[2], Vec3::new(1.0, 2.0, 0.5));
        // And the writer produces exactly the bytes of the kept strands.
        let kept = file(&[
            &[[0.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            &[[1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [1.0, 2.0, 0.5]],
        ]);
        assert_eq!(encode_usc(&loaded.model), kept);
    }

    #[test]
    fn crafted_bad_files_give_their_own_errors() {
        let good = file(&[&[[0.0, 0.0, 0.0], [0.0, 1.0, 0.0]]]);
        assert!(parse(&good).is_ok());
        assert!(matches!(
            parse(&good[..3]),
            Err(HairError::Truncated { .. })
        ));
        assert!(matches!(
            parse(&good[..good.len() - 2]),
            Err(HairError::Truncated { .. })
        ));
        let mut long = good.clone();
        long.push(0);
        assert!(matches!(parse(&long), Err(HairError::SizeMismatch { .. })));
        let mut absurd = good.clone();
        absurd[0..4].copy_from_slice(&i32::MAX.to_le_bytes());
        assert!(matches!(parse(&absurd), Err(HairError::AbsurdCount { .. })));
        let mut neg = good.clone();
        neg[0..4].copy_from_slice(&(-1i32).to_le_bytes());
        assert!(matches!(parse(&neg), Err(HairError::BadValue { .. })));
        let mut neg = good.clone();
        neg[4..8].copy_from_slice(&(-5i32).to_le_bytes());
        assert!(matches!(parse(&neg), Err(HairError::BadValue { .. })));
        let mut huge = good.clone();
        huge[4..8].copy_from_slice(&i32::MAX.to_le_bytes());
        assert!(matches!(parse(&huge), Err(HairError::Truncated { .. })));
        let nan = file(&[
            &[[0.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            &[[f32::NAN, 1.0, 0.0], [0.0; 3]],
        ]);
        assert!(matches!(
            parse(&nan),
            Err(HairError::NonFinite {
                strand: 1,
                point: 0,
                ..
            })
        ));
        let inf = file(&[&[[0.0, 0.0, 0.0], [f32::INFINITY, 1.0, 0.0]]]);
        assert!(matches!(
            parse(&inf),
            Err(HairError::NonFinite {
                strand: 0,
                point: 1,
                ..
            })
        ));
    }

    /// The counts are i32: a million strands (each able to claim 2³¹ points, 10¹⁵ in all) or
    /// i32::MAX of them in a file of a few bytes are refused against its length, at once.
    #[test]
    fn absurd_counts_are_refused_before_allocation() {
        for strands in [1_000_000i32, i32::MAX] {
            let mut f = strands.to_le_bytes().to_vec();
            f.extend_from_slice(&i32::MAX.to_le_bytes());
            let start = std::time::Instant::now();
            let e = parse(&f).unwrap_err();
            assert!(start.elapsed() < std::time::Duration::from_secs(1), "{e}");
            assert!(
                matches!(e, HairError::AbsurdCount { what: "strand", .. }),
                "{e}"
            );
            assert!(e.to_string().contains("crafted.data"), "{e}");
        }
        // One strand claiming i32::MAX points: its bytes are not there.
        let mut f = 1i32.to_le_bytes().to_vec();
        f.extend_from_slice(&i32::MAX.to_le_bytes());
        let e = parse(&f).unwrap_err();
        assert!(matches!(e, HairError::Truncated { .. }), "{e}");
        assert!(e.to_string().contains("crafted.data"), "{e}");
    }
}
