// Bin-sorted back-to-front order of the segments (Kim 2003 §4; Svoboda §2.5): each segment's key
// is the view depth of its farther endpoint, quantized into `bins` equal bins between the hair's
// nearest and farthest depths and reversed, so the farthest bin comes first. A counting sort
// (histogram, exclusive scan, scatter) writes the draw order; within a bin the order is whatever
// the atomics give, which is the approximation bin sorting makes.

struct SortParams {
    // xyz: the eye; w unused.
    eye: vec4<f32>,
    // xyz: the unit view axis.
    forward: vec4<f32>,
    nearest: f32,
    farthest: f32,
    bins: u32,
    segment_count: u32,
};

@group(0) @binding(0) var<uniform> sort: SortParams;
@group(0) @binding(1) var<storage, read> sort_points: array<f32>;
@group(0) @binding(2) var<storage, read> sort_segments: array<u32>;
@group(0) @binding(3) var<storage, read_write> bin_counts: array<atomic<u32>>;
@group(0) @binding(4) var<storage, read_write> sorted_segments: array<u32>;

const SORT_GROUP: u32 = 256u;

fn sort_point(i: u32) -> vec3<f32> {
    return vec3<f32>(sort_points[3u * i], sort_points[3u * i + 1u], sort_points[3u * i + 2u]);
}

fn back_to_front_bin(segment: u32) -> u32 {
    let i0 = sort_segments[segment] & 0x3fffffffu;
    let axis = sort.forward.xyz;
    let depth = max(dot(sort_point(i0) - sort.eye.xyz, axis), dot(sort_point(i0 + 1u) - sort.eye.xyz, axis));
    let x = (depth - sort.nearest) / max(sort.farthest - sort.nearest, 1e-30);
    let bin = min(u32(clamp(x, 0.0, 1.0) * f32(sort.bins)), sort.bins - 1u);
    return sort.bins - 1u - bin;
}

// Dispatches wider than 65535 groups wrap into y.
fn segment_index(id: vec3<u32>, groups: vec3<u32>) -> u32 {
    return id.x + id.y * groups.x * SORT_GROUP;
}

@compute @workgroup_size(256)
fn histogram(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let segment = segment_index(id, groups);
    if (segment >= sort.segment_count) { return; }
    atomicAdd(&bin_counts[back_to_front_bin(segment)], 1u);
}

// Counts to first slots; a few thousand bins at most, so one invocation does it.
@compute @workgroup_size(1)
fn scan() {
    var sum = 0u;
    for (var b = 0u; b < sort.bins; b++) {
        let count = atomicLoad(&bin_counts[b]);
        atomicStore(&bin_counts[b], sum);
        sum += count;
    }
}

@compute @workgroup_size(256)
fn scatter(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let segment = segment_index(id, groups);
    if (segment >= sort.segment_count) { return; }
    let slot = atomicAdd(&bin_counts[back_to_front_bin(segment)], 1u);
    sorted_segments[slot] = segment;
}
