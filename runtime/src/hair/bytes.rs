//! Bounds-checked little-endian reads from a whole file held in memory. Every read names what
//! it was reading, so a short file becomes a [`HairError::Truncated`] that says where it ended.

use std::path::Path;

use super::HairError;

/// A file's bytes and its name, for reads that fail with the file named.
#[derive(Clone, Copy)]
pub(crate) struct FileBytes<'a> {
    pub data: &'a [u8],
    pub file: &'a Path,
}

impl<'a> FileBytes<'a> {
    pub fn new(data: &'a [u8], file: &'a Path) -> Self {
        Self { data, file }
    }

    pub fn len(&self) -> u64 {
        self.data.len() as u64
    }

    /// `len` bytes at `offset`, or `Truncated` naming `what`.
    pub fn slice(
        &self,
        offset: u64,
        len: u64,
        what: impl FnOnce() -> String,
    ) -> Result<&'a [u8], HairError> {
        let end = offset.checked_add(len);
        match end {
            Some(end) if end <= self.len() => Ok(&self.data[offset as usize..end as usize]),
            _ => Err(HairError::Truncated {
                file: self.file.to_path_buf(),
                what: what(),
                needed: end.unwrap_or(u64::MAX),
                actual: self.len(),
            }),
        }
    }

    pub fn u32_at(&self, offset: u64, what: &str) -> Result<u32, HairError> {
        let b = self.slice(offset, 4, || what.to_string())?;
        Ok(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }

    #[cfg(feature = "scene-files")]
    pub fn u64_at(&self, offset: u64, what: &str) -> Result<u64, HairError> {
        let b = self.slice(offset, 8, || what.to_string())?;
        Ok(u64::from_le_bytes(b.try_into().expect("8 bytes")))
    }

    pub fn i32_at(&self, offset: u64, what: &str) -> Result<i32, HairError> {
        Ok(self.u32_at(offset, what)? as i32)
    }

    pub fn f32_at(&self, offset: u64, what: &str) -> Result<f32, HairError> {
        Ok(f32::from_bits(self.u32_at(offset, what)?))
    }

    /// Refuses a count whose elements cannot fit in the file even at `bytes_each` apiece: the
    /// check that must come before any allocation sized by that count.
    pub fn check_count_fits(
        &self,
        what: &'static str,
        count: u64,
        bytes_each: u64,
    ) -> Result<(), HairError> {
        let need = count.checked_mul(bytes_each);
        if need.is_none_or(|n| n > self.len()) {
            return Err(HairError::AbsurdCount {
                file: self.file.to_path_buf(),
                what,
                count,
                bytes_each,
                file_len: self.len(),
            });
        }
        Ok(())
    }
}

/// Little-endian f32s from a byte slice whose length is a multiple of 4.
pub(crate) fn f32s(bytes: &[u8]) -> impl Iterator<Item = f32> + '_ {
    bytes
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_past_the_end_are_truncation_errors() {
        let data = [1u8, 0, 0, 0, 2];
        let f = FileBytes::new(&data, Path::new("x.bin"));
        assert_eq!(f.u32_at(0, "a").unwrap(), 1);
        match f.u32_at(2, "the count") {
            Err(HairError::Truncated {
                needed: 6,
                actual: 5,
                what,
                ..
            }) => assert_eq!(what, "the count"),
            other => panic!("expected Truncated, got {other:?}"),
        }
        assert!(matches!(
            f.slice(u64::MAX, 2, || "x".into()),
            Err(HairError::Truncated { .. })
        ));
        assert!(matches!(
            f.check_count_fits("points", u64::MAX, 12),
            Err(HairError::AbsurdCount { .. })
        ));
        assert!(matches!(
            f.check_count_fits("points", 2, 3),
            Err(HairError::AbsurdCount { .. })
        ));
        assert!(f.check_count_fits("points", 1, 5).is_ok());
    }
}
