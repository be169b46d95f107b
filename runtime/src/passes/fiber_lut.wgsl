// The two point-light lookup tables of a fiber model (Hunz 2016 Algorithm 2): a longitudinal M
// table over (sin θ_i, sin θ_o, quantity) and an azimuthal N table over (azimuth, a second
// angle, lobe), RGB. The tables are strandlight `Table`s uploaded as-is (storage buffers,
// row-major, channels innermost) and interpolated here bilinearly over their two continuous
// axes, exactly as `Table::lookup` does on the CPU; the quantity / lobe axis is indexed, not
// interpolated. The model's own file (fiber_marschner_lut.wgsl, fiber_chiang_lut.wgsl) says
// how S is assembled from them.

#define_import_path strandlight::fiber_lut

#import strandlight::table_axis::{TableAxis, table_cell}

struct LutParams {
    // M: sin θ_i, sin θ_o. N: azimuth (cos φ or cos(φ/2)), then cos θ_d (Marschner) or sin θ_o
    // (Chiang).
    m_axes: array<TableAxis, 2>,
    n_axes: array<TableAxis, 2>,
    // Element strides of the three axes (x, y, z) of each table.
    m_strides: vec4<u32>,
    n_strides: vec4<u32>,
    // 1 when N's azimuth axis is cos(φ/2).
    half_phi: u32,
    // Marschner's floor of cos²θ_d (unused by Chiang).
    min_cos2_theta_d: f32,
    _pad_a: u32,
    _pad_b: u32,
};

@group(2) @binding(0) var<uniform> lut: LutParams;
@group(2) @binding(1) var<storage, read> lut_m: array<f32>;
@group(2) @binding(2) var<storage, read> lut_n: array<f32>;

// Bilinear weights and the four element offsets of one cell of a two-axis slice.
struct Bilinear {
    base: u32,
    step_x: u32,
    step_y: u32,
    wx: f32,
    wy: f32,
};

fn bilinear(ax: TableAxis, ay: TableAxis, strides: vec4<u32>, x: f32, y: f32) -> Bilinear {
    let cx = table_cell(ax, x);
    let cy = table_cell(ay, y);
    var sx = strides.x;
    var sy = strides.y;
    if (ax.last_index < 1.0) { sx = 0u; }
    if (ay.last_index < 1.0) { sy = 0u; }
    return Bilinear(cx.lower * strides.x + cy.lower * strides.y, sx, sy, cx.upper_weight, cy.upper_weight);
}

fn m_value(b: Bilinear, quantity: u32) -> f32 {
    let o = b.base + quantity * lut.m_strides.z;
    let v00 = lut_m[o];
    let v10 = lut_m[o + b.step_x];
    let v01 = lut_m[o + b.step_y];
    let v11 = lut_m[o + b.step_x + b.step_y];
    return mix(mix(v00, v10, b.wx), mix(v01, v11, b.wx), b.wy);
}

fn n_texel(o: u32) -> vec3<f32> {
    return vec3<f32>(lut_n[o], lut_n[o + 1u], lut_n[o + 2u]);
}

fn n_value(b: Bilinear, lobe: u32) -> vec3<f32> {
    let o = b.base + lobe * lut.n_strides.z;
    let v00 = n_texel(o);
    let v10 = n_texel(o + b.step_x);
    let v01 = n_texel(o + b.step_y);
    let v11 = n_texel(o + b.step_x + b.step_y);
    return mix(mix(v00, v10, b.wx), mix(v01, v11, b.wx), b.wy);
}

// N's azimuth coordinate of cos φ.
fn lut_azimuth(cos_phi: f32) -> f32 {
    if (lut.half_phi == 1u) { return sqrt(clamp(0.5 + 0.5 * cos_phi, 0.0, 1.0)); }
    return cos_phi;
}
