//! Shadow maps and ADSM through the strand pass's own lookup, against independent CPU answers:
//! with a 1-texel kernel a shadow map must equal a hard shadow test (does the ray from the shaded
//! point toward the light pass within a fiber's radius of an occluder's axis?), for a tilted
//! directional light and for a point light; ADSM must equal TressFX's fiber count computed from
//! the geometry, (1 − α)^(1 + (depth behind the occluder − bias) / spacing).
//!
//! Occluders: three thick horizontal fibers (along x) at z = 0.3. Receiver: a vertical fiber at
//! x = 0.3, z = −0.5, seen by the orthographic test camera from +z. The maps are built from the
//! occluders alone, so the receiver never shadows itself.

use crate::common::*;

use glam::Vec3;
use strandlight_runtime::camera::{Camera, light_camera, point_light_camera};
use strandlight_runtime::gpu::{GpuContext, read_texture_rgba};
use strandlight_runtime::hair::{Aabb, Attribute, HairModel};
use strandlight_runtime::lights::Light;
use strandlight_runtime::passes::deep_opacity::{DeepOpacityMap, DeepOpacityPass, ShadowLookup};
use strandlight_runtime::passes::frame_params::{FrameParams, KajiyaKay};
use strandlight_runtime::passes::render_target::RenderTarget;
use strandlight_runtime::passes::shadow_slots::ShadowInput;
use strandlight_runtime::passes::strand_geometry::StrandGeometry;
use strandlight_runtime::passes::strands::StrandPass;

const OCCLUDER_Z: f32 = 0.3;
const OCCLUDER_YS: [f32; 3] = [-0.5, 0.0, 0.4];
const OCCLUDER_THICKNESS: f32 = 0.2;
const OCCLUDER_HALF_LENGTH: f32 = 0.9;
const RECEIVER_X: f32 = 0.3;
const RECEIVER_Z: f32 = -0.5;
const MAP_RES: u32 = 128;

fn occluders() -> HairModel {
    let points = OCCLUDER_YS
        .iter()
        .flat_map(|&y| {
            [
                Vec3::new(-OCCLUDER_HALF_LENGTH, y, OCCLUDER_Z),
                Vec3::new(OCCLUDER_HALF_LENGTH, y, OCCLUDER_Z),
            ]
        })
        .collect();
    HairModel::new(
        points,
        vec![0, 2, 4, 6],
        Some(Attribute::Uniform(OCCLUDER_THICKNESS)),
        None,
        None,
    )
    .unwrap()
}

fn receiver() -> HairModel {
    HairModel::new(
        vec![
            Vec3::new(RECEIVER_X, -0.9, RECEIVER_Z),
            Vec3::new(RECEIVER_X, 0.9, RECEIVER_Z),
        ],
        vec![0, 2],
        None,
        None,
        Some(Attribute::Uniform(Vec3::new(0.5, 0.4, 0.3))),
    )
    .unwrap()
}

/// Both the occluders and the receiver: what every light map must cover.
fn scene_bounds() -> Aabb {
    Aabb {
        min: Vec3::new(-1.0, -1.0, RECEIVER_Z - 0.1),
        max: Vec3::new(1.0, 1.0, OCCLUDER_Z + 0.1),
    }
}

/// The world point under pixel (x, y) of the receiver (the test camera looks along −z, so the
/// receiver's quad lies in its plane z = RECEIVER_Z).
fn receiver_point(x: usize, y: usize) -> Vec3 {
    let per_unit = PER_UNIT as f32;
    Vec3::new(
        (x as f32 + 0.5) / per_unit - 1.0,
        1.0 - (y as f32 + 0.5) / per_unit,
        RECEIVER_Z,
    )
}

/// The receiver's pixel columns wholly inside its 4-pixel quad.
fn receiver_columns() -> std::ops::Range<usize> {
    let centre = ((RECEIVER_X + 1.0) * PER_UNIT as f32) as usize;
    centre - 1..centre + 1
}

/// For the ray from `p` along `toward_light`: the distance of its closest approach to each
/// occluder's axis, where that approach lies between p and the light and within the
/// occluder's length; the smallest one, with that occluder's axis height y.
fn nearest_occluder(p: Vec3, toward_light: Vec3) -> (f32, f32) {
    OCCLUDER_YS
        .iter()
        .filter_map(|&y| {
            let a = Vec3::new(0.0, y, OCCLUDER_Z);
            // Where the ray crosses the occluders' plane z = OCCLUDER_Z.
            let t = (OCCLUDER_Z - p.z) / toward_light.z;
            let crossing = p + toward_light * t;
            if t <= 0.0 || crossing.x.abs() > OCCLUDER_HALF_LENGTH - 0.05 {
                return None;
            }
            let n = toward_light.cross(Vec3::X);
            Some((((p - a).dot(n) / n.length()).abs(), y))
        })
        .fold(
            (f32::INFINITY, f32::NAN),
            |a, b| if b.0 < a.0 { b } else { a },
        )
}

