// Shading of the strand quads (strand_quads.wgsl) under several lights, written with
// pre-multiplied alpha. The fiber model is `fiber_radiance` of the module composed as
// `strandlight::fiber_model` (one of the fiber_*.wgsl files: Kajiya-Kay, Marschner or Chiang
// through lookup tables, artist-friendly; fiber_shading.rs).

#define_import_path strandlight::strand_shading

#import strandlight::fiber_model::fiber_radiance
#import strandlight::strand_quads::{Light, VertexOut, frame, lights}

// The maps of up to four lights (Svoboda §4, Hunz §4); slot k shadows light
// shadow[k].light_index, 0xffffffff: an unused slot (a 1×1 placeholder map is bound there).
// A slot holds one frustum (face 0) or a cube's six faces (+x, −x, +y, −y, +z, −z around a point
// light; shadow_layout.rs), each face a group of array layers of the same textures.
struct ShadowParams {
    view_proj: array<mat4x4<f32>, 6>,
    // xyz: a cube's light position; w: faces (1 or 6).
    cube: vec4<f32>,
    near: f32,
    far: f32,
    spacing: f32,
    layers: u32,
    light_index: u32,
    resolution: f32,
    // LOOKUP_*.
    lookup: u32,
    // 1: a point or spot light's perspective camera.
    perspective: u32,
    // Shadow map and ADSM: PCF kernel (texels per side), bias (world units along the light).
    kernel: u32,
    bias: f32,
    // ADSM: one fiber of this opacity every adsm_spacing world units behind the nearest one.
    adsm_alpha: f32,
    adsm_spacing: f32,
    // Array layers of shadow_layers_k per face.
    face_array_layers: u32,
    // First layer of this slot's faces in head_light_depth; NO_HEAD_LAYER: no head.
    head_layer: u32,
    // World size of one map texel: at unit depth along the light (perspective), or anywhere.
    texel_world: f32,
    _pad_a: u32,
};

const LOOKUP_LAYERS: u32 = 0u;
const LOOKUP_HARD: u32 = 1u;
const LOOKUP_ADSM: u32 = 2u;

const SHADOW_SLOTS: u32 = 4u;

@group(1) @binding(0) var shadow_depth_0: texture_depth_2d_array;
@group(1) @binding(1) var shadow_layers_0: texture_2d_array<f32>;
@group(1) @binding(2) var shadow_depth_1: texture_depth_2d_array;
@group(1) @binding(3) var shadow_layers_1: texture_2d_array<f32>;
@group(1) @binding(4) var shadow_depth_2: texture_depth_2d_array;
@group(1) @binding(5) var shadow_layers_2: texture_2d_array<f32>;
@group(1) @binding(6) var shadow_depth_3: texture_depth_2d_array;
@group(1) @binding(7) var shadow_layers_3: texture_2d_array<f32>;
@group(1) @binding(8) var<uniform> shadow: array<ShadowParams, 4>;

// The head (issue 40), opaque to every light and to the view (head.wgsl draws both depths): its
// depth in the light maps' 0..1 range, one layer per face of each slot, and from the frame's
// camera. 1×1 placeholders, never read, without a head.
const NO_HEAD_LAYER: u32 = 0xffffffffu;

struct HeadView {
    // 1: the view has a head; fibers behind it are not drawn.
    in_view: u32,
    _pad_a: u32,
    _pad_b: u32,
    _pad_c: u32,
};

@group(1) @binding(9) var head_light_depth: texture_2d_array<f32>;
@group(1) @binding(10) var head_view_depth: texture_depth_2d;
@group(1) @binding(11) var<uniform> head_view: HeadView;

// Whether the fragment lies behind the head along its pixel's ray. Every transparency mode's
// fragment entry point drops such fragments, since most of them draw without a depth test.
fn behind_head(in: VertexOut) -> bool {
    if (head_view.in_view == 0u) { return false; }
    return in.clip.z > textureLoad(head_view_depth, vec2<i32>(in.clip.xy), 0);
}

// Distance along the light camera's axis from a depth-buffer value.
fn light_depth(p: ShadowParams, z: f32) -> f32 {
    if (p.perspective != 0u) {
        return p.far * p.near / (p.far - z * (p.far - p.near));
    }
    return p.near + z * (p.far - p.near);
}

