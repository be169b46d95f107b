// A point-lit frame into the sums a host's composite draws (composite.wgsl): the hair, as its
// technique left it (a target's texture or a buffer of RGBA per pixel), pre-multiplied over the
// head's skin, into the single-scattering half; the multiple-scattering half stays zero.

struct GatherParams {
    width: u32,
    height: u32,
    // 1: the hair is in `hair_buffer`, 0: in `hair_texture`.
    hair_in_buffer: u32,
    has_skin: u32,
};

@group(0) @binding(0) var<storage, read_write> sums: array<vec4<f32>>;
@group(0) @binding(1) var<storage, read> hair_buffer: array<vec4<f32>>;
@group(0) @binding(2) var hair_texture: texture_2d<f32>;
@group(0) @binding(3) var skin_texture: texture_2d<f32>;
@group(0) @binding(4) var<uniform> params: GatherParams;

@compute @workgroup_size(8, 8)
fn gather(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= params.width || id.y >= params.height) { return; }
    let p = id.y * params.width + id.x;
    var hair: vec4<f32>;
    if (params.hair_in_buffer == 1u) {
        hair = hair_buffer[p];
    } else {
        hair = textureLoad(hair_texture, id.xy, 0);
    }
    var skin = vec4<f32>(0.0);
    if (params.has_skin == 1u) {
        skin = textureLoad(skin_texture, id.xy, 0);
    }
    // Pre-multiplied over: the fibers left in front of the head cover it by their alpha.
    sums[p] = hair + (1.0 - hair.a) * skin;
    sums[params.width * params.height + p] = vec4<f32>(0.0);
}
