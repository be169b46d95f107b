//! `render_frame` end to end with every kind of light map (deep opacity maps, opacity shadow maps,
//! shadow maps, ADSM) and with a spot light, against answers worked out on the CPU from the
//! geometry alone: which occluders the ray from a shaded point toward the light passes through
//! (segment distances in f64), and each technique's documented transmittance for that count or
//! depth. The pass-level tests (`shadow_maps.rs`, `deep_opacity.rs`) drive the passes by hand;
//! here `render_frame` builds the light camera, the maps and the lookup itself, from the whole
//! model, so the receiver is in its own maps as in a real frame.
//!
//! Scene: a receiver fiber along x at (y, z) = (−0.6, −0.4), and three occluder fibers along x
//! placed on the receiver's line toward the light: at s = 0.8, 0.9, 1.0 along (0, 1, 1) from
//! its axis. The occluders end at x = 0, so the receiver's half x < 0 lies behind all three and
//! the half x > 0 in full light. The orthographic test camera looks down −z: on screen the
//! occluders (rows ~19–26) never cover the receiver (rows 49–52), only the light sees them in
//! line. The receiver is 4 pixels wide on screen (the frame's width override) but 1e-5 units
//! thick in the light maps (under a thousandth of a texel: α ≈ 0.0006), so its own optical
//! depth, which layered maps count at its own depth, stays far below the tolerances.
//!
//! Every comparison is a ratio of the shadowed frame to the unshadowed one (`shadows: None`)
//! at the same pixel, so it reads the transmittance the shader applied whatever the shading.

use crate::common::*;

use glam::{DVec3, Vec3};
use strandlight_runtime::gpu::GpuContext;
use strandlight_runtime::hair::{Attribute, HairModel};
use strandlight_runtime::lights::Light;
use strandlight_runtime::passes::deep_opacity::{DomSettings, ShadowLookup};
use strandlight_runtime::passes::frame_params::{FrameParams, KajiyaKay};
use strandlight_runtime::point_frame::{RenderOptions, ShadowMaps, render_frame};
use strandlight_runtime::shadow_layout::{PointLayoutChoice, ShadowLayout};

const RECEIVER_Y: f32 = -0.6;
const RECEIVER_Z: f32 = -0.4;
const RECEIVER_HALF_LENGTH: f32 = 0.9;
const RECEIVER_THICKNESS: f32 = 1e-5;
/// Where the occluders sit, in steps along (0, 1, 1) from the receiver's axis.
const OCCLUDER_STEPS: [f32; 3] = [0.8, 0.9, 1.0];
const OCCLUDER_X: [f32; 2] = [-0.9, 0.0];
const OCCLUDER_THICKNESS: f32 = 0.2;
const OCCLUDER_OPACITY: f32 = 0.3;
/// 128² maps: a texel is under 0.02 world units at the occluders both for the directional
/// light's orthographic map (the hair's ~2.3-unit diagonal across) and for the point light's
/// perspective one (a ~66° cone, the occluders at most ~1.7 units from the lamp).
const MAP_RES: u32 = 128;
/// A ray that passes within this of an occluder's edge (its radius, or its end) is not decided:
/// the lookup reads the one texel holding the shaded point, so within a texel or two of an edge
/// rasterization decides, not geometry.
const EDGE_MARGIN: f64 = 0.06;
/// The receiver's width on screen; rows 50 and 51 lie wholly inside its quad (centre 51.2).
const RECEIVER_WIDTH_PX: f32 = 4.0;
const RECEIVER_ROWS: std::ops::Range<usize> = 50..52;

fn toward_light() -> Vec3 {
    Vec3::new(0.0, 1.0, 1.0).normalize()
}

fn directional() -> Light {
    Light::Directional {
        direction: toward_light(),
        intensity: 1.0,
    }
}

/// A point on the receiver's line toward the light, above the hair, so every ray from the
/// receiver to it lies in the plane of the occluders' axes.
const LAMP: Vec3 = Vec3::new(0.0, 1.4, 1.6);

