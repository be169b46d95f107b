//! Timings of the fiber shading code and the full-size hard-case sweeps.
//!
//! `cargo run --release -p strandlight-tables --example shading_bench [-- SWEEP_SAMPLES]`
//!
//! Reports medians of repeated runs. Machines are shared and noisy: compare ratios within one
//! run (e.g. table lookup vs on-demand averages), not absolute times across machines.

use std::hint::black_box;
use std::time::Instant;
use strandlight_tables::angles::FiberAngles;
use strandlight_tables::artist::{self, ArtistModel, ArtistParams, Normalization};
use strandlight_tables::dual_scattering::{
    DualScatteringAverages, DualScatteringConfig, fiber_averages_direct,
};
use strandlight_tables::hard_case_sweep::SweepRng;
use strandlight_tables::kajiya_kay::{self, KajiyaKay, KajiyaKayParams};
use strandlight_tables::scattering::ScatteringFunction;

/// Median wall time in seconds of `runs` calls of `f`.
fn median_seconds(runs: usize, mut f: impl FnMut()) -> f64 {
    let mut t: Vec<f64> = (0..runs)
        .map(|_| {
            let start = Instant::now();
            f();
            start.elapsed().as_secs_f64()
        })
        .collect();
    t.sort_by(f64::total_cmp);
    t[t.len() / 2]
}

fn random_angles(n: usize, seed: u64) -> Vec<FiberAngles> {
    let mut rng = SweepRng::new(seed);
    (0..n)
        .map(|_| {
            FiberAngles::new(
                rng.range(-1.5, 1.5),
                rng.range(-1.5, 1.5),
                rng.range(-3.1, 3.1),
            )
        })
        .collect()
}

fn main() {
    let sweep_samples: u64 = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(1_000_000);
    let angles = random_angles(1_000_000, 1);

    let kk = KajiyaKay::new(KajiyaKayParams::default()).unwrap();
    let t = median_seconds(5, || {
        black_box(angles.iter().map(|a| kk.eval(a)[0]).sum::<f64>());
    });
    println!(
        "kajiya-kay eval: {:.1} ns/call",
        t * 1e9 / angles.len() as f64
    );

    let art = ArtistModel::new(ArtistParams::default()).unwrap();
    let t = median_seconds(5, || {
        black_box(angles.iter().map(|a| art.eval(a)[0]).sum::<f64>());
    });
    println!("artist eval: {:.1} ns/call", t * 1e9 / angles.len() as f64);

    let t = median_seconds(9, || {
        black_box(art.normalization_integral());
    });
    println!("artist eq. 13 normalization integral: {:.3} ms", t * 1e3);
    let t = median_seconds(5, || {
        black_box(art.peak_total_attenuation());
    });
    println!(
        "artist peak ā_f+ā_b over inclinations (PeakPerChannel): {:.3} ms",
        t * 1e3
    );
    let norm = art.normalized(Normalization::PerChannel);

    for (theta_samples, theta_d_samples) in [(257, 181), (513, 361), (1025, 721)] {
        let config = DualScatteringConfig {
            theta_samples,
            theta_d_samples,
            ..Default::default()
        };
        let t = median_seconds(5, || {
            black_box(DualScatteringAverages::new(&norm, config).unwrap());
        });
        println!(
            "dual-scattering averages, θ grid {theta_samples}, θ_d grid {theta_d_samples}: {:.1} ms to build",
            t * 1e3
        );
    }
    let avg = DualScatteringAverages::new(&norm, DualScatteringConfig::default()).unwrap();
    let thetas: Vec<f64> = angles.iter().map(|a| a.theta_i).collect();
    let t_lookup = median_seconds(5, || {
        black_box(
            thetas
                .iter()
                .map(|&th| avg.averages_at(th).a_f[0] + avg.moments_at(th).attenuation[0])
                .sum::<f64>(),
        );
    }) / thetas.len() as f64;
    let t_direct = median_seconds(5, || {
        black_box(
            thetas[..20]
                .iter()
                .map(|&th| fiber_averages_direct(&norm, th).a_f[0])
                .sum::<f64>(),
        );
    }) / 20.0;
    println!(
        "averages at one θ: table lookup {:.1} ns, on demand {:.3} ms (ratio {:.0}×)",
        t_lookup * 1e9,
        t_direct * 1e3,
        t_direct / t_lookup
    );
    let t = median_seconds(5, || {
        black_box(
            angles
                .iter()
                .map(|a| avg.backward_scattering(a)[0])
                .sum::<f64>(),
        );
    });
    println!("S_back eval: {:.1} ns/call", t * 1e9 / angles.len() as f64);

    for (name, run) in [
        (
            "kajiya-kay",
            kajiya_kay::hard_case_sweep as fn(u64, u64) -> _,
        ),
        ("artist", artist::hard_case_sweep),
        (
            "dual-scattering",
            strandlight_tables::dual_scattering_hard_cases::hard_case_sweep,
        ),
    ] {
        let start = Instant::now();
        let report = run(sweep_samples, 2026);
        println!("{report} ({name}: {:.2} s)", start.elapsed().as_secs_f64());
    }
}
