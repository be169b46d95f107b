//! Ren 2010 Fig. 5's question, measured on whole images: how close is the effective
//! transmittance of one SRBF light through the convolution optical depth map to the numerical
//! integral over the SRBF's support?
//!
//! The tables are constant (the convolution table ≡ ∫G dω = 2π/λ·(1 − e^{−2λ}), the direct
//! table ≡ 1) and the SRBF amplitude is 1/∫G, so each image IS the transmittance (times the
//! pixel coverage). Reference: the same renderer with N directional lights drawn from G
//! (stratified in cos γ by its inverse CDF and in φ), each of irradiance 1/N, every strand drawn
//! in the light pass (κ = 1); each directional light reads its map's single texel, so the
//! reference averages exact per-direction deep opacity maps. Estimates: the one SRBF light with
//! each [`TransmittanceFilter`], at κ = 1 and κ = 0.1. Error: relative RMSE over hair pixels
//! (reference alpha > 0.01), sqrt(Σ(a − r)² / Σr²), on the red channel (all three are equal).
//!
//! Run: `cargo run --release -p strandlight-runtime --example effective_transmittance --
//! [OUT_DIR] [--procedural] [--strands N] [--size WxH] [--samples N] [--lambdas 16,32,64]`
//! (defaults: out/effective_transmittance, hair/straight.hair from the shared data folder when
//! present else the procedural groom (`--strands`: a groom of N strands), 640x480, 2000 samples, λ ∈ {16, 32, 64}). Writes the
//! reference, paper-support, matched-variance and centre images of each case as PNG.

use std::path::PathBuf;
use std::time::Instant;

use glam::Vec3;
use strandlight_runtime::camera::{Camera, UpAxis};
use strandlight_runtime::env::{
    EnvImage, EnvRenderOptions, EnvRenderer, EnvTables, TransmittanceFilter,
};
use strandlight_runtime::env_light::EnvLight;
use strandlight_runtime::gpu::GpuContext;
use strandlight_runtime::hair::groom::{GroomParams, generate_groom};
use strandlight_runtime::hair::{self, HairModel};
use strandlight_tables::image_out::write_png;
use strandlight_tables::srbf::{integral, sample_cos_gamma};
use strandlight_tables::table::{Axis, Table};
use strandlight_tables::table_axes::{
    AXIS_COS_DPHI, AXIS_INV_LAMBDA, AXIS_U_DOT_WO, AXIS_U_DOT_XI,
};

type BoxError = Box<dyn std::error::Error>;

struct Args {
    out_dir: PathBuf,
    procedural: bool,
    /// Strands of the procedural groom (`None`: `GroomParams::default()`).
    strands: Option<usize>,
    width: u32,
    height: u32,
    samples: usize,
    lambdas: Vec<f32>,
}

fn parse_args() -> Result<Args, BoxError> {
    let mut args = Args {
        out_dir: PathBuf::from("out/effective_transmittance"),
        procedural: false,
        strands: None,
        width: 640,
        height: 480,
        samples: 2000,
        lambdas: vec![16.0, 32.0, 64.0],
    };
    let mut it = std::env::args().skip(1);
    while let Some(a) = it.next() {
        let mut value = |name: &str| it.next().ok_or_else(|| format!("{name} needs a value"));
        match a.as_str() {
            "--procedural" => args.procedural = true,
            "--strands" => {
                let v = value("--strands")?;
                args.strands =
                    Some(v.parse().ok().filter(|&n| n > 0).ok_or_else(|| {
                        format!("--strands {v:?}: expected a positive whole number")
                    })?);
                args.procedural = true;
            }
            "--size" => {
                let v = value("--size")?;
                let (w, h) = v
                    .split_once('x')
                    .ok_or_else(|| format!("--size {v:?}: expected WxH"))?;
                args.width = w.parse().map_err(|_| format!("--size width {w:?}"))?;
                args.height = h.parse().map_err(|_| format!("--size height {h:?}"))?;
            }
            "--samples" => {
                let v = value("--samples")?;
                args.samples =
                    v.parse().ok().filter(|&n| n > 0).ok_or_else(|| {
                        format!("--samples {v:?}: expected a positive whole number")
                    })?;
            }
            "--lambdas" => {
                let v = value("--lambdas")?;
                args.lambdas = v
                    .split(',')
                    .map(|s| {
                        s.parse::<f32>()
                            .ok()
                            .filter(|l| *l >= 16.0 && *l <= 64.0)
                            .ok_or_else(|| format!("--lambdas {s:?}: expected λ in [16, 64]"))
                    })
                    .collect::<Result<_, _>>()?;
            }
            s if s.starts_with("--") => return Err(format!("unknown option {s}").into()),
            s => args.out_dir = PathBuf::from(s),
        }
    }
    Ok(args)
}