// The face of a slot's maps that holds `world`: 0 for a frustum; for a cube the dominant axis of
// (world − light) and its sign, ties going to x before y before z (CubeLight::face_of).
fn shadow_face(p: ShadowParams, world: vec3<f32>) -> u32 {
    if (p.cube.w < 1.5) { return 0u; }
    let d = world - p.cube.xyz;
    let a = abs(d);
    if (a.x >= a.y && a.x >= a.z) { return select(0u, 1u, d.x < 0.0); }
    if (a.y >= a.z) { return select(2u, 3u, d.y < 0.0); }
    return select(4u, 5u, d.z < 0.0);
}

// One face of a slot's maps: the face index and its first array layer of the layer texture.
struct Face {
    index: u32,
    first_layer: u32,
};

// The light a fragment at light depth `d` receives past one texel's nearest fiber: a hard test
// (shadow map) or TressFX's fiber count (ADSM).
fn depth_test_texel(
    depth: texture_depth_2d_array,
    face: Face,
    texel: vec2<i32>,
    d: f32,
    p: ShadowParams,
) -> f32 {
    let z0 = textureLoad(depth, texel, face.index, 0);
    if (z0 >= 1.0) { return 1.0; }
    let behind = d - light_depth(p, z0) - p.bias;
    if (behind <= 0.0) { return 1.0; }
    if (p.lookup == LOOKUP_HARD) { return 0.0; }
    return pow(1.0 - p.adsm_alpha, 1.0 + behind / p.adsm_spacing);
}

// Percentage-closer filtering: the depth test averaged over kernel × kernel texels (clamped at
// the map's edges, a cube face's too: the kernel does not cross onto the next face).
fn filtered_depth_test(
    depth: texture_depth_2d_array,
    face: Face,
    texel: vec2<i32>,
    d: f32,
    p: ShadowParams,
) -> f32 {
    let r = i32(p.kernel / 2u);
    let last = vec2<i32>(textureDimensions(depth)) - vec2<i32>(1);
    var sum = 0.0;
    for (var dy = -r; dy <= r; dy++) {
        for (var dx = -r; dx <= r; dx++) {
            let t = clamp(texel + vec2<i32>(dx, dy), vec2<i32>(0), last);
            sum += depth_test_texel(depth, face, t, d, p);
        }
    }
    let side = f32(2 * r + 1);
    return sum / (side * side);
}

// The fraction of the light that reaches `world` through one map. Layers: exp(−optical depth in
// front of it), the layers before its own plus the part of its own layer in front of it (linear
// within the layer), the last layer being spread over one spacing.
fn map_transmittance(
    depth: texture_depth_2d_array,
    layers: texture_2d_array<f32>,
    p: ShadowParams,
    world: vec3<f32>,
) -> f32 {
    let index = shadow_face(p, world);
    let face = Face(index, index * p.face_array_layers);
    let clip = p.view_proj[index] * vec4<f32>(world, 1.0);
    if (clip.w <= 0.0) { return 1.0; }
    let ndc = clip.xyz / clip.w;
    let uv = vec2<f32>(0.5 + 0.5 * ndc.x, 0.5 - 0.5 * ndc.y);
    // Outside a frustum the light is unshadowed; a cube face holds its point up to rounding at
    // the seams, so its texel is clamped onto the face instead.
    let outside = any(uv < vec2<f32>(0.0)) || any(uv >= vec2<f32>(1.0));
    if (outside && p.cube.w < 1.5) { return 1.0; }
    let last = vec2<i32>(textureDimensions(depth)) - vec2<i32>(1);
    let texel = clamp(vec2<i32>(floor(uv * p.resolution)), vec2<i32>(0), last);
    let d = light_depth(p, ndc.z);
    let past_head = head_visibility(p, face, texel, d);
    if (past_head <= 0.0) { return 0.0; }
    if (p.lookup != LOOKUP_LAYERS) { return past_head * filtered_depth_test(depth, face, texel, d, p); }
    // PCF: the transmittance of each texel in the kernel, averaged (clamped at the edges).
    let r = i32(p.kernel / 2u);
    var sum = 0.0;
    for (var dy = -r; dy <= r; dy++) {
        for (var dx = -r; dx <= r; dx++) {
            let t = clamp(texel + vec2<i32>(dx, dy), vec2<i32>(0), last);
            sum += layer_transmittance(depth, layers, p, face, t, d);
        }
    }
    let side = f32(2 * r + 1);
    return past_head * sum / (side * side);
}

