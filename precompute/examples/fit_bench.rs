//! Benchmark of the SRBF fit on every map in a folder (default: ../shared/data/envmaps) and on
//! the procedural environments; prints a Markdown section for docs/BENCHMARKS.md.
//!
//!     cargo run --release -p strandlight-precompute --example fit_bench -- [DIR] [--out FILE]
//!
//! Per map: (1) the default fit (30 initial lobes, stop at relative MSE ≤ 0.15 or 64 lobes):
//! lobes used, seconds; (2) a sweep from 16 to 64 lobes with no error target, reporting the
//! relative L2 error √(relative MSE) at 16/32/49/64 lobes and its seconds.
//! Times are wall-clock on this machine, with rayon's default thread count.

use std::path::{Path, PathBuf};
use std::time::Instant;
use strandlight_precompute::envmap::EnvMap;
use strandlight_precompute::envmap_io::{LoadOptions, load};
use strandlight_precompute::procedural_env;
use strandlight_precompute::srbf_fit::{FitOptions, RoundRecord, fit};
use strandlight_precompute::srbf_objective::relative_mse_by_pixels;

/// CPU seconds this process has used (all threads), from /proc/self/stat (Linux; 0 elsewhere).
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    // Fields after the ")" that closes the command name (utime, stime: fields 14, 15 of proc(5)).
    let rest = stat.rsplit(')').next().unwrap_or("");
    let f: Vec<f64> = rest
        .split_whitespace()
        .filter_map(|v| v.parse().ok())
        .collect();
    // The state letter is not a number and is skipped, so utime and stime land at 10 and 11.
    if f.len() > 12 {
        (f[10] + f[11]) / 100.0
    } else {
        0.0
    }
}

fn main() {
    let (dir, out) = parse_args();
    let dir = dir
        .or_else(|| strandlight_tables::shared_data::shared_data_dir().map(|d| d.join("envmaps")));
    let maps = benchmark_maps(dir.as_deref());

    let mut md = machine_header();
    md += "| map | size | lobes for rel. MSE ≤ 0.15 | rel. MSE reached | full-res rel. MSE | s (default fit) | CPU s | power fit/map (R/G/B) | L2 @16 | L2 @32 | L2 @49 | L2 @64 | s (16→64 sweep) |\n";
    md += "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    let mut extra = Vec::new();
    for (name, map) in &maps {
        let (row, missed_target) = default_fit_row(name, map);
        eprint!("{row}");
        md += &row;
        if missed_target {
            extra.push(wide_lambda_row(name, map));
        }
    }
    md += "\nThe maps that miss the target, with a wider bandwidth bound (`--lambda-max 1024`, default fit otherwise):\n\n";
    md += "| map | λ bounds | lobes | rel. MSE (fit grid) | full-res rel. MSE | s |\n|---|---|---|---|---|---|\n";
    for e in extra {
        md += &e;
    }
    println!("{md}");
    if let Some(out) = out {
        std::fs::write(&out, &md).expect("writable output");
        eprintln!("wrote {}", out.display());
    }
}

/// `[DIR] [--out FILE]`: the folder of maps and where to write the Markdown, both optional.
fn parse_args() -> (Option<PathBuf>, Option<PathBuf>) {
    let mut args = std::env::args().skip(1);
    let (mut dir, mut out) = (None, None);
    while let Some(a) = args.next() {
        if a == "--out" {
            out = args.next().map(PathBuf::from);
        } else {
            dir = Some(PathBuf::from(a));
        }
    }
    (dir, out)
}

/// Every map `dir` holds that loads (in file-name order; the others are reported and skipped),
/// then the procedural environments at 1024 wide.
fn benchmark_maps(dir: Option<&Path>) -> Vec<(String, EnvMap)> {
    let mut maps: Vec<(String, EnvMap)> = Vec::new();
    if let Some(dir) = dir {
        let mut files: Vec<_> = std::fs::read_dir(dir)
            .expect("readable folder")
            .flatten()
            .map(|e| e.path())
            .collect();
        files.sort();
        for f in files {
            match load(&f, LoadOptions::default()) {
                Ok(l) => maps.push((f.file_name().unwrap().to_string_lossy().into_owned(), l.map)),
                Err(e) => eprintln!("skipped: {e}"),
            }
        }
    }
    for name in procedural_env::NAMES {
        maps.push((
            format!("procedural:{name}"),
            procedural_env::by_name(name, 1024).unwrap(),
        ));
    }
    maps
}

