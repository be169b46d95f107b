//! Timings of the table container at the paper's I_M resolution (32 × 32 × 32 × 64, RGB):
//! parallel fill, random lookups, asset write/read in f32 and f16, slice pictures.
//! Run: `cargo run -p strandlight-tables --profile test --example table_bench [out_dir]`
//! (machines are shared: compare ratios, not absolute times).

use std::path::PathBuf;
use std::time::Instant;
use strandlight_tables::asset::{
    AssetDescription, CreationInfo, Generator, Storage, read_asset, write_asset,
};
use strandlight_tables::slices::{PngTonemap, SliceLayout, write_slices};
use strandlight_tables::table::{Axis, Table};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = std::env::args()
        .nth(1)
        .map(PathBuf::from)
        .unwrap_or_else(std::env::temp_dir);
    std::fs::create_dir_all(&out)?;
    let axes = vec![
        Axis::uniform("u·ξ", -1.0, 1.0, 32),
        Axis::uniform("u·ω_o", -1.0, 1.0, 32),
        Axis::uniform("cos(φ_ξ − φ_o)", -1.0, 1.0, 32),
        Axis::power("1/λ", 1.0 / 1024.0, 1.0, 64, 2.0),
    ];
    // A smooth stand-in for I_M: a lobe around u·ξ = −u·ω_o whose width grows with 1/λ.
    let lobe = |x: &[f64], out: &mut [f32]| {
        let d = x[0] + x[1];
        let w = 0.05 + x[3];
        let v = (-(d * d) / (w * w)).exp() * (1.0 + 0.5 * x[2]) / w;
        out.copy_from_slice(&[v as f32, 0.8 * v as f32, 0.6 * v as f32]);
    };
    let t = Instant::now();
    let table = Table::from_fn(axes, 3, lobe)?;
    println!(
        "from_fn 32×32×32×64×3 ({} values): {:.1} ms",
        table.values().len(),
        t.elapsed().as_secs_f64() * 1e3
    );

    // Random lookups from a fixed LCG, summed so the work is not optimized away.
    let mut state = 0x1234_5678_u64;
    let mut next = || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let n = 2_000_000;
    let points: Vec<[f64; 4]> = (0..n)
        .map(|_| {
            [
                2.0 * next() - 1.0,
                2.0 * next() - 1.0,
                2.0 * next() - 1.0,
                next(),
            ]
        })
        .collect();
    let t = Instant::now();
    let mut sum = 0.0f64;
    for p in &points {
        sum += table.lookup_rgb(p)?[0] as f64;
    }
    let dt = t.elapsed().as_secs_f64();
    println!(
        "lookup_rgb: {:.1} ns per lookup ({n} random 4-D lookups, checksum {sum:.3})",
        dt / n as f64 * 1e9
    );

    let description = AssetDescription {
        name: "I_M-standin".into(),
        quantity: "benchmark stand-in lobe".into(),
        scattering_function: "none".into(),
        fiber_parameters: serde_json::json!({}),
        generator: Generator {
            name: "table_bench".into(),
            version: env!("CARGO_PKG_VERSION").into(),
        },
        created: CreationInfo::now(),
        inputs_key: None,
    };
    for storage in [Storage::F32, Storage::F16] {
        let path = out.join(format!("bench-{storage:?}.sltab"));
        let t = Instant::now();
        write_asset(&path, &table, &description, storage)?;
        let write_ms = t.elapsed().as_secs_f64() * 1e3;
        let t = Instant::now();
        let asset = read_asset(&path)?;
        let read_ms = t.elapsed().as_secs_f64() * 1e3;
        let max_err = table
            .values()
            .iter()
            .zip(asset.table.values())
            .map(|(a, b)| (a - b).abs())
            .fold(0.0f32, f32::max);
        println!(
            "{storage:?} asset: {} bytes, write {write_ms:.1} ms, read+verify {read_ms:.1} ms, max |error| {max_err:e} (table max {:e})",
            std::fs::metadata(&path)?.len(),
            table.stats().max
        );
    }
    let t = Instant::now();
    let (picture, tonemap) = write_slices(
        &table,
        &SliceLayout::default_for(&table),
        &out.join("bench-slices.exr"),
        &out.join("bench-slices.png"),
        PngTonemap::LinearSrgb,
    )?;
    println!(
        "slices {}×{} px (EXR + PNG): {:.1} ms; PNG tonemap: {tonemap}",
        picture.width,
        picture.height,
        t.elapsed().as_secs_f64() * 1e3
    );
    println!("stats: {:?}", table.stats());
    Ok(())
}
