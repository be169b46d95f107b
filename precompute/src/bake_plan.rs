//! What to bake for a fiber: the table jobs of each model (Ren 2010 §4, §6; Hunz §3.3.4), and
//! the decision to skip multiple scattering for hair too dark to need it.
//!
//! Multiple scattering (`fiber_averages`, `multiple`) comes from one model: Marschner when it
//! is baked, else Chiang, else the artist model's normalized copy.

use crate::attenuation_ratio::attenuation_ratio_table;
use crate::bake::{BuildError, TableJob};
use crate::chiang_luts::{bake_chiang_lut_m, bake_chiang_lut_n};
use crate::convolution::{ConvolutionGrid, ConvolutionSettings, convolve_grid};
use crate::convolution_table::{ConvolutionResolution, bake_convolution_table};
use crate::direct_table::{DirectResolution, bake_direct_table};
use crate::multiple_scattering_table::{
    MultipleScatteringResolution, bake_multiple_scattering_table,
};
use crate::point_light_luts::{LutResolution, bake_lut_m, bake_lut_n};
use crate::srbf_spread::srbf_spread_table;
use serde::{Deserialize, Serialize};
use serde_json::json;
use std::path::Path;
use std::sync::{Arc, OnceLock};
use strandlight_tables::FiberAngles;
use strandlight_tables::artist::{ArtistModel, ArtistParams, Normalization};
use strandlight_tables::asset::Storage;
use strandlight_tables::chiang::{Chiang, ChiangParams};
use strandlight_tables::dual_scattering::{
    DualScatteringAverages, DualScatteringBcsdf, DualScatteringConfig, LobeDecomposition,
};
use strandlight_tables::error::ParamError;
use strandlight_tables::kajiya_kay::{KajiyaKay, KajiyaKayParams};
use strandlight_tables::marschner::{Marschner, MarschnerParams};
use strandlight_tables::scattering::{Rgb, ScatteringFunction};
use strandlight_tables::table::{Axis, AxisMapping, Table, TableError};
use strandlight_tables::table_axes::{AXIS_QUANTITY, AXIS_SIN_THETA};
use thiserror::Error;

/// Everything about a fiber that any table depends on. A TOML file with any subset of these
/// sections (`[marschner]`, `[kajiya_kay]`, `[artist]`, `[chiang]`, `[dual_scattering]`); the
/// rest default.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(default, deny_unknown_fields)]
pub struct FiberDescription {
    pub marschner: MarschnerParams,
    pub kajiya_kay: KajiyaKayParams,
    pub artist: ArtistParams,
    /// Chiang et al. 2016 under Mitsuba's parameter names (the path tracer's fiber).
    pub chiang: ChiangParams,
    pub dual_scattering: DualScatteringConfig,
}

#[derive(Debug, Error)]
pub enum FiberError {
    #[error("{}: {source}", .path.display())]
    Read {
        path: std::path::PathBuf,
        source: std::io::Error,
    },
    #[error("{}: not a valid fiber description: {message}", .path.display())]
    Parse {
        path: std::path::PathBuf,
        message: String,
    },
    #[error("{context}: {source}")]
    Param { context: String, source: ParamError },
    #[error("{context}: {source}")]
    Table {
        context: &'static str,
        source: TableError,
    },
}

impl FiberDescription {
    /// The defaults with the melanin of a named preset: Marschner's absorption and Chiang's
    /// concentrations.
    pub fn preset(name: &str) -> Result<Self, FiberError> {
        let preset_error = |source| FiberError::Param {
            context: "--preset".into(),
            source,
        };
        let marschner = MarschnerParams::with_preset(name).map_err(preset_error)?;
        let chiang = ChiangParams::with_preset(name).map_err(preset_error)?;
        Ok(Self {
            marschner,
            chiang,
            ..Self::default()
        })
    }

    pub fn from_toml_file(path: &Path) -> Result<Self, FiberError> {
        let text = std::fs::read_to_string(path).map_err(|source| FiberError::Read {
            path: path.into(),
            source,
        })?;
        let fiber: Self = toml::from_str(&text).map_err(|e| FiberError::Parse {
            path: path.into(),
            message: e.to_string(),
        })?;
        fiber.validate().map_err(|e| match e {
            FiberError::Param { context, source } => FiberError::Param {
                context: format!("{}: {context}", path.display()),
                source,
            },
            other => other,
        })?;
        Ok(fiber)
    }

    pub fn validate(&self) -> Result<(), FiberError> {
        self.marschner
            .validate()
            .map_err(param_error("[marschner]"))?;
        self.kajiya_kay
            .validate()
            .map_err(param_error("[kajiya_kay]"))?;
        self.artist.validate().map_err(param_error("[artist]"))?;
        self.chiang.validate().map_err(param_error("[chiang]"))?;
        self.dual_scattering
            .validate()
            .map_err(param_error("[dual_scattering]"))?;
        Ok(())
    }
}

/// The scattering models a bake can cover.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Model {
    Marschner,
    KajiyaKay,
    Artist,
    /// Chiang et al. 2016 (serde `"chiang"`).
    Chiang,
}

/// Node counts of every table.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BakeResolution {
    pub convolution: ConvolutionResolution,
    pub settings: ConvolutionSettingsSerde,
    pub multiple: MultipleScatteringResolution,
    pub luts: LutResolution,
    pub attenuation_ratio: [usize; 2],
    pub attenuation_nu_max: f64,
    pub srbf_spread: [usize; 2],
    pub fiber_average_thetas: usize,
    /// Nodes per direction axis of the Kajiya-Kay tables: cheap (at most 3D, monochrome), so
    /// they get enough nodes to follow the specular lobe (p = 40 is ~9° wide).
    pub kajiya_kay_direction_nodes: usize,
    /// Nodes per direction axis of the direct tables (S·cos θ_i for directional lights): 3D,
    /// so they can afford enough nodes to follow the narrow R lobe.
    pub direct_direction_nodes: usize,
}

/// [`ConvolutionSettings`] as it is written into cache keys.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ConvolutionSettingsSerde {
    pub theta_panels: usize,
    pub phi_panels: usize,
}

impl From<ConvolutionSettingsSerde> for ConvolutionSettings {
    fn from(s: ConvolutionSettingsSerde) -> Self {
        Self {
            theta_panels: s.theta_panels,
            phi_panels: s.phi_panels,
            max_harmonic: None,
        }
    }
}

