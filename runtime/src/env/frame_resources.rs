//! What one env-lit frame is asked for, and the resources it renders into, created once before
//! its batches.

use std::sync::Arc;

use strandlight_tables::table::Table;

use super::accumulate::FrameSums;
use super::light_kinds::LightKinds;
use super::light_maps::FrameLightMaps;
use super::segment_light_visibility::{intervals_per_segment, slots_that_fit};
use super::stats::Timings;
use super::table_binding::TableBinding;
use super::tables::check_table_limits;
use super::view_binding::FrameVisibility;
use super::view_targets::EnvViewTargets;
use super::view_visibility::OccupancyMap;
use super::volume::VolumeBuffers;
use super::{EnvRenderError, EnvRenderOptions, EnvRenderer, EnvTables};
use crate::camera::{Camera, LightFootprint};
use crate::gpu::GpuContext;
use crate::gpu::limits::GpuLimits;
use crate::hair::{Aabb, HairModel};
use crate::head::Head;
use crate::multiple::ForwardScatteringSource;
use crate::passes::convolution_depth::{SimplifiedSegments, simplification_order};
use crate::passes::frame_params::{FrameParams, KajiyaKay, QuadStyle};
use crate::passes::head::{HeadDepthMaps, HeadGeometry};
use crate::passes::strand_geometry::StrandGeometry;
use crate::passes::strand_quads::strand_bind_group_styled;

/// What one frame is asked for.
pub(super) struct FrameRequest<'a> {
    pub(super) model: &'a HairModel,
    pub(super) camera: &'a Camera,
    pub(super) width: u32,
    pub(super) height: u32,
    pub(super) tables: &'a EnvTables,
    pub(super) options: &'a EnvRenderOptions,
    pub(super) multiple: Option<&'a dyn ForwardScatteringSource>,
    pub(super) head: Option<&'a Head>,
}

impl FrameRequest<'_> {
    /// Single scattering with every light shadowed by its light map: no forward-scattering
    /// grid, no visibility volume.
    pub(super) fn single_from_light_maps(&self) -> bool {
        single_from_light_maps(self.options, self.multiple.is_some())
    }
}

/// [`FrameRequest::single_from_light_maps`] of a frame with `options`, with multiple
/// scattering or not.
pub(super) fn single_from_light_maps(options: &EnvRenderOptions, with_multiple: bool) -> bool {
    !with_multiple && options.lobe_visibility.volume().is_none()
}

/// What every part of a frame sees alike: the hair as uploaded (all of it for the view and
/// directional lights, the κ-simplified order for SRBF light passes), the head, and the view's
/// visibility (its depth, nearest fibers and coverage, or its occupancy map). The frame's first
/// part creates it and draws the visibility; a progressive frame keeps it in its [`FrameSums`]
/// for the parts that follow ([`FrameSums::kept_view`]), which draw only their lights. It lives
/// as long as the sums keep it (until their owner drops them or starts another frame).
#[derive(Clone)]
pub(super) struct FrameView {
    pub(super) geometry: StrandGeometry,
    pub(super) light_geometry: StrandGeometry,
    /// κ < 1: the strands in simplification order, whose windows the simplified light passes
    /// draw.
    pub(super) simplified: Option<Arc<SimplifiedSegments>>,
    pub(super) occupancy: OccupancyMap,
    pub(super) targets: EnvViewTargets,
    pub(super) width: u32,
    pub(super) height: u32,
    /// Group 0 of every view and visibility pass.
    pub(super) strands: wgpu::BindGroup,
    pub(super) coverage_view: wgpu::TextureView,
    /// [`EnvViewTargets::nearest_position`] and `nearest_tangent`.
    pub(super) nearest_views: [wgpu::TextureView; 2],
    pub(super) depth_view: wgpu::TextureView,
    /// The groom's visibility volume (or its placeholder under Ren's light maps).
    pub(super) volume: Arc<VolumeBuffers>,
    /// The head (issue 40), drawn into the view's depth and every light map.
    pub(super) head: Option<HeadGeometry>,
    /// The view camera's world to clip space.
    pub(super) view_proj: glam::Mat4,
    /// Intervals the gather of compact sources' visibility cuts each segment into
    /// ([`intervals_per_segment`]).
    pub(super) gather_intervals: u32,
    /// [`EnvViewTargets::head_position`] and `head_normal`.
    pub(super) head_views: [wgpu::TextureView; 2],
}

