// Summed-area tables of the DODM's four cumulative optical depths, one per light slot, in u32
// fixed point with wrapping arithmetic (Hensley et al. 2005; DESIGN.md "known traps": f32 SATs
// lose the low digits far from the origin). Each texel's τ is clamped to MAX_TEXEL_TAU and
// rounded to 1/FIXED_POINT_SCALE units; prefix sums wrap modulo 2³², so a box sum
// S(a) − S(b) − S(c) + S(d) is exact as long as the true box sum is below 2³² (the box area is
// bounded by the lookup side, see convolution_transmittance.wgsl).
// Layout: sat[(slot · res + y) · res + x], one vec4<u32> (the four boundaries) per texel.

struct SatParams {
    resolution: u32,
    slots: u32,
    _pad0: u32,
    _pad1: u32,
};

@group(0) @binding(0) var optical: texture_2d_array<f32>;
@group(0) @binding(1) var<storage, read_write> sat_out: array<vec4<u32>>;
@group(0) @binding(2) var<uniform> sat_params: SatParams;

const FIXED_POINT_SCALE: f32 = 256.0;
const MAX_TEXEL_TAU: f32 = 16.0;

fn quantize(tau: vec4<f32>) -> vec4<u32> {
    let t = clamp(tau, vec4<f32>(0.0), vec4<f32>(MAX_TEXEL_TAU));
    return vec4<u32>(round(t * FIXED_POINT_SCALE));
}

// One invocation per (row, slot): quantize and prefix-sum the row.
@compute @workgroup_size(64)
fn scan_rows(@builtin(global_invocation_id) id: vec3<u32>) {
    let res = sat_params.resolution;
    let row = id.x;
    let slot = id.y;
    if (row >= res || slot >= sat_params.slots) { return; }
    let base = (slot * res + row) * res;
    var acc = vec4<u32>(0u);
    for (var x = 0u; x < res; x++) {
        acc += quantize(textureLoad(optical, vec2<u32>(x, row), slot, 0));
        sat_out[base + x] = acc;
    }
}

// One invocation per (column, slot): prefix-sum the row sums down the column.
@compute @workgroup_size(64)
fn scan_columns(@builtin(global_invocation_id) id: vec3<u32>) {
    let res = sat_params.resolution;
    let column = id.x;
    let slot = id.y;
    if (column >= res || slot >= sat_params.slots) { return; }
    var acc = vec4<u32>(0u);
    for (var y = 0u; y < res; y++) {
        let i = (slot * res + y) * res + column;
        acc += sat_out[i];
        sat_out[i] = acc;
    }
}
