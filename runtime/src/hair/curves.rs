//! Batches of curves from scene files (a USD `BasisCurves` prim, an Alembic `ICurves` object)
//! to the polylines of a [`RawHair`]: cubic curves evaluated at their segment ends, per-curve,
//! per-vertex and per-segment-end values spread to points, and object space taken to the world.
//!
//! Cubic curves become the polyline through the curve's points at its segment boundaries, the
//! points where USD's `varying` values live (UsdGeomBasisCurves, "Segment Indexing"), so that
//! varying data maps one to one and vertex data is blended with the same basis weights. The
//! renderer draws straight segments, and hair exporters write one control vertex per simulated
//! point, so the boundaries are as dense as the artist's strands.

use std::path::Path;

use glam::{DMat4, DVec3, DVec4, Vec3};

use super::clean::RawHair;
use super::{Attribute, HairError};

/// The cubic bases of USD's `basis` and Alembic's `BasisType` that hair is written with.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Basis {
    Bezier,
    Bspline,
    CatmullRom,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Shape {
    Linear,
    Cubic(Basis),
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Wrap {
    Open,
    Periodic,
    /// USD's `pinned`: phantom end points make a bspline or Catmull-Rom curve reach its first
    /// and last control points.
    Pinned,
}

/// How many values a quantity holds per batch, in USD's names (Alembic's `GeometryScope`
/// maps onto them: con, uni, vtx, var).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Interpolation {
    Constant,
    Uniform,
    Vertex,
    Varying,
}

/// Values with the interpolation the file declared (None: unstated, inferred from the count).
pub(crate) struct Values<T> {
    pub values: Vec<T>,
    pub declared: Option<Interpolation>,
}

/// One batch of curves as its file stores it.
pub(crate) struct CurveBatch {
    /// The prim path or object name, for messages.
    pub name: String,
    pub points: Vec<Vec3>,
    /// Vertices per curve, as stored (negative counts are refused here).
    pub counts: Vec<i64>,
    pub shape: Shape,
    pub wrap: Wrap,
    /// Object space to strandlight's world (units and up axis included).
    pub to_world: DMat4,
    pub widths: Option<Values<f32>>,
    pub colors: Option<Values<Vec3>>,
}

/// A point of the output as a weighted sum of a curve's control points (indices into it).
type Stencil = Vec<(usize, f64)>;

/// The batches as one [`RawHair`], with a note for each value dropped or filled in.
pub(crate) fn assemble(
    batches: Vec<CurveBatch>,
    file: &Path,
) -> Result<(RawHair, Vec<String>), HairError> {
    let mut notes = Vec::new();
    let (mut points, mut counts) = (Vec::new(), Vec::new());
    let mut widths: Vec<Option<Vec<f32>>> = Vec::new();
    let mut colors: Vec<Option<Vec<Vec3>>> = Vec::new();
    let mut batch_points = Vec::new();
    for batch in batches {
        let bad = |problem: String| HairError::BadCurves {
            file: file.into(),
            at: batch.name.clone(),
            problem,
        };
        let stencils = stencils_of(&batch).map_err(bad)?;
        let spread = Spread::new(&batch, &stencils);
        let start = points.len();
        let width_scale = uniform_scale(batch.to_world) as f32;
        for (curve, curve_stencils) in stencils.iter().enumerate() {
            let base = spread.first_vertex[curve];
            for stencil in curve_stencils {
                let p = blend(stencil, |i| batch.points[base + i].as_dvec3());
                points.push(batch.to_world.transform_point3(p).as_vec3());
            }
            counts.push(curve_stencils.len() as u32);
        }
        let width_values = batch.widths.as_ref().and_then(|w| {
            let spread = spread.values(w, "widths", &mut notes, |w| w as f64);
            spread.map(|v| v.into_iter().map(|w| (w as f32 * width_scale).max(0.0)))
        });
        widths.push(width_values.map(Iterator::collect));
        let color_values = batch
            .colors
            .as_ref()
            .and_then(|c| spread.values(c, "displayColor", &mut notes, |c: Vec3| c.as_dvec3()));
        colors.push(color_values.map(|v| v.into_iter().map(|c| c.as_vec3()).collect()));
        debug_assert_eq!(points.len() - start, spread.output_points);
        batch_points.push(points.len() - start);
    }
    let thickness = merge(widths, &batch_points, "widths", &mut notes, fill_width);
    let color = merge(colors, &batch_points, "displayColor", &mut notes, |_| {
        // Hydra's fallback displayColor.
        Vec3::splat(0.5)
    });
    let raw = RawHair {
        points,
        counts,
        thickness,
        transparency: None,
        color,
    };
    Ok((raw, notes))
}

fn fill_width(known: &[f32]) -> f32 {
    known.iter().sum::<f32>() / known.len().max(1) as f32
}

