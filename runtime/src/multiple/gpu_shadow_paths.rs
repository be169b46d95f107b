//! The forward-scattering grid with the shadow-path march on the GPU (`gpu_shadow_paths.wgsl`),
//! as the paper does it (Ren 2010 §6, in CUDA there): the CPU still voxelizes and looks the
//! per-voxel medium up in the tables for each light (the part that needs the baked tables), the
//! GPU marches every sample of the coarse grid toward every light of a batch at once.
//!
//! Inputs: a [`CpuForwardScattering`] (volume, tables, settings, sample grid) and a device.
//! Output: the same [`ForwardScatteringGrid`] as the CPU source, within f32 rounding (the test
//! beside the CPU closed-form tests checks it). Which source is faster depends on the device:
//! `examples/forward_scattering_convergence.rs` times both (on lavapipe the "GPU" is the same
//! two CPU cores, see docs/BENCHMARKS.md).

use wgpu::util::DeviceExt;

use super::fiber_tables::ForwardScatteringError;
use super::forward_scattering::CpuForwardScattering;
use super::shadow_paths::{LightMedium, light_direction};
use crate::env_light::EnvLight;
use crate::gpu::bind_layout::{storage_entry, uniform_entry};
use crate::gpu::pipeline::{compute_pipeline, wgsl_module};
use crate::gpu::{GpuContext, GpuLimits, read_buffer};
use crate::multiple::{ForwardScatteringGrid, ForwardScatteringSource};

const WORKGROUP_SIZE: u32 = 64;
/// Two vec4 per voxel per light (see the shader's layout).
const MEDIUM_BYTES_PER_VOXEL: u64 = 32;
/// Lights marched by one dispatch at most (bounds the medium buffer to 16 lights' worth).
const MAX_LIGHTS_PER_DISPATCH: u32 = 16;

#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct MarchParams {
    origin: [f32; 3],
    voxel_size: f32,
    dims: [u32; 3],
    samples: u32,
    lights: u32,
    taps: u32,
    step_fraction: f32,
    include_direct: u32,
    _pad: [u32; 4],
}

/// T_f and σ̄_f for batches of lights, marched by a compute shader.
pub struct GpuForwardScattering<'g> {
    gpu: &'g GpuContext,
    cpu: CpuForwardScattering,
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    sample_points: wgpu::Buffer,
    lights_per_dispatch: u32,
}

