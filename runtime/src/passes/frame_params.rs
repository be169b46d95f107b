//! What a strand-quad pass needs besides the geometry: the camera and image size, the lights,
//! the Kajiya-Kay constants and the fiber width override, and their uniform as
//! `strand_quads.wgsl` reads it.

use glam::Mat4;

use crate::camera::Camera;
use crate::lights::Light;

/// Kajiya-Kay constants: `L = E·(kd·color·sin(t,l) + ks·max(0, sin(t,l)sin(t,e) − (t·l)(t·e))^p)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KajiyaKay {
    pub kd: f32,
    pub ks: f32,
    pub shininess: f32,
}

impl Default for KajiyaKay {
    fn default() -> Self {
        Self {
            kd: 0.6,
            ks: 0.25,
            shininess: 40.0,
        }
    }
}

/// What the pass needs besides the geometry.
#[derive(Clone, Debug)]
pub struct FrameParams {
    pub camera: Camera,
    pub width: u32,
    pub height: u32,
    pub lights: Vec<Light>,
    pub shading: KajiyaKay,
    /// Every fiber this many pixels wide instead of its projected thickness.
    pub width_override_px: Option<f32>,
}

/// How a pass turns fibers into quads (`strand_quads.wgsl`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum QuadStyle {
    /// A fiber thinner than a pixel is a one-pixel quad faded by its width, sampled at the
    /// pixel's centre: right on average, not per pixel (the light passes, the point-light
    /// techniques, a first preview).
    #[default]
    PixelQuads,
    /// [`QuadStyle::PixelQuads`] with every fiber this many times wider, its optical depth
    /// spread over the width: the light pass's enlargement by 1/κ (Ren 2010 §7).
    Widened(f32),
    /// A fiber thinner than a pixel covers each pixel by its centre line's length in the pixel
    /// times its width (the box filter the path tracer integrates): the env view's passes.
    ExactCoverage,
}

impl QuadStyle {
    fn width_scale(self) -> f32 {
        match self {
            QuadStyle::Widened(scale) => scale,
            QuadStyle::PixelQuads | QuadStyle::ExactCoverage => 1.0,
        }
    }
}

#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct FrameUniform {
    view_proj: [[f32; 4]; 4],
    eye: [f32; 4],
    toward_eye: [f32; 4],
    viewport: [f32; 2],
    focal_px: f32,
    width_override_px: f32,
    kd: f32,
    ks: f32,
    shininess: f32,
    light_count: u32,
    /// Fiber width multiplier (the light pass's stochastic simplification enlarges fibers by
    /// 1/κ); 1 elsewhere.
    width_scale: f32,
    /// 1: thin fibers' coverage is exact per pixel (the env view); 0: one-pixel quads.
    exact_coverage: u32,
    _pad: [f32; 2],
}

impl FrameParams {
    /// World to clip space of the camera at this frame's aspect.
    pub(crate) fn view_proj(&self) -> Mat4 {
        self.camera.view_projection([self.width, self.height])
    }

    pub(crate) fn uniform(&self, style: QuadStyle) -> FrameUniform {
        let aspect = self.width as f32 / self.height as f32;
        let proj = self.camera.projection_matrix(aspect);
        let view_proj: Mat4 = self.view_proj();
        FrameUniform {
            view_proj: view_proj.to_cols_array_2d(),
            eye: self
                .camera
                .eye
                .extend(if self.camera.is_perspective() {
                    1.0
                } else {
                    0.0
                })
                .into(),
            toward_eye: self.camera.toward_eye().extend(0.0).into(),
            viewport: [self.width as f32, self.height as f32],
            focal_px: proj.y_axis.y * self.height as f32 * 0.5,
            width_override_px: self.width_override_px.unwrap_or(0.0),
            kd: self.shading.kd,
            ks: self.shading.ks,
            shininess: self.shading.shininess,
            light_count: self.lights.len() as u32,
            width_scale: style.width_scale(),
            exact_coverage: (style == QuadStyle::ExactCoverage) as u32,
            _pad: [0.0; 2],
        }
    }
}

#[cfg(test)]
mod wgsl_layout {
    use super::*;
    use crate::shader_layout::{assert_same_layout, rust_layout};
    use crate::shaders::Wgsl;

    #[test]
    fn uploaded_structs_are_laid_out_as_the_wgsl_reads_them() {
        assert_same_layout(
            &Wgsl {
                file: "strand_quads.wgsl",
                source: include_str!("strand_quads.wgsl"),
            },
            None,
            "Frame",
            &rust_layout!(FrameUniform {
                view_proj,
                eye,
                toward_eye,
                viewport,
                focal_px,
                width_override_px,
                kd,
                ks,
                shininess,
                light_count,
                width_scale,
                exact_coverage
            }),
        );
    }
}
