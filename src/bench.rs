//! `strandlight bench`: speed against error on the real data in `../shared/data`. The full run
//! rewrites the generated section of docs/BENCHMARKS.md, its every-frame page and its report in
//! docs/bench/, and draws its plots in out/bench/ (the repository keeps pages and data, not
//! images); `--quick` (a few minutes) writes its report and plots to out/bench-quick/ and leaves
//! docs/ alone. `--from-report` draws the plots and the pages again from a saved report without
//! measuring.

use std::path::{Component, Path, PathBuf};

use anyhow::Context;
use clap::Args;

use strandlight_eval::baseline::Baseline;
use strandlight_eval::bench::{BenchPaths, BenchPlan, BenchReport, PlanChanges, run as run_bench};
use strandlight_eval::bench_plots::{Metric, plot};
use strandlight_eval::bench_report::{
    details, report_file, section, splice, splice_truth, truth_details, truth_section,
};
use strandlight_scene::head_input::HeadChoice;
use strandlight_scene::scene_tables::ScatteringMode;
use strandlight_scene::steps::Steps;
use strandlight_tables::atomic_write::write_atomically;
use strandlight_tables::shared_data::shared_data_dir;

#[derive(Args, Debug)]
pub struct BenchArgs {
    /// One map, single scattering, 160×120, a reference of at most 384 lights: a few minutes.
    #[arg(long)]
    pub quick: bool,
    /// Every map in both modes against the path-traced ground truth (Mitsuba 3, which must be
    /// installed: `pip install mitsuba`) with the Chiang fiber: the SRBF default, the median-cut
    /// front and the DOM reference; rewrites the section docs/BENCHMARKS.md opens with.
    #[arg(long, conflicts_with = "quick")]
    pub truth: bool,
    /// The shared data folder (default: $STRANDLIGHT_SHARED_DATA or ../shared/data).
    #[arg(long)]
    pub data: Option<PathBuf>,
    /// Where the report JSON, DETAILS.md and the plots go (default: docs/bench, or
    /// out/bench-quick with --quick); plots of a folder under docs/ go to its path under out/.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// The page whose generated section is rewritten (full runs only).
    #[arg(long, default_value = "docs/BENCHMARKS.md")]
    pub benchmarks: PathBuf,
    /// Only these maps (file names in the data folder's envmaps/, comma-separated).
    #[arg(long, value_delimiter = ',')]
    pub maps: Vec<String>,
    /// Only these scattering modes (default: the plan's; single with --quick, both without).
    #[arg(long, value_enum, value_delimiter = ',')]
    pub modes: Vec<ScatteringMode>,
    /// The most lights the converged reference may climb to (6n²; default: the plan's, 384
    /// with --quick, 1536 without). A map converges when N and 4N lights agree within 1%.
    #[arg(long)]
    pub reference_max_lights: Option<usize>,
    /// The median-cut light counts measured (default: the plan's, 4,16,64 with --quick).
    #[arg(long, value_delimiter = ',')]
    pub baseline_lights: Vec<usize>,
    /// The directional-light baseline (default: median cut over the whole map, as published;
    /// median-cut-sources: the compact sources exactly, median cut over the rest).
    #[arg(long, value_enum)]
    pub baseline: Option<Baseline>,
    /// Measure only where each map's error comes from (fit, tables, one visibility per lobe,
    /// κ, multiple scattering), no sweep: minutes per map with the references cached. Its
    /// report merges (`--from-report`) beside the sweeps' reports of the same maps.
    #[arg(long)]
    pub decomposition_only: bool,
    /// The head in every frame, the ground truth's too: none, ellipsoid (fitted to the strand
    /// roots) or a mesh FILE (.obj, .glb, .gltf, .usd*; several, comma-separated, make one
    /// head) (default: the plan's, none).
    #[arg(long, value_name = "none|ellipsoid|FILE[,FILE...]")]
    pub head: Option<HeadChoice>,
    /// The fiber's melanin preset (white, blonde, red, auburn, brown, dark) in every frame and
    /// ground truth (default: the plan's, brown).
    #[arg(long)]
    pub preset: Option<String>,
    /// Cache folder (fits, tables, reference images), shared with `compare`.
    #[arg(long, default_value = "out/cache")]
    pub cache: PathBuf,
    /// Measure nothing: write the plots and the page again from report JSONs earlier runs
    /// wrote (after a change to how they are drawn, without the hour of measuring). Several
    /// reports of the same plan on different maps or modes (a sweep run map by map, each with
    /// the reference budget its map needs) make one page; runs measured on different machines
    /// may share it, each naming its own.
    #[arg(long, value_name = "REPORT_JSON", num_args = 1.., conflicts_with_all = ["quick", "truth", "maps", "data", "modes", "reference_max_lights", "baseline_lights", "baseline", "decomposition_only", "head", "preset"])]
    pub from_report: Vec<PathBuf>,
}

