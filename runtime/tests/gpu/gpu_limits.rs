//! Requests past the adapter's limits are typed errors naming the limit, the request, the
//! adapter's value and a setting that fits — never a panic or a wgpu validation abort. Each
//! limit is reached on the real device where a setting can reach it; `gpu::limits`'s unit tests
//! reach the rest with small synthetic limits.

use crate::common::*;

use glam::Vec3;
use strandlight_runtime::camera::Camera;
use strandlight_runtime::env::{EnvRenderError, EnvRenderOptions, EnvTables, render_env_frame};
use strandlight_runtime::env_light::EnvLight;
use strandlight_runtime::gpu::LimitError;
use strandlight_runtime::lights::Light;
use strandlight_runtime::passes::abuffer::{ABufferError, ABufferPass, ListMode};
use strandlight_runtime::passes::convolution_depth::DodmSettings;
use strandlight_runtime::passes::frame_params::{FrameParams, KajiyaKay};
use strandlight_runtime::passes::strand_geometry::StrandGeometry;
use strandlight_runtime::point_frame::{RenderError, RenderOptions, render_frame};
use strandlight_tables::table::{Axis, Table};
use strandlight_tables::table_axes::{
    AXIS_COS_DPHI, AXIS_INV_LAMBDA, AXIS_U_DOT_WO, AXIS_U_DOT_XI,
};

fn frame(width: u32, height: u32) -> FrameParams {
    FrameParams {
        camera: ortho_camera(),
        width,
        height,
        lights: vec![Light::Directional {
            direction: Vec3::Z,
            intensity: 1.0,
        }],
        shading: KajiyaKay::default(),
        width_override_px: None,
    }
}

fn srbf_table() -> Table {
    let axes = vec![
        Axis::uniform(AXIS_U_DOT_XI, -1.0, 1.0, 3),
        Axis::uniform(AXIS_U_DOT_WO, -1.0, 1.0, 3),
        Axis::uniform(AXIS_COS_DPHI, -1.0, 1.0, 3),
        Axis::uniform(AXIS_INV_LAMBDA, 1.0 / 64.0, 1.0 / 16.0, 2),
    ];
    Table::from_fn(axes, 3, |_, out| out.fill(1.0)).unwrap()
}

fn env_render(
    width: u32,
    height: u32,
    lights: &[EnvLight],
    options: &EnvRenderOptions,
) -> Result<(), EnvRenderError> {
    let gpu = gpu();
    let model = slab(1, 0.01);
    let camera = Camera::framing(model.bounds(), 1.0, false);
    let tables = EnvTables {
        srbf: Some(srbf_table().into()),
        ..Default::default()
    };
    render_env_frame(
        &gpu, &model, &camera, width, height, lights, &tables, options, None,
    )
    .map(|_| ())
}

#[test]
fn a_huge_image_is_refused_with_a_size_that_fits() {
    let gpu = gpu();
    let max = gpu.device.limits().max_texture_dimension_2d;
    let e = render_frame(
        &gpu,
        &slab(1, 0.01),
        &frame(100_000, 100_000),
        &RenderOptions::default(),
    )
    .err()
    .expect("a 100000x100000 frame must be refused");
    println!("{e}");
    assert!(
        matches!(
            e,
            RenderError::Limit(LimitError::ImageTooLarge { fit_width, fit_height, .. })
                if fit_width == max && fit_height == max
        ),
        "{e}"
    );
    let text = e.to_string();
    assert!(text.contains("max_texture_dimension_2d"), "{text}");
    assert!(text.contains(&format!("--size {max}x{max}")), "{text}");

    let e = env_render(
        100_000,
        100_000,
        &[EnvLight::srbf(Vec3::Z, 32.0, [1.0; 3])],
        &EnvRenderOptions::default(),
    )
    .unwrap_err();
    println!("{e}");
    assert!(
        matches!(e, EnvRenderError::Limit(LimitError::ImageTooLarge { .. })),
        "{e}"
    );
}

#[test]
fn a_node_pool_past_the_buffer_limit_is_refused() {
    let gpu = gpu();
    let geometry = StrandGeometry::upload(&gpu, &slab(1, 0.01)).unwrap();
    let pass = ABufferPass::new(&gpu);
    // u32::MAX − 1 nodes of 32 bytes: 128 GiB, past any adapter's max_buffer_size.
    let e = pass
        .draw(
            &gpu,
            &geometry,
            &frame(RES, RES),
            None,
            u32::MAX - 1,
            ListMode::All,
        )
        .err()
        .expect("a 128 GiB node pool must be refused");
    println!("{e}");
    assert!(
        matches!(
            e,
            ABufferError::Limit(LimitError::BufferSize { .. } | LimitError::StorageBinding { .. })
        ),
        "{e}"
    );
    assert!(e.to_string().contains("A-buffer node pool"), "{e}");
    // What max_capacity allows draws, and overflow past it is counted, not silent.
    let capacity = ABufferPass::max_capacity(&gpu, 16);
    let out = pass
        .draw(
            &gpu,
            &geometry,
            &frame(RES, RES),
            None,
            capacity,
            ListMode::All,
        )
        .unwrap();
    assert!(out.fragments_dropped > 0, "a 16-node pool must overflow");
    assert_eq!(out.fragments_stored, 16);
}

#[test]
fn a_light_batch_past_the_texture_array_limit_is_refused() {
    let gpu = gpu();
    let layers = gpu.device.limits().max_texture_array_layers;
    let lights: Vec<EnvLight> = (0..=layers)
        .map(|_| EnvLight::srbf(Vec3::Z, 32.0, [1.0; 3]))
        .collect();
    let options = EnvRenderOptions {
        dodm: DodmSettings {
            resolution: 8,
            first_layer: None,
            batch_size: layers + 1,
        },
        ..Default::default()
    };
    let e = env_render(RES, RES, &lights, &options).unwrap_err();
    println!("{e}");
    assert!(
        matches!(e, EnvRenderError::Limit(LimitError::TextureLayers { .. })),
        "{e}"
    );
    assert!(
        e.to_string()
            .contains(&format!("use a light batch size of at most {layers}")),
        "{e}"
    );
}

#[test]
fn env_sums_past_the_storage_binding_limit_are_refused() {
    let gpu = gpu();
    let limits = gpu.device.limits();
    let max = limits.max_texture_dimension_2d;
    let sums = 2 * 16 * max as u64 * max as u64;
    if sums
        <= limits
            .max_storage_buffer_binding_size
            .min(limits.max_buffer_size)
    {
        println!("skipped: this adapter binds the sums of a {max}x{max} image");
        return;
    }
    let e = env_render(
        max,
        max,
        &[EnvLight::srbf(Vec3::Z, 32.0, [1.0; 3])],
        &EnvRenderOptions::default(),
    )
    .unwrap_err();
    println!("{e}");
    assert!(matches!(e, EnvRenderError::Limit(_)), "{e}");
    assert!(e.to_string().contains("env sums"), "{e}");
}
