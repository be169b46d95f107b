//! The table asset file: one [`Table`] with everything needed to know what it holds and
//! whether it may be used — the format the offline baker writes and the runtime reads.
//!
//! # File layout (format version 2)
//!
//! | offset | size | content |
//! | --- | --- | --- |
//! | 0 | 8 | magic `STRNDLUT` |
//! | 8 | 4 | format version, u32 little-endian (= [`FORMAT_VERSION`]) |
//! | 12 | 4 | metadata length `m` in bytes, u32 little-endian (≤ [`MAX_METADATA_BYTES`]) |
//! | 16 | m | metadata: UTF-8 JSON, an [`AssetMetadata`] |
//! | 16 + m | 32 | SHA-256 of the m metadata bytes |
//! | 48 + m | 0–15 | zero padding so that the payload starts at a multiple of 16 |
//! | p | n | payload: the table's values in [`Table`]'s layout (row-major, last axis fastest, channels innermost), f32 or f16 little-endian |
//!
//! The file ends exactly after the payload. `payload.sha256` in the metadata is the SHA-256 of
//! the payload bytes; the metadata has its own digest, so a flipped digit in a fiber parameter
//! is caught too (version 1 had none).
//! Files are written atomically (see [`crate::atomic_write`]) and every way a file can be
//! wrong on load is its own [`AssetError`] variant naming the file.

use crate::atomic_write::write_atomically;
use crate::checksum::sha256_hex;
use crate::table::{Axis, Table, TableError, checked_value_count};
use half::f16;
use serde::{Deserialize, Serialize};
use serde_json::Value;
use sha2::{Digest, Sha256};
use std::fs::File;
use std::io::{self, Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};
use thiserror::Error;

pub const MAGIC: [u8; 8] = *b"STRNDLUT";
pub const FORMAT_VERSION: u32 = 2;
/// Metadata is a few kB; a larger length field means a corrupt file, refused before allocating.
pub const MAX_METADATA_BYTES: u32 = 1 << 24;
const HEADER_BYTES: u64 = 16;
/// The SHA-256 of the metadata that follows it.
const METADATA_DIGEST_BYTES: u64 = 32;
const PAYLOAD_ALIGNMENT: u64 = 16;
/// The only payload layout of format version 1, spelled out in every file for human readers.
pub const PAYLOAD_LAYOUT: &str = "row-major, last axis fastest, channels innermost, little-endian";

#[derive(Debug, Error)]
pub enum AssetError {
    #[error("{}: {source}", .path.display())]
    Io { path: PathBuf, source: io::Error },
    #[error("{}: not a strandlight table asset (magic bytes \"{found}\", expected \"{}\")", .path.display(), String::from_utf8_lossy(&MAGIC))]
    BadMagic { path: PathBuf, found: String },
    #[error("{}: table format version {found} is not supported (this build reads version {supported}); re-bake the table", .path.display())]
    UnsupportedVersion {
        path: PathBuf,
        found: u32,
        supported: u32,
    },
    #[error("{}: file is truncated in the {section}: needs {needed} bytes, has {available}", .path.display())]
    Truncated {
        path: PathBuf,
        section: &'static str,
        needed: u64,
        available: u64,
    },
    #[error("{}: metadata length {bytes} exceeds {max} bytes (corrupt header)", .path.display())]
    MetadataTooLarge { path: PathBuf, bytes: u64, max: u32 },
    #[error("{}: metadata is not valid: {source}", .path.display())]
    BadMetadata {
        path: PathBuf,
        source: serde_json::Error,
    },
    #[error("{}: table shape in the metadata is invalid: {source}", .path.display())]
    InvalidShape { path: PathBuf, source: TableError },
    #[error("{}: inconsistent file: {problem}", .path.display())]
    Inconsistent { path: PathBuf, problem: String },
    #[error("{}: metadata checksum mismatch: the metadata block is corrupt", .path.display())]
    MetadataChecksumMismatch { path: PathBuf },
    #[error("{}: payload checksum mismatch (stored SHA-256 {stored}, computed {computed}): the file is corrupt", .path.display())]
    ChecksumMismatch {
        path: PathBuf,
        stored: String,
        computed: String,
    },
    #[error("{}: value {value} at node {node:?} channel {channel} is not finite; refusing to store it", .path.display())]
    NonFiniteValue {
        path: PathBuf,
        node: Vec<usize>,
        channel: usize,
        value: f32,
    },
    #[error("{}: value {value} at node {node:?} channel {channel} overflows f16 (|v| ≥ 65520); store as f32 or rescale", .path.display())]
    F16Overflow {
        path: PathBuf,
        node: Vec<usize>,
        channel: usize,
        value: f32,
    },
    #[error("{}: table was baked for other fiber parameters: `{parameter}` is {baked} in the table but {expected} was asked for; re-bake it", .path.display())]
    ParameterMismatch {
        path: PathBuf,
        parameter: String,
        baked: String,
        expected: String,
    },
}

/// How payload values are stored. Tables are always f32 in memory.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Storage {
    F32,
    /// Half precision: relative error ≤ 2⁻¹¹ for |v| ≥ 2⁻¹⁴, absolute ≤ 2⁻²⁵ below;
    /// values that would round to ±∞ (|v| ≥ 65520) are refused.
    F16,
}

impl Storage {
    pub fn bytes_per_value(self) -> usize {
        match self {
            Storage::F32 => 4,
            Storage::F16 => 2,
        }
    }
}

/// The program that baked the table.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Generator {
    pub name: String,
    pub version: String,
}

