//! How far the viewer's first look is from the whole frame it stands in for
//! (docs/BENCHMARKS.md, "The viewer's first look"): the default scene at 800×600 under MAP,
//! its first look (coarse tables, [`first_look`]'s groom, [`FramePart::Preview`]) against the
//! whole frame at the preview's size, with the first-look fit of few lobes and with the full
//! fit's strongest lights (before it). Prints the relative RMSE at 1×1, 4×4 and 16×16 blocks,
//! the mean ratio, and how long each fit and bake took on a cache of their own (cold the first
//! time).
//!
//!   cargo run --release -p strandlight-scene --example first_look_error -- [MAP] [CACHE]

use std::path::PathBuf;
use std::time::Instant;
use strandlight_scene::env_lighting::EnvLighting;
use strandlight_scene::env_scene::{AlsoServe, prepare_env};
use strandlight_scene::frame_render::{
    FramePart, Prepared, coarse_preview_settings, first_look, load_settings_hair, render_frame,
};
use strandlight_scene::frame_settings::{FrameSettings, Lighting};
use strandlight_scene::head_input::HeadChoice;
use strandlight_scene::image_metrics::{mean_ratio, relative_rmse_over_blocks};
use strandlight_scene::steps::Steps;

fn main() -> anyhow::Result<()> {
    let mut args = std::env::args().skip(1);
    let map = args.next().unwrap_or("procedural:sun_and_sky".into());
    let cache = PathBuf::from(args.next().unwrap_or("out/cache".into()));
    let mut settings =
        FrameSettings::new(Lighting::Environment(EnvLighting::new(&map)), [800, 600]);
    settings.preset = "blonde".into();
    settings.head = HeadChoice::Ellipsoid;
    let hair = load_settings_hair(&settings)?;
    let mut steps = Steps::new(true);
    let whole_settings = FrameSettings {
        size: FramePart::Preview.size(settings.size),
        ..settings.clone()
    };
    let full = prepare_env(
        &whole_settings,
        &hair.model,
        &cache,
        AlsoServe::default(),
        &mut steps,
        &mut |_| {},
    )?;
    let whole = render_frame(
        &whole_settings,
        &hair.model,
        Prepared::Env(&full),
        FramePart::Whole,
        false,
    )?;
    let first_look_fit = coarse_preview_settings(&settings);
    let mut full_fit = first_look_fit.clone();
    if let (Lighting::Environment(coarse), Lighting::Environment(env)) =
        (&mut full_fit.lighting, &settings.lighting)
    {
        coarse.fit = env.fit;
    }
    for (name, coarse) in [
        ("full fit's strongest lights", full_fit),
        ("first-look fit", first_look_fit),
    ] {
        let started = Instant::now();
        let prepared = prepare_env(
            &coarse,
            &hair.model,
            &cache.join("first-look"),
            AlsoServe::default(),
            &mut steps,
            &mut |_| {},
        )?;
        let prepare = started.elapsed().as_secs_f64();
        let (look, look_hair) = first_look(&coarse, &hair.model)?;
        let preview = render_frame(
            &look,
            &look_hair,
            Prepared::Env(&prepared),
            FramePart::Preview,
            false,
        )?;
        let errors: Vec<String> = [1, 4, 16]
            .map(|n| {
                relative_rmse_over_blocks(&preview.image, &whole.image, n)
                    .map(|e| format!("{n}×{n} {e:.3}"))
            })
            .into_iter()
            .collect::<Result<_, _>>()?;
        println!(
            "{name}: {} lobes + {} compact sources, fit and bake {prepare:.2} s; against the whole frame {}, mean {:.3}",
            prepared.scene.fit.lobes.len(),
            prepared.scene.fit.sources.len(),
            errors.join(", "),
            mean_ratio(&preview.image, &whole.image)?
        );
    }
    Ok(())
}