/// What one part of a frame renders into, created before its passes: the frame's [`FrameView`],
/// the DODM batch (DODM: the convolution optical depth map of Ren 2010 §5, one layer per light)
/// and its summed-area tables, and the tables bound per light kind.
pub(super) struct FrameResources {
    pub(super) view: Arc<FrameView>,
    /// Whether `view`'s visibility is still to be drawn (the frame's first part).
    pub(super) view_is_new: bool,
    /// The next simplified light's strand window (κ < 1).
    pub(super) next_window: u32,
    pub(super) footprint: LightFootprint,
    /// The light maps of every size the frame's batches draw.
    pub(super) maps: FrameLightMaps,
    /// The single-scattering tables of the SRBF and the directional lights (None: no such
    /// lights), each bound with the multiple-scattering table.
    pub(super) srbf_tables: Option<Arc<TableBinding>>,
    pub(super) directional_tables: Option<Arc<TableBinding>>,
}

impl FrameView {
    /// The visibility input of group 3 for this frame.
    pub(super) fn visibility(&self, options: &EnvRenderOptions) -> FrameVisibility<'_> {
        FrameVisibility {
            volume: &self.volume,
            map: &self.occupancy,
            coverage: &self.coverage_view,
            nearest: [&self.nearest_views[0], &self.nearest_views[1]],
            transparency: options.transparency,
            width: self.width,
            height: self.height,
            head: [&self.head_views[0], &self.head_views[1]],
            skin: self.head.as_ref().map(|h| h.albedo),
            view_proj: self.view_proj,
            layer_lights: false,
        }
    }
}

impl FrameResources {
    /// The strand windows of the next `lights` simplified light maps (the frame's κ-thinned
    /// SRBF lights, counted across batches): each light its own subset
    /// ([`SimplifiedSegments::window`]).
    pub(super) fn next_windows(
        &mut self,
        lights: usize,
        kappa: f32,
    ) -> Vec<Vec<std::ops::Range<u32>>> {
        let Some(simplified) = &self.view.simplified else {
            return vec![vec![0..self.view.light_geometry.segment_count]; lights];
        };
        let first = self.next_window;
        self.next_window += lights as u32;
        (first..self.next_window)
            .map(|k| simplified.window(kappa, k))
            .collect()
    }

    /// GPU memory held while one batch renders, per resource (tables and grid added later).
    pub(super) fn memory(&self) -> Vec<(String, u64)> {
        let view = &self.view;
        let mut memory = view.geometry.memory();
        memory.extend(self.maps.memory());
        memory.extend(view.targets.memory());
        memory.push(view.occupancy.memory());
        memory.push(("visibility volume".into(), view.volume.bytes));
        if let Some(head) = &view.head {
            memory.push(("head geometry".into(), head.bytes()));
        }
        memory
    }
}

/// The geometry the SRBF light passes draw: when κ < 1, the strands in simplification order
/// (with that order, whose windows the passes draw); else all of them as they are.
fn light_pass_geometry(
    gpu: &GpuContext,
    model: &HairModel,
    geometry: &StrandGeometry,
    options: &EnvRenderOptions,
) -> (StrandGeometry, Option<SimplifiedSegments>) {
    if options.kappa >= 1.0 {
        return (geometry.clone(), None);
    }
    let order = simplification_order(model, options.simplification_seed);
    let simplified = SimplifiedSegments::in_order(gpu, model, &order);
    (
        simplified.geometry(geometry, options.kappa),
        Some(simplified),
    )
}

