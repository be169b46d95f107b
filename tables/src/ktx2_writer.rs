//! A KTX 2.0 container for uncompressed floating-point textures (Khronos KTX File Format
//! Specification 2.0): identifier, header, index, one mip level, the Basic Data Format
//! Descriptor of the format, key/value data, then the texels.
//!
//! Written here because the maintained Rust crate (`ktx2`) only reads; the tests read every
//! file back with it and compare the descriptor with the one it generates for the format.
//!
//! # File layout (one level, no supercompression)
//!
//! | offset | size | content |
//! | --- | --- | --- |
//! | 0 | 12 | identifier `«KTX 20»\r\n\x1A\n` |
//! | 12 | 36 | vkFormat, typeSize, pixelWidth, pixelHeight, pixelDepth, layerCount (0), faceCount (1), levelCount (1), supercompressionScheme (0) |
//! | 48 | 32 | dfdByteOffset, dfdByteLength, kvdByteOffset, kvdByteLength (u32); sgdByteOffset, sgdByteLength (u64, 0) |
//! | 80 | 24 | level 0: byteOffset, byteLength, uncompressedByteLength (u64) |
//! | 104 | 4 + 24 + 16·s | DFD: dfdTotalSize, then one Basic block with s samples |
//! | … | | key/value data, each entry padded to 4 bytes, sorted by key |
//! | … | | zero padding to lcm(texel size, 4) |
//! | … | | texels: x fastest, then y, then z; little-endian |

use std::io::{self, Write};

/// `«KTX 20»\r\n\x1A\n`.
pub const IDENTIFIER: [u8; 12] = [
    0xAB, 0x4B, 0x54, 0x58, 0x20, 0x32, 0x30, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A,
];
const HEADER_BYTES: usize = 80;
const LEVEL_INDEX_BYTES: usize = 24;
const DFD_BLOCK_HEADER_BYTES: usize = 24;
const DFD_SAMPLE_BYTES: usize = 16;

/// The uncompressed float formats a table exports to (Vulkan's `VkFormat` numbering).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Ktx2Format {
    R16Sfloat,
    R16G16B16A16Sfloat,
    R32Sfloat,
    R32G32B32A32Sfloat,
}

impl Ktx2Format {
    pub fn vk_format(self) -> u32 {
        match self {
            Ktx2Format::R16Sfloat => 76,
            Ktx2Format::R16G16B16A16Sfloat => 97,
            Ktx2Format::R32Sfloat => 100,
            Ktx2Format::R32G32B32A32Sfloat => 109,
        }
    }

    pub fn vk_name(self) -> &'static str {
        match self {
            Ktx2Format::R16Sfloat => "VK_FORMAT_R16_SFLOAT",
            Ktx2Format::R16G16B16A16Sfloat => "VK_FORMAT_R16G16B16A16_SFLOAT",
            Ktx2Format::R32Sfloat => "VK_FORMAT_R32_SFLOAT",
            Ktx2Format::R32G32B32A32Sfloat => "VK_FORMAT_R32G32B32A32_SFLOAT",
        }
    }

    /// The WebGPU / wgpu name of the same format.
    pub fn webgpu_name(self) -> &'static str {
        match self {
            Ktx2Format::R16Sfloat => "r16float",
            Ktx2Format::R16G16B16A16Sfloat => "rgba16float",
            Ktx2Format::R32Sfloat => "r32float",
            Ktx2Format::R32G32B32A32Sfloat => "rgba32float",
        }
    }

    /// Bytes of one component: the header's typeSize.
    pub fn type_size(self) -> u32 {
        match self {
            Ktx2Format::R16Sfloat | Ktx2Format::R16G16B16A16Sfloat => 2,
            Ktx2Format::R32Sfloat | Ktx2Format::R32G32B32A32Sfloat => 4,
        }
    }

    pub fn components(self) -> u32 {
        match self {
            Ktx2Format::R16Sfloat | Ktx2Format::R32Sfloat => 1,
            Ktx2Format::R16G16B16A16Sfloat | Ktx2Format::R32G32B32A32Sfloat => 4,
        }
    }

    pub fn texel_bytes(self) -> u32 {
        self.type_size() * self.components()
    }
}

