//! Where the SRBF frame's error comes from (issue #16: "report the error decomposition per
//! map"). Each approximation of Ren 2010's method is added in turn and the image measured
//! against the reference it should match at that point:
//!
//! - single scattering, unshadowed (T = 1 everywhere, so no shadowing enters):
//!   - **fit**: the brute-force render of the fit's own lighting against that of the map;
//!   - **tables**: the SRBF frame against the brute-force render of the fit's lighting (the
//!     convolution tables' interpolation and the renderer's evaluation);
//!   - both: the SRBF frame against the map's reference;
//! - single scattering, shadowed, against the map's reference: the SRBF frame drawing every
//!   strand into its light maps (κ 1: the one visibility per lobe of the shadowing
//!   factorization), then at the default κ (stochastic simplification on top);
//! - full scattering: the error of the single- and the multiple-scattering part, each over the
//!   full reference's norm (they add as vectors to the full frame's error), and the whole.
//!
//! The unshadowed references are cheap (no light passes), so they climb further than the
//! shadowed ones ([`unshadowed_max_lights`]) and usually converge; the shadowed ones are the
//! run's.
//!
//! Against the path-traced ground truth (issue #38) each frame is measured against the truth
//! itself, so the steps show how each approximation moves the error that a reader of the
//! picture sees, the DOM reference's own included ([`single_scattering_against_truth`],
//! [`full_scattering_against_truth`]). The truth has no unshadowed image, so the fit is taken
//! as the DOM reference of the fit's lights, and the tables are not apart from the one
//! visibility per lobe there.

use crate::compare::{self, CompareScene, CompareSettings, Reference};
use crate::ground_truth::GroundTruth;
use crate::hdr_flip::hdr_flip;
use serde::{Deserialize, Serialize};
use strandlight_scene::env_lighting::{EnvLightSet, EnvLighting, ReferenceLighting};
use strandlight_scene::frame_settings::{FrameSettings, Lighting};
use strandlight_scene::image_metrics::{Image, relative_rmse, relative_rmse_of_part};
use strandlight_scene::look::LobeVisibilityArg;
use strandlight_scene::rendered_frame::RenderedFrame;
use strandlight_scene::scene_tables::ScatteringMode;
use strandlight_scene::steps::Steps;

/// The most lights an unshadowed reference climbs to (6·64²): one costs about a minute on
/// lavapipe at 160×120, its shading alone being what converges.
pub const UNSHADOWED_REFERENCE_MAX_LIGHTS: usize = 24576;

/// The unshadowed references' budget beside a shadowed budget of `shadowed_max_lights`: two
/// rungs (16×) past it, at most [`UNSHADOWED_REFERENCE_MAX_LIGHTS`] (`bench --quick`'s 384
/// gives 6144; the full plan's 1536 and above give 24576). Always 6n² when the input is.
pub fn unshadowed_max_lights(shadowed_max_lights: usize) -> usize {
    (16 * shadowed_max_lights).min(UNSHADOWED_REFERENCE_MAX_LIGHTS)
}

/// One approximation added: the image's error against the reference it should match.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DecompositionStep {
    pub label: String,
    pub relative_rmse: f64,
    /// Against the ground truth: the relative RMSE with the truth's noise removed in
    /// quadrature. None against a DOM reference, and for a part of an image.
    #[serde(default)]
    pub relative_rmse_noise_corrected: Option<f64>,
    /// None for a part of an image (its HDR-FLIP has no meaning: it is not a picture).
    pub hdr_flip: Option<f64>,
}

/// One map and mode's decomposition.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ErrorDecomposition {
    pub map: String,
    pub mode: String,
    /// The shadowed reference's lights and whether its ladder converged.
    pub reference_lights: usize,
    pub reference_converged: Option<bool>,
    /// Single scattering: the unshadowed references' lights (the map's, the fit's) and whether
    /// both converged.
    pub unshadowed_reference_lights: Option<(usize, usize)>,
    pub unshadowed_converged: Option<bool>,
    /// Every step measured against the path-traced ground truth, not the DOM reference.
    /// Reports written before it existed: false.
    #[serde(default)]
    pub against_truth: bool,
    pub steps: Vec<DecompositionStep>,
}

