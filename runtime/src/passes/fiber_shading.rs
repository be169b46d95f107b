//! The fiber scattering model the strand pass shades with, and its GPU resources (bind group 2 of
//! the strand pipeline).
//!
//! * [`ShadingModel::KajiyaKay`] — the constants of [`FrameParams::shading`](super::frame_params::FrameParams).
//! * [`ShadingModel::MarschnerLut`] — Marschner through the two point-light lookup tables of
//!   Hunz 2016 Algorithm 2, baked elsewhere (`strandlight_precompute::point_light_luts`; the
//!   runtime never links tabulation code) and uploaded as-is.
//! * [`ShadingModel::ChiangLut`] — Chiang et al. 2016 through the same kind of table pair
//!   (`S·cos θ_i = Σ_p M_p(sin θ_i, sin θ_o) N̄_p(cos φ, sin θ_o)`, four lobes with the residual).
//! * [`ShadingModel::Artist`] — Sadeghi et al. 2010 in closed form.
//!
//! Every model returns, per light, `E · S · cos θ_i` (Kajiya-Kay: `E · KK`, whose diffuse
//! `sin(t, l)` is the same cos θ_i), E being the light's irradiance at the fiber
//! (`Light::intensity` for a directional light, `intensity / d²` for point and spot lights).

use strandlight_tables::artist::ArtistModel;
use strandlight_tables::table::{AxisGpu, Table};
use strandlight_tables::table_axes::{
    AXIS_COS_HALF_PHI, AXIS_COS_PHI, AXIS_COS_THETA_D, AXIS_LOBE, AXIS_QUANTITY, AXIS_SIN_THETA_I,
    AXIS_SIN_THETA_O,
};
use wgpu::util::DeviceExt;

use crate::gpu::GpuContext;
use crate::gpu::bind_layout::{bind_group, storage_entry, uniform_entry};
use crate::shaders::Wgsl;

/// `cos²θ_d` floor of the Marschner division (`strandlight_tables::marschner::MIN_COS2_THETA_D`).
pub const MIN_COS2_THETA_D: f32 = 1e-8;
/// `|cos θ_d|` floor of the artist model (`strandlight_tables::dual_scattering::MIN_COS_THETA_D`).
pub const MIN_COS_THETA_D: f32 = 1e-4;

/// How the strand pass shades a fiber.
// Built once per pass, never in a hot loop: the variants' size difference does not matter.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug, Default)]
pub enum ShadingModel {
    #[default]
    KajiyaKay,
    MarschnerLut(MarschnerLuts),
    ChiangLut(ChiangLuts),
    Artist(ArtistModel),
}

impl ShadingModel {
    pub fn name(&self) -> &'static str {
        match self {
            ShadingModel::KajiyaKay => "kajiya-kay",
            ShadingModel::MarschnerLut(_) => "marschner (lookup tables)",
            ShadingModel::ChiangLut(_) => "chiang (lookup tables)",
            ShadingModel::Artist(_) => "artist",
        }
    }

    /// The WGSL that defines `fiber_radiance`, composed as
    /// [`FIBER_MODEL`](crate::shaders::FIBER_MODEL) into the strand shading passes.
    pub(crate) fn wgsl(&self) -> Wgsl {
        let (file, source) = match self {
            ShadingModel::KajiyaKay => (
                "fiber_kajiya_kay.wgsl",
                include_str!("fiber_kajiya_kay.wgsl"),
            ),
            ShadingModel::MarschnerLut(_) => (
                "fiber_marschner_lut.wgsl",
                include_str!("fiber_marschner_lut.wgsl"),
            ),
            ShadingModel::ChiangLut(_) => (
                "fiber_chiang_lut.wgsl",
                include_str!("fiber_chiang_lut.wgsl"),
            ),
            ShadingModel::Artist(_) => ("fiber_artist.wgsl", include_str!("fiber_artist.wgsl")),
        };
        Wgsl { file, source }
    }
}

#[derive(Debug, thiserror::Error, PartialEq)]
pub enum LutLayoutError {
    #[error("lookup table `{table}`: {problem}")]
    Layout {
        table: &'static str,
        problem: String,
    },
}

