// Random subsets resolve (Hunz §5.4): per pixel, the k subset images' nearest fragments sorted
// by depth and composited front to back with pre-multiplied "under".

struct ResolveParams {
    width: u32,
    height: u32,
    subsets: u32,
    _pad: u32,
};

const MAX_SUBSETS: u32 = 16u;

@group(0) @binding(0) var subset_colors: texture_2d_array<f32>;
@group(0) @binding(1) var subset_depths: texture_depth_2d_array;
@group(0) @binding(2) var<storage, read_write> resolved: array<vec4<f32>>;
@group(0) @binding(3) var<uniform> params: ResolveParams;

@compute @workgroup_size(8, 8)
fn resolve(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= params.width || id.y >= params.height) { return; }
    let texel = vec2<i32>(id.xy);
    var colors: array<vec4<f32>, MAX_SUBSETS>;
    var depths: array<f32, MAX_SUBSETS>;
    var count = 0u;
    for (var s = 0u; s < params.subsets; s++) {
        let depth = textureLoad(subset_depths, texel, i32(s), 0);
        if (depth >= 1.0) { continue; }
        let color = textureLoad(subset_colors, texel, i32(s), 0);
        var j = count;
        while (j > 0u && depths[j - 1u] > depth) {
            depths[j] = depths[j - 1u];
            colors[j] = colors[j - 1u];
            j--;
        }
        depths[j] = depth;
        colors[j] = color;
        count++;
    }
    var sum = vec4<f32>(0.0);
    for (var k = 0u; k < count; k++) {
        sum += (1.0 - sum.a) * colors[k];
    }
    resolved[id.y * params.width + id.x] = sum;
}
