//! The groom's visibility volume on the GPU (group 3, bindings 6 and 7 of the view shading pass,
//! `visibility_volume.wgsl`), and the cache that keeps it across frames.

use std::sync::{Arc, Mutex};

use super::EnvRenderOptions;
use super::error::EnvRenderError;
use super::stats::Timings;
use crate::gpu::GpuContext;
use crate::gpu::buffer::init_buffer;
use crate::gpu::limits::GpuLimits;
use crate::hair::HairModel;
use crate::head::Head;
use crate::visibility::{VisibilityVolume, VisibilityVolumeSettings};

/// The visibility volume as group 3 reads it (bindings 6 and 7, `visibility_volume.wgsl`): the
/// SH coefficients of T(ω) at a grid's vertices, or a placeholder that leaves SRBF lobes to
/// their light maps. Uploaded once per groom.
pub struct VolumeBuffers {
    pub(super) params: wgpu::Buffer,
    pub(super) coefficients: wgpu::Buffer,
    /// Bytes of the coefficients (0 for the placeholder).
    pub bytes: u64,
}

#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct VolumeUniform {
    origin: [f32; 4],
    dims: [u32; 4],
    spacing: [f32; 4],
}

impl VolumeBuffers {
    pub fn new(gpu: &GpuContext, volume: Option<&VisibilityVolume>) -> Self {
        let device = &gpu.device;
        let (uniform, coefficients, bytes) = match volume {
            Some(v) => (
                VolumeUniform {
                    origin: v.origin.extend(1.0).into(),
                    dims: [v.dims[0], v.dims[1], v.dims[2], 0],
                    spacing: [v.spacing, 0.0, 0.0, 0.0],
                },
                v.bytes(),
                v.bytes().len() as u64,
            ),
            None => (
                VolumeUniform {
                    origin: [0.0; 4],
                    dims: [1, 1, 1, 0],
                    spacing: [1.0, 0.0, 0.0, 0.0],
                },
                &[0u8; 64][..],
                0,
            ),
        };
        Self {
            params: init_buffer(
                device,
                "visibility volume params",
                bytemuck::bytes_of(&uniform),
                wgpu::BufferUsages::UNIFORM,
            ),
            coefficients: init_buffer(
                device,
                "visibility volume",
                coefficients,
                wgpu::BufferUsages::STORAGE,
            ),
            bytes,
        }
    }
}

/// The last groom's visibility volume on the GPU, kept while frames ask for the same hair and
/// settings (a static groom pays its build once).
#[derive(Default)]
pub(super) struct VolumeCache(Mutex<Option<CachedVolume>>);

/// A visibility volume uploaded for one groom and settings.
struct CachedVolume {
    key: (u64, VisibilityVolumeSettings),
    buffers: Arc<VolumeBuffers>,
}

/// A fingerprint of the hair a visibility volume was built from: its points, strands and
/// thicknesses (what the march sees).
fn hair_fingerprint(model: &HairModel) -> u64 {
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    model.points_bytes().hash(&mut h);
    model.strand_offsets_bytes().hash(&mut h);
    if let Some(t) = model.thickness() {
        t.per_point_values(model.point_count())
            .iter()
            .for_each(|v| v.to_bits().hash(&mut h));
    }
    h.finish()
}

impl VolumeCache {
    /// Makes `volume` the visibility volume of `model` under `settings` (instead of building
    /// it): a volume computed elsewhere, or a hand-made one in tests.
    pub(super) fn set(
        &self,
        gpu: &GpuContext,
        model: &HairModel,
        settings: VisibilityVolumeSettings,
        volume: &VisibilityVolume,
    ) {
        *self.0.lock().unwrap_or_else(|e| e.into_inner()) = Some(CachedVolume {
            key: (hair_fingerprint(model), settings),
            buffers: Arc::new(VolumeBuffers::new(gpu, Some(volume))),
        });
    }

    /// The frame's volume buffers: the cached volume where the hair and settings match, else
    /// built (timed as "visibility volume", a static groom's setup), or the placeholder.
    pub(super) fn buffers(
        &self,
        gpu: &GpuContext,
        model: &HairModel,
        head: Option<&Head>,
        options: &EnvRenderOptions,
        timings: &mut Timings,
    ) -> Result<Arc<VolumeBuffers>, EnvRenderError> {
        let Some(settings) = options
            .lobe_visibility
            .volume()
            .filter(|_| options.shadowed)
        else {
            return Ok(Arc::new(VolumeBuffers::new(gpu, None)));
        };
        // The head is in the volume (its marches stop at it): another head, another volume.
        let scene = hair_fingerprint(model) ^ head.map_or(0, |h| h.fingerprint().rotate_left(17));
        let key = (scene, *settings);
        let mut cache = self.0.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(cached) = cache.as_ref().filter(|c| c.key == key) {
            return Ok(cached.buffers.clone());
        }
        let volume = timings.time(gpu, "visibility volume", || {
            VisibilityVolume::build_with_head(model, settings, head)
        })?;
        GpuLimits::of(gpu).check_storage_buffer(
            "visibility volume",
            volume.bytes().len() as u64,
            |max| format!("use fewer voxels along the longest side (at most {max} bytes)"),
        )?;
        let buffers = Arc::new(VolumeBuffers::new(gpu, Some(&volume)));
        *cache = Some(CachedVolume {
            key,
            buffers: buffers.clone(),
        });
        Ok(buffers)
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
                file: "visibility_volume.wgsl",
                source: include_str!("visibility_volume.wgsl"),
            },
            None,
            "VolumeParams",
            &rust_layout!(VolumeUniform {
                origin,
                dims,
                spacing
            }),
        );
    }
}