// World size of one of the slot's map texels at light depth `d`.
fn texel_size(p: ShadowParams, d: f32) -> f32 {
    if (p.perspective != 0u) { return p.texel_world * d; }
    return p.texel_world;
}

// The fraction of the slot's kernel (PCF, as the hair's lookup) whose texel sees no head in
// front of light depth `d`. The head is opaque: past its nearest depth nothing arrives. Two
// texels of bias keep what lies on the surface facing the light (the roots, the skin) lit.
fn head_visibility(p: ShadowParams, face: Face, texel: vec2<i32>, d: f32) -> f32 {
    if (p.head_layer == NO_HEAD_LAYER) { return 1.0; }
    let bias = 2.0 * texel_size(p, d);
    let r = i32(p.kernel / 2u);
    let last = vec2<i32>(textureDimensions(head_light_depth)) - vec2<i32>(1);
    var sum = 0.0;
    for (var dy = -r; dy <= r; dy++) {
        for (var dx = -r; dx <= r; dx++) {
            let t = clamp(texel + vec2<i32>(dx, dy), vec2<i32>(0), last);
            let z = textureLoad(head_light_depth, t, p.head_layer + face.index, 0).r;
            if (z >= 1.0 || d - light_depth(p, z) <= bias) { sum += 1.0; }
        }
    }
    let side = f32(2 * r + 1);
    return sum / (side * side);
}

// Transmittance at light depth `d` through one texel's layers.
fn layer_transmittance(
    depth: texture_depth_2d_array,
    layers: texture_2d_array<f32>,
    p: ShadowParams,
    face: Face,
    texel: vec2<i32>,
    d: f32,
) -> f32 {
    let z0 = textureLoad(depth, texel, face.index, 0);
    if (z0 >= 1.0) { return 1.0; }
    let d0 = light_depth(p, z0);
    let position = max(d - d0, 0.0) / p.spacing;
    // Layer k is channel k % 4 of the face's array layer k / 4; only the layers in front are
    // read.
    let reached = min(p.layers, u32(ceil(position)));
    var tau = 0.0;
    for (var group = 0u; group * 4u < reached; group++) {
        let four = textureLoad(layers, texel, face.first_layer + group, 0);
        for (var c = 0u; c < 4u; c++) {
            let k = group * 4u + c;
            tau += clamp(position - f32(k), 0.0, 1.0) * four[c];
        }
    }
    return exp(-tau);
}

// The fraction of light `light_index` that reaches `world`: 1 unless a slot shadows that light.
fn shadow_transmittance(light_index: u32, world: vec3<f32>) -> f32 {
    if (shadow[0].light_index == light_index) {
        return map_transmittance(shadow_depth_0, shadow_layers_0, shadow[0], world);
    }
    if (shadow[1].light_index == light_index) {
        return map_transmittance(shadow_depth_1, shadow_layers_1, shadow[1], world);
    }
    if (shadow[2].light_index == light_index) {
        return map_transmittance(shadow_depth_2, shadow_layers_2, shadow[2], world);
    }
    if (shadow[3].light_index == light_index) {
        return map_transmittance(shadow_depth_3, shadow_layers_3, shadow[3], world);
    }
    return 1.0;
}

// World size of one texel of the map that shadows light `light_index` at `world` (0: none), to
// lift a surface's lookup off the depth it was drawn into itself.
fn shadow_texel_at(light_index: u32, world: vec3<f32>) -> f32 {
    for (var k = 0u; k < SHADOW_SLOTS; k++) {
        let p = shadow[k];
        if (p.light_index != light_index) { continue; }
        let clip = p.view_proj[shadow_face(p, world)] * vec4<f32>(world, 1.0);
        if (clip.w <= 0.0) { return 0.0; }
        return texel_size(p, light_depth(p, clip.z / clip.w));
    }
    return 0.0;
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
