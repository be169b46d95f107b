//! Which directional-light baseline a comparison races the SRBF frame against: Debevec's median
//! cut over the whole map (as published, and as Ren 2010 compares), or median cut given the
//! same exact compact sources as the reference and the SRBF frame. A sun holding half a map's
//! power, cut into regions each lit from its centroid, keeps plain median cut's error from
//! falling below a few percent (docs/BENCHMARKS.md, quarry with multiple scattering); the
//! second baseline separates that handicap from what the SRBF lobes buy on the rest of the map.

use serde::{Deserialize, Serialize};
use strandlight_precompute::EnvMap;
use strandlight_precompute::compact_sources::SourceOptions;
use strandlight_precompute::env_lights::{
    LightSpec, median_cut_lights, median_cut_lights_with_sources,
};

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
    /// `count` directional lights for `map` (with exact sources: every source and at least one
    /// more, so possibly more than `count`), turned by `rotate_degrees` like every light set.
    pub fn lights(
        self,
        map: &EnvMap,
        count: usize,
        rotate_degrees: f64,
        sources: &SourceOptions,
    ) -> Vec<LightSpec> {
        match self {
            Baseline::MedianCut => median_cut_lights(map, count, rotate_degrees),
            Baseline::MedianCutSources => {
                median_cut_lights_with_sources(map, count, rotate_degrees, sources)
            }
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Baseline::MedianCut => "median cut",
            Baseline::MedianCutSources => "median cut + exact sources",
        }
    }
}