/// Per-batch values to one per-point attribute: absent when no batch has any, missing batches
/// filled with `fill` (noted), uniform when every point has the same value.
fn merge<T: Copy + PartialEq>(
    per_batch: Vec<Option<Vec<T>>>,
    batch_points: &[usize],
    what: &str,
    notes: &mut Vec<String>,
    fill: impl Fn(&[T]) -> T,
) -> Option<Attribute<T>> {
    if per_batch.iter().all(Option::is_none) {
        return None;
    }
    let known: Vec<T> = per_batch.iter().flatten().flatten().copied().collect();
    let fallback = fill(&known);
    let missing = per_batch.iter().filter(|b| b.is_none()).count();
    if missing > 0 {
        notes.push(format!(
            "{missing} curve batch(es) without {what} given the others' fallback"
        ));
    }
    let mut all = Vec::with_capacity(batch_points.iter().sum());
    for (values, &n) in per_batch.into_iter().zip(batch_points) {
        match values {
            Some(v) => all.extend(v),
            None => all.extend(std::iter::repeat_n(fallback, n)),
        }
    }
    match all.first() {
        Some(&first) if all.iter().all(|&v| v == first) => Some(Attribute::Uniform(first)),
        _ => Some(Attribute::PerPoint(all)),
    }
}

/// The cube root of the linear part's determinant: how a transform scales a width (exact for
/// uniform scale, the volume-preserving mean otherwise).
fn uniform_scale(m: DMat4) -> f64 {
    let det = glam::DMat3::from_mat4(m).determinant().abs();
    det.cbrt()
}

fn blend<T>(stencil: &Stencil, at: impl Fn(usize) -> T) -> T
where
    T: std::ops::Mul<f64, Output = T> + std::ops::Add<Output = T> + Copy,
{
    let mut terms = stencil.iter().map(|&(i, w)| at(i) * w);
    let first = terms.next().expect("a stencil has at least one term");
    terms.fold(first, |a, b| a + b)
}

/// Where each curve's control points start, how many points come out, and how a quantity of
/// each interpolation reaches them.
struct Spread<'a> {
    batch: &'a CurveBatch,
    stencils: &'a [Vec<Stencil>],
    first_vertex: Vec<usize>,
    output_points: usize,
    /// USD's varying count: segment ends per curve (one fewer on a closed curve, whose last
    /// output point repeats its first).
    varying: Vec<usize>,
}

impl<'a> Spread<'a> {
    fn new(batch: &'a CurveBatch, stencils: &'a [Vec<Stencil>]) -> Self {
        let mut first_vertex = Vec::with_capacity(batch.counts.len());
        let mut at = 0usize;
        for &c in &batch.counts {
            first_vertex.push(at);
            at += c as usize;
        }
        let periodic = batch.wrap == Wrap::Periodic && batch.shape != Shape::Linear;
        let varying = stencils
            .iter()
            .map(|s| s.len().saturating_sub(periodic as usize))
            .collect();
        Self {
            batch,
            stencils,
            first_vertex,
            output_points: stencils.iter().map(Vec::len).sum(),
            varying,
        }
    }

    /// One value per output point, or None (noted) when the count fits no interpolation.
    fn values<T: Copy, U>(
        &self,
        given: &Values<T>,
        what: &str,
        notes: &mut Vec<String>,
        widen: impl Fn(T) -> U,
    ) -> Option<Vec<U>>
    where
        U: std::ops::Mul<f64, Output = U> + std::ops::Add<Output = U> + Copy,
    {
        let n = given.values.len();
        let varying_total: usize = self.varying.iter().sum();
        let sizes = [
            (Interpolation::Constant, 1),
            (Interpolation::Uniform, self.batch.counts.len()),
            (Interpolation::Vertex, self.batch.points.len()),
            (Interpolation::Varying, varying_total),
        ];
        let fits = |i: Interpolation| sizes.iter().any(|&(k, size)| k == i && size == n);
        let interpolation = match given.declared {
            Some(i) if fits(i) => i,
            _ => match sizes.iter().find(|&&(_, size)| size == n) {
                Some(&(i, _)) => i,
                None => {
                    notes.push(format!(
                        "{} {what}: {n} values fit no interpolation (1, {} curves, {} vertices or {varying_total} segment ends): ignored",
                        self.batch.name,
                        self.batch.counts.len(),
                        self.batch.points.len()
                    ));
                    return None;
                }
            },
        };
        let v = |i: usize| widen(given.values[i]);
        let mut out = Vec::with_capacity(self.output_points);
        let mut varying_at = 0usize;
        for (curve, stencils) in self.stencils.iter().enumerate() {
            for (k, stencil) in stencils.iter().enumerate() {
                out.push(match interpolation {
                    Interpolation::Constant => v(0),
                    Interpolation::Uniform => v(curve),
                    Interpolation::Vertex => blend(stencil, |i| v(self.first_vertex[curve] + i)),
                    Interpolation::Varying => v(varying_at + k % self.varying[curve].max(1)),
                });
            }
            varying_at += self.varying[curve];
        }
        Some(out)
    }
}

