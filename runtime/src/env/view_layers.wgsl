// The layered view (view_visibility.rs, ViewTransparency::Layered). The occupancy view
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

#define_import_path strandlight::view_layers

#import strandlight::occupancy_map::{OCC_RECORD, OCC_SLICES, OCC_SLICES_PER_SLAB, OCC_TAU_SCALE}
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
