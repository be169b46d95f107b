// Deep opacity map layers (Yuksel & Keyser; Svoboda §4, Hunz §4): the strand quads
// (strand_quads.wgsl) drawn from the light's camera after a depth prepass that left the nearest
// fiber depth z0 per texel. Each fragment adds its optical depth τ = −ln(1 − α) (α: coverage ×
// opacity) to layer k = floor((d − d0) / spacing), the last layer taking everything beyond, so
// the transmittance in front of layer k is exp(−Σ_{j<k} layer_j) = Π(1 − α) of the fibers there.
// One pass fills the 8 layers first_layer.. (two RGBA targets, additive blending); more layers
// take more passes.

#import strandlight::strand_quads::{VertexOut, strand_draw_vertex}

@vertex
fn vs_main(@builtin(vertex_index) vertex: u32, @builtin(instance_index) instance: u32) -> VertexOut {
    return strand_draw_vertex(vertex, instance);
}

struct DomParams {
    near: f32,
    far: f32,
    spacing: f32,
    layers: u32,
    // 1: a point or spot light's perspective camera (depths are linearized).
    perspective: u32,
    // The first layer this pass writes.
    first_layer: u32,
    _pad1: u32,
    _pad2: u32,
};

@group(1) @binding(0) var nearest_depth: texture_depth_2d;
@group(1) @binding(1) var<uniform> dom: DomParams;

struct Layers {
    @location(0) first: vec4<f32>,
    @location(1) second: vec4<f32>,
};

// The largest α a fragment may carry: an opaque fiber still lets exp(−6.9) ≈ 0.1% through,
// which keeps τ finite.
const MAX_ALPHA: f32 = 0.999;

// Distance along the light camera's axis from a depth-buffer value (wgpu's 0..1 depth of glam's
// "directx" projections).
fn dom_depth(z: f32) -> f32 {
    if (dom.perspective != 0u) {
        return dom.far * dom.near / (dom.far - z * (dom.far - dom.near));
    }
    return dom.near + z * (dom.far - dom.near);
}

@fragment
fn fs_layers(in: VertexOut) -> Layers {
    let z0 = textureLoad(nearest_depth, vec2<i32>(in.clip.xy), 0);
    let d0 = dom_depth(z0);
    let d = dom_depth(in.clip.z);
    let k = min(u32(max(d - d0, 0.0) / dom.spacing), dom.layers - 1u);
    let tau = -log(1.0 - min(in.alpha, MAX_ALPHA));
    var out: Layers;
    out.first = vec4<f32>(0.0);
    out.second = vec4<f32>(0.0);
    // Another pass's layer: add nothing here (a discard would cost the same).
    if (k < dom.first_layer || k >= dom.first_layer + 8u) {
        return out;
    }
    let slot = k - dom.first_layer;
    if (slot < 4u) {
        out.first[slot] = tau;
    } else {
        out.second[slot - 4u] = tau;
    }
    return out;
}
