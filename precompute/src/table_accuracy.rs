//! Accuracy of a convolution table: lookups at random off-grid points against direct f64
//! integration of Ren 2010 eq. 8 ([`convolve_reference`]), stratified so that grazing angles,
//! narrow lobes and the TT region are all hit.

use crate::convolution::convolve_reference;
use rayon::prelude::*;
use serde::Serialize;
use std::f64::consts::PI;
use strandlight_tables::angles::FiberAngles;
use strandlight_tables::hard_case_sweep::SweepRng;
use strandlight_tables::scattering::Rgb;
use strandlight_tables::table::{Table, TableError};

/// What `check-tables --json` reports per table.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct TableAccuracy {
    pub name: String,
    /// max |table − reference| over points and channels, relative to the table's maximum.
    pub max_abs_error: f64,
    /// RMS of the same.
    pub rms_abs_error: f64,
    /// max |table − reference| / reference over the points whose reference exceeds
    /// [`relative_error_floor`] (1% of the smaller of the table's maximum and its 99.9th
    /// percentile), 0 when none does: see `rel_samples`.
    pub max_rel_error: f64,
    /// How many points the relative error was taken over.
    pub rel_samples: usize,
    pub samples: usize,
    /// The worst point, as (u·ξ, u·ω_o, cos Δφ, 1/λ).
    pub worst_point: [f64; 4],
    /// The same two errors over the points off the fiber axis (|u·ξ|, |u·ω_o| < 0.999; see
    /// [`is_axial`]), and how many there were.
    pub off_axis_max_abs_error: f64,
    pub off_axis_rms_abs_error: f64,
    pub off_axis_samples: usize,
    /// max |value| of the table, the scale of the errors above.
    pub table_max: f64,
    /// The 99.9th percentile of |value|; where a corner singularity of the model makes the
    /// maximum unrepresentative (I_G at u·ξ = −u·ω_o = ±1), errors relative to it say more.
    pub table_p999: f64,
    /// `max_abs_error` and `rms_abs_error` rescaled to the 99.9th percentile.
    pub max_abs_error_p999: f64,
    pub rms_abs_error_p999: f64,
}

/// The reference value below which a point's relative error is not taken: 1% of the table's
/// scale, the smaller of its maximum and its 99.9th percentile. A corner singularity (I_G: a
/// maximum of 81.8 against a 99.9th percentile of 2.7) would otherwise put every sampled point
/// below 1% of the maximum, leaving a relative error of 0 that measured nothing.
pub fn relative_error_floor(table: &Table) -> f64 {
    let max = table.stats().max.abs().max(table.stats().min.abs()) as f64;
    0.01 * max.min(percentile_999(table.values()))
}

/// The 99.9th percentile of |v| over a table's values.
pub fn percentile_999(values: &[f32]) -> f64 {
    if values.is_empty() {
        return 0.0;
    }
    let mut a: Vec<f32> = values.iter().map(|v| v.abs()).collect();
    let k = ((a.len() - 1) as f64 * 0.999).round() as usize;
    let (_, v, _) = a.select_nth_unstable_by(k, f32::total_cmp);
    *v as f64
}

impl TableAccuracy {
    /// Fills the percentile-relative fields from the max-relative ones.
    pub fn with_percentile(mut self, table: &Table) -> Self {
        self.table_p999 = percentile_999(table.values());
        let ratio = if self.table_p999 > 0.0 {
            self.table_max / self.table_p999
        } else {
            1.0
        };
        self.max_abs_error_p999 = self.max_abs_error * ratio;
        self.rms_abs_error_p999 = self.rms_abs_error * ratio;
        self
    }
}

