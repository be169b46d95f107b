//! N-dimensional regular lookup tables: the one container every precomputed quantity lives in
//! (the 4D Marschner convolution I_M of Ren 2010 §4.2, the dual-scattering averages, …), shared
//! by the offline baker and the GPU runtime.
//!
//! # Memory layout (the GPU contract)
//!
//! Values are `f32`, stored **row-major: the last axis varies fastest, channels innermost**.
//! For axes with counts `n₀ … n_{d−1}` and `C` channels, the value of channel `c` at node
//! `(i₀, …, i_{d−1})` sits at
//!
//! ```text
//! ((…((i₀·n₁ + i₁)·n₂ + i₂)…)·n_{d−1} + i_{d−1})·C + c
//! ```
//!
//! so [`Table::as_bytes`] can be uploaded as a storage buffer unchanged.
//!
//! # Coordinates
//!
//! Every axis maps a coordinate `x` to a continuous node position `f ∈ [0, n−1]`
//! (see [`AxisMapping`]); out-of-range coordinates (±∞ included) clamp to the edge, a NaN
//! coordinate is a [`TableError::NotFiniteCoordinate`]. Lookups interpolate multilinearly
//! between the `2^d` surrounding nodes, in f64, and return the stored value exactly at a node.

use bytemuck::{Pod, Zeroable};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use thiserror::Error;

/// Most axes a table may have (a lookup visits 2^d nodes; the GPU side unrolls over d).
pub const MAX_AXES: usize = 8;
/// Most f32 values a table may hold (1 GiB): larger shapes are refused before allocating.
pub const MAX_VALUES: usize = 1 << 28;
/// Node positions this close to an integer (in units of one cell) are snapped to the node, so
/// that a lookup at `Axis::node(i)` returns the stored value bit for bit despite rounding in
/// the coordinate → position map. The interpolation error this introduces is ≤ 1e-9 of one
/// cell's variation, far below f32 precision.
const NODE_SNAP: f64 = 1e-9;

#[derive(Debug, Error, Clone, PartialEq)]
pub enum TableError {
    #[error("a table needs at least one axis")]
    NoAxes,
    #[error("{count} axes requested; a table has at most {max}")]
    TooManyAxes { count: usize, max: usize },
    #[error("axis `{axis}`: {problem}")]
    InvalidAxis { axis: String, problem: String },
    #[error("{channels} channels requested; a table has 1 (scalar) or 3 (RGB) channels")]
    InvalidChannels { channels: usize },
    #[error("table shape {shape:?} × {channels} channels exceeds {max} values")]
    TooLarge {
        shape: Vec<usize>,
        channels: usize,
        max: usize,
    },
    #[error("axes × channels need {expected} values but {actual} were given")]
    ShapeMismatch { expected: usize, actual: usize },
    #[error("the table has {expected} axes but {actual} coordinates were given")]
    WrongCoordinateCount { expected: usize, actual: usize },
    #[error(
        "coordinate for axis `{axis}` is {value}; lookups need a number (±∞ clamps, NaN does not)"
    )]
    NotFiniteCoordinate { axis: String, value: f64 },
    #[error("the table has {expected} channels but {actual} were asked for")]
    WrongChannelCount { expected: usize, actual: usize },
    #[error("node index {index:?} is outside the shape {shape:?}")]
    NodeOutOfRange {
        index: Vec<usize>,
        shape: Vec<usize>,
    },
}

/// How an axis spreads its nodes between `min` and `max`.
///
/// Every variant is at most one `asin`/`acos`, one multiply-add and one `pow` on the GPU
/// (see [`AxisGpu`]).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum AxisMapping {
    /// Node `i` at `min + (max − min)·i/(n−1)`.
    #[default]
    Uniform,
    /// Node `i` at `min + (max − min)·(i/(n−1))^exponent`: an exponent above 1 packs nodes
    /// toward `min` (e.g. narrow SRBF lobes on a `1/λ` axis), below 1 toward `max`.
    /// A lookup inverts it: `f = (n−1)·((x − min)/(max − min))^(1/exponent)`.
    Power { exponent: f64 },
    /// For coordinates that are sines of an angle (u·ω = sin θ): nodes uniform in `asin x`, so
    /// they crowd toward ±1 where functions of θ change fastest per unit of sin θ (grazing).
    Arcsine,
    /// For coordinates that are cosines of an angle (cos Δφ): nodes uniform in `acos x`, i.e.
    /// uniform in the angle — dense near cos = ±1, where the TT lobe (Δφ ≈ π) lives.
    Arccosine,
}

