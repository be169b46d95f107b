// The head's skin in the point-lit frame (with strand_shading.wgsl's lights and maps): a
// Lambertian surface of albedo `skin.albedo.rgb` under the frame's lights, each seen through the
// hair's map and the head's own depth in it (shadow_transmittance, looked up two texels off the
// surface so that the head's depth does not shadow the skin it was drawn from). Radiance =
// albedo/π · Σ_i T_i · E_i · max(n·l_i, 0), with E_i and l_i as light_at gives them (falloff, spot
// cone) for the fibers. The hair composites over it (point_frame.rs).

#import strandlight::strand_quads::{frame, lights}
#import strandlight::strand_shading::{light_at, shadow_texel_at, shadow_transmittance}

struct SkinParams {
    albedo: vec4<f32>,
};

// head.wgsl's view targets: xyz world position (w: 1 on the head) and the normal toward the eye.
@group(3) @binding(0) var skin_position: texture_2d<f32>;
@group(3) @binding(1) var skin_normal: texture_2d<f32>;
@group(3) @binding(2) var<uniform> skin: SkinParams;

// One triangle over the whole target.
@vertex
fn vs_skin(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0);
}

@fragment
fn fs_skin(@builtin(position) pixel: vec4<f32>) -> @location(0) vec4<f32> {
    let p = vec2<i32>(pixel.xy);
    let head = textureLoad(skin_position, p, 0);
    if (head.w == 0.0) { discard; }
    let n = textureLoad(skin_normal, p, 0).xyz;
    var e = 0.0;
    for (var i = 0u; i < frame.light_count; i++) {
        let li = light_at(lights[i], head.xyz);
        let cosine = dot(n, li.xyz);
        if (cosine <= 0.0 || li.w <= 0.0) { continue; }
        let lift = 2.0 * shadow_texel_at(i, head.xyz);
        e += shadow_transmittance(i, head.xyz + n * lift) * li.w * cosine;
    }
    return vec4<f32>(skin.albedo.rgb * e / 3.141592654, 1.0);
}
