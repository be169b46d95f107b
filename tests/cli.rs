//! End-to-end smoke test of the `strandlight` binary: `summary --json` and a small
//! `sweep --json` run, produce the documented fields, and the sweep is clean. The numbers
//! themselves are checked by the model tests in `strandlight-tables`; here the independent
//! checks are the ones the CLI computes against closed forms (the SRBF integral) and the
//! melanin formula σ_a = C_eu σ_eu + C_ph σ_ph recomputed from the printed concentrations.

use serde_json::Value;
use std::process::Command;

fn run_json(args: &[&str]) -> (bool, Value) {
    let out = Command::new(env!("CARGO_BIN_EXE_strandlight"))
        .args(args)
        .output()
        .expect("the strandlight binary runs");
    let text = String::from_utf8(out.stdout).expect("UTF-8 output");
    let json = serde_json::from_str(&text).unwrap_or_else(|e| {
        panic!(
            "`strandlight {}` printed no JSON ({e}):\n{text}",
            args.join(" ")
        )
    });
    (out.status.success(), json)
}

fn f(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

#[test]
fn summary_json_has_every_section() {
    let (ok, s) = run_json(&["summary", "--json"]);
    assert!(ok);
    let models = s["models"].as_array().expect("models");
    let names: Vec<&str> = models.iter().map(|m| m["name"].as_str().unwrap()).collect();
    println!("models: {names:?}");
    for wanted in ["marschner", "kajiya-kay", "artist"] {
        assert!(
            names.iter().any(|n| n.starts_with(wanted)),
            "{wanted} missing"
        );
    }
    for m in models {
        assert!(m["parameters"].is_object());
        for sample in m["samples"].as_array().unwrap() {
            let rgb = sample["s"].as_array().unwrap();
            assert!(
                rgb.iter().all(|v| f(v).is_finite() && f(v) >= 0.0),
                "{sample}"
            );
        }
    }
    // σ_a per preset from the printed concentrations (Chiang 2016 / pbrt-v3 coefficients).
    let (eu, ph) = ([0.419, 0.697, 1.37], [0.187, 0.4, 1.05]);
    for p in s["presets"].as_array().unwrap() {
        let (ce, cp) = (f(&p["eumelanin"]), f(&p["pheomelanin"]));
        for c in 0..3 {
            let expected = ce * eu[c] + cp * ph[c];
            assert!((f(&p["sigma_a"][c]) - expected).abs() < 1e-12, "{p}");
        }
    }
    for row in s["white_furnace_marschner"].as_array().unwrap() {
        println!("furnace: {row}");
        let sum = f(&row["r"]) + f(&row["tt"]) + f(&row["trt"]);
        assert!((sum - f(&row["total"])).abs() < 1e-12);
        // White hair loses only the higher-order paths (E_p≥3, a few percent) and gains or
        // loses a few percent from M_p's spread over θ_d (tables/src/marschner/tests.rs,
        // white_furnace_energy_per_lobe): within 10% of 1, not an order-of-magnitude window.
        assert!((f(&row["total"]) - 1.0).abs() < 0.1, "{row}");
        // Twice the quadrature panels moves the total by less than 1e-4: it has converged.
        assert!(
            (f(&row["total_refined"]) - f(&row["total"])).abs() < 1e-4,
            "{row}"
        );
    }
    assert_eq!(
        s["single_event_albedo_marschner"].as_array().unwrap().len(),
        s["presets"].as_array().unwrap().len()
    );
    for row in s["srbf_integral"].as_array().unwrap() {
        let lambda = f(&row["lambda"]);
        let closed = 2.0 * std::f64::consts::PI * (1.0 - (-2.0 * lambda).exp()) / lambda;
        println!(
            "SRBF λ = {lambda}: closed form {closed:.15}, CLI quadrature {}",
            row["quadrature"]
        );
        assert!((f(&row["quadrature"]) - closed).abs() < 1e-9 * closed);
    }
}

#[test]
fn small_sweep_is_clean_and_reports_every_model() {
    let (ok, s) = run_json(&["sweep", "--samples", "20000", "--json"]);
    assert!(ok, "sweep exited with failure: {s}");
    assert_eq!(s["clean"], Value::Bool(true));
    let models = s["models"].as_array().expect("models");
    assert_eq!(models.len(), 4);
    for m in models {
        println!("{m}");
        assert_eq!(m["requested"].as_u64(), Some(20_000));
        assert!(m["values_checked"].as_u64().unwrap() >= 20_000);
        assert_eq!(m["nan"].as_u64(), Some(0));
        assert_eq!(m["inf"].as_u64(), Some(0));
        assert_eq!(m["negative"].as_u64(), Some(0));
        assert!(f(&m["max_finite"]).is_finite());
        assert!(m["rejected_parameter_sets"].is_u64() && m["seconds"].is_f64());
    }
}

/// A frame past the adapter's texture limit is refused before anything is rendered or written:
/// a non-zero exit, the limit named with a size that fits, and no output file.
#[test]
fn render_past_the_texture_limit_fails_cleanly_without_output() {
    let dir = std::env::temp_dir().join(format!("strandlight-cli-limit-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("a temporary directory");
    let stem = dir.join("huge");
    let out = Command::new(env!("CARGO_BIN_EXE_strandlight"))
        .args(["render", "lights", "--size", "100000x100000", "--out"])
        .arg(&stem)
        .output()
        .expect("the strandlight binary runs");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success(),
        "exit status {:?}; stderr:\n{stderr}",
        out.status
    );
    assert!(stderr.contains("max_texture_dimension_2d"), "{stderr}");
    assert!(stderr.contains("--size"), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    for ext in ["exr", "png"] {
        assert!(!stem.with_extension(ext).exists(), "{ext} written");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
