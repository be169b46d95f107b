//! Deep opacity maps against the closed form for a slab of parallel strands: rows of fibers of
//! diameter d spaced s apart, each row at an independent lateral offset, transmit (1 − d/s)
//! per row, so the light reaching depth m rows in is (1 − d/s)^m.

use crate::common::*;

use glam::Vec3;
use strandlight_runtime::camera::{Camera, Projection};
use strandlight_runtime::gpu::GpuContext;
use strandlight_runtime::gpu::read_texture_rgba;
use strandlight_runtime::hair::{Attribute, HairModel};
use strandlight_runtime::lights::Light;
use strandlight_runtime::passes::deep_opacity::{
    DeepOpacityMap, DeepOpacityPass, DomSettings, MAX_LAYERS, ShadowLookupError,
    transmittance_before_layer,
};
use strandlight_runtime::passes::frame_params::{FrameParams, KajiyaKay};
use strandlight_runtime::passes::render_target::RenderTarget;
use strandlight_runtime::passes::shadow_slots::ShadowInput;
use strandlight_runtime::passes::strand_geometry::StrandGeometry;
use strandlight_runtime::passes::strands::StrandPass;

#[test]
fn slab_of_parallel_strands_matches_the_closed_form() {
    let gpu = GpuContext::new_headless().unwrap_or_else(|e| panic!("{e}"));
    let thickness = 0.01f32;
    let coverage = thickness as f64 * PER_UNIT; // d/s = 0.32
    let rows = 4;
    let model = slab(rows, thickness);
    let geometry = StrandGeometry::upload(&gpu, &model).unwrap();
    let pass = DeepOpacityPass::new(&gpu);
    // Rows lie 0.1 apart; with spacing 0.08 they fall at 0, 1.25, 2.5, 3.75 layers behind the
    // nearest fiber. K = 3: the last layer takes rows 2 and 3. K = 8: one row per layer 0..3.
    for (layers, expected_rows_per_layer) in [
        (3u32, vec![1.0, 1.0, 2.0]),
        (8, vec![1.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0]),
    ] {
        let settings = DomSettings {
            resolution: RES,
            layers,
            spacing: 0.08,
        };
        settings.check().unwrap();
        let map = DeepOpacityMap::new(&gpu, ortho_camera(), settings);
        pass.draw(&gpu, &geometry, &map);
        let texels = map.read_layers(&gpu).unwrap();
        let tau_row = -(1.0 - coverage).ln();
        let mut worst_t = 0.0f64;
        let mut checked = 0;
        for ty in 8..56usize {
            for tx in 2..62usize {
                let t = &texels[ty * RES as usize + tx];
                for (k, &rows_in_layer) in expected_rows_per_layer.iter().enumerate() {
                    let expected = rows_in_layer * tau_row;
                    assert!(
                        (t[k] as f64 - expected).abs() < 1e-4,
                        "K={layers} texel ({tx},{ty}) layer {k}: {} vs {expected}",
                        t[k]
                    );
                }
                // Transmittance in front of each layer and behind the whole slab.
                let mut rows_before = 0.0;
                for k in 0..=expected_rows_per_layer.len() {
                    let closed = (1.0 - coverage).powf(rows_before);
                    let dom = transmittance_before_layer(t, k);
                    worst_t = worst_t.max((dom - closed).abs() / closed);
                    if k < expected_rows_per_layer.len() {
                        rows_before += expected_rows_per_layer[k];
                    }
                }
                checked += 1;
            }
        }
        let sample = &texels[32 * RES as usize + 32];
        eprintln!(
            "K={layers}: {checked} texels; layers at the centre {sample:?} (τ per row {tau_row:.5}); \
             behind the slab exp(−Στ) = {:.5} vs (1 − d/s)^{rows} = {:.5}; worst relative transmittance error {worst_t:.2e}",
            transmittance_before_layer(sample, sample.len()),
            (1.0 - coverage).powi(rows as i32)
        );
        assert!(worst_t < 1e-3);
    }
}

