//! Fitting tests on small maps (64×32 to 128×64): recovery of known lobes, monotone error,
//! errors that match an independent recomputation, determinism across thread counts.

use glam::DVec3;
use std::f64::consts::PI;
use strandlight_precompute::compact_sources::SourceOptions;
use strandlight_precompute::envmap::{EnvMap, uv_to_direction};
use strandlight_precompute::procedural_env::{SunSky, from_srbf_lobes};
use strandlight_precompute::srbf_fit::{FitError, FitOptions, fit};
use strandlight_precompute::srbf_set::{Source, SrbfSet, SrbfSetError};
use strandlight_tables::srbf::{self, SrbfLobe};

fn known_lobes() -> Vec<SrbfLobe> {
    let lobe = |u, v, lambda, amplitude| SrbfLobe {
        center: uv_to_direction(u, v).to_array(),
        lambda,
        amplitude,
    };
    vec![
        lobe(0.15, 0.3, 20.0, [3.0, 2.0, 1.0]),
        lobe(0.45, 0.6, 40.0, [1.0, 1.5, 2.5]),
        lobe(0.7, 0.25, 30.0, [2.0, 2.0, 2.0]),
        lobe(0.9, 0.75, 50.0, [4.0, 1.0, 0.5]),
    ]
}

fn source(map: &EnvMap) -> Source<'_> {
    Source {
        map,
        name: "test".into(),
        sha256: String::new(),
        sanitized: Default::default(),
    }
}

#[test]
fn a_map_made_of_known_srbfs_is_recovered() {
    let truth = known_lobes();
    let map = from_srbf_lobes(128, &truth);
    let options = FitOptions {
        initial_lobes: 4,
        max_lobes: 4,
        target_relative_mse: 0.0,
        lambda_min: 10.0,
        lambda_max: 80.0,
        grid_width: 128,
        iterations_per_round: 300,
        ..FitOptions::default()
    };
    let result = fit(&map, &options, &mut |_| {}).unwrap();
    eprintln!(
        "recovery: objective relative MSE {:.3e}",
        result.objective_relative_mse
    );
    assert_eq!(result.lobes.len(), 4);
    for t in &truth {
        let nearest = result
            .lobes
            .iter()
            .min_by(|a, b| {
                b.center()
                    .dot(t.center())
                    .total_cmp(&a.center().dot(t.center()))
            })
            .unwrap();
        let angle = nearest
            .center()
            .dot(t.center())
            .clamp(-1.0, 1.0)
            .acos()
            .to_degrees();
        let amp_err = (0..3)
            .map(|c| (nearest.amplitude[c] / t.amplitude[c] - 1.0).abs())
            .fold(0.0, f64::max);
        let lambda_err = (nearest.lambda / t.lambda - 1.0).abs();
        eprintln!(
            "  true λ {:>4.1}: center off by {angle:.3}°, λ {:.2} ({:.2}%), amplitude worst {:.2}%",
            t.lambda,
            nearest.lambda,
            100.0 * lambda_err,
            100.0 * amp_err
        );
        assert!(angle < 0.5, "center {angle}°");
        assert!(amp_err < 0.03, "amplitude {amp_err}");
        assert!(lambda_err < 0.03, "lambda {lambda_err}");
    }
}

#[test]
fn error_decreases_as_lobes_are_added() {
    // Four known lobes plus the studio's soft lights: several rounds of real progress.
    let lobes = from_srbf_lobes(64, &known_lobes());
    let studio = strandlight_precompute::procedural_env::three_light_studio(64);
    let px = lobes
        .pixels()
        .iter()
        .zip(studio.pixels())
        .map(|(a, b)| std::array::from_fn(|c| a[c] + 0.1 * b[c]))
        .collect();
    let map = EnvMap::from_pixels(64, 32, px);
    let options = FitOptions {
        initial_lobes: 1,
        max_lobes: 10,
        target_relative_mse: 0.0,
        grid_width: 64,
        lambda_max: 64.0, // λ ≤ grid_width²/64
        ..FitOptions::default()
    };
    let result = fit(&map, &options, &mut |_| {}).unwrap();
    let errors: Vec<(usize, f64)> = result
        .history
        .iter()
        .map(|r| (r.lobes, r.relative_mse))
        .collect();
    eprintln!("history (lobes, relative MSE): {errors:.4?}");
    assert!(errors.len() >= 5);
    for pair in errors.windows(2) {
        // Each round starts from the previous optimum plus a lobe, so it can only be lower
        // (up to the optimizer's tolerance).
        assert!(pair[1].1 <= pair[0].1 * (1.0 + 1e-6) + 1e-12, "{pair:?}");
    }
    assert!(errors.last().unwrap().1 < 0.3 * errors[0].1);
}

