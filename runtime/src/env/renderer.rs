//! The env-lit renderer: its pipelines and caches, kept across frames, and the frame's order of
//! work: check the inputs, create the frame's resources, draw its visibility once, then each
//! batch of lights ([`super::batch`]) added into the frame's sums.

use super::accumulate::{AccumulatePass, FrameSums};
use super::batch::render_batch;
use super::checks::check_inputs;
use super::frame_resources::{FrameRequest, FrameResources, single_from_light_maps};
use super::frame_visibility::{count_fragments, encode_visibility};
use super::image::split_sums;
use super::light_kinds::LightKinds;
use super::light_maps::LightMapsPass;
use super::stats::{BatchUsage, Timings};
use super::table_binding::TableCache;
use super::view_shading::{EnvViewLayouts, ViewShadingPass, view_visibility_pass};
use super::view_visibility::{ViewTransparency, ViewVisibilityPass};
use super::volume::VolumeCache;
use super::{EncodedFrame, EnvImage, EnvRenderError, EnvRenderOptions, EnvRenderStats, EnvTables};
use crate::camera::Camera;
use crate::env_light::EnvLight;
use crate::gpu::GpuContext;
use crate::gpu::pipeline::build_both;
use crate::gpu::readback::read_buffer;
use crate::hair::HairModel;
use crate::head::Head;
use crate::multiple::ForwardScatteringSource;
use crate::passes::head::HeadPass;
use crate::visibility::{VisibilityVolume, VisibilityVolumeSettings};
use std::sync::OnceLock;

/// The pipelines of the env-lit renderer, reusable across frames.
pub struct EnvRenderer {
    pub(super) layouts: EnvViewLayouts,
    pub(super) head: HeadPass,
    pub(super) visibility: ViewVisibilityPass,
    pub(super) light_maps: LightMapsPass,
    pub(super) shading: ViewShadingPass,
    pub(super) accumulate: AccumulatePass,
    pub(super) volume: VolumeCache,
    pub(super) tables: TableCache,
    /// Per view (opaque, occupancy, layered), without and with a head, of any scattering or of
    /// single scattering from light maps: its pipelines are compiled.
    compiled: [[[OnceLock<()>; 2]; 2]; 3],
}

impl EnvRenderer {
    pub fn new(gpu: &GpuContext) -> Self {
        let layouts = EnvViewLayouts::new(&gpu.device);
        let ((shading, visibility), (light_maps, (head, accumulate))) = build_both(
            || {
                build_both(
                    || ViewShadingPass::new(gpu, &layouts),
                    || view_visibility_pass(gpu, &layouts),
                )
            },
            || {
                build_both(
                    || LightMapsPass::new(gpu),
                    || build_both(|| HeadPass::new(gpu), || AccumulatePass::new(&gpu.device)),
                )
            },
        );
        Self {
            head,
            visibility,
            light_maps,
            shading,
            accumulate,
            volume: VolumeCache::default(),
            tables: TableCache::default(),
            compiled: Default::default(),
            layouts,
        }
    }

    /// Compiles the pipelines a frame in `transparency`, with a head or not, draws with (each
    /// is otherwise compiled when a frame first uses it), the visibility's beside the view's:
    /// ahead of a first frame, on a thread of the application's. `single_from_light_maps`: the
    /// frame has single scattering alone, every light shadowed by its light map (a first look).
    pub fn compile(
        &self,
        transparency: ViewTransparency,
        with_head: bool,
        single_from_light_maps: bool,
    ) {
        let view = match transparency {
            ViewTransparency::Opaque => 0,
            ViewTransparency::Occupancy { .. } => 1,
            ViewTransparency::Layered { .. } => 2,
        };
        // Once: every part asks, and a frame's path spawns no threads after the first.
        let shading = usize::from(single_from_light_maps);
        self.compiled[view][usize::from(with_head)][shading].get_or_init(|| {
            build_both(
                || self.visibility.compile(transparency),
                || (self.shading).compile(transparency, with_head, single_from_light_maps),
            );
        });
    }

