// The env-lit view shading pass (view_shading.rs): one batch's lights shaded (env_shading.wgsl)
// at what the frame's visibility (view_visibility.wgsl) lets through, each fiber's single and
// multiple scattering written, weighted by what the viewer sees of it, into its own target.
// One fragment entry point per view transparency:
//   fs_env_deferred:    a full-screen pass over the nearest fiber of each pixel, which the depth
//                       prepass left in two textures (position, tangent); its radiance stands
//                       for the pixel's, weighted by the coverage of all its fibers,
//                       1 − exp(−Σ τ). No strand is rasterized again per batch of lights.
//                       _single: the same for single scattering from light maps alone.
//   fs_env_transparent: every fragment is weighted by coverage × its visibility through the
//                       fragments in front (the occupancy map) and added; fragments that can no
//                       longer contribute stop before any light is evaluated (early termination).
//   fs_env_layered:     the layers the frame's visibility gathered, each shaded once; a batch
//                       of compact sources first gathers its lights' visibility per layer
//                       (vs_/fs_env_layer_lights, from samples along each segment), the layers'
//                       fibers rasterized again.
// and fs_env_skin, the skin behind the hair of the occupancy and layered views.

#import strandlight::env_shading::{EnvOut, shade, shade_single_from_light_maps}
#import strandlight::fullscreen::fullscreen_triangle
#import strandlight::head_view::{head_at, behind_head}
#import strandlight::occupancy_map::{OCC_TAU_SCALE, occupancy_record, occupancy_visibility, occupancy_weight}
#import strandlight::skin::shade_skin
#import strandlight::strand_quads::{VertexOut, corner, covered_fragment, strand_draw_vertex}
#import strandlight::view_binding::{view, occupancy_map, coverage, nearest_position, nearest_tangent, head_normal}
#import strandlight::view_layers::{NO_LAYER_LIGHTS, OCC_LAYERS, add_fixed, layer_fragment, layer_lights_word, layer_word, load_fixed, on_pixel_ray}
#import strandlight::convolution_transmittance::batch
#import strandlight::segment_light_samples::{SampleCounts, sample_word}

@vertex
fn vs_main(@builtin(vertex_index) vertex: u32, @builtin(instance_index) instance: u32) -> VertexOut {
    return strand_draw_vertex(vertex, instance);
}

@vertex
fn vs_fullscreen(@builtin(vertex_index) vertex: u32) -> @builtin(position) vec4<f32> {
    return fullscreen_triangle(vertex);
}

// With a head, the prepass and the coverage kept only fibers in front of it (depth test against
// the head's depth): the hair's radiance over the skin's, the skin seen through 1 − coverage.
@fragment
fn fs_env_deferred(@builtin(position) pixel: vec4<f32>) -> EnvOut {
    return deferred(pixel, false);
}

@fragment
fn fs_env_deferred_single(@builtin(position) pixel: vec4<f32>) -> EnvOut {
    return deferred(pixel, true);
}

