//! A study, not a product path: one scene prepared as `compare` prepares it (straight.hair,
//! Chiang `brown`), the SRBF frame rendered under several looks, each timed and measured against
//! the cached ground truth (`strandlight truth`, or an earlier `compare`/`bench --truth`):
//! `cargo run --release -p strandlight-eval --example view_study -- MAP MODE LOOK...` with MODE
//! single|full and LOOK = TRANSPARENCY/VISIBILITY (opaque|layered|occupancy / volume|light-maps).
//! Prints a line and a JSON object per look (scripts/view-error.sh collects them); EXRs of the
//! frames and of the truth go to out/view-study/. Environment: SIZE (160x120), RUNS (3 timed
//! renders, the median kept), LIGHT_MAP_SIZE, KAPPA, TRUTH_MAX_SPP (the truth's ladder: by
//! default `strandlight truth`'s, falling back to the cached pair of a smaller budget such as
//! `--truth-max-spp 4096`), REFERENCE=n (the DOM reference's 6n² lights instead of the SRBF frame).
use anyhow::Context;
use strandlight_eval::compare::{CompareSettings, frame, prepare, timed_render, truth_of};
use strandlight_eval::ground_truth::TruthUse;
use strandlight_eval::hdr_flip::hdr_flip;
use strandlight_scene::env_frame::render_lights;
use strandlight_scene::env_lighting::{EnvLightSet, ReferenceLighting};
use strandlight_scene::hair_input::parse_size;
use strandlight_scene::image_metrics::relative_rmse;
use strandlight_scene::look::{EnvTransparency, LobeVisibilityArg};
use strandlight_scene::point_shading::Shading;
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
        modes: vec![mode],
        ground_truth: TruthUse::Cached,
        ..Default::default()
    };
    let (w, h) = parse_size(&std::env::var("SIZE").unwrap_or("160x120".into()))?;
    settings.frame.size = [w, h];
    settings.frame.hair = Some("../shared/data/hair/straight.hair".into());
    settings.frame.shading = Some(Shading::Chiang);
    settings.env_mut().map = map.clone();
    if let Ok(n) = std::env::var("LIGHT_MAP_SIZE") {
        settings.env_mut().dodm_size = n.parse()?;
    }
    if let Ok(spp) = std::env::var("TRUTH_MAX_SPP") {
        settings.truth_max_spp = spp.parse()?;
    }
    if let Ok(k) = std::env::var("KAPPA") {
        settings.env_mut().kappa = k.parse()?;
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
        s.env_mut().transparency = match t {
            "occupancy" => EnvTransparency::Occupancy,
            "layered" => EnvTransparency::Layered,
            _ => EnvTransparency::Opaque,
        };
        s.env_mut().view.lobe_visibility = match v {
            "volume" => LobeVisibilityArg::Volume,
            _ => LobeVisibilityArg::LightMaps,
        };
        let light_set = match reference_face {
            Some(face) => EnvLightSet::Reference {
                face,
                shading_face: None,
                lighting: ReferenceLighting::Map,
            },
            None => EnvLightSet::Fit,
        };
        let f = frame(&scene, &s.frame_of(mode, light_set))?;
        let _warm = render_lights(&f)?;
        let r = timed_render(&render_lights, &f, runs)?;
        let e = relative_rmse(&r.image, &truth.image)?;
        let nc = (e * e - truth.noise * truth.noise).max(0.0).sqrt();
        let flip = hdr_flip(&r.image, &truth.image)?.mean_over_hair;
        println!(
            "{look}: {:.0} ms, vs truth {e:.4} (n.c. {nc:.4}) HDR-FLIP {flip:.4}",
            r.milliseconds
        );
        println!(
            "{}",
            serde_json::json!({"map": map, "mode": mode.name(), "look": look, "ms": r.milliseconds,
                "rel_rmse": e, "rel_rmse_nc": nc, "hdr_flip": flip, "truth_noise": truth.noise,
                "truth_seconds": truth.seconds, "light_map_size": s.env().dodm_size,
                "size": s.frame.size, "reference_face": reference_face})
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
