//! The env-lit view shading pass (Ren 2010 §3.1, §5–6): each fiber the frame's visibility lets
//! through ([`ViewTransparency`]: the nearest fiber of each pixel, shaded by a full-screen pass;
//! every fragment of the strands rasterized again through the occupancy map; or the occupancy
//! map's layers) loops over a batch's lights and sums T̃ × table lookup × light weight (single
//! scattering) and, with a forward-scattering grid, power × T_f × I_G (multiple scattering) into
//! the two targets of [`EnvViewTargets`] (`view_shading.wgsl`, `env_shading.wgsl`).
//!
//! Inputs: the strands (group 0), [`BatchBinding`] (group 1: lights, DODM, SATs),
//! [`TableBinding`] (group 2: the tables), [`ViewBinding`] (group 3: the batch's grid and the
//! frame's visibility). Output: the batch's single and multiple images in [`EnvViewTargets`].

use super::segment_light_visibility::SegmentLightVisibilityPass;
use super::table_binding::{TableBinding, table_bind_group_layout};
use super::view_binding::{ViewBinding, view_bind_group_layout};
use super::view_targets::EnvViewTargets;
use super::view_visibility::{OccupancyMap, ViewTransparency, ViewVisibilityPass};
use crate::gpu::GpuContext;
use crate::gpu::bind_layout::pipeline_layout;
use crate::gpu::pipeline::{
    ADDITIVE, LazyPipeline, StrandDraw, build_both, color_target, depth_test,
};
use crate::passes::attachments::{cleared_color, prepassed_depth};
use crate::passes::convolution_transmittance::{BatchBinding, transmittance_bind_group_layout};
use crate::passes::render_target::DEPTH_FORMAT;
use crate::passes::strand_geometry::StrandGeometry;
use crate::passes::strand_quads::strand_bind_group_layout_vertex_storage;
use crate::shaders::{Wgsl, shader_module};

/// The bind group layouts of the view passes: strands (0), the batch's lights, DODM and SATs
/// (1), the tables (2), the grid and the frame's visibility (3).
pub(super) struct EnvViewLayouts {
    pub(super) strand: wgpu::BindGroupLayout,
    pub(super) batch: wgpu::BindGroupLayout,
    pub(super) table: wgpu::BindGroupLayout,
    pub(super) view: wgpu::BindGroupLayout,
}

impl EnvViewLayouts {
    pub(super) fn new(device: &wgpu::Device) -> Self {
        Self {
            strand: strand_bind_group_layout_vertex_storage(device),
            // COMPUTE: the compact sources' visibility at the strands' points.
            batch: transmittance_bind_group_layout(
                device,
                wgpu::ShaderStages::FRAGMENT | wgpu::ShaderStages::COMPUTE,
            ),
            table: table_bind_group_layout(device),
            view: view_bind_group_layout(device),
        }
    }
}

/// The frame's visibility pass, its shader composed from `view_visibility.wgsl`.
pub(super) fn view_visibility_pass(
    gpu: &GpuContext,
    layouts: &EnvViewLayouts,
) -> ViewVisibilityPass {
    let device = &gpu.device;
    let top = Wgsl {
        file: "view_visibility.wgsl",
        source: include_str!("view_visibility.wgsl"),
    };
    let shader = shader_module(device, &top, None);
    let visibility_layout = pipeline_layout(
        device,
        "view visibility",
        &[Some(&layouts.strand), None, None, Some(&layouts.view)],
    );
    // The coverage pass writes the texture group 3 reads: it binds the strands alone.
    let strands_only = pipeline_layout(device, "view coverage", &[Some(&layouts.strand)]);
    ViewVisibilityPass::new(
        device,
        &shader,
        &visibility_layout,
        &strands_only,
        gpu.hdr_format(),
    )
}

/// A view pipeline writing the single and multiple targets (`format`) from vertex entry
/// `vertex` and fragment entry `entry`.
fn view_pipeline(
    device: &wgpu::Device,
    format: wgpu::TextureFormat,
    layout: &wgpu::PipelineLayout,
    shader: &wgpu::ShaderModule,
    (label, vertex, entry): (&str, &str, &str),
    blend: Option<wgpu::BlendState>,
) -> wgpu::RenderPipeline {
    let target = color_target(format, blend);
    StrandDraw {
        label,
        layout,
        shader,
        vertex_entry: vertex,
        fragment: Some((entry, &[target.clone(), target])),
        depth: None,
    }
    .build(device)
}

