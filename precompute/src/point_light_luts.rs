//! The point-light lookup textures of Hunz 2016 §3.3.4 (Algorithm 2, after Nguyen and Donnelly):
//! the Marschner model split into a longitudinal table over (sin θ_i, sin θ_o) and an azimuthal
//! table over (cos φ, cos θ_d), so that a shader evaluates
//!
//! `S = Σ_p M_p(sin θ_i, sin θ_o) · N_p(cos φ, cos θ_d) / cos²θ_d`
//!
//! with three texture fetches and no inverse trigonometry.
//!
//! # Layout
//!
//! * [`bake_lut_m`] — axes (`sin_theta_i` ∈ [−1, 1], `sin_theta_o` ∈ [−1, 1], `quantity` with
//!   nodes 0, 1, 2, 3 = M_R, M_TT, M_TRT, cos θ_d), 1 channel. Hunz packs the same four numbers
//!   in one RGBA texel; here they sit on an integer axis, and a lookup at an integer quantity
//!   returns that quantity interpolated over the two sines only.
//! * [`bake_lut_n`] — axes (`cos_phi` ∈ [−1, 1], `cos_theta_d` ∈ [0, 1], `lobe` with nodes 0, 1,
//!   2 = R, TT, TRT), 3 channels (absorption is per channel; N_R is grey but shares the layout).
//!   Optionally ([`AzimuthAxis::CosHalfPhi`]) the first axis is `cos_half_phi` = cos(φ/2) =
//!   √(½(1 + cos φ)) ∈ [0, 1] instead: one square root more in the shader, and much better near
//!   φ = π, where N_R ∝ |cos(φ/2)| has a V-shaped kink that is a square-root edge in cos φ
//!   (the cos φ grid's first cell spans |φ − π| ≤ 10° at 128 nodes). The table's axis name says
//!   which one a table uses; [`reconstruct_s_from_sines`] reads it.
//!
//! Differences from Hunz's text, on purpose:
//! * Hunz folds 1/cos²θ_d into M. At the corner sin θ_i = ∓1, sin θ_o = ±1 (θ_d = ±90°) that
//!   product reaches 10⁸ × M (the model floors cos²θ_d at [`MIN_COS2_THETA_D`]) beside nodes
//!   10⁶ times smaller (1/cos²θ_d ≈ 126 one 128-grid cell away), and a bilinear fetch smears
//!   the spike over the whole corner cell: measured at 128², |θ| ≤ 80° (sin 80° lies inside the
//!   last cell), the folded table errs by 3.6·10³ × max S against 0.39 × max S for this layout
//!   (equal to 1% below |θ| = 60°). We store cos θ_d (which Hunz also stores, as the N
//!   coordinate) and divide once in the shader.
//! * The N coordinate is cos θ_d ∈ [0, 1], not Hunz's `cos θ_d · 0.5 + 0.5`: cos θ_d is never
//!   negative, so his mapping wastes half the texture.
//!
//! # What the parameterisation loses, and why it is harmless
//!
//! * **The sign of φ** (cos φ is even). Marschner's S for a round fiber (and for the mean index
//!   of randomly oriented elliptical ones, [`Marschner::eval`]) is even in φ; a fiber with a fixed
//!   orientation ([`Marschner::eval_oriented`]) is not and cannot be tabulated this way.
//! * **The sign of θ_d** (cos θ_d is even). N_p depends on θ_d only through cos θ_d and
//!   sin²θ_d (Bravais's indices η′, η″ and the refracted inclination θ_t), so it is even in θ_d.
//!   Both are tested below against the direct model.

use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;
use strandlight_tables::angles::FiberAngles;
use strandlight_tables::marschner::{Lobe, MIN_COS2_THETA_D, Marschner};
use strandlight_tables::scattering::{Rgb, ScatteringFunction};
use strandlight_tables::table::{Axis, Table, TableError};
use strandlight_tables::table_axes::{
    AXIS_COS_HALF_PHI, AXIS_COS_PHI, AXIS_COS_THETA_D, AXIS_LOBE, AXIS_QUANTITY, AXIS_SIN_THETA_I,
    AXIS_SIN_THETA_O,
};
use thiserror::Error;

/// Index of cos θ_d on the `quantity` axis of the M table (after M_R, M_TT, M_TRT).
pub const COS_THETA_D_QUANTITY: usize = 3;
/// Fewest nodes per continuous axis (a lookup needs one cell).
pub const MIN_LUT_NODES: usize = 2;
/// Most nodes per continuous axis: 4096² × 9 f32 is 600 MB, far past any useful texture.
pub const MAX_LUT_NODES: usize = 4096;

#[derive(Debug, Error, Clone, PartialEq)]
pub enum LutError {
    #[error(
        "LUT resolution `{parameter}` = {value}: must be in [{MIN_LUT_NODES}, {MAX_LUT_NODES}]"
    )]
    Resolution {
        parameter: &'static str,
        value: usize,
    },
    #[error(
        "table `{table}` holds a non-finite value at node {node:?}, channel {channel}; the fiber parameters produce NaN/∞ there"
    )]
    NonFinite {
        table: &'static str,
        node: Vec<usize>,
        channel: usize,
    },
    #[error(transparent)]
    Table(#[from] TableError),
}

/// The azimuthal coordinate of the N texture.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AzimuthAxis {
    /// Hunz 2016: cos φ ∈ [−1, 1].
    #[default]
    CosPhi,
    /// cos(φ/2) = √(½(1 + cos φ)) ∈ [0, 1] (φ ∈ [0, π]); see the module docs.
    CosHalfPhi,
}