fn receiver_axis() -> [Vec3; 2] {
    [-RECEIVER_HALF_LENGTH, RECEIVER_HALF_LENGTH].map(|x| Vec3::new(x, RECEIVER_Y, RECEIVER_Z))
}

fn occluder_axes() -> Vec<[Vec3; 2]> {
    OCCLUDER_STEPS
        .iter()
        .map(|&s| OCCLUDER_X.map(|x| Vec3::new(x, RECEIVER_Y + s, RECEIVER_Z + s)))
        .collect()
}

/// The three occluders and the receiver, as one model: the maps are drawn from all of it.
fn scene() -> HairModel {
    let axes: Vec<[Vec3; 2]> = occluder_axes()
        .into_iter()
        .chain([receiver_axis()])
        .collect();
    let occluders = axes.len() - 1;
    let per_point = |occluder: f32, receiver: f32| {
        let values = (0..axes.len())
            .flat_map(|i| [if i < occluders { occluder } else { receiver }; 2])
            .collect();
        Some(Attribute::PerPoint(values))
    };
    HairModel::new(
        axes.iter().flatten().copied().collect(),
        (0..=axes.len() as u32).map(|i| 2 * i).collect(),
        per_point(OCCLUDER_THICKNESS, RECEIVER_THICKNESS),
        // The format's transparency is 1 − opacity.
        per_point(1.0 - OCCLUDER_OPACITY, 0.0),
        Some(Attribute::Uniform(Vec3::new(0.5, 0.4, 0.3))),
    )
    .unwrap()
}

/// The whole frame under `light`, with `shadows`.
fn render(
    gpu: &GpuContext,
    hair: &HairModel,
    light: Light,
    shadows: Option<ShadowMaps>,
) -> Vec<[f32; 4]> {
    render_with_layout(gpu, hair, light, shadows, PointLayoutChoice::Auto)
}

/// [`render`] with the point-light maps' layout chosen.
fn render_with_layout(
    gpu: &GpuContext,
    hair: &HairModel,
    light: Light,
    shadows: Option<ShadowMaps>,
    point_layout: PointLayoutChoice,
) -> Vec<[f32; 4]> {
    let frame = FrameParams {
        camera: ortho_camera(),
        width: RES,
        height: RES,
        lights: vec![light],
        shading: KajiyaKay::default(),
        width_override_px: Some(RECEIVER_WIDTH_PX),
    };
    let options = RenderOptions {
        shadows,
        point_layout,
        ..Default::default()
    };
    render_frame(gpu, hair, &frame, &options)
        .unwrap_or_else(|e| panic!("{shadows:?}: {e}"))
        .pixels
}

/// The receiver's pixels wholly on its quad: the pixel index and the point of its axis under
/// the pixel's centre (the camera is orthographic, so the shaded point the quad interpolates).
fn receiver_pixels() -> Vec<(usize, Vec3)> {
    let per_unit = PER_UNIT as f32;
    let mut out = Vec::new();
    for y in RECEIVER_ROWS {
        for x in 0..RES as usize {
            let world_x = (x as f32 + 0.5) / per_unit - 1.0;
            // Half a pixel short of the ends, where the quad stops.
            if world_x.abs() < RECEIVER_HALF_LENGTH - 1.0 / per_unit {
                out.push((
                    y * RES as usize + x,
                    Vec3::new(world_x, RECEIVER_Y, RECEIVER_Z),
                ));
            }
        }
    }
    out
}

/// Where the light `light` is seen from `p`: its position, or far along its direction.
fn light_end(light: &Light, p: Vec3) -> DVec3 {
    match *light {
        Light::Directional { direction, .. } => (p + direction.normalize() * 10.0).as_dvec3(),
        Light::Point { position, .. } | Light::Spot { position, .. } => position.as_dvec3(),
    }
}

