//! Summed-area tables of a DODM batch by two compute passes (rows, then columns), in u32 fixed
//! point with wrapping arithmetic (`summed_area.wgsl`).
//!
//! Precision: each texel's optical depth is clamped to [`MAX_TEXEL_TAU`] = 16 (transmittance
//! e⁻¹⁶ ≈ 10⁻⁷: nothing visible is lost) and rounded to 1/[`FIXED_POINT_SCALE`] = 1/256 units
//! (an error ≤ 1/512 in τ, ≤ 0.2% in transmittance). A texel then holds at most 2¹² units, so any
//! box of at most 2²⁰ texels sums below 2³² and its S(a) − S(b) − S(c) + S(d) is exact modulo 2³²
//! however far the corners lie from the origin: boxes are limited to
//! 2·[`MAX_BOX_HALF_SIZE`] + 1 = 1023 texels a side (1023² < 2²⁰).
//! Inputs: the optical-depth array texture of a [`DodmBatch`]. Output: [`SummedAreaTables`].

use wgpu::util::DeviceExt;

use super::convolution_depth::{DodmBatch, DodmSettings};
use crate::gpu::GpuContext;
use crate::gpu::bind_layout::{storage_entry, texture_entry, uniform_entry};
use crate::gpu::limits::{GpuLimits, LimitError};
use crate::gpu::pipeline::{compute_pipeline, wgsl_module};

pub const FIXED_POINT_SCALE: f32 = 256.0;
pub const MAX_TEXEL_TAU: f32 = 16.0;
/// Boxes are at most 2·511 + 1 texels a side (see the module notes).
pub const MAX_BOX_HALF_SIZE: u32 = 511;
/// Bytes per texel per slot (four u32 sums).
pub const SAT_TEXEL_BYTES: u64 = 16;

/// A texel's τ as the SAT stores it (mirrors `quantize` in the shader; f32 rounding ties to even
/// as WGSL's `round` does).
pub fn quantize_optical_depth(tau: f32) -> u32 {
    (tau.clamp(0.0, MAX_TEXEL_TAU) * FIXED_POINT_SCALE).round_ties_even() as u32
}

/// Bytes of the SAT buffer for `slots` maps of `resolution`², checked against the adapter's
/// storage-binding and buffer-size limits (the fix names the largest batch that fits).
pub fn sat_bytes(gpu: &GpuContext, resolution: u32, slots: u32) -> Result<u64, LimitError> {
    let per_slot = resolution as u64 * resolution as u64 * SAT_TEXEL_BYTES;
    let bytes = per_slot * slots.max(1) as u64;
    let limits = GpuLimits::of(gpu);
    limits.check_storage_buffer("DODM summed-area tables", bytes, |max| {
        match max / per_slot {
            0 => format!(
                "use a DODM resolution of at most {}",
                ((max / SAT_TEXEL_BYTES) as f64).sqrt().floor() as u64
            ),
            fit => format!("use a light batch size of at most {fit} at this DODM resolution"),
        }
    })?;
    // One workgroup of 64 texels per row or column, one row of workgroups per slot.
    limits.check_workgroups(
        "DODM summed-area scan",
        [resolution.div_ceil(64), slots.max(1), 1],
        |max| format!("use a light batch size of at most {max}"),
    )?;
    Ok(bytes)
}

/// The SATs of one batch: `vec4<u32>` per texel per slot, `[(slot·res + y)·res + x]`, of the
/// quantized optical depths.
pub struct SummedAreaTables {
    pub buffer: wgpu::Buffer,
    pub resolution: u32,
    pub slots: u32,
}

impl SummedAreaTables {
    pub fn new(gpu: &GpuContext, resolution: u32, slots: u32) -> Result<Self, LimitError> {
        let size = sat_bytes(gpu, resolution, slots)?;
        let buffer = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("dodm summed-area tables"),
            size,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        Ok(Self {
            buffer,
            resolution,
            slots,
        })
    }

    pub fn memory(&self) -> Vec<(String, u64)> {
        vec![("dodm summed-area tables".into(), self.buffer.size())]
    }
}

#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct SatUniform {
    resolution: u32,
    slots: u32,
    _pad: [u32; 2],
}

/// The two compute pipelines, built once.
pub struct SummedAreaPass {
    rows: wgpu::ComputePipeline,
    columns: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
}

