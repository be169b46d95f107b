//! Named, timed steps of a long command (`demo`, `compare`), printed as they finish, with a
//! plain line every [`HEARTBEAT`] while one runs: a log (CI, a redirect) shows work going on
//! where a reference takes minutes.

use std::sync::mpsc::{Receiver, RecvTimeoutError, channel};
use std::time::{Duration, Instant};

/// How often a running step says it is still running.
pub const HEARTBEAT: Duration = Duration::from_secs(10);

pub struct Steps {
    /// (name, seconds, note) of every finished step.
    pub done: Vec<(String, f64, String)>,
    start: Instant,
    /// Print to stderr (so `--json` keeps stdout for the JSON).
    quiet_stdout: bool,
    heartbeat: Duration,
    /// "still running" lines printed so far.
    pub heartbeats: usize,
}

impl Steps {
    pub fn new(quiet_stdout: bool) -> Self {
        Self {
            done: Vec::new(),
            start: Instant::now(),
            quiet_stdout,
            heartbeat: HEARTBEAT,
            heartbeats: 0,
        }
    }

    /// The same, saying a running step is still running every `period`.
    pub fn with_heartbeat(quiet_stdout: bool, period: Duration) -> Self {
        Self {
            heartbeat: period,
            ..Self::new(quiet_stdout)
        }
    }

    /// Runs `f` as step `name`; `note` describes its result (e.g. "cached").
    pub fn run<T>(
        &mut self,
        name: &str,
        f: impl FnOnce() -> anyhow::Result<T>,
        note: impl FnOnce(&T) -> String,
    ) -> anyhow::Result<T> {
        let t = Instant::now();
        let (finished, running) = channel::<()>();
        let (period, quiet) = (self.heartbeat, self.quiet_stdout);
        let (value, beats) = std::thread::scope(|scope| {
            let beats = scope.spawn(move || heartbeat(name, period, quiet, &running));
            let value = f();
            drop(finished);
            (value, beats.join().unwrap_or(0))
        });
        self.heartbeats += beats;
        let value = value.map_err(|e| e.context(format!("step `{name}`")))?;
        let seconds = t.elapsed().as_secs_f64();
        let note = note(&value);
        self.say(format!("{name:<18} {seconds:>8.2} s  {note}"));
        self.done.push((name.to_string(), seconds, note));
        Ok(value)
    }

    pub fn say(&self, line: String) {
        say(self.quiet_stdout, &line);
    }

    pub fn total_seconds(&self) -> f64 {
        self.start.elapsed().as_secs_f64()
    }
}

fn say(quiet_stdout: bool, line: &str) {
    if quiet_stdout {
        eprintln!("{line}");
    } else {
        println!("{line}");
    }
}

/// Says `name` is still running every `period` until `finished` hangs up; returns the lines.
fn heartbeat(name: &str, period: Duration, quiet_stdout: bool, finished: &Receiver<()>) -> usize {
    let start = Instant::now();
    let mut lines = 0;
    while let Err(RecvTimeoutError::Timeout) = finished.recv_timeout(period) {
        let seconds = start.elapsed().as_secs_f64();
        say(
            quiet_stdout,
            &format!("{name:<18} {seconds:>8.0} s  … still running"),
        );
        lines += 1;
    }
    lines
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_long_step_says_it_is_running_and_a_short_one_does_not() {
        let mut steps = Steps::with_heartbeat(true, Duration::from_millis(100));
        let value = steps
            .run(
                "slow",
                || {
                    std::thread::sleep(Duration::from_millis(350));
                    Ok(7)
                },
                |v| format!("{v}"),
            )
            .unwrap();
        assert_eq!(value, 7);
        // Ticks at 100, 200 and 300 ms; a loaded machine may drop one, never add one.
        assert!((2..=3).contains(&steps.heartbeats), "{}", steps.heartbeats);
        steps.run("quick", || Ok(()), |_| String::new()).unwrap();
        assert!(steps.heartbeats <= 3);
        let e = steps
            .run(
                "failing",
                || -> anyhow::Result<()> { anyhow::bail!("no") },
                |_| String::new(),
            )
            .unwrap_err();
        assert!(format!("{e:#}").contains("step `failing`: no"), "{e:#}");
    }
}
