//! An environment-lit scene made ready to render: the map's SRBF fit and the fiber's tables,
//! both from the on-disk caches. What `render --env`, `demo`, `compare` and the viewer each did
//! step by step, in one place. The lights of a frame are made from it per frame
//! (`crate::frame_render::frame_lights`), where the frame's settings turn and select them.

use crate::env_frame::fit_summary;
use crate::environment::{LoadedEnv, load_env};
use crate::fit_cache::{FitOutcome, fit_cached};
use crate::frame_settings::{FrameSettings, Lighting, up_choice};
use crate::scene_tables::{
    EnvShading, ScatteringMode, SceneTables, bake_scene_tables, lambda_range_of_set, wanted_tables,
};
use crate::steps::Steps;
use anyhow::Context;
use std::path::Path;
use strandlight_precompute::FitOptions;
use strandlight_precompute::bake_plan::{BakeResolution, FiberDescription};
use strandlight_precompute::srbf_set::SrbfSet;
use strandlight_runtime::camera::UpAxis;
use strandlight_runtime::hair::HairModel;
use strandlight_tables::checksum::sha256_hex;

/// What the scene is made of besides the hair.
pub struct EnvSceneRequest<'a> {
    pub env: &'a LoadedEnv,
    pub fiber: &'a FiberDescription,
    pub shading: EnvShading,
    /// The scattering asked for; dark hair without a `multiple` table falls back to single.
    pub scattering: ScatteringMode,
    /// Bake the directional lights' tables even where the fit has no compact source: the
    /// reference's and the median-cut baseline's lights are all directional.
    pub directional_sets: bool,
    pub fit: &'a FitOptions,
    pub resolution: BakeResolution,
    /// Holds `fits/` and `tables/`.
    pub cache_dir: &'a Path,
    /// The folder under `cache_dir/tables` for this fiber's tables.
    pub table_set: &'a str,
}

/// The fit and the tables of a scene, and the scattering it can render.
pub struct EnvScene {
    /// In the map's own frame.
    pub fit: SrbfSet,
    pub tables: SceneTables,
    pub mode: ScatteringMode,
}

/// How far [`prepare_env_scene_reporting`] is, for a progress bar.
#[derive(Clone, Debug, PartialEq)]
pub enum PrepareProgress {
    Fitting,
    /// `done` of `total` tables baked (or found in the cache); `table` the last one.
    Baking {
        done: usize,
        total: usize,
        table: String,
    },
}

/// Fits (cached), bakes (cached) and places the lights, reporting each as a step.
pub fn prepare_env_scene(request: &EnvSceneRequest, steps: &mut Steps) -> anyhow::Result<EnvScene> {
    prepare_env_scene_reporting(request, steps, &mut |_| {})
}

/// [`prepare_env_scene`], telling `progress` about the fit and every table as it completes.
pub fn prepare_env_scene_reporting(
    request: &EnvSceneRequest,
    steps: &mut Steps,
    progress: &mut dyn FnMut(PrepareProgress),
) -> anyhow::Result<EnvScene> {
    progress(PrepareProgress::Fitting);
    let fit = steps.run(
        "fit",
        || fit_cached(request.env, request.fit, request.cache_dir),
        |f: &FitOutcome| {
            format!(
                "{}{}",
                fit_summary(&f.set),
                if f.cached { " (cached)" } else { "" }
            )
        },
    )?;
    // Full asks for the single-scattering tables too: dark hair skips the multiple table and
    // the frame falls back to single scattering.
    let modes: &[ScatteringMode] = match request.scattering {
        ScatteringMode::Single => &[ScatteringMode::Single],
        ScatteringMode::Full => &[ScatteringMode::Single, ScatteringMode::Full],
    };
    let wanted = wanted_tables(
        request.shading,
        modes,
        !fit.set.lobes.is_empty(),
        request.directional_sets || !fit.set.sources.is_empty(),
    );
    let lambda_range = lambda_range_of_set(&fit.set)?;
    let dir = request.cache_dir.join("tables").join(request.table_set);
    let total = wanted.len();
    let mut done = 0;
    let tables = steps.run(
        "bake",
        || {
            bake_scene_tables(
                request.fiber,
                request.shading,
                request.resolution.clone(),
                lambda_range,
                &wanted,
                &dir,
                &mut |t| {
                    done += 1;
                    progress(PrepareProgress::Baking {
                        done,
                        total,
                        table: t.name.clone(),
                    })
                },
            )
        },
        |t| {
            format!(
                "{} tables ({} cached) → {}",
                t.baked.len(),
                t.baked.iter().filter(|b| b.cached).count(),
                dir.display()
            )
        },
    )?;
    let mode =
        if request.scattering == ScatteringMode::Full && !tables.assets.contains_key("multiple") {
            for (name, reason) in &tables.skipped {
                steps.say(format!("skipped {name}: {reason}"));
            }
            ScatteringMode::Single
        } else {
            request.scattering
        };
    Ok(EnvScene {
        fit: fit.set,
        tables,
        mode,
    })
}