/// Opacity shadow maps: the slab's rows (z = 0.3 … 0.0, 0.1 apart) over 8 equal slices of its
/// 0.3 depth range fall at slices 0, 2.67, 5.33 and 8 (the far bound, clamped into the last),
/// so slices 0, 2, 5 and 7 each hold one row's optical depth and the rest none, whatever a
/// texel's nearest fiber; the transmittance in front of each slice is the closed form.
#[test]
fn opacity_slices_span_the_hair_depth_range_and_match_the_closed_form() {
    let gpu = GpuContext::new_headless().unwrap_or_else(|e| panic!("{e}"));
    let thickness = 0.01f32;
    let coverage = thickness as f64 * PER_UNIT;
    let model = slab(4, thickness);
    let geometry = StrandGeometry::upload(&gpu, &model).unwrap();
    let map = DeepOpacityMap::opacity_slices(&gpu, ortho_camera(), model.bounds(), RES, 8).unwrap();
    assert!(
        (map.settings.spacing - 0.3 / 8.0).abs() < 1e-6,
        "{:?}",
        map.settings
    );
    DeepOpacityPass::new(&gpu).draw(&gpu, &geometry, &map);
    let texels = map.read_layers(&gpu).unwrap();
    let rows_per_slice = [1.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 1.0];
    let tau_row = -(1.0 - coverage).ln();
    let mut worst_t = 0.0f64;
    for ty in 8..56usize {
        for tx in 2..62usize {
            let t = &texels[ty * RES as usize + tx];
            let mut rows_before = 0.0;
            for (k, &rows) in rows_per_slice.iter().enumerate() {
                assert!(
                    (t[k] as f64 - rows * tau_row).abs() < 1e-4,
                    "texel ({tx},{ty}) slice {k}: {} vs {}",
                    t[k],
                    rows * tau_row
                );
                let closed = (1.0 - coverage).powf(rows_before);
                worst_t = worst_t.max((transmittance_before_layer(t, k) - closed).abs() / closed);
                rows_before += rows;
            }
        }
    }
    eprintln!("OSM 8 slices: worst relative transmittance error in front of a slice {worst_t:.2e}");
    assert!(worst_t < 1e-3);
    // Slices are checked like layers: more than the layer array holds is refused.
    assert!(
        DeepOpacityMap::opacity_slices(&gpu, ortho_camera(), model.bounds(), RES, MAX_LAYERS + 1)
            .is_err()
    );
}

#[test]
fn bad_settings_are_refused() {
    assert!(
        DomSettings {
            resolution: 64,
            layers: MAX_LAYERS + 1,
            spacing: 0.1
        }
        .check()
        .is_err()
    );
    assert!(
        DomSettings {
            resolution: 64,
            layers: 4,
            spacing: 0.0
        }
        .check()
        .is_err()
    );
    assert!(
        DomSettings {
            resolution: 0,
            layers: 4,
            spacing: 0.1
        }
        .check()
        .is_err()
    );
}

