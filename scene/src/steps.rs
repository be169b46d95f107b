//! Named, timed steps of a long command (`demo`, `compare`), printed as they finish.

use std::time::Instant;

pub struct Steps {
    /// (name, seconds, note) of every finished step.
    pub done: Vec<(String, f64, String)>,
    start: Instant,
    /// Print to stderr (so `--json` keeps stdout for the JSON).
    quiet_stdout: bool,
}

impl Steps {
    pub fn new(quiet_stdout: bool) -> Self {
        Self {
            done: Vec::new(),
            start: Instant::now(),
            quiet_stdout,
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
        let value = f().map_err(|e| e.context(format!("step `{name}`")))?;
        let seconds = t.elapsed().as_secs_f64();
        let note = note(&value);
        self.say(format!("{name:<18} {seconds:>8.2} s  {note}"));
        self.done.push((name.to_string(), seconds, note));
        Ok(value)
    }

    pub fn say(&self, line: String) {
        if self.quiet_stdout {
            eprintln!("{line}");
        } else {
            println!("{line}");
        }
    }

    pub fn total_seconds(&self) -> f64 {
        self.start.elapsed().as_secs_f64()
    }
}
