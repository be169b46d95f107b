//! The markdown table of docs/BENCHMARKS.md from `compare --json` reports, one row per map and
//! mode, so the benchmark page is regenerated, never retyped.

use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use serde_json::Value;

const HEADER: &str = "| map | fit L2 err (map without its sources) | mode | SRBF lights (+ compact sources) | SRBF ms | SRBF rel. RMSE | SRBF HDR-FLIP | baseline lights | baseline ms | baseline rel. RMSE | baseline HDR-FLIP | reference lights | reference ms | speed-up vs reference | equal-error baseline lights | speed-up at equal error |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|";

/// An optional figure (reports older than HDR-FLIP lack it): four decimals or "–".
fn optional(v: &Value) -> String {
    v.as_f64().map_or("–".to_string(), |x| format!("{x:.4}"))
}

fn number(v: &Value, path: &[&str], file: &Path) -> anyhow::Result<f64> {
    let mut at = v;
    for key in path {
        at = at
            .get(key)
            .with_context(|| format!("{}: no \"{}\"", file.display(), path.join(".")))?;
    }
    at.as_f64()
        .with_context(|| format!("{}: \"{}\" is not a number", file.display(), path.join(".")))
}

/// The map's name: the report's `scene.env` file stem, else the report's own file stem.
fn map_name(report: &Value, file: &Path) -> String {
    let from_scene = report["scene"]["env"].as_str().and_then(|e| {
        Path::new(e)
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
    });
    from_scene.unwrap_or_else(|| {
        file.file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default()
    })
}

/// The rows of one report (`single` then `full`, whichever it holds).
pub fn rows(report: &Value, file: &Path) -> anyhow::Result<Vec<String>> {
    let name = map_name(report, file);
    let fit_error = report["scene"]["fit_relative_l2_error"]
        .as_f64()
        .map_or("–".to_string(), |e| format!("{e:.3}"));
    let mut out = Vec::new();
    for mode in ["single", "full"] {
        let Some(m) = report.get(mode) else { continue };
        let n = |path: &[&str]| number(m, path, file);
        let (equal_lights, equal_speedup) = match m.get("baseline_equal_error") {
            None => ("–".to_string(), "–".to_string()),
            Some(e) => {
                let lights = number(e, &["lights"], file)?;
                let speedup = n(&["speedup_at_equal_error"])?;
                if e["at_bound"].as_bool() == Some(true) {
                    (
                        format!("> {lights:.0} (not reached)"),
                        format!("> {speedup:.1}×"),
                    )
                } else {
                    (format!("{lights:.0}"), format!("{speedup:.1}×"))
                }
            }
        };
        // "N + k sun": N SRBFs and k compact sources rendered as directional lights.
        let sources = report["scene"]["compact_sources"]
            .as_array()
            .map_or(0, |s| s.len());
        let srbf_lights = n(&["srbf", "lights"])? as usize;
        let srbf_lights = match sources {
            0 => srbf_lights.to_string(),
            k => match srbf_lights.checked_sub(k) {
                Some(lobes) => format!("{lobes} + {k} src"),
                None => bail!(
                    "{}: {mode}: {srbf_lights} lights cannot hold {k} compact sources",
                    file.display()
                ),
            },
        };
        out.push(format!(
            "| {name} | {fit_error} | {mode} | {srbf_lights} | {:.0} | {:.4} | {} | {:.0} | {:.0} | {:.4} | {} | {:.0} | {:.0} | {:.1}× | {equal_lights} | {equal_speedup} |",
            n(&["srbf", "ms"])?,
            n(&["srbf", "relative_rmse"])?,
            optional(&m["srbf"]["hdr_flip"]),
            n(&["baseline", "lights"])?,
            n(&["baseline", "ms"])?,
            n(&["baseline", "relative_rmse"])?,
            optional(&m["baseline"]["hdr_flip"]),
            n(&["reference", "lights"])?,
            n(&["reference", "ms"])?,
            n(&["speedup_vs_reference"])?,
        ));
    }
    if out.is_empty() {
        bail!(
            "{}: neither \"single\" nor \"full\" — is it a `compare --json` report?",
            file.display()
        );
    }
    Ok(out)
}

/// The whole table (header and rows) of the `compare --json` reports at `files`.
pub fn markdown_table(files: &[PathBuf]) -> anyhow::Result<String> {
    let mut lines = vec![HEADER.to_string()];
    for file in files {
        let text = std::fs::read_to_string(file)
            .with_context(|| format!("cannot read {}", file.display()))?;
        let report: Value =
            serde_json::from_str(&text).with_context(|| format!("{}: not JSON", file.display()))?;
        lines.extend(rows(&report, file)?);
    }
    Ok(lines.join("\n"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn mode(srbf_err: f64) -> Value {
        json!({"srbf": {"lights": 30, "ms": 100.0, "relative_rmse": srbf_err},
               "baseline": {"lights": 12, "ms": 101.0, "relative_rmse": 0.5},
               "reference": {"lights": 6144, "ms": 20000.0}, "speedup_vs_reference": 200.0})
    }

    #[test]
    fn a_row_per_mode_and_missing_fields_are_named() {
        let report = json!({"single": mode(0.04), "full": mode(0.07), "scene": {"env": "maps/quarry_01_1k.hdr", "fit_relative_l2_error": 0.5}});
        let r = rows(&report, Path::new("x.json")).unwrap();
        assert_eq!(r.len(), 2);
        assert!(r[0].starts_with("| quarry_01_1k | 0.500 | single | 30 | 100 | 0.0400 | – | 12 | 101 | 0.5000 | – | 6144 | 20000 | 200.0× | – | – |"), "{}", r[0]);
        let mut with_flip = report.clone();
        with_flip["single"]["srbf"]["hdr_flip"] = json!(0.19);
        with_flip["single"]["baseline"]["hdr_flip"] = json!(0.48);
        let r = rows(&with_flip, Path::new("x.json")).unwrap();
        assert!(
            r[0].contains("| 0.0400 | 0.1900 | 12 | 101 | 0.5000 | 0.4800 |"),
            "{}",
            r[0]
        );
        assert!(r[1].contains("| full |") && r[1].contains("0.0700"));

        let mut with_equal = report.clone();
        with_equal["single"]["baseline_equal_error"] =
            json!({"lights": 450, "ms": 1500.0, "relative_rmse": 0.039, "at_bound": false});
        with_equal["single"]["speedup_at_equal_error"] = json!(15.0);
        let r = rows(&with_equal, Path::new("x.json")).unwrap();
        assert!(r[0].ends_with("| 450 | 15.0× |"), "{}", r[0]);

        let mut broken = report.clone();
        broken["full"]["baseline"]
            .as_object_mut()
            .unwrap()
            .remove("ms");
        let e = rows(&broken, Path::new("b.json")).unwrap_err().to_string();
        assert!(e.contains("b.json") && e.contains("baseline.ms"), "{e}");
        let e = rows(&json!({"steps": []}), Path::new("c.json"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("c.json"), "{e}");
    }
}
