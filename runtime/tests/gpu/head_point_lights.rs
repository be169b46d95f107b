//! The head in the point-lit frame (issue 40, `render_frame_with_head`) against answers worked
//! out from the geometry alone: the ray from a fiber toward the light meets the sphere or not
//! (`Head::ray_hit`), the ray from the eye reaches a fiber before the head or not, and the skin's
//! radiance is albedo/π · I/d² · max(n·l, 0) on the sphere's analytic normal.
//!
//! Scene (orthographic camera looking down −z, 64², 32 pixels per unit), as in
//! `head_occlusion.rs`: a head, the sphere of radius 0.4 at the origin, and three vertical
//! fibers (x, z) = (0.1, −0.6) behind the head from the camera, (−0.7, 0) on its −x side and
//! (0.7, −0.3) on its +x side. Lights on the +x side (directional, a spot's frustum, and a point
//! light inside the hair's bounds, whose maps take the cube layout) leave the middle of the −x
//! fiber in the head's shadow and never shade the +x one.
//!
//! Shadows are read as the ratio of the frame with the head to the frame without it, both
//! shadowed by the same technique, so they test the head's share of the transmittance whatever
//! the fiber shading and the fibers' own layers.
//!
//! The tests check every case before failing and name each failing one. Each was seen to fail
//! under a deliberate error, in every case: with `head_visibility` (strands.wgsl) returning 1,
//! all 12 technique × light cases ("dom, directional: row 21 x -0.7: behind the head, T = 1", …,
//! "adsm, point (cube): row 10 …"); with `behind_head` returning false, all 6 transparency modes
//! ("Opaque: row 21: the fiber behind the head shows through", …, "Dbk …"); with the skin's 1/π
//! left out (point_skin.wgsl), every probed pixel of every shadow choice and light (0.853 vs
//! 0.272 at (32, 32) under the point light).

use crate::common::*;

use glam::{DVec3, Vec3};
use strandlight_runtime::gpu::GpuContext;
use strandlight_runtime::hair::HairModel;
use strandlight_runtime::head::Head;
use strandlight_runtime::lights::Light;
use strandlight_runtime::passes::deep_opacity::{DomSettings, ShadowLookup};
use strandlight_runtime::passes::fiber_shading::ShadingModel;
use strandlight_runtime::passes::frame_params::{FrameParams, KajiyaKay};
use strandlight_runtime::point_frame::{
    RenderOptions, ShadowMaps, Transparency, render_frame_with_head,
};
use strandlight_runtime::shadow_layout::{PointLayoutChoice, ShadowLayout};

const RADIUS: f32 = HEAD_RADIUS;
const BEHIND_X: f32 = 0.1;
const SIDE_X: f32 = 0.7;
/// The +x fiber sits off the −x fiber's line toward +x (else it would shadow it).
const SIDE_Z: f32 = -0.3;
/// Map texels are at most ~0.02 units at the head (128² over the ~2.4-unit hair and head, a
/// cube face's 90° at ≤ 1.3 units): rays passing within a few texels of the sphere's
/// silhouette are left to rasterization and the bias.
const EDGE_MARGIN: f64 = 0.07;
const SKIN: [f32; 3] = HEAD_SKIN;
const MAP_RES: u32 = 128;

fn head() -> Head {
    sphere_head()
}

fn fiber(x: f32, z: f32) -> [Vec3; 2] {
    vertical_fiber(x, z)
}

fn hair(fibers: &[[Vec3; 2]]) -> HairModel {
    two_point_hair(fibers)
}

fn scene() -> HairModel {
    hair(&[
        fiber(BEHIND_X, -0.6),
        fiber(-SIDE_X, 0.0),
        fiber(SIDE_X, SIDE_Z),
        bound_marks()[0],
        bound_marks()[1],
    ])
}

/// Two short fibers at opposite corners, beyond every tested row and every light path, that
/// stretch the hair's bounds over the head: the light maps (fitted to hair and head) are then
/// the same with and without the head, so the ratio of the two frames is the head's share alone.
fn bound_marks() -> [[Vec3; 2]; 2] {
    let short = Vec3::new(0.01, 0.01, 0.0);
    let a = Vec3::new(-0.75, -0.95, 0.45);
    let b = Vec3::new(0.75, 0.95, -0.65);
    [[a, a + short], [b - short, b]]
}

