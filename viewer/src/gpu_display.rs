//! The window's picture of a frame, made on the GPU where the frame is (`gpu_display.wgsl`).
//!
//! Inputs: a [`GpuImage`] (the frame's sums and scale), the exposure (manual stops, or metered
//! on the hair: the 90th percentile of its luminance, as `strandlight_scene::exposure` meters a
//! written picture) and the backdrop's radiance per pixel (uploaded when the view changes).
//! Output: a texture of 8-bit sRGB bytes that egui draws, registered with egui-wgpu as a native texture.
//! Nothing is read back: the frame goes from the renderer's passes to the window's surface on
//! one device. [`crate::display`] holds the same picture's CPU form, for screenshots.

use crate::frame::GpuImage;
use std::sync::Arc;
use strandlight_runtime::gpu::bind_layout::{
    bind_group, pipeline_layout, storage_entry, storage_texture_entry, uniform_entry,
};
use strandlight_runtime::gpu::buffer::init_buffer;
use strandlight_runtime::gpu::pipeline::{compute_pipeline, wgsl_module};

/// The picture's format: sRGB-encoded bytes in a unorm texture, which is what egui-wgpu's
/// textures are (it samples and blends in gamma space).
const PICTURE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;
/// `Meter` in the shader: 512 + 1024 bin counts, the total, the bin, the rank, the stops.
const METER_BYTES: u64 = 4 * (512 + 1024 + 4);

/// What the window shows of a frame.
#[derive(Clone)]
pub struct DisplayRequest {
    pub image: Arc<GpuImage>,
    /// Manual stops; None meters them on the hair.
    pub exposure_stops: Option<f32>,
    /// The backdrop's radiance behind each pixel, at the hair's exposure; None for black.
    pub backdrop: Option<Arc<Vec<[f32; 3]>>>,
}

