//! Which directional-light baseline a comparison races the SRBF frame against: Debevec's median
//! cut over the whole map (as published, and as Ren 2010 compares), or median cut given the
//! same exact compact sources as the reference and the SRBF frame. A sun holding half a map's
//! power, cut into regions each lit from its centroid, keeps plain median cut's error from
//! falling below a few percent (docs/BENCHMARKS.md, quarry with multiple scattering); the
//! second baseline separates that handicap from what the SRBF lobes buy on the rest of the map.

use serde::{Deserialize, Serialize};
use strandlight_scene::env_lighting::EnvLightSet;

#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[cfg_attr(any(feature = "cli", test), derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum Baseline {
    /// Median cut over the whole map (Debevec 2005).
    #[default]
    MedianCut,
    /// The compact sources exactly, median cut over the rest (the count includes them).
    MedianCutSources,
}

impl Baseline {
    /// The light set of a budget of `count` directional lights (with exact sources: every
    /// source and at least one more, so possibly more than `count`).
    pub fn light_set(self, count: usize) -> EnvLightSet {
        EnvLightSet::MedianCut {
            lights: count,
            exact_sources: self == Baseline::MedianCutSources,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Baseline::MedianCut => "median cut",
            Baseline::MedianCutSources => "median cut + exact sources",
        }
    }
}
