// K-buffer resolve: per pixel, the slots (already nearest first) composited with pre-multiplied
// "under"; counts the fragments kept.

struct ResolveParams {
    width: u32,
    height: u32,
    k: u32,
    _pad: u32,
};

const EMPTY_SLOT: u32 = 0xffffffffu;

@group(0) @binding(0) var<storage, read> slot_depths: array<u32>;
@group(0) @binding(1) var<storage, read> slot_colors: array<vec2<u32>>;
@group(0) @binding(2) var<storage, read_write> resolved: array<vec4<f32>>;
// [1]: fragments kept.
@group(0) @binding(3) var<storage, read_write> kbuffer_counters: array<atomic<u32>, 2>;
@group(0) @binding(4) var<uniform> params: ResolveParams;

@compute @workgroup_size(8, 8)
fn resolve(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= params.width || id.y >= params.height) { return; }
    let pixel = id.y * params.width + id.x;
    let base = pixel * params.k;
    var sum = vec4<f32>(0.0);
    var kept = 0u;
    for (var i = 0u; i < params.k; i++) {
        if (slot_depths[base + i] == EMPTY_SLOT) { break; }
        let packed = slot_colors[base + i];
        let color = vec4<f32>(unpack2x16float(packed.x), unpack2x16float(packed.y));
        sum += (1.0 - sum.a) * color;
        kept++;
    }
    if (kept > 0u) { atomicAdd(&kbuffer_counters[1], kept); }
    resolved[pixel] = sum;
}
