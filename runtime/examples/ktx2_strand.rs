//! Lights a strand on the GPU from an exported LUT alone — the KTX2 texture, its JSON sidecar
//! and `strandlight_lut.wgsl`, as another engine would — and compares it with the runtime's
//! own evaluation of the same lookups.
//!
//! ```sh
//! strandlight bake --model marschner --export ktx2 --out tables
//! cargo run --release -p strandlight-runtime --example ktx2_strand -- tables/ktx2 [TABLE]
//! ```
//!
//! TABLE (default `marschner`) is a convolution table I(u·ξ, u·ω_o, cos Δφ, 1/λ). A helical
//! strand of 48 segments is shaded at each segment's midpoint under three SRBF lobes, without
//! visibility: L_o = Σ_j I(u·ξ_j, u·ω_o, cos(φ_ξj − φ_o), 1/λ_j) · L_j, the single-scattering sum
//! of the runtime's env view shading (`env_shading.wgsl`). The reference is that sum with the
//! runtime's lookup, `Table::lookup` on the `.sltab` beside the export (the GPU view pass
//! interpolates the same way), in f64.

use glam::Vec3;
use serde_json::Value;
use std::path::{Path, PathBuf};
use strandlight_runtime::env_light::EnvLight;
use strandlight_runtime::gpu::{GpuContext, read_buffer};
use strandlight_tables::asset::read_asset;
use strandlight_tables::table::{AxisMapping, Table};

/// Sub-texel precision of hardware linear filtering assumed by the tolerance: the fraction
/// between two texels is rounded to this many bits (8 on D3D11-class hardware; lavapipe uses
/// 8 too). Vulkan only promises 4 (`subTexelPrecisionBits`); a device with fewer bits needs a
/// looser tolerance.
pub const SUB_TEXEL_BITS: i32 = 8;

/// Which function of `strandlight_lut.wgsl` the strand is shaded with.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Sampling {
    /// `strandlight_lut_3d`: the hardware's trilinear filter, two samples.
    Filtered,
    /// `strandlight_lut_3d_exact`: 16 `textureLoad`s weighted in f32.
    Exact,
}

/// An exported texture as an engine loads it: the texels and the sidecar's sampling values.
pub struct LoadedLut {
    pub name: String,
    pub format: wgpu::TextureFormat,
    pub size: [u32; 3],
    pub texels: Vec<u8>,
    /// The `StrandLut` uniform: 4 × (min, inv_range, last_index, inv_exponent, warp, 3 pad).
    pub uniform: Vec<u8>,
    pub sidecar: Value,
}

/// Reads `<dir>/<name>.ktx2` with the `ktx2` crate and `<dir>/<name>.json`.
pub fn load_export(dir: &Path, name: &str) -> Result<LoadedLut, String> {
    let ktx_path = dir.join(format!("{name}.ktx2"));
    let json_path = dir.join(format!("{name}.json"));
    let bytes = std::fs::read(&ktx_path).map_err(|e| format!("{}: {e}", ktx_path.display()))?;
    let reader = ktx2::Reader::new(bytes).map_err(|e| format!("{}: {e:?}", ktx_path.display()))?;
    let header = reader.header();
    let format = match header.format {
        Some(ktx2::Format::R16G16B16A16_SFLOAT) => wgpu::TextureFormat::Rgba16Float,
        Some(ktx2::Format::R32G32B32A32_SFLOAT) => wgpu::TextureFormat::Rgba32Float,
        other => {
            return Err(format!(
                "{}: format {other:?}; this example shades with RGBA tables",
                ktx_path.display()
            ));
        }
    };
    if header.pixel_depth == 0 {
        return Err(format!(
            "{}: a 2D texture; the strand needs a 4D table (a 3D texture)",
            ktx_path.display()
        ));
    }
    let texels = reader
        .levels()
        .next()
        .map(|l| l.data.to_vec())
        .unwrap_or_default();
    let text =
        std::fs::read_to_string(&json_path).map_err(|e| format!("{}: {e}", json_path.display()))?;
    let sidecar: Value =
        serde_json::from_str(&text).map_err(|e| format!("{}: {e}", json_path.display()))?;
    let uniform = uniform_bytes(&sidecar["wgsl"]["uniform"])
        .ok_or_else(|| format!("{}: no wgsl.uniform of four axes", json_path.display()))?;
    Ok(LoadedLut {
        name: name.into(),
        format,
        size: [header.pixel_width, header.pixel_height, header.pixel_depth],
        texels,
        uniform,
        sidecar,
    })
}

