//! Mutations of a seed input, libFuzzer-style but simpler: each mutant is a seed with one to
//! three edits stacked. Header bytes are favoured because counts, sizes and offsets live there.

use strandlight_tables::split_mix::SplitMix64;

/// Bytes where counts, offsets and dimensions usually live: favoured by the word edits.
const HEADER_SPAN: usize = 256;

/// Boundary integers for 4-byte fields (little-endian); `-1` and `-2` reach signed readers.
const WORDS_32: [u32; 10] = [
    0,
    1,
    2,
    0xFFFF,
    0x7FFF_FFFF,
    0x8000_0000,
    0xFFFF_FFFF,
    (-1i32) as u32,
    (-2i32) as u32,
    0x0001_0000,
];

/// Boundary integers for 8-byte fields: 10¹² (an absurd count that still fits), the extremes.
const WORDS_64: [u64; 5] = [1_000_000_000_000, u64::MAX, i64::MAX as u64, 1 << 32, 0];

/// Non-finite and extreme f32 values, for coordinates and pixels.
const FLOATS: [f32; 7] = [
    f32::NAN,
    f32::INFINITY,
    f32::NEG_INFINITY,
    -1.0,
    f32::MAX,
    f32::MIN_POSITIVE / 2.0,
    -0.0,
];

/// Single bytes worth trying: extremes, sign bits, and the separators of the text formats.
const BYTES: [u8; 10] = [0, 1, 0x7F, 0x80, 0xFF, b'\n', b' ', b'-', b'9', b'"'];

/// Numbers for the text formats (PLY and Radiance headers, JSON): huge, negative, not numbers.
const NUMBERS: [&str; 10] = [
    "0",
    "-1",
    "1000000000000",
    "4294967296",
    "2147483648",
    "1e308",
    "NaN",
    "99999999999999999999999",
    "1000000",
    "-0.0",
];

/// Which edit a mutant received, for the record kept with a finding.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Edit {
    BitFlip,
    Byte,
    Word32,
    Word64,
    Float,
    Number,
    Truncate,
    DeleteChunk,
    DuplicateChunk,
    Splice,
}

const EDITS: [Edit; 10] = [
    Edit::BitFlip,
    Edit::Byte,
    Edit::Word32,
    Edit::Word64,
    Edit::Float,
    Edit::Number,
    Edit::Truncate,
    Edit::DeleteChunk,
    Edit::DuplicateChunk,
    Edit::Splice,
];

/// A mutant of `seed`: one to three random edits; `other` is the partner for splicing.
pub fn mutate(seed: &[u8], other: &[u8], rng: &mut SplitMix64) -> (Vec<u8>, Vec<Edit>) {
    let mut data = seed.to_vec();
    let edits: Vec<Edit> = (0..1 + rng.below(3))
        .map(|_| EDITS[rng.below(EDITS.len())])
        .collect();
    for &edit in &edits {
        apply(edit, &mut data, other, rng);
    }
    (data, edits)
}

/// Applies one edit in place (a no-op where the input is too short for it).
pub fn apply(edit: Edit, data: &mut Vec<u8>, other: &[u8], rng: &mut SplitMix64) {
    match edit {
        Edit::BitFlip => {
            if let Some(at) = position(data.len(), rng) {
                data[at] ^= 1 << rng.below(8);
            }
        }
        Edit::Byte => {
            if let Some(at) = position(data.len(), rng) {
                data[at] = BYTES[rng.below(BYTES.len())];
            }
        }
        Edit::Word32 => {
            let value = if rng.below(8) == 0 {
                rng.next_u64() as u32
            } else {
                WORDS_32[rng.below(WORDS_32.len())]
            };
            overwrite_word(data, &value.to_le_bytes(), rng);
        }
        Edit::Word64 => {
            let value = WORDS_64[rng.below(WORDS_64.len())];
            overwrite_word(data, &value.to_le_bytes(), rng);
        }
        Edit::Float => {
            let value = FLOATS[rng.below(FLOATS.len())];
            overwrite_word(data, &value.to_le_bytes(), rng);
        }
        Edit::Number => replace_number(data, rng),
        Edit::Truncate => {
            let cut = rng.below(data.len());
            data.truncate(cut);
        }
        Edit::DeleteChunk => {
            let (start, len) = chunk(data.len(), rng);
            data.drain(start..start + len);
        }
        Edit::DuplicateChunk => {
            let (start, len) = chunk(data.len(), rng);
            let copy = data[start..start + len].to_vec();
            let at = rng.below(data.len() + 1);
            data.splice(at..at, copy);
        }
        Edit::Splice => {
            let keep = rng.below(data.len() + 1);
            let from = rng.below(other.len() + 1);
            data.truncate(keep);
            data.extend_from_slice(&other[from..]);
        }
    }
}