/// The lines that say what the times were measured on: the load average at start (the machine
/// is shared) and the CPUs and threads available.
fn machine_header() -> String {
    let mut md = String::new();
    let threads = rayon::current_num_threads();
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    md += &format!(
        "Load average at start (machine shared with other builds): {}\n\n",
        load.trim()
    );
    md += &format!(
        "Machine: {} logical CPUs available, rayon threads: {threads}. Fit grid 256 × 128, λ ∈ [16, 64].\n\n",
        std::thread::available_parallelism()
            .map(|n| n.get())
            .unwrap_or(0)
    );
    md
}

/// One map's row of the main table: the default fit (lobes, errors, times, power ratio) and the
/// 16 → 64 lobe sweep. Also says whether the default fit missed its error target.
fn default_fit_row(name: &str, map: &EnvMap) -> (String, bool) {
    let defaults = FitOptions::default();
    let (t, cpu) = (Instant::now(), cpu_seconds());
    let result = fit(map, &defaults, &mut |_| {}).expect("fit");
    let s_default = t.elapsed().as_secs_f64();
    let cpu_default = cpu_seconds() - cpu;
    let reached = relative_mse_by_pixels(&result.grid_map, &result.lobes);
    let map_power = map.integral();
    let power_ratio: Vec<String> = (0..3)
        .map(|c| {
            let p: f64 = result
                .lobes
                .iter()
                .map(|l| strandlight_precompute::srbf_set::power(l)[c])
                .sum();
            format!("{:.2}", p / map_power[c])
        })
        .collect();
    let power_ratio = power_ratio.join("/");
    let full = relative_mse_by_pixels(map, &result.lobes);
    let lobes_cell = if reached <= defaults.target_relative_mse {
        format!("{}", result.lobes.len())
    } else {
        format!("not reached ({} lobes)", result.lobes.len())
    };

    let sweep = FitOptions {
        initial_lobes: 16,
        target_relative_mse: 0.0,
        ..FitOptions::default()
    };
    let t = Instant::now();
    let swept = fit(map, &sweep, &mut |_| {}).expect("fit");
    let s_sweep = t.elapsed().as_secs_f64();
    let at = |k: usize| sweep_l2_at(&swept.history, k);
    let row = format!(
        "| {name} | {}×{} | {lobes_cell} | {reached:.3} | {full:.3} | {s_default:.2} | {cpu_default:.2} | {power_ratio} | {} | {} | {} | {} | {s_sweep:.2} |\n",
        map.width(),
        map.height(),
        at(16),
        at(32),
        at(49),
        at(64)
    );
    (row, reached > defaults.target_relative_mse)
}

/// The sweep's relative L2 error at `k` lobes: the last round with at most k live lobes
/// (insertions that died do not count), with its lobe count in parentheses when below k.
fn sweep_l2_at(history: &[RoundRecord], k: usize) -> String {
    history
        .iter()
        .rfind(|r| r.lobes <= k)
        .map(|r| {
            let note = if r.lobes < k {
                format!(" ({})", r.lobes)
            } else {
                String::new()
            };
            format!("{:.3}{note}", r.relative_mse.sqrt())
        })
        .unwrap_or_else(|| "–".into())
}

/// What a wider λ bound buys where the default misses the target (λ ≤ 1024 is what the
/// 256-wide grid resolves): a row of the second table.
fn wide_lambda_row(name: &str, map: &EnvMap) -> String {
    let wide = FitOptions {
        lambda_max: 1024.0,
        ..FitOptions::default()
    };
    let t = Instant::now();
    let r = fit(map, &wide, &mut |_| {}).expect("fit");
    let s = t.elapsed().as_secs_f64();
    let e = relative_mse_by_pixels(&r.grid_map, &r.lobes);
    let f = relative_mse_by_pixels(map, &r.lobes);
    format!(
        "| {name} | [16, 1024] | {} | {e:.3} | {f:.3} | {s:.2} |\n",
        r.lobes.len()
    )
}
