// Adds one batch's images into the frame's running sums. Pre-multiplied "over" compositing is
// linear in colour for a fixed set of fragments, so the sum of the batches' colours is the
// colour under all lights; alpha (the same in every batch) is copied, not summed.
// sums[p] = single, sums[width·height + p] = multiple.

struct AccumulateParams {
    width: u32,
    height: u32,
    _pad0: u32,
    _pad1: u32,
};

@group(0) @binding(0) var batch_single: texture_2d<f32>;
@group(0) @binding(1) var batch_multiple: texture_2d<f32>;
@group(0) @binding(2) var<storage, read_write> sums: array<vec4<f32>>;
@group(0) @binding(3) var<uniform> acc_params: AccumulateParams;

@compute @workgroup_size(8, 8)
fn accumulate(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= acc_params.width || id.y >= acc_params.height) { return; }
    let p = id.y * acc_params.width + id.x;
    let n = acc_params.width * acc_params.height;
    let s = textureLoad(batch_single, id.xy, 0);
    let m = textureLoad(batch_multiple, id.xy, 0);
    sums[p] = vec4<f32>(sums[p].xyz + s.xyz, s.w);
    sums[n + p] = vec4<f32>(sums[n + p].xyz + m.xyz, m.w);
}