impl AzimuthAxis {
    /// The axis name the N table carries.
    pub fn name(self) -> &'static str {
        match self {
            AzimuthAxis::CosPhi => AXIS_COS_PHI,
            AzimuthAxis::CosHalfPhi => AXIS_COS_HALF_PHI,
        }
    }

    /// Which azimuth axis an N table uses, from its first axis's name.
    pub fn of_table(lut_n: &Table) -> Result<Self, TableError> {
        let name = lut_n.axes().first().map_or("", |a| a.name.as_str());
        [AzimuthAxis::CosPhi, AzimuthAxis::CosHalfPhi]
            .into_iter()
            .find(|a| a.name() == name)
            .ok_or_else(|| TableError::InvalidAxis {
                axis: name.to_string(),
                problem:
                    "is not the azimuth axis of a point-light N table (cos_phi or cos_half_phi)"
                        .into(),
            })
    }

    pub(crate) fn axis(self, count: usize) -> Axis {
        match self {
            AzimuthAxis::CosPhi => Axis::uniform(self.name(), -1.0, 1.0, count),
            AzimuthAxis::CosHalfPhi => Axis::uniform(self.name(), 0.0, 1.0, count),
        }
    }

    /// The table coordinate of cos φ (NaN stays NaN, for the lookup to report).
    pub fn coordinate(self, cos_phi: f64) -> f64 {
        match self {
            AzimuthAxis::CosPhi => cos_phi,
            AzimuthAxis::CosHalfPhi if cos_phi.is_nan() => cos_phi,
            AzimuthAxis::CosHalfPhi => (0.5 + 0.5 * cos_phi).clamp(0.0, 1.0).sqrt(),
        }
    }

    /// φ ∈ [0, π] at a table coordinate.
    pub fn phi(self, x: f64) -> f64 {
        match self {
            AzimuthAxis::CosPhi => x.clamp(-1.0, 1.0).acos(),
            AzimuthAxis::CosHalfPhi => 2.0 * x.clamp(0.0, 1.0).acos(),
        }
    }
}

/// Node counts and the azimuth coordinate of the two lookup textures. Hunz 2016 does not state
/// a texture size; 128 per axis is the default (see the module tests and
/// `examples/lut_error.rs` for error vs size).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LutResolution {
    pub sin_theta_i: usize,
    pub sin_theta_o: usize,
    /// Nodes on the N texture's azimuth axis (cos φ or cos(φ/2), per `azimuth_axis`).
    pub azimuth: usize,
    pub cos_theta_d: usize,
    pub azimuth_axis: AzimuthAxis,
}

impl Default for LutResolution {
    fn default() -> Self {
        Self::square(128)
    }
}

impl LutResolution {
    /// The same node count on all four continuous axes.
    pub fn square(n: usize) -> Self {
        Self {
            sin_theta_i: n,
            sin_theta_o: n,
            azimuth: n,
            cos_theta_d: n,
            azimuth_axis: AzimuthAxis::CosPhi,
        }
    }

    pub fn validate(&self) -> Result<(), LutError> {
        for (parameter, value) in [
            ("sin_theta_i", self.sin_theta_i),
            ("sin_theta_o", self.sin_theta_o),
            ("azimuth", self.azimuth),
            ("cos_theta_d", self.cos_theta_d),
        ] {
            if !(MIN_LUT_NODES..=MAX_LUT_NODES).contains(&value) {
                return Err(LutError::Resolution { parameter, value });
            }
        }
        Ok(())
    }

    /// Bytes of f32 data both tables hold (M: 4 quantities × 1 channel; N: 3 lobes × RGB).
    pub fn bytes(&self) -> usize {
        let m = self.sin_theta_i * self.sin_theta_o * 4;
        let n = self.azimuth * self.cos_theta_d * 3 * 3;
        (m + n) * std::mem::size_of::<f32>()
    }
}

/// Both lookup textures of one fiber.
#[derive(Debug, Clone, PartialEq)]
pub struct PointLightLuts {
    pub m: Table,
    pub n: Table,
}

impl PointLightLuts {
    pub fn bake(model: &Marschner, resolution: &LutResolution) -> Result<Self, LutError> {
        Ok(Self {
            m: bake_lut_m(model, resolution)?,
            n: bake_lut_n(model, resolution)?,
        })
    }

    /// S at fiber angles, as the shader computes it (see [`reconstruct_s_from_sines`]).
    pub fn eval(
        &self,
        theta_i: f64,
        theta_o: f64,
        phi: f64,
        source: CosThetaDSource,
    ) -> Result<Rgb, TableError> {
        reconstruct_s_from_sines(
            &self.m,
            &self.n,
            theta_i.sin(),
            theta_o.sin(),
            phi.cos(),
            source,
        )
    }

    pub fn bytes(&self) -> usize {
        self.m.as_bytes().len() + self.n.as_bytes().len()
    }
}

fn lobe_axis_value(lobe: Lobe) -> f64 {
    lobe.index() as f64
}

/// The M texture: M_R, M_TT, M_TRT and cos θ_d over (sin θ_i, sin θ_o).
pub fn bake_lut_m(model: &Marschner, resolution: &LutResolution) -> Result<Table, LutError> {
    resolution.validate()?;
    let axes = vec![
        Axis::uniform(AXIS_SIN_THETA_I, -1.0, 1.0, resolution.sin_theta_i),
        Axis::uniform(AXIS_SIN_THETA_O, -1.0, 1.0, resolution.sin_theta_o),
        Axis::uniform(AXIS_QUANTITY, 0.0, COS_THETA_D_QUANTITY as f64, 4),
    ];
    let table = Table::from_fn(axes, 1, |x, out| {
        let theta_i = x[0].clamp(-1.0, 1.0).asin();
        let theta_o = x[1].clamp(-1.0, 1.0).asin();
        let quantity = x[2].round() as usize;
        out[0] = match Lobe::from_index(quantity) {
            Some(lobe) => model.longitudinal(lobe, theta_i, theta_o),
            None => (0.5 * (theta_o - theta_i)).cos().max(0.0),
        } as f32;
    })?;
    refuse_non_finite("lut_m", table)
}

