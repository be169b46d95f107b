use super::*;
use crate::quadrature::GaussLegendre;

/// Only the components listed keep their intensity.
fn only(lobes: &[ArtistLobe]) -> ArtistParams {
    let mut p = ArtistParams::default();
    if !lobes.contains(&ArtistLobe::R) {
        p.r.intensity = 0.0;
    }
    if !lobes.contains(&ArtistLobe::Tt) {
        p.tt.intensity = 0.0;
    }
    if !lobes.contains(&ArtistLobe::TrtMinusGlints) && !lobes.contains(&ArtistLobe::Glints) {
        p.trt.intensity = 0.0;
    }
    if !lobes.contains(&ArtistLobe::Glints) {
        p.glints.relative_intensity = 0.0;
    }
    p
}

/// Angles from (θ_h, θ_d, φ).
fn half_diff(theta_h: f64, theta_d: f64, phi: f64) -> FiberAngles {
    FiberAngles::new(theta_h - theta_d, theta_h + theta_d, phi)
}

/// argmax of f over a uniform grid on [a, b] with `n` nodes.
fn argmax(a: f64, b: f64, n: usize, f: impl Fn(f64) -> f64) -> f64 {
    (0..n)
        .map(|k| a + (b - a) * k as f64 / (n - 1) as f64)
        .map(|x| (x, f(x)))
        .fold(
            (a, f64::NEG_INFINITY),
            |acc, v| if v.1 > acc.1 { v } else { acc },
        )
        .0
}

#[test]
fn highlight_position_follows_the_shift() {
    // At fixed θ_d the factor 1/cos²θ_d is constant, so the peak in θ_h is exactly at α_X.
    let step = 1e-3f64.to_radians();
    let n = (80.0f64.to_radians() / step) as usize + 1;
    for (lobe, phi) in [
        (ArtistLobe::R, 0.3),
        (ArtistLobe::Tt, PI),
        (ArtistLobe::TrtMinusGlints, 0.2),
    ] {
        for shift in [-12.0, -5.0, 0.0, 3.0, 14.0] {
            let mut p = only(&[lobe]);
            match lobe {
                ArtistLobe::R => p.r.shift_deg = shift,
                ArtistLobe::Tt => p.tt.shift_deg = shift,
                _ => p.trt.shift_deg = shift,
            }
            let m = ArtistModel::new(p).unwrap();
            let peak = argmax(-40f64.to_radians(), 40f64.to_radians(), n, |th| {
                m.eval(&half_diff(th, 0.25, phi))[0]
            });
            println!(
                "{lobe:?} shift {shift:+5.1}°: peak at θ_h = {:+.4}°",
                peak.to_degrees()
            );
            assert!(
                (peak - shift.to_radians()).abs() <= step,
                "{lobe:?} {shift}"
            );
        }
    }
}

#[test]
fn width_changes_keep_the_peak_intensity() {
    // Sadeghi §3.2 / eq. 5: a unit-height lobe keeps its brightness when it widens; its
    // measured half-width at half maximum is √(2 ln 2) β.
    let theta_d = 0.3;
    for width in [0.5, 2.0, 5.0, 20.0, 45.0] {
        let mut p = only(&[ArtistLobe::R]);
        p.r.width_deg = width;
        let m = ArtistModel::new(p).unwrap();
        let alpha = p.r.shift_deg.to_radians();
        let peak = m.eval(&half_diff(alpha, theta_d, 0.0))[0];
        let want = p.r.color[0] * p.r.intensity / theta_d.cos().powi(2);
        // Half maximum by bisection on the right flank.
        let f = |th: f64| m.eval(&half_diff(th, theta_d, 0.0))[0] - 0.5 * peak;
        let (mut lo, mut hi) = (alpha, alpha + 5.0 * width.to_radians());
        for _ in 0..100 {
            let mid = 0.5 * (lo + hi);
            if f(mid) > 0.0 { lo = mid } else { hi = mid }
        }
        let hwhm = (lo - alpha).to_degrees();
        let want_hwhm = (2.0 * 2f64.ln()).sqrt() * width;
        let unit_area_peak = 1.0 / ((2.0 * PI).sqrt() * width.to_radians());
        println!(
            "β = {width:4.1}°: peak {peak:.15} (closed form {want:.15}), HWHM {hwhm:.6}° (want {want_hwhm:.6}°); a unit-area lobe's peak would be {unit_area_peak:.2}"
        );
        assert!((peak - want).abs() <= 1e-14 * want);
        assert!((hwhm - want_hwhm).abs() < 1e-9 * want_hwhm);
    }
}

