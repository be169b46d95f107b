//! Hard-case sweeps: evaluate a model at many random parameter sets and angles, concentrated
//! where the formulas are fragile (θ → ±90°, very narrow lobes, very dark and very bright
//! colors), and count every non-finite or negative value. Each model module exposes
//! `hard_case_sweep(samples, seed) -> SweepReport`; tests assert a clean report and print it,
//! and a benchmark CLI can call the same functions.
//!
//! The generator is the crate's [`SplitMix64`] so that the library needs no `rand` dependency
//! and a sweep is reproducible from its seed alone.

use crate::split_mix::SplitMix64;
use std::f64::consts::{FRAC_PI_2, PI};
use std::fmt;

/// Counts of what a sweep saw. `samples` counts scalar values checked (an RGB value is three).
#[derive(Debug, Clone, PartialEq)]
pub struct SweepReport {
    pub name: String,
    pub samples: u64,
    pub nan: u64,
    pub infinite: u64,
    pub negative: u64,
    /// Largest finite value seen (useful to spot values that are finite but absurd).
    pub max_finite: f64,
    /// Random parameter sets the model refused with a typed error (not a failure).
    pub rejected: u64,
}

impl SweepReport {
    pub fn new(name: impl Into<String>) -> Self {
        Self {
            name: name.into(),
            samples: 0,
            nan: 0,
            infinite: 0,
            negative: 0,
            max_finite: 0.0,
            rejected: 0,
        }
    }

    /// Records one value that must be finite and non-negative.
    pub fn record(&mut self, v: f64) {
        self.samples += 1;
        if v.is_nan() {
            self.nan += 1;
        } else if v.is_infinite() {
            self.infinite += 1;
        } else {
            if v < 0.0 {
                self.negative += 1;
            }
            self.max_finite = self.max_finite.max(v);
        }
    }

    /// Records a value that may be negative (a signed angle) but must be finite.
    pub fn record_signed(&mut self, v: f64) {
        self.record(v.abs());
    }

    pub fn record_rgb(&mut self, v: [f64; 3]) {
        v.iter().for_each(|&x| self.record(x));
    }

    /// True when no NaN, Inf or negative value was seen.
    pub fn is_clean(&self) -> bool {
        self.nan == 0 && self.infinite == 0 && self.negative == 0
    }

    pub fn merge(&mut self, other: &SweepReport) {
        self.samples += other.samples;
        self.nan += other.nan;
        self.infinite += other.infinite;
        self.negative += other.negative;
        self.max_finite = self.max_finite.max(other.max_finite);
        self.rejected += other.rejected;
    }
}

impl fmt::Display for SweepReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}: {} values, {} NaN, {} Inf, {} negative, max finite {:.3e}, {} parameter sets rejected",
            self.name,
            self.samples,
            self.nan,
            self.infinite,
            self.negative,
            self.max_finite,
            self.rejected
        )
    }
}

/// [`SplitMix64`] with the samplers of hard cases the sweeps draw.
#[derive(Debug, Clone)]
pub struct SweepRng(SplitMix64);

impl SweepRng {
    pub fn new(seed: u64) -> Self {
        Self(SplitMix64::new(seed ^ 0x9E37_79B9_7F4A_7C15))
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0.next_u64()
    }

    /// Uniform in [0, 1).
    pub fn uniform(&mut self) -> f64 {
        self.0.uniform()
    }

    pub fn range(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.uniform()
    }

    /// Log-uniform in [a, b] (both > 0): as many very small as very large values.
    pub fn log_range(&mut self, a: f64, b: f64) -> f64 {
        (a.ln() + (b.ln() - a.ln()) * self.uniform()).exp()
    }

    /// An inclination in [−π/2, π/2] that is exactly ±π/2, within 10⁻¹²..10⁻¹ of it, or
    /// uniform, in roughly equal shares.
    pub fn hard_inclination(&mut self) -> f64 {
        let sign = if self.uniform() < 0.5 { -1.0 } else { 1.0 };
        match self.next_u64() % 4 {
            0 => sign * FRAC_PI_2,
            1 => sign * (FRAC_PI_2 - self.log_range(1e-12, 1e-1)),
            _ => self.range(-FRAC_PI_2, FRAC_PI_2),
        }
    }

    /// A relative azimuth in (−π, π], with extra weight on 0, ±π/2 and ±π.
    pub fn hard_azimuth(&mut self) -> f64 {
        match self.next_u64() % 6 {
            0 => [0.0, FRAC_PI_2, -FRAC_PI_2, PI][(self.next_u64() % 4) as usize],
            1 => PI - self.log_range(1e-12, 1e-1),
            _ => self.range(-PI, PI),
        }
    }

