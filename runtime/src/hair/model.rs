//! The in-memory hair model: flat arrays of points and per-strand ranges, laid out so that the
//! GPU can take them as they are.

use std::fmt;

use glam::Vec3;

use super::HairError;

/// A per-point quantity that a file may give once for the whole model or once per point.
#[derive(Clone, Debug, PartialEq)]
pub enum Attribute<T> {
    /// One value for every point (the HAIR format's header defaults, a TressFX model without the array).
    Uniform(T),
    /// One value per point, indexed like [`HairModel::points`].
    PerPoint(Vec<T>),
}

impl<T: Copy> Attribute<T> {
    /// The value at point `index` (which must be a valid point index for per-point data).
    pub fn at(&self, index: usize) -> T {
        match self {
            Attribute::Uniform(v) => *v,
            Attribute::PerPoint(values) => values[index],
        }
    }

    /// One value per point for `point_count` points, for a GPU buffer: per-point data as it is,
    /// a uniform value repeated.
    pub fn per_point_values(&self, point_count: usize) -> std::borrow::Cow<'_, [T]> {
        match self {
            Attribute::Uniform(v) => std::borrow::Cow::Owned(vec![*v; point_count]),
            Attribute::PerPoint(values) => std::borrow::Cow::Borrowed(values),
        }
    }

    pub fn is_per_point(&self) -> bool {
        matches!(self, Attribute::PerPoint(_))
    }

    /// The attribute of a model made of the points `indices` (valid point indices) of this one.
    pub fn at_points(&self, indices: &[usize]) -> Attribute<T> {
        match self {
            Attribute::Uniform(v) => Attribute::Uniform(*v),
            Attribute::PerPoint(values) => {
                Attribute::PerPoint(indices.iter().map(|&i| values[i]).collect())
            }
        }
    }
}

/// An axis-aligned bounding box. `empty()` has min = +∞, max = −∞ so that growing it works.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    pub min: Vec3,
    pub max: Vec3,
}

impl Aabb {
    pub fn empty() -> Self {
        Self {
            min: Vec3::splat(f32::INFINITY),
            max: Vec3::splat(f32::NEG_INFINITY),
        }
    }

    pub fn from_points(points: &[Vec3]) -> Self {
        points.iter().fold(Self::empty(), |b, &p| Self {
            min: b.min.min(p),
            max: b.max.max(p),
        })
    }

    pub fn size(&self) -> Vec3 {
        self.max - self.min
    }

    pub fn center(&self) -> Vec3 {
        0.5 * (self.min + self.max)
    }

    pub fn diagonal(&self) -> f32 {
        self.size().length()
    }

    pub fn corners(&self) -> [Vec3; 8] {
        std::array::from_fn(|i| {
            Vec3::new(
                if i & 1 == 0 { self.min.x } else { self.max.x },
                if i & 2 == 0 { self.min.y } else { self.max.y },
                if i & 4 == 0 { self.min.z } else { self.max.z },
            )
        })
    }
}

/// Strands of hair as polylines.
///
/// Layout (what a GPU upload takes as is):
/// - `points`: every strand's points, root first, strands one after another (tightly packed
///   `[f32; 3]`, 12 bytes each; in WGSL read them as `array<f32>` at `3 * i`, since
///   `array<vec3<f32>>` has a 16-byte stride);
/// - `strand_offsets`: `strands + 1` values, strand `s` owns points
///   `strand_offsets[s] .. strand_offsets[s + 1]`;
/// - optional thickness (in the model's units, as the file gives it), transparency (0 = opaque,
///   1 = invisible, as in the HAIR format) and linear RGB colour, uniform or per point
///   ([`Attribute::per_point_values`] expands a uniform value for a buffer).
///
/// Invariants (checked by [`HairModel::new`]): at least one strand, every strand has at least
/// two points, offsets start at 0 and end at `points.len()`, every value is finite, thickness
/// ≥ 0, transparency in [0, 1], per-point arrays have one value per point.
#[derive(Clone, Debug, PartialEq)]
pub struct HairModel {
    points: Vec<Vec3>,
    strand_offsets: Vec<u32>,
    thickness: Option<Attribute<f32>>,
    transparency: Option<Attribute<f32>>,
    color: Option<Attribute<Vec3>>,
    bounds: Aabb,
}

