// Effective transmittance of an SRBF light through the convolution optical depth map (Ren 2010
// §5), view side. Bind group 1 of the env view pass and of the transmittance probe: the batch's
// lights (each with its light camera), the DODM nearest depths (one array layer per slot) and
// the summed-area tables of the cumulative optical depths (summed_area.wgsl).
//
// For a point x: project into the light's map; z0 at its texel; δ = z − z0; the averaging
// radius on the effective occlusion plane R = δ/2 · s (s from transmittance_filter.rs, carried in
// rgb.w: tan α of the G = 10⁻³ support for the paper's box); a square box of half-width R (in
// texels, blended between the two nearest texel boxes) averages each boundary's optical depth
// through the SAT; l(δ) interpolates linearly between (0, 0) and the boundaries (z_k, l̄_k); T̃ = exp(−l).
// Directional lights (tan α = 0) read the single texel: a plain per-light deep opacity map.
// With the visibility volume (visibility_volume.wgsl), SRBF lights do not come here.
#define_import_path strandlight::convolution_transmittance

struct EnvLightGpu {
    view_proj: mat4x4<f32>,
    // xyz: unit vector toward the light (ξ); w: 1/λ (0 for a directional light).
    direction: vec4<f32>,
    // xyz: the slot's first light's L_j or irradiance (the view shades `shading_samples`); w: the
    // box slope s (0 for a directional light).
    rgb: vec4<f32>,
    near: f32,
    far: f32,
    first_layer: f32,
    texels_per_unit: f32,
    // The lights shaded with this slot's visibility: shading_samples[first_sample ..+ count].
    first_sample: u32,
    sample_count: u32,
    _pad_a: u32,
    _pad_b: u32,
};

// One light as the view pass shades it (the slot's light itself, or one of the sub-texel lights
// of a reference texel that share the slot's shadow map).
struct ShadingSample {
    // xyz: unit vector toward the light; w: 1/λ (0 for a directional light).
    direction: vec4<f32>,
    // xyz: L_j (SRBF) or irradiance (directional).
    rgb: vec4<f32>,
    // xyz: EnvLight::power().
    power: vec4<f32>,
};

struct BatchParams {
    light_count: u32,
    resolution: u32,
    max_half_size: u32,
    // Bit 0: skip shadowing (T̃ = 1). Bit 1: a forward-scattering grid is bound.
    flags: u32,
};

@group(1) @binding(0) var<uniform> batch: BatchParams;
@group(1) @binding(1) var<storage, read> env_lights: array<EnvLightGpu>;
@group(1) @binding(2) var dodm_depth: texture_2d_array<f32>;
@group(1) @binding(3) var<storage, read> sat: array<vec4<u32>>;
@group(1) @binding(4) var<storage, read> shading_samples: array<ShadingSample>;
// The head's depth from each slot's light (head.wgsl; 1 where it is not drawn). Read only with
// FLAG_HEAD: frames without a head bind a 1×1 placeholder.
@group(1) @binding(5) var head_depth: texture_2d_array<f32>;

const SAT_FIXED_POINT_SCALE: f32 = 256.0;
const FLAG_UNSHADOWED: u32 = 1u;
const FLAG_GRID: u32 = 2u;
const FLAG_HEAD: u32 = 4u;

fn sat_at(slot: u32, x: i32, y: i32) -> vec4<u32> {
    if (x < 0 || y < 0) { return vec4<u32>(0u); }
    let res = batch.resolution;
    return sat[(slot * res + u32(y)) * res + u32(x)];
}

// Σ of the quantized texels in [lo, hi] (inclusive, clamped to the map), exact modulo 2³².
fn sat_box_sum(slot: u32, lo_in: vec2<i32>, hi_in: vec2<i32>) -> vec4<u32> {
    let last = i32(batch.resolution) - 1;
    let lo = clamp(lo_in, vec2<i32>(0), vec2<i32>(last));
    let hi = clamp(hi_in, vec2<i32>(0), vec2<i32>(last));
    // u32 arithmetic wraps: the partial sums may overflow, the box sum is exact.
    return sat_at(slot, hi.x, hi.y) - sat_at(slot, lo.x - 1, hi.y) - sat_at(slot, hi.x, lo.y - 1)
        + sat_at(slot, lo.x - 1, lo.y - 1);
}

