//! A rendered frame (or part of one) and what it cost: what every frame function returns, the
//! point-lit and the env-lit one alike.

use crate::frame_settings::{FrameSettings, Lighting};
use crate::image_metrics::Image;
use crate::scene_tables::ScatteringMode;
use strandlight_runtime::env::FragmentCounts;
use strandlight_runtime::env_light::EnvLight;
use strandlight_runtime::point_frame::{PassTiming, RenderStats};

/// A rendered frame (or part of one) and what it cost.
pub struct RenderedFrame {
    pub image: Image,
    /// Frame time without the one-time setup passes.
    pub milliseconds: f64,
    pub passes: Vec<PassTiming>,
    /// GPU memory per resource while it renders (per light batch for an environment), bytes.
    pub memory: Vec<(String, u64)>,
    pub adapter: String,
    pub timing_method: String,
    pub details: FrameDetails,
}

/// A frame (or part of one) submitted into sums on the GPU, not read back, and what it cost.
pub struct SubmittedFrame {
    /// Frame time without the one-time setup passes.
    pub milliseconds: f64,
    pub passes: Vec<PassTiming>,
    /// GPU memory per resource while it renders (per light batch for an environment), bytes.
    pub memory: Vec<(String, u64)>,
    pub adapter: String,
    pub timing_method: String,
    /// Lights drawn: point lights, or SRBF lobes and directional sources.
    pub lights: usize,
    /// The sums' multiple-scattering half holds light (a full-scattering env frame).
    pub with_multiple: bool,
}

/// What only one kind of lighting reports.
pub enum FrameDetails {
    Point(RenderStats),
    Env {
        /// The lights drawn, in the hair's world frame.
        lights: Vec<EnvLight>,
        /// The scattering rendered (dark hair without a multiple table falls back to single).
        mode: ScatteringMode,
        /// With `count_fragments`.
        fragments: Option<FragmentCounts>,
    },
}

impl RenderedFrame {
    /// Lights drawn: point lights, or SRBF lobes and directional sources.
    pub fn light_count(&self, settings: &FrameSettings) -> usize {
        match (&self.details, &settings.lighting) {
            (FrameDetails::Env { lights, .. }, _) => lights.len(),
            (FrameDetails::Point(_), Lighting::Lights(point)) => point.lights.len(),
            (FrameDetails::Point(_), _) => 0,
        }
    }
}