    /// Makes `volume` the visibility volume of `model` under `settings` (instead of building
    /// it): a volume computed elsewhere, or a hand-made one in tests.
    pub fn use_visibility_volume(
        &self,
        gpu: &GpuContext,
        model: &HairModel,
        settings: VisibilityVolumeSettings,
        volume: &VisibilityVolume,
    ) {
        self.volume.set(gpu, model, settings, volume);
    }

    /// Renders `model` seen by `camera` into `width`×`height` under `lights` (SRBFs shaded with
    /// `tables.srbf`, directional lights with `tables.direct`), with multiple scattering from
    /// `multiple` (and `tables.multiple`) when given.
    #[allow(clippy::too_many_arguments)]
    pub fn render(
        &self,
        gpu: &GpuContext,
        model: &HairModel,
        camera: &Camera,
        width: u32,
        height: u32,
        lights: &[EnvLight],
        tables: &EnvTables,
        options: &EnvRenderOptions,
        multiple: Option<&dyn ForwardScatteringSource>,
    ) -> Result<EnvImage, EnvRenderError> {
        let part = (lights, 0);
        self.render_part(
            gpu, model, camera, width, height, part, tables, options, multiple, None,
        )
    }

    /// [`Self::render`] for `lights` that continue a frame rendered in parts (the viewer's
    /// progressive batches): its simplified lights draw the strand windows from `first_window`
    /// on, the number of simplified lights in the parts before, so the parts sum to the frame
    /// rendered at once ([`SimplifiedSegments::window`]). With `head`, the head hides the fibers
    /// behind it, is drawn as skin and is opaque in every light's visibility.
    ///
    /// [`SimplifiedSegments::window`]: crate::passes::convolution_depth::SimplifiedSegments::window
    #[allow(clippy::too_many_arguments)]
    pub fn render_part(
        &self,
        gpu: &GpuContext,
        model: &HairModel,
        camera: &Camera,
        width: u32,
        height: u32,
        part: (&[EnvLight], u32),
        tables: &EnvTables,
        options: &EnvRenderOptions,
        multiple: Option<&dyn ForwardScatteringSource>,
        head: Option<&Head>,
    ) -> Result<EnvImage, EnvRenderError> {
        let scope = gpu.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let encoded = self.encode_part(
            gpu, model, camera, width, height, part, tables, options, multiple, head,
        )?;
        let size = [encoded.width, encoded.height];
        read_image(
            gpu,
            scope,
            &encoded.sums,
            size,
            encoded.with_multiple,
            encoded.stats,
        )
    }

    /// [`Self::render_part`] added into `sums`, a running sum the caller keeps across the parts
    /// of a progressive frame (a viewer's batches), and submitted: the sums stay on the GPU for
    /// a caller that shows them there ([`Self::read_sums`] reads them back). Validation errors
    /// are checked. Returns the part's own stats.
    #[allow(clippy::too_many_arguments)]
    pub fn submit_part_into(
        &self,
        gpu: &GpuContext,
        model: &HairModel,
        camera: &Camera,
        part: (&[EnvLight], u32),
        tables: &EnvTables,
        options: &EnvRenderOptions,
        multiple: Option<&dyn ForwardScatteringSource>,
        head: Option<&Head>,
        sums: &FrameSums,
    ) -> Result<EnvRenderStats, EnvRenderError> {
        let scope = gpu.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let stats = self.encode_part_into(
            gpu, model, camera, part, tables, options, multiple, head, sums,
        )?;
        if let Some(error) = pollster::block_on(scope.pop()) {
            return Err(EnvRenderError::Gpu(error.to_string()));
        }
        Ok(stats)
    }