/// The view shading pipelines, one per view transparency, and the skin behind the hair; each
/// compiled when a frame first uses it.
pub(super) struct ViewShadingPass {
    opaque: LazyPipeline,
    /// The opaque view of a frame of single scattering whose lights all read their light maps
    /// (`fs_env_deferred_single`): a smaller shader than `opaque`'s. A first look's: on
    /// SwiftShader its first frame at 320×240 drew its view in 0.95 s against 1.25 s.
    opaque_single_from_light_maps: LazyPipeline,
    transparent: LazyPipeline,
    layered: LazyPipeline,
    /// A batch of compact sources in the layered view: its lights' visibility along every
    /// strand segment, then gathered per layer (`vs_/fs_env_layer_lights`) before the layers are
    /// shaded.
    segment_light_visibility: SegmentLightVisibilityPass,
    layer_lights: LazyPipeline,
    /// Occupancy and layered views: the skin behind the pixel's fibers (`skin.wgsl`), added
    /// after them.
    skin_behind_hair: LazyPipeline,
}

/// What one batch's view shading binds and draws into.
pub(super) struct ViewShadingInputs<'a> {
    pub(super) geometry: &'a StrandGeometry,
    /// Intervals the gather of compact sources' visibility cuts each segment into.
    pub(super) gather_intervals: u32,
    pub(super) strands: &'a wgpu::BindGroup,
    pub(super) transparency: ViewTransparency,
    pub(super) batch: &'a BatchBinding,
    pub(super) tables: &'a TableBinding,
    pub(super) view: &'a ViewBinding,
    pub(super) with_head: bool,
    /// Single scattering, every light shadowed by its light map (no grid, no visibility
    /// volume): the opaque view takes its smaller shader.
    pub(super) single_from_light_maps: bool,
    /// A batch whose layers read their fibers' mean light visibility: the map that holds it and
    /// the frame's depth (attached, not tested: the gathering tests against the head itself).
    pub(super) layer_lights: Option<(&'a OccupancyMap, &'a wgpu::TextureView)>,
}

impl ViewShadingPass {
    pub(super) fn new(gpu: &GpuContext, layouts: &EnvViewLayouts) -> Self {
        let top = Wgsl {
            file: "view_shading.wgsl",
            source: include_str!("view_shading.wgsl"),
        };
        let shader = shader_module(&gpu.device, &top, None);
        let layout = pipeline_layout(
            &gpu.device,
            "env view",
            &[
                Some(&layouts.strand),
                Some(&layouts.batch),
                Some(&layouts.table),
                Some(&layouts.view),
            ],
        );
        let (device, format) = (gpu.device.clone(), gpu.hdr_format());
        let lazy = |names: (&'static str, &'static str, &'static str), blend| {
            let (device, layout, shader) = (device.clone(), layout.clone(), shader.clone());
            LazyPipeline::new(move || {
                view_pipeline(&device, format, &layout, &shader, names, blend)
            })
        };
        let segment_light_visibility = SegmentLightVisibilityPass::new(gpu, &layouts.batch);
        let gather_layout = pipeline_layout(
            &gpu.device,
            "env view (layers' light visibility)",
            &[
                Some(&layouts.strand),
                Some(&layouts.batch),
                Some(&segment_light_visibility.gather_layout),
                Some(&layouts.view),
            ],
        );
        let gather = {
            let (device, shader) = (device.clone(), shader.clone());
            LazyPipeline::new(move || {
                StrandDraw {
                    label: "env view (layers' light visibility)",
                    layout: &gather_layout,
                    shader: &shader,
                    vertex_entry: "vs_layer_lights",
                    fragment: Some(("fs_env_layer_lights", &[])),
                    depth: Some(depth_test(
                        DEPTH_FORMAT,
                        false,
                        wgpu::CompareFunction::Always,
                    )),
                }
                .build(&device)
            })
        };
        Self {
            // The depth prepass left each pixel's nearest fiber in two textures: the opaque
            // view shades those pixels, rasterizing no strand per batch.
            opaque: lazy(
                ("env view (opaque)", "vs_fullscreen", "fs_env_deferred"),
                None,
            ),
            opaque_single_from_light_maps: lazy(
                (
                    "env view (opaque, single scattering from light maps)",
                    "vs_fullscreen",
                    "fs_env_deferred_single",
                ),
                None,
            ),
            transparent: lazy(
                ("env view (occupancy)", "vs_main", "fs_env_transparent"),
                Some(ADDITIVE),
            ),
            // The layers the frame's visibility gathered: a full-screen pass, added to by the
            // skin.
            layered: lazy(
                ("env view (layered)", "vs_fullscreen", "fs_env_layered"),
                Some(ADDITIVE),
            ),
            segment_light_visibility,
            layer_lights: gather,
            skin_behind_hair: lazy(
                (
                    "env view (skin behind hair)",
                    "vs_fullscreen",
                    "fs_env_skin",
                ),
                Some(ADDITIVE),
            ),
        }
    }