/// The strand pass reads the map: a horizontal probe fiber behind the slab (all four rows
/// between it and the light) is lit by (1 − d/s)^4 of the light; one in front of it by all of
/// it. The map is built from the slab alone so the probe does not shadow itself.
#[test]
fn shading_behind_the_slab_is_dimmed_by_the_closed_form_transmittance() {
    let gpu = GpuContext::new_headless().unwrap_or_else(|e| panic!("{e}"));
    let thickness = 0.01f32;
    let coverage = thickness as f64 * PER_UNIT;
    let slab_model = slab(4, thickness);
    let slab_geometry = StrandGeometry::upload(&gpu, &slab_model).unwrap();
    let dom = DeepOpacityMap::new(
        &gpu,
        ortho_camera(),
        DomSettings {
            resolution: RES,
            layers: 4,
            spacing: 0.08,
        },
    );
    let osm =
        DeepOpacityMap::opacity_slices(&gpu, ortho_camera(), slab_model.bounds(), RES, 8).unwrap();
    for map in [&dom, &osm] {
        DeepOpacityPass::new(&gpu).draw(&gpu, &slab_geometry, map);
    }

    let color = Vec3::new(0.5, 0.3, 0.2);
    let shading = KajiyaKay {
        kd: 0.6,
        ks: 0.25,
        shininess: 40.0,
    };
    let strand_pass = StrandPass::new(&gpu);
    let cases = [(-0.5f32, (1.0 - coverage).powi(4)), (0.5, 1.0)];
    for ((z, expected_t), (name, map)) in cases
        .into_iter()
        .flat_map(|c| [(c, ("DOM", &dom)), (c, ("OSM", &osm))])
    {
        // Along x at y = 0.5 (image row 16 ± 2 px): probe covers pixel rows 14..=17, columns 7..=56.
        let probe = HairModel::new(
            vec![Vec3::new(-0.8, 0.5, z), Vec3::new(0.8, 0.5, z)],
            vec![0, 2],
            None,
            None,
            Some(Attribute::Uniform(color)),
        )
        .unwrap();
        let geometry = StrandGeometry::upload(&gpu, &probe).unwrap();
        let frame = FrameParams {
            camera: ortho_camera(),
            width: RES,
            height: RES,
            lights: vec![Light::Directional {
                direction: Vec3::Z,
                intensity: 1.0,
            }],
            shading,
            width_override_px: Some(4.0),
        };
        let target = RenderTarget::new(&gpu, RES, RES);
        strand_pass.draw(
            &gpu,
            &geometry,
            &frame,
            &target,
            Some(ShadowInput {
                map,
                light_index: 0,
            }),
        );
        let pixels = read_texture_rgba(&gpu, &target.color).unwrap();
        // t = x, l = e = z: sin = 1, cone = 1, so L = T·(kd·c + ks).
        let mut worst = 0.0f64;
        for x in 8..56usize {
            for y in [14usize, 15, 16] {
                let got = pixels[y * RES as usize + x];
                for (k, c) in [0.5f64, 0.3, 0.2].into_iter().enumerate() {
                    let expected = expected_t * (0.6 * c + 0.25);
                    let err = (got[k] as f64 - expected).abs() / expected;
                    worst = worst.max(err);
                    assert!(
                        err < 1e-3,
                        "{name}: probe z {z} pixel ({x},{y}) channel {k}: {} vs {expected}",
                        got[k]
                    );
                }
            }
        }
        eprintln!(
            "{name}: probe at z = {z}: transmittance {expected_t:.5} expected; worst relative error of the shaded pixels {worst:.2e}"
        );
    }
}

/// Light a probe fiber receives through `map`, as the strand pass shades it: one horizontal
/// probe per depth in `depths`, each on its own image row (map texels and pixels coincide), read
/// back as the shaded value over the unshadowed one, averaged along the row.
fn probe_transmittances(gpu: &GpuContext, map: &DeepOpacityMap, depths: &[f32]) -> Vec<f64> {
    let color = Vec3::new(0.5, 0.3, 0.2);
    // Pixel row r's centre: y = 1 − (r + 0.5)/32; probes 4 rows apart, all over the slab.
    let rows: Vec<usize> = (0..depths.len()).map(|m| 8 + 4 * m).collect();
    let mut points = Vec::new();
    let mut offsets = vec![0u32];
    for (&row, &z) in rows.iter().zip(depths) {
        let y = 1.0 - (row as f32 + 0.5) / PER_UNIT as f32;
        points.extend([Vec3::new(-0.8, y, z), Vec3::new(0.8, y, z)]);
        offsets.push(points.len() as u32);
    }
    let probes =
        HairModel::new(points, offsets, None, None, Some(Attribute::Uniform(color))).unwrap();
    let geometry = StrandGeometry::upload(gpu, &probes).unwrap();
    let frame = FrameParams {
        camera: ortho_camera(),
        width: RES,
        height: RES,
        lights: vec![Light::Directional {
            direction: Vec3::Z,
            intensity: 1.0,
        }],
        shading: KajiyaKay {
            kd: 0.6,
            ks: 0.25,
            shininess: 40.0,
        },
        width_override_px: Some(3.0),
    };
    let target = RenderTarget::new(gpu, RES, RES);
    StrandPass::new(gpu).draw(
        gpu,
        &geometry,
        &frame,
        &target,
        Some(ShadowInput {
            map,
            light_index: 0,
        }),
    );
    let pixels = read_texture_rgba(gpu, &target.color).unwrap();
    // t = x, l = e = z: L = T·(kd·c + ks) per channel; the red channel.
    let unshadowed = 0.6 * 0.5 + 0.25;
    rows.iter()
        .map(|&row| {
            let sum: f64 = (8..56usize)
                .map(|x| pixels[row * RES as usize + x][0] as f64)
                .sum();
            sum / 48.0 / unshadowed
        })
        .collect()
}

