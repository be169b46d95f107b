//! How an environment-lit frame looks besides its scene and lights: the view's transparency,
//! the transmittance's box average, and where multiple scattering's shadow paths are marched.
//! The `cli` feature lets the command line parse these settings directly.

use anyhow::Context;
use strandlight_runtime::env::{
    BoxAverage, DEFAULT_SIMPLIFICATION_SEED, LobeSpread, ViewTransparency,
};
use strandlight_runtime::passes::convolution_depth::DodmSettings;

/// What the view shows of each pixel's fibers (Ren §8).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[cfg_attr(any(feature = "cli", test), derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum EnvTransparency {
    /// The nearest fiber, weighted by its coverage.
    Opaque,
    /// Every fiber, weighted by coverage × its visibility through the occupancy map.
    Occupancy,
}

/// Where the forward-scattering shadow paths are marched (Ren §6).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[cfg_attr(any(feature = "cli", test), derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum ForwardDevice {
    /// The GPU on a hardware adapter, rayon on a software one (lavapipe runs compute shaders on
    /// the same CPU cores, where rayon measured 4–9% faster at the interactive grid:
    /// docs/BENCHMARKS.md, "CPU vs GPU march").
    Auto,
    Cpu,
    Gpu,
}

/// What the effective transmittance's box averages (the CLI's names for [`BoxAverage`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[cfg_attr(any(feature = "cli", test), derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum BoxAverageArg {
    /// Ren 2010: exp(−mean optical depth).
    OpticalDepth,
    /// The mean of exp(−optical depth).
    Transmittance,
}

/// The renderer choices of the env-lit commands.
#[derive(Debug, Clone, Copy)]
#[cfg_attr(any(feature = "cli", test), derive(clap::Args))]
pub struct LookArgs {
    /// The nearest fiber of each pixel (opaque), or every fiber weighted by its visibility
    /// through an occupancy map (Ren §8; order-independent transparency; costs about as many
    /// times the view pass as the hair has fragments per pixel).
    #[cfg_attr(
        any(feature = "cli", test),
        arg(long, value_enum, default_value = "opaque")
    )]
    pub transparency: EnvTransparency,
    #[cfg_attr(any(feature = "cli", test), command(flatten))]
    pub view: ViewArgs,
}

/// The env-lit renderer's choices besides the transparency (which `render` names its own way,
/// sharing `--transparency` with the point-light renderer).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[cfg_attr(any(feature = "cli", test), derive(clap::Args))]
pub struct ViewArgs {
    /// With occupancy: fragments seen less than this fraction are not shaded (early termination).
    #[cfg_attr(any(feature = "cli", test), arg(long, default_value_t = ViewTransparency::DEFAULT_CUTOFF))]
    pub visibility_cutoff: f32,
    /// What the SRBF transmittance's box averages over the convolution optical depth map.
    #[cfg_attr(
        any(feature = "cli", test),
        arg(long, value_enum, default_value = "optical-depth")
    )]
    pub box_average: BoxAverageArg,
    /// Where multiple scattering's shadow paths are marched (the brute-force reference's dense
    /// grid always uses the CPU light sweep).
    #[cfg_attr(
        any(feature = "cli", test),
        arg(long, value_enum, default_value = "auto")
    )]
    pub forward_scattering: ForwardDevice,
    /// Seed of the strand order behind stochastic simplification (κ < 1): each seed draws
    /// other subsets, so an image's error under κ varies with it (docs/BENCHMARKS.md,
    /// "One subset per light", "Stratified subsets").
    #[cfg_attr(any(feature = "cli", test), arg(long, default_value_t = DEFAULT_SIMPLIFICATION_SEED))]
    #[serde(default = "default_simplification_seed")]
    pub simplification_seed: u64,
    /// Spread each SRBF light's visibility over its lobe: the mean over directions of the lobe,
    /// each traced through the light's own map, instead of one filtered visibility per lobe
    /// (docs/BENCHMARKS.md, "Lobe spread").
    #[cfg_attr(any(feature = "cli", test), arg(long))]
    #[serde(default)]
    pub lobe_spread: bool,
    /// Lobe spread: rings of directions.
    #[cfg_attr(any(feature = "cli", test), arg(long, default_value_t = LobeSpread::default().rings))]
    #[serde(default = "spread_defaults::rings")]
    pub lobe_spread_rings: u32,
    /// Lobe spread: directions per ring.
    #[cfg_attr(any(feature = "cli", test), arg(long, default_value_t = LobeSpread::default().per_ring))]
    #[serde(default = "spread_defaults::per_ring")]
    pub lobe_spread_per_ring: u32,
    /// Lobe spread: steps of each direction's march.
    #[cfg_attr(any(feature = "cli", test), arg(long, default_value_t = LobeSpread::default().steps))]
    #[serde(default = "spread_defaults::steps")]
    pub lobe_spread_steps: u32,
    /// Lobe spread: depth marched before the point, in the light map's first layers.
    #[cfg_attr(any(feature = "cli", test), arg(long, default_value_t = LobeSpread::default().reach_layers))]
    #[serde(default = "spread_defaults::reach")]
    pub lobe_spread_reach: f32,
    /// Lobe spread: tilt of the marched lines, times tan γ.
    #[cfg_attr(any(feature = "cli", test), arg(long, default_value_t = LobeSpread::default().cone_scale))]
    #[serde(default = "spread_defaults::cone_scale")]
    pub lobe_spread_cone_scale: f32,
    /// Lobe spread: weigh each direction by the fiber's response to it (the lobe times the
    /// fiber, not the lobe alone).
    #[cfg_attr(any(feature = "cli", test), arg(long))]
    #[serde(default)]
    pub lobe_spread_fiber_weighted: bool,
}