impl DisplayRequest {
    /// The same picture: the same image, exposure and backdrop (by identity).
    pub fn same_as(&self, other: &DisplayRequest) -> bool {
        Arc::ptr_eq(&self.image, &other.image)
            && self.exposure_stops == other.exposure_stops
            && match (&self.backdrop, &other.backdrop) {
                (Some(a), Some(b)) => Arc::ptr_eq(a, b),
                (None, None) => true,
                _ => false,
            }
    }
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Params {
    width: u32,
    height: u32,
    with_multiple: u32,
    has_backdrop: u32,
    scale: f32,
    manual: u32,
    manual_stops: f32,
    _pad: u32,
}

/// The picture's texture, with the egui id it is drawn by.
struct Picture {
    texture: wgpu::Texture,
    id: egui::TextureId,
}

/// The metering and display pipelines, and the picture they write.
pub struct GpuDisplay {
    layout: wgpu::BindGroupLayout,
    /// meter_coarse, meter_pick_coarse, meter_fine, meter_pick_fine, display.
    passes: [wgpu::ComputePipeline; 5],
    meter: wgpu::Buffer,
    /// Bound where there is no backdrop.
    no_backdrop: wgpu::Buffer,
    picture: Option<Picture>,
    /// The backdrop uploaded last, by identity, and its buffer.
    backdrop: Option<(Arc<Vec<[f32; 3]>>, wgpu::Buffer)>,
    /// The window is on a device of its own: images come as bytes, uploaded here.
    uploads: bool,
    /// The image uploaded last, and its buffer on the window's device.
    uploaded: Option<(Arc<GpuImage>, wgpu::Buffer)>,
}

impl GpuDisplay {
    /// The passes on the window's `device`; `uploads`: it is not the renderer's device, and
    /// images arrive read back ([`GpuImage::read_back`]).
    pub fn new(device: &wgpu::Device, uploads: bool) -> Self {
        let compute = wgpu::ShaderStages::COMPUTE;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("viewer display"),
            entries: &[
                storage_entry(0, compute, true),
                storage_entry(1, compute, true),
                uniform_entry(2, compute),
                storage_entry(3, compute, false),
                storage_texture_entry(4, compute, PICTURE_FORMAT),
            ],
        });
        let shader = wgsl_module(device, "gpu_display.wgsl", include_str!("gpu_display.wgsl"));
        let pipeline_layout = pipeline_layout(device, "viewer display", &[Some(&layout)]);
        let passes = [
            "meter_coarse",
            "meter_pick_coarse",
            "meter_fine",
            "meter_pick_fine",
            "display",
        ]
        .map(|entry| compute_pipeline(device, entry, &pipeline_layout, &shader, entry));
        let meter = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("viewer exposure meter"),
            size: METER_BYTES,
            usage: wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::COPY_DST
                | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let no_backdrop = init_buffer(
            device,
            "viewer: no backdrop",
            &[0u8; 16],
            wgpu::BufferUsages::STORAGE,
        );
        Self {
            layout,
            passes,
            meter,
            no_backdrop,
            picture: None,
            backdrop: None,
            uploads,
            uploaded: None,
        }
    }

    /// Draws `request`'s picture and returns the egui texture that shows it (one id for the
    /// window's life; the texture follows the image's size). Submitted on `queue` before the
    /// caller's egui pass, which samples it.
    pub fn show(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        renderer: &mut egui_wgpu::Renderer,
        request: &DisplayRequest,
    ) -> egui::TextureId {
        let size = request.image.size;
        let texture = self.picture_texture(device, renderer, size);
        let mut encoder = device.create_command_encoder(&Default::default());
        self.encode(device, &mut encoder, request, &texture);
        queue.submit([encoder.finish()]);
        self.picture.as_ref().expect("made above").id
    }

    /// The picture's texture at `size`, made (and given to egui) when the size changes.
    fn picture_texture(
        &mut self,
        device: &wgpu::Device,
        renderer: &mut egui_wgpu::Renderer,
        [width, height]: [u32; 2],
    ) -> wgpu::Texture {
        if let Some(p) = &self.picture
            && p.texture.width() == width
            && p.texture.height() == height
        {
            return p.texture.clone();
        }
        let texture = picture_texture(device, [width, height]);
        let view = texture.create_view(&wgpu::TextureViewDescriptor {
            usage: Some(wgpu::TextureUsages::TEXTURE_BINDING),
            ..Default::default()
        });
        let filter = wgpu::FilterMode::Linear;
        let id = match &self.picture {
            Some(p) => {
                renderer.update_egui_texture_from_wgpu_texture(device, &view, filter, p.id);
                p.id
            }
            None => renderer.register_native_texture(device, &view, filter),
        };
        self.picture = Some(Picture {
            texture: texture.clone(),
            id,
        });
        texture
    }

    /// Records the metering and the display of `request` into `picture` (its size).
    pub fn encode(
        &mut self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        request: &DisplayRequest,
        picture: &wgpu::Texture,
    ) {
        let image = &request.image;
        let [width, height] = image.size;
        let params = Params {
            width,
            height,
            with_multiple: image.with_multiple as u32,
            has_backdrop: request.backdrop.is_some() as u32,
            scale: image.scale,
            manual: request.exposure_stops.is_some() as u32,
            manual_stops: request.exposure_stops.unwrap_or(0.0),
            _pad: 0,
        };
        let params = init_buffer(
            device,
            "viewer display params",
            bytemuck::bytes_of(&params),
            wgpu::BufferUsages::UNIFORM,
        );
        let backdrop = self.backdrop_buffer(device, request.backdrop.as_ref());
        let sums = self.sums_buffer(device, image);
        let view = picture.create_view(&Default::default());
        let group = bind_group(
            device,
            "viewer display",
            &self.layout,
            &[
                sums.as_entire_binding(),
                backdrop.as_entire_binding(),
                params.as_entire_binding(),
                self.meter.as_entire_binding(),
                wgpu::BindingResource::TextureView(&view),
            ],
        );
        encoder.clear_buffer(&self.meter, 0, None);
        let per_pixel = [width.div_ceil(8), height.div_ceil(8), 1];
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("viewer display"),
            timestamp_writes: None,
        });
        pass.set_bind_group(0, &group, &[]);
        let dispatches =
            (self.passes.iter()).zip([per_pixel, [1, 1, 1], per_pixel, [1, 1, 1], per_pixel]);
        // Manual stops need no metering: only the display pass (the last) runs.
        let metering = if request.exposure_stops.is_some() {
            4
        } else {
            0
        };
        for (pipeline, groups) in dispatches.skip(metering) {
            pass.set_pipeline(pipeline);
            pass.dispatch_workgroups(groups[0], groups[1], groups[2]);
        }
    }

    /// The image's sums on the window's device: the renderer's buffer itself, or its bytes
    /// uploaded once (a new display setting draws the same image again).
    fn sums_buffer(&mut self, device: &wgpu::Device, image: &Arc<GpuImage>) -> wgpu::Buffer {
        let bytes = match (&image.read_back, self.uploads) {
            (Some(bytes), true) => bytes,
            _ => return image.buffer.clone(),
        };
        if let Some((kept, buffer)) = &self.uploaded
            && Arc::ptr_eq(kept, image)
        {
            return buffer.clone();
        }
        let buffer = init_buffer(
            device,
            "viewer: uploaded sums",
            bytes,
            wgpu::BufferUsages::STORAGE,
        );
        self.uploaded = Some((image.clone(), buffer.clone()));
        buffer
    }

    /// The backdrop's buffer: uploaded once per backdrop (it changes with the view, not with
    /// the refinement's steps).
    fn backdrop_buffer(
        &mut self,
        device: &wgpu::Device,
        backdrop: Option<&Arc<Vec<[f32; 3]>>>,
    ) -> wgpu::Buffer {
        let Some(pixels) = backdrop else {
            return self.no_backdrop.clone();
        };
        if let Some((kept, buffer)) = &self.backdrop
            && Arc::ptr_eq(kept, pixels)
        {
            return buffer.clone();
        }
        let padded: Vec<[f32; 4]> = pixels.iter().map(|p| [p[0], p[1], p[2], 0.0]).collect();
        let buffer = init_buffer(
            device,
            "viewer backdrop",
            bytemuck::cast_slice(&padded),
            wgpu::BufferUsages::STORAGE,
        );
        self.backdrop = Some((pixels.clone(), buffer.clone()));
        buffer
    }

    /// The meter's buffer (`Meter` in the shader; its stops are the last of its words), for
    /// tests.
    #[cfg(test)]
    fn meter(&self) -> &wgpu::Buffer {
        &self.meter
    }
}