#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct CreationInfo {
    /// Seconds since the Unix epoch (UTC).
    pub unix_time_s: u64,
    #[serde(default)]
    pub command_line: Option<String>,
    #[serde(default)]
    pub notes: Option<String>,
}

impl CreationInfo {
    /// Now, with this process's command line.
    pub fn now() -> Self {
        let unix_time_s = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map(|d| d.as_secs())
            .unwrap_or(0);
        let command_line = Some(std::env::args().collect::<Vec<_>>().join(" "));
        Self {
            unix_time_s,
            command_line,
            notes: None,
        }
    }
}

/// What the caller says about a table: what it is and what produced it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AssetDescription {
    /// Short identifier, e.g. `I_M`.
    pub name: String,
    /// Free text: what was tabulated, over which axes, in which units.
    pub quantity: String,
    /// [`crate::ScatteringFunction::name`] of the model tabulated (empty if none).
    pub scattering_function: String,
    /// The model's full parameter set, as the model serializes it.
    pub fiber_parameters: Value,
    pub generator: Generator,
    pub created: CreationInfo,
    /// Content hash of everything that determined the values (parameters, resolution,
    /// integration settings, generator version): equal keys mean a re-bake can be skipped.
    #[serde(default)]
    pub inputs_key: Option<String>,
}

/// What the writer derives from the table: shape, storage and checksum of the payload.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PayloadInfo {
    pub axes: Vec<Axis>,
    pub channels: usize,
    pub storage: Storage,
    pub layout: String,
    pub payload_bytes: u64,
    /// Lower-case hex SHA-256 of the payload bytes.
    pub sha256: String,
}

/// The JSON metadata block of an asset.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AssetMetadata {
    pub description: AssetDescription,
    pub payload: PayloadInfo,
}

/// A loaded asset: where it came from, its metadata and its table (f32, whatever the storage).
#[derive(Debug, Clone, PartialEq)]
pub struct TableAsset {
    pub path: PathBuf,
    pub metadata: AssetMetadata,
    /// Shared, so that a renderer can tell the same table from frame to frame by its address
    /// and keep it on the GPU (`EnvRenderer`'s table bindings).
    pub table: std::sync::Arc<Table>,
}

/// Writes `table` to `path` atomically, returning the metadata written.
pub fn write_asset(
    path: &Path,
    table: &Table,
    description: &AssetDescription,
    storage: Storage,
) -> Result<AssetMetadata, AssetError> {
    let (metadata, head, payload) = encode_asset(path, table, description, storage)?;
    let io_error = |source| AssetError::Io {
        path: path.to_path_buf(),
        source,
    };
    write_atomically(path, |w| {
        w.write_all(&head)?;
        w.write_all(&payload)
    })
    .map_err(io_error)?;
    Ok(metadata)
}

/// Writes the bytes [`write_asset`] would put in a file to `out` instead (no temporary file, no
/// fsync), returning the metadata written; `path` only names the asset in errors. For callers
/// that keep the asset in memory or in a file they manage, such as the fuzz harness's round trip.
pub fn write_asset_to(
    out: &mut impl Write,
    path: &Path,
    table: &Table,
    description: &AssetDescription,
    storage: Storage,
) -> Result<AssetMetadata, AssetError> {
    let (metadata, head, payload) = encode_asset(path, table, description, storage)?;
    out.write_all(&head)
        .and_then(|()| out.write_all(&payload))
        .map_err(|source| AssetError::Io {
            path: path.to_path_buf(),
            source,
        })?;
    Ok(metadata)
}

/// The header + metadata + padding bytes and the payload bytes of an asset.
fn encode_asset(
    path: &Path,
    table: &Table,
    description: &AssetDescription,
    storage: Storage,
) -> Result<(AssetMetadata, Vec<u8>, Vec<u8>), AssetError> {
    let payload = encode_payload(path, table, storage)?;
    let metadata = AssetMetadata {
        description: description.clone(),
        payload: PayloadInfo {
            axes: table.axes().to_vec(),
            channels: table.channels(),
            storage,
            layout: PAYLOAD_LAYOUT.to_string(),
            payload_bytes: payload.len() as u64,
            sha256: sha256_hex(&payload),
        },
    };
    let json = serde_json::to_vec_pretty(&metadata).map_err(|source| AssetError::BadMetadata {
        path: path.to_path_buf(),
        source,
    })?;
    if json.len() > MAX_METADATA_BYTES as usize {
        return Err(AssetError::MetadataTooLarge {
            path: path.to_path_buf(),
            bytes: json.len() as u64,
            max: MAX_METADATA_BYTES,
        });
    }
    let mut head = Vec::with_capacity(json.len() + 32);
    head.extend_from_slice(&MAGIC);
    head.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
    head.extend_from_slice(&(json.len() as u32).to_le_bytes());
    head.extend_from_slice(&json);
    head.extend_from_slice(&Sha256::digest(&json));
    head.resize(payload_offset(json.len() as u64) as usize, 0);
    Ok((metadata, head, payload))
}

fn payload_offset(metadata_len: u64) -> u64 {
    (HEADER_BYTES + metadata_len + METADATA_DIGEST_BYTES).div_ceil(PAYLOAD_ALIGNMENT)
        * PAYLOAD_ALIGNMENT
}

