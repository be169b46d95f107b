//! Error of the Marschner convolution table against direct f64 integration, by resolution,
//! axis placement and storage: which size buys which error (docs/BENCHMARKS.md).
//! `cargo run --release -p strandlight-precompute --example table_resolution -- [POINTS] [PRESET]`
use rayon::prelude::*;
use std::time::Instant;
use strandlight_precompute::convolution::{ConvolutionSettings, convolve_reference};
use strandlight_precompute::convolution_table::{
    ConvolutionResolution, DirectionAxes, bake_convolution_table,
};
use strandlight_precompute::table_accuracy::{is_axial, stratified_points};
use strandlight_tables::marschner::{Marschner, MarschnerParams};
use strandlight_tables::table::Table;
use strandlight_tables::{FiberAngles, ScatteringFunction};

/// (max, RMS) relative to the table maximum over all points, then over off-axis points.
fn errors(table: &Table, points: &[[f64; 4]], refs: &[[f64; 3]]) -> [f64; 4] {
    let scale = table.stats().max as f64;
    let (mut max, mut sum, mut off_max, mut off_sum, mut off_n) = (0.0f64, 0.0, 0.0f64, 0.0, 0);
    for (p, r) in points.iter().zip(refs) {
        let v = table.lookup_rgb(p).unwrap();
        let e = (0..3)
            .map(|c| (v[c] as f64 - r[c]).abs())
            .fold(0.0, f64::max);
        max = max.max(e);
        sum += e * e;
        if !is_axial(p) {
            off_max = off_max.max(e);
            off_sum += e * e;
            off_n += 1;
        }
    }
    [
        max / scale,
        (sum / points.len() as f64).sqrt() / scale,
        off_max / scale,
        (off_sum / off_n as f64).sqrt() / scale,
    ]
}

fn as_f16(table: &Table) -> Table {
    let v = table
        .values()
        .iter()
        .map(|&x| half::f16::from_f32(x).to_f32())
        .collect();
    Table::new(table.axes().to_vec(), table.channels(), v).unwrap()
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let count: usize = args.first().map(|a| a.parse().unwrap()).unwrap_or(500);
    let preset = args.get(1).cloned().unwrap_or_else(|| "brown".into());
    let m = Marschner::new(MarschnerParams::with_preset(&preset).unwrap()).unwrap();
    let s = |a: &FiberAngles| m.eval(a);
    let points = stratified_points(count, 16.0, 64.0, 11);
    let t = Instant::now();
    let refs: Vec<[f64; 3]> = points
        .par_iter()
        .map(|p| convolve_reference(&s, p[0].asin(), p[1].asin(), p[2].acos(), 1.0 / p[3], 32))
        .collect();
    eprintln!(
        "reference at {count} points: {:.1} s",
        t.elapsed().as_secs_f64()
    );
    println!(
        "| direction nodes | 1/λ nodes | axes | storage | bytes | bake s | max error | RMS error | off-axis max | off-axis RMS |"
    );
    println!("|---:|---:|---|---|---:|---:|---:|---:|---:|---:|");
    for n in [16usize, 24, 32, 48] {
        for axes in [DirectionAxes::Uniform, DirectionAxes::Angular] {
            let res = ConvolutionResolution {
                u_dot_xi: n,
                u_dot_wo: n,
                cos_dphi: n,
                inv_lambda: 2 * n,
                axes,
                ..Default::default()
            };
            let t = Instant::now();
            let table = bake_convolution_table(&s, &res, &ConvolutionSettings::default()).unwrap();
            let secs = t.elapsed().as_secs_f64();
            for (storage, tab, bytes) in [
                ("f32", table.clone(), table.values().len() * 4),
                ("f16", as_f16(&table), table.values().len() * 2),
            ] {
                let [max, rms, off_max, off_rms] = errors(&tab, &points, &refs);
                println!(
                    "| {n} | {} | {axes:?} | {storage} | {bytes} | {secs:.1} | {:.2}% | {:.3}% | {:.2}% | {:.3}% |",
                    2 * n,
                    100.0 * max,
                    100.0 * rms,
                    100.0 * off_max,
                    100.0 * off_rms
                );
            }
        }
    }
}