    /// A color channel that is often exactly 0 or 1, or extremely dark.
    pub fn hard_channel(&mut self) -> f64 {
        match self.next_u64() % 5 {
            0 => 0.0,
            1 => 1.0,
            2 => self.log_range(1e-9, 1e-2),
            _ => self.uniform(),
        }
    }

    pub fn hard_color(&mut self) -> [f64; 3] {
        [
            self.hard_channel(),
            self.hard_channel(),
            self.hard_channel(),
        ]
    }
}

/// Seed of chunk `index` of a sweep seeded `seed`: one SplitMix64 step from a mix of both, so
/// neighbouring chunks (and neighbouring seeds) draw unrelated streams.
pub fn chunk_seed(seed: u64, index: u64) -> u64 {
    SweepRng::new(seed ^ index.wrapping_mul(0xD1B5_4A32_D192_ED03)).next_u64()
}

/// Runs `sweep(samples, seed)` as chunks of at most `chunk` requested samples, in parallel on
/// the rayon pool, and merges the chunk reports in chunk order. Chunk `k` is seeded
/// [`chunk_seed`]`(seed, k)`, so the result depends on `samples`, `seed` and `chunk` only, never
/// on the number of threads. `on_chunk(n)` is called (from any thread) after each chunk of `n`
/// requested samples, for progress display.
pub fn chunked_sweep(
    name: &str,
    samples: u64,
    seed: u64,
    chunk: u64,
    sweep: impl Fn(u64, u64) -> SweepReport + Sync,
    on_chunk: impl Fn(u64) + Sync,
) -> SweepReport {
    use rayon::prelude::*;
    let chunk = chunk.max(1);
    let reports: Vec<SweepReport> = (0..samples.div_ceil(chunk))
        .into_par_iter()
        .map(|k| {
            let n = chunk.min(samples - k * chunk);
            let report = sweep(n, chunk_seed(seed, k));
            on_chunk(n);
            report
        })
        .collect();
    let mut total = SweepReport::new(name);
    reports.iter().for_each(|r| total.merge(r));
    total
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uniform_has_the_right_mean_and_range() {
        let mut rng = SweepRng::new(7);
        let n = 200_000;
        let mut sum = 0.0;
        for _ in 0..n {
            let u = rng.uniform();
            assert!((0.0..1.0).contains(&u));
            sum += u;
        }
        let mean = sum / n as f64;
        // Standard error of the mean of U(0,1) over n draws is 1/sqrt(12 n) ≈ 6.5e-4.
        println!("SplitMix64 mean of {n} uniforms: {mean:.5}");
        assert!((mean - 0.5).abs() < 4e-3);
    }

    #[test]
    fn report_counts_each_kind() {
        let mut r = SweepReport::new("t");
        for v in [1.0, f64::NAN, f64::INFINITY, -2.0, 3.0] {
            r.record(v);
        }
        assert_eq!((r.samples, r.nan, r.infinite, r.negative), (5, 1, 1, 1));
        assert_eq!(r.max_finite, 3.0);
        assert!(!r.is_clean());
    }

    /// A stand-in sweep whose report is a pure function of (samples, seed): the chunked
    /// result must equal the in-order merge of the chunks run one by one, on any pool.
    fn toy_sweep(samples: u64, seed: u64) -> SweepReport {
        let mut r = SweepReport::new("toy");
        let mut rng = SweepRng::new(seed);
        for _ in 0..samples {
            r.record(rng.log_range(1e-3, 1e3));
        }
        r
    }

    #[test]
    fn chunked_sweep_is_independent_of_the_thread_count() {
        let (samples, seed, chunk) = (10_007u64, 42u64, 1_000u64);
        let mut serial = SweepReport::new("toy");
        for k in 0..samples.div_ceil(chunk) {
            serial.merge(&toy_sweep(
                chunk.min(samples - k * chunk),
                chunk_seed(seed, k),
            ));
        }
        for threads in [1, 2, 5] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let counted = std::sync::atomic::AtomicU64::new(0);
            let r = pool.install(|| {
                chunked_sweep("toy", samples, seed, chunk, toy_sweep, |n| {
                    counted.fetch_add(n, std::sync::atomic::Ordering::Relaxed);
                })
            });
            println!("{threads} threads: {r}");
            assert_eq!(r, serial);
            assert_eq!(r.samples, samples);
            assert_eq!(counted.into_inner(), samples);
        }
        // Different chunks must draw different streams (a repeated seed would repeat maxima).
        assert_ne!(chunk_seed(seed, 0), chunk_seed(seed, 1));
    }
}
