//! The Ogawa container under an Alembic archive, checked before `ogawa-rs` reads it.
//!
//! Ogawa is a tree of groups (a u64 child count, then one u64 per child: a group's position,
//! or with the high bit set a data chunk's) and data chunks (a u64 size, then the bytes), from a
//! root group whose position is at byte 8. `ogawa-rs` allocates a buffer of a chunk's stated
//! size before reading it and follows groups recursively, so a corrupt size would ask for
//! exabytes (an abort, not a panic) and a group that contains itself would recurse until the
//! stack overflows. Here every group reachable from the root is visited once: each must lie in
//! the file, no group may contain itself, the nesting stays shallow, and every data chunk's
//! size fits the file. The time samplings (root child 4), whose sample count `ogawa-rs` also
//! allocates before reading, are checked to fill their chunk exactly.

use std::collections::HashMap;
use std::path::Path;

use super::HairError;
use super::bytes::FileBytes;

pub(crate) const MAGIC: &[u8; 5] = b"Ogawa";
const DATA_BIT: u64 = 1 << 63;
/// Deeper than any archive needs (each object level costs a few group levels), shallow enough
/// for `ogawa-rs`'s recursion.
const MAX_DEPTH: usize = 256;

/// Checks the container of `data` (see the module notes).
pub(crate) fn check_container(data: &[u8], file: &Path) -> Result<(), HairError> {
    let bytes = FileBytes::new(data, file);
    let head = bytes.slice(0, 16, || "the 16-byte Ogawa header".into())?;
    if &head[..5] != MAGIC {
        return Err(HairError::BadMagic {
            file: file.into(),
            format: "Alembic (Ogawa)",
            found: head[..5].escape_ascii().to_string(),
        });
    }
    let root = bytes.u64_at(8, "root group position")?;
    let children = walk_groups(&bytes, root)?;
    if let Some(&sampling) = children.get(4).filter(|&&c| c & DATA_BIT != 0) {
        check_time_samplings(&bytes, sampling & !DATA_BIT)?;
    }
    Ok(())
}

#[derive(Clone, Copy, PartialEq)]
enum Visit {
    Open,
    Done,
}

/// Visits every group under `root` (depth first, each once) and returns the root's children.
fn walk_groups(bytes: &FileBytes, root: u64) -> Result<Vec<u64>, HairError> {
    let corrupt = |why: String| HairError::Decode {
        file: bytes.file.into(),
        format: "Alembic (Ogawa)",
        why,
    };
    let mut state: HashMap<u64, Visit> = HashMap::new();
    // (group position, its children, next child to visit)
    let mut stack: Vec<(u64, Vec<u64>, usize)> = vec![(root, group_children(bytes, root)?, 0)];
    state.insert(root, Visit::Open);
    let root_children = stack[0].1.clone();
    while let Some((position, children, next)) = stack.last_mut() {
        let Some(&child) = children.get(*next) else {
            state.insert(*position, Visit::Done);
            stack.pop();
            continue;
        };
        *next += 1;
        if child & DATA_BIT != 0 {
            check_data(bytes, child & !DATA_BIT)?;
            continue;
        }
        match state.get(&child) {
            _ if child == 0 => {} // the empty group
            Some(Visit::Done) => {}
            Some(Visit::Open) => {
                return Err(corrupt(format!("group at byte {child} contains itself")));
            }
            None => {
                if stack.len() >= MAX_DEPTH {
                    return Err(corrupt(format!("groups nested deeper than {MAX_DEPTH}")));
                }
                state.insert(child, Visit::Open);
                stack.push((child, group_children(bytes, child)?, 0));
            }
        }
    }
    Ok(root_children)
}

fn group_children(bytes: &FileBytes, position: u64) -> Result<Vec<u64>, HairError> {
    let count = bytes.u64_at(position, "a group's child count")?;
    bytes.check_count_fits("Ogawa group child", count, 8)?;
    let children = bytes.slice(position + 8, 8 * count, || {
        format!("the {count} children of the group at byte {position}")
    })?;
    Ok(children
        .chunks_exact(8)
        .map(|c| u64::from_le_bytes(c.try_into().unwrap()))
        .collect())
}

fn check_data(bytes: &FileBytes, position: u64) -> Result<(), HairError> {
    if position == 0 {
        return Ok(()); // the empty data chunk
    }
    let size = bytes.u64_at(position, "a data chunk's size")?;
    bytes.slice(position + 8, size, || {
        format!("the data chunk at byte {position}")
    })?;
    Ok(())
}

/// Each time sampling is a u32 maximum sample, an f64 time per cycle, a u32 count and that many
/// f64 times; together they fill the chunk.
fn check_time_samplings(bytes: &FileBytes, position: u64) -> Result<(), HairError> {
    if position == 0 {
        return Ok(());
    }
    let size = bytes.u64_at(position, "the time samplings' size")?;
    let (start, end) = (position + 8, position + 8 + size);
    let mut at = start;
    while at < end {
        let count = bytes.u32_at(at + 12, "a time sampling's sample count")? as u64;
        at += 16 + 8 * count;
        if at > end {
            return Err(HairError::Decode {
                file: bytes.file.into(),
                format: "Alembic (Ogawa)",
                why: format!("a time sampling of {count} samples runs past its chunk"),
            });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A header, a root group with the given children, and the data chunks appended.
    fn archive(children: &[u64], chunks: &[&[u8]]) -> Vec<u8> {
        let mut f = b"Ogawa\xff\x01\x00".to_vec();
        f.extend(16u64.to_le_bytes());
        f.extend((children.len() as u64).to_le_bytes());
        for c in children {
            f.extend(c.to_le_bytes());
        }
        for chunk in chunks {
            f.extend((chunk.len() as u64).to_le_bytes());
            f.extend(*chunk);
        }
        f
    }

    fn check(data: &[u8]) -> Result<(), HairError> {
        check_container(data, Path::new("t.abc"))
    }

    #[test]
    fn sizes_cycles_and_samplings_are_checked() {
        let data_at = 16 + 8 + 8;
        assert!(check(&archive(&[DATA_BIT | data_at], &[b"abc"])).is_ok());
        let mut huge = archive(&[DATA_BIT | data_at], &[b"abc"]);
        huge[data_at as usize..data_at as usize + 8].copy_from_slice(&u64::MAX.to_le_bytes());
        assert!(matches!(check(&huge), Err(HairError::Truncated { .. })));
        // The root group listing itself.
        assert!(matches!(
            check(&archive(&[16], &[])),
            Err(HairError::Decode { .. })
        ));
        assert!(matches!(
            check(&archive(&[1 << 40], &[])),
            Err(HairError::Truncated { .. })
        ));
        // Root child 4 holds time samplings: one claiming 2³² − 1 samples in 16 bytes.
        let at = 16 + 8 + 5 * 8;
        let mut sampling = vec![0u8; 16];
        sampling[12..16].copy_from_slice(&u32::MAX.to_le_bytes());
        let f = archive(&[0, 0, 0, 0, DATA_BIT | at], &[&sampling]);
        assert!(
            matches!(check(&f), Err(HairError::Decode { .. })),
            "{:?}",
            check(&f)
        );
        sampling[12..16].copy_from_slice(&0u32.to_le_bytes());
        assert!(check(&archive(&[0, 0, 0, 0, DATA_BIT | at], &[&sampling])).is_ok());
        assert!(matches!(
            check(b"Ogawb\xff\x01\x00\x10\0\0\0\0\0\0\0"),
            Err(HairError::BadMagic { .. })
        ));
    }
}
