//! From the strands as a file stores them to a valid [`HairModel`]: every value checked, zero-length
//! segments merged, strands too short to draw dropped, and all of it counted in a [`LoadReport`].

use std::path::Path;

use glam::Vec3;

use super::{Attribute, HairError, HairModel};

/// Which file format a model came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HairFormat {
    /// Cem Yuksel's `.hair`.
    Yuksel,
    /// AMD TressFX 4 `.tfx`.
    TressFx,
    /// USC-HairSalon `.data`.
    UscHairSalon,
    /// Binary PLY with `vertex` and `strand` elements.
    Ply,
    /// `BasisCurves` prims of a USD stage (`.usda`, `.usdc`, `.usdz`, `.usd`).
    Usd,
    /// `ICurves` objects of an Alembic (Ogawa) archive, `.abc`.
    Alembic,
}

/// What loading did to the file's strands.
#[derive(Clone, Debug, PartialEq)]
pub struct LoadReport {
    pub format: HairFormat,
    /// Strands and points as the file declares them.
    pub source_strands: usize,
    pub source_points: usize,
    /// Segments of (near) zero length removed by merging their two points into one.
    pub degenerate_segments_merged: usize,
    /// Strands left with fewer than two points (after merging), removed.
    pub short_strands_dropped: usize,
    /// Free text the file carries (the HAIR header's info field), or empty.
    pub info: String,
}

/// A loaded model with what loading did.
#[derive(Clone, Debug)]
pub struct LoadedHair {
    pub model: HairModel,
    pub report: LoadReport,
}

/// Strands as decoded from a file, before any check.
pub(crate) struct RawHair {
    pub points: Vec<Vec3>,
    /// Points per strand, as stored (may be 0 or 1).
    pub counts: Vec<u32>,
    pub thickness: Option<Attribute<f32>>,
    pub transparency: Option<Attribute<f32>>,
    pub color: Option<Attribute<Vec3>>,
}

/// True when `b` is the same place as `a` to float precision: the segment between them has no
/// direction, so tangents (and GPU quads built from them) would be NaN. The tolerance is a few
/// ulps of the coordinates' magnitude, so it means the same at any model scale.
pub fn is_degenerate_segment(a: Vec3, b: Vec3) -> bool {
    let scale = a.abs().max(b.abs()).max_element();
    (b - a).length() <= 4.0 * f32::EPSILON * scale
}

/// Checks every value, merges degenerate segments, drops short strands and builds the model.
pub(crate) fn finish(
    raw: RawHair,
    file: &Path,
    format: HairFormat,
    info: String,
) -> Result<LoadedHair, HairError> {
    check_values(&raw, file)?;
    let source_strands = raw.counts.len();
    let source_points = raw.points.len();
    let RawHair {
        mut points,
        counts,
        mut thickness,
        mut transparency,
        mut color,
    } = raw;

    let mut offsets = Vec::with_capacity(counts.len() + 1);
    offsets.push(0u32);
    let (mut merged, mut dropped) = (0usize, 0usize);
    let mut write = 0usize; // next free slot; reading always stays at or ahead of it
    let mut read = 0usize;
    for &count in &counts {
        let strand_start = write;
        for _ in 0..count {
            let keep =
                write == strand_start || !is_degenerate_segment(points[write - 1], points[read]);
            if keep {
                points[write] = points[read];
                move_value(&mut thickness, read, write);
                move_value(&mut transparency, read, write);
                move_value(&mut color, read, write);
                write += 1;
            } else {
                merged += 1;
            }
            read += 1;
        }
        if write - strand_start < 2 {
            write = strand_start;
            dropped += 1;
        } else {
            offsets.push(write as u32);
        }
    }
    if offsets.len() < 2 {
        return Err(HairError::NoStrands {
            file: file.to_path_buf(),
        });
    }
    points.truncate(write);
    for a in [&mut thickness, &mut transparency] {
        if let Some(Attribute::PerPoint(v)) = a {
            v.truncate(write);
        }
    }
    if let Some(Attribute::PerPoint(v)) = &mut color {
        v.truncate(write);
    }
    let model = HairModel::new(points, offsets, thickness, transparency, color)?;
    let report = LoadReport {
        format,
        source_strands,
        source_points,
        degenerate_segments_merged: merged,
        short_strands_dropped: dropped,
        info,
    };
    Ok(LoadedHair { model, report })
}

