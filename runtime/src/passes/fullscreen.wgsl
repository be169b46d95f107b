// One triangle covering the viewport: the vertex stage of full-screen passes.
#define_import_path strandlight::fullscreen

fn fullscreen_triangle(vertex: u32) -> vec4<f32> {
    let uv = vec2<f32>(f32((vertex << 1u) & 2u), f32(vertex & 2u));
    return vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0);
}
