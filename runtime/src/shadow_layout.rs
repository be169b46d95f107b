//! Where a light's shadow maps look from. One frustum wherever one holds the hair: an
//! orthographic one for a directional light, a perspective one aimed at the hair for a point or
//! spot light that sees it within [`MAX_LIGHT_CONE_DEGREES`] (every texel on the hair, one draw
//! per map). Otherwise, for a lamp beside or inside the hair, a cube of six 90° frustums around
//! the light ([`CubeLight`]), which holds the hair from anywhere. A spot light whose cone fits
//! one frustum keeps one frustum along its cone even where the hair does not fit: what lies
//! outside the cone is unlit, so its shadow does not matter.
//!
//! Every shadow technique (deep opacity maps, opacity shadow maps, shadow maps, ADSM) stores a
//! cube's faces as array layers of the same textures as a frustum, and the lookup
//! (`strands.wgsl`, `shadow_face`) picks the face by the dominant axis of (fragment − light),
//! as [`CubeLight::face_of`] does here.

use glam::Vec3;

use crate::camera::{Camera, MAX_LIGHT_CONE_DEGREES, Projection, light_camera, point_light_camera};
use crate::hair::Aabb;
use crate::lights::Light;

/// Faces of a cube layout.
pub const CUBE_FACES: usize = 6;

/// Face k looks along `FACE_AXES[k]`: +x, −x, +y, −y, +z, −z, i.e. face 2·axis + (negative),
/// the order of `shadow_face` in `strands.wgsl`.
const FACE_AXES: [Vec3; CUBE_FACES] = [
    Vec3::X,
    Vec3::NEG_X,
    Vec3::Y,
    Vec3::NEG_Y,
    Vec3::Z,
    Vec3::NEG_Z,
];

/// An up vector for each face, perpendicular to its axis, so that each face's image axes are
/// world axes and its square 90° frustum is exactly the region where its axis dominates.
const FACE_UPS: [Vec3; CUBE_FACES] = [Vec3::Y, Vec3::Y, Vec3::Z, Vec3::Z, Vec3::Y, Vec3::Y];

/// The near plane of a perspective map as a fraction of its far plane where the hair comes
/// closer to the lamp than that (a lamp inside the hair): fibers within it cast no shadow. A
/// Depth32Float buffer then resolves depth d to about 6e-8·d²/near, 6e-5 of the far distance
/// at the far plane, well under a DOM layer or a shadow bias.
pub const NEAR_OVER_FAR: f32 = 1e-3;

/// A point light's cube of six 90° perspective frustums; all faces share `near` and `far`
/// (depths along each face's own axis).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CubeLight {
    pub position: Vec3,
    pub near: f32,
    pub far: f32,
    /// Per face, whether it can see the bounds the cube was built around ([`Self::face_sees`]):
    /// a face that cannot is cleared but not drawn, and no fragment of the hair looks it up.
    pub drawn: [bool; CUBE_FACES],
}

impl CubeLight {
    /// The cube at `position` that holds all of `bounds`.
    pub fn around(position: Vec3, bounds: Aabb) -> Self {
        // A point's depth along its face's (dominant) axis is at least its distance / √3.
        let (near, far) = perspective_range(position, bounds, 1.0 / 3f32.sqrt());
        let mut cube = Self {
            position,
            near,
            far,
            drawn: [true; CUBE_FACES],
        };
        cube.drawn = std::array::from_fn(|k| cube.face_sees(k, bounds));
        cube
    }

    /// The camera of face `k` (0..6: +x, −x, +y, −y, +z, −z).
    pub fn face(&self, k: usize) -> Camera {
        Camera {
            eye: self.position,
            target: self.position + FACE_AXES[k],
            up: FACE_UPS[k],
            projection: Projection::Perspective {
                fov_y: std::f32::consts::FRAC_PI_2,
            },
            near: self.near,
            far: self.far,
        }
    }

