//! Progressive refinement's plan: a cheap preview, then the full frame light batch by light
//! batch, most powerful first (the desktop viewer and the web page follow the same plan). An
//! env-lit frame is a sum over its lights, so the batches sum to the frame; before the last the
//! running sum is shown scaled by the share of the lights' power it holds.

use crate::frame_render::FramePart;

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

#[cfg(test)]
mod tests {
    use super::*;

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
}
