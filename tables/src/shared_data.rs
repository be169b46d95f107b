//! Where tests and benchmarks find the real data files of others (`../shared/data` beside the
//! checkout; see its SOURCES.md). They are never copied into the repository.

use std::path::{Path, PathBuf};

/// The shared data folder: `$STRANDLIGHT_SHARED_DATA` if set, else the first `shared/data`
/// found beside the workspace root or one of its ancestors. `None` when absent.
pub fn shared_data_dir() -> Option<PathBuf> {
    if let Some(dir) = std::env::var_os("STRANDLIGHT_SHARED_DATA") {
        let dir = PathBuf::from(dir);
        return dir.is_dir().then_some(dir);
    }
    let here = Path::new(env!("CARGO_MANIFEST_DIR"));
    here.ancestors()
        .map(|a| a.join("shared").join("data"))
        .find(|d| d.is_dir())
}

/// A file below the shared data folder, or `None` after printing why the caller must skip.
pub fn shared_file(relative: &str) -> Option<PathBuf> {
    match shared_data_dir() {
        Some(dir) if dir.join(relative).is_file() => Some(dir.join(relative)),
        Some(dir) => {
            eprintln!("skipped: {} is not in {}", relative, dir.display());
            None
        }
        None => {
            eprintln!("skipped: no ../shared/data folder beside the checkout (needed: {relative})");
            None
        }
    }
}
