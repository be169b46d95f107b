//! Our Chiang near field against Mitsuba 3's own `hair` BSDF (written by others, evaluated in
//! f32) at a few thousand random (view, light, h, parameter) cases, through
//! `mitsuba_hair_eval.py`. Skips with a reason when Mitsuba is missing (fails under
//! `STRANDLIGHT_REQUIRE_TOOLS=1`).
//!
//! What is compared: Mitsuba's `eval(ctx, si, wo)` with `si.wi` = view and `wo` = light in its
//! local frame, against [`Chiang::near_field_local`] on the same f32-rounded vectors, both
//! with pbrt's and Mitsuba's I₀ approximations ([`BesselForm::PbrtMitsuba`]: what is left is
//! f32 rounding) and with the exact d'Eon term ([`BesselForm::Exact`]: adds the approximations'
//! own error, up to ≈ 0.6%). A value is *tiny* below 10⁻⁶ of its parameter set's largest value
//! in that channel and is not compared (an f32 value that far down a lobe's tail carries the
//! rounding of its exponent, not the model). Excluded besides: cases whose I₀ argument lies within
//! 10⁻⁵ (relative) of 12, where pbrt and Mitsuba switch from the series to the asymptotic form
//! (a jump of up to 0.5%) and f32 and f64 may take different branches.

use glam::DVec3;
use serde_json::{Value, json};
use std::f64::consts::PI;
use std::process::Command;
use strandlight_tables::chiang::{BesselForm, Chiang, ChiangParams};
use strandlight_tables::outside_tools::{python, require_python_modules};
use strandlight_tables::split_mix::SplitMix64;

const PAIRS_PER_SET: usize = 500;
/// Below this fraction of the set's largest value (per channel) a value is tiny.
const TINY: f64 = 1e-6;

fn parameter_sets() -> Vec<(&'static str, ChiangParams)> {
    let preset = |name: &str| ChiangParams::with_preset(name).unwrap();
    vec![
        ("brown (defaults)", ChiangParams::default()),
        (
            "blonde, β 0.1/0.1",
            ChiangParams {
                longitudinal_roughness: 0.1,
                azimuthal_roughness: 0.1,
                ..preset("blonde")
            },
        ),
        (
            "dark, β 0.6/0.7",
            ChiangParams {
                longitudinal_roughness: 0.6,
                azimuthal_roughness: 0.7,
                ..preset("dark")
            },
        ),
        (
            "red, α 5°, η 1.4",
            ChiangParams {
                scale_tilt_degrees: 5.0,
                ior: 1.4,
                ..preset("red")
            },
        ),
        (
            "σ_a (0.2, 0.5, 0.9), η 1.9, α −3°",
            ChiangParams {
                sigma_a: Some([0.2, 0.5, 0.9]),
                ior: 1.9,
                scale_tilt_degrees: -3.0,
                ..ChiangParams::default()
            },
        ),
        (
            "σ_a (1.5, 3, 6), β 0.4/0.2",
            ChiangParams {
                sigma_a: Some([1.5, 3.0, 6.0]),
                longitudinal_roughness: 0.4,
                azimuthal_roughness: 0.2,
                ..ChiangParams::default()
            },
        ),
        (
            "white, β 0.25/0.05, α 0",
            ChiangParams {
                longitudinal_roughness: 0.25,
                azimuthal_roughness: 0.05,
                scale_tilt_degrees: 0.0,
                ..preset("white")
            },
        ),
        (
            "auburn, β 0.9/0.3, η 1.6, α 10°",
            ChiangParams {
                longitudinal_roughness: 0.9,
                ior: 1.6,
                scale_tilt_degrees: 10.0,
                ..preset("auburn")
            },
        ),
    ]
}

/// A vector as Mitsuba will hold it (f32 components), back in f64.
fn f32_rounded(v: DVec3) -> DVec3 {
    DVec3::new(v.x as f32 as f64, v.y as f32 as f64, v.z as f32 as f64)
}