/// A longitudinal M table and an azimuthal N table as `fiber_lut.wgsl` reads them.
#[derive(Clone, Debug, PartialEq)]
struct LutPair {
    lut_m: Table,
    lut_n: Table,
    /// N's azimuth axis is cos(φ/2) rather than cos φ.
    half_phi: bool,
}

impl LutPair {
    fn uniform(&self) -> LutUniform {
        let m = self.lut_m.gpu_axes();
        let n = self.lut_n.gpu_axes();
        LutUniform {
            m_axes: [m[0], m[1]],
            n_axes: [n[0], n[1]],
            m_strides: strides(&self.lut_m),
            n_strides: strides(&self.lut_n),
            half_phi: self.half_phi as u32,
            min_cos2_theta_d: MIN_COS2_THETA_D,
            _pad: [0; 2],
        }
    }
}

/// The M table (axes `sin_theta_i`, `sin_theta_o`, `quantity` with 4 nodes M_R, M_TT, M_TRT,
/// cos θ_d; 1 channel) and the N table (axes `cos_phi` or `cos_half_phi`, `cos_theta_d`, `lobe`
/// with 3 nodes; 3 channels), checked for that layout.
#[derive(Clone, Debug, PartialEq)]
pub struct MarschnerLuts(LutPair);

/// Chiang's M table (axes `sin_theta_i`, `sin_theta_o`, `quantity` with 4 nodes: M_p of the
/// lobes R, TT, TRT with the scale tilt and of the residual; 1 channel) and N table (axes
/// `cos_phi` or `cos_half_phi`, `sin_theta_o`, `lobe` with 4 nodes: N̄_p = ½∫A_p N_p dh of the
/// same lobes; 3 channels), checked for that layout.
#[derive(Clone, Debug, PartialEq)]
pub struct ChiangLuts(LutPair);

fn check_layout(
    table_name: &'static str,
    table: &Table,
    names: [&[&str]; 3],
    discrete_nodes: usize,
    channels: usize,
) -> Result<(), LutLayoutError> {
    let bad = |problem: String| LutLayoutError::Layout {
        table: table_name,
        problem,
    };
    let axes = table.axes();
    if axes.len() != 3 {
        return Err(bad(format!("has {} axes, expected 3", axes.len())));
    }
    for (axis, allowed) in axes.iter().zip(names) {
        if !allowed.contains(&axis.name.as_str()) {
            return Err(bad(format!(
                "axis `{}` where {} was expected",
                axis.name,
                allowed.join(" or ")
            )));
        }
    }
    if axes[2].count != discrete_nodes {
        return Err(bad(format!(
            "axis `{}` has {} nodes, expected {discrete_nodes}",
            axes[2].name, axes[2].count
        )));
    }
    if table.channels() != channels {
        return Err(bad(format!(
            "has {} channels, expected {channels}",
            table.channels()
        )));
    }
    if u32::try_from(table.values().len()).is_err() {
        return Err(bad("holds more than 2^32 values".into()));
    }
    Ok(())
}

impl LutPair {
    /// The pair checked for the layout `fiber_lut.wgsl` reads: M over (`sin_theta_i`,
    /// `sin_theta_o`, 4 quantities), 1 channel; N over (`cos_phi` or `cos_half_phi`,
    /// `n_second_axis`, `lobes` lobes), RGB.
    fn checked(
        names: [&'static str; 2],
        lut_m: Table,
        lut_n: Table,
        n_second_axis: &'static str,
        lobes: usize,
    ) -> Result<Self, LutLayoutError> {
        check_layout(
            names[0],
            &lut_m,
            [&[AXIS_SIN_THETA_I], &[AXIS_SIN_THETA_O], &[AXIS_QUANTITY]],
            4,
            1,
        )?;
        check_layout(
            names[1],
            &lut_n,
            [
                &[AXIS_COS_PHI, AXIS_COS_HALF_PHI],
                &[n_second_axis],
                &[AXIS_LOBE],
            ],
            lobes,
            3,
        )?;
        let half_phi = lut_n.axes()[0].name == AXIS_COS_HALF_PHI;
        Ok(Self {
            lut_m,
            lut_n,
            half_phi,
        })
    }
}

impl MarschnerLuts {
    pub fn new(lut_m: Table, lut_n: Table) -> Result<Self, LutLayoutError> {
        LutPair::checked(["lut_m", "lut_n"], lut_m, lut_n, AXIS_COS_THETA_D, 3).map(Self)
    }

