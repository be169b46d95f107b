//! The camera: a view and an orthographic or perspective projection, with a default that frames
//! a bounding box.

use glam::{Mat4, Vec3};

use crate::hair::Aabb;

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Projection {
    /// Vertical field of view in radians.
    Perspective { fov_y: f32 },
    /// Half the visible height in world units.
    Orthographic { half_height: f32 },
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    pub eye: Vec3,
    pub target: Vec3,
    pub up: Vec3,
    pub projection: Projection,
    pub near: f32,
    pub far: f32,
}

/// The default vertical field of view of [`Camera::framing`], 30°.
pub const DEFAULT_FOV_Y_DEGREES: f32 = 30.0;

impl Camera {
    /// Looks along −z at the box's centre from far enough that its bounding sphere fits the
    /// narrower of the two fields of view.
    pub fn framing(bounds: Aabb, aspect: f32, orthographic: bool) -> Self {
        let center = bounds.center();
        let radius = (bounds.diagonal() * 0.5).max(1e-6);
        let fov_y = DEFAULT_FOV_Y_DEGREES.to_radians();
        // Horizontal half-angle from the vertical one and the aspect ratio.
        let half_x = ((fov_y * 0.5).tan() * aspect).atan();
        let half_min = (fov_y * 0.5).min(half_x);
        let distance = radius / half_min.sin();
        let projection = if orthographic {
            Projection::Orthographic {
                half_height: radius / aspect.min(1.0),
            }
        } else {
            Projection::Perspective { fov_y }
        };
        Self {
            eye: center + Vec3::Z * distance,
            target: center,
            up: Vec3::Y,
            projection,
            near: (distance - radius) * 0.5,
            far: distance + radius * 2.0,
        }
    }

    pub fn view(&self) -> Mat4 {
        glam::camera::rh::view::look_at_mat4(self.eye, self.target, self.up)
    }

    /// wgpu clip space (depth 0..1, y up: the "directx" convention).
    pub fn projection_matrix(&self, aspect: f32) -> Mat4 {
        use glam::camera::rh::proj::directx;
        match self.projection {
            Projection::Perspective { fov_y } => {
                directx::perspective(fov_y, aspect, self.near.max(1e-6), self.far)
            }
            Projection::Orthographic { half_height } => {
                let half_width = half_height * aspect;
                directx::orthographic(
                    -half_width,
                    half_width,
                    -half_height,
                    half_height,
                    self.near,
                    self.far,
                )
            }
        }
    }

    pub fn is_perspective(&self) -> bool {
        matches!(self.projection, Projection::Perspective { .. })
    }

    /// Unit direction from the target toward the eye (the view direction of an orthographic camera).
    pub fn toward_eye(&self) -> Vec3 {
        (self.eye - self.target).normalize()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every corner of the framed box projects inside the image, for both projections.
    #[test]
    fn framing_keeps_the_box_in_view() {
        let bounds = Aabb {
            min: Vec3::new(-1.0, 2.0, -0.5),
            max: Vec3::new(3.0, 5.0, 0.7),
        };
        for aspect in [0.5f32, 1.0, 1.9] {
            for ortho in [false, true] {
                let cam = Camera::framing(bounds, aspect, ortho);
                let vp = cam.projection_matrix(aspect) * cam.view();
                for i in 0..8 {
                    let corner = Vec3::new(
                        if i & 1 == 0 {
                            bounds.min.x
                        } else {
                            bounds.max.x
                        },
                        if i & 2 == 0 {
                            bounds.min.y
                        } else {
                            bounds.max.y
                        },
                        if i & 4 == 0 {
                            bounds.min.z
                        } else {
                            bounds.max.z
                        },
                    );
                    let ndc = vp.project_point3(corner);
                    assert!(
                        ndc.x.abs() <= 1.0 && ndc.y.abs() <= 1.0 && (0.0..=1.0).contains(&ndc.z),
                        "aspect {aspect} ortho {ortho}: corner {corner} → {ndc}"
                    );
                }
            }
        }
    }
}