/// Random (view, light) pairs in Mitsuba's local frame: views on the front of the cylinder
/// (z > 0) with h uniform and |sin θ_o| ≤ 0.97; lights half uniform on the sphere, half near
/// one of the lobes' specular cones (θ_i = 2α_p − θ_o ± the lobe's width).
fn pairs(model: &Chiang, rng: &mut SplitMix64) -> Vec<(DVec3, DVec3)> {
    (0..PAIRS_PER_SET)
        .map(|k| {
            let sin_o = 0.97 * (2.0 * rng.uniform() - 1.0);
            let cos_o = (1.0 - sin_o * sin_o).sqrt();
            let h = 0.999 * (2.0 * rng.uniform() - 1.0);
            let view = DVec3::new(-h * cos_o, sin_o, (1.0 - h * h).sqrt() * cos_o);
            let phi = 2.0 * PI * rng.uniform();
            let sin_i = if k % 2 == 0 {
                0.999 * (2.0 * rng.uniform() - 1.0)
            } else {
                let p = (k / 2) % 3;
                let width = model.variances()[p].sqrt();
                let theta =
                    2.0 * model.lobe_shift(p) - sin_o.asin() + width * (2.0 * rng.uniform() - 1.0);
                theta.clamp(-1.5, 1.5).sin()
            };
            let cos_i = (1.0 - sin_i * sin_i).sqrt();
            let light = DVec3::new(cos_i * phi.cos(), sin_i, cos_i * phi.sin());
            (f32_rounded(view), f32_rounded(light))
        })
        .collect()
}

/// Whether some lobe's I₀ argument cos θ'_p cos θ_i / v_p is within 10⁻⁵ of 12.
fn near_bessel_switch(model: &Chiang, view: DVec3, light: DVec3) -> bool {
    let theta_o = view.y.clamp(-1.0, 1.0).asin();
    let cos_i = (1.0 - light.y * light.y).max(0.0).sqrt();
    (0..4).any(|p| {
        let cos_p = (theta_o - 2.0 * model.lobe_shift(p)).cos().abs();
        let x = cos_p * cos_i / model.variances()[p];
        (x / 12.0 - 1.0).abs() < 1e-5
    })
}

#[derive(Default)]
struct Errors {
    compared: usize,
    max: f64,
    sum_sq: f64,
    worst: String,
}

impl Errors {
    fn add(&mut self, e: f64, what: impl FnOnce() -> String) {
        self.compared += 1;
        self.sum_sq += e * e;
        if e > self.max {
            self.max = e;
            self.worst = what();
        }
    }

    fn rms(&self) -> f64 {
        (self.sum_sq / self.compared.max(1) as f64).sqrt()
    }
}

/// Both tallies over every set, and how many values were left out and why.
#[derive(Default)]
struct Comparison {
    /// With pbrt's and Mitsuba's I₀ approximations.
    approx: Errors,
    /// With the exact d'Eon term.
    exact: Errors,
    tiny: usize,
    near_switch: usize,
    total: usize,
}

impl Comparison {
    /// Compares one parameter set's values with Mitsuba's (`theirs`, in the order of `cases`),
    /// adds them to the totals and prints the set's own errors. Every value of ours must be
    /// finite and non-negative, compared or not.
    fn add_set(
        &mut self,
        name: &str,
        model: &Chiang,
        cases: &[(DVec3, DVec3)],
        theirs: &[[f64; 3]],
    ) {
        let peak: [f64; 3] =
            std::array::from_fn(|c| theirs.iter().map(|v| v[c]).fold(0.0, f64::max));
        let (mut set_approx, mut set_exact) = (Errors::default(), Errors::default());
        for (&(view, light), want) in cases.iter().zip(theirs) {
            let ours = model.near_field_local(view, light, BesselForm::PbrtMitsuba);
            let ours_exact = model.near_field_local(view, light, BesselForm::Exact);
            let switch = near_bessel_switch(model, view, light);
            for c in 0..3 {
                self.total += 1;
                assert!(
                    ours[c].is_finite() && ours[c] >= 0.0,
                    "{name}: {ours:?} at {view}, {light}"
                );
                if want[c] < TINY * peak[c] {
                    self.tiny += 1;
                    continue;
                }
                if switch {
                    self.near_switch += 1;
                    continue;
                }
                let what = |v: f64| {
                    move || {
                        format!(
                            "{name}, channel {c}, view {view}, light {light}: ours {v:.6e}, Mitsuba {:.6e}",
                            want[c]
                        )
                    }
                };
                let e = (ours[c] - want[c]).abs() / want[c];
                set_approx.add(e, what(ours[c]));
                self.approx.add(e, what(ours[c]));
                let e = (ours_exact[c] - want[c]).abs() / want[c];
                set_exact.add(e, what(ours_exact[c]));
                self.exact.add(e, what(ours_exact[c]));
            }
        }
        eprintln!(
            "{name}: {} values compared; pbrt/Mitsuba I₀: max {:.2e} rms {:.2e}; exact d'Eon: max {:.2e} rms {:.2e}",
            set_approx.compared,
            set_approx.max,
            set_approx.rms(),
            set_exact.max,
            set_exact.rms()
        );
    }
}

