//! Baking: turns table jobs into asset files, skipping those whose inputs are unchanged.
//!
//! Each job names its table, the fiber parameters and the settings that determine its values;
//! their SHA-256 is the job's `inputs_key`, stored in the asset. A re-bake whose key matches the
//! file on disk is skipped (a content-addressed cache), and any change rebakes. A file is served
//! from the cache only after its payload checksum is verified too: a truncated or bit-flipped
//! asset is rebuilt (and reported), never kept. Writes are atomic, so two bakes of the same
//! table at once, or a bake killed half way, leave either the old file or a complete new one.

use serde::Serialize;
use serde_json::{Value, json};
use std::path::{Path, PathBuf};
use std::time::Instant;
use strandlight_tables::asset::{
    AssetDescription, AssetError, CreationInfo, Generator, Storage, TableAsset, read_asset,
    read_asset_metadata, write_asset,
};
use strandlight_tables::checksum::sha256_hex;
use strandlight_tables::table::Table;
use thiserror::Error;

/// File extension of baked tables.
pub const TABLE_EXTENSION: &str = "sltab";

#[derive(Debug, Error)]
pub enum BakeError {
    #[error("{table}: {source}")]
    Build {
        table: String,
        source: Box<dyn std::error::Error + Send + Sync>,
    },
    #[error(transparent)]
    Asset(#[from] AssetError),
    #[error(
        "{table}: the computed table holds {nan} NaN and {inf} infinite values (first at node {first:?}); refusing to write it"
    )]
    NonFinite {
        table: String,
        nan: usize,
        inf: usize,
        first: Option<Vec<usize>>,
    },
    #[error("cannot create the output folder {}: {source}", .path.display())]
    OutputDir {
        path: PathBuf,
        source: std::io::Error,
    },
}

/// Whatever a table's builder can fail with.
pub type BuildError = Box<dyn std::error::Error + Send + Sync>;

/// One table to bake.
pub struct TableJob {
    /// File and report name (`marschner`, `kk_diffuse`, …).
    pub name: &'static str,
    pub quantity: String,
    pub scattering_function: String,
    /// The model parameters the table depends on; the runtime checks them.
    pub fiber_parameters: Value,
    /// Resolution and integration settings: part of the cache key, not of the parameter check.
    pub settings: Value,
    pub build: Box<dyn FnOnce() -> Result<Table, BuildError> + Send>,
}

/// What happened to one job.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct BakedTable {
    pub name: String,
    pub path: PathBuf,
    pub bytes: u64,
    pub seconds: f64,
    /// True when an existing file with the same inputs was kept.
    pub cached: bool,
    pub max_value: f32,
    /// Why the file that was there could not be served, when it was damaged (and so rebuilt).
    pub replaced_damaged: Option<String>,
}

/// What is on disk where a job's asset belongs.
enum ExistingAsset {
    /// A complete asset baked from the same inputs, as read: serve it.
    Current(Box<TableAsset>),
    /// No file, or a valid one from other inputs: bake.
    AbsentOrStale,
    /// A file that fails its own checks (truncated, bit-flipped, not an asset): rebake.
    Damaged(AssetError),
}

/// Checks the asset at `path` against `key`: its metadata first (cheap, and enough to see other
/// inputs), then, for a key match, the whole file with its payload checksum.
fn existing_asset(path: &Path, key: &str, storage: Storage) -> ExistingAsset {
    if !path.exists() {
        return ExistingAsset::AbsentOrStale;
    }
    let same_inputs = |m: &strandlight_tables::asset::AssetMetadata| {
        m.description.inputs_key.as_deref() == Some(key) && m.payload.storage == storage
    };
    match read_asset_metadata(path) {
        Err(e) => ExistingAsset::Damaged(e),
        Ok(m) if !same_inputs(&m) => ExistingAsset::AbsentOrStale,
        Ok(_) => match read_asset(path) {
            Ok(asset) => ExistingAsset::Current(Box::new(asset)),
            Err(e) => ExistingAsset::Damaged(e),
        },
    }
}

impl TableJob {
    pub fn inputs_key(&self) -> String {
        let inputs = json!({
            "name": self.name,
            "scattering_function": self.scattering_function,
            "fiber_parameters": self.fiber_parameters,
            "settings": self.settings,
            "generator": env!("CARGO_PKG_VERSION"),
        });
        sha256_hex(inputs.to_string().as_bytes())
    }
}

pub fn table_path(dir: &Path, name: &str) -> PathBuf {
    dir.join(format!("{name}.{TABLE_EXTENSION}"))
}

/// Bakes `job` into `dir` unless a file with the same inputs is already there.
pub fn bake_job(job: TableJob, dir: &Path, storage: Storage) -> Result<BakedTable, BakeError> {
    bake_job_keeping(job, dir, storage).map(|(baked, _)| baked)
}