/// A deterministic stratified point set over the table's domain, 10% of it on the domain's
/// hard edges (u·ξ or u·ω_o = ±1, λ at a bound): u·ξ and u·ω_o stratified in
/// the sine (so grazing ±1 ends get their share), Δφ stratified in angle (so the TT region near
/// π is sampled as densely as the rest), 1/λ uniform. `lambda` spans [λ_min, λ_max].
pub fn stratified_points(
    count: usize,
    lambda_min: f64,
    lambda_max: f64,
    seed: u64,
) -> Vec<[f64; 4]> {
    // A fixed generator: the points must not change with thread count or a crate's version.
    let mut rng = SweepRng::new(seed);
    (0..count)
        .map(|k| {
            let stratum = (k as f64 + rng.uniform()) / count as f64;
            let mut sx = -1.0 + 2.0 * rng.uniform();
            let mut so = -1.0 + 2.0 * rng.uniform();
            // Cycle strata over the Δφ axis, the one whose lobes are narrowest.
            let delta = PI * stratum;
            let mut inv = 1.0 / lambda_max + (1.0 / lambda_min - 1.0 / lambda_max) * rng.uniform();
            // One point in ten sits on a hard edge of the domain: ξ or ω_o along the fiber
            // (u·ξ, u·ω_o = ±1) or λ at either bound.
            let sign = if k % 20 < 10 { 1.0 } else { -1.0 };
            match k % 10 {
                0 => sx = sign,
                1 => so = sign,
                2 => inv = 1.0 / lambda_max,
                3 => inv = 1.0 / lambda_min,
                _ => {}
            }
            [sx, so, delta.cos(), inv]
        })
        .collect()
}

/// One checked point: the point, its largest error, and the relative error where the
/// reference is large enough to divide by.
type CheckedPoint = ([f64; 4], f64, Option<f64>);

/// Compares `table` with the reference integral of `s` at `points`.
pub fn check_table<F>(
    name: &str,
    table: &Table,
    s: &F,
    points: &[[f64; 4]],
    reference_panels: usize,
) -> Result<TableAccuracy, TableError>
where
    F: Fn(&FiberAngles) -> Rgb + Sync,
{
    let table_max = table.stats().max as f64;
    let floor = relative_error_floor(table);
    let rows: Vec<Result<CheckedPoint, TableError>> = points
        .par_iter()
        .map(|p| {
            let looked = table.lookup_rgb(p)?;
            let (theta_xi, theta_o) = (p[0].clamp(-1.0, 1.0).asin(), p[1].clamp(-1.0, 1.0).asin());
            let reference = convolve_reference(
                s,
                theta_xi,
                theta_o,
                p[2].clamp(-1.0, 1.0).acos(),
                1.0 / p[3],
                reference_panels,
            );
            let mut abs: f64 = 0.0;
            let mut rel: Option<f64> = None;
            for c in 0..3 {
                let e = (looked[c] as f64 - reference[c]).abs();
                abs = abs.max(e);
                if reference[c] > floor {
                    rel = Some(rel.unwrap_or(0.0).max(e / reference[c]));
                }
            }
            Ok((*p, abs, rel))
        })
        .collect();
    let rows = rows
        .into_iter()
        .map(|r| r.map(|(p, abs, rel)| (p.to_vec(), abs, rel)))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(summarize(name, table, table_max, &rows, true))
}

/// Points where ξ or ω_o lies within ~2.6° of the fiber axis (|u·ξ| or |u·ω_o| ≥ 0.999): there
/// the model's 1/cos²θ_d makes eq. 8 nearly singular (it diverges logarithmically at ±1), while
/// a fiber seen or lit along its axis has (nearly) no projected width and adds ~nothing to an
/// image. Errors are reported with and without them.
pub fn is_axial(p: &[f64]) -> bool {
    p.len() >= 2 && (p[0].abs() >= AXIAL || p[1].abs() >= AXIAL)
}

const AXIAL: f64 = 0.999;

