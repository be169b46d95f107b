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
//!
//! Differences from Hunz's text, on purpose:
//! * Hunz folds 1/cos²θ_d into M. At the corner sin θ_i = ∓1, sin θ_o = ±1 (θ_d = ±90°) that
//!   product reaches 10⁸ × M (the model floors cos²θ_d at [`MIN_COS2_THETA_D`]) beside nodes a
//!   hundred times smaller, which a bilinear fetch smears over a whole cell. We store cos θ_d
//!   (which Hunz also stores, as the N coordinate) and divide once in the shader.
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
use thiserror::Error;

/// Index of cos θ_d on the `quantity` axis of the M table (after M_R, M_TT, M_TRT).
pub const COS_THETA_D_QUANTITY: usize = 3;
/// Fewest nodes per continuous axis (a lookup needs one cell).
pub const MIN_LUT_NODES: usize = 2;
/// Most nodes per continuous axis: 4096² × 9 f32 is 600 MB, far past any useful texture.
pub const MAX_LUT_NODES: usize = 4096;

#[derive(Debug, Error, Clone, PartialEq)]
pub enum LutError {
    #[error("LUT resolution `{parameter}` = {value}: must be in [{MIN_LUT_NODES}, {MAX_LUT_NODES}]")]
    Resolution { parameter: &'static str, value: usize },
    #[error("table `{table}` holds a non-finite value at node {node:?}, channel {channel}; the fiber parameters produce NaN/∞ there")]
    NonFinite {
        table: &'static str,
        node: Vec<usize>,
        channel: usize,
    },
    #[error(transparent)]
    Table(#[from] TableError),
}

/// Node counts of the two lookup textures. Hunz 2016 does not state a texture size; 128 per
/// axis is the default (see the module tests and `examples/lut_error.rs` for error vs size).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LutResolution {
    pub sin_theta_i: usize,
    pub sin_theta_o: usize,
    pub cos_phi: usize,
    pub cos_theta_d: usize,
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
            cos_phi: n,
            cos_theta_d: n,
        }
    }

    pub fn validate(&self) -> Result<(), LutError> {
        for (parameter, value) in [
            ("sin_theta_i", self.sin_theta_i),
            ("sin_theta_o", self.sin_theta_o),
            ("cos_phi", self.cos_phi),
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
        let n = self.cos_phi * self.cos_theta_d * 3 * 3;
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
    pub fn eval(&self, theta_i: f64, theta_o: f64, phi: f64, source: CosThetaDSource) -> Result<Rgb, TableError> {
        reconstruct_s_from_sines(&self.m, &self.n, theta_i.sin(), theta_o.sin(), phi.cos(), source)
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
        Axis::uniform("sin_theta_i", -1.0, 1.0, resolution.sin_theta_i),
        Axis::uniform("sin_theta_o", -1.0, 1.0, resolution.sin_theta_o),
        Axis::uniform("quantity", 0.0, COS_THETA_D_QUANTITY as f64, 4),
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

/// The N texture: N_R, N_TT, N_TRT (RGB) over (cos φ, cos θ_d).
pub fn bake_lut_n(model: &Marschner, resolution: &LutResolution) -> Result<Table, LutError> {
    resolution.validate()?;
    let axes = vec![
        Axis::uniform("cos_phi", -1.0, 1.0, resolution.cos_phi),
        Axis::uniform("cos_theta_d", 0.0, 1.0, resolution.cos_theta_d),
        Axis::uniform("lobe", 0.0, 2.0, 3),
    ];
    let table = Table::from_fn(axes, 3, |x, out| {
        let phi = x[0].clamp(-1.0, 1.0).acos();
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
    (0.5 * (1.0 + cos_i * cos_o + sin_theta_i * sin_theta_o)).clamp(0.0, 1.0).sqrt()
}

/// Hunz Algorithm 2 from the shader's inputs: `sin_theta_i = u·ω_i`, `sin_theta_o = u·ω_o` and
/// `cos_phi` between the projections of ω_i and ω_o on the normal plane. Out-of-range inputs
/// clamp to the texture edge (as a GPU sampler does); NaN is an error.
pub fn reconstruct_s_from_sines(
    lut_m: &Table,
    lut_n: &Table,
    sin_theta_i: f64,
    sin_theta_o: f64,
    cos_phi: f64,
    source: CosThetaDSource,
) -> Result<Rgb, TableError> {
    let m_at = |q: f64| lut_m.lookup_scalar(&[sin_theta_i, sin_theta_o, q]).map(f64::from);
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
    let mut s = [0.0; 3];
    for lobe in Lobe::ALL {
        let m = m_at(lobe_axis_value(lobe))?;
        let n = lut_n.lookup_rgb(&[cos_phi, cos_d, lobe_axis_value(lobe)])?;
        for c in 0..3 {
            s[c] += m * n[c] as f64 * inv_cos2;
        }
    }
    Ok(s)
}

/// S(θ_i, θ_o, φ) from the two tables exactly as Hunz's shader computes it (cos θ_d from the
/// M texture).
pub fn reconstruct_s(lut_m: &Table, lut_n: &Table, theta_i: f64, theta_o: f64, phi: f64) -> Result<Rgb, TableError> {
    reconstruct_s_from_sines(lut_m, lut_n, theta_i.sin(), theta_o.sin(), phi.cos(), CosThetaDSource::Table)
}

/// Accuracy of the reconstructed S against [`Marschner::eval`]; the same meaning as the
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
        .map(|a| Ok((luts.eval(a.theta_i, a.theta_o, a.phi, source)?, model.eval(a))))
        .collect::<Result<_, TableError>>()?;
    let reference_max = pairs
        .iter()
        .flat_map(|(_, r)| r.iter().copied())
        .fold(0.0f64, f64::max);
    let scale = if reference_max > 0.0 { reference_max } else { 1.0 };
    let (mut max_abs, mut sum_sq, mut max_rel) = (0.0f64, 0.0f64, 0.0f64);
    let mut worst_point = [0.0; 3];
    for ((got, want), a) in pairs.iter().zip(points) {
        for c in 0..3 {
            let e = (got[c] - want[c]).abs();
            if !(e <= max_abs) {
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
    Ok(LutAccuracy {
        name: name.to_string(),
        max_abs_error: max_abs / scale,
        rms_abs_error: (sum_sq / values).sqrt() / scale,
        max_rel_error: max_rel,
        samples: points.len(),
        reference_max,
        worst_point,
    })
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
pub fn stratified_points(model: &Marschner, count: usize, max_inclination: f64, seed: u64) -> Vec<FiberAngles> {
    let limit = max_inclination.clamp(0.0, PI / 2.0);
    let band = limit.min(10f64.to_radians());
    let mut rng = SplitMix64(seed);
    let per_kind = count.div_ceil(4).max(1);
    (0..count)
        .map(|k| {
            let stratum = ((k / 4) as f64 + rng.unit()) / per_kind as f64;
            let lobe = Lobe::ALL[(k / 4) % 3];
            let ridge = |rng: &mut SplitMix64, theta_other: f64| {
                let (alpha, beta) = model.shift_width(lobe);
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