/// The N texture: N_R, N_TT, N_TRT (RGB) over (cos φ or cos(φ/2), cos θ_d).
pub fn bake_lut_n(model: &Marschner, resolution: &LutResolution) -> Result<Table, LutError> {
    resolution.validate()?;
    let axes = vec![
        resolution.azimuth_axis.axis(resolution.azimuth),
        Axis::uniform(AXIS_COS_THETA_D, 0.0, 1.0, resolution.cos_theta_d),
        Axis::uniform(AXIS_LOBE, 0.0, 2.0, 3),
    ];
    let table = Table::from_fn(axes, 3, |x, out| {
        let phi = resolution.azimuth_axis.phi(x[0]);
        let theta_d = x[1].clamp(0.0, 1.0).acos();
        let lobe = Lobe::from_index(x[2].round() as usize).unwrap_or(Lobe::TRT);
        let n = model.azimuthal(lobe, theta_d, phi);
        for (o, v) in out.iter_mut().zip(n) {
            *o = v as f32;
        }
    })?;
    refuse_non_finite("lut_n", table)
}

fn refuse_non_finite(name: &'static str, table: Table) -> Result<Table, LutError> {
    match table.stats().first_non_finite {
        None => Ok(table),
        Some((node, channel)) => Err(LutError::NonFinite {
            table: name,
            node,
            channel,
        }),
    }
}

/// Where the shader takes cos θ_d from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CosThetaDSource {
    /// Hunz Algorithm 2: the fourth quantity of the M texture, interpolated like M.
    #[default]
    Table,
    /// `cos θ_d = √(½(1 + cos θ_i cos θ_o + sin θ_i sin θ_o))` with `cos θ = √(1 − sin²θ)`:
    /// three square roots instead of one fetch, exact where the interpolated value is worst
    /// (near |sin θ| = 1, where cos θ_d has a square-root edge in the sines).
    ClosedForm,
}

/// cos θ_d = cos((θ_o − θ_i)/2) from the two sines, without inverse trigonometry.
pub fn cos_theta_d_from_sines(sin_theta_i: f64, sin_theta_o: f64) -> f64 {
    let cos_i = (1.0 - sin_theta_i * sin_theta_i).max(0.0).sqrt();
    let cos_o = (1.0 - sin_theta_o * sin_theta_o).max(0.0).sqrt();
    // cos(θ_o − θ_i) = cos θ_i cos θ_o + sin θ_i sin θ_o; half-angle formula (θ_d ∈ [−π/2, π/2]).
    (0.5 * (1.0 + cos_i * cos_o + sin_theta_i * sin_theta_o))
        .clamp(0.0, 1.0)
        .sqrt()
}

/// Hunz Algorithm 2 from the shader's inputs: `sin_theta_i = u·ω_i`, `sin_theta_o = u·ω_o` and
/// `cos_phi` between the projections of ω_i and ω_o on the normal plane (turned into cos(φ/2)
/// when the N table's azimuth axis is `cos_half_phi`). Out-of-range inputs
/// clamp to the texture edge (as a GPU sampler does); NaN is an error.
pub fn reconstruct_s_from_sines(
    lut_m: &Table,
    lut_n: &Table,
    sin_theta_i: f64,
    sin_theta_o: f64,
    cos_phi: f64,
    source: CosThetaDSource,
) -> Result<Rgb, TableError> {
    let m_at = |q: f64| {
        lut_m
            .lookup_scalar(&[sin_theta_i, sin_theta_o, q])
            .map(f64::from)
    };
    let cos_d = match source {
        CosThetaDSource::Table => m_at(COS_THETA_D_QUANTITY as f64)?.clamp(0.0, 1.0),
        CosThetaDSource::ClosedForm => {
            if sin_theta_i.is_nan() || sin_theta_o.is_nan() {
                // Let the lookup name the axis.
                m_at(0.0)?;
            }
            cos_theta_d_from_sines(sin_theta_i.clamp(-1.0, 1.0), sin_theta_o.clamp(-1.0, 1.0))
        }
    };
    let inv_cos2 = 1.0 / (cos_d * cos_d).max(MIN_COS2_THETA_D);
    let azimuth = AzimuthAxis::of_table(lut_n)?.coordinate(cos_phi);
    let mut s = [0.0; 3];
    for lobe in Lobe::ALL {
        let m = m_at(lobe_axis_value(lobe))?;
        let n = lut_n.lookup_rgb(&[azimuth, cos_d, lobe_axis_value(lobe)])?;
        for c in 0..3 {
            s[c] += m * n[c] as f64 * inv_cos2;
        }
    }
    Ok(s)
}

/// S(θ_i, θ_o, φ) from the two tables exactly as Hunz's shader computes it (cos θ_d from the
/// M texture).
pub fn reconstruct_s(
    lut_m: &Table,
    lut_n: &Table,
    theta_i: f64,
    theta_o: f64,
    phi: f64,
) -> Result<Rgb, TableError> {
    reconstruct_s_from_sines(
        lut_m,
        lut_n,
        theta_i.sin(),
        theta_o.sin(),
        phi.cos(),
        CosThetaDSource::Table,
    )
}

