//! The JSON sidecar of an exported lookup texture: what the table holds, each axis's
//! parametrization, range and resolution, the texel-centre convention and the sampling formula,
//! so that an engine can sample the KTX2 file without this project's code.

use crate::table::{Axis, AxisGpu, AxisMapping};
use crate::table_axes::*;
use serde::{Deserialize, Serialize};
use serde_json::Value;

/// Names this sidecar's schema; bumped when a field changes meaning.
pub const SIDECAR_FORMAT: &str = "strandlight-lut-ktx2/1";

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LutSidecar {
    pub format: String,
    pub table: String,
    pub quantity: String,
    pub scattering_function: String,
    pub fiber_parameters: Value,
    pub source: SidecarSource,
    pub texture: SidecarTexture,
    pub axes: Vec<SidecarAxis>,
    pub texel_centre: String,
    /// The formula, step by step, from the table's coordinates to texture coordinates and the
    /// value.
    pub sampling: Vec<String>,
    pub wgsl: SidecarWgsl,
    /// Half-float rounding against the f32 table (absent for float exports).
    pub half_rounding: Option<HalfRounding>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SidecarSource {
    /// The `.sltab` file the texture was made from.
    pub file: String,
    /// SHA-256 of that file's payload, as its metadata records it.
    pub payload_sha256: String,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SidecarTexture {
    pub file: String,
    /// "2d" or "3d".
    pub dimension: String,
    pub width: usize,
    pub height: usize,
    /// 0 for a 2D texture.
    pub depth: usize,
    pub vk_format: String,
    pub vk_format_value: u32,
    pub webgpu_format: String,
    /// What each texel component holds.
    pub components: Vec<String>,
    pub layout: String,
    pub sampler: String,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SidecarAxis {
    /// Axis number in the table (coordinate order of the sampling function).
    pub table_axis: usize,
    pub name: String,
    pub meaning: String,
    pub min: f64,
    pub max: f64,
    pub count: usize,
    pub mapping: AxisMapping,
    /// Coordinate of node i, i = 0 … count − 1.
    pub node_formula: String,
    /// Where the axis goes in the texture.
    pub texture_axis: String,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SidecarWgsl {
    pub file: String,
    /// The hardware-filtered sampling function (needs a filterable format).
    pub function: String,
    /// The same lookup from textureLoads, exact in f32 and for any float format.
    pub exact_function: String,
    /// The four `StrandLutAxis` values of this table's `StrandLut` uniform, in order (one-node
    /// axes fill the places of missing ones).
    pub uniform: Vec<SidecarGpuAxis>,
}

/// One `StrandLutAxis` of the WGSL file.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SidecarGpuAxis {
    pub min: f32,
    pub inv_range: f32,
    pub last_index: f32,
    pub inv_exponent: f32,
    pub warp: u32,
}

impl From<AxisGpu> for SidecarGpuAxis {
    fn from(g: AxisGpu) -> Self {
        Self {
            min: g.min,
            inv_range: g.inv_range,
            last_index: g.last_index,
            inv_exponent: g.inv_exponent,
            warp: g.warp,
        }
    }
}

impl SidecarGpuAxis {
    /// The place of a missing axis: one node, position 0 whatever the coordinate.
    pub const ONE_NODE: Self = Self {
        min: 0.0,
        inv_range: 0.0,
        last_index: 0.0,
        inv_exponent: 1.0,
        warp: 0,
    };
}

#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct HalfRounding {
    /// Largest |half − f32| / |f32| over values ≥ 1% of the table's largest |value|.
    pub max_relative_error: f64,
    /// Largest |half − f32| over all values, relative to the table's largest |value|.
    pub max_error_of_table_max: f64,
}

/// What a named axis measures (the names are those of [`crate::table_axes`]).
pub fn axis_meaning(name: &str) -> &'static str {
    match name {
        AXIS_U_DOT_XI => {
            "u·ξ: sine of the inclination of the light's centre direction ξ from the fiber's normal plane (u the fiber tangent, root to tip)"
        }
        AXIS_U_DOT_WO => "u·ω_o: sine of the inclination of the view direction ω_o",
        AXIS_COS_DPHI => {
            "cos(φ_ξ − φ_o): cosine of the azimuth between ξ and ω_o projected on the fiber's normal plane"
        }
        AXIS_INV_LAMBDA => {
            "1/λ: inverse bandwidth of the SRBF G(ω) = exp(λ(ω·ξ − 1)); a single node at 0 for directional lights"
        }
        AXIS_SIGMA_F => {
            "σ̄_f (radians): longitudinal spread of forward scattering (Ren 2010 eq. 11)"
        }
        AXIS_NU => "ν (radians): direction deviation of the fibers in a voxel",
        AXIS_ABS_SIN_THETA => "|sin θ|: light inclination from the voxel's mean fiber direction",
        AXIS_ABS_U_DOT_XI => "|u·ξ|: an SRBF centre's inclination (the table is even in u·ξ)",
        AXIS_LAMBDA => "λ: SRBF bandwidth",
        AXIS_SIN_THETA => "sin θ: inclination",
        AXIS_QUANTITY => "index of the quantity stored (one node each; see the table's quantity)",
        AXIS_SIN_THETA_I => "sin θ_i: the light's inclination",
        AXIS_SIN_THETA_O => "sin θ_o: the view's inclination",
        AXIS_COS_PHI => "cos φ, φ = φ_o − φ_i ∈ [0, π]",
        AXIS_COS_HALF_PHI => "cos(φ/2)",
        AXIS_COS_THETA_D => "cos θ_d, θ_d = (θ_o − θ_i)/2",
        AXIS_LOBE => "lobe index 0, 1, 2 (R, TT, TRT)",
        _ => "",
    }
}

/// The coordinate of node i, as a formula of the axis's range and count.
pub fn node_formula(axis: &Axis) -> String {
    let (a, b, n) = (axis.min, axis.max, axis.count);
    if n <= 1 {
        return format!("x_0 = {a}");
    }
    match axis.mapping {
        AxisMapping::Uniform => format!("x_i = {a} + ({b} − {a})·i/{}", n - 1),
        AxisMapping::Power { exponent } => {
            format!("x_i = {a} + ({b} − {a})·(i/{})^{exponent}", n - 1)
        }
        AxisMapping::Arcsine => {
            format!("x_i = sin(asin({a}) + (asin({b}) − asin({a}))·i/{})", n - 1)
        }
        AxisMapping::Arccosine => {
            format!("x_i = cos(acos({a}) − (acos({a}) − acos({b}))·i/{})", n - 1)
        }
    }
}

/// The sampling formula for a table of `axes` axes.
pub fn sampling_steps(axes: usize) -> Vec<String> {
    let mut steps = vec![
        "For each axis k, the node position f_k ∈ [0, n_k − 1] of coordinate x_k: w = x (uniform, power), asin(clamp(x, −1, 1)) (arcsine) or −acos(clamp(x, −1, 1)) (arccosine); t = clamp((w − w(min)) / (w(max) − w(min)), 0, 1); t = t^(1/exponent) for a power axis; f_k = t·(n_k − 1). A one-node axis has f_k = 0. (WGSL: strandlight_lut_position with the uniform's values.)".to_string(),
        "Texel centres: node i of an axis with n texels is the centre of texel i, at normalized coordinate (i + 0.5)/n; with linear filtering and clamp-to-edge, sampling at (f + 0.5)/n interpolates nodes floor(f) and floor(f) + 1 with weight f − floor(f), exactly as the CPU's multilinear lookup.".to_string(),
    ];
    steps.push(match axes {
        1 => "u = (f_0 + 0.5)/n_0, v = 0.5; value = sample(u, v).".into(),
        2 => "u = (f_1 + 0.5)/n_1, v = (f_0 + 0.5)/n_0; value = sample(u, v).".into(),
        3 => "u = (f_2 + 0.5)/n_2, v = (f_1 + 0.5)/n_1, w = (f_0 + 0.5)/n_0; value = sample(u, v, w) (trilinear).".into(),
        _ => "Fourth axis (done in the shader, not by the hardware): s = min(floor(f_3), max(n_3 − 2, 0)), a = f_3 − s. u = (f_2 + 0.5)/n_2, v = (f_1 + 0.5)/n_1, w_s = (s·n_0 + f_0 + 0.5)/(n_0·n_3); value = (1 − a)·sample(u, v, w_s) + a·sample(u, v, w_{s+1}) (two trilinear samples, one per slab; skip the second when a = 0). Because 0 ≤ f_0 ≤ n_0 − 1, the trilinear sample never mixes two slabs.".into(),
    });
    steps
}
