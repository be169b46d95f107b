//! The tables a scene's frames read: which ones each fiber model and scattering mode needs, and
//! their bake (cached by content) for the λ range a fit actually uses.

use crate::point_shading::Shading;
use anyhow::{Context, bail};
use serde_json::Value;
use std::collections::BTreeMap;
use std::path::Path;
use strandlight_precompute::bake::{BakedTable, bake_and_load};
use strandlight_precompute::bake_plan::{
    BakeResolution, DEFAULT_MULTIPLE_THRESHOLD, FiberDescription, Model, PlanOptions,
    plan_with_cache,
};
use strandlight_precompute::srbf_set::SrbfSet;
use strandlight_tables::asset::{Storage, TableAsset, expect_parameters};

/// The fiber model whose tables shade the hair.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[cfg_attr(any(feature = "cli", test), derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum EnvShading {
    Marschner,
    Artist,
    /// Chiang et al. 2016 (pbrt-v4, Mitsuba 3 and Cycles' Principled Hair): the model the
    /// path-traced ground truth renders.
    Chiang,
}

/// Single scattering only, or with multiple scattering (Ren §3.2).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[cfg_attr(any(feature = "cli", test), derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum ScatteringMode {
    Single,
    Full,
}

impl ScatteringMode {
    pub fn name(self) -> &'static str {
        match self {
            ScatteringMode::Single => "single",
            ScatteringMode::Full => "full",
        }
    }
}

impl From<EnvShading> for Shading {
    fn from(shading: EnvShading) -> Self {
        match shading {
            EnvShading::Marschner => Shading::Marschner,
            EnvShading::Artist => Shading::Artist,
            EnvShading::Chiang => Shading::Chiang,
        }
    }
}

impl EnvShading {
    fn model(self) -> Model {
        match self {
            EnvShading::Marschner => Model::Marschner,
            EnvShading::Artist => Model::Artist,
            EnvShading::Chiang => Model::Chiang,
        }
    }

    /// The convolution table of SRBF lights in `mode` (the artist model has no d_b·S_back
    /// variant: its full mode adds only I_G).
    pub fn srbf_table(self, mode: ScatteringMode) -> &'static str {
        match (self, mode) {
            (EnvShading::Marschner, ScatteringMode::Single) => "marschner",
            (EnvShading::Marschner, ScatteringMode::Full) => "marschner_full",
            (EnvShading::Chiang, ScatteringMode::Single) => "chiang",
            (EnvShading::Chiang, ScatteringMode::Full) => "chiang_full",
            (EnvShading::Artist, _) => "artist",
        }
    }

    /// The direct table of directional lights in `mode`.
    pub fn direct_table(self, mode: ScatteringMode) -> &'static str {
        match (self, mode) {
            (EnvShading::Marschner, ScatteringMode::Single) => "marschner_direct",
            (EnvShading::Marschner, ScatteringMode::Full) => "marschner_full_direct",
            (EnvShading::Chiang, ScatteringMode::Single) => "chiang_direct",
            (EnvShading::Chiang, ScatteringMode::Full) => "chiang_full_direct",
            (EnvShading::Artist, _) => "artist_direct",
        }
    }
}

/// The tables multiple scattering reads (the first is absent for hair too dark to need it).
pub const MULTIPLE_TABLES: [&str; 4] = [
    "multiple",
    "fiber_averages",
    "attenuation_ratio",
    "srbf_spread",
];

/// The tables a frame in any of `modes` may read: the multiple-scattering tables (full mode), the SRBF
/// tables and, with `directional` lights (baselines, references, a fit's compact sources), the
/// direct tables.
pub fn wanted_tables(
    shading: EnvShading,
    modes: &[ScatteringMode],
    srbf: bool,
    directional: bool,
) -> Vec<&'static str> {
    // Only the full mode reads them (a single-scattering first look bakes in half the time).
    let mut wanted: Vec<&str> = match modes.contains(&ScatteringMode::Full) {
        true => MULTIPLE_TABLES.to_vec(),
        false => Vec::new(),
    };
    for &mode in modes {
        if srbf {
            wanted.push(shading.srbf_table(mode));
        }
        if directional {
            wanted.push(shading.direct_table(mode));
        }
    }
    wanted.dedup();
    wanted
}