impl HairModel {
    /// A model from its flat arrays, checked against every invariant listed on the type.
    pub fn new(
        points: Vec<Vec3>,
        strand_offsets: Vec<u32>,
        thickness: Option<Attribute<f32>>,
        transparency: Option<Attribute<f32>>,
        color: Option<Attribute<Vec3>>,
    ) -> Result<Self, HairError> {
        let invalid = |problem: String| Err(HairError::InvalidModel { problem });
        if points.len() > u32::MAX as usize {
            return invalid(format!("{} points do not fit 32-bit offsets", points.len()));
        }
        if strand_offsets.len() < 2 {
            return invalid("no strands (strand_offsets needs strands + 1 entries)".into());
        }
        if strand_offsets[0] != 0 || *strand_offsets.last().unwrap() as usize != points.len() {
            return invalid(format!(
                "strand_offsets must run from 0 to the point count {}, found {}..{}",
                points.len(),
                strand_offsets[0],
                strand_offsets.last().unwrap()
            ));
        }
        if let Some(s) = strand_offsets
            .windows(2)
            .position(|w| w[1] < w[0].saturating_add(2))
        {
            return invalid(format!(
                "strand {s} has fewer than 2 points (or offsets decrease)"
            ));
        }
        if let Some(i) = points.iter().position(|p| !p.is_finite()) {
            return invalid(format!("point {i} is not finite ({})", points[i]));
        }
        check_attribute("thickness", &thickness, points.len(), |t| {
            t.is_finite() && *t >= 0.0
        })?;
        check_attribute("transparency", &transparency, points.len(), |a| {
            (0.0..=1.0).contains(a)
        })?;
        check_attribute("color", &color, points.len(), |c| c.is_finite())?;
        let bounds = Aabb::from_points(&points);
        Ok(Self {
            points,
            strand_offsets,
            thickness,
            transparency,
            color,
            bounds,
        })
    }

    /// Every `n`th strand (the first of each `n`), each `n` times as thick: about the same
    /// coverage and optical depth from a `n`th of the segments, for a first look drawn in a
    /// fraction of the time. A model without thickness gets the renderer's default times `n`.
    pub fn thinned(&self, n: usize) -> HairModel {
        if n <= 1 {
            return self.clone();
        }
        let kept: Vec<usize> = (0..self.strand_count()).step_by(n).collect();
        let mut point_indices = Vec::new();
        let mut strand_offsets = vec![0u32];
        for &s in &kept {
            let range = self.strand_offsets[s] as usize..self.strand_offsets[s + 1] as usize;
            point_indices.extend(range);
            strand_offsets.push(point_indices.len() as u32);
        }
        let points = point_indices.iter().map(|&i| self.points[i]).collect();
        let thicker = |t: f32| t * n as f32;
        let thickness = match &self.thickness {
            Some(Attribute::Uniform(t)) => Attribute::Uniform(thicker(*t)),
            Some(Attribute::PerPoint(t)) => {
                Attribute::PerPoint(point_indices.iter().map(|&i| thicker(t[i])).collect())
            }
            None => Attribute::Uniform(thicker(crate::passes::strand_geometry::default_thickness(
                self,
            ))),
        };
        let kept_of = |a: &Option<Attribute<f32>>| a.as_ref().map(|a| a.at_points(&point_indices));
        HairModel::new(
            points,
            strand_offsets,
            Some(thickness),
            kept_of(&self.transparency),
            self.color.as_ref().map(|c| c.at_points(&point_indices)),
        )
        .expect("a subset of a valid model's strands is valid")
    }

