//! Every file reader fuzzed from its seed corpus (issue #15, "Bad input"): see
//! `strandlight_tests::fuzz` for what is checked. The executions per target are the `execs` of
//! `fuzz::targets::all()` times `STRANDLIGHT_FUZZ_EXECS` (default 1):
//!
//! ```text
//! cargo test -p strandlight-tests --test fuzz_readers -- --nocapture
//! STRANDLIGHT_FUZZ_EXECS=10 cargo test -p strandlight-tests --test fuzz_readers -- --nocapture
//! ```
//!
//! The targets share one process-wide allocation counter, so they run one at a time (each test
//! holds `fuzz::alloc::MEASURING`).

use strandlight_tests::fuzz::{self, alloc};

#[global_allocator]
static COUNTING: alloc::CountingAlloc = alloc::CountingAlloc;

#[test]
fn the_counting_allocator_is_installed() {
    let _measuring = alloc::MEASURING.lock().unwrap_or_else(|e| e.into_inner());
    assert!(alloc::is_installed());
    // And it sees a large request as one.
    let (v, largest) = alloc::measure(|| std::hint::black_box(vec![0u8; 3 << 20]));
    assert!(largest >= v.len());
}

#[test]
fn every_target_has_a_test_here() {
    let names: Vec<_> = fuzz::targets::all().iter().map(|t| t.name).collect();
    assert_eq!(
        names,
        [
            "hair", "tfx", "data", "ply", "hdr", "exr", "sltab", "srbf", "usda", "usdc", "usdz",
            "abc", "glb", "gltf"
        ]
    );
}

/// The round-trip check can fail: every target run with a re-load that changes the last bit of
/// one value (a position, a pixel, a table value, a field of the SRBF set) reports every load
/// as a round-trip finding, saved like any other under its own name.
#[test]
fn a_round_trip_that_changes_one_bit_is_a_finding() {
    use fuzz::round_trip::{self, Reloaded};
    use fuzz::targets::Loaded;
    fn corrupted(first: &Loaded) -> Result<Reloaded, String> {
        match round_trip::write_and_reload(first)? {
            Reloaded::Loaded(mut again) => {
                round_trip::corrupt(&mut again);
                Ok(Reloaded::Loaded(again))
            }
            other => Ok(other),
        }
    }
    let _measuring = alloc::MEASURING.lock().unwrap_or_else(|e| e.into_inner());
    assert!(alloc::is_installed());
    for target in fuzz::targets::all() {
        if !fuzz::seeds::available(target.name) {
            continue;
        }
        let seeds = fuzz::seeds::seeds(target.name);
        let name: &'static str = Box::leak(format!("{}-corrupted-reload", target.name).into());
        let corrupting = fuzz::targets::Target {
            name,
            reload: corrupted,
            execs: 64,
            ..target
        };
        let report = fuzz::run_with_seeds(&corrupting, seeds);
        let round_trip_findings = report
            .findings
            .iter()
            .filter(|f| matches!(f.problem, fuzz::Problem::RoundTrip { .. }))
            .count();
        eprintln!(
            "{name}: {} loads, {round_trip_findings} round-trip findings, e.g. {}",
            report.ok,
            report
                .findings
                .first()
                .map(|f| f.problem.to_string())
                .unwrap_or_default()
        );
        assert!(report.ok > 0, "{name}: nothing loaded");
        assert_eq!(report.round_trips, 0, "{name}");
        assert_eq!(
            round_trip_findings,
            report.ok - report.not_representable,
            "{name}: every load written back is a finding"
        );
        assert_eq!(round_trip_findings, report.findings.len(), "{name}");
        assert!(
            report.findings[0]
                .saved
                .starts_with(fuzz::fuzz_dir().join(name))
        );
        assert!(report.findings[0].saved.exists());
    }
}

#[test]
fn hair() {
    fuzz::fuzz_target("hair");
}

#[test]
fn tfx() {
    fuzz::fuzz_target("tfx");
}

#[test]
fn data() {
    fuzz::fuzz_target("data");
}

#[test]
fn ply() {
    fuzz::fuzz_target("ply");
}

#[test]
fn hdr() {
    fuzz::fuzz_target("hdr");
}

#[test]
fn exr() {
    fuzz::fuzz_target("exr");
}

#[test]
fn sltab() {
    fuzz::fuzz_target("sltab");
}

#[test]
fn srbf() {
    fuzz::fuzz_target("srbf");
}

/// The scene formats' seeds are written by usd-core, PyAlembic and pygltflib: skipped without
/// them.
fn fuzz_scene_target(name: &str) {
    if fuzz::seeds::available(name) {
        fuzz::fuzz_target(name);
    }
}

#[test]
fn usda() {
    fuzz_scene_target("usda");
}

#[test]
fn usdc() {
    fuzz_scene_target("usdc");
}

#[test]
fn usdz() {
    fuzz_scene_target("usdz");
}

#[test]
fn abc() {
    fuzz_scene_target("abc");
}

#[test]
fn glb() {
    fuzz_scene_target("glb");
}

#[test]
fn gltf() {
    fuzz_scene_target("gltf");
}

