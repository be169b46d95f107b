//! `check-tables`: every baked table against an independent f64 computation of what it
//! tabulates, at random off-grid points. The models are rebuilt from the parameters stored in
//! each asset, so the check needs nothing but the files.

use crate::attenuation_ratio::attenuation_ratio;

use crate::convolution::convolve_reference;
use crate::direct_table::direct_value;
use crate::multiple_scattering_table::multiple_scattering_reference;
use crate::point_light_luts::AzimuthAxis;
use crate::srbf_spread::srbf_longitudinal_variance;
use crate::table_accuracy::{TableAccuracy, stratified_points, summarize};
use rayon::prelude::*;
use serde_json::Value;
use std::sync::Arc;
use strandlight_tables::FiberAngles;
use strandlight_tables::artist::{ArtistModel, ArtistParams, Normalization};
use strandlight_tables::asset::TableAsset;
use strandlight_tables::chiang::{
    AzimuthalResolution, Chiang, ChiangParams, LOBES, MIN_LOGISTIC_SCALE,
};
use strandlight_tables::dual_scattering::{
    DualScatteringAverages, DualScatteringConfig, LobeDecomposition, backscatter_series,
    fiber_averages_direct,
};
use strandlight_tables::kajiya_kay::{KajiyaKay, KajiyaKayParams};
use strandlight_tables::marschner::{Lobe, Marschner, MarschnerParams};
use strandlight_tables::scattering::{Rgb, ScatteringFunction};
use strandlight_tables::table_axes::{AXIS_LOBE, AXIS_QUANTITY};
use thiserror::Error;

#[derive(Debug, Error)]
pub enum CheckError {
    #[error("{}: table `{name}` is not one strandlight knows how to check", .path.display())]
    UnknownTable {
        path: std::path::PathBuf,
        name: String,
    },
    #[error("{}: its fiber parameters cannot be read back: {message}", .path.display())]
    Parameters {
        path: std::path::PathBuf,
        message: String,
    },
    #[error("{}: lookup failed: {source}", .path.display())]
    Lookup {
        path: std::path::PathBuf,
        source: strandlight_tables::table::TableError,
    },
}

/// Panels of the reference quadratures: converged well below the tables' errors (the harmonic
/// method and this reference agree to 1e-13 on smooth integrands; see `convolution`).
const REFERENCE_PANELS: usize = 32;

type Reference = Arc<dyn Fn(&[f64]) -> Vec<f64> + Send + Sync>;

/// Checks one table at `samples` points.
pub fn check_asset(
    asset: &TableAsset,
    samples: usize,
    seed: u64,
) -> Result<TableAccuracy, CheckError> {
    check_asset_with(asset, samples, seed, false)
}

/// [`check_asset`] at `samples` random grid nodes of the table, where interpolation adds no
/// error: what is left is the bake's integration against the reference's, so a table that is
/// wrong by some factor shows exactly that factor.
pub fn check_asset_at_nodes(
    asset: &TableAsset,
    samples: usize,
    seed: u64,
) -> Result<TableAccuracy, CheckError> {
    check_asset_with(asset, samples, seed, true)
}