pub fn run(args: BenchArgs) -> anyhow::Result<()> {
    // Its generated section is rewritten at the end: a page that is not there is said now, not
    // after an hour of measuring (a quick run writes its own REPORT.md instead).
    if !args.quick && !args.benchmarks.is_file() {
        anyhow::bail!(
            "--benchmarks {}: no such page, whose generated section the run would rewrite (copy docs/BENCHMARKS.md there, or name it)",
            args.benchmarks.display()
        );
    }
    let report = match args.from_report.is_empty() {
        false => {
            let reports = args
                .from_report
                .iter()
                .map(|path| read_report(path))
                .collect::<anyhow::Result<Vec<_>>>()?;
            BenchReport::merged(reports).context("merging the --from-report reports")?
        }
        true => match measure(&args)? {
            Some(report) => report,
            None => return Ok(()),
        },
    };
    let quick = report.plan.is_quick();
    // The page's generated section is brown's; a run of another melanin keeps its own page.
    let own_page = quick || report.plan.preset != "brown";
    let out = args.out.clone().unwrap_or_else(|| {
        let folder = match report.plan.name.as_str() {
            "quick" => return PathBuf::from("out/bench-quick"),
            "truth" => "docs/bench-truth",
            _ => "docs/bench",
        };
        match report.plan.preset.as_str() {
            "brown" => PathBuf::from(folder),
            other => PathBuf::from(format!("{folder}-{other}")),
        }
    });
    std::fs::create_dir_all(&out).with_context(|| format!("creating {}", out.display()))?;
    let plots = plots_dir(&out);
    std::fs::create_dir_all(&plots).with_context(|| format!("creating {}", plots.display()))?;
    let json = out.join(report_file(&report));
    write_atomically(&json, |w| {
        serde_json::to_writer_pretty(w, &report).map_err(std::io::Error::other)
    })
    .with_context(|| format!("writing {}", json.display()))?;
    for r in &report.env_lit {
        for metric in Metric::of_result(r) {
            let stem = format!("{}-{}-{}", r.map, r.mode, metric.file_tag());
            let [png, _] = plot(&plots, &stem, r, metric)?;
            println!("wrote {} (and .svg)", png.display());
        }
    }
    let details_page = out.join("DETAILS.md");
    let plots_from_details = relative_path(&plots, &out);
    let mut details_text = match report.plan.is_truth() {
        true => truth_details(&report, &plots_from_details),
        false => details(&report, &plots_from_details),
    };
    if plots != out {
        // The command writes into a scratch page and the plots' folder only: run on docs/, it
        // would rewrite an older report in today's format and a page's generated section.
        let note = format!(
            "Its plots are not kept in the repository. `mkdir -p out && cp docs/BENCHMARKS.md out/page.md && strandlight bench --from-report {} --out {plots} --benchmarks out/page.md` draws them into `{plots}/`, where the images below point, without touching docs/.",
            slashed(&json),
            plots = slashed(&plots)
        );
        details_text = after_title(&details_text, &note);
    }
    write_atomically(&details_page, |w| {
        std::io::Write::write_all(w, details_text.as_bytes())
    })
    .with_context(|| format!("writing {}", details_page.display()))?;
    println!("wrote {}", details_page.display());
    if own_page {
        let page = out.join("REPORT.md");
        let text = match report.plan.is_truth() {
            true => truth_section(&report, "."),
            false => section(&report, "."),
        };
        write_atomically(&page, |w| std::io::Write::write_all(w, text.as_bytes()))
            .with_context(|| format!("writing {}", page.display()))?;
        println!("wrote {} and {}", page.display(), json.display());
    } else {
        let page = std::fs::read_to_string(&args.benchmarks)
            .with_context(|| format!("reading {}", args.benchmarks.display()))?;
        let relative = relative_path(&out, args.benchmarks.parent().unwrap_or(Path::new(".")));
        let updated = match report.plan.is_truth() {
            true => splice_truth(&page, &truth_section(&report, &relative)),
            false => splice(&page, &section(&report, &relative)),
        }
        .with_context(|| args.benchmarks.display().to_string())?;
        write_atomically(&args.benchmarks, |w| {
            std::io::Write::write_all(w, updated.as_bytes())
        })
        .with_context(|| format!("writing {}", args.benchmarks.display()))?;
        println!(
            "rewrote the generated section of {} ({})",
            args.benchmarks.display(),
            json.display()
        );
    }
    Ok(())
}

