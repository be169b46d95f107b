//! Load time of hair files: `cargo run --release -p strandlight-runtime --example load_timing --
//! LOADS FILE…` loads each file LOADS times and prints the median and the model's size
//! (`scripts/scene_groom_load_bench.py` runs it on one groom as `.hair`, USD and Alembic).

use std::path::Path;
use std::time::Instant;

use strandlight_runtime::hair;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let loads: usize = args
        .next()
        .ok_or("usage: load_timing LOADS FILE…")?
        .parse()?;
    for file in args {
        let path = Path::new(&file);
        let bytes = std::fs::metadata(path)?.len();
        let mut seconds = Vec::with_capacity(loads);
        let mut summary = String::new();
        for _ in 0..loads.max(1) {
            let start = Instant::now();
            let loaded = hair::load(path)?;
            seconds.push(start.elapsed().as_secs_f64());
            summary = format!(
                "{} strands, {} points",
                loaded.model.strand_count(),
                loaded.model.point_count()
            );
        }
        seconds.sort_by(f64::total_cmp);
        println!(
            "{file}: {:.1} MB, median {:.1} ms of {} loads (min {:.1}, max {:.1}); {summary}",
            bytes as f64 / 1e6,
            1e3 * seconds[seconds.len() / 2],
            seconds.len(),
            1e3 * seconds[0],
            1e3 * seconds[seconds.len() - 1]
        );
    }
    Ok(())
}
