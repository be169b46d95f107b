//! The hard-case sweep of dual scattering: averages built from random artist-model fibers
//! (Sadeghi 2010), whose lobes span the narrow, wide, dark and light fibers that stress the
//! fiber averages. It lives apart from both modules so that `dual_scattering` never depends on
//! the artist model that depends on it.

use crate::FiberAngles;
use crate::artist::{ArtistModel, Normalization, random_params};
use crate::dual_scattering::{DualScatteringAverages, DualScatteringConfig, forward_spread};
use crate::hard_case_sweep::{SweepReport, SweepRng};

/// Builds averages for random artist-model fibers (narrow and wide lobes, dark and light,
/// normalized per Sadeghi eq. 13) and evaluates S_back, the spread function and the moments at
/// angles concentrated near ±90°. Counts `samples` scalar values.
pub fn hard_case_sweep(samples: u64, seed: u64) -> SweepReport {
    let mut report = SweepReport::new("dual-scattering");
    let mut rng = SweepRng::new(seed);
    let config = DualScatteringConfig {
        theta_samples: 181,
        theta_d_samples: 181,
        ..Default::default()
    };
    let per_model = 30_000u64;
    while report.samples < samples {
        let params = random_params(&mut rng);
        let model = ArtistModel::new(params).expect("random_params yields valid parameters");
        let norm = [
            Normalization::PerChannel,
            Normalization::SharedScale,
            Normalization::PeakPerChannel,
        ][(rng.next_u64() % 3) as usize];
        let normalized = model.normalized(norm);
        let Ok(avg) = DualScatteringAverages::new(&normalized, config) else {
            // ā_f ≥ 1 somewhere is refused with a typed error, which is the correct outcome.
            report.rejected += 1;
            if report.rejected > 10_000 {
                break; // every draw refused: stop rather than loop forever (is_clean still holds)
            }
            continue;
        };
        let mut path = avg.forward_path();
        for _ in 0..per_model / 12 {
            let a = FiberAngles::new(
                rng.hard_inclination(),
                rng.hard_inclination(),
                rng.hard_azimuth(),
            );
            report.record_rgb(avg.backward_scattering(&a));
            let var = [rng.log_range(1e-14, 4.0); 3];
            report.record_rgb(avg.backward_scattering_spread(&a, var));
            let m = avg.moments_at(a.theta_i);
            report.record_rgb(m.attenuation);
            report.record_rgb(m.variance);
            m.shift.iter().for_each(|&s| report.record_signed(s));
            report.record(forward_spread(a.theta_o, a.theta_i, a.phi, var[0]));
            if path.events() < 50 {
                path.add_event(&avg, a.theta_i);
            }
            report.record_rgb(path.transmittance(avg.config().density_forward));
        }
    }
    report
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hard_cases_never_produce_nan_or_inf() {
        let r = hard_case_sweep(300_000, 31);
        println!("{r}");
        assert!(r.samples >= 300_000);
        assert!(r.is_clean(), "{r}");
    }
}