    /// The face whose frustum holds `p`: the dominant axis of `p − position` and its sign (ties
    /// go to x before y before z, as in `strands.wgsl`).
    pub fn face_of(&self, p: Vec3) -> usize {
        let d = p - self.position;
        let a = d.abs();
        let axis = if a.x >= a.y && a.x >= a.z {
            0
        } else if a.y >= a.z {
            1
        } else {
            2
        };
        2 * axis + usize::from(d[axis] < 0.0)
    }

    /// Whether face `k` can see any of `bounds`: false only where the whole box lies outside one
    /// of the face's four side planes or in front of its near plane (conservative).
    pub fn face_sees(&self, k: usize, bounds: Aabb) -> bool {
        let axis = FACE_AXES[k];
        let across = [FACE_UPS[k], axis.cross(FACE_UPS[k])];
        let offsets = bounds.corners().map(|c| c - self.position);
        let outside = |normal: Vec3| offsets.iter().all(|d| d.dot(normal) < 0.0);
        let sides = across.iter().flat_map(|&a| [axis + a, axis - a]);
        !sides.into_iter().any(outside) && offsets.iter().any(|d| d.dot(axis) > self.near)
    }
}

/// Near and far planes of a perspective map at `position` over `bounds`: far just past the
/// farthest corner; near just short of the box for a lamp outside it, where `min_cos` bounds the
/// cosine between the map's axis and any direction it holds (a depth along the axis is at least
/// the distance times it), else [`NEAR_OVER_FAR`] of far.
fn perspective_range(position: Vec3, bounds: Aabb, min_cos: f32) -> (f32, f32) {
    let farthest = bounds
        .corners()
        .iter()
        .map(|c| c.distance(position))
        .fold(0.0f32, f32::max);
    let far = (farthest * 1.05).max(1e-6);
    let outside = position.distance(position.clamp(bounds.min, bounds.max));
    let near = (outside * min_cos * 0.95).max(far * NEAR_OVER_FAR);
    (near, far)
}

/// A spot light's one frustum along its cone, where the cone fits one (at most
/// [`MAX_LIGHT_CONE_DEGREES`] across): its square holds the cone, so every lit fragment and
/// every fiber between it and the lamp.
pub fn spot_cone_camera(
    position: Vec3,
    direction: Vec3,
    half_angle: f32,
    bounds: Aabb,
) -> Option<Camera> {
    let fov = 2.0 * half_angle * 1.01;
    if !(fov.to_degrees() <= MAX_LIGHT_CONE_DEGREES) {
        return None;
    }
    let direction = direction.normalize_or_zero();
    if direction == Vec3::ZERO {
        return None;
    }
    // The square frustum's corners lie √2 times farther off its axis than its edges.
    let corner = (std::f32::consts::SQRT_2 * (fov * 0.5).tan()).atan();
    let (near, far) = perspective_range(position, bounds, corner.cos());
    let up = if direction.y.abs() > 0.99 {
        Vec3::Z
    } else {
        Vec3::Y
    };
    Some(Camera {
        eye: position,
        target: position + direction,
        up,
        projection: Projection::Perspective { fov_y: fov },
        near,
        far,
    })
}

/// A point or spot light whose position is not finite.
#[derive(Debug, thiserror::Error, PartialEq)]
#[error("light position {0} is not finite: no shadow map can be placed there")]
pub struct LightNotFinite(pub Vec3);

/// Which layout a point or spot light's maps use.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum PointLayoutChoice {
    /// One frustum where it holds the hair (or a spot's cone), else the cube.
    #[default]
    Auto,
    /// The cube always (to compare it with the frustum).
    Cube,
}

/// The frustums of one light's maps.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ShadowLayout {
    Frustum(Camera),
    Cube(CubeLight),
}

impl From<Camera> for ShadowLayout {
    fn from(camera: Camera) -> Self {
        ShadowLayout::Frustum(camera)
    }
}

