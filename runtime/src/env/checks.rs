//! What a frame's inputs must satisfy before anything is created on the GPU: usable lights, a
//! well-formed forward-scattering grid, settings in range and the tables each kind of light
//! needs.

use strandlight_tables::table_axes::{AXIS_INV_LAMBDA, AXIS_SIGMA_F};

use super::light_kinds::LightKinds;
use super::tables::required_table;
use super::{EnvRenderError, EnvRenderOptions, EnvTables};
use crate::env_light::EnvLight;
use crate::multiple::ForwardScatteringGrid;
use crate::passes::convolution_depth::check_kappa;

fn check_light(index: usize, light: &EnvLight) -> Result<(), EnvRenderError> {
    let bad = |problem: String| EnvRenderError::BadLight { index, problem };
    if !light.direction.is_finite() || light.direction.length() < 1e-6 {
        return Err(bad(format!(
            "direction {:?} is not a usable unit vector",
            light.direction
        )));
    }
    if let Some(lambda) = light.lambda
        && !(lambda.is_finite() && lambda > 0.0)
    {
        return Err(bad(format!(
            "SRBF bandwidth λ = {lambda} must be positive and finite"
        )));
    }
    if light.rgb.iter().any(|c| !c.is_finite()) {
        return Err(bad(format!("rgb {:?} is not finite", light.rgb)));
    }
    if !(light.angular_variance.is_finite() && light.angular_variance >= 0.0) {
        return Err(bad(format!(
            "angular variance {} must be finite and non-negative",
            light.angular_variance
        )));
    }
    if light.angular_variance > 0.0 && light.lambda.is_some() {
        return Err(bad(
            "angular_variance is for directional lights (an SRBF's spread is its λ)".into(),
        ));
    }
    if let Some(from) = light.shadowed_from {
        if light.lambda.is_some() {
            return Err(bad(
                "an SRBF light casts its own shadow map (shadowed_from is for directional lights)"
                    .into(),
            ));
        }
        if !from.is_finite() || from.length() < 1e-6 {
            return Err(bad(format!(
                "shadowed_from {from:?} is not a usable unit vector"
            )));
        }
    }
    Ok(())
}

pub(super) fn check_grid(
    grid: &ForwardScatteringGrid,
    lights: usize,
) -> Result<(), EnvRenderError> {
    let vertices = grid.dims.iter().map(|&d| d as usize).product::<usize>();
    if vertices == 0 {
        return Err(EnvRenderError::Grid(format!(
            "dims {:?} has a zero",
            grid.dims
        )));
    }
    if grid.values.len() != vertices * lights {
        return Err(EnvRenderError::Grid(format!(
            "{} values for {lights} lights × {vertices} vertices",
            grid.values.len()
        )));
    }
    if !grid.origin.is_finite() || !grid.spacing.is_finite() || grid.spacing.min_element() <= 0.0 {
        return Err(EnvRenderError::Grid(format!(
            "origin {:?} / spacing {:?} must be finite, spacing positive",
            grid.origin, grid.spacing
        )));
    }
    if grid.values.iter().any(|v| v.iter().any(|c| !c.is_finite())) {
        return Err(EnvRenderError::Grid("holds non-finite values".into()));
    }
    Ok(())
}

/// Everything the inputs must satisfy before anything is created on the GPU.
pub(super) fn check_inputs(
    lights: &[EnvLight],
    kinds: &LightKinds,
    tables: &EnvTables,
    options: &EnvRenderOptions,
    with_multiple: bool,
) -> Result<(), EnvRenderError> {
    if lights.is_empty() {
        return Err(EnvRenderError::NoLights);
    }
    for (i, l) in lights.iter().enumerate() {
        check_light(i, l)?;
    }
    options.dodm.check()?;
    check_kappa(options.kappa)?;
    options.transparency.check()?;
    if let Some(volume) = options.lobe_visibility.volume() {
        volume.validate()?;
    }
    if kinds.has_srbf() {
        required_table(&tables.srbf, "srbf", "SRBF lights", Some(AXIS_INV_LAMBDA))?;
    }
    if kinds.has_directional() {
        required_table(&tables.direct, "direct", "directional lights", None)?;
    }
    if with_multiple {
        required_table(
            &tables.multiple,
            "multiple",
            "multiple scattering",
            Some(AXIS_SIGMA_F),
        )?;
    }
    Ok(())
}