/// What a light's map must hold: the hair, and the head whose skin it shadows and which shadows
/// the hair (outside a map a point reads as lit, and a caster past its depth range casts
/// nothing). The box holds both, for every map's depth range and a lobe's sphere; a compact
/// source's map is fitted across the light to the points of both. Without compact sources no
/// map is fitted, and the points are not copied.
fn light_footprint(
    model: &HairModel,
    head: Option<&Head>,
    has_compact_sources: bool,
) -> LightFootprint {
    let hair_bounds = model.bounds();
    let bounds = match head {
        Some(head) => {
            let h = head.bounds();
            Aabb {
                min: hair_bounds.min.min(h.min),
                max: hair_bounds.max.max(h.max),
            }
        }
        None => hair_bounds,
    };
    if !has_compact_sources {
        return LightFootprint::new(bounds, Vec::new().into());
    }
    let mut points = model.points().to_vec();
    if let Some(head) = head {
        points.extend_from_slice(&head.triangles().positions);
    }
    LightFootprint::new(bounds, points.into())
}

/// What decides a frame's view: a part whose key differs from the kept view's draws its own.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct ViewKey {
    camera: Camera,
    options: EnvRenderOptions,
    hair: (usize, usize, Aabb),
    head: Option<(Aabb, [f32; 3])>,
}

impl ViewKey {
    pub(super) fn of(request: &FrameRequest<'_>) -> Self {
        let model = request.model;
        Self {
            camera: *request.camera,
            // The light maps' settings are each part's own.
            options: EnvRenderOptions {
                dodm: Default::default(),
                count_fragments: false,
                ..*request.options
            },
            hair: (model.segment_count(), model.points().len(), model.bounds()),
            head: request.head.map(|h| (h.bounds(), h.albedo)),
        }
    }
}

impl FrameView {
    /// The hair uploaded, the head and the view's targets, after checking them against the
    /// adapter's limits; the visibility is not drawn yet.
    fn new(
        gpu: &GpuContext,
        renderer: &EnvRenderer,
        request: &FrameRequest<'_>,
        (compact_slots, gather_intervals): (u32, u32),
        timings: &mut Timings,
    ) -> Result<Self, EnvRenderError> {
        let FrameRequest {
            model,
            camera,
            width,
            height,
            options,
            head,
            ..
        } = *request;
        GpuLimits::of(gpu).check_image(width, height)?;
        let occupancy =
            OccupancyMap::new(gpu, options.transparency, (width, height), compact_slots)?;
        FrameSums::check_limits(gpu, width, height)?;
        let geometry = timings.time(gpu, "upload", || StrandGeometry::upload(gpu, model))?;
        // Per hair and settings, not per light or view: setup, as the upload is.
        let (light_geometry, simplified) = timings.time(gpu, "upload", || {
            light_pass_geometry(gpu, model, &geometry, options)
        });
        let simplified = simplified.map(Arc::new);
        let head_geometry =
            head.map(|h| timings.time(gpu, "upload", || HeadGeometry::upload(gpu, h)));
        let targets = EnvViewTargets::new(
            gpu,
            width,
            height,
            options.transparency,
            head_geometry.is_some(),
        );
        let view_params = FrameParams {
            camera: *camera,
            width,
            height,
            lights: Vec::new(),
            shading: KajiyaKay::default(),
            width_override_px: options.width_override_px,
        };
        let volume = renderer
            .volume
            .buffers(gpu, model, head, options, timings)?;
        let head_views = [&targets.head_position, &targets.head_normal]
            .map(|t| t.create_view(&Default::default()));
        Ok(Self {
            strands: strand_bind_group_styled(
                gpu,
                &renderer.layouts.strand,
                &geometry,
                &view_params,
                match options.exact_coverage {
                    true => QuadStyle::ExactCoverage,
                    false => QuadStyle::PixelQuads,
                },
            ),
            view_proj: view_params.view_proj(),
            coverage_view: targets.coverage.create_view(&Default::default()),
            nearest_views: [&targets.nearest_position, &targets.nearest_tangent]
                .map(|t| t.create_view(&Default::default())),
            depth_view: targets.depth.create_view(&Default::default()),
            geometry,
            light_geometry,
            simplified,
            occupancy,
            targets,
            width,
            height,
            volume,
            head_views,
            head: head_geometry,
            gather_intervals,
        })
    }
}

