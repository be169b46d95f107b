//! USD and Alembic grooms written by writers this project did not write (Pixar's `usd-core`,
//! PyAlembic) load with every strand where the writer's own library puts it: the scripts in
//! `tests/scripts/` compute the world-space points with usd-core's
//! `ComputeLocalToWorldTransform` and Alembic's `XformSample.getMatrix`, and the loaders must
//! agree strand by strand, with the per-strand widths and per-point colours. Damaged copies of
//! the same files are refused with the error that names the problem.
//!
//! Needs `pip install usd-core alembic3d` (skips without; fails under
//! `STRANDLIGHT_REQUIRE_TOOLS=1`).

use std::path::{Path, PathBuf};

use strandlight_runtime::hair::{self, Attribute, HairError, HairFormat, LoadedHair};
use strandlight_tests::scene_grooms::{ExpectedStrand, Writer, expected};

fn out_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!(
        "strandlight-scene-grooms-{name}-{}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// Positions agree to float precision of the groom's size, widths and colours to f32's.
fn assert_matches(loaded: &LoadedHair, want: &[ExpectedStrand], file: &Path) {
    let m = &loaded.model;
    assert_eq!(
        m.strand_count(),
        want.len(),
        "{}: strands ({})",
        file.display(),
        loaded.report.info
    );
    let size = m.bounds().diagonal() as f64;
    let mut worst = 0.0f64;
    for (s, strand) in want.iter().enumerate() {
        let ours = m.strand(s);
        assert_eq!(
            ours.len(),
            strand.points.len(),
            "{}: strand {s}",
            file.display()
        );
        let first = m.strand_offsets()[s] as usize;
        for (i, (p, q)) in ours.iter().zip(&strand.points).enumerate() {
            let d = (0..3)
                .map(|c| (p[c] as f64 - q[c]).powi(2))
                .sum::<f64>()
                .sqrt();
            worst = worst.max(d / size);
            assert!(
                d <= 1e-5 * size,
                "{}: strand {s} point {i}: ours {p}, the writer's {q:?}",
                file.display()
            );
            let width = m.thickness().expect("widths are read").at(first + i) as f64;
            assert!(
                (width - strand.width).abs() <= 1e-5 * strand.width,
                "{}: strand {s} point {i}: width {width}, the writer's {}",
                file.display(),
                strand.width
            );
            if let Some(colors) = &strand.colors {
                let c = m.color().expect("colours are read").at(first + i);
                for k in 0..3 {
                    assert!(
                        (c[k] as f64 - colors[i][k]).abs() < 1e-6,
                        "{}: strand {s} point {i}: colour {c}, the writer's {:?}",
                        file.display(),
                        colors[i]
                    );
                }
            }
        }
    }
    eprintln!(
        "{}: {} strands, {} points match the writer's within {worst:.1e} of the groom's size; {}",
        file.display(),
        m.strand_count(),
        m.point_count(),
        loaded.report.info
    );
}

#[test]
fn usd_core_grooms_load_where_usd_core_puts_them() {
    let dir = out_dir("usd");
    if !Writer::UsdCore.write(&dir, &[]) {
        return;
    }
    let want = expected(&dir);
    for ext in ["usda", "usdc", "usdz"] {
        let file = dir.join(format!("groom.{ext}"));
        let loaded = hair::load(&file).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(loaded.report.format, HairFormat::Usd);
        assert_matches(&loaded, &want, &file);
        // The linear prim's colours are per vertex; the cubic prim has none and gets Hydra's
        // grey, so the model's colour is per point.
        assert!(matches!(loaded.model.color(), Some(Attribute::PerPoint(_))));
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn alembic_grooms_load_where_alembic_puts_them() {
    let dir = out_dir("abc");
    if !Writer::Alembic.write(&dir, &[]) {
        return;
    }
    let want = expected(&dir);
    let file = dir.join("groom.abc");
    let loaded = hair::load(&file).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(loaded.report.format, HairFormat::Alembic);
    assert_matches(&loaded, &want, &file);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Writes `bytes` as `name` in `dir` and loads it.
fn load_bytes(dir: &Path, name: &str, bytes: &[u8]) -> Result<LoadedHair, HairError> {
    let file = dir.join(name);
    std::fs::write(&file, bytes).unwrap();
    hair::load(&file)
}

#[test]
fn damaged_usd_and_alembic_files_are_refused_with_the_file_named() {
    let dir = out_dir("damaged");
    if !Writer::UsdCore.write(&dir, &[]) || !Writer::Alembic.write(&dir, &[]) {
        return;
    }
    for name in ["groom.usdc", "groom.usdz", "groom.abc"] {
        let good = std::fs::read(dir.join(name)).unwrap();
        let ext = name.rsplit('.').next().unwrap();
        for (what, bytes) in [
            ("half", good[..good.len() / 2].to_vec()),
            ("first 20 bytes", good[..20].to_vec()),
            ("garbage", b"this is not a scene file at all".repeat(8)),
            ("empty", Vec::new()),
        ] {
            let cut = format!("{what}.{ext}").replace(' ', "-");
            let e = match load_bytes(&dir, &cut, &bytes) {
                Ok(l) => panic!("{name} {what}: loaded {}", l.model.summary()),
                Err(e) => e,
            };
            eprintln!("{name} {what}: {e}");
            assert!(e.to_string().contains(&cut), "{e}");
            assert!(
                matches!(
                    e,
                    HairError::Decode { .. }
                        | HairError::Truncated { .. }
                        | HairError::BadMagic { .. }
                ),
                "{name} {what}: {e:?}"
            );
        }
    }
    // Alembic: counts that do not sum to the points, NaN points, and no curves at all.
    for (args, want) in [
        ("--bad-counts", "BadCurves"),
        ("--nan-point", "NonFinite"),
        ("--no-curves", "NoCurves"),
    ] {
        let case = dir.join(args.trim_start_matches('-'));
        assert!(Writer::Alembic.write(&case, &[args]));
        let e = hair::load(&case.join("groom.abc")).unwrap_err();
        eprintln!("alembic {args}: {e}");
        assert!(format!("{e:?}").starts_with(want), "{args}: {e:?}");
        assert!(e.to_string().contains("groom.abc"), "{e}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
