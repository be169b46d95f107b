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

use crate::compare::{self, CompareArgs, CompareScene, Reference, ReferenceLighting};
use crate::env_frame::{EnvFrame, FrameRole, RenderedEnv};
use crate::hdr_flip::hdr_flip;
use crate::image_metrics::{Image, relative_rmse, relative_rmse_of_part};
use crate::scene_tables::ScatteringMode;
use crate::steps::Steps;
use serde::{Deserialize, Serialize};
use strandlight_runtime::env::EnvLight;

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

/// What a decomposition renders with: the scene, the run's compare settings (`args`) and the
/// same with `unshadowed` set, the SRBF default's lights and κ.
pub struct DecompositionInputs<'a> {
    pub render: compare::Renderer<'a>,
    pub scene: &'a CompareScene,
    pub args: &'a CompareArgs,
    pub unshadowed_args: &'a CompareArgs,
    pub lights: &'a [EnvLight],
    pub kappa: f32,
}

impl DecompositionInputs<'_> {
    fn srbf(
        &self,
        args: &CompareArgs,
        mode: ScatteringMode,
        kappa: f32,
        label: &str,
        steps: &mut Steps,
    ) -> anyhow::Result<Image> {
        let mut frame: EnvFrame = compare::frame(self.scene, args, self.lights, mode);
        frame.role = FrameRole::Interactive { kappa };
        let r = steps.run(
            &format!("{}: decomposition, SRBF {label}", mode.name()),
            || (self.render)(&frame),
            |r: &RenderedEnv| format!("{:.0} ms", r.milliseconds),
        )?;
        Ok(r.image)
    }
}

fn step(label: &str, image: &Image, reference: &Image) -> anyhow::Result<DecompositionStep> {
    Ok(DecompositionStep {
        label: label.into(),
        relative_rmse: relative_rmse(image, reference)?,
        hdr_flip: Some(hdr_flip(image, reference)?.mean_over_hair),
    })
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
    let multiple_part = relative_rmse_of_part(
        &srbf_full.minus(&srbf_single)?,
        &r_full.minus(r_single)?,
        r_full,
    )?;
    Ok(ErrorDecomposition {
        map: map.into(),
        mode: ScatteringMode::Full.name().into(),
        reference_lights: full.chosen.record.lights,
        reference_converged: full.converged,
        unshadowed_reference_lights: None,
        unshadowed_converged: None,
        steps: vec![
            DecompositionStep {
                label: SINGLE_PART.into(),
                relative_rmse: relative_rmse_of_part(&srbf_single, r_single, r_full)?,
                hdr_flip: None,
            },
            DecompositionStep {
                label: MULTIPLE_PART.into(),
                relative_rmse: multiple_part,
                hdr_flip: None,
            },
            step(FULL, &srbf_full, r_full)?,
        ],
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