/// The sidecar's four `StrandLutAxis` values as the WGSL uniform's bytes.
fn uniform_bytes(axes: &Value) -> Option<Vec<u8>> {
    let axes = axes.as_array().filter(|a| a.len() == 4)?;
    let mut out = Vec::with_capacity(128);
    for a in axes {
        for key in ["min", "inv_range", "last_index", "inv_exponent"] {
            out.extend_from_slice(&(a[key].as_f64()? as f32).to_le_bytes());
        }
        out.extend_from_slice(&(a["warp"].as_u64()? as u32).to_le_bytes());
        out.extend_from_slice(&[0; 12]);
    }
    Some(out)
}

/// A shading point: position and unit tangent (root to tip).
#[derive(Clone, Copy)]
pub struct StrandPoint {
    pub position: Vec3,
    pub tangent: Vec3,
}

/// Midpoints of a helical strand's 48 segments: its tangents sweep every inclination from the
/// view and the lights.
pub fn helical_strand() -> Vec<StrandPoint> {
    let vertex = |i: usize| {
        let t = i as f32 / 48.0;
        let angle = t * 3.0 * std::f32::consts::TAU;
        Vec3::new(0.3 * angle.cos(), 2.0 * t - 1.0, 0.3 * angle.sin())
    };
    (0..48)
        .map(|i| {
            let (a, b) = (vertex(i), vertex(i + 1));
            StrandPoint {
                position: 0.5 * (a + b),
                tangent: (b - a).normalize(),
            }
        })
        .collect()
}

/// Three SRBF lobes with bandwidths inside the table's 1/λ range (from the sidecar).
pub fn srbf_lobes(sidecar: &Value) -> Vec<EnvLight> {
    let axis = &sidecar["axes"][3];
    let (lo, hi) = (
        axis["min"].as_f64().unwrap_or(1.0 / 64.0),
        axis["max"].as_f64().unwrap_or(1.0 / 16.0),
    );
    let lambda = |t: f64| (1.0 / (lo + t * (hi - lo))) as f32;
    vec![
        EnvLight::srbf(Vec3::new(0.3, 0.8, 0.5), lambda(0.2), [4.0, 3.6, 3.0]),
        EnvLight::srbf(Vec3::new(-0.7, 0.1, 0.6), lambda(0.55), [0.8, 1.0, 1.4]),
        EnvLight::srbf(Vec3::new(0.1, -0.4, -0.9), lambda(0.9), [2.0, 1.5, 1.0]),
    ]
}

pub const EYE: Vec3 = Vec3::new(0.4, 0.3, 3.0);

/// The table coordinates of lobe `light` at a point: (u·ξ, u·ω_o, cos Δφ, 1/λ), in f64.
fn coordinates(p: &StrandPoint, light: &EnvLight) -> [f64; 4] {
    let u = p.tangent.as_dvec3();
    let xi = light.direction.as_dvec3().normalize();
    let e = (EYE.as_dvec3() - p.position.as_dvec3()).normalize();
    let (s_xi, s_o) = (u.dot(xi).clamp(-1.0, 1.0), u.dot(e).clamp(-1.0, 1.0));
    let (xp, ep) = (xi - s_xi * u, e - s_o * u);
    let norms = xp.length_squared() * ep.length_squared();
    let cos_dphi = if norms > 1e-20 {
        (xp.dot(ep) / norms.sqrt()).clamp(-1.0, 1.0)
    } else {
        1.0
    };
    let inv_lambda = light.lambda.map_or(0.0, |l| 1.0 / l as f64);
    [s_xi, s_o, cos_dphi, inv_lambda]
}