impl AxisMapping {
    /// The space in which nodes are spread uniformly (before any power warp); increasing in x.
    fn warp(self, x: f64) -> f64 {
        match self {
            AxisMapping::Uniform | AxisMapping::Power { .. } => x,
            AxisMapping::Arcsine => x.clamp(-1.0, 1.0).asin(),
            AxisMapping::Arccosine => -x.clamp(-1.0, 1.0).acos(),
        }
    }

    fn unwarp(self, w: f64) -> f64 {
        match self {
            AxisMapping::Uniform | AxisMapping::Power { .. } => w,
            AxisMapping::Arcsine => w.sin(),
            AxisMapping::Arccosine => (-w).cos(),
        }
    }

    fn exponent(self) -> f64 {
        match self {
            AxisMapping::Power { exponent } => exponent,
            _ => 1.0,
        }
    }

    /// The GPU's code for [`AxisMapping::warp`]: 0 none, 1 asin, 2 −acos.
    fn gpu_code(self) -> u32 {
        match self {
            AxisMapping::Uniform | AxisMapping::Power { .. } => 0,
            AxisMapping::Arcsine => 1,
            AxisMapping::Arccosine => 2,
        }
    }
}

/// One named table axis with `count` nodes spanning `[min, max]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Axis {
    pub name: String,
    pub min: f64,
    pub max: f64,
    pub count: usize,
    #[serde(default)]
    pub mapping: AxisMapping,
}

/// An axis as the GPU evaluates it: `w = x` (warp 0), `asin(x)` (1) or `−acos(x)` (2); then
/// `t = clamp((w − min)·inv_range, 0, 1)`, `t = pow(t, inv_exponent)` (skip when it is 1), and
/// `f = t·last_index`. `min` and `inv_range` are in the warped space. A one-node axis has
/// `inv_range = last_index = 0`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct AxisGpu {
    pub min: f32,
    pub inv_range: f32,
    pub last_index: f32,
    pub inv_exponent: f32,
    pub warp: u32,
    pub _pad: [u32; 3],
}

impl Axis {
    pub fn uniform(name: impl Into<String>, min: f64, max: f64, count: usize) -> Self {
        Self {
            name: name.into(),
            min,
            max,
            count,
            mapping: AxisMapping::Uniform,
        }
    }

    pub fn power(name: impl Into<String>, min: f64, max: f64, count: usize, exponent: f64) -> Self {
        Self {
            name: name.into(),
            min,
            max,
            count,
            mapping: AxisMapping::Power { exponent },
        }
    }

    pub fn with_mapping(
        name: impl Into<String>,
        min: f64,
        max: f64,
        count: usize,
        mapping: AxisMapping,
    ) -> Self {
        Self {
            name: name.into(),
            min,
            max,
            count,
            mapping,
        }
    }

    /// Checks finiteness and ordering; a one-node axis may have `min == max`.
    pub fn validate(&self) -> Result<(), TableError> {
        let fail = |problem: String| {
            Err(TableError::InvalidAxis {
                axis: self.name.clone(),
                problem,
            })
        };
        if self.count == 0 {
            return fail("has no nodes (count = 0)".into());
        }
        if !self.min.is_finite() || !self.max.is_finite() || !(self.max - self.min).is_finite() {
            return fail(format!("range [{}, {}] is not finite", self.min, self.max));
        }
        if self.count > 1 && self.min >= self.max {
            return fail(format!(
                "range [{}, {}] must have min < max",
                self.min, self.max
            ));
        }
        if self.count == 1 && self.min > self.max {
            return fail(format!(
                "range [{}, {}] must have min ≤ max",
                self.min, self.max
            ));
        }
        match self.mapping {
            AxisMapping::Power { exponent } if !(exponent.is_finite() && exponent > 0.0) => fail(
                format!("power mapping exponent {exponent} must be finite and > 0"),
            ),
            AxisMapping::Arcsine | AxisMapping::Arccosine if self.min < -1.0 || self.max > 1.0 => {
                fail(format!(
                    "range [{}, {}] must lie in [−1, 1] for an arcsine/arccosine mapping",
                    self.min, self.max
                ))
            }
            _ => Ok(()),
        }
    }