/// Nodes of the convolution tables' u·ω_o axis: the R lobe is as narrow in θ_o as the fiber's
/// longitudinal width, and the convolution with an SRBF widens it only over ω_i, so the view
/// axis needs three times the paper's 32 nodes (the SRBF frame's unshadowed error, fit and
/// tables together, against a 6144-light reference of the same map: venice 0.045 → 0.011 at
/// 64 → 0.008 at 96, quarry 0.021 → 0.013; 128 gains nothing more; docs/BENCHMARKS.md,
/// "Where the error comes from, map by map").
pub const CONVOLUTION_VIEW_NODES: usize = 96;
/// Nodes of the convolution tables' 1/λ axis: it spans only the fitted set's bandwidths, over
/// which the convolution varies slowly (64 → 8 nodes left both maps above unchanged; 16 keeps
/// a margin for wide ranges such as quarry's λ 18–276).
pub const CONVOLUTION_INV_LAMBDA_NODES: usize = 16;

impl Default for BakeResolution {
    /// The paper's sample counts (32 per direction axis, 64 for σ̄_f) on angular axes, except
    /// the convolution tables' view and 1/λ axes ([`CONVOLUTION_VIEW_NODES`],
    /// [`CONVOLUTION_INV_LAMBDA_NODES`]): 19 MB a table instead of 25, and 4-6× less error.
    fn default() -> Self {
        let convolution = ConvolutionResolution {
            axes: crate::convolution_table::DirectionAxes::Angular,
            u_dot_wo: CONVOLUTION_VIEW_NODES,
            inv_lambda: CONVOLUTION_INV_LAMBDA_NODES,
            ..Default::default()
        };
        let d = ConvolutionSettings::default();
        Self {
            convolution,
            settings: ConvolutionSettingsSerde {
                theta_panels: d.theta_panels,
                phi_panels: d.phi_panels,
            },
            multiple: MultipleScatteringResolution {
                axes: crate::convolution_table::DirectionAxes::Angular,
                ..Default::default()
            },
            luts: LutResolution::default(),
            attenuation_ratio: [32, 32],
            attenuation_nu_max: 1.0,
            srbf_spread: [32, 64],
            fiber_average_thetas: 128,
            kajiya_kay_direction_nodes: 96,
            direct_direction_nodes: DEFAULT_DIRECT_NODES,
        }
    }
}

/// Direct-table nodes per direction axis at full resolution (measured: docs/BENCHMARKS.md).
pub const DEFAULT_DIRECT_NODES: usize = 128;

impl BakeResolution {
    /// The layout of the direct tables: the convolution tables' direction axes, `n` nodes each.
    pub fn direct(&self) -> DirectResolution {
        DirectResolution::cube(self.direct_direction_nodes, self.convolution.axes)
    }

    /// Every direction axis with `n` nodes, λ and σ̄_f with `2n`: for quick runs and CI.
    pub fn reduced(n: usize) -> Self {
        let mut r = Self::default();
        r.convolution = ConvolutionResolution {
            u_dot_xi: n,
            u_dot_wo: n,
            cos_dphi: n,
            inv_lambda: 2 * n,
            ..r.convolution
        };
        r.multiple = MultipleScatteringResolution {
            u_dot_xi: n,
            u_dot_wo: n,
            cos_dphi: n,
            sigma_f: 2 * n,
            theta_nodes: 513,
            ..r.multiple
        };
        r.luts = LutResolution::square(4 * n);
        r.attenuation_ratio = [n, n];
        r.srbf_spread = [n, 2 * n];
        r.fiber_average_thetas = 4 * n;
        r.kajiya_kay_direction_nodes = 3 * n;
        // 3D and cheap, so 4n, but never above the full-resolution count (1024³ would be 13 GB).
        r.direct_direction_nodes = (4 * n).min(DEFAULT_DIRECT_NODES);
        r.settings = ConvolutionSettingsSerde {
            theta_panels: 48,
            phi_panels: 16,
        };
        r
    }

    /// Spans only the SRBF bandwidths actually used (with a margin), not the global bounds.
    pub fn with_lambda_range(mut self, lambda_min: f64, lambda_max: f64) -> Self {
        self.convolution.lambda_min = lambda_min;
        self.convolution.lambda_max = lambda_max;
        self
    }
}

/// What the plan decided not to bake, and why.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct SkippedTable {
    pub name: String,
    pub reason: String,
}

/// The jobs for `models`, plus the tables skipped.
pub struct BakePlan {
    pub jobs: Vec<TableJob>,
    pub skipped: Vec<SkippedTable>,
    /// The direction-averaged single-event albedo ā_f + ā_b of the brightest channel: the
    /// share of the scattered energy that goes on to scatter again (the multiple-scattering
    /// share in a dense volume). `None` when no model has one, or the plan's tables leave out
    /// `multiple`.
    pub multiple_scattering_share: Option<f64>,
}

/// Below this multiple-scattering share the `multiple` table is skipped unless forced.
pub const DEFAULT_MULTIPLE_THRESHOLD: f64 = 0.15;

#[derive(Debug, Clone)]
pub struct PlanOptions {
    pub models: Vec<Model>,
    pub resolution: BakeResolution,
    pub force_multiple: bool,
    pub multiple_threshold: f64,
    /// Only these of the models' tables (`None`: all of them). A plan without `multiple`
    /// makes no multiple-scattering decision, so it integrates no fiber averages.
    pub tables: Option<Vec<String>>,
}

impl PlanOptions {
    fn wants(&self, table: &str) -> bool {
        self.tables
            .as_ref()
            .is_none_or(|wanted| wanted.iter().any(|name| name == table))
    }
}

impl Default for PlanOptions {
    fn default() -> Self {
        Self {
            models: vec![Model::Marschner, Model::KajiyaKay, Model::Artist],
            resolution: BakeResolution::default(),
            force_multiple: false,
            multiple_threshold: DEFAULT_MULTIPLE_THRESHOLD,
            tables: None,
        }
    }
}

fn boxed<E: std::error::Error + Send + Sync + 'static>(e: E) -> BuildError {
    Box::new(e)
}

fn param_error(context: &'static str) -> impl Fn(ParamError) -> FiberError {
    move |source| FiberError::Param {
        context: context.into(),
        source,
    }
}

