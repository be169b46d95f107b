//! Radiance RGBE (`.hdr`, `.pic`) decoding.
//!
//! Written by hand on purpose: the `image` crate's decoder reads only the standard
//! `-Y H +X W` orientation, while Radiance allows all eight (`±Y H ±X W` and the transposed
//! `±X W ±Y H`), and real files also carry old-style run-length encoding and arbitrary `#`
//! comment lines. The format is small (Ward, "Real Pixels", Graphics Gems II, and Radiance's
//! `color.c`/`header.c`), so the whole reader fits here.
//!
//! Notes: `EXPOSURE=` and `COLORCORR=` lines are ignored (as most renderers do; the map is
//! used as stored); `FORMAT=32-bit_rle_xyze` is rejected rather than silently mis-read.

use crate::envmap::{EnvMap, Rgb32};
use crate::envmap_error::EnvMapError;
use std::path::Path;

/// Decodes a Radiance file already read into memory; `path` is only for messages.
pub fn decode(path: &Path, bytes: &[u8]) -> Result<EnvMap, EnvMapError> {
    let header_err = |problem: String| EnvMapError::RadianceHeader {
        path: path.into(),
        problem,
    };
    let mut pos = 0;
    let next_line = |pos: &mut usize| -> Option<String> {
        if *pos >= bytes.len() {
            return None;
        }
        let end = bytes[*pos..]
            .iter()
            .position(|&b| b == b'\n')
            .map_or(bytes.len(), |i| *pos + i);
        let line = String::from_utf8_lossy(&bytes[*pos..end])
            .trim_end_matches('\r')
            .to_string();
        *pos = (end + 1).min(bytes.len());
        Some(line)
    };

    let magic = next_line(&mut pos).unwrap_or_default();
    if !(magic.starts_with("#?RADIANCE") || magic.starts_with("#?RGBE") || magic.starts_with("#?"))
    {
        return Err(header_err("missing the '#?RADIANCE' signature".into()));
    }
    // Header lines up to the first empty line: VAR=value pairs and '#' comments.
    loop {
        let line = next_line(&mut pos).ok_or_else(|| header_err("the header never ends".into()))?;
        if line.is_empty() {
            break;
        }
        if let Some(format) = line.strip_prefix("FORMAT=")
            && format.trim() != "32-bit_rle_rgbe"
        {
            return Err(header_err(format!("unsupported pixel format {format:?}")));
        }
    }
    let resolution =
        next_line(&mut pos).ok_or_else(|| header_err("missing the resolution line".into()))?;
    let layout = Layout::parse(&resolution)
        .ok_or_else(|| header_err(format!("unreadable resolution line {resolution:?}")))?;

    // Even the densest run-length code (127 pixels in 2 bytes per plane) needs about one byte
    // per 16 pixels: refuse a header that promises more than the file can hold before
    // allocating for it. (Old-style runs can
    // in principle compress further; files that rely on that are refused too.)
    let max_pixels = max_pixels(bytes.len() - pos);
    if (layout.width as u64) * (layout.height as u64) > max_pixels {
        return Err(EnvMapError::ImpossibleSize {
            path: path.into(),
            width: layout.width as u64,
            height: layout.height as u64,
            bytes: bytes.len() as u64,
            encoding: "Radiance run-length code",
            max_pixels,
        });
    }
    let mut reader = ScanlineReader { bytes, pos, path };
    let mut pixels = vec![[0.0f32; 3]; layout.width * layout.height];
    let mut line = vec![[0u8; 4]; layout.scanline_len];
    for s in 0..layout.scanlines {
        reader.read_scanline(&mut line, s, layout.scanlines)?;
        for (t, rgbe) in line.iter().enumerate() {
            let (x, y) = layout.image_position(s, t);
            pixels[y * layout.width + x] = rgbe_to_float(*rgbe);
        }
    }
    Ok(EnvMap::from_pixels(layout.width, layout.height, pixels))
}

