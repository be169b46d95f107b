//! `strandlight bake`, `check-tables` and `inspect`: the convolution tables of Ren 2010 §4/§6
//! and the point-light lookup textures, baked, checked against f64 integration, and pictured.

use anyhow::{Context, bail};
use indicatif::{ProgressBar, ProgressStyle};
use serde_json::json;
use std::path::{Path, PathBuf};
use std::time::Instant;
use strandlight_precompute::bake::{BakedTable, TABLE_EXTENSION, bake_job};
use strandlight_precompute::bake_plan::{
    BakeResolution, DEFAULT_MULTIPLE_THRESHOLD, FiberDescription, Model, PlanOptions, plan,
};
use strandlight_precompute::baked_tables_check::check_asset;
use strandlight_precompute::srbf_set::SrbfSet;
use strandlight_scene::scene_tables::lambda_range_of_set;
use strandlight_tables::asset::{Storage, read_asset};
use strandlight_tables::lut_export::{TexelStorage, export_ktx2, write_wgsl};
use strandlight_tables::slices::{PngTonemap, SliceLayout, write_slices};

#[derive(Clone, Copy, clap::ValueEnum)]
pub enum ModelArg {
    Marschner,
    KajiyaKay,
    Artist,
    /// Chiang et al. 2016 (pbrt-v4, Mitsuba 3, Cycles): the path-traced ground truth's fiber.
    Chiang,
    All,
}

#[derive(clap::Args)]
pub struct BakeArgs {
    /// A named fiber (absorption preset): white, blonde, red, auburn, brown, dark.
    #[arg(long, conflicts_with = "fiber", default_value = "brown")]
    pub preset: String,
    /// A TOML fiber description ([marschner], [kajiya_kay], [artist], [dual_scattering]).
    #[arg(long, value_name = "FILE.toml")]
    pub fiber: Option<PathBuf>,
    #[arg(long, value_enum, default_value = "all")]
    pub model: ModelArg,
    /// An SRBF set from `strandlight fit`: the λ axis then spans only its λ range (±10%).
    #[arg(long, value_name = "FILE.json")]
    pub srbf: Option<PathBuf>,
    /// Nodes per direction axis (λ and σ̄_f get twice as many). Default: the paper's 32/64.
    #[arg(long, value_name = "N")]
    pub resolution: Option<usize>,
    /// Store values as f16 (half the bytes; relative error ≤ 2⁻¹¹).
    #[arg(long)]
    pub half: bool,
    /// Bake the multiple-scattering table even for hair too dark to need it.
    #[arg(long)]
    pub force_multiple: bool,
    #[arg(long, default_value = "tables")]
    pub out: PathBuf,
    #[arg(long)]
    pub json: bool,
    /// Also write every table as a texture other engines load: OUT/ktx2/NAME.ktx2 with a JSON
    /// sidecar (axes, texel centres, sampling formula) and strandlight_lut.wgsl.
    #[arg(long, value_enum, value_name = "CONTAINER")]
    pub export: Option<ExportContainer>,
    /// Texel type of --export: half (rgba16float, filterable on every device; max relative
    /// error 2⁻¹¹) or float (rgba32float, exact).
    #[arg(long, value_enum, default_value = "half", requires = "export")]
    pub export_format: ExportFormat,
}

#[derive(Clone, Copy, clap::ValueEnum)]
pub enum ExportContainer {
    /// Khronos KTX 2.0.
    Ktx2,
}

#[derive(Clone, Copy, clap::ValueEnum)]
pub enum ExportFormat {
    Half,
    Float,
}

#[derive(clap::Args)]
pub struct CheckArgs {
    /// A folder of baked tables (or one table file).
    pub dir: PathBuf,
    /// Random off-grid points per table.
    #[arg(long, default_value_t = 2000)]
    pub samples: usize,
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    #[arg(long)]
    pub json: bool,
}

#[derive(clap::Args)]
pub struct InspectArgs {
    pub table: PathBuf,
    /// Writes the tiled slice picture (Ren 2010 Fig. 3 style) here as PNG, and beside it as EXR.
    #[arg(long, value_name = "OUT.png")]
    pub slices: Option<PathBuf>,
}

/// Prints a line above the progress bar, or plainly when there is no terminal to draw it on.
fn say(bar: &ProgressBar, line: String) {
    if bar.is_hidden() {
        println!("{line}");
    } else {
        bar.println(line);
    }
}