/// A model's dual-scattering averages, integrated when a job or the multiple-scattering
/// decision first reads them. Built up front (with Chiang's azimuthal grid) they took 0.29 s of
/// every plan, which a first look's single-scattering tables, or a cache holding every table,
/// never need.
#[derive(Clone)]
struct LazyAverages {
    averages: Arc<OnceLock<Result<DualScatteringAverages, ParamError>>>,
    compute: Arc<dyn Fn() -> Result<DualScatteringAverages, ParamError> + Send + Sync>,
    /// Known without integrating anything (a plan of cached tables integrates nothing).
    config: DualScatteringConfig,
    context: &'static str,
}

impl LazyAverages {
    fn new<M: LobeDecomposition + 'static>(
        model: Arc<M>,
        config: DualScatteringConfig,
        context: &'static str,
    ) -> Self {
        Self {
            averages: Arc::new(OnceLock::new()),
            compute: Arc::new(move || DualScatteringAverages::new(model.as_ref(), config)),
            config,
            context,
        }
    }

    fn get(&self) -> Result<&DualScatteringAverages, FiberError> {
        self.averages
            .get_or_init(|| (self.compute)())
            .as_ref()
            .map_err(|e| param_error(self.context)(e.clone()))
    }

    /// The dual-scattering BCSDF of `single` with these averages (its `d_b S_back` term).
    fn bcsdf<S: Clone + 'static>(&self, single: &S) -> Result<DualScatteringBcsdf<S>, BuildError> {
        Ok(DualScatteringBcsdf {
            single: single.clone(),
            averages: self.get().map_err(boxed)?.clone(),
        })
    }
}

/// The model whose BCSDF multiple scattering uses, with its dual-scattering averages, their
/// fiber parameters (for the cache key) and the name written into the `multiple` table.
struct MultipleScatteringSource {
    single: Arc<dyn ScatteringFunction>,
    averages: LazyAverages,
    params: serde_json::Value,
    name: &'static str,
}

/// Builds the list of jobs. Cheap: every table is computed only when its job runs.
pub fn plan(fiber: &FiberDescription, options: &PlanOptions) -> Result<BakePlan, FiberError> {
    plan_with_cache(fiber, options, None)
}

/// [`plan`] for tables that may already be baked in `cache`: where that folder holds the
/// current `fiber_averages`, the multiple-scattering decision reads it instead of integrating
/// the fiber averages again (0.38 s of every env frame's preparation with its tables cached,
/// on 2 cores). Either way the decision reads the same table, so it is the same decision.
pub fn plan_with_cache(
    fiber: &FiberDescription,
    options: &PlanOptions,
    cache: Option<&Path>,
) -> Result<BakePlan, FiberError> {
    fiber.validate()?;
    let res = &options.resolution;
    let settings: ConvolutionSettings = res.settings.into();
    let mut jobs = Vec::new();
    let mut skipped = Vec::new();

    // The physical model whose BCSDF multiple scattering uses: Marschner if baked, else Chiang,
    // else the artist model's normalized copy (Sadeghi eq. 13).
    let mut multiple_source = None;

    if options.models.contains(&Model::Marschner) {
        multiple_source = Some(push_marschner(&mut jobs, fiber, res, settings)?);
    }

    if options.models.contains(&Model::Chiang) {
        let source = push_chiang(&mut jobs, fiber, res, settings)?;
        if multiple_source.is_none() {
            let (single, averages, params) = source;
            push_fiber_averages(
                &mut jobs,
                averages.clone(),
                params.clone(),
                res.fiber_average_thetas,
            );
            multiple_source = Some(MultipleScatteringSource {
                single,
                averages,
                params,
                name: "chiang",
            });
        }
    }

    if options.models.contains(&Model::KajiyaKay) {
        push_kajiya_kay(&mut jobs, fiber, res, settings)?;
    }

    if options.models.contains(&Model::Artist) {
        let artist_source =
            push_artist(&mut jobs, fiber, res, settings, multiple_source.is_none())?;
        multiple_source = multiple_source.or(artist_source);
    }

    let share = match multiple_source {
        Some(source) => push_multiple_scattering(&mut jobs, &mut skipped, source, options, cache)?,
        None => None,
    };
    if let Some(wanted) = &options.tables {
        jobs.retain(|job| wanted.iter().any(|name| name == job.name));
    }
    Ok(BakePlan {
        jobs,
        skipped,
        multiple_scattering_share: share,
    })
}