/// Every curve's output points as stencils over its control points, after checking the counts.
fn stencils_of(batch: &CurveBatch) -> Result<Vec<Vec<Stencil>>, String> {
    let mut total = 0u64;
    for (curve, &c) in batch.counts.iter().enumerate() {
        if c < 0 {
            return Err(format!("curve {curve} has a negative vertex count ({c})"));
        }
        total = total.saturating_add(c as u64);
    }
    if total != batch.points.len() as u64 {
        return Err(format!(
            "the vertex counts of its {} curves sum to {total}, but it has {} points",
            batch.counts.len(),
            batch.points.len()
        ));
    }
    batch
        .counts
        .iter()
        .enumerate()
        .map(|(curve, &c)| {
            curve_stencils(c as usize, batch.shape, batch.wrap)
                .map_err(|why| format!("curve {curve}: {why}"))
        })
        .collect()
}

/// The output points of one curve of `n` control points.
fn curve_stencils(n: usize, shape: Shape, wrap: Wrap) -> Result<Vec<Stencil>, String> {
    let Shape::Cubic(basis) = shape else {
        return Ok((0..n).map(|i| vec![(i, 1.0)]).collect());
    };
    if n == 0 {
        return Ok(Vec::new());
    }
    // The control points the segments run over, each a combination of real ones.
    let mut controls: Vec<Stencil> = (0..n).map(|i| vec![(i, 1.0)]).collect();
    let pinned = wrap == Wrap::Pinned && basis != Basis::Bezier;
    if pinned {
        if n < 2 {
            return Err(format!("{n} vertex; a pinned cubic curve needs at least 2"));
        }
        controls.insert(0, vec![(0, 2.0), (1, -1.0)]);
        controls.push(vec![(n - 1, 2.0), (n - 2, -1.0)]);
    }
    let periodic = wrap == Wrap::Periodic;
    let step = if basis == Basis::Bezier { 3 } else { 1 };
    let m = controls.len();
    let segments = match (periodic, basis) {
        (true, Basis::Bezier) if m >= 3 && m.is_multiple_of(3) => m / 3,
        (true, _) if m >= 3 => m,
        (false, Basis::Bezier) if m >= 4 && (m - 4).is_multiple_of(3) => (m - 4) / 3 + 1,
        (false, Basis::Bspline | Basis::CatmullRom) if m >= 4 => m - 3,
        _ => {
            return Err(format!(
                "{n} vertices do not make whole {basis:?} segments ({} wrap)",
                match wrap {
                    Wrap::Open => "nonperiodic",
                    Wrap::Periodic => "periodic",
                    Wrap::Pinned => "pinned",
                }
            ));
        }
    };
    let (start, end) = end_weights(basis);
    let at = |segment: usize, weights: [f64; 4]| -> Stencil {
        let mut s: Stencil = Vec::with_capacity(8);
        for (j, w) in weights.into_iter().enumerate().filter(|(_, w)| *w != 0.0) {
            for &(i, c) in &controls[(segment * step + j) % m] {
                s.push((i, w * c));
            }
        }
        s
    };
    let mut out: Vec<Stencil> = (0..segments).map(|k| at(k, start)).collect();
    out.push(at(segments - 1, end));
    Ok(out)
}

/// A cubic segment's weights of its four control points at t = 0 and t = 1 (the rows of the
/// basis matrices in the UsdGeomBasisCurves documentation evaluated at the ends).
fn end_weights(basis: Basis) -> ([f64; 4], [f64; 4]) {
    match basis {
        Basis::Bezier => ([1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0]),
        Basis::Bspline => (
            [1.0 / 6.0, 4.0 / 6.0, 1.0 / 6.0, 0.0],
            [0.0, 1.0 / 6.0, 4.0 / 6.0, 1.0 / 6.0],
        ),
        Basis::CatmullRom => ([0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0]),
    }
}

/// Strandlight's world from a scene's: Y up (a Z-up scene turned −90° about x, which takes its
/// front, −y, to strandlight's +z), in centimetres (the procedural groom's unit).
pub(crate) fn scene_to_world(z_up: bool, meters_per_unit: f64) -> DMat4 {
    // (x, y, z) ↦ (x, z, −y), written out so that it is exact (a rotation built from π/2 leaves
    // 6e-17 where zeros belong).
    let turn = if z_up {
        DMat4::from_cols(DVec4::X, DVec4::NEG_Z, DVec4::Y, DVec4::W)
    } else {
        DMat4::IDENTITY
    };
    DMat4::from_scale(DVec3::splat(meters_per_unit * 100.0)) * turn
}