    /// Every `k`th point of each strand and its last (so no strand gets shorter): about a
    /// `k`th of the segments, each `k` times as long, for a first look drawn at a fraction of
    /// a strand's on-screen length per segment.
    pub fn with_fewer_points(&self, k: usize) -> HairModel {
        if k <= 1 {
            return self.clone();
        }
        let mut point_indices = Vec::new();
        let mut strand_offsets = vec![0u32];
        for s in 0..self.strand_count() {
            let (first, end) = (
                self.strand_offsets[s] as usize,
                self.strand_offsets[s + 1] as usize,
            );
            point_indices.extend((first..end).step_by(k));
            if (end - 1 - first) % k != 0 {
                point_indices.push(end - 1);
            }
            strand_offsets.push(point_indices.len() as u32);
        }
        let points = point_indices.iter().map(|&i| self.points[i]).collect();
        let kept_of = |a: &Option<Attribute<f32>>| a.as_ref().map(|a| a.at_points(&point_indices));
        HairModel::new(
            points,
            strand_offsets,
            kept_of(&self.thickness),
            kept_of(&self.transparency),
            self.color.as_ref().map(|c| c.at_points(&point_indices)),
        )
        .expect("a strand's first and last points with some between form a valid strand")
    }

    pub fn points(&self) -> &[Vec3] {
        &self.points
    }

    /// `strands + 1` offsets into [`Self::points`].
    pub fn strand_offsets(&self) -> &[u32] {
        &self.strand_offsets
    }

    /// The points of strand `s`, root first.
    pub fn strand(&self, s: usize) -> &[Vec3] {
        &self.points[self.strand_offsets[s] as usize..self.strand_offsets[s + 1] as usize]
    }

    pub fn strands(&self) -> impl ExactSizeIterator<Item = &[Vec3]> + '_ {
        self.strand_offsets
            .windows(2)
            .map(|w| &self.points[w[0] as usize..w[1] as usize])
    }

    pub fn strand_count(&self) -> usize {
        self.strand_offsets.len() - 1
    }

    pub fn point_count(&self) -> usize {
        self.points.len()
    }

    /// Line segments between consecutive points of a strand: points − strands.
    pub fn segment_count(&self) -> usize {
        self.points.len() - self.strand_count()
    }

    pub fn thickness(&self) -> Option<&Attribute<f32>> {
        self.thickness.as_ref()
    }

    pub fn transparency(&self) -> Option<&Attribute<f32>> {
        self.transparency.as_ref()
    }

    pub fn color(&self) -> Option<&Attribute<Vec3>> {
        self.color.as_ref()
    }

    /// The same strands with every fiber opaque: a file's transparency is a rendering hint for
    /// non-physical shaders, while a physically based fiber (and a path tracer's cylinder)
    /// passes light only by scattering it.
    pub fn without_transparency(mut self) -> Self {
        self.transparency = None;
        self
    }

    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// The points as bytes for a vertex/storage buffer (12 bytes per point, x y z f32).
    pub fn points_bytes(&self) -> &[u8] {
        bytemuck::cast_slice(&self.points)
    }

    /// The offsets as bytes for a storage buffer (u32 each).
    pub fn strand_offsets_bytes(&self) -> &[u8] {
        bytemuck::cast_slice(&self.strand_offsets)
    }

    /// Counts and bounds for logs and reports.
    pub fn summary(&self) -> HairSummary {
        let (mut min_points, mut max_points) = (usize::MAX, 0);
        for w in self.strand_offsets.windows(2) {
            let n = (w[1] - w[0]) as usize;
            min_points = min_points.min(n);
            max_points = max_points.max(n);
        }
        HairSummary {
            strands: self.strand_count(),
            points: self.point_count(),
            segments: self.segment_count(),
            min_points_per_strand: min_points,
            max_points_per_strand: max_points,
            bounds: self.bounds,
            thickness: describe(&self.thickness),
            transparency: describe(&self.transparency),
            color: describe(&self.color),
        }
    }
}

fn check_attribute<T: fmt::Debug>(
    name: &str,
    attribute: &Option<Attribute<T>>,
    point_count: usize,
    valid: impl Fn(&T) -> bool,
) -> Result<(), HairError> {
    let invalid = |problem: String| Err(HairError::InvalidModel { problem });
    match attribute {
        None => Ok(()),
        Some(Attribute::Uniform(v)) if !valid(v) => {
            invalid(format!("uniform {name} {v:?} is out of range"))
        }
        Some(Attribute::Uniform(_)) => Ok(()),
        Some(Attribute::PerPoint(values)) if values.len() != point_count => invalid(format!(
            "{} {name} values for {point_count} points",
            values.len()
        )),
        Some(Attribute::PerPoint(values)) => match values.iter().position(|v| !valid(v)) {
            Some(i) => invalid(format!(
                "{name} of point {i} ({:?}) is out of range",
                values[i]
            )),
            None => Ok(()),
        },
    }
}

