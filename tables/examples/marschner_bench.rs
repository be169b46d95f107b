//! Per-evaluation cost of the Marschner model and the NaN/Inf hard-case sweep at scale.
//!
//! `cargo run --release -p strandlight-tables --example marschner_bench -- [evals] [sweep_samples]`
//! (defaults 10⁶ and 10⁶; the sweep is meant to be run with 10⁸ as a benchmark).

use std::f64::consts::PI;
use std::hint::black_box;
use std::time::Instant;
use strandlight_tables::longitudinal::LongitudinalModel;
use strandlight_tables::marschner::{Lobe, Marschner, MarschnerParams, hard_case_sweep};
use strandlight_tables::{FiberAngles, ScatteringFunction};

fn main() {
    let mut args = std::env::args().skip(1);
    let evals: u64 = args
        .next()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1_000_000);
    let sweep: u64 = args
        .next()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1_000_000);

    // A fixed low-discrepancy set of angles (golden-ratio sequences), so runs compare.
    let angles: Vec<FiberAngles> = (0..4096u64)
        .map(|k| {
            let f = |a: f64| (k as f64 * a).fract();
            FiberAngles::new(
                (f(0.618_033_988_7) - 0.5) * PI,
                (f(0.754_877_666_2) - 0.5) * PI,
                (2.0 * f(0.569_840_290_9) - 1.0) * PI,
            )
        })
        .collect();
    for model in [LongitudinalModel::Gaussian, LongitudinalModel::DEon] {
        let m = Marschner::new(MarschnerParams {
            longitudinal_model: model,
            ..MarschnerParams::default()
        })
        .expect("default parameters are valid");
        let mut times = vec![];
        for _ in 0..5 {
            let t = Instant::now();
            let mut acc = 0.0;
            for i in 0..evals {
                acc += m.eval(&angles[(i % 4096) as usize])[0];
            }
            black_box(acc);
            times.push(t.elapsed().as_secs_f64() * 1e9 / evals as f64);
        }
        times.sort_by(f64::total_cmp);
        let t = Instant::now();
        let mut acc = 0.0;
        for i in 0..evals {
            let a = &angles[(i % 4096) as usize];
            acc += m.azimuthal(Lobe::TRT, a.theta_d(), a.phi)[0];
        }
        black_box(acc);
        let trt = t.elapsed().as_secs_f64() * 1e9 / evals as f64;
        println!(
            "{model:?}: eval median {:.1} ns (min {:.1}, max {:.1}) over 5×{evals}; N_TRT alone {trt:.1} ns",
            times[2], times[0], times[4]
        );
    }
    let t = Instant::now();
    let r = hard_case_sweep(sweep, 0x5eed);
    println!(
        "hard-case sweep, {} samples in {:.2} s: {r:#?}",
        sweep,
        t.elapsed().as_secs_f64()
    );
    if !r.is_clean() {
        std::process::exit(1);
    }
}
