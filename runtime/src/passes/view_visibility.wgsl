// The occupancy map's build (two fragment passes over the hair, once per frame) and its read by
// the transparent view pass. Appended to the env view module (env_view.wgsl declares
// `occupancy_map` and `view`) so that the build rasterizes exactly the view pass's fragments.

// Opaque view: the optical depth of all of a pixel's fragments (additive blending). Capped so
// that one opaque fiber covers its pixel to 1e-6, not to the light pass's 0.999.
@fragment
fn fs_coverage(in: VertexOut) -> @location(0) vec4<f32> {
    return vec4<f32>(-log(max(1.0 - in.alpha, 1e-6)), 0.0, 0.0, 0.0);
}

// Opaque view, the depth prepass: the nearest fragment of each pixel (depth test Less, so the
// last write is the nearest) leaves its position and tangent for the deferred view pass.
struct NearestSurface {
    @location(0) position: vec4<f32>,
    @location(1) tangent: vec4<f32>,
};

@fragment
fn fs_nearest_surface(in: VertexOut) -> NearestSurface {
    return NearestSurface(vec4<f32>(in.world, 1.0), vec4<f32>(in.tangent, 0.0));
}

// Pass 1: the nearest and farthest view depth of each pixel's fragments.
@fragment
fn fs_occupancy_range(in: VertexOut) {
    if (behind_head(in)) { discard; }
    let r = occupancy_record(in.clip.xy, view.width);
    let key = ordered_depth(view_depth(in.world));
    atomicMax(&occupancy_map[r], ~key);
    atomicMax(&occupancy_map[r + 1u], key);
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

// Pass 2: each fragment marks its slice and adds its optical depth to its slab.
@fragment
fn fs_occupancy_slices(in: VertexOut) {
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
fn fs_occupancy_weights(in: VertexOut) {
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
fn fs_count_nearest(in: VertexOut) -> @location(0) vec4<f32> {
    return vec4<f32>(0.0, 1.0, 0.0, 0.0);
}

@fragment
fn fs_count_visible(in: VertexOut) -> @location(0) vec4<f32> {
    if (behind_head(in)) { discard; }
    if (occupancy_visibility(in) < view.visibility_cutoff) { discard; }
    return vec4<f32>(0.0, 1.0, 0.0, 0.0);
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
