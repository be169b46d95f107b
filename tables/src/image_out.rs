//! Every image file the project writes, in one place: linear EXRs (RGBA frames, alpha
//! pre-multiplied as OpenEXR expects; RGB maps and table slices) and 8-bit PNGs for looking at
//! (frames tonemapped with [`PNG_TONEMAP`], or pictures already in sRGB bytes). All are written
//! atomically, so a failed write never leaves a half-written file, and each carries the
//! software's name and a description in its metadata.

use std::io;
use std::path::{Path, PathBuf};

use crate::atomic_write::write_atomically;
use crate::colour::srgb_encode;

/// The software name written into every file.
const SOFTWARE: &str = concat!("strandlight ", env!("CARGO_PKG_VERSION"));

#[derive(Debug, thiserror::Error)]
pub enum ImageWriteError {
    #[error("{path}: {width}×{height} image needs {expected} pixels, got {got}")]
    WrongSize {
        path: PathBuf,
        width: u32,
        height: u32,
        expected: usize,
        got: usize,
    },
    #[error("writing {path}: {source}")]
    Write {
        path: PathBuf,
        #[source]
        source: io::Error,
    },
}

/// The PNG's operator, also written into its `Tonemap` text chunk.
pub const PNG_TONEMAP: &str = "composited over black (pre-multiplied colour as is), exposure 1, \
    Reinhard c/(1+c) per channel, sRGB transfer curve, 8 bit RGB";

fn check_size(path: &Path, width: u32, height: u32, got: usize) -> Result<(), ImageWriteError> {
    let expected = width as usize * height as usize;
    if got != expected {
        return Err(ImageWriteError::WrongSize {
            path: path.into(),
            width,
            height,
            expected,
            got,
        });
    }
    Ok(())
}

/// Linear float RGBA EXR, ZIP-compressed: a rendered frame.
pub fn write_exr(
    path: &Path,
    width: u32,
    height: u32,
    pixels: &[[f32; 4]],
    comment: &str,
) -> Result<(), ImageWriteError> {
    use exr::prelude::*;
    check_size(path, width, height, pixels.len())?;
    let w = width as usize;
    let channels = SpecificChannels::rgba(|p: Vec2<usize>| {
        let [r, g, b, a] = pixels[p.y() * w + p.x()];
        (r, g, b, a)
    });
    let attributes = exr_attributes("strandlight render", comment);
    let layer = Layer::new(
        (w, height as usize),
        attributes,
        Encoding::SMALL_LOSSLESS,
        channels,
    );
    let image = Image::from_layer(layer);
    write_exr_file(path, |out| image.write().to_buffered(out))
}

/// Linear float RGB EXR, ZIP-compressed: an environment map or a picture of a table.
pub fn write_exr_rgb(
    path: &Path,
    width: u32,
    height: u32,
    pixels: &[[f32; 3]],
    layer_name: &str,
    comment: &str,
) -> Result<(), ImageWriteError> {
    use exr::prelude::*;
    check_size(path, width, height, pixels.len())?;
    let w = width as usize;
    let channels = SpecificChannels::rgb(|p: Vec2<usize>| {
        let [r, g, b] = pixels[p.y() * w + p.x()];
        (r, g, b)
    });
    let attributes = exr_attributes(layer_name, comment);
    let layer = Layer::new(
        (w, height as usize),
        attributes,
        Encoding::SMALL_LOSSLESS,
        channels,
    );
    let image = Image::from_layer(layer);
    write_exr_file(path, |out| image.write().to_buffered(out))
}

/// The layer's name, the comment and the software's name, in EXR's Latin-1 text.
fn exr_attributes(layer_name: &str, comment: &str) -> exr::meta::header::LayerAttributes {
    let mut attributes = exr::meta::header::LayerAttributes::named(latin1_text(layer_name));
    attributes.comments = Some(latin1_text(comment));
    attributes.software_name = Some(latin1_text(SOFTWARE));
    attributes
}

fn write_exr_file(
    path: &Path,
    write: impl FnOnce(&mut io::BufWriter<std::fs::File>) -> exr::error::UnitResult,
) -> Result<(), ImageWriteError> {
    write_atomically(path, |out| write(out).map_err(io::Error::other)).map_err(|source| {
        ImageWriteError::Write {
            path: path.into(),
            source,
        }
    })
}

/// One channel of [`PNG_TONEMAP`]; non-finite values become 0 (and are counted by callers that care).
pub fn tonemap_channel(c: f32) -> u8 {
    let c = if c.is_finite() {
        c.max(0.0) as f64
    } else {
        0.0
    };
    let p = c / (1.0 + c);
    (srgb_encode(p) * 255.0).round().clamp(0.0, 255.0) as u8
}

/// 8-bit RGB PNG tonemapped with [`PNG_TONEMAP`] (named in its `Tonemap` text chunk).
pub fn write_png(
    path: &Path,
    width: u32,
    height: u32,
    pixels: &[[f32; 4]],
    description: &str,
) -> Result<(), ImageWriteError> {
    write_png_exposed(path, width, height, pixels, 0.0, description)
}