/// An environment's fit and tables, ready to light frames.
pub struct PreparedEnv {
    /// The map, which the reference's and the median-cut baseline's lights are made from;
    /// None where only the fit and tables travelled (the web page's bundle).
    pub env: Option<LoadedEnv>,
    pub scene: EnvScene,
    pub shading: EnvShading,
    /// The fiber the tables were baked for.
    pub fiber: FiberDescription,
    /// The hair's up axis, onto which the map's +y goes.
    pub up: UpAxis,
}

impl PreparedEnv {
    /// The map, for light sets made from it.
    pub fn map(&self) -> anyhow::Result<&LoadedEnv> {
        self.env.as_ref().context(
            "this scene carries its fit and tables only, not the map: a reference or median-cut frame needs the map",
        )
    }
}

/// The cache folder of a fiber's tables: custom artist controls get one of their own, named by
/// their hash, so switching back and forth serves both from the cache; tables of another
/// resolution get one of their own too.
pub fn env_table_set(settings: &FrameSettings, shading: EnvShading) -> String {
    let base = format!("{}-{:?}", settings.preset, shading).to_lowercase();
    let base = match (shading, settings.artist) {
        (EnvShading::Artist, Some(params)) => {
            let json = serde_json::to_vec(&params).expect("artist controls serialize");
            format!("{base}-{}", &sha256_hex(&json)[..12])
        }
        _ => base,
    };
    let resolution = match &settings.lighting {
        Lighting::Environment(env) => env.table_resolution,
        Lighting::Lights(_) => None,
    };
    match resolution {
        Some(n) => format!("{base}-n{n}"),
        None => base,
    }
}

/// What a preparation must serve beyond the frame of its settings.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct AlsoServe {
    /// Full scattering's tables even where the settings ask for single.
    pub full_scattering: bool,
    /// The directional lights' tables (the reference's and the baseline's frames).
    pub directional_sets: bool,
}

/// Loads the map, fits it and bakes the fiber's tables (both cached under `cache_dir`) for the
/// frame of `settings` (an env-lit one) and what `also` asks for.
pub fn prepare_env(
    settings: &FrameSettings,
    hair: &HairModel,
    cache_dir: &Path,
    also: AlsoServe,
    steps: &mut Steps,
    progress: &mut dyn FnMut(PrepareProgress),
) -> anyhow::Result<PreparedEnv> {
    let Lighting::Environment(env) = &settings.lighting else {
        anyhow::bail!("an environment is prepared for env-lit settings only");
    };
    let shading = settings.env_shading()?;
    let loaded = steps.run(
        "environment",
        || load_env(&env.map, env.sanitize),
        |e| format!("{} {}x{}", e.name, e.map.width(), e.map.height()),
    )?;
    let mut fiber = FiberDescription::preset(&settings.preset)
        .with_context(|| format!("--preset {:?}", settings.preset))?;
    if let Some(artist) = settings.artist {
        fiber.artist = artist;
    }
    let table_set = env_table_set(settings, shading);
    let fit = env.fit.options();
    let request = EnvSceneRequest {
        env: &loaded,
        fiber: &fiber,
        shading,
        scattering: match also.full_scattering {
            true => ScatteringMode::Full,
            false => env.scattering,
        },
        directional_sets: also.directional_sets || !env.light_set.is_fit(),
        fit: &fit,
        resolution: env
            .table_resolution
            .map(BakeResolution::reduced)
            .unwrap_or_default(),
        cache_dir,
        table_set: &table_set,
    };
    let scene = prepare_env_scene_reporting(&request, steps, progress)?;
    Ok(PreparedEnv {
        env: Some(loaded),
        scene,
        shading,
        fiber,
        up: up_choice(settings).axis(hair),
    })
}
