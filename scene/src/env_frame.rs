//! THE call into the environment-lit renderer: one frame (hair, camera, lights, tables, look)
//! rendered on a GPU device created once per process, with its frame time.

use crate::image_metrics::Image;
use crate::look::{EnvLook, ForwardDevice};
use crate::rendered_frame::{FrameDetails, RenderedFrame, SubmittedFrame};
use crate::scene_tables::{EnvShading, ScatteringMode, SceneTables};
use anyhow::Context;
use std::sync::OnceLock;
use strandlight_precompute::srbf_set::SrbfSet;
use strandlight_runtime::camera::Camera;
use strandlight_runtime::env::{
    EnvImage, EnvRenderOptions, EnvRenderStats, EnvRenderer, EnvTables, FrameSums, ViewTransparency,
};
use strandlight_runtime::env_light::EnvLight;
use strandlight_runtime::gpu::GpuContext;
use strandlight_runtime::hair::HairModel;
use strandlight_runtime::head::Head;
use strandlight_runtime::host::HairFrame;
use strandlight_runtime::multiple::ForwardScatteringSource;
use strandlight_runtime::multiple::{
    CpuForwardScattering, ForwardScatteringSettings, ForwardScatteringTables, GpuForwardScattering,
};
use strandlight_runtime::visibility::LobeVisibility;

/// "N SRBF lights" or "N SRBF lights + k directional" for a frame's lights.
pub fn light_summary(lights: &[EnvLight]) -> String {
    let srbf = lights.iter().filter(|l| l.lambda.is_some()).count();
    match lights.len() - srbf {
        0 => format!("{srbf} SRBF lights"),
        k => format!("{srbf} SRBF lights + {k} directional"),
    }
}

/// "N SRBFs + k compact sources (x% of the power), relative L2 error e" for a fitted set.
pub fn fit_summary(set: &SrbfSet) -> String {
    let sources = match set.sources.len() {
        0 => String::new(),
        n => format!(
            " + {n} compact source{} as directional light{} ({:.0}% of the power)",
            if n == 1 { "" } else { "s" },
            if n == 1 { "" } else { "s" },
            100.0 * set.sources.iter().map(|s| s.power_share).sum::<f64>()
        ),
    };
    let without = if set.sources.is_empty() {
        ""
    } else {
        " (of the rest)"
    };
    format!(
        "{} SRBFs{sources}, relative L2 error {:.3}{without}",
        set.lobes.len(),
        set.relative_l2_error
    )
}

/// One frame for the environment-lit renderer: a hair, a camera and one set of lights (all
/// SRBFs, directional lights, or SRBFs with a fit's compact sources as directional lights),
/// shaded in `mode` with `tables`. Built from settings by `crate::frame_render::env_frame` only.
pub struct EnvFrame<'a> {
    pub hair: &'a HairModel,
    pub camera: Camera,
    pub width: u32,
    pub height: u32,
    pub lights: Vec<EnvLight>,
    pub tables: &'a SceneTables,
    pub shading: EnvShading,
    pub mode: ScatteringMode,
    pub role: FrameRole,
    pub look: EnvLook,
    /// The head (issue 40): hides the fibers behind it, drawn as skin, opaque to every light.
    pub head: Option<Head>,
}

/// The process's GPU device: created on first use by whichever frame needs it first (an
/// env-lit frame, a point-light frame, the viewer's render thread) and shared by all of them,
/// so a run opens one device and every timing is on the same adapter.
pub fn shared_gpu() -> anyhow::Result<&'static GpuContext> {
    SHARED_GPU
        .get_or_init(|| GpuContext::new_headless().map_err(|e| e.to_string()))
        .as_ref()
        .map_err(|e| anyhow::anyhow!("no GPU device: {e}"))
}

static SHARED_GPU: OnceLock<Result<GpuContext, String>> = OnceLock::new();

/// Makes `gpu` the process's [`shared_gpu`], before anything has used one: an application
/// that presents to a window renders on the device its surface needs (the viewer draws and
/// presents on one device). An error once a device exists.
pub fn install_shared_gpu(gpu: GpuContext) -> anyhow::Result<()> {
    SHARED_GPU
        .set(Ok(gpu))
        .map_err(|_| anyhow::anyhow!("the process's GPU device was made before it was installed"))
}