/// The most pixels `pixel_bytes` bytes of run-length coded scanlines can describe (with a
/// little slack for tiny images): 16 per byte.
pub const PIXELS_PER_BYTE: u64 = 16;

fn max_pixels(pixel_bytes: usize) -> u64 {
    PIXELS_PER_BYTE * pixel_bytes as u64 + 1024
}

/// Radiance `colr_color`: mantissa + ½ times 2^(e − 136); e = 0 is black.
fn rgbe_to_float([r, g, b, e]: [u8; 4]) -> Rgb32 {
    if e == 0 {
        return [0.0; 3];
    }
    let f = (2.0f64).powi(e as i32 - 136);
    [r, g, b].map(|c| ((c as f64 + 0.5) * f) as f32)
}

/// The resolution line: which image axis the scanlines run along, and in which directions.
struct Layout {
    width: usize,
    height: usize,
    scanlines: usize,
    scanline_len: usize,
    /// Scanlines are rows (`±Y H ±X W`) rather than columns (`±X W ±Y H`).
    rows: bool,
    /// The first scanline / first pixel is at the top / left of the image.
    major_from_start: bool,
    minor_from_start: bool,
}

impl Layout {
    fn parse(line: &str) -> Option<Layout> {
        let t: Vec<&str> = line.split_whitespace().collect();
        if t.len() != 4 {
            return None;
        }
        let (a1, n1): (&str, usize) = (t[0], t[1].parse().ok()?);
        let (a2, n2): (&str, usize) = (t[2], t[3].parse().ok()?);
        if n1 == 0 || n2 == 0 || n1 > 1 << 20 || n2 > 1 << 20 {
            return None;
        }
        // In images, +Y points up, so "-Y" means the first scanline is the top one; "+X" means
        // left to right.
        let layout = |rows, major_from_start, minor_from_start| {
            let (width, height) = if rows { (n2, n1) } else { (n1, n2) };
            Some(Layout {
                width,
                height,
                scanlines: n1,
                scanline_len: n2,
                rows,
                major_from_start,
                minor_from_start,
            })
        };
        match (a1, a2) {
            ("-Y", "+X") => layout(true, true, true),
            ("-Y", "-X") => layout(true, true, false),
            ("+Y", "+X") => layout(true, false, true),
            ("+Y", "-X") => layout(true, false, false),
            ("+X", "-Y") => layout(false, true, true),
            ("+X", "+Y") => layout(false, true, false),
            ("-X", "-Y") => layout(false, false, true),
            ("-X", "+Y") => layout(false, false, false),
            _ => None,
        }
    }

    /// Image (x, y), y = 0 at the top, of pixel t of scanline s.
    fn image_position(&self, s: usize, t: usize) -> (usize, usize) {
        let major = if self.major_from_start {
            s
        } else {
            self.scanlines - 1 - s
        };
        let minor = if self.minor_from_start {
            t
        } else {
            self.scanline_len - 1 - t
        };
        if self.rows {
            (minor, major)
        } else {
            (major, minor)
        }
    }
}

struct ScanlineReader<'a> {
    bytes: &'a [u8],
    pos: usize,
    path: &'a Path,
}