fn box_area(lo_in: vec2<i32>, hi_in: vec2<i32>) -> f32 {
    let last = i32(batch.resolution) - 1;
    let lo = clamp(lo_in, vec2<i32>(0), vec2<i32>(last));
    let hi = clamp(hi_in, vec2<i32>(0), vec2<i32>(last));
    return f32((hi.x - lo.x + 1) * (hi.y - lo.y + 1));
}

// Optical depth at δ behind z0 from the cumulative depths at the boundaries d, 3d, 6d, 10d,
// linear in between (and from 0 at δ = 0); beyond 10d the last (everything) value.
fn layered_optical_depth(l: vec4<f32>, delta: f32, d: f32) -> f32 {
    var previous_z = 0.0;
    var previous_l = 0.0;
    for (var k = 0u; k < 4u; k++) {
        let z = f32((k + 1u) * (k + 2u) / 2u) * d;
        if (delta < z) {
            return mix(previous_l, l[k], (delta - previous_z) / (z - previous_z));
        }
        previous_z = z;
        previous_l = l[k];
    }
    return l.w;
}

// Mean of the quantized cumulative depths over the square of half-size h texels around
// `texel`: Ren 2010's convolution optical depth (exp(−mean τ), not the mean of exp(−τ), which
// measured farther from both references: docs/history, "Transmittance SATs").
fn box_mean(slot: u32, texel: vec2<i32>, h: i32) -> vec4<f32> {
    let lo = texel - vec2<i32>(h);
    let hi = texel + vec2<i32>(h);
    return vec4<f32>(sat_box_sum(slot, lo, hi)) / (box_area(lo, hi) * SAT_FIXED_POINT_SCALE);
}

// Texels searched around an empty texel for the hair's front (5 × 5).
const EMPTY_TEXEL_SEARCH: i32 = 2;

// The nearest depth within EMPTY_TEXEL_SEARCH texels of `texel` (1 when all are empty).
fn nearest_depth_around(slot: u32, texel: vec2<i32>) -> f32 {
    let last = i32(batch.resolution) - 1;
    var z0 = 1.0;
    for (var dy = -EMPTY_TEXEL_SEARCH; dy <= EMPTY_TEXEL_SEARCH; dy++) {
        for (var dx = -EMPTY_TEXEL_SEARCH; dx <= EMPTY_TEXEL_SEARCH; dx++) {
            let t = clamp(texel + vec2<i32>(dx, dy), vec2<i32>(0), vec2<i32>(last));
            z0 = min(z0, textureLoad(dodm_depth, t, i32(slot), 0).r);
        }
    }
    return z0;
}

// Taps per side of the head's percentage-closer filter.
const HEAD_TAPS: i32 = 5;

// The fraction of the light that passes the head: 0 behind it, 1 in front. A point sees the
// head's depth map over a box that widens with its distance behind the head as the lobe's box
// does with the distance behind the hair (R = δ/2 · slope; a directional light reads one
// texel), so that a broad lobe's head shadow is soft; 5 × 5 taps across the box, each opaque
// where the head is nearer the light than the point by more than two texels (the head's own
// surface, and the roots on it, must not shadow themselves).
fn head_transmittance(slot: u32, light: EnvLightGpu, uv: vec2<f32>, z: f32) -> f32 {
    if ((batch.flags & FLAG_HEAD) == 0u) { return 1.0; }
    let last = i32(batch.resolution) - 1;
    let texel = map_texel(uv);
    let bias = 2.0 / (light.texels_per_unit * (light.far - light.near));
    let centre = textureLoad(head_depth, texel, i32(slot), 0).r;
    let behind = max(z - centre, 0.0) * (light.far - light.near);
    let radius = min(0.5 * behind * light.rgb.w * light.texels_per_unit, f32(batch.max_half_size));
    if (radius < 0.5) {
        return select(1.0, 0.0, centre < z - bias);
    }
    var passed = 0.0;
    for (var j = 0; j < HEAD_TAPS; j++) {
        for (var i = 0; i < HEAD_TAPS; i++) {
            let offset = (vec2<f32>(f32(i), f32(j)) / f32(HEAD_TAPS - 1) * 2.0 - 1.0) * radius;
            let t = clamp(texel + vec2<i32>(round(offset)), vec2<i32>(0), vec2<i32>(last));
            let d = textureLoad(head_depth, t, i32(slot), 0).r;
            passed += select(1.0, 0.0, d < z - bias);
        }
    }
    return passed / f32(HEAD_TAPS * HEAD_TAPS);
}

