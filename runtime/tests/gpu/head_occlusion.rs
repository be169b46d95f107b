//! The head in the env-lit frame (issue 40) against answers worked out from the geometry alone:
//! the ray from a shaded point toward the light meets the sphere or not (`Head::ray_hit`, f64
//! roots), the ray from the eye reaches a fiber before the head or not, and the skin's radiance is
//! albedo/π × irradiance on the sphere's analytic normal (directional: the clamped cosine; SRBF:
//! `head::srbf_irradiance`, itself held to quadrature in the runtime's unit tests).
//!
//! Scene (orthographic camera looking down −z, 64², 32 pixels per unit): a head, the sphere of
//! radius 0.4 at the origin, and three vertical fibers (x, z) = (0.1, −0.6) behind the head from
//! the camera, (−0.7, 0) on its −x side and (0.7, −0.3) on its +x side. A light toward +x leaves the
//! part |y| < 0.4 of the −x fiber in the head's shadow and never shades the +x one.
//!
//! Shadows are read as the ratio of the shadowed frame to the unshadowed one at the same pixel,
//! so they test the transmittance the shader applied whatever the fiber shading.

use crate::common::*;

use glam::{DVec3, Vec3};
use strandlight_runtime::camera::Camera;
use strandlight_runtime::env::{EnvRenderOptions, EnvRenderer, EnvTables, ViewTransparency};
use strandlight_runtime::env_light::EnvLight;
use strandlight_runtime::gpu::GpuContext;
use strandlight_runtime::hair::HairModel;
use strandlight_runtime::head::{Head, HeadSurface, srbf_irradiance, tessellate_ellipsoid};
use strandlight_runtime::passes::convolution_depth::DodmSettings;
use strandlight_runtime::visibility::{LobeVisibility, VisibilityVolumeSettings};
use strandlight_tables::table::{Axis, AxisMapping, Table};
use strandlight_tables::table_axes::{
    AXIS_COS_DPHI, AXIS_INV_LAMBDA, AXIS_U_DOT_WO, AXIS_U_DOT_XI,
};

const RADIUS: f32 = HEAD_RADIUS;
const BEHIND_X: f32 = 0.1;
const SIDE_X: f32 = 0.7;
/// The +x fiber sits off the −x fiber's line toward +x (else it would shadow it).
const SIDE_Z: f32 = -0.3;
/// Light-map texels are 1/32 unit over the hair's ~2.6-unit diagonal at 128²: within two of the
/// head's silhouette from the light, rasterization decides, not geometry.
const EDGE_MARGIN: f64 = 0.08;
const SKIN: [f32; 3] = HEAD_SKIN;

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
    ])
}

/// A positive table with the convolution tables' axes (its values only scale the hair).
fn table(fourth: Axis) -> Table {
    let axes = vec![
        Axis::with_mapping(AXIS_U_DOT_XI, -1.0, 1.0, 5, AxisMapping::Arcsine),
        Axis::uniform(AXIS_U_DOT_WO, -1.0, 1.0, 5),
        Axis::with_mapping(AXIS_COS_DPHI, -1.0, 1.0, 4, AxisMapping::Arccosine),
        fourth,
    ];
    Table::from_fn(axes, 3, |x, out| {
        let v = (2.0 + x[0] + 0.5 * x[1] + 0.3 * x[2]) as f32;
        out.copy_from_slice(&[v, 0.8 * v, 0.6 * v]);
    })
    .unwrap()
}

fn tables() -> EnvTables {
    EnvTables {
        srbf: Some(table(Axis::uniform(AXIS_INV_LAMBDA, 0.0, 2.0, 5)).into()),
        direct: Some(table(Axis::uniform("direct", 0.0, 0.0, 1)).into()),
        multiple: None,
    }
}

fn options(shadowed: bool) -> EnvRenderOptions {
    EnvRenderOptions {
        dodm: DodmSettings {
            resolution: 128,
            first_layer: None,
            batch_size: 4,
        },
        kappa: 1.0,
        shadowed,
        ..Default::default()
    }
}