/// How an attribute is stored, for summaries.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AttributeKind {
    Absent,
    Uniform,
    PerPoint,
}

fn describe<T>(a: &Option<Attribute<T>>) -> AttributeKind {
    match a {
        None => AttributeKind::Absent,
        Some(Attribute::Uniform(_)) => AttributeKind::Uniform,
        Some(Attribute::PerPoint(_)) => AttributeKind::PerPoint,
    }
}

/// Counts and bounds of a [`HairModel`].
#[derive(Clone, Debug, PartialEq)]
pub struct HairSummary {
    pub strands: usize,
    pub points: usize,
    pub segments: usize,
    pub min_points_per_strand: usize,
    pub max_points_per_strand: usize,
    pub bounds: Aabb,
    pub thickness: AttributeKind,
    pub transparency: AttributeKind,
    pub color: AttributeKind,
}

impl fmt::Display for HairSummary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (lo, hi) = (self.bounds.min, self.bounds.max);
        write!(
            f,
            "{} strands, {} points, {} segments ({}..{} points per strand), bounds ({:.4}, {:.4}, {:.4})..({:.4}, {:.4}, {:.4}), thickness {:?}, transparency {:?}, color {:?}",
            self.strands,
            self.points,
            self.segments,
            self.min_points_per_strand,
            self.max_points_per_strand,
            lo.x,
            lo.y,
            lo.z,
            hi.x,
            hi.y,
            hi.z,
            self.thickness,
            self.transparency,
            self.color
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn two_strands() -> (Vec<Vec3>, Vec<u32>) {
        let points = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(1.0, 2.0, -3.0),
        ];
        (points, vec![0, 2, 5])
    }

    #[test]
    fn counts_bounds_and_strand_ranges() {
        let (points, offsets) = two_strands();
        let m = HairModel::new(points.clone(), offsets, None, None, None).unwrap();
        assert_eq!(
            (m.strand_count(), m.point_count(), m.segment_count()),
            (2, 5, 3)
        );
        assert_eq!(m.strand(1), &points[2..5]);
        assert_eq!(m.bounds().min, Vec3::new(0.0, 0.0, -3.0));
        assert_eq!(m.bounds().max, Vec3::new(1.0, 2.0, 0.0));
        assert_eq!(m.points_bytes().len(), 5 * 12);
        assert_eq!(m.strand_offsets_bytes().len(), 3 * 4);
        let s = m.summary();
        assert_eq!((s.min_points_per_strand, s.max_points_per_strand), (2, 3));
        eprintln!("{s}");
    }

    #[test]
    fn invariants_are_enforced() {
        let (points, offsets) = two_strands();
        let bad =
            |p: Vec<Vec3>, o: Vec<u32>, t: Option<Attribute<f32>>, a: Option<Attribute<f32>>| {
                matches!(
                    HairModel::new(p, o, t, a, None),
                    Err(HairError::InvalidModel { .. })
                )
            };
        assert!(bad(points.clone(), vec![0], None, None));
        assert!(bad(points.clone(), vec![0, 1, 5], None, None));
        assert!(bad(points.clone(), vec![0, 2, 4], None, None));
        assert!(bad(points.clone(), vec![1, 3, 5], None, None));
        let mut nan = points.clone();
        nan[3].y = f32::NAN;
        assert!(bad(nan, offsets.clone(), None, None));
        assert!(bad(
            points.clone(),
            offsets.clone(),
            Some(Attribute::Uniform(-1.0)),
            None
        ));
        assert!(bad(
            points.clone(),
            offsets.clone(),
            Some(Attribute::PerPoint(vec![1.0; 4])),
            None
        ));
        assert!(bad(
            points.clone(),
            offsets.clone(),
            None,
            Some(Attribute::Uniform(1.5))
        ));
        assert!(!bad(
            points,
            offsets,
            Some(Attribute::PerPoint(vec![1.0; 5])),
            Some(Attribute::Uniform(1.0))
        ));
        assert_eq!(
            Attribute::Uniform(0.5f32).per_point_values(3).as_ref(),
            &[0.5, 0.5, 0.5]
        );
        assert_eq!(
            Attribute::PerPoint(vec![1.0f32, 2.0])
                .per_point_values(2)
                .as_ref(),
            &[1.0, 2.0]
        );
    }

    /// A thinned groom keeps every `n`th strand whole (points, colour) at `n` times the
    /// thickness, and a groom without thickness gets `n` times the renderer's default.
    #[test]
    fn a_thinned_groom_keeps_every_nth_strand_at_n_times_the_thickness() {
        let strands: Vec<[Vec3; 3]> = (0..10)
            .map(|s| {
                let x = s as f32;
                [
                    Vec3::new(x, 0.0, 0.0),
                    Vec3::new(x, 1.0, 0.0),
                    Vec3::new(x, 2.0, 0.5),
                ]
            })
            .collect();
        let points: Vec<Vec3> = strands.iter().flatten().copied().collect();
        let offsets = (0..=10u32).map(|s| 3 * s).collect();
        let thickness = (0..30).map(|i| 0.01 + 0.001 * i as f32).collect();
        let colour = (0..30).map(|i| Vec3::splat(i as f32 / 30.0)).collect();
        let model = HairModel::new(
            points,
            offsets,
            Some(Attribute::PerPoint(thickness)),
            None,
            Some(Attribute::PerPoint(colour)),
        )
        .unwrap();
        let thin = model.thinned(3);
        assert_eq!(thin.strand_count(), 4, "strands 0, 3, 6, 9");
        for (k, s) in [0usize, 3, 6, 9].into_iter().enumerate() {
            assert_eq!(thin.strand(k), model.strand(s));
            for p in 0..3 {
                let (i, j) = (3 * k + p, 3 * s + p);
                let thick = |m: &HairModel, i| m.thickness().unwrap().at(i);
                assert!((thick(&thin, i) - 3.0 * thick(&model, j)).abs() < 1e-6);
                assert_eq!(thin.color().unwrap().at(i), model.color().unwrap().at(j));
            }
        }
        let unthickened = HairModel::new(
            model.points().to_vec(),
            model.strand_offsets().to_vec(),
            None,
            None,
            None,
        )
        .unwrap();
        let default = crate::passes::strand_geometry::default_thickness(&unthickened);
        let thin = unthickened.thinned(2);
        assert_eq!(thin.strand_count(), 5);
        assert!((thin.thickness().unwrap().at(0) - 2.0 * default).abs() < 1e-7);
    }

    /// Fewer points keep every `k`th point of each strand and its last, with their attributes:
    /// a strand of 7 points at k = 3 keeps 0, 3, 6; one of 5 keeps 0, 3, 4; one of 2 keeps both.
    #[test]
    fn fewer_points_keep_every_kth_point_and_each_strands_last() {
        let lengths = [7usize, 5, 2];
        let mut points = Vec::new();
        let mut offsets = vec![0u32];
        for (s, &n) in lengths.iter().enumerate() {
            points.extend((0..n).map(|i| Vec3::new(s as f32, i as f32, 0.0)));
            offsets.push(points.len() as u32);
        }
        let thickness = (0..points.len()).map(|i| 0.01 * (i + 1) as f32).collect();
        let model = HairModel::new(
            points,
            offsets,
            Some(Attribute::PerPoint(thickness)),
            None,
            None,
        )
        .unwrap();
        let fewer = model.with_fewer_points(3);
        let kept: [&[usize]; 3] = [&[0, 3, 6], &[0, 3, 4], &[0, 1]];
        assert_eq!(fewer.strand_count(), 3);
        let mut i = 0;
        for (s, kept) in kept.into_iter().enumerate() {
            let ys: Vec<f32> = fewer.strand(s).iter().map(|p| p.y).collect();
            assert_eq!(ys, kept.iter().map(|&k| k as f32).collect::<Vec<_>>());
            for &k in kept {
                let j = model.strand_offsets()[s] as usize + k;
                assert_eq!(
                    fewer.thickness().unwrap().at(i),
                    model.thickness().unwrap().at(j)
                );
                i += 1;
            }
        }
        assert_eq!(model.with_fewer_points(1), model);
    }
}
