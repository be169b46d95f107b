//! The camera: a view and an orthographic or perspective projection, with defaults that frame a
//! bounding box from the front, whichever way the file's "up" points.
//!
//! Hair files disagree on their up axis: Cem Yuksel's `.hair` models (straight.hair, ...) are
//! Z-up, TressFX and most game assets Y-up. [`UpAxis::detect`] guesses it from gravity: strands
//! hang from their roots, so the mean root→tip vector points down. The "front" (the side the
//! face is on) is +z for Y-up files (the OpenGL convention, TressFX) and +y for Z-up files:
//! Yuksel's models face +y (straight.hair's face opening and hairline are on the +y side; seen
//! from −y it shows the back of the head). So +x is to the right of the picture for Y-up files
//! and to the left for Z-up ones (the model's own left and right).

use glam::{Mat4, Vec3};

use crate::hair::{Aabb, HairModel};

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

/// The widest vertical field of view [`Camera::framing_from_eye`] opens to fit the hair, 120°.
pub const MAX_FOV_Y_DEGREES: f32 = 120.0;

/// Which world axis points up in a hair file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UpAxis {
    Y,
    Z,
}

impl UpAxis {
    pub fn vector(self) -> Vec3 {
        match self {
            UpAxis::Y => Vec3::Y,
            UpAxis::Z => Vec3::Z,
        }
    }

    /// Unit direction from the hair toward a camera that sees it from the front.
    pub fn toward_front(self) -> Vec3 {
        match self {
            UpAxis::Y => Vec3::Z,
            UpAxis::Z => Vec3::Y,
        }
    }

    /// Gravity heuristic: Z when the summed root→tip vector points more along −z than along −y,
    /// Y otherwise (also for hair that does not hang, e.g. strands standing up or straight out).
    pub fn detect(model: &HairModel) -> Self {
        let hang: Vec3 = model
            .strands()
            .map(|s| s[s.len() - 1] - s[0])
            .fold(Vec3::ZERO, |a, b| a + b);
        if -hang.z > -hang.y && hang.z < 0.0 {
            UpAxis::Z
        } else {
            UpAxis::Y
        }
    }
}

/// The eye lies inside the bounding sphere of what it should frame.
#[derive(Debug, thiserror::Error, PartialEq)]
#[error(
    "camera eye {eye} is {distance} from the hair's centre {center}, inside its bounding sphere (radius {radius}); place it farther away"
)]
pub struct EyeInsideBounds {
    pub eye: Vec3,
    pub center: Vec3,
    pub distance: f32,
    pub radius: f32,
}

/// `up`, or another axis when `up` is (nearly) parallel to the view direction, where look-at
/// would be undefined.
fn usable_up(up: Vec3, toward_eye: Vec3) -> Vec3 {
    let up = up.normalize_or(Vec3::Y);
    if up.dot(toward_eye).abs() < 0.999 {
        return up;
    }
    [Vec3::Y, Vec3::Z, Vec3::X]
        .into_iter()
        .find(|a| a.dot(toward_eye).abs() < 0.9)
        .unwrap_or(Vec3::X)
}

/// Vertical half-angle whose narrower field (vertical or horizontal at `aspect`) is
/// `half_min`.
fn fov_y_for_narrow_half_angle(half_min: f32, aspect: f32) -> f32 {
    if aspect >= 1.0 {
        2.0 * half_min
    } else {
        2.0 * (half_min.tan() / aspect).atan()
    }
}

impl Camera {
    /// Looks along −z (Y up) at the box's centre from far enough that its bounding sphere fits
    /// the narrower of the two fields of view.
    pub fn framing(bounds: Aabb, aspect: f32, orthographic: bool) -> Self {
        Self::framing_along(bounds, aspect, orthographic, Vec3::Z, Vec3::Y)
    }

    /// Frames the box from the front for the given up axis (see [`UpAxis::toward_front`]).
    pub fn framing_front(bounds: Aabb, aspect: f32, orthographic: bool, up: UpAxis) -> Self {
        Self::framing_along(bounds, aspect, orthographic, up.toward_front(), up.vector())
    }

