//! One env-lit frame (Ren 2010): per batch of lights of one kind, the light pass (DODM), the
//! summed-area tables, then the view pass whose images are summed on the GPU; one readback at
//! the end. [`EnvRenderer`] keeps the pipelines across frames; [`render_env_frame`] builds them
//! for one frame.

use std::time::Instant;

use strandlight_tables::table::Table;
use strandlight_tables::table_axes::{
    AXIS_COS_DPHI, AXIS_INV_LAMBDA, AXIS_SIGMA_F, AXIS_U_DOT_WO, AXIS_U_DOT_XI,
};

use super::{EnvLight, ForwardScatteringGrid, ForwardScatteringSource};
use crate::camera::Camera;
use crate::gpu::readback::{ReadbackError, read_buffer};
use crate::gpu::{AdapterReport, GpuContext};
use crate::hair::HairModel;
use crate::passes::convolution_depth::{
    ConvolutionDepthPass, DodmBatch, DodmSettings, DodmSettingsError, SimplifiedSegments,
    check_kappa,
};
use crate::passes::env_view::{
    BatchBinding, EnvViewPass, EnvViewTargets, FrameVisibility, TableBinding, ViewBinding,
};
use crate::passes::frame_params::{FrameParams, KajiyaKay};
use crate::passes::strand_geometry::{StrandGeometry, TooManyPoints};
pub use crate::passes::summed_area::BoxAverage;
use crate::passes::summed_area::{SatTooLarge, SummedAreaPass, SummedAreaTables};
pub use crate::passes::transmittance_filter::TransmittanceFilter;
use crate::passes::view_visibility::OccupancyMap;
pub use crate::passes::view_visibility::{FragmentCounts, OccupancyError, ViewTransparency};
use crate::render::PassTiming;

/// The tables a frame shades with. Each is an RGB [`Table`] with axes (u·ξ, u·ω_o, cos Δφ, w):
/// * `srbf`: the convolution table I (I_M, `marschner_full` or the artist I_A), w = 1/λ;
/// * `direct`: S(ω_i, ω_o)·cos θ_i for directional lights, w a one-node axis (any name);
/// * `multiple`: I_G, w = σ̄_f (used only with a [`ForwardScatteringSource`]).
#[derive(Clone, Debug, Default)]
pub struct EnvTables {
    pub srbf: Option<Table>,
    pub direct: Option<Table>,
    pub multiple: Option<Table>,
}

#[derive(Debug, thiserror::Error, PartialEq)]
pub enum EnvTableError {
    #[error("env table `{table}` is needed ({needed_by}) but was not given")]
    Missing {
        table: &'static str,
        needed_by: &'static str,
    },
    #[error("env table `{table}`: {problem}")]
    Shape {
        table: &'static str,
        problem: String,
    },
}

/// Checks an env table's layout: 4 axes, the three direction axes by name, the fourth named
/// `fourth` (or any name with one node when `None`), 3 channels.
pub fn check_env_table(
    table_name: &'static str,
    table: &Table,
    fourth: Option<&str>,
) -> Result<(), EnvTableError> {
    let bad = |problem: String| EnvTableError::Shape {
        table: table_name,
        problem,
    };
    let axes = table.axes();
    if axes.len() != 4 {
        return Err(bad(format!("has {} axes, expected 4", axes.len())));
    }
    for (axis, name) in axes
        .iter()
        .zip([AXIS_U_DOT_XI, AXIS_U_DOT_WO, AXIS_COS_DPHI])
    {
        if axis.name != name {
            return Err(bad(format!(
                "axis `{}` where `{name}` was expected",
                axis.name
            )));
        }
    }
    match fourth {
        Some(name) if axes[3].name != name => {
            return Err(bad(format!(
                "fourth axis `{}` where `{name}` was expected",
                axes[3].name
            )));
        }
        None if axes[3].count != 1 => {
            return Err(bad(format!(
                "fourth axis `{}` has {} nodes; a direct table has one",
                axes[3].name, axes[3].count
            )));
        }
        _ => {}
    }
    if table.channels() != 3 {
        return Err(bad(format!(
            "has {} channels, expected 3 (RGB)",
            table.channels()
        )));
    }
    if u32::try_from(table.values().len()).is_err() {
        return Err(bad("holds more than 2^32 values".into()));
    }
    Ok(())
}

