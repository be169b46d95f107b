// A-buffer build (appended to strand_quads.wgsl + strands.wgsl): every shaded fragment goes into
// a per-pixel linked list in storage buffers (WebGPU has no fragment interlock, so lists are
// built with atomics and sorted at resolve). A full node buffer drops the fragment and counts it.

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

@group(2) @binding(0) var<storage, read_write> heads: array<atomic<u32>>;
@group(2) @binding(1) var<storage, read_write> nodes: array<Node>;
// [0]: nodes requested, [1]: fragments dropped because the node buffer was full.
@group(2) @binding(2) var<storage, read_write> counters: array<atomic<u32>, 2>;
@group(2) @binding(3) var<uniform> abuffer: ABufferParams;

@fragment
fn fs_abuffer(in: VertexOut) {
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