/// Step labels, shared by the measurement and the page.
pub const FIT: &str = "fit";
pub const TABLES: &str = "tables";
pub const UNSHADOWED: &str = "fit and tables (unshadowed)";
pub const EVERY_STRAND: &str = "+ one visibility per lobe (κ 1)";
pub const DEFAULT_KAPPA: &str = "+ κ (the default)";
pub const SINGLE_PART: &str = "single-scattering part";
pub const MULTIPLE_PART: &str = "multiple-scattering part";
pub const FULL: &str = "full (the default)";
/// Single-scattering steps against the ground truth.
pub const TRUTH_MAP_LIGHTS: &str = "DOM reference (the map's lights)";
pub const TRUTH_FIT_LIGHTS: &str = "DOM reference of the fit's lights";
pub const TRUTH_EVERY_STRAND: &str = "SRBF: tables, one light map per lobe (κ 1)";
pub const TRUTH_LIGHT_MAPS: &str = "+ κ (Ren 2010)";
pub const TRUTH_VOLUME: &str = "visibility volume instead (the default)";
pub const TRUTH_SHARP_SOURCES: &str = "the default, compact sources' maps at 4× size";
/// How many times the default light-map size the compact sources' maps get in
/// [`TRUTH_SHARP_SOURCES`]: what their shadows' resolution costs against the truth.
pub const SHARP_SOURCE_MAP_SCALE: u32 = 4;

/// What a decomposition renders with: the scene, the run's compare settings (`args`) and the
/// same with the frame unshadowed, the SRBF default's lobe count and κ.
pub struct DecompositionInputs<'a> {
    pub render: compare::Renderer<'a>,
    pub scene: &'a CompareScene,
    pub args: &'a CompareSettings,
    pub unshadowed_args: &'a CompareSettings,
    pub lobes: usize,
    pub kappa: f32,
}

impl DecompositionInputs<'_> {
    /// The SRBF frame of `args` in `mode` with κ `kappa` (and the look of `args`).
    fn srbf(
        &self,
        args: &CompareSettings,
        mode: ScatteringMode,
        kappa: f32,
        label: &str,
        steps: &mut Steps,
    ) -> anyhow::Result<Image> {
        let settings = self.srbf_settings(args, mode, |env| env.kappa = kappa);
        self.render_srbf(&settings, mode, label, steps)
    }

    /// The product's default frame (lobes read the visibility volume), with compact sources'
    /// light maps `dodm_size` texels across.
    fn srbf_volume(
        &self,
        mode: ScatteringMode,
        dodm_size: u32,
        label: &str,
        steps: &mut Steps,
    ) -> anyhow::Result<Image> {
        let settings = self.srbf_settings(self.args, mode, |env| {
            env.kappa = self.kappa;
            env.view.lobe_visibility = LobeVisibilityArg::Volume;
            env.dodm_size = dodm_size;
        });
        self.render_srbf(&settings, mode, label, steps)
    }

    /// The SRBF frame of `args` in `mode` with the default's lobes, then `change`d.
    fn srbf_settings(
        &self,
        args: &CompareSettings,
        mode: ScatteringMode,
        change: impl FnOnce(&mut EnvLighting),
    ) -> FrameSettings {
        let mut settings = args.frame_of(mode, EnvLightSet::Fit);
        if let Lighting::Environment(env) = &mut settings.lighting {
            env.lobes = Some(self.lobes);
            change(env);
        }
        settings
    }

    fn render_srbf(
        &self,
        settings: &FrameSettings,
        mode: ScatteringMode,
        label: &str,
        steps: &mut Steps,
    ) -> anyhow::Result<Image> {
        let frame = compare::frame(self.scene, settings)?;
        let r = steps.run(
            &format!("{}: decomposition, SRBF {label}", mode.name()),
            || (self.render)(&frame),
            |r: &RenderedFrame| format!("{:.0} ms", r.milliseconds),
        )?;
        Ok(r.image)
    }

    fn has_compact_sources(&self) -> bool {
        !self.scene.prepared.scene.fit.sources.is_empty()
    }
}

fn step(label: &str, image: &Image, reference: &Image) -> anyhow::Result<DecompositionStep> {
    Ok(DecompositionStep {
        label: label.into(),
        relative_rmse: relative_rmse(image, reference)?,
        relative_rmse_noise_corrected: None,
        hdr_flip: Some(hdr_flip(image, reference)?.mean_over_hair),
    })
}

fn truth_step(
    label: &str,
    image: &Image,
    truth: &GroundTruth,
) -> anyhow::Result<DecompositionStep> {
    let e = relative_rmse(image, &truth.image)?;
    Ok(DecompositionStep {
        label: label.into(),
        relative_rmse: e,
        relative_rmse_noise_corrected: Some(truth.noise_corrected(e)),
        hdr_flip: Some(hdr_flip(image, &truth.image)?.mean_over_hair),
    })
}

