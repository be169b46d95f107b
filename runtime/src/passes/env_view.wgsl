// The env-lit view pass (Ren 2010 §3.1, §5, §6), appended to strand_quads.wgsl, fiber_frame.wgsl,
// convolution_transmittance.wgsl and occupancy_map.wgsl: every fragment loops over the batch's
// light slots (one shadow map each) and each slot's shading samples (the light itself, or the
// reference's sub-texel lights sharing the slot's visibility), and sums
//   single:   T̃_j(x) · I(u·ξ_j, u·ω_o, cos Δφ, 1/λ_j) · L_j
//   multiple: power_j · T_f,j(x) · I_G(u·ξ_j, u·ω_o, cos Δφ, σ̄_f,j(x))
// writing each, weighted by what the viewer sees of the fragment, into its own target. For
// directional lights `I` is the direct table S·cos θ_i (its fourth axis has one node) and L_j the
// irradiance. Tables are strandlight `Table`s (row-major, channels innermost, RGB) uploaded as-is
// and interpolated quadrilinearly exactly like `Table::lookup`.
//
// Two entry points, one per view transparency (view_visibility.rs):
//   fs_env_deferred:    a full-screen pass over the nearest fiber of each pixel, which the depth
//                       prepass left in two textures (position, tangent); its radiance stands
//                       for the pixel's, weighted by the coverage of all its fibers,
//                       1 − exp(−Σ τ). No strand is rasterized again per batch of lights.
//   fs_env_transparent: every fragment is weighted by coverage × its visibility through the
//                       fragments in front (the occupancy map) and added; fragments that can no
//                       longer contribute stop before any light is evaluated (early termination).

struct TableLayout {
    axes: array<TableAxis, 4>,
    // Element strides of the four axes.
    strides: vec4<u32>,
};

// Group 3: what the view pass reads besides lights and tables: the batch's forward-scattering
// grid and the frame's occupancy map.
struct ViewParams {
    // Grid: xyz the world position of vertex (0,0,0).
    origin: vec4<f32>,
    // Grid: xyz the spacing between vertices.
    spacing: vec4<f32>,
    // Grid: xyz the vertices per axis.
    dims: vec4<u32>,
    // Image width and height (occupancy records).
    width: u32,
    height: u32,
    // Fragments seen less than this stop before shading (transparent view).
    visibility_cutoff: f32,
    // u32 per pixel of `occupancy_map` (occupancy_map.wgsl).
    record_words: u32,
    // rgb: the head's skin albedo; w: 1 where the frame has a head (skin.wgsl).
    skin: vec4<f32>,
    // Clip space to world: the layered view puts each layer's fibers back on its pixel's ray.
    clip_to_world: mat4x4<f32>,
};

@group(2) @binding(0) var<uniform> single_layout: TableLayout;
@group(2) @binding(1) var<storage, read> single_table: array<f32>;
@group(2) @binding(2) var<uniform> multiple_layout: TableLayout;
@group(2) @binding(3) var<storage, read> multiple_table: array<f32>;
@group(3) @binding(0) var<uniform> view: ViewParams;
@group(3) @binding(1) var<storage, read> grid_values: array<vec4<f32>>;
@group(3) @binding(2) var<storage, read_write> occupancy_map: array<atomic<u32>>;
// Red: the optical depth Σ −ln(1 − α) of all the pixel's fragments (opaque view).
@group(3) @binding(3) var coverage: texture_2d<f32>;
// The nearest fiber of each pixel (opaque view, fs_nearest_surface): xyz its world position,
// w 1 where the pixel holds hair; and its (unnormalized) tangent.
@group(3) @binding(4) var nearest_position: texture_2d<f32>;
@group(3) @binding(5) var nearest_tangent: texture_2d<f32>;
// The head seen from the view (head.wgsl): xyz its world position, w 1 on the head; its normal.
@group(3) @binding(8) var head_position: texture_2d<f32>;
@group(3) @binding(9) var head_normal: texture_2d<f32>;