/// The Marschner jobs: `marschner` (I of S), `marschner_full` (S + d_b S_back), the two direct
/// tables, the fiber averages and Hunz's point-light textures `lut_m`, `lut_n`. Marschner is the
/// first choice of multiple-scattering source, so its averages are always tabulated; the source
/// is returned for the caller.
fn push_marschner(
    jobs: &mut Vec<TableJob>,
    fiber: &FiberDescription,
    res: &BakeResolution,
    settings: ConvolutionSettings,
) -> Result<MultipleScatteringSource, FiberError> {
    let conv_settings = json!({ "resolution": res.convolution, "settings": res.settings });
    let m = Arc::new(Marschner::new(fiber.marschner.clone()).map_err(param_error("[marschner]"))?);
    let params = json!({ "marschner": fiber.marschner });
    let (s, r) = (m.clone(), res.clone());
    jobs.push(TableJob {
        name: "marschner",
        quantity: "I_M: ∫ G(ω_i; ξ, λ) S(ω_i, ω_o) cos θ_i dω_i, Marschner single scattering (Ren eq. 8), RGB".into(),
        scattering_function: "marschner".into(),
        fiber_parameters: params.clone(),
        settings: conv_settings.clone(),
        build: Box::new(move || Ok(bake_convolution_table(&|a: &FiberAngles| s.eval(a), &r.convolution, &settings)?)),
    });
    let averages = LazyAverages::new(
        m.clone(),
        fiber.dual_scattering,
        "[marschner] dual-scattering averages",
    );
    let full_params =
        json!({ "marschner": fiber.marschner, "dual_scattering": fiber.dual_scattering });
    let (a, single, r) = (averages.clone(), m.clone(), res.clone());
    jobs.push(TableJob {
        name: "marschner_full",
        quantity: "I_M with d_b·S_back: ∫ G (S + d_b S_back) cos θ_i dω_i (Ren §7), RGB".into(),
        scattering_function: "marschner+dual-scattering-back".into(),
        fiber_parameters: full_params.clone(),
        settings: conv_settings,
        build: Box::new(move || {
            let b = a.bcsdf(single.as_ref())?;
            Ok(bake_convolution_table(
                &|a: &FiberAngles| b.eval(a),
                &r.convolution,
                &settings,
            )?)
        }),
    });
    let direct_model = m.clone();
    push_direct(
        jobs,
        "marschner_direct",
        "S(ω_i, ω_o)·cos θ_i of Marschner for a directional light, RGB",
        "marschner",
        params.clone(),
        res,
        move || Ok(direct_model),
    );
    let (a, single) = (averages.clone(), m.clone());
    push_direct(
        jobs,
        "marschner_full_direct",
        "(S + d_b S_back)·cos θ_i for a directional light (Ren §7), RGB",
        "marschner+dual-scattering-back",
        full_params.clone(),
        res,
        move || Ok(Arc::new(a.bcsdf(single.as_ref())?)),
    );
    push_fiber_averages(
        jobs,
        averages.clone(),
        full_params.clone(),
        res.fiber_average_thetas,
    );
    let (mm, mn) = (m.clone(), m.clone());
    let luts = res.luts;
    jobs.push(TableJob {
        name: "lut_m",
        quantity: "Hunz Alg. 2 M texture: M_R, M_TT, M_TRT, cos θ_d over (sin θ_i, sin θ_o)".into(),
        scattering_function: "marschner".into(),
        fiber_parameters: params.clone(),
        settings: json!({ "luts": luts }),
        build: Box::new(move || bake_lut_m(&mm, &luts).map_err(boxed)),
    });
    jobs.push(TableJob {
        name: "lut_n",
        quantity: "Hunz Alg. 2 N texture: N_R, N_TT, N_TRT over (cos φ, cos θ_d), RGB".into(),
        scattering_function: "marschner".into(),
        fiber_parameters: params,
        settings: json!({ "luts": luts }),
        build: Box::new(move || bake_lut_n(&mn, &luts).map_err(boxed)),
    });
    Ok(MultipleScatteringSource {
        single: m,
        averages,
        params: full_params,
        name: "marschner",
    })
}

/// The artist-model jobs: `artist` (I of f'_s) and `artist_direct`. When no physical model is
/// baked (`multiple_source_needed`), the model's normalized copy (Sadeghi eq. 13) becomes the
/// multiple-scattering source: its fiber averages are tabulated and the source returned.
fn push_artist(
    jobs: &mut Vec<TableJob>,
    fiber: &FiberDescription,
    res: &BakeResolution,
    settings: ConvolutionSettings,
    multiple_source_needed: bool,
) -> Result<Option<MultipleScatteringSource>, FiberError> {
    let conv_settings = json!({ "resolution": res.convolution, "settings": res.settings });
    let a = Arc::new(ArtistModel::new(fiber.artist).map_err(param_error("[artist]"))?);
    let (s, r) = (a.clone(), res.clone());
    jobs.push(TableJob {
        name: "artist",
        quantity: "I_A: ∫ G(ω_i; ξ, λ) f'_s(ω_i, ω_o) cos θ_i dω_i, artist-friendly model (Sadeghi eq. 12), RGB".into(),
        scattering_function: "artist".into(),
        fiber_parameters: json!({ "artist": fiber.artist }),
        settings: conv_settings,
        build: Box::new(move || Ok(bake_convolution_table(&|x: &FiberAngles| s.eval(x), &r.convolution, &settings)?)),
    });
    push_direct(
        jobs,
        "artist_direct",
        "f'_s(ω_i, ω_o)·cos θ_i of the artist-friendly model for a directional light, RGB",
        "artist",
        json!({ "artist": fiber.artist }),
        res,
        {
            let a = a.clone();
            move || Ok(a)
        },
    );
    if !multiple_source_needed {
        return Ok(None);
    }
    let normalized = Arc::new(a.normalized(Normalization::PeakPerChannel));
    let averages = LazyAverages::new(
        normalized.clone(),
        fiber.dual_scattering,
        "[artist] dual-scattering averages",
    );
    let params = json!({ "artist": fiber.artist, "dual_scattering": fiber.dual_scattering, "normalization": "peak-per-channel" });
    push_fiber_averages(
        jobs,
        averages.clone(),
        params.clone(),
        res.fiber_average_thetas,
    );
    Ok(Some(MultipleScatteringSource {
        single: normalized,
        averages,
        params,
        name: "artist-normalized",
    }))
}