/// Σ w‖fit − map‖² / Σ w‖map‖² with a midpoint-rule solid angle and this file's own
/// direction formula (θ from +Y, image center toward −Z): independent of the library's sums.
fn independent_relative_mse(map: &EnvMap, lobes: &[SrbfLobe]) -> f64 {
    let (w, h) = (map.width(), map.height());
    let (mut err, mut norm) = (0.0, 0.0);
    for y in 0..h {
        let theta = PI * (y as f64 + 0.5) / h as f64;
        let d_omega = theta.sin() * (PI / h as f64) * (2.0 * PI / w as f64);
        for x in 0..w {
            let phi = 2.0 * PI * ((x as f64 + 0.5) / w as f64 - 0.5);
            let dir = DVec3::new(
                theta.sin() * phi.sin(),
                theta.cos(),
                -theta.sin() * phi.cos(),
            );
            let p = map.pixel(x, y);
            for (c, &pixel) in p.iter().enumerate() {
                let f: f64 = lobes
                    .iter()
                    .map(|l| l.amplitude[c] * srbf::kernel(dir.dot(l.center()), l.lambda))
                    .sum();
                err += d_omega * (f - pixel as f64).powi(2);
                norm += d_omega * (pixel as f64).powi(2);
            }
        }
    }
    err / norm
}

#[test]
fn reported_errors_equal_an_independent_recomputation() {
    let map = SunSky::default().to_map(128).downsampled(64, 32);
    // The lobes alone against the whole map: no compact source taken out.
    let options = FitOptions {
        initial_lobes: 8,
        max_lobes: 10,
        grid_width: 64,
        lambda_max: 64.0, // λ ≤ grid_width²/64
        sources: SourceOptions::none(),
        ..FitOptions::default()
    };
    let set = SrbfSet::fit(&source(&map), &options, &mut |_| {}).unwrap();
    let check = independent_relative_mse(&map, &set.lobes);
    eprintln!(
        "reported relative MSE {:.6} (L2 {:.6}), independent {:.6}; full resolution {:.6}",
        set.relative_mse, set.relative_l2_error, check, set.full_resolution_relative_mse
    );
    assert!((set.relative_mse - check).abs() < 2e-3 * check);
    assert!((set.relative_l2_error.powi(2) - set.relative_mse).abs() < 1e-12);
}

#[test]
fn the_result_does_not_depend_on_the_thread_count() {
    let map = SunSky::default().to_map(128).downsampled(64, 32);
    let options = FitOptions {
        initial_lobes: 6,
        max_lobes: 9,
        target_relative_mse: 0.0,
        grid_width: 64,
        lambda_max: 64.0, // λ ≤ grid_width²/64
        ..FitOptions::default()
    };
    let run = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| fit(&map, &options, &mut |_| {}).unwrap().lobes)
    };
    let (one, three) = (run(1), run(3));
    eprintln!("1 thread and 3 threads: {} lobes each", one.len());
    assert_eq!(one, three);
}

#[test]
fn bad_options_and_black_maps_are_refused_by_name() {
    let map = SunSky::default().to_map(64);
    let e = fit(
        &map,
        &FitOptions {
            lambda_min: 300.0,
            ..FitOptions::default()
        },
        &mut |_| {},
    )
    .unwrap_err();
    assert!(e.to_string().contains("lambda_max"), "{e}");
    let e = fit(
        &map,
        &FitOptions {
            lambda_min: f64::NAN,
            ..FitOptions::default()
        },
        &mut |_| {},
    )
    .unwrap_err();
    assert!(e.to_string().contains("lambda_min"), "{e}");
    let e = fit(
        &map,
        &FitOptions {
            lambda_max: 2000.0,
            ..FitOptions::default()
        },
        &mut |_| {},
    )
    .unwrap_err();
    assert!(e.to_string().contains("grid_width"), "{e}");
    eprintln!("example: {e}");
    let black = EnvMap::from_pixels(64, 32, vec![[0.0; 3]; 64 * 32]);
    assert!(matches!(
        fit(&black, &FitOptions::default(), &mut |_| {}),
        Err(FitError::BlackMap)
    ));
}

