//! What the toolkit knows, with values a person can sanity-check, every number computed live:
//! the models at their defaults, the melanin presets, a white furnace of Marschner's lobes by
//! f64 sphere quadrature, the dual-scattering single-event albedo per preset, and the SRBF
//! closed-form integral against quadrature. `strandlight summary` prints it.

use rayon::prelude::*;
use serde::Serialize;
use strandlight_tables::absorption::{PRESETS, preset_sigma_a};
use strandlight_tables::angles::direction;
use strandlight_tables::artist::{ArtistModel, ArtistParams, Normalization};
use strandlight_tables::dual_scattering::fiber_averages_direct;
use strandlight_tables::kajiya_kay::{KajiyaKay, KajiyaKayParams};
use strandlight_tables::longitudinal::LongitudinalModel;
use strandlight_tables::marschner::{Lobe, Marschner, MarschnerParams};
use strandlight_tables::quadrature::integrate_sphere;
use strandlight_tables::{FiberAngles, Rgb, ScatteringFunction, srbf};

/// Named (θ_i, θ_o, φ) in degrees where each model is sampled.
pub const CONFIGURATIONS: [(&str, f64, f64, f64); 4] = [
    ("specular cone, front (R)", 30.0, -30.0, 0.0),
    ("backlit (TT)", 30.0, -30.0, 180.0),
    ("side, 90°", 30.0, -30.0, 90.0),
    ("grazing (θ_i 89.9°)", 89.9, -85.0, 45.0),
];

#[derive(Serialize)]
pub struct Sample {
    pub configuration: &'static str,
    pub theta_i_deg: f64,
    pub theta_o_deg: f64,
    pub phi_deg: f64,
    pub s: Rgb,
}

#[derive(Serialize)]
pub struct ModelSummary {
    pub name: &'static str,
    pub parameters: serde_json::Value,
    pub samples: Vec<Sample>,
}

#[derive(Serialize)]
pub struct PresetSummary {
    pub name: &'static str,
    pub eumelanin: f64,
    pub pheomelanin: f64,
    /// Per unit fiber radius.
    pub sigma_a: Rgb,
}

#[derive(Serialize)]
pub struct FurnaceRow {
    pub theta_i_deg: f64,
    pub r: f64,
    pub tt: f64,
    pub trt: f64,
    pub total: f64,
    /// The total again with twice the panels in θ and φ: the quadrature's own convergence.
    pub total_refined: f64,
}

#[derive(Serialize)]
pub struct AlbedoRow {
    pub preset: &'static str,
    pub theta_deg: f64,
    pub forward: Rgb,
    pub backward: Rgb,
    pub total: Rgb,
}

#[derive(Serialize)]
pub struct SrbfRow {
    pub lambda: f64,
    pub closed_form: f64,
    pub quadrature: f64,
    pub relative_difference: f64,
}

#[derive(Serialize)]
pub struct Summary {
    pub version: &'static str,
    pub models: Vec<ModelSummary>,
    pub presets: Vec<PresetSummary>,
    pub furnace_rule: String,
    pub white_furnace_marschner: Vec<FurnaceRow>,
    pub single_event_albedo_marschner: Vec<AlbedoRow>,
    pub srbf_rule: String,
    pub srbf_integral: Vec<SrbfRow>,
}

/// Every figure of the summary, computed now.
pub fn compute() -> anyhow::Result<Summary> {
    Ok(Summary {
        version: env!("CARGO_PKG_VERSION"),
        models: models()?,
        presets: presets()?,
        furnace_rule: format!(
            "integrate_sphere({FURNACE_PANELS:?}) (8-point Gauss–Legendre panels)"
        ),
        white_furnace_marschner: white_furnace()?,
        single_event_albedo_marschner: single_event_albedo()?,
        srbf_rule: format!("integrate_sphere({SRBF_PANELS:?}) (8-point Gauss–Legendre panels)"),
        srbf_integral: srbf_rows(),
    })
}

// ---------------------------------------------------------------------------------------------
// Models at their defaults.

fn models() -> anyhow::Result<Vec<ModelSummary>> {
    let gaussian = MarschnerParams::default();
    let deon = MarschnerParams {
        longitudinal_model: LongitudinalModel::DEon,
        ..MarschnerParams::default()
    };
    let artist = ArtistModel::new(ArtistParams::default())?;
    Ok(vec![
        summarize(
            "marschner (defaults: brown, Gaussian M_p)",
            &gaussian,
            &Marschner::new(gaussian.clone())?,
        )?,
        summarize(
            "marschner (d'Eon M_p)",
            &deon,
            &Marschner::new(deon.clone())?,
        )?,
        summarize(
            "kajiya-kay",
            &KajiyaKayParams::default(),
            &KajiyaKay::new(KajiyaKayParams::default())?,
        )?,
        summarize("artist (raw f'_s)", artist.params(), &artist)?,
        summarize(
            "artist (normalized per channel, Sadeghi eq. 13)",
            artist.params(),
            &artist.normalized(Normalization::PerChannel),
        )?,
    ])
}

