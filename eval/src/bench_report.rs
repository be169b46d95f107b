//! The Markdown of `strandlight bench`: the generated section of docs/BENCHMARKS.md (between
//! [`BEGIN`] and [`END`], replaced whole on every run; the rest of the page is left alone).

use crate::bench::{BenchReport, EnvLitResult};
use crate::error_decomposition::{self as decomposition, DecompositionStep, ErrorDecomposition};
use anyhow::bail;
use std::fmt::Write;
use strandlight_scene::look::EnvTransparency;
use strandlight_scene::scene_tables::ScatteringMode;

pub const BEGIN: &str = "<!-- strandlight bench: generated section, begin -->";
pub const END: &str = "<!-- strandlight bench: generated section, end -->";
/// The markers of the ground-truth plan's section (`bench --truth`), which opens the page.
pub const TRUTH_BEGIN: &str = "<!-- strandlight bench --truth: generated section, begin -->";
pub const TRUTH_END: &str = "<!-- strandlight bench --truth: generated section, end -->";

fn optional_speedup(s: Option<f64>, r: &EnvLitResult, baseline: &str) -> String {
    match (s, r.speedup_lower_bound()) {
        (Some(s), _) => format!("{s:.1}×"),
        (None, Some((lights, bound))) => format!(
            "more than {bound:.1}× ({baseline} with {lights} lights, the most measured, is still less accurate)"
        ),
        (None, None) => "not measured".into(),
    }
}

/// "N vs M: d" per rung of the reference's ladder: each rung against the next, the last against
/// the reference (M is not 4N where compact sources add the same lights to every rung).
fn ladder_rungs(r: &EnvLitResult) -> Vec<String> {
    let ladder = &r.reference_ladder;
    ladder
        .iter()
        .enumerate()
        .map(|(i, (n, d))| {
            let next = ladder.get(i + 1).map_or(r.reference_lights, |rung| rung.0);
            format!("{n} vs {next}: {d:.4}")
        })
        .collect()
}

/// The goals every map's SRBF default is held to: relative RMSE against the converged reference
/// per scattering mode, and the speed-up over the reference and over the baseline at equal error.
const SINGLE_ERROR_GOAL: f64 = 0.05;
const FULL_ERROR_GOAL: f64 = 0.08;
const SPEEDUP_GOAL: f64 = 10.0;

fn mark(met: bool) -> &'static str {
    if met { " ✓" } else { "" }
}

/// An equal-error speed-up's cell, marked where it meets the goal; where the baseline never got
/// as accurate, its lower bound ("> x", marked when even the bound meets it).
fn speedup_goal_cell(s: Option<f64>, r: &EnvLitResult) -> String {
    match (s, r.speedup_lower_bound()) {
        (Some(s), _) => format!("{s:.1}×{}", mark(s >= SPEEDUP_GOAL)),
        (None, Some((_, bound))) => format!("> {bound:.1}×{}", mark(bound >= SPEEDUP_GOAL)),
        (None, None) => "–".into(),
    }
}

/// One row per map and mode: the SRBF default against the goals, so where each map stands is
/// read before its sweep.
fn goals_table(out: &mut String, report: &BenchReport) {
    let _ = writeln!(
        out,
        "### Where each map stands\n\nThe SRBF default against the goals: relative RMSE ≤ {SINGLE_ERROR_GOAL} (single scattering) or ≤ {FULL_ERROR_GOAL} (full) against the converged reference, at ≥ {SPEEDUP_GOAL}× the reference's speed and ≥ {SPEEDUP_GOAL}× {}'s at equal error; ✓ marks a goal met. Against a reference that did not converge the error is an estimate, off by up to its last rung.\n\n| map | mode | reference lights | ms | relative RMSE | HDR-FLIP | × reference | × {} at equal rel. RMSE | × at equal HDR-FLIP |\n|---|---|---|---:|---:|---:|---:|---:|---:|",
        report.plan.baseline.name(),
        report.plan.baseline.name()
    );
    for r in &report.env_lit {
        let Some(default) = r.points.first() else {
            continue;
        };
        let goal = match r.mode == ScatteringMode::Full.name() {
            true => FULL_ERROR_GOAL,
            false => SINGLE_ERROR_GOAL,
        };
        let reference = match r.reference_converged {
            Some(true) => format!("{} (converged)", r.reference_lights),
            Some(false) => format!("{} (not converged)", r.reference_lights),
            None => r.reference_lights.to_string(),
        };
        let over_reference = r.reference_ms / default.ms;
        let _ = writeln!(
            out,
            "| {} | {} | {reference} | {:.0} | {:.4}{} | {:.4} | {over_reference:.0}×{} | {} | {} |",
            r.map,
            r.mode,
            default.ms,
            default.relative_rmse,
            mark(default.relative_rmse <= goal && r.reference_converged == Some(true)),
            default.hdr_flip,
            mark(over_reference >= SPEEDUP_GOAL),
            speedup_goal_cell(r.speedup_equal_rmse, r),
            speedup_goal_cell(r.speedup_equal_flip, r),
        );
    }
    out.push('\n');
}

/// A decomposition step's cell: relative RMSE, and HDR-FLIP where the step is a picture.
fn step_cell(step: Option<&DecompositionStep>) -> String {
    match step {
        Some(DecompositionStep {
            relative_rmse,
            hdr_flip: Some(flip),
            relative_rmse_noise_corrected: Some(corrected),
            ..
        }) => format!("{relative_rmse:.4} ({corrected:.4}) / {flip:.4}"),
        Some(DecompositionStep {
            relative_rmse,
            hdr_flip: Some(flip),
            ..
        }) => format!("{relative_rmse:.4} / {flip:.4}"),
        Some(s) => format!("{:.4}", s.relative_rmse),
        None => "–".into(),
    }
}

fn reference_cell(lights: usize, converged: Option<bool>) -> String {
    match converged {
        Some(true) => format!("{lights} (converged)"),
        Some(false) => format!("{lights} (not converged)"),
        None => lights.to_string(),
    }
}

