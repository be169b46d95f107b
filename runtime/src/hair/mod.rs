//! Hair input: the [`HairModel`] every pass draws, loaders for the strand formats others publish
//! (Cem Yuksel's `.hair`, AMD TressFX `.tfx`, USC-HairSalon `.data`, hapPLY-style `.ply`) and
//! for the curves of the scene files a groom leaves a DCC in (USD `BasisCurves`, Alembic
//! `ICurves`), a `.hair` writer, and the procedural [`groom`] that is the project's own default
//! hair.
//!
//! Loading reads the whole file, refuses absurd counts before allocating anything sized by them,
//! checks every value, merges zero-length segments and drops strands left with fewer than two
//! points; what it changed is in the [`LoadReport`].

#[cfg(feature = "scene-files")]
pub mod alembic;
mod bytes;
mod clean;
#[cfg(feature = "scene-files")]
mod curves;
mod error;
pub mod groom;
mod groom_style;
#[cfg(feature = "scene-files")]
pub mod guard;
mod model;
#[cfg(feature = "scene-files")]
mod ogawa;
pub mod ply;
pub mod tfx;
pub mod usc;
#[cfg(feature = "scene-files")]
pub mod usd;
pub mod yuksel;

use std::path::Path;

#[cfg(feature = "scene-files")]
pub use alembic::load_alembic;
pub use clean::{HairFormat, LoadReport, LoadedHair, is_degenerate_segment};
pub use error::HairError;
pub use groom::{GroomParams, Scalp, generate_groom};
pub use groom_style::GroomStyle;
pub use model::{Aabb, Attribute, AttributeKind, HairModel, HairSummary};
pub use ply::load_ply;
pub use tfx::load_tfx;
pub use usc::{load_usc, write_usc};
#[cfg(feature = "scene-files")]
pub use usd::load_usd;
pub use yuksel::{HairWriteOptions, load_hair, write_hair};

/// The extensions [`load`] reads, lower case, for file dialogs and help texts.
pub const EXTENSIONS: [&str; 9] = [
    "hair", "tfx", "data", "ply", "usda", "usdc", "usdz", "usd", "abc",
];

/// Loads a hair file, choosing the format by extension (see [`EXTENSIONS`]).
pub fn load(path: &Path) -> Result<LoadedHair, HairError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("hair") => load_hair(path),
        Some("tfx") => load_tfx(path),
        Some("data") => load_usc(path),
        Some("ply") => load_ply(path),
        #[cfg(feature = "scene-files")]
        Some("usda" | "usdc" | "usdz" | "usd") => load_usd(path),
        #[cfg(feature = "scene-files")]
        Some("abc") => load_alembic(path),
        #[cfg(not(feature = "scene-files"))]
        Some(format @ ("usda" | "usdc" | "usdz" | "usd" | "abc")) => {
            Err(HairError::FormatNotBuilt {
                file: path.into(),
                format: if format == "abc" { "Alembic" } else { "USD" },
            })
        }
        _ => Err(HairError::UnknownExtension { file: path.into() }),
    }
}

fn read_file(path: &Path) -> Result<Vec<u8>, HairError> {
    std::fs::read(path).map_err(|source| HairError::Io {
        file: path.into(),
        action: "read",
        source,
    })
}

/// Writes `bytes` through [`strandlight_tables::atomic_write`], so that a failure never leaves a
/// half-written file under the final name.
fn write_atomically(path: &Path, bytes: &[u8]) -> Result<(), HairError> {
    strandlight_tables::atomic_write::write_atomically(path, |out| {
        std::io::Write::write_all(out, bytes)
    })
    .map_err(|source| HairError::Io {
        file: path.into(),
        action: "write",
        source,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unknown_extension_and_missing_file_are_errors() {
        assert!(matches!(
            load(Path::new("x.obj")),
            Err(HairError::UnknownExtension { .. })
        ));
        let e = load(Path::new("/nonexistent/dir/x.hair")).unwrap_err();
        assert!(matches!(e, HairError::Io { .. }));
        assert!(e.to_string().contains("/nonexistent/dir/x.hair"), "{e}");
    }

    #[test]
    fn a_failed_write_leaves_no_file_behind() {
        let dir = std::env::temp_dir().join(format!("strandlight-write-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        // The final name is taken by a directory, so the rename fails after the temp file exists.
        let target = dir.join("taken.hair");
        std::fs::create_dir_all(&target).unwrap();
        let e = write_atomically(&target, b"HAIR").unwrap_err();
        assert!(matches!(e, HairError::Io { .. }), "{e}");
        let left: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(left, vec![std::ffi::OsString::from("taken.hair")]);
        // A missing folder fails at the first write.
        assert!(matches!(
            write_atomically(&dir.join("no/such/x.hair"), b"x"),
            Err(HairError::Io { .. })
        ));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
