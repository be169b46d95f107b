// The compute pass of segment_light_samples.wgsl (segment_light_visibility.rs). Evaluated per
// fragment instead, the gather read the maps ~7 times as often at 800×600 (1.9 M fragments
// against 282 k segments on the default groom) and was half the layered view's time.
#import strandlight::convolution_transmittance::{batch, directional_transmittance}
#import strandlight::segment_light_samples::{SampleCounts, sample_word, words_per_sample}

@group(0) @binding(0) var<storage, read> points: array<f32>;
// Per segment: its first point's index in the low 30 bits (strand_quads.wgsl).
@group(0) @binding(1) var<storage, read> segments: array<u32>;
@group(0) @binding(2) var<storage, read_write> sample_visibility: array<u32>;
@group(0) @binding(3) var<uniform> counts: SampleCounts;

const WORKGROUP: u32 = 64u;

fn point(i: u32) -> vec3<f32> {
    return vec3<f32>(points[3u * i], points[3u * i + 1u], points[3u * i + 2u]);
}

fn visibility_of_sample(id: vec3<u32>, with_head: bool) {
    let i = id.x + id.y * WORKGROUP * 65535u;
    if (i >= counts.samples) { return; }
    let segment = i / (counts.per_segment + 1u);
    let j = i % (counts.per_segment + 1u);
    let first = segments[segment] & 0x3fffffffu;
    let world = mix(point(first), point(first + 1u), f32(j) / f32(counts.per_segment));
    for (var word = 0u; word < words_per_sample(counts); word++) {
        let slot = 2u * word;
        var pair = vec2<f32>(directional_transmittance(slot, world, with_head), 0.0);
        if (slot + 1u < batch.light_count) {
            pair.y = directional_transmittance(slot + 1u, world, with_head);
        }
        sample_visibility[sample_word(counts, segment, j, word)] = pack2x16float(pair);
    }
}

@compute @workgroup_size(64)
fn cs_segment_light_visibility(@builtin(global_invocation_id) id: vec3<u32>) {
    visibility_of_sample(id, false);
}

// The head's filter is compiled in only here (llvmpipe runs every branch, taken or not).
@compute @workgroup_size(64)
fn cs_segment_light_visibility_head(@builtin(global_invocation_id) id: vec3<u32>) {
    visibility_of_sample(id, true);
}
