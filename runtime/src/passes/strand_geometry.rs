//! The hair on the GPU, as every pass that draws strand quads reads it (`strand_quads.wgsl`):
//! points, a segment table flagged at strand ends, and per-point colour, thickness and opacity.
//! Uploaded once per model; the passes only bind it.

use glam::Vec3;
use wgpu::util::DeviceExt;

use crate::gpu::GpuContext;
use crate::hair::HairModel;

/// Hair colour where the file has none (linear RGB, a mid brown).
pub const DEFAULT_HAIR_COLOR: [f32; 3] = [0.35, 0.22, 0.12];

/// The hair's arrays on the GPU, laid out as `strand_quads.wgsl` reads them (a clone shares the
/// buffers).
#[derive(Clone)]
pub struct StrandGeometry {
    pub points: wgpu::Buffer,
    pub segments: wgpu::Buffer,
    pub attributes: wgpu::Buffer,
    pub segment_count: u32,
    /// The thickness used where the file gives none (world units).
    pub default_thickness: f32,
}

/// Per-point attributes (32 bytes): colour, diameter, opacity.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct PointAttributes {
    color: [f32; 3],
    thickness: f32,
    opacity: f32,
    _pad: [f32; 3],
}

const FIRST_SEGMENT_BIT: u32 = 1 << 30;
const LAST_SEGMENT_BIT: u32 = 1 << 31;

/// Where a model has no thickness: a thousandth of its bounding-box diagonal (sub-pixel for a
/// framed head at ordinary image sizes, which is what real fibers are).
pub fn default_thickness(model: &HairModel) -> f32 {
    model.bounds().diagonal() * 1e-3
}

/// One entry per segment: the index of its first point, flagged at strand ends.
pub fn segment_table(model: &HairModel) -> Vec<u32> {
    let mut table = Vec::with_capacity(model.segment_count());
    for w in model.strand_offsets().windows(2) {
        let (start, end) = (w[0], w[1]);
        for i in start..end - 1 {
            let mut entry = i;
            if i == start {
                entry |= FIRST_SEGMENT_BIT;
            }
            if i == end - 2 {
                entry |= LAST_SEGMENT_BIT;
            }
            table.push(entry);
        }
    }
    table
}

#[derive(Debug, thiserror::Error)]
#[error("the hair has {points} points; the strand pass indexes at most 2^30")]
pub struct TooManyPoints {
    pub points: usize,
}

impl StrandGeometry {
    pub fn upload(gpu: &GpuContext, model: &HairModel) -> Result<Self, TooManyPoints> {
        let n = model.point_count();
        if n >= FIRST_SEGMENT_BIT as usize {
            return Err(TooManyPoints { points: n });
        }
        let default_thickness = default_thickness(model);
        let thickness = model
            .thickness()
            .map(|a| a.per_point_values(n).into_owned())
            .unwrap_or_else(|| vec![default_thickness; n]);
        let transparency = model
            .transparency()
            .map(|a| a.per_point_values(n).into_owned())
            .unwrap_or_else(|| vec![0.0; n]);
        let color = model
            .color()
            .map(|a| a.per_point_values(n).into_owned())
            .unwrap_or_else(|| vec![Vec3::from(DEFAULT_HAIR_COLOR); n]);
        let attributes: Vec<PointAttributes> = (0..n)
            .map(|i| PointAttributes {
                color: color[i].into(),
                thickness: thickness[i],
                opacity: 1.0 - transparency[i],
                _pad: [0.0; 3],
            })
            .collect();
        let segments = segment_table(model);
        let storage = |label, contents: &[u8]| {
            gpu.device
                .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some(label),
                    contents,
                    usage: wgpu::BufferUsages::STORAGE,
                })
        };
        Ok(Self {
            points: storage("hair points", model.points_bytes()),
            segments: storage("hair segments", bytemuck::cast_slice(&segments)),
            attributes: storage("hair point attributes", bytemuck::cast_slice(&attributes)),
            segment_count: segments.len() as u32,
            default_thickness,
        })
    }

    /// Bytes held per buffer, for reports.
    pub fn memory(&self) -> Vec<(String, u64)> {
        [&self.points, &self.segments, &self.attributes]
            .iter()
            .zip(["hair points", "hair segments", "hair point attributes"])
            .map(|(b, name)| (name.to_string(), b.size()))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn segment_table_flags_strand_ends() {
        let points = (0..5).map(|i| Vec3::new(i as f32, 0.0, 0.0)).collect();
        let model = HairModel::new(points, vec![0, 3, 5], None, None, None).unwrap();
        let t = segment_table(&model);
        assert_eq!(
            t,
            vec![
                FIRST_SEGMENT_BIT,
                1 | LAST_SEGMENT_BIT,
                3 | FIRST_SEGMENT_BIT | LAST_SEGMENT_BIT
            ]
        );
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
                file: "strand_quads.wgsl",
                source: include_str!("strand_quads.wgsl"),
            },
            None,
            "PointAttributes",
            &rust_layout!(PointAttributes {
                color,
                thickness,
                opacity
            }),
        );
    }
}
