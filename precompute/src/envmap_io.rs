//! Reading environment maps from disk: Radiance `.hdr` (our decoder, [`crate::radiance_hdr`])
//! and OpenEXR (the `exr` crate: half/float/uint samples, any channel order, every compression
//! it supports), then the 2:1 and bad-pixel checks.

use crate::envmap::{BadPixelCounts, EnvMap};
use crate::envmap_error::EnvMapError;
use std::path::{Path, PathBuf};
use strandlight_tables::checksum::sha256_hex;
use strandlight_tables::image_out::write_exr_rgb;

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

/// The most bytes of samples one byte of compressed EXR chunk data can expand to, by
/// compression method: deflate (ZIP, PXR24 after its 32 → 24-bit packing) at most 1032:1, RLE a
/// 128-byte run in 2 bytes, B44A a flat 4×4 block of halves (32 bytes) in 3, PIZ's Huffman runs
/// (up to 255 repeats of a 16-bit symbol in 9 bits) under the deflate figure.
fn max_expansion(compression: exr::compression::Compression) -> f64 {
    use exr::compression::Compression::*;
    match compression {
        Uncompressed => 1.0,
        RLE => 64.0,
        B44 | B44A => 32.0 / 3.0,
        PXR24 => 1032.0 * 4.0 / 3.0,
        ZIP1 | ZIP16 | PIZ => 1032.0,
        // Not decodable by the exr crate; the bound only has to stop a wild allocation.
        _ => 1032.0,
    }
}

/// Refuses a layer whose data window the file cannot hold, before the decoder allocates its
/// pixels: `width × height × stored bytes per pixel` must fit in the file's length times the
/// compression's [`max_expansion`]. The figures come from the header alone.
fn check_exr_sizes(path: &Path, bytes: &[u8]) -> Result<(), EnvMapError> {
    let exr_error = |message: String| EnvMapError::Exr {
        path: path.into(),
        message,
    };
    let meta = exr::meta::MetaData::read_from_buffered(std::io::Cursor::new(bytes), false)
        .map_err(|e| exr_error(e.to_string()))?;
    for header in meta.headers.iter() {
        let mut stored_per_pixel = 0usize;
        for channel in header.channels.list.iter() {
            if channel.sampling.x() != 1 || channel.sampling.y() != 1 {
                return Err(exr_error(format!(
                    "channel {} is subsampled ({} × {}); environment maps need full-resolution channels",
                    channel.name,
                    channel.sampling.x(),
                    channel.sampling.y()
                )));
            }
            stored_per_pixel += channel.sample_type.bytes_per_sample();
        }
        let (width, height) = (header.layer_size.x() as u64, header.layer_size.y() as u64);
        let max_bytes = bytes.len() as f64 * max_expansion(header.compression);
        let max_pixels = (max_bytes / stored_per_pixel.max(1) as f64) as u64;
        if width as f64 * height as f64 > max_pixels as f64 {
            return Err(EnvMapError::ImpossibleSize {
                path: path.into(),
                width,
                height,
                bytes: bytes.len() as u64,
                encoding: "OpenEXR compression of its header",
                max_pixels,
            });
        }
    }
    Ok(())
}

fn decode_exr(path: &Path, bytes: &[u8]) -> Result<EnvMap, EnvMapError> {
    use exr::prelude::*;
    check_exr_sizes(path, bytes)?;
    struct Pixels {
        width: usize,
        data: Vec<[f32; 3]>,
    }
    // The exr crate can panic on corrupt chunk data (e.g. an arithmetic overflow in its B44
    // decoder, found by the fuzz harness): decoding runs on this thread (`non_parallel`, since a
    // panic on a rayon worker aborts the process) and a panic becomes an error naming the file.
    let decoded = std::panic::catch_unwind(|| {
        read()
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
            .non_parallel()
            .from_buffered(std::io::Cursor::new(bytes))
    });
    let image = match decoded {
        Ok(result) => result.map_err(|e| EnvMapError::Exr {
            path: path.into(),
            message: e.to_string(),
        })?,
        Err(panic) => {
            let why = panic
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| panic.downcast_ref::<String>().cloned())
                .unwrap_or_default();
            return Err(EnvMapError::Exr {
                path: path.into(),
                message: format!("the decoder failed on corrupt pixel data ({why})"),
            });
        }
    };
    let pixels = image.layer_data.channel_data.pixels;
    let height = pixels.data.len() / pixels.width.max(1);
    Ok(EnvMap::from_pixels(pixels.width, height, pixels.data))
}