/// The multiple-scattering jobs of `source`: `multiple` (skipped, with the reason recorded,
/// when the hair is too dark for it to matter and it is not forced), and the two tables the
/// forward-scattering volume reads with the fiber averages, `attenuation_ratio` and
/// `srbf_spread`, which are baked either way. Returns the multiple-scattering share the
/// decision was made on.
fn push_multiple_scattering(
    jobs: &mut Vec<TableJob>,
    skipped: &mut Vec<SkippedTable>,
    source: MultipleScatteringSource,
    options: &PlanOptions,
    cache: Option<&Path>,
) -> Result<Option<f64>, FiberError> {
    let MultipleScatteringSource {
        single,
        averages,
        params,
        name,
    } = source;
    // The decision reads the averages: made only for a plan that may bake `multiple`.
    let albedo = match options.wants("multiple") {
        true => {
            let table = decision_averages(jobs, &averages, options, cache)?;
            let albedo = single_event_albedo(&table).map_err(|source| FiberError::Table {
                context: "fiber_averages",
                source,
            })?;
            Some(albedo)
        }
        false => None,
    };
    if let Some(albedo) = albedo
        && albedo < options.multiple_threshold
        && !options.force_multiple
    {
        skipped.push(SkippedTable {
            name: "multiple".into(),
            reason: format!(
                "multiple scattering carries about {:.1}% of the scattered energy (largest single-event albedo ā_f + ā_b), below the {:.1}% threshold: rendering single scattering only (use --force-multiple to bake it anyway)",
                100.0 * albedo,
                100.0 * options.multiple_threshold
            ),
        });
    } else if albedo.is_some() {
        let r = options.resolution.clone();
        let d_b = averages.config.density_backward;
        jobs.push(TableJob {
            name: "multiple",
            quantity: "I_G: ∫ ψ_f(ξ, ω_i, σ̄_f) (S + d_b S_back) cos θ_i dω_i (Ren eq. 11), σ̄_f = std of θ_i, RGB".into(),
            scattering_function: format!("{name}+dual-scattering-back"),
            fiber_parameters: params,
            settings: json!({ "multiple": r.multiple }),
            build: Box::new(move || {
                let averages = averages.get()?;
                let s_d = |a: &FiberAngles| -> Rgb {
                    let s = single.eval(a);
                    let b = averages.backward_scattering(a);
                    std::array::from_fn(|c| s[c] + d_b * b[c])
                };
                Ok(bake_multiple_scattering_table(&s_d, &r.multiple)?)
            }),
        });
    }
    let r = options.resolution.clone();
    jobs.push(TableJob {
        name: "attenuation_ratio",
        quantity: "α(ν, θ) = σ_t(ω)/σ_t⊥ for fiber-direction deviation ν (Ren §6)".into(),
        scattering_function: String::new(),
        fiber_parameters: json!({}),
        settings: json!({ "attenuation_ratio": r.attenuation_ratio, "nu_max": r.attenuation_nu_max }),
        build: Box::new(move || Ok(attenuation_ratio_table(r.attenuation_ratio[0], r.attenuation_ratio[1], r.attenuation_nu_max)?)),
    });
    let r = options.resolution.clone();
    jobs.push(TableJob {
        name: "srbf_spread",
        quantity: "first-event longitudinal variance of an SRBF light over (|u·ξ|, λ), rad² (Ren §6)".into(),
        scattering_function: String::new(),
        fiber_parameters: json!({}),
        settings: json!({ "srbf_spread": r.srbf_spread, "lambda": [r.convolution.lambda_min, r.convolution.lambda_max] }),
        build: Box::new(move || Ok(srbf_spread_table(r.srbf_spread[0], r.srbf_spread[1], r.convolution.lambda_min, r.convolution.lambda_max)?)),
    });
    Ok(albedo)
}

/// The Chiang jobs, parallel to Marschner's: `chiang` (I of S), `chiang_full` (S + d_b S_back
/// with the averages of Chiang's lobe decomposition), the two direct tables and the
/// point-light textures `chiang_lut_m`, `chiang_lut_n` ([`crate::chiang_luts`]). Returns the
/// model, its dual-scattering averages and their parameters, for the caller to use as the
/// multiple-scattering source.
#[allow(clippy::type_complexity)]
fn push_chiang(
    jobs: &mut Vec<TableJob>,
    fiber: &FiberDescription,
    res: &BakeResolution,
    settings: ConvolutionSettings,
) -> Result<(Arc<dyn ScatteringFunction>, LazyAverages, serde_json::Value), FiberError> {
    // Its N̄ grid is built by the first job that evaluates it (0.17 s: none, when every
    // table is cached).
    let c = Arc::new(Chiang::new(fiber.chiang.clone()).map_err(param_error("[chiang]"))?);
    let params = json!({ "chiang": fiber.chiang });
    let conv_settings = json!({ "resolution": res.convolution, "settings": res.settings });
    let (s, r) = (c.clone(), res.clone());
    jobs.push(TableJob {
        name: "chiang",
        quantity: "I_C: ∫ G(ω_i; ξ, λ) S(ω_i, ω_o) cos θ_i dω_i, Chiang et al. 2016 single scattering averaged over the fiber's width, RGB".into(),
        scattering_function: "chiang".into(),
        fiber_parameters: params.clone(),
        settings: conv_settings.clone(),
        build: Box::new(move || Ok(bake_convolution_table(&|a: &FiberAngles| s.eval(a), &r.convolution, &settings)?)),
    });
    let averages = LazyAverages::new(
        c.clone(),
        fiber.dual_scattering,
        "[chiang] dual-scattering averages",
    );
    let full_params = json!({ "chiang": fiber.chiang, "dual_scattering": fiber.dual_scattering });
    let (a, single, r) = (averages.clone(), c.clone(), res.clone());
    jobs.push(TableJob {
        name: "chiang_full",
        quantity: "I_C with d_b·S_back: ∫ G (S + d_b S_back) cos θ_i dω_i (Ren §7), RGB".into(),
        scattering_function: "chiang+dual-scattering-back".into(),
        fiber_parameters: full_params.clone(),
        settings: conv_settings,
        build: Box::new(move || {
            let b = a.bcsdf(single.as_ref())?;
            Ok(bake_convolution_table(
                &|a: &FiberAngles| b.eval(a),
                &r.convolution,
                &settings,
            )?)
        }),
    });
    let direct_model = c.clone();
    push_direct(
        jobs,
        "chiang_direct",
        "S(ω_i, ω_o)·cos θ_i of Chiang et al. 2016 for a directional light, RGB",
        "chiang",
        params.clone(),
        res,
        move || Ok(direct_model),
    );
    let (a, single) = (averages.clone(), c.clone());
    push_direct(
        jobs,
        "chiang_full_direct",
        "(S + d_b S_back)·cos θ_i of Chiang et al. 2016 for a directional light (Ren §7), RGB",
        "chiang+dual-scattering-back",
        full_params.clone(),
        res,
        move || Ok(Arc::new(a.bcsdf(single.as_ref())?)),
    );
    let (cm, cn) = (c.clone(), c.clone());
    let luts = res.luts;
    jobs.push(TableJob {
        name: "chiang_lut_m",
        quantity: "Chiang M texture: M_R, M_TT, M_TRT, M_residual over (sin θ_i, sin θ_o); S·cos θ_i = Σ_p M_p N̄_p".into(),
        scattering_function: "chiang".into(),
        fiber_parameters: params.clone(),
        settings: json!({ "luts": luts }),
        build: Box::new(move || bake_chiang_lut_m(&cm, &luts).map_err(boxed)),
    });
    jobs.push(TableJob {
        name: "chiang_lut_n",
        quantity: "Chiang N texture: N̄_R, N̄_TT, N̄_TRT, N̄_residual over (cos φ, sin θ_o), RGB; S·cos θ_i = Σ_p M_p N̄_p".into(),
        scattering_function: "chiang".into(),
        fiber_parameters: params,
        settings: json!({ "luts": luts }),
        build: Box::new(move || bake_chiang_lut_n(&cn, &luts).map_err(boxed)),
    });
    Ok((c as Arc<dyn ScatteringFunction>, averages, full_params))
}