    /// [`Self::render_part`] up to the pixels: every pass submitted, the sums left on the GPU
    /// (a web page cannot wait for a readback; it draws them or maps them later). The caller
    /// owns the error scope.
    #[allow(clippy::too_many_arguments)]
    pub fn encode_part(
        &self,
        gpu: &GpuContext,
        model: &HairModel,
        camera: &Camera,
        width: u32,
        height: u32,
        (lights, first_window): (&[EnvLight], u32),
        tables: &EnvTables,
        options: &EnvRenderOptions,
        multiple: Option<&dyn ForwardScatteringSource>,
        head: Option<&Head>,
    ) -> Result<EncodedFrame, EnvRenderError> {
        let request = FrameRequest {
            model,
            camera,
            width,
            height,
            tables,
            options,
            multiple,
            head,
        };
        // Once per renderer, outside the frame's timed passes.
        self.compile(
            options.transparency,
            head.is_some(),
            request.single_from_light_maps(),
        );
        let mut timings = Timings(Vec::new());
        let part = (lights, first_window);
        let (frame, kinds) = self.start_part(gpu, &request, part, None, &mut timings)?;
        let sums = FrameSums::new(gpu, width, height)?;
        let stats = self.finish_part(gpu, &request, lights, frame, &kinds, &sums, timings)?;
        Ok(EncodedFrame {
            width,
            height,
            sums: sums.into_buffer(),
            with_multiple: multiple.is_some(),
            stats,
        })
    }

    /// [`Self::encode_part`] adding the part into `sums`, a running sum the caller keeps across
    /// the parts of a progressive frame (the image is `sums`' size): after the last part it
    /// holds the frame rendered at once. Returns the part's stats; the caller owns the error
    /// scope.
    #[allow(clippy::too_many_arguments)]
    pub fn encode_part_into(
        &self,
        gpu: &GpuContext,
        model: &HairModel,
        camera: &Camera,
        (lights, first_window): (&[EnvLight], u32),
        tables: &EnvTables,
        options: &EnvRenderOptions,
        multiple: Option<&dyn ForwardScatteringSource>,
        head: Option<&Head>,
        sums: &FrameSums,
    ) -> Result<EnvRenderStats, EnvRenderError> {
        let [width, height] = sums.size();
        let request = FrameRequest {
            model,
            camera,
            width,
            height,
            tables,
            options,
            multiple,
            head,
        };
        // Once per renderer, outside the frame's timed passes.
        self.compile(
            options.transparency,
            head.is_some(),
            request.single_from_light_maps(),
        );
        let mut timings = Timings(Vec::new());
        let part = (lights, first_window);
        let (frame, kinds) = self.start_part(gpu, &request, part, Some(sums), &mut timings)?;
        self.finish_part(gpu, &request, lights, frame, &kinds, sums, timings)
    }

    /// `sums` read back as an image (one readback, waiting for the GPU), with `stats` (the last
    /// part's).
    pub fn read_sums(
        gpu: &GpuContext,
        sums: &FrameSums,
        with_multiple: bool,
        stats: EnvRenderStats,
    ) -> Result<EnvImage, EnvRenderError> {
        let scope = gpu.device.push_error_scope(wgpu::ErrorFilter::Validation);
        read_image(gpu, scope, sums.buffer(), sums.size(), with_multiple, stats)
    }

    /// Checks a part's inputs, then creates its resources (its simplified lights drawing the
    /// strand windows from `first_window` on; the view an earlier part kept in `kept`, if any).
    fn start_part(
        &self,
        gpu: &GpuContext,
        request: &FrameRequest<'_>,
        (lights, first_window): (&[EnvLight], u32),
        kept: Option<&FrameSums>,
        timings: &mut Timings,
    ) -> Result<(FrameResources, LightKinds), EnvRenderError> {
        let kinds = LightKinds::of(lights);
        let with_multiple = request.multiple.is_some();
        check_inputs(
            lights,
            &kinds,
            request.tables,
            request.options,
            with_multiple,
        )?;
        let mut frame = FrameResources::new(gpu, self, request, &kinds, kept, timings)?;
        frame.next_window = first_window;
        Ok((frame, kinds))
    }