/// The environment-lit renderer's pipelines on [`shared_gpu`], created on first use and kept for
/// every frame of the run (pipeline creation is a one-time cost, not part of a frame).
fn env_renderer() -> anyhow::Result<(&'static GpuContext, &'static EnvRenderer)> {
    static RENDERER: OnceLock<EnvRenderer> = OnceLock::new();
    let gpu = shared_gpu()?;
    Ok((gpu, RENDERER.get_or_init(|| EnvRenderer::new(gpu))))
}

/// Creates the device and the env-lit renderer now, and compiles the pipelines of a first
/// look (the opaque view of [`crate::frame_render::FramePart::Preview`], single scattering
/// from light maps), with a head or not,
/// so that an application's first frame, prepared meanwhile, does not wait for them. The full
/// frame's view compiles when its first part needs it: compiled beside the first look, it took
/// the cores that look was drawn on (viewer, 800×600 on lavapipe).
pub fn prepare_env_renderer(with_head: bool) -> anyhow::Result<()> {
    let (_, renderer) = env_renderer()?;
    renderer.compile(ViewTransparency::Opaque, with_head, true);
    Ok(())
}

/// The adapter the renderers run on (creating the device on first use).
pub fn env_adapter() -> anyhow::Result<String> {
    Ok(shared_gpu()?.report.to_string())
}

/// Passes an application pays once (device, pipelines, uploads of hair and tables), not per
/// frame; everything else the renderer times is the frame.
///
/// The visibility volume is a static groom's, built once and kept while the hair does not move
/// (docs/BENCHMARKS.md reports its build beside the frame).
const SETUP_PASSES: [&str; 4] = ["pipelines", "upload", "table upload", "visibility volume"];

/// Milliseconds of one frame: the renderer's passes without the one-time setup.
pub fn frame_milliseconds(stats: &EnvRenderStats) -> f64 {
    stats
        .timings
        .iter()
        .filter(|t| !SETUP_PASSES.contains(&t.pass.as_str()))
        .map(|t| t.milliseconds)
        .sum()
}

/// Which renderer settings a frame uses.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FrameRole {
    /// The interactive method: SRBF lights (or the equal-cost directional baseline) with the
    /// paper's sparse forward-scattering grid and, for SRBFs, stochastic simplification κ.
    Interactive { kappa: f32 },
    /// The brute-force reference: every fiber in every light's map (κ = 1) and the forward
    /// scattering from the dense grid ([`ForwardScatteringSettings::dense_reference`]).
    Reference,
}

fn render_options(frame: &EnvFrame) -> EnvRenderOptions {
    // κ thins the SRBF lights' light passes (the runtime never thins a directional light's).
    let srbf = frame.lights.iter().any(|l| l.lambda.is_some());
    let kappa = match frame.role {
        FrameRole::Interactive { kappa } if srbf => kappa,
        _ => 1.0,
    };
    let look = frame.look;
    EnvRenderOptions {
        kappa,
        shadowed: look.shadowed,
        transparency: look.transparency,
        count_fragments: look.count_fragments,
        dodm: look.dodm,
        simplification_seed: look.simplification_seed,
        exact_coverage: look.exact_coverage,
        // Only SRBF lobes read the volume: frames without them (the reference, the baselines)
        // keep the options, and so the cache keys, they always had.
        lobe_visibility: match srbf {
            true if frame.head.is_some() && look.light_maps_under_a_head => {
                LobeVisibility::LightMaps
            }
            true => look.lobe_visibility,
            false => LobeVisibility::LightMaps,
        },
        ..EnvRenderOptions::default()
    }
}

/// Forward-scattering settings of `role`.
pub fn forward_settings(role: FrameRole) -> ForwardScatteringSettings {
    match role {
        FrameRole::Interactive { .. } => ForwardScatteringSettings::interactive(),
        FrameRole::Reference => ForwardScatteringSettings::dense_reference(),
    }
}

