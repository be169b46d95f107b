//! Bake time and `check-tables` accuracy of the Chiang tables beside Marschner's, same fiber
//! preset, same resolution, same run.
//!
//! `cargo run --release -p strandlight-precompute --example chiang_bake -- [N] [POINTS] [TABLES] [PRESET]`
//!
//! N: nodes per direction axis of `BakeResolution::reduced(N)`, 0 for the default resolution
//! (default 0). POINTS: check points per table, 0 to skip the check (default 2000). TABLES:
//! comma-separated job names (default `marschner,chiang`). PRESET: melanin preset (`brown`).

use std::time::Instant;
use strandlight_precompute::bake::bake_job;
use strandlight_precompute::bake_plan::{
    BakeResolution, FiberDescription, Model, PlanOptions, plan,
};
use strandlight_precompute::baked_tables_check::check_asset;
use strandlight_tables::asset::{Storage, read_asset};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let n: usize = args.first().map_or(Ok(0), |a| a.parse())?;
    let points: usize = args.get(1).map_or(Ok(2000), |a| a.parse())?;
    let wanted: Vec<String> = args
        .get(2)
        .map_or("marschner,chiang", |s| s.as_str())
        .split(',')
        .map(str::to_string)
        .collect();
    let preset = args.get(3).map_or("brown", |s| s.as_str());
    let resolution = if n == 0 {
        BakeResolution::default()
    } else {
        BakeResolution::reduced(n)
    };
    let fiber = FiberDescription::preset(preset)?;
    let options = PlanOptions {
        models: vec![Model::Marschner, Model::Chiang],
        resolution: resolution.clone(),
        force_multiple: true,
        ..Default::default()
    };
    let dir = std::env::temp_dir().join(format!("strandlight-chiang-bake-{}", std::process::id()));
    let t = Instant::now();
    let jobs = plan(&fiber, &options)?.jobs;
    println!(
        "fiber {preset}, {} ({:?} convolution nodes, {:?}); {} threads; plan {:.2} s",
        if n == 0 {
            "default resolution".to_string()
        } else {
            format!("BakeResolution::reduced({n})")
        },
        [
            resolution.convolution.u_dot_xi,
            resolution.convolution.u_dot_wo,
            resolution.convolution.cos_dphi,
            resolution.convolution.inv_lambda
        ],
        resolution.settings,
        rayon::current_num_threads(),
        t.elapsed().as_secs_f64()
    );
    for job in jobs
        .into_iter()
        .filter(|j| wanted.iter().any(|w| w == j.name))
    {
        let t = Instant::now();
        let baked = bake_job(job, &dir, Storage::F32)?;
        let bake_s = t.elapsed().as_secs_f64();
        print!(
            "{:<20} bake {bake_s:>8.2} s {:>10} bytes",
            baked.name, baked.bytes
        );
        if points > 0 {
            let t = Instant::now();
            let acc = check_asset(&read_asset(&baked.path)?, points, 1)?;
            print!(
                " | check {:.1} s, {points} points: max {:.3e} rms {:.3e} (of the table's max) max rel(>1%) {:.3e}, worst at {:.3?}",
                t.elapsed().as_secs_f64(),
                acc.max_abs_error,
                acc.rms_abs_error,
                acc.max_rel_error,
                acc.worst_point
            );
        }
        println!();
    }
    std::fs::remove_dir_all(&dir)?;
    Ok(())
}