/// The occluders that the segment from `p` to the light passes through, as their axes; `None`
/// where it passes within [`EDGE_MARGIN`] of any occluder's edge (through a fiber: within the
/// radius less the margin of its axis shortened by the margin at both ends; missing it: farther
/// than the radius plus the margin from the whole axis).
fn occluders_crossed(p: Vec3, light: &Light) -> Option<Vec<[Vec3; 2]>> {
    let (from, to) = (p.as_dvec3(), light_end(light, p));
    let radius = OCCLUDER_THICKNESS as f64 / 2.0;
    let mut crossed = Vec::new();
    for axis in occluder_axes() {
        let [a, b] = axis.map(|v| v.as_dvec3());
        let inward = (b - a).normalize() * EDGE_MARGIN;
        if segment_distance(from, to, a + inward, b - inward) < radius - EDGE_MARGIN {
            crossed.push(axis);
        } else if segment_distance(from, to, a, b) <= radius + EDGE_MARGIN {
            return None;
        }
    }
    Some(crossed)
}

/// The shadowed frame over the unshadowed one at `pixel` (red channel), after checking the
/// unshadowed receiver is lit there.
fn transmittance(shadowed: &[[f32; 4]], lit: &[[f32; 4]], pixel: usize) -> f32 {
    assert!(
        lit[pixel][0] > 1e-3,
        "receiver pixel {pixel} is not lit without shadows: {:?}",
        lit[pixel]
    );
    shadowed[pixel][0] / lit[pixel][0]
}

/// Checks every decided receiver pixel under the directional light: `expected(occluders
/// crossed, point)` behind the occluders, 1 (the unshadowed frame) elsewhere, each within
/// `tolerance` (absolute on the transmittance), and enough pixels of both kinds.
fn check_directional(
    name: &str,
    shadows: ShadowMaps,
    tolerance: f32,
    expected: impl Fn(&[[Vec3; 2]], Vec3) -> f32,
) {
    let gpu = gpu();
    let hair = scene();
    let lit = render(&gpu, &hair, directional(), None);
    let shadowed = render(&gpu, &hair, directional(), Some(shadows));
    let (mut in_shadow, mut in_light, mut worst) = (0, 0, 0.0f32);
    for (pixel, p) in receiver_pixels() {
        let Some(crossed) = occluders_crossed(p, &directional()) else {
            continue;
        };
        let want = if crossed.is_empty() {
            in_light += 1;
            1.0
        } else {
            in_shadow += 1;
            expected(&crossed, p)
        };
        let got = transmittance(&shadowed, &lit, pixel);
        worst = worst.max((got - want).abs());
        assert!(
            (got - want).abs() <= tolerance,
            "{name}: receiver point {p} behind {} occluders: transmittance {got}, expected {want}",
            crossed.len()
        );
    }
    eprintln!(
        "{name}: {in_shadow} shadowed and {in_light} lit receiver pixels; worst error {worst:.2e}"
    );
    // Without both kinds the comparison says nothing (e.g. a scene that no longer lines up).
    assert!(
        in_shadow >= 20 && in_light >= 20,
        "{name}: {in_shadow} shadowed, {in_light} lit"
    );
}

/// Depth along the light (larger: farther from it) of `p`, for the directional light.
fn depth_along_light(p: Vec3) -> f64 {
    -p.as_dvec3().dot(toward_light().as_dvec3())
}

/// Beer–Lambert through the crossed fibers: each covers its texels wholly (it is ~11 texels
/// wide in a 128² map), so each passes 1 − opacity.
fn fibers_transmittance(crossed: &[[Vec3; 2]]) -> f32 {
    (1.0 - OCCLUDER_OPACITY as f64).powi(crossed.len() as i32) as f32
}

// Layered maps and ADSM: 3e-3 absolute on the transmittance. The receiver's own optical depth
// in its layer is ≤ 0.0006 (α of a 1e-5-unit fiber in a ~0.018-unit texel); layers may be half
// floats (2^-11 relative on each of three τ ≈ 0.36: ≤ 2e-4 on T) and so may the frame (2^-11 on
// each pixel of the ratio: ≤ 1e-3). Lavapipe, with 32-bit floats, stays under 6e-4. A fiber left
// out or counted twice moves the answer by 0.1 or more (0.343 against 0.49 or 0.24).
const SOFT_TOLERANCE: f32 = 3e-3;

