//! A lamp inside the hair: `render_frame` shadows a point light ringed by occluders on every
//! side, where no single frustum can hold the hair, so its maps take the cube layout
//! (`shadow_layout.rs`). Every technique (deep opacity maps, opacity shadow maps, shadow maps,
//! ADSM) is checked against answers worked out on the CPU from the geometry alone, as in
//! `frame_shadows.rs`: which occluders the segment from a shaded point to the lamp passes
//! through (segment distances in f64), and each technique's transmittance for that.
//!
//! Scene, in a plane through the lamp: a receiver ring (a 96-gon of radius 0.8, 1e-5 thick in
//! the light maps) around the lamp, and inside it eight occluder chords at radius 0.45, each
//! spanning 25° with 20° gaps between, so that every side of the lamp has shadowed and lit
//! receiver. The chords centred at 10° + 45°k straddle the cube's seams (45°) and its face
//! centres (0°, 90°, …). The orthographic camera looks straight at the plane, so each receiver
//! pixel's shaded point is exactly the plane point under its centre. The lamp sits a little off
//! the ring's centre and plane, so no ray runs along a seam by construction. The scene is drawn
//! in two orientations, the plane z = 0 (faces ±x, ±y) and x = 0 (faces ±y, ±z): all six faces.

use crate::common::*;

use glam::{DVec3, Vec3};
use strandlight_runtime::camera::{Camera, Projection};
use strandlight_runtime::gpu::GpuContext;
use strandlight_runtime::hair::{Attribute, HairModel};
use strandlight_runtime::lights::Light;
use strandlight_runtime::passes::deep_opacity::{DomSettings, ShadowLookup};
use strandlight_runtime::passes::frame_params::{FrameParams, KajiyaKay};
use strandlight_runtime::point_frame::{RenderOptions, ShadowMaps, render_frame};
use strandlight_runtime::shadow_layout::{CUBE_FACES, CubeLight, PointLayoutChoice, ShadowLayout};

/// Image side in pixels: the camera shows 2 units, so 64 pixels per unit.
const IMAGE: u32 = 128;
const PIXELS_PER_UNIT: f32 = IMAGE as f32 / 2.0;
const RECEIVER_RADIUS: f32 = 0.8;
const RECEIVER_SIDES: usize = 96;
const RECEIVER_THICKNESS: f32 = 1e-5;
const OCCLUDER_RADIUS: f32 = 0.45;
const OCCLUDER_SPAN_DEGREES: f32 = 25.0;
const OCCLUDERS: usize = 8;
const OCCLUDER_FIRST_DEGREES: f32 = 10.0;
/// ~8 texels of a 128² cube face at the occluders (a texel there is ≤ 0.007 units).
const OCCLUDER_THICKNESS: f32 = 0.06;
const OCCLUDER_OPACITY: f32 = 0.3;
/// Every fiber's width on screen: 4 pixels (1/16 unit), so occluders (within 0.48 of the lamp)
/// and receivers (beyond 0.76) never share a pixel.
const WIDTH_PX: f32 = 4.0;
/// Receiver pixels are those whose centre lies within half a pixel of the ring's axis.
const RECEIVER_BAND: f32 = 0.5 / PIXELS_PER_UNIT;
const MAP_RES: u32 = 128;
/// Rays passing within this of an occluder's end are not decided (two to four texels of the
/// cube's faces at the occluders: the lookup reads one texel, and rasterization decides within
/// a texel of an edge).
const END_MARGIN: f64 = 0.015;
/// Nor are rays passing within this of the occluder's strip out of the plane (the lamp sits
/// 0.004 off the plane, so rays cross the strips ≤ 0.003 from their axes, far inside).
const SIDE_MARGIN: f64 = 0.01;

/// A plane through the lamp: in-plane axes `right` and `up` (on screen), `normal` toward the
/// camera.
#[derive(Clone, Copy, Debug)]
struct Plane {
    right: Vec3,
    up: Vec3,
    normal: Vec3,
}

const PLANES: [Plane; 2] = [
    Plane {
        right: Vec3::X,
        up: Vec3::Y,
        normal: Vec3::Z,
    },
    Plane {
        right: Vec3::Y,
        up: Vec3::Z,
        normal: Vec3::X,
    },
];

impl Plane {
    fn at(&self, u: f32, v: f32) -> Vec3 {
        self.right * u + self.up * v
    }

