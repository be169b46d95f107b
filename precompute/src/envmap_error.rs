//! Why an environment map could not be used, naming the file and what to do.

use crate::envmap::BadPixelCounts;
use std::path::PathBuf;

#[derive(Debug, thiserror::Error)]
pub enum EnvMapError {
    #[error("{path}: cannot read: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },

    #[error(transparent)]
    Write(#[from] strandlight_tables::image_out::ImageWriteError),

    #[error("{path}: unknown environment map format (expected a Radiance .hdr or an OpenEXR .exr)")]
    UnknownFormat { path: PathBuf },

    #[error("{path}: not a Radiance file: {problem}")]
    RadianceHeader { path: PathBuf, problem: String },

    #[error("{path}: truncated: the pixel data ends in scanline {scanline} of {scanlines}")]
    Truncated {
        path: PathBuf,
        scanline: usize,
        scanlines: usize,
    },

    #[error("{path}: corrupt run-length data in scanline {scanline}: {problem}")]
    CorruptScanline {
        path: PathBuf,
        scanline: usize,
        problem: String,
    },

    /// A header whose pixel count the file's bytes cannot hold even at the format's densest
    /// encoding: refused before anything is allocated for the pixels.
    #[error(
        "{path}: the header claims {width} × {height} pixels, more than its {bytes} bytes can \
         hold even at the densest {encoding} ({max_pixels} pixels at most); the file is corrupt \
         or truncated"
    )]
    ImpossibleSize {
        path: PathBuf,
        width: u64,
        height: u64,
        bytes: u64,
        encoding: &'static str,
        max_pixels: u64,
    },

    #[error("{path}: cannot decode OpenEXR: {message}")]
    Exr { path: PathBuf, message: String },

    #[error(
        "{path}: is {width} × {height}; an equirectangular environment map must be 2:1 \
         (width = 2 × height)"
    )]
    NotTwoToOne {
        path: PathBuf,
        width: usize,
        height: usize,
    },

    #[error(
        "{path}: has bad pixels ({counts}); fix the file or pass --sanitize to replace them \
         (negative and NaN → 0, +Inf → the largest finite value)"
    )]
    BadPixels {
        path: PathBuf,
        counts: BadPixelCounts,
    },
}
