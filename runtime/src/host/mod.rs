//! Hair in someone else's renderer: [`HairRenderer`] draws env-lit hair into a host
//! application's own render pass, on the host's device, depth-tested against what the host drew.
//!
//! It is shaped like the wgpu ecosystem's renderers (egui-wgpu's `Renderer`, glyphon):
//! - [`HairRenderer::new`] takes the host's `Device`, `Queue` and target formats; the runtime
//!   requests no device of its own.
//! - [`HairRenderer::prepare`] starts a frame for a groom, camera, lights and tables;
//!   [`HairRenderer::encode_next_batch`] adds the next batch of lights to it (progressive
//!   refinement: the host encodes a batch when it has time, and the batches sum to the frame
//!   rendered at once).
//! - [`HairRenderer::render`] draws the frame so far into the host's render pass.
//!
//! - [`HairRenderer::draw_point_lit`] draws a frame of the thesis techniques instead (point and
//!   directional lights, their shadow or deep opacity maps, any transparency technique), whole:
//!   [`HairRenderer::render`] then draws it the same way.
//!
//! Nothing on that path reads back or waits for the GPU: work is submitted on the host's queue
//! and the frame stays on the GPU. [`HairRenderer::read_image`] is the one readback, for a
//! headless host that writes files. One exception: multiple scattering from the GPU's
//! forward-scattering march (`multiple::GpuForwardScattering`) reads its grid back once per
//! batch; single scattering and the CPU's source read nothing back. The A-buffer and DBK without
//! a node count count their fragments first, to size the pool. GPU validation errors go to
//! the device's own error handler (the host's).
//!
//! The hair's depth is wgpu's 0..1 depth of [`Camera::view_projection`] at the frame's size: a
//! host that projects its scene with the same matrix shares one depth buffer with the hair.

#![warn(missing_docs)]

use crate::camera::Camera;
use crate::env::{EnvImage, EnvRenderError, EnvRenderOptions, EnvRenderer, EnvTables, FrameSums};
use crate::env_light::EnvLight;
use crate::gpu::GpuContext;
use crate::hair::HairModel;
use crate::head::Head;
use crate::multiple::ForwardScatteringSource;
use crate::passes::fiber_shading::ShadingModel;
use crate::passes::frame_params::FrameParams;
use crate::point_frame::{RenderError, RenderOptions, RenderStats, submit_frame};
use composite::{CompositeBinding, CompositePass};
use point_gather::PointGatherPass;

mod composite;
mod point_gather;

/// The host's render targets that [`HairRenderer::render`] draws into.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HairTargets {
    /// The colour attachment's format. The hair is linear radiance (times
    /// [`HairRenderer::set_radiance_scale`]), pre-multiplied: an HDR format keeps it, an 8-bit
    /// one clips it.
    pub color: wgpu::TextureFormat,
    /// The depth attachment's format; `None` for a pass without one (the hair is then drawn
    /// over everything).
    pub depth: Option<wgpu::TextureFormat>,
    /// The pass's samples per pixel (1 without MSAA).
    pub sample_count: u32,
}

/// One frame's inputs, borrowed for each call that draws lights: the runtime uploads what a
/// batch needs as it encodes it.
#[derive(Clone, Copy)]
pub struct HairFrame<'a> {
    /// The groom.
    pub model: &'a HairModel,
    /// The view, shared with the host (see the module's note on depth).
    pub camera: &'a Camera,
    /// Width and height in pixels: the host's target size.
    pub size: [u32; 2],
    /// Every light of the frame, in any order: the batches draw the strongest first, in the
    /// order that makes them sum to the frame drawn at once.
    pub lights: &'a [EnvLight],
    /// The baked tables the lights are shaded with.
    pub tables: &'a EnvTables,
    /// The renderer's settings (κ, light maps, view transparency, …).
    pub options: &'a EnvRenderOptions,
    /// Multiple scattering's forward-scattering source; `None` for single scattering.
    pub multiple: Option<&'a dyn ForwardScatteringSource>,
    /// A head that hides the fibers behind it, is drawn as skin and shadows the hair.
    pub head: Option<&'a Head>,
}

