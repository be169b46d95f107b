//! Copying a colour texture back to the CPU as linear f32 RGBA.

use super::GpuContext;

#[derive(Debug, thiserror::Error)]
pub enum ReadbackError {
    #[error("texture format {0:?} cannot be read back (only Rgba16Float and Rgba32Float)")]
    UnsupportedFormat(wgpu::TextureFormat),
    #[error("mapping the readback buffer failed: {0}")]
    Map(#[from] wgpu::BufferAsyncError),
    #[error("reading the mapped readback buffer failed: {0}")]
    MapRange(#[from] wgpu::MapRangeError),
}

/// The texture's pixels (of its first array layer), row-major from the top row, 4 floats per
/// pixel.
pub fn read_texture_rgba(
    gpu: &GpuContext,
    texture: &wgpu::Texture,
) -> Result<Vec<[f32; 4]>, ReadbackError> {
    read_texture_layer_rgba(gpu, texture, 0)
}

/// Array layer `layer` of the texture, row-major from the top row, 4 floats per pixel.
pub fn read_texture_layer_rgba(
    gpu: &GpuContext,
    texture: &wgpu::Texture,
    layer: u32,
) -> Result<Vec<[f32; 4]>, ReadbackError> {
    let format = texture.format();
    let bytes_per_pixel = match format {
        wgpu::TextureFormat::Rgba16Float => 8,
        wgpu::TextureFormat::Rgba32Float => 16,
        other => return Err(ReadbackError::UnsupportedFormat(other)),
    };
    let (width, height) = (texture.width(), texture.height());
    let unpadded_row = width * bytes_per_pixel;
    // Buffer copies need rows aligned to 256 bytes.
    let row = unpadded_row.div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT)
        * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
    let buffer = gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback"),
        size: (row * height) as u64,
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    encoder.copy_texture_to_buffer(
        wgpu::TexelCopyTextureInfo {
            origin: wgpu::Origin3d {
                x: 0,
                y: 0,
                z: layer,
            },
            ..texture.as_image_copy()
        },
        wgpu::TexelCopyBufferInfo {
            buffer: &buffer,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(row),
                rows_per_image: Some(height),
            },
        },
        wgpu::Extent3d {
            depth_or_array_layers: 1,
            ..texture.size()
        },
    );
    gpu.queue.submit([encoder.finish()]);
    let slice = buffer.slice(..);
    let (sender, receiver) = std::sync::mpsc::channel();
    slice.map_async(wgpu::MapMode::Read, move |r| {
        let _ = sender.send(r);
    });
    gpu.wait_idle();
    receiver.recv().unwrap_or(Err(wgpu::BufferAsyncError))?;
    let data = slice.get_mapped_range()?;
    let mut pixels = Vec::with_capacity((width * height) as usize);
    for y in 0..height as usize {
        let start = y * row as usize;
        let line = &data[start..start + unpadded_row as usize];
        match format {
            wgpu::TextureFormat::Rgba32Float => {
                let floats: &[f32] = bytemuck::cast_slice(line);
                pixels.extend(floats.chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]));
            }
            _ => {
                let halves: &[half::f16] = bytemuck::cast_slice(line);
                pixels.extend(
                    halves
                        .chunks_exact(4)
                        .map(|c| [c[0].to_f32(), c[1].to_f32(), c[2].to_f32(), c[3].to_f32()]),
                );
            }
        }
    }
    drop(data);
    buffer.unmap();
    Ok(pixels)
}

/// A storage buffer's bytes (the buffer needs `COPY_SRC`).
pub fn read_buffer(gpu: &GpuContext, source: &wgpu::Buffer) -> Result<Vec<u8>, ReadbackError> {
    let buffer = gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback"),
        size: source.size(),
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    encoder.copy_buffer_to_buffer(source, 0, &buffer, 0, source.size());
    gpu.queue.submit([encoder.finish()]);
    let slice = buffer.slice(..);
    let (sender, receiver) = std::sync::mpsc::channel();
    slice.map_async(wgpu::MapMode::Read, move |r| {
        let _ = sender.send(r);
    });
    gpu.wait_idle();
    receiver.recv().unwrap_or(Err(wgpu::BufferAsyncError))?;
    let bytes = slice.get_mapped_range()?.to_vec();
    buffer.unmap();
    Ok(bytes)
}