impl ShadowLayout {
    /// The layout of `light`'s maps over hair within `bounds` (see the module's notes).
    pub fn for_light(
        light: &Light,
        bounds: Aabb,
        choice: PointLayoutChoice,
    ) -> Result<Self, LightNotFinite> {
        let (position, cone) = match *light {
            Light::Directional { direction, .. } => {
                return Ok(Self::Frustum(light_camera(direction, bounds)));
            }
            Light::Point { position, .. } => (position, None),
            Light::Spot {
                position,
                direction,
                half_angle,
                ..
            } => (position, Some((direction, half_angle))),
        };
        if !position.is_finite() {
            return Err(LightNotFinite(position));
        }
        if choice == PointLayoutChoice::Auto {
            if let Ok(camera) = point_light_camera(position, bounds) {
                return Ok(Self::Frustum(camera));
            }
            let along_cone = cone.and_then(|(direction, half_angle)| {
                spot_cone_camera(position, direction, half_angle, bounds)
            });
            if let Some(camera) = along_cone {
                return Ok(Self::Frustum(camera));
            }
        }
        Ok(Self::Cube(CubeLight::around(position, bounds)))
    }

    /// The faces' cameras: one for a frustum, six for a cube.
    pub fn faces(&self) -> Vec<Camera> {
        match self {
            ShadowLayout::Frustum(camera) => vec![*camera],
            ShadowLayout::Cube(cube) => (0..CUBE_FACES).map(|k| cube.face(k)).collect(),
        }
    }

    pub fn face_count(&self) -> u32 {
        match self {
            ShadowLayout::Frustum(_) => 1,
            ShadowLayout::Cube(_) => CUBE_FACES as u32,
        }
    }

    /// Whether face `k` is drawn (a frustum's one face always is).
    pub fn face_drawn(&self, k: usize) -> bool {
        match self {
            ShadowLayout::Frustum(_) => true,
            ShadowLayout::Cube(cube) => cube.drawn[k],
        }
    }