#[test]
fn deep_opacity_maps_pass_one_minus_opacity_per_fiber_crossed() {
    let settings = DomSettings {
        resolution: MAP_RES,
        layers: 8,
        spacing: 0.25,
    };
    // The layers start at the nearest occluder; the CPU checks that the occluders all fall in
    // layers wholly in front of the receiver's, and the receiver short of the last layer (which
    // takes everything beyond, itself included).
    let nearest = occluder_axes()
        .iter()
        .map(|a| depth_along_light(a[0]))
        .fold(f64::INFINITY, f64::min);
    let layer_position = |p: Vec3| (depth_along_light(p) - nearest) / settings.spacing as f64;
    let receiver = layer_position(receiver_axis()[0]);
    assert!(
        receiver < settings.layers as f64 - 1.0,
        "receiver at {receiver}"
    );
    for axis in occluder_axes() {
        assert!(
            layer_position(axis[0]) < receiver.floor(),
            "occluder behind the receiver's layer"
        );
    }
    check_directional(
        "deep opacity",
        ShadowMaps::Deep { settings, pcf: 1 },
        SOFT_TOLERANCE,
        |crossed, _| fibers_transmittance(crossed),
    );
}

#[test]
fn opacity_shadow_maps_pass_one_minus_opacity_per_fiber_crossed() {
    let slices = 8;
    // Kim & Neumann's slices span the hair's depth range along the light: the occluders must
    // lie in slices wholly in front of the receiver's, as the CPU finds from the bounds.
    let depths = scene().bounds().corners().map(depth_along_light);
    let nearest = depths.iter().copied().fold(f64::INFINITY, f64::min);
    let farthest = depths.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let spacing = (farthest - nearest) / slices as f64;
    let slice_position = |p: Vec3| (depth_along_light(p) - nearest) / spacing;
    let receiver = slice_position(receiver_axis()[0]);
    for axis in occluder_axes() {
        assert!(
            slice_position(axis[0]) + 1.0 < receiver,
            "occluder in the receiver's slice"
        );
    }
    check_directional(
        "opacity shadow maps",
        ShadowMaps::OpacitySlices {
            resolution: MAP_RES,
            slices,
            pcf: 1,
        },
        SOFT_TOLERANCE,
        |crossed, _| fibers_transmittance(crossed),
    );
}

// Shadow maps: the shadowed and unshadowed pixels come from the same arithmetic times exactly 0
// or 1, so the ratio is 0 or 1 up to float noise.
const HARD_TOLERANCE: f32 = 1e-6;

#[test]
fn shadow_maps_black_out_everything_behind_the_nearest_fiber() {
    check_directional(
        "shadow map",
        ShadowMaps::Depth {
            resolution: MAP_RES,
            lookup: ShadowLookup::Hard {
                kernel: 1,
                bias: 0.02,
            },
        },
        HARD_TOLERANCE,
        // Opaque regardless of the occluders' opacity: only the nearest depth is kept.
        |_, _| 0.0,
    );
}

#[test]
fn adsm_follows_tressfx_count_behind_the_nearest_fiber() {
    let (alpha, spacing, bias) = (0.3f32, 0.5f32, 0.05f32);
    check_directional(
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
        // Depths read back from a 32-bit depth buffer are good to ~1e-6 units, far below the
        // 0.016 units of depth that would move (1 − α)^(b / spacing) by 3e-3; the rest is the
        // frame's precision as for the layered maps. Counting from the wrong fiber (0.14 units
        // off) moves it by 0.027.
        SOFT_TOLERANCE,
        |crossed, p| {
            // Behind the nearest fiber (the one nearest the light) by b along the light: TressFX
            // counts one fiber of opacity α every `spacing` past the bias.
            let nearest = crossed
                .iter()
                .map(|a| depth_along_light(a[0]))
                .fold(f64::INFINITY, f64::min);
            let behind = depth_along_light(p) - nearest;
            (1.0 - alpha as f64).powf(1.0 + (behind - bias as f64) / spacing as f64) as f32
        },
    );
}

const SPOT_HALF_ANGLE_DEGREES: f64 = 10.0;
/// The cone is judged in f64 on the CPU and in f32 on the GPU from the same pixel-centre point;
/// 0.25° (~0.012 units at the receiver, under half a pixel) keeps rounding from deciding.
const CONE_MARGIN_DEGREES: f64 = 0.25;

