// A-buffer resolve: per pixel, the list's fragments sorted front to back (insertion sort keeping
// the nearest MAX_SORTED; the rest are counted as truncated) and composited with pre-multiplied "under".

struct Node {
    color: vec4<f32>,
    depth: f32,
    next: u32,
    _pad0: u32,
    _pad1: u32,
};

struct ResolveParams {
    width: u32,
    height: u32,
    _pad0: u32,
    _pad1: u32,
};

const END_OF_LIST: u32 = 0xffffffffu;
const MAX_SORTED: u32 = 64u;

@group(0) @binding(0) var<storage, read> heads: array<u32>;
@group(0) @binding(1) var<storage, read> nodes: array<Node>;
@group(0) @binding(2) var<storage, read_write> resolved: array<vec4<f32>>;
// Fragments beyond MAX_SORTED in one pixel, left out of the composite.
@group(0) @binding(3) var<storage, read_write> truncated: atomic<u32>;
@group(0) @binding(4) var<uniform> params: ResolveParams;
// DBK: the opaque fallback drawn beyond the layer (params._pad0 = 1); unused for the A-buffer.
@group(0) @binding(5) var fallback: texture_2d<f32>;

@compute @workgroup_size(8, 8)
fn resolve(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= params.width || id.y >= params.height) { return; }
    let pixel = id.y * params.width + id.x;
    var colors: array<vec4<f32>, MAX_SORTED>;
    var depths: array<f32, MAX_SORTED>;
    var count = 0u;
    var index = heads[pixel];
    loop {
        if (index == END_OF_LIST) { break; }
        let node = nodes[index];
        index = node.next;
        if (count == MAX_SORTED) {
            // Keep the nearest MAX_SORTED: the farther of this node and the farthest kept one
            // is the fragment left out.
            atomicAdd(&truncated, 1u);
            if (node.depth >= depths[MAX_SORTED - 1u]) { continue; }
            count = MAX_SORTED - 1u;
        }
        var j = count;
        while (j > 0u && depths[j - 1u] > node.depth) {
            depths[j] = depths[j - 1u];
            colors[j] = colors[j - 1u];
            j--;
        }
        depths[j] = node.depth;
        colors[j] = node.color;
        count++;
    }
    var sum = vec4<f32>(0.0);
    for (var k = 0u; k < count; k++) {
        sum += (1.0 - sum.a) * colors[k];
    }
    if (params._pad0 != 0u) {
        sum += (1.0 - sum.a) * textureLoad(fallback, vec2<i32>(id.xy), 0);
    }
    resolved[pixel] = sum;
}