/// Loaded tables by name, each checked against the fiber parameters it was asked for.
pub struct SceneTables {
    pub assets: BTreeMap<String, TableAsset>,
    pub baked: Vec<BakedTable>,
    /// Tables the plan skipped, with the reason (e.g. `multiple` for dark hair).
    pub skipped: Vec<(String, String)>,
}

impl SceneTables {
    pub fn get(&self, name: &str) -> anyhow::Result<&TableAsset> {
        self.assets.get(name).with_context(|| {
            format!(
                "table `{name}` was not baked (known: {:?})",
                self.assets.keys().collect::<Vec<_>>()
            )
        })
    }
}

/// Bakes (or finds in `dir`'s cache) the tables named in `wanted` for `shading`, with the 1/λ
/// axis spanning only `lambda_range`, and loads them with a parameter check. `report` sees
/// each table as it is done.
pub fn bake_scene_tables(
    fiber: &FiberDescription,
    shading: EnvShading,
    resolution: BakeResolution,
    lambda_range: (f64, f64),
    wanted: &[&str],
    dir: &Path,
    report: &mut dyn FnMut(&BakedTable),
) -> anyhow::Result<SceneTables> {
    let options = PlanOptions {
        models: vec![shading.model()],
        resolution: resolution.with_lambda_range(lambda_range.0, lambda_range.1),
        force_multiple: false,
        multiple_threshold: DEFAULT_MULTIPLE_THRESHOLD,
        tables: Some(wanted.iter().map(|name| name.to_string()).collect()),
    };
    let plan = plan_with_cache(fiber, &options, Some(dir))?;
    let skipped = plan
        .skipped
        .iter()
        .map(|s| (s.name.clone(), s.reason.clone()))
        .collect();
    let mut expected: BTreeMap<String, Value> = BTreeMap::new();
    let mut keys: BTreeMap<String, String> = BTreeMap::new();
    let mut baked = Vec::new();
    let mut assets = BTreeMap::new();
    for job in plan.jobs {
        expected.insert(job.name.to_string(), job.fiber_parameters.clone());
        keys.insert(job.name.to_string(), job.inputs_key());
        let (t, asset) = bake_and_load(job, dir, Storage::F32)?;
        if let Some(reason) = &t.replaced_damaged {
            eprintln!(
                "warning: the cached table {} was damaged and has been rebaked ({reason})",
                t.path.display()
            );
        }
        report(&t);
        check_baked(&asset, &keys[&t.name], &expected[&t.name])?;
        assets.insert(t.name.clone(), asset);
        baked.push(t);
    }
    Ok(SceneTables {
        assets,
        baked,
        skipped,
    })
}

/// The table as baked or found with inputs `key`, its fiber `parameters` checked. Another
/// process baking other settings (a λ range, a resolution) into the same folder may have
/// replaced a freshly baked file before it was read back: that is an error, never a table of
/// other settings.
fn check_baked(asset: &TableAsset, key: &str, parameters: &Value) -> anyhow::Result<()> {
    expect_parameters(asset, parameters)?;
    if asset.metadata.description.inputs_key.as_deref() != Some(key) {
        bail!(
            "{}: the table was replaced after it was baked, by one of other settings (another run baking into the same folder at the same time?); run again, or give each run its own --cache",
            asset.path.display()
        );
    }
    Ok(())
}