/// The forward-scattering source of Ren §6 for `frame` on the device its look asks for
/// (voxelization included: a static hair pays it once, outside the frame time; dynamic hair per
/// frame — see docs/BENCHMARKS.md). The reference's light sweep runs on the CPU only.
fn forward_scattering<'g>(
    frame: &EnvFrame,
    gpu: &'g GpuContext,
) -> anyhow::Result<Box<dyn ForwardScatteringSource + 'g>> {
    let tables = forward_tables(frame)?;
    let settings = forward_settings(frame.role);
    let cpu =
        CpuForwardScattering::new(frame.hair, tables, settings)?.with_head(frame.head.clone());
    // The GPU marches from every sample: the same grid without the CPU's light sweep.
    let on_gpu = |cpu: CpuForwardScattering| {
        let march = ForwardScatteringSettings {
            light_sweep: false,
            ..settings
        };
        GpuForwardScattering::new(gpu, cpu.with_settings(march)?)
    };
    Ok(match frame.look.forward_scattering {
        _ if frame.role == FrameRole::Reference => Box::new(cpu),
        ForwardDevice::Cpu => Box::new(cpu),
        ForwardDevice::Gpu => Box::new(on_gpu(cpu).context("--forward-scattering gpu")?),
        ForwardDevice::Auto if gpu.report.is_software => Box::new(cpu),
        // A volume beyond the adapter's limits is still rendered, by rayon.
        ForwardDevice::Auto => match on_gpu(cpu.clone()) {
            Ok(on_gpu) => Box::new(on_gpu),
            Err(_) => Box::new(cpu),
        },
    })
}

fn forward_tables(frame: &EnvFrame) -> anyhow::Result<ForwardScatteringTables> {
    Ok(ForwardScatteringTables::from_tables(
        &frame.tables.get("fiber_averages")?.table,
        &frame.tables.get("attenuation_ratio")?.table,
        &frame.tables.get("srbf_spread")?.table,
    )?)
}

/// The voxelized hair and medium of `frame`'s forward scattering, set up for the GPU march
/// (`--forward-scattering gpu`): what the web page marches with `GpuForwardScattering`.
pub fn gpu_march_volume(frame: &EnvFrame) -> anyhow::Result<CpuForwardScattering> {
    let settings = ForwardScatteringSettings {
        light_sweep: false,
        ..forward_settings(frame.role)
    };
    Ok(
        CpuForwardScattering::new(frame.hair, forward_tables(frame)?, settings)?
            .with_head(frame.head.clone()),
    )
}

/// The runtime's tables for `frame`: the SRBF table of its mode for SRBF lights, the direct
/// table for directional ones (the baselines, the reference, a fit's compact sources), and in
/// full mode I_G.
fn env_tables(frame: &EnvFrame) -> anyhow::Result<EnvTables> {
    let mut tables = EnvTables::default();
    if frame.lights.iter().any(|l| l.lambda.is_some()) {
        tables.srbf = Some(
            frame
                .tables
                .get(frame.shading.srbf_table(frame.mode))?
                .table
                .clone(),
        );
    }
    if frame.lights.iter().any(|l| l.lambda.is_none()) {
        tables.direct = Some(
            frame
                .tables
                .get(frame.shading.direct_table(frame.mode))?
                .table
                .clone(),
        );
    }
    if frame.mode == ScatteringMode::Full {
        tables.multiple = Some(frame.tables.get("multiple")?.table.clone());
    }
    Ok(tables)
}

/// What the renderer is called with for `frame`, besides the frame itself.
pub struct LightsCall<'g> {
    pub tables: EnvTables,
    pub options: EnvRenderOptions,
    /// Multiple scattering's source in full mode.
    pub source: Option<Box<dyn ForwardScatteringSource + 'g>>,
}

/// The tables, options and forward-scattering source [`render_lights`] renders `frame` with on
/// `gpu` (a web page calls the renderer with them itself).
pub fn lights_call<'g>(frame: &EnvFrame, gpu: &'g GpuContext) -> anyhow::Result<LightsCall<'g>> {
    Ok(LightsCall {
        source: match frame.mode {
            ScatteringMode::Single => None,
            ScatteringMode::Full => Some(forward_scattering(frame, gpu)?),
        },
        ..lights_call_without_source(frame)?
    })
}