impl ScanlineReader<'_> {
    fn truncated(&self, s: usize, n: usize) -> EnvMapError {
        EnvMapError::Truncated {
            path: self.path.into(),
            scanline: s,
            scanlines: n,
        }
    }

    fn corrupt(&self, s: usize, problem: impl Into<String>) -> EnvMapError {
        EnvMapError::CorruptScanline {
            path: self.path.into(),
            scanline: s,
            problem: problem.into(),
        }
    }

    fn byte(&mut self, s: usize, n: usize) -> Result<u8, EnvMapError> {
        let b = *self
            .bytes
            .get(self.pos)
            .ok_or_else(|| self.truncated(s, n))?;
        self.pos += 1;
        Ok(b)
    }

    fn quad(&mut self, s: usize, n: usize) -> Result<[u8; 4], EnvMapError> {
        let q = self
            .bytes
            .get(self.pos..self.pos + 4)
            .ok_or_else(|| self.truncated(s, n))?;
        self.pos += 4;
        Ok([q[0], q[1], q[2], q[3]])
    }

    fn read_scanline(
        &mut self,
        out: &mut [[u8; 4]],
        s: usize,
        n: usize,
    ) -> Result<(), EnvMapError> {
        let len = out.len();
        if !(8..=0x7fff).contains(&len) {
            return self.read_old_style(out, s, n);
        }
        let first = self.quad(s, n)?;
        if first[0] != 2 || first[1] != 2 || first[2] & 0x80 != 0 {
            // Not new-style RLE: the quad is the first pixel of a flat/old-style scanline.
            self.pos -= 4;
            return self.read_old_style(out, s, n);
        }
        let encoded_len = ((first[2] as usize) << 8) | first[3] as usize;
        if encoded_len != len {
            return Err(self.corrupt(s, format!("scanline length {encoded_len}, expected {len}")));
        }
        // Four planes (R, G, B, E), each run-length coded separately.
        for c in 0..4 {
            let mut i = 0;
            while i < len {
                let count = self.byte(s, n)? as usize;
                if count > 128 {
                    let run = count - 128;
                    if i + run > len {
                        return Err(self.corrupt(s, "a run overflows the scanline"));
                    }
                    let v = self.byte(s, n)?;
                    out[i..i + run].iter_mut().for_each(|p| p[c] = v);
                    i += run;
                } else {
                    if count == 0 || i + count > len {
                        return Err(self.corrupt(s, "a literal block is empty or overflows"));
                    }
                    for p in &mut out[i..i + count] {
                        p[c] = self.byte(s, n)?;
                    }
                    i += count;
                }
            }
        }
        Ok(())
    }

    /// Flat RGBE quads, with old-style runs: (1, 1, 1, k) repeats the previous pixel
    /// k · 256^m times, m counting consecutive run quads.
    fn read_old_style(
        &mut self,
        out: &mut [[u8; 4]],
        s: usize,
        n: usize,
    ) -> Result<(), EnvMapError> {
        let mut i = 0;
        let mut shift = 0u32;
        while i < out.len() {
            let q = self.quad(s, n)?;
            if q[0] == 1 && q[1] == 1 && q[2] == 1 {
                if i == 0 || shift > 16 {
                    return Err(self.corrupt(s, "an old-style run with no pixel to repeat"));
                }
                let run = (q[3] as usize) << shift;
                if i + run > out.len() {
                    return Err(self.corrupt(s, "an old-style run overflows the scanline"));
                }
                let prev = out[i - 1];
                out[i..i + run].iter_mut().for_each(|p| *p = prev);
                i += run;
                shift += 8;
            } else {
                out[i] = q;
                i += 1;
                shift = 0;
            }
        }
        Ok(())
    }
}

/// Encodes a map as a Radiance file (flat or new-style RLE rows, standard or any orientation):
/// used by tests to write synthetic files and by nothing else.
#[doc(hidden)]
pub fn encode_for_tests(map: &EnvMap, resolution: &str, rle: bool) -> Vec<u8> {
    let layout = Layout::parse(resolution).expect("valid resolution line");
    assert_eq!((layout.width, layout.height), (map.width(), map.height()));
    let mut out =
        b"#?RADIANCE\n# written by strandlight tests\nFORMAT=32-bit_rle_rgbe\n\n".to_vec();
    out.extend_from_slice(resolution.as_bytes());
    out.push(b'\n');
    for s in 0..layout.scanlines {
        let line: Vec<[u8; 4]> = (0..layout.scanline_len)
            .map(|t| {
                let (x, y) = layout.image_position(s, t);
                float_to_rgbe(map.pixel(x, y))
            })
            .collect();
        if rle && (8..=0x7fff).contains(&line.len()) {
            out.extend_from_slice(&[2, 2, (line.len() >> 8) as u8, line.len() as u8]);
            for c in 0..4 {
                // Literal blocks of ≤ 128 and runs where ≥ 3 equal bytes follow.
                let mut i = 0;
                while i < line.len() {
                    let mut run = 1;
                    while i + run < line.len() && run < 127 && line[i + run][c] == line[i][c] {
                        run += 1;
                    }
                    if run >= 3 {
                        out.extend_from_slice(&[128 + run as u8, line[i][c]]);
                        i += run;
                    } else {
                        let n = (line.len() - i).min(128).min(2);
                        out.push(n as u8);
                        out.extend(line[i..i + n].iter().map(|p| p[c]));
                        i += n;
                    }
                }
            }
        } else {
            line.iter().for_each(|q| out.extend_from_slice(q));
        }
    }
    out
}