/// Accuracy of a point-light LUT pair against its fiber model; the same meaning as the
/// convolution tables' report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LutAccuracy {
    pub name: String,
    /// max |S_lut − S| over points and channels, relative to the max of S over the points.
    pub max_abs_error: f64,
    /// RMS of the same (over points × channels).
    pub rms_abs_error: f64,
    /// max |S_lut − S| / S over values above 1% of the max of S.
    pub max_rel_error: f64,
    pub samples: usize,
    /// The max of S over the points (the scale of the two absolute errors).
    pub reference_max: f64,
    /// (θ_i, θ_o, φ) of the largest absolute error, radians.
    pub worst_point: [f64; 3],
}

impl LutAccuracy {
    /// The measures over (reconstructed, model) value pairs, one per point of `points`.
    pub fn of_pairs(name: &str, pairs: &[(Rgb, Rgb)], points: &[FiberAngles]) -> Self {
        let reference_max = pairs
            .iter()
            .flat_map(|(_, r)| r.iter().copied())
            .fold(0.0f64, f64::max);
        let scale = if reference_max > 0.0 {
            reference_max
        } else {
            1.0
        };
        let (mut max_abs, mut sum_sq, mut max_rel) = (0.0f64, 0.0f64, 0.0f64);
        let mut worst_point = [0.0; 3];
        for ((got, want), a) in pairs.iter().zip(points) {
            for c in 0..3 {
                let e = (got[c] - want[c]).abs();
                if e > max_abs || e.is_nan() {
                    max_abs = e;
                    worst_point = [a.theta_i, a.theta_o, a.phi];
                }
                sum_sq += e * e;
                if want[c] > 0.01 * reference_max {
                    max_rel = max_rel.max(e / want[c]);
                }
            }
        }
        let values = (3 * points.len()).max(1) as f64;
        LutAccuracy {
            name: name.to_string(),
            max_abs_error: max_abs / scale,
            rms_abs_error: (sum_sq / values).sqrt() / scale,
            max_rel_error: max_rel,
            samples: points.len(),
            reference_max,
            worst_point,
        }
    }
}

/// Compares the reconstruction with the direct model at `points`.
pub fn check_luts(
    name: &str,
    luts: &PointLightLuts,
    source: CosThetaDSource,
    model: &Marschner,
    points: &[FiberAngles],
) -> Result<LutAccuracy, TableError> {
    let pairs: Vec<(Rgb, Rgb)> = points
        .par_iter()
        .map(|a| {
            Ok((
                luts.eval(a.theta_i, a.theta_o, a.phi, source)?,
                model.eval(a),
            ))
        })
        .collect::<Result<_, TableError>>()?;
    Ok(LutAccuracy::of_pairs(name, &pairs, points))
}

/// A deterministic stratified point set with inclinations in [−max_inclination, max_inclination]
/// (radians, ≤ π/2). Four kinds of point, in turn:
/// 0. θ_i stratified, θ_o uniform, φ stratified over (−π, π];
/// 1. on a longitudinal ridge θ_h = α_p ± 2β_p of lobe p = R, TT, TRT in turn, with φ near the
///    lobe's azimuthal peak: anywhere for R, within 35° of π for TT (forward scattering), within
///    [10°, 70°] of 0 for TRT (where the glints sit);
/// 2. grazing incidence: |θ_i| within 10° of the limit, θ_o on a ridge;
/// 3. grazing exit: the same with θ_i and θ_o exchanged.
///
/// The sign of φ is random so that the test exercises the cos φ folding.
pub fn stratified_points(
    model: &Marschner,
    count: usize,
    max_inclination: f64,
    seed: u64,
) -> Vec<FiberAngles> {
    let lobes = Lobe::ALL.map(|l| model.shift_width(l));
    stratified_points_for_lobes(lobes, count, max_inclination, seed)
}

/// [`stratified_points`] for any model with lobes R, TT, TRT of longitudinal shift α_p and
/// width β_p in θ_h (radians, in that order).
pub fn stratified_points_for_lobes(
    lobes: [(f64, f64); 3],
    count: usize,
    max_inclination: f64,
    seed: u64,
) -> Vec<FiberAngles> {
    let limit = max_inclination.clamp(0.0, PI / 2.0);
    let band = limit.min(10f64.to_radians());
    let mut rng = SplitMix64(seed);
    let per_kind = count.div_ceil(4).max(1);
    (0..count)
        .map(|k| {
            let stratum = ((k / 4) as f64 + rng.unit()) / per_kind as f64;
            let lobe = Lobe::ALL[(k / 4) % 3];
            let ridge = |rng: &mut SplitMix64, theta_other: f64| {
                let (alpha, beta) = lobes[lobe.index()];
                let theta_h = alpha + 2.0 * beta * (2.0 * rng.unit() - 1.0);
                (2.0 * theta_h - theta_other).clamp(-limit, limit)
            };
            let sign = |rng: &mut SplitMix64| if rng.unit() < 0.5 { -1.0 } else { 1.0 };
            let peak_phi = |rng: &mut SplitMix64| match lobe {
                Lobe::R => PI * rng.unit(),
                Lobe::TT => PI - 35f64.to_radians() * rng.unit(),
                Lobe::TRT => (10.0 + 60.0 * rng.unit()).to_radians(),
            };
            let (theta_i, theta_o, phi) = match k % 4 {
                0 => {
                    let ti = limit * (2.0 * stratum - 1.0);
                    let to = limit * (2.0 * rng.unit() - 1.0);
                    (ti, to, PI * (2.0 * rng.unit() - 1.0))
                }
                1 => {
                    let ti = limit * (2.0 * stratum - 1.0);
                    (ti, ridge(&mut rng, ti), peak_phi(&mut rng))
                }
                2 => {
                    let ti = sign(&mut rng) * (limit - band * stratum);
                    (ti, ridge(&mut rng, ti), peak_phi(&mut rng))
                }
                _ => {
                    let to = sign(&mut rng) * (limit - band * stratum);
                    (ridge(&mut rng, to), to, peak_phi(&mut rng))
                }
            };
            FiberAngles::new(theta_i, theta_o, sign(&mut rng) * phi)
        })
        .collect()
}