    /// Coordinate of node `i` (`min` at 0 and exactly `max` at `count − 1`).
    pub fn node(&self, i: usize) -> f64 {
        if self.count <= 1 || i == 0 {
            return self.min;
        }
        if i >= self.count - 1 {
            return self.max;
        }
        let t = (i as f64 / (self.count - 1) as f64).powf(self.mapping.exponent());
        let (w0, w1) = (self.mapping.warp(self.min), self.mapping.warp(self.max));
        self.mapping.unwarp(w0 + (w1 - w0) * t)
    }

    /// Continuous node position of `x` in `[0, count − 1]`, clamped to the edges.
    pub fn position(&self, x: f64) -> Result<f64, TableError> {
        if x.is_nan() {
            return Err(TableError::NotFiniteCoordinate {
                axis: self.name.clone(),
                value: x,
            });
        }
        if self.count <= 1 {
            return Ok(0.0);
        }
        let m = self.mapping;
        let (w0, w1) = (m.warp(self.min), m.warp(self.max));
        let t = ((m.warp(x) - w0) / (w1 - w0))
            .clamp(0.0, 1.0)
            .powf(1.0 / m.exponent());
        let f = t * (self.count - 1) as f64;
        let nearest = f.round();
        Ok(if (f - nearest).abs() <= NODE_SNAP {
            nearest
        } else {
            f
        })
    }

    /// The lower node of the cell holding `x` and the weight of the upper node, in [0, 1].
    fn cell(&self, x: f64) -> Result<(usize, f64), TableError> {
        let f = self.position(x)?;
        if self.count <= 1 {
            return Ok((0, 0.0));
        }
        let lower = (f.floor() as usize).min(self.count - 2);
        Ok((lower, f - lower as f64))
    }

    pub fn gpu(&self) -> AxisGpu {
        let m = self.mapping;
        let (w0, w1) = (m.warp(self.min), m.warp(self.max));
        let (inv_range, last_index) = if self.count > 1 {
            (1.0 / (w1 - w0), (self.count - 1) as f64)
        } else {
            (0.0, 0.0)
        };
        AxisGpu {
            min: w0 as f32,
            inv_range: inv_range as f32,
            last_index: last_index as f32,
            inv_exponent: (1.0 / m.exponent()) as f32,
            warp: m.gpu_code(),
            _pad: [0; 3],
        }
    }
}

/// Number of f32 values a table of this shape holds, after validating every axis, the channel
/// count and the size bound — without allocating. The asset loader calls this before reading.
pub fn checked_value_count(axes: &[Axis], channels: usize) -> Result<usize, TableError> {
    if axes.is_empty() {
        return Err(TableError::NoAxes);
    }
    if axes.len() > MAX_AXES {
        return Err(TableError::TooManyAxes {
            count: axes.len(),
            max: MAX_AXES,
        });
    }
    if channels != 1 && channels != 3 {
        return Err(TableError::InvalidChannels { channels });
    }
    for axis in axes {
        axis.validate()?;
    }
    let too_large = || TableError::TooLarge {
        shape: axes.iter().map(|a| a.count).collect(),
        channels,
        max: MAX_VALUES,
    };
    let count = axes
        .iter()
        .try_fold(channels, |acc, a| acc.checked_mul(a.count))
        .ok_or_else(too_large)?;
    if count > MAX_VALUES {
        return Err(too_large());
    }
    Ok(count)
}

/// A regular grid of f32 values over named axes. See the module docs for the layout.
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    axes: Vec<Axis>,
    channels: usize,
    /// Distance in `values` between neighbouring nodes along each axis.
    strides: Vec<usize>,
    values: Vec<f32>,
}

/// Summary of a table's values for reports. `min`, `max` and `mean` are over the finite values
/// only; they are NaN when `finite_count` is 0.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TableStats {
    pub min: f32,
    pub max: f32,
    pub mean: f64,
    pub finite_count: usize,
    pub nan_count: usize,
    pub infinite_count: usize,
    /// Node index and channel of the first NaN or ±∞ in memory order.
    pub first_non_finite: Option<(Vec<usize>, usize)>,
}

impl Table {
    /// Wraps `values` (in the documented layout) after checking them against the shape.
    pub fn new(axes: Vec<Axis>, channels: usize, values: Vec<f32>) -> Result<Self, TableError> {
        let expected = checked_value_count(&axes, channels)?;
        if values.len() != expected {
            return Err(TableError::ShapeMismatch {
                expected,
                actual: values.len(),
            });
        }
        let strides = strides(&axes, channels);
        Ok(Self {
            axes,
            channels,
            strides,
            values,
        })
    }