/// Everything besides the scene that changes how a frame is rendered.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EnvRenderOptions {
    /// Light-pass map resolution, first-layer depth and lights per batch.
    pub dodm: DodmSettings,
    /// Stochastic simplification (Ren §7): the light pass of SRBF lights draws this fraction of
    /// the strands (their width enlarged by 1/κ, τ scaled by 1/κ); 1 draws them all. Default
    /// 0.1. Directional lights (a sun taken out of the map) always draw every strand: one sharp
    /// shadow is what the simplification would blur.
    pub kappa: f32,
    /// Seed of the strand shuffle behind κ.
    pub simplification_seed: u64,
    /// What the view sees of each pixel's fibers: the nearest one (default) or all of them
    /// through the occupancy map (Ren §8).
    pub transparency: ViewTransparency,
    /// Count the fragments rasterized and shaded ([`EnvRenderStats::fragments`]; two extra
    /// passes over the hair, outside the timed passes).
    pub count_fragments: bool,
    /// `false`: no self-shadowing (T̃ = 1; for tests and for comparisons).
    pub shadowed: bool,
    /// The averaging box of the effective transmittance (default
    /// [`TransmittanceFilter::MatchedVariance`], the best measured: docs/BENCHMARKS.md).
    pub transmittance_filter: TransmittanceFilter,
    /// What that box averages for SRBF lights (directional lights read one texel, where both
    /// agree): Ren's optical depth or the transmittance (docs/BENCHMARKS.md).
    pub box_average: BoxAverage,
    /// View pass only: every fiber this many pixels wide instead of its projected thickness (as
    /// `FrameParams::width_override_px`); the light pass always uses the file's thickness.
    pub width_override_px: Option<f32>,
}

impl Default for EnvRenderOptions {
    fn default() -> Self {
        Self {
            dodm: DodmSettings::default(),
            kappa: 0.1,
            simplification_seed: 0x5eed,
            transparency: ViewTransparency::Opaque,
            count_fragments: false,
            shadowed: true,
            transmittance_filter: TransmittanceFilter::default(),
            box_average: BoxAverage::default(),
            width_override_px: None,
        }
    }
}

