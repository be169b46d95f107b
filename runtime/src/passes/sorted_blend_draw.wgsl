// Sorted blending's draw (appended to strand_quads.wgsl + strands.wgsl + the fiber model, which
// holds group 2): instance i draws segment sorted_segments[i], shaded by `fs_main` and blended
// "over" with no depth test, so the back-to-front order alone decides what covers what.

@group(3) @binding(0) var<storage, read> draw_order: array<u32>;

@vertex
fn vs_sorted(@builtin(vertex_index) vertex: u32, @builtin(instance_index) i: u32) -> VertexOut {
    return strand_vertex(vertex, draw_order[i]);
}