/// The angle between the spot's axis and the ray from the lamp to `p`, in degrees.
fn off_axis_degrees(axis: DVec3, p: Vec3) -> f64 {
    (p.as_dvec3() - LAMP.as_dvec3())
        .angle_between(axis)
        .to_degrees()
}

#[test]
fn a_spot_light_is_the_point_light_inside_its_cone_and_dark_outside() {
    let gpu = gpu();
    let hair = scene();
    // Aimed at x = 0.2 on the receiver: the 10° cone covers about x ∈ (−0.3, 0.7), shadowed and
    // lit parts of it, with receiver outside the cone on both sides.
    let aim = Vec3::new(0.2, RECEIVER_Y, RECEIVER_Z);
    let axis = (aim - LAMP).as_dvec3().normalize();
    let intensity = 9.0;
    let point = Light::Point {
        position: LAMP,
        intensity,
    };
    let spot = Light::Spot {
        position: LAMP,
        direction: axis.as_vec3(),
        half_angle: (SPOT_HALF_ANGLE_DEGREES as f32).to_radians(),
        intensity,
    };
    let shadow_map = ShadowMaps::Depth {
        resolution: MAP_RES,
        lookup: ShadowLookup::Hard {
            kernel: 1,
            bias: 0.02,
        },
    };
    let point_lit = render(&gpu, &hair, point, None);
    let spot_lit = render(&gpu, &hair, spot, None);
    let point_shadowed = render(&gpu, &hair, point, Some(shadow_map));
    let spot_shadowed = render(&gpu, &hair, spot, Some(shadow_map));
    let (mut inside, mut outside, mut in_shadow, mut in_light) = (0, 0, 0, 0);
    for (pixel, p) in receiver_pixels() {
        // The point light's shadow map against the CPU ray test toward the lamp: the spot's map
        // is built the same way from the same position, so this checks the perspective map.
        if let Some(crossed) = occluders_crossed(p, &point) {
            let want = if crossed.is_empty() { 1.0 } else { 0.0 };
            let got = transmittance(&point_shadowed, &point_lit, pixel);
            assert!(
                (got - want).abs() <= HARD_TOLERANCE,
                "point light shadow map at {p}: transmittance {got}, the ray test says {want}"
            );
            if crossed.is_empty() {
                in_light += 1;
            } else {
                in_shadow += 1;
            }
        }
        let angle = off_axis_degrees(axis, p);
        if (angle - SPOT_HALF_ANGLE_DEGREES).abs() < CONE_MARGIN_DEGREES {
            continue;
        }
        // The spot has a hard edge (`Light::Spot`): no falloff inside, so its frames equal the
        // point light's there, shadowed or not; outside it adds nothing at all.
        let in_cone = angle < SPOT_HALF_ANGLE_DEGREES;
        for (spot_frame, point_frame, what) in [
            (&spot_lit, &point_lit, "unshadowed"),
            (&spot_shadowed, &point_shadowed, "shadow-mapped"),
        ] {
            let (s, q) = (spot_frame[pixel], point_frame[pixel]);
            let want = if in_cone {
                [q[0], q[1], q[2]]
            } else {
                [0.0; 3]
            };
            // Identical arithmetic inside (1e-6 for float noise); exactly black outside.
            let close = (0..3).all(|k| (s[k] - want[k]).abs() <= 1e-6 * want[k].abs().max(1e-3));
            assert!(
                close,
                "{what} spot at {p}, {angle:.2}° off its axis (inside: {in_cone}): {s:?}, expected {want:?}"
            );
        }
        if in_cone {
            inside += 1;
        } else {
            outside += 1;
        }
    }
    eprintln!(
        "spot: {inside} pixels inside the cone, {outside} outside; point light shadow map: \
         {in_shadow} shadowed, {in_light} lit"
    );
    assert!(
        inside >= 20 && outside >= 20 && in_shadow >= 20 && in_light >= 20,
        "too few decided pixels: {inside} in the cone, {outside} outside, {in_shadow} shadowed, {in_light} lit"
    );
}

