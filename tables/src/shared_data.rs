//! Where tests and benchmarks find the real data files of others (`../shared/data` beside the
//! checkout; see its SOURCES.md). They are never copied into the repository. A test without
//! them skips, or fails under `STRANDLIGHT_REQUIRE_TOOLS=1` ([`crate::outside_tools`]).

use std::path::{Path, PathBuf};

use crate::outside_tools::skip_or_fail;

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

/// The shared data folder for a test that needs `what` from it, or `None` after
/// [`skip_or_fail`] (the caller then skips; under `STRANDLIGHT_REQUIRE_TOOLS=1` it failed).
pub fn shared_dir_for(what: &str) -> Option<PathBuf> {
    let dir = shared_data_dir();
    if dir.is_none() {
        skip_or_fail(&format!(
            "no shared data folder (../shared/data beside the checkout, or $STRANDLIGHT_SHARED_DATA) for {what}"
        ));
    }
    dir
}

/// A file below the shared data folder, or `None` after [`skip_or_fail`].
pub fn shared_file(relative: &str) -> Option<PathBuf> {
    let dir = shared_dir_for(relative)?;
    let path = dir.join(relative);
    if !path.is_file() {
        skip_or_fail(&format!("{relative} is not in {}", dir.display()));
        return None;
    }
    Some(path)
}