    /// Fills a table by evaluating `f(coordinates, out)` at every node, in parallel over rows
    /// of the fastest axis. `coordinates[k] = axes[k].node(i_k)`; `out` has `channels` slots.
    pub fn from_fn<F>(axes: Vec<Axis>, channels: usize, f: F) -> Result<Self, TableError>
    where
        F: Fn(&[f64], &mut [f32]) + Sync,
    {
        let count = checked_value_count(&axes, channels)?;
        let nodes: Vec<Vec<f64>> = axes
            .iter()
            .map(|a| (0..a.count).map(|i| a.node(i)).collect())
            .collect();
        let d = axes.len();
        let row_len = axes[d - 1].count * channels;
        let mut values = vec![0.0f32; count];
        values
            .par_chunks_mut(row_len)
            .enumerate()
            .for_each(|(row, chunk)| {
                let mut coords = [0.0f64; MAX_AXES];
                // Unravel the row number into the indices of all axes but the last.
                let mut rest = row;
                for k in (0..d - 1).rev() {
                    coords[k] = nodes[k][rest % axes[k].count];
                    rest /= axes[k].count;
                }
                for (j, out) in chunk.chunks_mut(channels).enumerate() {
                    coords[d - 1] = nodes[d - 1][j];
                    f(&coords[..d], out);
                }
            });
        Self::new(axes, channels, values)
    }

    pub fn axes(&self) -> &[Axis] {
        &self.axes
    }

    pub fn channels(&self) -> usize {
        self.channels
    }

    pub fn shape(&self) -> Vec<usize> {
        self.axes.iter().map(|a| a.count).collect()
    }

    /// All values in the documented layout.
    pub fn values(&self) -> &[f32] {
        &self.values
    }

    pub fn into_values(self) -> Vec<f32> {
        self.values
    }

    /// The values as bytes in native (on every GPU host: little-endian) order, for upload.
    pub fn as_bytes(&self) -> &[u8] {
        bytemuck::cast_slice(&self.values)
    }

    /// Per-axis parameters for the GPU lookup, in axis order.
    pub fn gpu_axes(&self) -> Vec<AxisGpu> {
        self.axes.iter().map(Axis::gpu).collect()
    }

    /// Offset in [`Table::values`] of channel 0 at a node.
    pub fn node_offset(&self, index: &[usize]) -> Result<usize, TableError> {
        let out_of_range = || TableError::NodeOutOfRange {
            index: index.to_vec(),
            shape: self.shape(),
        };
        if index.len() != self.axes.len() {
            return Err(out_of_range());
        }
        let mut offset = 0;
        for ((&i, axis), &stride) in index.iter().zip(&self.axes).zip(&self.strides) {
            if i >= axis.count {
                return Err(out_of_range());
            }
            offset += i * stride;
        }
        Ok(offset)
    }

    /// The channels stored at a node.
    pub fn node(&self, index: &[usize]) -> Result<&[f32], TableError> {
        let offset = self.node_offset(index)?;
        Ok(&self.values[offset..offset + self.channels])
    }

    /// Node index of the node whose channel 0 is at `offset` (the inverse of `node_offset`).
    pub fn node_index_of(&self, offset: usize) -> Vec<usize> {
        let mut rest = offset / self.channels;
        let mut index = vec![0; self.axes.len()];
        for (k, axis) in self.axes.iter().enumerate().rev() {
            index[k] = rest % axis.count;
            rest /= axis.count;
        }
        index
    }

    /// Multilinear interpolation at `coords` (one per axis) into `out` (one per channel).
    pub fn lookup_into(&self, coords: &[f64], out: &mut [f32]) -> Result<(), TableError> {
        let d = self.axes.len();
        if coords.len() != d {
            return Err(TableError::WrongCoordinateCount {
                expected: d,
                actual: coords.len(),
            });
        }
        if out.len() != self.channels {
            return Err(TableError::WrongChannelCount {
                expected: self.channels,
                actual: out.len(),
            });
        }
        let mut base = 0;
        let mut upper_weight = [0.0f64; MAX_AXES];
        let mut step = [0usize; MAX_AXES];
        for k in 0..d {
            let (lower, w) = self.axes[k].cell(coords[k])?;
            base += lower * self.strides[k];
            upper_weight[k] = w;
            step[k] = if self.axes[k].count > 1 {
                self.strides[k]
            } else {
                0
            };
        }
        let mut acc = [0.0f64; 3];
        for corner in 0..(1usize << d) {
            let mut weight = 1.0;
            let mut offset = base;
            for k in 0..d {
                if corner >> k & 1 == 1 {
                    weight *= upper_weight[k];
                    offset += step[k];
                } else {
                    weight *= 1.0 - upper_weight[k];
                }
            }
            // Skipping zero weights keeps node values exact even beside a non-finite neighbour.
            if weight == 0.0 {
                continue;
            }
            for (c, a) in acc.iter_mut().take(self.channels).enumerate() {
                *a += weight * self.values[offset + c] as f64;
            }
        }
        for (o, a) in out.iter_mut().zip(acc) {
            *o = a as f32;
        }
        Ok(())
    }