/// Kim 2003's opacity shadow maps converge to the deep opacity map, and both to the slab's
/// closed form, inside a slab 12 rows deep: a probe midway between rows m and m + 1 receives
/// (1 − d/s)^(m+1). Few slices are thick, and the lookup spreads a slice's opacity over its
/// depth, so the rows a probe shares a slice with shadow it only in part; as slices thin that
/// error vanishes. DOM layers start at the slab's first row and, 0.04 apart, put every row in a
/// layer wholly in front of the next probe.
#[test]
fn opacity_slices_converge_to_deep_opacity_and_the_closed_form_inside_a_slab() {
    let gpu = GpuContext::new_headless().unwrap_or_else(|e| panic!("{e}"));
    let thickness = 0.01f32;
    let coverage = thickness as f64 * PER_UNIT;
    let rows = 12;
    let slab_model = slab(rows, thickness);
    let slab_geometry = StrandGeometry::upload(&gpu, &slab_model).unwrap();
    let depths: Vec<f32> = (0..rows).map(|m| 0.3 - 0.1 * m as f32 - 0.05).collect();
    let closed: Vec<f64> = (0..rows)
        .map(|m| (1.0 - coverage).powi(m as i32 + 1))
        .collect();
    // Worst error relative to the transmittance, with a floor of 1e-3 of full light so the
    // deepest probes (0.68^12 ≈ 0.01) do not dominate through half-float rounding.
    let worst_error = |t: &[f64], reference: &[f64]| {
        t.iter()
            .zip(reference)
            .map(|(a, b)| (a - b).abs() / b.max(1e-3))
            .fold(0.0f64, f64::max)
    };
    let pass = DeepOpacityPass::new(&gpu);
    let mut osm = Vec::new();
    for slices in [4u32, 8, 16, 32] {
        let map =
            DeepOpacityMap::opacity_slices(&gpu, ortho_camera(), slab_model.bounds(), RES, slices)
                .unwrap();
        pass.draw(&gpu, &slab_geometry, &map);
        let t = probe_transmittances(&gpu, &map, &depths);
        osm.push((slices, worst_error(&t, &closed), t));
    }
    let dom_map = DeepOpacityMap::new(
        &gpu,
        ortho_camera(),
        DomSettings {
            resolution: RES,
            layers: 32,
            spacing: 0.04,
        },
    );
    pass.draw(&gpu, &slab_geometry, &dom_map);
    let dom = probe_transmittances(&gpu, &dom_map, &depths);
    let dom_error = worst_error(&dom, &closed);
    for (slices, error, t) in &osm {
        eprintln!(
            "OSM {slices:2} slices: worst relative error {error:.4} against the closed form, {:.4} against DOM 32 layers",
            worst_error(t, &dom)
        );
    }
    eprintln!(
        "DOM 32 layers: worst relative error {dom_error:.2e}: {dom:.4?}; closed form {closed:.4?}"
    );
    assert!(dom_error < 5e-3, "DOM against the closed form: {dom_error}");
    assert!(
        osm.windows(2).all(|w| w[1].1 <= w[0].1 + 1e-3),
        "more slices must not be worse: {:?}",
        osm.iter().map(|o| (o.0, o.1)).collect::<Vec<_>>()
    );
    assert!(osm[0].1 > 0.1, "4 slices are far off: {}", osm[0].1);
    let (_, last_error, last) = &osm[3];
    assert!(*last_error < 5e-3, "OSM 32 slices: {last_error}");
    assert!(worst_error(last, &dom) < 5e-3);
}

