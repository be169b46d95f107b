//! `bake --export ktx2`: a baked table as a GPU texture any engine can load — a KTX2 file
//! ([`crate::ktx2_writer`]) laid out by [`crate::lut_layout`], a JSON sidecar
//! ([`crate::lut_sidecar`]) and the WGSL function that samples it (`lut_sampling.wgsl`).
//!
//! Every file is written atomically and every error names the file.

use crate::asset::TableAsset;
use crate::atomic_write::write_atomically;
use crate::ktx2_writer::{Ktx2Extent, Ktx2Format, write_ktx2};
use crate::lut_layout::LutLayout;
use crate::lut_sidecar::{
    HalfRounding, LutSidecar, SIDECAR_FORMAT, SidecarAxis, SidecarGpuAxis, SidecarSource,
    SidecarTexture, SidecarWgsl, axis_meaning, node_formula, sampling_steps,
};
use half::f16;
use serde::{Deserialize, Serialize};
use std::io::Write;
use std::path::{Path, PathBuf};
use thiserror::Error;

/// The WGSL every export ships, verbatim.
pub const WGSL_SOURCE: &str = include_str!("lut_sampling.wgsl");
pub const WGSL_FILE: &str = "strandlight_lut.wgsl";

/// Texel component type of an export.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum TexelStorage {
    /// IEEE binary16 (rgba16float / r16float): filterable on every WebGPU device.
    Half,
    /// IEEE binary32 (rgba32float / r32float): exact, but filtering needs `float32-filterable`.
    Float,
}

impl TexelStorage {
    pub fn format(self, channels: usize) -> Ktx2Format {
        match (self, channels) {
            (TexelStorage::Half, 1) => Ktx2Format::R16Sfloat,
            (TexelStorage::Half, _) => Ktx2Format::R16G16B16A16Sfloat,
            (TexelStorage::Float, 1) => Ktx2Format::R32Sfloat,
            (TexelStorage::Float, _) => Ktx2Format::R32G32B32A32Sfloat,
        }
    }
}

#[derive(Debug, Error)]
pub enum LutExportError {
    #[error("{}: {source}", .path.display())]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{}: a table of {axes} axes cannot be a texture; the export takes 1 to 4", .path.display())]
    TooManyAxes { path: PathBuf, axes: usize },
    #[error("{}: value {value} at node {node:?} does not fit a half float (|v| ≥ 65520); export with --export-format float", .path.display())]
    HalfOverflow {
        path: PathBuf,
        node: Vec<usize>,
        value: f32,
    },
    #[error("{}: value {value} at node {node:?} is not finite", .path.display())]
    NonFinite {
        path: PathBuf,
        node: Vec<usize>,
        value: f32,
    },
}

/// What one table's export wrote.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ExportedLut {
    pub table: String,
    pub texture: PathBuf,
    pub sidecar: PathBuf,
    pub texture_bytes: u64,
    pub width: usize,
    pub height: usize,
    pub depth: usize,
    pub half_rounding: Option<HalfRounding>,
    /// (largest extent, WebGPU's default limit) when the texture is larger than every WebGPU
    /// device must accept.
    pub exceeds_webgpu_limit: Option<(usize, usize)>,
}

/// The texture file of table `name` in `dir`.
pub fn texture_path(dir: &Path, name: &str) -> PathBuf {
    dir.join(format!("{name}.ktx2"))
}

/// The sidecar of table `name` in `dir`.
pub fn sidecar_path(dir: &Path, name: &str) -> PathBuf {
    dir.join(format!("{name}.json"))
}

