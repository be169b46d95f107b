//! The readers under test, each as a function from bytes to what it loaded or a classified
//! error. Each decodes as a user's file would be loaded: the hair parsers with cleaning, the
//! environment maps through `envmap_io::load_bytes` (2:1 and bad-pixel checks, sanitizing), the
//! table asset and SRBF set through their public loaders. What loaded goes on to the round trip
//! of [`super::round_trip`].

use std::fs::File;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, OnceLock};

use strandlight_precompute::SrbfSet;
use strandlight_precompute::envmap_io::{LoadOptions, LoadedEnvMap, load_bytes};
use strandlight_runtime::hair;
use strandlight_runtime::head::TriangleMesh;
use strandlight_scene::head_gltf::parse_gltf;
use strandlight_tables::asset;

use super::round_trip::{self, Reloaded};

/// A reader's failure: the error's variant (for the tally) and its message.
#[derive(Clone, Debug)]
pub struct Refusal {
    pub kind: String,
    pub message: String,
}

/// What a reader loaded, kept for the round trip.
#[derive(Clone, Debug)]
pub enum Loaded {
    Hair(hair::LoadedHair),
    EnvMap(LoadedEnvMap),
    Asset(asset::TableAsset),
    Srbf(SrbfSet),
    Head(TriangleMesh),
}

/// One reader.
pub struct Target {
    /// Short name, also the extension of the seed files (`hair`, `sltab`, …).
    pub name: &'static str,
    /// The name errors must mention (the path handed to the reader ends with it).
    pub file_name: &'static str,
    pub run: fn(&[u8]) -> Result<Loaded, Refusal>,
    /// Writes what `run` loaded with the project's writer for its kind and loads that again
    /// ([`round_trip::write_and_reload`]; a test swaps in a corrupting one to see the check fail).
    pub reload: fn(&Loaded) -> Result<Reloaded, String>,
    /// The writer and reader of the round trip, for the report.
    pub round_trip: &'static str,
    /// Every strict prefix of a valid file is refused (the format fixes its own size).
    pub prefixes_fail: bool,
    /// Pixels (or values) a byte of this format can legitimately decode to at most: the
    /// allowance of the wild-allocation check beyond 64 bytes per input byte.
    pub bytes_out_per_byte_in: u64,
    /// Executions in CI (times `STRANDLIGHT_FUZZ_EXECS`): chosen so the whole file runs in
    /// about 100 s in the test profile on 2 cores. (With the round trip, `tfx`, `hdr` and `exr`
    /// were cut from 250 000, 350 000 and 150 000: an environment map's round trip through the
    /// EXR writer and reader costs about 1 ms.)
    pub execs: usize,
    /// Fixes up a mutant so that it gets past an integrity check to the parser behind it.
    pub reseal: Option<fn(&mut [u8])>,
}

fn refusal<E: std::fmt::Debug + std::fmt::Display>(e: E) -> Refusal {
    let debug = format!("{e:?}");
    let kind = debug
        .split([' ', '{', '('])
        .next()
        .unwrap_or_default()
        .to_string();
    Refusal {
        kind,
        message: e.to_string(),
    }
}

fn hair_with(
    parse: fn(&[u8], &Path) -> Result<hair::LoadedHair, hair::HairError>,
    file: &str,
    bytes: &[u8],
) -> Result<Loaded, Refusal> {
    parse(bytes, Path::new(file))
        .map(Loaded::Hair)
        .map_err(refusal)
}

fn run_hair(bytes: &[u8]) -> Result<Loaded, Refusal> {
    hair_with(hair::yuksel::parse_hair, "fuzz-input.hair", bytes)
}

fn run_tfx(bytes: &[u8]) -> Result<Loaded, Refusal> {
    hair_with(hair::tfx::parse_tfx, "fuzz-input.tfx", bytes)
}

fn run_data(bytes: &[u8]) -> Result<Loaded, Refusal> {
    hair_with(hair::usc::parse_usc, "fuzz-input.data", bytes)
}

