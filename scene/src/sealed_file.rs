//! Cache files sealed by a SHA-256 sidecar (`NAME.sha256` beside `NAME`): a cache entry counts
//! only when its bytes still hash to the digest written after them, so a truncated or
//! bit-flipped entry (a disk error, a copy cut short, a process killed between two writes) is
//! rebuilt instead of silently read. Formats with their own checksum (table assets) don't need
//! this; JSON and EXR entries do.

use std::io::Write;
use std::path::{Path, PathBuf};
use strandlight_tables::atomic_write::write_atomically;
use strandlight_tables::checksum::sha256_hex;

fn sidecar(path: &Path) -> PathBuf {
    let mut name = path.file_name().unwrap_or_default().to_os_string();
    name.push(".sha256");
    path.with_file_name(name)
}

/// Writes the digest of the file now at `path` beside it (atomically, after the file itself).
pub fn seal(path: &Path) -> std::io::Result<()> {
    let digest = sha256_hex(&std::fs::read(path)?);
    write_atomically(&sidecar(path), |out| out.write_all(digest.as_bytes()))
}

/// Writes `bytes` to `path` atomically, then seals it.
pub fn write_sealed(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    write_atomically(path, |out| out.write_all(bytes))?;
    seal(path)
}

/// Why a sealed file was not served.
#[derive(Debug, PartialEq, Eq)]
pub enum Unsealed {
    /// The file or its digest is absent (never written, or written by an older version).
    Missing,
    /// The bytes no longer match their digest.
    Damaged,
}

/// The bytes at `path` if they match the digest beside them.
pub fn read_sealed(path: &Path) -> Result<Vec<u8>, Unsealed> {
    let bytes = std::fs::read(path).map_err(|_| Unsealed::Missing)?;
    let digest = std::fs::read_to_string(sidecar(path)).map_err(|_| Unsealed::Missing)?;
    if sha256_hex(&bytes) == digest.trim() {
        Ok(bytes)
    } else {
        Err(Unsealed::Damaged)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_flipped_or_truncated_byte_is_caught() {
        let dir = std::env::temp_dir().join(format!("strandlight-sealed-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("entry.json");
        let original: Vec<u8> = (0..200u32).map(|i| (i * 37 % 251) as u8).collect();
        write_sealed(&path, &original).unwrap();
        assert_eq!(read_sealed(&path).unwrap(), original);
        for at in 0..original.len() {
            for bit in [0x01u8, 0x80] {
                let mut bytes = original.clone();
                bytes[at] ^= bit;
                std::fs::write(&path, &bytes).unwrap();
                assert_eq!(
                    read_sealed(&path),
                    Err(Unsealed::Damaged),
                    "flip {bit:#x} at {at}"
                );
            }
            std::fs::write(&path, &original[..at]).unwrap();
            assert_eq!(
                read_sealed(&path),
                Err(Unsealed::Damaged),
                "truncated to {at}"
            );
        }
        std::fs::write(&path, &original).unwrap();
        assert_eq!(read_sealed(&path).unwrap(), original);
        std::fs::remove_file(sidecar(&path)).unwrap();
        assert_eq!(
            read_sealed(&path),
            Err(Unsealed::Missing),
            "no digest, no hit"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