/// Mitsuba's RGB value of every case of every set, from `mitsuba_hair_eval.py` through a
/// scratch folder, and the Mitsuba version that computed them.
fn mitsuba_values(
    sets: &[(&str, ChiangParams)],
    cases: &[Vec<(DVec3, DVec3)>],
) -> (String, Vec<Vec<[f64; 3]>>) {
    let groups: Vec<Value> = sets
        .iter()
        .zip(cases)
        .map(|((_, params), pairs)| {
            json!({
                "params": params,
                "pairs": pairs
                    .iter()
                    .map(|(v, l)| [[v.x, v.y, v.z], [l.x, l.y, l.z]])
                    .collect::<Vec<_>>(),
            })
        })
        .collect();
    let dir =
        std::env::temp_dir().join(format!("strandlight-chiang-mitsuba-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (input, output) = (dir.join("cases.json"), dir.join("values.json"));
    std::fs::write(
        &input,
        serde_json::to_vec(&json!({ "groups": groups })).unwrap(),
    )
    .unwrap();
    let script =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/mitsuba_hair_eval.py");
    let run = Command::new(python())
        .arg(&script)
        .arg(&input)
        .arg(&output)
        .output()
        .expect("the Python interpreter runs");
    assert!(
        run.status.success(),
        "{} failed: {}",
        script.display(),
        String::from_utf8_lossy(&run.stderr)
    );
    let result: Value = serde_json::from_slice(&std::fs::read(&output).unwrap()).unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
    let version = result["mitsuba"].as_str().unwrap_or("?").to_string();
    let values = result["values"]
        .as_array()
        .unwrap()
        .iter()
        .map(|set| {
            set.as_array()
                .unwrap()
                .iter()
                .map(|v| std::array::from_fn(|c| v[c].as_f64().unwrap()))
                .collect()
        })
        .collect();
    (version, values)
}

#[test]
fn near_field_matches_mitsuba_hair_bsdf() {
    if !require_python_modules(&["mitsuba"], "pip install mitsuba") {
        return;
    }
    let sets = parameter_sets();
    let mut rng = SplitMix64::new(2016);
    let models: Vec<Chiang> = sets
        .iter()
        .map(|(_, p)| Chiang::new(p.clone()).unwrap())
        .collect();
    let cases: Vec<Vec<(DVec3, DVec3)>> = models.iter().map(|m| pairs(m, &mut rng)).collect();
    let (version, values) = mitsuba_values(&sets, &cases);

    let mut all = Comparison::default();
    for (s, ((name, _), model)) in sets.iter().zip(&models).enumerate() {
        all.add_set(name, model, &cases[s], &values[s]);
    }
    let Comparison {
        approx,
        exact,
        tiny,
        near_switch,
        total,
    } = all;
    eprintln!(
        "Mitsuba {version}, {total} values ({} cases × RGB): {} compared, {tiny} tiny (< {TINY:e} of the set's max), {near_switch} excluded within 10⁻⁵ of the I₀ switch at 12",
        total / 3,
        approx.compared
    );
    eprintln!(
        "relative error with pbrt's and Mitsuba's I₀: max {:.2e}, rms {:.2e} (worst: {})",
        approx.max,
        approx.rms(),
        approx.worst
    );
    eprintln!(
        "relative error with the exact d'Eon term: max {:.2e}, rms {:.2e} (worst: {})",
        exact.max,
        exact.rms(),
        exact.worst
    );
    assert!(approx.compared > total / 2, "too few values compared");
    // f32 rounding only (measured 6.8e-4 at 3.9.1); the 1% of the brief for the exact form.
    assert!(approx.max < 2e-3, "max relative error {:e}", approx.max);
    assert!(exact.max < 1e-2, "max relative error {:e}", exact.max);
}
