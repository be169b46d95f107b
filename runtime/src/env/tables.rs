//! The tables an env-lit frame shades with, and the checks of their layout and size.

use std::sync::Arc;

use strandlight_tables::table::Table;
use strandlight_tables::table_axes::{AXIS_COS_DPHI, AXIS_U_DOT_WO, AXIS_U_DOT_XI};

use super::light_kinds::LightKinds;
use crate::gpu::GpuContext;
use crate::gpu::limits::{GpuLimits, LimitError};

/// The tables a frame shades with. Each is an RGB [`Table`] with axes (u·ξ, u·ω_o, cos Δφ, w):
/// * `srbf`: the convolution table I (I_M, `marschner_full` or the artist I_A), w = 1/λ;
/// * `direct`: S(ω_i, ω_o)·cos θ_i for directional lights, w a one-node axis (any name);
/// * `multiple`: I_G, w = σ̄_f (used only with a [`ForwardScatteringSource`](crate::multiple::ForwardScatteringSource)).
#[derive(Clone, Debug, Default)]
pub struct EnvTables {
    pub srbf: Option<Arc<Table>>,
    pub direct: Option<Arc<Table>>,
    pub multiple: Option<Arc<Table>>,
}

#[derive(Debug, thiserror::Error, PartialEq)]
pub enum EnvTableError {
    #[error("env table `{table}` is needed ({needed_by}) but was not given")]
    Missing {
        table: &'static str,
        needed_by: &'static str,
    },
    #[error("env table `{table}`: {problem}")]
    Shape {
        table: &'static str,
        problem: String,
    },
}

/// Checks an env table's layout: 4 axes, the three direction axes by name, the fourth named
/// `fourth` (or any name with one node when `None`), 3 channels.
pub fn check_env_table(
    table_name: &'static str,
    table: &Table,
    fourth: Option<&str>,
) -> Result<(), EnvTableError> {
    let bad = |problem: String| EnvTableError::Shape {
        table: table_name,
        problem,
    };
    let axes = table.axes();
    if axes.len() != 4 {
        return Err(bad(format!("has {} axes, expected 4", axes.len())));
    }
    for (axis, name) in axes
        .iter()
        .zip([AXIS_U_DOT_XI, AXIS_U_DOT_WO, AXIS_COS_DPHI])
    {
        if axis.name != name {
            return Err(bad(format!(
                "axis `{}` where `{name}` was expected",
                axis.name
            )));
        }
    }
    match fourth {
        Some(name) if axes[3].name != name => {
            return Err(bad(format!(
                "fourth axis `{}` where `{name}` was expected",
                axes[3].name
            )));
        }
        None if axes[3].count != 1 => {
            return Err(bad(format!(
                "fourth axis `{}` has {} nodes; a direct table has one",
                axes[3].name, axes[3].count
            )));
        }
        _ => {}
    }
    if table.channels() != 3 {
        return Err(bad(format!(
            "has {} channels, expected 3 (RGB)",
            table.channels()
        )));
    }
    if u32::try_from(table.values().len()).is_err() {
        return Err(bad("holds more than 2^32 values".into()));
    }
    Ok(())
}

/// The table a kind of light needs, checked for its layout.
pub(super) fn required_table<'t>(
    table: &'t Option<Arc<Table>>,
    name: &'static str,
    needed_by: &'static str,
    fourth_axis: Option<&str>,
) -> Result<&'t Table, EnvTableError> {
    let t = table.as_deref().ok_or(EnvTableError::Missing {
        table: name,
        needed_by,
    })?;
    check_env_table(name, t, fourth_axis)?;
    Ok(t)
}

/// The tables a frame binds whole, against the adapter's storage-binding limit: a table baked
/// with too many nodes (64 per direction axis is 400 MB) is refused by name, not by the driver.
pub(super) fn check_table_limits(
    gpu: &GpuContext,
    tables: &EnvTables,
    kinds: &LightKinds,
    with_multiple: bool,
) -> Result<(), LimitError> {
    let limits = GpuLimits::of(gpu);
    let bound = [
        ("env table `srbf`", kinds.has_srbf(), &tables.srbf),
        (
            "env table `direct`",
            kinds.has_directional(),
            &tables.direct,
        ),
        ("env table `multiple`", with_multiple, &tables.multiple),
    ];
    for (what, needed, table) in bound {
        if let Some(t) = table.as_ref().filter(|_| needed) {
            limits.check_storage_buffer(what, t.as_bytes().len() as u64, |max| {
                format!("bake it with fewer nodes per axis, to at most {max} bytes")
            })?;
        }
    }
    Ok(())
}