/// PCF on a deep opacity map averages the transmittance of the texels around the lookup: behind
/// a slab that covers only the left half of the map (texel columns 0..32), a probe fiber is lit
/// (1 − d/s)^4 on the left and fully on the right through one texel; through 3×3 PCF the two
/// columns at the edge get the mean of their three neighbours: (2T + 1)/3 and (T + 2)/3.
#[test]
fn pcf_averages_the_layer_transmittance_of_neighbouring_texels() {
    let gpu = GpuContext::new_headless().unwrap_or_else(|e| panic!("{e}"));
    let thickness = 0.01f32;
    let coverage = thickness as f64 * PER_UNIT;
    let full = slab(4, thickness);
    // Keep the strands of columns 0..32 (x < 0): each strand is one column's fiber.
    let mut points = Vec::new();
    let mut offsets = vec![0u32];
    for strand in full.strands() {
        if strand[0].x < 0.0 {
            points.extend_from_slice(strand);
            offsets.push(points.len() as u32);
        }
    }
    let half = HairModel::new(
        points,
        offsets,
        Some(Attribute::Uniform(thickness)),
        None,
        None,
    )
    .unwrap();
    let geometry = StrandGeometry::upload(&gpu, &half).unwrap();
    let settings = DomSettings {
        resolution: RES,
        layers: 4,
        spacing: 0.08,
    };
    let pass = DeepOpacityPass::new(&gpu);
    let t = (1.0 - coverage).powi(4);
    for kernel in [1u32, 3] {
        let map = DeepOpacityMap::new(&gpu, ortho_camera(), settings)
            .with_layer_pcf(kernel)
            .unwrap();
        pass.draw(&gpu, &geometry, &map);
        // One probe behind the slab, read per column on pixel row 8 + 4·0 (y = 0.73).
        let color = Vec3::new(0.5, 0.3, 0.2);
        let probe = HairModel::new(
            vec![
                Vec3::new(-0.95, 0.734375, -0.5),
                Vec3::new(0.95, 0.734375, -0.5),
            ],
            vec![0, 2],
            None,
            None,
            Some(Attribute::Uniform(color)),
        )
        .unwrap();
        let frame = FrameParams {
            camera: ortho_camera(),
            width: RES,
            height: RES,
            lights: vec![Light::Directional {
                direction: Vec3::Z,
                intensity: 1.0,
            }],
            shading: KajiyaKay {
                kd: 0.6,
                ks: 0.25,
                shininess: 40.0,
            },
            width_override_px: Some(3.0),
        };
        let target = RenderTarget::new(&gpu, RES, RES);
        StrandPass::new(&gpu).draw(
            &gpu,
            &StrandGeometry::upload(&gpu, &probe).unwrap(),
            &frame,
            &target,
            Some(ShadowInput {
                map: &map,
                light_index: 0,
            }),
        );
        let pixels = read_texture_rgba(&gpu, &target.color).unwrap();
        let per_texel = |c: usize| if c < 32 { t } else { 1.0 };
        let mut worst = 0.0f64;
        for column in 26..38usize {
            let expected = if kernel == 1 {
                per_texel(column)
            } else {
                (per_texel(column - 1) + per_texel(column) + per_texel(column + 1)) / 3.0
            };
            let got = pixels[8 * RES as usize + column][0] as f64 / (0.6 * 0.5 + 0.25);
            worst = worst.max((got - expected).abs() / expected);
            assert!(
                (got - expected).abs() < 2e-3 * expected,
                "kernel {kernel}, column {column}: {got} vs {expected}"
            );
        }
        eprintln!("PCF {kernel}×{kernel}: worst relative error at the slab's edge {worst:.2e}");
    }
    let bad = DeepOpacityMap::new(&gpu, ortho_camera(), settings).with_layer_pcf(2);
    assert!(
        matches!(bad, Err(ShadowLookupError::Kernel(2))),
        "an even kernel is refused"
    );
}

/// The reference renderer of the environment-lit pipeline draws one map per light for
/// thousands of lights: one map re-aimed and redrawn must equal a fresh map for the new light
/// (no state left over from the previous light), so its textures can be reused.
#[test]
fn a_reused_map_equals_a_fresh_one_for_each_light() {
    let gpu = GpuContext::new_headless().unwrap_or_else(|e| panic!("{e}"));
    let model = slab(4, 0.01);
    let geometry = StrandGeometry::upload(&gpu, &model).unwrap();
    let pass = DeepOpacityPass::new(&gpu);
    let settings = DomSettings {
        resolution: RES,
        layers: 4,
        spacing: 0.08,
    };
    let tilted = Camera {
        eye: Vec3::new(1.5, 0.5, 4.6),
        ..ortho_camera()
    };
    let mut reused = DeepOpacityMap::new(&gpu, ortho_camera(), settings);
    pass.draw(&gpu, &geometry, &reused);
    let first = reused.read_layers(&gpu).unwrap();
    reused.layout = tilted.into();
    pass.draw(&gpu, &geometry, &reused);
    let fresh = DeepOpacityMap::new(&gpu, tilted, settings);
    pass.draw(&gpu, &geometry, &fresh);
    let (a, b) = (
        reused.read_layers(&gpu).unwrap(),
        fresh.read_layers(&gpu).unwrap(),
    );
    assert_eq!(
        a, b,
        "a re-aimed map must hold exactly what a fresh one holds"
    );
    assert_ne!(a, first, "the two lights must see different optical depths");
}