    /// Compiles the pipelines a frame in `transparency`, with a head or not, of single
    /// scattering from light maps or not, draws with, side by side ([`build_both`]), before
    /// its first batch needs them.
    pub(super) fn compile(
        &self,
        transparency: ViewTransparency,
        with_head: bool,
        single_from_light_maps: bool,
    ) {
        match transparency {
            ViewTransparency::Opaque => {
                self.opaque_pipeline(single_from_light_maps);
            }
            ViewTransparency::Occupancy { .. } => {
                build_both(|| self.transparent.get(), || self.skin_behind_hair.get());
            }
            ViewTransparency::Layered { .. } => {
                build_both(
                    || self.layered.get(),
                    || {
                        build_both(
                            || {
                                self.layer_lights.get();
                                self.segment_light_visibility.pipeline(with_head);
                            },
                            || self.skin_behind_hair.get(),
                        )
                    },
                );
            }
        }
    }

    /// Encodes one batch's view into `targets` (opaque: a full-screen pass over the nearest
    /// fibers the frame's depth prepass left; occupancy: the strands rasterized again).
    pub(super) fn encode(
        &self,
        gpu: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        inputs: &ViewShadingInputs<'_>,
        targets: &EnvViewTargets,
    ) {
        if let Some((map, depth)) = inputs.layer_lights {
            self.encode_layer_lights(gpu, encoder, inputs, map, depth);
        }
        let single = targets.single.create_view(&Default::default());
        let multiple = targets.multiple.create_view(&Default::default());
        let transparency = inputs.transparency;
        let (pipeline, vertices, instances) = match transparency {
            ViewTransparency::Opaque => (self.opaque_pipeline(inputs.single_from_light_maps), 3, 1),
            ViewTransparency::Occupancy { .. } => {
                (self.transparent.get(), 6, inputs.geometry.segment_count)
            }
            ViewTransparency::Layered { .. } => (self.layered.get(), 3, 1),
        };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("env view"),
            color_attachments: &[cleared_color(&single), cleared_color(&multiple)],
            depth_stencil_attachment: None,
            timestamp_writes: gpu.render_timestamps(),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, inputs.strands, &[]);
        pass.set_bind_group(1, &inputs.batch.group, &[]);
        pass.set_bind_group(2, &inputs.tables.group, &[]);
        pass.set_bind_group(3, &inputs.view.group, &[]);
        pass.draw(0..vertices, 0..instances);
        if transparency.uses_occupancy_map() && inputs.with_head {
            pass.set_pipeline(self.skin_behind_hair.get());
            pass.draw(0..3, 0..1);
        }
    }

    fn opaque_pipeline(&self, single_from_light_maps: bool) -> &wgpu::RenderPipeline {
        match single_from_light_maps {
            true => self.opaque_single_from_light_maps.get(),
            false => self.opaque.get(),
        }
    }

    /// The batch's lights' visibility, Σw·v per layer and light, gathered from every fragment
    /// the layers hold (zeroed first), v interpolated along its segment.
    fn encode_layer_lights(
        &self,
        gpu: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        inputs: &ViewShadingInputs<'_>,
        map: &OccupancyMap,
        depth: &wgpu::TextureView,
    ) {
        let samples = self.segment_light_visibility.encode(
            gpu,
            encoder,
            (inputs.geometry, inputs.gather_intervals),
            inputs.batch,
            inputs.with_head,
        );
        map.clear_layer_lights(encoder);
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("env view (layers' light visibility)"),
            color_attachments: &[],
            depth_stencil_attachment: prepassed_depth(depth),
            timestamp_writes: gpu.render_timestamps(),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(self.layer_lights.get());
        pass.set_bind_group(0, inputs.strands, &[]);
        pass.set_bind_group(1, &inputs.batch.group, &[]);
        pass.set_bind_group(2, &samples.gather_group, &[]);
        pass.set_bind_group(3, &inputs.view.group, &[]);
        pass.draw(0..6 * inputs.geometry.segment_count, 0..1);
    }
}
