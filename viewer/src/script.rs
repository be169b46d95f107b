//! Scripted input for `view --script FILE`: a JSON list of steps that drive the real window the
//! way a person would — drags over the image and key presses go in as egui input events, through
//! the same handlers as the mouse and keyboard; `settings` steps do what a panel control does
//! (a JSON merge patch on the frame settings). Waits let the script follow the renderer.
//!
//! ```json
//! [ {"wait": "converged"},
//!   {"drag": [[0.5, 0.5], [0.65, 0.45]]},
//!   {"key": "B"},
//!   {"settings": {"artist": {"r": {"intensity": 0.9}}}},
//!   {"frames": 20},
//!   {"screenshot": "out/view"} ]
//! ```

use anyhow::{Context, bail};
use serde::Deserialize;
use serde_json::Value;
use std::path::{Path, PathBuf};

/// Frames a scripted drag takes from press to release.
const DRAG_FRAMES: usize = 8;

#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum Step {
    /// `converged`: the latest settings rendered in full with their own tables; `tables`: no
    /// bake running.
    Wait(WaitFor),
    /// A primary-button drag between two points given as fractions of the image (orbit).
    Drag([[f32; 2]; 2]),
    /// A secondary-button drag (pan).
    Pan([[f32; 2]; 2]),
    /// Scroll steps over the image (zoom; positive is closer).
    Scroll(f32),
    /// A key press: B (next backdrop), O (readout), S (screenshot), R (reset camera).
    Key(String),
    /// A JSON merge patch (RFC 7396) on the frame settings, as a panel control would change them.
    Settings(Value),
    /// Exposure in stops, or null for automatic.
    Exposure(Option<f32>),
    /// Present this many frames.
    Frames(u64),
    /// Save a screenshot (PNG, EXR, JSON sidecar) of the converged image at this path stem.
    Screenshot(PathBuf),
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum WaitFor {
    Converged,
    Tables,
}

/// What the window does for a script this frame.
#[derive(Clone, Debug, PartialEq)]
pub enum Action {
    /// Pointer at a fraction of the image; `button`: Some((primary?, pressed)) changes a button.
    Pointer {
        at: [f32; 2],
        button: Option<(bool, bool)>,
    },
    Scroll(f32),
    Key(egui::Key),
    Settings(Value),
    Exposure(Option<f32>),
    Screenshot(PathBuf),
    /// Nothing this frame until the condition holds.
    Wait(WaitFor),
}

pub struct Script {
    steps: Vec<Step>,
    next: usize,
    /// Frames into the current step.
    frame: u64,
}

impl Script {
    pub fn read(path: &Path) -> anyhow::Result<Self> {
        let text = std::fs::read_to_string(path)
            .with_context(|| format!("--script {}", path.display()))?;
        let steps: Vec<Step> = serde_json::from_str(&text)
            .with_context(|| format!("--script {}: not a list of steps", path.display()))?;
        for step in &steps {
            if let Step::Key(k) = step {
                key(k).with_context(|| format!("--script {}", path.display()))?;
            }
        }
        Ok(Self {
            steps,
            next: 0,
            frame: 0,
        })
    }

    /// The script of `--screenshot` alone: wait for the first converged image.
    pub fn converged_then_exit() -> Self {
        Self {
            steps: vec![Step::Wait(WaitFor::Converged)],
            next: 0,
            frame: 0,
        }
    }

    pub fn finished(&self) -> bool {
        self.next >= self.steps.len()
    }

    /// Whether the next step waits on the renderer (whose changes wake the window), rather
    /// than acting on the window frame by frame.
    pub fn waiting(&self) -> bool {
        matches!(self.steps.get(self.next), Some(Step::Wait(_)))
    }

    /// How far: "step 3/7".
    pub fn position(&self) -> String {
        format!(
            "step {}/{}",
            self.next.min(self.steps.len()),
            self.steps.len()
        )
    }