fn move_value<T: Copy>(attribute: &mut Option<Attribute<T>>, from: usize, to: usize) {
    if let Some(Attribute::PerPoint(v)) = attribute {
        v[to] = v[from];
    }
}

/// Every point finite; thickness finite and ≥ 0; transparency in [0, 1]; colour finite. The
/// error names the strand and point so the user can find it in their tool.
fn check_values(raw: &RawHair, file: &Path) -> Result<(), HairError> {
    check_uniform(
        file,
        "thickness",
        &raw.thickness,
        |t| t.is_finite() && *t >= 0.0,
        "must be finite and ≥ 0",
    )?;
    check_uniform(
        file,
        "transparency",
        &raw.transparency,
        |a| (0.0..=1.0).contains(a),
        "must be in [0, 1]",
    )?;
    check_uniform(
        file,
        "color",
        &raw.color,
        |c| c.is_finite(),
        "must be finite",
    )?;
    let mut index = 0usize;
    for (strand, &count) in raw.counts.iter().enumerate() {
        for point in 0..count as usize {
            let non_finite = |what: &'static str, value: String| HairError::NonFinite {
                file: file.to_path_buf(),
                what,
                strand,
                point,
                value,
            };
            let bad = |what: String, value: String, why| HairError::BadValue {
                file: file.to_path_buf(),
                what,
                value,
                why,
            };
            let p = raw.points[index];
            if !p.is_finite() {
                return Err(non_finite("position", format!("{p}")));
            }
            if let Some(Attribute::PerPoint(t)) = &raw.thickness {
                if !t[index].is_finite() {
                    return Err(non_finite("thickness", t[index].to_string()));
                }
                if t[index] < 0.0 {
                    return Err(bad(
                        format!("thickness of strand {strand}, point {point}"),
                        t[index].to_string(),
                        "negative",
                    ));
                }
            }
            if let Some(Attribute::PerPoint(a)) = &raw.transparency {
                if !a[index].is_finite() {
                    return Err(non_finite("transparency", a[index].to_string()));
                }
                if !(0.0..=1.0).contains(&a[index]) {
                    return Err(bad(
                        format!("transparency of strand {strand}, point {point}"),
                        a[index].to_string(),
                        "outside [0, 1]",
                    ));
                }
            }
            match &raw.color {
                Some(Attribute::PerPoint(c)) if !c[index].is_finite() => {
                    return Err(non_finite("color", format!("{}", c[index])));
                }
                _ => {}
            }
            index += 1;
        }
    }
    Ok(())
}

