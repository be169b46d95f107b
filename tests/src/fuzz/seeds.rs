//! Seed corpora: small valid files written by the project's own writers (so the harness runs
//! without the shared data), plus the shared real samples of each format from `../shared/data`
//! (without it a printed skip, or a failure under `STRANDLIGHT_REQUIRE_TOOLS=1`). Real files of
//! more than a few hundred kB are cut down to their first strands or scanlines by rewriting
//! their headers (their bytes are otherwise kept as they are), so an execution stays in the
//! millisecond range.

use std::path::Path;

use glam::Vec3;
use strandlight_precompute::EnvMap;
use strandlight_precompute::compact_sources::CompactSource;
use strandlight_precompute::envmap::BadPixelCounts;
use strandlight_precompute::radiance_hdr;
use strandlight_precompute::srbf_fit::{FitOptions, RoundRecord};
use strandlight_precompute::srbf_set::{FORMAT, FORMAT_VERSION, LightKind, SrbfSet};
use strandlight_runtime::hair::{self, GroomParams, HairModel, HairWriteOptions};
use strandlight_tables::asset::{self, AssetDescription, CreationInfo, Generator, Storage};
use strandlight_tables::shared_data::shared_dir_for;
use strandlight_tables::table::{Axis, Table};

/// One seed input.
#[derive(Clone, Debug)]
pub struct Seed {
    /// Where it came from: a shared file's name (with how it was cut) or `generated: …`.
    pub name: String,
    pub bytes: Vec<u8>,
    /// Written by the project's own code (and so known to load).
    pub generated: bool,
}

fn generated(name: impl Into<String>, bytes: Vec<u8>) -> Seed {
    Seed {
        name: format!("generated: {}", name.into()),
        bytes,
        generated: true,
    }
}

/// The seeds of target `name` (`hair`, `tfx`, `data`, `ply`, `hdr`, `exr`, `sltab`, `srbf`),
/// the generated ones first. Prints which shared files were used or why none were.
pub fn seeds(name: &str) -> Vec<Seed> {
    let mut out = match name {
        "hair" => hair_seeds(),
        "tfx" => vec![generated(
            "2 × 3-point strands, thickness, colours",
            tfx_file(true),
        )],
        "data" => vec![generated(
            "small groom",
            hair::usc::encode_usc(&small_groom(6, 5)),
        )],
        "ply" => vec![
            generated(
                "3 strands, uchar colours, list element",
                ply_file(Some("uchar")),
            ),
            generated(
                "3 strands, list with double lengths",
                ply_file(Some("double")),
            ),
            generated("3 strands", ply_file(None)),
        ],
        "hdr" => hdr_seeds(),
        "exr" => exr_seeds(),
        "sltab" => sltab_seeds(),
        "srbf" => vec![generated("2 lobes, 1 source", srbf_json())],
        "usda" | "usdc" | "usdz" | "abc" | "glb" | "gltf" => scene_seeds(name),
        other => panic!("no seeds for target {other}"),
    };
    out.extend(shared_seeds(name));
    out
}

/// Targets whose seeds another project's writer makes (usd-core, PyAlembic, pygltflib).
pub const SCENE_TARGETS: [&str; 6] = ["usda", "usdc", "usdz", "abc", "glb", "gltf"];

/// Whether the seeds of `target` can be made here: always for the project's own formats; for
/// the scene formats when Python has the writer (otherwise the skip is printed, or under
/// `STRANDLIGHT_REQUIRE_TOOLS=1` this panics).
pub fn available(target: &str) -> bool {
    !SCENE_TARGETS.contains(&target) || !scene_seeds(target).is_empty()
}

