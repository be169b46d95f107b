// Test hook: evaluates the view pass's own effective_transmittance and sat_box_sum
// (convolution_transmittance.wgsl) at given points / boxes.

#import strandlight::convolution_transmittance::{effective_transmittance, sat_box_sum}

struct ProbePoint {
    // xyz: world position; w: light slot (as f32).
    position: vec4<f32>,
};

struct ProbeBox {
    // x0, y0, x1, y1 (inclusive texels).
    corners: vec4<i32>,
    slot: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
};

@group(0) @binding(0) var<storage, read> probe_points: array<ProbePoint>;
@group(0) @binding(1) var<storage, read_write> probe_transmittance_out: array<f32>;
@group(0) @binding(2) var<storage, read> probe_boxes: array<ProbeBox>;
@group(0) @binding(3) var<storage, read_write> probe_box_out: array<vec4<u32>>;

// No fiber here: lobe spread's directions weigh the same.
fn spread_weight(omega: vec3<f32>, t: vec3<f32>, e: vec3<f32>) -> f32 {
    return 1.0;
}

@compute @workgroup_size(64)
fn probe_transmittance(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= arrayLength(&probe_points)) { return; }
    let p = probe_points[id.x].position;
    probe_transmittance_out[id.x] = effective_transmittance(u32(p.w), p.xyz);
}

@compute @workgroup_size(64)
fn probe_box_sums(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= arrayLength(&probe_boxes)) { return; }
    let b = probe_boxes[id.x];
    probe_box_out[id.x] = sat_box_sum(b.slot, b.corners.xy, b.corners.zw);
}
