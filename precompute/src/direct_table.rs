//! Direct tables: S(ω_i, ω_o)·cos θ_i of a fiber model for a directional light, on the same
//! axes as the convolution tables (u·ξ, u·ω_o, cos(φ_ξ − φ_o)) with ξ = ω_i, plus a fourth
//! `inv_lambda` axis of ONE node at 1/λ = 0 (a directional light is the λ → ∞ limit of an
//! SRBF). A renderer's 4-axis convolution lookup therefore reads them unchanged; they shade
//! the brute-force reference and the median-cut baseline (Ren 2010 §8) as
//! `L_o = D · irradiance · table(u·ω_i, u·ω_o, cos Δφ, 0)`.

use crate::convolution_table::DirectionAxes;
use serde::{Deserialize, Serialize};
use strandlight_tables::angles::FiberAngles;
use strandlight_tables::scattering::Rgb;
use strandlight_tables::table::{Axis, Table, TableError};
use strandlight_tables::table_axes::AXIS_INV_LAMBDA;

/// Node counts of a direct table (the 1/λ axis always has one node).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct DirectResolution {
    pub u_dot_xi: usize,
    pub u_dot_wo: usize,
    pub cos_dphi: usize,
    pub axes: DirectionAxes,
}

impl DirectResolution {
    pub fn cube(n: usize, axes: DirectionAxes) -> Self {
        Self {
            u_dot_xi: n,
            u_dot_wo: n,
            cos_dphi: n,
            axes,
        }
    }

    /// The three direction axes of [`DirectionAxes::build`] and a one-node `inv_lambda` at 0.
    pub fn axes(&self) -> Vec<Axis> {
        let [xi, wo, dphi] = self.axes.build(self.u_dot_xi, self.u_dot_wo, self.cos_dphi);
        vec![xi, wo, dphi, Axis::uniform(AXIS_INV_LAMBDA, 0.0, 0.0, 1)]
    }
}

/// S·cos θ_i at table coordinates (u·ω_i, u·ω_o, cos Δφ), in f64: the table's definition and
/// the reference `check-tables` compares it with. Coordinates are clamped to [−1, 1]. At
/// u·ω_i = ±1 (cos θ_i = 0) the value is 0 without evaluating the model, which may have its
/// 1/cos²θ_d pole there (u·ω_o = ∓1): a fiber lit along its axis receives no light.
pub fn direct_value<F>(s: &F, coords: &[f64]) -> Rgb
where
    F: Fn(&FiberAngles) -> Rgb + ?Sized,
{
    let theta_i = coords[0].clamp(-1.0, 1.0).asin();
    let theta_o = coords[1].clamp(-1.0, 1.0).asin();
    let phi = coords[2].clamp(-1.0, 1.0).acos();
    // cos(asin(x)) = √(1 − x²), exactly 0 at x = ±1 (asin then cos would leave 6e-17).
    let cos_theta_i = (1.0 - coords[0].clamp(-1.0, 1.0).powi(2)).sqrt();
    if cos_theta_i == 0.0 {
        return [0.0; 3];
    }
    s(&FiberAngles::new(theta_i, theta_o, phi)).map(|c| c * cos_theta_i)
}

/// Tabulates [`direct_value`] of `s` at every node (in parallel).
pub fn bake_direct_table<F>(s: &F, resolution: &DirectResolution) -> Result<Table, TableError>
where
    F: Fn(&FiberAngles) -> Rgb + Sync,
{
    Table::from_fn(resolution.axes(), 3, |x, out| {
        let v = direct_value(s, x);
        for c in 0..3 {
            out[c] = v[c] as f32;
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::convolution_table::ConvolutionResolution;
    use strandlight_tables::table_axes::{AXIS_COS_DPHI, AXIS_U_DOT_WO, AXIS_U_DOT_XI};

    /// A smooth stand-in model: a Gaussian in θ_h times (1 + cos φ).
    fn model(a: &FiberAngles) -> Rgb {
        let m = (-(a.theta_h()).powi(2) / 0.3).exp();
        [m * (1.0 + a.phi.cos()), m, 2.0 * m]
    }

    #[test]
    fn axes_match_the_convolution_tables_and_the_lambda_axis_has_one_node() {
        for axes in [DirectionAxes::Uniform, DirectionAxes::Angular] {
            let d = DirectResolution::cube(7, axes).axes();
            let c = ConvolutionResolution {
                u_dot_xi: 7,
                u_dot_wo: 7,
                cos_dphi: 7,
                axes,
                ..Default::default()
            }
            .axes();
            for k in 0..3 {
                assert_eq!(d[k], c[k]);
            }
            assert_eq!(
                [
                    d[0].name.as_str(),
                    d[1].name.as_str(),
                    d[2].name.as_str(),
                    d[3].name.as_str()
                ],
                [
                    AXIS_U_DOT_XI,
                    AXIS_U_DOT_WO,
                    AXIS_COS_DPHI,
                    c[3].name.as_str()
                ]
            );
            assert_eq!(d[3].count, 1);
        }
    }

    #[test]
    fn a_four_axis_lookup_at_any_inv_lambda_reads_the_three_axis_interpolation() {
        let table =
            bake_direct_table(&model, &DirectResolution::cube(9, DirectionAxes::Angular)).unwrap();
        let axes = table.axes().to_vec();
        // At a node the table is the model·cos θ_i computed independently here.
        let (i, j, k) = (3, 5, 2);
        let x = [axes[0].node(i), axes[1].node(j), axes[2].node(k)];
        let cos_ti = (1.0 - x[0] * x[0]).sqrt();
        let want = model(&FiberAngles::new(x[0].asin(), x[1].asin(), x[2].acos()))[0] * cos_ti;
        for inv in [0.0, 0.03, 1.0] {
            let got = table.lookup_rgb(&[x[0], x[1], x[2], inv]).unwrap()[0] as f64;
            assert!(
                (got - want).abs() < 1e-6 * want.abs().max(1.0),
                "{got} vs {want}"
            );
        }
        // Halfway between two nodes of the first axis: the mean of the two node values.
        let mid = 0.5 * (axes[0].node(i) + axes[0].node(i + 1));
        let f = |s: f64| table.lookup_rgb(&[s, x[1], x[2], 0.0]).unwrap()[1] as f64;
        let position = axes[0].position(mid).unwrap();
        let t = position - i as f64;
        let lin = (1.0 - t) * f(axes[0].node(i)) + t * f(axes[0].node(i + 1));
        assert!((f(mid) - lin).abs() < 1e-6, "{} vs {lin}", f(mid));
    }

    #[test]
    fn grazing_nodes_are_zero_not_nan() {
        let pole = |_: &FiberAngles| [f64::INFINITY; 3];
        assert_eq!(direct_value(&pole, &[1.0, -1.0, 1.0]), [0.0; 3]);
        assert_eq!(direct_value(&pole, &[-1.0, 1.0, -0.3]), [0.0; 3]);
        // Elsewhere a bad model value is passed on (the bake refuses non-finite tables).
        assert!(direct_value(&pole, &[0.2, -1.0, 1.0])[0].is_infinite());
    }
}
