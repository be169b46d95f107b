//! Progressive refinement: what the worker draws for a request, step by step, and how the steps
//! add up. An env-lit frame is a sum over its lights, so summing the batches of the full frame
//! gives that frame; before the last batch the window shows the running sum scaled by the share
//! of the lights' power it holds (lights are drawn most powerful first).

use crate::frame::{FrameStats, LinearImage, Stage};
use std::sync::Arc;
use strandlight_scene::frame_render::FramePart;

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Step {
    /// Half size, cheap settings.
    Preview,
    /// Lights `first..first + count` of the full frame; `power_after` is the share of the
    /// frame's light power drawn once this batch is summed (exactly 1 for the last).
    Batch {
        first: usize,
        count: usize,
        power_after: f32,
    },
    /// The whole full-size frame at once (point lights).
    Full,
}

impl Step {
    /// The part of the frame this step renders.
    pub fn part(self) -> FramePart {
        match self {
            Step::Preview => FramePart::Preview,
            Step::Batch { first, count, .. } => FramePart::Lights { first, count },
            Step::Full => FramePart::Whole,
        }
    }
}

/// A preview, then the full frame: in batches of `batch` lights whose powers are `powers`
/// (most powerful first) for an environment, or at once (`None`) for point lights.
pub fn plan_steps(env: Option<(&[f32], usize)>) -> Vec<Step> {
    let mut steps = vec![Step::Preview];
    match env {
        None => steps.push(Step::Full),
        Some((powers, batch)) => {
            let total: f64 = powers.iter().map(|&p| p.max(0.0) as f64).sum();
            let mut done = 0.0;
            let chunks = powers.chunks(batch.max(1)).count();
            for (i, chunk) in powers.chunks(batch.max(1)).enumerate() {
                done += chunk.iter().map(|&p| p.max(0.0) as f64).sum::<f64>();
                let power_after = if i + 1 == chunks || total <= 0.0 {
                    1.0
                } else {
                    (done / total) as f32
                };
                steps.push(Step::Batch {
                    first: i * batch.max(1),
                    count: chunk.len(),
                    power_after,
                });
            }
        }
    }
    steps
}

/// Sums the steps of one request into the image the window shows.
#[derive(Default)]
pub struct Accumulator {
    sum: Option<LinearImage>,
    shown: Option<(Arc<LinearImage>, FrameStats)>,
    stats: FrameStats,
    batches_done: usize,
    batches_total: usize,
}

impl Accumulator {
    /// Adds one step's image; returns the stage the shown image is at.
    pub fn add(&mut self, step: Step, image: LinearImage, stats: FrameStats) -> Stage {
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

    fn add_batch(&mut self, image: LinearImage, stats: FrameStats, power_after: f32) -> Stage {
        let sum = self.sum.get_or_insert_with(|| LinearImage {
            width: image.width,
            height: image.height,
            pixels: vec![[0.0; 4]; image.pixels.len()],
        });
        for (s, p) in sum.pixels.iter_mut().zip(&image.pixels) {
            for c in 0..3 {
                s[c] += p[c];
            }
            // Coverage does not depend on the lights: every batch has the same alpha.
            s[3] = p[3];
        }
        self.batches_done += 1;
        add_stats(&mut self.stats, stats);
        let scale = if power_after > 0.0 {
            1.0 / power_after
        } else {
            1.0
        };
        let estimate = LinearImage {
            width: sum.width,
            height: sum.height,
            pixels: sum
                .pixels
                .iter()
                .map(|p| [p[0] * scale, p[1] * scale, p[2] * scale, p[3]])
                .collect(),
        };
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

    pub fn shown(&self) -> (Arc<LinearImage>, FrameStats) {
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

    fn image(value: f32) -> LinearImage {
        LinearImage {
            width: 2,
            height: 1,
            pixels: vec![[value, 2.0 * value, 0.0, 0.5]; 2],
        }
    }

    #[test]
    fn batches_cover_every_light_once_and_end_at_full_power() {
        let powers = [5.0, 4.0, 3.0, 2.0, 1.0];
        let steps = plan_steps(Some((&powers, 2)));
        assert_eq!(steps[0], Step::Preview);
        let mut covered = Vec::new();
        let mut last = 0.0;
        for step in &steps[1..] {
            let Step::Batch {
                first,
                count,
                power_after,
            } = *step
            else {
                panic!("{step:?}")
            };
            covered.extend(first..first + count);
            assert!(power_after > last);
            last = power_after;
        }
        assert_eq!(covered, vec![0, 1, 2, 3, 4]);
        assert_eq!(last, 1.0);
        assert!(
            matches!(steps[1], Step::Batch { power_after, .. } if (power_after - 0.6).abs() < 1e-6)
        );
        assert_eq!(plan_steps(None), vec![Step::Preview, Step::Full]);
    }

    #[test]
    fn the_running_sum_is_scaled_by_its_power_share_and_the_last_batch_is_exact() {
        let mut acc = Accumulator::default();
        acc.expect_batches(2);
        assert_eq!(
            acc.add(Step::Preview, image(9.0), FrameStats::default()),
            Stage::Preview
        );
        let first = Step::Batch {
            first: 0,
            count: 1,
            power_after: 0.75,
        };
        assert_eq!(
            acc.add(first, image(3.0), FrameStats::default()),
            Stage::Refining { done: 1, total: 2 }
        );
        assert_eq!(acc.shown().0.pixels[0], [4.0, 8.0, 0.0, 0.5]);
        let last = Step::Batch {
            first: 1,
            count: 1,
            power_after: 1.0,
        };
        assert_eq!(
            acc.add(last, image(1.0), FrameStats::default()),
            Stage::Converged
        );
        assert_eq!(acc.shown().0.pixels[1], [4.0, 8.0, 0.0, 0.5]);
    }
}