fn run_ply(bytes: &[u8]) -> Result<Loaded, Refusal> {
    hair_with(hair::ply::parse_ply, "fuzz-input.ply", bytes)
}

/// USD stages open through a path (openusd picks the layer format by extension): text, the
/// binary crate file and the zip package holding one. The crate reader is openusd's with the
/// allocation bounds of third_party/openusd/PATCHED.md: before them a corrupt count aborted the
/// process within the first few hundred `.usdc` mutants.
fn run_usd(file: &ScratchFile, bytes: &[u8]) -> Result<Loaded, Refusal> {
    use std::io::Write;
    file.rewrite(|f| f.write_all(bytes))
        .expect("the scratch file is writable");
    hair::load_usd(file.path())
        .map(Loaded::Hair)
        .map_err(refusal)
}

fn run_usda(bytes: &[u8]) -> Result<Loaded, Refusal> {
    static FILE: OnceLock<ScratchFile> = OnceLock::new();
    run_usd(
        FILE.get_or_init(|| ScratchFile::new("fuzz-input.usda")),
        bytes,
    )
}

fn run_usdc(bytes: &[u8]) -> Result<Loaded, Refusal> {
    static FILE: OnceLock<ScratchFile> = OnceLock::new();
    run_usd(
        FILE.get_or_init(|| ScratchFile::new("fuzz-input.usdc")),
        bytes,
    )
}

fn run_usdz(bytes: &[u8]) -> Result<Loaded, Refusal> {
    static FILE: OnceLock<ScratchFile> = OnceLock::new();
    run_usd(
        FILE.get_or_init(|| ScratchFile::new("fuzz-input.usdz")),
        bytes,
    )
}

fn run_abc(bytes: &[u8]) -> Result<Loaded, Refusal> {
    hair_with(hair::alembic::parse_alembic, "fuzz-input.abc", bytes)
}

/// glTF heads, named as if in the scratch folder: a mutant's relative buffer URI resolves there
/// (to the fuzzer's own small files at most). The kind of a refusal is its root cause's: the
/// `gltf` crate's error variant, or the reader's own first words.
fn run_head(file: &str, bytes: &[u8]) -> Result<Loaded, Refusal> {
    parse_gltf(bytes, &super::scratch_dir().join(file))
        .map(Loaded::Head)
        .map_err(|e| {
            let root = format!("{:?}", e.root_cause());
            let kind = root
                .trim_start_matches('"')
                .split([' ', '{', '(', ':', '"'])
                .next()
                .unwrap_or_default()
                .to_string();
            Refusal {
                kind,
                message: format!("{e:#}"),
            }
        })
}

fn run_glb(bytes: &[u8]) -> Result<Loaded, Refusal> {
    run_head("fuzz-input.glb", bytes)
}

fn run_gltf(bytes: &[u8]) -> Result<Loaded, Refusal> {
    run_head("fuzz-input.gltf", bytes)
}

/// Environment maps are loaded with sanitizing on, so that decoded maps with bad pixels go on
/// through the cleaning code instead of stopping at the refusal.
fn run_envmap(file: &str, bytes: &[u8]) -> Result<Loaded, Refusal> {
    let loaded = load_bytes(Path::new(file), bytes, LoadOptions { sanitize: true });
    loaded.map(Loaded::EnvMap).map_err(refusal)
}

fn run_hdr(bytes: &[u8]) -> Result<Loaded, Refusal> {
    run_envmap("fuzz-input.hdr", bytes)
}

fn run_exr(bytes: &[u8]) -> Result<Loaded, Refusal> {
    run_envmap("fuzz-input.exr", bytes)
}

/// A file of the scratch folder kept open and rewritten in place, for readers and writers that
/// take a path (creating a file per execution costs milliseconds here).
pub struct ScratchFile {
    path: PathBuf,
    file: Mutex<File>,
}