/// One map's row: its name, the reference cell and one cell per step, in `steps`' order.
fn decomposition_row(out: &mut String, d: &ErrorDecomposition, reference: &str, steps: &[&str]) {
    let cells: Vec<String> = steps.iter().map(|l| step_cell(d.step(l))).collect();
    let _ = writeln!(out, "| {} | {reference} | {} |", d.map, cells.join(" | "));
}

/// Per map, where the SRBF default's error comes from: each approximation of the method added
/// in turn ([`decomposition`]).
fn decomposition_tables(out: &mut String, report: &BenchReport) {
    if !report.decompositions.iter().any(|d| !d.against_truth) {
        return;
    }
    let of_mode = |mode: ScatteringMode| {
        report
            .decompositions
            .iter()
            .filter(move |d| d.mode == mode.name() && !d.against_truth)
    };
    let _ = writeln!(
        out,
        "### Where the error comes from

Each approximation of the method added in turn, the image measured against the reference it should match at that point (relative RMSE / HDR-FLIP over the hair). Unshadowed (T = 1, no light maps): the fit (the brute-force render of the fitted lighting, its sources exact and its lobes one light per cube texel, against that of the map), the tables (the SRBF frame against the render of the fitted lighting) and both (the SRBF frame against the map's render); their references climb to {} lights. Shadowed, against the map's reference: every strand in every light map (κ 1: what is left is the one visibility per lobe), then the default κ.

| map | reference lights (unshadowed: map, fit) | fit | tables | fit and tables | + one visibility per lobe (κ 1) | + κ (the default) |
|---|---|---:|---:|---:|---:|---:|",
        decomposition::unshadowed_max_lights(report.plan.reference_max_lights)
    );
    for d in of_mode(ScatteringMode::Single) {
        let unshadowed = match (d.unshadowed_reference_lights, d.unshadowed_converged) {
            (Some((map, fit)), Some(true)) => format!("{map}, {fit}, converged"),
            (Some((map, fit)), _) => format!("{map}, {fit}, not converged"),
            (None, _) => "–".into(),
        };
        let reference = reference_cell(d.reference_lights, d.reference_converged);
        let steps = [
            decomposition::FIT,
            decomposition::TABLES,
            decomposition::UNSHADOWED,
            decomposition::EVERY_STRAND,
            decomposition::DEFAULT_KAPPA,
        ];
        decomposition_row(out, d, &format!("{reference} ({unshadowed})"), &steps);
    }
    let full: Vec<&ErrorDecomposition> = of_mode(ScatteringMode::Full).collect();
    if !full.is_empty() {
        out.push_str("
Full scattering, the SRBF default: the error of its single- and of its multiple-scattering part against the references' (full minus single scattering), each over the full reference's norm, so that they add as vectors to the full frame's error.

| map | reference lights | single-scattering part | multiple-scattering part | full |
|---|---|---:|---:|---:|
");
    }
    for d in full {
        let reference = reference_cell(d.reference_lights, d.reference_converged);
        let steps = [
            decomposition::SINGLE_PART,
            decomposition::MULTIPLE_PART,
            decomposition::FULL,
        ];
        decomposition_row(out, d, &reference, &steps);
    }
    out.push('\n');
}

/// Per map, each approximation's frame against the ground truth ([`decomposition`]'s
/// `…_against_truth`).
fn truth_decomposition_tables(out: &mut String, report: &BenchReport) {
    let of_mode = |mode: ScatteringMode| -> Vec<&ErrorDecomposition> {
        report
            .decompositions
            .iter()
            .filter(|d| d.mode == mode.name() && d.against_truth)
            .collect()
    };
    let (single, full) = (
        of_mode(ScatteringMode::Single),
        of_mode(ScatteringMode::Full),
    );
    if single.is_empty() && full.is_empty() {
        return;
    }
    let _ = writeln!(
        out,
        "\n### Where the error comes from, against the truth\n\nEach frame against the ground truth (relative RMSE (n.c.) / HDR-FLIP over the hair), one approximation changed from the frame on its left: the DOM reference of the map's lights; the DOM reference of the fit's lights (the fit: its lobes one light per cube texel, its compact sources exact; the same light count); Ren 2010's SRBF frame with every strand in every lobe's light map (κ 1: the tables and one visibility per lobe); at the default κ; the visibility volume in place of the light maps (the product's default); and, on maps with compact sources, the default with their light maps {}× finer ({}² against {}²: what the compact sources' shadow resolution costs). The truth has no unshadowed image, so the tables are not measured apart here (\"Where the error comes from\" under \"Speed against error\" measures them against the DOM reference).\n\n| map | DOM reference: map | DOM reference: fit | SRBF light maps, κ 1 | + κ (Ren 2010) | volume (default) | compact sources' maps ×{} |\n|---|---|---|---|---|---|---|",
        decomposition::SHARP_SOURCE_MAP_SCALE,
        decomposition::SHARP_SOURCE_MAP_SCALE * report.plan.dodm_sizes[0],
        report.plan.dodm_sizes[0],
        decomposition::SHARP_SOURCE_MAP_SCALE,
    );
    let single_steps = [
        decomposition::TRUTH_MAP_LIGHTS,
        decomposition::TRUTH_FIT_LIGHTS,
        decomposition::TRUTH_EVERY_STRAND,
        decomposition::TRUTH_LIGHT_MAPS,
        decomposition::TRUTH_VOLUME,
        decomposition::TRUTH_SHARP_SOURCES,
    ];
    for d in single {
        let cells: Vec<String> = single_steps.iter().map(|l| step_cell(d.step(l))).collect();
        let _ = writeln!(out, "| {} | {} |", d.map, cells.join(" | "));
    }
    if !full.is_empty() {
        out.push_str("\nFull scattering, the default frame: its single- and multiple-scattering parts against the truth's (the full truth less the single-scattering truth), each over the full truth's norm (they add as vectors to the full frame's error), and the whole.\n\n| map | single-scattering part | multiple-scattering part | full (n.c.) / HDR-FLIP |\n|---|---:|---:|---|\n");
    }
    for d in full {
        let steps = [
            decomposition::SINGLE_PART,
            decomposition::MULTIPLE_PART,
            decomposition::FULL,
        ];
        let cells: Vec<String> = steps.iter().map(|l| step_cell(d.step(l))).collect();
        let _ = writeln!(out, "| {} | {} |", d.map, cells.join(" | "));
    }
}

fn env_lit_table(out: &mut String, r: &EnvLitResult, plots: &str, baseline: &str) {
    let _ = writeln!(
        out,
        "\n#### {} — {} scattering\n\nReference: {} lights, {:.0} ms{}. Equal-error speed-up of the SRBF default over {baseline}: {} (relative RMSE), {} (HDR-FLIP).\n",
        r.map,
        r.mode,
        r.reference_lights,
        r.reference_ms,
        match r.reference_converged {
            Some(true) => ", converged (N and 4N lights within 1%)".to_string(),
            Some(false) => format!(
                ", NOT converged within the run's light budget (last rung {})",
                ladder_rungs(r).last().map_or("–".into(), String::clone)
            ),
            None => String::new(),
        },
        optional_speedup(r.speedup_equal_rmse, r, baseline),
        optional_speedup(r.speedup_equal_flip, r, baseline),
    );
    if !r.reference_ladder.is_empty() {
        let ladder = ladder_rungs(r);
        let _ = writeln!(
            out,
            "Reference convergence (relative RMSE): {}.\n",
            ladder.join("; ")
        );
    }
    out.push_str("| frame | lights | ms | relative RMSE | HDR-FLIP |\n|---|---:|---:|---:|---:|\n");
    for p in &r.points {
        let _ = writeln!(
            out,
            "| {} {} | {} | {:.0} | {:.4} | {:.4} |",
            p.family, p.label, p.lights, p.ms, p.relative_rmse, p.hdr_flip
        );
    }
    let _ = writeln!(
        out,
        "\n![error against ms, relative RMSE]({plots}-rmse.png) ![error against ms, HDR-FLIP]({plots}-flip.png)"
    );
}

/// The report's file name in its page's folder, as `bench` writes it.
pub fn report_file(report: &BenchReport) -> String {
    format!("report-{}.json", report.plan.name)
}

/// The commands of a merged report's runs, as the page names them, each with its machine
/// where they differ.
fn run_commands(report: &BenchReport) -> String {
    let machines = report.spans_machines();
    report
        .runs
        .iter()
        .map(|run| match machines {
            true => format!("`bench{}` (on {}; {})", run.args, run.machine, run.adapter),
            false => format!("`bench{}`", run.args),
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// Where the page's frames were timed: a merged page's runs may each have had their own machine;
/// a speed-up compares frames of one run.
fn timed_on(report: &BenchReport) -> &'static str {
    match report.spans_machines() {
        true => "each run's machine and adapter (a map's speed-ups compare frames of its own run)",
        false => "this machine's adapter",
    }
}

/// The generated section, `page_dir` (where DETAILS.md and the report are) relative to the
/// Markdown file (e.g. `bench`).
pub fn section(report: &BenchReport, page_dir: &str) -> String {
    let mut out = String::new();
    let timed_on = timed_on(report);
    let plan = &report.plan;
    let args = report.plan.regenerate_args();
    // One run reruns with its own arguments; a merged page names each run instead.
    let (heading_args, regenerate, budget) = match report.runs.is_empty() {
        true => (
            args.as_str(),
            format!("Regenerate with `cargo run --release -- bench{args}`"),
            format!("or stops at {} lights", plan.reference_max_lights),
        ),
        false => (
            "",
            format!(
                "Measured in {} runs, {}, merged into this page by `bench --from-report` into one report that holds every run's data and arguments ([`{page_dir}/{report_file}`]({page_dir}/{report_file}))",
                report.runs.len(),
                run_commands(report),
                report_file = report_file(report)
            ),
            format!(
                "or stops at its run's budget (at most {} lights)",
                plan.reference_max_lights
            ),
        ),
    };
    let _ = writeln!(
        out,
        "{BEGIN}\n## Speed against error (`strandlight bench{heading_args}`)\n\nGenerated {} at git revision {} on {}; adapter {}; {:.0} s in all. {regenerate} (needs `../shared/data`; skips with a message without it). Everything is straight.hair under the `{}` Marschner fiber at {}×{} with the default front camera and {}; errors are over the reference's hair pixels (compact sources exact, the rest one light per cube texel; the reference climbs N = 96, 384, … until N and 4N lights agree within 1% relative RMSE, {budget}: each map below says whether it converged); ms are frame times on {timed_on}, {} (lavapipe: ratios only).\n",
        report.date,
        report.git_revision,
        report.machine,
        report.adapter,
        report.seconds,
        plan.preset,
        plan.size.0,
        plan.size.1,
        view_phrase(plan.transparency),
        match plan.timing_runs {
            1 => "one run each".to_string(),
            n => format!("the median of {n} runs each (the reference one run)"),
        },
    );
    if !report.skipped.is_empty() {
        let _ = writeln!(out, "Skipped: {}.\n", report.skipped.join("; "));
    }
    goals_table(&mut out, report);
    decomposition_tables(&mut out, report);
    out.push_str("### SRBF fit: error and time against the lobe count\n\n| map | most lobes | lobes | compact sources | relative L2 error (without sources) | fit s |\n|---|---:|---:|---:|---:|---:|\n");
    for f in &report.fits {
        let _ = writeln!(
            out,
            "| {} | {} | {} | {} | {:.3} | {:.1} |",
            f.map, f.max_lobes, f.lobes, f.sources, f.relative_l2_error, f.seconds
        );
    }
    out.push_str("\n### Marschner convolution table: error against resolution\n\nMax and RMS error against f64 integration relative to the table's maximum (`check-tables`), direction nodes n (n³ × 2n with the 1/λ axis).\n\n| n | MB | bake s | max | RMS | off-axis max |\n|---:|---:|---:|---:|---:|---:|\n");
    for t in &report.tables {
        let _ = writeln!(
            out,
            "| {} | {:.1} | {:.1} | {:.2}% | {:.3}% | {:.2}% |",
            t.nodes,
            t.bytes as f64 / 1e6,
            t.bake_seconds,
            100.0 * t.max_error,
            100.0 * t.rms_error,
            100.0 * t.off_axis_max_error
        );
    }
    let _ = writeln!(
        out,
        "\nEvery frame of every map, with its plots: [{page_dir}/DETAILS.md]({page_dir}/DETAILS.md)."
    );
    let _ = writeln!(out, "\n{END}");
    out
}

/// Every env-lit frame of the run, map by map, with its plots (`plot_dir` relative to the page
/// this is written to): too long for the page, which links it.
pub fn details(report: &BenchReport, plot_dir: &str) -> String {
    let plan = &report.plan;
    let mut out = String::from(
        "# Speed against error: every frame (`strandlight bench`)\n\nGenerated by `bench` with its plots; docs/BENCHMARKS.md holds the summary.\n",
    );
    let _ = writeln!(
        out,
        "\n## Env-lit frames: error against milliseconds\n\nThe SRBF default (each lobe's visibility integrated over it from the groom's SH visibility volume, no light pass per lobe) with the lobe count varied (the most powerful kept); Ren 2010's light maps (`--lobe-visibility light-maps`) with κ (Ren's stochastic simplification) and the light-map size varied one at a time; the {} baseline at several light counts; and the reference. Reports written before the volume became the default vary Ren's frame as \"the default\", and some hold frames since removed (adaptive κ, the light pass's chord tolerance, lobe spread).",
        plan.baseline.name()
    );
    for r in &report.env_lit {
        let stem = format!("{plot_dir}/{}-{}", r.map, r.mode);
        env_lit_table(&mut out, r, &stem, plan.baseline.name());
    }
    out
}

/// `page` with its generated section replaced by `section` (appended when it has none).
pub fn splice(page: &str, section: &str) -> anyhow::Result<String> {
    splice_between(page, section, BEGIN, END, Placement::End)
}

/// `page` with the ground-truth section replaced by `section` (placed after the page's first
/// paragraph when it has none: the page opens with it).
pub fn splice_truth(page: &str, section: &str) -> anyhow::Result<String> {
    splice_between(page, section, TRUTH_BEGIN, TRUTH_END, Placement::Top)
}

/// Where a section goes on a page that has none yet.
enum Placement {
    End,
    /// After the title and the paragraph under it.
    Top,
}

fn splice_between(
    page: &str,
    section: &str,
    begin: &str,
    end: &str,
    placement: Placement,
) -> anyhow::Result<String> {
    match (page.find(begin), page.find(end)) {
        (Some(b), Some(e)) if b < e => {
            let after = e + end.len();
            let tail = page[after..].strip_prefix('\n').unwrap_or(&page[after..]);
            Ok(format!("{}{}{}", &page[..b], section, tail))
        }
        (None, None) => Ok(match placement {
            Placement::End => format!(
                "{}\n{}",
                page.trim_end_matches('\n').to_owned() + "\n",
                section
            ),
            Placement::Top => {
                // The end of the first paragraph after the title (or of the page).
                let body = page.find("\n\n").map_or(page.len(), |t| t + 2);
                let cut = page[body..]
                    .find("\n\n")
                    .map_or(page.len(), |p| body + p + 2);
                format!("{}{}\n{}", &page[..cut], section, &page[cut..])
            }
        }),
        _ => bail!(
            "the page's generated-section markers ({begin}) are damaged (one missing or out of order): fix them by hand"
        ),
    }
}

/// The ground-truth plan's section: per map and mode the SRBF default, the DOM reference and
/// the median-cut front, each against the path-traced ground truth, with the equal-error
/// speed-ups measured against it and the path tracer's time beside the frame's.
/// The view a plan's frames use, as the page says it.
/// "eumelanin 1.3" (and the pheomelanin where there is some) of a preset's Chiang fiber.
fn melanin_phrase(preset: &str) -> String {
    match strandlight_precompute::bake_plan::FiberDescription::preset(preset) {
        Ok(fiber) if fiber.chiang.pheomelanin > 0.0 => format!(
            "eumelanin {}, pheomelanin {}",
            fiber.chiang.eumelanin, fiber.chiang.pheomelanin
        ),
        Ok(fiber) => format!("eumelanin {}", fiber.chiang.eumelanin),
        Err(_) => "an unknown preset".into(),
    }
}

fn view_phrase(transparency: EnvTransparency) -> &'static str {
    match transparency {
        EnvTransparency::Opaque => {
            "the opaque view (each pixel's nearest fiber, weighted by the coverage of all)"
        }
        EnvTransparency::Occupancy => {
            "the occupancy view (every fiber weighted by its visibility through the occupancy map, shaded one by one)"
        }
        EnvTransparency::Layered => {
            "the layered view (every fiber weighted by its visibility through the occupancy map, gathered into 4 layers per pixel, each shaded once)"
        }
    }
}

/// The ground truth's generated section, `page_dir` as in [`section`].
pub fn truth_section(report: &BenchReport, page_dir: &str) -> String {
    let mut out = String::new();
    let timed_on = timed_on(report);
    let plan = &report.plan;
    let regenerate = match report.runs.is_empty() {
        true => format!(
            "Regenerate with `cargo run --release -- bench{}`",
            report.plan.regenerate_args()
        ),
        false => format!(
            "Measured in {} runs, {}, merged into this page by `bench --from-report` into one report that holds every run's data and arguments ([`{page_dir}/{report_file}`]({page_dir}/{report_file}))",
            report.runs.len(),
            run_commands(report),
            report_file = report_file(report)
        ),
    };
    let _ = writeln!(
        out,
        "{TRUTH_BEGIN}\n## Against the path-traced ground truth (`strandlight bench --truth`)\n\nGenerated {} at git revision {} on {}; adapter {}; {:.0} s in all. {regenerate} (needs `../shared/data` and Mitsuba 3: `pip install mitsuba`).\n\n**What is measured.** straight.hair under each shared map at {}×{} (default front camera), shaded with the `{}` Chiang fiber (Chiang et al. 2016: {}, longitudinal and azimuthal roughness 0.3, IOR 1.55, scale tilt 2°). Fibers are opaque cylinders of the file's width in both renderers: straight.hair's transparency field (0.36) is ignored. **The ground truth** is Mitsuba 3's path tracer with its own `hair` BSDF (the same model, written by others), `bsplinecurve` fibers through the strands' points and the map as its `envmap`, hidden from the camera: single scattering at `max_depth` 2, full scattering at the first depth D where 2D moves the image by < 1%. Its samples climb ×4 from 1024 per pixel until N and 4N agree within 1% or the budget ({} spp single, {} full) is reached; the kept image averages both, and its noise (relative RMSE, from the last N-vs-4N difference) is given. **Errors** are relative RMSE over the truth's hair pixels, raw and with the truth's noise removed in quadrature (\"n.c.\"), and HDR-FLIP. The **DOM reference** is the project's own reference (the map as directional lights, each shadowed by a deep opacity map, 1536 of them unless the light ladder converged sooner; each map's section says whether it converged): its error against the truth is what it shares with the method and so cannot show. **× median cut** is the SRBF default's speed-up over median cut at equal error, both measured against the truth (log-log interpolated along median cut's measured front). ms are frame times on {timed_on} (lavapipe: ratios only); Mitsuba's seconds are its render time on the same 2 cores. Every strandlight frame uses {}. Mitsuba has no Marschner BSDF: the Marschner figures (\"Speed against error\", at the end of this page) stay measured against the DOM reference.\n",
        report.date,
        report.git_revision,
        report.machine,
        report.adapter,
        report.seconds,
        plan.size.0,
        plan.size.1,
        plan.preset,
        melanin_phrase(&plan.preset),
        plan.truth_max_spp[0],
        plan.truth_max_spp[1],
        view_phrase(plan.transparency),
    );
    out.push_str("| map | mode | SRBF ms | SRBF vs truth: rel. RMSE (n.c.) / HDR-FLIP | over 4×4 / 16×16 blocks; coverage; mean | DOM reference vs truth | × median cut at equal rel. RMSE | at equal HDR-FLIP | truth: spp, depth, noise | Mitsuba s |\n|---|---|---:|---|---|---|---:|---:|---|---:|\n");
    for r in &report.env_lit {
        let (Some(truth), Some(default)) = (&r.truth, r.points.first()) else {
            continue;
        };
        let reference = r.points.iter().find(|p| p.family == "reference");
        let cell = |p: Option<&crate::bench::Point>| match p.and_then(|p| p.truth) {
            Some(t) => format!(
                "{:.4} ({:.4}) / {:.4}",
                t.relative_rmse, t.relative_rmse_noise_corrected, t.hdr_flip
            ),
            None => "–".into(),
        };
        // Where median cut never gets as accurate, the speed-up is at least its costliest frame's.
        let speedup = |s: Option<f64>| match (s, r.speedup_lower_bound()) {
            (Some(s), _) => format!("{s:.1}×"),
            (None, Some((_, bound))) => format!("> {bound:.1}×"),
            (None, None) => "–".into(),
        };
        let _ = writeln!(
            out,
            "| {} | {} | {:.0} | {} | {} | {} ({} lights) | {} | {} | {}, {}, {:.4}{} | {:.0} |",
            r.map,
            r.mode,
            default.ms,
            cell(Some(default)),
            scales_cell(default.truth.as_ref()),
            cell(reference),
            r.reference_lights,
            speedup(r.speedup_equal_rmse_truth),
            speedup(r.speedup_equal_flip_truth),
            truth.spp,
            truth.max_depth,
            truth.noise,
            if truth.converged {
                ""
            } else {
                " (not converged)"
            },
            truth.seconds,
        );
    }
    out.push_str("\n\"> x×\" under × median cut: median cut's measured front (up to its costliest frame, x times the SRBF default's time) never got as accurate as the SRBF default against the truth.\n");
    truth_decomposition_tables(&mut out, report);
    let _ = writeln!(
        out,
        "\nEvery frame of every map, with its plots: [{page_dir}/DETAILS.md]({page_dir}/DETAILS.md)."
    );
    let _ = writeln!(out, "\n{TRUTH_END}");
    out
}

/// A frame's error against the truth over 4×4 and 16×16 blocks, its coverage's error and its
/// mean ratio; "–" for runs measured before them.
fn scales_cell(truth: Option<&crate::bench::TruthError>) -> String {
    match truth.and_then(|t| t.scales) {
        Some(s) => format!(
            "{:.4} / {:.4}; {:.4}; {:.3}×",
            s.blocks[2], s.blocks[3], s.coverage, s.mean_ratio
        ),
        None => "–".into(),
    }
}

/// Every frame of a truth run, map by map, against the truth and the DOM reference, with its
/// plots (`plot_dir` relative to the page this is written to).
pub fn truth_details(report: &BenchReport, plot_dir: &str) -> String {
    let mut out = String::from(
        "# Against the path-traced ground truth: every frame (`strandlight bench --truth`)\n\nGenerated by `bench --truth` with its plots; docs/BENCHMARKS.md holds the summary.\n",
    );
    for r in &report.env_lit {
        let Some(truth) = &r.truth else { continue };
        let _ = writeln!(
            out,
            "\n## {} — {} scattering\n\nGround truth: {} spp (ladder {}){}, noise {:.4}; DOM reference {} lights{}.\n\n| frame | lights | ms | vs truth: rel. RMSE | n.c. | HDR-FLIP | over 4×4 / 16×16 blocks; coverage; mean | vs DOM reference: rel. RMSE | HDR-FLIP |\n|---|---:|---:|---:|---:|---:|---|---:|---:|",
            r.map,
            r.mode,
            truth.spp,
            truth
                .ladder
                .iter()
                .map(|(n, d)| format!("{n} vs {}: {d:.4}", 4 * n))
                .collect::<Vec<_>>()
                .join("; "),
            match truth.depth_ladder.is_empty() {
                true => String::new(),
                false => format!(
                    ", depth {} (depth search {})",
                    truth.max_depth,
                    truth
                        .depth_ladder
                        .iter()
                        .map(|(d, e)| format!("{d} vs {}: {e:.4}", 2 * d))
                        .collect::<Vec<_>>()
                        .join("; ")
                ),
            },
            truth.noise,
            r.reference_lights,
            match r.reference_converged {
                Some(true) => ", converged",
                Some(false) => ", not converged",
                None => "",
            }
        );
        for p in &r.points {
            let t = p.truth.unwrap_or(crate::bench::TruthError {
                relative_rmse: f64::NAN,
                relative_rmse_noise_corrected: f64::NAN,
                hdr_flip: f64::NAN,
                scales: None,
            });
            let _ = writeln!(
                out,
                "| {} {} | {} | {:.0} | {:.4} | {:.4} | {:.4} | {} | {:.4} | {:.4} |",
                p.family,
                p.label,
                p.lights,
                p.ms,
                t.relative_rmse,
                t.relative_rmse_noise_corrected,
                t.hdr_flip,
                scales_cell(Some(&t)),
                p.relative_rmse,
                p.hdr_flip
            );
        }
        let stem = format!("{plot_dir}/{}-{}", r.map, r.mode);
        let _ = writeln!(
            out,
            "\n![error against ms, relative RMSE vs the truth]({stem}-truth-rmse.png) ![error against ms, HDR-FLIP vs the truth]({stem}-truth-flip.png)"
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::baseline::Baseline;
    use crate::bench::{BenchPlan, PlanChanges, Point};
    use strandlight_scene::head_input::HeadChoice;

    #[test]
    fn the_generated_section_is_replaced_and_the_rest_kept() {
        let page = "# Benchmarks\n\nhand-written\n";
        let first = splice(page, &format!("{BEGIN}\nA\n{END}\n")).unwrap();
        assert!(first.starts_with(page) && first.contains("\nA\n"));
        let second = splice(&first, &format!("{BEGIN}\nB\n{END}\n")).unwrap();
        assert!(second.contains("\nB\n") && !second.contains("\nA\n"));
        assert!(second.starts_with(page));
        let again = splice(&second, &format!("{BEGIN}\nB\n{END}\n")).unwrap();
        assert_eq!(again, second, "idempotent");
        let damaged = format!("{page}{END}\n{BEGIN}\n");
        let e = splice(&damaged, "x").unwrap_err().to_string();
        assert!(e.contains("markers") && e.contains("damaged"), "{e}");
    }

    fn report_of(plan: BenchPlan) -> BenchReport {
        BenchReport {
            plan,
            machine: String::new(),
            adapter: String::new(),
            date: String::new(),
            git_revision: String::new(),
            seconds: 0.0,
            fits: Vec::new(),
            tables: Vec::new(),
            env_lit: Vec::new(),
            decompositions: Vec::new(),
            skipped: Vec::new(),
            runs: Vec::new(),
        }
    }

    fn with_truth(family: &str, ms: f64, relative_rmse: f64, truth_rmse: f64) -> Point {
        Point {
            truth: Some(crate::bench::TruthError {
                relative_rmse: truth_rmse,
                relative_rmse_noise_corrected: truth_rmse - 0.001,
                hdr_flip: 0.3,
                scales: Some(strandlight_scene::image_metrics::ScaleErrors {
                    blocks: [truth_rmse, 0.3, 0.2, 0.1],
                    coverage: 0.05,
                    mean_ratio: 1.02,
                }),
            }),
            ..frame(family, ms, relative_rmse)
        }
    }

    #[test]
    fn the_truth_section_opens_the_page_and_names_both_yardsticks() {
        let mut report = report_of(BenchPlan::truth());
        report.env_lit = vec![EnvLitResult {
            map: "quarry".into(),
            mode: "single".into(),
            reference_lights: 1537,
            reference_ms: 9000.0,
            reference_converged: Some(false),
            reference_ladder: Vec::new(),
            points: vec![
                with_truth("srbf", 10.0, 0.06, 0.44),
                with_truth("median cut", 40.0, 0.15, 0.46),
                with_truth("reference", 9000.0, 0.0, 0.48),
            ],
            speedup_equal_rmse: Some(3.0),
            speedup_equal_flip: None,
            truth: Some(crate::bench::TruthSummary {
                renderer: "Mitsuba".into(),
                spp: 5120,
                max_depth: 2,
                seconds: 75.0,
                converged: false,
                noise: 0.036,
                ladder: vec![(1024, 0.09)],
                depth_ladder: Vec::new(),
            }),
            speedup_equal_rmse_truth: None,
            speedup_equal_flip_truth: Some(18.1),
        }];
        let section = truth_section(&report, "bench-truth");
        // Median cut never reaches the SRBF's 0.44 against the truth: at least its costliest
        // frame's time over the SRBF's, 40/10.
        assert!(
            section.contains("| quarry | single | 10 | 0.4400 (0.4390) / 0.3000 | 0.2000 / 0.1000; 0.0500; 1.020× | 0.4800 (0.4790) / 0.3000 (1537 lights) | > 4.0× | 18.1× | 5120, 2, 0.0360 (not converged) | 75 |"),
            "{section}"
        );
        // Each frame's row is in the details page the section links, not on the page.
        assert!(section.contains("(bench-truth/DETAILS.md)"), "{section}");
        assert!(!section.contains("| median cut  | 64 |"), "{section}");
        let details = truth_details(&report, ".");
        assert!(
            details
                .contains("| median cut  | 64 | 40 | 0.4600 | 0.4590 | 0.3000 | 0.2000 / 0.1000; 0.0500; 1.020× | 0.1500 | 0.2000 |"),
            "{details}"
        );
        assert!(section.contains("bench --truth"), "{section}");
        assert!(section.contains("no Marschner BSDF"), "{section}");
        // The page names the view its frames were measured in: the plan's.
        assert!(section.contains("uses the layered view"), "{section}");
        report.plan.transparency = EnvTransparency::Opaque;
        let opaque = truth_section(&report, "bench-truth");
        assert!(opaque.contains("uses the opaque view"), "{opaque}");
        let page = "# Benchmarks\n\nIntro paragraph.\n\n## Older\n\ntext\n";
        let first = splice_truth(page, &section).unwrap();
        assert!(
            first.starts_with("# Benchmarks\n\nIntro paragraph.\n\n<!-- strandlight bench --truth"),
            "{first}"
        );
        assert!(first.ends_with("## Older\n\ntext\n"), "{first}");
        let again = splice_truth(&first, &section).unwrap();
        assert_eq!(again, first, "a second run replaces the section in place");
        // The other plan's section is spliced independently.
        let both = splice(&again, &format!("{BEGIN}\nX\n{END}\n")).unwrap();
        assert_eq!(splice_truth(&both, &section).unwrap(), both);
    }

    #[test]
    fn the_ladder_names_the_lights_each_rung_was_compared_with() {
        // Eight compact sources ride on every rung: 104 = 8 + 96 is compared with 392 = 8 + 384,
        // not 416, and the last rung with the reference.
        let r = EnvLitResult {
            map: "golf".into(),
            mode: "single".into(),
            reference_lights: 1544,
            reference_ms: 1.0,
            reference_converged: Some(false),
            reference_ladder: vec![(104, 0.12), (392, 0.045)],
            points: Vec::new(),
            speedup_equal_rmse: None,
            speedup_equal_flip: None,
            truth: None,
            speedup_equal_rmse_truth: None,
            speedup_equal_flip_truth: None,
        };
        assert_eq!(
            ladder_rungs(&r),
            ["104 vs 392: 0.1200", "392 vs 1544: 0.0450"]
        );
        let mut table = String::new();
        env_lit_table(&mut table, &r, "plots", "median cut");
        assert!(table.contains("(last rung 392 vs 1544: 0.0450)"), "{table}");
    }

    #[test]
    fn the_regenerate_command_names_maps_only_when_the_run_chose_them() {
        assert_eq!(BenchPlan::quick().regenerate_args(), " --quick");
        assert_eq!(BenchPlan::full().regenerate_args(), "");
        let mut every_map = BenchPlan::quick();
        every_map.maps = BenchPlan::full().maps;
        let args = every_map.regenerate_args();
        assert!(
            args.starts_with(" --quick --maps hdr_overcast_soil_puresky_1k.hdr,quarry_01_1k.hdr,")
        );
        let page = section(&report_of(every_map), "bench");
        assert!(page.contains(&format!("`cargo run --release -- bench{args}`")));
    }

    fn frame(family: &str, ms: f64, relative_rmse: f64) -> Point {
        Point {
            family: family.into(),
            label: String::new(),
            lights: 64,
            ms,
            relative_rmse,
            hdr_flip: 0.2,
            truth: None,
        }
    }

    #[test]
    fn the_goals_table_marks_only_the_goals_met() {
        let met = EnvLitResult {
            map: "quarry".into(),
            mode: "single".into(),
            reference_lights: 6145,
            reference_ms: 1000.0,
            reference_converged: Some(true),
            reference_ladder: Vec::new(),
            points: vec![frame("srbf", 10.0, 0.04), frame("median cut", 50.0, 0.3)],
            speedup_equal_rmse: Some(12.0),
            speedup_equal_flip: None,
            truth: None,
            speedup_equal_rmse_truth: None,
            speedup_equal_flip_truth: None,
        };
        // Below the full-scattering goal, but against a reference that did not converge.
        let unconverged = EnvLitResult {
            map: "golf".into(),
            mode: "full".into(),
            reference_converged: Some(false),
            reference_ms: 50.0,
            speedup_equal_rmse: Some(9.9),
            ..met.clone()
        };
        let mut report = report_of(BenchPlan::full());
        report.env_lit = vec![met, unconverged];
        let mut table = String::new();
        goals_table(&mut table, &report);
        assert!(
            table.contains("| quarry | single | 6145 (converged) | 10 | 0.0400 ✓ | 0.2000 | 100× ✓ | 12.0× ✓ | > 5.0× |"),
            "{table}"
        );
        assert!(
            table.contains(
                "| golf | full | 6145 (not converged) | 10 | 0.0400 | 0.2000 | 5× | 9.9× | > 5.0× |"
            ),
            "{table}"
        );
    }

    #[test]
    fn a_merged_page_names_every_run_instead_of_one_command() {
        let mut merged = report_of(BenchPlan::full());
        let run = |args: &str| crate::bench::BenchRun {
            args: args.into(),
            machine: "m".into(),
            adapter: "a".into(),
        };
        merged.runs = vec![
            run(" --modes single"),
            run(" --maps quarry_01_1k.hdr --modes single --reference-max-lights 6144"),
        ];
        let page = section(&merged, "bench");
        assert!(page.contains("Measured in 2 runs, `bench --modes single`, `bench --maps quarry_01_1k.hdr --modes single --reference-max-lights 6144`"), "{page}");
        assert!(
            page.contains(
                "`bench --from-report` into one report that holds every run's data and arguments ([`bench/report-full.json`](bench/report-full.json))"
            ),
            "{page}"
        );
        assert!(!page.contains("Regenerate with"), "{page}");
    }

    fn step(label: &str, relative_rmse: f64, hdr_flip: Option<f64>) -> DecompositionStep {
        DecompositionStep {
            label: label.into(),
            relative_rmse,
            relative_rmse_noise_corrected: None,
            hdr_flip,
        }
    }

    /// Each step lands in its own column whatever order it was measured in; a part of an image
    /// shows no HDR-FLIP; a page measured before decompositions existed shows no table.
    #[test]
    fn each_decomposition_step_is_shown_in_its_column() {
        use decomposition::*;
        let mut report = report_of(BenchPlan::full());
        assert!(!section(&report, "bench").contains("Where the error comes from"));
        report.decompositions = vec![
            ErrorDecomposition {
                map: "m".into(),
                mode: "single".into(),
                reference_lights: 1536,
                reference_converged: Some(false),
                unshadowed_reference_lights: Some((6144, 1536)),
                unshadowed_converged: Some(true),
                against_truth: false,
                steps: vec![
                    step(DEFAULT_KAPPA, 0.5, Some(0.55)),
                    step(FIT, 0.1, Some(0.11)),
                    step(EVERY_STRAND, 0.4, Some(0.44)),
                    step(TABLES, 0.2, Some(0.22)),
                    step(UNSHADOWED, 0.3, Some(0.33)),
                ],
            },
            ErrorDecomposition {
                map: "m".into(),
                mode: "full".into(),
                reference_lights: 6145,
                reference_converged: Some(true),
                unshadowed_reference_lights: None,
                unshadowed_converged: None,
                against_truth: false,
                steps: vec![
                    step(MULTIPLE_PART, 0.07, None),
                    step(SINGLE_PART, 0.06, None),
                    step(FULL, 0.08, Some(0.09)),
                ],
            },
        ];
        let page = section(&report, "bench");
        assert!(page.contains("| m | 1536 (not converged) (6144, 1536, converged) | 0.1000 / 0.1100 | 0.2000 / 0.2200 | 0.3000 / 0.3300 | 0.4000 / 0.4400 | 0.5000 / 0.5500 |"), "{page}");
        assert!(
            page.contains("| m | 6145 (converged) | 0.0600 | 0.0700 | 0.0800 / 0.0900 |"),
            "{page}"
        );
    }

    /// Against the truth: each frame in its column with its noise-corrected error, a map
    /// without compact sources shows none for their step, and the truth's table is not the
    /// DOM reference's (nor the other way round).
    #[test]
    fn each_step_against_the_truth_is_shown_in_its_column() {
        use decomposition::*;
        let mut report = report_of(BenchPlan::truth());
        let truth_step = |label: &str, e: f64| DecompositionStep {
            relative_rmse_noise_corrected: Some(e - 0.001),
            ..step(label, e, Some(e + 0.1))
        };
        let of = |mode: &str, steps| ErrorDecomposition {
            map: "m".into(),
            mode: mode.into(),
            reference_lights: 1536,
            reference_converged: Some(false),
            unshadowed_reference_lights: None,
            unshadowed_converged: None,
            against_truth: true,
            steps,
        };
        report.decompositions = vec![
            of(
                "single",
                vec![
                    truth_step(TRUTH_VOLUME, 0.35),
                    truth_step(TRUTH_MAP_LIGHTS, 0.31),
                    truth_step(TRUTH_LIGHT_MAPS, 0.34),
                    truth_step(TRUTH_FIT_LIGHTS, 0.32),
                    truth_step(TRUTH_EVERY_STRAND, 0.33),
                ],
            ),
            of(
                "full",
                vec![
                    step(SINGLE_PART, 0.2, None),
                    truth_step(FULL, 0.3),
                    step(MULTIPLE_PART, 0.1, None),
                ],
            ),
        ];
        let page = truth_section(&report, "bench-truth");
        assert!(page.contains("| m | 0.3100 (0.3090) / 0.4100 | 0.3200 (0.3190) / 0.4200 | 0.3300 (0.3290) / 0.4300 | 0.3400 (0.3390) / 0.4400 | 0.3500 (0.3490) / 0.4500 | – |"), "{page}");
        assert!(
            page.contains("| m | 0.2000 | 0.1000 | 0.3000 (0.2990) / 0.4000 |"),
            "{page}"
        );
        assert!(page.contains("4× finer (2048² against 512²"), "{page}");
        assert!(!section(&report, "bench").contains("Where the error comes from"));
    }

    #[test]
    fn the_regenerate_command_repeats_every_changed_flag_and_only_those() {
        let changes = PlanChanges {
            maps: vec!["quarry_01_1k.hdr".into()],
            modes: vec![ScatteringMode::Full],
            reference_max_lights: Some(6144),
            baseline_lights: vec![256, 16, 64, 16],
            baseline: Some(Baseline::MedianCutSources),
            decomposition_only: true,
            head: Some(HeadChoice::Ellipsoid),
            preset: Some("blonde".into()),
        };
        let plan = BenchPlan::quick().changed(&changes).unwrap();
        assert_eq!(plan.baseline_lights, [16, 64, 256]);
        assert_eq!(
            plan.regenerate_args(),
            " --quick --maps quarry_01_1k.hdr --modes full --reference-max-lights 6144 --baseline-lights 16,64,256 --baseline median-cut-sources --decomposition-only --head ellipsoid --preset blonde"
        );
        let unchanged = PlanChanges {
            modes: BenchPlan::full().modes,
            reference_max_lights: Some(BenchPlan::full().reference_max_lights),
            baseline: Some(Baseline::MedianCut),
            ..PlanChanges::default()
        };
        let plan = BenchPlan::full().changed(&unchanged).unwrap();
        assert_eq!(plan.regenerate_args(), "");
    }

    #[test]
    fn a_changed_plan_names_its_bad_value() {
        let bad = |changes: PlanChanges| {
            BenchPlan::quick()
                .changed(&changes)
                .unwrap_err()
                .to_string()
        };
        let too_many = bad(PlanChanges {
            baseline_lights: vec![16, 0],
            ..PlanChanges::default()
        });
        assert!(too_many.contains("--baseline-lights 0"), "{too_many}");
        let not_a_cube = bad(PlanChanges {
            reference_max_lights: Some(1000),
            ..PlanChanges::default()
        });
        assert!(
            not_a_cube.contains("--reference-max-lights 1000"),
            "{not_a_cube}"
        );
        let no_such_fiber = bad(PlanChanges {
            preset: Some("green".into()),
            ..PlanChanges::default()
        });
        assert!(no_such_fiber.contains("--preset green"), "{no_such_fiber}");
    }
}
