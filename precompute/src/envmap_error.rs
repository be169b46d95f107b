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