/// A part of an image (single or multiple scattering) against the same part of `yardstick`,
/// over the whole `norm` image: the parts' errors add as vectors to the whole's.
fn part_step(
    label: &str,
    part: &Image,
    yardstick: &Image,
    norm: &Image,
) -> anyhow::Result<DecompositionStep> {
    Ok(DecompositionStep {
        label: label.into(),
        relative_rmse: relative_rmse_of_part(part, yardstick, norm)?,
        relative_rmse_noise_corrected: None,
        hdr_flip: None,
    })
}

/// A full-scattering frame's single- and multiple-scattering parts (`single` is the frame's
/// single-scattering render) against the same parts of a yardstick, over its full image.
fn scattering_parts(
    (single, full): (&Image, &Image),
    (yardstick_single, yardstick_full): (&Image, &Image),
) -> anyhow::Result<[DecompositionStep; 2]> {
    Ok([
        part_step(SINGLE_PART, single, yardstick_single, yardstick_full)?,
        part_step(
            MULTIPLE_PART,
            &full.minus(single)?,
            &yardstick_full.minus(yardstick_single)?,
            yardstick_full,
        )?,
    ])
}

/// Single scattering: fit, tables, shadowing at κ 1, κ; `reference` is the run's shadowed
/// single-scattering reference.
pub fn single_scattering(
    map: &str,
    inputs: &DecompositionInputs,
    reference: &Reference,
    steps: &mut Steps,
) -> anyhow::Result<ErrorDecomposition> {
    let mode = ScatteringMode::Single;
    let unshadowed = |lighting, steps: &mut Steps| {
        compare::reference_of(
            inputs.render,
            inputs.scene,
            inputs.unshadowed_args,
            mode,
            lighting,
            steps,
        )
    };
    let map_unshadowed = unshadowed(ReferenceLighting::Map, steps)?;
    let fit_unshadowed = unshadowed(ReferenceLighting::Fit, steps)?;
    let srbf_unshadowed = inputs.srbf(inputs.unshadowed_args, mode, 1.0, "unshadowed", steps)?;
    let every_strand = inputs.srbf(inputs.args, mode, 1.0, "κ 1", steps)?;
    let default = inputs.srbf(inputs.args, mode, inputs.kappa, "default", steps)?;
    let (map_u, fit_u) = (&map_unshadowed.chosen.image, &fit_unshadowed.chosen.image);
    let shadowed = &reference.chosen.image;
    Ok(ErrorDecomposition {
        map: map.into(),
        mode: mode.name().into(),
        reference_lights: reference.chosen.record.lights,
        reference_converged: reference.converged,
        unshadowed_reference_lights: Some((
            map_unshadowed.chosen.record.lights,
            fit_unshadowed.chosen.record.lights,
        )),
        unshadowed_converged: map_unshadowed
            .converged
            .zip(fit_unshadowed.converged)
            .map(|(a, b)| a && b),
        against_truth: false,
        steps: vec![
            step(FIT, fit_u, map_u)?,
            step(TABLES, &srbf_unshadowed, fit_u)?,
            step(UNSHADOWED, &srbf_unshadowed, map_u)?,
            step(EVERY_STRAND, &every_strand, shadowed)?,
            step(DEFAULT_KAPPA, &default, shadowed)?,
        ],
    })
}

/// Full scattering: the single- and multiple-scattering parts of the SRBF default against
/// those of the references (`single` and `full`, the run's, of one light budget).
pub fn full_scattering(
    map: &str,
    inputs: &DecompositionInputs,
    single: &Reference,
    full: &Reference,
    steps: &mut Steps,
) -> anyhow::Result<ErrorDecomposition> {
    let srbf_single = inputs.srbf(
        inputs.args,
        ScatteringMode::Single,
        inputs.kappa,
        "default",
        steps,
    )?;
    let srbf_full = inputs.srbf(
        inputs.args,
        ScatteringMode::Full,
        inputs.kappa,
        "default",
        steps,
    )?;
    let (r_single, r_full) = (&single.chosen.image, &full.chosen.image);
    Ok(ErrorDecomposition {
        map: map.into(),
        mode: ScatteringMode::Full.name().into(),
        reference_lights: full.chosen.record.lights,
        reference_converged: full.converged,
        unshadowed_reference_lights: None,
        unshadowed_converged: None,
        against_truth: false,
        steps: [
            scattering_parts((&srbf_single, &srbf_full), (r_single, r_full))?.to_vec(),
            vec![step(FULL, &srbf_full, r_full)?],
        ]
        .concat(),
    })
}

/// The cube's 6n² texel lights of a reference whose record also counts its compact sources
/// (at most a few, far fewer than the gap to the next cube: quarry's 1537 is 1536 + its sun).
fn cube_lights(recorded: usize) -> usize {
    let face = ((recorded / 6) as f64).sqrt().floor() as usize;
    6 * face * face
}

