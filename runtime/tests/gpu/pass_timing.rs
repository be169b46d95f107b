//! GPU pass times from timestamp queries: present exactly where the adapter has them, and
//! physically possible — every pass's GPU time is positive and fits inside the wall-clock
//! window that enclosed its submission and completion.

use crate::common::*;

use glam::Vec3;
use strandlight_runtime::lights::Light;
use strandlight_runtime::passes::deep_opacity::DomSettings;
use strandlight_runtime::passes::frame_params::{FrameParams, KajiyaKay};
use strandlight_runtime::point_frame::{RenderOptions, ShadowMaps, render_frame};

#[test]
fn gpu_pass_times_are_reported_where_supported_and_fit_inside_the_wall_clock() {
    let gpu = gpu();
    let supported = gpu
        .device
        .features()
        .contains(wgpu::Features::TIMESTAMP_QUERY);
    let frame = FrameParams {
        camera: ortho_camera(),
        width: 512,
        height: 512,
        lights: vec![Light::Directional {
            direction: Vec3::new(0.0, 0.3, 1.0).normalize(),
            intensity: 1.0,
        }],
        shading: KajiyaKay {
            kd: 0.6,
            ks: 0.4,
            shininess: 20.0,
        },
        width_override_px: None,
    };
    let options = RenderOptions {
        shadows: Some(ShadowMaps::Deep {
            settings: DomSettings {
                resolution: 256,
                layers: 4,
                spacing: 0.05,
            },
            pcf: 1,
        }),
        ..Default::default()
    };
    let out = render_frame(&gpu, &slab(6, 0.02), &frame, &options).unwrap();
    eprintln!(
        "adapter {} timestamp queries: {supported}; {}",
        gpu.report, out.stats.timing_method
    );
    for t in &out.stats.timings {
        eprintln!(
            "  {:<20} wall {:8.3} ms  gpu {:?}",
            t.pass, t.milliseconds, t.gpu_milliseconds
        );
    }
    let with_gpu: Vec<_> = out
        .stats
        .timings
        .iter()
        .filter_map(|t| t.gpu_milliseconds.map(|g| (t, g)))
        .collect();
    if !supported {
        assert!(with_gpu.is_empty(), "GPU times without timestamp queries");
        eprintln!("skipped the range checks: this adapter has no timestamp queries");
        return;
    }
    for pass in ["deep opacity (light 0)", "strands"] {
        assert!(
            with_gpu.iter().any(|(t, _)| t.pass == pass),
            "no GPU time for {pass}"
        );
    }
    for (t, g) in with_gpu {
        assert!(g > 0.0, "{}: GPU time {g} ms", t.pass);
        // The clocks differ (GPU ticks against the CPU's monotonic clock): allow 0.1 ms.
        assert!(
            g <= t.milliseconds + 0.1,
            "{}: GPU {g} ms exceeds the {} ms wall-clock window around it",
            t.pass,
            t.milliseconds
        );
    }
}