fn float_to_rgbe(c: Rgb32) -> [u8; 4] {
    let m = c[0].max(c[1]).max(c[2]) as f64;
    if m < 1e-32 {
        return [0; 4];
    }
    let e = m.log2().floor() as i32 + 1; // m / 2^e ∈ [0.5, 1)
    let scale = 256.0 / 2f64.powi(e);
    let q = |v: f32| ((v as f64 * scale).floor().clamp(0.0, 255.0)) as u8;
    [q(c[0]), q(c[1]), q(c[2]), (e + 128) as u8]
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::{Duration, Instant};

    fn decode_named(bytes: &[u8]) -> Result<EnvMap, EnvMapError> {
        decode(Path::new("crafted.hdr"), bytes)
    }

    /// A header claiming 10⁶ × 10⁶ pixels (or the largest resolution the reader accepts) in a
    /// file of a few bytes is refused before the pixel buffer is allocated, naming the file.
    #[test]
    fn absurd_resolutions_are_refused_before_allocation() {
        for resolution in [
            "-Y 1000000 +X 1000000",
            "-Y 1048576 +X 1048576",
            "+X 1000000 -Y 500000",
        ] {
            let mut bytes =
                format!("#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n{resolution}\n").into_bytes();
            bytes.extend_from_slice(&[2, 2, 0x40, 0, 0x80 + 127, 0]);
            let start = Instant::now();
            let e = decode_named(&bytes).unwrap_err();
            assert!(start.elapsed() < Duration::from_secs(1), "{e}");
            assert!(matches!(e, EnvMapError::ImpossibleSize { .. }), "{e}");
            assert!(e.to_string().contains("crafted.hdr"), "{e}");
        }
        // Past the reader's 2²⁰ limit per axis the resolution line itself is refused.
        let e = decode_named(b"#?RADIANCE\n\n-Y 1000000000000 +X 2\n").unwrap_err();
        assert!(matches!(e, EnvMapError::RadianceHeader { .. }), "{e}");
    }

    /// The bound is honest: a map of one colour, which new-style RLE packs at 127 pixels per
    /// 2 bytes per channel, is still accepted.
    #[test]
    fn a_maximally_compressed_map_still_loads() {
        let (w, h) = (2032, 1016);
        let map = EnvMap::from_pixels(w, h, vec![[0.5, 0.25, 0.125]; w * h]);
        let bytes = encode_for_tests(&map, &format!("-Y {h} +X {w}"), true);
        assert!(
            ((w * h) as u64) > 15 * bytes.len() as u64,
            "{} bytes",
            bytes.len()
        );
        let decoded = decode_named(&bytes).unwrap();
        let (got, want) = (decoded.pixel(w - 1, h - 1), map.pixel(w - 1, h - 1));
        for c in 0..3 {
            // RGBE keeps 8 bits of mantissa.
            assert!(
                (got[c] - want[c]).abs() <= want[c] / 64.0,
                "{got:?} vs {want:?}"
            );
        }
    }
}