// A light's map coordinates of a point it projects to `clip` (outside [0, 1)² off the map).
fn map_uv(clip: vec4<f32>) -> vec2<f32> {
    return vec2<f32>(0.5 + 0.5 * clip.x, 0.5 - 0.5 * clip.y);
}

// The texel of the slot's maps holding `uv` (in [0, 1)²).
fn map_texel(uv: vec2<f32>) -> vec2<i32> {
    return min(vec2<i32>(uv * f32(batch.resolution)), vec2<i32>(i32(batch.resolution) - 1));
}

fn effective_transmittance(slot: u32, world: vec3<f32>) -> f32 {
    if ((batch.flags & FLAG_UNSHADOWED) != 0u) { return 1.0; }
    // Loaded and projected once for the head and the hair.
    let light = env_lights[slot];
    let clip = light.view_proj * vec4<f32>(world, 1.0);
    let uv = map_uv(clip);
    if (any(uv < vec2<f32>(0.0)) || any(uv >= vec2<f32>(1.0))) { return 1.0; }
    let head = head_transmittance(slot, light, uv, clip.z);
    if (head <= 0.0) { return 0.0; }
    return head * hair_transmittance(slot, light, uv, clip.z);
}

// effective_transmittance of a compact source (a directional light, whose box follows its
// angular spread), as the layered view gathers it at samples along each segment and per source
// (segment_light_visibility.wgsl): an empty texel lets the light through instead of searching
// for the hair's front (the frame moves by 1e-4), and the head's filter is compiled in only
// `with_head` (a constant of the entry point). llvmpipe runs every branch, taken or not, the
// loops' first pass included: these two were most of the per-fragment gather's cost
// (docs/history/benchmarks-2026-12-05-to-12-06.md, "The compact sources' gather").
fn directional_transmittance(slot: u32, world: vec3<f32>, with_head: bool) -> f32 {
    if ((batch.flags & FLAG_UNSHADOWED) != 0u) { return 1.0; }
    let light = env_lights[slot];
    let clip = light.view_proj * vec4<f32>(world, 1.0);
    let uv = map_uv(clip);
    if (any(uv < vec2<f32>(0.0)) || any(uv >= vec2<f32>(1.0))) { return 1.0; }
    var head = 1.0;
    if (with_head) {
        head = head_transmittance(slot, light, uv, clip.z);
        if (head <= 0.0) { return 0.0; }
    }
    let texel = map_texel(uv);
    let z0 = textureLoad(dodm_depth, texel, i32(slot), 0).r;
    if (z0 >= 1.0) { return head; }
    return head * box_transmittance(slot, light, texel, z0, clip.z);
}

fn hair_transmittance(slot: u32, light: EnvLightGpu, uv: vec2<f32>, z: f32) -> f32 {
    let texel = map_texel(uv);
    var z0 = textureLoad(dodm_depth, texel, i32(slot), 0).r;
    if (z0 >= 1.0) {
        // Nothing drawn on this texel: the point's own fiber fell in a gap of the map (left out
        // by the simplification, or thinner than a texel). A one-texel box (directional light)
        // reads no depth there; an SRBF's box measures δ from the hair's front around it.
        if (light.rgb.w <= 0.0) { return 1.0; }
        z0 = nearest_depth_around(slot, texel);
        if (z0 >= 1.0) { return 1.0; }
    }
    return box_transmittance(slot, light, texel, z0, z);
}

// exp(−l(δ)) at depth z behind the hair's front z0 seen from `texel`.
fn box_transmittance(slot: u32, light: EnvLightGpu, texel: vec2<i32>, z0: f32, z: f32) -> f32 {
    let delta = max(z - z0, 0.0) * (light.far - light.near);
    // Continuous box half-width in texels (R = δ/2 · slope); the texel box of half-size h spans
    // h + 1/2 each side, so blend the two integer boxes around h = R − 1/2 (smooth in R).
    let radius = 0.5 * delta * light.rgb.w * light.texels_per_unit;
    let h = clamp(radius - 0.5, 0.0, f32(batch.max_half_size));
    let h0 = i32(floor(h));
    let f = h - f32(h0);
    var mean = box_mean(slot, texel, h0);
    if (f > 0.0 && h0 < i32(batch.max_half_size)) {
        mean = mix(mean, box_mean(slot, texel, h0 + 1), f);
    }
    return exp(-layered_optical_depth(mean, delta, light.first_layer));
}
