//! The compact sources' visibility along every strand segment, for the layered view's gather
//! (`segment_light_visibility.wgsl`, laid out as `segment_light_samples.wgsl` says): one compute
//! pass per batch of compact sources writes the transmittance toward each of the batch's lights
//! at samples along each segment ([`intervals_per_segment`]), and the gather's fragments interpolate it at
//! their place on the segment. Evaluated per fragment, the same maps were read for every fragment
//! of every layer: at 800×600 on the default groom 1.9 M fragments against 282 k segments, and
//! half the layered view's time.
//!
//! Inputs: the strands' points and segments, the batch's lights and maps ([`BatchBinding`],
//! group 1). Output: [`SegmentLightVisibility`], bound in the gather's group 2.

use wgpu::util::DeviceExt;

use std::sync::OnceLock;

use glam::{Mat4, Vec2, Vec3};

use crate::gpu::GpuContext;
use crate::gpu::bind_layout::{bind_group, pipeline_layout, storage_entry, uniform_entry};
use crate::gpu::limits::GpuLimits;
use crate::gpu::pipeline::compute_pipeline;
use crate::hair::HairModel;
use crate::passes::convolution_transmittance::BatchBinding;
use crate::passes::strand_geometry::StrandGeometry;
use crate::shaders::{Wgsl, shader_module};

/// Samples per workgroup (`WORKGROUP` in the shader).
const WORKGROUP: u32 = 64;
/// Workgroups along x before a dispatch takes a second row (every adapter's minimum limit; the
/// shader's index assumes it).
const GROUPS_PER_ROW: u32 = 65535;
/// Bytes a sample's visibility takes per light slot (f16).
const SLOT_BYTES: u64 = 2;

/// The longest a segment's interval between two samples may be on screen, pixels: the
/// fragments between two samples take their linear blend, so a sun's shadow sharper than this
/// along a fiber is blurred.
const SAMPLE_SPACING_PX: f32 = 2.0;
/// The most intervals a segment is cut into (a groom of long segments seen close).
const MAX_INTERVALS: u32 = 16;
/// Strands whose segments are measured on screen, at most (evenly spread over the groom).
const MEASURED_STRANDS: usize = 1024;

/// Intervals each segment of `model` is cut into for a view through `view_proj` at `size`: its
/// mean length on screen over [`SAMPLE_SPACING_PX`], 1 to [`MAX_INTERVALS`].
pub(super) fn intervals_per_segment(
    model: &HairModel,
    view_proj: Mat4,
    (width, height): (u32, u32),
) -> u32 {
    let half_size = Vec2::new(width as f32, height as f32) * 0.5;
    let on_screen = |p: Vec3| {
        let clip = view_proj * p.extend(1.0);
        (clip.w > 0.0).then(|| Vec2::new(clip.x, clip.y) / clip.w * half_size)
    };
    let step = (model.strand_count() / MEASURED_STRANDS).max(1);
    let (mut length, mut segments) = (0.0f64, 0u64);
    for strand in model.strands().step_by(step) {
        for pair in strand.windows(2) {
            if let (Some(a), Some(b)) = (on_screen(pair[0]), on_screen(pair[1])) {
                length += a.distance(b) as f64;
                segments += 1;
            }
        }
    }
    let mean_px = if segments == 0 {
        0.0
    } else {
        length / segments as f64
    };
    ((mean_px / SAMPLE_SPACING_PX as f64).ceil() as u32).clamp(1, MAX_INTERVALS)
}

/// The most light slots a batch of compact sources can hold for `segments` segments cut into
/// `intervals` within the adapter's storage-binding limit (at least one).
pub(super) fn slots_that_fit(gpu: &GpuContext, segments: u64, intervals: u32, wanted: u32) -> u32 {
    let samples = segments.max(1) * (intervals as u64 + 1);
    let room = GpuLimits::of(gpu).max_storage_bytes() / (samples * SLOT_BYTES);
    // Slots come in pairs (one word).
    (room & !1).clamp(1, wanted.max(1) as u64) as u32
}

/// Bytes of one batch's samples: `slots` light slots (in pairs) at `intervals` + 1 samples on
/// each of `segments` segments.
pub(super) fn sample_bytes(segments: u32, intervals: u32, slots: u32) -> u64 {
    segments as u64 * (intervals as u64 + 1) * slots.max(1).next_multiple_of(2) as u64 * SLOT_BYTES
}

/// The compute pipelines (without a head, and with one: its shadow filter compiled in only
/// there), each compiled when a frame first needs it, and the layout of their output, which the
/// gather binds as its group 2.
pub(super) struct SegmentLightVisibilityPass {
    device: wgpu::Device,
    shader: wgpu::ShaderModule,
    pipeline_layout: wgpu::PipelineLayout,
    pipelines: [OnceLock<wgpu::ComputePipeline>; 2],
    layout: wgpu::BindGroupLayout,
    /// The gather's view of the output: read in its fragment stage.
    pub(super) gather_layout: wgpu::BindGroupLayout,
}

/// One batch's visibility along the segments, bound for the gather.
pub(super) struct SegmentLightVisibility {
    pub(super) gather_group: wgpu::BindGroup,
}

