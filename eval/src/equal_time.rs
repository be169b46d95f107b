//! The equal-time baseline (Ren 2010 §8, Fig. 6): how many median-cut directional lights render
//! in the time of the SRBF frame. Each measurement is a render (slow on a software GPU), so the
//! search spends few: doubling (or halving) until the target time is bracketed, then bisection
//! on the light count down to a relative width.

/// The search's answer and every measurement it took, in order.
#[derive(Debug, Clone, PartialEq)]
pub struct EqualTime {
    /// The light count whose measured time is closest to the target.
    pub lights: usize,
    pub milliseconds: f64,
    /// (light count, measured milliseconds) in the order measured.
    pub measurements: Vec<(usize, f64)>,
    /// True when even `max_lights` rendered faster than the target (or `1` slower): the answer
    /// is that bound, not a match.
    pub at_bound: bool,
}

/// Bounds of the search.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EqualTimeSearch {
    pub target_ms: f64,
    /// First count tried.
    pub start: usize,
    pub max_lights: usize,
    /// Stop bisecting when the bracket [lo, hi] has hi − lo ≤ relative_width · lo (or 1).
    pub relative_width: f64,
    /// At most this many measurements in all.
    pub max_measurements: usize,
}

impl EqualTimeSearch {
    pub fn new(target_ms: f64) -> Self {
        Self {
            target_ms,
            start: 16,
            max_lights: 8192,
            relative_width: 0.1,
            max_measurements: 10,
        }
    }
}

/// Finds the light count whose `time_ms(count)` (the caller's median of a few renders) is
/// closest to `search.target_ms`, assuming time grows with the count.
pub fn equal_time_lights<E>(
    search: &EqualTimeSearch,
    mut time_ms: impl FnMut(usize) -> Result<f64, E>,
) -> Result<EqualTime, E> {
    let max = search.max_lights.max(1);
    let budget = search.max_measurements.max(2);
    let mut measurements: Vec<(usize, f64)> = Vec::new();
    let mut measure = |n: usize, m: &mut Vec<(usize, f64)>| -> Result<f64, E> {
        if let Some(&(_, t)) = m.iter().find(|(k, _)| *k == n) {
            return Ok(t);
        }
        let t = time_ms(n)?;
        m.push((n, t));
        Ok(t)
    };
    // Bracket: lo renders under the target, hi at or over it.
    let mut n = search.start.clamp(1, max);
    let mut lo: Option<usize> = None;
    let mut hi: Option<usize> = None;
    while measurements.len() < budget {
        let t = measure(n, &mut measurements)?;
        if t < search.target_ms {
            lo = Some(n);
            if hi.is_some() || n == max {
                break;
            }
            n = (n * 2).min(max);
        } else {
            hi = Some(n);
            if lo.is_some() || n == 1 {
                break;
            }
            n = (n / 2).max(1);
        }
    }
    if let (Some(mut l), Some(mut h)) = (lo, hi) {
        while measurements.len() < budget
            && h - l > ((search.relative_width * l as f64) as usize).max(1)
        {
            let mid = l + (h - l) / 2;
            if measure(mid, &mut measurements)? < search.target_ms {
                l = mid;
            } else {
                h = mid;
            }
        }
    }
    let &(lights, milliseconds) = measurements
        .iter()
        .min_by(|a, b| {
            (a.1 - search.target_ms)
                .abs()
                .total_cmp(&(b.1 - search.target_ms).abs())
        })
        .expect("at least one measurement");
    let at_bound = (lights == max && milliseconds < search.target_ms)
        || (lights == 1 && milliseconds > search.target_ms);
    Ok(EqualTime {
        lights,
        milliseconds,
        measurements,
        at_bound,
    })
}

/// The equal-error baseline (Ren 2010 Fig. 6: 450 directional lights to match 50 SRBFs): the
/// fewest median-cut lights whose image is at least as accurate as the SRBF frame's.
#[derive(Debug, Clone, PartialEq)]
pub struct EqualError {
    /// The fewest measured lights with an error ≤ the target, or `max_lights` when none was.
    pub lights: usize,
    /// (light count, error) in the order measured.
    pub measurements: Vec<(usize, f64)>,
    /// True when even `max_lights` stayed above the target error.
    pub at_bound: bool,
}

