//! Group 0 of every pass that draws strand quads (`strand_quads.wgsl`): the frame uniform, the
//! hair's points, segments and point attributes ([`StrandGeometry`]) and the lights
//! ([`FrameParams`]).

use wgpu::util::DeviceExt;

use super::frame_params::{FrameParams, QuadStyle};
use super::strand_geometry::StrandGeometry;
use crate::gpu::GpuContext;
use crate::gpu::bind_layout::{bind_group, storage_entry, uniform_entry};
use crate::lights::{GpuLight, Light};

/// Group 0 of every pass that draws strand quads (`strand_quads.wgsl`): frame uniform, points,
/// segments, point attributes, lights.
pub fn strand_bind_group_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    strand_bind_group_layout_for(device, wgpu::ShaderStages::VERTEX_FRAGMENT)
}

/// [`strand_bind_group_layout`] for the shader `stages` that read it (a compute pass that
/// rasterizes the quads itself: the light pass).
pub fn strand_bind_group_layout_for(
    device: &wgpu::Device,
    stages: wgpu::ShaderStages,
) -> wgpu::BindGroupLayout {
    strand_layout(device, stages, stages)
}

/// [`strand_bind_group_layout`] whose storage buffers only the vertex stage sees (they build
/// the quads): a fragment stage with many buffers of its own (the env view's eight) stays
/// within WebGPU's default of 8 storage buffers per stage.
pub fn strand_bind_group_layout_vertex_storage(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    strand_layout(
        device,
        wgpu::ShaderStages::VERTEX_FRAGMENT,
        wgpu::ShaderStages::VERTEX,
    )
}

fn strand_layout(
    device: &wgpu::Device,
    uniform_stages: wgpu::ShaderStages,
    storage_stages: wgpu::ShaderStages,
) -> wgpu::BindGroupLayout {
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("strands"),
        entries: &[
            uniform_entry(0, uniform_stages),
            storage_entry(1, storage_stages, true),
            storage_entry(2, storage_stages, true),
            storage_entry(3, storage_stages, true),
            storage_entry(4, storage_stages, true),
        ],
    })
}

/// Group 0's resources for `geometry` seen through `frame`.
pub fn strand_bind_group(
    gpu: &GpuContext,
    layout: &wgpu::BindGroupLayout,
    geometry: &StrandGeometry,
    frame: &FrameParams,
) -> wgpu::BindGroup {
    strand_bind_group_styled(gpu, layout, geometry, frame, QuadStyle::default())
}

/// [`strand_bind_group`] with its fibers drawn in `style`: the light pass's fibers 1/κ wider
/// (Ren 2010 §7), the env view's exact coverage.
pub fn strand_bind_group_styled(
    gpu: &GpuContext,
    layout: &wgpu::BindGroupLayout,
    geometry: &StrandGeometry,
    frame: &FrameParams,
    style: QuadStyle,
) -> wgpu::BindGroup {
    let device = &gpu.device;
    let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("strand frame"),
        contents: bytemuck::bytes_of(&frame.uniform(style)),
        usage: wgpu::BufferUsages::UNIFORM,
    });
    // A storage binding may not be empty: pad with one unused light.
    let mut lights: Vec<GpuLight> = frame.lights.iter().map(Light::to_gpu).collect();
    if lights.is_empty() {
        lights.push(bytemuck::Zeroable::zeroed());
    }
    let lights = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("lights"),
        contents: bytemuck::cast_slice(&lights),
        usage: wgpu::BufferUsages::STORAGE,
    });

    bind_group(
        device,
        "strands",
        layout,
        &[
            uniform.as_entire_binding(),
            geometry.points.as_entire_binding(),
            geometry.segments.as_entire_binding(),
            geometry.attributes.as_entire_binding(),
            lights.as_entire_binding(),
        ],
    )
}