    /// Looks at the box's centre from direction `toward_eye` (need not be normalised), `up`
    /// upward in the picture, at [`DEFAULT_FOV_Y_DEGREES`] and at the distance where the
    /// bounding sphere just fits the narrower field of view.
    pub fn framing_along(
        bounds: Aabb,
        aspect: f32,
        orthographic: bool,
        toward_eye: Vec3,
        up: Vec3,
    ) -> Self {
        let toward_eye = toward_eye.normalize_or(Vec3::Z);
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
            eye: center + toward_eye * distance,
            target: center,
            up: usable_up(up, toward_eye),
            projection,
            near: (distance - radius) * 0.5,
            far: distance + radius * 2.0,
        }
    }

    /// A camera at `eye` looking at the box's centre; the perspective field of view opens just
    /// enough for the bounding sphere (up to [`MAX_FOV_Y_DEGREES`], beyond which the hair is
    /// cropped), the orthographic one as in [`Self::framing_along`].
    pub fn framing_from_eye(
        bounds: Aabb,
        aspect: f32,
        orthographic: bool,
        eye: impl Into<Vec3>,
        up: impl Into<Vec3>,
    ) -> Result<Self, EyeInsideBounds> {
        let (eye, up) = (eye.into(), up.into());
        let center = bounds.center();
        let radius = (bounds.diagonal() * 0.5).max(1e-6);
        let distance = eye.distance(center);
        // Written so that a NaN distance (a NaN eye) is refused too.
        if distance.is_nan() || distance <= radius * 1.0001 {
            return Err(EyeInsideBounds {
                eye,
                center,
                distance,
                radius,
            });
        }
        let toward_eye = (eye - center) / distance;
        let half_min = (radius / distance).asin();
        let fov_y =
            fov_y_for_narrow_half_angle(half_min, aspect).min(MAX_FOV_Y_DEGREES.to_radians());
        let projection = if orthographic {
            Projection::Orthographic {
                half_height: radius / aspect.min(1.0),
            }
        } else {
            Projection::Perspective { fov_y }
        };
        Ok(Self {
            eye,
            target: center,
            up: usable_up(up, toward_eye),
            projection,
            near: (distance - radius) * 0.5,
            far: distance + radius * 2.0,
        })
    }

    pub fn view(&self) -> Mat4 {
        glam::camera::rh::view::look_at_mat4(self.eye, self.target, self.up)
    }

    /// World to clip space for a `[width, height]` image: what every view pass draws with, and
    /// what a host that shares the hair's depth buffer projects its own scene with.
    pub fn view_projection(&self, [width, height]: [u32; 2]) -> Mat4 {
        self.projection_matrix(width as f32 / height as f32) * self.view()
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

    /// The depth-buffer value (wgpu's 0..1) of a point `distance` along the view axis.
    pub fn depth_buffer_value(&self, distance: f32) -> f32 {
        let (near, far) = (self.near, self.far);
        if self.is_perspective() {
            far * (distance - near) / (distance * (far - near))
        } else {
            (distance - near) / (far - near)
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

/// The orthographic camera of a directional light (`toward_light` points at the light) that
/// just covers `bounds`.
pub fn light_camera(toward_light: Vec3, bounds: Aabb) -> Camera {
    let center = bounds.center();
    let radius = (bounds.diagonal() * 0.5).max(1e-6);
    let dir = toward_light.normalize();
    let up = if dir.y.abs() > 0.99 { Vec3::Z } else { Vec3::Y };
    Camera {
        eye: center + dir * (2.0 * radius),
        target: center,
        up,
        projection: Projection::Orthographic {
            half_height: radius,
        },
        near: radius * 0.5,
        far: radius * 3.5,
    }
}

/// What a directional light's map must hold: the hair's points, and their box. A fitted map's
/// square holds the points' projection across the light ([`Self::light_camera`]) rather than the
/// box's bounding sphere ([`light_camera`]): on straight.hair it has 1.4–2× more texels across
/// the hair per side (median 1.53× over directions), so a sun's sharp shadow gets that much finer
/// for the same map (docs/history/benchmarks-2026-12-02-to-12-04.md, "Compact sources' maps
/// fitted to the hair").
#[derive(Clone, Debug)]
pub struct LightFootprint {
    pub bounds: Aabb,
    points: std::sync::Arc<[Vec3]>,
}

/// Room left around the points' projection, as a fraction of the bounding sphere's radius:
/// fibers are drawn at their width and at least a texel wide around their centre lines, and a
/// source's disc filter reads a few texels past them.
const FOOTPRINT_MARGIN: f32 = 0.02;

impl LightFootprint {
    pub fn of(model: &HairModel) -> Self {
        Self::new(model.bounds(), model.points().into())
    }

    pub fn new(bounds: Aabb, points: std::sync::Arc<[Vec3]>) -> Self {
        Self { bounds, points }
    }

    /// The orthographic camera toward `toward_light` whose square just holds every point (with
    /// `FOOTPRINT_MARGIN`); its depth range is [`light_camera`]'s, which holds the box.
    pub fn light_camera(&self, toward_light: Vec3) -> Camera {
        let sphere = light_camera(toward_light, self.bounds);
        let Some((lo, hi)) = self.projected_extent(&sphere) else {
            return sphere;
        };
        let Projection::Orthographic {
            half_height: radius,
        } = sphere.projection
        else {
            return sphere;
        };
        let half = 0.5 * (hi - lo).max_element() + FOOTPRINT_MARGIN * radius;
        if !(half.is_finite() && half < radius) {
            return sphere;
        }
        let centre = 0.5 * (lo + hi);
        let shift = sphere
            .view()
            .inverse()
            .transform_vector3(centre.extend(0.0));
        Camera {
            eye: sphere.eye + shift,
            target: sphere.target + shift,
            projection: Projection::Orthographic { half_height: half },
            ..sphere
        }
    }

    /// The points' least and greatest (x, y) in `camera`'s view space (None without points).
    fn projected_extent(&self, camera: &Camera) -> Option<(glam::Vec2, glam::Vec2)> {
        use rayon::prelude::*;
        let view = camera.view();
        let (x, y) = (view.row(0).truncate(), view.row(1).truncate());
        let empty = || (glam::Vec2::INFINITY, glam::Vec2::NEG_INFINITY);
        let (lo, hi) = self
            .points
            .par_chunks(8192)
            .map(|chunk| {
                chunk.iter().fold(empty(), |(lo, hi), &p| {
                    let q = glam::Vec2::new(x.dot(p), y.dot(p));
                    (lo.min(q), hi.max(q))
                })
            })
            .reduce(empty, |(a, b), (c, d)| (a.min(c), b.max(d)));
        // The view's translation moves both ends alike; it cancels in the extent but not the centre.
        let t = glam::Vec2::new(view.w_axis.x, view.w_axis.y);
        (lo.is_finite() && hi.is_finite()).then_some((lo + t, hi + t))
    }
}

/// How a batch's directional maps are framed: around the box's bounding sphere, or fitted to
/// the hair's points. Compact sources are fitted: their shadows are sharp at fiber scale, and
/// texels are what they lack. SRBF lobes and region lights keep the sphere: their shadows are
/// box-filtered over many texels, whose room past the hair's edge the sphere leaves (fitted
/// lobes moved light maps by −0.002 on quarry to +0.023 on piz against the truth).
#[derive(Clone, Copy, Debug)]
pub enum LightFraming<'a> {
    Sphere(Aabb),
    Fitted(&'a LightFootprint),
}

impl LightFraming<'_> {
    pub fn light_camera(&self, toward_light: Vec3) -> Camera {
        match self {
            LightFraming::Sphere(bounds) => light_camera(toward_light, *bounds),
            LightFraming::Fitted(footprint) => footprint.light_camera(toward_light),
        }
    }
}

/// A point or spot light inside (or too close to) the hair's bounding box: no single
/// perspective shadow map sees all of the hair from there.
#[derive(Debug, thiserror::Error, PartialEq)]
#[error(
    "light at {position} sees the hair's bounding box ({min} to {max}) over {cone_degrees:.0}° or from inside it; a single perspective shadow map covers at most {MAX_LIGHT_CONE_DEGREES}° (the renderer then uses a cube of six maps, `ShadowLayout::Cube`)"
)]
pub struct LightInsideHair {
    pub position: Vec3,
    pub min: Vec3,
    pub max: Vec3,
    /// The full cone angle the box needs from the light (NaN where a corner lies behind it).
    pub cone_degrees: f32,
}

