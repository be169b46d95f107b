//! A study, not a product path: one scene prepared as `compare` prepares it, the SRBF frame (or
//! the DOM reference's lights) rendered under several looks, each measured against the cached
//! ground truth. `cargo run --release -p strandlight-eval --example view_study -- MAP MODE
//! [reference] LOOK...` with LOOK = TRANSPARENCY/VISIBILITY (opaque|occupancy / light-maps|volume);
//! EXRs go to out/view-study/.
use anyhow::Context;
use strandlight_eval::compare::{
    CompareSettings, ReferenceLighting, frame, prepare, timed_render, truth_of,
};
use strandlight_eval::ground_truth::TruthUse;
use strandlight_eval::hdr_flip::hdr_flip;
use strandlight_scene::env_frame::FrameRole;
use strandlight_scene::env_frame::render_lights;
use strandlight_scene::image_metrics::relative_rmse;
use strandlight_scene::look::{EnvTransparency, LobeVisibilityArg};
use strandlight_scene::scene_tables::EnvShading;
use strandlight_scene::scene_tables::ScatteringMode;
use strandlight_scene::steps::Steps;

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let map = args.first().context("MAP")?;
    let mode = match args.get(1).map(String::as_str) {
        Some("full") => ScatteringMode::Full,
        _ => ScatteringMode::Single,
    };
    let mut settings = CompareSettings {
        hair: "../shared/data/hair/straight.hair".into(),
        env: map.clone(),
        size: std::env::var("SIZE").unwrap_or("160x120".into()),
        shading: EnvShading::Chiang,
        modes: vec![mode],
        ground_truth: TruthUse::Cached,
        ..Default::default()
    };
    if let Ok(n) = std::env::var("LIGHT_MAP_SIZE") {
        settings.light_map_size = n.parse()?;
    }
    if let Ok(k) = std::env::var("KAPPA") {
        settings.kappa = k.parse()?;
    }
    // REFERENCE=n: the DOM reference's lights for n×n texels per cube face (6n² lights).
    let reference_face: Option<usize> = std::env::var("REFERENCE")
        .ok()
        .map(|n| n.parse())
        .transpose()?;
    let runs: usize = std::env::var("RUNS")
        .ok()
        .map(|n| n.parse())
        .transpose()?
        .unwrap_or(3);
    let mut steps = Steps::new(true);
    let scene = prepare(&settings, &mut steps)?;
    let truth = truth_of(&scene, &settings, mode, &mut steps)?.context("no cached truth")?;
    let out = std::path::Path::new("out/view-study");
    std::fs::create_dir_all(out)?;
    let map_stem = std::path::Path::new(map)
        .file_stem()
        .unwrap()
        .to_string_lossy()
        .to_string();
    strandlight_tables::image_out::write_exr(
        &out.join(format!("{map_stem}-{}-truth.exr", mode.name())),
        truth.image.width,
        truth.image.height,
        &truth.image.pixels,
        "view study: the ground truth",
    )?;
    for look in &args[2..] {
        let (t, v) = look
            .split_once('/')
            .context("LOOK = TRANSPARENCY/VISIBILITY")?;
        let mut s = settings.clone();
        s.look.transparency = match t {
            "occupancy" => EnvTransparency::Occupancy,
            "layered" => EnvTransparency::Layered,
            _ => EnvTransparency::Opaque,
        };
        s.look.view.lobe_visibility = match v {
            "volume" => LobeVisibilityArg::Volume,
            _ => LobeVisibilityArg::LightMaps,
        };
        let reference_lights;
        let f = match reference_face {
            Some(face) => {
                reference_lights =
                    scene.reference_set(face, None, s.rotate, ReferenceLighting::Map)?;
                strandlight_scene::env_frame::EnvFrame {
                    role: FrameRole::Reference,
                    ..frame(&scene, &s, &reference_lights, mode)
                }
            }
            None => frame(&scene, &s, &scene.srbf, mode),
        };
        let _warm = render_lights(&f)?;
        let r = render_lights(&f)?;
        let e = relative_rmse(&r.image, &truth.image)?;
        let nc = (e * e - truth.noise * truth.noise).max(0.0).sqrt();
        println!(
            "{look}: {:.0} ms, vs truth {e:.4} (n.c. {nc:.4})",
            r.milliseconds
        );
        let stem = out.join(format!(
            "{}-{}-{t}-{v}",
            std::path::Path::new(map)
                .file_stem()
                .unwrap()
                .to_string_lossy(),
            mode.name()
        ));
        strandlight_tables::image_out::write_exr(
            &stem.with_extension("exr"),
            r.image.width,
            r.image.height,
            &r.image.pixels,
            "view study",
        )?;
    }
    Ok(())
}
