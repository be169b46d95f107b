//! Bakes the Marschner convolution table at a given resolution and checks it.
//! `cargo run --release -p strandlight-precompute --example marschner_table -- N_DIR N_LAMBDA POINTS [EXPONENT]`
use std::time::Instant;
use strandlight_precompute::convolution::ConvolutionSettings;
use strandlight_precompute::convolution_table::{ConvolutionResolution, bake_convolution_table};
use strandlight_precompute::table_accuracy::{check_table, stratified_points};
use strandlight_tables::ScatteringFunction;
use strandlight_tables::marschner::{Marschner, MarschnerParams};

fn main() {
    let args: Vec<f64> = std::env::args()
        .skip(1)
        .map(|a| a.parse().unwrap())
        .collect();
    let (n, nl, pts) = (args[0] as usize, args[1] as usize, args[2] as usize);
    let angular = args.get(3).copied().unwrap_or(0.0) > 0.0;
    let axes = if angular {
        strandlight_precompute::convolution_table::DirectionAxes::Angular
    } else {
        Default::default()
    };
    let m = Marschner::new(MarschnerParams::default()).unwrap();
    let s = |a: &strandlight_tables::FiberAngles| m.eval(a);
    let res = ConvolutionResolution {
        u_dot_xi: n,
        u_dot_wo: n,
        cos_dphi: n,
        inv_lambda: nl,
        axes,
        ..Default::default()
    };
    let t = Instant::now();
    let table = bake_convolution_table(&s, &res, &ConvolutionSettings::default()).unwrap();
    let bake_s = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let acc = check_table(
        "marschner",
        &table,
        &s,
        &stratified_points(pts, 16.0, 64.0, 1),
        32,
    )
    .unwrap();
    println!(
        "{n}^3x{nl} {axes:?}: bake {bake_s:.2} s, check {:.1} s: max {:.3e} rms {:.3e} maxrel {:.3e} worst {:?}",
        t.elapsed().as_secs_f64(),
        acc.max_abs_error,
        acc.rms_abs_error,
        acc.max_rel_error,
        acc.worst_point
    );
}