// The 16 corners of a 4D cell: base offset, per-axis steps (0 on one-node axes), weights.
struct Cell4 {
    base: u32,
    step: vec4<u32>,
    w: vec4<f32>,
};

fn cell4(t: TableLayout, coords: vec4<f32>) -> Cell4 {
    var out: Cell4;
    out.base = 0u;
    for (var k = 0u; k < 4u; k++) {
        let c = table_cell(t.axes[k], coords[k]);
        out.base += c.lower * t.strides[k];
        out.w[k] = c.upper_weight;
        out.step[k] = select(0u, t.strides[k], t.axes[k].last_index >= 1.0);
    }
    return out;
}

fn corner_weight(c: Cell4, corner: u32) -> f32 {
    var weight = 1.0;
    for (var k = 0u; k < 4u; k++) {
        if (((corner >> k) & 1u) == 1u) {
            weight *= c.w[k];
        } else {
            weight *= 1.0 - c.w[k];
        }
    }
    return weight;
}

fn corner_offset(c: Cell4, corner: u32) -> u32 {
    var offset = c.base;
    for (var k = 0u; k < 4u; k++) {
        if (((corner >> k) & 1u) == 1u) { offset += c.step[k]; }
    }
    return offset;
}

fn single_lookup(coords: vec4<f32>) -> vec3<f32> {
    let c = cell4(single_layout, coords);
    var acc = vec3<f32>(0.0);
    for (var corner = 0u; corner < 16u; corner++) {
        let w = corner_weight(c, corner);
        // Zero weights are skipped, as on the CPU.
        if (w == 0.0) { continue; }
        let o = corner_offset(c, corner);
        acc += w * vec3<f32>(single_table[o], single_table[o + 1u], single_table[o + 2u]);
    }
    return acc;
}

fn multiple_lookup(coords: vec4<f32>) -> vec3<f32> {
    let c = cell4(multiple_layout, coords);
    var acc = vec3<f32>(0.0);
    for (var corner = 0u; corner < 16u; corner++) {
        let w = corner_weight(c, corner);
        if (w == 0.0) { continue; }
        let o = corner_offset(c, corner);
        acc += w * vec3<f32>(multiple_table[o], multiple_table[o + 1u], multiple_table[o + 2u]);
    }
    return acc;
}

fn grid_vertex(slot: u32, i: vec3<u32>) -> vec4<f32> {
    let d = view.dims.xyz;
    return grid_values[((slot * d.z + i.z) * d.y + i.y) * d.x + i.x];
}

// [T_r, T_g, T_b, σ̄_f] of light `slot` at `world`: trilinear, clamped at the border.
fn forward_scattering(slot: u32, world: vec3<f32>) -> vec4<f32> {
    let d = view.dims.xyz;
    let last = vec3<f32>(d) - vec3<f32>(1.0);
    let f = clamp((world - view.origin.xyz) / view.spacing.xyz, vec3<f32>(0.0), last);
    let lower = min(floor(f), max(last - vec3<f32>(1.0), vec3<f32>(0.0)));
    let w = select(f - lower, vec3<f32>(0.0), last < vec3<f32>(1.0));
    let i = vec3<u32>(lower);
    let step = vec3<u32>(select(vec3<f32>(1.0), vec3<f32>(0.0), last < vec3<f32>(1.0)));
    var acc = vec4<f32>(0.0);
    for (var corner = 0u; corner < 8u; corner++) {
        let bits = vec3<u32>(corner & 1u, (corner >> 1u) & 1u, (corner >> 2u) & 1u);
        let wb = select(vec3<f32>(1.0) - w, w, bits == vec3<u32>(1u));
        acc += wb.x * wb.y * wb.z * grid_vertex(slot, i + bits * step);
    }
    return acc;
}

struct EnvOut {
    @location(0) single: vec4<f32>,
    @location(1) multiple: vec4<f32>,
};

