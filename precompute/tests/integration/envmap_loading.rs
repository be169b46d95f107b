//! Loader tests: every shared map, then synthetic files for each way a file can be bad.

use std::path::{Path, PathBuf};
use strandlight_precompute::EnvMapError;
use strandlight_precompute::envmap::EnvMap;
use strandlight_precompute::envmap_io::{LoadOptions, decode, load, write_exr};
use strandlight_precompute::radiance_hdr::encode_for_tests;
use strandlight_tables::shared_data::shared_file;

const SHARED_MAPS: [&str; 8] = [
    "hdr_overcast_soil_puresky_1k.hdr",
    "moonless_golf_1k.hdr",
    "photo_studio_01_1k.hdr",
    "piz_compressed.exr",
    "quarry_01_1k.hdr",
    "royal_esplanade_1k.hdr",
    "spruit_sunrise_1k.hdr",
    "venice_sunset_1k.hdr",
];

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("strandlight-loader-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// A small map with distinct values everywhere, so any orientation mistake shows.
fn gradient_map(w: usize, h: usize) -> EnvMap {
    let px = (0..w * h)
        .map(|i| {
            [
                (1 + i % w) as f32 * 0.25,
                (1 + i / w) as f32 * 2.0,
                0.5 + (i % 7) as f32,
            ]
        })
        .collect();
    EnvMap::from_pixels(w, h, px)
}

#[test]
fn every_shared_map_loads_and_standard_hdr_agrees_with_the_image_crate() {
    for name in SHARED_MAPS {
        let Some(path) = shared_file(&format!("envmaps/{name}")) else {
            continue;
        };
        let loaded = load(&path, LoadOptions::default()).unwrap_or_else(|e| panic!("{e}"));
        let m = &loaded.map;
        let integral = m.integral();
        eprintln!(
            "{name}: {}×{}, ∫L dω = {:.3?}, sha256 {}…",
            m.width(),
            m.height(),
            integral,
            &loaded.sha256[..12]
        );
        assert_eq!(m.width(), 2 * m.height());
        assert!(integral.iter().all(|v| v.is_finite() && *v > 0.0));
        if name.ends_with(".hdr") {
            // Independent decoder (standard -Y H +X W orientation only). Radiance's colr_color
            // adds ½ to each mantissa, the image crate does not: at most 1/256 of the pixel's
            // largest channel apart, and never below it.
            let img = image::load_from_memory(&std::fs::read(&path).unwrap())
                .unwrap()
                .into_rgb32f();
            let mut worst = 0.0f64;
            for (x, y, p) in img.enumerate_pixels() {
                let ours = m.pixel(x as usize, y as usize);
                let max = p.0.iter().fold(0.0f32, |a, &b| a.max(b)) as f64;
                for c in 0..3 {
                    let d = ours[c] as f64 - p.0[c] as f64;
                    assert!(
                        d >= -1e-30 && d <= max / 256.0 * 1.0001 + 1e-30,
                        "{name} ({x},{y}) c{c}: {ours:?} vs {:?}",
                        p.0
                    );
                    if max > 0.0 {
                        worst = worst.max(d / max);
                    }
                }
            }
            eprintln!("  vs image crate: largest difference {worst:.5} of the pixel's max channel");
        }
    }
}

#[test]
fn exr_channels_are_matched_by_name() {
    // piz_compressed.exr stores B, G, R: red must come from the channel named R.
    let Some(path) = shared_file("envmaps/piz_compressed.exr") else {
        return;
    };
    let ours = load(&path, LoadOptions::default()).unwrap().map;
    let flat = exr::prelude::read_all_flat_layers_from_file(&path).unwrap();
    let layer = &flat.layer_data[0];
    let names: Vec<String> = layer
        .channel_data
        .list
        .iter()
        .map(|c| c.name.to_string())
        .collect();
    eprintln!("piz_compressed.exr channels in file order: {names:?}");
    let w = layer.size.width();
    for (c, want) in ["R", "G", "B"].iter().enumerate() {
        let ch = layer
            .channel_data
            .list
            .iter()
            .find(|ch| ch.name.to_string() == *want)
            .unwrap();
        for i in (0..layer.size.area()).step_by(997) {
            let v = ch.sample_data.value_by_flat_index(i).to_f32();
            assert_eq!(ours.pixel(i % w, i / w)[c], v, "channel {want} pixel {i}");
        }
    }
}

#[test]
fn every_radiance_orientation_and_encoding_decodes_to_the_same_image() {
    let map = gradient_map(32, 16);
    let reference = decode(
        Path::new("ref.hdr"),
        &encode_for_tests(&map, "-Y 16 +X 32", false),
    )
    .unwrap();
    for res in [
        "-Y 16 +X 32",
        "-Y 16 -X 32",
        "+Y 16 +X 32",
        "+Y 16 -X 32",
        "+X 32 -Y 16",
        "+X 32 +Y 16",
        "-X 32 -Y 16",
        "-X 32 +Y 16",
    ] {
        for rle in [false, true] {
            let got = decode(Path::new("t.hdr"), &encode_for_tests(&map, res, rle)).unwrap();
            assert_eq!(got, reference, "{res} rle={rle}");
        }
    }
    // Quantization only: RGBE keeps 8 bits of mantissa.
    for (a, b) in map.pixels().iter().zip(reference.pixels()) {
        for c in 0..3 {
            assert!((a[c] - b[c]).abs() <= a[0].max(a[1]).max(a[2]) / 128.0);
        }
    }
}

#[test]
fn old_style_run_length_and_unknown_header_lines() {
    // 2×1 would not be 2:1-checked here (decode only): one row of 4 pixels, the last 3 a run.
    let mut bytes =
        b"#?RADIANCE\n# a comment\nSOFTWARE=hand made\nEXPOSURE=1.0\n\n-Y 1 +X 4\n".to_vec();
    bytes.extend_from_slice(&[128, 64, 32, 129]); // (128+½, 64+½, 32+½) · 2^(129−136)
    bytes.extend_from_slice(&[1, 1, 1, 3]);
    let m = decode(Path::new("old.hdr"), &bytes).unwrap();
    let want = [128.5 / 128.0, 64.5 / 128.0, 32.5 / 128.0];
    for x in 0..4 {
        assert_eq!(m.pixel(x, 0), want.map(|v| v as f32), "pixel {x}");
    }
}

#[test]
fn each_bad_file_gives_its_own_error() {
    let good = encode_for_tests(&gradient_map(16, 8), "-Y 8 +X 16", true);
    let p = Path::new("bad.hdr");
    let err = |bytes: &[u8]| decode(p, bytes).unwrap_err();
    assert!(matches!(err(b""), EnvMapError::UnknownFormat { .. }));
    assert!(matches!(
        err(b"P6\n1 1\n255\n"),
        EnvMapError::UnknownFormat { .. }
    ));
    let e = err(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n");
    assert!(
        matches!(&e, EnvMapError::RadianceHeader { problem, .. } if problem.contains("never ends")),
        "{e}"
    );
    let e = err(b"#?RADIANCE\nFORMAT=32-bit_rle_xyze\n\n-Y 8 +X 16\n");
    assert!(
        matches!(&e, EnvMapError::RadianceHeader { problem, .. } if problem.contains("xyze")),
        "{e}"
    );
    let e = err(b"#?RADIANCE\n\n-Y eight +X 16\n");
    assert!(
        matches!(&e, EnvMapError::RadianceHeader { problem, .. } if problem.contains("resolution")),
        "{e}"
    );
    let e = err(&good[..good.len() - 20]);
    assert!(
        matches!(
            e,
            EnvMapError::Truncated {
                scanline: 7,
                scanlines: 8,
                ..
            }
        ),
        "{e}"
    );
    // A header that promises a million-pixel-square image in a few bytes.
    let e = err(b"#?RADIANCE\n\n-Y 1000000 +X 1000000\n\x02\x02");
    assert!(
        matches!(
            e,
            EnvMapError::ImpossibleSize {
                width: 1_000_000,
                height: 1_000_000,
                ..
            }
        ),
        "{e}"
    );
    // A run longer than the scanline.
    let mut corrupt = b"#?RADIANCE\n\n-Y 1 +X 8\n".to_vec();
    corrupt.extend_from_slice(&[2, 2, 0, 8, 128 + 9, 7]);
    let e = err(&corrupt);
    assert!(
        matches!(e, EnvMapError::CorruptScanline { scanline: 0, .. }),
        "{e}"
    );
    eprintln!("example message: {e}");

    // Through `load` (needs files): wrong aspect, missing file, NaN pixels.
    let square = scratch("square.hdr");
    std::fs::write(
        &square,
        encode_for_tests(&gradient_map(8, 8), "-Y 8 +X 8", false),
    )
    .unwrap();
    let e = load(&square, LoadOptions::default()).unwrap_err();
    assert!(
        matches!(
            e,
            EnvMapError::NotTwoToOne {
                width: 8,
                height: 8,
                ..
            }
        ),
        "{e}"
    );
    eprintln!("example message: {e}");
    let e = load(&scratch("missing.hdr"), LoadOptions::default()).unwrap_err();
    assert!(matches!(e, EnvMapError::Io { .. }), "{e}");
}

#[test]
fn bad_pixels_are_refused_or_sanitized_with_counts() {
    let mut px = vec![[1.0f32, 2.0, 3.0]; 16 * 8];
    px[3] = [f32::NAN, 1.0, 1.0];
    px[4] = [f32::INFINITY, 1.0, f32::NAN];
    px[5] = [-2.0, f32::NEG_INFINITY, 1.0];
    px[6] = [50.0, 1.0, 1.0];
    let path = scratch("nan.exr");
    write_exr(&EnvMap::from_pixels(16, 8, px), &path).unwrap();
    let e = load(&path, LoadOptions::default()).unwrap_err();
    eprintln!("refused: {e}");
    let EnvMapError::BadPixels { counts, path: p } = e else {
        panic!("wrong error {e}")
    };
    assert_eq!(p, path);
    assert_eq!(
        (
            counts.nan,
            counts.positive_infinity,
            counts.negative_infinity,
            counts.negative
        ),
        (2, 1, 1, 1)
    );
    let ok = load(&path, LoadOptions { sanitize: true }).unwrap();
    assert_eq!(ok.sanitized, counts);
    assert_eq!(ok.map.pixel(3, 0), [0.0, 1.0, 1.0]);
    assert_eq!(
        ok.map.pixel(4, 0),
        [50.0, 1.0, 0.0],
        "+Inf becomes the largest finite value"
    );
    assert_eq!(ok.map.pixel(5, 0), [0.0, 0.0, 1.0]);
    assert_eq!(ok.map.bad_pixels().total(), 0);
}

#[test]
fn exr_round_trip_and_corrupt_exr() {
    let map = gradient_map(16, 8);
    let path = scratch("round.exr");
    write_exr(&map, &path).unwrap();
    assert_eq!(load(&path, LoadOptions::default()).unwrap().map, map);
    let bytes = std::fs::read(&path).unwrap();
    let cut = scratch("cut.exr");
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    let e = load(&cut, LoadOptions::default()).unwrap_err();
    eprintln!("truncated EXR: {e}");
    assert!(matches!(e, EnvMapError::Exr { .. }));
}