/// λ range of the constant SRBF table; 1/16, 1/32 and 1/64 fall on nodes (spacing 1/1024).
const INV_LAMBDA_NODES: usize = 49;

fn constant_tables() -> Result<EnvTables, BoxError> {
    let directions = || {
        vec![
            Axis::uniform(AXIS_U_DOT_XI, -1.0, 1.0, 2),
            Axis::uniform(AXIS_U_DOT_WO, -1.0, 1.0, 2),
            Axis::uniform(AXIS_COS_DPHI, -1.0, 1.0, 2),
        ]
    };
    let mut srbf_axes = directions();
    srbf_axes.push(Axis::uniform(
        AXIS_INV_LAMBDA,
        1.0 / 64.0,
        1.0 / 16.0,
        INV_LAMBDA_NODES,
    ));
    let srbf = Table::from_fn(srbf_axes, 3, |x, out| {
        out.fill(integral(1.0 / x[3]) as f32);
    })?;
    let mut direct_axes = directions();
    direct_axes.push(Axis::uniform("none", 0.0, 0.0, 1));
    let direct = Table::from_fn(direct_axes, 3, |_, out| out.fill(1.0))?;
    Ok(EnvTables {
        srbf: Some(srbf.into()),
        direct: Some(direct.into()),
        multiple: None,
    })
}

/// `n` directions drawn from G around `xi` (a stratified grid: ~√n in cos γ by the inverse CDF,
/// the rest in φ), each a directional light of irradiance 1/n.
fn reference_lights(xi: Vec3, lambda: f32, n: usize) -> Vec<EnvLight> {
    let n_gamma = ((n as f64 * 0.8).sqrt().round() as usize).max(1);
    let n_phi = n.div_ceil(n_gamma);
    let helper = if xi.x.abs() < 0.9 { Vec3::X } else { Vec3::Y };
    let t1 = xi.cross(helper).normalize();
    let t2 = xi.cross(t1);
    let total = n_gamma * n_phi;
    let mut lights = Vec::with_capacity(total);
    for i in 0..n_gamma {
        let cos_g = sample_cos_gamma(lambda as f64, (i as f64 + 0.5) / n_gamma as f64) as f32;
        let sin_g = (1.0 - cos_g * cos_g).max(0.0).sqrt();
        for j in 0..n_phi {
            // Shifted per ring so the rings' azimuths do not line up.
            let phi = std::f32::consts::TAU * (j as f32 + 0.5 + 0.37 * i as f32) / n_phi as f32;
            let w = xi * cos_g + (t1 * phi.cos() + t2 * phi.sin()) * sin_g;
            lights.push(EnvLight::directional(w, [1.0 / total as f32; 3]));
        }
    }
    lights
}

fn frame_ms(frame: &EnvImage) -> f64 {
    frame
        .stats
        .timings
        .iter()
        .filter(|t| t.pass != "pipelines")
        .map(|t| t.milliseconds)
        .sum()
}

/// sqrt(Σ(a − r)² / Σr²) over pixels whose reference alpha exceeds 0.01.
fn relative_rmse(estimate: &[[f32; 4]], reference: &[[f32; 4]]) -> f64 {
    let (mut e, mut n) = (0.0f64, 0.0f64);
    for (a, r) in estimate.iter().zip(reference) {
        if r[3] > 0.01 {
            e += (a[0] as f64 - r[0] as f64).powi(2);
            n += (r[0] as f64).powi(2);
        }
    }
    (e / n).sqrt()
}

fn load_model(procedural: bool, strands: Option<usize>) -> Result<(HairModel, String), BoxError> {
    if !procedural
        && let Some(path) = strandlight_tables::shared_data::shared_file("hair/straight.hair")
    {
        return Ok((hair::load(&path)?.model, "straight.hair".into()));
    }
    let mut params = GroomParams::default();
    if let Some(n) = strands {
        params.strand_count = n;
    }
    Ok((
        generate_groom(&params)?,
        format!("procedural groom ({} strands)", params.strand_count),
    ))
}

