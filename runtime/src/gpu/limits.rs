//! The adapter's limits, checked before a pass creates a resource or dispatches work: a
//! request past a limit is a typed error naming the limit, the value asked for, the adapter's
//! value and a setting that fits, instead of a wgpu validation abort (or a device loss) later.
//!
//! The passes call these checks with what they are about to create; the fix each check names
//! is the caller's, since only the caller knows which of its settings drives the size.

use crate::gpu::GpuContext;

#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum LimitError {
    #[error("image {width}x{height}: both sides must be at least 1 pixel")]
    EmptyImage { width: u32, height: u32 },
    #[error(
        "image {width}x{height} exceeds this adapter's max_texture_dimension_2d {max}; use \
         --size {fit_width}x{fit_height} or smaller"
    )]
    ImageTooLarge {
        width: u32,
        height: u32,
        max: u32,
        fit_width: u32,
        fit_height: u32,
    },
    #[error(
        "{what}: {width}x{height} texels exceed this adapter's max_texture_dimension_2d {max}; \
         {fix}"
    )]
    Texture2d {
        what: &'static str,
        width: u32,
        height: u32,
        max: u32,
        fix: String,
    },
    #[error(
        "{what}: {layers} array layers exceed this adapter's max_texture_array_layers {max}; \
         {fix}"
    )]
    TextureLayers {
        what: &'static str,
        layers: u32,
        max: u32,
        fix: String,
    },
    #[error("{what}: {bytes} bytes exceed this adapter's max_buffer_size {max}; {fix}")]
    BufferSize {
        what: &'static str,
        bytes: u64,
        max: u64,
        fix: String,
    },
    #[error(
        "{what}: {bytes} bytes in one storage binding exceed this adapter's \
         max_storage_buffer_binding_size {max}; {fix}"
    )]
    StorageBinding {
        what: &'static str,
        bytes: u64,
        max: u64,
        fix: String,
    },
    #[error(
        "{what}: {groups} workgroups along {axis} exceed this adapter's \
         max_compute_workgroups_per_dimension {max}; {fix}"
    )]
    Workgroups {
        what: &'static str,
        axis: char,
        groups: u32,
        max: u32,
        fix: String,
    },
}

/// The limits of one device, with the checks the passes make.
#[derive(Clone, Debug)]
pub struct GpuLimits {
    limits: wgpu::Limits,
}

impl GpuLimits {
    /// The limits `gpu`'s device was created with (the adapter's own: `GpuContext` asks for
    /// them all).
    pub fn of(gpu: &GpuContext) -> Self {
        Self::from_limits(gpu.device.limits())
    }

    /// Checks against given limits (tests use small ones to reach every check).
    pub fn from_limits(limits: wgpu::Limits) -> Self {
        Self { limits }
    }

    pub fn limits(&self) -> &wgpu::Limits {
        &self.limits
    }

    /// The largest storage binding a pass can create: both the buffer and the binding limit.
    pub fn max_storage_bytes(&self) -> u64 {
        self.limits
            .max_storage_buffer_binding_size
            .min(self.limits.max_buffer_size)
    }

    /// An output image of `width`×`height` (render targets of that size); the fix keeps the
    /// aspect ratio.
    pub fn check_image(&self, width: u32, height: u32) -> Result<(), LimitError> {
        if width == 0 || height == 0 {
            return Err(LimitError::EmptyImage { width, height });
        }
        let max = self.limits.max_texture_dimension_2d;
        if width <= max && height <= max {
            return Ok(());
        }
        let (fit_width, fit_height) = fit_within(width, height, max as u64);
        Err(LimitError::ImageTooLarge {
            width,
            height,
            max,
            fit_width,
            fit_height,
        })
    }

    /// A 2D texture (or each layer of an array) of `width`×`height` texels.
    pub fn check_texture_2d(
        &self,
        what: &'static str,
        width: u32,
        height: u32,
        fix: impl FnOnce(u32) -> String,
    ) -> Result<(), LimitError> {
        let max = self.limits.max_texture_dimension_2d;
        if width <= max && height <= max {
            return Ok(());
        }
        Err(LimitError::Texture2d {
            what,
            width,
            height,
            max,
            fix: fix(max),
        })
    }

    /// A texture array of `layers` layers.
    pub fn check_texture_layers(
        &self,
        what: &'static str,
        layers: u32,
        fix: impl FnOnce(u32) -> String,
    ) -> Result<(), LimitError> {
        let max = self.limits.max_texture_array_layers;
        if layers <= max {
            return Ok(());
        }
        Err(LimitError::TextureLayers {
            what,
            layers,
            max,
            fix: fix(max),
        })
    }

    /// A buffer of `bytes` bound whole as one storage binding; `fix` gets the largest size
    /// that fits.
    pub fn check_storage_buffer(
        &self,
        what: &'static str,
        bytes: u64,
        fix: impl FnOnce(u64) -> String,
    ) -> Result<(), LimitError> {
        let buffer_max = self.limits.max_buffer_size;
        if bytes > buffer_max {
            return Err(LimitError::BufferSize {
                what,
                bytes,
                max: buffer_max,
                fix: fix(self.max_storage_bytes()),
            });
        }
        let binding_max = self.limits.max_storage_buffer_binding_size;
        if bytes > binding_max {
            return Err(LimitError::StorageBinding {
                what,
                bytes,
                max: binding_max,
                fix: fix(self.max_storage_bytes()),
            });
        }
        Ok(())
    }