fn render(
    gpu: &GpuContext,
    model: &HairModel,
    lights: &[EnvLight],
    shadowed: bool,
    head: Option<&Head>,
) -> Vec<[f32; 4]> {
    render_with(gpu, model, lights, &options(shadowed), head)
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

#[test]
fn the_head_hides_the_fiber_behind_it_and_shows_skin() {
    let gpu = gpu();
    let lights = [EnvLight::directional(
        Vec3::new(0.3, 0.2, 1.0),
        [1.0, 1.0, 1.0],
    )];
    let head = head();
    let with = render(&gpu, &scene(), &lights, false, Some(&head));
    // The same frame without the fiber behind the head: where the head hides it, nothing
    // changes; where it sticks out above and below, it is there.
    let without_behind = render(
        &gpu,
        &hair(&[fiber(-SIDE_X, 0.0), fiber(SIDE_X, SIDE_Z)]),
        &lights,
        false,
        Some(&head),
    );
    let (mut hidden, mut shown) = (0, 0);
    for (row, y) in rows() {
        let i = pixel(BEHIND_X, y);
        // Eye rays at this pixel meet the sphere when x² + y² < r² (minus a pixel's margin).
        let r = (BEHIND_X * BEHIND_X + y * y).sqrt();
        if r < RADIUS - 0.05 {
            assert!(
                (0..4).all(|k| (with[i][k] - without_behind[i][k]).abs() < 1e-5),
                "row {row}: the fiber behind the head shows through: {:?} vs {:?}",
                with[i],
                without_behind[i]
            );
            hidden += 1;
        } else if r > RADIUS + 0.05 {
            assert!(
                with[i][3] > 0.5,
                "row {row}: the fiber in the open is missing"
            );
            assert!(without_behind[i][3] == 0.0, "row {row}");
            shown += 1;
        }
    }
    assert!(hidden > 15 && shown > 20, "{hidden} hidden, {shown} shown");
}

#[test]
fn the_skin_is_lambertian_under_a_directional_light_and_an_srbf() {
    let gpu = gpu();
    let head = head();
    let toward = Vec3::new(0.6, 0.0, 0.8);
    let lambda = 4.0f32;
    let cases = [
        (EnvLight::directional(toward, [2.0, 2.0, 2.0]), None),
        (
            EnvLight::srbf(toward, lambda, [1.5, 1.5, 1.5]),
            Some(lambda),
        ),
    ];
    // No fiber near the probed pixels: one far off in a corner.
    let model = hair(&[[Vec3::new(0.95, -0.95, 0.0), Vec3::new(0.95, -0.9, 0.0)]]);
    for (light, lambda) in cases {
        let amplitude = light.rgb[0] as f64;
        let image = render(&gpu, &model, &[light], false, Some(&head));
        let mut checked = 0;
        for (col, row) in [(32, 32), (40, 30), (25, 36), (38, 40), (28, 26)] {
            let (x, y) = centre(col, row);
            let z2 = RADIUS * RADIUS - x * x - y * y;
            assert!(z2 > 0.01);
            let n = DVec3::new(x as f64, y as f64, (z2 as f64).sqrt()).normalize();
            let c = n.dot(toward.normalize().as_dvec3());
            let irradiance = match lambda {
                None => amplitude * c.max(0.0),
                Some(l) => amplitude * srbf_irradiance(c, l as f64),
            };
            let p = image[row * RES as usize + col];
            assert!((p[3] - 1.0).abs() < 1e-6, "skin is opaque: {p:?}");
            for k in 0..3 {
                let expected = SKIN[k] as f64 / std::f64::consts::PI * irradiance;
                // The tessellation's normals and the f32 shader: 1 %.
                assert!(
                    (p[k] as f64 - expected).abs() <= 0.01 * expected + 1e-5,
                    "pixel ({col}, {row}) channel {k}: {} vs {expected} ({lambda:?})",
                    p[k]
                );
            }
            checked += 1;
        }
        assert_eq!(checked, 5);
    }
}

/// Directional light and an SRBF lobe, both toward +x: the −x fiber is dark exactly where the
/// ray toward the light meets the head, the +x fiber never.
#[test]
fn the_head_shadows_every_light_map_where_the_geometry_says() {
    let gpu = gpu();
    let head = head();
    let toward = DVec3::X;
    for light in [
        EnvLight::directional(toward.as_vec3(), [1.0; 3]),
        EnvLight::srbf(toward.as_vec3(), 300.0, [1.0; 3]),
    ] {
        let lights = [light];
        let lit = render(&gpu, &scene(), &lights, false, Some(&head));
        let shadowed = render(&gpu, &scene(), &lights, true, Some(&head));
        let no_head = render(&gpu, &scene(), &lights, true, None);
        let (mut dark, mut bright) = (0, 0);
        for (row, y) in rows() {
            for (x, z) in [(-SIDE_X, 0.0), (SIDE_X, SIDE_Z)] {
                let i = pixel(x, y);
                if lit[i][3] < 0.5 {
                    continue;
                }
                let ratio = shadowed[i][0] / lit[i][0];
                let p = Vec3::new(x, y, z);
                // The CPU reference: does the ray from the fiber toward the light meet the head,
                // and how far from its silhouette does it pass?
                let blocked = head.ray_hit(p, toward.as_vec3(), 10.0).is_some();
                let from_edge = ((y as f64).abs() - RADIUS as f64).abs();
                if from_edge < EDGE_MARGIN {
                    continue;
                }
                if blocked {
                    assert!(
                        ratio < 0.02,
                        "row {row} x {x}: behind the head, T = {ratio}"
                    );
                    dark += 1;
                } else {
                    assert!(ratio > 0.95, "row {row} x {x}: in the open, T = {ratio}");
                    bright += 1;
                }
                // Without the head nothing shadows a lone fiber.
                let free = no_head[i][0] / lit[i][0];
                assert!(free > 0.95, "row {row} x {x}: no head, T = {free}");
            }
        }
        assert!(dark > 15 && bright > 40, "{dark} dark, {bright} bright");
    }
}

/// A screen of fibers at x = 0.5 across z, between the head and a light from +x.
fn screen() -> HairModel {
    let fibers: Vec<[Vec3; 2]> = (0..13)
        .map(|k| fiber(0.5, -0.3 + 0.05 * k as f32))
        .collect();
    hair(&fibers)
}

fn with_volume(shadowed: bool) -> EnvRenderOptions {
    EnvRenderOptions {
        lobe_visibility: LobeVisibility::Volume(VisibilityVolumeSettings::default()),
        ..options(shadowed)
    }
}

fn render_with(
    gpu: &GpuContext,
    model: &HairModel,
    lights: &[EnvLight],
    options: &EnvRenderOptions,
    head: Option<&Head>,
) -> Vec<[f32; 4]> {
    let camera: Camera = ortho_camera();
    EnvRenderer::new(gpu)
        .render_part(
            gpu,
            model,
            &camera,
            RES,
            RES,
            (lights, 0),
            &tables(),
            options,
            None,
            head,
        )
        .unwrap_or_else(|e| panic!("{e}"))
        .pixels
}

/// The skin seen through the visibility volume: where a screen of fibers stands between it and
/// an SRBF lobe, it is in shadow as in the lobe's light map (less deep: the volume's 16 SH
/// coefficients smooth an opaque screen to about a third of the light), and a mesh head
/// (brute-force rays, `contains` by parity) builds the volume the ellipsoid it tessellates
/// builds. Fails when the skin's volume lookup is lifted by the placeholder light map's texel
/// (0.6 units here, past the screen: the skin read the unshadowed lobe).
#[test]
fn the_skin_under_fibers_is_shadowed_through_the_volume_and_a_mesh_head_agrees() {
    let gpu = gpu();
    let ellipsoid = head();
    let mesh = Head {
        surface: HeadSurface::Mesh(tessellate_ellipsoid(Vec3::ZERO, Vec3::splat(RADIUS))),
        albedo: SKIN,
    };
    let lights = [EnvLight::srbf(Vec3::X, 300.0, [1.0; 3])];
    let model = screen();
    let maps = render_with(&gpu, &model, &lights, &options(true), Some(&ellipsoid));
    let volume = render_with(&gpu, &model, &lights, &with_volume(true), Some(&ellipsoid));
    let volume_mesh = render_with(&gpu, &model, &lights, &with_volume(true), Some(&mesh));
    let open = render_with(&gpu, &model, &lights, &with_volume(false), Some(&ellipsoid));
    // Skin facing the light: x in 0.25..0.35 (n·x ≥ 0.6), rows near y = 0.
    let (mut n, mut sums) = (0, [0.0f64; 4]);
    for (_, y) in rows().filter(|(_, y)| y.abs() < 0.15) {
        for x in [0.27f32, 0.3, 0.33] {
            let i = pixel(x, y);
            for (sum, image) in sums.iter_mut().zip([&maps, &volume, &volume_mesh, &open]) {
                *sum += image[i][0] as f64;
            }
            n += 1;
        }
    }
    let [maps, volume, volume_mesh, open] = sums.map(|s| s / n as f64);
    println!(
        "skin facing the lobe: light maps {maps:.4}, volume {volume:.4}, mesh head {volume_mesh:.4}, unshadowed {open:.4}"
    );
    assert!(open > 0.0);
    assert!(
        maps < 0.7 * open,
        "the screen shadows the skin in the light map: {maps} of {open}"
    );
    assert!(
        volume < 0.5 * open,
        "the screen shadows the skin through the volume: {volume} of {open}"
    );
    assert!(
        (volume_mesh - volume).abs() < 0.05 * volume.max(0.05 * open),
        "mesh head {volume_mesh} against the ellipsoid {volume}"
    );
}

/// Light maps fitted to a compact source's footprint (4167e3b) hold the head as well as the
/// hair (9d6a30f): here the hair is one short fiber on the head's −x side, x = −0.9 and |y| ≤ 0.25,
/// so under a sun toward +x the head lies wholly outside the hair's extent (across the light and
/// along it), between it and the sun. The fiber is still in the head's shadow, and the skin facing
/// the sun is lit. With the sun toward −x behind a screen of fibers, the skin facing it is in the
/// screen's shadow. Seen failing with the head left out of the footprint's box
/// (`frame_resources::light_footprint`), as it was until this test: the map's depth range held
/// only the hair, the head was clipped from the fiber's map and cast no shadow (T = 1).
#[test]
fn a_head_outside_the_hairs_footprint_casts_and_receives_a_suns_shadow() {
    // The layered view gathers a compact source's visibility per layer in a pass of its own,
    // whose head filter is compiled in only for frames with a head (seen failing, T = 1 behind
    // the head, with the gather's pipeline without it).
    for transparency in [ViewTransparency::Opaque, ViewTransparency::layered()] {
        head_and_suns_shadows_in(transparency);
    }
}

fn head_and_suns_shadows_in(transparency: ViewTransparency) {
    let gpu = gpu();
    let render = |gpu: &GpuContext, model: &HairModel, lights: &[EnvLight], shadowed, head| {
        let options = EnvRenderOptions {
            transparency,
            ..options(shadowed)
        };
        render_with(gpu, model, lights, &options, head)
    };
    let head = head();
    let toward = DVec3::X;
    let sun = [EnvLight::directional(toward.as_vec3(), [1.0; 3])];
    assert!(
        sun[0].has_sharp_shadow(),
        "a compact source, whose maps are fitted"
    );
    const FIBER_X: f32 = -0.9;
    const HALF_LENGTH: f32 = 0.25;
    let lone = hair(&[[
        Vec3::new(FIBER_X, -HALF_LENGTH, 0.0),
        Vec3::new(FIBER_X, HALF_LENGTH, 0.0),
    ]]);
    let lit = render(&gpu, &lone, &sun, false, Some(&head));
    let shadowed = render(&gpu, &lone, &sun, true, Some(&head));
    let no_head = render(&gpu, &lone, &sun, true, None);
    let mut dark = 0;
    for (row, y) in rows().filter(|(_, y)| y.abs() < HALF_LENGTH - 0.05) {
        let i = pixel(FIBER_X, y);
        assert!(lit[i][3] > 0.5, "row {row}: the fiber is drawn");
        let p = Vec3::new(FIBER_X, y, 0.0);
        assert!(head.ray_hit(p, toward.as_vec3(), 10.0).is_some());
        let ratio = shadowed[i][0] / lit[i][0];
        assert!(
            ratio < 0.02,
            "{transparency:?}, row {row}: behind the head, T = {ratio}"
        );
        let free = no_head[i][0] / lit[i][0];
        assert!(
            free > 0.95,
            "{transparency:?}, row {row}: no head, T = {free}"
        );
        dark += 1;
    }
    assert!(dark > 10, "{dark} rows");
    let facing = |image: &[[f32; 4]], x: f32| -> f64 {
        let rows = rows().filter(|(_, y)| y.abs() < 0.15);
        let values: Vec<f64> = rows.map(|(_, y)| image[pixel(x, y)][0] as f64).collect();
        values.iter().sum::<f64>() / values.len() as f64
    };
    let skin_lit = facing(&shadowed, 0.3) / facing(&lit, 0.3);
    assert!(skin_lit > 0.95, "the skin facing the sun, T = {skin_lit}");

    let away = [EnvLight::directional(-toward.as_vec3(), [1.0; 3])];
    let screen = hair(
        &(0..13)
            .map(|k| fiber(-0.5, -0.3 + 0.05 * k as f32))
            .collect::<Vec<_>>(),
    );
    let open = render(&gpu, &screen, &away, false, Some(&head));
    let behind = render(&gpu, &screen, &away, true, Some(&head));
    let skin_behind = facing(&behind, -0.3) / facing(&open, -0.3);
    println!(
        "{dark} fiber rows in the head's shadow; skin facing the sun T = {skin_lit:.3}, behind \
         the screen T = {skin_behind:.3}"
    );
    assert!(
        skin_behind < 0.1,
        "the screen shadows the skin, T = {skin_behind}"
    );
}