/// A tiny deterministic generator: the check's points must not depend on a crate's stream.
struct SplitMix64(u64);

impl SplitMix64 {
    fn unit(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use strandlight_tables::marschner::MarschnerParams;

    fn brown() -> Marschner {
        Marschner::new(MarschnerParams::default()).unwrap()
    }

    /// |a − b| within the f32 rounding of the stored value (plus a denormal floor).
    fn assert_f32_exact(table: f32, model: f64, what: &str) {
        let tol = f32::EPSILON as f64 * model.abs() + 1e-37;
        assert!(
            (table as f64 - model).abs() <= tol,
            "{what}: table {table:e} vs model {model:e}"
        );
    }

    #[test]
    fn m_table_is_the_model_at_its_nodes() {
        let model = brown();
        let n = 33;
        let lut = bake_lut_m(&model, &LutResolution::square(n)).unwrap();
        assert_eq!(lut.shape(), vec![n, n, 4]);
        let node = |i: usize| -1.0 + 2.0 * i as f64 / (n - 1) as f64;
        for i in 0..n {
            for j in 0..n {
                let (si, so) = (node(i), node(j));
                let (ti, to) = (si.asin(), so.asin());
                for lobe in Lobe::ALL {
                    let got = lut.lookup_scalar(&[si, so, lobe.index() as f64]).unwrap();
                    assert_f32_exact(
                        got,
                        model.longitudinal(lobe, ti, to),
                        &format!("M_{lobe:?} at ({si}, {so})"),
                    );
                }
                let got = lut.lookup_scalar(&[si, so, 3.0]).unwrap();
                assert_f32_exact(
                    got,
                    (0.5 * (to - ti)).cos(),
                    &format!("cos θ_d at ({si}, {so})"),
                );
            }
        }
    }

    #[test]
    fn n_table_is_the_model_at_its_nodes() {
        let model = brown();
        let n = 33;
        for azimuth_axis in [AzimuthAxis::CosPhi, AzimuthAxis::CosHalfPhi] {
            let res = LutResolution {
                azimuth_axis,
                ..LutResolution::square(n)
            };
            let lut = bake_lut_n(&model, &res).unwrap();
            assert_eq!((lut.shape(), lut.channels()), (vec![n, n, 3], 3));
            assert_eq!(AzimuthAxis::of_table(&lut).unwrap(), azimuth_axis);
            for i in 0..n {
                // Node i of the azimuth axis and its φ, written out independently.
                let (x, phi) = match azimuth_axis {
                    AzimuthAxis::CosPhi => {
                        let c = -1.0 + 2.0 * i as f64 / (n - 1) as f64;
                        (c, c.acos())
                    }
                    AzimuthAxis::CosHalfPhi => {
                        let c = i as f64 / (n - 1) as f64;
                        (c, 2.0 * c.acos())
                    }
                };
                for j in 0..n {
                    let cos_d = j as f64 / (n - 1) as f64;
                    for lobe in Lobe::ALL {
                        let got = lut.lookup_rgb(&[x, cos_d, lobe.index() as f64]).unwrap();
                        let want = model.azimuthal(lobe, cos_d.acos(), phi);
                        for c in 0..3 {
                            assert_f32_exact(
                                got[c],
                                want[c],
                                &format!(
                                    "N_{lobe:?}[{c}] at {azimuth_axis:?} {x}, cos θ_d {cos_d}"
                                ),
                            );
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn reconstruction_at_table_nodes_is_the_model() {
        // With θ_i = −θ_o, θ_d = θ_o: (sin θ_o, cos θ_o) ∈ {(0, 1), (0.6, 0.8), (0.8, 0.6)} puts
        // sin θ_i, sin θ_o and cos θ_d on nodes of grids with 0.1 steps (21 nodes over [−1, 1],
        // 11 over [0, 1]), and cos φ = −1 + 0.1k on the azimuth nodes: every fetch is a node.
        let model = brown();
        let res = LutResolution {
            sin_theta_i: 21,
            sin_theta_o: 21,
            azimuth: 21,
            cos_theta_d: 11,
            azimuth_axis: AzimuthAxis::CosPhi,
        };
        let luts = PointLightLuts::bake(&model, &res).unwrap();
        let mut worst: f64 = 0.0;
        for (s, c) in [(0.0, 1.0), (0.6, 0.8), (0.8, 0.6)] {
            for k in 0..=20 {
                let cos_phi = -1.0 + 0.1 * k as f64;
                for sign in [-1.0, 1.0] {
                    let theta_o = sign * f64::atan2(s, c);
                    let got = luts
                        .eval(
                            -theta_o,
                            theta_o,
                            cos_phi.acos(),
                            CosThetaDSource::ClosedForm,
                        )
                        .unwrap();
                    let want = model.eval(&FiberAngles::new(-theta_o, theta_o, cos_phi.acos()));
                    for ch in 0..3 {
                        worst = worst.max((got[ch] - want[ch]).abs() / want[ch].abs().max(1e-30));
                    }
                }
            }
        }
        eprintln!("reconstruction at nodes of both tables: max relative error {worst:.1e}");
        // f32 storage of M and N (2 roundings each side) plus coordinates rounded off the
        // node by ~1e-16 (snapped back by the table).
        assert!(worst < 4.0 * f32::EPSILON as f64, "{worst:e}");
    }

    /// The two foldings the parameterisation relies on, measured on the direct model.
    #[test]
    fn n_is_even_in_theta_d_and_s_is_even_in_phi() {
        let model = Marschner::new(MarschnerParams::with_preset("blonde").unwrap()).unwrap();
        let mut worst_d: f64 = 0.0;
        let mut worst_phi: f64 = 0.0;
        for a in 0..=36 {
            let theta_d = (a as f64 * 2.5).to_radians();
            for b in 0..=72 {
                let phi = (b as f64 * 2.5).to_radians();
                for lobe in Lobe::ALL {
                    let (p, m) = (
                        model.azimuthal(lobe, theta_d, phi),
                        model.azimuthal(lobe, -theta_d, phi),
                    );
                    for c in 0..3 {
                        worst_d = worst_d.max((p[c] - m[c]).abs() / p[c].abs().max(1e-300));
                    }
                }
            }
        }
        for a in -18..=18 {
            for b in -18..=18 {
                for k in 0..=36 {
                    let (ti, to, phi) = (
                        (a as f64 * 5.0).to_radians(),
                        (b as f64 * 5.0).to_radians(),
                        (k as f64 * 5.0).to_radians(),
                    );
                    let p = model.eval(&FiberAngles::new(ti, to, phi));
                    let m = model.eval(&FiberAngles::new(ti, to, -phi));
                    for c in 0..3 {
                        worst_phi = worst_phi.max((p[c] - m[c]).abs() / p[c].abs().max(1e-300));
                    }
                }
            }
        }
        eprintln!(
            "max relative |N(θ_d) − N(−θ_d)| = {worst_d:.1e}; max relative |S(φ) − S(−φ)| = {worst_phi:.1e}"
        );
        assert!(worst_d < 1e-12 && worst_phi < 1e-12);
    }

    #[test]
    fn closed_form_cos_theta_d_matches_the_half_angle() {
        let mut worst: f64 = 0.0;
        for a in -36..=36 {
            for b in -36..=36 {
                let (ti, to) = ((a as f64 * 2.5).to_radians(), (b as f64 * 2.5).to_radians());
                let got = cos_theta_d_from_sines(ti.sin(), to.sin());
                worst = worst.max((got - (0.5 * (to - ti)).cos()).abs());
            }
        }
        eprintln!("max |cos θ_d closed form − cos((θ_o − θ_i)/2)| = {worst:.1e}");
        // Near θ_d = ±90° the half-angle square root turns a 1e-16 rounding into ~1e-8.
        assert!(worst < 1e-7, "{worst:e}");
    }

    fn accuracy(
        model: &Marschner,
        n: usize,
        limit_deg: f64,
        azimuth_axis: AzimuthAxis,
        source: CosThetaDSource,
        samples: usize,
    ) -> LutAccuracy {
        let res = LutResolution {
            azimuth_axis,
            ..LutResolution::square(n)
        };
        let luts = PointLightLuts::bake(model, &res).unwrap();
        let points = stratified_points(model, samples, limit_deg.to_radians(), 5);
        check_luts("brown", &luts, source, model, &points).unwrap()
    }

    #[test]
    fn error_falls_as_the_textures_grow() {
        let model = brown();
        // Smooth parts fall 4× per doubling (bilinear interpolation is second order), the
        // √-edges (N_R at φ = π on a cos φ grid; the parallel Fresnel factor beyond θ_d ≈ 57°,
        // where η″ < 1) 2× in RMS: demand 1.5×, and 3× where only smooth parts remain
        // (cos(φ/2) axis, |θ| ≤ 45° so |θ_d| ≤ 45°).
        let cases = [
            (60.0, AzimuthAxis::CosPhi, CosThetaDSource::Table, 1.5),
            (80.0, AzimuthAxis::CosPhi, CosThetaDSource::ClosedForm, 1.5),
            (
                45.0,
                AzimuthAxis::CosHalfPhi,
                CosThetaDSource::ClosedForm,
                3.0,
            ),
        ];
        for (limit, azimuth, source, factor) in cases {
            let mut previous: Option<LutAccuracy> = None;
            for n in [32, 64, 128] {
                let acc = accuracy(&model, n, limit, azimuth, source, 6000);
                eprintln!(
                    "{n}² |θ| ≤ {limit}° {azimuth:?}, cos θ_d {source:?}: max {:.2e} rms {:.2e} max rel {:.2e}",
                    acc.max_abs_error, acc.rms_abs_error, acc.max_rel_error
                );
                if let Some(prev) = previous {
                    assert!(
                        acc.rms_abs_error * factor < prev.rms_abs_error,
                        "{n}: rms did not fall {factor}×"
                    );
                    assert!(
                        acc.max_abs_error < prev.max_abs_error,
                        "{n}: max did not fall"
                    );
                }
                previous = Some(acc);
            }
        }
    }

    /// The default 128² textures against the direct model.
    ///
    /// Bounds. Smooth parts: bilinear interpolation errs by at most Σ_k h_k²/8 · |∂²f/∂x_k²|. The
    /// narrowest lobe, M_TT (β = 3.75°), on the sine grid at |θ| = 45° has θ_h steps of
    /// ½·(2/127)/cos 45° = 0.64° per axis, an error ≤ 2·0.64²/(8·3.75²) = 0.7% of its peak
    /// (1.4% at |θ| = 60°), and the N lobes on the cos(φ/2) × cos θ_d grid are wider still: with
    /// the cos(φ/2) axis and |θ| ≤ 45° (|θ_d| ≤ 45°, smooth everywhere) max < 2%. On Hunz's cos φ
    /// axis N_R ∝ |cos(φ/2)| has a square-root edge at cos φ = −1 (φ = π), and beyond
    /// θ_d ≈ 57° the N_R term has another (total reflection of the parallel polarisation where
    /// h > η″, η″ < 1); no regular grid resolves those: their error is O(√cell) on a band one
    /// cell wide, which dominates the max and max-rel figures but is only O(cell) in the RMS.
    /// Hence RMS < 1% (the smooth bound plus the bands' share) and max < 12% for |θ| ≤ 60°; toward grazing (|θ| ≤ 80°) the sine grid's cells widen by
    /// cos 60°/cos 80° ≈ 2.9, so ~8× the smooth error: RMS < 2%, max < 40%. Hunz's interpolated
    /// cos θ_d adds its own error there: cos θ_d has a √(1 − |sin θ|) edge in the sines, and
    /// at θ_i = −80°, θ_o = 80° the 128² texture gives 0.1706 for 0.1736 (−1.8%), i.e. +3.6% in
    /// 1/cos²θ_d on top of the N_R edge: max < 50% with `Table`. The max bounds are the
    /// measured figures (0.07, 0.26, 0.43) with margin; the rate test above backs them.
    #[test]
    fn default_resolution_error_is_reported_and_bounded() {
        let model = brown();
        let n = LutResolution::default().sin_theta_i;
        assert_eq!(LutResolution::default(), LutResolution::square(128));
        let (cos_phi, half) = (AzimuthAxis::CosPhi, AzimuthAxis::CosHalfPhi);
        let cases = [
            (45.0, cos_phi, CosThetaDSource::Table, 1e-2, 0.12),
            (45.0, half, CosThetaDSource::ClosedForm, 2e-3, 0.02),
            (60.0, cos_phi, CosThetaDSource::Table, 1e-2, 0.12),
            (60.0, cos_phi, CosThetaDSource::ClosedForm, 1e-2, 0.12),
            (60.0, half, CosThetaDSource::ClosedForm, 1e-2, 0.12),
            (80.0, cos_phi, CosThetaDSource::Table, 2e-2, 0.5),
            (80.0, cos_phi, CosThetaDSource::ClosedForm, 2e-2, 0.4),
            (80.0, half, CosThetaDSource::ClosedForm, 2e-2, 0.4),
        ];
        for (limit, azimuth, source, rms_bound, max_bound) in cases {
            let acc = accuracy(&model, n, limit, azimuth, source, 20_000);
            let w = acc.worst_point.map(f64::to_degrees);
            eprintln!(
                "{n}² |θ| ≤ {limit}° {azimuth:?}, cos θ_d {source:?}: max S {:.3e}, max abs {:.3e}, rms {:.3e}, max rel {:.3e} ({} samples; worst at θ_i {:.1}°, θ_o {:.1}°, φ {:.1}°)",
                acc.reference_max,
                acc.max_abs_error,
                acc.rms_abs_error,
                acc.max_rel_error,
                acc.samples,
                w[0],
                w[1],
                w[2]
            );
            assert!(
                acc.rms_abs_error < rms_bound && acc.max_abs_error < max_bound,
                "{acc:?}"
            );
        }
    }

    fn extreme_fibers() -> Vec<(&'static str, MarschnerParams)> {
        let (alpha_deg, beta_deg) = MarschnerParams::lobes_from_r(-5.0, 2.0);
        vec![
            ("dark", MarschnerParams::with_preset("dark").unwrap()),
            ("white", MarschnerParams::with_preset("white").unwrap()),
            ("blonde", MarschnerParams::with_preset("blonde").unwrap()),
            (
                "σ_a = 10³",
                MarschnerParams {
                    sigma_a: [1e3; 3],
                    ..MarschnerParams::default()
                },
            ),
            (
                "β_R = 2°",
                MarschnerParams {
                    alpha_deg,
                    beta_deg,
                    ..MarschnerParams::default()
                },
            ),
        ]
    }

    #[test]
    fn no_nan_or_infinity_for_extreme_fibers_including_the_texture_edges() {
        // Values off the grid, the texture edges ±1 themselves and one step outside them.
        let coords: Vec<f64> = (0..=40)
            .map(|k| -1.0 + k as f64 / 20.0)
            .chain([-1.5, 1.5, -0.99999, 0.99999])
            .collect();
        for (name, params) in extreme_fibers() {
            let model = Marschner::new(params).unwrap();
            let luts = PointLightLuts::bake(&model, &LutResolution::square(48)).unwrap();
            for t in [&luts.m, &luts.n] {
                let s = t.stats();
                assert_eq!((s.nan_count, s.infinite_count), (0, 0), "{name}");
                assert!(s.min >= 0.0, "{name}: negative value {}", s.min);
            }
            let mut largest: f64 = 0.0;
            for &si in &coords {
                for &so in &coords {
                    for &cp in &coords {
                        for source in [CosThetaDSource::Table, CosThetaDSource::ClosedForm] {
                            let s = reconstruct_s_from_sines(&luts.m, &luts.n, si, so, cp, source)
                                .unwrap();
                            assert!(
                                s.iter().all(|v| v.is_finite() && *v >= 0.0),
                                "{name}: S{s:?} at ({si}, {so}, {cp})"
                            );
                            largest = largest.max(s[0]);
                        }
                    }
                }
            }
            eprintln!(
                "{name}: all S finite and ≥ 0; largest S_r = {largest:.3e} (the θ_d = ±90° corner, cos²θ_d floored at {MIN_COS2_THETA_D:e})"
            );
        }
    }

    #[test]
    fn absorption_extremes_give_the_physically_required_colours() {
        // σ_a = 10³: every internal chord is ≥ 2√(1 − 1/η²) ≈ 1.5 radii, T ≤ e^−1500 = 0 in f32.
        let opaque = Marschner::new(MarschnerParams {
            sigma_a: [1e3; 3],
            ..MarschnerParams::default()
        })
        .unwrap();
        let n = bake_lut_n(&opaque, &LutResolution::square(32)).unwrap();
        let mut r_max: f32 = 0.0;
        for i in 0..32 {
            for j in 0..32 {
                assert_eq!(n.node(&[i, j, 1]).unwrap(), &[0.0; 3], "TT at node {i},{j}");
                assert_eq!(
                    n.node(&[i, j, 2]).unwrap(),
                    &[0.0; 3],
                    "TRT at node {i},{j}"
                );
                r_max = r_max.max(n.node(&[i, j, 0]).unwrap()[0]);
            }
        }
        assert!(
            r_max > 0.0,
            "surface reflection does not depend on absorption"
        );
        // σ_a = 0: every lobe is grey.
        let white = Marschner::new(MarschnerParams::with_preset("white").unwrap()).unwrap();
        let n = bake_lut_n(&white, &LutResolution::square(32)).unwrap();
        for v in n.values().chunks(3) {
            assert!(v[0] == v[1] && v[1] == v[2], "{v:?}");
        }
    }

    #[test]
    fn nan_angles_are_errors_naming_the_axis() {
        let model = brown();
        for azimuth_axis in [AzimuthAxis::CosPhi, AzimuthAxis::CosHalfPhi] {
            let res = LutResolution {
                azimuth_axis,
                ..LutResolution::square(8)
            };
            let luts = PointLightLuts::bake(&model, &res).unwrap();
            for source in [CosThetaDSource::Table, CosThetaDSource::ClosedForm] {
                let err = luts.eval(f64::NAN, 0.1, 0.2, source).unwrap_err();
                assert!(err.to_string().contains("sin_theta_i"), "{err}");
                let err = luts.eval(0.1, 0.2, f64::NAN, source).unwrap_err();
                assert!(err.to_string().contains(azimuth_axis.name()), "{err}");
            }
        }
    }

    #[test]
    fn a_table_that_is_not_an_n_table_is_refused() {
        let model = brown();
        let luts = PointLightLuts::bake(&model, &LutResolution::square(8)).unwrap();
        // The M table in the N slot: its first axis is sin_theta_i.
        let err = reconstruct_s_from_sines(&luts.m, &luts.m, 0.1, 0.2, 0.3, CosThetaDSource::Table)
            .unwrap_err();
        assert!(
            matches!(&err, TableError::InvalidAxis { axis, .. } if axis == "sin_theta_i"),
            "{err}"
        );
    }

    #[test]
    fn resolution_is_validated_serialisable_and_sized() {
        let err = PointLightLuts::bake(
            &brown(),
            &LutResolution {
                azimuth: 1,
                ..LutResolution::default()
            },
        )
        .unwrap_err();
        assert!(
            matches!(
                err,
                LutError::Resolution {
                    parameter: "azimuth",
                    value: 1
                }
            ),
            "{err}"
        );
        assert!(err.to_string().contains("azimuth"));
        assert!(matches!(
            LutResolution::square(MAX_LUT_NODES + 1).validate(),
            Err(LutError::Resolution { .. })
        ));
        let res = LutResolution {
            sin_theta_i: 40,
            sin_theta_o: 50,
            azimuth: 60,
            cos_theta_d: 70,
            azimuth_axis: AzimuthAxis::CosHalfPhi,
        };
        assert!(
            serde_json::to_string(&res)
                .unwrap()
                .contains(r#""azimuth_axis":"cos_half_phi""#)
        );
        let json = serde_json::to_string(&res).unwrap();
        assert_eq!(serde_json::from_str::<LutResolution>(&json).unwrap(), res);
        let partial: LutResolution = serde_json::from_str(r#"{"azimuth": 64}"#).unwrap();
        assert_eq!(
            (partial.azimuth, partial.sin_theta_i, partial.azimuth_axis),
            (64, 128, AzimuthAxis::CosPhi)
        );
        let typo = serde_json::from_str::<LutResolution>(r#"{"cos_ph": 64}"#).unwrap_err();
        assert!(
            typo.to_string().contains("unknown field `cos_ph`"),
            "{typo}"
        );
        let luts = PointLightLuts::bake(&brown(), &res).unwrap();
        // 40·50·4 + 60·70·9 f32 values, counted by hand.
        assert_eq!(luts.bytes(), (8000 + 37800) * 4);
        assert_eq!(res.bytes(), luts.bytes());
    }

    #[test]
    fn stratified_points_reach_grazing_angles_and_the_lobe_peaks() {
        let model = brown();
        let points = stratified_points(&model, 4000, 80f64.to_radians(), 3);
        let limit = 80f64.to_radians() + 1e-12;
        assert!(
            points
                .iter()
                .all(|p| p.theta_i.abs() <= limit && p.theta_o.abs() <= limit)
        );
        let grazing = points
            .iter()
            .filter(|p| p.theta_i.abs().max(p.theta_o.abs()) > 75f64.to_radians())
            .count();
        let tt_peak = points
            .iter()
            .filter(|p| p.phi.abs() > 150f64.to_radians())
            .count();
        let negative_phi = points.iter().filter(|p| p.phi < 0.0).count();
        eprintln!(
            "of 4000: {grazing} with an inclination beyond 75°, {tt_peak} with |φ| > 150°, {negative_phi} with φ < 0"
        );
        assert!(grazing > 1000 && tt_peak > 300 && negative_phi > 1500 && negative_phi < 2500);
    }
}