/// The runtime's radiance at each point, and the tolerance the exported texture must meet
/// there, per lobe times |L_j|, in units of the spread of the cell's 16 node values (largest −
/// smallest, which bounds what any error in the interpolation weights can cost):
/// - half rounding: 2⁻¹¹ of each value (0 for float);
/// - the hardware filter (filtered sampling only): weights rounded to [`SUB_TEXEL_BITS`] on
///   the three axes it interpolates, 3 · 2^−(bits+1) of the spread;
/// - the shader's f32 `asin`/`acos` on the angular axes: Vulkan allows them 4096 ULP
///   ("inherited from atan"), 2⁻¹⁰ rad for angles up to π, i.e. 2⁻¹⁰·(n−1)/(angle range) of a
///   cell per axis. lavapipe's are that coarse: its trilinear and 16-load results agree to 1e-6
///   and both differ from the f64 lookup by ~1e-3 of a cell's spread.
pub fn runtime_radiance(
    table: &Table,
    points: &[StrandPoint],
    lights: &[EnvLight],
    half: bool,
    sampling: Sampling,
) -> Vec<([f64; 3], [f64; 3])> {
    let rounding = if half { 2f64.powi(-11) } else { 0.0 };
    let filter = match sampling {
        Sampling::Filtered => 3.0 * 2f64.powi(-(SUB_TEXEL_BITS + 1)),
        Sampling::Exact => 0.0,
    };
    let weight_error = filter + angular_position_error(table);
    points
        .iter()
        .map(|p| {
            let (mut sum, mut tolerance) = ([0.0; 3], [0.0; 3]);
            for light in lights {
                let coords = coordinates(p, light);
                let value = table.lookup_rgb(&coords).expect("finite coordinates");
                let spread = cell_spread(table, &coords);
                for c in 0..3 {
                    let l = light.rgb[c] as f64;
                    sum[c] += value[c] as f64 * l;
                    tolerance[c] +=
                        (rounding * value[c].abs() as f64 + weight_error * spread[c]) * l.abs();
                }
            }
            (sum, tolerance)
        })
        .collect()
}

/// Σ over the arcsine/arccosine axes of the node-position error that 4096-ULP trig costs.
fn angular_position_error(table: &Table) -> f64 {
    let angle_error = 2f64.powi(-10);
    table
        .axes()
        .iter()
        .map(|a| {
            let range = match a.mapping {
                AxisMapping::Arcsine => a.max.asin() - a.min.asin(),
                AxisMapping::Arccosine => a.min.acos() - a.max.acos(),
                _ => return 0.0,
            };
            if a.count > 1 && range > 0.0 {
                angle_error * (a.count - 1) as f64 / range
            } else {
                0.0
            }
        })
        .sum()
}

/// Per channel, the largest minus the smallest value among the 16 nodes of the cell holding
/// `coords` (the cell `Table::lookup` interpolates).
fn cell_spread(table: &Table, coords: &[f64; 4]) -> [f64; 3] {
    let lower: Vec<usize> = table
        .axes()
        .iter()
        .zip(coords)
        .map(|(a, &x)| {
            let f = a.position(x).expect("finite");
            (f.floor() as usize).min(a.count.saturating_sub(2))
        })
        .collect();
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for corner in 0..16usize {
        let index: Vec<usize> = (0..4)
            .map(|k| (lower[k] + (corner >> k & 1)).min(table.axes()[k].count - 1))
            .collect();
        let node = table.node(&index).expect("in range");
        for c in 0..3 {
            lo[c] = lo[c].min(node[c] as f64);
            hi[c] = hi[c].max(node[c] as f64);
        }
    }
    [0, 1, 2].map(|c| hi[c] - lo[c])
}