/// Doubles from `start` until `error(count)` ≤ `target` (halves while it already is), then bisects the last bracket down to
/// `relative_width`, within `max_measurements` renders. Assumes the error falls as lights are
/// added, which median cut only does on average: the answer is the smallest count *measured* to
/// reach the target, so a noisy curve can only make it larger (the SRBF's advantage smaller).
pub fn equal_error_lights<E>(
    target: f64,
    start: usize,
    max_lights: usize,
    relative_width: f64,
    max_measurements: usize,
    mut error: impl FnMut(usize) -> Result<f64, E>,
) -> Result<EqualError, E> {
    let max = max_lights.max(1);
    let mut measurements: Vec<(usize, f64)> = Vec::new();
    let mut n = start.clamp(1, max);
    let mut below: Option<usize> = None; // largest count known to miss the target
    let mut reached: Option<usize> = None; // smallest count known to reach it
    // Bracket: double while missing, halve while reaching.
    while measurements.len() < max_measurements.max(1) {
        let e = error(n)?;
        measurements.push((n, e));
        if e <= target {
            reached = Some(n);
            if below.is_some() || n == 1 {
                break;
            }
            n = (n / 2).max(1);
        } else {
            below = Some(n);
            if reached.is_some() || n == max {
                break;
            }
            n = (n * 2).min(max);
        }
    }
    if let (Some(mut lo), Some(mut hi)) = (below, reached) {
        while measurements.len() < max_measurements
            && hi - lo > ((relative_width * lo as f64) as usize).max(1)
        {
            let mid = lo + (hi - lo) / 2;
            let e = error(mid)?;
            measurements.push((mid, e));
            if e <= target { hi = mid } else { lo = mid }
        }
    }
    let best = measurements
        .iter()
        .filter(|(_, e)| *e <= target)
        .map(|(n, _)| *n)
        .min();
    Ok(EqualError {
        lights: best.unwrap_or(max),
        at_bound: best.is_none(),
        measurements,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::convert::Infallible;

    /// A frame costing a fixed overhead plus a per-light cost: 2 ms + 0.1 ms per light.
    fn linear(n: usize) -> Result<f64, Infallible> {
        Ok(2.0 + 0.1 * n as f64)
    }

    #[test]
    fn finds_the_count_of_a_linear_cost_in_few_renders() {
        // 15 ms ⇔ 130 lights exactly.
        let r = equal_time_lights(&EqualTimeSearch::new(15.0), linear).unwrap();
        println!("{r:?}");
        assert!(
            (r.lights as f64 - 130.0).abs() <= 0.1 * 130.0,
            "{}",
            r.lights
        );
        assert!(r.measurements.len() <= 10);
        assert!(!r.at_bound);
        // Every reported time is the cost function's at that count.
        assert!(r.measurements.iter().all(|&(n, t)| t == linear(n).unwrap()));
        // Starting above the target halves down.
        let r = equal_time_lights(
            &EqualTimeSearch {
                start: 4096,
                ..EqualTimeSearch::new(4.5)
            },
            linear,
        )
        .unwrap();
        assert!((r.lights as f64 - 25.0).abs() <= 3.0, "{}", r.lights);
    }

    #[test]
    fn noisy_costs_still_land_near_the_target() {
        // ±4% deterministic jitter on a cost with a quadratic part (fragment-bound frames).
        let mut k = 0u32;
        let cost = |n: usize| -> Result<f64, Infallible> {
            k = k.wrapping_mul(1_103_515_245).wrapping_add(12_345);
            let jitter = 1.0 + 0.04 * ((k >> 16) as f64 / 32768.0 - 1.0);
            Ok((5.0 + 0.05 * n as f64 + 1e-5 * (n * n) as f64) * jitter)
        };
        let r = equal_time_lights(&EqualTimeSearch::new(40.0), cost).unwrap();
        // Noise-free answer: 0.05 n + 1e-5 n² = 35 → n = (−0.05 + √0.0039)/2e-5 ≈ 622.
        println!("{r:?}");
        assert!(
            (r.lights as f64 - 622.0).abs() < 0.15 * 622.0,
            "{}",
            r.lights
        );
        assert!((r.milliseconds - 40.0).abs() < 0.1 * 40.0);
    }

    #[test]
    fn bounds_and_errors() {
        let r = equal_time_lights(
            &EqualTimeSearch {
                max_lights: 64,
                ..EqualTimeSearch::new(1000.0)
            },
            linear,
        )
        .unwrap();
        assert_eq!(r.lights, 64);
        assert!(r.at_bound);
        let r = equal_time_lights(&EqualTimeSearch::new(0.5), linear).unwrap();
        assert_eq!(r.lights, 1);
        assert!(r.at_bound);
        let failing = |_: usize| -> Result<f64, String> { Err("device lost".into()) };
        assert_eq!(
            equal_time_lights(&EqualTimeSearch::new(1.0), failing).unwrap_err(),
            "device lost"
        );
    }
    #[test]
    fn equal_error_finds_the_fewest_lights_reaching_the_target() {
        // A 1/√n error curve: 0.5/√n ≤ 0.05 ⇔ n ≥ 100.
        let err = |n: usize| -> Result<f64, Infallible> { Ok(0.5 / (n as f64).sqrt()) };
        let r = equal_error_lights(0.05, 16, 8192, 0.1, 12, err).unwrap();
        println!("{r:?}");
        assert!(!r.at_bound);
        assert!(r.lights >= 100 && r.lights as f64 <= 110.0, "{}", r.lights);
        assert!(r.measurements.iter().all(|&(n, e)| e == err(n).unwrap()));
        // Unreachable within the bound: the bound, flagged.
        let r = equal_error_lights(0.001, 16, 256, 0.1, 12, err).unwrap();
        assert_eq!((r.lights, r.at_bound), (256, true));
        // Already reached at the start: halves down to the crossing (0.5/√n ≤ 0.2 ⇔ n ≥ 6.25).
        let r = equal_error_lights(0.2, 16, 256, 0.1, 12, err).unwrap();
        assert_eq!((r.lights, r.at_bound), (7, false), "{r:?}");
    }
}
