//! Reading environment maps from disk: Radiance `.hdr` (our decoder, [`crate::radiance_hdr`])
//! and OpenEXR (the `exr` crate: half/float/uint samples, any channel order, every compression
//! it supports), then the 2:1 and bad-pixel checks.

use crate::envmap::{BadPixelCounts, EnvMap};
use crate::envmap_error::EnvMapError;
use strandlight_tables::atomic_write::write_atomically;
use strandlight_tables::checksum::sha256_hex;
use std::path::{Path, PathBuf};

/// How to treat a map's bad pixels (NaN, ±Inf, negative).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct LoadOptions {
    /// Replace bad values instead of refusing the file.
    pub sanitize: bool,
}

/// A map read from disk with what is known about its origin.
#[derive(Debug, Clone)]
pub struct LoadedEnvMap {
    pub map: EnvMap,
    pub path: PathBuf,
    /// Hex SHA-256 of the file's bytes.
    pub sha256: String,
    /// Bad values found (and replaced, since loading succeeded with them present).
    pub sanitized: BadPixelCounts,
}

/// Reads, checks and (if asked) sanitizes an environment map.
pub fn load(path: &Path, options: LoadOptions) -> Result<LoadedEnvMap, EnvMapError> {
    let bytes = std::fs::read(path).map_err(|source| EnvMapError::Io {
        path: path.into(),
        source,
    })?;
    load_bytes(path, &bytes, options)
}

/// [`load`] for a file already in memory (`path` only names it in errors): the entry point the
/// fuzz harness drives, so that it exercises exactly what loading a file does.
pub fn load_bytes(
    path: &Path,
    bytes: &[u8],
    options: LoadOptions,
) -> Result<LoadedEnvMap, EnvMapError> {
    let sha256 = sha256_hex(bytes);
    let mut map = decode(path, bytes)?;
    if map.width() != 2 * map.height() {
        return Err(EnvMapError::NotTwoToOne {
            path: path.into(),
            width: map.width(),
            height: map.height(),
        });
    }
    let bad = map.bad_pixels();
    let sanitized = if bad.total() == 0 {
        bad
    } else if options.sanitize {
        map.sanitize()
    } else {
        return Err(EnvMapError::BadPixels {
            path: path.into(),
            counts: bad,
        });
    };
    Ok(LoadedEnvMap {
        map,
        path: path.into(),
        sha256,
        sanitized,
    })
}

/// Decodes by content (signature), not by extension.
pub fn decode(path: &Path, bytes: &[u8]) -> Result<EnvMap, EnvMapError> {
    if bytes.starts_with(b"#?") {
        crate::radiance_hdr::decode(path, bytes)
    } else if bytes.starts_with(&[0x76, 0x2f, 0x31, 0x01]) {
        decode_exr(path, bytes)
    } else {
        Err(EnvMapError::UnknownFormat { path: path.into() })
    }
}

fn decode_exr(path: &Path, bytes: &[u8]) -> Result<EnvMap, EnvMapError> {
    use exr::prelude::*;
    struct Pixels {
        width: usize,
        data: Vec<[f32; 3]>,
    }
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .rgba_channels(
            |size, _| Pixels {
                width: size.width(),
                data: vec![[0.0; 3]; size.area()],
            },
            // The reader matches channels by name (R, G, B; alpha optional), so files that
            // store B, G, R come out right; samples of any type are converted to f32.
            |p: &mut Pixels, pos: Vec2<usize>, (r, g, b, _a): (f32, f32, f32, f32)| {
                p.data[pos.y() * p.width + pos.x()] = [r, g, b];
            },
        )
        .first_valid_layer()
        .all_attributes()
        .from_buffered(std::io::Cursor::new(bytes))
        .map_err(|e| EnvMapError::Exr {
            path: path.into(),
            message: e.to_string(),
        })?;
    let pixels = image.layer_data.channel_data.pixels;
    let height = pixels.data.len() / pixels.width.max(1);
    Ok(EnvMap::from_pixels(pixels.width, height, pixels.data))
}

/// Writes an EXR (f32, RGB) atomically: used for tests and for debugging output.
pub fn write_exr(map: &EnvMap, path: &Path) -> Result<(), EnvMapError> {
    use exr::prelude::*;
    let w = map.width();
    let channels = SpecificChannels::rgb(|p: Vec2<usize>| {
        let [r, g, b] = map.pixel(p.x(), p.y());
        (r, g, b)
    });
    let image = Image::from_channels((w, map.height()), channels);
    write_atomically(path, |out| {
        image.write().to_buffered(out).map_err(std::io::Error::other)
    })
    .map_err(|source| EnvMapError::Io {
        path: path.into(),
        source,
    })
}