/// A direct table of `model` (see [`crate::direct_table`]): same fiber parameters as the
/// convolution table it stands beside, so one parameter check serves both.
fn push_direct(
    jobs: &mut Vec<TableJob>,
    name: &'static str,
    quantity: &str,
    scattering_function: &str,
    fiber_parameters: serde_json::Value,
    res: &BakeResolution,
    model: impl FnOnce() -> Result<Arc<dyn ScatteringFunction>, BuildError> + Send + 'static,
) {
    let direct = res.direct();
    jobs.push(TableJob {
        name,
        quantity: quantity.into(),
        scattering_function: scattering_function.into(),
        fiber_parameters,
        settings: json!({ "direct": direct }),
        build: Box::new(move || {
            let model = model()?;
            Ok(bake_direct_table(
                &|a: &FiberAngles| model.eval(a),
                &direct,
            )?)
        }),
    });
}

/// The `fiber_averages` table the decision reads: the one baked in `cache` when it is current
/// (f32, the inputs of this plan's job), else computed as that job computes it.
fn decision_averages(
    jobs: &[TableJob],
    averages: &LazyAverages,
    options: &PlanOptions,
    cache: Option<&Path>,
) -> Result<Arc<Table>, FiberError> {
    let cached = cache.zip(jobs.iter().find(|j| j.name == "fiber_averages"));
    if let Some(asset) = cached.and_then(|(dir, job)| {
        crate::bake::current_asset(dir, job.name, &job.inputs_key(), Storage::F32)
    }) {
        return Ok(asset.table);
    }
    let table = fiber_averages_table(averages.get()?, options.resolution.fiber_average_thetas)
        .map_err(|source| FiberError::Table {
            context: "fiber_averages",
            source,
        })?;
    Ok(Arc::new(table))
}

/// The single-event albedo ā_f + ā_b averaged over incident directions (cos θ-weighted over
/// inclinations, as light arrives isotropically in a dense volume), for the brightest channel,
/// read from a `fiber_averages` table. In a dense medium of albedo a the multiply scattered
/// share of the scattered light is a.
pub fn single_event_albedo(fiber_averages: &Table) -> Result<f64, TableError> {
    let rule = strandlight_tables::quadrature::GaussLegendre::composite(
        8,
        16,
        -std::f64::consts::FRAC_PI_2,
        std::f64::consts::FRAC_PI_2,
    );
    let mut sum = [0.0f64; 3];
    for (theta, weight) in rule.nodes.iter().zip(&rule.weights) {
        let a_f = fiber_averages.lookup_rgb(&[theta.sin(), 0.0])?;
        let a_b = fiber_averages.lookup_rgb(&[theta.sin(), 1.0])?;
        for c in 0..3 {
            sum[c] += 0.5 * weight * (a_f[c] + a_b[c]) as f64 * theta.cos();
        }
    }
    Ok(sum.into_iter().fold(0.0, f64::max))
}

/// Names of the quantities on the `quantity` axis of `fiber_averages`, in node order.
pub const FIBER_AVERAGE_QUANTITIES: [&str; 9] = [
    "a_f", "a_b", "alpha_f", "alpha_b", "beta2_f", "beta2_b", "A_b", "Delta_b", "sigma2_b",
];

fn push_fiber_averages(
    jobs: &mut Vec<TableJob>,
    averages: LazyAverages,
    params: serde_json::Value,
    thetas: usize,
) {
    jobs.push(TableJob {
        name: "fiber_averages",
        quantity: format!("dual-scattering fiber averages per inclination (Zinke 2008), quantity axis = {FIBER_AVERAGE_QUANTITIES:?}, angles in radians of θ_h, RGB"),
        scattering_function: "dual-scattering".into(),
        fiber_parameters: params,
        settings: json!({ "thetas": thetas }),
        build: Box::new(move || Ok(fiber_averages_table(averages.get()?, thetas)?)),
    });
}

/// Zinke's averages of `averages` at `thetas` inclinations (arcsine-spaced), one node per
/// [`FIBER_AVERAGE_QUANTITIES`]: the `fiber_averages` table, which the forward-scattering grid
/// reads and the multiple-scattering decision is made on.
pub fn fiber_averages_table(
    averages: &DualScatteringAverages,
    thetas: usize,
) -> Result<Table, TableError> {
    let axes = vec![
        Axis::with_mapping(AXIS_SIN_THETA, -1.0, 1.0, thetas, AxisMapping::Arcsine),
        Axis::uniform(
            AXIS_QUANTITY,
            0.0,
            (FIBER_AVERAGE_QUANTITIES.len() - 1) as f64,
            FIBER_AVERAGE_QUANTITIES.len(),
        ),
    ];
    Table::from_fn(axes, 3, |x, out| {
        let theta = x[0].clamp(-1.0, 1.0).asin();
        let a = averages.averages_at(theta);
        let m = averages.moments_at(theta);
        let q: Rgb = match x[1].round() as usize {
            0 => a.a_f,
            1 => a.a_b,
            2 => a.alpha_f,
            3 => a.alpha_b,
            4 => a.beta2_f,
            5 => a.beta2_b,
            6 => m.attenuation,
            7 => m.shift,
            _ => m.variance,
        };
        for c in 0..3 {
            out[c] = q[c] as f32;
        }
    })
}