#[derive(Debug, thiserror::Error)]
pub enum EnvRenderError {
    #[error("the environment has no lights")]
    NoLights,
    #[error("light {index}: {problem}")]
    BadLight { index: usize, problem: String },
    #[error(
        "image size {width}×{height} must be between 1 and {max} on each side (the adapter's limit)"
    )]
    BadSize { width: u32, height: u32, max: u32 },
    #[error(transparent)]
    Settings(#[from] DodmSettingsError),
    #[error(transparent)]
    Table(#[from] EnvTableError),
    #[error(transparent)]
    GpuLimit(#[from] SatTooLarge),
    #[error("forward-scattering grid: {0}")]
    Grid(String),
    #[error(transparent)]
    Transparency(#[from] OccupancyError),
    #[error(transparent)]
    TooManyPoints(#[from] TooManyPoints),
    #[error(transparent)]
    Readback(#[from] ReadbackError),
    #[error("the GPU reported an error: {0}")]
    Gpu(String),
}

#[derive(Clone, Debug)]
pub struct EnvRenderStats {
    pub adapter: AdapterReport,
    /// Per pass, summed over batches: "upload", "pipelines", "view visibility", "light pass",
    /// "summed-area tables", "view", "multiple grid (CPU)" or "multiple grid (GPU)", "readback".
    pub timings: Vec<PassTiming>,
    /// GPU memory held while one batch renders (the frame's buffers included), per resource.
    pub memory_per_batch: Vec<(String, u64)>,
    pub batches: u32,
    pub lights: u32,
    pub segments: u32,
    /// Segments an SRBF batch's light pass draws (κ of the strands; directional batches draw all).
    pub light_pass_segments: u32,
    pub timing_method: &'static str,
    /// With [`EnvRenderOptions::count_fragments`]: the fragments of one batch's view pass.
    pub fragments: Option<FragmentCounts>,
}

/// A rendered frame: linear, pre-multiplied RGBA, row-major from the top.
#[derive(Clone, Debug)]
pub struct EnvFrame {
    pub width: u32,
    pub height: u32,
    /// single + multiple.
    pub pixels: Vec<[f32; 4]>,
    pub single_pixels: Vec<[f32; 4]>,
    /// `None` without a forward-scattering source.
    pub multiple_pixels: Option<Vec<[f32; 4]>>,
    pub stats: EnvRenderStats,
}

fn check_light(index: usize, light: &EnvLight) -> Result<(), EnvRenderError> {
    let bad = |problem: String| EnvRenderError::BadLight { index, problem };
    if !light.direction.is_finite() || light.direction.length() < 1e-6 {
        return Err(bad(format!(
            "direction {:?} is not a usable unit vector",
            light.direction
        )));
    }
    if let Some(lambda) = light.lambda
        && !(lambda.is_finite() && lambda > 0.0)
    {
        return Err(bad(format!(
            "SRBF bandwidth λ = {lambda} must be positive and finite"
        )));
    }
    if light.rgb.iter().any(|c| !c.is_finite()) {
        return Err(bad(format!("rgb {:?} is not finite", light.rgb)));
    }
    Ok(())
}

fn check_grid(grid: &ForwardScatteringGrid, lights: usize) -> Result<(), EnvRenderError> {
    let vertices = grid.dims.iter().map(|&d| d as usize).product::<usize>();
    if vertices == 0 {
        return Err(EnvRenderError::Grid(format!(
            "dims {:?} has a zero",
            grid.dims
        )));
    }
    if grid.values.len() != vertices * lights {
        return Err(EnvRenderError::Grid(format!(
            "{} values for {lights} lights × {vertices} vertices",
            grid.values.len()
        )));
    }
    if !grid.origin.is_finite() || !grid.spacing.is_finite() || grid.spacing.min_element() <= 0.0 {
        return Err(EnvRenderError::Grid(format!(
            "origin {:?} / spacing {:?} must be finite, spacing positive",
            grid.origin, grid.spacing
        )));
    }
    if grid.values.iter().any(|v| v.iter().any(|c| !c.is_finite())) {
        return Err(EnvRenderError::Grid("holds non-finite values".into()));
    }
    Ok(())
}

/// Wall-clock totals per pass name.
struct Timings(Vec<PassTiming>);

impl Timings {
    fn time<T>(&mut self, gpu: &GpuContext, pass: &str, work: impl FnOnce() -> T) -> T {
        let start = Instant::now();
        let out = work();
        gpu.wait_idle();
        let ms = start.elapsed().as_secs_f64() * 1e3;
        match self.0.iter_mut().find(|t| t.pass == pass) {
            Some(t) => t.milliseconds += ms,
            None => self.0.push(PassTiming {
                pass: pass.to_string(),
                milliseconds: ms,
            }),
        }
        out
    }
}

/// The pipelines of the env-lit renderer, reusable across frames.
pub struct EnvRenderer {
    depth: ConvolutionDepthPass,
    sat: SummedAreaPass,
    view: EnvViewPass,
}

impl EnvRenderer {
    pub fn new(gpu: &GpuContext) -> Self {
        Self {
            depth: ConvolutionDepthPass::new(gpu),
            sat: SummedAreaPass::new(gpu),
            view: EnvViewPass::new(gpu),
        }
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
    ) -> Result<EnvFrame, EnvRenderError> {
        let mut timings = Timings(Vec::new());
        if lights.is_empty() {
            return Err(EnvRenderError::NoLights);
        }
        for (i, l) in lights.iter().enumerate() {
            check_light(i, l)?;
        }
        options.dodm.check()?;
        check_kappa(options.kappa)?;
        options.transparency.check()?;
        let max = gpu.device.limits().max_texture_dimension_2d;
        if width == 0 || height == 0 || width > max || height > max {
            return Err(EnvRenderError::BadSize { width, height, max });
        }
        let srbf_lights: Vec<EnvLight> = lights
            .iter()
            .copied()
            .filter(|l| l.lambda.is_some())
            .collect();
        let directional: Vec<EnvLight> = lights
            .iter()
            .copied()
            .filter(|l| l.lambda.is_none())
            .collect();
        if !srbf_lights.is_empty() {
            let t = tables.srbf.as_ref().ok_or(EnvTableError::Missing {
                table: "srbf",
                needed_by: "SRBF lights",
            })?;
            check_env_table("srbf", t, Some(AXIS_INV_LAMBDA))?;
        }
        if !directional.is_empty() {
            let t = tables.direct.as_ref().ok_or(EnvTableError::Missing {
                table: "direct",
                needed_by: "directional lights",
            })?;
            check_env_table("direct", t, None)?;
        }
        if multiple.is_some() {
            let t = tables.multiple.as_ref().ok_or(EnvTableError::Missing {
                table: "multiple",
                needed_by: "multiple scattering",
            })?;
            check_env_table("multiple", t, Some(AXIS_SIGMA_F))?;
        }
        let batch_size = options.dodm.batch_size as usize;
        let slots = batch_size.min(srbf_lights.len().max(directional.len())) as u32;
        let resolution = options.dodm.resolution;
        // Checked before anything is allocated.
        let mut sat = SummedAreaTables::new(gpu, resolution, slots)?;
        let occupancy = OccupancyMap::new(gpu, options.transparency, width, height)?;

        let scope = gpu.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let geometry = timings.time(gpu, "upload", || StrandGeometry::upload(gpu, model))?;
        let simplified = (options.kappa < 1.0)
            .then(|| SimplifiedSegments::new(gpu, model, options.simplification_seed));
        let light_geometry = match &simplified {
            Some(s) => s.geometry(&geometry, options.kappa),
            None => StrandGeometry {
                points: geometry.points.clone(),
                segments: geometry.segments.clone(),
                attributes: geometry.attributes.clone(),
                segment_count: geometry.segment_count,
                default_thickness: geometry.default_thickness,
            },
        };
        let bounds = model.bounds();
        let mut dodm = DodmBatch::new(gpu, resolution, slots, options.dodm.first_layer_for(bounds));
        let targets = EnvViewTargets::new(gpu, width, height, options.transparency);
        let sums = self.view.accumulator(gpu, &targets);
        let frame = FrameParams {
            camera: *camera,
            width,
            height,
            lights: Vec::new(),
            shading: KajiyaKay::default(),
            width_override_px: options.width_override_px,
        };
        let table_bindings = timings.time(gpu, "table upload", || {
            let multiple_table = multiple.and(tables.multiple.as_ref());
            let bind = |t: &Option<Table>| {
                t.as_ref()
                    .map(|t| TableBinding::new(gpu, &self.view.table_layout, t, multiple_table))
            };
            (
                if srbf_lights.is_empty() {
                    None
                } else {
                    bind(&tables.srbf)
                },
                if directional.is_empty() {
                    None
                } else {
                    bind(&tables.direct)
                },
            )
        });
        let mut memory: Vec<(String, u64)> = geometry.memory();
        memory.extend(dodm.memory());
        memory.extend(sat.memory());
        memory.extend(targets.memory());
        memory.push(occupancy.memory());
        memory.push(("env sums".into(), sums.sums.size()));
        let strands = self.view.strands(gpu, &geometry, &frame);
        let coverage_view = targets.coverage.create_view(&Default::default());
        let visibility = FrameVisibility {
            map: &occupancy,
            coverage: &coverage_view,
            transparency: options.transparency,
            width,
            height,
        };
        let depth_view = targets.depth.create_view(&Default::default());
        timings.time(gpu, "view visibility", || {
            let view = ViewBinding::new(gpu, &self.view.view_layout, None, &visibility);
            let mut encoder = gpu.device.create_command_encoder(&Default::default());
            self.view.visibility.encode(
                &mut encoder,
                options.transparency,
                &strands,
                &view.group,
                &depth_view,
                &coverage_view,
                &occupancy,
                geometry.segment_count,
            );
            gpu.queue.submit([encoder.finish()]);
        });
        let fragments = if options.count_fragments {
            let view = ViewBinding::new(gpu, &self.view.view_layout, None, &visibility);
            Some(self.view.visibility.count_fragments(
                gpu,
                options.transparency,
                &strands,
                &view.group,
                &depth_view,
                (width, height),
                geometry.segment_count,
            )?)
        } else {
            None
        };
        let mut table_bytes = 0;
        let mut grid_bytes = 0u64;
        let mut batches = 0u32;
        for (kind_lights, binding) in [
            (&srbf_lights, &table_bindings.0),
            (&directional, &table_bindings.1),
        ] {
            let Some(binding) = binding else { continue };
            table_bytes += binding.bytes;
            let srbf_kind = kind_lights.first().is_some_and(|l| l.lambda.is_some());
            sat.average = if srbf_kind {
                options.box_average
            } else {
                BoxAverage::OpticalDepth
            };
            let (kind_geometry, enlargement) = if srbf_kind {
                (&light_geometry, 1.0 / options.kappa)
            } else {
                (&geometry, 1.0)
            };
            for chunk in kind_lights.chunks(batch_size) {
                batches += 1;
                let grid = match multiple {
                    Some(source) => {
                        let pass = format!("multiple grid ({})", source.device());
                        let grid = timings
                            .time(gpu, &pass, || source.grid(chunk))
                            .map_err(|e| EnvRenderError::Grid(e.to_string()))?;
                        check_grid(&grid, chunk.len())?;
                        Some(grid)
                    }
                    None => None,
                };
                let directions: Vec<_> = chunk.iter().map(|l| l.direction).collect();
                timings.time(gpu, "light pass", || {
                    let mut encoder = gpu.device.create_command_encoder(&Default::default());
                    self.depth.encode(
                        gpu,
                        &mut encoder,
                        kind_geometry,
                        &directions,
                        bounds,
                        enlargement,
                        enlargement,
                        &mut dodm,
                    );
                    gpu.queue.submit([encoder.finish()]);
                });
                timings.time(gpu, "summed-area tables", || {
                    let mut encoder = gpu.device.create_command_encoder(&Default::default());
                    self.sat
                        .encode(gpu, &mut encoder, &dodm.optical_depth, &sat);
                    gpu.queue.submit([encoder.finish()]);
                });
                timings.time(gpu, "view", || {
                    let batch = BatchBinding::with_filter(
                        gpu,
                        &self.view.batch_layout,
                        chunk,
                        &dodm,
                        &sat,
                        options.shadowed,
                        grid.is_some(),
                        options.transmittance_filter,
                    );
                    let view =
                        ViewBinding::new(gpu, &self.view.view_layout, grid.as_ref(), &visibility);
                    grid_bytes = grid_bytes.max(view.bytes);
                    let mut encoder = gpu.device.create_command_encoder(&Default::default());
                    self.view.encode(
                        &mut encoder,
                        &geometry,
                        &strands,
                        options.transparency,
                        &batch,
                        binding,
                        &view,
                        &targets,
                        &sums,
                    );
                    gpu.queue.submit([encoder.finish()]);
                });
            }
        }
        memory.push(("env tables".into(), table_bytes));
        memory.push(("forward-scattering grid".into(), grid_bytes));
        let bytes = timings.time(gpu, "readback", || read_buffer(gpu, &sums.sums))?;

        if let Some(error) = pollster::block_on(scope.pop()) {
            return Err(EnvRenderError::Gpu(error.to_string()));
        }
        let all: &[[f32; 4]] = bytemuck::cast_slice(&bytes);
        let n = width as usize * height as usize;
        let single_pixels = all[..n].to_vec();
        let multiple_pixels = multiple.map(|_| all[n..2 * n].to_vec());
        let pixels = match &multiple_pixels {
            None => single_pixels.clone(),
            Some(m) => single_pixels
                .iter()
                .zip(m)
                .map(|(s, m)| [s[0] + m[0], s[1] + m[1], s[2] + m[2], s[3]])
                .collect(),
        };
        Ok(EnvFrame {
            width,
            height,
            pixels,
            single_pixels,
            multiple_pixels,
            stats: EnvRenderStats {
                adapter: gpu.report.clone(),
                timings: timings.0,
                memory_per_batch: memory,
                batches,
                lights: lights.len() as u32,
                segments: geometry.segment_count,
                light_pass_segments: light_geometry.segment_count,
                timing_method: "CPU wall clock around submit + wait for idle, summed over batches",
                fragments,
            },
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
) -> Result<EnvFrame, EnvRenderError> {
    let mut timings = Timings(Vec::new());
    let renderer = timings.time(gpu, "pipelines", || EnvRenderer::new(gpu));
    let mut frame = renderer.render(
        gpu, model, camera, width, height, lights, tables, options, multiple,
    )?;
    frame.stats.timings.splice(0..0, timings.0);
    Ok(frame)
}