/// One frame of the thesis techniques ([`HairRenderer::draw_point_lit`]), borrowed for the call.
#[derive(Clone, Copy)]
pub struct PointLitFrame<'a> {
    /// The groom.
    pub model: &'a HairModel,
    /// The camera, the size (the host's target size), the lights and Kajiya-Kay's constants.
    pub params: &'a FrameParams,
    /// The shadow maps and the transparency technique.
    pub options: &'a RenderOptions,
    /// The fiber model the strands are shaded with.
    pub shading: &'a ShadingModel,
    /// A head that hides the fibers behind it, is drawn as skin and shadows the hair.
    pub head: Option<&'a Head>,
}

/// How far the frame has come.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BatchProgress {
    /// Lights drawn into the frame so far.
    pub lights_drawn: usize,
    /// Lights of the whole frame.
    pub lights_total: usize,
}

impl BatchProgress {
    /// Every light is drawn: the frame equals the one rendered at once.
    pub fn converged(self) -> bool {
        self.lights_drawn >= self.lights_total
    }
}

/// A frame being refined: its sums on the GPU and the lights drawn into them.
struct FrameInProgress {
    /// The frame's lights (indices) in the order the batches draw them ([`drawing_order`]).
    order: Vec<usize>,
    sums: FrameSums,
    composite: CompositeBinding,
    progress: BatchProgress,
    with_multiple: bool,
    last_stats: Option<crate::env::EnvRenderStats>,
}

/// The order the batches draw `lights` in: κ gives each simplified light a window of the strands
/// by its rank in the whole frame (thinned SRBFs by power, strongest first, then thinned
/// directional lights; `env::light_kinds`), so batches that follow that rank sum to the frame
/// drawn at once. Lights that draw every strand follow, strongest first. Stable: equal powers
/// keep the caller's order, as the renderer's own ranking does.
fn drawing_order(lights: &[EnvLight]) -> Vec<usize> {
    let class = |l: &EnvLight| match (l.is_simplified(), l.lambda.is_some()) {
        (true, true) => 0,
        (true, false) => 1,
        (false, _) => 2,
    };
    let mut order: Vec<usize> = (0..lights.len()).collect();
    order.sort_by(|&i, &j| {
        let (a, b) = (&lights[i], &lights[j]);
        class(a).cmp(&class(b)).then_with(|| match class(a) {
            1 => std::cmp::Ordering::Equal,
            _ => b.luminous_power().total_cmp(&a.luminous_power()),
        })
    });
    order
}

/// Env-lit hair drawn into a host's render pass. See the [module](self) for the frame's path.
pub struct HairRenderer {
    gpu: GpuContext,
    env: EnvRenderer,
    composite: CompositePass,
    /// Made when the first point-lit frame is drawn.
    point_lit: Option<PointLitDrawer>,
    frame: Option<FrameInProgress>,
}