/// [`bake_job`] and the asset it names, read and checked once: the cached file as its check
/// read it (reading 113 MB of cached tables twice took 0.16 s of every env frame's preparation
/// on 2 cores), a fresh one read back from disk.
pub fn bake_and_load(
    job: TableJob,
    dir: &Path,
    storage: Storage,
) -> Result<(BakedTable, TableAsset), BakeError> {
    let (baked, asset) = bake_job_keeping(job, dir, storage)?;
    let asset = match asset {
        Some(asset) => asset,
        None => read_asset(&baked.path)?,
    };
    Ok((baked, asset))
}

/// The asset `name` in `dir` when it was baked from inputs `key` in `storage` and passes its
/// checks; None otherwise (absent, stale or damaged: a bake would replace it).
pub fn current_asset(dir: &Path, name: &str, key: &str, storage: Storage) -> Option<TableAsset> {
    match existing_asset(&table_path(dir, name), key, storage) {
        ExistingAsset::Current(asset) => Some(*asset),
        _ => None,
    }
}

/// The bake, and the asset when a cached one was read to check it.
fn bake_job_keeping(
    job: TableJob,
    dir: &Path,
    storage: Storage,
) -> Result<(BakedTable, Option<TableAsset>), BakeError> {
    std::fs::create_dir_all(dir).map_err(|source| BakeError::OutputDir {
        path: dir.to_path_buf(),
        source,
    })?;
    let path = table_path(dir, job.name);
    let key = job.inputs_key();
    let start = Instant::now();
    let replaced_damaged = match existing_asset(&path, &key, storage) {
        ExistingAsset::Current(asset) => {
            let bytes = std::fs::metadata(&path).map(|m| m.len()).unwrap_or(0);
            let baked = BakedTable {
                name: job.name.into(),
                path,
                bytes,
                seconds: start.elapsed().as_secs_f64(),
                cached: true,
                max_value: f32::NAN,
                replaced_damaged: None,
            };
            return Ok((baked, Some(*asset)));
        }
        ExistingAsset::AbsentOrStale => None,
        ExistingAsset::Damaged(e) => Some(e.to_string()),
    };
    let name = job.name;
    let description = AssetDescription {
        name: name.into(),
        quantity: job.quantity.clone(),
        scattering_function: job.scattering_function.clone(),
        fiber_parameters: job.fiber_parameters.clone(),
        generator: Generator {
            name: "strandlight bake".into(),
            version: env!("CARGO_PKG_VERSION").into(),
        },
        created: CreationInfo::now(),
        inputs_key: Some(key),
    };
    let table = (job.build)().map_err(|source| BakeError::Build {
        table: name.into(),
        source,
    })?;
    let stats = table.stats();
    if stats.nan_count + stats.infinite_count > 0 {
        return Err(BakeError::NonFinite {
            table: name.into(),
            nan: stats.nan_count,
            inf: stats.infinite_count,
            first: stats.first_non_finite.map(|(node, _channel)| node),
        });
    }
    write_asset(&path, &table, &description, storage)?;
    let bytes = std::fs::metadata(&path).map(|m| m.len()).unwrap_or(0);
    let baked = BakedTable {
        name: name.into(),
        path,
        bytes,
        seconds: start.elapsed().as_secs_f64(),
        cached: false,
        max_value: stats.max,
        replaced_damaged,
    };
    Ok((baked, None))
}

#[cfg(test)]
mod tests {
    use super::*;
    use strandlight_tables::table::Axis;

    fn job(scale: f32) -> TableJob {
        TableJob {
            name: "test_table",
            quantity: "x·scale".into(),
            scattering_function: "none".into(),
            fiber_parameters: json!({ "scale": scale }),
            settings: json!({ "n": 5 }),
            build: Box::new(move || {
                Ok(Table::from_fn(
                    vec![Axis::uniform("x", 0.0, 1.0, 5)],
                    1,
                    move |x, out| out[0] = x[0] as f32 * scale,
                )?)
            }),
        }
    }