/// A byte position, two times in three within the header span.
fn position(len: usize, rng: &mut SplitMix64) -> Option<usize> {
    if len == 0 {
        return None;
    }
    Some(if rng.below(3) > 0 {
        rng.below(len.min(HEADER_SPAN))
    } else {
        rng.below(len)
    })
}

/// Overwrites a 4-byte-aligned word, usually in the header (where binary formats keep their
/// counts at aligned offsets).
fn overwrite_word(data: &mut [u8], word: &[u8], rng: &mut SplitMix64) {
    if data.len() < word.len() {
        return;
    }
    let span = if rng.below(4) > 0 {
        data.len().min(HEADER_SPAN)
    } else {
        data.len()
    };
    let slots = (span.saturating_sub(word.len())) / 4 + 1;
    let at = 4 * rng.below(slots);
    if at + word.len() <= data.len() {
        data[at..at + word.len()].copy_from_slice(word);
    }
}

/// A random span of up to a quarter of the input (at least one byte when there is any).
fn chunk(len: usize, rng: &mut SplitMix64) -> (usize, usize) {
    if len == 0 {
        return (0, 0);
    }
    let size = 1 + rng.below((len / 4).max(1));
    let start = rng.below(len - size + 1);
    (start, size)
}

/// Replaces one run of ASCII digits (with its sign) by a boundary number: how a count in a PLY
/// or Radiance header, or a field of a JSON file, turns absurd.
fn replace_number(data: &mut Vec<u8>, rng: &mut SplitMix64) {
    let runs = digit_runs(&data[..data.len().min(1 << 16)]);
    if runs.is_empty() {
        return;
    }
    let (start, end) = runs[rng.below(runs.len())];
    let number = NUMBERS[rng.below(NUMBERS.len())].as_bytes();
    data.splice(start..end, number.iter().copied());
}

/// (start, end) of each maximal run of digits, a leading '-' included.
fn digit_runs(data: &[u8]) -> Vec<(usize, usize)> {
    let mut runs = Vec::new();
    let mut i = 0;
    while i < data.len() {
        if data[i].is_ascii_digit() {
            let start = if i > 0 && data[i - 1] == b'-' {
                i - 1
            } else {
                i
            };
            let mut end = i;
            while end < data.len() && data[end].is_ascii_digit() {
                end += 1;
            }
            runs.push((start, end));
            i = end;
        } else {
            i += 1;
        }
    }
    runs
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_edit_changes_or_keeps_bounds() {
        let seed: Vec<u8> = (0..300u32).map(|i| (i % 251) as u8).collect();
        let mut rng = SplitMix64::new(1);
        for edit in EDITS {
            for _ in 0..200 {
                let mut d = seed.clone();
                apply(edit, &mut d, b"other", &mut rng);
                assert!(d.len() <= seed.len() * 2 + 32, "{edit:?}");
            }
        }
        // Empty inputs are edited without panicking.
        for edit in EDITS {
            apply(edit, &mut Vec::new(), b"", &mut rng);
        }
    }

    #[test]
    fn numbers_are_found_with_their_sign() {
        assert_eq!(digit_runs(b"a -12 b 3"), vec![(2, 5), (8, 9)]);
        let mut d = b"element vertex 42\n".to_vec();
        replace_number(&mut d, &mut SplitMix64::new(3));
        assert!(!d.windows(2).any(|w| w == b"42"), "{}", d.escape_ascii());
    }
}