    fn polar(&self, radius: f32, degrees: f32) -> Vec3 {
        let a = degrees.to_radians();
        self.at(radius * a.cos(), radius * a.sin())
    }

    /// Off the ring's centre and plane by a little, so that rays cross seams at generic points.
    fn lamp(&self) -> Vec3 {
        self.at(0.013, -0.021) + self.normal * 0.004
    }

    fn camera(&self) -> Camera {
        Camera {
            eye: self.normal * 5.0,
            target: Vec3::ZERO,
            up: self.up,
            projection: Projection::Orthographic { half_height: 1.0 },
            near: 1.0,
            far: 10.0,
        }
    }

    fn occluder_axes(&self) -> Vec<[Vec3; 2]> {
        let half = OCCLUDER_SPAN_DEGREES / 2.0;
        (0..OCCLUDERS)
            .map(|k| {
                let centre = OCCLUDER_FIRST_DEGREES + 360.0 / OCCLUDERS as f32 * k as f32;
                [centre - half, centre + half].map(|a| self.polar(OCCLUDER_RADIUS, a))
            })
            .collect()
    }

    fn receiver_points(&self) -> Vec<Vec3> {
        (0..=RECEIVER_SIDES)
            .map(|k| self.polar(RECEIVER_RADIUS, 360.0 * k as f32 / RECEIVER_SIDES as f32))
            .collect()
    }

    /// The occluder chords (one strand each) and the receiver ring (one strand).
    fn hair(&self) -> HairModel {
        let mut points: Vec<Vec3> = self.occluder_axes().into_iter().flatten().collect();
        let mut offsets: Vec<u32> = (0..=OCCLUDERS as u32).map(|i| 2 * i).collect();
        let occluder_points = points.len();
        points.extend(self.receiver_points());
        offsets.push(points.len() as u32);
        let per_point = |occluder: f32, receiver: f32| {
            let values = (0..points.len())
                .map(|i| {
                    if i < occluder_points {
                        occluder
                    } else {
                        receiver
                    }
                })
                .collect();
            Some(Attribute::PerPoint(values))
        };
        HairModel::new(
            points.clone(),
            offsets,
            per_point(OCCLUDER_THICKNESS, RECEIVER_THICKNESS),
            // The format's transparency is 1 − opacity.
            per_point(1.0 - OCCLUDER_OPACITY, 0.0),
            Some(Attribute::Uniform(Vec3::new(0.5, 0.4, 0.3))),
        )
        .unwrap()
    }

    /// Pixels whose centre lies within [`RECEIVER_BAND`] of the ring's axis, with that centre's
    /// point in the plane (the shaded point: the receiver's quad lies in the plane). Pixels
    /// within half a pixel of a corner of the ring are left out: each segment's quad ends square
    /// at its ends, leaving a sliver uncovered outside each corner.
    fn receiver_pixels(&self) -> Vec<(usize, Vec3)> {
        let ring = self.receiver_points();
        let mut out = Vec::new();
        for row in 0..IMAGE as usize {
            for col in 0..IMAGE as usize {
                let u = (col as f32 + 0.5) / PIXELS_PER_UNIT - 1.0;
                let v = 1.0 - (row as f32 + 0.5) / PIXELS_PER_UNIT;
                let p = self.at(u, v);
                let near_ring = ring.windows(2).any(|s| {
                    let (a, b) = (s[0].as_dvec3(), s[1].as_dvec3());
                    let along = (p.as_dvec3() - a).dot(b - a) / (b - a).length_squared();
                    let margin = RECEIVER_BAND as f64 / (b - a).length();
                    let off = (p.as_dvec3() - (a + (b - a) * along)).length();
                    (margin..=1.0 - margin).contains(&along) && off < RECEIVER_BAND as f64
                });
                if near_ring {
                    out.push((row * IMAGE as usize + col, p));
                }
            }
        }
        out
    }
}

fn point_light(plane: &Plane) -> Light {
    Light::Point {
        position: plane.lamp(),
        intensity: 1.0,
    }
}

fn render(
    gpu: &GpuContext,
    plane: &Plane,
    light: Light,
    shadows: Option<ShadowMaps>,
) -> Vec<[f32; 4]> {
    let frame = FrameParams {
        camera: plane.camera(),
        width: IMAGE,
        height: IMAGE,
        lights: vec![light],
        shading: KajiyaKay::default(),
        width_override_px: Some(WIDTH_PX),
    };
    let options = RenderOptions {
        shadows,
        ..Default::default()
    };
    render_frame(gpu, &plane.hair(), &frame, &options)
        .unwrap_or_else(|e| panic!("{shadows:?}: {e}"))
        .pixels
}