impl FrameResources {
    /// Creates the part's resources, after checking them against the adapter's limits. A part
    /// added into `kept`'s sums after another part of the same frame reuses the view that part
    /// kept there (its occupancy map grown when this part's compact sources need more slots).
    pub(super) fn new(
        gpu: &GpuContext,
        renderer: &EnvRenderer,
        request: &FrameRequest<'_>,
        kinds: &LightKinds,
        kept: Option<&FrameSums>,
        timings: &mut Timings,
    ) -> Result<Self, EnvRenderError> {
        let FrameRequest {
            model,
            width,
            height,
            tables,
            options,
            multiple,
            head,
            ..
        } = *request;
        let gather_intervals = intervals_per_segment(
            model,
            request.camera.view_projection([width, height]),
            (width, height),
        );
        let segments = model.segment_count() as u64;
        let compact_slots = kinds
            .compact_sources()
            .min(options.dodm.batch_size as usize) as u32;
        let compact_slots = slots_that_fit(gpu, segments, gather_intervals, compact_slots);
        let key = ViewKey::of(request);
        let (view, view_is_new) = match kept.and_then(|sums| sums.kept_view(&key)) {
            Some(view) => {
                let size = (width, height);
                match (view.occupancy).grown(gpu, options.transparency, size, compact_slots)? {
                    Some(occupancy) => {
                        let grown = FrameView {
                            occupancy,
                            ..(*view).clone()
                        };
                        (Arc::new(grown), false)
                    }
                    None => (view, false),
                }
            }
            None => {
                let slots = (compact_slots, gather_intervals);
                let view = FrameView::new(gpu, renderer, request, slots, timings)?;
                (Arc::new(view), true)
            }
        };
        let first_layer = options.dodm.first_layer_for(model.bounds());
        let mut maps = FrameLightMaps::for_frame(gpu, options, kinds, first_layer)?;
        if view.head.is_some() {
            for maps in maps.each_mut() {
                maps.head = Some(HeadDepthMaps::new(
                    gpu,
                    maps.dodm.resolution,
                    maps.dodm.slots,
                ));
            }
        }
        check_table_limits(gpu, tables, kinds, multiple.is_some())?;
        let [srbf_tables, directional_tables] = timings.time(gpu, "table upload", || {
            bind_kind_tables(gpu, renderer, request, kinds)
        });
        if let Some(sums) = kept {
            sums.keep_view(key, view.clone());
        }
        Ok(Self {
            view,
            view_is_new,
            next_window: 0,
            footprint: light_footprint(model, head, kinds.has_sharp_shadows()),
            maps,
            srbf_tables,
            directional_tables,
        })
    }
}

/// The single-scattering tables of the SRBF and the directional lights, each bound with the
/// multiple-scattering table (None: the frame has no lights of that kind).
fn bind_kind_tables(
    gpu: &GpuContext,
    renderer: &EnvRenderer,
    request: &FrameRequest<'_>,
    kinds: &LightKinds,
) -> [Option<Arc<TableBinding>>; 2] {
    let tables = request.tables;
    let multiple_table = request.multiple.and(tables.multiple.as_ref());
    let bind = |needed: bool, t: &Option<Arc<Table>>| {
        t.as_ref()
            .filter(|_| needed)
            .map(|t| (renderer.tables).binding(gpu, &renderer.layouts.table, t, multiple_table))
    };
    [
        bind(kinds.has_srbf(), &tables.srbf),
        bind(kinds.has_directional(), &tables.direct),
    ]
}
