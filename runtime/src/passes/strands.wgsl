// Shading of the strand quads (strand_quads.wgsl) under several lights, written with
// pre-multiplied alpha. The fiber model is `fiber_radiance`, defined by one of the fiber_*.wgsl
// files appended after this one (Kajiya-Kay, Marschner through lookup tables, artist-friendly).

// Deep opacity maps of up to four directional lights (Svoboda §4, Hunz §4); slot k shadows light
// shadow[k].light_index, 0xffffffff: an unused slot (a 1×1 placeholder map is bound there).
struct ShadowParams {
    view_proj: mat4x4<f32>,
    near: f32,
    far: f32,
    spacing: f32,
    layers: u32,
    light_index: u32,
    resolution: f32,
    _pad0: f32,
    _pad1: f32,
};

const SHADOW_SLOTS: u32 = 4u;

@group(1) @binding(0) var shadow_depth_0: texture_depth_2d;
@group(1) @binding(1) var shadow_layers_a_0: texture_2d<f32>;
@group(1) @binding(2) var shadow_layers_b_0: texture_2d<f32>;
@group(1) @binding(3) var shadow_depth_1: texture_depth_2d;
@group(1) @binding(4) var shadow_layers_a_1: texture_2d<f32>;
@group(1) @binding(5) var shadow_layers_b_1: texture_2d<f32>;
@group(1) @binding(6) var shadow_depth_2: texture_depth_2d;
@group(1) @binding(7) var shadow_layers_a_2: texture_2d<f32>;
@group(1) @binding(8) var shadow_layers_b_2: texture_2d<f32>;
@group(1) @binding(9) var shadow_depth_3: texture_depth_2d;
@group(1) @binding(10) var shadow_layers_a_3: texture_2d<f32>;
@group(1) @binding(11) var shadow_layers_b_3: texture_2d<f32>;
@group(1) @binding(12) var<uniform> shadow: array<ShadowParams, 4>;

fn layer_value(a: vec4<f32>, b: vec4<f32>, k: u32) -> f32 {
    if (k < 4u) { return a[k]; }
    return b[k - 4u];
}

// exp(−optical depth in front of `world`) in one map: the layers before its own, plus the part
// of its own layer in front of it (linear within the layer), the last layer being spread over
// one spacing.
fn map_transmittance(
    depth: texture_depth_2d,
    layers_a: texture_2d<f32>,
    layers_b: texture_2d<f32>,
    p: ShadowParams,
    world: vec3<f32>,
) -> f32 {
    let clip = p.view_proj * vec4<f32>(world, 1.0);
    let uv = vec2<f32>(0.5 + 0.5 * clip.x, 0.5 - 0.5 * clip.y);
    if (any(uv < vec2<f32>(0.0)) || any(uv >= vec2<f32>(1.0))) { return 1.0; }
    let texel = vec2<i32>(uv * p.resolution);
    let z0 = textureLoad(depth, texel, 0);
    if (z0 >= 1.0) { return 1.0; }
    let d0 = p.near + z0 * (p.far - p.near);
    let d = p.near + clip.z * (p.far - p.near);
    let position = max(d - d0, 0.0) / p.spacing;
    let a = textureLoad(layers_a, texel, 0);
    let b = textureLoad(layers_b, texel, 0);
    var tau = 0.0;
    for (var k = 0u; k < p.layers; k++) {
        let fraction = clamp(position - f32(k), 0.0, 1.0);
        tau += fraction * layer_value(a, b, k);
    }
    return exp(-tau);
}

// The fraction of light `light_index` that reaches `world`: 1 unless a slot shadows that light.
fn shadow_transmittance(light_index: u32, world: vec3<f32>) -> f32 {
    if (shadow[0].light_index == light_index) {
        return map_transmittance(shadow_depth_0, shadow_layers_a_0, shadow_layers_b_0, shadow[0], world);
    }
    if (shadow[1].light_index == light_index) {
        return map_transmittance(shadow_depth_1, shadow_layers_a_1, shadow_layers_b_1, shadow[1], world);
    }
    if (shadow[2].light_index == light_index) {
        return map_transmittance(shadow_depth_2, shadow_layers_a_2, shadow_layers_b_2, shadow[2], world);
    }
    if (shadow[3].light_index == light_index) {
        return map_transmittance(shadow_depth_3, shadow_layers_a_3, shadow_layers_b_3, shadow[3], world);
    }
    return 1.0;
}

// Direction toward the light and the irradiance it brings to `world`.
fn light_at(light: Light, world: vec3<f32>) -> vec4<f32> {
    let kind = light.position_or_direction.w;
    if (kind < 0.5) {
        return vec4<f32>(light.position_or_direction.xyz, light.intensity.x);
    }
    let to_light = light.position_or_direction.xyz - world;
    let d2 = max(dot(to_light, to_light), 1e-12);
    let l = to_light * inverseSqrt(d2);
    var e = light.intensity.x / d2;
    if (kind > 1.5 && dot(-l, light.spot.xyz) < light.spot.w) { e = 0.0; }
    return vec4<f32>(l, e);
}

// The fragment's pre-multiplied shaded colour (Svoboda §2.5).
fn shade(in: VertexOut) -> vec4<f32> {
    let t = normalize(in.tangent);
    var e = frame.toward_eye.xyz;
    if (frame.eye.w > 0.5) { e = normalize(frame.eye.xyz - in.world); }
    var radiance = vec3<f32>(0.0);
    for (var i = 0u; i < frame.light_count; i++) {
        let li = light_at(lights[i], in.world);
        let visible = shadow_transmittance(i, in.world);
        radiance += visible * li.w * fiber_radiance(t, li.xyz, e, in.color);
    }
    return vec4<f32>(radiance * in.alpha, in.alpha);
}

// Blended in draw order with "one, one − source alpha".
@fragment
fn fs_main(in: VertexOut) -> @location(0) vec4<f32> {
    return shade(in);
}