/// Texture extent: `depth == 0` is a 2D texture (KTX2 writes pixelDepth 0 for 2D).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Ktx2Extent {
    pub width: u32,
    pub height: u32,
    pub depth: u32,
}

impl Ktx2Extent {
    pub fn texel_count(self) -> u64 {
        self.width as u64 * self.height.max(1) as u64 * self.depth.max(1) as u64
    }
}

/// The Basic Data Format Descriptor block (Khronos Data Format Specification 1.3) of an
/// uncompressed, linear, signed-float RGBA-ordered format, preceded by dfdTotalSize.
pub fn data_format_descriptor(format: Ktx2Format) -> Vec<u8> {
    let samples = format.components() as usize;
    let block_size = DFD_BLOCK_HEADER_BYTES + DFD_SAMPLE_BYTES * samples;
    let mut out = Vec::with_capacity(4 + block_size);
    push_u32(&mut out, (4 + block_size) as u32);
    // vendorId 0 (Khronos) in bits 0–16, descriptorType 0 (basic) in bits 17–31.
    push_u32(&mut out, 0);
    // versionNumber 2 (KHR_DF_VERSIONNUMBER_1_3), descriptorBlockSize.
    push_u32(&mut out, 2 | (block_size as u32) << 16);
    // colorModel RGBSDA (1), colorPrimaries BT709 (1), transferFunction LINEAR (1), flags 0
    // (straight alpha): the values KTX tools write for *_SFLOAT formats.
    out.extend_from_slice(&[1, 1, 1, 0]);
    // texelBlockDimension0–3: one texel (stored as size − 1).
    out.extend_from_slice(&[0, 0, 0, 0]);
    // bytesPlane0–7: the texel is one plane.
    out.extend_from_slice(&[format.texel_bytes() as u8, 0, 0, 0, 0, 0, 0, 0]);
    let bits = format.type_size() * 8;
    const CHANNEL_IDS: [u8; 4] = [0, 1, 2, 15]; // R, G, B, A
    // Qualifiers in the channelType byte's top bits: FLOAT (0x80) | SIGNED (0x40).
    const FLOAT_SIGNED: u8 = 0x80 | 0x40;
    for (i, &channel) in CHANNEL_IDS.iter().take(samples).enumerate() {
        let bit_offset = i as u32 * bits;
        push_u32(
            &mut out,
            bit_offset | (bits - 1) << 16 | ((channel | FLOAT_SIGNED) as u32) << 24,
        );
        push_u32(&mut out, 0); // samplePosition0–3
        // sampleLower/Upper: −1.0 and 1.0 as f32 bits for every float width, which is what
        // the KTX reference validator expects.
        push_u32(&mut out, (-1.0f32).to_bits());
        push_u32(&mut out, 1.0f32.to_bits());
    }
    out
}

/// Key/value data: entries sorted by key, each `length, key\0value`, padded to 4 bytes.
/// Values are written as given (text values should end in NUL, as `KTXwriter` must).
pub fn key_value_data(entries: &[(&str, &[u8])]) -> Vec<u8> {
    let mut sorted: Vec<_> = entries.to_vec();
    sorted.sort_by(|a, b| a.0.as_bytes().cmp(b.0.as_bytes()));
    let mut out = Vec::new();
    for (key, value) in sorted {
        push_u32(&mut out, (key.len() + 1 + value.len()) as u32);
        out.extend_from_slice(key.as_bytes());
        out.push(0);
        out.extend_from_slice(value);
        out.resize(out.len().next_multiple_of(4), 0);
    }
    out
}

