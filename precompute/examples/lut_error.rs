//! Error of the Hunz 2016 point-light lookup textures (M over sin θ_i × sin θ_o, N over
//! cos φ × cos θ_d) against the direct Marschner model, for several texture sizes, as a
//! markdown table. Run: `cargo run --release -p strandlight-precompute --example lut_error`
//! (optional arguments: preset name, sample count per domain).

use strandlight_precompute::point_light_luts::{
    AzimuthAxis, CosThetaDSource, LutResolution, PointLightLuts, check_luts, stratified_points,
};
use strandlight_tables::marschner::{Marschner, MarschnerParams};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let preset = args.next().unwrap_or_else(|| "brown".into());
    let samples: usize = args
        .next()
        .map(|s| s.parse())
        .transpose()?
        .unwrap_or(40_000);
    let model = Marschner::new(MarschnerParams::with_preset(&preset)?)?;
    println!(
        "Marschner preset `{preset}`, {samples} stratified points per domain (inclinations |θ_i|, |θ_o| ≤ limit); \
         errors relative to the max of S over the points; max rel over S > 1% of that max.\n"
    );
    println!(
        "| nodes per axis | bytes | N azimuth axis | |θ| ≤ | cos θ_d from | max S | max abs | RMS abs | max rel | worst (θ_i, θ_o, φ)° |"
    );
    println!("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |");
    let variants = [
        (AzimuthAxis::CosPhi, CosThetaDSource::Table),
        (AzimuthAxis::CosPhi, CosThetaDSource::ClosedForm),
        (AzimuthAxis::CosHalfPhi, CosThetaDSource::ClosedForm),
    ];
    for n in [32, 64, 128, 256, 512] {
        for (azimuth_axis, source) in variants {
            let res = LutResolution {
                azimuth_axis,
                ..LutResolution::square(n)
            };
            let luts = PointLightLuts::bake(&model, &res)?;
            for limit_deg in [45.0f64, 60.0, 80.0, 90.0] {
                let points = stratified_points(&model, samples, limit_deg.to_radians(), 1);
                let acc = check_luts(&preset, &luts, source, &model, &points)?;
                let w = acc.worst_point.map(f64::to_degrees);
                println!(
                    "| {n} | {} | {} | {limit_deg}° | {:?} | {:.3e} | {:.2e} | {:.2e} | {:.2e} | ({:.1}, {:.1}, {:.1}) |",
                    luts.bytes(),
                    azimuth_axis.name(),
                    source,
                    acc.reference_max,
                    acc.max_abs_error,
                    acc.rms_abs_error,
                    acc.max_rel_error,
                    w[0],
                    w[1],
                    w[2]
                );
            }
        }
    }
    Ok(())
}