/// One header per format claiming an absurd size (10¹² strands or points, 10⁶ × 10⁶ pixels, a
/// 10⁶ × 10⁶ EXR data window, table axes of 10¹⁰ entries): each is refused with an error naming
/// the file, and no allocation made while reading it reaches 1 MiB.
#[test]
fn absurd_sizes_are_refused_before_any_allocation() {
    use fuzz::seeds;
    let _measuring = alloc::MEASURING.lock().unwrap_or_else(|e| e.into_inner());
    assert!(alloc::is_installed());

    let le = |values: &[u32]| -> Vec<u8> { values.iter().flat_map(|v| v.to_le_bytes()).collect() };
    let mut cases: Vec<(&str, &str, Vec<u8>)> = Vec::new();

    // .hair: u32 counts, so the largest they hold (4.3 × 10⁹), and 10¹² truncated to 32 bits.
    for (strands, points, flags) in [
        (1, u32::MAX, 2),
        (u32::MAX, 2, 3),
        (1, (1_000_000_000_000u64 % (1 << 32)) as u32, 2),
    ] {
        let mut f = b"HAIR".to_vec();
        f.extend(le(&[strands, points, flags, 1]));
        f.resize(128 + 24, 0);
        cases.push(("hair", "strand or point count", f));
    }
    // .tfx: 10⁶ strands of 10⁶ vertices.
    let mut f = 4.0f32.to_le_bytes().to_vec();
    f.extend(le(&[1_000_000, 1_000_000, 160]));
    f.resize(160 + 64, 0);
    cases.push(("tfx", "10⁶ × 10⁶ vertices", f));
    // .data: 10⁶ strands, the first claiming i32::MAX points.
    cases.push((
        "data",
        "10⁶ strands",
        le(&[1_000_000, i32::MAX as u32, 0, 0]),
    ));
    // .ply: 10¹² vertices.
    let ply = "ply\nformat binary_little_endian 1.0\nelement vertex 1000000000000\nproperty float x\n\
               property float y\nproperty float z\nelement strand 1\nproperty uchar nsegs\nend_header\n";
    let mut f = ply.as_bytes().to_vec();
    f.extend_from_slice(&[0; 13]);
    cases.push(("ply", "10¹² vertices", f));
    // .abc: an Ogawa data chunk claiming 2⁶⁰ bytes (ogawa-rs would allocate that before
    // reading), under a root group that lists it.
    let mut f = b"Ogawa\xff\x01\x00".to_vec();
    f.extend(16u64.to_le_bytes());
    f.extend(1u64.to_le_bytes());
    f.extend(((1u64 << 63) | 32).to_le_bytes());
    f.extend((1u64 << 60).to_le_bytes());
    f.extend([0u8; 64]);
    cases.push(("abc", "a data chunk of 2⁶⁰ bytes", f));
    // .hdr: 10⁶ × 10⁶ pixels.
    let mut f = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1000000 +X 1000000\n".to_vec();
    f.extend_from_slice(&[2, 2, 0x40, 0, 0xFF, 0]);
    cases.push(("hdr", "10⁶ × 10⁶ pixels", f));
    // .exr: a 10⁶ × 10⁶ data window in a file of a few hundred bytes.
    let map = strandlight_precompute::EnvMap::from_pixels(8, 4, vec![[0.5; 3]; 32]);
    let mut f = seeds::exr_bytes(&map, exr::prelude::Encoding::UNCOMPRESSED, true);
    let key = b"dataWindow\0box2i\0";
    let at = f.windows(key.len()).position(|w| w == key).unwrap() + key.len() + 4;
    f[at + 8..at + 16].copy_from_slice(&le(&[999_999, 999_999]));
    cases.push(("exr", "10⁶ × 10⁶ data window", f));
    // .sltab: axes of 10¹⁰ entries (metadata resealed so the claim reaches the shape check).
    let good = seeds::sltab_bytes(strandlight_tables::asset::Storage::F32);
    let len = u32::from_le_bytes(good[12..16].try_into().unwrap()) as usize;
    let mut meta: serde_json::Value = serde_json::from_slice(&good[16..16 + len]).unwrap();
    meta["payload"]["axes"][0]["count"] = serde_json::json!(100_000);
    meta["payload"]["axes"][1]["count"] = serde_json::json!(100_000);
    meta["payload"]["payload_bytes"] = serde_json::json!(4u64 * 3 * 10_000_000_000);
    let json = serde_json::to_vec(&meta).unwrap();
    let mut f = good[..12].to_vec();
    f.extend((json.len() as u32).to_le_bytes());
    f.extend(&json);
    f.extend([0u8; 32]);
    f.resize((16 + json.len() + 32).div_ceil(16) * 16, 0);
    f.extend(&good[good.len() - 3 * 2 * 3 * 4..]);
    fuzz::targets::reseal_asset(&mut f);
    cases.push(("sltab", "axes of 10¹⁰ entries", f));

    let targets = fuzz::targets::all();
    for (name, what, bytes) in cases {
        let target = targets.iter().find(|t| t.name == name).unwrap();
        let start = std::time::Instant::now();
        let (result, largest) = alloc::measure(|| (target.run)(&bytes));
        let refusal = match result {
            Err(r) => r,
            Ok(_) => panic!("{name}: {what} loaded"),
        };
        eprintln!(
            "{name} ({what}): {} in {:.1} ms, largest allocation {largest} bytes",
            refusal.message,
            start.elapsed().as_secs_f64() * 1e3
        );
        assert!(
            refusal.message.contains(target.file_name),
            "{}",
            refusal.message
        );
        assert!(
            largest < 1 << 20,
            "{name}: {what}: an allocation of {largest} bytes"
        );
    }
}
