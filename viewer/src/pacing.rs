//! When the window draws its next frame. Input, a script's step or a new picture are drawn at
//! once (at most [`BUSY_FRAME`] apart); while only a refinement's progress moves, frames come
//! at the progress pace, which keeps the window's own frames to a twentieth of the time. On a
//! software adapter the window draws on the cores the worker renders on: at 800×600 on
//! lavapipe a window frame cost 36 ms (median), 2.9 s of a 15.1 s convergence at one frame
//! every 250 ms (docs/BENCHMARKS.md, "The viewer's cached convergence").

use std::time::{Duration, Instant};

/// Frame interval while something changes (input, a new picture, a script's step).
pub const BUSY_FRAME: Duration = Duration::from_millis(33);
/// The progress pace's bounds: a GPU's cheap frames still show progress four times a second,
/// and a slow window still shows it every second (the viewer test allows 1.5 s between frames
/// during a bake).
pub const PROGRESS_FRAME_MIN: Duration = Duration::from_millis(250);
pub const PROGRESS_FRAME_MAX: Duration = Duration::from_millis(1000);
/// A window frame may take this share of the time while only progress moves.
const PROGRESS_SHARE: f64 = 0.05;
/// Weight of the latest frame in the running frame cost.
const COST_WEIGHT: f64 = 0.25;

#[derive(Debug)]
pub struct FramePacing {
    last_frame: Instant,
    /// Running mean of what a window frame costs (None before the first).
    frame_cost: Option<Duration>,
}

impl Default for FramePacing {
    fn default() -> Self {
        Self {
            last_frame: Instant::now(),
            frame_cost: None,
        }
    }
}

impl FramePacing {
    /// A frame starts now; pass the instant to [`Self::frame_ended`].
    pub fn frame_started(&mut self) -> Instant {
        self.last_frame = Instant::now();
        self.last_frame
    }

    pub fn frame_ended(&mut self, started: Instant) {
        self.add_cost(started.elapsed());
    }

    fn add_cost(&mut self, cost: Duration) {
        self.frame_cost = Some(match self.frame_cost {
            None => cost,
            Some(mean) => mean.mul_f64(1.0 - COST_WEIGHT) + cost.mul_f64(COST_WEIGHT),
        });
    }

    /// Between frames while only progress moves.
    pub fn progress_interval(&self) -> Duration {
        let cost = self.frame_cost.unwrap_or_default();
        cost.mul_f64(1.0 / PROGRESS_SHARE)
            .clamp(PROGRESS_FRAME_MIN, PROGRESS_FRAME_MAX)
    }

    /// When the next frame is due: soon while something `changing` waits to be shown, else at
    /// the progress pace.
    pub fn next_frame(&self, changing: bool) -> Instant {
        let interval = match changing {
            true => BUSY_FRAME,
            false => self.progress_interval(),
        };
        self.last_frame + interval
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn after(costs_ms: &[u64]) -> Duration {
        let mut pacing = FramePacing::default();
        for &ms in costs_ms {
            pacing.add_cost(Duration::from_millis(ms));
        }
        pacing.progress_interval()
    }

    #[test]
    fn progress_frames_take_a_twentieth_of_the_time_within_bounds() {
        assert_eq!(after(&[]), PROGRESS_FRAME_MIN);
        assert_eq!(after(&[2, 2, 2]), PROGRESS_FRAME_MIN);
        assert_eq!(after(&[36]), Duration::from_millis(720));
        assert_eq!(after(&[200]), PROGRESS_FRAME_MAX);
        // One slow frame (a resize, a new texture) moves the pace a quarter of the way.
        assert_eq!(after(&[20, 100]), Duration::from_millis(800));
    }

    #[test]
    fn something_changing_is_drawn_at_once() {
        let mut pacing = FramePacing::default();
        let start = pacing.frame_started();
        pacing.add_cost(Duration::from_millis(40));
        assert_eq!(pacing.next_frame(true), start + BUSY_FRAME);
        assert_eq!(pacing.next_frame(false), start + Duration::from_millis(800));
    }
}
