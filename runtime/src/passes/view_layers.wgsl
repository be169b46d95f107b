// The layered view (view_visibility.rs, ViewTransparency::Layered), appended to the env view
// module after occupancy_map.wgsl, env_view.wgsl and view_visibility.wgsl. The occupancy view
// weighs every fragment of a pixel (occupancy_weight) and shades each one with every light: as
// many shading loops per pixel as the pixel has fibers (about 30 on straight.hair at 160×120).
// Here the weighted fragments are gathered once per frame into OCC_LAYERS layers of equal
// coverage (a fragment's layer is the share of its pixel's coverage in front of it), each
// keeping Σw, Σw·depth and Σw·tangent; each batch then shades every layer once, at its weighted
// mean depth on the pixel's ray with its weighted mean tangent, times Σw. Across a layer the
// shading is linear in neither, so the mean fiber's radiance is not the mean radiance: the
// price of OCC_LAYERS shading loops per pixel instead of one per fragment
// (docs/BENCHMARKS.md, "The view: layers").
//
// Record words after the occupancy map's OCC_RECORD, per layer: Σw, Σw·z (z the fragment's
// depth in [0, 1], as the rasterizer writes it), Σw·t (three words, t the unit tangent), each
// a fixed-point i32 of OCC_LAYER_SCALE summed with wrapping u32 atomics (a pixel's weights add
// up to its coverage ≤ 1, so every sum stays within ±2^30).

const OCC_LAYERS: u32 = 4u;
const OCC_LAYER_WORDS: u32 = 5u;
const OCC_LAYER_SCALE: f32 = 1073741824.0;

fn layer_word(r: u32, layer: u32, word: u32) -> u32 {
    return r + OCC_RECORD + layer * OCC_LAYER_WORDS + word;
}

fn add_fixed(index: u32, value: f32) {
    atomicAdd(&occupancy_map[index], bitcast<u32>(i32(round(value * OCC_LAYER_SCALE))));
}

fn load_fixed(index: u32) -> f32 {
    return f32(bitcast<i32>(atomicLoad(&occupancy_map[index]))) / OCC_LAYER_SCALE;
}

// The pixel's coverage 1 − exp(−Σ τ) from its slabs.
fn pixel_coverage(r: u32) -> f32 {
    var tau = 0.0;
    for (var k = 0u; k < OCC_SLICES / OCC_SLICES_PER_SLAB; k++) {
        tau += f32(atomicLoad(&occupancy_map[r + 6u + k]));
    }
    return 1.0 - exp(-tau / OCC_TAU_SCALE);
}

// Pass 4 of the build (after the weights): each fragment the view would shade adds itself to
// its layer.
@fragment
fn fs_view_layers(in: VertexOut) {
    if (behind_head(in)) { discard; }
    let seen = occupancy_visibility(in);
    if (seen < view.visibility_cutoff) { discard; }
    let r = occupancy_record(in.clip.xy, view.width);
    let w = occupancy_weight(in, seen);
    let in_front = (1.0 - seen) / max(pixel_coverage(r), 1e-6);
    let layer = min(u32(max(in_front, 0.0) * f32(OCC_LAYERS)), OCC_LAYERS - 1u);
    let t = normalize(in.tangent);
    add_fixed(layer_word(r, layer, 0u), w);
    add_fixed(layer_word(r, layer, 1u), w * in.clip.z);
    add_fixed(layer_word(r, layer, 2u), w * t.x);
    add_fixed(layer_word(r, layer, 3u), w * t.y);
    add_fixed(layer_word(r, layer, 4u), w * t.z);
}

// The world point at depth `z` on the ray through pixel centre `pixel`.
fn on_pixel_ray(pixel: vec2<f32>, z: f32) -> vec3<f32> {
    let ndc = vec2<f32>(
        2.0 * pixel.x / f32(view.width) - 1.0,
        1.0 - 2.0 * pixel.y / f32(view.height),
    );
    let world = view.clip_to_world * vec4<f32>(ndc, z, 1.0);
    return world.xyz / world.w;
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
        let shaded = shade(on_pixel_ray(pixel.xy, z), t, w);
        out.single += shaded.single;
        out.multiple += shaded.multiple;
    }
    if (out.single.a == 0.0) { discard; }
    return out;
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
