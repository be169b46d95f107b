// Progressive refinement's running sum on the GPU: a light batch's sums added into the frame's
// (colour adds; coverage does not depend on the lights, so the latest batch's alpha stands).

@group(0) @binding(0) var<storage, read> part: array<vec4<f32>>;
@group(0) @binding(1) var<storage, read_write> total: array<vec4<f32>>;

@compute @workgroup_size(64)
fn add(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.y * 65535u * 64u + id.x;
    if i >= arrayLength(&total) {
        return;
    }
    let p = part[i];
    total[i] = vec4<f32>(total[i].rgb + p.rgb, p.a);
}