fn nearest_occluder_distance(p: Vec3, toward_light: Vec3) -> f32 {
    nearest_occluder(p, toward_light).0
}

struct Probe {
    gpu: GpuContext,
    pass: StrandPass,
    occluders: StrandGeometry,
    receiver: StrandGeometry,
}

impl Probe {
    fn new() -> Self {
        let gpu = gpu();
        let pass = StrandPass::new(&gpu);
        let occluders = StrandGeometry::upload(&gpu, &occluders()).unwrap();
        let receiver = StrandGeometry::upload(&gpu, &receiver()).unwrap();
        Self {
            gpu,
            pass,
            occluders,
            receiver,
        }
    }

    /// The receiver's pixels under `light`, shadowed through `map` (None: unshadowed).
    fn render(&self, light: Light, map: Option<&DeepOpacityMap>) -> Vec<[f32; 4]> {
        let frame = FrameParams {
            camera: ortho_camera(),
            width: RES,
            height: RES,
            lights: vec![light],
            shading: KajiyaKay {
                kd: 0.6,
                ks: 0.25,
                shininess: 40.0,
            },
            width_override_px: Some(4.0),
        };
        let target = RenderTarget::new(&self.gpu, RES, RES);
        let shadow = map.map(|map| ShadowInput {
            map,
            light_index: 0,
        });
        self.pass
            .draw(&self.gpu, &self.receiver, &frame, &target, shadow);
        read_texture_rgba(&self.gpu, &target.color).unwrap()
    }

    /// The map of `lookup` from `camera`, drawn from the occluders.
    fn map(&self, camera: Camera, lookup: ShadowLookup) -> DeepOpacityMap {
        let map = DeepOpacityMap::depth_only(&self.gpu, camera, MAP_RES, lookup).unwrap();
        DeepOpacityPass::new(&self.gpu).draw(&self.gpu, &self.occluders, &map);
        map
    }

    /// Per receiver pixel: its world point and the transmittance the shader applied
    /// (shadowed / unshadowed red channel).
    fn transmittance(&self, light: Light, map: &DeepOpacityMap) -> Vec<(Vec3, f32)> {
        let lit = self.render(light, None);
        let shadowed = self.render(light, Some(map));
        let mut out = Vec::new();
        for y in 3..59 {
            for x in receiver_columns() {
                let i = y * RES as usize + x;
                assert!(
                    lit[i][0] > 1e-3,
                    "pixel ({x},{y}) of the receiver is not lit"
                );
                out.push((receiver_point(x, y), shadowed[i][0] / lit[i][0]));
            }
        }
        out
    }
}

fn toward(light: &Light, p: Vec3) -> Vec3 {
    match *light {
        Light::Directional { direction, .. } => direction.normalize(),
        Light::Point { position, .. } | Light::Spot { position, .. } => (position - p).normalize(),
    }
}

#[test]
fn a_one_texel_shadow_map_equals_the_hard_shadow_test() {
    let probe = Probe::new();
    let bounds = scene_bounds();
    let directional = Vec3::new(0.0, 0.3, 1.0).normalize();
    let point = Vec3::new(0.2, 1.5, 5.0);
    let cases = [
        (
            "directional",
            Light::Directional {
                direction: directional,
                intensity: 1.0,
            },
            light_camera(directional, bounds),
        ),
        (
            "point",
            Light::Point {
                position: point,
                intensity: 30.0,
            },
            point_light_camera(point, bounds).unwrap(),
        ),
    ];
    let lookup = ShadowLookup::Hard {
        kernel: 1,
        bias: 0.02,
    };
    for (name, light, camera) in cases {
        let map = probe.map(camera, lookup);
        let (mut shadowed, mut lit, mut skipped) = (0, 0, 0);
        for (p, t) in probe.transmittance(light, &map) {
            let distance = nearest_occluder_distance(p, toward(&light, p));
            // Within a map texel or so of an occluder's edge the answer depends on rasterization.
            if (distance - OCCLUDER_THICKNESS / 2.0).abs() < 0.05 {
                skipped += 1;
                continue;
            }
            let expected = if distance < OCCLUDER_THICKNESS / 2.0 {
                shadowed += 1;
                0.0
            } else {
                lit += 1;
                1.0
            };
            assert!(
                (t - expected).abs() < 1e-4,
                "{name}: receiver point {p}: transmittance {t}, the hard shadow test says {expected} (ray passes {distance} from an occluder axis)"
            );
        }
        eprintln!(
            "{name}: {shadowed} shadowed and {lit} lit pixels agree; {skipped} at edges skipped"
        );
        assert!(
            shadowed >= 12 && lit >= 12,
            "{name}: too few decided pixels"
        );
    }
}

