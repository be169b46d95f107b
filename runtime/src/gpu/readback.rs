//! Copying a colour texture back to the CPU as linear f32 RGBA.

use super::GpuContext;
use std::sync::atomic::{AtomicU64, Ordering};

/// Copies from the GPU to the CPU so far in this process: every readback of the runtime goes
/// through [`wait_for_copy`], so a host can check that its frame path makes none.
static READBACKS: AtomicU64 = AtomicU64::new(0);
/// Those of them that read the pass timer's timestamps (a measurement, not the frame's data).
static TIMESTAMP_READBACKS: AtomicU64 = AtomicU64::new(0);

thread_local! {
    /// Data readbacks (not timestamps) made on this thread.
    static DATA_READBACKS_HERE: std::cell::Cell<u64> = const { std::cell::Cell::new(0) };
}

/// How many GPU→CPU copies this process has made (textures, buffers, timestamps).
pub fn readbacks_so_far() -> u64 {
    READBACKS.load(Ordering::Relaxed)
}

/// How many GPU→CPU copies of data (pixels, depth, counters, grids) this process has made: every
/// copy but the pass timer's timestamps. A frame path that keeps its frame on the GPU makes none.
pub fn data_readbacks_so_far() -> u64 {
    READBACKS.load(Ordering::Relaxed) - TIMESTAMP_READBACKS.load(Ordering::Relaxed)
}

/// [`data_readbacks_so_far`] made on the calling thread.
pub fn data_readbacks_on_this_thread() -> u64 {
    DATA_READBACKS_HERE.with(|n| n.get())
}

/// What a copy reads.
#[derive(Clone, Copy, PartialEq)]
enum CopyOf {
    Data,
    Timestamps,
}

/// Maps `slice` for reading and waits for it: the one place the runtime blocks on a copy.
fn wait_for_copy(gpu: &GpuContext, slice: &wgpu::BufferSlice<'_>) -> Result<(), ReadbackError> {
    wait_for_copy_of(gpu, slice, CopyOf::Data)
}

fn wait_for_copy_of(
    gpu: &GpuContext,
    slice: &wgpu::BufferSlice<'_>,
    of: CopyOf,
) -> Result<(), ReadbackError> {
    // Counted before the wait, as the one copy asked for whether or not it succeeds.
    READBACKS.fetch_add(1, Ordering::Relaxed);
    match of {
        CopyOf::Timestamps => {
            TIMESTAMP_READBACKS.fetch_add(1, Ordering::Relaxed);
        }
        CopyOf::Data => DATA_READBACKS_HERE.with(|n| n.set(n.get() + 1)),
    }
    let (sender, receiver) = std::sync::mpsc::channel();
    slice.map_async(wgpu::MapMode::Read, move |r| {
        let _ = sender.send(r);
    });
    gpu.wait_idle();
    receiver.recv().unwrap_or(Err(wgpu::BufferAsyncError))?;
    Ok(())
}

#[derive(Debug, thiserror::Error)]
pub enum ReadbackError {
    #[error(
        "texture format {0:?} cannot be read back (only Rgba16Float, Rgba32Float and \
         Depth32Float)"
    )]
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
    let bytes = match texture.format() {
        wgpu::TextureFormat::Rgba16Float | wgpu::TextureFormat::Rgba32Float => {
            read_texels(gpu, texture, layer, wgpu::TextureAspect::All)?
        }
        other => return Err(ReadbackError::UnsupportedFormat(other)),
    };
    // Copied out value by value: a byte vector promises no alignment for a cast.
    Ok(match texture.format() {
        wgpu::TextureFormat::Rgba32Float => bytes
            .chunks_exact(16)
            .map(|t| std::array::from_fn(|k| f32::from_le_bytes(word(&t[4 * k..]))))
            .collect(),
        _ => bytes
            .chunks_exact(8)
            .map(|t| {
                std::array::from_fn(|k| half::f16::from_le_bytes([t[2 * k], t[2 * k + 1]]).to_f32())
            })
            .collect(),
    })
}

/// The first four bytes of `bytes`.
fn word(bytes: &[u8]) -> [u8; 4] {
    [bytes[0], bytes[1], bytes[2], bytes[3]]
}

/// A `Depth32Float` texture's depths, row-major from the top row.
pub fn read_depth(gpu: &GpuContext, texture: &wgpu::Texture) -> Result<Vec<f32>, ReadbackError> {
    if texture.format() != wgpu::TextureFormat::Depth32Float {
        return Err(ReadbackError::UnsupportedFormat(texture.format()));
    }
    let bytes = read_texels(gpu, texture, 0, wgpu::TextureAspect::DepthOnly)?;
    Ok(bytes
        .chunks_exact(4)
        .map(|t| f32::from_le_bytes(word(t)))
        .collect())
}

/// Array layer `layer` of `texture` (its `aspect`), row-major from the top row, rows packed
/// without the copy's padding.
fn read_texels(
    gpu: &GpuContext,
    texture: &wgpu::Texture,
    layer: u32,
    aspect: wgpu::TextureAspect,
) -> Result<Vec<u8>, ReadbackError> {
    let bytes_per_texel = texture
        .format()
        .block_copy_size(Some(aspect))
        .ok_or(ReadbackError::UnsupportedFormat(texture.format()))?;
    let (width, height) = (texture.width(), texture.height());
    let unpadded_row = width * bytes_per_texel;
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
            aspect,
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
    wait_for_copy(gpu, &slice)?;
    let data = slice.get_mapped_range()?;
    let texels = (0..height as usize)
        .flat_map(|y| {
            let start = y * row as usize;
            data[start..start + unpadded_row as usize].iter().copied()
        })
        .collect();
    drop(data);
    buffer.unmap();
    Ok(texels)
}

/// A storage buffer's bytes (the buffer needs `COPY_SRC`).
pub fn read_buffer(gpu: &GpuContext, source: &wgpu::Buffer) -> Result<Vec<u8>, ReadbackError> {
    read_buffer_of(gpu, source, CopyOf::Data)
}

/// [`read_buffer`] of the pass timer's resolved timestamps (counted apart from data).
pub(crate) fn read_timestamps(
    gpu: &GpuContext,
    source: &wgpu::Buffer,
) -> Result<Vec<u8>, ReadbackError> {
    read_buffer_of(gpu, source, CopyOf::Timestamps)
}

fn read_buffer_of(
    gpu: &GpuContext,
    source: &wgpu::Buffer,
    of: CopyOf,
) -> Result<Vec<u8>, ReadbackError> {
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
    wait_for_copy_of(gpu, &slice, of)?;
    let bytes = slice.get_mapped_range()?.to_vec();
    buffer.unmap();
    Ok(bytes)
}