/// The point light at [`LAMP`] (a ~66° cone: one frustum holds the hair).
fn lamp() -> Light {
    Light::Point {
        position: LAMP,
        intensity: 9.0,
    }
}

/// The unit axis along which `layout`'s map measures the depth of `p`: the frustum's, or the
/// axis of the cube face that holds `p`.
fn map_axis(layout: &ShadowLayout, p: Vec3) -> DVec3 {
    let camera = match layout {
        ShadowLayout::Frustum(camera) => *camera,
        ShadowLayout::Cube(cube) => cube.face(cube.face_of(p)),
    };
    (camera.target - camera.eye).as_dvec3().normalize()
}

/// The point of the ray from `from` toward `to` nearest the line through `axis` (where the ray
/// crosses that occluder's camera-facing quad, up to the quad's tilt).
fn crossing(from: DVec3, to: DVec3, axis: [Vec3; 2]) -> DVec3 {
    let [a, b] = axis.map(|v| v.as_dvec3());
    let (d1, d2, r) = (to - from, b - a, from - a);
    let (aa, bb, ee) = (d1.dot(d1), d1.dot(d2), d2.dot(d2));
    let t = (bb * d2.dot(r) - ee * d1.dot(r)) / (aa * ee - bb * bb);
    from + d1 * t
}

/// Checks every decided receiver pixel under the lamp with its maps in `choice`'s layout, as
/// [`check_directional`] does: `expected(crossed, p, axis)` behind the occluders (`axis`: the
/// map's depth axis at `p`), 1 elsewhere. Returns the layout and the transmittance per pixel.
fn check_lamp(
    name: &str,
    shadows: ShadowMaps,
    choice: PointLayoutChoice,
    tolerance: f32,
    expected: impl Fn(&[[Vec3; 2]], Vec3, DVec3) -> f32,
) -> (ShadowLayout, Vec<(usize, f32)>) {
    let gpu = gpu();
    let hair = scene();
    let layout = ShadowLayout::for_light(&lamp(), hair.bounds(), choice).unwrap();
    let lit = render(&gpu, &hair, lamp(), None);
    let shadowed = render_with_layout(&gpu, &hair, lamp(), Some(shadows), choice);
    let (mut in_shadow, mut in_light, mut worst) = (0, 0, 0.0f32);
    let mut seen = Vec::new();
    for (pixel, p) in receiver_pixels() {
        let Some(crossed) = occluders_crossed(p, &lamp()) else {
            continue;
        };
        let want = if crossed.is_empty() {
            in_light += 1;
            1.0
        } else {
            in_shadow += 1;
            expected(&crossed, p, map_axis(&layout, p))
        };
        let got = transmittance(&shadowed, &lit, pixel);
        worst = worst.max((got - want).abs());
        assert!(
            (got - want).abs() <= tolerance,
            "{name}: receiver point {p} behind {} occluders: transmittance {got}, expected {want}",
            crossed.len()
        );
        seen.push((pixel, got));
    }
    eprintln!(
        "{name}: {in_shadow} shadowed and {in_light} lit receiver pixels; worst error {worst:.2e}"
    );
    assert!(
        in_shadow >= 20 && in_light >= 20,
        "{name}: {in_shadow} shadowed, {in_light} lit"
    );
    (layout, seen)
}

/// Layered maps: each crossed occluder must lie in a layer wholly in front of the receiver's
/// position, counted along the map's axis from the nearest crossed occluder (the DOM's start at
/// that texel); then the light passes 1 − opacity per fiber.
fn layered_expectation(spacing: f64) -> impl Fn(&[[Vec3; 2]], Vec3, DVec3) -> f32 {
    move |crossed, p, axis| {
        let lamp = LAMP.as_dvec3();
        let depth = |q: DVec3| (q - lamp).dot(axis);
        let depths: Vec<f64> = crossed
            .iter()
            .map(|&a| depth(crossing(p.as_dvec3(), lamp, a)))
            .collect();
        let nearest = depths.iter().copied().fold(f64::INFINITY, f64::min);
        let receiver = (depth(p.as_dvec3()) - nearest) / spacing;
        for d in &depths {
            assert!(
                ((d - nearest) / spacing).floor() + 1.0 <= receiver,
                "an occluder in the receiver's layer at {p}"
            );
        }
        fibers_transmittance(crossed)
    }
}