fn toward_eye(world: vec3<f32>) -> vec3<f32> {
    if (frame.eye.w > 0.5) { return normalize(frame.eye.xyz - world); }
    return frame.toward_eye.xyz;
}

// SRBF lobes integrate the visibility volume's T over the lobe instead of reading their light
// maps (visibility_volume.wgsl); directional lights keep their maps.
fn shades_from_volume() -> bool {
    return volume_enabled() && (batch.flags & FLAG_UNSHADOWED) == 0u;
}

// Single and multiple scattering of the fiber at `world` along `tangent` under the batch's
// lights, times `weight` (pre-multiplied; the weight is also the alpha written).
fn shade(world: vec3<f32>, tangent: vec3<f32>, weight: f32) -> EnvOut {
    let t = normalize(tangent);
    let e = toward_eye(world);
    var single = vec3<f32>(0.0);
    var multiple = vec3<f32>(0.0);
    let with_grid = (batch.flags & FLAG_GRID) != 0u;
    let with_volume = shades_from_volume();
    var sh: Sh16;
    if (with_volume) { sh = volume_coefficients(world); }
    for (var slot = 0u; slot < batch.light_count; slot++) {
        let light = env_lights[slot];
        var visible: f32;
        if (with_volume && light.direction.w > 0.0) {
            visible = volume_lobe_visibility(sh, light.direction.xyz, light.direction.w);
        } else {
            visible = effective_transmittance(slot, world);
        }
        var g = vec4<f32>(0.0);
        if (with_grid) { g = forward_scattering(slot, world); }
        for (var s = light.first_sample; s < light.first_sample + light.sample_count; s++) {
            let sample = shading_samples[s];
            let f = fiber_frame(t, sample.direction.xyz, e);
            let coords = vec4<f32>(f.sin_theta_i, f.sin_theta_o, f.cos_phi, sample.direction.w);
            single += visible * single_lookup(coords) * sample.rgb.xyz;
            if (with_grid) {
                let cm = vec4<f32>(coords.xyz, g.w);
                multiple += sample.power.xyz * g.xyz * multiple_lookup(cm);
            }
        }
    }
    var out: EnvOut;
    out.single = vec4<f32>(single * weight, weight);
    out.multiple = vec4<f32>(multiple * weight, weight);
    return out;
}

// One triangle covering the viewport.
@vertex
fn vs_fullscreen(@builtin(vertex_index) vertex: u32) -> @builtin(position) vec4<f32> {
    let uv = vec2<f32>(f32((vertex << 1u) & 2u), f32(vertex & 2u));
    return vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0);
}

// With a head, the prepass and the coverage kept only fibers in front of it (depth test against
// the head's depth): the hair's radiance over the skin's, the skin seen through 1 − coverage.
@fragment
fn fs_env_deferred(@builtin(position) pixel: vec4<f32>) -> EnvOut {
    let p = vec2<i32>(pixel.xy);
    let nearest = textureLoad(nearest_position, p, 0);
    let head = head_at(p);
    if (nearest.w == 0.0 && head.w == 0.0) { discard; }
    var out: EnvOut;
    out.single = vec4<f32>(0.0);
    out.multiple = vec4<f32>(0.0);
    if (nearest.w != 0.0) {
        let tau = textureLoad(coverage, p, 0).r;
        out = shade(nearest.xyz, textureLoad(nearest_tangent, p, 0).xyz, 1.0 - exp(-tau));
    }
    if (head.w != 0.0) {
        let seen = 1.0 - out.single.a;
        let skin = shade_skin(head.xyz, textureLoad(head_normal, p, 0).xyz) * seen;
        out.single += vec4<f32>(skin, seen);
        out.multiple.a += seen;
    }
    return out;
}

@fragment
fn fs_env_transparent(in: VertexOut) -> EnvOut {
    if (behind_head(in)) { discard; }
    let seen = occupancy_visibility(in);
    if (seen < view.visibility_cutoff) { discard; }
    return shade(in.world, in.tangent, occupancy_weight(in, seen));
}