#[test]
fn azimuthal_shapes_match_the_paper() {
    let m = ArtistModel::new(ArtistParams::default()).unwrap();
    let gamma = m.params().tt.azimuthal_width_deg.to_radians();
    assert!((m.azimuthal(ArtistLobe::Tt, PI) - 1.0).abs() < 1e-15);
    assert!((m.azimuthal(ArtistLobe::Tt, PI - gamma) - (-0.5f64).exp()).abs() < 1e-15);
    assert!((m.azimuthal(ArtistLobe::Tt, -PI + gamma) - (-0.5f64).exp()).abs() < 1e-15);
    assert!((m.azimuthal(ArtistLobe::R, 0.0) - 1.0).abs() < 1e-15);
    assert!(m.azimuthal(ArtistLobe::R, PI).abs() < 1e-15);
    assert!((m.azimuthal(ArtistLobe::TrtMinusGlints, 2.0) - 1f64.cos()).abs() < 1e-15);
}

#[test]
fn glints_sit_at_the_half_angle_and_follow_a_per_fiber_angle() {
    let m = ArtistModel::new(ArtistParams::default()).unwrap();
    let step = 1e-3f64.to_radians();
    let n = (PI / step) as usize + 1;
    let a0 = |phi: f64| half_diff(m.params().trt.shift_deg.to_radians(), 0.1, phi);
    let g = m.params().glints.half_angle_deg;
    let peak = argmax(0.0, PI, n, |phi| {
        m.lobe_value(ArtistLobe::Glints, &a0(phi))[0]
    });
    println!("glint peak at φ = {:.4}° (G_angle {g}°)", peak.to_degrees());
    assert!((peak.to_degrees() - g).abs() <= 1e-3);
    // Glint part of eval_with_glint_half_angle = total minus the other three lobes.
    for g_fiber in [30.0f64, 41.0, 45.0] {
        let glint_only = |phi: f64| {
            let a = a0(phi);
            let all = m.eval_with_glint_half_angle(&a, g_fiber.to_radians())[0];
            let rest: f64 = [ArtistLobe::R, ArtistLobe::Tt, ArtistLobe::TrtMinusGlints]
                .iter()
                .map(|&l| m.lobe_value(l, &a)[0])
                .sum::<f64>()
                * inverse_cos2_guarded(a.theta_d());
            all - rest
        };
        let peak = argmax(0.0, PI, n, glint_only);
        let peak_neg = argmax(-PI, 0.0, n, glint_only);
        println!(
            "per-fiber G_angle {g_fiber}°: glints at φ = {:+.4}°, {:+.4}°",
            peak.to_degrees(),
            peak_neg.to_degrees()
        );
        assert!((peak.to_degrees() - g_fiber).abs() <= 2e-3);
        assert!((peak_neg.to_degrees() + g_fiber).abs() <= 2e-3);
    }
}

#[test]
fn symmetric_in_azimuth_and_reciprocal() {
    let mut rng = SweepRng::new(5);
    for _ in 0..20 {
        let m = ArtistModel::new(random_params(&mut rng)).unwrap();
        for _ in 0..2000 {
            let a = FiberAngles::new(
                rng.hard_inclination(),
                rng.hard_inclination(),
                rng.range(-PI, PI),
            );
            let mirrored = FiberAngles::new(a.theta_i, a.theta_o, -a.phi);
            assert_eq!(m.eval(&a), m.eval(&mirrored));
            // Swapping ω_i and ω_o keeps θ_h, flips θ_d and φ: f' is reciprocal.
            let s = m.eval(&a.swapped());
            let e = m.eval(&a);
            for c in 0..3 {
                assert!(
                    (s[c] - e[c]).abs() <= 1e-12 * e[c].abs().max(1e-300),
                    "{a:?}"
                );
            }
        }
    }
}

