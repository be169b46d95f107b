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

use std::f64::consts::FRAC_PI_2;

use strandlight_tables::table::Table;
use strandlight_tables::table_axes::{
    AXIS_ABS_SIN_THETA, AXIS_ABS_U_DOT_XI, AXIS_LAMBDA, AXIS_NU, AXIS_QUANTITY, AXIS_SIN_THETA,
};
use thiserror::Error;

/// Node of `beta2_f` and `a_f` on the `quantity` axis of `fiber_averages` (bake_plan's order).
const QUANTITY_A_F: f64 = 0.0;
const QUANTITY_BETA2_F: f64 = 4.0;
const FIBER_AVERAGE_QUANTITY_COUNT: usize = 9;

/// A table or setting the forward-scattering module cannot use.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum ForwardScatteringError {
    #[error("table `{table}`: {problem}")]
    TableShape {
        table: &'static str,
        problem: String,
    },
    #[error("forward-scattering setting `{parameter}` = {value}: {problem}")]
    InvalidSetting {
        parameter: &'static str,
        value: String,
        problem: String,
    },
    #[error(transparent)]
    Limit(#[from] crate::gpu::LimitError),
    #[error("the GPU march failed: {0}")]
    Gpu(String),
}

/// Checks axis names/counts and the channel count of a baked table.
fn check_shape(
    table: &Table,
    name: &'static str,
    axes: &[&str],
    channels: usize,
) -> Result<(), ForwardScatteringError> {
    let fail = |problem: String| {
        Err(ForwardScatteringError::TableShape {
            table: name,
            problem,
        })
    };
    let found: Vec<&str> = table.axes().iter().map(|a| a.name.as_str()).collect();
    if found != axes {
        return fail(format!("axes are {found:?}, expected {axes:?}"));
    }
    if table.channels() != channels {
        return fail(format!(
            "{} channels, expected {channels}",
            table.channels()
        ));
    }
    if let Some(a) = table.axes().iter().find(|a| a.count < 2) {
        return fail(format!(
            "axis `{}` has {} node(s), at least 2 are needed",
            a.name, a.count
        ));
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

/// Nodes per radian-uniform resampling: the march looks values up millions of times per
/// frame; a generic `Table` lookup (axis warps, error paths) costs ~0.2 µs, a lerp on a
/// uniform θ grid a few ns. 1025 nodes over 180° (0.18°, θ = 0 a node) are far finer than any baked axis,
/// so the resampled piecewise-linear curve differs from the table's own interpolation by a
/// fraction of one table cell's curvature (tested).
const THETA_NODES: usize = 1025;

/// Values sampled uniformly in θ ∈ [θ_min, θ_max], `C` per node, linearly interpolated.
#[derive(Clone, Debug)]
struct ThetaCurve<const C: usize> {
    theta_min: f64,
    step: f64,
    values: Vec<[f32; C]>,
}

impl<const C: usize> ThetaCurve<C> {
    fn sample(theta_min: f64, theta_max: f64, nodes: usize, f: impl Fn(f64) -> [f32; C]) -> Self {
        let step = (theta_max - theta_min) / (nodes - 1) as f64;
        let values = (0..nodes).map(|k| f(theta_min + step * k as f64)).collect();
        Self {
            theta_min,
            step,
            values,
        }
    }

    fn at(&self, theta: f64) -> [f32; C] {
        let last = self.values.len() - 1;
        let x = ((theta - self.theta_min) / self.step).clamp(0.0, last as f64);
        let x = if x.is_nan() { 0.0 } else { x };
        let i = (x as usize).min(last - 1);
        let t = (x - i as f64) as f32;
        let (a, b) = (self.values[i], self.values[i + 1]);
        std::array::from_fn(|c| a[c] + t * (b[c] - a[c]))
    }
}

/// ā_f(θ) and β̄_f²(θ) per channel, from the `fiber_averages` table (resampled in θ).
#[derive(Clone, Debug)]
pub struct ForwardFiberAverages {
    curve: ThetaCurve<6>,
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
        check_shape(table, "fiber_averages", &[AXIS_SIN_THETA, AXIS_QUANTITY], 3)?;
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
        let curve = ThetaCurve::sample(-FRAC_PI_2, FRAC_PI_2, THETA_NODES, |theta| {
            let s = theta.sin();
            let a = table.lookup_rgb(&[s, QUANTITY_A_F]).unwrap_or([0.0; 3]);
            let b = table.lookup_rgb(&[s, QUANTITY_BETA2_F]).unwrap_or([0.0; 3]);
            [
                a[0].clamp(0.0, 1.0),
                a[1].clamp(0.0, 1.0),
                a[2].clamp(0.0, 1.0),
                b[0].max(0.0),
                b[1].max(0.0),
                b[2].max(0.0),
            ]
        });
        Ok(Self { curve })
    }

    /// The event at sin θ = u·ξ (clamped to [−1, 1]); attenuations clamped to [0, 1],
    /// variances to ≥ 0.
    pub fn at(&self, sin_theta: f64) -> ForwardEvent {
        let theta = finite_or(sin_theta, 0.0).clamp(-1.0, 1.0).asin();
        let v = self.curve.at(theta);
        ForwardEvent {
            attenuation: [v[0], v[1], v[2]],
            variance: [v[3], v[4], v[5]],
        }
    }
}

/// Rows of the resampled α table along ν.
const NU_NODES: usize = 65;

/// α(ν, θ) from the `attenuation_ratio` table (resampled: `NU_NODES` rows uniform in ν,
/// each a θ curve over [0, π/2]).
#[derive(Clone, Debug)]
pub struct AttenuationRatio {
    nu_max: f64,
    rows: Vec<ThetaCurve<1>>,
}

impl AttenuationRatio {
    pub fn from_table(table: &Table) -> Result<Self, ForwardScatteringError> {
        check_shape(
            table,
            "attenuation_ratio",
            &[AXIS_NU, AXIS_ABS_SIN_THETA],
            1,
        )?;
        let (nu_min, nu_max) = (table.axes()[0].min, table.axes()[0].max);
        let rows = (0..NU_NODES)
            .map(|r| {
                let nu = nu_min + (nu_max - nu_min) * r as f64 / (NU_NODES - 1) as f64;
                ThetaCurve::sample(0.0, FRAC_PI_2, THETA_NODES / 2 + 1, |theta| {
                    [table
                        .lookup_scalar(&[nu, theta.sin()])
                        .unwrap_or(0.0)
                        .max(0.0)]
                })
            })
            .collect();
        Ok(Self { nu_max, rows })
    }

    /// Largest direction deviation ν tabulated (radians): voxel deviations are clamped to it.
    pub fn nu_max(&self) -> f64 {
        self.nu_max
    }

    /// α(ν, θ) for sin θ = u·ξ (α is even in θ), ≥ 0.
    pub fn at(&self, nu: f64, sin_theta: f64) -> f32 {
        let theta = finite_or(sin_theta, 0.0).abs().min(1.0).asin();
        let x = (finite_or(nu, 0.0) / self.nu_max).clamp(0.0, 1.0) * (NU_NODES - 1) as f64;
        let i = (x as usize).min(NU_NODES - 2);
        let t = (x - i as f64) as f32;
        let (a, b) = (self.rows[i].at(theta)[0], self.rows[i + 1].at(theta)[0]);
        a + t * (b - a)
    }
}

/// The SRBF first-event variance from the `srbf_spread` table.
#[derive(Clone, Debug)]
pub struct SrbfSpread {
    table: Table,
}

impl SrbfSpread {
    pub fn from_table(table: &Table) -> Result<Self, ForwardScatteringError> {
        check_shape(table, "srbf_spread", &[AXIS_ABS_U_DOT_XI, AXIS_LAMBDA], 1)?;
        Ok(Self {
            table: table.clone(),
        })
    }

    /// Variance (rad², incident inclination) of an SRBF of bandwidth λ seen by a fiber with
    /// u·ξ = `u_dot_xi`; λ outside the table clamps to its ends.
    pub fn variance(&self, u_dot_xi: f64, lambda: f64) -> f32 {
        let s = finite_or(u_dot_xi, 0.0).abs().min(1.0);
        let l = finite_or(lambda, self.table.axes()[1].max);
        self.table.lookup_scalar(&[s, l]).unwrap_or(0.0).max(0.0)
    }

    /// The variance for one bandwidth as a function of u·ξ, resampled in θ for the march's
    /// per-voxel lookups (see `THETA_NODES`).
    pub fn for_bandwidth(&self, lambda: f64) -> SrbfSpreadCurve {
        SrbfSpreadCurve {
            curve: ThetaCurve::sample(0.0, FRAC_PI_2, THETA_NODES / 2 + 1, |theta| {
                [self.variance(theta.sin(), lambda)]
            }),
        }
    }
}

/// [`SrbfSpread`] at one bandwidth.
#[derive(Clone, Debug)]
pub struct SrbfSpreadCurve {
    curve: ThetaCurve<1>,
}

impl SrbfSpreadCurve {
    pub fn variance(&self, u_dot_xi: f64) -> f32 {
        self.curve
            .at(finite_or(u_dot_xi, 0.0).abs().min(1.0).asin())[0]
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
            Axis::with_mapping(AXIS_SIN_THETA, -1.0, 1.0, 17, AxisMapping::Arcsine),
            Axis::uniform(AXIS_QUANTITY, 0.0, (quantities - 1) as f64, quantities),
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
    fn resampled_lookups_follow_the_tables() {
        // Tables with curvature everywhere; the resampled curves must track the tables' own
        // interpolation far below one table cell's error.
        let fiber = Table::from_fn(
            vec![
                Axis::with_mapping(AXIS_SIN_THETA, -1.0, 1.0, 64, AxisMapping::Arcsine),
                Axis::uniform(AXIS_QUANTITY, 0.0, 8.0, 9),
            ],
            3,
            |x, out| {
                let th = x[0].asin();
                for (c, o) in out.iter_mut().enumerate() {
                    *o = (0.5 + 0.4 * (3.0 * th + c as f64).sin() * (1.0 + x[1] * 0.1)) as f32;
                }
            },
        )
        .unwrap();
        let ratio = Table::from_fn(
            vec![
                Axis::uniform(AXIS_NU, 0.0, 1.0, 16),
                Axis::with_mapping(AXIS_ABS_SIN_THETA, 0.0, 1.0, 32, AxisMapping::Arcsine),
            ],
            1,
            |x, o| {
                o[0] = ((1.0 - x[1] * x[1]).sqrt() * (1.0 - 0.3 * x[0]) + 0.4 * x[0] * x[0]) as f32
            },
        )
        .unwrap();
        let (f, r) = (
            ForwardFiberAverages::from_table(&fiber).unwrap(),
            AttenuationRatio::from_table(&ratio).unwrap(),
        );
        let (mut worst_f, mut worst_r) = (0.0f32, 0.0f32);
        for k in 0..=2000 {
            let s = -1.0 + 2.0 * k as f64 / 2000.0;
            let want = fiber.lookup_rgb(&[s, 0.0]).unwrap();
            let got = f.at(s).attenuation;
            for c in 0..3 {
                worst_f = worst_f.max((got[c] - want[c].clamp(0.0, 1.0)).abs());
            }
            let nu = (k % 97) as f64 / 96.0;
            worst_r =
                worst_r.max((r.at(nu, s) - ratio.lookup_scalar(&[nu, s.abs()]).unwrap()).abs());
        }
        println!(
            "resampled vs table: fiber averages {worst_f:.2e}, attenuation ratio {worst_r:.2e}"
        );
        assert!(worst_f < 2e-4 && worst_r < 2e-3);
    }

    #[test]
    fn wrong_shapes_are_typed_errors() {
        let err = ForwardFiberAverages::from_table(&fiber_table(6)).unwrap_err();
        println!("{err}");
        assert!(matches!(
            err,
            ForwardScatteringError::TableShape {
                table: "fiber_averages",
                ..
            }
        ));
        let wrong_axes = Table::from_fn(
            vec![
                Axis::uniform(AXIS_LAMBDA, 1.0, 2.0, 3),
                Axis::uniform(AXIS_NU, 0.0, 1.0, 3),
            ],
            1,
            |_, o| o[0] = 1.0,
        )
        .unwrap();
        let err = AttenuationRatio::from_table(&wrong_axes).unwrap_err();
        println!("{err}");
        assert!(err.to_string().contains("attenuation_ratio"));
        let err = SrbfSpread::from_table(&fiber_table(9)).unwrap_err();
        assert!(
            matches!(
                err,
                ForwardScatteringError::TableShape {
                    table: "srbf_spread",
                    ..
                }
            ),
            "{err}"
        );
    }
}