impl ScratchFile {
    /// `name` in [`super::scratch_dir`], created (empty).
    pub fn new(name: &str) -> Self {
        let path = super::scratch_dir().join(name);
        let file = File::create(&path).expect("the scratch folder is writable");
        Self {
            path,
            file: Mutex::new(file),
        }
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Empties the file and lets `write` fill it again.
    pub fn rewrite<T>(&self, write: impl FnOnce(&mut File) -> T) -> T {
        use std::io::Seek;
        let mut file = self.file.lock().unwrap_or_else(|e| e.into_inner());
        file.set_len(0).expect("the scratch file is writable");
        file.rewind().expect("the scratch file is writable");
        write(&mut file)
    }
}

/// The table asset reader takes a path, so each input goes through one scratch file.
fn run_sltab(bytes: &[u8]) -> Result<Loaded, Refusal> {
    use std::io::Write;
    static FILE: OnceLock<ScratchFile> = OnceLock::new();
    let file = FILE.get_or_init(|| ScratchFile::new("fuzz-input.sltab"));
    file.rewrite(|f| f.write_all(bytes))
        .expect("the scratch file is writable");
    asset::read_asset(file.path())
        .map(Loaded::Asset)
        .map_err(refusal)
}

fn run_srbf(bytes: &[u8]) -> Result<Loaded, Refusal> {
    SrbfSet::from_json(Path::new("fuzz-input.srbf.json"), bytes)
        .map(Loaded::Srbf)
        .map_err(refusal)
}

/// The metadata of a table asset is guarded by its own SHA-256, so a mutated JSON block would
/// only ever reach the checksum test. Half the asset mutants get a digest that matches again.
pub fn reseal_asset(data: &mut [u8]) {
    if data.len() < 16 || data[..8] != asset::MAGIC {
        return;
    }
    let len = u32::from_le_bytes(data[12..16].try_into().unwrap()) as usize;
    let Some(digest_end) = (16 + len).checked_add(32) else {
        return;
    };
    if digest_end > data.len() {
        return;
    }
    let hex = strandlight_tables::checksum::sha256_hex(&data[16..16 + len]);
    for (i, byte) in data[16 + len..digest_end].iter_mut().enumerate() {
        *byte = u8::from_str_radix(&hex[2 * i..2 * i + 2], 16).unwrap();
    }
}

/// Gives every stored entry of a zip (a USDZ package: entries are stored, not deflated) the
/// CRC-32 of the bytes it holds, in its local header and in the central directory, so that a
/// mutant reaches the crate file inside instead of stopping at the zip's checksum.
pub fn reseal_usdz(data: &mut [u8]) {
    let u16_at = |d: &[u8], i: usize| d.get(i..i + 2).map(|b| u16::from_le_bytes([b[0], b[1]]));
    let u32_at = |d: &[u8], i: usize| {
        d.get(i..i + 4)
            .map(|b| u32::from_le_bytes(b.try_into().unwrap()))
    };
    let mut crcs = std::collections::HashMap::new();
    let mut i = 0;
    while u32_at(data, i) == Some(0x0403_4b50) {
        let (Some(size), Some(name), Some(extra)) = (
            u32_at(data, i + 18),
            u16_at(data, i + 26),
            u16_at(data, i + 28),
        ) else {
            return;
        };
        let start = i + 30 + name as usize + extra as usize;
        let Some(bytes) = data.get(start..start.saturating_add(size as usize)) else {
            return;
        };
        let crc = crc32fast::hash(bytes);
        data[i + 14..i + 18].copy_from_slice(&crc.to_le_bytes());
        crcs.insert(i as u32, crc);
        i = start + size as usize;
    }
    // The central directory: each entry names its local header's offset.
    for j in 0..data.len().saturating_sub(46) {
        if u32_at(data, j) == Some(0x0201_4b50)
            && let Some(crc) = u32_at(data, j + 42).and_then(|local| crcs.get(&local))
        {
            data[j + 16..j + 20].copy_from_slice(&crc.to_le_bytes());
        }
    }
}

/// CI executions of the USD text and Alembic targets (about 0.5 ms and 0.2 ms each here).
const USDA_EXECS: usize = 5_000;
/// CI executions of the USD crate-file and package targets.
const USDC_EXECS: usize = 20_000;
const USDZ_EXECS: usize = 20_000;
const ABC_EXECS: usize = 10_000;
/// CI executions of the glTF head targets.
const GLB_EXECS: usize = 20_000;
const GLTF_EXECS: usize = 10_000;

/// Every reader, with its CI execution count and the writer its loads round-trip through. The
/// counts were halved on 2026-11-29 to keep CI under its time budget (the whole fuzz test took
/// 156 s of a 30-minute run); `STRANDLIGHT_FUZZ_EXECS=10` runs ten times as many.
pub fn all() -> Vec<Target> {
    let target = |name, file_name, run, execs| Target {
        name,
        file_name,
        run,
        reload: round_trip::write_and_reload,
        round_trip: round_trip::describe(name),
        prefixes_fail: true,
        bytes_out_per_byte_in: 64,
        execs,
        reseal: None,
    };
    vec![
        target(
            "hair",
            "fuzz-input.hair",
            run_hair as fn(&[u8]) -> Result<Loaded, Refusal>,
            250_000,
        ),
        Target {
            // Offsets may leave gaps and trailing bytes (TressFX files have them), so a file
            // cut after its last array still loads.
            prefixes_fail: false,
            ..target("tfx", "fuzz-input.tfx", run_tfx, 100_000)
        },
        target("data", "fuzz-input.data", run_data, 200_000),
        target("ply", "fuzz-input.ply", run_ply, 175_000),
        Target {
            // A byte of run-length code holds up to 16 pixels of 12 bytes (f32 RGB) each.
            bytes_out_per_byte_in: 16 * 12,
            ..target("hdr", "fuzz-input.hdr", run_hdr, 125_000)
        },
        Target {
            // Up to 1376 bytes of samples per byte (PXR24's deflate), 6 of them (half RGB) per
            // pixel of 12 bytes (f32 RGB) in memory.
            bytes_out_per_byte_in: 1376 * 12 / 6,
            ..target("exr", "fuzz-input.exr", run_exr, 50_000)
        },
        Target {
            reseal: Some(reseal_asset),
            ..target("sltab", "fuzz-input.sltab", run_sltab, 50_000)
        },
        target("srbf", "fuzz-input.srbf.json", run_srbf, 175_000),
        // The scene formats' seeds come from usd-core and PyAlembic (`seeds::scene_seeds`).
        Target {
            // A text stage cut after a closing brace is a whole stage.
            prefixes_fail: false,
            ..target("usda", "fuzz-input.usda", run_usda, USDA_EXECS)
        },
        Target {
            // LZ4 expands a byte into at most 256, and the integer coding's 2-bit codes each
            // into a value of up to 8 bytes.
            bytes_out_per_byte_in: 256 * 4 * 8,
            ..target("usdc", "fuzz-input.usdc", run_usdc, USDC_EXECS)
        },
        Target {
            bytes_out_per_byte_in: 256 * 4 * 8,
            reseal: Some(reseal_usdz),
            // A zip names its entries' sizes in a directory at its end: a prefix loses it.
            ..target("usdz", "fuzz-input.usdz", run_usdz, USDZ_EXECS)
        },
        target("abc", "fuzz-input.abc", run_abc, ABC_EXECS),
        // The heads' seeds come from pygltflib (`seeds::scene_seeds`).
        target("glb", "fuzz-input.glb", run_glb, GLB_EXECS),
        Target {
            // JSON cut after its closing brace is whole; so is one missing only trailing spaces.
            prefixes_fail: false,
            ..target("gltf", "fuzz-input.gltf", run_gltf, GLTF_EXECS)
        },
    ]
}