impl SummedAreaPass {
    pub fn new(gpu: &GpuContext) -> Self {
        let device = &gpu.device;
        let shader = wgsl_module(device, "summed_area.wgsl", include_str!("summed_area.wgsl"));
        let compute = wgpu::ShaderStages::COMPUTE;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("summed area"),
            entries: &[
                texture_entry(
                    0,
                    compute,
                    wgpu::TextureSampleType::Float { filterable: false },
                    wgpu::TextureViewDimension::D2Array,
                ),
                storage_entry(1, compute, false),
                uniform_entry(2, compute),
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("summed area"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = |entry| compute_pipeline(device, entry, &pipeline_layout, &shader, entry);
        Self {
            rows: pipeline("scan_rows"),
            columns: pipeline("scan_columns"),
            layout,
        }
    }

    /// Encodes the SATs of every slot of `optical_depth` (an RGBA float array texture of
    /// `tables.resolution`² texels) into `tables`.
    pub fn encode(
        &self,
        gpu: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        optical_depth: &wgpu::Texture,
        tables: &SummedAreaTables,
    ) {
        let device = &gpu.device;
        let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("sat params"),
            contents: bytemuck::bytes_of(&SatUniform {
                resolution: tables.resolution,
                slots: tables.slots,
                _pad: [0; 2],
            }),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let view = DodmBatch::array_view(optical_depth);
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("summed area"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(&view),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: tables.buffer.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: uniform.as_entire_binding(),
                },
            ],
        });
        let groups = tables.resolution.div_ceil(64);
        for pipeline in [&self.rows, &self.columns] {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("summed area"),
                timestamp_writes: gpu.compute_timestamps(),
            });
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &group, &[]);
            pass.dispatch_workgroups(groups, tables.slots.max(1), 1);
        }
    }
}

/// WebGPU's default `max_storage_buffer_binding_size` (128 MiB): what every adapter grants.
const PORTABLE_STORAGE_BINDING_BYTES: u64 = 128 << 20;

/// The batch a light-map size allows is set by the SAT: its tables must fit one storage binding.
impl DodmSettings {
    /// The default settings with `resolution`² maps and the largest batch, up to the default
    /// 16, whose summed-area tables fit one storage binding on any adapter (2048² maps: 2).
    pub fn at_resolution(resolution: u32) -> Self {
        let per_slot = (resolution as u64).pow(2) * SAT_TEXEL_BYTES;
        let default = Self::default();
        let fits = (PORTABLE_STORAGE_BINDING_BYTES / per_slot.max(1)).max(1);
        Self {
            resolution,
            batch_size: fits.min(default.batch_size as u64) as u32,
            ..default
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantization_bounds_the_box_sum() {
        assert_eq!(quantize_optical_depth(1.0), 256);
        assert_eq!(quantize_optical_depth(1e9), 4096);
        assert_eq!(quantize_optical_depth(-3.0), 0);
        let side = 2 * MAX_BOX_HALF_SIZE as u64 + 1;
        assert!(side * side * quantize_optical_depth(MAX_TEXEL_TAU) as u64 <= u32::MAX as u64);
        // One more texel a side would overflow.
        assert!((side + 2) * (side + 2) * 4096 > u32::MAX as u64);
    }

    #[test]
    fn a_resolution_gets_the_largest_batch_that_fits_a_portable_binding() {
        assert_eq!(DodmSettings::at_resolution(512), DodmSettings::default());
        for (resolution, batch) in [(256, 16), (1024, 8), (2048, 2)] {
            let s = DodmSettings::at_resolution(resolution);
            assert_eq!((s.resolution, s.batch_size), (resolution, batch));
            let bytes = (resolution as u64).pow(2) * 16 * batch as u64;
            assert!(bytes <= 128 << 20 && bytes * 2 > 128 << 20 || batch == 16);
        }
    }
}

#[cfg(test)]
mod wgsl_layout {
    use super::*;
    use crate::shader_layout::{assert_same_layout, rust_layout};
    use crate::shaders::Wgsl;

    #[test]
    fn uploaded_structs_are_laid_out_as_the_wgsl_reads_them() {
        assert_same_layout(
            &Wgsl {
                file: "summed_area.wgsl",
                source: include_str!("summed_area.wgsl"),
            },
            None,
            "SatParams",
            &rust_layout!(SatUniform { resolution, slots }),
        );
    }
}
