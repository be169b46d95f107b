//! An environment-lit scene made ready to render: the map's SRBF fit and the fiber's tables,
//! both from the on-disk caches, and the fitted lights in the hair's world frame. What `render
//! --env`, `demo` and the viewer each did step by step, in one place.

use crate::env_frame::fit_summary;
use crate::environment::LoadedEnv;
use crate::fit_cache::{FitOutcome, fit_cached};
use crate::scene_tables::{
    EnvShading, ScatteringMode, SceneTables, bake_scene_tables, lambda_range_of_set, wanted_tables,
};
use crate::steps::Steps;
use crate::world_lights::to_env_lights;
use std::path::Path;
use strandlight_precompute::FitOptions;
use strandlight_precompute::bake_plan::{BakeResolution, FiberDescription};
use strandlight_precompute::env_lights::srbf_set_lights;
use strandlight_runtime::camera::UpAxis;
use strandlight_runtime::env_light::EnvLight;

/// What the scene is made of besides the hair.
pub struct EnvSceneRequest<'a> {
    pub env: &'a LoadedEnv,
    pub fiber: &'a FiberDescription,
    pub shading: EnvShading,
    /// The scattering asked for; dark hair without a `multiple` table falls back to single.
    pub scattering: ScatteringMode,
    pub resolution: BakeResolution,
    /// Holds `fits/` and `tables/`.
    pub cache_dir: &'a Path,
    /// The folder under `cache_dir/tables` for this fiber's tables.
    pub table_set: &'a str,
    /// The hair's up axis: the map's +y is turned onto it.
    pub up: UpAxis,
}

/// The fit, the tables and the lights of a scene, and the scattering it can render.
pub struct EnvScene {
    pub fit: FitOutcome,
    pub tables: SceneTables,
    pub lights: Vec<EnvLight>,
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
        || fit_cached(request.env, &FitOptions::default(), request.cache_dir),
        |f| {
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
        !fit.set.sources.is_empty(),
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
    let lights = to_env_lights(&srbf_set_lights(&fit.set), request.up);
    Ok(EnvScene {
        fit,
        tables,
        lights,
        mode,
    })
}