fn encode_payload(path: &Path, table: &Table, storage: Storage) -> Result<Vec<u8>, AssetError> {
    let values = table.values();
    let locate = |offset: usize| (table.node_index_of(offset), offset % table.channels());
    let mut bytes = Vec::with_capacity(values.len() * storage.bytes_per_value());
    for (offset, &value) in values.iter().enumerate() {
        if !value.is_finite() {
            let (node, channel) = locate(offset);
            return Err(AssetError::NonFiniteValue {
                path: path.to_path_buf(),
                node,
                channel,
                value,
            });
        }
        match storage {
            Storage::F32 => bytes.extend_from_slice(&value.to_le_bytes()),
            Storage::F16 => {
                let half = f16::from_f32(value);
                if half.is_infinite() {
                    let (node, channel) = locate(offset);
                    return Err(AssetError::F16Overflow {
                        path: path.to_path_buf(),
                        node,
                        channel,
                        value,
                    });
                }
                bytes.extend_from_slice(&half.to_le_bytes());
            }
        }
    }
    Ok(bytes)
}

/// Reads and checks an asset: header, metadata, shape, payload size and checksum.
pub fn read_asset(path: &Path) -> Result<TableAsset, AssetError> {
    read_opened(OpenedAsset::open(path)?)
}

/// [`read_asset`] of an asset already in memory (fetched by a web page); `path` names it in
/// errors.
pub fn read_asset_bytes(path: &Path, bytes: &[u8]) -> Result<TableAsset, AssetError> {
    let source = std::io::Cursor::new(bytes);
    read_opened(OpenedAsset::from_source(path, source, bytes.len() as u64)?)
}

fn read_opened<R: Read + Seek>(mut opened: OpenedAsset<R>) -> Result<TableAsset, AssetError> {
    let payload = opened.read_payload()?;
    let OpenedAsset { path, metadata, .. } = opened;
    let computed = sha256_hex(&payload);
    if computed != metadata.payload.sha256 {
        return Err(AssetError::ChecksumMismatch {
            path,
            stored: metadata.payload.sha256,
            computed,
        });
    }
    let values = decode_payload(&payload, metadata.payload.storage);
    let table = Table::new(
        metadata.payload.axes.clone(),
        metadata.payload.channels,
        values,
    )
    .map_err(|source| AssetError::InvalidShape {
        path: path.clone(),
        source,
    })?;
    Ok(TableAsset {
        path,
        metadata,
        table: table.into(),
    })
}

/// Reads only the header and metadata (checked for consistency with the file size), e.g. to
/// list assets or check their parameters without loading the payload.
pub fn read_asset_metadata(path: &Path) -> Result<AssetMetadata, AssetError> {
    Ok(OpenedAsset::open(path)?.metadata)
}

/// An asset whose header and metadata have been read and checked against the file size.
struct OpenedAsset<R> {
    path: PathBuf,
    file: R,
    metadata: AssetMetadata,
    payload_offset: u64,
    payload_bytes: u64,
}

impl OpenedAsset<File> {
    fn open(path: &Path) -> Result<Self, AssetError> {
        let io_error = |source| AssetError::Io {
            path: path.to_path_buf(),
            source,
        };
        let file = File::open(path).map_err(io_error)?;
        let file_len = file.metadata().map_err(io_error)?.len();
        Self::from_source(path, file, file_len)
    }
}

impl<R: Read + Seek> OpenedAsset<R> {
    /// Reads and checks the header and metadata of `file_len` bytes from `file`.
    fn from_source(path: &Path, mut file: R, file_len: u64) -> Result<Self, AssetError> {
        let path_buf = path.to_path_buf();
        let io_error = |source| AssetError::Io {
            path: path_buf.clone(),
            source,
        };
        let truncated = |section, needed| AssetError::Truncated {
            path: path_buf.clone(),
            section,
            needed,
            available: file_len,
        };

        if file_len < MAGIC.len() as u64 {
            return Err(truncated("magic bytes", MAGIC.len() as u64));
        }
        let mut header = [0u8; HEADER_BYTES as usize];
        let header_len = file_len.min(HEADER_BYTES) as usize;
        file.read_exact(&mut header[..header_len])
            .map_err(io_error)?;
        if header[..8] != MAGIC {
            let found = header[..8].escape_ascii().to_string();
            return Err(AssetError::BadMagic {
                path: path_buf,
                found,
            });
        }
        if file_len < HEADER_BYTES {
            return Err(truncated("header", HEADER_BYTES));
        }
        let version = u32::from_le_bytes(header[8..12].try_into().unwrap());
        if version != FORMAT_VERSION {
            return Err(AssetError::UnsupportedVersion {
                path: path_buf,
                found: version,
                supported: FORMAT_VERSION,
            });
        }
        let metadata_len = u32::from_le_bytes(header[12..16].try_into().unwrap());
        if metadata_len > MAX_METADATA_BYTES {
            return Err(AssetError::MetadataTooLarge {
                path: path_buf,
                bytes: metadata_len as u64,
                max: MAX_METADATA_BYTES,
            });
        }
        if file_len < HEADER_BYTES + metadata_len as u64 {
            return Err(truncated("metadata", HEADER_BYTES + metadata_len as u64));
        }
        let mut json = vec![0u8; metadata_len as usize];
        file.read_exact(&mut json).map_err(io_error)?;
        let digest_end = HEADER_BYTES + metadata_len as u64 + METADATA_DIGEST_BYTES;
        if file_len < digest_end {
            return Err(truncated("metadata checksum", digest_end));
        }
        let mut digest = [0u8; METADATA_DIGEST_BYTES as usize];
        file.read_exact(&mut digest).map_err(io_error)?;
        if Sha256::digest(&json).as_slice() != digest {
            return Err(AssetError::MetadataChecksumMismatch { path: path_buf });
        }
        // The padding is covered by no checksum, so it must be what the writer wrote: zeros. A
        // flipped bit there is harmless to the values but says the file is not the one written.
        let padding_len = payload_offset(metadata_len as u64)
            .saturating_sub(digest_end)
            .min(16);
        if file_len < digest_end + padding_len {
            return Err(truncated("padding", digest_end + padding_len));
        }
        let mut padding = vec![0u8; padding_len as usize];
        file.read_exact(&mut padding).map_err(io_error)?;
        if padding.iter().any(|&b| b != 0) {
            return Err(AssetError::Inconsistent {
                path: path_buf,
                problem: "the padding before the payload is not zero: the file is corrupt".into(),
            });
        }
        let metadata: AssetMetadata =
            serde_json::from_slice(&json).map_err(|source| AssetError::BadMetadata {
                path: path_buf.clone(),
                source,
            })?;

        let payload_bytes = check_payload_shape(&path_buf, &metadata.payload)?;
        let payload_offset = payload_offset(metadata_len as u64);
        let needed = payload_offset + payload_bytes;
        if file_len < needed {
            return Err(truncated("payload", needed));
        }
        if file_len > needed {
            return Err(AssetError::Inconsistent {
                path: path_buf,
                problem: format!(
                    "{} bytes after the end of the payload (file has {file_len}, axes × channels × storage give {needed})",
                    file_len - needed
                ),
            });
        }
        Ok(Self {
            path: path_buf,
            file,
            metadata,
            payload_offset,
            payload_bytes,
        })
    }