impl SegmentLightVisibilityPass {
    pub(super) fn new(gpu: &GpuContext, batch_layout: &wgpu::BindGroupLayout) -> Self {
        let device = &gpu.device;
        let compute = wgpu::ShaderStages::COMPUTE;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("segment light visibility"),
            entries: &[
                storage_entry(0, compute, true),
                storage_entry(1, compute, true),
                storage_entry(2, compute, false),
                uniform_entry(3, compute),
            ],
        });
        let fragment = wgpu::ShaderStages::FRAGMENT;
        let gather_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("segment light visibility (gather)"),
            // Bindings 4 and 5: group 2's first four are the tables' in the view shader's other
            // entry points.
            entries: &[storage_entry(4, fragment, true), uniform_entry(5, fragment)],
        });
        let top = Wgsl {
            file: "segment_light_visibility.wgsl",
            source: include_str!("segment_light_visibility.wgsl"),
        };
        let shader = shader_module(device, &top, None);
        let pipeline_layout = pipeline_layout(
            device,
            "segment light visibility",
            &[Some(&layout), Some(batch_layout)],
        );
        Self {
            device: device.clone(),
            shader,
            pipeline_layout,
            pipelines: Default::default(),
            layout,
            gather_layout,
        }
    }

    /// The pipeline of a frame with a head or without, compiled now if no frame has used it.
    pub(super) fn pipeline(&self, with_head: bool) -> &wgpu::ComputePipeline {
        self.pipelines[usize::from(with_head)].get_or_init(|| {
            let entry = match with_head {
                false => "cs_segment_light_visibility",
                true => "cs_segment_light_visibility_head",
            };
            let label = "segment light visibility";
            compute_pipeline(
                &self.device,
                label,
                &self.pipeline_layout,
                &self.shader,
                entry,
            )
        })
    }

    /// Encodes the visibility along every segment of `geometry`, cut into `intervals`, toward
    /// each light of `batch`.
    pub(super) fn encode(
        &self,
        gpu: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        (geometry, intervals): (&StrandGeometry, u32),
        batch: &BatchBinding,
        with_head: bool,
    ) -> SegmentLightVisibility {
        let samples = geometry.segment_count * (intervals + 1);
        let slots = batch.light_count.max(1);
        let output = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("segment light visibility"),
            size: sample_bytes(geometry.segment_count, intervals, slots).max(16),
            usage: wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        });
        let counts = gpu
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("segment light visibility counts"),
                contents: bytemuck::cast_slice(&[samples, slots, intervals, 0]),
                usage: wgpu::BufferUsages::UNIFORM,
            });
        let group = bind_group(
            &gpu.device,
            "segment light visibility",
            &self.layout,
            &[
                geometry.points.as_entire_binding(),
                geometry.segments.as_entire_binding(),
                output.as_entire_binding(),
                counts.as_entire_binding(),
            ],
        );
        let groups = samples.div_ceil(WORKGROUP).max(1);
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("segment light visibility"),
            timestamp_writes: None,
        });
        pass.set_pipeline(self.pipeline(with_head));
        pass.set_bind_group(0, &group, &[]);
        pass.set_bind_group(1, &batch.group, &[]);
        pass.dispatch_workgroups(
            groups.min(GROUPS_PER_ROW),
            groups.div_ceil(GROUPS_PER_ROW),
            1,
        );
        drop(pass);
        let gather_group = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("segment light visibility (gather)"),
            layout: &self.gather_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 4,
                    resource: output.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 5,
                    resource: counts.as_entire_binding(),
                },
            ],
        });
        SegmentLightVisibility { gather_group }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Strands of `points` each, `step` apart along x (world = clip space: IDENTITY).
    fn strands(count: usize, points: usize, step: f32) -> HairModel {
        let mut all = Vec::new();
        let mut offsets = vec![0u32];
        for s in 0..count {
            let y = s as f32 * 0.01;
            all.extend((0..points).map(|i| Vec3::new(-0.5 + step * i as f32, y, 0.0)));
            offsets.push(all.len() as u32);
        }
        HairModel::new(all, offsets, None, None, None).unwrap()
    }

    #[test]
    fn a_segment_is_cut_every_two_pixels_of_its_length_on_screen() {
        // Clip x ∈ [−1, 1] spans 200 pixels: a step of 0.099 is 9.9 pixels, 5 intervals.
        let model = strands(3, 5, 0.099);
        assert_eq!(intervals_per_segment(&model, Mat4::IDENTITY, (200, 100)), 5);
        // 10.4 pixels at 210 wide: 6 intervals (none longer than 2 pixels).
        assert_eq!(intervals_per_segment(&model, Mat4::IDENTITY, (210, 100)), 6);
        // Shorter than a pixel: one interval, its two ends.
        let short = strands(3, 5, 0.001);
        assert_eq!(intervals_per_segment(&short, Mat4::IDENTITY, (200, 100)), 1);
        // Long segments are cut into MAX_INTERVALS at most.
        assert_eq!(
            intervals_per_segment(&model, Mat4::IDENTITY, (20_000, 100)),
            MAX_INTERVALS
        );
    }

    #[test]
    fn points_behind_the_camera_do_not_count() {
        // w = 1 − z: the second strand lies behind the eye (w < 0) and is left out.
        let mut view_proj = Mat4::IDENTITY;
        view_proj.w_axis.w = 1.0;
        view_proj.z_axis.w = -1.0;
        let mut points: Vec<Vec3> = (0..5)
            .map(|i| Vec3::new(0.1 * i as f32, 0.0, 0.0))
            .collect();
        points.extend((0..5).map(|i| Vec3::new(0.5 * i as f32, 0.0, 2.0)));
        let model = HairModel::new(points, vec![0, 5, 10], None, None, None).unwrap();
        assert_eq!(intervals_per_segment(&model, view_proj, (200, 100)), 5);
    }
}