fn check_asset_with(
    asset: &TableAsset,
    samples: usize,
    seed: u64,
    at_nodes: bool,
) -> Result<TableAccuracy, CheckError> {
    let name = asset.metadata.description.name.clone();
    let params = &asset.metadata.description.fiber_parameters;
    let path = asset.path.clone();
    let bad = |message: String| CheckError::Parameters {
        path: path.clone(),
        message,
    };
    let lookup = |source| CheckError::Lookup {
        path: path.clone(),
        source,
    };
    let table = &asset.table;
    let axes = table.axes();
    let random = || random_points(table, samples, seed);
    let (reference, points): (Reference, Vec<Vec<f64>>) = match name.as_str() {
        "marschner" | "marschner_full" | "artist" | "chiang" | "chiang_full" => {
            let s = scattering_from(&name, params).map_err(bad)?;
            let (lmin, lmax) = (1.0 / axes[3].max, 1.0 / axes[3].min);
            let pts = stratified_points(samples, lmin, lmax, seed)
                .into_iter()
                .map(|p| p.to_vec())
                .collect();
            (convolution_reference(s), pts)
        }
        "marschner_direct"
        | "marschner_full_direct"
        | "artist_direct"
        | "chiang_direct"
        | "chiang_full_direct" => {
            let s = scattering_from(name.trim_end_matches("_direct"), params).map_err(bad)?;
            // The convolution tables' stratification (grazing ends, Δφ strata), at the one
            // 1/λ node; the reference evaluates the model itself in f64.
            let inv = axes[3].min;
            let pts = stratified_points(samples, 16.0, 64.0, seed)
                .into_iter()
                .map(|p| vec![p[0], p[1], p[2], inv])
                .collect();
            let r: Reference =
                Arc::new(move |x: &[f64]| direct_value(&|a: &FiberAngles| s.eval(a), x).to_vec());
            (r, pts)
        }
        "kk_diffuse" | "kk_specular" => (
            kajiya_kay_reference(params, name == "kk_diffuse").map_err(bad)?,
            random(),
        ),
        "multiple" => (
            multiple_reference(bcsdf_from(params).map_err(bad)?),
            random(),
        ),
        "attenuation_ratio" => (
            Arc::new(|x: &[f64]| vec![attenuation_ratio(x[0], x[1])]),
            random(),
        ),
        "srbf_spread" => (
            Arc::new(|x: &[f64]| vec![srbf_longitudinal_variance(x[0], x[1])]),
            random(),
        ),
        "fiber_averages" => (
            fiber_averages_reference(lobes_from(params).map_err(bad)?),
            random(),
        ),
        "lut_m" | "lut_n" => {
            let m = marschner_from(params).map_err(bad)?;
            let is_m = name == "lut_m";
            let azimuth = lut_azimuth_axis(table, is_m).map_err(lookup)?;
            (marschner_lut_reference(m, is_m, azimuth), random())
        }
        "chiang_lut_m" | "chiang_lut_n" => {
            let m = chiang_from(params).map_err(bad)?;
            let is_m = name == "chiang_lut_m";
            let azimuth = lut_azimuth_axis(table, is_m).map_err(lookup)?;
            (chiang_lut_reference(m, is_m, azimuth), random())
        }
        _ => {
            return Err(CheckError::UnknownTable {
                path: asset.path.clone(),
                name,
            });
        }
    };
    let points = if at_nodes {
        random_nodes(table, samples, seed)
    } else {
        points
    };
    compare(asset, &name, &reference, &points)
}

/// The convolution tables' reference, at (u·ξ, u·ω_o, cos Δφ, 1/λ): the SRBF convolution of `s`
/// by direct quadrature in f64, independent of the bake's harmonic method.
fn convolution_reference(s: Arc<dyn ScatteringFunction>) -> Reference {
    Arc::new(move |x: &[f64]| {
        let v = convolve_reference(
            &|a: &FiberAngles| s.eval(a),
            x[0].asin(),
            x[1].asin(),
            x[2].clamp(-1.0, 1.0).acos(),
            1.0 / x[3],
            REFERENCE_PANELS,
        );
        v.to_vec()
    })
}

/// The Kajiya-Kay tables' reference, with the model rebuilt from the stored exponent:
/// `kk_diffuse` at (u·ξ, 1/λ) convolves 1, `kk_specular` at (u·ξ, u·ω_o, 1/λ) convolves the
/// specular lobe over cos θ_i (the table has no cos θ_i, the convolution engine adds one).
fn kajiya_kay_reference(params: &Value, diffuse: bool) -> Result<Reference, String> {
    let exponent = params
        .get("exponent")
        .and_then(Value::as_f64)
        .unwrap_or(KajiyaKayParams::default().exponent);
    let kk = KajiyaKay::new(KajiyaKayParams {
        exponent,
        ..Default::default()
    })
    .map_err(|e| e.to_string())?;
    Ok(Arc::new(move |x: &[f64]| {
        let (theta_xi, theta_o, inv) = if diffuse {
            (x[0].asin(), 0.0, x[1])
        } else {
            (x[0].asin(), x[1].asin(), x[2])
        };
        let s = |a: &FiberAngles| {
            let v = if diffuse {
                1.0
            } else {
                kk.specular_lobe(a) / a.theta_i.cos()
            };
            [v, v, v]
        };
        vec![convolve_reference(&s, theta_xi, theta_o, 0.0, 1.0 / inv, REFERENCE_PANELS)[0]]
    }))
}

/// The `multiple` table's reference at (u·ξ, u·ω_o, cos Δφ, σ̄_f): the forward-scattering
/// convolution of the BCSDF `s_d` by direct quadrature.
fn multiple_reference(s_d: Arc<dyn ScatteringFunction>) -> Reference {
    Arc::new(move |x: &[f64]| {
        multiple_scattering_reference(
            &|a: &FiberAngles| s_d.eval(a),
            x[0].asin(),
            x[1].asin(),
            x[2].clamp(-1.0, 1.0).acos(),
            x[3].max(1e-4),
            24,
        )
        .to_vec()
    })
}