/// Writes `<dir>/<name>.ktx2` and `<dir>/<name>.json` for a loaded table asset.
pub fn export_ktx2(
    asset: &TableAsset,
    dir: &Path,
    storage: TexelStorage,
) -> Result<ExportedLut, LutExportError> {
    let name = &asset.metadata.description.name;
    let texture = texture_path(dir, name);
    let table = &asset.table;
    let layout = LutLayout::of(table.axes()).ok_or_else(|| LutExportError::TooManyAxes {
        path: texture.clone(),
        axes: table.axes().len(),
    })?;
    let format = storage.format(table.channels());
    let texels = encode_texels(asset, &layout, format, &texture)?;
    let [width, height, depth] = layout.extent();
    let extent = Ktx2Extent {
        width: width as u32,
        height: height as u32,
        depth: depth as u32,
    };
    let writer = format!("strandlight {}\0", env!("CARGO_PKG_VERSION"));
    write_atomically(&texture, |w| {
        write_ktx2(
            w,
            format,
            extent,
            &texels,
            &[("KTXwriter", writer.as_bytes())],
        )
    })
    .map_err(|source| LutExportError::Io {
        path: texture.clone(),
        source,
    })?;
    let half_rounding = (storage == TexelStorage::Half).then(|| half_rounding(table.values()));
    let sidecar = sidecar_of(asset, &layout, format, half_rounding);
    let sidecar_file = sidecar_path(dir, name);
    write_json(&sidecar_file, &sidecar)?;
    Ok(ExportedLut {
        table: name.clone(),
        texture,
        sidecar: sidecar_file,
        texture_bytes: extent.texel_count() * format.texel_bytes() as u64,
        width,
        height,
        depth,
        half_rounding,
        exceeds_webgpu_limit: layout.exceeds_webgpu_limits(),
    })
}

/// Writes `<dir>/strandlight_lut.wgsl`.
pub fn write_wgsl(dir: &Path) -> Result<PathBuf, LutExportError> {
    let path = dir.join(WGSL_FILE);
    write_atomically(&path, |w| w.write_all(WGSL_SOURCE.as_bytes())).map_err(|source| {
        LutExportError::Io {
            path: path.clone(),
            source,
        }
    })?;
    Ok(path)
}

/// The texels in the layout's order, each table value converted to the format; RGB tables get
/// alpha 1 (WebGPU has no three-component float format).
fn encode_texels(
    asset: &TableAsset,
    layout: &LutLayout,
    format: Ktx2Format,
    path: &Path,
) -> Result<Vec<u8>, LutExportError> {
    let table = &asset.table;
    let channels = table.channels();
    let components = format.components() as usize;
    let texel_bytes = format.texel_bytes() as usize;
    let mut out = vec![0u8; table.values().len() / channels * texel_bytes];
    for (node_number, values) in table.values().chunks(channels).enumerate() {
        let node = table.node_index_of(node_number * channels);
        let start = layout.texel_offset(layout.texel(&node)) * texel_bytes;
        let texel = &mut out[start..start + texel_bytes];
        for c in 0..components {
            let value = if c < channels { values[c] } else { 1.0 };
            if !value.is_finite() {
                return Err(LutExportError::NonFinite {
                    path: path.to_path_buf(),
                    node,
                    value,
                });
            }
            let size = format.type_size() as usize;
            let slot = &mut texel[c * size..(c + 1) * size];
            if size == 4 {
                slot.copy_from_slice(&value.to_le_bytes());
                continue;
            }
            let half = f16::from_f32(value);
            if half.is_infinite() {
                return Err(LutExportError::HalfOverflow {
                    path: path.to_path_buf(),
                    node,
                    value,
                });
            }
            slot.copy_from_slice(&half.to_le_bytes());
        }
    }
    Ok(out)
}

/// The rounding that storing `values` as half floats costs.
pub fn half_rounding(values: &[f32]) -> HalfRounding {
    let largest = values.iter().fold(0.0f64, |m, v| m.max(v.abs() as f64));
    let (mut relative, mut absolute) = (0.0f64, 0.0f64);
    for &v in values {
        let error = (f16::from_f32(v).to_f64() - v as f64).abs();
        absolute = absolute.max(error);
        if v.abs() as f64 >= 0.01 * largest && v != 0.0 {
            relative = relative.max(error / v.abs() as f64);
        }
    }
    HalfRounding {
        max_relative_error: relative,
        max_error_of_table_max: if largest > 0.0 {
            absolute / largest
        } else {
            0.0
        },
    }
}

