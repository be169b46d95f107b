//! The web page's bundle: one scene the page renders without the desktop tool. `strandlight
//! web` writes it; the page (`web/`) reads it. Everything is a file a static server serves:
//!
//! - `settings.json`: the [`FrameSettings`] the page starts from (`render replay` renders the
//!   same frame natively);
//! - `scene.json`: [`BundleScene`], the SRBF fit and, per fiber preset baked, its tables' files;
//! - `hair.hair`: the groom in cyHairFile's binary format (the page also takes a dropped one);
//! - `tables/*.sltab`: the baked tables, checksummed assets, half floats where their error
//!   allows ([`BundledTable::max_relative_error`]).
//!
//! The page makes a [`PreparedEnv`] of the bundle ([`BundleScene::prepared`]) and builds its
//! frames from it and its settings as every other front end does
//! (`crate::frame_render::env_frame`), so a bundle never holds a derived copy (lights, turned
//! or not) that could disagree.

use crate::env_scene::{EnvScene, PreparedEnv};
use crate::scene_tables::{EnvShading, MULTIPLE_TABLES, ScatteringMode, SceneTables};
use anyhow::Context;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;
use strandlight_precompute::bake_plan::FiberDescription;
use strandlight_precompute::srbf_set::SrbfSet;
use strandlight_runtime::camera::UpAxis;
use strandlight_tables::asset::{Storage, TableAsset, read_asset_bytes, write_asset_to};

pub const SETTINGS_FILE: &str = "settings.json";
pub const SCENE_FILE: &str = "scene.json";
pub const HAIR_FILE: &str = "hair.hair";
pub const TABLES_DIR: &str = "tables";
/// Bumped when a reader of the old layout would misread the new one (2: the first look has a
/// fit and tables of its own).
pub const FORMAT: u32 = 2;

/// Half floats are kept only where they change no table value by more than this (relative to
/// the table's largest value): below the tables' own interpolation error (docs/BENCHMARKS.md).
pub const HALF_TOLERANCE: f64 = 1e-3;

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct BundleScene {
    pub format: u32,
    /// The environment's name, for the page's panel.
    pub environment: String,
    pub fit: SrbfSet,
    pub shading: EnvShading,
    pub mode: ScatteringMode,
    /// Per fiber preset baked into the bundle: its tables.
    pub presets: BTreeMap<String, Vec<BundledTable>>,
    /// What the first look is drawn from, as the desktop's (`coarse_preview_settings`): the
    /// page fetches and opens these first, draws its preview, and takes the rest as they
    /// arrive.
    pub first_look: FirstLookScene,
}

/// The first look's own fit (few lobes) and, per preset, its coarse single-scattering tables
/// ([`BundleScene::first_look_table_names`]).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct FirstLookScene {
    pub fit: SrbfSet,
    pub presets: BTreeMap<String, Vec<BundledTable>>,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct BundledTable {
    /// The name the renderer asks for (`SceneTables::get`).
    pub name: String,
    /// Under `tables/`.
    pub file: String,
    pub bytes: u64,
    pub storage: Storage,
    /// Largest |half − f32| over the table's largest |value| (0 for f32).
    pub max_relative_error: f64,
}

impl BundleScene {
    pub fn parse(bytes: &[u8]) -> anyhow::Result<Self> {
        let scene: Self = serde_json::from_slice(bytes).context(SCENE_FILE)?;
        anyhow::ensure!(
            scene.format == FORMAT,
            "{SCENE_FILE}: bundle format {} (this page reads {FORMAT}); rebuild it with `strandlight web`",
            scene.format
        );
        anyhow::ensure!(!scene.presets.is_empty(), "{SCENE_FILE}: no fiber preset");
        Ok(scene)
    }

    /// The scene of `preset`'s tables over a hair with `up`, as `prepare_env` makes it from the
    /// same fit (without the map: the page draws the fit's frames only).
    pub fn prepared(
        &self,
        preset: &str,
        up: UpAxis,
        fetched: impl Fn(&str) -> Option<Vec<u8>>,
    ) -> anyhow::Result<PreparedEnv> {
        let tables = self.scene_tables(preset, fetched)?;
        self.prepared_from(preset, up, &self.fit, tables)
    }

