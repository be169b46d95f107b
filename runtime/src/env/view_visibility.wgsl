// The frame's visibility (view_visibility.rs), drawn once before its batches: the opaque view's
// depth prepass and coverage, the occupancy map's build (three fragment passes over the hair,
// occupancy_map.wgsl) and the layered view's gathering (view_layers.wgsl), and the fragment
// counts of the benchmarks. Its strands are rasterized by the same vertex stage as the view
// shading pass's (strand_quads.wgsl, whose clip position is @invariant), so that both see the
// same fragments.

#import strandlight::fullscreen::fullscreen_triangle
#import strandlight::head_view::behind_head
#import strandlight::occupancy_map::{OCC_SLICES_PER_SLAB, OCC_TAU_SCALE, OCC_WEIGHT_SCALE, fragment_optical_depth, occupancy_record, occupancy_slice, occupancy_visibility, ordered_depth, pixel_depth_range, view_depth}
#import strandlight::strand_quads::{VertexOut, covered_fragment, strand_draw_vertex}
#import strandlight::view_binding::{view, occupancy_map}
#import strandlight::view_layers::{OCC_LAYERS, add_fixed, layer_fragment, layer_word, load_fixed}

@vertex
fn vs_main(@builtin(vertex_index) vertex: u32, @builtin(instance_index) instance: u32) -> VertexOut {
    return strand_draw_vertex(vertex, instance);
}

@vertex
fn vs_fullscreen(@builtin(vertex_index) vertex: u32) -> @builtin(position) vec4<f32> {
    return fullscreen_triangle(vertex);
}

// Opaque view: the optical depth of all of a pixel's fragments (additive blending). Capped so
// that one opaque fiber covers its pixel to 1e-6, not to the light pass's 0.999.
@fragment
fn fs_coverage(drawn: VertexOut) -> @location(0) vec4<f32> {
    let in = covered_fragment(drawn);
    return vec4<f32>(-log(max(1.0 - in.alpha, 1e-6)), 0.0, 0.0, 0.0);
}

// The frame's front depth for a host (view_visibility.rs, encode_front_depth): where the hair
// covers something.
@fragment
fn fs_front_depth(drawn: VertexOut) {
    _ = covered_fragment(drawn);
}

// Opaque view, the depth prepass: the nearest fragment of each pixel (depth test Less, so the
// last write is the nearest) leaves its position and tangent for the deferred view pass.
struct NearestSurface {
    @location(0) position: vec4<f32>,
    @location(1) tangent: vec4<f32>,
};

@fragment
fn fs_nearest_surface(drawn: VertexOut) -> NearestSurface {
    let in = covered_fragment(drawn);
    return NearestSurface(vec4<f32>(in.world, 1.0), vec4<f32>(in.tangent, 0.0));
}

// Pass 1: the nearest and farthest view depth of each pixel's fragments.
@fragment
fn fs_occupancy_range(drawn: VertexOut) {
    let in = covered_fragment(drawn);
    if (behind_head(in)) { discard; }
    let r = occupancy_record(in.clip.xy, view.width);
    let key = ordered_depth(view_depth(in.world));
    atomicMax(&occupancy_map[r], ~key);
    atomicMax(&occupancy_map[r + 1u], key);
}

// Pass 2: each fragment marks its slice and adds its optical depth to its slab.
@fragment
fn fs_occupancy_slices(drawn: VertexOut) {
    let in = covered_fragment(drawn);
    if (behind_head(in)) { discard; }
    let r = occupancy_record(in.clip.xy, view.width);
    let range = pixel_depth_range(r);
    let s = occupancy_slice(view_depth(in.world), range.nearest, range.farthest);
    let slab = s / OCC_SLICES_PER_SLAB;
    atomicOr(&occupancy_map[r + 2u + slab], 1u << (s % OCC_SLICES_PER_SLAB));
    let tau = u32(round(fragment_optical_depth(in.alpha) * OCC_TAU_SCALE));
    atomicAdd(&occupancy_map[r + 6u + slab], tau);
}

// Pass 3: each fragment adds the weight the map gives it to its pixel's sum (culled or not: the
// culled fragments' share is dropped, not handed to the others).
@fragment
fn fs_occupancy_weights(drawn: VertexOut) {
    let in = covered_fragment(drawn);
    if (behind_head(in)) { discard; }
    let r = occupancy_record(in.clip.xy, view.width);
    let weight = in.alpha * occupancy_visibility(in);
    atomicAdd(&occupancy_map[r + 10u], u32(round(weight * OCC_WEIGHT_SCALE)));
}

// Benchmarks only, into an additively blended target summed on the CPU: red counts the
// fragments the hair rasterizes into (depth test Always), green those the view pass shades (the
// nearest, at an Equal depth after the prepass; or those the occupancy map does not cull).
@fragment
fn fs_count_rasterized(in: VertexOut) -> @location(0) vec4<f32> {
    return vec4<f32>(1.0, 0.0, 0.0, 0.0);
}

@fragment
fn fs_count_nearest(drawn: VertexOut) -> @location(0) vec4<f32> {
    let in = covered_fragment(drawn);
    return vec4<f32>(0.0, 1.0, 0.0, 0.0);
}

@fragment
fn fs_count_visible(drawn: VertexOut) -> @location(0) vec4<f32> {
    let in = covered_fragment(drawn);
    if (behind_head(in)) { discard; }
    if (occupancy_visibility(in) < view.visibility_cutoff) { discard; }
    return vec4<f32>(0.0, 1.0, 0.0, 0.0);
}

// Pass 4 of the build (after the weights): each fragment the view would shade adds itself to
// its layer.
@fragment
fn fs_view_layers(drawn: VertexOut) {
    let in = covered_fragment(drawn);
    let f = layer_fragment(in);
    if (!f.kept) { discard; }
    let t = normalize(in.tangent);
    let w = f.weight;
    add_fixed(layer_word(f.record, f.layer, 0u), w);
    add_fixed(layer_word(f.record, f.layer, 1u), w * in.clip.z);
    add_fixed(layer_word(f.record, f.layer, 2u), w * t.x);
    add_fixed(layer_word(f.record, f.layer, 3u), w * t.y);
    add_fixed(layer_word(f.record, f.layer, 4u), w * t.z);
}

// Benchmarks: the layers one batch shades (green), as fs_count_visible counts fragments.
@fragment
fn fs_count_layers(@builtin(position) pixel: vec4<f32>) -> @location(0) vec4<f32> {
    let r = occupancy_record(pixel.xy, view.width);
    var layers = 0.0;
    for (var layer = 0u; layer < OCC_LAYERS; layer++) {
        if (load_fixed(layer_word(r, layer, 0u)) > 0.0) { layers += 1.0; }
    }
    return vec4<f32>(0.0, layers, 0.0, 0.0);
}