fn sidecar_of(
    asset: &TableAsset,
    layout: &LutLayout,
    format: Ktx2Format,
    half_rounding: Option<HalfRounding>,
) -> LutSidecar {
    let d = &asset.metadata.description;
    let table = &asset.table;
    let [width, height, depth] = layout.extent();
    let file_name = |p: &Path| {
        p.file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default()
    };
    let mut components: Vec<String> = match table.channels() {
        1 => vec!["r: the value".into()],
        _ => vec!["r: red".into(), "g: green".into(), "b: blue".into()],
    };
    if format.components() == 4 {
        components.push("a: 1 (unused)".into());
    }
    let texture_axes: &[&str] = match table.axes().len() {
        1 => &["x"],
        2 => &["y", "x"],
        3 => &["z", "y", "x"],
        _ => &["z within a slab", "y", "x", "slab along z"],
    };
    let axes = table
        .axes()
        .iter()
        .enumerate()
        .map(|(k, a)| SidecarAxis {
            table_axis: k,
            name: a.name.clone(),
            meaning: axis_meaning(&a.name).into(),
            min: a.min,
            max: a.max,
            count: a.count,
            mapping: a.mapping,
            node_formula: node_formula(a),
            texture_axis: texture_axes[k].into(),
        })
        .collect();
    LutSidecar {
        format: SIDECAR_FORMAT.into(),
        table: d.name.clone(),
        quantity: d.quantity.clone(),
        scattering_function: d.scattering_function.clone(),
        fiber_parameters: d.fiber_parameters.clone(),
        source: SidecarSource {
            file: file_name(&asset.path),
            payload_sha256: asset.metadata.payload.sha256.clone(),
        },
        texture: SidecarTexture {
            file: format!("{}.ktx2", d.name),
            dimension: if layout.is_3d() { "3d" } else { "2d" }.into(),
            width,
            height,
            depth,
            vk_format: format.vk_name().into(),
            vk_format_value: format.vk_format(),
            webgpu_format: format.webgpu_name().into(),
            components,
            layout: layout.describe(),
            sampler: "linear min/mag filtering, clamp-to-edge on every axis, one mip level"
                .into(),
        },
        axes,
        texel_centre: "node i of an axis with n nodes is the centre of texel i: normalized texture coordinate (i + 0.5)/n".into(),
        sampling: sampling_steps(table.axes().len()),
        wgsl: SidecarWgsl {
            file: WGSL_FILE.into(),
            function: if layout.is_3d() {
                "strandlight_lut_3d"
            } else {
                "strandlight_lut_2d"
            }
            .into(),
            exact_function: if layout.is_3d() {
                "strandlight_lut_3d_exact"
            } else {
                "strandlight_lut_2d_exact"
            }
            .into(),
            uniform: gpu_uniform(asset),
        },
        half_rounding,
    }
}

/// The four `StrandLutAxis` of the WGSL uniform: a one-axis table gets a one-node axis first
/// (its coordinate goes in `.y`), tables of two or three axes one-node axes after theirs.
pub fn gpu_uniform(asset: &TableAsset) -> Vec<SidecarGpuAxis> {
    let mut axes: Vec<SidecarGpuAxis> = asset
        .table
        .gpu_axes()
        .into_iter()
        .map(SidecarGpuAxis::from)
        .collect();
    if axes.len() == 1 {
        axes.insert(0, SidecarGpuAxis::ONE_NODE);
    }
    axes.resize(4, SidecarGpuAxis::ONE_NODE);
    axes
}

fn write_json(path: &Path, sidecar: &LutSidecar) -> Result<(), LutExportError> {
    let io_error = |source| LutExportError::Io {
        path: path.to_path_buf(),
        source,
    };
    let text = serde_json::to_vec_pretty(sidecar).map_err(|e| io_error(e.into()))?;
    write_atomically(path, |w| w.write_all(&text)).map_err(io_error)
}