    /// A compute dispatch of `groups` workgroups along x, y, z.
    pub fn check_workgroups(
        &self,
        what: &'static str,
        groups: [u32; 3],
        fix: impl FnOnce(u32) -> String,
    ) -> Result<(), LimitError> {
        let max = self.limits.max_compute_workgroups_per_dimension;
        match groups.iter().zip(['x', 'y', 'z']).find(|(g, _)| **g > max) {
            None => Ok(()),
            Some((&groups, axis)) => Err(LimitError::Workgroups {
                what,
                axis,
                groups,
                max,
                fix: fix(max),
            }),
        }
    }
}

/// The largest `w`×`h` with the aspect of `width`×`height` whose sides are at most `max`
/// (each side at least 1).
pub fn fit_within(width: u32, height: u32, max: u64) -> (u32, u32) {
    let longest = width.max(height) as u64;
    if longest <= max {
        return (width, height);
    }
    let scale = |side: u32| ((side as u64 * max) / longest).max(1) as u32;
    (scale(width), scale(height))
}

/// The largest `w`×`h` with the aspect of `width`×`height` whose pixel count is at most
/// `pixels` (for per-pixel buffers).
pub fn fit_pixels(width: u32, height: u32, pixels: u64) -> (u32, u32) {
    let have = width as u64 * height as u64;
    if have <= pixels {
        return (width, height);
    }
    let scale = (pixels as f64 / have as f64).sqrt();
    let side = |s: u32| ((s as f64 * scale).floor() as u32).max(1);
    (side(width), side(height))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn small() -> GpuLimits {
        GpuLimits::from_limits(wgpu::Limits {
            max_texture_dimension_2d: 4096,
            max_texture_array_layers: 64,
            max_buffer_size: 1 << 28,
            max_storage_buffer_binding_size: 1 << 27,
            max_compute_workgroups_per_dimension: 100,
            ..wgpu::Limits::default()
        })
    }

    #[test]
    fn an_image_past_the_texture_limit_names_a_size_that_fits() {
        let e = small().check_image(100_000, 50_000).unwrap_err();
        assert_eq!(
            e.to_string(),
            "image 100000x50000 exceeds this adapter's max_texture_dimension_2d 4096; use \
             --size 4096x2048 or smaller"
        );
        assert!(small().check_image(4096, 4096).is_ok());
        assert!(matches!(
            small().check_image(0, 5),
            Err(LimitError::EmptyImage { .. })
        ));
    }

    #[test]
    fn each_check_names_its_limit_the_request_and_the_adapter_value() {
        let l = small();
        let e = l
            .check_texture_2d("deep opacity map", 5000, 5000, |m| {
                format!("use a resolution of at most {m}")
            })
            .unwrap_err();
        let text = e.to_string();
        assert!(text.contains("max_texture_dimension_2d 4096"), "{text}");
        assert!(text.contains("5000x5000"), "{text}");
        assert!(text.contains("at most 4096"), "{text}");

        let e = l
            .check_texture_layers("DODM batch", 65, |m| format!("use a batch size of {m}"))
            .unwrap_err();
        assert!(e.to_string().contains("max_texture_array_layers 64"), "{e}");

        let e = l
            .check_storage_buffer("node pool", 1 << 29, |m| format!("{m} bytes fit"))
            .unwrap_err();
        assert!(matches!(e, LimitError::BufferSize { .. }), "{e}");
        assert!(e.to_string().contains("max_buffer_size 268435456"), "{e}");
        assert!(e.to_string().contains("134217728 bytes fit"), "{e}");

        let e = l
            .check_storage_buffer("node pool", (1 << 27) + 1, |m| format!("{m} bytes fit"))
            .unwrap_err();
        assert!(matches!(e, LimitError::StorageBinding { .. }), "{e}");
        assert!(
            e.to_string()
                .contains("max_storage_buffer_binding_size 134217728"),
            "{e}"
        );

        let e = l
            .check_workgroups("resolve", [10, 101, 1], |m| format!("at most {m}"))
            .unwrap_err();
        assert_eq!(
            e.to_string(),
            "resolve: 101 workgroups along y exceed this adapter's \
             max_compute_workgroups_per_dimension 100; at most 100"
        );
        assert!(
            l.check_workgroups("resolve", [100, 100, 100], |_| String::new())
                .is_ok()
        );
    }

    #[test]
    fn fitted_sizes_keep_the_aspect_and_fit() {
        assert_eq!(fit_within(100_000, 100_000, 8192), (8192, 8192));
        assert_eq!(fit_within(3, 100_000, 8192), (1, 8192));
        let (w, h) = fit_pixels(4000, 2000, 1_000_000);
        assert!(w as u64 * h as u64 <= 1_000_000 && w == 2 * h, "{w}x{h}");
    }
}