/// The test grooms and heads of `tests/scripts/` written once per process into the fuzz folder:
/// USD text from usd-core, Alembic from PyAlembic, glTF from pygltflib. Generated at test time, never
/// checked in; empty when the writer is missing.
fn scene_seeds(target: &str) -> Vec<Seed> {
    use crate::scene_grooms::Writer;
    use std::sync::OnceLock;
    static USD: OnceLock<bool> = OnceLock::new();
    static ABC: OnceLock<bool> = OnceLock::new();
    static HEADS: OnceLock<bool> = OnceLock::new();
    let dir = super::fuzz_dir().join("scene-seeds");
    // The .gltf seed holds its buffer as a data URI: a fuzzed file stands alone.
    let (written, writer, name, sub, file) = match target {
        "abc" => (&ABC, Writer::Alembic, "PyAlembic", "abc", "groom.abc"),
        "glb" => (&HEADS, Writer::Heads, "pygltflib", "heads", "head.glb"),
        "gltf" => (
            &HEADS,
            Writer::Heads,
            "pygltflib",
            "heads",
            "head-embedded.gltf",
        ),
        "usdc" => (&USD, Writer::UsdCore, "usd-core", "usd", "groom.usdc"),
        "usdz" => (&USD, Writer::UsdCore, "usd-core", "usd", "groom.usdz"),
        _ => (&USD, Writer::UsdCore, "usd-core", "usd", "groom.usda"),
    };
    let sub = dir.join(sub);
    if !*written.get_or_init(|| writer.write(&sub, &[])) {
        return Vec::new();
    }
    let bytes = std::fs::read(sub.join(file)).expect("the writer wrote its file");
    vec![Seed {
        name: format!("{name}: tests/scripts {file}"),
        bytes,
        generated: true,
    }]
}

/// A procedural groom of `strands` strands of `points` points (the project's default hair).
fn small_groom(strands: usize, points: usize) -> HairModel {
    hair::generate_groom(&GroomParams {
        strand_count: strands,
        points_per_strand: points,
        clump_count: 2,
        seed: 7,
        ..GroomParams::default()
    })
    .expect("a small groom generates")
}

fn hair_seeds() -> Vec<Seed> {
    let groom = small_groom(8, 6);
    let path = Path::new("seed.hair");
    let plain = hair::yuksel::encode_hair(&groom, &HairWriteOptions::default(), path)
        .expect("the groom is representable");
    // Every attribute per point, with a segments array: all five arrays of the format.
    let n = groom.point_count();
    let full = HairModel::new(
        groom.points().to_vec(),
        groom.strand_offsets().to_vec(),
        Some(hair::Attribute::PerPoint(
            (0..n).map(|i| 0.01 + 0.001 * i as f32).collect(),
        )),
        Some(hair::Attribute::PerPoint(
            (0..n).map(|i| (i % 10) as f32 / 10.0).collect(),
        )),
        Some(hair::Attribute::PerPoint(
            (0..n)
                .map(|i| Vec3::new(0.5, 0.25, i as f32 / n as f32))
                .collect(),
        )),
    )
    .expect("a valid model");
    let options = HairWriteOptions {
        segments_array: true,
        info: "strandlight fuzz seed".into(),
    };
    let all_arrays = hair::yuksel::encode_hair(&full, &options, path).expect("representable");
    vec![
        generated("groom, no segments array", plain),
        generated("groom, every array", all_arrays),
    ]
}

/// A TressFX 4 file of two 3-point strands, optionally with thickness and colours.
fn tfx_file(attributes: bool) -> Vec<u8> {
    let strands: [[[f32; 3]; 3]; 2] = [
        [[0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.1, 2.0, 0.0]],
        [[1.0, 0.0, 0.0], [1.0, 1.0, 0.2], [1.0, 2.0, 0.4]],
    ];
    let vertices = 6u32;
    let positions_at = 160u32;
    let thickness_at = if attributes {
        positions_at + 16 * vertices
    } else {
        0
    };
    let color_at = if attributes { thickness_at + 8 } else { 0 };
    let mut out = 4.0f32.to_le_bytes().to_vec();
    for v in [2u32, 3, positions_at, 0, 0, thickness_at, color_at] {
        out.extend_from_slice(&v.to_le_bytes());
    }
    out.resize(160, 0);
    for p in strands.iter().flatten() {
        out.extend(p.iter().chain(&[1.0]).flat_map(|v| v.to_le_bytes()));
    }
    if attributes {
        for t in [0.5f32, 0.25] {
            out.extend_from_slice(&t.to_le_bytes());
        }
        for p in strands.iter().flatten() {
            out.extend([p[0], 0.5, 0.25, 1.0].iter().flat_map(|v| v.to_le_bytes()));
        }
    }
    out
}