    /// This frame's actions; `waiting_done(cond)` tells whether a wait is over.
    pub fn advance(&mut self, waiting_done: &dyn Fn(WaitFor) -> bool) -> Vec<Action> {
        let Some(step) = self.steps.get(self.next).cloned() else {
            return Vec::new();
        };
        let frame = self.frame as usize;
        let (actions, done) = match step {
            Step::Wait(cond) => {
                let done = waiting_done(cond);
                (
                    if done {
                        Vec::new()
                    } else {
                        vec![Action::Wait(cond)]
                    },
                    done,
                )
            }
            Step::Drag([from, to]) => (drag_frame(from, to, true, frame), frame >= DRAG_FRAMES),
            Step::Pan([from, to]) => (drag_frame(from, to, false, frame), frame >= DRAG_FRAMES),
            Step::Scroll(s) => (
                vec![
                    Action::Pointer {
                        at: [0.5, 0.5],
                        button: None,
                    },
                    Action::Scroll(s),
                ],
                true,
            ),
            Step::Key(k) => (vec![Action::Key(key(&k).expect("checked on read"))], true),
            Step::Settings(patch) => (vec![Action::Settings(patch)], true),
            Step::Exposure(e) => (vec![Action::Exposure(e)], true),
            Step::Frames(n) => (Vec::new(), self.frame + 1 >= n),
            Step::Screenshot(path) => (vec![Action::Screenshot(path)], true),
        };
        if done {
            self.next += 1;
            self.frame = 0;
        } else {
            self.frame += 1;
        }
        actions
    }
}

/// Frame `frame` of a drag: press at `from`, move in steps, release at `to`.
fn drag_frame(from: [f32; 2], to: [f32; 2], primary: bool, frame: usize) -> Vec<Action> {
    let t = (frame as f32 / (DRAG_FRAMES - 1) as f32).min(1.0);
    let at = [
        from[0] + (to[0] - from[0]) * t,
        from[1] + (to[1] - from[1]) * t,
    ];
    let button = match frame {
        0 => Some((primary, true)),
        f if f >= DRAG_FRAMES => Some((primary, false)),
        _ => None,
    };
    vec![Action::Pointer { at, button }]
}

fn key(name: &str) -> anyhow::Result<egui::Key> {
    match egui::Key::from_name(name) {
        Some(k) => Ok(k),
        None => bail!("unknown key {name:?} (e.g. B, O, S, R)"),
    }
}

/// RFC 7396: `patch` merged into `target`.
pub fn merge_patch(target: &mut Value, patch: &Value) {
    match (target, patch) {
        (Value::Object(t), Value::Object(p)) => {
            for (k, v) in p {
                if v.is_null() {
                    t.remove(k);
                } else {
                    merge_patch(t.entry(k.clone()).or_insert(Value::Null), v);
                }
            }
        }
        (t, p) => *t = p.clone(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_drag_presses_moves_and_releases_and_waits_hold_the_script() {
        let mut script = Script {
            steps: vec![
                Step::Wait(WaitFor::Converged),
                Step::Drag([[0.0, 0.0], [1.0, 0.5]]),
            ],
            next: 0,
            frame: 0,
        };
        assert_eq!(
            script.advance(&|_| false),
            vec![Action::Wait(WaitFor::Converged)]
        );
        assert_eq!(script.advance(&|_| true), vec![]);
        let frames: Vec<_> = (0..=DRAG_FRAMES)
            .map(|_| script.advance(&|_| true))
            .collect();
        assert_eq!(
            frames[0],
            vec![Action::Pointer {
                at: [0.0, 0.0],
                button: Some((true, true))
            }]
        );
        assert_eq!(
            frames[DRAG_FRAMES],
            vec![Action::Pointer {
                at: [1.0, 0.5],
                button: Some((true, false))
            }]
        );
        assert!(script.finished());
    }

    #[test]
    fn merge_patch_changes_only_what_it_names() {
        let mut v = serde_json::json!({"a": {"b": 1, "c": 2}, "d": 3});
        merge_patch(&mut v, &serde_json::json!({"a": {"b": 5}, "d": null}));
        assert_eq!(v, serde_json::json!({"a": {"b": 5, "c": 2}}));
    }

    #[test]
    fn bad_scripts_are_refused_with_the_file_named() {
        let dir = std::env::temp_dir().join(format!("strandlight-script-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("bad.json");
        std::fs::write(&path, r#"[{"key": "NoSuchKey"}]"#).unwrap();
        let e = Script::read(&path).err().unwrap();
        assert!(format!("{e:#}").contains("bad.json"), "{e:#}");
        std::fs::write(&path, r#"[{"fly": 1}]"#).unwrap();
        let e = Script::read(&path).err().unwrap();
        assert!(format!("{e:#}").contains("bad.json"), "{e:#}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