/// Serde defaults of the lobe-spread arguments (reports written before they existed).
mod spread_defaults {
    use super::LobeSpread;
    pub fn rings() -> u32 {
        LobeSpread::default().rings
    }
    pub fn per_ring() -> u32 {
        LobeSpread::default().per_ring
    }
    pub fn steps() -> u32 {
        LobeSpread::default().steps
    }
    pub fn reach() -> f32 {
        LobeSpread::default().reach_layers
    }
    pub fn cone_scale() -> f32 {
        LobeSpread::default().cone_scale
    }
}

impl ViewArgs {
    /// The lobe spread these arguments ask for (None when off).
    pub fn lobe_spread(&self) -> Option<LobeSpread> {
        self.lobe_spread.then_some(LobeSpread {
            rings: self.lobe_spread_rings,
            per_ring: self.lobe_spread_per_ring,
            steps: self.lobe_spread_steps,
            reach_layers: self.lobe_spread_reach,
            cone_scale: self.lobe_spread_cone_scale,
            fiber_weighted: self.lobe_spread_fiber_weighted,
        })
    }
}

fn default_simplification_seed() -> u64 {
    DEFAULT_SIMPLIFICATION_SEED
}

impl Default for ViewArgs {
    fn default() -> Self {
        Self {
            visibility_cutoff: ViewTransparency::DEFAULT_CUTOFF,
            box_average: BoxAverageArg::OpticalDepth,
            forward_scattering: ForwardDevice::Auto,
            simplification_seed: DEFAULT_SIMPLIFICATION_SEED,
            lobe_spread: false,
            lobe_spread_rings: spread_defaults::rings(),
            lobe_spread_per_ring: spread_defaults::per_ring(),
            lobe_spread_steps: spread_defaults::steps(),
            lobe_spread_reach: spread_defaults::reach(),
            lobe_spread_cone_scale: spread_defaults::cone_scale(),
            lobe_spread_fiber_weighted: false,
        }
    }
}

impl Default for LookArgs {
    fn default() -> Self {
        Self {
            transparency: EnvTransparency::Opaque,
            view: ViewArgs::default(),
        }
    }
}

impl LookArgs {
    /// The look these arguments ask for (`shadowed` and no fragment counts).
    pub fn look(&self) -> anyhow::Result<EnvLook> {
        let view = &self.view;
        let transparency = match self.transparency {
            EnvTransparency::Opaque => ViewTransparency::Opaque,
            EnvTransparency::Occupancy => ViewTransparency::Occupancy {
                visibility_cutoff: view.visibility_cutoff,
            },
        };
        transparency
            .check()
            .with_context(|| format!("--visibility-cutoff {}", view.visibility_cutoff))?;
        let lobe_spread = view.lobe_spread();
        if let Some(spread) = &lobe_spread {
            spread.validate().context("--lobe-spread")?;
        }
        let box_average = match view.box_average {
            BoxAverageArg::OpticalDepth => BoxAverage::OpticalDepth,
            BoxAverageArg::Transmittance => BoxAverage::Transmittance,
        };
        Ok(EnvLook {
            shadowed: true,
            transparency,
            box_average,
            count_fragments: false,
            forward_scattering: view.forward_scattering,
            dodm: DodmSettings::default(),
            simplification_seed: view.simplification_seed,
            simplified_lights_before: 0,
            lobe_spread,
        })
    }
}

/// How a frame is rendered besides its scene and lights.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EnvLook {
    /// False sets every single-scattering transmittance to 1 (a diagnostic: what is left is
    /// the lighting and table error alone).
    pub shadowed: bool,
    pub transparency: ViewTransparency,
    pub box_average: BoxAverage,
    /// Count the fragments rasterized and shaded (two extra passes, outside the frame time).
    pub count_fragments: bool,
    pub forward_scattering: ForwardDevice,
    /// Light-pass map resolution and lights per batch.
    pub dodm: DodmSettings,
    /// Seed of the strand order behind κ ([`ViewArgs::simplification_seed`]).
    pub simplification_seed: u64,
    /// A frame rendered in parts (the viewer's batches): the simplified SRBF lights in the
    /// parts before this one, so that each light draws the strands it draws in the whole
    /// frame (`EnvRenderer::render_part`). 0 for a whole frame.
    pub simplified_lights_before: u32,
    /// SRBF visibility spread over the lobe ([`ViewArgs::lobe_spread`]).
    pub lobe_spread: Option<LobeSpread>,
}
