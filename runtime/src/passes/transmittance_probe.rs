//! Test hook: runs the view pass's own WGSL (`convolution_transmittance.wgsl`) in a compute
//! shader at given world points (effective transmittance) or texel boxes (SAT box sums), so
//! tests check the real shader code against independent CPU computations.

use glam::Vec3;
use wgpu::util::DeviceExt;

use super::convolution_transmittance::{BatchBinding, transmittance_bind_group_layout};
use crate::gpu::GpuContext;
use crate::gpu::bind_layout::storage_entry;
use crate::gpu::pipeline::compute_pipeline;
use crate::gpu::readback::{ReadbackError, read_buffer};
use crate::shaders::{Wgsl, shader_module};

#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct ProbePoint {
    position: [f32; 4],
}

/// An inclusive texel box `[x0, x1] × [y0, y1]` of slot `slot`'s map.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct ProbeBox {
    pub corners: [i32; 4],
    pub slot: u32,
    pub _pad: [u32; 3],
}

impl ProbeBox {
    pub fn new(slot: u32, x0: i32, y0: i32, x1: i32, y1: i32) -> Self {
        Self {
            corners: [x0, y0, x1, y1],
            slot,
            _pad: [0; 3],
        }
    }
}

pub struct TransmittanceProbe {
    transmittance: wgpu::ComputePipeline,
    boxes: wgpu::ComputePipeline,
    probe_layout: wgpu::BindGroupLayout,
    /// Group 1: build a [`BatchBinding`] against this layout.
    pub batch_layout: wgpu::BindGroupLayout,
}

impl TransmittanceProbe {
    pub fn new(gpu: &GpuContext) -> Self {
        let device = &gpu.device;
        let top = Wgsl {
            file: "transmittance_probe.wgsl",
            source: include_str!("transmittance_probe.wgsl"),
        };
        let shader = shader_module(device, &top, None);
        let compute = wgpu::ShaderStages::COMPUTE;
        let probe_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("probe"),
            entries: &[
                storage_entry(0, compute, true),
                storage_entry(1, compute, false),
                storage_entry(2, compute, true),
                storage_entry(3, compute, false),
            ],
        });
        let batch_layout = transmittance_bind_group_layout(device, compute);
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("probe"),
            bind_group_layouts: &[Some(&probe_layout), Some(&batch_layout)],
            immediate_size: 0,
        });
        let pipeline = |entry| compute_pipeline(device, entry, &layout, &shader, entry);
        Self {
            transmittance: pipeline("probe_transmittance"),
            boxes: pipeline("probe_box_sums"),
            probe_layout,
            batch_layout,
        }
    }

    fn run(
        &self,
        gpu: &GpuContext,
        batch: &BatchBinding,
        points: &[ProbePoint],
        boxes: &[ProbeBox],
    ) -> Result<(Vec<f32>, Vec<[u32; 4]>), ReadbackError> {
        let device = &gpu.device;
        let input = |label, bytes: &[u8]| {
            let mut contents = bytes.to_vec();
            contents.resize(contents.len().max(16), 0);
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents: &contents,
                usage: wgpu::BufferUsages::STORAGE,
            })
        };
        let output = |label, bytes: u64| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: bytes.max(16),
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            })
        };
        let points_in = input("probe points", bytemuck::cast_slice(points));
        let points_out = output("probe transmittance", 4 * points.len() as u64);
        let boxes_in = input("probe boxes", bytemuck::cast_slice(boxes));
        let boxes_out = output("probe box sums", 16 * boxes.len() as u64);
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("probe"),
            layout: &self.probe_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: points_in.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: points_out.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: boxes_in.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: boxes_out.as_entire_binding(),
                },
            ],
        });
        let mut encoder = device.create_command_encoder(&Default::default());
        for (pipeline, n) in [
            (&self.transmittance, points.len()),
            (&self.boxes, boxes.len()),
        ] {
            if n == 0 {
                continue;
            }
            let mut pass = encoder.begin_compute_pass(&Default::default());
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &group, &[]);
            pass.set_bind_group(1, &batch.group, &[]);
            pass.dispatch_workgroups((n as u32).div_ceil(64), 1, 1);
        }
        gpu.queue.submit([encoder.finish()]);
        let t: Vec<f32> = bytemuck::cast_slice(&read_buffer(gpu, &points_out)?).to_vec();
        let b: Vec<[u32; 4]> = bytemuck::cast_slice(&read_buffer(gpu, &boxes_out)?).to_vec();
        Ok((t[..points.len()].to_vec(), b[..boxes.len()].to_vec()))
    }

    /// T̃ of light slot `slot` at each world point.
    pub fn transmittance(
        &self,
        gpu: &GpuContext,
        batch: &BatchBinding,
        slot: u32,
        points: &[Vec3],
    ) -> Result<Vec<f32>, ReadbackError> {
        let points: Vec<ProbePoint> = points
            .iter()
            .map(|p| ProbePoint {
                position: p.extend(slot as f32).into(),
            })
            .collect();
        Ok(self.run(gpu, batch, &points, &[])?.0)
    }

    /// The shader's `sat_box_sum` (exact modulo 2³²) for each box.
    pub fn box_sums(
        &self,
        gpu: &GpuContext,
        batch: &BatchBinding,
        boxes: &[ProbeBox],
    ) -> Result<Vec<[u32; 4]>, ReadbackError> {
        Ok(self.run(gpu, batch, &[], boxes)?.1)
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
                file: "transmittance_probe.wgsl",
                source: include_str!("transmittance_probe.wgsl"),
            },
            None,
            "ProbePoint",
            &rust_layout!(ProbePoint { position }),
        );
        assert_same_layout(
            &Wgsl {
                file: "transmittance_probe.wgsl",
                source: include_str!("transmittance_probe.wgsl"),
            },
            None,
            "ProbeBox",
            &rust_layout!(ProbeBox { corners, slot }),
        );
    }
}