#[test]
fn adsm_counts_fibers_behind_the_nearest_one() {
    let probe = Probe::new();
    let toward_light = Vec3::new(0.0, 0.3, 1.0).normalize();
    let (alpha, spacing, bias) = (0.3f32, 0.1f32, 0.05f32);
    let lookup = ShadowLookup::Adsm {
        kernel: 1,
        bias,
        alpha,
        spacing,
    };
    let map = probe.map(light_camera(toward_light, scene_bounds()), lookup);
    let light = Light::Directional {
        direction: toward_light,
        intensity: 1.0,
    };
    let mut worst = 0.0f32;
    let mut shadowed = 0;
    for (p, t) in probe.transmittance(light, &map) {
        let (distance, occluder_y) = nearest_occluder(p, toward_light);
        if (distance - OCCLUDER_THICKNESS / 2.0).abs() < 0.05 {
            continue;
        }
        let expected = if distance < OCCLUDER_THICKNESS / 2.0 {
            shadowed += 1;
            // The occluders' quads face the light: every point of one lies at its axis's depth.
            let behind = (Vec3::new(0.0, occluder_y, OCCLUDER_Z) - p).dot(toward_light);
            (1.0 - alpha).powf(1.0 + (behind - bias) / spacing)
        } else {
            1.0
        };
        let error = (t - expected).abs() / expected;
        worst = worst.max(error);
        assert!(
            error < 2e-3,
            "receiver point {p}: ADSM transmittance {t}, TressFX's count gives {expected}"
        );
    }
    eprintln!("ADSM: {shadowed} shadowed pixels; worst relative error {worst:.2e}");
    assert!(shadowed >= 12);
}

#[test]
fn pcf_softens_the_edge_between_the_hard_answers() {
    let probe = Probe::new();
    let toward_light = Vec3::new(0.0, 0.3, 1.0).normalize();
    let light = Light::Directional {
        direction: toward_light,
        intensity: 1.0,
    };
    let camera = light_camera(toward_light, scene_bounds());
    let hard = probe.transmittance(
        light,
        &probe.map(
            camera,
            ShadowLookup::Hard {
                kernel: 1,
                bias: 0.02,
            },
        ),
    );
    let soft = probe.transmittance(
        light,
        &probe.map(
            camera,
            ShadowLookup::Hard {
                kernel: 5,
                bias: 0.02,
            },
        ),
    );
    let mut partial = 0;
    for ((p, h), (_, s)) in hard.iter().zip(&soft) {
        assert!((0.0..=1.0).contains(s), "{p}: PCF transmittance {s}");
        // Deep inside a shadow or far from one, 5×5 texels all agree with the hard answer.
        let distance = nearest_occluder_distance(*p, toward_light);
        if (distance - OCCLUDER_THICKNESS / 2.0).abs() > 0.1 {
            assert!(
                (s - h).abs() < 1e-4,
                "{p}: PCF {s} vs hard {h} away from any edge"
            );
        }
        if *s > 0.01 && *s < 0.99 {
            partial += 1;
        }
    }
    assert!(
        partial >= 4,
        "PCF left only {partial} partially lit pixels at the shadow edges"
    );
}

#[test]
fn bad_lookups_and_a_light_inside_the_hair_are_refused() {
    let gpu = gpu();
    let camera = ortho_camera();
    for lookup in [
        ShadowLookup::Hard {
            kernel: 2,
            bias: 0.0,
        },
        ShadowLookup::Hard {
            kernel: 11,
            bias: 0.0,
        },
        ShadowLookup::Hard {
            kernel: 3,
            bias: f32::NAN,
        },
        ShadowLookup::Adsm {
            kernel: 3,
            bias: 0.0,
            alpha: 1.0,
            spacing: 0.1,
        },
        ShadowLookup::Adsm {
            kernel: 3,
            bias: 0.0,
            alpha: 0.5,
            spacing: 0.0,
        },
    ] {
        assert!(
            DeepOpacityMap::depth_only(&gpu, camera, 64, lookup).is_err(),
            "{lookup:?}"
        );
    }
    let inside = point_light_camera(Vec3::ZERO, scene_bounds());
    let message = inside.unwrap_err().to_string();
    assert!(message.contains("light at"), "{message}");
}