    /// Interpolated value of a table with exactly `C` channels.
    pub fn lookup<const C: usize>(&self, coords: &[f64]) -> Result<[f32; C], TableError> {
        let mut out = [0.0f32; C];
        self.lookup_into(coords, &mut out)?;
        Ok(out)
    }

    pub fn lookup_scalar(&self, coords: &[f64]) -> Result<f32, TableError> {
        Ok(self.lookup::<1>(coords)?[0])
    }

    pub fn lookup_rgb(&self, coords: &[f64]) -> Result<[f32; 3], TableError> {
        self.lookup::<3>(coords)
    }

    /// Min, max, mean and non-finite counts over all channels.
    pub fn stats(&self) -> TableStats {
        self.stats_of(self.values.iter().copied().enumerate())
    }

    /// The same for one channel.
    pub fn channel_stats(&self, channel: usize) -> Result<TableStats, TableError> {
        if channel >= self.channels {
            return Err(TableError::WrongChannelCount {
                expected: self.channels,
                actual: channel + 1,
            });
        }
        let it = self
            .values
            .iter()
            .copied()
            .enumerate()
            .skip(channel)
            .step_by(self.channels);
        Ok(self.stats_of(it))
    }

    fn stats_of(&self, values: impl Iterator<Item = (usize, f32)>) -> TableStats {
        let (mut min, mut max, mut sum) = (f32::INFINITY, f32::NEG_INFINITY, 0.0f64);
        let (mut finite_count, mut nan_count, mut infinite_count) = (0, 0, 0);
        let mut first_non_finite = None;
        for (offset, v) in values {
            if v.is_finite() {
                min = min.min(v);
                max = max.max(v);
                sum += v as f64;
                finite_count += 1;
                continue;
            }
            if v.is_nan() {
                nan_count += 1;
            } else {
                infinite_count += 1;
            }
            if first_non_finite.is_none() {
                first_non_finite = Some((self.node_index_of(offset), offset % self.channels));
            }
        }
        if finite_count == 0 {
            (min, max) = (f32::NAN, f32::NAN);
        }
        TableStats {
            min,
            max,
            mean: sum / finite_count as f64,
            finite_count,
            nan_count,
            infinite_count,
            first_non_finite,
        }
    }
}

