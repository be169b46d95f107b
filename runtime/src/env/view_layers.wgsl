// The layered view (view_visibility.rs, ViewTransparency::Layered). The occupancy view
// weighs every fragment of a pixel (occupancy_weight) and shades each one with every light: as
// many shading loops per pixel as the pixel has fibers (about 30 on straight.hair at 160×120).
// Here the weighted fragments are gathered once per frame into OCC_LAYERS layers of equal
// coverage (a fragment's layer is the share of its pixel's coverage in front of it), each
// keeping Σw, Σw·depth and Σw·tangent; each batch then shades every layer once, at its weighted
// mean depth on the pixel's ray with its weighted mean tangent, times Σw. Across a layer the
// shading is linear in neither, so the mean fiber's radiance is not the mean radiance: the
// price of OCC_LAYERS shading loops per pixel instead of one per fragment
// (docs/history/benchmarks-2026-12-02-to-12-04.md, "The view: layers").
//
// A batch of compact sources (suns, lamps) also gathers, per layer and light slot, Σw·v: its
// fibers' visibility v of the light (fs_env_layer_lights, view_shading.wgsl), which the layer's
// shading divides by Σw. A compact source's shadow is sharp at fiber scale: the visibility at
// the layer's mean position is not its fibers' mean visibility (quarry at 160×120 against the
// truth: 0.338 read at the mean position, 0.290 shaded per fragment, 0.288 from Σw·v;
// docs/BENCHMARKS.md, "Compact sources per layer"). These words follow every pixel's record,
// `view.layer_lights.y` slots per layer from word `view.layer_lights.x` on, zeroed before each
// such batch.
//
// Record words after the occupancy map's OCC_RECORD, per layer: Σw, Σw·z (z the fragment's
// depth in [0, 1], as the rasterizer writes it), Σw·t (three words, t the unit tangent), each
// a fixed-point i32 of OCC_LAYER_SCALE summed with wrapping u32 atomics (a pixel's weights add
// up to its coverage ≤ 1, so every sum stays within ±2^30).

#define_import_path strandlight::view_layers

#import strandlight::head_view::behind_head
#import strandlight::occupancy_map::{OCC_RECORD, OCC_SLICES, OCC_SLICES_PER_SLAB, OCC_TAU_SCALE, occupancy_record, occupancy_visibility, occupancy_weight}
#import strandlight::strand_quads::VertexOut
#import strandlight::view_binding::{view, occupancy_map}

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

// No per-layer light visibility: the shading reads each light's visibility at its point.
const NO_LAYER_LIGHTS: u32 = 0xffffffffu;

// A fragment the view shades, in its layer: its pixel's record, the layer and its weight
// (`kept` false: behind the head, or seen less than the cutoff).
struct LayerFragment {
    record: u32,
    layer: u32,
    weight: f32,
    kept: bool,
}

fn layer_fragment(in: VertexOut) -> LayerFragment {
    var out = LayerFragment(0u, 0u, 0.0, false);
    if (behind_head(in)) { return out; }
    let seen = occupancy_visibility(in);
    if (seen < view.visibility_cutoff) { return out; }
    out.record = occupancy_record(in.clip.xy, view.width);
    out.weight = occupancy_weight(in, seen);
    let in_front = (1.0 - seen) / max(pixel_coverage(out.record), 1e-6);
    out.layer = min(u32(max(in_front, 0.0) * f32(OCC_LAYERS)), OCC_LAYERS - 1u);
    out.kept = true;
    return out;
}

// The word of light slot 0 in `layer` of the pixel at `pixel` (after every record).
fn layer_lights_word(pixel: vec2<f32>, layer: u32) -> u32 {
    let index = u32(pixel.y) * view.width + u32(pixel.x);
    return view.layer_lights.x + (index * OCC_LAYERS + layer) * view.layer_lights.y;
}

// The pixel's coverage 1 − exp(−Σ τ) from its slabs.
fn pixel_coverage(r: u32) -> f32 {
    var tau = 0.0;
    for (var k = 0u; k < OCC_SLICES / OCC_SLICES_PER_SLAB; k++) {
        tau += f32(atomicLoad(&occupancy_map[r + 6u + k]));
    }
    return 1.0 - exp(-tau / OCC_TAU_SCALE);
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