    fn read_payload(&mut self) -> Result<Vec<u8>, AssetError> {
        let io_error = |source| AssetError::Io {
            path: self.path.clone(),
            source,
        };
        self.file
            .seek(SeekFrom::Start(self.payload_offset))
            .map_err(io_error)?;
        // Bounded: the shape check capped the size and the file was seen to hold it.
        let mut payload = vec![0u8; self.payload_bytes as usize];
        self.file.read_exact(&mut payload).map_err(io_error)?;
        Ok(payload)
    }
}

/// Validates the shape (before any allocation) and returns the payload size it implies.
fn check_payload_shape(path: &Path, info: &PayloadInfo) -> Result<u64, AssetError> {
    let count = checked_value_count(&info.axes, info.channels).map_err(|source| {
        AssetError::InvalidShape {
            path: path.to_path_buf(),
            source,
        }
    })?;
    let inconsistent = |problem| AssetError::Inconsistent {
        path: path.to_path_buf(),
        problem,
    };
    if info.layout != PAYLOAD_LAYOUT {
        return Err(inconsistent(format!(
            "unknown payload layout {:?}",
            info.layout
        )));
    }
    let expected = (count * info.storage.bytes_per_value()) as u64;
    if info.payload_bytes != expected {
        return Err(inconsistent(format!(
            "metadata says the payload has {} bytes but axes {:?} × {} channels × {:?} give {expected}",
            info.payload_bytes,
            info.axes.iter().map(|a| a.count).collect::<Vec<_>>(),
            info.channels,
            info.storage,
        )));
    }
    Ok(expected)
}

fn decode_payload(bytes: &[u8], storage: Storage) -> Vec<f32> {
    match storage {
        Storage::F32 => bytes
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes(b.try_into().unwrap()))
            .collect(),
        Storage::F16 => bytes
            .chunks_exact(2)
            .map(|b| f16::from_le_bytes(b.try_into().unwrap()).to_f32())
            .collect(),
    }
}

/// Refuses an asset baked for other fiber parameters than `expected`, naming the first
/// differing parameter as a JSON pointer (e.g. `/sigma_a/1`). Numbers compare by value
/// (`1` equals `1.0`); object keys are compared in sorted order.
pub fn expect_parameters(asset: &TableAsset, expected: &Value) -> Result<(), AssetError> {
    let baked = &asset.metadata.description.fiber_parameters;
    match first_difference(baked, expected, String::new()) {
        None => Ok(()),
        Some((parameter, baked, expected)) => Err(AssetError::ParameterMismatch {
            path: asset.path.clone(),
            parameter: if parameter.is_empty() {
                "/".into()
            } else {
                parameter
            },
            baked,
            expected,
        }),
    }
}

/// The first place two JSON values differ: (pointer, baked as text, expected as text).
fn first_difference(
    baked: &Value,
    expected: &Value,
    pointer: String,
) -> Option<(String, String, String)> {
    let differ = |p: String| Some((p, baked.to_string(), expected.to_string()));
    match (baked, expected) {
        (Value::Object(a), Value::Object(b)) => {
            let mut keys: Vec<&String> = a.keys().chain(b.keys()).collect();
            keys.sort();
            keys.dedup();
            keys.into_iter().find_map(|k| {
                let child = format!("{pointer}/{}", k.replace('~', "~0").replace('/', "~1"));
                match (a.get(k), b.get(k)) {
                    (Some(x), Some(y)) => first_difference(x, y, child),
                    (x, y) => Some((child, describe(x), describe(y))),
                }
            })
        }
        (Value::Array(a), Value::Array(b)) => {
            let common = a.iter().zip(b).enumerate();
            if let Some(d) = common
                .into_iter()
                .find_map(|(i, (x, y))| first_difference(x, y, format!("{pointer}/{i}")))
            {
                return Some(d);
            }
            (a.len() != b.len()).then(|| {
                (
                    pointer,
                    format!("an array of {}", a.len()),
                    format!("an array of {}", b.len()),
                )
            })
        }
        (Value::Number(a), Value::Number(b)) => {
            let equal = match (a.as_i64(), b.as_i64(), a.as_u64(), b.as_u64()) {
                (Some(x), Some(y), _, _) => x == y,
                (_, _, Some(x), Some(y)) => x == y,
                _ => a.as_f64() == b.as_f64(),
            };
            if equal { None } else { differ(pointer) }
        }
        _ if baked == expected => None,
        _ => differ(pointer),
    }
}