/// The `fiber_averages` reference at (sin θ, quantity): the averages integrated directly from
/// the model's lobes, and the back-scattering series built from them, in the order of
/// `FIBER_AVERAGE_QUANTITIES`.
fn fiber_averages_reference(model: Arc<dyn LobesAndScattering>) -> Reference {
    Arc::new(move |x: &[f64]| {
        let theta = x[0].clamp(-1.0, 1.0).asin();
        let a = fiber_averages_direct(model.as_lobes(), theta);
        let q = x[1].round() as usize;
        (0..3)
            .map(|c| {
                let (ab, db, sb) = backscatter_series(
                    a.a_f[c],
                    a.a_b[c],
                    a.alpha_f[c],
                    a.alpha_b[c],
                    a.beta2_f[c],
                    a.beta2_b[c],
                );
                [
                    a.a_f[c],
                    a.a_b[c],
                    a.alpha_f[c],
                    a.alpha_b[c],
                    a.beta2_f[c],
                    a.beta2_b[c],
                    ab,
                    db,
                    sb,
                ][q]
            })
            .collect()
    })
}

/// The azimuth axis of a point-light texture: an N texture names it in its first axis (cos φ
/// or cos φ/2); an M texture has none, and its reference ignores the value.
fn lut_azimuth_axis(
    table: &strandlight_tables::table::Table,
    is_m: bool,
) -> Result<AzimuthAxis, strandlight_tables::table::TableError> {
    if is_m {
        Ok(AzimuthAxis::CosPhi)
    } else {
        AzimuthAxis::of_table(table)
    }
}

/// Hunz's point-light textures from Marschner's own lobe functions: `lut_m` at
/// (sin θ_i, sin θ_o, lobe) with cos θ_d as its fourth "lobe", `lut_n` at (azimuth, cos θ_d,
/// lobe).
fn marschner_lut_reference(m: Marschner, is_m: bool, azimuth: AzimuthAxis) -> Reference {
    Arc::new(move |x: &[f64]| {
        let lobe = |q: f64| [Lobe::R, Lobe::TT, Lobe::TRT][(q.round() as usize).min(2)];
        if is_m {
            let (ti, to) = (x[0].asin(), x[1].asin());
            if x[2].round() as usize == 3 {
                vec![((to - ti) / 2.0).cos()]
            } else {
                vec![m.longitudinal(lobe(x[2]), ti, to)]
            }
        } else {
            m.azimuthal(lobe(x[2]), x[1].clamp(0.0, 1.0).acos(), azimuth.phi(x[0]))
                .to_vec()
        }
    })
}

/// Chiang's point-light textures from the model's own lobe functions: `chiang_lut_m` at
/// (sin θ_i, sin θ_o, lobe), `chiang_lut_n` at (azimuth, sin θ_o, lobe) by quadrature at each
/// point rather than from the model's own interpolated N̄ grid.
fn chiang_lut_reference(m: Chiang, is_m: bool, azimuth: AzimuthAxis) -> Reference {
    Arc::new(move |x: &[f64]| {
        let p = (x[2].round() as usize).min(LOBES - 1);
        if is_m {
            vec![m.longitudinal(p, x[0].asin(), x[1].asin())]
        } else {
            m.azimuthal_exact(x[1].clamp(-1.0, 1.0).asin(), azimuth.phi(x[0]))[p].to_vec()
        }
    })
}

/// `count` points at random nodes of every axis.
fn random_nodes(
    table: &strandlight_tables::table::Table,
    count: usize,
    seed: u64,
) -> Vec<Vec<f64>> {
    let mut rng = strandlight_tables::hard_case_sweep::SweepRng::new(seed);
    (0..count)
        .map(|_| {
            table
                .axes()
                .iter()
                .map(|a| {
                    let i = ((rng.uniform() * a.count as f64) as usize).min(a.count - 1);
                    a.node(i)
                })
                .collect()
        })
        .collect()
}

/// Points uniform over every continuous axis; integer-labelled axes (`quantity`, `lobe`) get a
/// random node.
fn random_points(
    table: &strandlight_tables::table::Table,
    count: usize,
    seed: u64,
) -> Vec<Vec<f64>> {
    let mut rng = strandlight_tables::hard_case_sweep::SweepRng::new(seed);
    let mut unit = move || rng.uniform();
    (0..count)
        .map(|_| {
            table
                .axes()
                .iter()
                .map(|a| {
                    if a.name == AXIS_QUANTITY || a.name == AXIS_LOBE {
                        (unit() * a.count as f64).floor().min((a.count - 1) as f64)
                    } else {
                        a.min + (a.max - a.min) * unit()
                    }
                })
                .collect()
        })
        .collect()
}

/// One checked point: the looked-up values, their largest error, and the relative error
/// where the reference is large enough to divide by.
type CheckedPoint = (Vec<f64>, f64, Option<f64>);