/// The widest cone a point light's single shadow map covers.
pub const MAX_LIGHT_CONE_DEGREES: f32 = 150.0;

/// The perspective camera of a point or spot light at `position`: one frustum aimed at the
/// box's centre whose cone just holds its eight corners (so the whole box, which is their convex
/// hull). A light that lights a groom from outside needs only this frustum, with all of its
/// texels on the hair; where it cannot hold the box, [`crate::shadow_layout::ShadowLayout`]
/// falls back to a cube of six.
pub fn point_light_camera(position: Vec3, bounds: Aabb) -> Result<Camera, LightInsideHair> {
    let refuse = |cone_degrees| LightInsideHair {
        position,
        min: bounds.min,
        max: bounds.max,
        cone_degrees,
    };
    let axis = (bounds.center() - position).normalize_or_zero();
    if !position.is_finite() || axis == Vec3::ZERO {
        return Err(refuse(f32::NAN));
    }
    let mut nearest = f32::INFINITY;
    let mut farthest = 0.0f32;
    let mut half_angle = 0.0f32;
    for corner in bounds.corners() {
        let to_corner = corner - position;
        let depth = to_corner.dot(axis);
        if !(depth > 0.0) {
            return Err(refuse(f32::NAN));
        }
        nearest = nearest.min(depth);
        farthest = farthest.max(depth);
        half_angle = half_angle.max(to_corner.angle_between(axis));
    }
    // A square frustum holds the cone of its half-width.
    let cone_degrees = 2.0 * half_angle.to_degrees();
    if !(cone_degrees <= MAX_LIGHT_CONE_DEGREES) {
        return Err(refuse(cone_degrees));
    }
    let up = if axis.y.abs() > 0.99 {
        Vec3::Z
    } else {
        Vec3::Y
    };
    Ok(Camera {
        eye: position,
        target: bounds.center(),
        up,
        projection: Projection::Perspective {
            fov_y: 2.0 * half_angle * 1.01,
        },
        // Margins keep the nearest and farthest fibers off the clip planes.
        near: nearest * 0.95,
        far: farthest * 1.05,
    })
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

    fn corners(b: Aabb) -> impl Iterator<Item = Vec3> {
        (0..8).map(move |i| {
            Vec3::new(
                if i & 1 == 0 { b.min.x } else { b.max.x },
                if i & 2 == 0 { b.min.y } else { b.max.y },
                if i & 4 == 0 { b.min.z } else { b.max.z },
            )
        })
    }

    /// Camera-space (right, up, forward) coordinates from a basis built by hand with cross
    /// products, independent of glam's look-at and projection matrices.
    fn camera_space(cam: &Camera, p: Vec3) -> Vec3 {
        let forward = (cam.target - cam.eye).normalize();
        let right = forward.cross(cam.up).normalize();
        let up = right.cross(forward);
        let d = p - cam.eye;
        Vec3::new(d.dot(right), d.dot(up), d.dot(forward))
    }

    /// Every corner lies inside the view frustum, checked in camera space by hand: the slopes
    /// x/z and y/z within tan of the half-angles (perspective) or |x|, |y| within the half
    /// extents (orthographic), and depth between near and far.
    fn assert_in_view(cam: &Camera, bounds: Aabb, aspect: f32, what: &str) -> f32 {
        let mut widest = 0.0f32;
        for corner in corners(bounds) {
            let c = camera_space(cam, corner);
            assert!(
                c.z > cam.near && c.z < cam.far,
                "{what}: {corner} depth {} outside {}..{}",
                c.z,
                cam.near,
                cam.far
            );
            let (sx, sy) = match cam.projection {
                Projection::Perspective { fov_y } => {
                    let t = (fov_y * 0.5).tan();
                    (c.x / c.z / (t * aspect), c.y / c.z / t)
                }
                Projection::Orthographic { half_height } => {
                    (c.x / (half_height * aspect), c.y / half_height)
                }
            };
            assert!(
                sx.abs() <= 1.0 && sy.abs() <= 1.0,
                "{what}: {corner} at screen ({sx}, {sy})"
            );
            widest = widest.max(sx.abs()).max(sy.abs());
        }
        widest
    }

    #[test]
    fn front_framing_keeps_the_box_in_view_and_is_tight() {
        let bounds = Aabb {
            min: Vec3::new(-1.0, 2.0, -0.5),
            max: Vec3::new(3.0, 5.0, 0.7),
        };
        let radius = bounds.diagonal() * 0.5;
        for up in [UpAxis::Y, UpAxis::Z] {
            for aspect in [0.5f32, 656.0 / 861.0, 1.0, 1.9] {
                for ortho in [false, true] {
                    let cam = Camera::framing_front(bounds, aspect, ortho, up);
                    let what = format!("{up:?} aspect {aspect} ortho {ortho}");
                    let widest = assert_in_view(&cam, bounds, aspect, &what);
                    // Tightness: the bounding sphere seen from the eye spans exactly the
                    // narrower half-field, tan(half_y)·min(1, aspect) as a slope.
                    if let Projection::Perspective { fov_y } = cam.projection {
                        let sphere_half = (radius / cam.eye.distance(bounds.center())).asin();
                        let narrow_half = ((fov_y * 0.5).tan() * aspect.min(1.0)).atan();
                        assert!(
                            (sphere_half - narrow_half).abs() < 1e-5,
                            "{what}: sphere {sphere_half} vs field {narrow_half}"
                        );
                    }
                    eprintln!("{what}: widest corner at {widest:.3} of the half-screen");
                    assert!(
                        widest > 0.3,
                        "{what}: the box is framed too loosely ({widest})"
                    );
                }
            }
        }
    }

    /// The front view of a Z-up file: +z up in the picture, eye on +y, so +x to the left;
    /// checked through glam's matrices (NDC) and the hand-built basis alike.
    #[test]
    fn z_up_front_view_is_upright() {
        let bounds = Aabb {
            min: Vec3::splat(-1.0),
            max: Vec3::splat(1.0),
        };
        let cam = Camera::framing_front(bounds, 1.0, false, UpAxis::Z);
        assert!(cam.eye.y > 1.0 && cam.eye.x.abs() < 1e-6 && cam.eye.z.abs() < 1e-6);
        let vp = cam.projection_matrix(1.0) * cam.view();
        let top = vp.project_point3(Vec3::new(0.0, 0.0, 0.9));
        let plus_x = vp.project_point3(Vec3::new(0.9, 0.0, 0.0));
        assert!(
            top.y > 0.1 && top.x.abs() < 1e-5,
            "top of a Z-up box at NDC {top}"
        );
        assert!(
            plus_x.x < -0.1 && plus_x.y.abs() < 1e-5,
            "+x of a Z-up box at NDC {plus_x}"
        );
        let by_hand = camera_space(&cam, Vec3::new(0.9, 0.0, 0.9));
        assert!(by_hand.x < 0.0 && by_hand.y > 0.0);
        // Y-up: +y up, eye on +z, +x to the right.
        let cam = Camera::framing_front(bounds, 1.0, false, UpAxis::Y);
        let vp = cam.projection_matrix(1.0) * cam.view();
        let top = vp.project_point3(Vec3::new(0.0, 0.9, 0.0));
        assert!(
            top.y > 0.1 && cam.eye.z > 1.0,
            "top of a Y-up box at NDC {top}"
        );
        assert!(vp.project_point3(Vec3::new(0.9, 0.0, 0.0)).x > 0.1);
    }

    #[test]
    fn eye_placement_frames_the_box_or_refuses_an_eye_inside_it() {
        let bounds = Aabb {
            min: Vec3::new(-1.0, -2.0, 0.0),
            max: Vec3::new(1.0, 2.0, 3.0),
        };
        for eye in [
            Vec3::new(0.0, -10.0, 2.0),
            Vec3::new(7.0, 3.0, 8.0),
            Vec3::new(0.0, 0.0, 9.0),
        ] {
            for ortho in [false, true] {
                let cam =
                    Camera::framing_from_eye(bounds, 656.0 / 861.0, ortho, eye, Vec3::Z).unwrap();
                assert_eq!(cam.eye, eye);
                assert_in_view(
                    &cam,
                    bounds,
                    656.0 / 861.0,
                    &format!("eye {eye} ortho {ortho}"),
                );
            }
        }
        let inside =
            Camera::framing_from_eye(bounds, 1.0, false, Vec3::new(0.0, 0.0, 1.0), Vec3::Z);
        assert!(matches!(inside, Err(EyeInsideBounds { .. })));
        let nan = Camera::framing_from_eye(bounds, 1.0, false, Vec3::NAN, Vec3::Z);
        assert!(nan.is_err(), "a NaN eye must be refused");
    }

    #[test]
    fn a_point_light_camera_holds_the_box_or_refuses_a_light_beside_it() {
        let bounds = Aabb {
            min: Vec3::new(-1.0, -2.0, 0.0),
            max: Vec3::new(1.0, 2.0, 3.0),
        };
        // Far away, near a face (cone ≈ 112°), and along the y axis (another up).
        for light in [
            Vec3::new(0.0, -40.0, 2.0),
            Vec3::new(0.0, 0.0, 4.5),
            Vec3::new(0.0, 12.0, 1.5),
        ] {
            let cam = point_light_camera(light, bounds).unwrap();
            let widest = assert_in_view(&cam, bounds, 1.0, &format!("light {light}"));
            assert!(
                widest > 0.6,
                "light {light}: the box fills {widest} of the map"
            );
        }
        for light in [
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(0.0, 0.0, 3.05),
            Vec3::NAN,
        ] {
            let refused = point_light_camera(light, bounds);
            assert!(refused.is_err(), "light {light}: {refused:?}");
        }
    }

    fn hanging(direction: Vec3) -> HairModel {
        let mut points = Vec::new();
        let mut offsets = vec![0u32];
        for s in 0..5 {
            let root = Vec3::new(s as f32 * 0.1, 0.3, 0.2);
            for k in 0..4 {
                // Mostly along `direction`, with a sideways wiggle to make it less trivial.
                points.push(root + direction * k as f32 + Vec3::X * 0.3 * (k % 2) as f32);
            }
            offsets.push(points.len() as u32);
        }
        HairModel::new(points, offsets, None, None, None).unwrap()
    }

    #[test]
    fn up_axis_follows_gravity() {
        assert_eq!(
            UpAxis::detect(&hanging(Vec3::new(0.1, 0.2, -1.0))),
            UpAxis::Z
        );
        assert_eq!(
            UpAxis::detect(&hanging(Vec3::new(0.1, -1.0, 0.2))),
            UpAxis::Y
        );
        assert_eq!(
            UpAxis::detect(&hanging(Vec3::new(0.0, -0.5, -0.4))),
            UpAxis::Y
        );
        // Strands standing up give no evidence: the Y-up default.
        assert_eq!(
            UpAxis::detect(&hanging(Vec3::new(0.0, 0.0, 1.0))),
            UpAxis::Y
        );
    }

    /// The fitted light camera holds every point (checked in a camera basis built by hand),
    /// with its margin, inside a square no larger than the bounding sphere's; a long thin groom
    /// seen end-on fills its square, where the sphere's leaves most of it empty.
    #[test]
    fn a_fitted_light_camera_holds_every_point_and_is_tight_around_a_long_groom_seen_end_on() {
        let points: Vec<Vec3> = (0..200)
            .map(|i| {
                let t = i as f32 / 199.0;
                Vec3::new(0.2 * (7.0 * t).sin(), 10.0 * t - 3.0, 0.5 * (3.0 * t).cos())
            })
            .collect();
        let footprint = LightFootprint::new(Aabb::from_points(&points), points.clone().into());
        let radius = 0.5 * footprint.bounds.diagonal();
        for (k, toward_light) in [
            Vec3::X,
            Vec3::Z,
            Vec3::new(1.0, 0.2, -0.7),
            Vec3::new(-0.3, 1.0, 0.1),
            Vec3::Y,
            Vec3::new(0.0, -1.0, 0.0),
        ]
        .into_iter()
        .enumerate()
        {
            let camera = footprint.light_camera(toward_light);
            assert!(
                camera.toward_eye().dot(toward_light.normalize()) > 0.9999,
                "light {k}"
            );
            let Projection::Orthographic { half_height } = camera.projection else {
                panic!("light {k}: {camera:?}");
            };
            assert!(
                half_height <= radius * 1.0001,
                "light {k}: {half_height} > {radius}"
            );
            let mut widest = 0.0f32;
            for &p in &points {
                let c = camera_space(&camera, p);
                assert!(
                    c.z > camera.near && c.z < camera.far,
                    "light {k}: {p} at depth {}",
                    c.z
                );
                widest = widest.max(c.x.abs()).max(c.y.abs());
            }
            assert!(
                widest <= half_height,
                "light {k}: a point at {widest} outside {half_height}"
            );
            // The square's room beyond the farthest point is the margin, at most.
            assert!(
                half_height - widest <= FOOTPRINT_MARGIN * radius + 1e-4,
                "light {k}: {widest} in {half_height}"
            );
        }
        // Along the groom (light along y) the square holds its 1-unit-wide cross-section, against
        // the sphere's half diagonal of 5.
        let end_on = footprint.light_camera(Vec3::Y);
        let Projection::Orthographic { half_height } = end_on.projection else {
            unreachable!()
        };
        assert!(half_height < 0.6, "{half_height} vs {radius}");
        let none = LightFootprint::new(footprint.bounds, Vec::new().into());
        assert_eq!(
            none.light_camera(Vec3::X),
            light_camera(Vec3::X, footprint.bounds)
        );
    }
}