    fn prepared_from(
        &self,
        preset: &str,
        up: UpAxis,
        fit: &SrbfSet,
        tables: SceneTables,
    ) -> anyhow::Result<PreparedEnv> {
        let fiber =
            FiberDescription::preset(preset).with_context(|| format!("preset {preset:?}"))?;
        Ok(PreparedEnv {
            env: None,
            scene: EnvScene {
                fit: fit.clone(),
                tables,
                mode: self.mode,
            },
            shading: self.shading,
            fiber,
            up,
        })
    }

    /// The tables the page reads: the SRBF table, and the direct table where the fit took
    /// compact sources out as directional lights, of single scattering (the preview's, and the
    /// frame's when the page asks for single) and, for a scene with multiple scattering, of
    /// the full mode with the multiple-scattering tables.
    pub fn table_names(&self) -> Vec<&'static str> {
        let modes: &[ScatteringMode] = match self.mode {
            ScatteringMode::Single => &[ScatteringMode::Single],
            ScatteringMode::Full => &[ScatteringMode::Single, ScatteringMode::Full],
        };
        let mut names = Vec::new();
        for &mode in modes {
            names.push(self.shading.srbf_table(mode));
            if !self.fit.sources.is_empty() {
                names.push(self.shading.direct_table(mode));
            }
        }
        if self.mode == ScatteringMode::Full {
            names.extend(MULTIPLE_TABLES);
        }
        // The artist fiber has one table for both modes: bundle it once.
        let mut unique = Vec::new();
        for name in names {
            if !unique.contains(&name) {
                unique.push(name);
            }
        }
        unique
    }

    /// The tables of a first look of `fit` (`FramePart::Preview`: single scattering): the SRBF
    /// table, and the direct table where the fit took compact sources out.
    pub fn first_look_table_names(&self, fit: &SrbfSet) -> Vec<&'static str> {
        let mut names = vec![self.shading.srbf_table(ScatteringMode::Single)];
        if !fit.sources.is_empty() {
            names.push(self.shading.direct_table(ScatteringMode::Single));
        }
        names
    }

    /// The first look's scene ([`Self::first_look`]): its fit and coarse tables, enough for a
    /// preview while the rest are still being fetched.
    pub fn prepared_first_look(
        &self,
        preset: &str,
        up: UpAxis,
        fetched: impl Fn(&str) -> Option<Vec<u8>>,
    ) -> anyhow::Result<PreparedEnv> {
        let tables = tables_of(&self.first_look.presets, preset, fetched)?;
        self.prepared_from(preset, up, &self.first_look.fit, tables)
    }

    /// `preset`'s tables from their files' bytes (`fetched(file)`), checked as any asset is.
    pub fn scene_tables(
        &self,
        preset: &str,
        fetched: impl Fn(&str) -> Option<Vec<u8>>,
    ) -> anyhow::Result<SceneTables> {
        tables_of(&self.presets, preset, fetched)
    }
}

/// The tables `presets` lists for `preset`, from their files' bytes (`fetched(file)`), checked
/// as any asset is.
fn tables_of(
    presets: &BTreeMap<String, Vec<BundledTable>>,
    preset: &str,
    fetched: impl Fn(&str) -> Option<Vec<u8>>,
) -> anyhow::Result<SceneTables> {
    let tables = presets
        .get(preset)
        .with_context(|| format!("{SCENE_FILE}: no preset {preset:?}"))?;
    let mut assets = BTreeMap::new();
    for table in tables {
        let path = Path::new(TABLES_DIR).join(&table.file);
        let bytes =
            fetched(&table.file).with_context(|| format!("{} was not fetched", path.display()))?;
        assets.insert(table.name.clone(), read_asset_bytes(&path, &bytes)?);
    }
    Ok(SceneTables {
        assets,
        baked: Vec::new(),
        skipped: Vec::new(),
    })
}