#[test]
fn lobes_reassemble_the_scattering_function() {
    // The LobeDecomposition (unit-area M_p times √(2π)β-scaled N_p) must give back eq. 12.
    let mut rng = SweepRng::new(8);
    let mut worst: f64 = 0.0;
    for _ in 0..20 {
        let m = ArtistModel::new(random_params(&mut rng)).unwrap();
        for _ in 0..2000 {
            let a = FiberAngles::new(
                rng.range(-1.5, 1.5),
                rng.range(-1.5, 1.5),
                rng.range(-PI, PI),
            );
            let (s, l) = (m.eval(&a), m.eval_lobes(&a));
            for c in 0..3 {
                let rel = (s[c] - l[c]).abs() / s[c].abs().max(1e-300);
                if s[c] > 1e-250 {
                    worst = worst.max(rel);
                }
            }
        }
    }
    println!("eval vs eval_lobes: worst relative difference {worst:.2e}");
    assert!(worst < 1e-12);
}

/// Composite Gauss–Legendre on [−π/2, π/2] with extra pieces geometrically graded toward both
/// ends: near θ_i = −θ_o = ∓π/2 the integrand cos²θ_i cos θ_o/cos²θ_d is bounded but not smooth.
fn graded_rule(panels: usize) -> GaussLegendre {
    let mut cuts = vec![-FRAC_PI_2, FRAC_PI_2];
    for k in 1..=6 {
        let e = 10f64.powi(-k);
        cuts.push(-FRAC_PI_2 + e);
        cuts.push(FRAC_PI_2 - e);
    }
    cuts.sort_by(f64::total_cmp);
    let mut rule = GaussLegendre {
        nodes: vec![],
        weights: vec![],
    };
    for w in cuts.windows(2) {
        let n = if w[1] - w[0] > 1.0 { panels } else { 1 };
        let r = GaussLegendre::composite(8, n, w[0], w[1]);
        rule.nodes.extend(r.nodes);
        rule.weights.extend(r.weights);
    }
    rule
}

/// (1/4π) ∫∫ f cos θ_i dω_o dω_i by brute force over (θ_i, θ_o, φ) with `eval`.
fn mean_albedo_brute_force(
    f: &dyn ScatteringFunction,
    ti_panels: usize,
    to_panels: usize,
    phi_panels: usize,
) -> Rgb {
    let ri = graded_rule(ti_panels);
    let ro = graded_rule(to_panels);
    let rp = GaussLegendre::composite(8, phi_panels, -PI, PI);
    let mut total = [0.0; 3];
    for (&ti, &wi) in ri.nodes.iter().zip(&ri.weights) {
        for (&to, &wo) in ro.nodes.iter().zip(&ro.weights) {
            let k = wi * wo * ti.cos().powi(2) * to.cos();
            for (&phi, &wp) in rp.nodes.iter().zip(&rp.weights) {
                let s = f.eval(&FiberAngles::new(ti, to, phi));
                for c in 0..3 {
                    total[c] += k * wp * s[c];
                }
            }
        }
    }
    // (1/4π) · 2π (the φ_i integral) = 1/2.
    total.map(|t| 0.5 * t)
}