fn push_kajiya_kay(
    jobs: &mut Vec<TableJob>,
    fiber: &FiberDescription,
    res: &BakeResolution,
    settings: ConvolutionSettings,
) -> Result<(), FiberError> {
    // Neither integrand depends on φ: only the zeroth harmonic is non-zero, exactly.
    let settings = ConvolutionSettings {
        max_harmonic: Some(0),
        ..settings
    };
    let kk = Arc::new(KajiyaKay::new(fiber.kajiya_kay).map_err(param_error("[kajiya_kay]"))?);
    let n = res.kajiya_kay_direction_nodes;
    let conv = ConvolutionResolution {
        u_dot_xi: n,
        u_dot_wo: n,
        ..res.convolution
    };
    let grid_2d = {
        let axes = conv.axes();
        ConvolutionGrid {
            sin_theta_xi: (0..axes[0].count).map(|i| axes[0].node(i)).collect(),
            sin_theta_o: vec![0.0],
            cos_delta_phi: vec![1.0],
            lambda: (0..axes[3].count).map(|i| 1.0 / axes[3].node(i)).collect(),
        }
    };
    let diffuse_axes = {
        let a = conv.axes();
        vec![a[0].clone(), a[3].clone()]
    };
    jobs.push(TableJob {
        name: "kk_diffuse",
        quantity: "I_d: ∫ G(ω_i; ξ, λ) cos θ_i dω_i (Ren §4; times K_d at run time), monochrome"
            .into(),
        scattering_function: "kajiya-kay".into(),
        fiber_parameters: json!({}),
        settings: json!({ "resolution": conv, "settings": res.settings }),
        build: Box::new(move || {
            let v = convolve_grid(&|_: &FiberAngles| [1.0, 1.0, 1.0], &grid_2d, &settings);
            Ok(Table::new(
                diffuse_axes,
                1,
                v.iter().map(|x| x[0] as f32).collect(),
            )?)
        }),
    });
    let exponent = fiber.kajiya_kay.exponent;
    let spec_axes = {
        let a = conv.axes();
        vec![a[0].clone(), a[1].clone(), a[3].clone()]
    };
    let grid_3d = {
        let a = conv.axes();
        ConvolutionGrid {
            sin_theta_xi: (0..a[0].count).map(|i| a[0].node(i)).collect(),
            sin_theta_o: (0..a[1].count).map(|i| a[1].node(i)).collect(),
            cos_delta_phi: vec![1.0],
            lambda: (0..a[3].count).map(|i| 1.0 / a[3].node(i)).collect(),
        }
    };
    jobs.push(TableJob {
        name: "kk_specular",
        quantity:
            "I_s: ∫ G(ω_i; ξ, λ) cos^p(θ_i + θ_o) dω_i (Ren §4; times K_s at run time), monochrome"
                .into(),
        scattering_function: "kajiya-kay".into(),
        fiber_parameters: json!({ "exponent": exponent }),
        settings: json!({ "resolution": conv, "settings": res.settings }),
        build: Box::new(move || {
            // The engine integrates S·cos θ_i; I_s has no cos θ_i, so hand it lobe / cos θ_i
            // (Gauss–Legendre nodes never sit on the poles).
            let s = |a: &FiberAngles| {
                let v = kk.specular_lobe(a) / a.theta_i.cos();
                [v, v, v]
            };
            let v = convolve_grid(&s, &grid_3d, &settings);
            Ok(Table::new(
                spec_axes,
                1,
                v.iter().map(|x| x[0] as f32).collect(),
            )?)
        }),
    });
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The decision reads a cached `fiber_averages` when its inputs are this plan's: the same
    /// share as integrating them afresh, and a doctored table of the same inputs (every
    /// average 0.5, so ā_f + ā_b = 1 at every inclination) moves it to 1.
    #[test]
    fn a_plan_decides_from_the_cached_fiber_averages_as_from_fresh_ones() {
        let options = PlanOptions {
            models: vec![Model::Chiang],
            resolution: BakeResolution::reduced(4),
            tables: Some(vec!["fiber_averages".into(), "multiple".into()]),
            ..Default::default()
        };
        let fiber = FiberDescription::preset("blonde").unwrap();
        let fresh = plan(&fiber, &options).unwrap().multiple_scattering_share;
        let root =
            std::env::temp_dir().join(format!("strandlight-plan-cache-{}", std::process::id()));
        let bake_averages = |dir: &Path, doctored: bool| {
            let job = plan(&fiber, &options)
                .unwrap()
                .jobs
                .into_iter()
                .find(|j| j.name == "fiber_averages")
                .unwrap();
            let job = match doctored {
                false => job,
                true => TableJob {
                    build: Box::new(|| {
                        let averages = fiber_averages_table(
                            &DualScatteringAverages::new(
                                &Chiang::new(ChiangParams::default()).unwrap(),
                                DualScatteringConfig::default(),
                            )
                            .unwrap(),
                            4,
                        )?;
                        let axes = averages.axes().to_vec();
                        Ok(Table::new(axes, 3, vec![0.5; averages.values().len()])?)
                    }),
                    ..job
                },
            };
            crate::bake::bake_job(job, dir, Storage::F32).unwrap();
            plan_with_cache(&fiber, &options, Some(dir))
                .unwrap()
                .multiple_scattering_share
                .unwrap()
        };
        let cached = bake_averages(&root.join("true"), false);
        let doctored = bake_averages(&root.join("doctored"), true);
        std::fs::remove_dir_all(&root).ok();
        assert_eq!(Some(cached), fresh);
        assert!((doctored - 1.0).abs() < 1e-9, "{doctored}");
    }

    #[test]
    fn a_plan_of_some_tables_keeps_their_cache_keys_and_leaves_multiple_undecided() {
        let all = PlanOptions {
            models: vec![Model::Chiang],
            resolution: BakeResolution::reduced(4),
            ..Default::default()
        };
        let first_look = PlanOptions {
            tables: Some(vec!["chiang".into(), "chiang_full_direct".into()]),
            ..all.clone()
        };
        let fiber = FiberDescription::preset("blonde").unwrap();
        let keys = |options: &PlanOptions| -> Vec<(&str, String)> {
            let plan = plan(&fiber, options).unwrap();
            plan.jobs.iter().map(|j| (j.name, j.inputs_key())).collect()
        };
        let some = keys(&first_look);
        let every = keys(&all);
        assert_eq!(some.len(), 2, "{some:?}");
        for job in &some {
            assert!(every.contains(job), "{job:?} not in the whole plan");
        }
        let partial = plan(&fiber, &first_look).unwrap();
        assert_eq!(partial.multiple_scattering_share, None);
        assert!(partial.skipped.is_empty());
        let whole = plan(&fiber, &all).unwrap();
        assert!(whole.multiple_scattering_share.is_some());
    }

    #[test]
    fn dark_hair_skips_multiple_scattering_and_blonde_keeps_it() {
        let options = PlanOptions {
            models: vec![Model::Marschner],
            resolution: BakeResolution::reduced(4),
            ..Default::default()
        };
        let dark = plan(&FiberDescription::preset("dark").unwrap(), &options).unwrap();
        let blonde = plan(&FiberDescription::preset("blonde").unwrap(), &options).unwrap();
        for preset in ["dark", "brown", "red", "blonde", "white"] {
            let p = plan(&FiberDescription::preset(preset).unwrap(), &options).unwrap();
            println!(
                "multiple-scattering share {preset}: {:.4}",
                p.multiple_scattering_share.unwrap()
            );
        }
        assert!(dark.skipped.iter().any(|s| s.name == "multiple"));
        assert!(blonde.jobs.iter().any(|j| j.name == "multiple"));
        // The share is an albedo: above the ~4.6% Fresnel reflectance of R alone, below 1.
        let d = dark.multiple_scattering_share.unwrap();
        assert!(d > 0.046 && d < DEFAULT_MULTIPLE_THRESHOLD, "{d}");
        let forced = plan(
            &FiberDescription::preset("dark").unwrap(),
            &PlanOptions {
                force_multiple: true,
                ..options
            },
        )
        .unwrap();
        assert!(forced.jobs.iter().any(|j| j.name == "multiple"));
    }

    #[test]
    fn chiang_jobs_parallel_marschners_and_skip_multiple_scattering_for_dark_hair() {
        let options = PlanOptions {
            models: vec![Model::Chiang],
            resolution: BakeResolution::reduced(4),
            ..Default::default()
        };
        let blonde = plan(&FiberDescription::preset("blonde").unwrap(), &options).unwrap();
        let names: Vec<&str> = blonde.jobs.iter().map(|j| j.name).collect();
        for want in [
            "chiang",
            "chiang_full",
            "chiang_direct",
            "chiang_full_direct",
            "chiang_lut_m",
            "chiang_lut_n",
            "fiber_averages",
            "multiple",
            "attenuation_ratio",
            "srbf_spread",
        ] {
            assert!(names.contains(&want), "{want} missing from {names:?}");
        }
        let averages = blonde
            .jobs
            .iter()
            .find(|j| j.name == "fiber_averages")
            .unwrap();
        assert!(averages.fiber_parameters.get("chiang").is_some());
        for preset in ["dark", "brown", "red", "blonde", "white"] {
            let p = plan(&FiberDescription::preset(preset).unwrap(), &options).unwrap();
            println!(
                "chiang multiple-scattering share {preset}: {:.4}",
                p.multiple_scattering_share.unwrap()
            );
        }
        let dark = plan(&FiberDescription::preset("dark").unwrap(), &options).unwrap();
        assert!(dark.skipped.iter().any(|s| s.name == "multiple"));
        let d = dark.multiple_scattering_share.unwrap();
        assert!(d > 0.03 && d < DEFAULT_MULTIPLE_THRESHOLD, "{d}");
        let b = blonde.multiple_scattering_share.unwrap();
        assert!(b > DEFAULT_MULTIPLE_THRESHOLD && b < 1.0, "{b}");
    }

    #[test]
    fn marschner_stays_the_multiple_scattering_source_beside_chiang() {
        let options = PlanOptions {
            models: vec![Model::Chiang, Model::Marschner, Model::Artist],
            resolution: BakeResolution::reduced(4),
            ..Default::default()
        };
        let p = plan(&FiberDescription::preset("blonde").unwrap(), &options).unwrap();
        let averages: Vec<_> = p
            .jobs
            .iter()
            .filter(|j| j.name == "fiber_averages")
            .collect();
        assert_eq!(averages.len(), 1);
        assert!(averages[0].fiber_parameters.get("marschner").is_some());
        let multiple = p.jobs.iter().find(|j| j.name == "multiple").unwrap();
        assert!(multiple.scattering_function.starts_with("marschner"));
        // Every table name is unique.
        let mut names: Vec<&str> = p.jobs.iter().map(|j| j.name).collect();
        names.sort_unstable();
        let before = names.len();
        names.dedup();
        assert_eq!(names.len(), before);
    }

    #[test]
    fn presets_set_the_chiang_melanin_and_model_names_round_trip() {
        let dark = FiberDescription::preset("dark").unwrap();
        assert_eq!((dark.chiang.eumelanin, dark.chiang.pheomelanin), (8.0, 0.0));
        let red = FiberDescription::preset("red").unwrap();
        assert_eq!((red.chiang.eumelanin, red.chiang.pheomelanin), (0.3, 2.0));
        assert_eq!(red.marschner.sigma_a, red.chiang.absorption().unwrap());
        assert_eq!(serde_json::to_string(&Model::Chiang).unwrap(), "\"chiang\"");
        assert_eq!(
            serde_json::from_str::<Model>("\"chiang\"").unwrap(),
            Model::Chiang
        );
    }

    #[test]
    fn fiber_files_report_the_file_and_the_parameter() {
        let dir = std::env::temp_dir().join(format!("strandlight-fiber-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("bad.toml");
        std::fs::write(&path, "[marschner]\neta = 0.9\n").unwrap();
        let err = FiberDescription::from_toml_file(&path)
            .unwrap_err()
            .to_string();
        assert!(err.contains("bad.toml") && err.contains("eta"), "{err}");
        std::fs::write(&path, "[marschner]\netta = 1.5\n").unwrap();
        let err = FiberDescription::from_toml_file(&path)
            .unwrap_err()
            .to_string();
        assert!(err.contains("bad.toml") && err.contains("etta"), "{err}");
        std::fs::write(
            &path,
            "[marschner]\neta = 1.6\n[dual_scattering]\ndensity_backward = 0.6\n",
        )
        .unwrap();
        let ok = FiberDescription::from_toml_file(&path).unwrap();
        assert_eq!(ok.marschner.eta, 1.6);
        std::fs::write(&path, "[chiang]\nlongitudinal_roughness = 1.5\n").unwrap();
        let err = FiberDescription::from_toml_file(&path)
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("[chiang]") && err.contains("longitudinal_roughness"),
            "{err}"
        );
        std::fs::write(
            &path,
            "[chiang]\neumelanin = 0.5\nscale_tilt_degrees = 3.0\n",
        )
        .unwrap();
        let ok = FiberDescription::from_toml_file(&path).unwrap();
        assert_eq!(
            (ok.chiang.eumelanin, ok.chiang.scale_tilt_degrees),
            (0.5, 3.0)
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