#[test]
fn sets_round_trip_through_json_and_bad_files_are_refused() {
    let map = SunSky::default().to_map(64);
    let options = FitOptions {
        initial_lobes: 3,
        max_lobes: 3,
        grid_width: 64,
        lambda_max: 64.0, // λ ≤ grid_width²/64
        ..FitOptions::default()
    };
    let set = SrbfSet::fit(&source(&map), &options, &mut |_| {}).unwrap();
    let dir = std::env::temp_dir().join(format!("strandlight-set-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("set.json");
    set.save(&path).unwrap();
    assert_eq!(SrbfSet::load(&path).unwrap(), set);
    let text = std::fs::read_to_string(&path).unwrap();
    std::fs::write(&path, text.replacen("\"lambda\": ", "\"lambda\": -", 1)).unwrap();
    assert!(matches!(
        SrbfSet::load(&path),
        Err(SrbfSetError::BadLobe { index: 0, .. })
    ));
    std::fs::write(&path, &text[..text.len() / 2]).unwrap();
    assert!(matches!(
        SrbfSet::load(&path),
        Err(SrbfSetError::Json { .. })
    ));

    // The directional baseline in the same format carries the whole map's power.
    let d = SrbfSet::directional(&source(&map), 16, &options);
    let total: f64 = d
        .lobes
        .iter()
        .map(|l| strandlight_precompute::srbf_set::power(l)[0])
        .sum();
    eprintln!(
        "16 directional lights carry {total:.4} of ∫L dω = {:.4}",
        map.integral()[0]
    );
    assert!((total - map.integral()[0]).abs() < 1e-9 * total);
}

#[test]
fn a_sun_narrower_than_any_lobe_doubles_its_power_unless_power_is_preserved() {
    // L2 theory: for a point source of power E, the best single lobe has amplitude
    // E·G(0)/‖G‖², so it carries E·∫G/‖G‖² = E·(2π/λ)/(π/λ) = 2E. Nothing can be found
    // elsewhere on a black map, so the plain least-squares fit carries about twice the
    // sun's power. The default fit rescales amplitudes to the map's power (at a small cost
    // in L2 error), which is what a renderer needs: the hair's brightness must not double.
    let mut px = vec![[0.0f32; 3]; 256 * 128];
    for (x, y) in [(150, 40), (151, 40), (150, 41), (151, 41)] {
        px[y * 256 + x] = [1.0e4; 3];
    }
    let map = EnvMap::from_pixels(256, 128, px);
    let fit_with = |preserve_power: bool| {
        let options = FitOptions {
            initial_lobes: 1,
            max_lobes: 4,
            target_relative_mse: 0.0,
            grid_width: 64,
            lambda_max: 64.0, // λ ≤ grid_width²/64
            preserve_power,
            // The SRBF fit itself: no compact source taken out first.
            sources: SourceOptions::none(),
            ..FitOptions::default()
        };
        let set = SrbfSet::fit(&source(&map), &options, &mut |_| {}).unwrap();
        eprintln!(
            "point-like sun, preserve_power {preserve_power}: {} lobes, λ {:?}, relative MSE {:.3}, power fit/map {:.3}",
            set.lobes.len(),
            set.lobes.iter().map(|l| l.lambda).collect::<Vec<_>>(),
            set.relative_mse,
            set.power_ratio[0]
        );
        assert!(set.power_ratio.iter().all(|r| r.is_finite()));
        set
    };
    let least_squares = fit_with(false);
    assert!(
        least_squares.power_ratio[0] > 1.9 && least_squares.power_ratio[0] < 2.05,
        "{:?}",
        least_squares.power_ratio
    );
    let preserved = fit_with(true);
    for r in preserved.power_ratio {
        assert!((r - 1.0).abs() < 1e-3, "{:?}", preserved.power_ratio);
    }
    // Halving the power costs L2 error, but it must stay a fit (a black map scores 1.0).
    assert!(preserved.relative_mse >= least_squares.relative_mse - 1e-9);
    assert!(preserved.relative_mse < 1.0);
}

#[test]
fn by_default_a_sun_is_taken_out_as_a_directional_light_with_its_power() {
    // The map of the test above: four pixels of 1e4 on black. Its power, summed here from
    // the pixels' exact solid angles, must come out as one source and no lobe.
    let mut px = vec![[0.0f32; 3]; 256 * 128];
    let mut expected = 0.0;
    for (x, y) in [(150, 40), (151, 40), (150, 41), (151, 41)] {
        px[y * 256 + x] = [1.0e4; 3];
        expected += 1.0e4 * strandlight_precompute::envmap::row_solid_angle(y, 256, 128);
    }
    let map = EnvMap::from_pixels(256, 128, px);
    let options = FitOptions {
        grid_width: 64,
        lambda_max: 64.0, // λ ≤ grid_width²/64
        ..FitOptions::default()
    };
    let set = SrbfSet::fit(&source(&map), &options, &mut |_| {}).unwrap();
    assert!(set.lobes.is_empty(), "{:?}", set.lobes);
    assert_eq!(set.sources.len(), 1, "{:?}", set.sources);
    for c in 0..3 {
        assert!((set.sources[0].power[c] - expected).abs() < 1e-9 * expected);
        assert!(
            (set.power_ratio[c] - 1.0).abs() < 1e-9,
            "{:?}",
            set.power_ratio
        );
    }
    // The sources round-trip through the set file, and a corrupted one is refused by index.
    let dir = std::env::temp_dir().join(format!("strandlight-set-sources-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("set.json");
    set.save(&path).unwrap();
    assert_eq!(SrbfSet::load(&path).unwrap(), set);
    let mut corrupt = set.clone();
    corrupt.sources[0].power[1] = -1.0;
    corrupt.save(&path).unwrap();
    assert!(matches!(
        SrbfSet::load(&path),
        Err(SrbfSetError::BadSource { index: 0, .. })
    ));
    std::fs::remove_dir_all(&dir).unwrap();
}