/// A point light very far away is a directional light: its perspective map (the camera at the
/// light, its frustum matching the orthographic test camera's footprint at z = 0) must hold the
/// same layers as the directional map, texel for texel, and shade a probe fiber behind the slab
/// with the same closed-form transmittance. This checks the perspective path: depths
/// linearized in the layer pass and in the lookup, and the lookup's divide by w.
#[test]
fn a_far_point_light_map_equals_the_directional_one() {
    let gpu = GpuContext::new_headless().unwrap_or_else(|e| panic!("{e}"));
    let thickness = 0.01f32;
    let coverage = thickness as f64 * PER_UNIT;
    let distance = 1000.0f32;
    let far_point = Camera {
        eye: Vec3::new(0.0, 0.0, distance),
        target: Vec3::ZERO,
        up: Vec3::Y,
        projection: Projection::Perspective {
            fov_y: 2.0 * (1.0 / distance).atan(),
        },
        near: distance - 10.0,
        far: distance + 10.0,
    };
    let slab_model = slab(4, thickness);
    let slab_geometry = StrandGeometry::upload(&gpu, &slab_model).unwrap();
    let settings = DomSettings {
        resolution: RES,
        layers: 4,
        spacing: 0.08,
    };
    let pass = DeepOpacityPass::new(&gpu);
    let directional = DeepOpacityMap::new(&gpu, ortho_camera(), settings);
    let point = DeepOpacityMap::new(&gpu, far_point, settings);
    for map in [&directional, &point] {
        pass.draw(&gpu, &slab_geometry, map);
    }
    let (a, b) = (
        directional.read_layers(&gpu).unwrap(),
        point.read_layers(&gpu).unwrap(),
    );
    let mut worst = 0.0f32;
    for ty in 8..56usize {
        for tx in 2..62usize {
            let i = ty * RES as usize + tx;
            for k in 0..4 {
                worst = worst.max((a[i][k] - b[i][k]).abs());
            }
        }
    }
    eprintln!("far point vs directional map: worst layer difference {worst:.2e}");
    assert!(worst < 1e-3, "layers differ by {worst}");

    // The probe fiber behind the slab, lit by the far point light (I / d² ≈ 1).
    let intensity = distance * distance;
    let probe = HairModel::new(
        vec![Vec3::new(-0.8, 0.5, -0.5), Vec3::new(0.8, 0.5, -0.5)],
        vec![0, 2],
        None,
        None,
        Some(Attribute::Uniform(Vec3::new(0.5, 0.3, 0.2))),
    )
    .unwrap();
    let geometry = StrandGeometry::upload(&gpu, &probe).unwrap();
    let frame = FrameParams {
        camera: ortho_camera(),
        width: RES,
        height: RES,
        lights: vec![Light::Point {
            position: far_point.eye,
            intensity,
        }],
        shading: KajiyaKay {
            kd: 0.6,
            ks: 0.25,
            shininess: 40.0,
        },
        width_override_px: Some(4.0),
    };
    let target = RenderTarget::new(&gpu, RES, RES);
    StrandPass::new(&gpu).draw(
        &gpu,
        &geometry,
        &frame,
        &target,
        Some(ShadowInput {
            map: &point,
            light_index: 0,
        }),
    );
    let pixels = read_texture_rgba(&gpu, &target.color).unwrap();
    let expected_t = (1.0 - coverage).powi(4);
    let mut worst = 0.0f64;
    for x in 8..56usize {
        for y in [14usize, 15, 16] {
            let world = Vec3::new((x as f32 + 0.5) / 32.0 - 1.0, 0.5, -0.5);
            let irradiance = intensity as f64 / far_point.eye.distance_squared(world) as f64;
            let got = pixels[y * RES as usize + x];
            for (k, c) in [0.5f64, 0.3, 0.2].into_iter().enumerate() {
                let expected = expected_t * irradiance * (0.6 * c + 0.25);
                worst = worst.max((got[k] as f64 - expected).abs() / expected);
            }
        }
    }
    eprintln!("far point light behind the slab: worst relative shading error {worst:.2e}");
    assert!(worst < 2e-3, "shading behind the slab off by {worst}");
}