/// [`PNG_TONEMAP`] with the exposure of [`write_png_exposed`] in place of exposure 1.
pub fn png_tonemap(stops: f32) -> String {
    if stops == 0.0 {
        return PNG_TONEMAP.to_string();
    }
    PNG_TONEMAP.replace("exposure 1", &format!("exposure {stops:+.2} stops"))
}

/// [`write_png`] with the radiance scaled by `2^stops` before the tonemap.
pub fn write_png_exposed(
    path: &Path,
    width: u32,
    height: u32,
    pixels: &[[f32; 4]],
    stops: f32,
    description: &str,
) -> Result<(), ImageWriteError> {
    check_size(path, width, height, pixels.len())?;
    let scale = stops.exp2();
    let bytes: Vec<u8> = pixels
        .iter()
        .flat_map(|p| [0, 1, 2].map(|k| tonemap_channel(scale * p[k])))
        .collect();
    write_png_rgb8_with_text(
        path,
        width,
        height,
        &bytes,
        &[
            ("Description", description),
            ("Tonemap", &png_tonemap(stops)),
        ],
    )
}

/// An 8-bit sRGB picture already made (3 bytes per pixel, e.g. a false-colour error map), with
/// its description in the file.
pub fn write_png_rgb8(
    path: &Path,
    width: u32,
    height: u32,
    bytes: &[u8],
    description: &str,
) -> Result<(), ImageWriteError> {
    write_png_rgb8_with_text(path, width, height, bytes, &[("Description", description)])
}

/// [`write_png_rgb8`] with any text chunks (key, value) beside the software's name.
pub fn write_png_rgb8_with_text(
    path: &Path,
    width: u32,
    height: u32,
    bytes: &[u8],
    text: &[(&str, &str)],
) -> Result<(), ImageWriteError> {
    if !bytes.len().is_multiple_of(3) {
        return Err(ImageWriteError::WrongSize {
            path: path.into(),
            width,
            height,
            expected: width as usize * height as usize,
            got: bytes.len() / 3,
        });
    }
    check_size(path, width, height, bytes.len() / 3)?;
    let encode = |w: &mut std::io::BufWriter<std::fs::File>| -> Result<(), png::EncodingError> {
        let mut encoder = png::Encoder::new(w, width, height);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        encoder.add_itxt_chunk("Software".into(), SOFTWARE.into())?;
        for (key, value) in text {
            encoder.add_itxt_chunk((*key).into(), (*value).into())?;
        }
        let mut writer = encoder.write_header()?;
        writer.write_image_data(bytes)?;
        writer.finish()
    };
    write_atomically(path, |w| encode(w).map_err(io::Error::other)).map_err(|source| {
        ImageWriteError::Write {
            path: path.into(),
            source,
        }
    })
}

/// EXR text is Latin-1: other characters (×, λ) are written as `<U+00D7>`.
fn latin1_text(s: &str) -> exr::meta::attribute::Text {
    let latin1: String = s
        .chars()
        .map(|c| {
            if (c as u32) < 256 {
                c.to_string()
            } else {
                format!("<U+{:04X}>", c as u32)
            }
        })
        .collect();
    exr::meta::attribute::Text::new_or_none(latin1)
        .unwrap_or_else(|| exr::meta::attribute::Text::new_or_panic("(text)"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exr_round_trips_and_png_decodes_with_the_tonemap_named() {
        let dir =
            std::env::temp_dir().join(format!("strandlight-image-out-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let (w, h) = (5u32, 3u32);
        let pixels: Vec<[f32; 4]> = (0..w * h)
            .map(|i| [i as f32 * 0.25, 1.0, 1e3, 0.5])
            .collect();
        let exr_path = dir.join("a.exr");
        write_exr(&exr_path, w, h, &pixels, "test").unwrap();
        let back = exr::prelude::read_first_rgba_layer_from_file(
            &exr_path,
            |res, _| vec![[0f32; 4]; res.width() * res.height()],
            move |v: &mut Vec<[f32; 4]>, p, (r, g, b, a): (f32, f32, f32, f32)| {
                v[p.y() * w as usize + p.x()] = [r, g, b, a]
            },
        )
        .unwrap();
        assert_eq!(back.layer_data.channel_data.pixels, pixels);

        let png_path = dir.join("a.png");
        write_png(&png_path, w, h, &pixels, "test").unwrap();
        let decoder = png::Decoder::new(std::io::BufReader::new(
            std::fs::File::open(&png_path).unwrap(),
        ));
        let mut reader = decoder.read_info().unwrap();
        let text = reader
            .info()
            .utf8_text
            .iter()
            .map(|t| t.get_text().unwrap())
            .collect::<Vec<_>>()
            .join("|");
        assert!(text.contains("Reinhard"), "{text}");
        let mut buf = vec![0; reader.output_buffer_size().unwrap()];
        reader.next_frame(&mut buf).unwrap();
        // 1.0 → Reinhard 0.5 → sRGB 0.7354 → 188; 1e3 → 0.999 → 255.
        assert_eq!(&buf[0..3], &[0, 188, 255]);
        assert!(matches!(
            write_png(&png_path, 4, 4, &pixels, "x"),
            Err(ImageWriteError::WrongSize { .. })
        ));
        std::fs::remove_dir_all(&dir).ok();
    }
}