impl<'g> GpuForwardScattering<'g> {
    /// Builds the pipeline and uploads the sample points; checks the adapter's limits against
    /// the volume (one light's medium must fit one storage binding) and the sample count.
    pub fn new(
        gpu: &'g GpuContext,
        cpu: CpuForwardScattering,
    ) -> Result<Self, ForwardScatteringError> {
        if cpu.settings().light_sweep {
            return Err(ForwardScatteringError::InvalidSetting {
                parameter: "light_sweep",
                value: "true".into(),
                problem: "the light sweep runs on the CPU only; the GPU marches from every sample"
                    .into(),
            });
        }
        let limits = GpuLimits::of(gpu);
        let voxels = cpu.volume().grid.voxel_count() as u64;
        let per_light = voxels * MEDIUM_BYTES_PER_VOXEL;
        limits.check_storage_buffer("one light's voxel medium", per_light, |max| {
            format!(
                "use at most {} voxels (a smaller voxels_longest_side)",
                max / MEDIUM_BYTES_PER_VOXEL
            )
        })?;
        let samples = cpu.sample_grid().vertex_count() as u64;
        let output_per_light = samples * 16;
        limits.check_storage_buffer("one light's sample values", output_per_light, |max| {
            format!(
                "use at most {} sample-grid vertices (a larger coarse_factor)",
                max / 16
            )
        })?;
        let groups = samples.div_ceil(WORKGROUP_SIZE as u64);
        let max_groups = limits.limits().max_compute_workgroups_per_dimension;
        limits.check_workgroups(
            "the sample grid's march",
            [u32::try_from(groups).unwrap_or(u32::MAX), 1, 1],
            |max| {
                format!(
                    "use at most {} sample-grid vertices (a larger coarse_factor)",
                    max as u64 * WORKGROUP_SIZE as u64
                )
            },
        )?;
        let fit = (limits.max_storage_bytes() / per_light.max(output_per_light))
            .min(MAX_LIGHTS_PER_DISPATCH as u64);
        let lights_per_dispatch = (fit as u32).min(max_groups).max(1);
        let points: Vec<[f32; 4]> = cpu
            .sample_points()
            .iter()
            .map(|p| [p.x, p.y, p.z, 1.0])
            .collect();
        let sample_points = gpu
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("forward-scattering sample points"),
                contents: bytemuck::cast_slice(&points),
                usage: wgpu::BufferUsages::STORAGE,
            });
        let (pipeline, layout) = build_pipeline(gpu);
        Ok(Self {
            gpu,
            cpu,
            pipeline,
            layout,
            sample_points,
            lights_per_dispatch,
        })
    }

    pub fn cpu(&self) -> &CpuForwardScattering {
        &self.cpu
    }

    /// Submits the march of `lights` in dispatches of at most `lights_per_dispatch` lights (the
    /// adapter's limits and 16) and returns each dispatch's values buffer (per light, in order;
    /// `COPY_SRC`), not yet read: a web page maps them when the browser has them, then calls
    /// [`Self::grid_from_values`].
    pub fn encode_march(&self, lights: &[EnvLight]) -> Vec<wgpu::Buffer> {
        lights
            .chunks(self.lights_per_dispatch as usize)
            .map(|chunk| self.encode_chunk(chunk))
            .collect()
    }

    /// The grid of `lights` from the values of [`Self::encode_march`]'s buffers, in order (of
    /// one call or of several, each buffer holding as many lights as its length says). The
    /// head stops the light as on the CPU: the same exact ray test per sample, after the march
    /// (the shader knows only the voxelized hair).
    pub fn grid_from_values(
        &self,
        lights: &[EnvLight],
        marched: Vec<Vec<[f32; 4]>>,
    ) -> ForwardScatteringGrid {
        let points = self.cpu.sample_points();
        let mut values = Vec::with_capacity(points.len() * lights.len());
        let mut rest = lights;
        for mut chunk_values in marched {
            let (chunk, after) = rest.split_at(chunk_values.len() / points.len());
            for (light, light_values) in chunk.iter().zip(chunk_values.chunks_mut(points.len())) {
                self.cpu
                    .block_by_head(light_direction(light), points, light_values);
            }
            values.extend(chunk_values);
            rest = after;
        }
        let grid = self.cpu.sample_grid();
        ForwardScatteringGrid {
            origin: grid.origin,
            spacing: grid.spacing,
            dims: grid.dims,
            values,
        }
    }

    /// Submits the march of `lights` (at most `lights_per_dispatch`) in one dispatch.
    fn encode_chunk(&self, lights: &[EnvLight]) -> wgpu::Buffer {
        let device = &self.gpu.device;
        let volume = self.cpu.volume();
        let settings = self.cpu.settings();
        let samples = self.cpu.sample_grid().vertex_count() as u32;
        let mut medium = Vec::with_capacity(volume.grid.voxel_count() * 2 * lights.len());
        for light in lights {
            pack_medium(&self.cpu.medium(light), &mut medium);
        }
        let directions: Vec<[f32; 4]> = lights
            .iter()
            // w: the light's d_f (compact sources and SRBF lobes differ).
            .map(|l| {
                let d_f = settings.density_forward_of(l) as f32;
                light_direction(l).extend(d_f).to_array()
            })
            .collect();
        let g = &volume.grid;
        let params = MarchParams {
            origin: g.origin.to_array(),
            voxel_size: g.voxel_size,
            dims: g.dims,
            samples,
            lights: lights.len() as u32,
            taps: settings.filter_taps.max(1),
            step_fraction: settings.step_fraction,
            include_direct: settings.include_direct as u32,
            _pad: [0; 4],
        };
        let init = |label, contents: &[u8], usage| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage,
            })
        };
        let storage = wgpu::BufferUsages::STORAGE;
        let params = init(
            "march params",
            bytemuck::bytes_of(&params),
            wgpu::BufferUsages::UNIFORM,
        );
        let medium = init("voxel medium", bytemuck::cast_slice(&medium), storage);
        let directions = init(
            "light directions",
            bytemuck::cast_slice(&directions),
            storage,
        );
        let values = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("forward-scattering values"),
            size: samples as u64 * lights.len() as u64 * 16,
            usage: storage | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("shadow paths"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: params.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: medium.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: self.sample_points.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: directions.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 4,
                    resource: values.as_entire_binding(),
                },
            ],
        });
        let mut encoder = device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("shadow paths"),
                timestamp_writes: self.gpu.compute_timestamps(),
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &group, &[]);
            pass.dispatch_workgroups(samples.div_ceil(WORKGROUP_SIZE), lights.len() as u32, 1);
        }
        self.gpu.queue.submit([encoder.finish()]);
        values
    }
}

