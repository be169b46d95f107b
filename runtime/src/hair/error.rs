//! What can go wrong when reading or writing a hair file. Every variant names the file and the
//! problem so that the message alone tells the user what to fix.

use std::path::PathBuf;

/// A hair file that could not be read or written, or an in-memory model that breaks an invariant.
#[derive(Debug, thiserror::Error)]
pub enum HairError {
    #[error("{file}: cannot {action}: {source}")]
    Io {
        file: PathBuf,
        action: &'static str,
        #[source]
        source: std::io::Error,
    },

    /// `found` is the file's first bytes, ASCII-escaped.
    #[error("{file}: not a {format} file (it starts with \"{found}\")")]
    BadMagic {
        file: PathBuf,
        format: &'static str,
        found: String,
    },

    #[error("{file}: truncated: {what} needs {needed} bytes but the file has {actual}")]
    Truncated {
        file: PathBuf,
        what: String,
        needed: u64,
        actual: u64,
    },

    /// A count so large that even at the smallest possible size per element the file could not
    /// hold it (a corrupt count, or a badly truncated file). Refused before anything is allocated.
    #[error(
        "{file}: {what} count {count} needs at least {bytes_each} bytes each, more than the file's {file_len} bytes: the count is corrupt or the file truncated"
    )]
    AbsurdCount {
        file: PathBuf,
        what: &'static str,
        count: u64,
        bytes_each: u64,
        file_len: u64,
    },

    /// The counts are plausible and the data is all there, but the file is longer than they say.
    #[error(
        "{file}: the header's counts describe {expected} bytes but the file has {actual}; the file is corrupt or not this format"
    )]
    SizeMismatch {
        file: PathBuf,
        expected: u64,
        actual: u64,
    },

    /// Two counts in the file that must agree do not.
    #[error("{file}: {what}: declared {declared}, but the data gives {actual}")]
    CountMismatch {
        file: PathBuf,
        what: &'static str,
        declared: u64,
        actual: u64,
    },

    #[error("{file}: invalid {what}: {value} ({why})")]
    BadValue {
        file: PathBuf,
        what: String,
        value: String,
        why: &'static str,
    },

    #[error("{file}: {what} of strand {strand}, point {point} is not finite ({value})")]
    NonFinite {
        file: PathBuf,
        what: &'static str,
        strand: usize,
        point: usize,
        value: String,
    },

    #[error("{file}: unsupported {format} file: {why}")]
    Unsupported {
        file: PathBuf,
        format: &'static str,
        why: String,
    },

    #[error("{file}: no strand with at least two distinct points is left after cleaning")]
    NoStrands { file: PathBuf },

    /// A scene file (USD, Alembic) that another library could not decode: `why` is that
    /// library's own message, or the panic it raised (caught: a bad file never ends the process).
    #[error("{file}: cannot read as {format}: {why}")]
    Decode {
        file: PathBuf,
        format: &'static str,
        why: String,
    },

    /// A scene file that decodes but holds no curves of the kind read as hair.
    #[error("{file}: no {looked_for} in this {format} file, so there is no hair to draw")]
    NoCurves {
        file: PathBuf,
        format: &'static str,
        looked_for: &'static str,
    },

    /// One batch of curves in a scene file (a USD prim, an Alembic object, named by `at`) whose
    /// arrays disagree, e.g. vertex counts that do not sum to the number of points.
    #[error("{file}: {at}: {problem}")]
    BadCurves {
        file: PathBuf,
        at: String,
        problem: String,
    },

    #[error(
        "{file}: unknown hair file extension (expected .hair, .tfx, .data, .ply, .usda, .usdc, .usdz, .usd or .abc)"
    )]
    UnknownExtension { file: PathBuf },

    /// A scene-file format left out of this build (the web page reads no USD or Alembic).
    #[error("{}: this build reads no {format} files (the desktop tool does)", .file.display())]
    FormatNotBuilt { file: PathBuf, format: &'static str },

    /// An in-memory model (from code, not a file) that breaks an invariant of [`super::HairModel`].
    #[error("invalid hair model: {problem}")]
    InvalidModel { problem: String },

    #[error("invalid groom parameter: {0}")]
    Param(#[from] strandlight_tables::ParamError),

    /// A model that the target file format cannot represent.
    #[error("{file}: cannot write as {format}: {why}")]
    NotRepresentable {
        file: PathBuf,
        format: &'static str,
        why: String,
    },
}
