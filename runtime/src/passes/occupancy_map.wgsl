// Occupancy and slab maps of the view (after Sintorn & Assarsson 2009, the transparency of Ren
// 2010 §8), appended to strand_quads.wgsl. Built once per frame by view_visibility.rs, read by
// every batch of the env view pass (env_view.wgsl).
//
// Per pixel one record of `view.record_words` u32 in `occupancy_map` (group 3, binding 2), of
// which the first OCC_RECORD are the occupancy map's:
//   [0]      ~ordered(nearest view depth)   (atomicMax of the complement = a minimum; 0 = empty)
//   [1]      ordered(farthest view depth)
//   [2..6)   OCC_SLICES occupancy bits: slice s of [nearest, farthest] holds a fragment
//   [6..10)  per slab of 32 slices, the fragments' optical depth Σ −ln(1 − α), fixed point
//   [10]     Σ α·exp(−τ in front) over the pixel's fragments, fixed point: what the weights the
//            map gives add up to, which the view pass rescales to the pixel's coverage
//
// Sintorn & Assarsson count fragments per slab to rescale the bit order of a fragment; our
// fragments carry different coverages (thin fibers are one-pixel quads with α = width), so the
// slab map holds optical depth instead, and the optical depth in front of a fragment is the
// slabs before its own plus its own slab's share of the occupied slices before it.
//
// Fragments that share a slice do not occlude one another in that estimate, and a slab's depth is
// spread evenly over its occupied slices, so a pixel's weights Σ α·exp(−τ in front) miss its
// coverage 1 − exp(−Σ τ) by ±15% per pixel on straight.hair at 160×120 (the path tracer's
// coverage is exact). A third pass sums the weights (word 10) and the view pass scales each
// fragment's weight by coverage / sum, so every pixel's weights add up to its coverage.

const OCC_RECORD: u32 = 11u;
const OCC_SLICES: u32 = 128u;
const OCC_SLICES_PER_SLAB: u32 = 32u;
const OCC_TAU_SCALE: f32 = 4096.0;
// Fixed point of the weight sum (word 10): a fragment's weight is at most 1, so 2^18 leaves
// 16384 fragments of weight 1 of headroom and rounds a weight to 4e-6.
const OCC_WEIGHT_SCALE: f32 = 262144.0;
// As the light pass (convolution_depth.wgsl): an opaque fiber still lets 0.1% through.
const OCC_MAX_ALPHA: f32 = 0.999;

fn occupancy_record(pixel: vec2<f32>, width: u32) -> u32 {
    return (u32(pixel.y) * width + u32(pixel.x)) * view.record_words;
}

// u32 keys whose unsigned order is the order of the floats (negatives included).
fn ordered_depth(z: f32) -> u32 {
    let b = bitcast<u32>(z);
    return select(b | 0x80000000u, ~b, (b & 0x80000000u) != 0u);
}

fn unordered_depth(key: u32) -> f32 {
    return bitcast<f32>(select(~key, key & 0x7fffffffu, (key & 0x80000000u) != 0u));
}

// Distance along the view: from the eye (perspective) or along the view axis (orthographic).
fn view_depth(world: vec3<f32>) -> f32 {
    if (frame.eye.w > 0.5) { return distance(world, frame.eye.xyz); }
    return -dot(world, frame.toward_eye.xyz);
}

fn occupancy_slice(z: f32, nearest: f32, farthest: f32) -> u32 {
    let range = farthest - nearest;
    if (!(range > 0.0)) { return 0u; }
    let t = clamp((z - nearest) / range, 0.0, 1.0);
    return min(u32(t * f32(OCC_SLICES)), OCC_SLICES - 1u);
}

fn fragment_optical_depth(alpha: f32) -> f32 {
    return -log(1.0 - min(alpha, OCC_MAX_ALPHA));
}
