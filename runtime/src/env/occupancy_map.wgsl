// Occupancy and slab maps of the view (after Sintorn & Assarsson 2009, the transparency of Ren
// 2010 §8). Built once per frame by view_visibility.rs (view_visibility.wgsl), read by every
// batch of the view shading pass (view_shading.wgsl).
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
// fragments carry different coverages (a thin fiber's is its length in the pixel × its width,
// strand_quads.wgsl), so the slab map holds optical depth instead, and the optical depth in
// front of a fragment is the slabs before its own plus its own slab's share of the occupied
// slices before it.
//
// Fragments that share a slice do not occlude one another in that estimate, and a slab's depth is
// spread evenly over its occupied slices, so a pixel's weights Σ α·exp(−τ in front) miss its
// coverage 1 − exp(−Σ τ) by ±15% per pixel on straight.hair at 160×120 (the path tracer's
// coverage is exact). A third pass sums the weights (word 10) and the view pass scales each
// fragment's weight by coverage / sum, so every pixel's weights add up to its coverage.

#define_import_path strandlight::occupancy_map

#import strandlight::strand_quads::{frame, VertexOut}
#import strandlight::view_binding::{view, occupancy_map}

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

struct DepthRange {
    nearest: f32,
    farthest: f32,
};

fn pixel_depth_range(r: u32) -> DepthRange {
    return DepthRange(
        unordered_depth(~atomicLoad(&occupancy_map[r])),
        unordered_depth(atomicLoad(&occupancy_map[r + 1u])),
    );
}

// What the viewer sees of this fragment through the fragments in front of it: exp(−τ in front),
// τ in front = the slabs before its own + its own slab's optical depth × the share of the slab's
// occupied slices that lie before its slice.
fn occupancy_visibility(in: VertexOut) -> f32 {
    let r = occupancy_record(in.clip.xy, view.width);
    let range = pixel_depth_range(r);
    let s = occupancy_slice(view_depth(in.world), range.nearest, range.farthest);
    let slab = s / OCC_SLICES_PER_SLAB;
    var tau = 0.0;
    for (var k = 0u; k < slab; k++) {
        tau += f32(atomicLoad(&occupancy_map[r + 6u + k]));
    }
    let bits = atomicLoad(&occupancy_map[r + 2u + slab]);
    let before = countOneBits(bits & ((1u << (s % OCC_SLICES_PER_SLAB)) - 1u));
    let occupied = max(countOneBits(bits), 1u);
    tau += f32(atomicLoad(&occupancy_map[r + 6u + slab])) * f32(before) / f32(occupied);
    return exp(-tau / OCC_TAU_SCALE);
}

// The fragment's share of its pixel, `seen` its occupancy_visibility: coverage × seen, scaled
// so that the pixel's shares add up to its coverage 1 − exp(−Σ τ) (pass 3's sum).
fn occupancy_weight(in: VertexOut, seen: f32) -> f32 {
    let r = occupancy_record(in.clip.xy, view.width);
    var tau = 0.0;
    for (var k = 0u; k < OCC_SLICES / OCC_SLICES_PER_SLAB; k++) {
        tau += f32(atomicLoad(&occupancy_map[r + 6u + k]));
    }
    let coverage = 1.0 - exp(-tau / OCC_TAU_SCALE);
    let sum = f32(atomicLoad(&occupancy_map[r + 10u])) / OCC_WEIGHT_SCALE;
    if (!(sum > 0.0)) { return 0.0; }
    return in.alpha * seen * coverage / sum;
}
