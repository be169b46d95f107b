//! The fiber tables the forward-scattering march reads, as the bake writes them (`Table`s; the
//! runtime never links the tabulation code):
//!
//! * `fiber_averages` — axes (`sin_theta` ∈ [−1, 1], `quantity` with the 9 nodes of
//!   `FIBER_AVERAGE_QUANTITIES` = a_f, a_b, alpha_f, alpha_b, beta2_f, beta2_b, A_b, Delta_b,
//!   sigma2_b), 3 channels (RGB). The march reads ā_f (node 0) and β̄_f² (node 4, rad² in θ_h).
//! * `attenuation_ratio` — axes (`nu`, `abs_sin_theta`), 1 channel: α(ν, θ) = σ_t(ω)/σ_t⊥.
//! * `srbf_spread` — axes (`abs_u_dot_xi`, `lambda`), 1 channel: the variance (rad², of the
//!   incident inclination) an SRBF light of bandwidth λ brings to the first event.
//!
//! Each accessor checks the table's shape once (typed error naming the table and the problem)
//! and is infallible afterwards: coordinates are clamped and made finite before every lookup.

use strandlight_tables::table::Table;
use thiserror::Error;

/// Node of `beta2_f` and `a_f` on the `quantity` axis of `fiber_averages` (bake_plan's order).
const QUANTITY_A_F: f64 = 0.0;
const QUANTITY_BETA2_F: f64 = 4.0;
const FIBER_AVERAGE_QUANTITY_COUNT: usize = 9;

/// A table or setting the forward-scattering module cannot use.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum ForwardScatteringError {
    #[error("table `{table}`: {problem}")]
    TableShape { table: &'static str, problem: String },
    #[error("forward-scattering setting `{parameter}` = {value}: {problem}")]
    InvalidSetting { parameter: &'static str, value: String, problem: String },
}

/// Checks axis names/counts and the channel count of a baked table.
fn check_shape(
    table: &Table,
    name: &'static str,
    axes: &[&str],
    channels: usize,
) -> Result<(), ForwardScatteringError> {
    let fail = |problem: String| Err(ForwardScatteringError::TableShape { table: name, problem });
    let found: Vec<&str> = table.axes().iter().map(|a| a.name.as_str()).collect();
    if found != axes {
        return fail(format!("axes are {found:?}, expected {axes:?}"));
    }
    if table.channels() != channels {
        return fail(format!("{} channels, expected {channels}", table.channels()));
    }
    if let Some(a) = table.axes().iter().find(|a| a.count < 2) {
        return fail(format!("axis `{}` has {} node(s), at least 2 are needed", a.name, a.count));
    }
    let stats = table.stats();
    if stats.nan_count + stats.infinite_count > 0 {
        return fail(format!(
            "{} NaN and {} infinite values",
            stats.nan_count, stats.infinite_count
        ));
    }
    Ok(())
}

/// Replaces NaN by `fallback` so a lookup can never fail (±∞ clamp inside `Table`).
fn finite_or(x: f64, fallback: f64) -> f64 {
    if x.is_nan() { fallback } else { x }
}

/// ā_f(θ) and β̄_f²(θ) per channel, from the `fiber_averages` table.
#[derive(Clone, Debug)]
pub struct ForwardFiberAverages {
    table: Table,
}

/// The two per-event quantities of a forward-scattering event at one inclination.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ForwardEvent {
    /// ā_f: fraction of the light kept in the forward hemisphere.
    pub attenuation: [f32; 3],
    /// β̄_f²: longitudinal variance the event adds (rad², in θ_h).
    pub variance: [f32; 3],
}

impl ForwardFiberAverages {
    pub fn from_table(table: &Table) -> Result<Self, ForwardScatteringError> {
        check_shape(table, "fiber_averages", &["sin_theta", "quantity"], 3)?;
        let q = &table.axes()[1];
        if q.count != FIBER_AVERAGE_QUANTITY_COUNT {
            return Err(ForwardScatteringError::TableShape {
                table: "fiber_averages",
                problem: format!(
                    "quantity axis has {} nodes, expected {FIBER_AVERAGE_QUANTITY_COUNT}",
                    q.count
                ),
            });
        }
        Ok(Self { table: table.clone() })
    }

    /// The event at sin θ = u·ξ (clamped to [−1, 1]); attenuations clamped to [0, 1],
    /// variances to ≥ 0 (interpolation of non-negative nodes stays non-negative anyway).
    pub fn at(&self, sin_theta: f64) -> ForwardEvent {
        let s = finite_or(sin_theta, 0.0).clamp(-1.0, 1.0);
        let a = self.table.lookup_rgb(&[s, QUANTITY_A_F]).unwrap_or([0.0; 3]);
        let b = self.table.lookup_rgb(&[s, QUANTITY_BETA2_F]).unwrap_or([0.0; 3]);
        ForwardEvent {
            attenuation: a.map(|x| x.clamp(0.0, 1.0)),
            variance: b.map(|x| x.max(0.0)),
        }
    }
}

/// α(ν, θ) from the `attenuation_ratio` table.
#[derive(Clone, Debug)]
pub struct AttenuationRatio {
    table: Table,
}

