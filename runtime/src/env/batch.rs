//! One batch of lights of one kind: its forward-scattering grid, its light maps, then the view
//! shading of its lights added into the frame's sums.

use super::accumulate::FrameSums;
use super::checks::check_grid;
use super::frame_resources::{FrameRequest, FrameResources};
use super::light_kinds::LightBatch;
use super::segment_light_visibility::sample_bytes;
use super::stats::{BatchUsage, Timings};
use super::view_binding::ViewBinding;
use super::view_shading::ViewShadingInputs;
use super::{EnvRenderError, EnvRenderer};
use crate::env_light::EnvLight;
use crate::gpu::GpuContext;
use crate::multiple::{ForwardScatteringGrid, ForwardScatteringSource};
use crate::passes::convolution_transmittance::BatchBinding;

/// Renders `batch` into the frame's targets and adds them into `sums`.
pub(super) fn render_batch(
    gpu: &GpuContext,
    renderer: &EnvRenderer,
    (frame, sums): (&mut FrameResources, &FrameSums),
    batch: &LightBatch<'_>,
    request: &FrameRequest<'_>,
    timings: &mut Timings,
    usage: &mut BatchUsage,
) -> Result<(), EnvRenderError> {
    let options = request.options;
    usage.batches += 1;
    let grid = match request.multiple {
        Some(source) => {
            let representatives: Vec<_> = batch.groups.iter().map(|g| g.representative()).collect();
            Some(batch_grid(gpu, source, &representatives, timings)?)
        }
        None => None,
    };
    // Unshadowed frames never read the light maps, nor do SRBF lobes that read the
    // visibility volume: skip drawing them.
    let srbf_from_volume = options.lobe_visibility.volume().is_some()
        && batch.first_light().is_some_and(|l| l.lambda.is_some());
    if options.shadowed && !srbf_from_volume {
        let head_pass = &renderer.head;
        (renderer.light_maps).encode(gpu, frame, batch, options, head_pass, timings);
    }
    let map_size = batch.map_size();
    timings.time(gpu, "view", || {
        let maps = frame.maps.get_mut(map_size);
        let lights = BatchBinding::with_groups(
            gpu,
            &renderer.layouts.batch,
            batch.groups,
            &maps.dodm,
            &maps.sat,
            options.shadowed,
            grid.is_some(),
            options.transmittance_filter,
            maps.head.as_ref().filter(|_| !srbf_from_volume),
        );
        let view = &frame.view;
        let mut visibility = view.visibility(options);
        let transparency = options.transparency;
        // Only the layered view keeps slots for them.
        visibility.layer_lights = view.occupancy.layer_light_slots > 0 && batch.has_sharp_shadows();
        let binding = ViewBinding::new(gpu, &renderer.layouts.view, grid.as_ref(), &visibility);
        usage.grid_bytes = usage.grid_bytes.max(binding.bytes);
        if visibility.layer_lights {
            let (segments, intervals) = (view.geometry.segment_count, view.gather_intervals);
            let bytes = sample_bytes(segments, intervals, lights.light_count);
            usage.segment_visibility_bytes = usage.segment_visibility_bytes.max(bytes);
        }
        let inputs = ViewShadingInputs {
            geometry: &view.geometry,
            gather_intervals: view.gather_intervals,
            strands: &view.strands,
            transparency,
            layer_lights: visibility
                .layer_lights
                .then_some((&view.occupancy, &view.depth_view)),
            batch: &lights,
            tables: batch.tables,
            view: &binding,
            with_head: view.head.is_some(),
            single_from_light_maps: request.single_from_light_maps(),
        };
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        (renderer.shading).encode(gpu, &mut encoder, &inputs, &view.targets);
        (renderer.accumulate).encode(gpu, &mut encoder, &view.targets, sums);
        gpu.queue.submit([encoder.finish()]);
    });
    Ok(())
}

/// The forward-scattering grid of one batch, checked.
fn batch_grid(
    gpu: &GpuContext,
    source: &dyn ForwardScatteringSource,
    lights: &[EnvLight],
    timings: &mut Timings,
) -> Result<ForwardScatteringGrid, EnvRenderError> {
    let pass = format!("multiple grid ({})", source.device());
    let grid = timings
        .time(gpu, &pass, || source.grid(lights))
        .map_err(|e| EnvRenderError::Grid(e.to_string()))?;
    check_grid(&grid, lights.len())?;
    Ok(grid)
}
