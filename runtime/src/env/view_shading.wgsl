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
//                       (fs_env_layer_lights, _head with a head), the layers' fibers
//                       rasterized again.
// and fs_env_skin, the skin behind the hair of the occupancy and layered views.

#import strandlight::env_shading::{EnvOut, shade, shade_single_from_light_maps}
#import strandlight::fullscreen::fullscreen_triangle
#import strandlight::head_view::{head_at, behind_head}
#import strandlight::occupancy_map::{OCC_TAU_SCALE, occupancy_record, occupancy_visibility, occupancy_weight}
#import strandlight::skin::shade_skin
#import strandlight::strand_quads::{VertexOut, covered_fragment, strand_draw_vertex}
#import strandlight::view_binding::{view, occupancy_map, coverage, nearest_position, nearest_tangent, head_normal}
#import strandlight::view_layers::{NO_LAYER_LIGHTS, OCC_LAYERS, add_fixed, layer_fragment, layer_lights_word, layer_word, load_fixed, on_pixel_ray}
#import strandlight::convolution_transmittance::{batch, directional_transmittance}

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
// slot to its layer (view_layers.wgsl). A frame with a head takes the entry point that filters
// its shadow; without one the filter's code is compiled out (directional_transmittance).
@fragment
fn fs_env_layer_lights(drawn: VertexOut) {
    gather_layer_lights(drawn, false);
}

@fragment
fn fs_env_layer_lights_head(drawn: VertexOut) {
    gather_layer_lights(drawn, true);
}

fn gather_layer_lights(drawn: VertexOut, with_head: bool) {
    let in = covered_fragment(drawn);
    let f = layer_fragment(in);
    if (!f.kept) { discard; }
    let first = layer_lights_word(in.clip.xy, f.layer);
    for (var slot = 0u; slot < batch.light_count; slot++) {
        add_fixed(first + slot, f.weight * directional_transmittance(slot, in.world, with_head));
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
