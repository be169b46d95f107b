//! How an environment-lit frame looks besides its scene and lights: the view's transparency,
//! where the lobes' visibility comes from, and where multiple scattering's shadow paths are
//! marched.
//! The `cli` feature lets the command line parse these settings directly.

use anyhow::Context;
use strandlight_runtime::env::{DEFAULT_SIMPLIFICATION_SEED, ViewTransparency};
use strandlight_runtime::passes::convolution_depth::DodmSettings;
use strandlight_runtime::visibility::{LobeVisibility, VisibilityVolumeSettings};

/// What the view shows of each pixel's fibers (Ren §8). The default is the layered view: the
/// path tracer's pixel averages every fiber it sees, so the opaque view's nearest (best-lit)
/// fiber reads too bright (docs/history/benchmarks-2026-12-02-to-12-04.md, "The view:
/// layers").
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[cfg_attr(any(feature = "cli", test), derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum EnvTransparency {
    /// The nearest fiber, weighted by its coverage: one shading loop per pixel.
    Opaque,
    /// Every fiber, weighted by coverage × its visibility through the occupancy map, shaded
    /// one by one: as many shading loops per pixel as it has fragments.
    Occupancy,
    /// The occupancy map's weights gathered into 4 layers of equal coverage per pixel, each
    /// shaded once at its fibers' mean depth and tangent.
    #[default]
    Layered,
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

/// Where SRBF lobes' visibility comes from (the CLI's names for [`LobeVisibility`]).
/// The default is the volume: faster on 15 of the 16 map × mode frames and as close to the
/// path-traced truth (docs/BENCHMARKS.md, "Lobe visibility"); light maps stay on the front where
/// they are a little more accurate for their time (quarry, esplanade, venice, piz).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[cfg_attr(any(feature = "cli", test), derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum LobeVisibilityArg {
    /// The volume, or light maps in a frame with a head: the volume's voxels (about 2 units on
    /// straight.hair) cannot resolve the hair lying on the scalp, and the skin under it read
    /// far too bright (venice with the fitted ellipsoid: 0.76 against the truth, light maps
    /// 0.17; docs/history/benchmarks-2026-11-28-to-12-01.md, "A head under the hair").
    #[default]
    Auto,
    /// Ren 2010: each lobe's own convolution optical depth map, read at its centre.
    LightMaps,
    /// The groom's visibility volume (SH of the transmittance, marched once per groom),
    /// integrated over each lobe: no light pass per lobe.
    Volume,
}

impl LobeVisibilityArg {
    /// The visibility of a frame without (`head` false) or with a head.
    pub fn settings(self, head: bool) -> LobeVisibility {
        match self {
            Self::LightMaps => LobeVisibility::LightMaps,
            Self::Auto if head => LobeVisibility::LightMaps,
            Self::Auto | Self::Volume => {
                LobeVisibility::Volume(VisibilityVolumeSettings::default())
            }
        }
    }
}

/// The renderer choices of the env-lit commands.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize, serde::Deserialize)]
#[cfg_attr(any(feature = "cli", test), derive(clap::Args))]
pub struct LookArgs {
    /// Every fiber weighted by its visibility through an occupancy map (Ren §8), gathered into
    /// 4 layers per pixel and shaded once a layer (layered), shaded one by one (occupancy;
    /// costs as many times the view pass as a pixel has fragments), or the nearest fiber of each
    /// pixel (opaque, fastest).
    #[cfg_attr(
        any(feature = "cli", test),
        arg(long, value_enum, default_value = "layered")
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
    /// Where SRBF lobes' visibility comes from: auto (the volume; light maps in a frame with a
    /// head), their light maps (Ren 2010) or the groom's visibility volume integrated over each
    /// lobe (docs/BENCHMARKS.md, "Lobe visibility"; docs/history/benchmarks-2026-11-28-to-12-01.md,
    /// "A head under the hair").
    #[cfg_attr(
        any(feature = "cli", test),
        arg(long, value_enum, default_value = "auto")
    )]
    #[serde(default = "light_maps")]
    pub lobe_visibility: LobeVisibilityArg,
    /// With layered or occupancy: fragments seen less than this fraction are not shaded (early termination).
    #[cfg_attr(any(feature = "cli", test), arg(long, default_value_t = ViewTransparency::DEFAULT_CUTOFF))]
    pub visibility_cutoff: f32,
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
}

/// Reports and screenshots written before the visibility volume existed used light maps.
fn light_maps() -> LobeVisibilityArg {
    LobeVisibilityArg::LightMaps
}

fn default_simplification_seed() -> u64 {
    DEFAULT_SIMPLIFICATION_SEED
}

impl Default for ViewArgs {
    fn default() -> Self {
        Self {
            lobe_visibility: LobeVisibilityArg::default(),
            visibility_cutoff: ViewTransparency::DEFAULT_CUTOFF,
            forward_scattering: ForwardDevice::Auto,
            simplification_seed: DEFAULT_SIMPLIFICATION_SEED,
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
            EnvTransparency::Layered => ViewTransparency::Layered {
                visibility_cutoff: view.visibility_cutoff,
            },
        };
        transparency
            .check()
            .with_context(|| format!("--visibility-cutoff {}", view.visibility_cutoff))?;
        Ok(EnvLook {
            shadowed: true,
            transparency,
            count_fragments: false,
            forward_scattering: view.forward_scattering,
            dodm: DodmSettings::default(),
            simplification_seed: view.simplification_seed,
            simplified_lights_before: 0,
            lobe_visibility: view.lobe_visibility.settings(false),
            light_maps_under_a_head: view.lobe_visibility == LobeVisibilityArg::Auto,
            exact_coverage: true,
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
    /// Where SRBF lobes' visibility comes from ([`ViewArgs::lobe_visibility`]) without a head.
    pub lobe_visibility: LobeVisibility,
    /// A frame with a head uses light maps instead ([`LobeVisibilityArg::Auto`]).
    pub light_maps_under_a_head: bool,
    /// Each pixel covered exactly by its thin fibers (default), or by one-pixel quads faded
    /// by their width (a preview's: [`strandlight_runtime::env::EnvRenderOptions::exact_coverage`]).
    pub exact_coverage: bool,
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        look: LookArgs,
    }

    #[test]
    fn the_volume_is_the_default_and_light_maps_are_one_flag_away() {
        let default = Cli::parse_from(["x"]).look.look().unwrap();
        assert_eq!(
            default.lobe_visibility,
            LobeVisibility::Volume(VisibilityVolumeSettings::default())
        );
        let maps = Cli::parse_from(["x", "--lobe-visibility", "light-maps"])
            .look
            .look()
            .unwrap();
        assert_eq!(maps.lobe_visibility, LobeVisibility::LightMaps);
        let e = Cli::try_parse_from(["x", "--lobe-visibility", "cone"])
            .err()
            .expect("an unknown value is refused");
        assert_eq!(e.kind(), clap::error::ErrorKind::InvalidValue, "{e}");
    }

    #[test]
    fn settings_saved_before_the_volume_read_back_as_light_maps() {
        let mut saved = serde_json::to_value(ViewArgs::default()).unwrap();
        saved.as_object_mut().unwrap().remove("lobe_visibility");
        let old: ViewArgs = serde_json::from_value(saved).unwrap();
        assert_eq!(old.lobe_visibility, LobeVisibilityArg::LightMaps);
        assert_eq!(ViewArgs::default().lobe_visibility, LobeVisibilityArg::Auto);
    }
}