impl HairRenderer {
    /// The renderer's pipelines on the host's `device` and `queue`, drawing into `targets`.
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue, targets: HairTargets) -> Self {
        Self::on(
            GpuContext::from_device(device.clone(), queue.clone()),
            targets,
        )
    }

    /// [`Self::new`] on a context the caller already has (one from
    /// [`GpuContext::new_headless`], whose passes are timed by waiting for the GPU).
    pub fn on(gpu: GpuContext, targets: HairTargets) -> Self {
        Self {
            env: EnvRenderer::new(&gpu),
            composite: CompositePass::new(&gpu.device, &targets),
            point_lit: None,
            frame: None,
            gpu,
        }
    }

    /// The device and queue the hair is drawn with (to build a GPU forward-scattering source
    /// on the same device, for example).
    pub fn gpu(&self) -> &GpuContext {
        &self.gpu
    }

    /// Starts a new frame of `frame`: no light drawn yet, so [`Self::render`] draws nothing
    /// until the first batch. The frame's buffers are kept across frames of one size and
    /// cleared on the GPU. A frame without lights is an error.
    pub fn prepare(&mut self, frame: &HairFrame<'_>) -> Result<(), EnvRenderError> {
        if frame.lights.is_empty() {
            return Err(EnvRenderError::NoLights);
        }
        let kept = self.frame_of_size(frame.size)?;
        self.clear(&kept.sums);
        self.frame = Some(FrameInProgress {
            order: drawing_order(frame.lights),
            progress: BatchProgress {
                lights_drawn: 0,
                lights_total: frame.lights.len(),
            },
            with_multiple: frame.multiple.is_some(),
            last_stats: None,
            ..kept
        });
        Ok(())
    }

    /// The frame kept from before if it has this size (its sums are reused), else a new one.
    fn frame_of_size(&mut self, size: [u32; 2]) -> Result<FrameInProgress, crate::gpu::LimitError> {
        if let Some(kept) = self.frame.take().filter(|kept| kept.sums.size() == size) {
            return Ok(kept);
        }
        let sums = FrameSums::with_front_depth(&self.gpu, size[0], size[1])?;
        Ok(FrameInProgress {
            composite: self.composite.bind(&self.gpu.device, &sums),
            sums,
            order: Vec::new(),
            progress: BatchProgress {
                lights_drawn: 0,
                lights_total: 0,
            },
            with_multiple: false,
            last_stats: None,
        })
    }

    /// Draws a frame of the thesis techniques, whole, and submits it without waiting:
    /// [`Self::render`] then draws it into the host's pass like an env-lit frame (hidden where
    /// the host's depth is nearer; the radiance scale applies). Its progress is converged at
    /// once. Errors name the setting or limit at fault (a frame past the adapter's limits, a
    /// technique's bad count, shadows without a light).
    pub fn draw_point_lit(&mut self, frame: &PointLitFrame<'_>) -> Result<(), RenderError> {
        let params = frame.params;
        let kept = self.frame_of_size([params.width, params.height])?;
        kept.sums.forget_view();
        self.point_lit
            .get_or_insert_with(|| PointLitDrawer::new(&self.gpu))
            .draw_into(&self.gpu, frame, &kept.sums)?;
        let lights = params.lights.len();
        self.frame = Some(FrameInProgress {
            order: Vec::new(),
            progress: BatchProgress {
                lights_drawn: lights,
                lights_total: lights,
            },
            with_multiple: false,
            last_stats: None,
            ..kept
        });
        Ok(())
    }

    /// Zeroes `sums` and sets their front depth to the far plane (nothing drawn), on the GPU:
    /// until its first batch a frame draws nothing into the host's pass, not even depth.
    fn clear(&self, sums: &FrameSums) {
        sums.forget_view();
        let mut encoder = self.gpu.device.create_command_encoder(&Default::default());
        encoder.clear_buffer(sums.buffer(), 0, None);
        if let Some(depth) = sums.front_depth() {
            let view = depth.create_view(&Default::default());
            encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("hair front depth cleared"),
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &view,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(1.0),
                        store: wgpu::StoreOp::Store,
                    }),
                    stencil_ops: None,
                }),
                ..Default::default()
            });
        }
        self.gpu.queue.submit([encoder.finish()]);
    }

    /// Adds the next batch of lights (the options' `dodm.batch_size` of them) to the frame
    /// [`Self::prepare`] started, submitted on the queue without waiting. `frame` must be the
    /// one prepared. Returns the progress after this batch; past the last batch it does
    /// nothing.
    pub fn encode_next_batch(
        &mut self,
        frame: &HairFrame<'_>,
    ) -> Result<BatchProgress, EnvRenderError> {
        let Some(kept) = &mut self.frame else {
            return Err(EnvRenderError::NotPrepared);
        };
        if kept.sums.size() != frame.size || kept.progress.lights_total != frame.lights.len() {
            return Err(EnvRenderError::NotPrepared);
        }
        let first = kept.progress.lights_drawn;
        if first >= frame.lights.len() {
            return Ok(kept.progress);
        }
        let count = (frame.options.dodm.batch_size.max(1) as usize).min(frame.lights.len() - first);
        let batch: Vec<EnvLight> = kept.order[first..first + count]
            .iter()
            .map(|&i| frame.lights[i])
            .collect();
        // κ's strand windows continue from the simplified lights drawn before this batch, so
        // the batches sum to the frame drawn at once.
        let windows_before = kept.order[..first]
            .iter()
            .filter(|&&i| frame.lights[i].is_simplified())
            .count() as u32;
        let stats = self.env.encode_part_into(
            &self.gpu,
            frame.model,
            frame.camera,
            (&batch, windows_before),
            frame.tables,
            frame.options,
            frame.multiple,
            frame.head,
            &kept.sums,
        )?;
        kept.last_stats = Some(stats);
        kept.progress.lights_drawn += count;
        Ok(kept.progress)
    }

    /// The frame's progress; `None` before [`Self::prepare`].
    pub fn progress(&self) -> Option<BatchProgress> {
        self.frame.as_ref().map(|f| f.progress)
    }

    /// Multiplies the radiance drawn by [`Self::render`] by `scale`: an exposure (`2^stops`),
    /// or a progressive frame's running sum over the share of the power drawn so far.
    pub fn set_radiance_scale(&self, scale: f32) {
        if let Some(kept) = &self.frame {
            kept.composite.set_scale(&self.gpu.queue, scale);
        }
    }

    /// Draws the frame so far into the host's `pass`, whose attachments are the
    /// [`HairTargets`] this renderer was made for and the frame's size: pre-multiplied over
    /// the host's colour, hidden where the host's depth is nearer. Draws nothing before
    /// [`Self::prepare`].
    pub fn render(&self, pass: &mut wgpu::RenderPass<'_>) {
        if let Some(kept) = &self.frame {
            self.composite.draw(pass, &kept.composite);
        }
    }

    /// The env-lit frame so far, read back to the CPU with its stats (linear, pre-multiplied;
    /// the radiance scale is not applied): the one readback, for a headless host that writes
    /// files. Waits for the GPU.
    pub fn read_image(&self) -> Result<EnvImage, EnvRenderError> {
        let Some(kept) = &self.frame else {
            return Err(EnvRenderError::NotPrepared);
        };
        let stats = kept.last_stats.clone().ok_or(EnvRenderError::NotPrepared)?;
        EnvRenderer::read_sums(&self.gpu, &kept.sums, kept.with_multiple, stats)
    }

    /// The frame so far as [`Self::render`] draws it (linear, pre-multiplied: single and
    /// multiple scattering added; the radiance scale is not applied), read back, for either
    /// lighting. Waits for the GPU.
    pub fn read_pixels(&self) -> Result<Vec<[f32; 4]>, EnvRenderError> {
        let Some(kept) = &self.frame else {
            return Err(EnvRenderError::NotPrepared);
        };
        let bytes = crate::gpu::readback::read_buffer(&self.gpu, kept.sums.buffer())?;
        let sums: &[[f32; 4]] = bytemuck::cast_slice(&bytes);
        let (single, multiple) = sums.split_at(sums.len() / 2);
        Ok(single
            .iter()
            .zip(multiple)
            .map(|(s, m)| [s[0] + m[0], s[1] + m[1], s[2] + m[2], s[3]])
            .collect())
    }

    /// The frame's front depth (wgpu's 0..1, 1 where neither hair nor head is), read back:
    /// for tests of a host's depth test.
    pub fn read_front_depth(&self) -> Result<Vec<f32>, EnvRenderError> {
        let Some(kept) = &self.frame else {
            return Err(EnvRenderError::NotPrepared);
        };
        let depth = kept.sums.front_depth().expect("the host's sums keep one");
        Ok(crate::gpu::readback::read_depth(&self.gpu, depth)?)
    }
}