/// The example's compute shader: the exported WGSL, then one entry point that shades a point
/// with the `sampling` function.
fn shader_source(lut_wgsl: &str, sampling: Sampling) -> String {
    let lookup = match sampling {
        Sampling::Filtered => "strandlight_lut_3d(lut_texture, lut_sampler, lut, coords)",
        Sampling::Exact => "strandlight_lut_3d_exact(lut_texture, lut, coords)",
    };
    let entry = SHADE_ENTRY.replace("LOOKUP", lookup);
    format!("{lut_wgsl}\n{entry}")
}

const SHADE_ENTRY: &str = r#"
struct Lobe { direction: vec4<f32>, rgb: vec4<f32> };
struct Params { eye: vec4<f32>, counts: vec4<u32> };
@group(0) @binding(0) var lut_texture: texture_3d<f32>;
@group(0) @binding(1) var lut_sampler: sampler;
@group(0) @binding(2) var<uniform> lut: StrandLut;
@group(0) @binding(3) var<uniform> params: Params;
@group(0) @binding(4) var<storage, read> points: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read> lobes: array<Lobe>;
@group(0) @binding(6) var<storage, read_write> radiance: array<vec4<f32>>;

@compute @workgroup_size(64)
fn shade(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if (i >= params.counts.x) { return; }
    let u = normalize(points[2u * i + 1u].xyz);
    let e = normalize(params.eye.xyz - points[2u * i].xyz);
    var sum = vec3<f32>(0.0);
    for (var j = 0u; j < params.counts.y; j++) {
        let xi = normalize(lobes[j].direction.xyz);
        let s_xi = clamp(dot(u, xi), -1.0, 1.0);
        let s_o = clamp(dot(u, e), -1.0, 1.0);
        let xp = xi - s_xi * u;
        let ep = e - s_o * u;
        let norms = dot(xp, xp) * dot(ep, ep);
        var cos_dphi = 1.0;
        if (norms > 1e-20) { cos_dphi = clamp(dot(xp, ep) * inverseSqrt(norms), -1.0, 1.0); }
        let coords = vec4<f32>(s_xi, s_o, cos_dphi, lobes[j].direction.w);
        sum += LOOKUP.rgb * lobes[j].rgb.rgb;
    }
    radiance[i] = vec4<f32>(sum, 1.0);
}
"#;

fn buffer(gpu: &GpuContext, label: &str, bytes: &[u8], usage: wgpu::BufferUsages) -> wgpu::Buffer {
    let buffer = gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: bytes.len().max(16) as u64,
        usage: usage | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    gpu.queue.write_buffer(&buffer, 0, bytes);
    buffer
}

fn f32_bytes(values: &[f32]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_le_bytes()).collect()
}

/// The exported texture, uploaded as it was read.
fn lut_texture(gpu: &GpuContext, lut: &LoadedLut) -> wgpu::TextureView {
    let [width, height, depth] = lut.size;
    let texel_bytes = lut.format.block_copy_size(None).unwrap_or(8);
    let texture = gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: Some(&lut.name),
        size: wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: depth,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D3,
        format: lut.format,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    gpu.queue.write_texture(
        texture.as_image_copy(),
        &lut.texels,
        wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(width * texel_bytes),
            rows_per_image: Some(height),
        },
        texture.size(),
    );
    texture.create_view(&Default::default())
}

/// The sampler the sidecar asks for: linear, clamped to the edge, one level.
fn lut_sampler(gpu: &GpuContext) -> wgpu::Sampler {
    gpu.device.create_sampler(&wgpu::SamplerDescriptor {
        label: Some("lut"),
        address_mode_u: wgpu::AddressMode::ClampToEdge,
        address_mode_v: wgpu::AddressMode::ClampToEdge,
        address_mode_w: wgpu::AddressMode::ClampToEdge,
        mag_filter: wgpu::FilterMode::Linear,
        min_filter: wgpu::FilterMode::Linear,
        mipmap_filter: wgpu::MipmapFilterMode::Nearest,
        ..Default::default()
    })
}