/// A binary PLY of three strands (hapPLY layout); with `lists`, a trailing `face` element
/// with a list property whose lengths have that type, which the reader must step over.
fn ply_file(lists: Option<&str>) -> Vec<u8> {
    let strands: [&[[f32; 3]]; 3] = [
        &[[0.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        &[[1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [1.0, 2.0, 0.5]],
        &[
            [2.0, 0.0, 0.0],
            [2.0, 1.0, 0.1],
            [2.0, 2.0, 0.3],
            [2.5, 3.0, 0.0],
        ],
    ];
    let points: usize = strands.iter().map(|s| s.len()).sum();
    let mut out = format!(
        "ply\nformat binary_little_endian 1.0\ncomment fuzz seed\nelement vertex {points}\n\
         property float x\nproperty float y\nproperty float z\nproperty uchar red\n\
         property uchar green\nproperty uchar blue\nelement strand 3\nproperty ushort nsegs\n{}end_header\n",
        match lists {
            Some(kind) => format!("element face 2\nproperty list {kind} int vertex_indices\n"),
            None => String::new(),
        }
    )
    .into_bytes();
    for p in strands.iter().copied().flatten() {
        out.extend(p.iter().flat_map(|v| v.to_le_bytes()));
        out.extend_from_slice(&[200, 100, 50]);
    }
    for s in strands {
        out.extend_from_slice(&(s.len() as u16 - 1).to_le_bytes());
    }
    if let Some(kind) = lists {
        for face in [[0i32, 1, 2].as_slice(), &[3, 4]] {
            match kind {
                "double" => out.extend_from_slice(&(face.len() as f64).to_le_bytes()),
                _ => out.push(face.len() as u8),
            }
            out.extend(face.iter().flat_map(|v| v.to_le_bytes()));
        }
    }
    out
}

/// A 2:1 map with a bright spot, a gradient and black pixels (so runs and literals both occur).
fn test_map(width: usize, height: usize) -> EnvMap {
    let pixels = (0..width * height)
        .map(|i| {
            let (x, y) = (i % width, i / width);
            if (x, y) == (width / 3, height / 4) {
                [5000.0, 4000.0, 3000.0]
            } else if y > height * 3 / 4 {
                [0.0; 3]
            } else {
                [
                    x as f32 / width as f32,
                    0.5,
                    y as f32 / height as f32 + 0.01,
                ]
            }
        })
        .collect();
    EnvMap::from_pixels(width, height, pixels)
}

fn hdr_seeds() -> Vec<Seed> {
    let map = test_map(32, 16);
    let small = test_map(8, 4);
    vec![
        generated(
            "32×16, new-style RLE",
            radiance_hdr::encode_for_tests(&map, "-Y 16 +X 32", true),
        ),
        generated(
            "32×16 flat, columns (+X 32 -Y 16)",
            radiance_hdr::encode_for_tests(&map, "+X 32 -Y 16", false),
        ),
        generated(
            "8×4 flat",
            radiance_hdr::encode_for_tests(&small, "-Y 4 +X 8", false),
        ),
    ]
}

/// An EXR of `map` written by the `exr` crate with `encoding`, in half or full floats.
pub fn exr_bytes(map: &EnvMap, encoding: exr::prelude::Encoding, half: bool) -> Vec<u8> {
    use exr::prelude::*;
    let mut out = std::io::Cursor::new(Vec::new());
    let size = (map.width(), map.height());
    if half {
        let channels = SpecificChannels::rgb(|p: Vec2<usize>| {
            let [r, g, b] = map.pixel(p.x(), p.y());
            (f16::from_f32(r), f16::from_f32(g), f16::from_f32(b))
        });
        Image::from_encoded_channels(size, encoding, channels)
            .write()
            .to_buffered(&mut out)
            .expect("an in-memory EXR writes");
    } else {
        let channels = SpecificChannels::rgb(|p: Vec2<usize>| {
            let [r, g, b] = map.pixel(p.x(), p.y());
            (r, g, b)
        });
        Image::from_encoded_channels(size, encoding, channels)
            .write()
            .to_buffered(&mut out)
            .expect("an in-memory EXR writes");
    }
    out.into_inner()
}

fn exr_seeds() -> Vec<Seed> {
    use exr::prelude::*;
    let map = test_map(32, 16);
    let zip = Encoding {
        compression: Compression::ZIP16,
        ..Encoding::UNCOMPRESSED
    };
    let piz = Encoding {
        compression: Compression::PIZ,
        ..Encoding::UNCOMPRESSED
    };
    vec![
        generated(
            "32×16 float, uncompressed",
            exr_bytes(&map, Encoding::UNCOMPRESSED, false),
        ),
        generated("32×16 half, ZIP", exr_bytes(&map, zip, true)),
        generated("32×16 half, PIZ", exr_bytes(&map, piz, true)),
        generated(
            "32×16 float, RLE tiles",
            exr_bytes(&map, Encoding::FAST_LOSSLESS, false),
        ),
    ]
}

/// The bytes of a small table asset baked through the tables API.
pub fn sltab_bytes(storage: Storage) -> Vec<u8> {
    let axes = vec![
        Axis::uniform("u·ξ", -1.0, 1.0, 3),
        Axis::power("1/λ", 1.0 / 64.0, 1.0 / 3.0, 2, 1.0 / 0.3),
    ];
    let values = (0..3 * 2 * 3).map(|i| 0.25 * i as f32 - 1.0).collect();
    let table = Table::new(axes, 3, values).expect("a valid table");
    let description = AssetDescription {
        name: "I_fuzz".into(),
        quantity: "fuzz seed".into(),
        scattering_function: "marschner".into(),
        fiber_parameters: serde_json::json!({"eta": 1.55, "sigma_a": [0.4, 0.6, 0.9]}),
        generator: Generator {
            name: "strandlight fuzz harness".into(),
            version: "0".into(),
        },
        created: CreationInfo {
            unix_time_s: 1_763_770_000,
            command_line: None,
            notes: None,
        },
        inputs_key: Some("fuzz".into()),
    };
    let path = super::scratch_dir().join(format!("seed-{storage:?}.sltab"));
    asset::write_asset(&path, &table, &description, storage)
        .expect("the scratch folder is writable");
    let bytes = std::fs::read(&path).expect("the asset was just written");
    let _ = std::fs::remove_file(&path);
    bytes
}

fn sltab_seeds() -> Vec<Seed> {
    vec![
        generated("3×2 RGB table, f32", sltab_bytes(Storage::F32)),
        generated("3×2 RGB table, f16", sltab_bytes(Storage::F16)),
    ]
}

/// An SRBF set as the fitter saves it (pretty JSON).
pub fn srbf_json() -> Vec<u8> {
    let lobe = |center: [f64; 3], lambda: f64| strandlight_tables::srbf::SrbfLobe {
        center,
        lambda,
        amplitude: [1.5, 1.25, 1.0],
    };
    let set = SrbfSet {
        format: FORMAT.into(),
        version: FORMAT_VERSION,
        kind: LightKind::Srbf,
        lobes: vec![lobe([0.0, 1.0, 0.0], 8.0), lobe([0.6, 0.0, -0.8], 120.0)],
        sources: vec![CompactSource {
            direction: [0.0, 0.6, 0.8],
            power: [2.0, 1.5, 1.0],
            power_share: 0.4,
            angular_variance: 1e-4,
        }],
        source: "fuzz.hdr".into(),
        source_sha256: "0".repeat(64),
        options: FitOptions::default(),
        sanitized: BadPixelCounts::default(),
        fit_grid: [64, 32],
        relative_l2_error: 0.1,
        relative_mse: 0.01,
        full_resolution_relative_mse: 0.02,
        power_ratio: [1.0, 1.0, 1.0],
        history: vec![RoundRecord {
            lobes: 2,
            relative_mse: 0.01,
            evaluations: 100,
        }],
        seconds: 0.5,
    };
    serde_json::to_vec_pretty(&set).expect("an SrbfSet serializes")
}

/// Seeds above this size are cut down (or left out where no cutter exists).
const LARGE: usize = 200_000;

/// The shared real files of this format, cut down where large.
fn shared_seeds(name: &str) -> Vec<Seed> {
    let (folder, extension) = match name {
        "hair" | "tfx" | "data" | "ply" => ("hair", name),
        "hdr" | "exr" => ("envmaps", name),
        _ => return Vec::new(), // no shared samples of the project's own formats
    };
    let Some(dir) = shared_dir_for(&format!("the real {name} seeds (generated seeds only)")) else {
        return Vec::new();
    };
    let mut files: Vec<_> = std::fs::read_dir(dir.join(folder))
        .map(|d| d.filter_map(|e| e.ok()).map(|e| e.path()).collect())
        .unwrap_or_default();
    files.retain(|p| p.extension().is_some_and(|e| e == extension));
    files.sort();
    let mut out = Vec::new();
    for path in files {
        let file_name = path.file_name().unwrap().to_string_lossy().into_owned();
        let Ok(bytes) = std::fs::read(&path) else {
            eprintln!("{name}: cannot read {}; skipped", path.display());
            continue;
        };
        if bytes.len() <= LARGE {
            out.push(Seed {
                name: file_name,
                bytes,
                generated: false,
            });
            continue;
        }
        let cut = match name {
            "hair" => cut_hair(&bytes, 64),
            "tfx" => cut_tfx(&bytes, 64),
            "hdr" => cut_hdr(&bytes, 8),
            "exr" => cut_exr(&bytes, 1),
            _ => None,
        };
        match cut {
            Some((how, bytes)) => out.push(Seed {
                name: format!("{file_name} ({how})"),
                bytes,
                generated: false,
            }),
            None => eprintln!("{name}: {file_name} is large and could not be cut; skipped"),
        }
    }
    out
}

fn u32_at(b: &[u8], at: usize) -> Option<u32> {
    Some(u32::from_le_bytes(b.get(at..at + 4)?.try_into().ok()?))
}

/// The first `keep` strands of a `.hair` file: header counts rewritten, each array cut.
fn cut_hair(b: &[u8], keep: usize) -> Option<(String, Vec<u8>)> {
    let (strands, flags, default_segments) = (
        u32_at(b, 4)? as usize,
        u32_at(b, 12)?,
        u32_at(b, 16)? as usize,
    );
    let keep = keep.min(strands);
    let has_segments = flags & 1 != 0;
    let counts: Vec<usize> = if has_segments {
        (0..strands)
            .map(|s| {
                Some(
                    u16::from_le_bytes(b.get(128 + 2 * s..130 + 2 * s)?.try_into().ok()?) as usize
                        + 1,
                )
            })
            .collect::<Option<_>>()?
    } else {
        vec![default_segments + 1; strands]
    };
    let points: usize = counts.iter().sum();
    let kept_points: usize = counts[..keep].iter().sum();
    let mut out = b.get(..128)?.to_vec();
    out[4..8].copy_from_slice(&(keep as u32).to_le_bytes());
    out[8..12].copy_from_slice(&(kept_points as u32).to_le_bytes());
    let mut at = 128;
    if has_segments {
        out.extend_from_slice(b.get(at..at + 2 * keep)?);
        at += 2 * strands;
    }
    // points, thickness, transparency, colour: bytes per point of each array present.
    for (bit, per_point) in [(2u32, 12usize), (4, 4), (8, 4), (16, 12)] {
        if flags & bit != 0 {
            out.extend_from_slice(b.get(at..at + per_point * kept_points)?);
            at += per_point * points;
        }
    }
    Some((format!("first {keep} strands"), out))
}

/// The first `keep` strands of a TressFX file: every per-strand and per-vertex array cut and
/// laid out again after the positions, offsets rewritten.
fn cut_tfx(b: &[u8], keep: usize) -> Option<(String, Vec<u8>)> {
    let (strands, per_strand) = (u32_at(b, 4)? as usize, u32_at(b, 8)? as usize);
    let keep = keep.min(strands);
    let mut out = b.get(..160)?.to_vec();
    out[4..8].copy_from_slice(&(keep as u32).to_le_bytes());
    // positions, strand UVs, vertex UVs, thickness, colours: bytes per strand of each.
    let per_strand_bytes = [16 * per_strand, 8, 8 * per_strand, 4, 16 * per_strand];
    for (i, bytes_each) in per_strand_bytes.into_iter().enumerate() {
        let at = u32_at(b, 12 + 4 * i)? as usize;
        if at == 0 {
            continue;
        }
        let new_at = out.len() as u32;
        out[12 + 4 * i..16 + 4 * i].copy_from_slice(&new_at.to_le_bytes());
        out.extend_from_slice(b.get(at..at + bytes_each * keep)?);
    }
    Some((format!("first {keep} strands"), out))
}

/// The header and first `keep` scanlines of a Radiance file, with the resolution line
/// rewritten (so the map is no longer 2:1: it reaches the decoder, not the fitter).
fn cut_hdr(b: &[u8], keep: usize) -> Option<(String, Vec<u8>)> {
    let blank = b.windows(2).position(|w| w == b"\n\n")? + 2;
    let res_end = blank + b[blank..].iter().position(|&c| c == b'\n')?;
    let res = std::str::from_utf8(&b[blank..res_end]).ok()?;
    let words: Vec<&str> = res.split_whitespace().collect();
    let [y, _, x, width] = words.as_slice() else {
        return None;
    };
    let width: usize = width.parse().ok()?;
    // Walk `keep` new-style RLE scanlines to find where they end.
    let mut at = res_end + 1;
    for _ in 0..keep {
        let head = b.get(at..at + 4)?;
        if head[0] != 2 || head[1] != 2 {
            return None;
        }
        at += 4;
        for _ in 0..4 {
            let mut i = 0;
            while i < width {
                let count = *b.get(at)? as usize;
                if count > 128 {
                    at += 2;
                    i += count - 128;
                } else {
                    at += 1 + count;
                    i += count;
                }
            }
        }
    }
    let mut out = b[..blank].to_vec();
    out.extend_from_slice(format!("{y} {keep} {x} {width}\n").as_bytes());
    out.extend_from_slice(b.get(res_end + 1..at)?);
    Some((format!("header and first {keep} scanlines"), out))
}

/// The first `keep` chunks of a single-part scan-line EXR: the data window's last line, the
/// offset table and the chunks cut.
fn cut_exr(b: &[u8], keep: usize) -> Option<(String, Vec<u8>)> {
    // Attributes: name\0 type\0 size:i32 value, ending with an empty name.
    let mut at = 8;
    let mut data_window = None;
    let mut lines_per_chunk = 1;
    loop {
        let name_end = at + b[at..].iter().position(|&c| c == 0)?;
        if name_end == at {
            at += 1;
            break;
        }
        let name = &b[at..name_end];
        let type_end = name_end + 1 + b[name_end + 1..].iter().position(|&c| c == 0)?;
        let size = u32_at(b, type_end + 1)? as usize;
        let value = type_end + 5;
        if name == b"dataWindow" {
            data_window = Some(value);
        }
        if name == b"compression" {
            lines_per_chunk = match *b.get(value)? {
                0..=2 => 1,      // none, RLE, ZIPS
                3 | 5 => 16,     // ZIP, PXR24
                4 | 6 | 7 => 32, // PIZ, B44, B44A
                _ => return None,
            };
        }
        if name == b"tiles" {
            return None;
        }
        at = value + size;
    }
    let window = data_window?;
    let (y_min, y_max) = (
        u32_at(b, window + 4)? as i32,
        u32_at(b, window + 12)? as i32,
    );
    let chunks = ((y_max - y_min + 1) as usize).div_ceil(lines_per_chunk);
    let keep = keep.min(chunks);
    let offsets: Vec<u64> = (0..chunks)
        .map(|i| {
            Some(u64::from_le_bytes(
                b.get(at + 8 * i..at + 8 * i + 8)?.try_into().ok()?,
            ))
        })
        .collect::<Option<_>>()?;
    // The kept chunks, in file order.
    let mut kept: Vec<(u64, &[u8])> = Vec::new();
    for &offset in &offsets {
        let o = offset as usize;
        let size = u32_at(b, o + 4)? as usize;
        let chunk = b.get(o..o + 8 + size)?;
        let y = u32_at(chunk, 0)? as i32;
        if (y - y_min) < (keep * lines_per_chunk) as i32 {
            kept.push((offset, chunk));
        }
    }
    let mut out = b[..at].to_vec();
    let new_y_max = y_min + (keep * lines_per_chunk) as i32 - 1;
    out[window + 12..window + 16].copy_from_slice(&new_y_max.to_le_bytes());
    let table_end = at + 8 * keep;
    let mut next = table_end as u64;
    let mut body = Vec::new();
    for (_, chunk) in &kept {
        out.extend_from_slice(&next.to_le_bytes());
        next += chunk.len() as u64;
        body.extend_from_slice(chunk);
    }
    out.extend_from_slice(&body);
    Some((
        format!("first {keep} chunk(s), {} lines", keep * lines_per_chunk),
        out,
    ))
}
