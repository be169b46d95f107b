//! Everything besides the scene that changes how an env-lit frame is rendered.

use super::TransmittanceFilter;
use super::view_visibility::ViewTransparency;
use crate::passes::convolution_depth::DodmSettings;
use crate::visibility::LobeVisibility;

/// The default seed of the strand order behind stochastic simplification.
pub const DEFAULT_SIMPLIFICATION_SEED: u64 = 0x5eed;

/// Everything besides the scene that changes how a frame is rendered. Its `Debug` text is part
/// of the cached references' keys (`compare`): options added later print only when set, so
/// the references rendered before them keep their keys.
#[derive(Clone, Copy, PartialEq)]
pub struct EnvRenderOptions {
    /// Light-pass map resolution, first-layer depth and lights per batch.
    pub dodm: DodmSettings,
    /// Stochastic simplification (Ren §7): the light pass of SRBF lights draws this fraction of
    /// the strands (their width enlarged by 1/κ, τ scaled by 1/κ); 1 draws them all. Default
    /// 0.1. Directional lights (a sun taken out of the map) always draw every strand: one sharp
    /// shadow is what the simplification would blur.
    pub kappa: f32,
    /// Seed of the strand order behind κ (`simplification_order`'s scramble).
    pub simplification_seed: u64,
    /// What the view sees of each pixel's fibers: the nearest one (default) or all of them
    /// through the occupancy map (Ren §8).
    pub transparency: ViewTransparency,
    /// Count the fragments rasterized and shaded ([`EnvRenderStats::fragments`](super::EnvRenderStats::fragments); two extra
    /// passes over the hair, outside the timed passes).
    pub count_fragments: bool,
    /// `false`: no self-shadowing (T̃ = 1; for tests and for comparisons).
    pub shadowed: bool,
    /// The averaging box of the effective transmittance (default
    /// [`TransmittanceFilter::MatchedVariance`], the best measured: docs/BENCHMARKS.md).
    pub transmittance_filter: TransmittanceFilter,
    /// View pass only: every fiber this many pixels wide instead of its projected thickness (as
    /// `FrameParams::width_override_px`); the light pass always uses the file's thickness.
    pub width_override_px: Option<f32>,
    /// Where SRBF lobes' visibility comes from: their light maps (Ren's) or the groom's
    /// visibility volume integrated over each lobe.
    pub lobe_visibility: LobeVisibility,
    /// View pass only: `true` (default) covers each pixel by the length of every thin fiber's
    /// centre line inside it times its width, the box filter a path tracer integrates;
    /// `false` draws a thin fiber as a one-pixel quad faded by its width and sampled at the
    /// pixel's centre: right on average, not per pixel, and cheaper (a first preview's).
    pub exact_coverage: bool,
}

impl std::fmt::Debug for EnvRenderOptions {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mut s = f.debug_struct("EnvRenderOptions");
        s.field("dodm", &self.dodm)
            .field("kappa", &self.kappa)
            .field("simplification_seed", &self.simplification_seed)
            .field("transparency", &self.transparency)
            .field("count_fragments", &self.count_fragments)
            .field("shadowed", &self.shadowed)
            .field("transmittance_filter", &self.transmittance_filter)
            .field("width_override_px", &self.width_override_px);
        if self.lobe_visibility != LobeVisibility::LightMaps {
            s.field("lobe_visibility", &self.lobe_visibility);
        }
        if !self.exact_coverage {
            s.field("exact_coverage", &self.exact_coverage);
        }
        s.finish()
    }
}

impl Default for EnvRenderOptions {
    fn default() -> Self {
        Self {
            dodm: DodmSettings::default(),
            kappa: 0.1,
            simplification_seed: DEFAULT_SIMPLIFICATION_SEED,
            transparency: ViewTransparency::Opaque,
            count_fragments: false,
            shadowed: true,
            transmittance_filter: TransmittanceFilter::default(),
            width_override_px: None,
            lobe_visibility: LobeVisibility::LightMaps,
            exact_coverage: true,
        }
    }
}