/// Writes an EXR (f32, RGB) atomically: the procedural maps, tests and debugging output.
pub fn write_exr(map: &EnvMap, path: &Path) -> Result<(), EnvMapError> {
    Ok(write_exr_rgb(
        path,
        map.width() as u32,
        map.height() as u32,
        map.pixels(),
        "environment map",
        "equirectangular, linear RGB",
    )?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::{Duration, Instant};

    /// An EXR of `map` (f32 RGB, scan lines) with `compression`, in memory.
    fn exr_bytes(map: &EnvMap, compression: exr::compression::Compression) -> Vec<u8> {
        use exr::prelude::*;
        let channels = SpecificChannels::rgb(|p: Vec2<usize>| {
            let [r, g, b] = map.pixel(p.x(), p.y());
            (r, g, b)
        });
        let encoding = Encoding {
            compression,
            ..Encoding::UNCOMPRESSED
        };
        let mut out = std::io::Cursor::new(Vec::new());
        Image::from_encoded_channels((map.width(), map.height()), encoding, channels)
            .write()
            .to_buffered(&mut out)
            .unwrap();
        out.into_inner()
    }

    /// The same in half floats.
    fn exr_half_bytes(map: &EnvMap, compression: exr::compression::Compression) -> Vec<u8> {
        use exr::prelude::*;
        let channels = SpecificChannels::rgb(|p: Vec2<usize>| {
            let [r, g, b] = map.pixel(p.x(), p.y()).map(f16::from_f32);
            (r, g, b)
        });
        let encoding = Encoding {
            compression,
            ..Encoding::UNCOMPRESSED
        };
        let mut out = std::io::Cursor::new(Vec::new());
        Image::from_encoded_channels((map.width(), map.height()), encoding, channels)
            .write()
            .to_buffered(&mut out)
            .unwrap();
        out.into_inner()
    }

    fn gradient(width: usize, height: usize) -> EnvMap {
        let pixels = (0..width * height)
            .map(|i| [(i % width) as f32 / width as f32, 0.5, (i / width) as f32])
            .collect();
        EnvMap::from_pixels(width, height, pixels)
    }

    /// Byte offset of the value of header attribute `name` (after its name, type and size).
    fn attribute_value(bytes: &[u8], name: &str, kind: &str) -> usize {
        let key = format!("{name}\0{kind}\0");
        let at = bytes
            .windows(key.len())
            .position(|w| w == key.as_bytes())
            .unwrap_or_else(|| panic!("no {name} attribute"));
        at + key.len() + 4
    }

    fn load_exr(bytes: &[u8], sanitize: bool) -> Result<LoadedEnvMap, EnvMapError> {
        load_bytes(Path::new("crafted.exr"), bytes, LoadOptions { sanitize })
    }

    /// Fuzz finding (exr target): a data window of 10⁶ × 10⁶ pixels in a file of a few hundred
    /// bytes made the decoder ask for a 12 TB pixel buffer, which aborted the process. It is now
    /// refused from the header, before anything is allocated for the pixels.
    #[test]
    fn a_huge_exr_data_window_is_refused_before_allocation() {
        let good = exr_bytes(&gradient(16, 8), exr::compression::Compression::ZIP16);
        assert!(load_exr(&good, false).is_ok());
        for (width, height) in [
            (1_000_000i32, 1_000_000i32),
            (1 << 20, 1 << 19),
            (64, 1 << 24),
        ] {
            let mut bad = good.clone();
            let window = attribute_value(&bad, "dataWindow", "box2i");
            bad[window + 8..window + 12].copy_from_slice(&(width - 1).to_le_bytes());
            bad[window + 12..window + 16].copy_from_slice(&(height - 1).to_le_bytes());
            let start = Instant::now();
            let e = load_exr(&bad, false).unwrap_err();
            assert!(start.elapsed() < Duration::from_secs(1), "slow: {e}");
            assert!(
                matches!(e, EnvMapError::ImpossibleSize { width: w, height: h, .. }
                    if w == width as u64 && h == height as u64),
                "{e}"
            );
            assert!(e.to_string().contains("crafted.exr"), "{e}");
        }
        // The honest bound admits what ZIP can really hold: a constant 2048 × 1024 map
        // compresses far below its 25 MB of floats and still loads.
        let flat = EnvMap::from_pixels(2048, 1024, vec![[0.25; 3]; 2048 * 1024]);
        let zipped = exr_bytes(&flat, exr::compression::Compression::ZIP16);
        assert!(zipped.len() < 2048 * 1024, "{} bytes", zipped.len());
        assert_eq!(load_exr(&zipped, false).unwrap().map.width(), 2048);
    }

    /// Fuzz finding (exr target): ZIP data relabelled as B44/B44A by a flipped compression byte
    /// made the exr crate's B44 decoder panic on an arithmetic overflow — on a rayon worker
    /// thread, which aborted the whole process. Decoding now runs on the caller's thread and a
    /// decoder panic is an error naming the file.
    #[test]
    fn a_decoder_panic_on_corrupt_chunks_is_an_error_naming_the_file() {
        let good = exr_half_bytes(&gradient(32, 16), exr::compression::Compression::ZIP16);
        assert!(load_exr(&good, false).is_ok());
        let at = attribute_value(&good, "compression", "compression");
        assert_eq!(good[at], 3, "ZIP16 is compression 3");
        let mut panics = 0;
        for relabel in [6u8, 7] {
            let mut bad = good.clone();
            bad[at] = relabel;
            let e = load_exr(&bad, true).unwrap_err();
            assert!(matches!(e, EnvMapError::Exr { .. }), "{e}");
            assert!(e.to_string().contains("crafted.exr"), "{e}");
            panics += e.to_string().contains("the decoder failed") as usize;
        }
        // The input still reaches the decoder's panic (so this stays a regression test).
        assert!(panics > 0);
    }

    #[test]
    fn subsampled_exr_channels_are_refused() {
        let mut bytes = exr_bytes(
            &gradient(16, 8),
            exr::compression::Compression::Uncompressed,
        );
        // The channel list: name\0, pixel type i32, pLinear u8, 3 reserved, xSampling, ySampling.
        let list = attribute_value(&bytes, "channels", "chlist");
        let sampling = list + 2 + 4 + 4; // "B\0", type, pLinear + reserved
        bytes[sampling..sampling + 4].copy_from_slice(&2i32.to_le_bytes());
        let e = load_exr(&bytes, false).unwrap_err();
        assert!(matches!(e, EnvMapError::Exr { .. }), "{e}");
        assert!(e.to_string().contains("crafted.exr"), "{e}");
    }

    /// NaN, ±Inf and negative values: refused with their counts and the file's name, or
    /// replaced (and counted) when sanitizing.
    #[test]
    fn bad_pixels_are_counted_and_refused_or_cleaned() {
        let mut map = gradient(8, 4);
        let bad = [
            (0, [f32::NAN, 0.5, 0.5]),
            (1, [f32::INFINITY, f32::INFINITY, 1.0]),
            (2, [0.5, f32::NEG_INFINITY, 0.5]),
            (3, [-2.0, -0.5, 0.5]),
        ];
        let mut pixels = map.pixels().to_vec();
        for (i, p) in bad {
            pixels[i] = p;
        }
        map = EnvMap::from_pixels(8, 4, pixels);
        let bytes = exr_bytes(&map, exr::compression::Compression::Uncompressed);
        let expected = BadPixelCounts {
            nan: 1,
            positive_infinity: 2,
            negative_infinity: 1,
            negative: 2,
        };
        match load_exr(&bytes, false) {
            Err(e @ EnvMapError::BadPixels { counts, .. }) => {
                assert_eq!(counts, expected);
                assert!(e.to_string().contains("crafted.exr"), "{e}");
            }
            other => panic!("expected BadPixels, got {other:?}"),
        }
        let loaded = load_exr(&bytes, true).unwrap();
        assert_eq!(loaded.sanitized, expected);
        assert_eq!(loaded.map.bad_pixels().total(), 0);
        let largest = map
            .pixels()
            .iter()
            .flatten()
            .filter(|v| v.is_finite())
            .fold(0.0f32, |m, &v| m.max(v));
        assert_eq!(loaded.map.pixel(0, 0), [0.0, 0.5, 0.5]);
        assert_eq!(loaded.map.pixel(1, 0), [largest, largest, 1.0]);
        assert_eq!(loaded.map.pixel(2, 0), [0.5, 0.0, 0.5]);
        assert_eq!(loaded.map.pixel(3, 0), [0.0, 0.0, 0.5]);
    }
}
