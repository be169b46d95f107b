//! The camera a user asks for: projection, up axis and an optional eye, framing the hair.

use anyhow::Context;
use strandlight_runtime::camera::{Camera, UpAxis};
use strandlight_runtime::hair::HairModel;

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[cfg_attr(any(feature = "cli", test), derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum CameraKind {
    #[default]
    Perspective,
    Orthographic,
}

/// The hair file's up axis.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[cfg_attr(any(feature = "cli", test), derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum UpChoice {
    /// Z when the strands hang along −z (Yuksel's .hair files), else Y.
    #[default]
    Auto,
    Y,
    Z,
}

impl UpChoice {
    pub fn axis(self, model: &HairModel) -> UpAxis {
        match self {
            UpChoice::Auto => UpAxis::detect(model),
            UpChoice::Y => UpAxis::Y,
            UpChoice::Z => UpAxis::Z,
        }
    }
}

#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct CameraChoice {
    pub kind: CameraKind,
    pub up: UpChoice,
    /// Looking at the hair's centre from here; None: in front, framing the hair.
    pub eye: Option<[f32; 3]>,
}

impl CameraChoice {
    /// The camera framing `model`'s bounds at this aspect ratio (width / height).
    pub fn camera(&self, model: &HairModel, aspect: f32) -> anyhow::Result<Camera> {
        let up = self.up.axis(model);
        let orthographic = self.kind == CameraKind::Orthographic;
        Ok(match self.eye {
            None => Camera::framing_front(model.bounds(), aspect, orthographic, up),
            Some(eye) => {
                Camera::framing_from_eye(model.bounds(), aspect, orthographic, eye, up.vector())
                    .with_context(|| format!("--eye {},{},{}", eye[0], eye[1], eye[2]))?
            }
        })
    }
}

/// The hair's up axis and the default camera that frames it from the front at `size`.
pub fn front_camera(hair: &HairModel, size: (u32, u32)) -> (UpAxis, Camera) {
    let up = UpAxis::detect(hair);
    let aspect = size.0 as f32 / size.1 as f32;
    (up, Camera::framing_front(hair.bounds(), aspect, false, up))
}
