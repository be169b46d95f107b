//! The frame's visibility, drawn once before its batches: the head's depth and surface, then
//! the depth prepass and coverage (opaque view) or the occupancy map (transparent views) of
//! [`ViewVisibilityPass`](super::view_visibility::ViewVisibilityPass).

use super::frame_resources::FrameResources;
use super::stats::Timings;
use super::view_binding::ViewBinding;
use super::view_visibility::FragmentCounts;
use super::{EnvRenderOptions, EnvRenderer};
use crate::camera::Camera;
use crate::gpu::GpuContext;
use crate::gpu::readback::ReadbackError;

/// The frame's visibility (depth prepass and coverage, or the occupancy map), once; and the
/// front depth of head and hair into `front_depth` when the caller keeps one (a host's).
pub(super) fn encode_visibility(
    gpu: &GpuContext,
    renderer: &EnvRenderer,
    frame: &FrameResources,
    options: &EnvRenderOptions,
    camera: &Camera,
    front_depth: Option<&wgpu::Texture>,
    timings: &mut Timings,
) {
    timings.time(gpu, "view visibility", || {
        let visibility = frame.view.visibility(options);
        let view = ViewBinding::new(gpu, &renderer.layouts.view, None, &visibility);
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        // The head first: its depth bounds the hair's passes (and clears the depth).
        renderer.head.encode_view(
            gpu,
            &mut encoder,
            frame.view.head.as_ref(),
            camera,
            (frame.view.width, frame.view.height),
            &frame.view.depth_view,
            [&frame.view.head_views[0], &frame.view.head_views[1]],
        );
        renderer.visibility.encode(
            gpu,
            &mut encoder,
            options.transparency,
            &frame.view.strands,
            &view.group,
            &frame.view.depth_view,
            &frame.view.coverage_view,
            [&frame.view.nearest_views[0], &frame.view.nearest_views[1]],
            &frame.view.occupancy,
            frame.view.geometry.segment_count,
        );
        if let Some(front_depth) = front_depth {
            let depth = front_depth.create_view(&Default::default());
            let size = (frame.view.width, frame.view.height);
            let head_views = [&frame.view.head_views[0], &frame.view.head_views[1]];
            let head = frame.view.head.as_ref();
            renderer
                .head
                .encode_view(gpu, &mut encoder, head, camera, size, &depth, head_views);
            let segments = frame.view.geometry.segment_count;
            renderer.visibility.encode_front_depth(
                gpu,
                &mut encoder,
                &frame.view.strands,
                &depth,
                segments,
            );
        }
        gpu.queue.submit([encoder.finish()]);
    });
}

/// The fragments one batch's view pass rasterizes and shades (benchmarks).
pub(super) fn count_fragments(
    gpu: &GpuContext,
    renderer: &EnvRenderer,
    frame: &FrameResources,
    options: &EnvRenderOptions,
) -> Result<FragmentCounts, ReadbackError> {
    let visibility = frame.view.visibility(options);
    let view = ViewBinding::new(gpu, &renderer.layouts.view, None, &visibility);
    renderer.visibility.count_fragments(
        gpu,
        options.transparency,
        &frame.view.strands,
        &view.group,
        &frame.view.depth_view,
        (frame.view.width, frame.view.height),
        frame.view.geometry.segment_count,
    )
}