#[test]
fn normalized_copy_has_unit_mean_albedo() {
    let mut wide = ArtistParams::default();
    wide.tt.width_deg = 6.0;
    wide.r.width_deg = 8.0;
    wide.glints.azimuthal_width_deg = 8.0;
    for (label, params, panels, tol) in [
        ("wide lobes", wide, (6, 32, 32), 1e-9),
        ("defaults", ArtistParams::default(), (6, 64, 48), 1e-8),
    ] {
        let m = ArtistModel::new(params).unwrap();
        let k = m.normalization_integral();
        let brute = mean_albedo_brute_force(&m, panels.0, panels.1, panels.2);
        let n = m.normalized(Normalization::PerChannel);
        let one = mean_albedo_brute_force(&n, panels.0, panels.1, panels.2);
        println!(
            "{label}: K = {k:.12?}, brute-force K = {brute:.12?}; normalized mean albedo {one:.12?}"
        );
        for c in 0..3 {
            assert!((brute[c] - k[c]).abs() < tol * k[c], "{label} channel {c}");
            assert!((one[c] - 1.0).abs() < tol, "{label} channel {c}");
        }
        let shared = m.normalized(Normalization::SharedScale);
        let kmax = k.iter().copied().fold(0.0, f64::max);
        for c in 0..3 {
            assert!((shared.scale()[c] - 1.0 / kmax).abs() < 1e-15 / kmax);
        }
    }
}

#[test]
fn validation_names_the_parameter() {
    let mut p = ArtistParams::default();
    p.tt.width_deg = 0.0;
    let e = ArtistModel::new(p).unwrap_err();
    assert!(e.to_string().contains("artist.tt.width_deg"), "{e}");
    let mut p = ArtistParams::default();
    p.r.intensity = f64::NAN;
    assert!(matches!(
        ArtistModel::new(p),
        Err(ParamError::NotFinite {
            name: "artist.r.intensity",
            ..
        })
    ));
    let mut p = ArtistParams::default();
    p.trt.color[2] = -1.0;
    assert!(matches!(
        ArtistModel::new(p),
        Err(ParamError::OutOfRange {
            name: "artist.trt.color[2]",
            ..
        })
    ));
    let mut p = ArtistParams::default();
    p.glints.half_angle_deg = 200.0;
    assert!(
        ArtistModel::new(p)
            .unwrap_err()
            .to_string()
            .contains("artist.glints.half_angle_deg")
    );
    let mut p = ArtistParams::default();
    p.r.shift_deg = 60.0;
    let e = ArtistModel::new(p).unwrap_err().to_string();
    assert!(e.contains("artist.r.shift_deg"), "{e}");
    let json = serde_json::to_string_pretty(&ArtistParams::default()).unwrap();
    let back: ArtistParams = serde_json::from_str(&json).unwrap();
    assert_eq!(back, ArtistParams::default());
    let typo = json.replace("\"intensity\"", "\"intensty\"");
    let e = serde_json::from_str::<ArtistParams>(&typo).unwrap_err();
    assert!(e.to_string().contains("unknown field `intensty`"), "{e}");
}

#[test]
fn hard_cases_never_produce_nan_or_inf() {
    let r = hard_case_sweep(400_000, 21);
    println!("{r}");
    assert!(r.samples >= 400_000);
    assert!(r.is_clean(), "{r}");
}

#[test]
fn inclination_weight_matches_quadrature() {
    for theta_h in [1e-3, 0.01, 0.2, -0.7, 1.3, 1.55] {
        let h = FRAC_PI_2 - f64::abs(theta_h);
        // The integrand has boundary layers of width ~|θ_h| at ±h: grade the rule there.
        let t = f64::abs(theta_h);
        let q = crate::dual_scattering::peaked_rule(
            -h,
            h,
            &[(-h, t), (h, t), (-h, 10.0 * t), (h, 10.0 * t)],
            &[],
            16,
        )
        .integrate(|td: f64| {
            (theta_h - td).cos().powi(2) * (theta_h + td).cos() / td.cos().powi(2)
        });
        let w = inclination_weight(theta_h);
        println!("W({theta_h:+.3}) closed form {w:.15}, quadrature {q:.15}");
        assert!((w - q).abs() < 1e-12, "{theta_h}");
    }
    assert_eq!(inclination_weight(0.0), 2.0);
}
