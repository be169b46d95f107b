//! Writes the default procedural groom (or one with another seed) as a Cem Yuksel `.hair` file,
//! to look at in other tools: `cargo run -p strandlight-runtime --example write_groom -- out.hair [seed]`.

use std::path::PathBuf;

use strandlight_runtime::hair::{GroomParams, HairWriteOptions, generate_groom, write_hair};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let path = PathBuf::from(args.next().ok_or("usage: write_groom OUT.hair [SEED]")?);
    let seed = args.next().map(|s| s.parse()).transpose()?.unwrap_or(1);
    let start = std::time::Instant::now();
    let model = generate_groom(&GroomParams {
        seed,
        ..GroomParams::default()
    })?;
    let elapsed = start.elapsed();
    let options = HairWriteOptions {
        segments_array: false,
        info: format!("strandlight procedural groom, seed {seed}"),
    };
    write_hair(&model, &path, &options)?;
    println!(
        "{} ({:.1} ms to grow): {}",
        path.display(),
        elapsed.as_secs_f64() * 1e3,
        model.summary()
    );
    Ok(())
}