/// Runs the plan on the shared data; None (with the reason printed) where that data is absent.
fn measure(args: &BenchArgs) -> anyhow::Result<Option<BenchReport>> {
    let Some(data) = args.data.clone().or_else(shared_data_dir) else {
        println!(
            "skipped: no ../shared/data folder beside the checkout (or --data, $STRANDLIGHT_SHARED_DATA): the benchmark measures the real maps and hair there"
        );
        return Ok(None);
    };
    if !data.join("hair/straight.hair").is_file() {
        println!(
            "skipped: {} has no hair/straight.hair, the benchmark's hair",
            data.display()
        );
        return Ok(None);
    }
    let base = match (args.quick, args.truth) {
        (true, _) => BenchPlan::quick(),
        (_, true) => BenchPlan::truth(),
        _ => BenchPlan::full(),
    };
    let plan = base.changed(&PlanChanges {
        maps: args.maps.clone(),
        modes: args.modes.clone(),
        reference_max_lights: args.reference_max_lights,
        baseline_lights: args.baseline_lights.clone(),
        baseline: args.baseline,
        decomposition_only: args.decomposition_only,
        head: args.head.clone(),
        preset: args.preset.clone(),
    })?;
    let mut steps = Steps::new(false);
    let paths = BenchPaths {
        data,
        cache: args.cache.clone(),
        scratch: PathBuf::from("out/bench-scratch"),
    };
    run_bench(&plan, &paths, &mut steps).map(Some)
}

fn read_report(path: &std::path::Path) -> anyhow::Result<BenchReport> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    serde_json::from_str(&text).with_context(|| {
        format!(
            "{} is not a report `strandlight bench` wrote",
            path.display()
        )
    })
}

/// Where the plots of pages written to `out` go. A folder under docs/ keeps what a reader needs
/// in the repository, the pages and their report, and hundreds of per-map images would crowd it
/// (issue 61): its plots go to the same path under out/ (ignored by git), where the run and
/// `--from-report` draw them. Any other folder takes its plots too.
fn plots_dir(out: &Path) -> PathBuf {
    let relative: PathBuf = out
        .components()
        .skip_while(|c| matches!(c, Component::CurDir))
        .collect();
    match relative.strip_prefix("docs") {
        Ok(rest) => Path::new("out").join(rest),
        Err(_) => out.to_path_buf(),
    }
}

/// `path` relative to the folder `base`, for a Markdown link from a page in `base` (docs/bench
/// from docs → "bench", out/bench from docs/bench → "../../out/bench").
fn relative_path(path: &Path, base: &Path) -> String {
    // An empty parent (a page named without a folder) is the working folder.
    let absolute = |p: &Path| match p.as_os_str().is_empty() {
        true => std::path::absolute("."),
        false => std::path::absolute(p),
    };
    let (Ok(path_abs), Ok(base_abs)) = (absolute(path), absolute(base)) else {
        return slashed(path);
    };
    let (to, from) = (normal_components(&path_abs), normal_components(&base_abs));
    let common = to.iter().zip(&from).take_while(|(a, b)| a == b).count();
    let parts: Vec<String> = std::iter::repeat_n("..".to_string(), from.len() - common)
        .chain(
            to[common..]
                .iter()
                .map(|c| c.as_os_str().to_string_lossy().into_owned()),
        )
        .collect();
    match parts.is_empty() {
        true => ".".into(),
        false => parts.join("/"),
    }
}

fn normal_components(path: &Path) -> Vec<Component<'_>> {
    path.components()
        .filter(|c| !matches!(c, Component::CurDir))
        .collect()
}

/// A path as Markdown and a shell on any platform write it.
fn slashed(path: &Path) -> String {
    path.components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect::<Vec<_>>()
        .join("/")
}

/// `page` with the paragraph `note` after its first line (its title).
fn after_title(page: &str, note: &str) -> String {
    match page.split_once("\n\n") {
        Some((title, rest)) => format!("{title}\n\n{note}\n\n{rest}"),
        None => format!("{page}\n\n{note}\n"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plots_of_a_page_under_docs_go_to_out() {
        let cases = [
            ("docs/bench", "out/bench"),
            ("./docs/bench-truth/layered", "out/bench-truth/layered"),
            ("out/bench-quick", "out/bench-quick"),
            ("elsewhere/docs", "elsewhere/docs"),
        ];
        for (out, plots) in cases {
            assert_eq!(plots_dir(Path::new(out)), PathBuf::from(plots), "{out}");
        }
    }

    #[test]
    fn links_between_folders_climb_out_of_the_page() {
        let cases = [
            ("docs/bench", "docs", "bench"),
            (
                "out/bench-truth/layered",
                "docs/bench-truth/layered",
                "../../../out/bench-truth/layered",
            ),
            ("out/bench-quick", "out/bench-quick", "."),
            ("docs/bench", "", "docs/bench"),
        ];
        for (path, base, want) in cases {
            assert_eq!(
                relative_path(Path::new(path), Path::new(base)),
                want,
                "{path} from {base}"
            );
        }
    }

    #[test]
    fn the_note_goes_under_the_title() {
        let page = after_title("# Title\n\nGenerated by bench.\n\n## A map\n", "NOTE");
        assert_eq!(page, "# Title\n\nNOTE\n\nGenerated by bench.\n\n## A map\n");
    }
}
