//! `strandlight fit ENVMAP`: environment map in, SRBF lights out (or the median-cut baseline
//! with `--directional N`), in the map's own frame: a frame turns the map (`render --rotate`),
//! not its fit. Parsing, progress and printing only; the work is in `strandlight_precompute`.

use anyhow::Context;
use std::path::{Path, PathBuf};
use strandlight_precompute::srbf_set::SrbfSet;
use strandlight_precompute::{FitOptions, preview};
use strandlight_scene::environment::load_env;

#[derive(clap::Args)]
pub struct FitArgs {
    /// A Radiance .hdr or OpenEXR equirectangular map (2:1), or procedural:sun_and_sky /
    /// procedural:studio.
    pub envmap: String,
    /// Stop adding lobes at this count.
    #[arg(long, default_value_t = 64)]
    pub max_lobes: usize,
    /// Lobes placed (by importance) before the first optimization.
    #[arg(long, default_value_t = 30)]
    pub initial_lobes: usize,
    /// Target relative MSE Σw‖fit−map‖²/Σw‖map‖² (the paper's "15%" criterion).
    #[arg(long, default_value_t = 0.15)]
    pub target_error: f64,
    #[arg(long, default_value_t = 16.0)]
    pub lambda_min: f64,
    /// The narrowest lobe's bandwidth (default 256; the paper's is 64).
    #[arg(long, default_value_t = strandlight_precompute::srbf_fit::DEFAULT_LAMBDA_MAX)]
    pub lambda_max: f64,
    /// Width of the prefiltered grid the fit runs on (height = width/2); λ_max ≤ width²/64.
    #[arg(long, default_value_t = 256)]
    pub grid_width: usize,
    /// Most compact bright sources (suns, lamps) taken out as directional lights before the
    /// fit; 0 fits SRBFs alone, as the paper.
    #[arg(long, default_value_t = strandlight_precompute::compact_sources::SourceOptions::default().max_sources)]
    pub sources: usize,
    /// Angular radius of a compact source, degrees.
    #[arg(long, default_value_t = strandlight_precompute::compact_sources::SourceOptions::default().radius_degrees)]
    pub source_radius: f64,
    /// Least share of the (remaining) map's squared norm Σ w‖L‖² a compact source must hold
    /// above its surroundings.
    #[arg(long, default_value_t = strandlight_precompute::compact_sources::SourceOptions::default().min_norm_share)]
    pub source_min_share: f64,
    /// Take the sources at this wider radius (degrees) instead where they hold ≥ 10 points
    /// more of the map's power (extended lamps: a studio's softboxes, a wide sun); 0: never.
    #[arg(long, value_name = "DEGREES", default_value_t = strandlight_precompute::compact_sources::DEFAULT_WIDER_RADIUS_DEGREES)]
    pub wider_source_radius: f64,
    /// Replace NaN/negative values by 0 and +Inf by the largest finite value instead of refusing.
    #[arg(long)]
    pub sanitize: bool,
    /// Instead of SRBFs, write N median-cut directional lights (Debevec 2005) for comparison.
    #[arg(long, value_name = "N")]
    pub directional: Option<usize>,
    /// Output file (default: ENVMAP's stem + .srbf.json or .directional-N.json, here).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Write original | reconstruction | |error| side by side as a PNG. The reconstruction is
    /// the lobes alone: compact sources (listed on stderr) show in the error panel.
    #[arg(long, value_name = "FILE.png")]
    pub preview: Option<PathBuf>,
    /// Print one JSON object with the result on stdout.
    #[arg(long)]
    pub json: bool,
}

pub fn run(args: FitArgs) -> anyhow::Result<()> {
    let env = load_env(&args.envmap, args.sanitize)?;
    let (map, name) = (&env.map, env.name.clone());
    let options = FitOptions {
        initial_lobes: args.initial_lobes,
        max_lobes: args.max_lobes,
        target_relative_mse: args.target_error,
        lambda_min: args.lambda_min,
        lambda_max: args.lambda_max,
        grid_width: args.grid_width,
        sources: strandlight_precompute::compact_sources::SourceOptions {
            max_sources: if args.directional.is_some() {
                0
            } else {
                args.sources
            },
            radius_degrees: args.source_radius,
            min_norm_share: args.source_min_share,
        },
        wider_source_radius: strandlight_precompute::compact_sources::wider_radius(
            args.wider_source_radius,
        ),
        ..FitOptions::default()
    };
    let source = env.source();
    let set = match args.directional {
        Some(n) => SrbfSet::directional(&source, n, &options),
        None => {
            let bar = indicatif::ProgressBar::new(args.max_lobes as u64);
            bar.set_style(
                indicatif::ProgressStyle::with_template(
                    "{elapsed_precise} [{bar:40}] {pos}/{len} lobes  {msg}",
                )
                .expect("valid template"),
            );
            let set = SrbfSet::fit(&source, &options, &mut |r| {
                bar.set_position(r.lobes as u64);
                bar.set_message(format!("relative MSE {:.4}", r.relative_mse));
            })?;
            bar.finish_and_clear();
            set
        }
    };
    let stem = Path::new(name.trim_start_matches("procedural:"))
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned());
    let out = args.out.clone().unwrap_or_else(|| {
        let stem = stem.unwrap_or_else(|| "envmap".into());
        match args.directional {
            Some(n) => PathBuf::from(format!("{stem}.directional-{n}.json")),
            None => PathBuf::from(format!("{stem}.srbf.json")),
        }
    });
    set.save(&out)?;
    if let Some(png) = &args.preview {
        preview::write_preview(map, &set.lobes, 512, png)
            .with_context(|| format!("writing {}", png.display()))?;
        eprintln!("preview: {} (tonemap: {})", png.display(), preview::TONEMAP);
    }
    for s in &set.sources {
        eprintln!(
            "compact source toward ({:.4}, {:.4}, {:.4}): power {:.4e} {:.4e} {:.4e} ({:.1}% of the map's), a directional light spread {:.2}° (rms per axis)",
            s.direction[0],
            s.direction[1],
            s.direction[2],
            s.power[0],
            s.power[1],
            s.power[2],
            100.0 * s.power_share,
            s.angular_variance.sqrt().to_degrees()
        );
    }
    eprintln!(
        "{}: {} {} lights, relative L2 error {:.4}, relative MSE {:.4} (full resolution {:.4}), {:.2} s → {}",
        name,
        set.lobes.len(),
        if args.directional.is_some() {
            "directional"
        } else {
            "SRBF"
        },
        set.relative_l2_error,
        set.relative_mse,
        set.full_resolution_relative_mse,
        set.seconds,
        out.display()
    );
    if args.json {
        let summary = serde_json::json!({
            "source": set.source,
            "kind": set.kind,
            "lobes": set.lobes.len(),
            "sources": set.sources,
            "relative_l2_error": set.relative_l2_error,
            "relative_mse": set.relative_mse,
            "full_resolution_relative_mse": set.full_resolution_relative_mse,
            "power_ratio": set.power_ratio,
            "seconds": set.seconds,
            "out": out,
        });
        println!("{summary}");
    }
    Ok(())
}
