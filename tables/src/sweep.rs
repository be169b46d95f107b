//! Hard-case sweeps: evaluate a model at many random parameter sets and angles, concentrated
//! where the formulas are fragile (θ → ±90°, very narrow lobes, very dark and very bright
//! colors), and count every non-finite or negative value. Each model module exposes
//! `hard_case_sweep(samples, seed) -> SweepReport`; tests assert a clean report and print it,
//! and a benchmark CLI can call the same functions.
//!
//! The generator is a self-contained SplitMix64 so that the library needs no `rand` dependency
//! and a sweep is reproducible from its seed alone.

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

/// SplitMix64 (Steele, Lea, Flood 2014): tiny, fast, and good enough for test sampling.
#[derive(Debug, Clone)]
pub struct SweepRng(u64);

impl SweepRng {
    pub fn new(seed: u64) -> Self {
        Self(seed ^ 0x9E37_79B9_7F4A_7C15)
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
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
}