fn check_uniform<T: std::fmt::Debug>(
    file: &Path,
    name: &str,
    attribute: &Option<Attribute<T>>,
    valid: impl Fn(&T) -> bool,
    why: &'static str,
) -> Result<(), HairError> {
    match attribute {
        Some(Attribute::Uniform(v)) if !valid(v) => Err(HairError::BadValue {
            file: file.to_path_buf(),
            what: format!("default {name}"),
            value: format!("{v:?}"),
            why,
        }),
        _ => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn raw(points: Vec<Vec3>, counts: Vec<u32>) -> RawHair {
        let n = points.len();
        RawHair {
            points,
            counts,
            thickness: Some(Attribute::PerPoint((0..n).map(|i| i as f32).collect())),
            transparency: Some(Attribute::Uniform(0.5)),
            color: None,
        }
    }

    #[test]
    fn merges_repeated_points_and_drops_short_strands() {
        let p = |x: f32, y: f32| Vec3::new(x, y, 1000.0);
        // Strand 0: a repeated point in the middle and at the tip (2 merges).
        // Strand 1: one point only (dropped). Strand 2: all three points equal (2 merges, dropped).
        // Strand 3: differs by one ulp at 1000 (a merge: below float resolution). Strand 4: empty.
        let ulp = f32::from_bits(1000f32.to_bits() + 1) - 1000.0;
        let points = vec![
            p(0.0, 0.0),
            p(0.0, 1.0),
            p(0.0, 1.0),
            p(0.0, 2.0),
            p(0.0, 2.0),
            p(5.0, 5.0),
            p(7.0, 7.0),
            p(7.0, 7.0),
            p(7.0, 7.0),
            Vec3::new(1.0, 1.0, 1000.0),
            Vec3::new(1.0, 1.0, 1000.0 + ulp),
            Vec3::new(1.0, 3.0, 1000.0),
        ];
        let loaded = finish(
            raw(points, vec![5, 1, 3, 3, 0]),
            Path::new("t.hair"),
            HairFormat::Yuksel,
            String::new(),
        )
        .unwrap();
        let (m, r) = (&loaded.model, &loaded.report);
        eprintln!(
            "merged {} dropped {} -> {}",
            r.degenerate_segments_merged,
            r.short_strands_dropped,
            m.summary()
        );
        assert_eq!(r.degenerate_segments_merged, 5);
        assert_eq!(r.short_strands_dropped, 3);
        assert_eq!((r.source_strands, r.source_points), (5, 12));
        assert_eq!(m.strand_offsets(), &[0, 3, 5]);
        assert_eq!(m.strand(0), &[p(0.0, 0.0), p(0.0, 1.0), p(0.0, 2.0)]);
        // Attributes follow the kept points: thickness was the original point index.
        assert_eq!(
            m.thickness(),
            Some(&Attribute::PerPoint(vec![0.0, 1.0, 3.0, 9.0, 11.0]))
        );
        assert_eq!(m.transparency(), Some(&Attribute::Uniform(0.5)));
    }

    #[test]
    fn nothing_left_is_an_error() {
        let r = raw(vec![Vec3::ONE, Vec3::ONE], vec![2]);
        assert!(matches!(
            finish(r, Path::new("t.hair"), HairFormat::Yuksel, String::new()),
            Err(HairError::NoStrands { .. })
        ));
    }

    #[test]
    fn bad_values_name_strand_and_point() {
        let mut r = raw(
            vec![
                Vec3::ZERO,
                Vec3::X,
                Vec3::Y,
                Vec3::new(0.0, f32::INFINITY, 0.0),
            ],
            vec![2, 2],
        );
        match finish(r, Path::new("t.hair"), HairFormat::Yuksel, String::new()) {
            Err(HairError::NonFinite {
                strand: 1,
                point: 1,
                what: "position",
                ..
            }) => {}
            other => panic!("expected NonFinite at strand 1 point 1, got {other:?}"),
        }
        r = raw(vec![Vec3::ZERO, Vec3::X], vec![2]);
        r.thickness = Some(Attribute::PerPoint(vec![0.1, -0.1]));
        assert!(matches!(
            finish(r, Path::new("t"), HairFormat::Yuksel, String::new()),
            Err(HairError::BadValue { .. })
        ));
        r = raw(vec![Vec3::ZERO, Vec3::X], vec![2]);
        r.transparency = Some(Attribute::Uniform(f32::NAN));
        assert!(matches!(
            finish(r, Path::new("t"), HairFormat::Yuksel, String::new()),
            Err(HairError::BadValue { .. })
        ));
        r = raw(vec![Vec3::ZERO, Vec3::X], vec![2]);
        r.color = Some(Attribute::PerPoint(vec![Vec3::ONE, Vec3::NAN]));
        assert!(matches!(
            finish(r, Path::new("t"), HairFormat::Yuksel, String::new()),
            Err(HairError::NonFinite { what: "color", .. })
        ));
    }
}