    /// A started part's visibility, then each of its batches added into `sums`.
    #[allow(clippy::too_many_arguments)]
    fn finish_part(
        &self,
        gpu: &GpuContext,
        request: &FrameRequest<'_>,
        lights: &[EnvLight],
        mut frame: FrameResources,
        kinds: &LightKinds,
        sums: &FrameSums,
        mut timings: Timings,
    ) -> Result<EnvRenderStats, EnvRenderError> {
        let options = request.options;
        let mut memory = frame.memory();
        memory.push(("env sums".into(), sums.buffer().size()));
        if frame.view_is_new {
            let front_depth = sums.front_depth();
            let camera = request.camera;
            encode_visibility(
                gpu,
                self,
                &frame,
                options,
                camera,
                front_depth,
                &mut timings,
            );
        }
        let fragments = match options.count_fragments {
            true => Some(count_fragments(gpu, self, &frame, options)?),
            false => None,
        };
        let mut usage = BatchUsage::default();
        let (srbf_tables, directional_tables) =
            (frame.srbf_tables.take(), frame.directional_tables.take());
        usage.table_bytes = [&srbf_tables, &directional_tables]
            .iter()
            .filter_map(|t| t.as_ref().map(|t| t.bytes))
            .sum();
        let tables = [srbf_tables.as_deref(), directional_tables.as_deref()];
        let compact_batch_size = match frame.view.occupancy.layer_light_slots {
            0 => options.dodm.batch_size,
            slots => slots,
        };
        let batch_sizes = [options.dodm.batch_size, compact_batch_size];
        kinds.for_each_batch(tables, batch_sizes, |batch| {
            let resources = (&mut frame, sums);
            render_batch(
                gpu,
                self,
                resources,
                batch,
                request,
                &mut timings,
                &mut usage,
            )
        })?;
        memory.push(("env tables".into(), usage.table_bytes));
        memory.push(("forward-scattering grid".into(), usage.grid_bytes));
        if usage.segment_visibility_bytes > 0 {
            let bytes = usage.segment_visibility_bytes;
            memory.push(("compact sources' visibility along segments".into(), bytes));
        }
        Ok(EnvRenderStats {
            adapter: gpu.report.clone(),
            timings: timings.0,
            memory_per_batch: memory,
            batches: usage.batches,
            lights: lights.len() as u32,
            segments: frame.view.geometry.segment_count,
            light_pass_segments: frame.view.light_geometry.segment_count,
            timing_method: crate::point_frame::TIMING_METHOD,
            fragments,
        })
    }
}

/// [`EnvRenderer::render`] with pipelines built for this one frame.
#[allow(clippy::too_many_arguments)]
pub fn render_env_frame(
    gpu: &GpuContext,
    model: &HairModel,
    camera: &Camera,
    width: u32,
    height: u32,
    lights: &[EnvLight],
    tables: &EnvTables,
    options: &EnvRenderOptions,
    multiple: Option<&dyn ForwardScatteringSource>,
) -> Result<EnvImage, EnvRenderError> {
    let mut timings = Timings(Vec::new());
    let renderer = timings.time(gpu, "pipelines", || {
        let renderer = EnvRenderer::new(gpu);
        let single = single_from_light_maps(options, multiple.is_some());
        renderer.compile(options.transparency, false, single);
        renderer
    });
    let mut frame = renderer.render(
        gpu, model, camera, width, height, lights, tables, options, multiple,
    )?;
    frame.stats.timings.splice(0..0, timings.0);
    Ok(frame)
}

/// A frame's sums read back (timed as "readback"), once its passes are submitted and the
/// caller's validation `scope` closes without an error.
fn read_image(
    gpu: &GpuContext,
    scope: wgpu::ErrorScopeGuard,
    sums: &wgpu::Buffer,
    [width, height]: [u32; 2],
    with_multiple: bool,
    stats: EnvRenderStats,
) -> Result<EnvImage, EnvRenderError> {
    let mut timings = Timings(stats.timings.clone());
    let bytes = timings.time(gpu, "readback", || read_buffer(gpu, sums))?;
    if let Some(error) = pollster::block_on(scope.pop()) {
        return Err(EnvRenderError::Gpu(error.to_string()));
    }
    let (pixels, single_pixels, multiple_pixels) = split_sums(&bytes, width, height, with_multiple);
    Ok(EnvImage {
        width,
        height,
        pixels,
        single_pixels,
        multiple_pixels,
        stats: EnvRenderStats {
            timings: timings.0,
            ..stats
        },
    })
}