fn summarize(
    name: &'static str,
    params: &impl Serialize,
    model: &dyn ScatteringFunction,
) -> anyhow::Result<ModelSummary> {
    let samples = CONFIGURATIONS
        .iter()
        .map(|&(configuration, ti, to, phi)| Sample {
            configuration,
            theta_i_deg: ti,
            theta_o_deg: to,
            phi_deg: phi,
            s: model.eval(&FiberAngles::new(
                ti.to_radians(),
                to.to_radians(),
                phi.to_radians(),
            )),
        })
        .collect();
    Ok(ModelSummary {
        name,
        parameters: serde_json::to_value(params)?,
        samples,
    })
}

fn presets() -> anyhow::Result<Vec<PresetSummary>> {
    PRESETS
        .iter()
        .map(|p| {
            Ok(PresetSummary {
                name: p.name,
                eumelanin: p.eumelanin,
                pheomelanin: p.pheomelanin,
                sigma_a: preset_sigma_a(p.name)?,
            })
        })
        .collect()
}

// ---------------------------------------------------------------------------------------------
// Reference checks by quadrature.

/// (θ panels, φ panels) of the furnace quadrature: 256 × 512 nodes, ~0.7° in θ, enough for
/// β_TT = 3.75°.
const FURNACE_PANELS: (usize, usize) = (32, 64);

/// White furnace: E_p(θ_i) = ∫ S_p(θ_i, θ_o, φ) cos θ_o dω_o for a non-absorbing fiber with
/// otherwise default parameters (glints on). With the energy-conserving M_p the total is near
/// 1 minus what leaves after more than two internal reflections; M_p's spread over θ_d (the
/// 1/cos²θ_d factor) moves it by a few percent either way.
fn white_furnace() -> anyhow::Result<Vec<FurnaceRow>> {
    let white = Marschner::new(MarschnerParams {
        sigma_a: [0.0; 3],
        ..MarschnerParams::default()
    })?;
    Ok([0.0, 60.0]
        .into_iter()
        .map(|ti| furnace_row(&white, ti))
        .collect())
}

fn furnace_row(model: &Marschner, theta_i_deg: f64) -> FurnaceRow {
    let e = lobe_energies(model, theta_i_deg.to_radians(), FURNACE_PANELS);
    let fine = (2 * FURNACE_PANELS.0, 2 * FURNACE_PANELS.1);
    let e_fine = lobe_energies(model, theta_i_deg.to_radians(), fine);
    FurnaceRow {
        theta_i_deg,
        r: e[0],
        tt: e[1],
        trt: e[2],
        total: e.iter().sum(),
        total_refined: e_fine.iter().sum(),
    }
}

/// ∫ S_p cos θ_o dω_o per lobe (dω_o = cos θ_o dθ_o dφ is in `integrate_sphere`).
fn lobe_energies(model: &Marschner, theta_i: f64, panels: (usize, usize)) -> Vec<f64> {
    Lobe::ALL
        .par_iter()
        .map(|&lobe| {
            integrate_sphere(panels.0, panels.1, |to, phi| {
                model.eval_lobe(lobe, &FiberAngles::new(theta_i, to, phi))[0] * to.cos()
            })
        })
        .collect()
}

/// Zinke's ā_f + ā_b at normal incidence (θ = 0) for Marschner with each preset's σ_a: the
/// fraction of light one scattering event returns (Marschner's direct f64 integration).
fn single_event_albedo() -> anyhow::Result<Vec<AlbedoRow>> {
    PRESETS
        .par_iter()
        .map(|p| {
            let model = Marschner::new(MarschnerParams::with_preset(p.name)?)?;
            let avg = fiber_averages_direct(&model, 0.0);
            Ok(AlbedoRow {
                preset: p.name,
                theta_deg: 0.0,
                forward: avg.a_f,
                backward: avg.a_b,
                total: std::array::from_fn(|c| avg.a_f[c] + avg.a_b[c]),
            })
        })
        .collect()
}

/// Panels of the SRBF quadrature: 512 × 1024 nodes, ~0.35° in θ against a λ = 64 lobe of
/// width ~1/√64 rad ≈ 7°.
const SRBF_PANELS: (usize, usize) = (64, 128);

fn srbf_rows() -> Vec<SrbfRow> {
    // An off-axis center so that the lobe straddles grid lines rather than sitting on a pole.
    let xi = direction(0.4, 1.1);
    [16.0, 64.0]
        .into_iter()
        .map(|lambda| {
            let quadrature = integrate_sphere(SRBF_PANELS.0, SRBF_PANELS.1, |t, p| {
                srbf::kernel(direction(t, p).dot(xi), lambda)
            });
            let closed_form = srbf::integral(lambda);
            SrbfRow {
                lambda,
                closed_form,
                quadrature,
                relative_difference: (quadrature - closed_form) / closed_form,
            }
        })
        .collect()
}

// ---------------------------------------------------------------------------------------------
// Text output.