    pub fn is_cube(&self) -> bool {
        matches!(self, ShadowLayout::Cube(_))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bounds() -> Aabb {
        Aabb {
            min: Vec3::new(-1.0, -2.0, 0.0),
            max: Vec3::new(1.0, 2.0, 3.0),
        }
    }

    /// Points around a lamp inside the box, on a deterministic spiral of directions and
    /// distances.
    fn points_around(centre: Vec3) -> impl Iterator<Item = Vec3> {
        (0..2000).map(move |i| {
            let t = i as f32 + 0.5;
            let z = 1.0 - 2.0 * t / 2000.0;
            let phi = t * 2.399_963;
            let r = (1.0 - z * z).sqrt();
            let distance = 0.05 + 3.0 * ((i * 7919) % 1000) as f32 / 1000.0;
            centre + distance * Vec3::new(r * phi.cos(), r * phi.sin(), z)
        })
    }

    /// Every point around the lamp projects inside the face `face_of` names, checked through
    /// glam's view and projection matrices (the ones the GPU gets), and lies between the
    /// faces' near and far planes when it lies in the box.
    #[test]
    fn each_point_lies_in_the_frustum_of_its_face() {
        let lamp = Vec3::new(0.2, -0.5, 1.0);
        let cube = CubeLight::around(lamp, bounds());
        assert!(cube.near > 0.0 && cube.near <= cube.far * NEAR_OVER_FAR * 1.0001);
        for p in points_around(lamp) {
            let face = cube.face_of(p);
            let camera = cube.face(face);
            let ndc = (camera.projection_matrix(1.0) * camera.view()).project_point3(p);
            assert!(
                ndc.x.abs() <= 1.0 + 1e-5 && ndc.y.abs() <= 1.0 + 1e-5,
                "{p} in face {face} at NDC {ndc}"
            );
            let depth = (p - lamp).dot(FACE_AXES[face]);
            let inside = p.cmpge(bounds().min).all() && p.cmple(bounds().max).all();
            if inside && depth > cube.near {
                assert!((0.0..=1.0).contains(&ndc.z), "{p}: depth {}", ndc.z);
            }
        }
    }

    #[test]
    fn a_lamp_outside_the_box_keeps_the_box_beyond_the_near_plane() {
        let lamp = Vec3::new(3.0, 0.5, 1.0);
        let cube = CubeLight::around(lamp, bounds());
        for c in bounds().corners() {
            let depth = (c - lamp).dot(FACE_AXES[cube.face_of(c)]);
            assert!(depth > cube.near && depth < cube.far, "{c}: {depth}");
        }
        // The +x face looks away from the box and is not drawn; every point of the box lies
        // in a face that is.
        assert!(!cube.drawn[0] && cube.drawn[1], "{:?}", cube.drawn);
        for p in points_around(bounds().center()) {
            let p = p.clamp(bounds().min, bounds().max);
            assert!(
                cube.drawn[cube.face_of(p)],
                "{p} in face {}",
                cube.face_of(p)
            );
        }
        let inside = CubeLight::around(bounds().center(), bounds());
        assert_eq!(inside.drawn, [true; CUBE_FACES]);
    }

    #[test]
    fn the_layout_is_one_frustum_where_it_fits_and_a_cube_elsewhere() {
        let point = |position| Light::Point {
            position,
            intensity: 1.0,
        };
        let far = ShadowLayout::for_light(
            &point(Vec3::new(0.0, -40.0, 2.0)),
            bounds(),
            PointLayoutChoice::Auto,
        );
        assert!(matches!(far, Ok(ShadowLayout::Frustum(_))), "{far:?}");
        let forced = ShadowLayout::for_light(
            &point(Vec3::new(0.0, -40.0, 2.0)),
            bounds(),
            PointLayoutChoice::Cube,
        );
        assert!(matches!(forced, Ok(ShadowLayout::Cube(_))), "{forced:?}");
        let inside = ShadowLayout::for_light(
            &point(Vec3::new(0.0, 0.0, 1.0)),
            bounds(),
            PointLayoutChoice::Auto,
        );
        assert!(matches!(inside, Ok(ShadowLayout::Cube(_))), "{inside:?}");
        let spot = |half_degrees: f32| Light::Spot {
            position: Vec3::new(0.0, 0.0, 1.0),
            direction: Vec3::NEG_Z,
            half_angle: half_degrees.to_radians(),
            intensity: 1.0,
        };
        let narrow = ShadowLayout::for_light(&spot(40.0), bounds(), PointLayoutChoice::Auto);
        match narrow {
            Ok(ShadowLayout::Frustum(camera)) => {
                assert_eq!(camera.eye, Vec3::new(0.0, 0.0, 1.0));
                assert!((camera.target - camera.eye).normalize().dot(Vec3::NEG_Z) > 0.9999);
            }
            other => panic!("a 40° spot inside the box: {other:?}"),
        }
        let wide = ShadowLayout::for_light(&spot(100.0), bounds(), PointLayoutChoice::Auto);
        assert!(matches!(wide, Ok(ShadowLayout::Cube(_))), "{wide:?}");
        assert!(ShadowLayout::for_light(&point(Vec3::NAN), bounds(), Default::default()).is_err());
    }

    /// The spot's frustum holds its whole cone: directions at the cone's edge, all around it,
    /// project inside the map.
    #[test]
    fn a_spot_frustum_holds_its_cone() {
        let direction = Vec3::new(0.3, -0.2, -1.0).normalize();
        let half = 60f32.to_radians();
        let lamp = Vec3::new(0.0, 0.0, 1.0);
        let camera = spot_cone_camera(lamp, direction, half, bounds()).unwrap();
        let view_proj = camera.projection_matrix(1.0) * camera.view();
        let side = direction.any_orthonormal_vector();
        for i in 0..360 {
            let around = glam::Quat::from_axis_angle(direction, (i as f32).to_radians());
            let edge = glam::Quat::from_axis_angle(around * side, half) * direction;
            let ndc = view_proj.project_point3(lamp + edge * 2.0);
            assert!(
                ndc.x.abs() <= 1.0 && ndc.y.abs() <= 1.0,
                "cone edge {i}° at {ndc}"
            );
        }
        assert!(spot_cone_camera(lamp, direction, 80f32.to_radians(), bounds()).is_none());
    }
}