impl ForwardScatteringSource for GpuForwardScattering<'_> {
    fn grid(&self, lights: &[EnvLight]) -> Result<ForwardScatteringGrid, ForwardScatteringError> {
        let marched = self
            .encode_march(lights)
            .iter()
            .map(|values| {
                let bytes = read_buffer(self.gpu, values)
                    .map_err(|e| ForwardScatteringError::Gpu(e.to_string()))?;
                Ok(bytemuck::pod_collect_to_vec(&bytes))
            })
            .collect::<Result<Vec<_>, ForwardScatteringError>>()?;
        Ok(self.grid_from_values(lights, marched))
    }

    fn device(&self) -> &'static str {
        "GPU"
    }
}

/// Appends one light's medium in the shader's layout: [k, ā_f.rgb], [β̄_f².rgb, σ²_SRBF] per voxel.
fn pack_medium(medium: &LightMedium, out: &mut Vec<[f32; 4]>) {
    for v in 0..medium.extinction.len() {
        let e = &medium.event[v];
        let [a, b2] = [e.attenuation, e.variance];
        out.push([medium.extinction[v], a[0], a[1], a[2]]);
        out.push([b2[0], b2[1], b2[2], medium.srbf_variance[v]]);
    }
}

fn build_pipeline(gpu: &GpuContext) -> (wgpu::ComputePipeline, wgpu::BindGroupLayout) {
    let device = &gpu.device;
    let shader = wgsl_module(
        device,
        "gpu_shadow_paths.wgsl",
        include_str!("gpu_shadow_paths.wgsl"),
    );
    let compute = wgpu::ShaderStages::COMPUTE;
    let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("shadow paths"),
        entries: &[
            uniform_entry(0, compute),
            storage_entry(1, compute, true),
            storage_entry(2, compute, true),
            storage_entry(3, compute, true),
            storage_entry(4, compute, false),
        ],
    });
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("shadow paths"),
        bind_group_layouts: &[Some(&layout)],
        immediate_size: 0,
    });
    let pipeline = compute_pipeline(
        device,
        "march_samples",
        &pipeline_layout,
        &shader,
        "march_samples",
    );
    (pipeline, layout)
}

/// A grid marched once for a frame's lights and handed out light batch by light batch: the web
/// page marches every light before its batches (it cannot wait for a readback inside one).
pub struct MarchedForwardScattering {
    pub lights: Vec<EnvLight>,
    pub grid: ForwardScatteringGrid,
}

impl ForwardScatteringSource for MarchedForwardScattering {
    fn grid(&self, lights: &[EnvLight]) -> Result<ForwardScatteringGrid, ForwardScatteringError> {
        let block = self
            .grid
            .dims
            .iter()
            .map(|&d| d as usize)
            .product::<usize>();
        let mut values = Vec::with_capacity(block * lights.len());
        for light in lights {
            let index = self
                .lights
                .iter()
                .position(|marched| marched == light)
                .ok_or_else(|| {
                    ForwardScatteringError::Gpu(format!("light {light:?} was not marched"))
                })?;
            values.extend_from_slice(&self.grid.values[index * block..(index + 1) * block]);
        }
        Ok(ForwardScatteringGrid {
            origin: self.grid.origin,
            spacing: self.grid.spacing,
            dims: self.grid.dims,
            values,
        })
    }

    fn device(&self) -> &'static str {
        "GPU"
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
                file: "gpu_shadow_paths.wgsl",
                source: include_str!("gpu_shadow_paths.wgsl"),
            },
            None,
            "MarchParams",
            &rust_layout!(MarchParams {
                origin,
                voxel_size,
                dims,
                samples,
                lights,
                taps,
                step_fraction,
                include_direct
            }),
        );
    }
}