/// Every point-light shadow technique, crisp (no PCF) at 128².
fn techniques() -> [(&'static str, ShadowMaps); 4] {
    let (kernel, bias) = (1, 0.02);
    [
        (
            "dom",
            ShadowMaps::Deep {
                settings: DomSettings {
                    resolution: MAP_RES,
                    layers: 4,
                    spacing: 0.05,
                },
                pcf: kernel,
            },
        ),
        (
            "osm",
            ShadowMaps::OpacitySlices {
                resolution: MAP_RES,
                slices: 8,
                pcf: kernel,
            },
        ),
        (
            "sm",
            ShadowMaps::Depth {
                resolution: MAP_RES,
                lookup: ShadowLookup::Hard { kernel, bias },
            },
        ),
        (
            "adsm",
            ShadowMaps::Depth {
                resolution: MAP_RES,
                lookup: ShadowLookup::Adsm {
                    kernel,
                    bias,
                    alpha: 0.5,
                    spacing: 0.05,
                },
            },
        ),
    ]
}

/// A point light inside the hair's bounds (so its maps are a cube), on the +x side, off the
/// axes so that no ray runs along a cube seam.
const POINT: Vec3 = Vec3::new(0.62, 0.05, -0.15);

fn shadow_lights() -> [(&'static str, Light); 3] {
    [
        (
            "directional",
            Light::Directional {
                direction: Vec3::X,
                intensity: 1.0,
            },
        ),
        (
            "spot",
            Light::Spot {
                position: Vec3::new(1.6, 0.05, -0.05),
                direction: -Vec3::X,
                half_angle: 50f32.to_radians(),
                intensity: 2.0,
            },
        ),
        (
            "point (cube)",
            Light::Point {
                position: POINT,
                intensity: 0.5,
            },
        ),
    ]
}

fn render(
    gpu: &GpuContext,
    model: &HairModel,
    lights: &[Light],
    shadows: Option<ShadowMaps>,
    transparency: Transparency,
    head: Option<&Head>,
) -> Vec<[f32; 4]> {
    let frame = FrameParams {
        camera: ortho_camera(),
        width: RES,
        height: RES,
        lights: lights.to_vec(),
        shading: KajiyaKay::default(),
        width_override_px: None,
    };
    let options = RenderOptions {
        shadows,
        transparency,
        point_layout: PointLayoutChoice::Auto,
    };
    render_frame_with_head(gpu, model, &frame, &options, &ShadingModel::KajiyaKay, head)
        .unwrap_or_else(|e| panic!("{e}"))
        .pixels
}

/// The pixel whose centre lies nearest world (x, y) (32 per unit, y down).
fn pixel(x: f32, y: f32) -> usize {
    let col = ((x + 1.0) * 32.0).floor() as usize;
    let row = ((1.0 - y) * 32.0).floor() as usize;
    row * RES as usize + col
}

/// World (x, y) of a pixel's centre.
fn centre(col: usize, row: usize) -> (f32, f32) {
    (
        (col as f32 + 0.5) / 32.0 - 1.0,
        1.0 - (row as f32 + 0.5) / 32.0,
    )
}

/// Pixel rows down the fiber at world x: (row, y of the row's centre).
fn rows() -> impl Iterator<Item = (usize, f32)> {
    (4..60).map(|row| (row, centre(0, row).1))
}

/// Toward the light from `p` and how far it is (directional: unbounded).
fn toward_light(light: &Light, p: DVec3) -> (DVec3, f64) {
    match *light {
        Light::Directional { direction, .. } => (direction.as_dvec3().normalize(), 1e3),
        Light::Point { position, .. } | Light::Spot { position, .. } => {
            let d = position.as_dvec3() - p;
            (d.normalize(), d.length())
        }
    }
}

/// How far outside the sphere the segment from `p` toward the light passes (negative: through
/// it), in f64.
fn clearance(p: DVec3, dir: DVec3, length: f64) -> f64 {
    let t = (-p.dot(dir)).clamp(0.0, length);
    (p + dir * t).length() - RADIUS as f64
}

#[test]
fn the_point_lights_maps_take_the_layouts_the_tests_name() {
    let (bounds, head) = (scene().bounds(), head().bounds());
    // The head lies within the hair's bounds, so the maps fit the same with and without it.
    assert!(bounds.min.cmple(head.min).all() && bounds.max.cmpge(head.max).all());
    for (name, light) in shadow_lights() {
        let layout = ShadowLayout::for_light(&light, bounds, PointLayoutChoice::Auto).unwrap();
        assert_eq!(layout.is_cube(), name.contains("cube"), "{name}");
    }
}

/// Every technique, every light: the −x fiber is dark exactly where the segment toward the light
/// meets the head (`Head::ray_hit`), lit as without the head elsewhere; the +x fiber never
/// changes. Every case is checked before the test fails, so that a failure names them all.
#[test]
fn the_head_shadows_fibers_in_every_technique_where_the_geometry_says() {
    let gpu = gpu();
    let head = head();
    let model = scene();
    let mut failures = Vec::new();
    for (technique, maps) in techniques() {
        for (light_name, light) in shadow_lights() {
            let lights = [light];
            let opaque = Transparency::Opaque;
            let with = render(&gpu, &model, &lights, Some(maps), opaque, Some(&head));
            let without = render(&gpu, &model, &lights, Some(maps), opaque, None);
            if let Err(e) = check_head_shadow(&head, &light, &with, &without) {
                failures.push(format!("{technique}, {light_name}: {e}"));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// One technique and light: the head's share of the light (`with` / `without`) on the side
/// fibers' pixels against the CPU's rays.
fn check_head_shadow(
    head: &Head,
    light: &Light,
    with: &[[f32; 4]],
    without: &[[f32; 4]],
) -> Result<(), String> {
    let (mut dark, mut bright) = (0, 0);
    for (row, y) in rows() {
        for (x, z) in [(-SIDE_X, 0.0), (SIDE_X, SIDE_Z)] {
            let i = pixel(x, y);
            if without[i][3] < 0.5 || without[i][0] < 1e-4 {
                continue; // no fiber here, or outside the spot's cone
            }
            let ratio = with[i][0] / without[i][0];
            let p = DVec3::new(x as f64, y as f64, z as f64);
            let (dir, length) = toward_light(light, p);
            let blocked = head
                .ray_hit(p.as_vec3(), dir.as_vec3(), length as f32)
                .is_some();
            assert_eq!(blocked, clearance(p, dir, length) < 0.0, "CPU references");
            if clearance(p, dir, length).abs() < EDGE_MARGIN {
                continue;
            }
            if blocked {
                if ratio >= 0.02 {
                    return Err(format!("row {row} x {x}: behind the head, T = {ratio}"));
                }
                dark += 1;
            } else {
                if (ratio - 1.0).abs() >= 0.02 {
                    return Err(format!(
                        "row {row} x {x}: in the open, {ratio} of the light without a head"
                    ));
                }
                bright += 1;
            }
        }
    }
    if dark > 10 && bright > 30 {
        Ok(())
    } else {
        Err(format!("{dark} dark, {bright} bright"))
    }
}

/// Every transparency mode: the fiber behind the head is not in the image where the eye ray
/// meets the head (the frame equals the one without that fiber there) and is where it sticks
/// out above and below.
#[test]
fn the_head_hides_the_fiber_behind_it_in_every_transparency_mode() {
    let gpu = gpu();
    let head = head();
    let lights = [Light::Directional {
        direction: Vec3::new(0.3, 0.2, 1.0),
        intensity: 1.0,
    }];
    let modes = [
        Transparency::Opaque,
        Transparency::Sorted { bins: 64 },
        Transparency::RandomSubsets { subsets: 4 },
        Transparency::KBuffer { k: 4 },
        Transparency::ABuffer {
            nodes_per_pixel: None,
        },
        Transparency::Dbk {
            nodes_per_pixel: None,
            delta: 0.1,
        },
    ];
    let [a, b] = bound_marks();
    let front_only = hair(&[fiber(-SIDE_X, 0.0), fiber(SIDE_X, SIDE_Z), a, b]);
    let mut failures = Vec::new();
    for mode in modes {
        let with = render(&gpu, &scene(), &lights, None, mode, Some(&head));
        let without_behind = render(&gpu, &front_only, &lights, None, mode, Some(&head));
        if let Err(e) = check_hidden(&with, &without_behind) {
            failures.push(format!("{mode:?}: {e}"));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Down the column of the fiber behind the head: `with` it equals `without_behind` where the eye
/// ray meets the head, and shows it where it sticks out above and below.
fn check_hidden(with: &[[f32; 4]], without_behind: &[[f32; 4]]) -> Result<(), String> {
    let (mut hidden, mut shown) = (0, 0);
    for (row, y) in rows() {
        let i = pixel(BEHIND_X, y);
        // Eye rays at this pixel meet the sphere when x² + y² < r² (minus a pixel's margin).
        let r = (BEHIND_X * BEHIND_X + y * y).sqrt();
        if r < RADIUS - 0.05 {
            if (0..4).any(|k| (with[i][k] - without_behind[i][k]).abs() >= 1e-5) {
                return Err(format!(
                    "row {row}: the fiber behind the head shows through: {:?} vs {:?}",
                    with[i], without_behind[i]
                ));
            }
            if with[i][3] <= 0.999 {
                return Err(format!("row {row}: the skin is not opaque: {:?}", with[i]));
            }
            hidden += 1;
        } else if r > RADIUS + 0.05 {
            if with[i][3] <= 0.5 || without_behind[i][3] != 0.0 {
                return Err(format!("row {row}: the fiber in the open is missing"));
            }
            shown += 1;
        }
    }
    if hidden > 15 && shown > 20 {
        Ok(())
    } else {
        Err(format!("{hidden} hidden, {shown} shown"))
    }
}

/// Skin pixels away from every fiber equal albedo/π · E on the sphere's analytic normal, E the
/// point light's I/d² · max(n·l, 0) or the directional light's I · max(n·l, 0), unshadowed and
/// under every technique (whose maps hold the head: the skin must not shadow itself).
#[test]
fn the_skin_is_lambertian_under_point_and_directional_lights() {
    let gpu = gpu();
    let head = head();
    let model = scene();
    let lights = [
        Light::Point {
            position: Vec3::new(0.3, 0.2, 1.5),
            intensity: 2.0,
        },
        Light::Directional {
            direction: Vec3::new(-0.2, 0.1, 0.9),
            intensity: 1.5,
        },
    ];
    let shadow_choices = std::iter::once(("unshadowed", None)).chain(
        techniques()
            .into_iter()
            .map(|(name, maps)| (name, Some(maps))),
    );
    let (mut worst, mut failures) = (0.0f64, Vec::new());
    for (technique, maps) in shadow_choices {
        for light in lights {
            let image = render(
                &gpu,
                &model,
                &[light],
                maps,
                Transparency::Opaque,
                Some(&head),
            );
            for (col, row) in [(32, 32), (40, 30), (25, 36), (38, 40), (28, 26), (30, 22)] {
                let (x, y) = centre(col, row);
                let z2 = RADIUS * RADIUS - x * x - y * y;
                assert!(z2 > 0.01);
                let p = DVec3::new(x as f64, y as f64, (z2 as f64).sqrt());
                let n = p.normalize();
                let (l, distance) = toward_light(&light, p);
                let irradiance = match light {
                    Light::Point { intensity, .. } => intensity as f64 / (distance * distance),
                    _ => 1.5,
                } * n.dot(l).max(0.0);
                assert!(n.dot(l) > 0.2, "probe ({col}, {row}) faces the light");
                let got = image[row * RES as usize + col];
                if (got[3] - 1.0).abs() > 1e-6 {
                    failures.push(format!("{technique}: skin is not opaque: {got:?}"));
                }
                for k in 0..3 {
                    let expected = SKIN[k] as f64 / std::f64::consts::PI * irradiance;
                    let error = (got[k] as f64 - expected).abs() / expected;
                    worst = worst.max(error);
                    // The tessellation's normals and positions and the f32 shader: 1 %.
                    if error > 0.01 {
                        failures.push(format!(
                            "{technique} {light:?}: pixel ({col}, {row}) channel {k}: {} vs \
                             {expected}",
                            got[k]
                        ));
                    }
                }
            }
        }
    }
    println!(
        "worst skin error against the closed form: {:.3} %",
        worst * 100.0
    );
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
