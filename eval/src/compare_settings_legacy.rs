//! `compare` settings as reports recorded them before the frame was a `FrameSettings` (5 Dec
//! 2026): one flat object. Read only, so that `compare --settings OLD_REPORT.json` still
//! measures what it measured; everything written since is the current form.

use crate::baseline::Baseline;
use crate::compare::CompareSettings;
use crate::error_metric::ErrorMetric;
use crate::ground_truth::TruthUse;
use serde::Deserialize;
use serde_json::Value;
use std::path::PathBuf;
use strandlight_scene::env_lighting::{EnvLighting, FitSettings};
use strandlight_scene::frame_settings::{FrameSettings, Lighting};
use strandlight_scene::hair_input::parse_size;
use strandlight_scene::head_input::HeadChoice;
use strandlight_scene::look::LookArgs;
use strandlight_scene::point_shading::Shading;
use strandlight_scene::scene_tables::{EnvShading, ScatteringMode};

/// The flat form; absent fields took the defaults of the day, which were today's.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct LegacyCompareSettings {
    hair: PathBuf,
    env: String,
    max_lobes: Option<usize>,
    target_error: Option<f64>,
    lambda_max: Option<f64>,
    sources: Option<usize>,
    source_radius: Option<f64>,
    source_min_share: Option<f64>,
    wider_source_radius: Option<f64>,
    size: Option<String>,
    json: Option<bool>,
    reference_lights: Option<Option<usize>>,
    reference_tolerance: Option<f64>,
    reference_max_lights: Option<usize>,
    reference_shading_lights: Option<usize>,
    shading: Option<EnvShading>,
    preset: Option<String>,
    out: Option<PathBuf>,
    cache: Option<PathBuf>,
    rotate: Option<f64>,
    sanitize: Option<bool>,
    table_resolution: Option<Option<usize>>,
    modes: Option<Vec<ScatteringMode>>,
    kappa: Option<f32>,
    timing_runs: Option<usize>,
    equal_error: Option<bool>,
    baseline: Option<Baseline>,
    equal_error_metric: Option<ErrorMetric>,
    unshadowed: Option<bool>,
    light_map_size: Option<u32>,
    look: Option<LookArgs>,
    head: Option<HeadChoice>,
    ground_truth: Option<TruthUse>,
    truth_max_spp: Option<u32>,
}

/// The current settings of a flat settings object.
pub fn read(value: Value) -> anyhow::Result<CompareSettings> {
    let old: LegacyCompareSettings = serde_json::from_value(value)?;
    let mut settings = CompareSettings::default();
    let fit_defaults = FitSettings::default();
    let mut env = EnvLighting::new(old.env);
    env.fit = FitSettings {
        max_lobes: old.max_lobes.unwrap_or(fit_defaults.max_lobes),
        target_error: old.target_error.unwrap_or(fit_defaults.target_error),
        lambda_max: old.lambda_max.unwrap_or(fit_defaults.lambda_max),
        sources: old.sources.unwrap_or(fit_defaults.sources),
        source_radius: old.source_radius.unwrap_or(fit_defaults.source_radius),
        source_min_share: old
            .source_min_share
            .unwrap_or(fit_defaults.source_min_share),
        wider_source_radius: old
            .wider_source_radius
            .unwrap_or(fit_defaults.wider_source_radius),
    };
    env.rotation_deg = old.rotate.unwrap_or(0.0) as f32;
    env.sanitize = old.sanitize.unwrap_or(false);
    env.table_resolution = old.table_resolution.flatten();
    env.kappa = old.kappa.unwrap_or(env.kappa);
    env.shadowed = !old.unshadowed.unwrap_or(false);
    env.dodm_size = old.light_map_size.unwrap_or(env.dodm_size);
    if let Some(look) = old.look {
        env.transparency = look.transparency;
        env.view = look.view;
    }
    let size = match &old.size {
        Some(text) => parse_size(text)?,
        None => (settings.frame.size[0], settings.frame.size[1]),
    };
    settings.frame = FrameSettings {
        hair: Some(old.hair),
        shading: Some(Shading::from(old.shading.unwrap_or(EnvShading::Marschner))),
        preset: old.preset.unwrap_or_else(|| "brown".into()),
        head: old.head.unwrap_or_default(),
        ..FrameSettings::new(Lighting::Environment(env), [size.0, size.1])
    };
    let defaults = CompareSettings::default();
    settings.json = old.json.unwrap_or(defaults.json);
    settings.reference_lights = old.reference_lights.flatten();
    settings.reference_tolerance = old
        .reference_tolerance
        .unwrap_or(defaults.reference_tolerance);
    settings.reference_max_lights = old
        .reference_max_lights
        .unwrap_or(defaults.reference_max_lights);
    settings.reference_shading_lights = old
        .reference_shading_lights
        .unwrap_or(defaults.reference_shading_lights);
    settings.out = old.out.unwrap_or(defaults.out);
    settings.cache = old.cache.unwrap_or(defaults.cache);
    settings.modes = old.modes.unwrap_or(defaults.modes);
    settings.timing_runs = old.timing_runs.unwrap_or(defaults.timing_runs);
    settings.equal_error = old.equal_error.unwrap_or(defaults.equal_error);
    settings.baseline = old.baseline.unwrap_or(defaults.baseline);
    settings.equal_error_metric = old
        .equal_error_metric
        .unwrap_or(defaults.equal_error_metric);
    settings.ground_truth = old.ground_truth.unwrap_or(defaults.ground_truth);
    settings.truth_max_spp = old.truth_max_spp.unwrap_or(defaults.truth_max_spp);
    Ok(settings)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A settings object as a report of 4 Dec 2026 recorded it (abridged to the fields that
    /// differ from the defaults): it reads as the same frame and measurement.
    #[test]
    fn a_flat_report_reads_as_the_same_comparison() {
        let old = serde_json::json!({
            "hair": "../shared/data/hair/straight.hair",
            "env": "../shared/data/envmaps/piz_compressed.exr",
            "size": "160x120",
            "shading": "chiang",
            "rotate": 30.0,
            "kappa": 0.25,
            "unshadowed": true,
            "light_map_size": 256,
            "reference_lights": 384,
            "modes": ["single"],
            "lambda_max": 128.0,
        });
        let s = CompareSettings::from_json(old).unwrap();
        assert_eq!(s.frame.size, [160, 120]);
        assert_eq!(s.frame.shading, Some(Shading::Chiang));
        assert_eq!(
            s.frame.hair.as_deref(),
            Some(std::path::Path::new("../shared/data/hair/straight.hair"))
        );
        let env = s.env();
        assert_eq!(env.map, "../shared/data/envmaps/piz_compressed.exr");
        assert_eq!(
            (env.rotation_deg, env.kappa, env.shadowed, env.dodm_size),
            (30.0, 0.25, false, 256)
        );
        assert_eq!(env.fit.lambda_max, 128.0);
        assert_eq!(s.reference_lights, Some(384));
        assert_eq!(s.modes, vec![ScatteringMode::Single]);
        // Written back, it is the current form, which reads as itself.
        let again = CompareSettings::from_json(serde_json::to_value(&s).unwrap()).unwrap();
        assert_eq!(again, s);
    }
}
