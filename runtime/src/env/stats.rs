//! What a frame cost (time per pass, GPU memory, counts), and the tallies that gather it.

use super::view_visibility::FragmentCounts;
use crate::gpu::{AdapterReport, GpuContext};
use crate::point_frame::PassTiming;

/// What a frame cost: time per pass, memory, counts.
#[derive(Clone, Debug)]
pub struct EnvRenderStats {
    pub adapter: AdapterReport,
    /// Per pass, summed over batches: "upload", "pipelines", "view visibility", "light pass",
    /// "summed-area tables", "view", "multiple grid (CPU)" or "multiple grid (GPU)", "readback".
    pub timings: Vec<PassTiming>,
    /// GPU memory held while one batch renders (the frame's buffers included), per resource.
    pub memory_per_batch: Vec<(String, u64)>,
    pub batches: u32,
    pub lights: u32,
    pub segments: u32,
    /// Segments an SRBF batch's light pass draws (κ of the strands; directional batches draw all).
    pub light_pass_segments: u32,
    pub timing_method: &'static str,
    /// With [`EnvRenderOptions::count_fragments`](super::EnvRenderOptions::count_fragments): the fragments of one batch's view pass.
    pub fragments: Option<FragmentCounts>,
}

/// Totals per pass name over the frame's batches.
pub(super) struct Timings(pub(super) Vec<PassTiming>);

impl Timings {
    pub(super) fn time<T>(&mut self, gpu: &GpuContext, pass: &str, work: impl FnOnce() -> T) -> T {
        let (out, milliseconds, gpu_milliseconds) = gpu.time_passes(work);
        PassTiming {
            pass: pass.to_string(),
            milliseconds,
            gpu_milliseconds,
        }
        .add_to(&mut self.0);
        out
    }
}

/// Counts over the batches, for the stats.
#[derive(Default)]
pub(super) struct BatchUsage {
    pub(super) batches: u32,
    pub(super) table_bytes: u64,
    pub(super) grid_bytes: u64,
    /// The compact sources' visibility along the segments (the layered view's gather).
    pub(super) segment_visibility_bytes: u64,
}