/// The radiance at each point, shaded on the GPU from the exported LUT and WGSL alone.
pub fn gpu_radiance(
    gpu: &GpuContext,
    lut: &LoadedLut,
    lut_wgsl: &str,
    points: &[StrandPoint],
    lights: &[EnvLight],
    sampling: Sampling,
) -> Result<Vec<[f32; 3]>, String> {
    if sampling == Sampling::Filtered
        && lut.format == wgpu::TextureFormat::Rgba32Float
        && !gpu.float32_filterable
    {
        return Err(format!(
            "{} ({}) cannot filter rgba32float textures; use the exact sampling or export with --export-format half",
            lut.name, gpu.report
        ));
    }
    let usage = wgpu::BufferUsages::STORAGE;
    let point_data: Vec<f32> = points
        .iter()
        .flat_map(|p| {
            let (x, t) = (p.position, p.tangent);
            [x.x, x.y, x.z, 1.0, t.x, t.y, t.z, 0.0]
        })
        .collect();
    let lobe_data: Vec<f32> = lights
        .iter()
        .flat_map(|l| {
            let d = l.direction;
            let inv_lambda = l.lambda.map_or(0.0, |v| 1.0 / v);
            [d.x, d.y, d.z, inv_lambda, l.rgb[0], l.rgb[1], l.rgb[2], 0.0]
        })
        .collect();
    let mut params = f32_bytes(&[EYE.x, EYE.y, EYE.z, 1.0]);
    for v in [points.len() as u32, lights.len() as u32, 0, 0] {
        params.extend_from_slice(&v.to_le_bytes());
    }
    let out_bytes = vec![0u8; points.len() * 16];
    let buffers = [
        buffer(gpu, "lut axes", &lut.uniform, wgpu::BufferUsages::UNIFORM),
        buffer(gpu, "params", &params, wgpu::BufferUsages::UNIFORM),
        buffer(gpu, "points", &f32_bytes(&point_data), usage),
        buffer(gpu, "lobes", &f32_bytes(&lobe_data), usage),
        buffer(
            gpu,
            "radiance",
            &out_bytes,
            usage | wgpu::BufferUsages::COPY_SRC,
        ),
    ];
    let view = lut_texture(gpu, lut);
    let sampler = lut_sampler(gpu);
    let module = strandlight_runtime::gpu::pipeline::wgsl_module(
        &gpu.device,
        "ktx2_strand",
        &shader_source(lut_wgsl, sampling),
    );
    let pipeline = gpu
        .device
        .create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("ktx2_strand"),
            layout: None,
            module: &module,
            entry_point: Some("shade"),
            compilation_options: Default::default(),
            cache: None,
        });
    let mut entries = vec![wgpu::BindGroupEntry {
        binding: 0,
        resource: wgpu::BindingResource::TextureView(&view),
    }];
    // The exact lookup never samples: the derived layout has no sampler then.
    if sampling == Sampling::Filtered {
        entries.push(wgpu::BindGroupEntry {
            binding: 1,
            resource: wgpu::BindingResource::Sampler(&sampler),
        });
    }
    for (k, b) in buffers.iter().enumerate() {
        entries.push(wgpu::BindGroupEntry {
            binding: 2 + k as u32,
            resource: b.as_entire_binding(),
        });
    }
    let bind_group = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("ktx2_strand"),
        layout: &pipeline.get_bind_group_layout(0),
        entries: &entries,
    });
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &bind_group, &[]);
        pass.dispatch_workgroups((points.len() as u32).div_ceil(64), 1, 1);
    }
    gpu.queue.submit([encoder.finish()]);
    let bytes = read_buffer(gpu, &buffers[4]).map_err(|e| e.to_string())?;
    Ok(bytes
        .chunks_exact(16)
        .take(points.len())
        .map(|c| {
            let v = |k: usize| f32::from_le_bytes(c[4 * k..4 * k + 4].try_into().unwrap());
            [v(0), v(1), v(2)]
        })
        .collect())
}

/// How the GPU's strand compares with the runtime's.
#[derive(Debug)]
pub struct StrandComparison {
    pub points: usize,
    /// Largest |GPU − runtime| over the largest radiance on the strand.
    pub max_error_of_max: f64,
    /// Largest |GPU − runtime| / runtime, over channels above 1% of the largest radiance.
    pub max_relative_error: f64,
    /// Largest |GPU − runtime| / tolerance (≤ 1 passes).
    pub worst_over_tolerance: f64,
    pub largest_radiance: f64,
}

