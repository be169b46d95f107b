//! Which image error a comparison reports or searches on: relative RMSE in linear radiance (what
//! the method's accuracy targets are stated in) or HDR-FLIP (what a viewer sees).

use crate::hdr_flip::hdr_flip;
use serde::{Deserialize, Serialize};
use strandlight_scene::image_metrics::{CompareError, Image, relative_rmse};

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(any(feature = "cli", test), derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum ErrorMetric {
    /// √(Σ‖a − r‖² / Σ‖r‖²) over the reference's hair pixels.
    RelativeRmse,
    /// HDR-FLIP's error map averaged over the reference's hair pixels.
    HdrFlip,
}

impl ErrorMetric {
    pub fn measure(self, test: &Image, reference: &Image) -> Result<f64, CompareError> {
        match self {
            ErrorMetric::RelativeRmse => relative_rmse(test, reference),
            ErrorMetric::HdrFlip => Ok(hdr_flip(test, reference)?.mean_over_hair),
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            ErrorMetric::RelativeRmse => "relative RMSE",
            ErrorMetric::HdrFlip => "HDR-FLIP",
        }
    }
}
