//! The viewers' camera (the window's and the web page's): an orbit around a target (yaw about the hair's up axis, pitch above its
//! normal plane, a distance), panned in the view plane and zoomed by distance. It starts from
//! the same framing `render` uses, and always hands the renderer an exact camera.

use glam::Vec3;
use strandlight_runtime::camera::{Camera, Projection};

/// Degrees of orbit per pixel dragged.
const DEGREES_PER_PIXEL: f32 = 0.3;
/// Pitch stays short of the poles, where the view would align with up.
const MAX_PITCH_DEGREES: f32 = 89.0;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Orbit {
    pub target: Vec3,
    pub distance: f32,
    /// About `up`, radians; 0 looks from `front`.
    pub yaw: f32,
    /// Above the plane normal to `up`, radians.
    pub pitch: f32,
    pub up: Vec3,
    pub front: Vec3,
    pub fov_y: f32,
    /// Radius of the hair's bounds: keeps near and far around it at every distance.
    pub radius: f32,
}

impl Orbit {
    /// The orbit through `camera` (a perspective camera looking at its target).
    pub fn from_camera(camera: &Camera, front: Vec3, radius: f32) -> Self {
        let up = camera.up.normalize();
        let front = (front - up * front.dot(up)).normalize();
        let right = up.cross(front);
        let offset = camera.eye - camera.target;
        let distance = offset.length();
        let d = offset / distance;
        let fov_y = match camera.projection {
            Projection::Perspective { fov_y } => fov_y,
            Projection::Orthographic { .. } => 30f32.to_radians(),
        };
        Self {
            target: camera.target,
            distance,
            yaw: d.dot(right).atan2(d.dot(front)),
            pitch: d.dot(up).clamp(-1.0, 1.0).asin(),
            up,
            front,
            fov_y,
            radius: radius.max(1e-6),
        }
    }

    /// Unit vector from the target to the eye.
    fn toward_eye(&self) -> Vec3 {
        let right = self.up.cross(self.front);
        let horizontal = self.front * self.yaw.cos() + right * self.yaw.sin();
        horizontal * self.pitch.cos() + self.up * self.pitch.sin()
    }

    pub fn camera(&self) -> Camera {
        let eye = self.target + self.toward_eye() * self.distance;
        // Near and far hug the hair's bounding sphere (depth precision), never behind the eye.
        let near = (self.distance - 2.0 * self.radius).max(self.distance * 1e-3);
        Camera {
            eye,
            target: self.target,
            up: self.up,
            projection: Projection::Perspective { fov_y: self.fov_y },
            near,
            far: self.distance + 2.0 * self.radius,
        }
    }

    /// A drag of (dx, dy) pixels: right turns the hair to the right, down looks from above.
    pub fn rotate(&mut self, dx: f32, dy: f32) {
        self.yaw -= (dx * DEGREES_PER_PIXEL).to_radians();
        let limit = MAX_PITCH_DEGREES.to_radians();
        self.pitch = (self.pitch + (dy * DEGREES_PER_PIXEL).to_radians()).clamp(-limit, limit);
    }

    /// Scroll `steps` (positive: closer), never through the target.
    pub fn zoom(&mut self, steps: f32) {
        self.distance = (self.distance * (-0.1 * steps).exp()).max(self.radius * 0.05);
    }

    /// A drag of (dx, dy) pixels of a `viewport_height`-pixel view: the hair follows the cursor.
    pub fn pan(&mut self, dx: f32, dy: f32, viewport_height: f32) {
        let toward_eye = self.toward_eye();
        let right = self.up.cross(toward_eye).normalize();
        let screen_up = toward_eye.cross(right);
        let world_per_pixel = 2.0 * self.distance * (self.fov_y * 0.5).tan() / viewport_height;
        self.target += (-right * dx + screen_up * dy) * world_per_pixel;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera() -> Camera {
        Camera {
            eye: Vec3::new(0.0, 1.0, 5.0),
            target: Vec3::new(0.0, 1.0, 0.0),
            up: Vec3::Y,
            projection: Projection::Perspective {
                fov_y: 30f32.to_radians(),
            },
            near: 1.0,
            far: 9.0,
        }
    }

    #[test]
    fn the_orbit_of_a_camera_gives_that_camera_back() {
        for eye in [
            Vec3::new(0.0, 1.0, 5.0),
            Vec3::new(3.0, 2.0, -4.0),
            Vec3::new(-1.0, -3.0, 0.5),
        ] {
            let c = Camera { eye, ..camera() };
            let orbit = Orbit::from_camera(&c, Vec3::Z, 1.0);
            let back = orbit.camera();
            assert!((back.eye - eye).length() < 1e-5, "{eye} → {}", back.eye);
            assert_eq!(back.target, c.target);
        }
    }

    #[test]
    fn a_full_turn_of_drags_comes_back_and_pitch_stops_short_of_the_pole() {
        let mut orbit = Orbit::from_camera(&camera(), Vec3::Z, 1.0);
        let start = orbit.camera().eye;
        orbit.rotate(360.0 / DEGREES_PER_PIXEL, 0.0);
        assert!((orbit.camera().eye - start).length() < 1e-4);
        orbit.rotate(90.0 / DEGREES_PER_PIXEL, 0.0);
        // A quarter turn to the right moves the eye to the hair's left (−x for a +z front).
        assert!(orbit.camera().eye.x < -4.9, "{}", orbit.camera().eye);
        orbit.rotate(0.0, 10_000.0);
        assert!((orbit.pitch.to_degrees() - MAX_PITCH_DEGREES).abs() < 1e-3);
        let eye = orbit.camera().eye - orbit.target;
        assert!(eye.normalize().dot(Vec3::Y) < 1.0 - 1e-5);
    }

    #[test]
    fn zoom_keeps_the_target_and_pan_moves_it_in_the_view_plane() {
        let mut orbit = Orbit::from_camera(&camera(), Vec3::Z, 1.0);
        orbit.zoom(1000.0);
        assert!(orbit.distance >= 0.05 - 1e-6);
        assert!(orbit.camera().near > 0.0 && orbit.camera().far > orbit.camera().near);
        let mut orbit = Orbit::from_camera(&camera(), Vec3::Z, 1.0);
        orbit.pan(100.0, 0.0, 480.0);
        // Dragging right moves the target left (−x), in the plane normal to the view (z fixed).
        assert!(orbit.target.x < 0.0 && orbit.target.z.abs() < 1e-6 && orbit.target.y == 1.0);
        let expected = 100.0 * 2.0 * 5.0 * (15f32.to_radians()).tan() / 480.0;
        assert!((orbit.target.x + expected).abs() < 1e-5);
    }
}