fn strides(axes: &[Axis], channels: usize) -> Vec<usize> {
    let mut strides = vec![0; axes.len()];
    let mut s = channels;
    for (k, axis) in axes.iter().enumerate().rev() {
        strides[k] = s;
        s *= axis.count;
    }
    strides
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_pcg::Pcg64;

    /// A random multilinear polynomial Σ_S c_S Π_{k∈S} s_k over all subsets S of the axes.
    struct Multilinear {
        coefficients: Vec<f64>,
    }

    impl Multilinear {
        fn random(dims: usize, rng: &mut Pcg64) -> Self {
            Self {
                coefficients: (0..1 << dims)
                    .map(|_| rng.random_range(-2.0..2.0))
                    .collect(),
            }
        }

        fn eval(&self, s: &[f64]) -> f64 {
            let mut total = 0.0;
            for (subset, c) in self.coefficients.iter().enumerate() {
                let mut term = *c;
                for (k, sk) in s.iter().enumerate() {
                    if subset >> k & 1 == 1 {
                        term *= sk;
                    }
                }
                total += term;
            }
            total
        }

        fn bound(&self) -> f64 {
            self.coefficients.iter().map(|c| c.abs()).sum()
        }
    }

    fn random_axes(dims: usize, rng: &mut Pcg64) -> Vec<Axis> {
        (0..dims)
            .map(|k| {
                let min = rng.random_range(-3.0..1.0);
                let max = min + rng.random_range(0.5..4.0);
                Axis::uniform(format!("x{k}"), min, max, rng.random_range(2..7))
            })
            .collect()
    }

    #[test]
    fn interpolation_reproduces_multilinear_functions_in_1_to_4_dimensions() {
        let mut rng = Pcg64::seed_from_u64(7);
        for dims in 1..=4 {
            let axes = random_axes(dims, &mut rng);
            let poly = Multilinear::random(dims, &mut rng);
            let table =
                Table::from_fn(axes.clone(), 1, |x, out| out[0] = poly.eval(x) as f32).unwrap();
            let mut worst = 0.0f64;
            for _ in 0..2000 {
                // Points strictly inside the range: the closed form is the reference.
                let x: Vec<f64> = axes
                    .iter()
                    .map(|a| rng.random_range(a.min..a.max))
                    .collect();
                let got = table.lookup_scalar(&x).unwrap() as f64;
                worst = worst.max((got - poly.eval(&x)).abs() / poly.bound());
            }
            eprintln!("{dims}-D multilinear: max |error| / Σ|c| = {worst:.2e}");
            // Only the f32 rounding of the node values and the result remains.
            assert!(worst < 4.0 * f32::EPSILON as f64, "{dims}-D: {worst:e}");
        }
    }

    #[test]
    fn power_mapping_is_multilinear_in_the_warped_coordinate() {
        let mut rng = Pcg64::seed_from_u64(11);
        let axes = vec![
            Axis::power("a", 0.01, 1.0, 9, 2.5),
            Axis::power("b", -1.0, 1.0, 5, 0.5),
        ];
        // Independent inverse of the documented node placement.
        let warped = |x: &[f64]| -> Vec<f64> {
            vec![
                ((x[0] - 0.01) / 0.99).powf(1.0 / 2.5),
                ((x[1] + 1.0) / 2.0).powf(1.0 / 0.5),
            ]
        };
        let poly = Multilinear::random(2, &mut rng);
        let table =
            Table::from_fn(axes, 1, |x, out| out[0] = poly.eval(&warped(x)) as f32).unwrap();
        let mut worst = 0.0f64;
        for _ in 0..2000 {
            let x = [rng.random_range(0.01..1.0), rng.random_range(-1.0..1.0)];
            let got = table.lookup_scalar(&x).unwrap() as f64;
            worst = worst.max((got - poly.eval(&warped(&x))).abs() / poly.bound());
        }
        eprintln!("power-mapped 2-D: max |error| / Σ|c| = {worst:.2e}");
        assert!(worst < 4.0 * f32::EPSILON as f64);
        // Denser toward min for exponent > 1: the first cell is narrower than the last.
        let a = &table.axes()[0];
        assert!(a.node(1) - a.node(0) < a.node(8) - a.node(7));
    }

    #[test]
    fn exact_at_nodes_including_beside_non_finite_neighbours() {
        let mut rng = Pcg64::seed_from_u64(3);
        let axes = vec![
            Axis::uniform("u·ξ", -1.0, 1.0, 32),
            Axis::power("1/λ", 1.0 / 64.0, 1.0 / 16.0, 7, 1.7),
            Axis::uniform("cosφ", -1.0, 1.0, 5),
        ];
        let mut values: Vec<f32> = (0..32 * 7 * 5 * 3)
            .map(|_| rng.random_range(-1e3..1e3))
            .collect();
        values[3] = f32::INFINITY; // channel 0 of node (0, 0, 1)
        let table = Table::new(axes.clone(), 3, values).unwrap();
        for i in 0..32 {
            for j in 0..7 {
                for k in 0..5 {
                    let x = [axes[0].node(i), axes[1].node(j), axes[2].node(k)];
                    let got = table.lookup_rgb(&x).unwrap();
                    assert_eq!(
                        &got[..],
                        table.node(&[i, j, k]).unwrap(),
                        "node {i},{j},{k}"
                    );
                }
            }
        }
    }

    #[test]
    fn out_of_range_clamps_to_the_edge_and_nan_is_an_error() {
        let axes = vec![
            Axis::uniform("a", 0.0, 1.0, 3),
            Axis::uniform("b", -2.0, 2.0, 4),
        ];
        let table = Table::from_fn(axes, 1, |x, out| out[0] = (10.0 * x[0] + x[1]) as f32).unwrap();
        let at = |x: [f64; 2]| table.lookup_scalar(&x).unwrap();
        assert_eq!(at([-5.0, 0.5]), at([0.0, 0.5]));
        assert_eq!(at([f64::INFINITY, 0.5]), at([1.0, 0.5]));
        assert_eq!(at([0.3, f64::NEG_INFINITY]), at([0.3, -2.0]));
        assert_eq!(at([7.0, 9.0]), 12.0); // corner (1, 2): 10·1 + 2
        let err = table.lookup_scalar(&[0.5, f64::NAN]).unwrap_err();
        assert!(
            matches!(&err, TableError::NotFiniteCoordinate { axis, .. } if axis == "b"),
            "{err}"
        );
        assert!(err.to_string().contains("`b`"));
    }

    #[test]
    fn shape_and_argument_mismatches_are_typed_errors() {
        let axes = vec![
            Axis::uniform("a", 0.0, 1.0, 4),
            Axis::uniform("b", 0.0, 1.0, 5),
        ];
        assert_eq!(
            Table::new(axes.clone(), 3, vec![0.0; 59]).unwrap_err(),
            TableError::ShapeMismatch {
                expected: 60,
                actual: 59
            }
        );
        assert!(matches!(
            Table::new(axes.clone(), 2, vec![0.0; 40]),
            Err(TableError::InvalidChannels { .. })
        ));
        assert!(matches!(
            Table::new(vec![], 1, vec![]),
            Err(TableError::NoAxes)
        ));
        let bad = vec![Axis::uniform("flat", 1.0, 1.0, 4)];
        assert!(matches!(
            Table::new(bad, 1, vec![0.0; 4]),
            Err(TableError::InvalidAxis { .. })
        ));
        let bad = vec![Axis::power("p", 0.0, 1.0, 4, -1.0)];
        assert!(matches!(
            Table::new(bad, 1, vec![0.0; 4]),
            Err(TableError::InvalidAxis { .. })
        ));
        let table = Table::new(axes, 3, vec![0.0; 60]).unwrap();
        assert!(matches!(
            table.lookup_rgb(&[0.5]),
            Err(TableError::WrongCoordinateCount { .. })
        ));
        assert!(matches!(
            table.lookup_scalar(&[0.5, 0.5]),
            Err(TableError::WrongChannelCount { .. })
        ));
        assert!(matches!(
            table.node(&[4, 0]),
            Err(TableError::NodeOutOfRange { .. })
        ));
    }

    #[test]
    fn absurd_shapes_are_refused_without_allocating() {
        let huge = vec![
            Axis::uniform("a", 0.0, 1.0, usize::MAX),
            Axis::uniform("b", 0.0, 1.0, 3),
        ];
        assert!(matches!(
            checked_value_count(&huge, 3),
            Err(TableError::TooLarge { .. })
        ));
        let big = vec![Axis::uniform("a", 0.0, 1.0, 1 << 15); 2];
        assert!(matches!(
            Table::from_fn(big, 1, |_, _| {}),
            Err(TableError::TooLarge { .. })
        ));
        let many = vec![Axis::uniform("a", 0.0, 1.0, 2); MAX_AXES + 1];
        assert!(matches!(
            checked_value_count(&many, 1),
            Err(TableError::TooManyAxes { .. })
        ));
        // The paper's I_M resolution fits.
        let im = [32, 32, 32, 64].map(|n| Axis::uniform("x", -1.0, 1.0, n));
        assert_eq!(checked_value_count(&im, 3), Ok(32 * 32 * 32 * 64 * 3));
    }

    #[test]
    fn layout_is_row_major_last_axis_fastest_channels_innermost() {
        let axes = vec![
            Axis::uniform("a", 0.0, 1.0, 2),
            Axis::uniform("b", 0.0, 2.0, 3),
        ];
        let table = Table::from_fn(axes, 3, |x, out| {
            for (c, o) in out.iter_mut().enumerate() {
                *o = (100.0 * x[0] + 10.0 * x[1]) as f32 + c as f32;
            }
        })
        .unwrap();
        // Written out by hand from the documented formula ((i·3 + j)·3 + c).
        let expected = [
            0., 1., 2., 10., 11., 12., 20., 21., 22., //
            100., 101., 102., 110., 111., 112., 120., 121., 122.,
        ];
        assert_eq!(table.values(), &expected);
        assert_eq!(table.as_bytes().len(), 18 * 4);
        assert_eq!(
            table.node_index_of(table.node_offset(&[1, 2]).unwrap()),
            vec![1, 2]
        );
    }

    #[test]
    fn one_node_axes_are_constant_along_themselves() {
        let axes = vec![
            Axis::uniform("fixed", 0.5, 0.5, 1),
            Axis::uniform("b", 0.0, 1.0, 2),
        ];
        let table = Table::new(axes, 1, vec![3.0, 5.0]).unwrap();
        assert_eq!(table.lookup_scalar(&[-100.0, 0.25]).unwrap(), 3.5);
        assert_eq!(
            table.gpu_axes()[0],
            AxisGpu {
                min: 0.5,
                inv_range: 0.0,
                last_index: 0.0,
                inv_exponent: 1.0,
                warp: 0,
                _pad: [0; 3],
            }
        );
    }

    #[test]
    fn gpu_parameters_reproduce_the_cpu_position() {
        let axis = Axis::power("1/λ", 0.001, 0.1, 64, 2.0);
        let g = axis.gpu();
        for &x in &[0.0, 0.001, 0.0123, 0.05, 0.1, 0.5] {
            let t = ((x as f32 - g.min) * g.inv_range)
                .clamp(0.0, 1.0)
                .powf(g.inv_exponent);
            let f = (t * g.last_index) as f64;
            assert!((f - axis.position(x).unwrap()).abs() < 1e-4, "x={x}");
        }
    }

    #[test]
    fn angle_mappings_are_uniform_in_the_angle_and_invert_exactly() {
        let sine = Axis::with_mapping("u·ω", -1.0, 1.0, 7, AxisMapping::Arcsine);
        let cosine = Axis::with_mapping("cos Δφ", -1.0, 1.0, 7, AxisMapping::Arccosine);
        for i in 0..7 {
            let angle = -std::f64::consts::FRAC_PI_2 + std::f64::consts::PI * i as f64 / 6.0;
            assert!((sine.node(i) - angle.sin()).abs() < 1e-15);
            let phi = std::f64::consts::PI * (1.0 - i as f64 / 6.0);
            assert!((cosine.node(i) - phi.cos()).abs() < 1e-15, "node {i}");
            assert!((sine.position(sine.node(i)).unwrap() - i as f64).abs() < 1e-12);
            assert!((cosine.position(cosine.node(i)).unwrap() - i as f64).abs() < 1e-12);
        }
        // The GPU recipe (warp, scale, clamp) gives the CPU's position.
        for axis in [&sine, &cosine] {
            let g = axis.gpu();
            for &x in &[-1.0, -0.93, -0.2, 0.0, 0.51, 0.999, 1.0] {
                let w = match g.warp {
                    1 => (x as f32).asin(),
                    2 => -(x as f32).acos(),
                    _ => x as f32,
                };
                let f = ((w - g.min) * g.inv_range).clamp(0.0, 1.0) * g.last_index;
                assert!(
                    (f as f64 - axis.position(x).unwrap()).abs() < 1e-5,
                    "{} x={x}",
                    axis.name
                );
            }
        }
        assert!(
            Axis::with_mapping("bad", -2.0, 1.0, 3, AxisMapping::Arcsine)
                .validate()
                .is_err()
        );
    }

    #[test]
    fn stats_count_non_finite_values_and_locate_the_first() {
        let axes = vec![
            Axis::uniform("a", 0.0, 1.0, 2),
            Axis::uniform("b", 0.0, 1.0, 2),
        ];
        let values = vec![
            1.0,
            -2.0,
            3.0,
            4.0,
            5.0,
            6.0,
            f32::NAN,
            8.0,
            9.0,
            10.0,
            f32::INFINITY,
            12.0,
        ];
        let table = Table::new(axes, 3, values).unwrap();
        let s = table.stats();
        assert_eq!(
            (s.min, s.max, s.finite_count, s.nan_count, s.infinite_count),
            (-2.0, 12.0, 10, 1, 1)
        );
        assert_eq!(
            s.mean,
            (1.0 - 2.0 + 3.0 + 4.0 + 5.0 + 6.0 + 8.0 + 9.0 + 10.0 + 12.0) / 10.0
        );
        // Offset 6 = node (1, 0), channel 0.
        assert_eq!(s.first_non_finite, Some((vec![1, 0], 0)));
        let c1 = table.channel_stats(1).unwrap();
        // Channel 1 holds offsets 1, 4, 7, 10: −2, 5, 8, +∞.
        assert_eq!(
            (c1.min, c1.max, c1.finite_count, c1.infinite_count),
            (-2.0, 8.0, 3, 1)
        );
    }
}