/// [`lights_call`] without its forward-scattering source, for a caller that marched the grid
/// itself (the web page).
pub fn lights_call_without_source<'g>(frame: &EnvFrame) -> anyhow::Result<LightsCall<'g>> {
    Ok(LightsCall {
        tables: env_tables(frame)?,
        options: render_options(frame),
        source: None,
    })
}

/// `frame` as a host application draws it with the runtime's
/// [`HairRenderer`](strandlight_runtime::host::HairRenderer), with `call`'s tables, options and
/// forward-scattering source ([`lights_call`]).
pub fn hair_frame<'a>(frame: &'a EnvFrame, call: &'a LightsCall) -> HairFrame<'a> {
    HairFrame {
        model: frame.hair,
        camera: &frame.camera,
        size: [frame.width, frame.height],
        lights: &frame.lights,
        tables: &call.tables,
        options: &call.options,
        multiple: call.source.as_deref(),
        head: frame.head.as_ref(),
    }
}

/// The running sum of a progressive frame on the renderers' device (the viewer's batches).
pub fn frame_sums(width: u32, height: u32) -> anyhow::Result<FrameSums> {
    let (gpu, _) = env_renderer()?;
    Ok(FrameSums::new(gpu, width, height)?)
}

/// [`render_lights`] added into `sums`, the running sum a progressive front end keeps across
/// its batches ([`frame_sums`]), and submitted: the sums stay on the GPU, where the front end
/// shows them (the viewer).
pub fn submit_lights_into(frame: &EnvFrame, sums: &FrameSums) -> anyhow::Result<SubmittedFrame> {
    let (gpu, renderer) = env_renderer()?;
    let call = lights_call(frame, gpu)?;
    let stats = renderer
        .submit_part_into(
            gpu,
            frame.hair,
            &frame.camera,
            (&frame.lights, frame.look.simplified_lights_before),
            &call.tables,
            &call.options,
            call.source.as_deref(),
            frame.head.as_ref(),
            sums,
        )
        .with_context(|| format!("adding {} lights to the frame", frame.lights.len()))?;
    Ok(SubmittedFrame {
        milliseconds: frame_milliseconds(&stats),
        passes: stats.timings.clone(),
        memory: stats.memory_per_batch.clone(),
        adapter: gpu.report.to_string(),
        timing_method: stats.timing_method.into(),
        lights: frame.lights.len(),
        with_multiple: call.source.is_some(),
    })
}

/// THE call into the environment-lit renderer. The SRBF path reads
/// `tables.get(shading.srbf_table(mode))`, directional lights `tables.get(shading.direct_table(mode))`
/// (4 axes, the 1/λ axis a single node), and the full mode also [`MULTIPLE_TABLES`].
pub fn render_lights(frame: &EnvFrame) -> anyhow::Result<RenderedFrame> {
    let (gpu, renderer) = env_renderer()?;
    let call = lights_call(frame, gpu)?;
    let (tables, multiple) = (&call.tables, call.source.as_deref());
    let out = renderer
        .render_part(
            gpu,
            frame.hair,
            &frame.camera,
            frame.width,
            frame.height,
            (&frame.lights, frame.look.simplified_lights_before),
            tables,
            &call.options,
            multiple,
            frame.head.as_ref(),
        )
        .with_context(|| {
            format!(
                "rendering {} lights ({} scattering)",
                frame.lights.len(),
                frame.mode.name()
            )
        })?;
    Ok(rendered_env(frame, gpu, out))
}

/// The renderer's image of `frame` as every front end reports it.
fn rendered_env(frame: &EnvFrame, gpu: &GpuContext, out: EnvImage) -> RenderedFrame {
    RenderedFrame {
        milliseconds: frame_milliseconds(&out.stats),
        passes: out.stats.timings.clone(),
        memory: out.stats.memory_per_batch.clone(),
        adapter: gpu.report.to_string(),
        timing_method: out.stats.timing_method.into(),
        image: Image {
            width: out.width,
            height: out.height,
            pixels: out.pixels,
        },
        details: FrameDetails::Env {
            lights: frame.lights.clone(),
            mode: frame.mode,
            fragments: out.stats.fragments,
        },
    }
}
