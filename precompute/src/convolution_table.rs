//! Convolution tables I(u·ξ, u·ω_o, cos(φ_ξ − φ_o), 1/λ) (Ren 2010 §4) as [`Table`]s: the axis
//! layout the runtime indexes, and the filling of every node by [`convolve_grid`].

use crate::convolution::{ConvolutionGrid, ConvolutionSettings, convolve_grid};
use serde::{Deserialize, Serialize};
use strandlight_tables::angles::FiberAngles;
use strandlight_tables::scattering::Rgb;
use strandlight_tables::table::{Axis, AxisMapping, Table, TableError};
use strandlight_tables::table_axes::{
    AXIS_COS_DPHI, AXIS_INV_LAMBDA, AXIS_U_DOT_WO, AXIS_U_DOT_XI,
};

/// Node counts and ranges of a 4D convolution table.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ConvolutionResolution {
    pub u_dot_xi: usize,
    pub u_dot_wo: usize,
    pub cos_dphi: usize,
    pub inv_lambda: usize,
    /// How the direction axes spread their nodes: the paper's uniform steps in u·ξ, u·ω_o and
    /// cos Δφ, or steps uniform in the angles (denser at grazing angles and near the TT lobe).
    pub axes: DirectionAxes,
    /// The SRBF bandwidths the table spans.
    pub lambda_min: f64,
    pub lambda_max: f64,
}

impl Default for ConvolutionResolution {
    /// The paper's sample counts (Ren 2010 §7) and λ bounds.
    fn default() -> Self {
        Self {
            u_dot_xi: 32,
            u_dot_wo: 32,
            cos_dphi: 32,
            inv_lambda: 64,
            axes: DirectionAxes::Uniform,
            lambda_min: 16.0,
            lambda_max: 64.0,
        }
    }
}

/// Node placement of the three direction axes of a 4D table.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum DirectionAxes {
    /// Ren 2010: uniform in u·ξ, u·ω_o and cos Δφ.
    #[default]
    Uniform,
    /// Uniform in θ_ξ, θ_o and Δφ (arcsine/arccosine mappings; one asin/acos per lookup).
    Angular,
}

impl DirectionAxes {
    /// The three direction axes (u·ξ, u·ω_o, cos Δφ) with these counts.
    pub fn build(self, n_xi: usize, n_o: usize, n_phi: usize) -> [Axis; 3] {
        let (sine, cosine) = match self {
            DirectionAxes::Uniform => (AxisMapping::Uniform, AxisMapping::Uniform),
            DirectionAxes::Angular => (AxisMapping::Arcsine, AxisMapping::Arccosine),
        };
        [
            Axis::with_mapping(AXIS_U_DOT_XI, -1.0, 1.0, n_xi, sine),
            Axis::with_mapping(AXIS_U_DOT_WO, -1.0, 1.0, n_o, sine),
            Axis::with_mapping(AXIS_COS_DPHI, -1.0, 1.0, n_phi, cosine),
        ]
    }
}

impl ConvolutionResolution {
    pub fn axes(&self) -> Vec<Axis> {
        let [xi, wo, cos_dphi] = self.axes.build(self.u_dot_xi, self.u_dot_wo, self.cos_dphi);
        vec![
            xi,
            wo,
            cos_dphi,
            Axis::uniform(
                AXIS_INV_LAMBDA,
                1.0 / self.lambda_max,
                1.0 / self.lambda_min,
                self.inv_lambda,
            ),
        ]
    }

    /// The grid of the convolution engine at this table's nodes.
    pub fn grid(&self) -> ConvolutionGrid {
        let axes = self.axes();
        let nodes = |a: &Axis| (0..a.count).map(|i| a.node(i)).collect::<Vec<f64>>();
        ConvolutionGrid {
            sin_theta_xi: nodes(&axes[0]),
            sin_theta_o: nodes(&axes[1]),
            cos_delta_phi: nodes(&axes[2]),
            lambda: nodes(&axes[3]).into_iter().map(|inv| 1.0 / inv).collect(),
        }
    }
}

/// Tabulates ∫ G(ω_i; ξ, λ) S(ω_i, ω_o) cos θ_i dω_i for RGB `s` at every node.
pub fn bake_convolution_table<F>(
    s: &F,
    resolution: &ConvolutionResolution,
    settings: &ConvolutionSettings,
) -> Result<Table, TableError>
where
    F: Fn(&FiberAngles) -> Rgb + Sync,
{
    let values = convolve_grid(s, &resolution.grid(), settings);
    let flat = values.iter().flat_map(|v| v.map(|x| x as f32)).collect();
    Table::new(resolution.axes(), 3, flat)
}

/// The table coordinates of an SRBF center ξ and view direction ω_o around tangent `u`.
pub fn table_coordinates(theta_xi: f64, theta_o: f64, delta_phi: f64, lambda: f64) -> [f64; 4] {
    [theta_xi.sin(), theta_o.sin(), delta_phi.cos(), 1.0 / lambda]
}
