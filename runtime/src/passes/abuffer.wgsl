// A-buffer build (the strands shaded by strand_shading.wgsl and the fiber model, which holds
// group 2, so the lists are group 3): every shaded fragment goes into
// a per-pixel linked list in storage buffers (WebGPU has no fragment interlock, so lists are
// built with atomics and sorted at resolve). A full node buffer drops the fragment and counts it.

#import strandlight::strand_quads::{VertexOut, strand_draw_vertex}
#import strandlight::strand_shading::{behind_head, shade}

@vertex
fn vs_main(@builtin(vertex_index) vertex: u32, @builtin(instance_index) instance: u32) -> VertexOut {
    return strand_draw_vertex(vertex, instance);
}

struct Node {
    color: vec4<f32>,
    depth: f32,
    next: u32,
    _pad0: u32,
    _pad1: u32,
};

struct ABufferParams {
    width: u32,
    capacity: u32,
    _pad0: u32,
    _pad1: u32,
};

const END_OF_LIST: u32 = 0xffffffffu;

@group(3) @binding(0) var<storage, read_write> heads: array<atomic<u32>>;
@group(3) @binding(1) var<storage, read_write> nodes: array<Node>;
// [0]: nodes requested, [1]: fragments dropped because the node buffer was full.
@group(3) @binding(2) var<storage, read_write> counters: array<atomic<u32>, 2>;
@group(3) @binding(3) var<uniform> abuffer: ABufferParams;

@fragment
fn fs_abuffer(in: VertexOut) {
    if (behind_head(in)) { return; }
    let color = shade(in);
    if (color.a <= 0.0) { return; }
    let index = atomicAdd(&counters[0], 1u);
    if (index >= abuffer.capacity) {
        atomicAdd(&counters[1], 1u);
        return;
    }
    let pixel = u32(in.clip.y) * abuffer.width + u32(in.clip.x);
    nodes[index].color = color;
    nodes[index].depth = in.clip.z;
    nodes[index].next = atomicExchange(&heads[pixel], index);
}

// DBK-buffer (Hunz §5.3): after a depth prepass left the nearest depth z0 per pixel, fragments
// within [z0, z0 + delta] (view depth, world units) go into the lists; the others are drawn
// depth-tested into an opaque fallback target that the resolve puts under the sorted layer.

struct DbkParams {
    near: f32,
    far: f32,
    delta: f32,
    perspective: u32,
};

// Bindings 4-5 of the lists' group: wgpu allows four groups and the model takes the third.
@group(3) @binding(4) var view_nearest: texture_depth_2d;
@group(3) @binding(5) var<uniform> dbk: DbkParams;

// View depth from a depth-buffer value (wgpu's 0..1 depth of glam's "directx" projections).
fn view_depth(z: f32) -> f32 {
    if (dbk.perspective != 0u) {
        return dbk.far * dbk.near / (dbk.far - z * (dbk.far - dbk.near));
    }
    return dbk.near + z * (dbk.far - dbk.near);
}

@fragment
fn fs_dbk(in: VertexOut) -> @location(0) vec4<f32> {
    if (behind_head(in)) { discard; }
    let color = shade(in);
    let z0 = textureLoad(view_nearest, vec2<i32>(in.clip.xy), 0);
    if (view_depth(in.clip.z) <= view_depth(z0) + dbk.delta) {
        if (color.a > 0.0) {
            let index = atomicAdd(&counters[0], 1u);
            if (index >= abuffer.capacity) {
                atomicAdd(&counters[1], 1u);
            } else {
                let pixel = u32(in.clip.y) * abuffer.width + u32(in.clip.x);
                nodes[index].color = color;
                nodes[index].depth = in.clip.z;
                nodes[index].next = atomicExchange(&heads[pixel], index);
            }
        }
        discard;
    }
    return color;
}