fn describe(v: Option<&Value>) -> String {
    v.map_or_else(|| "absent".to_string(), Value::to_string)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::atomic_write::tests::{ScratchDir, entries, scratch_dir};
    use rand::{RngExt, SeedableRng};
    use rand_pcg::Pcg64;
    use serde_json::json;

    fn description() -> AssetDescription {
        AssetDescription {
            name: "I_M".into(),
            quantity: "test table: random values".into(),
            scattering_function: "marschner".into(),
            fiber_parameters: json!({
                "eta": 1.55,
                "alpha_r_deg": -7.5,
                "sigma_a": [0.432, 0.612, 0.98],
                "eccentricity": {"enabled": false, "a": 0.9},
                "lobes": 3,
            }),
            generator: Generator {
                name: "strandlight-tables tests".into(),
                version: "0.1.0".into(),
            },
            created: CreationInfo {
                unix_time_s: 1_763_770_000,
                command_line: Some("cargo test".into()),
                notes: None,
            },
            inputs_key: Some("test-key".into()),
        }
    }

    fn axes() -> Vec<Axis> {
        vec![
            Axis::uniform("u·ξ", -1.0, 1.0, 5),
            Axis::power("1/λ", 1.0 / 64.0, 1.0 / 3.0, 4, 1.0 / 0.3),
            Axis::uniform("cos(φ_ξ − φ_o)", -1.0, 1.0, 3),
        ]
    }

    fn random_table(rng: &mut Pcg64, channels: usize, magnitude: f32) -> Table {
        let n = 5 * 4 * 3 * channels;
        let values = (0..n)
            .map(|_| {
                let sign = if rng.random::<bool>() { 1.0 } else { -1.0 };
                // Log-uniform magnitudes: subnormal-f16 through near-max values.
                sign * magnitude * 10f32.powf(rng.random_range(-12.0..0.0))
            })
            .collect();
        Table::new(axes(), channels, values).unwrap()
    }

    fn write(dir: &Path, name: &str, table: &Table, storage: Storage) -> PathBuf {
        let path = dir.join(name);
        write_asset(&path, table, &description(), storage).unwrap();
        path
    }

    #[test]
    fn write_asset_to_gives_the_bytes_of_write_asset() {
        let dir = scratch_dir("asset-write-to");
        let mut rng = Pcg64::seed_from_u64(5);
        let table = random_table(&mut rng, 3, 6.0e4);
        for storage in [Storage::F32, Storage::F16] {
            let path = write(&dir, "t.sltab", &table, storage);
            let mut bytes = Vec::new();
            let metadata =
                write_asset_to(&mut bytes, &path, &table, &description(), storage).unwrap();
            assert_eq!(bytes, std::fs::read(&path).unwrap(), "{storage:?}");
            assert_eq!(metadata, read_asset(&path).unwrap().metadata);
        }
        // Its refusals name the path it was given.
        let mut values = table.values().to_vec();
        values[7] = f32::NAN;
        let bad = Table::new(axes(), 3, values).unwrap();
        let e = write_asset_to(
            &mut Vec::new(),
            Path::new("memory.sltab"),
            &bad,
            &description(),
            Storage::F32,
        )
        .unwrap_err();
        assert!(matches!(e, AssetError::NonFiniteValue { .. }), "{e}");
        assert!(e.to_string().contains("memory.sltab"), "{e}");
    }

    /// The in-memory reader (a web page's fetched bytes) is the file reader: same table, same
    /// refusals, naming the path it was given.
    #[test]
    fn bytes_read_as_the_file_does() {
        let dir = scratch_dir("asset-bytes");
        let mut rng = Pcg64::seed_from_u64(9);
        let table = random_table(&mut rng, 3, 6.0e4);
        for storage in [Storage::F32, Storage::F16] {
            let path = write(&dir, "t.sltab", &table, storage);
            let bytes = std::fs::read(&path).unwrap();
            let from_bytes = read_asset_bytes(&path, &bytes).unwrap();
            assert_eq!(from_bytes, read_asset(&path).unwrap(), "{storage:?}");
            let named = Path::new("bundle/tables/t.sltab");
            let e = read_asset_bytes(named, &bytes[..bytes.len() - 3]).unwrap_err();
            assert!(matches!(e, AssetError::Truncated { .. }), "{e}");
            assert!(e.to_string().contains("bundle/tables/t.sltab"), "{e}");
            let mut flipped = bytes.clone();
            *flipped.last_mut().unwrap() ^= 1;
            let e = read_asset_bytes(named, &flipped).unwrap_err();
            assert!(matches!(e, AssetError::ChecksumMismatch { .. }), "{e}");
        }
    }

    #[test]
    fn f32_round_trip_is_bit_exact_with_metadata() {
        let dir = scratch_dir("asset-f32");
        let mut rng = Pcg64::seed_from_u64(1);
        let table = random_table(&mut rng, 3, 1e30);
        let path = write(&dir, "t.sltab", &table, Storage::F32);
        let asset = read_asset(&path).unwrap();
        let bits = |t: &Table| t.values().iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&asset.table), bits(&table));
        assert_eq!(
            asset.table.axes(),
            table.axes(),
            "axes (f64 via JSON) round-trip exactly"
        );
        assert_eq!(asset.metadata.description, description());
        assert_eq!(asset.metadata.payload.storage, Storage::F32);
        assert_eq!(read_asset_metadata(&path).unwrap(), asset.metadata);
        let len = std::fs::metadata(&path).unwrap().len();
        assert_eq!(
            len % 16,
            0,
            "the 16-aligned payload of 180 × 4 bytes ends the file"
        );
        eprintln!("f32 asset: {} values, {len} bytes", table.values().len());
    }

    #[test]
    fn f16_round_trip_stays_within_the_half_precision_bound() {
        let dir = scratch_dir("asset-f16");
        let mut rng = Pcg64::seed_from_u64(2);
        let table = random_table(&mut rng, 3, 6.0e4);
        let path = write(&dir, "t.sltab", &table, Storage::F16);
        let asset = read_asset(&path).unwrap();
        let (mut worst_rel, mut worst_abs_sub) = (0.0f64, 0.0f64);
        for (&a, &b) in table.values().iter().zip(asset.table.values()) {
            let err = (a as f64 - b as f64).abs();
            // IEEE binary16: 10 stored mantissa bits, so round-to-nearest is within 2⁻¹¹
            // relative for normal numbers (≥ 2⁻¹⁴), and within half the subnormal spacing
            // 2⁻²⁴ below.
            if a.abs() >= 2f32.powi(-14) {
                worst_rel = worst_rel.max(err / a.abs() as f64);
            } else {
                worst_abs_sub = worst_abs_sub.max(err);
            }
        }
        eprintln!(
            "f16: max relative error {worst_rel:.3e} (bound {:.3e}), max abs error below 2⁻¹⁴ {worst_abs_sub:.3e} (bound {:.3e})",
            2f64.powi(-11),
            2f64.powi(-25)
        );
        assert!(worst_rel <= 2f64.powi(-11));
        assert!(worst_abs_sub <= 2f64.powi(-25));
        assert_eq!(
            std::fs::metadata(&path).unwrap().len(),
            payload_offset(serde_json::to_vec_pretty(&asset.metadata).unwrap().len() as u64)
                + 60 * 3 * 2
        );
    }

    #[test]
    fn f16_overflow_is_an_error_naming_the_value() {
        let dir = scratch_dir("asset-f16-overflow");
        let mut values = vec![1.0f32; 60];
        values[0] = 65504.0; // f16::MAX: fine
        values[1] = -65519.0; // rounds to −65504: fine
        let table = Table::new(axes(), 1, values.clone()).unwrap();
        let path = write(&dir, "ok.sltab", &table, Storage::F16);
        assert_eq!(
            &read_asset(&path).unwrap().table.values()[..2],
            &[65504.0, -65504.0]
        );

        values[13] = 65520.0; // node (1, 0, 1): would round to +∞
        let table = Table::new(axes(), 1, values).unwrap();
        let bad = dir.join("bad.sltab");
        let err = write_asset(&bad, &table, &description(), Storage::F16).unwrap_err();
        eprintln!("{err}");
        assert!(
            matches!(&err, AssetError::F16Overflow { node, channel: 0, value, .. } if node == &vec![1, 0, 1] && *value == 65520.0)
        );
        assert!(err.to_string().contains("bad.sltab"));
        assert!(!bad.exists());
        // The same table is fine in f32.
        write_asset(&bad, &table, &description(), Storage::F32).unwrap();
    }

    #[test]
    fn non_finite_values_are_refused() {
        let dir = scratch_dir("asset-nan");
        let mut values = vec![0.5f32; 60];
        values[59] = f32::NAN;
        let table = Table::new(axes(), 1, values).unwrap();
        let path = dir.join("nan.sltab");
        let err = write_asset(&path, &table, &description(), Storage::F32).unwrap_err();
        assert!(
            matches!(&err, AssetError::NonFiniteValue { node, .. } if node == &vec![4, 3, 2]),
            "{err}"
        );
        assert!(!path.exists());
    }

    /// Bytes of a valid asset, and the offsets of its metadata and payload.
    fn valid_bytes() -> (Vec<u8>, usize, usize) {
        let mut rng = Pcg64::seed_from_u64(5);
        let table = random_table(&mut rng, 1, 10.0);
        let (_, head, payload) =
            encode_asset(Path::new("x"), &table, &description(), Storage::F32).unwrap();
        let payload_start = head.len();
        ([head, payload].concat(), 16, payload_start)
    }

    /// A file from a header with the given version and arbitrary metadata and payload bytes.
    fn assemble(version: u32, json: &[u8], payload: &[u8]) -> Vec<u8> {
        let mut bytes = MAGIC.to_vec();
        bytes.extend_from_slice(&version.to_le_bytes());
        bytes.extend_from_slice(&(json.len() as u32).to_le_bytes());
        bytes.extend_from_slice(json);
        bytes.extend_from_slice(&Sha256::digest(json));
        bytes.resize(payload_offset(json.len() as u64) as usize, 0);
        bytes.extend_from_slice(payload);
        bytes
    }

    fn load(dir: &Path, name: &str, bytes: &[u8]) -> AssetError {
        let path = dir.join(name);
        std::fs::write(&path, bytes).unwrap();
        let err = read_asset(&path).unwrap_err();
        eprintln!("{name}: {err}");
        assert!(
            err.to_string().contains(name),
            "error names the file: {err}"
        );
        err
    }

    /// A valid asset, checked to read back, in a scratch folder of its own, for the corruption
    /// tests to damage one part at a time. Every load names its file in its error ([`load`]).
    struct Corruptible {
        dir: ScratchDir,
        good: Vec<u8>,
        json_start: usize,
        payload_start: usize,
    }

    impl Corruptible {
        fn new(label: &str) -> Self {
            let dir = scratch_dir(label);
            let (good, json_start, payload_start) = valid_bytes();
            std::fs::write(dir.join("good.sltab"), &good).unwrap();
            read_asset(&dir.join("good.sltab")).unwrap();
            Self {
                dir,
                good,
                json_start,
                payload_start,
            }
        }

        fn json(&self) -> &[u8] {
            let len = u32::from_le_bytes(self.good[12..16].try_into().unwrap()) as usize;
            &self.good[self.json_start..self.json_start + len]
        }

        fn payload(&self) -> &[u8] {
            &self.good[self.payload_start..]
        }

        /// The error of reading the valid bytes after `change`, written as `name`.
        fn load_changed(&self, name: &str, change: impl FnOnce(&mut Vec<u8>)) -> AssetError {
            let mut b = self.good.clone();
            change(&mut b);
            load(&self.dir, name, &b)
        }

        /// The error of reading a file whose metadata is the valid one after `change`, with a
        /// digest that matches it: what only the metadata's own checks can refuse.
        fn load_with_metadata(&self, name: &str, change: impl FnOnce(&mut Value)) -> AssetError {
            let mut m: Value = serde_json::from_slice(self.json()).unwrap();
            change(&mut m);
            let b = assemble(
                FORMAT_VERSION,
                &serde_json::to_vec(&m).unwrap(),
                self.payload(),
            );
            load(&self.dir, name, &b)
        }
    }

    #[test]
    fn a_corrupt_header_has_its_own_error() {
        let c = Corruptible::new("asset-corrupt-header");
        assert!(matches!(
            c.load_changed("magic.sltab", |b| b[0] = b'X'),
            AssetError::BadMagic { .. }
        ));
        assert!(matches!(
            load(&c.dir, "png.sltab", b"\x89PNG\r\n\x1a\n rest"),
            AssetError::BadMagic { .. }
        ));
        assert!(matches!(
            c.load_changed("version.sltab", |b| b[8..12]
                .copy_from_slice(&1u32.to_le_bytes())),
            AssetError::UnsupportedVersion {
                found: 1,
                supported: FORMAT_VERSION,
                ..
            }
        ));
        assert!(matches!(
            c.load_changed("metalen.sltab", |b| b[12..16]
                .copy_from_slice(&u32::MAX.to_le_bytes())),
            AssetError::MetadataTooLarge { .. }
        ));
    }

    #[test]
    fn a_truncated_file_names_the_section_cut() {
        let c = Corruptible::new("asset-corrupt-truncated");
        for (name, cut, section) in [
            ("cut-magic.sltab", 5, "magic bytes"),
            ("cut-header.sltab", 12, "header"),
            ("cut-metadata.sltab", c.json_start + 40, "metadata"),
            ("cut-payload.sltab", c.good.len() - 1, "payload"),
        ] {
            let err = load(&c.dir, name, &c.good[..cut]);
            assert!(
                matches!(err, AssetError::Truncated { section: s, .. } if s == section),
                "{name}"
            );
        }
    }

    #[test]
    fn corrupt_metadata_has_its_own_error() {
        let c = Corruptible::new("asset-corrupt-metadata");
        let json_start = c.json_start;
        // The opening brace of the JSON object.
        assert!(matches!(
            c.load_changed("json.sltab", |b| b[json_start] = b'['),
            AssetError::MetadataChecksumMismatch { .. }
        ));
        // A flipped digit inside a parameter still parses; only the digest catches it.
        let digit = c.json().windows(4).position(|w| w == b"1.55").unwrap() + json_start + 2;
        assert!(matches!(
            c.load_changed("digit.sltab", |b| b[digit] = b'6'),
            AssetError::MetadataChecksumMismatch { .. }
        ));
        // JSON that is not an asset's metadata, with a valid digest.
        assert!(matches!(
            load(
                &c.dir,
                "notjson.sltab",
                &assemble(FORMAT_VERSION, b"[1, 2", c.payload())
            ),
            AssetError::BadMetadata { .. }
        ));
        assert!(matches!(
            c.load_with_metadata("storage.sltab", |m| m["payload"]["storage"] = json!("f64")),
            AssetError::BadMetadata { .. }
        ));
    }

    #[test]
    fn metadata_that_disagrees_with_the_payload_has_its_own_error() {
        let c = Corruptible::new("asset-corrupt-shape");
        // Metadata that disagrees with the payload size it declares.
        assert!(matches!(
            c.load_with_metadata("shape.sltab", |m| {
                m["payload"]["axes"][0]["count"] = json!(6)
            }),
            AssetError::Inconsistent { .. }
        ));
        // An absurd axis count is refused from the metadata alone, before any allocation.
        let err = c.load_with_metadata("absurd.sltab", |m| {
            m["payload"]["axes"][0]["count"] = json!(1u64 << 40);
            m["payload"]["payload_bytes"] = json!(1u64 << 50);
        });
        assert!(
            matches!(
                err,
                AssetError::InvalidShape {
                    source: TableError::TooLarge { .. },
                    ..
                }
            ),
            "{err}"
        );
    }

    #[test]
    fn a_corrupt_payload_has_its_own_error() {
        let c = Corruptible::new("asset-corrupt-payload");
        let payload_start = c.payload_start;
        assert!(matches!(
            c.load_changed("checksum.sltab", |b| b[payload_start + 7] ^= 0x10),
            AssetError::ChecksumMismatch { .. }
        ));
        assert!(matches!(
            c.load_changed("trailing.sltab", |b| b.extend_from_slice(&[0; 4])),
            AssetError::Inconsistent { .. }
        ));
    }

    #[test]
    fn a_missing_file_is_an_io_error_naming_it() {
        let dir = scratch_dir("asset-missing");
        let err = read_asset(&dir.join("missing.sltab")).unwrap_err();
        assert!(
            matches!(&err, AssetError::Io { source, .. } if source.kind() == io::ErrorKind::NotFound)
        );
        assert!(err.to_string().contains("missing.sltab"));
    }

    /// Axes claiming 10¹⁰ entries are refused from the metadata alone; a shape under the
    /// table size limit but bigger than the file is refused against the file's length (the
    /// honest bound). Neither allocates for the payload, and both answer at once.
    #[test]
    fn absurd_shapes_are_refused_before_allocation() {
        let dir = scratch_dir("asset-absurd");
        let (good, json_start, payload_start) = valid_bytes();
        let json = &good[json_start
            ..json_start + u32::from_le_bytes(good[12..16].try_into().unwrap()) as usize];
        let payload = &good[payload_start..];
        let metadata: Value = serde_json::from_slice(json).unwrap();
        let with_counts = |counts: [u64; 3]| {
            let mut m = metadata.clone();
            for (i, c) in counts.iter().enumerate() {
                m["payload"]["axes"][i]["count"] = json!(c);
            }
            let values: u64 = counts.iter().product();
            m["payload"]["payload_bytes"] = json!(4 * values);
            assemble(FORMAT_VERSION, &serde_json::to_vec(&m).unwrap(), payload)
        };

        let start = std::time::Instant::now();
        let err = load(
            &dir,
            "ten-billion.sltab",
            &with_counts([100_000, 10_000, 10]),
        );
        assert!(
            matches!(
                &err,
                AssetError::InvalidShape {
                    source: TableError::TooLarge { shape, .. },
                    ..
                } if shape.iter().product::<usize>() == 10_000_000_000
            ),
            "{err}"
        );
        let err = load(&dir, "under-the-limit.sltab", &with_counts([512, 512, 256]));
        assert!(
            matches!(
                err,
                AssetError::Truncated {
                    section: "payload",
                    needed,
                    ..
                } if needed > 1 << 28
            ),
            "{err}"
        );
        assert!(start.elapsed() < std::time::Duration::from_secs(2));
    }

    #[test]
    fn parameters_must_match_and_the_first_difference_is_named() {
        let dir = scratch_dir("asset-params");
        let table = Table::new(axes(), 1, vec![1.0; 60]).unwrap();
        let asset = read_asset(&write(&dir, "p.sltab", &table, Storage::F32)).unwrap();
        let mut wanted = description().fiber_parameters;
        expect_parameters(&asset, &wanted).unwrap();
        wanted["lobes"] = json!(3.0); // same number written as a float
        expect_parameters(&asset, &wanted).unwrap();

        let mismatch = |wanted: &Value| match expect_parameters(&asset, wanted).unwrap_err() {
            AssetError::ParameterMismatch {
                parameter,
                baked,
                expected,
                path,
            } => {
                assert_eq!(path, dir.join("p.sltab"));
                (parameter, baked, expected)
            }
            e => panic!("{e}"),
        };
        let mut w = wanted.clone();
        w["sigma_a"][1] = json!(0.6120000001);
        assert_eq!(
            mismatch(&w),
            ("/sigma_a/1".into(), "0.612".into(), "0.6120000001".into())
        );
        let mut w = wanted.clone();
        w["eccentricity"]["a"] = json!(0.8);
        w["eta"] = json!(1.6); // later in key order than `eccentricity`
        assert_eq!(mismatch(&w).0, "/eccentricity/a");
        let mut w = wanted.clone();
        w.as_object_mut().unwrap().remove("eta");
        assert_eq!(
            mismatch(&w),
            ("/eta".into(), "1.55".into(), "absent".into())
        );
        let mut w = wanted.clone();
        w["sigma_a"] = json!([0.432, 0.612, 0.98, 1.0]);
        assert_eq!(mismatch(&w).0, "/sigma_a");
        let err = expect_parameters(&asset, &json!({"model": "kajiya-kay"})).unwrap_err();
        eprintln!("{err}");
        assert!(err.to_string().contains("p.sltab"));
    }

    #[test]
    fn a_write_failing_midway_leaves_no_asset() {
        let dir = scratch_dir("asset-killed");
        let mut rng = Pcg64::seed_from_u64(9);
        let table = random_table(&mut rng, 3, 1.0);
        let path = dir.join("t.sltab");
        let (_, head, payload) = encode_asset(&path, &table, &description(), Storage::F32).unwrap();
        // The same writes as `write_asset`, with a failure injected after the header.
        let err = write_atomically(&path, |w| {
            w.write_all(&head)?;
            w.write_all(&payload[..payload.len() / 2])?;
            Err(io::Error::other("injected: disk full"))
        })
        .unwrap_err();
        assert_eq!(err.to_string(), "injected: disk full");
        assert!(entries(&dir).is_empty(), "{:?}", entries(&dir));
        assert!(matches!(read_asset(&path), Err(AssetError::Io { .. })));

        // An impossible destination is an Io error naming it, leaving nothing behind.
        let blocked = dir.join("not-a-folder");
        std::fs::write(&blocked, b"file").unwrap();
        let err = write_asset(
            &blocked.join("t.sltab"),
            &table,
            &description(),
            Storage::F32,
        )
        .unwrap_err();
        assert!(
            matches!(err, AssetError::Io { .. }) && err.to_string().contains("not-a-folder"),
            "{err}"
        );
        assert_eq!(entries(&dir), vec!["not-a-folder"]);
    }
}