fn compare(
    asset: &TableAsset,
    name: &str,
    reference: &Reference,
    points: &[Vec<f64>],
) -> Result<TableAccuracy, CheckError> {
    let table = &asset.table;
    let channels = table.channels();
    let table_max = table.stats().max.abs().max(table.stats().min.abs()) as f64;
    let floor = crate::table_accuracy::relative_error_floor(table);
    let rows: Vec<Result<CheckedPoint, CheckError>> = points
        .par_iter()
        .map(|p| {
            let mut looked = vec![0f32; channels];
            table
                .lookup_into(p, &mut looked)
                .map_err(|source| CheckError::Lookup {
                    path: asset.path.clone(),
                    source,
                })?;
            let want = reference(p);
            let mut abs: f64 = 0.0;
            let mut rel: Option<f64> = None;
            for c in 0..channels {
                let e = (looked[c] as f64 - want[c]).abs();
                abs = abs.max(e);
                if want[c].abs() > floor {
                    rel = Some(rel.unwrap_or(0.0).max(e / want[c].abs()));
                }
            }
            Ok((p.clone(), abs, rel))
        })
        .collect();
    let rows = rows.into_iter().collect::<Result<Vec<_>, _>>()?;
    let directional = matches!(
        name,
        "marschner"
            | "marschner_full"
            | "artist"
            | "multiple"
            | "kk_specular"
            | "marschner_direct"
            | "marschner_full_direct"
            | "artist_direct"
            | "chiang"
            | "chiang_full"
            | "chiang_direct"
            | "chiang_full_direct"
    );
    Ok(summarize(name, table, table_max, &rows, directional))
}

fn section<T: serde::de::DeserializeOwned + Default>(
    params: &Value,
    key: &str,
) -> Result<T, String> {
    match params.get(key) {
        Some(v) => serde_json::from_value(v.clone()).map_err(|e| format!("[{key}]: {e}")),
        None => Ok(T::default()),
    }
}

fn marschner_from(params: &Value) -> Result<Marschner, String> {
    Marschner::new(section::<MarschnerParams>(params, "marschner")?).map_err(|e| e.to_string())
}

fn artist_from(params: &Value) -> Result<ArtistModel, String> {
    ArtistModel::new(section::<ArtistParams>(params, "artist")?).map_err(|e| e.to_string())
}

/// The Chiang fiber of the stored parameters, with its N̄ grid twice as fine as a bake's on
/// both axes (≈ 8× less interpolation error), so that the reference does not share the
/// bake's N̄ grid.
fn chiang_from(params: &Value) -> Result<Chiang, String> {
    let p = section::<ChiangParams>(params, "chiang")?;
    let s = p.logistic_scale().max(MIN_LOGISTIC_SCALE);
    Chiang::with_resolution(p, AzimuthalResolution::for_scale(s).refined(2))
        .map_err(|e| e.to_string())
}

/// The function a convolution table integrates.
fn scattering_from(name: &str, params: &Value) -> Result<Arc<dyn ScatteringFunction>, String> {
    Ok(match name {
        "marschner" => Arc::new(marschner_from(params)?),
        "artist" => Arc::new(artist_from(params)?),
        "chiang" => Arc::new(chiang_from(params)?),
        _ => bcsdf_from(params)?,
    })
}

/// The single-scattering model with its lobe view, as the bake chose it from the parameters.
fn lobes_from(params: &Value) -> Result<Arc<dyn LobesAndScattering>, String> {
    if params.get("marschner").is_some() {
        Ok(Arc::new(marschner_from(params)?))
    } else if params.get("chiang").is_some() {
        Ok(Arc::new(chiang_from(params)?))
    } else {
        Ok(Arc::new(
            artist_from(params)?.normalized(Normalization::PeakPerChannel),
        ))
    }
}

trait LobesAndScattering: LobeDecomposition + ScatteringFunction {
    fn as_lobes(&self) -> &dyn LobeDecomposition;
}
impl<T: LobeDecomposition + ScatteringFunction> LobesAndScattering for T {
    fn as_lobes(&self) -> &dyn LobeDecomposition {
        self
    }
}

struct Bcsdf {
    single: Arc<dyn LobesAndScattering>,
    averages: DualScatteringAverages,
}

impl ScatteringFunction for Bcsdf {
    fn name(&self) -> &'static str {
        "bcsdf"
    }
    fn eval(&self, a: &FiberAngles) -> Rgb {
        let s = self.single.eval(a);
        let b = self.averages.backward_scattering(a);
        let d_b = self.averages.config().density_backward;
        std::array::from_fn(|c| s[c] + d_b * b[c])
    }
}

/// S + d_b·S_back, rebuilt from the stored parameters.
fn bcsdf_from(params: &Value) -> Result<Arc<dyn ScatteringFunction>, String> {
    let single = lobes_from(params)?;
    let config = section::<DualScatteringConfig>(params, "dual_scattering")?;
    let averages =
        DualScatteringAverages::new(single.as_lobes(), config).map_err(|e| e.to_string())?;
    Ok(Arc::new(Bcsdf { single, averages }))
}
