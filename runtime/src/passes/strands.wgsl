// The strand pass (strands.rs): every segment's quad shaded (strand_shading.wgsl) and blended
// in draw order with "one, one − source alpha".

#import strandlight::strand_quads::{VertexOut, strand_draw_vertex}
#import strandlight::strand_shading::{behind_head, shade}

@vertex
fn vs_main(@builtin(vertex_index) vertex: u32, @builtin(instance_index) instance: u32) -> VertexOut {
    return strand_draw_vertex(vertex, instance);
}

@fragment
fn fs_main(in: VertexOut) -> @location(0) vec4<f32> {
    if (behind_head(in)) { discard; }
    return shade(in);
}