/// The occluders the segment from `p` to the lamp passes through; `None` where it passes
/// within [`END_MARGIN`] of an occluder's end or [`SIDE_MARGIN`] of its side. An occluder is a
/// strip in its light maps: its chord, widened by its thickness out of the ring's plane (its
/// quads face the lamp, which lies nearly in that plane), so the segment crosses it where it
/// passes the chord's line between the chord's ends, within half the thickness of it.
fn occluders_crossed(plane: &Plane, p: Vec3) -> Option<Vec<[Vec3; 2]>> {
    let (from, to) = (p.as_dvec3(), plane.lamp().as_dvec3());
    let half_width = OCCLUDER_THICKNESS as f64 / 2.0;
    let mut crossed = Vec::new();
    for axis in plane.occluder_axes() {
        let [a, b] = axis.map(|v| v.as_dvec3());
        let q = crossing(from, to, axis);
        // Where along the chord (0..1) and how far from it the segment passes.
        let along = (q - a).dot(b - a) / (b - a).length_squared();
        let off = segment_distance(
            q,
            q + (b - a) * 1e-9,
            a - (b - a) * 10.0,
            b + (b - a) * 10.0,
        );
        let margin = END_MARGIN / (b - a).length();
        let between = (q - from).dot(to - from) / (to - from).length_squared();
        if !(0.0..=1.0).contains(&between) || off > half_width + SIDE_MARGIN {
            continue;
        }
        if (margin..=1.0 - margin).contains(&along) && off < half_width - SIDE_MARGIN {
            crossed.push(axis);
        } else if (-margin..=1.0 + margin).contains(&along) {
            return None;
        }
    }
    Some(crossed)
}

/// The point of the segment from `from` toward `to` nearest the line through `axis`.
fn crossing(from: DVec3, to: DVec3, axis: [Vec3; 2]) -> DVec3 {
    let [a, b] = axis.map(|v| v.as_dvec3());
    let (d1, d2, r) = (to - from, b - a, from - a);
    let (aa, bb, ee) = (d1.dot(d1), d1.dot(d2), d2.dot(d2));
    let t = (bb * d2.dot(r) - ee * d1.dot(r)) / (aa * ee - bb * bb);
    from + d1 * t
}

/// The axis of the cube face that holds `p` seen from `lamp`, found here from the dominant
/// component of p − lamp (independently of `CubeLight::face_of`).
fn face_axis(lamp: Vec3, p: Vec3) -> (usize, DVec3) {
    let d = (p - lamp).as_dvec3();
    let a = d.abs();
    let axis = if a.x >= a.y && a.x >= a.z {
        0
    } else if a.y >= a.z {
        1
    } else {
        2
    };
    let mut unit = DVec3::ZERO;
    unit[axis] = d[axis].signum();
    (2 * axis + usize::from(d[axis] < 0.0), unit)
}

/// What the expected transmittance of a shadowed receiver point depends on.
struct Ray<'a> {
    crossed: &'a [[Vec3; 2]],
    p: Vec3,
    lamp: Vec3,
    /// The axis of the cube face holding `p` (depths are measured along it).
    axis: DVec3,
}

/// A light and its maps, checked to `tolerance`.
struct Case<'a> {
    name: &'a str,
    light: Light,
    shadows: ShadowMaps,
    tolerance: f32,
}

/// Per cube face: decided receiver pixels in shadow and in light.
type FaceCounts = [[usize; 2]; CUBE_FACES];

