//! Writing a file so that readers only ever see the old file or the complete new one: the
//! bytes go to a temporary file in the destination's folder, which is flushed, fsynced and then
//! renamed over the destination (rename is atomic within one filesystem on POSIX and NTFS).
//! On any error or panic the temporary file is removed and the destination is untouched; a
//! process killed mid-write leaves at most a hidden `.<name>.tmp-…` file beside it, never a
//! partial destination.

use std::fs::{self, File, OpenOptions};
use std::io::{self, BufWriter};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

static TEMP_COUNTER: AtomicU64 = AtomicU64::new(0);

/// Writes `path` atomically with `write`, which receives a buffered writer (it is also
/// `Seek`, as the EXR encoder needs). Errors from `write` are returned unchanged.
pub fn write_atomically<E, F>(path: &Path, write: F) -> Result<(), E>
where
    E: From<io::Error>,
    F: FnOnce(&mut BufWriter<File>) -> Result<(), E>,
{
    let (temp_path, file) = create_temp_beside(path)?;
    let guard = RemoveOnDrop(Some(temp_path));
    let mut writer = BufWriter::new(file);
    write(&mut writer)?;
    let file = writer.into_inner().map_err(|e| e.into_error())?;
    file.sync_all()?;
    drop(file);
    fs::rename(guard.path(), path)?;
    guard.disarm();
    sync_parent_dir(path);
    Ok(())
}

/// The folder a relative bare file name lives in is the current one.
fn parent_dir(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

fn create_temp_beside(path: &Path) -> io::Result<(PathBuf, File)> {
    let name = path.file_name().ok_or_else(|| {
        io::Error::new(
            io::ErrorKind::InvalidInput,
            "the destination has no file name",
        )
    })?;
    let dir = parent_dir(path);
    loop {
        let n = TEMP_COUNTER.fetch_add(1, Ordering::Relaxed);
        let temp = dir.join(format!(
            ".{}.tmp-{}-{n}",
            name.to_string_lossy(),
            std::process::id()
        ));
        match OpenOptions::new().write(true).create_new(true).open(&temp) {
            Ok(file) => return Ok((temp, file)),
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists => continue,
            Err(e) => return Err(e),
        }
    }
}

/// Makes the rename itself durable. Best effort: some platforms cannot open a folder.
fn sync_parent_dir(path: &Path) {
    if let Ok(dir) = File::open(parent_dir(path)) {
        let _ = dir.sync_all();
    }
}

struct RemoveOnDrop(Option<PathBuf>);

impl RemoveOnDrop {
    fn path(&self) -> &Path {
        self.0.as_deref().expect("armed guard holds a path")
    }

    fn disarm(mut self) {
        self.0 = None;
    }
}

impl Drop for RemoveOnDrop {
    fn drop(&mut self) {
        if let Some(p) = self.0.take() {
            let _ = fs::remove_file(p);
        }
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use std::io::Write;

    /// A fresh empty folder under the system temp dir, removed when dropped.
    pub(crate) struct ScratchDir(PathBuf);

    impl std::ops::Deref for ScratchDir {
        type Target = Path;
        fn deref(&self) -> &Path {
            &self.0
        }
    }

    impl Drop for ScratchDir {
        fn drop(&mut self) {
            let _ = fs::remove_dir_all(&self.0);
        }
    }

    pub(crate) fn scratch_dir(label: &str) -> ScratchDir {
        let n = TEMP_COUNTER.fetch_add(1, Ordering::Relaxed);
        let dir = std::env::temp_dir().join(format!(
            "strandlight-test-{label}-{}-{n}",
            std::process::id()
        ));
        let _ = fs::remove_dir_all(&dir);
        fs::create_dir_all(&dir).unwrap();
        ScratchDir(dir)
    }

    pub(crate) fn entries(dir: &Path) -> Vec<String> {
        let mut names: Vec<String> = fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into())
            .collect();
        names.sort();
        names
    }

    #[test]
    fn success_replaces_the_destination_and_leaves_no_temp_file() {
        let dir = scratch_dir("atomic-ok");
        let dest = dir.join("out.bin");
        fs::write(&dest, b"old").unwrap();
        write_atomically::<io::Error, _>(&dest, |w| w.write_all(b"new contents")).unwrap();
        assert_eq!(fs::read(&dest).unwrap(), b"new contents");
        assert_eq!(entries(&dir), vec!["out.bin"]);
    }

    #[test]
    fn an_error_midway_leaves_no_destination_and_no_temp_file() {
        let dir = scratch_dir("atomic-fail");
        let dest = dir.join("out.bin");
        let err = write_atomically(&dest, |w| {
            w.write_all(&[7u8; 100_000])?; // more than the buffer: bytes reach the temp file
            assert_eq!(entries(&dir).len(), 1, "the temp file exists while writing");
            Err(io::Error::other("injected failure"))
        })
        .unwrap_err();
        assert_eq!(err.to_string(), "injected failure");
        assert!(!dest.exists());
        assert!(entries(&dir).is_empty(), "{:?}", entries(&dir));
    }

    #[test]
    fn a_failed_replacement_keeps_the_old_file_intact() {
        let dir = scratch_dir("atomic-keep");
        let dest = dir.join("out.bin");
        fs::write(&dest, b"old").unwrap();
        let _ = write_atomically(&dest, |w| {
            w.write_all(b"partial")?;
            Err(io::Error::other("injected"))
        });
        assert_eq!(fs::read(&dest).unwrap(), b"old");
        assert_eq!(entries(&dir), vec!["out.bin"]);
    }

    #[test]
    fn a_panic_midway_removes_the_temp_file() {
        let dir = scratch_dir("atomic-panic");
        let dest = dir.join("out.bin");
        let result = std::panic::catch_unwind(|| {
            let _ = write_atomically::<io::Error, _>(&dest, |w| {
                w.write_all(b"partial")?;
                panic!("injected panic");
            });
        });
        assert!(result.is_err());
        assert!(entries(&dir).is_empty());
    }

    #[test]
    fn a_missing_folder_is_an_io_error() {
        let dir = scratch_dir("atomic-nodir");
        let dest = dir.join("no-such-folder").join("out.bin");
        let err = write_atomically::<io::Error, _>(&dest, |w| w.write_all(b"x")).unwrap_err();
        assert_eq!(err.kind(), io::ErrorKind::NotFound);
        assert!(entries(&dir).is_empty());
    }
}
