//! The page's one pass of its own: the running sum of progressive refinement, a batch's sums
//! added into the frame's on the GPU (a page cannot wait for a readback between batches).
//! Everything else is the runtime's.

/// Adds a batch's sums into the frame's running sum.
pub struct AccumulatePass {
    pipeline: wgpu::ComputePipeline,
}

/// Invocations per workgroup of accumulate.wgsl.
const WORKGROUP: u32 = 64;
/// WebGPU's default limit on workgroups per dimension.
const MAX_GROUPS_X: u32 = 65535;

impl AccumulatePass {
    pub fn new(device: &wgpu::Device) -> Self {
        let module = device.create_shader_module(wgpu::include_wgsl!("accumulate.wgsl"));
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("accumulate"),
            layout: None,
            module: &module,
            entry_point: Some("add"),
            compilation_options: Default::default(),
            cache: None,
        });
        Self { pipeline }
    }

    /// Records `total += part` (same size, RGBA f32 each).
    pub fn encode(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        part: &wgpu::Buffer,
        total: &wgpu::Buffer,
    ) {
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("accumulate"),
            layout: &self.pipeline.get_bind_group_layout(0),
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: part.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: total.as_entire_binding(),
                },
            ],
        });
        let texels = (total.size() / 16) as u32;
        let groups = texels.div_ceil(WORKGROUP);
        let mut pass = encoder.begin_compute_pass(&Default::default());
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &bind_group, &[]);
        pass.dispatch_workgroups(groups.min(MAX_GROUPS_X), groups.div_ceil(MAX_GROUPS_X), 1);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use strandlight_runtime::gpu::{GpuContext, read_buffer};
    use wgpu::util::DeviceExt;

    fn gpu() -> GpuContext {
        GpuContext::new_headless().unwrap_or_else(|e| panic!("{e}"))
    }

    fn storage(gpu: &GpuContext, pixels: &[[f32; 4]]) -> wgpu::Buffer {
        gpu.device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: None,
                contents: bytemuck::cast_slice(pixels),
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            })
    }

    /// Sums of batches equal the sum of their values; the latest alpha stands. Sized past one
    /// dispatch row (65535 workgroups) so the second grid dimension is exercised.
    #[test]
    fn accumulation_adds_colour_and_keeps_the_latest_coverage() {
        let gpu = gpu();
        let accumulate = AccumulatePass::new(&gpu.device);
        let n = 65535 * 64 + 100;
        let part: Vec<[f32; 4]> = (0..n).map(|i| [i as f32, 1.0, 0.5, 0.75]).collect();
        let total: Vec<[f32; 4]> = (0..n).map(|i| [1.0, i as f32, 0.0, 0.1]).collect();
        let (part_buffer, total_buffer) = (storage(&gpu, &part), storage(&gpu, &total));
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        accumulate.encode(&gpu.device, &mut encoder, &part_buffer, &total_buffer);
        gpu.queue.submit([encoder.finish()]);
        let bytes = read_buffer(&gpu, &total_buffer).unwrap();
        let summed: &[[f32; 4]] = bytemuck::cast_slice(&bytes);
        for i in [0, 1, 64, 65535 * 64 - 1, 65535 * 64, n - 1] {
            let want = [i as f32 + 1.0, 1.0 + i as f32, 0.5, 0.75];
            assert_eq!(summed[i], want, "texel {i}");
        }
        assert!(summed.iter().all(|p| p[3] == 0.75));
    }
}
