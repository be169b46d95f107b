//! Direct-table accuracy against node count: bakes `marschner_direct`, `marschner_full_direct`
//! and `artist_direct` of a preset fiber at several resolutions and checks each against direct
//! f64 evaluation at random off-grid points (the `check-tables` check).
//!
//! `cargo run --release -p strandlight-precompute --example direct_resolution -- [PRESET] [N...]`

use std::time::Instant;
use strandlight_precompute::bake::bake_job;
use strandlight_precompute::bake_plan::{
    BakeResolution, FiberDescription, Model, PlanOptions, plan,
};
use strandlight_precompute::baked_tables_check::check_asset;
use strandlight_tables::asset::{Storage, read_asset};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let preset = args.first().cloned().unwrap_or_else(|| "brown".into());
    let counts: Vec<usize> = if args.len() > 1 {
        args[1..]
            .iter()
            .map(|a| a.parse())
            .collect::<Result<_, _>>()?
    } else {
        vec![32, 64, 96, 128]
    };
    let fiber = FiberDescription::preset(&preset)?;
    let dir = std::env::temp_dir().join(format!("strandlight-direct-res-{}", std::process::id()));
    println!("fiber {preset}; errors relative to each table's maximum; 4000 points");
    for n in counts {
        let resolution = BakeResolution {
            direct_direction_nodes: n,
            ..BakeResolution::default()
        };
        let options = PlanOptions {
            models: vec![Model::Marschner, Model::Artist],
            resolution,
            ..Default::default()
        };
        for job in plan(&fiber, &options)?
            .jobs
            .into_iter()
            .filter(|j| j.name.ends_with("_direct"))
        {
            let t = Instant::now();
            let baked = bake_job(job, &dir, Storage::F32)?;
            let bake_s = t.elapsed().as_secs_f64();
            let acc = check_asset(&read_asset(&baked.path)?, 4000, 1)?;
            println!(
                "n={n:<4} {:<22} bake {bake_s:>6.2} s {:>9} bytes | max {:.3e} rms {:.3e} max rel(>1%) {:.3e} | off-axis max {:.3e} rms {:.3e}",
                acc.name,
                baked.bytes,
                acc.max_abs_error,
                acc.rms_abs_error,
                acc.max_rel_error,
                acc.off_axis_max_abs_error,
                acc.off_axis_rms_abs_error
            );
        }
    }
    std::fs::remove_dir_all(&dir)?;
    Ok(())
}