/// The cube of a far lamp against its one frustum, for every technique: both against the CPU
/// ray test, each with its own map axis, so the cube can be trusted wherever the frustum was.
/// Texel densities differ (the cube's 90° faces spread 128 texels over a wider angle than the
/// ~66° frustum), which the edge margin absorbs: only pixels whose rays clear every occluder
/// edge by 0.06 units (≥ 3 texels of either layout at the occluders) are compared.
#[test]
fn a_forced_cube_matches_the_frustum_and_the_cpu_for_a_far_lamp() {
    let spacing = 0.25;
    let dom = ShadowMaps::Deep {
        settings: DomSettings {
            resolution: MAP_RES,
            layers: 8,
            spacing,
        },
        pcf: 1,
    };
    let hard = ShadowMaps::Depth {
        resolution: MAP_RES,
        lookup: ShadowLookup::Hard {
            kernel: 1,
            bias: 0.02,
        },
    };
    let (alpha, adsm_spacing, bias) = (0.3f32, 0.5f32, 0.05f32);
    let adsm = ShadowMaps::Depth {
        resolution: MAP_RES,
        lookup: ShadowLookup::Adsm {
            kernel: 1,
            bias,
            alpha,
            spacing: adsm_spacing,
        },
    };
    let adsm_expected = |crossed: &[[Vec3; 2]], p: Vec3, axis: DVec3| {
        let lamp = LAMP.as_dvec3();
        let behind = crossed
            .iter()
            .map(|&a| (p.as_dvec3() - crossing(p.as_dvec3(), lamp, a)).dot(axis))
            .fold(f64::NEG_INFINITY, f64::max);
        (1.0 - alpha as f64).powf(1.0 + (behind - bias as f64) / adsm_spacing as f64) as f32
    };
    for choice in [PointLayoutChoice::Auto, PointLayoutChoice::Cube] {
        let name = |what: &str| format!("{what}, lamp, {choice:?}");
        let (layout, _) = check_lamp(
            &name("deep opacity"),
            dom,
            choice,
            SOFT_TOLERANCE,
            layered_expectation(spacing as f64),
        );
        assert_eq!(layout.is_cube(), choice == PointLayoutChoice::Cube);
        check_lamp(
            &name("shadow map"),
            hard,
            choice,
            HARD_TOLERANCE,
            |_, _, _| 0.0,
        );
        check_lamp(&name("ADSM"), adsm, choice, SOFT_TOLERANCE, adsm_expected);
    }
}

/// Opacity shadow maps, whose slices start at each face's nearest extent of the hair: the cube
/// gives the frustum's transmittance, 1 − opacity per fiber, pixel for pixel.
#[test]
fn a_forced_cube_gives_the_frustums_opacity_shadow_maps_for_a_far_lamp() {
    let osm = ShadowMaps::OpacitySlices {
        resolution: MAP_RES,
        slices: 16,
        pcf: 1,
    };
    let mut frames = Vec::new();
    for choice in [PointLayoutChoice::Auto, PointLayoutChoice::Cube] {
        // The slices' spacing follows the layout; only fibers in slices wholly in front of the
        // receiver's count in full, which holds here: the occluders lie ≥ 1.1 units in front
        // of the receiver along every ray, and 16 slices over any face's or the frustum's
        // depth range of the ~2.3-unit hair are under 0.16 units thick.
        let (_, seen) = check_lamp(
            &format!("opacity shadow maps, lamp, {choice:?}"),
            osm,
            choice,
            SOFT_TOLERANCE,
            |crossed, _, _| fibers_transmittance(crossed),
        );
        frames.push(seen);
    }
    assert_eq!(frames[0].len(), frames[1].len());
    for ((pixel, frustum), (_, cube)) in frames[0].iter().zip(&frames[1]) {
        assert!(
            (frustum - cube).abs() <= 2.0 * SOFT_TOLERANCE,
            "pixel {pixel}: frustum {frustum}, cube {cube}"
        );
    }
}