/// A table's file in the bundle: half floats within [`HALF_TOLERANCE`], else f32.
pub fn bundled_table_bytes(
    name: &str,
    file: &str,
    asset: &TableAsset,
) -> anyhow::Result<(BundledTable, Vec<u8>)> {
    let path = Path::new(TABLES_DIR).join(file);
    let description = &asset.metadata.description;
    let half = write_half(&path, asset).ok();
    let (storage, bytes, error) = match half {
        Some((bytes, error)) if error <= HALF_TOLERANCE => (Storage::F16, bytes, error),
        _ => {
            let mut bytes = Vec::new();
            write_asset_to(&mut bytes, &path, &asset.table, description, Storage::F32)?;
            (Storage::F32, bytes, 0.0)
        }
    };
    let entry = BundledTable {
        name: name.into(),
        file: file.into(),
        bytes: bytes.len() as u64,
        storage,
        max_relative_error: error,
    };
    Ok((entry, bytes))
}

/// The asset in half floats and its largest error relative to the table's largest value.
fn write_half(path: &Path, asset: &TableAsset) -> anyhow::Result<(Vec<u8>, f64)> {
    let mut bytes = Vec::new();
    let description = &asset.metadata.description;
    write_asset_to(&mut bytes, path, &asset.table, description, Storage::F16)?;
    let back = read_asset_bytes(path, &bytes)?;
    let values = asset.table.values();
    let largest = values.iter().fold(0.0f64, |m, v| m.max(v.abs() as f64));
    let worst = values
        .iter()
        .zip(back.table.values())
        .fold(0.0f64, |m, (a, b)| m.max((*a as f64 - *b as f64).abs()));
    Ok((bytes, if largest > 0.0 { worst / largest } else { 0.0 }))
}

/// A table file of the bundle: its name under `tables/` and its bytes.
pub type TableFile = (String, Vec<u8>);

/// What one preset of the bundle was prepared into: its full scene and its first look's
/// (`coarse_preview_settings`).
pub struct BundledPreset<'a> {
    pub name: String,
    pub full: &'a PreparedEnv,
    pub first_look: &'a PreparedEnv,
}

/// The bundle's scene description and table files for `presets`.
pub fn bundle_scene(
    environment: &str,
    presets: &[BundledPreset],
) -> anyhow::Result<(BundleScene, Vec<TableFile>)> {
    let first = presets.first().context("no preset to bundle")?;
    let mut scene = BundleScene {
        format: FORMAT,
        environment: environment.into(),
        fit: first.full.scene.fit.clone(),
        shading: first.full.shading,
        mode: first.full.scene.mode,
        presets: BTreeMap::new(),
        first_look: FirstLookScene {
            fit: first.first_look.scene.fit.clone(),
            presets: BTreeMap::new(),
        },
    };
    let mut files = Vec::new();
    for preset in presets {
        let name = &preset.name;
        anyhow::ensure!(
            preset.full.scene.fit == scene.fit && preset.full.scene.mode == scene.mode,
            "preset {name}: prepared under another fit or scattering mode than the first"
        );
        anyhow::ensure!(
            preset.first_look.scene.fit == scene.first_look.fit,
            "preset {name}: its first look was fitted apart from the first preset's"
        );
        let full = (scene.table_names().into_iter()).map(|t| (t, format!("{name}-{t}.sltab")));
        let entries = bundle_tables(preset.full, full, &mut files)?;
        scene.presets.insert(name.clone(), entries);
        let first_look = (scene
            .first_look_table_names(&scene.first_look.fit)
            .into_iter())
        .map(|t| (t, format!("{name}-first-look-{t}.sltab")));
        let entries = bundle_tables(preset.first_look, first_look, &mut files)?;
        scene.first_look.presets.insert(name.clone(), entries);
    }
    Ok((scene, files))
}

/// The tables `names` (table, file) of `prepared`, their files pushed onto `files`.
fn bundle_tables(
    prepared: &PreparedEnv,
    names: impl Iterator<Item = (&'static str, String)>,
    files: &mut Vec<TableFile>,
) -> anyhow::Result<Vec<BundledTable>> {
    let mut entries = Vec::new();
    for (name, file) in names {
        let asset = prepared.scene.tables.get(name)?;
        let (entry, bytes) = bundled_table_bytes(name, &file, asset)?;
        files.push((file, bytes));
        entries.push(entry);
    }
    Ok(entries)
}