fn deferred(pixel: vec4<f32>, single_from_light_maps: bool) -> EnvOut {
    let p = vec2<i32>(pixel.xy);
    let nearest = textureLoad(nearest_position, p, 0);
    let head = head_at(p);
    if (nearest.w == 0.0 && head.w == 0.0) { discard; }
    var out: EnvOut;
    out.single = vec4<f32>(0.0);
    out.multiple = vec4<f32>(0.0);
    if (nearest.w != 0.0) {
        let tau = textureLoad(coverage, p, 0).r;
        let tangent = textureLoad(nearest_tangent, p, 0).xyz;
        let weight = 1.0 - exp(-tau);
        if (single_from_light_maps) {
            out = shade_single_from_light_maps(nearest.xyz, tangent, weight);
        } else {
            out = shade(nearest.xyz, tangent, weight, NO_LAYER_LIGHTS);
        }
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
fn fs_env_transparent(drawn: VertexOut) -> EnvOut {
    let in = covered_fragment(drawn);
    if (behind_head(in)) { discard; }
    let seen = occupancy_visibility(in);
    if (seen < view.visibility_cutoff) { discard; }
    return shade(in.world, in.tangent, occupancy_weight(in, seen), NO_LAYER_LIGHTS);
}

// A batch of compact sources, before fs_env_layered: each fragment adds w·v of every light
// slot to its layer (view_layers.wgsl), v interpolated at its place along its segment from the
// samples the batch's compute pass left there (segment_light_visibility.rs).
struct GatherVertex {
    // VertexOut's fields (an entry point's struct cannot nest one), then the segment and the
    // place along it (0 at its first point, 1 at its last).
    @builtin(position) @invariant clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) tangent: vec3<f32>,
    @location(2) color: vec3<f32>,
    @location(3) alpha: f32,
    @location(4) @interpolate(flat) segment_px: vec4<f32>,
    @location(5) @interpolate(flat) before_px: vec4<f32>,
    @location(6) @interpolate(flat) after_px: vec4<f32>,
    @location(7) @interpolate(flat) line_flags: u32,
    @location(8) @interpolate(flat) segment: u32,
    @location(9) along: f32,
};

@group(2) @binding(4) var<storage, read> sample_visibility: array<u32>;
@group(2) @binding(5) var<uniform> sample_counts: SampleCounts;

@vertex
fn vs_layer_lights(@builtin(vertex_index) vertex: u32) -> GatherVertex {
    let drawn = strand_draw_vertex(vertex, 0u);
    return GatherVertex(
        drawn.clip, drawn.world, drawn.tangent, drawn.color, drawn.alpha, drawn.segment_px,
        drawn.before_px, drawn.after_px, drawn.line_flags, vertex / 6u, corner(vertex % 6u).x,
    );
}

@fragment
fn fs_env_layer_lights(g: GatherVertex) {
    let drawn = VertexOut(
        g.clip, g.world, g.tangent, g.color, g.alpha, g.segment_px, g.before_px, g.after_px,
        g.line_flags,
    );
    let in = covered_fragment(drawn);
    let f = layer_fragment(in);
    if (!f.kept) { discard; }
    let first = layer_lights_word(in.clip.xy, f.layer);
    // A thin line's quad reaches beyond its segment's ends: those pixels take the end's value.
    let x = clamp(g.along, 0.0, 1.0) * f32(sample_counts.per_segment);
    let j = min(u32(x), sample_counts.per_segment - 1u);
    let t = x - f32(j);
    for (var slot = 0u; slot < batch.light_count; slot++) {
        let word = slot / 2u;
        let v0 = unpack2x16float(sample_visibility[sample_word(sample_counts, g.segment, j, word)]);
        let v1 = unpack2x16float(sample_visibility[sample_word(sample_counts, g.segment, j + 1u, word)]);
        add_fixed(first + slot, f.weight * mix(v0[slot % 2u], v1[slot % 2u], t));
    }
}

// Every batch: each layer of the pixel shaded once (the skin behind is fs_env_skin's).
@fragment
fn fs_env_layered(@builtin(position) pixel: vec4<f32>) -> EnvOut {
    let r = occupancy_record(pixel.xy, view.width);
    var out: EnvOut;
    out.single = vec4<f32>(0.0);
    out.multiple = vec4<f32>(0.0);
    for (var layer = 0u; layer < OCC_LAYERS; layer++) {
        let w = load_fixed(layer_word(r, layer, 0u));
        if (!(w > 0.0)) { continue; }
        let z = load_fixed(layer_word(r, layer, 1u)) / w;
        var t = vec3<f32>(
            load_fixed(layer_word(r, layer, 2u)),
            load_fixed(layer_word(r, layer, 3u)),
            load_fixed(layer_word(r, layer, 4u)),
        );
        // Fibers crossing in opposite directions can cancel: any unit tangent then, not NaN.
        if (dot(t, t) < 1e-12) { t = vec3<f32>(0.0, 1.0, 0.0); }
        var lights = NO_LAYER_LIGHTS;
        if (view.layer_lights.z != 0u) { lights = layer_lights_word(pixel.xy, layer); }
        let shaded = shade(on_pixel_ray(pixel.xy, z), t, w, lights);
        out.single += shaded.single;
        out.multiple += shaded.multiple;
    }
    if (out.single.a == 0.0) { discard; }
    return out;
}

// Occupancy view: the skin behind all the pixel's fibers, seen through their optical depth
// (every slab of the occupancy record: its fibers all lie in front of the head).
@fragment
fn fs_env_skin(@builtin(position) pixel: vec4<f32>) -> EnvOut {
    let p = vec2<i32>(pixel.xy);
    let head = head_at(p);
    if (head.w == 0.0) { discard; }
    let r = occupancy_record(pixel.xy, view.width);
    var tau = 0.0;
    for (var k = 0u; k < 4u; k++) {
        tau += f32(atomicLoad(&occupancy_map[r + 6u + k]));
    }
    let seen = exp(-tau / OCC_TAU_SCALE);
    let n = textureLoad(head_normal, p, 0).xyz;
    var out: EnvOut;
    out.single = vec4<f32>(shade_skin(head.xyz, n) * seen, seen);
    out.multiple = vec4<f32>(0.0, 0.0, 0.0, seen);
    return out;
}