/// A picture texture: written as storage, sampled by egui.
fn picture_texture(device: &wgpu::Device, [width, height]: [u32; 2]) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some("viewer picture"),
        size: wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: PICTURE_FORMAT,
        usage: wgpu::TextureUsages::STORAGE_BINDING
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::display::{composite, to_rgba8};
    use strandlight_runtime::gpu::{GpuContext, read_buffer};
    use strandlight_scene::exposure::metered_stops;
    use strandlight_scene::image_metrics::Image;

    /// A frame's sums with hair of spread luminance (some pixels bare, one NaN), single and
    /// multiple halves.
    fn sums(width: u32, height: u32) -> (Vec<[f32; 4]>, Vec<[f32; 4]>) {
        let n = (width * height) as usize;
        let mut single = Vec::with_capacity(n);
        let mut multiple = Vec::with_capacity(n);
        for i in 0..n {
            let t = i as f32 / n as f32;
            let alpha = if i % 7 == 0 { 0.0 } else { 0.25 + 0.75 * t };
            let l = 1e-3 * (1e5f32).powf((i * 7919 % n) as f32 / n as f32);
            single.push([0.8 * l * alpha, l * alpha, 0.5 * l * alpha, alpha]);
            multiple.push([0.1 * l * alpha, 0.2 * l * alpha, 0.05 * l * alpha, 0.0]);
        }
        single[3][0] = f32::NAN;
        (single, multiple)
    }

    fn read_picture(gpu: &GpuContext, texture: &wgpu::Texture) -> Vec<u8> {
        let (w, h) = (texture.width(), texture.height());
        let row = (4 * w).div_ceil(256) * 256;
        let buffer = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: None,
            size: (row * h) as u64,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        encoder.copy_texture_to_buffer(
            texture.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &buffer,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(row),
                    rows_per_image: None,
                },
            },
            texture.size(),
        );
        gpu.queue.submit([encoder.finish()]);
        let bytes = read_buffer(gpu, &buffer).unwrap();
        (0..h as usize)
            .flat_map(|y| bytes[y * row as usize..][..4 * w as usize].to_vec())
            .collect()
    }

    /// The GPU's picture against the CPU's (`display::composite` and `to_rgba8` at the CPU's
    /// exactly selected 90th percentile): the exposure within 1/1000 of a stop, and every byte
    /// within one level (f32 on the GPU against f64 rounding on the CPU).
    #[test]
    fn the_gpu_picture_is_the_cpus_metered_composited_and_tonemapped_picture() {
        let gpu = GpuContext::new_headless().unwrap_or_else(|e| panic!("{e}"));
        let (width, height) = (61, 37);
        let (single, multiple) = sums(width, height);
        let scale = 1.7;
        let backdrop: Vec<[f32; 3]> = (0..width * height)
            .map(|i| [0.01 * (i % 13) as f32, 0.02, 0.3])
            .collect();
        let cpu_image = Image {
            width,
            height,
            pixels: single
                .iter()
                .zip(&multiple)
                .map(|(s, m)| {
                    let c = |k: usize| scale * (s[k] + m[k]);
                    [c(0), c(1), c(2), s[3]]
                })
                .collect(),
        };
        let cpu_stops = metered_stops(&cpu_image.pixels).unwrap();
        let expected = to_rgba8(&composite(&cpu_image, cpu_stops, Some(&backdrop)));

        let mut bytes = bytemuck::cast_slice::<_, u8>(&single).to_vec();
        bytes.extend_from_slice(bytemuck::cast_slice(&multiple));
        let image = Arc::new(GpuImage {
            buffer: init_buffer(
                &gpu.device,
                "test sums",
                &bytes,
                wgpu::BufferUsages::STORAGE,
            ),
            size: [width, height],
            with_multiple: true,
            scale,
            read_back: None,
        });
        let mut display = GpuDisplay::new(&gpu.device, false);
        let picture = picture_texture(&gpu.device, [width, height]);
        let request = DisplayRequest {
            image,
            exposure_stops: None,
            backdrop: Some(Arc::new(backdrop)),
        };
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        display.encode(&gpu.device, &mut encoder, &request, &picture);
        gpu.queue.submit([encoder.finish()]);
        let meter = read_buffer(&gpu, display.meter()).unwrap();
        let gpu_stops = f32::from_le_bytes(meter[meter.len() - 4..].try_into().unwrap());
        assert!(
            (gpu_stops - cpu_stops).abs() < 1e-3,
            "GPU metered {gpu_stops} stops, the CPU {cpu_stops}"
        );
        let got = read_picture(&gpu, &picture);
        let mut worst = 0;
        for (i, (g, e)) in got.iter().zip(&expected).enumerate() {
            let d = (*g as i32 - *e as i32).abs();
            assert!(d <= 1, "byte {i}: GPU {g}, CPU {e}");
            worst = worst.max(d);
        }
        eprintln!("GPU {gpu_stops} vs CPU {cpu_stops} stops; worst byte difference {worst}");

        // Manual stops are taken as they are.
        let manual = DisplayRequest {
            exposure_stops: Some(-3.0),
            ..request.clone()
        };
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        display.encode(&gpu.device, &mut encoder, &manual, &picture);
        gpu.queue.submit([encoder.finish()]);
        let expected = to_rgba8(&composite(
            &cpu_image,
            -3.0,
            request.backdrop.as_deref().map(|b| b.as_slice()),
        ));
        let got = read_picture(&gpu, &picture);
        assert!(
            got.iter()
                .zip(&expected)
                .all(|(g, e)| (*g as i32 - *e as i32).abs() <= 1)
        );
    }
}