/// Single scattering against the ground truth: the DOM reference of the map and of the fit's
/// lights (at the map reference's light count), Ren's SRBF frame at κ 1 and at the default κ,
/// the visibility volume in its place (the default), and, where the map has compact sources,
/// the default with their light maps [`SHARP_SOURCE_MAP_SCALE`] times finer.
pub fn single_scattering_against_truth(
    map: &str,
    inputs: &DecompositionInputs,
    reference: &Reference,
    truth: &GroundTruth,
    steps: &mut Steps,
) -> anyhow::Result<ErrorDecomposition> {
    let mode = ScatteringMode::Single;
    let fit_args = CompareSettings {
        reference_lights: Some(cube_lights(reference.chosen.record.lights)),
        ..inputs.args.clone()
    };
    let fit = compare::reference_of(
        inputs.render,
        inputs.scene,
        &fit_args,
        mode,
        ReferenceLighting::Fit,
        steps,
    )?;
    let every_strand = inputs.srbf(inputs.args, mode, 1.0, "light maps, κ 1", steps)?;
    let light_maps = inputs.srbf(inputs.args, mode, inputs.kappa, "light maps", steps)?;
    let size = inputs.args.env().dodm_size;
    let volume = inputs.srbf_volume(mode, size, "volume", steps)?;
    let mut measured = vec![
        truth_step(TRUTH_MAP_LIGHTS, &reference.chosen.image, truth)?,
        truth_step(TRUTH_FIT_LIGHTS, &fit.chosen.image, truth)?,
        truth_step(TRUTH_EVERY_STRAND, &every_strand, truth)?,
        truth_step(TRUTH_LIGHT_MAPS, &light_maps, truth)?,
        truth_step(TRUTH_VOLUME, &volume, truth)?,
    ];
    if inputs.has_compact_sources() {
        let sharp = SHARP_SOURCE_MAP_SCALE * size;
        let label = format!("volume, compact sources' maps {sharp}²");
        let image = inputs.srbf_volume(mode, sharp, &label, steps)?;
        measured.push(truth_step(TRUTH_SHARP_SOURCES, &image, truth)?);
    }
    Ok(ErrorDecomposition {
        map: map.into(),
        mode: mode.name().into(),
        reference_lights: reference.chosen.record.lights,
        reference_converged: reference.converged,
        unshadowed_reference_lights: None,
        unshadowed_converged: None,
        against_truth: true,
        steps: measured,
    })
}

/// Full scattering against the ground truth: the default frame's single- and multiple-
/// scattering parts against the truth's (its full image less its single-scattering image),
/// each over the full truth's norm, and the whole.
pub fn full_scattering_against_truth(
    map: &str,
    inputs: &DecompositionInputs,
    reference: &Reference,
    single: &GroundTruth,
    full: &GroundTruth,
    steps: &mut Steps,
) -> anyhow::Result<ErrorDecomposition> {
    let dodm = inputs.args.env().dodm_size;
    let srbf_single = inputs.srbf_volume(ScatteringMode::Single, dodm, "volume", steps)?;
    let srbf_full = inputs.srbf_volume(ScatteringMode::Full, dodm, "volume", steps)?;
    let (t_single, t_full) = (&single.image, &full.image);
    Ok(ErrorDecomposition {
        map: map.into(),
        mode: ScatteringMode::Full.name().into(),
        reference_lights: reference.chosen.record.lights,
        reference_converged: reference.converged,
        unshadowed_reference_lights: None,
        unshadowed_converged: None,
        against_truth: true,
        steps: [
            scattering_parts((&srbf_single, &srbf_full), (t_single, t_full))?.to_vec(),
            vec![truth_step(FULL, &srbf_full, full)?],
        ]
        .concat(),
    })
}

impl ErrorDecomposition {
    /// The step of `label`, where measured.
    pub fn step(&self, label: &str) -> Option<&DecompositionStep> {
        self.steps.iter().find(|s| s.label == label)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_reference_record_with_sources_gives_its_cube() {
        for (recorded, cube) in [(1536, 1536), (1537, 1536), (104, 96), (6147, 6144), (6, 6)] {
            assert_eq!(cube_lights(recorded), cube, "{recorded}");
        }
    }
    use strandlight_precompute::env_lights::face_resolution_for;

    #[test]
    fn the_unshadowed_budget_is_a_cube_two_rungs_past_the_shadowed_one() {
        for (shadowed, want) in [(384, 6144), (1536, 24576), (6144, 24576)] {
            let got = unshadowed_max_lights(shadowed);
            assert_eq!(got, want, "beside {shadowed}");
            assert!(face_resolution_for(got).is_some(), "{got} is 6n²");
        }
    }
}
