use strandlight_precompute::convolution::*;
use strandlight_tables::marschner::{Marschner, MarschnerParams};
use strandlight_tables::ScatteringFunction;
fn main() {
    let m = Marschner::new(MarschnerParams::default()).unwrap();
    let s = |a: &strandlight_tables::FiberAngles| m.eval(a);
    let p = [-0.95367581098791f64, 0.9720940186952058, 0.3222055460215883, 0.03298213142856389];
    for dso in [-0.02, -0.01, 0.0, 0.01, 0.02] {
        let so = (p[1] + dso).min(1.0);
        let g = ConvolutionGrid { sin_theta_xi: vec![p[0]], sin_theta_o: vec![so], cos_delta_phi: vec![p[2]], lambda: vec![1.0 / p[3]] };
        let f = convolve_grid(&s, &g, &ConvolutionSettings::default())[0];
        let r = convolve_reference(&s, p[0].asin(), so.asin(), p[2].acos(), 1.0 / p[3], 32);
        let r2 = convolve_reference(&s, p[0].asin(), so.asin(), p[2].acos(), 1.0 / p[3], 64);
        println!("so={so:.4}: fast {:.6?} ref32 {:.6?} ref64 {:.6?}", f, r, r2);
    }
}