/// Folds per-point errors (point, max |Δ| over channels, max relative |Δ|) into the report;
/// `directional` says the first two axes are u·ξ and u·ω_o (so axial points can be told apart).
pub fn summarize(
    name: &str,
    table: &Table,
    table_max: f64,
    rows: &[(Vec<f64>, f64, Option<f64>)],
    directional: bool,
) -> TableAccuracy {
    let scale = if table_max > 0.0 { table_max } else { 1.0 };
    let (mut max_abs, mut sum_sq, mut max_rel) = (0.0f64, 0.0, 0.0f64);
    let rel_samples = rows.iter().filter(|r| r.2.is_some()).count();
    let (mut inner_max, mut inner_sq, mut inner_n) = (0.0f64, 0.0, 0usize);
    let mut worst = [0.0; 4];
    for (p, abs, rel) in rows {
        if *abs > max_abs {
            max_abs = *abs;
            worst = [0.0; 4];
            worst.iter_mut().zip(p).for_each(|(w, v)| *w = *v);
        }
        sum_sq += abs * abs;
        max_rel = max_rel.max(rel.unwrap_or(0.0));
        if !(directional && is_axial(p)) {
            inner_max = inner_max.max(*abs);
            inner_sq += abs * abs;
            inner_n += 1;
        }
    }
    TableAccuracy {
        name: name.to_string(),
        max_abs_error: max_abs / scale,
        rms_abs_error: (sum_sq / rows.len().max(1) as f64).sqrt() / scale,
        max_rel_error: max_rel,
        rel_samples,
        samples: rows.len(),
        worst_point: worst,
        off_axis_max_abs_error: inner_max / scale,
        off_axis_rms_abs_error: (inner_sq / inner_n.max(1) as f64).sqrt() / scale,
        off_axis_samples: inner_n,
        table_max: scale,
        table_p999: 0.0,
        max_abs_error_p999: 0.0,
        rms_abs_error_p999: 0.0,
    }
    .with_percentile(table)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::convolution::ConvolutionSettings;
    use crate::convolution_table::{ConvolutionResolution, bake_convolution_table};

    /// A lobe model with Marschner's shape: a Gaussian in θ_h and a peaked azimuthal term.
    /// Its 1/cos²θ_d is softened: the true one makes eq. 8 diverge logarithmically at
    /// u·ω_o = ±1 (θ_d → ±π/2 as θ_i → ∓π/2), which would test the singularity, not the table.
    fn lobe(a: &FiberAngles) -> Rgb {
        let m = (-(a.theta_h() + 0.05).powi(2) / (2.0 * 0.13f64.powi(2))).exp();
        let n_r = (a.phi / 2.0).cos().abs();
        let n_tt = (-(PI - a.phi.abs()).powi(2) / (2.0 * 0.3f64.powi(2))).exp();
        let d = a.theta_d().cos().powi(2) + 0.05;
        [m * n_r / d, m * (n_r + 2.0 * n_tt) / d, m * n_tt / d]
    }

    #[test]
    fn error_shrinks_with_resolution_and_is_measured_against_the_reference() {
        let settings = ConvolutionSettings {
            theta_panels: 48,
            phi_panels: 16,
            max_harmonic: None,
        };
        let points = stratified_points(60, 16.0, 64.0, 7);
        let mut previous = f64::INFINITY;
        for n in [8usize, 16] {
            let res = ConvolutionResolution {
                u_dot_xi: n,
                u_dot_wo: n,
                cos_dphi: n,
                inv_lambda: n,
                ..Default::default()
            };
            let table = bake_convolution_table(&lobe, &res, &settings).unwrap();
            let acc = check_table("lobe", &table, &lobe, &points, 24).unwrap();
            println!(
                "{n}^4 nodes: max {:.3e}, rms {:.3e}, max rel {:.3e}",
                acc.max_abs_error, acc.rms_abs_error, acc.max_rel_error
            );
            assert!(
                acc.rms_abs_error < previous,
                "error must fall as the table grows"
            );
            previous = acc.rms_abs_error;
        }
        // Interpolation error of a smooth 4D function falls ~4× per doubling; demand at least 2×
        // and that 16^4 is already at the percent level.
        assert!(previous < 0.02, "rms at 16^4 = {previous}");
    }

    #[test]
    fn at_nodes_the_table_is_the_reference() {
        let settings = ConvolutionSettings {
            theta_panels: 48,
            phi_panels: 16,
            max_harmonic: None,
        };
        let res = ConvolutionResolution {
            u_dot_xi: 5,
            u_dot_wo: 4,
            cos_dphi: 6,
            inv_lambda: 3,
            ..Default::default()
        };
        let table = bake_convolution_table(&lobe, &res, &settings).unwrap();
        let axes = res.axes();
        let points: Vec<[f64; 4]> = vec![
            [
                axes[0].node(1),
                axes[1].node(2),
                axes[2].node(0),
                axes[3].node(2),
            ],
            [
                axes[0].node(4),
                axes[1].node(0),
                axes[2].node(5),
                axes[3].node(0),
            ],
            [
                axes[0].node(2),
                axes[1].node(3),
                axes[2].node(3),
                axes[3].node(1),
            ],
        ];
        let acc = check_table("lobe", &table, &lobe, &points, 48).unwrap();
        println!(
            "at nodes: max {:.3e} of the table maximum",
            acc.max_abs_error
        );
        // Only f32 storage and the reference's own ~1e-8 error remain.
        assert!(acc.max_abs_error < 1e-6);
    }
}
