//! A rendered frame as the window shows it: how far its refinement is and what it cost (the
//! image is the scene's `Image`, linear pre-multiplied RGBA). The render thread produces it,
//! progressive refinement sums it, the window and screenshots read it.

use strandlight_runtime::point_frame::PassTiming;

/// How far the shown image is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Stage {
    Preview,
    /// `done` of `total` light batches summed.
    Refining {
        done: usize,
        total: usize,
    },
    Converged,
}

/// What the overlay reports of the shown image.
#[derive(Clone, Debug, Default)]
pub struct FrameStats {
    /// Time per pass, summed over the batches so far.
    pub passes: Vec<PassTiming>,
    /// GPU memory per resource while one batch renders, bytes.
    pub memory: Vec<(String, u64)>,
    /// Lights drawn (SRBF lobes and directional sources, or point lights).
    pub lights: usize,
    /// Render calls (light batches) so far.
    pub batches: usize,
    pub adapter: String,
    pub timing_method: String,
}