/// Loads the export `dir/<name>` and the `.sltab` the sidecar names (in `tables`), shades the
/// strand on the GPU with `sampling` and with the runtime's lookup, and compares.
pub fn run(
    gpu: &GpuContext,
    dir: &Path,
    tables: &Path,
    name: &str,
    sampling: Sampling,
) -> Result<StrandComparison, String> {
    let lut = load_export(dir, name)?;
    let wgsl_path = dir.join("strandlight_lut.wgsl");
    let wgsl =
        std::fs::read_to_string(&wgsl_path).map_err(|e| format!("{}: {e}", wgsl_path.display()))?;
    let points = helical_strand();
    let lights = srbf_lobes(&lut.sidecar);
    let gpu_values = gpu_radiance(gpu, &lut, &wgsl, &points, &lights, sampling)?;

    let source = lut.sidecar["source"]["file"].as_str().unwrap_or_default();
    let asset = read_asset(&tables.join(source)).map_err(|e| e.to_string())?;
    let half = lut.format == wgpu::TextureFormat::Rgba16Float;
    let reference = runtime_radiance(&asset.table, &points, &lights, half, sampling);
    let largest = reference
        .iter()
        .flat_map(|(v, _)| v.iter().copied())
        .fold(0.0f64, f64::max);
    let mut comparison = StrandComparison {
        points: points.len(),
        max_error_of_max: 0.0,
        max_relative_error: 0.0,
        worst_over_tolerance: 0.0,
        largest_radiance: largest,
    };
    for (got, (want, tolerance)) in gpu_values.iter().zip(&reference) {
        for c in 0..3 {
            let error = (got[c] as f64 - want[c]).abs();
            comparison.max_error_of_max = comparison.max_error_of_max.max(error / largest);
            if want[c] > 0.01 * largest {
                comparison.max_relative_error = comparison.max_relative_error.max(error / want[c]);
            }
            // f32 arithmetic on the GPU and in the shader's coordinates: 1e-5 of the value.
            let allowed = tolerance[c] + 1e-5 * want[c].abs() + 1e-7 * largest;
            comparison.worst_over_tolerance = comparison.worst_over_tolerance.max(error / allowed);
        }
    }
    Ok(comparison)
}

#[allow(dead_code)] // the test includes this file for `run`
fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(dir) = args.first().map(PathBuf::from) else {
        eprintln!(
            "usage: ktx2_strand EXPORT_DIR [TABLE]   (EXPORT_DIR from `strandlight bake --export ktx2`, e.g. tables/ktx2)"
        );
        std::process::exit(2);
    };
    let name = args.get(1).map_or("marschner", String::as_str);
    let tables = dir.parent().unwrap_or(Path::new(".")).to_path_buf();
    let gpu = GpuContext::new_headless().unwrap_or_else(|e| {
        eprintln!("error: {e}");
        std::process::exit(1);
    });
    println!("device: {}", gpu.report);
    let mut failed = false;
    for sampling in [Sampling::Filtered, Sampling::Exact] {
        match run(&gpu, &dir, &tables, name, sampling) {
            Ok(c) => {
                println!(
                    "{name}, {sampling:?}: {} points, 3 SRBF lobes; GPU from {}/{name}.ktx2 against the runtime's lookup: max error {:.2e} of the largest radiance {:.3e}, max relative error {:.2e} (channels above 1%), {:.2} of the tolerance",
                    c.points,
                    dir.display(),
                    c.max_error_of_max,
                    c.largest_radiance,
                    c.max_relative_error,
                    c.worst_over_tolerance
                );
                failed |= c.worst_over_tolerance > 1.0;
            }
            Err(e) => {
                eprintln!("error: {e}");
                failed = true;
            }
        }
    }
    if failed {
        std::process::exit(1);
    }
}
