//! Bakes and fits must not depend on how many threads run them: a table baked on a laptop and on
//! a 64-core farm machine, or a fit cached by one and served to the other, must be the same bits
//! (the caches are keyed by inputs, not by machine). Each case runs under rayon pools of 1, 2 and
//! 8 threads and compares every output bit.

use strandlight_precompute::bake::bake_job;
use strandlight_precompute::bake_plan::{BakeResolution, FiberDescription, PlanOptions, plan};
use strandlight_precompute::compact_sources::SourceOptions;
use strandlight_precompute::procedural_env::SunSky;
use strandlight_precompute::srbf_fit::FitOptions;
use strandlight_precompute::srbf_set::{Source, SrbfSet};
use strandlight_tables::asset::{Storage, read_asset};

const THREAD_COUNTS: [usize; 3] = [1, 2, 8];

fn in_pool<T: Send>(threads: usize, work: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(work)
}

/// Every table of every model (a reduced resolution: the code paths are those of a full bake),
/// identified by name and the SHA-256 of its payload.
fn bake_all(threads: usize) -> Vec<(String, String)> {
    let dir = std::env::temp_dir().join(format!(
        "strandlight-determinism-{threads}-{}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&dir);
    let options = PlanOptions {
        resolution: BakeResolution::reduced(6),
        force_multiple: true,
        ..PlanOptions::default()
    };
    let jobs = plan(&FiberDescription::preset("blonde").unwrap(), &options)
        .unwrap()
        .jobs;
    let digests = in_pool(threads, || {
        jobs.into_iter()
            .map(|job| {
                let baked = bake_job(job, &dir, Storage::F32).unwrap();
                let asset = read_asset(&baked.path).unwrap();
                (baked.name, asset.metadata.payload.sha256)
            })
            .collect()
    });
    std::fs::remove_dir_all(&dir).unwrap();
    digests
}

#[test]
fn bakes_are_bit_identical_across_thread_counts() {
    let runs: Vec<_> = THREAD_COUNTS.iter().map(|&t| bake_all(t)).collect();
    assert!(runs[0].len() >= 10, "every model's tables: {:?}", runs[0]);
    for (threads, run) in THREAD_COUNTS.iter().zip(&runs).skip(1) {
        for (one, other) in runs[0].iter().zip(run) {
            assert_eq!(
                one, other,
                "{} differs between 1 and {threads} threads",
                one.0
            );
        }
    }
    println!(
        "{} tables, identical payloads with {THREAD_COUNTS:?} threads",
        runs[0].len()
    );
}

#[test]
fn fits_with_a_compact_sun_are_bit_identical_across_thread_counts() {
    // The full fit as `strandlight fit` runs it: the sun found and fitted as a compact source,
    // then the SRBF rounds on the rest.
    let map = SunSky::default().to_map(128);
    let options = FitOptions {
        initial_lobes: 4,
        max_lobes: 8,
        target_relative_mse: 0.0,
        grid_width: 64,
        lambda_max: 64.0, // λ ≤ grid_width²/64
        sources: SourceOptions::default(),
        ..FitOptions::default()
    };
    let source = Source {
        map: &map,
        name: "sun-sky".into(),
        sha256: String::new(),
        sanitized: Default::default(),
    };
    let fits: Vec<SrbfSet> = THREAD_COUNTS
        .iter()
        .map(|&t| in_pool(t, || SrbfSet::fit(&source, &options, &mut |_| {}).unwrap()))
        .collect();
    let bits = |set: &SrbfSet| serde_json::to_string(&set.lobes).unwrap();
    for (threads, fit) in THREAD_COUNTS.iter().zip(&fits).skip(1) {
        assert_eq!(fits[0].lobes.len(), fit.lobes.len(), "{threads} threads");
        for (a, b) in fits[0].lobes.iter().zip(&fit.lobes) {
            let same = a
                .center
                .iter()
                .chain(&a.amplitude)
                .zip(b.center.iter().chain(&b.amplitude))
                .all(|(x, y)| x.to_bits() == y.to_bits())
                && a.lambda.to_bits() == b.lambda.to_bits();
            assert!(
                same,
                "a lobe differs between 1 and {threads} threads:\n{a:?}\n{b:?}"
            );
        }
        assert_eq!(bits(&fits[0]), bits(fit));
    }
    println!(
        "{} lobes, identical with {THREAD_COUNTS:?} threads",
        fits[0].lobes.len()
    );
}
