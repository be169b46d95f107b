//! Our HDR-FLIP (`strandlight_eval::hdr_flip`: NVIDIA's LDR-FLIP through `nv-flip`, with the
//! exposure bracket written here and 8-bit tone-mapped exposures) against NVIDIA's own HDR-FLIP,
//! the `flip-evaluator` Python package (v1.7, float throughout), on the same image pairs with the
//! same exposure bracket. Skips with a message where python3 or the package is missing
//! (`pip install flip-evaluator`; `.ci/run` installs it).

use std::path::Path;
use std::process::Command;
use strandlight_eval::hdr_flip::{PIXELS_PER_DEGREE, hdr_flip};
use strandlight_scene::image_metrics::{HAIR_ALPHA, Image};
use strandlight_tables::outside_tools::{python, require_python_modules};

const NVIDIA_HDR_FLIP: &str = r#"
import sys, numpy as np, flip_evaluator as flip
w, h, start, stop, n, ppd = int(sys.argv[1]), int(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4]), int(sys.argv[5]), float(sys.argv[6])
load = lambda p: np.fromfile(p, dtype='<f4').reshape(h, w, 3)
error, mean, _ = flip.evaluate(load(sys.argv[7]), load(sys.argv[8]), "HDR", applyMagma=False,
    parameters={"ppd": ppd, "startExposure": start, "stopExposure": stop, "numExposures": n, "tonemapper": "ACES"})
np.asarray(error, dtype='<f4').reshape(h, w).tofile(sys.argv[9])
"#;

fn write_rgb(path: &Path, image: &Image) {
    let bytes: Vec<u8> = image
        .pixels
        .iter()
        .flat_map(|p| p[..3].iter().flat_map(|c| c.to_le_bytes()))
        .collect();
    std::fs::write(path, bytes).unwrap();
}

/// A deterministic value in [0, 1) per integer.
fn hash(k: u32) -> f32 {
    let mut z = (k as u64).wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    ((z ^ (z >> 31)) >> 40) as f32 / (1u64 << 24) as f32
}

/// Hair-like test images on black: near-vertical fibers of varying brightness over three
/// decades with a highlight band at `highlight_row`, radiance noise of `noise` (relative).
fn fibers(highlight_row: f32, noise: f32, seed: u32) -> Image {
    let (w, h) = (160u32, 120u32);
    let pixels = (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            if !(20..140).contains(&x) || !(10..110).contains(&y) {
                return [0.0; 4];
            }
            let fiber = (x + y / 12) / 2;
            let base = 0.02 + 2.0 * hash(fiber).powi(3);
            let band = 6.0 * (-((y as f32 - highlight_row) / 6.0).powi(2)).exp();
            let n = 1.0 + noise * (2.0 * hash(i.wrapping_mul(7).wrapping_add(seed)) - 1.0);
            let v = (base + band) * n;
            [v, 0.75 * v, 0.5 * v, 1.0]
        })
        .collect();
    Image::new(w, h, pixels)
}

#[test]
fn our_hdr_flip_matches_nvidias_float_implementation() {
    if !require_python_modules(&["flip_evaluator", "numpy"], "pip install flip-evaluator") {
        return;
    }
    let dir = std::env::temp_dir().join(format!("strandlight-flip-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let reference = fibers(40.0, 0.0, 0);
    let cases = [
        ("noise 10%", fibers(40.0, 0.1, 1)),
        ("noise 40%", fibers(40.0, 0.4, 2)),
        ("highlight moved 8 px", fibers(48.0, 0.0, 0)),
        ("2× brighter", {
            let mut b = reference.clone();
            b.pixels
                .iter_mut()
                .for_each(|p| p[..3].iter_mut().for_each(|c| *c *= 2.0));
            b
        }),
    ];
    let (ref_path, test_path, out_path) = (
        dir.join("reference.f32"),
        dir.join("test.f32"),
        dir.join("error.f32"),
    );
    write_rgb(&ref_path, &reference);
    let hair: Vec<bool> = reference.pixels.iter().map(|p| p[3] > HAIR_ALPHA).collect();
    for (name, test) in &cases {
        let ours = hdr_flip(test, &reference).unwrap();
        write_rgb(&test_path, test);
        let status = Command::new(python())
            .args(["-c", NVIDIA_HDR_FLIP])
            .arg(reference.width.to_string())
            .arg(reference.height.to_string())
            .arg(ours.start_exposure.to_string())
            .arg(ours.stop_exposure.to_string())
            .arg(ours.exposures.to_string())
            .arg(PIXELS_PER_DEGREE.to_string())
            .args([&ref_path, &test_path, &out_path])
            .status()
            .unwrap();
        assert!(status.success(), "{name}: NVIDIA's HDR-FLIP failed");
        let theirs: Vec<f32> = std::fs::read(&out_path)
            .unwrap()
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .collect();
        let (mut sum_ours, mut sum_theirs, mut sum_abs, mut n) = (0.0f64, 0.0f64, 0.0f64, 0.0);
        for ((a, b), h) in ours.error_map.iter().zip(&theirs).zip(&hair) {
            if *h {
                sum_ours += *a as f64;
                sum_theirs += *b as f64;
                sum_abs += (a - b).abs() as f64;
                n += 1.0;
            }
        }
        let (mean_ours, mean_theirs, mean_abs) = (sum_ours / n, sum_theirs / n, sum_abs / n);
        eprintln!(
            "{name}: mean over hair ours {mean_ours:.4}, NVIDIA {mean_theirs:.4}; mean |Δ| per pixel {mean_abs:.4} ({} exposures from {:.2} to {:.2})",
            ours.exposures, ours.start_exposure, ours.stop_exposure
        );
        assert!((mean_ours - ours.mean_over_hair).abs() < 1e-9);
        assert!(
            (mean_ours - mean_theirs).abs() < 0.01 + 0.03 * mean_theirs,
            "{name}: {mean_ours} vs {mean_theirs}"
        );
        assert!(mean_abs < 0.02, "{name}: per-pixel |Δ| {mean_abs}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