/// Every decided receiver pixel of `plane`'s scene under `light` with `shadows`: the ratio of
/// the shadowed frame to the unshadowed one is `expected` of the ray behind the
/// occluders and 1 elsewhere, within `tolerance`. Pixels `skip` rejects are left out.
fn check_plane(
    gpu: &GpuContext,
    plane: &Plane,
    case: Case,
    expected: &dyn Fn(&Ray) -> f32,
    skip: &dyn Fn(Vec3) -> bool,
) -> FaceCounts {
    let Case {
        name,
        light,
        shadows,
        tolerance,
    } = case;
    let layout = ShadowLayout::for_light(&light, plane.hair().bounds(), PointLayoutChoice::Auto);
    let lit = render(gpu, plane, light, None);
    let shadowed = render(gpu, plane, light, Some(shadows));
    let mut counts = [[0; 2]; CUBE_FACES];
    let mut worst = 0.0f32;
    for (pixel, p) in plane.receiver_pixels() {
        let Some(crossed) = occluders_crossed(plane, p).filter(|_| !skip(p)) else {
            continue;
        };
        let (face, axis) = face_axis(plane.lamp(), p);
        let want = if crossed.is_empty() {
            1.0
        } else {
            expected(&Ray {
                crossed: &crossed,
                p,
                lamp: plane.lamp(),
                axis,
            })
        };
        counts[face][usize::from(crossed.is_empty())] += 1;
        assert!(
            lit[pixel][0] > 1e-3,
            "{name}: receiver pixel {pixel} at {p} is not lit without shadows: {:?}",
            lit[pixel]
        );
        let got = shadowed[pixel][0] / lit[pixel][0];
        assert!(got.is_finite(), "{name}: {p}: {got}");
        worst = worst.max((got - want).abs());
        assert!(
            (got - want).abs() <= tolerance,
            "{name} ({layout:?}): receiver point {p} (face {face}) behind {} occluders: \
             transmittance {got}, expected {want}",
            crossed.len()
        );
    }
    eprintln!("{name}: per face [shadowed, lit] {counts:?}; worst error {worst:.2e}");
    counts
}

/// [`check_plane`] for the point light in both orientations: the layout must be the cube, and
/// every face must have shadowed and lit receiver pixels.
fn check_all_faces(
    name: &str,
    shadows: ShadowMaps,
    tolerance: f32,
    expected: impl Fn(&Ray) -> f32,
) {
    let gpu = gpu();
    let mut total: FaceCounts = [[0; 2]; CUBE_FACES];
    for plane in &PLANES {
        let light = point_light(plane);
        let layout = ShadowLayout::for_light(&light, plane.hair().bounds(), Default::default());
        assert!(
            matches!(layout, Ok(ShadowLayout::Cube(CubeLight { .. }))),
            "{layout:?}"
        );
        let name = format!("{name}, ring facing {}", plane.normal);
        let case = Case {
            name: &name,
            light,
            shadows,
            tolerance,
        };
        let counts = check_plane(&gpu, plane, case, &expected, &|_| false);
        for (t, c) in total.iter_mut().zip(counts) {
            t[0] += c[0];
            t[1] += c[1];
        }
    }
    for (face, [shadowed, lit]) in total.iter().enumerate() {
        assert!(
            *shadowed >= 10 && *lit >= 10,
            "{name}: face {face} has {shadowed} shadowed and {lit} lit receiver pixels"
        );
    }
}

/// One fiber crossed (the ring's occluders never overlap along a ray): 1 − opacity.
fn one_minus_opacity(ray: &Ray) -> f32 {
    assert_eq!(ray.crossed.len(), 1);
    1.0 - OCCLUDER_OPACITY
}

/// As in `frame_shadows.rs`: the receiver's own optical depth (α ≤ 1e-5 / 0.006 in its layer)
/// and half-float layers or frames stay under 3e-3; a fiber missed or counted twice moves the
/// answer by 0.2 or more.
const SOFT_TOLERANCE: f32 = 3e-3;
/// Shadow maps: 0 or 1 times the same arithmetic.
const HARD_TOLERANCE: f32 = 1e-6;

#[test]
fn deep_opacity_maps_shadow_a_lamp_inside_a_ring_on_every_side() {
    // The occluders lie ≥ 0.24 units along any face axis in front of the receiver (0.35 units
    // along the ray, at ≤ 45° from the axis): with 0.1-unit layers starting at the occluder,
    // its layer is wholly in front of the receiver.
    check_all_faces(
        "deep opacity",
        ShadowMaps::Deep {
            settings: DomSettings {
                resolution: MAP_RES,
                layers: 8,
                spacing: 0.1,
            },
            pcf: 1,
        },
        SOFT_TOLERANCE,
        one_minus_opacity,
    );
}

#[test]
fn opacity_shadow_maps_shadow_a_lamp_inside_a_ring_on_every_side() {
    // Slices from each face's near plane, 16 over the faces' widest depth range (≤ 0.85
    // units): ≤ 0.054 units thick, so the occluder's slice (it lies ≥ 0.24 units in front of
    // the receiver along the axis) is wholly in front.
    check_all_faces(
        "opacity shadow maps",
        ShadowMaps::OpacitySlices {
            resolution: MAP_RES,
            slices: 16,
            pcf: 1,
        },
        SOFT_TOLERANCE,
        one_minus_opacity,
    );
}

