//! Several shadowed directional lights in one strand pass: each light is dimmed by its own deep
//! opacity map, checked against the closed-form transmittance of a slab of parallel strands,
//! (1 − d/s)^m after m rows of fibers of diameter d spaced s apart.

use crate::common::*;

use glam::Vec3;
use strandlight_runtime::gpu::{GpuContext, read_texture_rgba};
use strandlight_runtime::hair::{Attribute, HairModel};
use strandlight_runtime::lights::Light;
use strandlight_runtime::passes::deep_opacity::{DeepOpacityMap, DeepOpacityPass, DomSettings};
use strandlight_runtime::passes::frame_params::{FrameParams, KajiyaKay};
use strandlight_runtime::passes::render_target::RenderTarget;
use strandlight_runtime::passes::shadow_slots::{
    MAX_SHADOWED_LIGHTS, ShadowInput, TooManyShadowMaps,
};
use strandlight_runtime::passes::strand_geometry::StrandGeometry;
use strandlight_runtime::passes::strands::StrandPass;

fn map_of_slab(gpu: &GpuContext, rows: usize, thickness: f32) -> DeepOpacityMap {
    let geometry = StrandGeometry::upload(gpu, &slab(rows, thickness)).unwrap();
    let map = DeepOpacityMap::new(
        gpu,
        ortho_camera(),
        DomSettings {
            resolution: RES,
            layers: 4,
            spacing: 0.08,
        },
    );
    DeepOpacityPass::new(gpu).draw(gpu, &geometry, &map);
    map
}

/// Three lights from +z (intensities 1, 0.5, 0.25): light 0 behind a 4-row slab's map, light 2
/// behind a 2-row slab's map, light 1 unshadowed. A probe fiber behind both slabs (built from
/// the slabs alone, so the probe does not shadow itself) receives
/// 1·T⁴ + 0.5 + 0.25·T², T = 1 − d/s.
#[test]
fn each_shadowed_light_is_dimmed_by_its_own_map() {
    let gpu = GpuContext::new_headless().unwrap_or_else(|e| panic!("{e}"));
    let thickness = 0.01f32;
    let t = 1.0 - thickness as f64 * PER_UNIT;
    let four_rows = map_of_slab(&gpu, 4, thickness);
    let two_rows = map_of_slab(&gpu, 2, thickness);
    let color = Vec3::new(0.5, 0.3, 0.2);
    let probe = HairModel::new(
        vec![Vec3::new(-0.8, 0.5, -0.5), Vec3::new(0.8, 0.5, -0.5)],
        vec![0, 2],
        None,
        None,
        Some(Attribute::Uniform(color)),
    )
    .unwrap();
    let geometry = StrandGeometry::upload(&gpu, &probe).unwrap();
    let light = |intensity| Light::Directional {
        direction: Vec3::Z,
        intensity,
    };
    let frame = FrameParams {
        camera: ortho_camera(),
        width: RES,
        height: RES,
        lights: vec![light(1.0), light(0.5), light(0.25)],
        shading: KajiyaKay {
            kd: 0.6,
            ks: 0.25,
            shininess: 40.0,
        },
        width_override_px: Some(4.0),
    };
    let target = RenderTarget::new(&gpu, RES, RES);
    let pass = StrandPass::new(&gpu);
    pass.draw_shadowed(
        &gpu,
        &geometry,
        &frame,
        &target,
        &[
            ShadowInput {
                map: &two_rows,
                light_index: 2,
            },
            ShadowInput {
                map: &four_rows,
                light_index: 0,
            },
        ],
        None,
    )
    .unwrap();
    let pixels = read_texture_rgba(&gpu, &target.color).unwrap();
    let received = t.powi(4) + 0.5 + 0.25 * t.powi(2);
    // t = x, l = e = z: sin = 1, cone = 1, so L = E·(kd·c + ks) per light.
    let mut worst = 0.0f64;
    for x in 8..56usize {
        for y in [14usize, 15, 16] {
            let got = pixels[y * RES as usize + x];
            for (k, c) in [0.5f64, 0.3, 0.2].into_iter().enumerate() {
                let expected = received * (0.6 * c + 0.25);
                let err = (got[k] as f64 - expected).abs() / expected;
                worst = worst.max(err);
                assert!(
                    err < 1e-3,
                    "pixel ({x},{y}) channel {k}: {} vs {expected}",
                    got[k]
                );
            }
        }
    }
    eprintln!(
        "three lights, two shadow maps: received {received:.5} of unit light (T = {t:.4}); worst relative error {worst:.2e}"
    );

    // More maps than slots: a typed error, nothing drawn.
    let too_many: Vec<ShadowInput> = (0..=MAX_SHADOWED_LIGHTS as u32)
        .map(|i| ShadowInput {
            map: &two_rows,
            light_index: i,
        })
        .collect();
    assert_eq!(
        pass.draw_shadowed(&gpu, &geometry, &frame, &target, &too_many, None),
        Err(TooManyShadowMaps {
            maps: MAX_SHADOWED_LIGHTS + 1
        })
    );
}
