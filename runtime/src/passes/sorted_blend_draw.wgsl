// Sorted blending's draw (the strands shaded by strand_shading.wgsl and the fiber model, which
// holds group 2): instance i draws segment sorted_segments[i], shaded as the strand pass shades
// it and blended "over" with no depth test, so the back-to-front order alone decides what covers
// what.

#import strandlight::strand_quads::{VertexOut, strand_vertex}
#import strandlight::strand_shading::{behind_head, shade}

@group(3) @binding(0) var<storage, read> draw_order: array<u32>;

@vertex
fn vs_sorted(@builtin(vertex_index) vertex: u32, @builtin(instance_index) i: u32) -> VertexOut {
    return strand_vertex(vertex, draw_order[i]);
}

@fragment
fn fs_main(in: VertexOut) -> @location(0) vec4<f32> {
    if (behind_head(in)) { discard; }
    return shade(in);
}
