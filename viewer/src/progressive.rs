//! Progressive refinement: what the worker draws for a request, step by step, and what the window
//! shows of it. An env-lit frame is a sum over its lights: the renderer adds each batch of the
//! full frame into one running sum on the GPU (`submit_frame_into`), which after the last batch
//! is that frame; before it the window shows the running sum scaled by the share of the lights'
//! power it holds (lights are drawn most powerful first). The images stay on the GPU: a step
//! changes only the scale the display pass draws them at.

use crate::frame::{FrameStats, GpuImage, Stage};
use std::sync::Arc;
pub use strandlight_scene::progressive::{Step, plan_steps};

/// The image the window shows of one request's steps, and their stats added up.
#[derive(Default)]
pub struct Accumulator {
    shown: Option<(Arc<GpuImage>, FrameStats)>,
    stats: FrameStats,
    batches_done: usize,
    batches_total: usize,
}

impl Accumulator {
    /// Adds one step: a preview or full frame, or a batch's running sum (every batch so far);
    /// returns the stage the shown image is at.
    pub fn add(&mut self, step: Step, image: GpuImage, stats: FrameStats) -> Stage {
        match step {
            Step::Preview => {
                self.shown = Some((Arc::new(image), stats));
                Stage::Preview
            }
            Step::Full => {
                self.shown = Some((Arc::new(image), stats));
                Stage::Converged
            }
            Step::Batch { power_after, .. } => self.add_batch(image, stats, power_after),
        }
    }

    /// Tells the accumulator how many batches the request has.
    pub fn expect_batches(&mut self, total: usize) {
        self.batches_total = total;
    }

    fn add_batch(&mut self, sum: GpuImage, stats: FrameStats, power_after: f32) -> Stage {
        self.batches_done += 1;
        add_stats(&mut self.stats, stats);
        let scale = if power_after > 0.0 {
            1.0 / power_after
        } else {
            1.0
        };
        let estimate = GpuImage { scale, ..sum };
        self.shown = Some((Arc::new(estimate), self.stats.clone()));
        if self.batches_done >= self.batches_total {
            Stage::Converged
        } else {
            Stage::Refining {
                done: self.batches_done,
                total: self.batches_total,
            }
        }
    }

    /// Whether a step was added (there is an image to show).
    pub fn has_shown(&self) -> bool {
        self.shown.is_some()
    }

    pub fn shown(&self) -> (Arc<GpuImage>, FrameStats) {
        self.shown.clone().expect("a step was added")
    }
}

/// Pass times add up over batches; memory is per batch (the latest); lights and batches count.
fn add_stats(total: &mut FrameStats, batch: FrameStats) {
    for pass in batch.passes {
        pass.add_to(&mut total.passes);
    }
    total.memory = batch.memory;
    total.lights += batch.lights;
    total.batches += batch.batches;
    total.adapter = batch.adapter;
    total.timing_method = batch.timing_method;
}

#[cfg(test)]
mod tests {
    use super::*;
    use strandlight_runtime::gpu::GpuContext;

    fn image(gpu: &GpuContext) -> GpuImage {
        GpuImage {
            buffer: gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: None,
                size: 64,
                usage: wgpu::BufferUsages::STORAGE,
                mapped_at_creation: false,
            }),
            size: [2, 1],
            with_multiple: false,
            scale: 1.0,
            read_back: None,
        }
    }

    #[test]
    fn the_running_sum_is_scaled_by_its_power_share_and_the_last_sum_is_shown_as_it_is() {
        let gpu = GpuContext::new_headless().unwrap_or_else(|e| panic!("{e}"));
        let mut acc = Accumulator::default();
        acc.expect_batches(2);
        assert_eq!(
            acc.add(Step::Preview, image(&gpu), FrameStats::default()),
            Stage::Preview
        );
        assert_eq!(acc.shown().0.scale, 1.0);
        let first = Step::Batch {
            first: 0,
            count: 1,
            power_after: 0.75,
        };
        assert_eq!(
            acc.add(first, image(&gpu), FrameStats::default()),
            Stage::Refining { done: 1, total: 2 }
        );
        assert_eq!(acc.shown().0.scale, 1.0 / 0.75);
        let last = Step::Batch {
            first: 1,
            count: 1,
            power_after: 1.0,
        };
        assert_eq!(
            acc.add(last, image(&gpu), FrameStats::default()),
            Stage::Converged
        );
        assert_eq!(acc.shown().0.scale, 1.0);
    }
}