/// Writes a one-level KTX2 file of `format` and `extent` with `texels` (already encoded in the
/// format, x fastest) and the key/value `entries`.
pub fn write_ktx2(
    out: &mut impl Write,
    format: Ktx2Format,
    extent: Ktx2Extent,
    texels: &[u8],
    entries: &[(&str, &[u8])],
) -> io::Result<()> {
    let expected = extent.texel_count() * format.texel_bytes() as u64;
    if texels.len() as u64 != expected {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!(
                "{} texel bytes for a {}×{}×{} {} texture, which needs {expected}",
                texels.len(),
                extent.width,
                extent.height,
                extent.depth,
                format.vk_name()
            ),
        ));
    }
    let dfd = data_format_descriptor(format);
    let kvd = key_value_data(entries);
    let dfd_offset = HEADER_BYTES + LEVEL_INDEX_BYTES;
    let kvd_offset = dfd_offset + dfd.len();
    let level_alignment = lcm(format.texel_bytes() as usize, 4);
    let level_offset = (kvd_offset + kvd.len()).next_multiple_of(level_alignment);

    let mut head = Vec::with_capacity(level_offset);
    head.extend_from_slice(&IDENTIFIER);
    for v in [
        format.vk_format(),
        format.type_size(),
        extent.width,
        extent.height,
        extent.depth,
        0, // layerCount: not an array
        1, // faceCount
        1, // levelCount: the texels are the only level (no mipmaps: a LUT is not minified)
        0, // supercompressionScheme: none
        dfd_offset as u32,
        dfd.len() as u32,
        if kvd.is_empty() { 0 } else { kvd_offset as u32 },
        kvd.len() as u32,
    ] {
        push_u32(&mut head, v);
    }
    for v in [0u64, 0, level_offset as u64, expected, expected] {
        head.extend_from_slice(&v.to_le_bytes()); // sgd offset/length, level 0
    }
    head.extend_from_slice(&dfd);
    head.extend_from_slice(&kvd);
    head.resize(level_offset, 0);
    out.write_all(&head)?;
    out.write_all(texels)
}

fn push_u32(out: &mut Vec<u8>, v: u32) {
    out.extend_from_slice(&v.to_le_bytes());
}

fn lcm(a: usize, b: usize) -> usize {
    let gcd = |mut a: usize, mut b: usize| {
        while b != 0 {
            (a, b) = (b, a % b);
        }
        a
    };
    a / gcd(a, b) * b
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_fields_sit_where_the_specification_puts_them() {
        let texels = vec![0u8; 3 * 2 * 4 * 8];
        let extent = Ktx2Extent {
            width: 3,
            height: 2,
            depth: 4,
        };
        let mut file = Vec::new();
        let writer = (b"KTXwriter".as_slice(), b"test\0".as_slice());
        write_ktx2(
            &mut file,
            Ktx2Format::R16G16B16A16Sfloat,
            extent,
            &texels,
            &[(std::str::from_utf8(writer.0).unwrap(), writer.1)],
        )
        .unwrap();
        let u32_at = |o: usize| u32::from_le_bytes(file[o..o + 4].try_into().unwrap());
        let u64_at = |o: usize| u64::from_le_bytes(file[o..o + 8].try_into().unwrap());
        assert_eq!(file[..12], IDENTIFIER);
        assert_eq!(
            (0..9).map(|i| u32_at(12 + 4 * i)).collect::<Vec<_>>(),
            [97, 2, 3, 2, 4, 0, 1, 1, 0]
        );
        assert_eq!((u32_at(48), u32_at(52)), (104, 4 + 24 + 4 * 16));
        assert_eq!(u32_at(56), 104 + 92, "key/value data follows the DFD");
        let level_offset = u64_at(80) as usize;
        assert_eq!(level_offset % 8, 0, "level aligned to lcm(8, 4)");
        assert_eq!((u64_at(88), u64_at(96)), (192, 192));
        assert_eq!(file.len(), level_offset + 192);
    }

    #[test]
    fn key_value_entries_are_sorted_and_padded() {
        let kvd = key_value_data(&[("b", b"12\0"), ("KTXwriter", b"x\0")]);
        // "KTXwriter" sorts before "b" (byte order: 'K' < 'b').
        assert_eq!(&kvd[4..13], b"KTXwriter");
        assert_eq!(u32::from_le_bytes(kvd[0..4].try_into().unwrap()), 12);
        assert_eq!(kvd.len(), 16 + 12, "4 + 5 bytes padded to 12");
        assert_eq!(u32::from_le_bytes(kvd[16..20].try_into().unwrap()), 5);
    }

    #[test]
    fn a_wrong_texel_count_is_refused() {
        let extent = Ktx2Extent {
            width: 2,
            height: 2,
            depth: 0,
        };
        let err = write_ktx2(
            &mut Vec::new(),
            Ktx2Format::R32Sfloat,
            extent,
            &[0; 12],
            &[],
        )
        .unwrap_err();
        assert!(err.to_string().contains("needs 16"), "{err}");
    }
}