#[test]
fn shadow_maps_shadow_a_lamp_inside_a_ring_on_every_side() {
    // The bias covers the receiver's own depth in its texel: the shaded point lies within half
    // a pixel (0.008 units) of the ring's axis.
    check_all_faces(
        "shadow map",
        ShadowMaps::Depth {
            resolution: MAP_RES,
            lookup: ShadowLookup::Hard {
                kernel: 1,
                bias: 0.03,
            },
        },
        HARD_TOLERANCE,
        |_| 0.0,
    );
}

#[test]
fn adsm_shadows_a_lamp_inside_a_ring_on_every_side() {
    let (alpha, spacing, bias) = (0.3f32, 0.5f32, 0.03f32);
    check_all_faces(
        "ADSM",
        ShadowMaps::Depth {
            resolution: MAP_RES,
            lookup: ShadowLookup::Adsm {
                kernel: 1,
                bias,
                alpha,
                spacing,
            },
        },
        // The nearest depth of the texel is the occluder's quad where the texel's centre ray
        // crosses it, not exactly where the shaded point's ray does: within a texel (≤ 0.007
        // units) of depth, (1 − α)^(0.007 / 0.5) moves T by ≤ 5e-3 × T.
        5e-3,
        |ray| {
            // TressFX's count behind the nearest fiber, along the face's axis.
            let p = ray.p.as_dvec3();
            let q = crossing(p, ray.lamp.as_dvec3(), ray.crossed[0]);
            let behind = (p - q).dot(ray.axis);
            (1.0 - alpha as f64).powf(1.0 + (behind - bias as f64) / spacing as f64) as f32
        },
    );
}

const CONE_MARGIN_DEGREES: f64 = 0.5;

/// Spot lights at the lamp: a 60° cone (a 121° frustum along it holds it, though not the
/// hair) and a 120° one (the cube). Inside the cone the receiver gets the point light's
/// shadow; outside it nothing at all.
#[test]
fn spot_lights_inside_the_ring_shadow_through_their_cone_or_the_cube() {
    let gpu = gpu();
    let plane = &PLANES[0];
    let shadows = ShadowMaps::Depth {
        resolution: MAP_RES,
        lookup: ShadowLookup::Hard {
            kernel: 1,
            bias: 0.03,
        },
    };
    // Aimed along the plane, between the faces' axes, a little out of the plane.
    let direction = (plane.at(1.0, 0.4) - plane.normal * 0.1).normalize();
    for (half_degrees, cube) in [(60.0f32, false), (120.0, true)] {
        let spot = Light::Spot {
            position: plane.lamp(),
            direction,
            half_angle: half_degrees.to_radians(),
            intensity: 1.0,
        };
        let layout =
            ShadowLayout::for_light(&spot, plane.hair().bounds(), Default::default()).unwrap();
        assert_eq!(layout.is_cube(), cube, "{half_degrees}°: {layout:?}");
        let off_axis = |p: Vec3| {
            (p - plane.lamp())
                .as_dvec3()
                .angle_between(direction.as_dvec3())
                .to_degrees()
        };
        let name = format!("spot {half_degrees}°");
        let case = Case {
            name: &name,
            light: spot,
            shadows,
            tolerance: HARD_TOLERANCE,
        };
        let counts = check_plane(
            &gpu,
            plane,
            case,
            &|_| 0.0,
            // Outside the cone the spot lights nothing, shadowed or not: no ratio to check.
            &|p| off_axis(p) > half_degrees as f64 - CONE_MARGIN_DEGREES,
        );
        let [shadowed, lit] = counts.iter().fold([0, 0], |[s, l], c| [s + c[0], l + c[1]]);
        assert!(shadowed >= 20 && lit >= 20, "{name}: {shadowed}, {lit}");
        let dark = render(&gpu, plane, spot, Some(shadows));
        for (pixel, p) in plane.receiver_pixels() {
            if off_axis(p) > half_degrees as f64 + CONE_MARGIN_DEGREES {
                assert_eq!(dark[pixel][..3], [0.0; 3], "{name}: {p} outside the cone");
            }
        }
    }
}