/// λ range of an SRBF set with a 10% margin (the bake's 1/λ axis spans only this). A set of
/// compact sources alone (a sun on black: no lobes) gets the fit's default range, which no
/// table uses (`wanted_tables` then asks for no SRBF table).
pub fn lambda_range_of_set(set: &SrbfSet) -> anyhow::Result<(f64, f64)> {
    let lambdas = set.lobes.iter().map(|l| l.lambda);
    let (lo, hi) = lambdas.fold((f64::INFINITY, 0.0f64), |(lo, hi), l| {
        (lo.min(l), hi.max(l))
    });
    if !(lo.is_finite() && hi > 0.0) {
        if set.sources.is_empty() {
            bail!("the SRBF set holds no lobes and no compact sources (a black map?)");
        }
        let defaults = strandlight_precompute::FitOptions::default();
        return Ok((defaults.lambda_min, defaults.lambda_max));
    }
    let (lo, hi) = (lo / 1.1, hi * 1.1);
    if hi > 1e4 {
        bail!(
            "λ up to {hi:.0} (directional lights?); bake tables for SRBF sets, not directional baselines"
        );
    }
    Ok((lo, if hi > lo * 1.01 { hi } else { lo * 1.01 }))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two runs baking other λ ranges into one folder: the first run's table, replaced on disk
    /// by the second's, is refused when loaded instead of shading with the wrong λ axis.
    #[test]
    fn a_table_replaced_after_its_bake_is_refused() {
        let dir = std::env::temp_dir().join(format!(
            "strandlight-scene-tables-replaced-{}",
            std::process::id()
        ));
        let _ = std::fs::remove_dir_all(&dir);
        let fiber = FiberDescription::preset("blonde").unwrap();
        let name = EnvShading::Marschner.srbf_table(ScatteringMode::Single);
        let bake = |range| {
            bake_scene_tables(
                &fiber,
                EnvShading::Marschner,
                BakeResolution::reduced(4),
                range,
                &[name],
                &dir,
                &mut |_| {},
            )
            .unwrap()
        };
        let first = bake((20.0, 40.0));
        let asset = first.get(name).unwrap();
        let key = asset.metadata.description.inputs_key.clone().unwrap();
        let parameters = asset.metadata.description.fiber_parameters.clone();
        let baked = &first.baked[0];
        let read = || strandlight_tables::asset::read_asset(&baked.path).unwrap();
        check_baked(&read(), &key, &parameters).expect("the file as baked loads");
        bake((30.0, 60.0));
        let error = check_baked(&read(), &key, &parameters)
            .unwrap_err()
            .to_string();
        assert!(error.contains("replaced after it was baked"), "{error}");
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn tables_for_each_mode_exist_in_the_plan() {
        let dir =
            std::env::temp_dir().join(format!("strandlight-scene-tables-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let fiber = FiberDescription::preset("blonde").unwrap();
        for shading in [EnvShading::Marschner, EnvShading::Artist] {
            let mut wanted: Vec<&str> = MULTIPLE_TABLES.to_vec();
            for mode in [ScatteringMode::Single, ScatteringMode::Full] {
                wanted.push(shading.srbf_table(mode));
                wanted.push(shading.direct_table(mode));
            }
            let tables = bake_scene_tables(
                &fiber,
                shading,
                BakeResolution::reduced(4),
                (20.0, 40.0),
                &wanted,
                &dir.join(format!("{shading:?}")),
                &mut |_| {},
            )
            .unwrap();
            for name in &wanted {
                let t = tables.get(name).unwrap();
                if !["fiber_averages", "attenuation_ratio", "srbf_spread"].contains(name) {
                    assert_eq!(
                        t.table.axes().len(),
                        4,
                        "{name}: the renderer's 4-axis lookup"
                    );
                }
            }
            // The 1/λ axis spans the requested range, not the global bounds.
            let conv = tables
                .get(shading.srbf_table(ScatteringMode::Single))
                .unwrap();
            let inv = &conv.table.axes()[3];
            assert!(
                (inv.min - 1.0 / 40.0).abs() < 1e-12 && (inv.max - 1.0 / 20.0).abs() < 1e-12,
                "{inv:?}"
            );
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
