// Shading of the strand quads (strand_quads.wgsl) under several lights, written with
// pre-multiplied alpha. The fiber model is `fiber_radiance`, defined by one of the fiber_*.wgsl
// files appended after this one (Kajiya-Kay, Marschner through lookup tables, artist-friendly).

// Deep opacity map of one directional light (Svoboda §4, Hunz §4); light_index = 0xffffffff: none.
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

@group(1) @binding(0) var shadow_depth: texture_depth_2d;
@group(1) @binding(1) var shadow_layers_a: texture_2d<f32>;
@group(1) @binding(2) var shadow_layers_b: texture_2d<f32>;
@group(1) @binding(3) var<uniform> shadow: ShadowParams;

fn layer_value(a: vec4<f32>, b: vec4<f32>, k: u32) -> f32 {
    if (k < 4u) { return a[k]; }
    return b[k - 4u];
}

// exp(−optical depth in front of `world`): the layers before its own, plus the part of its own
// layer in front of it (linear within the layer), the last layer being spread over one spacing.
fn shadow_transmittance(world: vec3<f32>) -> f32 {
    let clip = shadow.view_proj * vec4<f32>(world, 1.0);
    let uv = vec2<f32>(0.5 + 0.5 * clip.x, 0.5 - 0.5 * clip.y);
    if (any(uv < vec2<f32>(0.0)) || any(uv >= vec2<f32>(1.0))) { return 1.0; }
    let texel = vec2<i32>(uv * shadow.resolution);
    let z0 = textureLoad(shadow_depth, texel, 0);
    if (z0 >= 1.0) { return 1.0; }
    let d0 = shadow.near + z0 * (shadow.far - shadow.near);
    let d = shadow.near + clip.z * (shadow.far - shadow.near);
    let position = max(d - d0, 0.0) / shadow.spacing;
    let a = textureLoad(shadow_layers_a, texel, 0);
    let b = textureLoad(shadow_layers_b, texel, 0);
    var tau = 0.0;
    for (var k = 0u; k < shadow.layers; k++) {
        let fraction = clamp(position - f32(k), 0.0, 1.0);
        tau += fraction * layer_value(a, b, k);
    }
    return exp(-tau);
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
        var visible = 1.0;
        if (i == shadow.light_index) { visible = shadow_transmittance(in.world); }
        radiance += visible * li.w * fiber_radiance(t, li.xyz, e, in.color);
    }
    return vec4<f32>(radiance * in.alpha, in.alpha);
}

// Blended in draw order with "one, one − source alpha".
@fragment
fn fs_main(in: VertexOut) -> @location(0) vec4<f32> {
    return shade(in);
}