    pub fn lut_m(&self) -> &Table {
        &self.0.lut_m
    }

    pub fn lut_n(&self) -> &Table {
        &self.0.lut_n
    }
}

impl ChiangLuts {
    pub fn new(lut_m: Table, lut_n: Table) -> Result<Self, LutLayoutError> {
        LutPair::checked(
            ["chiang_lut_m", "chiang_lut_n"],
            lut_m,
            lut_n,
            AXIS_SIN_THETA_O,
            4,
        )
        .map(Self)
    }

    pub fn lut_m(&self) -> &Table {
        &self.0.lut_m
    }

    pub fn lut_n(&self) -> &Table {
        &self.0.lut_n
    }
}

/// Element strides of a three-axis table, row-major with the channels innermost.
fn strides(table: &Table) -> [u32; 4] {
    let shape = table.shape();
    let c = table.channels();
    [
        (shape[1] * shape[2] * c) as u32,
        (shape[2] * c) as u32,
        c as u32,
        0,
    ]
}

#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct LutUniform {
    m_axes: [AxisGpu; 2],
    n_axes: [AxisGpu; 2],
    m_strides: [u32; 4],
    n_strides: [u32; 4],
    half_phi: u32,
    min_cos2_theta_d: f32,
    _pad: [u32; 2],
}

#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct ArtistUniform {
    weight: [[f32; 4]; 4],
    alpha: [f32; 4],
    beta: [f32; 4],
    gamma_tt: f32,
    gamma_glint: f32,
    glint_half_angle: f32,
    min_cos_theta_d: f32,
}

/// The lobe constants of `fiber_artist.wgsl`, as Sadeghi's eqs. 10–11 combine the controls: the
/// glints take the secondary highlight's shift, width, colour × C_G and intensity × I_g.
fn artist_uniform(model: &ArtistModel) -> ArtistUniform {
    let p = model.params();
    let rad = |d: f64| d.to_radians() as f32;
    let weight =
        |c: [f64; 3], i: f64| [(c[0] * i) as f32, (c[1] * i) as f32, (c[2] * i) as f32, 0.0];
    let glint_color = std::array::from_fn(|k| p.trt.color[k] * p.glints.color[k]);
    ArtistUniform {
        weight: [
            weight(p.r.color, p.r.intensity),
            weight(p.tt.color, p.tt.intensity),
            weight(p.trt.color, p.trt.intensity),
            weight(glint_color, p.trt.intensity * p.glints.relative_intensity),
        ],
        alpha: [
            rad(p.r.shift_deg),
            rad(p.tt.shift_deg),
            rad(p.trt.shift_deg),
            rad(p.trt.shift_deg),
        ],
        beta: [
            rad(p.r.width_deg),
            rad(p.tt.width_deg),
            rad(p.trt.width_deg),
            rad(p.trt.width_deg),
        ],
        gamma_tt: rad(p.tt.azimuthal_width_deg),
        gamma_glint: rad(p.glints.azimuthal_width_deg),
        glint_half_angle: rad(p.glints.half_angle_deg),
        min_cos_theta_d: MIN_COS_THETA_D,
    }
}

/// Bind group 2 of the strand pipeline: the model's constants and tables (none for Kajiya-Kay).
pub(crate) struct ModelBinding {
    pub layout: wgpu::BindGroupLayout,
    pub group: wgpu::BindGroup,
}

