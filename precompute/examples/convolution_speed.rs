//! Times the SRBF convolution at the paper's resolution (32·32·32·64) for a smooth test function.
//! `cargo run --release -p strandlight-precompute --example convolution_speed`
use std::time::Instant;
use strandlight_precompute::convolution::*;
use strandlight_tables::FiberAngles;

fn main() {
    let uniform = |n: usize, a: f64, b: f64| (0..n).map(|i| a + (b - a) * i as f64 / (n - 1) as f64).collect::<Vec<_>>();
    let inv = uniform(64, 1.0 / 64.0, 1.0 / 16.0);
    let grid = ConvolutionGrid {
        sin_theta_xi: uniform(32, -1.0, 1.0),
        sin_theta_o: uniform(32, -1.0, 1.0),
        cos_delta_phi: uniform(32, -1.0, 1.0),
        lambda: inv.iter().map(|v| 1.0 / v).collect(),
    };
    let s = |a: &FiberAngles| {
        let b = (-(a.theta_h() - 0.1).powi(2) / 0.01).exp();
        [b * (1.0 + a.phi.cos()), b, b * (a.phi / 2.0).cos().abs()]
    };
    let t = Instant::now();
    let v = convolve_grid(&s, &grid, &ConvolutionSettings::default());
    println!("{} entries in {:.2} s (checksum {:.6})", v.len(), t.elapsed().as_secs_f64(), v.iter().map(|x| x[0]).sum::<f64>());
}