fn progress(len: u64, hidden: bool) -> ProgressBar {
    if hidden {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(len);
    bar.set_style(
        ProgressStyle::with_template("{spinner} [{elapsed_precise}] {bar:30} {pos}/{len} {msg}")
            .unwrap(),
    );
    bar
}

/// λ range of an SRBF set file with a 10% margin, clamped to what tables can hold.
fn lambda_range_of(path: &Path) -> anyhow::Result<(f64, f64)> {
    let set = SrbfSet::load(path)?;
    lambda_range_of_set(&set).with_context(|| path.display().to_string())
}

pub fn bake(args: BakeArgs) -> anyhow::Result<()> {
    let fiber = match &args.fiber {
        Some(path) => FiberDescription::from_toml_file(path)?,
        None => FiberDescription::preset(&args.preset)?,
    };
    let models = match args.model {
        ModelArg::Marschner => vec![Model::Marschner],
        ModelArg::KajiyaKay => vec![Model::KajiyaKay],
        ModelArg::Artist => vec![Model::Artist],
        ModelArg::Chiang => vec![Model::Chiang],
        ModelArg::All => vec![
            Model::Marschner,
            Model::KajiyaKay,
            Model::Artist,
            Model::Chiang,
        ],
    };
    let mut resolution = match args.resolution {
        Some(n) if !(2..=256).contains(&n) => {
            bail!("--resolution {n}: use 2 to 256 nodes per direction axis")
        }
        Some(n) => BakeResolution::reduced(n),
        None => BakeResolution::default(),
    };
    if let Some(srbf) = &args.srbf {
        let (lo, hi) = lambda_range_of(srbf)?;
        resolution = resolution.with_lambda_range(lo, hi);
    }
    let options = PlanOptions {
        models,
        resolution,
        force_multiple: args.force_multiple,
        multiple_threshold: DEFAULT_MULTIPLE_THRESHOLD,
        tables: None,
    };
    let start = Instant::now();
    let plan = plan(&fiber, &options)?;
    if let Some(share) = plan.multiple_scattering_share
        && !args.json
    {
        println!(
            "multiple-scattering share (direction-averaged single-event albedo): {:.1}%",
            100.0 * share
        );
    }
    for s in &plan.skipped {
        if !args.json {
            println!("skipped {}: {}", s.name, s.reason);
        }
    }
    let storage = if args.half {
        Storage::F16
    } else {
        Storage::F32
    };
    let bar = progress(plan.jobs.len() as u64, args.json);
    let mut baked: Vec<BakedTable> = Vec::new();
    for job in plan.jobs {
        bar.set_message(job.name);
        let t = bake_job(job, &args.out, storage)?;
        bar.inc(1);
        if let Some(reason) = &t.replaced_damaged {
            say(
                &bar,
                format!(
                    "warning: {} was damaged and has been rebaked ({reason})",
                    t.path.display()
                ),
            );
        }
        if !args.json {
            say(
                &bar,
                format!(
                    "{:<18} {:>10} bytes {:>7.2} s{}  {}",
                    t.name,
                    t.bytes,
                    t.seconds,
                    if t.cached { " (cached)" } else { "" },
                    t.path.display()
                ),
            );
        }
        baked.push(t);
    }
    bar.finish_and_clear();
    let total = start.elapsed().as_secs_f64();
    let exported = match args.export {
        Some(ExportContainer::Ktx2) => Some(export_ktx2_all(&baked, &args)?),
        None => None,
    };
    if args.json {
        let tables: Vec<_> = baked.iter().map(|t| json!({"name": t.name, "bytes": t.bytes, "seconds": t.seconds, "cached": t.cached, "replaced_damaged": t.replaced_damaged, "path": t.path})).collect();
        println!(
            "{}",
            json!({"tables": tables, "skipped": plan.skipped, "multiple_scattering_share": plan.multiple_scattering_share, "total_seconds": total, "total_bytes": baked.iter().map(|t| t.bytes).sum::<u64>(), "export": exported})
        );
    } else {
        println!(
            "{} tables, {} bytes, {total:.1} s → {}",
            baked.len(),
            baked.iter().map(|t| t.bytes).sum::<u64>(),
            args.out.display()
        );
    }
    Ok(())
}

fn table_files(dir: &Path) -> anyhow::Result<Vec<PathBuf>> {
    if dir.is_file() {
        return Ok(vec![dir.to_path_buf()]);
    }
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .with_context(|| format!("cannot read the table folder {}", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == TABLE_EXTENSION))
        .collect();
    files.sort();
    if files.is_empty() {
        bail!(
            "{}: no .{TABLE_EXTENSION} tables here (run `strandlight bake --out {}` first)",
            dir.display(),
            dir.display()
        );
    }
    Ok(files)
}

/// `--export ktx2`: every baked table as OUT/ktx2/NAME.ktx2 + NAME.json, and the WGSL.
fn export_ktx2_all(baked: &[BakedTable], args: &BakeArgs) -> anyhow::Result<serde_json::Value> {
    let start = Instant::now();
    let dir = args.out.join("ktx2");
    std::fs::create_dir_all(&dir)
        .with_context(|| format!("cannot create the export folder {}", dir.display()))?;
    let storage = match args.export_format {
        ExportFormat::Half => TexelStorage::Half,
        ExportFormat::Float => TexelStorage::Float,
    };
    let mut exports = Vec::new();
    for t in baked {
        let lut = export_ktx2(&read_asset(&t.path)?, &dir, storage)?;
        if !args.json {
            let rounding = lut.half_rounding.map_or(String::new(), |r| {
                format!("  half: max rel. error {:.1e}", r.max_relative_error)
            });
            println!(
                "{:<18} {:>10} bytes  {}×{}×{}{rounding}  {}",
                lut.table,
                lut.texture_bytes,
                lut.width,
                lut.height,
                lut.depth,
                lut.texture.display()
            );
        }
        if let Some((extent, limit)) = lut.exceeds_webgpu_limit {
            eprintln!(
                "warning: {} is {extent} texels along one axis; WebGPU only guarantees {limit} (bake with a smaller --resolution for the web)",
                lut.texture.display()
            );
        }
        exports.push(lut);
    }
    let wgsl = write_wgsl(&dir)?;
    let seconds = start.elapsed().as_secs_f64();
    let bytes: u64 = exports.iter().map(|e| e.texture_bytes).sum();
    if !args.json {
        println!(
            "exported {} textures, {bytes} texel bytes, {seconds:.1} s → {} (sampling: {})",
            exports.len(),
            dir.display(),
            wgsl.display()
        );
    }
    Ok(
        json!({"dir": dir, "textures": exports, "wgsl": wgsl, "seconds": seconds, "texel_bytes": bytes}),
    )
}

pub fn check(args: CheckArgs) -> anyhow::Result<()> {
    let files = table_files(&args.dir)?;
    let bar = progress(files.len() as u64, args.json);
    let mut results = Vec::new();
    for path in files {
        bar.set_message(
            path.file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default(),
        );
        let asset = read_asset(&path)?;
        let t = Instant::now();
        let acc = check_asset(&asset, args.samples, args.seed)?;
        if !args.json {
            say(
                &bar,
                format!(
                    "{:<18} max {:>9.3e}  rms {:>9.3e}  max rel {:>9.3e} over {} points (> 1% of min(max, p99.9)) | off-axis: max {:>9.3e} rms {:>9.3e} | vs p99.9: max {:>9.3e} rms {:>9.3e}  {} samples  {:.1} s",
                    acc.name,
                    acc.max_abs_error,
                    acc.rms_abs_error,
                    acc.max_rel_error,
                    acc.rel_samples,
                    acc.off_axis_max_abs_error,
                    acc.off_axis_rms_abs_error,
                    acc.max_abs_error_p999,
                    acc.rms_abs_error_p999,
                    acc.samples,
                    t.elapsed().as_secs_f64()
                ),
            );
        }
        results.push(acc);
        bar.inc(1);
    }
    bar.finish_and_clear();
    if args.json {
        println!("{}", serde_json::to_string(&results)?);
    } else {
        println!(
            "errors are relative to each table's maximum (and, after |, to its 99.9th percentile of |value|); references: direct f64 integration (see docs/BENCHMARKS.md)"
        );
    }
    Ok(())
}

pub fn inspect(args: InspectArgs) -> anyhow::Result<()> {
    let asset = read_asset(&args.table)?;
    let meta = &asset.metadata;
    println!("{} — {}", meta.description.name, meta.description.quantity);
    for a in asset.table.axes() {
        println!(
            "  axis {:<14} [{}, {}] × {} ({:?})",
            a.name, a.min, a.max, a.count, a.mapping
        );
    }
    let s = asset.table.stats();
    println!(
        "  {} channel(s), {:?} storage, min {:.4e} max {:.4e} mean {:.4e}",
        asset.table.channels(),
        meta.payload.storage,
        s.min,
        s.max,
        s.mean
    );
    println!("  parameters: {}", meta.description.fiber_parameters);
    if let Some(png) = &args.slices {
        let layout = SliceLayout::default_for(&asset.table);
        let exr = png.with_extension("exr");
        let (_, note) = write_slices(
            &asset.table,
            &layout,
            &exr,
            png,
            PngTonemap::Log10 { decades: 4.0 },
        )?;
        println!("wrote {} and {} ({note})", png.display(), exr.display());
    }
    Ok(())
}