impl ModelBinding {
    pub(crate) fn new(gpu: &GpuContext, model: &ShadingModel) -> Option<Self> {
        let device = &gpu.device;
        let fragment = wgpu::ShaderStages::FRAGMENT;
        let buffer = |label, contents: &[u8], usage| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage,
            })
        };
        let (entries, buffers): (Vec<_>, Vec<wgpu::Buffer>) = match model {
            ShadingModel::KajiyaKay => return None,
            ShadingModel::MarschnerLut(MarschnerLuts(luts))
            | ShadingModel::ChiangLut(ChiangLuts(luts)) => (
                vec![
                    uniform_entry(0, fragment),
                    storage_entry(1, fragment, true),
                    storage_entry(2, fragment, true),
                ],
                vec![
                    buffer(
                        "lut params",
                        bytemuck::bytes_of(&luts.uniform()),
                        wgpu::BufferUsages::UNIFORM,
                    ),
                    buffer("lut_m", luts.lut_m.as_bytes(), wgpu::BufferUsages::STORAGE),
                    buffer("lut_n", luts.lut_n.as_bytes(), wgpu::BufferUsages::STORAGE),
                ],
            ),
            ShadingModel::Artist(model) => (
                vec![uniform_entry(0, fragment)],
                vec![buffer(
                    "artist lobes",
                    bytemuck::bytes_of(&artist_uniform(model)),
                    wgpu::BufferUsages::UNIFORM,
                )],
            ),
        };
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("fiber model"),
            entries: &entries,
        });
        let resources: Vec<_> = buffers.iter().map(|b| b.as_entire_binding()).collect();
        let group = bind_group(device, "fiber model", &layout, &resources);
        Some(Self { layout, group })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use strandlight_tables::table::Axis;

    fn table(names: [&str; 3], counts: [usize; 3], channels: usize) -> Table {
        let axes = names
            .iter()
            .zip(counts)
            .map(|(n, c)| Axis::uniform(*n, 0.0, 1.0, c))
            .collect();
        Table::from_fn(axes, channels, |_, out| out.fill(0.0)).unwrap()
    }

    #[test]
    fn lut_layout_is_checked_and_strides_are_row_major() {
        let m = table(
            [AXIS_SIN_THETA_I, AXIS_SIN_THETA_O, AXIS_QUANTITY],
            [5, 6, 4],
            1,
        );
        let n = table(
            [AXIS_COS_HALF_PHI, AXIS_COS_THETA_D, AXIS_LOBE],
            [7, 8, 3],
            3,
        );
        let luts = MarschnerLuts::new(m.clone(), n.clone()).unwrap();
        assert!(luts.0.half_phi);
        // The stride of each axis is the offset between neighbouring nodes.
        assert_eq!(
            strides(&n),
            [
                (n.node_offset(&[1, 0, 0]).unwrap()) as u32,
                (n.node_offset(&[0, 1, 0]).unwrap()) as u32,
                (n.node_offset(&[0, 0, 1]).unwrap()) as u32,
                0
            ]
        );
        assert_eq!(strides(&m), [24, 4, 1, 0]);
        let e = MarschnerLuts::new(n.clone(), m.clone()).unwrap_err();
        assert!(e.to_string().contains("lut_m"), "{e}");
        let wrong_lobes = table([AXIS_COS_PHI, AXIS_COS_THETA_D, AXIS_LOBE], [7, 8, 4], 3);
        let e = MarschnerLuts::new(m, wrong_lobes).unwrap_err();
        assert!(e.to_string().contains("4 nodes, expected 3"), "{e}");
    }
}

#[cfg(test)]
mod wgsl_layout {
    use super::*;
    use crate::shader_layout::{assert_same_layout, rust_layout};
    use crate::shaders::Wgsl;

    #[test]
    fn uploaded_structs_are_laid_out_as_the_wgsl_reads_them() {
        assert_same_layout(
            &Wgsl {
                file: "fiber_lut.wgsl",
                source: include_str!("fiber_lut.wgsl"),
            },
            None,
            "LutParams",
            &rust_layout!(LutUniform {
                m_axes,
                n_axes,
                m_strides,
                n_strides,
                half_phi,
                min_cos2_theta_d
            }),
        );
        assert_same_layout(
            &Wgsl {
                file: "fiber_artist.wgsl",
                source: include_str!("fiber_artist.wgsl"),
            },
            None,
            "ArtistLobes",
            &rust_layout!(ArtistUniform {
                weight,
                alpha,
                beta,
                gamma_tt,
                gamma_glint,
                glint_half_angle,
                min_cos_theta_d
            }),
        );
    }
}