/// Draws frames of the thesis techniques into [`FrameSums`] a caller keeps, on the GPU: what
/// [`HairRenderer::draw_point_lit`] does for its own frame, for an application that shows the
/// sums itself (the viewer's display pass reads them where they are).
pub struct PointLitDrawer {
    gather: PointGatherPass,
}

impl PointLitDrawer {
    /// The gather pipeline on `gpu`'s device.
    pub fn new(gpu: &GpuContext) -> Self {
        Self {
            gather: PointGatherPass::new(gpu),
        }
    }

    /// Draws `frame` whole and gathers it into `sums` (the frame's size; their single-scattering
    /// half gets the hair over the skin, the multiple-scattering half zero), submitted without
    /// reading anything back, and the frame's costs. With a front depth in `sums`, the
    /// nearest of head and fiber is drawn there. Errors name the setting or limit at fault.
    pub fn draw_into(
        &self,
        gpu: &GpuContext,
        frame: &PointLitFrame<'_>,
        sums: &FrameSums,
    ) -> Result<RenderStats, RenderError> {
        if sums.size() != [frame.params.width, frame.params.height] {
            return Err(RenderError::SumsSize {
                sums: sums.size(),
                frame: [frame.params.width, frame.params.height],
            });
        }
        let drawn = submit_frame(
            gpu,
            frame.model,
            frame.params,
            frame.options,
            frame.shading,
            frame.head,
            sums.front_depth(),
        )?;
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        self.gather.encode(gpu, &mut encoder, &drawn, sums);
        gpu.queue.submit([encoder.finish()]);
        Ok(drawn.stats(gpu))
    }
}