    #[test]
    fn unchanged_inputs_are_cached_and_changed_ones_rebake() {
        let dir =
            std::env::temp_dir().join(format!("strandlight-bake-test-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let first = bake_job(job(2.0), &dir, Storage::F32).unwrap();
        assert!(!first.cached);
        let again = bake_job(job(2.0), &dir, Storage::F32).unwrap();
        assert!(again.cached, "same inputs must be served from the file");
        let changed = bake_job(job(3.0), &dir, Storage::F32).unwrap();
        assert!(!changed.cached, "new parameters must rebake");
        let asset = strandlight_tables::asset::read_asset(&first.path).unwrap();
        assert_eq!(asset.table.lookup_scalar(&[1.0]).unwrap(), 3.0);
        // Served and loaded in one read: the table the cache check read is the file's.
        let (served, loaded) = bake_and_load(job(3.0), &dir, Storage::F32).unwrap();
        assert!(served.cached);
        assert_eq!(loaded.table.lookup_scalar(&[1.0]).unwrap(), 3.0);
        let (fresh, loaded) = bake_and_load(job(4.0), &dir, Storage::F32).unwrap();
        assert!(!fresh.cached);
        assert_eq!(loaded.table.lookup_scalar(&[1.0]).unwrap(), 4.0);
        let other_storage = bake_job(job(3.0), &dir, Storage::F16).unwrap();
        assert!(!other_storage.cached);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    fn temp_dir(tag: &str) -> PathBuf {
        let dir =
            std::env::temp_dir().join(format!("strandlight-bake-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        dir
    }

    /// Every byte of an asset matters: the magic, version, lengths, metadata, its digest,
    /// padding and payload. A flip of any byte, or a cut, must be rebuilt, not served.
    #[test]
    fn damaged_assets_are_rebuilt_not_served() {
        let dir = temp_dir("damaged");
        let good = bake_job(job(2.0), &dir, Storage::F32).unwrap();
        let original = std::fs::read(&good.path).unwrap();
        let mut damages: Vec<(String, Vec<u8>)> = Vec::new();
        for at in 0..original.len() {
            let mut bytes = original.clone();
            bytes[at] ^= 0x10;
            damages.push((format!("bit flip at byte {at}"), bytes));
        }
        for cut in [0, 8, 16, original.len() / 2, original.len() - 1] {
            damages.push((
                format!("truncated to {cut} bytes"),
                original[..cut].to_vec(),
            ));
        }
        let mut rebuilt = 0;
        for (what, bytes) in &damages {
            std::fs::write(&good.path, bytes).unwrap();
            let again = bake_job(job(2.0), &dir, Storage::F32).unwrap();
            assert!(
                !again.cached,
                "{what}: a damaged asset was served from the cache"
            );
            assert!(
                again.replaced_damaged.is_some(),
                "{what}: the rebuild was not reported"
            );
            let asset = strandlight_tables::asset::read_asset(&good.path)
                .unwrap_or_else(|e| panic!("{what}: rebuilt asset unreadable: {e}"));
            assert_eq!(asset.table.lookup_scalar(&[1.0]).unwrap(), 2.0, "{what}");
            rebuilt += 1;
        }
        assert_eq!(rebuilt, damages.len());
        println!(
            "{rebuilt} damaged copies of a {}-byte asset, every one rebuilt",
            original.len()
        );
        assert!(
            damages.len() > 50,
            "the asset is only {} bytes: the sweep is too thin",
            original.len()
        );
        // And an intact file is served again.
        assert!(bake_job(job(2.0), &dir, Storage::F32).unwrap().cached);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// Two bakes of one table into one folder at the same moment: both succeed and the file
    /// left behind is complete (atomic renames; the last writer wins with identical content).
    #[test]
    fn concurrent_bakes_of_one_table_leave_a_valid_asset() {
        let dir = temp_dir("concurrent");
        for round in 0..8 {
            let _ = std::fs::remove_file(table_path(&dir, "test_table"));
            let barrier = std::sync::Barrier::new(4);
            std::thread::scope(|scope| {
                for _ in 0..4 {
                    scope.spawn(|| {
                        barrier.wait();
                        bake_job(job(2.0), &dir, Storage::F32)
                            .unwrap_or_else(|e| panic!("round {round}: {e}"))
                    });
                }
            });
            let asset =
                strandlight_tables::asset::read_asset(&table_path(&dir, "test_table")).unwrap();
            assert_eq!(asset.table.lookup_scalar(&[0.5]).unwrap(), 1.0);
        }
        let leftovers: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .filter(|n| n.to_string_lossy().contains(".tmp-"))
            .collect();
        assert!(
            leftovers.is_empty(),
            "temporary files left behind: {leftovers:?}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn non_finite_tables_are_refused_and_leave_no_file() {
        let dir = std::env::temp_dir().join(format!("strandlight-bake-nan-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let bad = TableJob {
            build: Box::new(|| {
                Ok(Table::from_fn(
                    vec![Axis::uniform("x", 0.0, 1.0, 3)],
                    1,
                    |x, out| out[0] = if x[0] > 0.7 { f32::NAN } else { 1.0 },
                )?)
            }),
            ..job(1.0)
        };
        let err = bake_job(bad, &dir, Storage::F32).unwrap_err();
        assert!(matches!(err, BakeError::NonFinite { nan: 1, .. }), "{err}");
        assert!(!table_path(&dir, "test_table").exists());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