fn main() -> Result<(), BoxError> {
    let args = parse_args()?;
    let (model, hair_name) = load_model(args.procedural, args.strands)?;
    std::fs::create_dir_all(&args.out_dir)?;
    let gpu = GpuContext::new_headless()?;
    let renderer = EnvRenderer::new(&gpu);
    let tables = constant_tables()?;
    let (width, height) = (args.width, args.height);
    let bounds = model.bounds();
    let camera = Camera::framing_front(
        bounds,
        width as f32 / height as f32,
        false,
        UpAxis::detect(&model),
    );
    let toward_eye = camera.toward_eye();
    let right = (camera.target - camera.eye).cross(camera.up).normalize();
    let screen_up = right.cross(camera.target - camera.eye).normalize();
    let directions = [
        (
            "upper front, 45° elevation",
            "upper",
            (toward_eye + screen_up).normalize(),
        ),
        (
            "back rim (behind, 30° up, 15° right)",
            "rim",
            (-toward_eye + 0.6 * screen_up + 0.3 * right).normalize(),
        ),
    ];
    let filters = [
        (TransmittanceFilter::PaperSupport, "paper"),
        (TransmittanceFilter::MatchedVariance, "matched"),
        (TransmittanceFilter::Centre, "centre"),
    ];
    println!(
        "{hair_name}: {} strands, {} segments; {width}×{height}; DODM {}²; reference: {} directional lights from G; {}",
        model.strand_count(),
        model.segment_count(),
        EnvRenderOptions::default().dodm.resolution,
        args.samples,
        gpu.report
    );
    let started = Instant::now();
    let mut rows = Vec::new();
    for &(dir_label, dir_tag, xi) in &directions {
        for &lambda in &args.lambdas {
            let full = EnvRenderOptions {
                kappa: 1.0,
                ..EnvRenderOptions::default()
            };
            let lights = reference_lights(xi, lambda, args.samples);
            let reference = renderer.render(
                &gpu, &model, &camera, width, height, &lights, &tables, &full, None,
            )?;
            let reference_ms = frame_ms(&reference);
            let stem = format!("{dir_tag}_lambda{lambda}");
            let write = |name: &str, frame: &EnvImage, what: &str| {
                write_png(
                    &args.out_dir.join(format!("{stem}_{name}.png")),
                    width,
                    height,
                    &frame.pixels,
                    &format!("effective transmittance, {dir_label}, λ = {lambda}: {what}"),
                )
            };
            write(
                "reference",
                &reference,
                &format!("{} directional lights from G", lights.len()),
            )?;
            let mut row = format!("| {dir_label} | {lambda} | {:.0} |", reference_ms);
            let srbf = [EnvLight::srbf(
                xi,
                lambda,
                [(1.0 / integral(lambda as f64)) as f32; 3],
            )];
            for kappa in [1.0f32, 0.1] {
                for &(filter, tag) in &filters {
                    let options = EnvRenderOptions {
                        kappa,
                        transmittance_filter: filter,
                        ..EnvRenderOptions::default()
                    };
                    let estimate = renderer.render(
                        &gpu, &model, &camera, width, height, &srbf, &tables, &options, None,
                    )?;
                    let rmse = relative_rmse(&estimate.pixels, &reference.pixels);
                    row += &format!(" {rmse:.4} ({:.0} ms) |", frame_ms(&estimate));
                    if kappa == 1.0 {
                        write(tag, &estimate, filter.name())?;
                    }
                }
            }
            println!("{row}");
            rows.push(row);
        }
    }
    println!();
    println!(
        "| light | λ | reference ms | paper κ=1 | matched κ=1 | centre κ=1 | paper κ=0.1 | matched κ=0.1 | centre κ=0.1 |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    for row in &rows {
        println!("{row}");
    }
    println!(
        "\nrelative RMSE over hair pixels vs the {}-direction reference (frame ms in brackets); total {:.1} s; images in {}",
        args.samples,
        started.elapsed().as_secs_f64(),
        args.out_dir.display()
    );
    Ok(())
}