impl AttenuationRatio {
    pub fn from_table(table: &Table) -> Result<Self, ForwardScatteringError> {
        check_shape(table, "attenuation_ratio", &["nu", "abs_sin_theta"], 1)?;
        Ok(Self { table: table.clone() })
    }

    /// Largest direction deviation ν tabulated (radians): voxel deviations are clamped to it.
    pub fn nu_max(&self) -> f64 {
        self.table.axes()[0].max
    }

    /// α(ν, θ) for sin θ = u·ξ (α is even in θ), ≥ 0.
    pub fn at(&self, nu: f64, sin_theta: f64) -> f32 {
        let s = finite_or(sin_theta, 0.0).abs().min(1.0);
        let nu = finite_or(nu, 0.0).max(0.0);
        self.table.lookup_scalar(&[nu, s]).unwrap_or(0.0).max(0.0)
    }
}

/// The SRBF first-event variance from the `srbf_spread` table.
#[derive(Clone, Debug)]
pub struct SrbfSpread {
    table: Table,
}

impl SrbfSpread {
    pub fn from_table(table: &Table) -> Result<Self, ForwardScatteringError> {
        check_shape(table, "srbf_spread", &["abs_u_dot_xi", "lambda"], 1)?;
        Ok(Self { table: table.clone() })
    }

    /// Variance (rad², incident inclination) of an SRBF of bandwidth λ seen by a fiber with
    /// u·ξ = `u_dot_xi`; λ outside the table clamps to its ends.
    pub fn variance(&self, u_dot_xi: f64, lambda: f64) -> f32 {
        let s = finite_or(u_dot_xi, 0.0).abs().min(1.0);
        let l = finite_or(lambda, self.table.axes()[1].max);
        self.table.lookup_scalar(&[s, l]).unwrap_or(0.0).max(0.0)
    }
}

/// The three tables the forward-scattering module reads, checked.
#[derive(Clone, Debug)]
pub struct ForwardScatteringTables {
    pub fiber_averages: ForwardFiberAverages,
    pub attenuation_ratio: AttenuationRatio,
    pub srbf_spread: SrbfSpread,
}

impl ForwardScatteringTables {
    /// From the baked `fiber_averages`, `attenuation_ratio` and `srbf_spread` tables.
    pub fn from_tables(
        fiber_averages: &Table,
        attenuation_ratio: &Table,
        srbf_spread: &Table,
    ) -> Result<Self, ForwardScatteringError> {
        Ok(Self {
            fiber_averages: ForwardFiberAverages::from_table(fiber_averages)?,
            attenuation_ratio: AttenuationRatio::from_table(attenuation_ratio)?,
            srbf_spread: SrbfSpread::from_table(srbf_spread)?,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use strandlight_tables::table::{Axis, AxisMapping};

    fn fiber_table(quantities: usize) -> Table {
        let axes = vec![
            Axis::with_mapping("sin_theta", -1.0, 1.0, 17, AxisMapping::Arcsine),
            Axis::uniform("quantity", 0.0, (quantities - 1) as f64, quantities),
        ];
        // Node q holds q + (0.1, 0.2, 0.3) scaled by cos θ: a_f = 0.1..0.3 cos θ, β² = 4.1.. cos θ.
        Table::from_fn(axes, 3, |x, out| {
            let c = (1.0 - x[0] * x[0]).max(0.0).sqrt();
            for (k, o) in out.iter_mut().enumerate() {
                *o = ((x[1] + 0.1 * (k + 1) as f64) * c) as f32;
            }
        })
        .unwrap()
    }

    #[test]
    fn fiber_averages_read_the_a_f_and_beta2_f_nodes() {
        let t = ForwardFiberAverages::from_table(&fiber_table(9)).unwrap();
        let e = t.at(0.0);
        println!("at θ=0: {e:?}");
        for c in 0..3 {
            assert!((e.attenuation[c] - 0.1 * (c + 1) as f32).abs() < 1e-6);
            assert!((e.variance[c] - (4.0 + 0.1 * (c + 1) as f32)).abs() < 1e-5);
        }
        // Out-of-range and NaN coordinates are clamped, not errors.
        assert!(t.at(f64::NAN).attenuation[0].is_finite());
        assert_eq!(t.at(3.0), t.at(1.0));
    }

    #[test]
    fn wrong_shapes_are_typed_errors() {
        let err = ForwardFiberAverages::from_table(&fiber_table(6)).unwrap_err();
        println!("{err}");
        assert!(matches!(err, ForwardScatteringError::TableShape { table: "fiber_averages", .. }));
        let wrong_axes = Table::from_fn(
            vec![Axis::uniform("lambda", 1.0, 2.0, 3), Axis::uniform("nu", 0.0, 1.0, 3)],
            1,
            |_, o| o[0] = 1.0,
        )
        .unwrap();
        let err = AttenuationRatio::from_table(&wrong_axes).unwrap_err();
        println!("{err}");
        assert!(err.to_string().contains("attenuation_ratio"));
        assert!(SrbfSpread::from_table(&fiber_table(9)).is_err());
    }
}
