//! One headless frame end to end: upload, strand pass, readback, with per-pass timings and the
//! GPU memory each buffer and texture holds.

use std::time::Instant;

use crate::gpu::readback::ReadbackError;
use crate::gpu::{AdapterReport, GpuContext, read_texture_rgba};
use crate::hair::HairModel;
use crate::lights::Light;
use crate::passes::deep_opacity::{
    DeepOpacityMap, DeepOpacityPass, DomSettings, DomSettingsError, light_camera,
};
use crate::passes::strands::{
    FrameParams, RenderTarget, ShadowInput, StrandGeometry, StrandPass, TooManyPoints,
};

#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    #[error(
        "image size {width}×{height} must be between 1 and {max} on each side (the adapter's limit)"
    )]
    BadSize { width: u32, height: u32, max: u32 },
    #[error(transparent)]
    TooManyPoints(#[from] TooManyPoints),
    #[error(transparent)]
    DomSettings(#[from] DomSettingsError),
    #[error("deep opacity maps need a directional light; the frame has none")]
    NoDirectionalLight,
    #[error(transparent)]
    Readback(#[from] ReadbackError),
    #[error("the GPU reported an error: {0}")]
    Gpu(String),
}

/// Wall-clock milliseconds of one pass: CPU time around submit and wait-for-idle (timestamp
/// queries are not used yet).
#[derive(Clone, Debug, PartialEq)]
pub struct PassTiming {
    pub pass: String,
    pub milliseconds: f64,
}

#[derive(Clone, Debug)]
pub struct RenderStats {
    pub adapter: AdapterReport,
    pub timings: Vec<PassTiming>,
    pub memory_bytes: Vec<(String, u64)>,
    pub segments: u32,
    pub timing_method: &'static str,
}

pub struct Frame {
    pub width: u32,
    pub height: u32,
    /// Linear, pre-multiplied RGBA, row-major from the top.
    pub pixels: Vec<[f32; 4]>,
    pub stats: RenderStats,
}

fn timed<T>(
    timings: &mut Vec<PassTiming>,
    gpu: &GpuContext,
    pass: &str,
    work: impl FnOnce() -> T,
) -> T {
    let start = Instant::now();
    let out = work();
    gpu.wait_idle();
    timings.push(PassTiming {
        pass: pass.to_string(),
        milliseconds: start.elapsed().as_secs_f64() * 1e3,
    });
    out
}

/// Renders `model` with `frame` and reads the picture back. With `shadows`, the first
/// directional light is shadowed through a deep opacity map (other lights are unshadowed).
pub fn render_frame(
    gpu: &GpuContext,
    model: &HairModel,
    frame: &FrameParams,
    shadows: Option<DomSettings>,
) -> Result<Frame, RenderError> {
    let shadowed_light = match shadows {
        None => None,
        Some(settings) => {
            settings.check()?;
            let (index, direction) = frame
                .lights
                .iter()
                .enumerate()
                .find_map(|(i, l)| match l {
                    Light::Directional { direction, .. } => Some((i, *direction)),
                    _ => None,
                })
                .ok_or(RenderError::NoDirectionalLight)?;
            Some((settings, index as u32, direction))
        }
    };
    let max = gpu.device.limits().max_texture_dimension_2d;
    if frame.width == 0 || frame.height == 0 || frame.width > max || frame.height > max {
        return Err(RenderError::BadSize {
            width: frame.width,
            height: frame.height,
            max,
        });
    }
    let scope = gpu.device.push_error_scope(wgpu::ErrorFilter::Validation);
    let mut timings = Vec::new();
    let geometry = timed(&mut timings, gpu, "upload", || {
        StrandGeometry::upload(gpu, model)
    })?;
    let pass = timed(&mut timings, gpu, "pipeline", || StrandPass::new(gpu));
    let target = RenderTarget::new(gpu, frame.width, frame.height);
    let mut memory_bytes = geometry.memory();
    let shadow_map = match shadowed_light {
        None => None,
        Some((settings, index, direction)) => {
            let dom_pass = timed(&mut timings, gpu, "dom pipeline", || {
                DeepOpacityPass::new(gpu)
            });
            let map = DeepOpacityMap::new(gpu, light_camera(direction, model.bounds()), settings);
            timed(&mut timings, gpu, "deep opacity", || {
                dom_pass.draw(gpu, &geometry, &map)
            });
            memory_bytes.extend(map.memory());
            Some((map, index))
        }
    };
    let shadow = shadow_map.as_ref().map(|(map, light_index)| ShadowInput {
        map,
        light_index: *light_index,
    });
    timed(&mut timings, gpu, "strands", || {
        pass.draw(gpu, &geometry, frame, &target, shadow)
    });
    let pixels = timed(&mut timings, gpu, "readback", || {
        read_texture_rgba(gpu, &target.color)
    })?;
    if let Some(error) = pollster::block_on(scope.pop()) {
        return Err(RenderError::Gpu(error.to_string()));
    }
    memory_bytes.extend(target.memory());
    Ok(Frame {
        width: frame.width,
        height: frame.height,
        pixels,
        stats: RenderStats {
            adapter: gpu.report.clone(),
            timings,
            memory_bytes,
            segments: geometry.segment_count,
            timing_method: "CPU wall clock around submit + wait for idle",
        },
    })
}
