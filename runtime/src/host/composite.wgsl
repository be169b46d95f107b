// Draws a frame's running sums into a host's render pass: the hair (and the head, when the frame
// has one) pre-multiplied over what the host drew, at the frame's front depth, so the host's depth
// test hides the hair wherever its own scene is nearer. sums[p] = single, sums[n + p] = multiple
// (accumulate.wgsl); the colour is linear radiance times `scale`.

struct CompositeParams {
    width: u32,
    height: u32,
    scale: f32,
    _pad: u32,
};

@group(0) @binding(0) var<storage, read> sums: array<vec4<f32>>;
@group(0) @binding(1) var front_depth: texture_depth_2d;
@group(0) @binding(2) var<uniform> params: CompositeParams;

@vertex
fn vs_fullscreen(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let corner = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4<f32>(corner * 2.0 - 1.0, 0.0, 1.0);
}

// The frame's pixel under a fragment; false outside the frame.
fn frame_pixel(at: vec4<f32>) -> vec3<u32> {
    let pixel = vec2<u32>(at.xy);
    let inside = pixel.x < params.width && pixel.y < params.height;
    return vec3<u32>(pixel, select(0u, 1u, inside));
}

fn hair_colour(pixel: vec2<u32>) -> vec4<f32> {
    let p = pixel.y * params.width + pixel.x;
    let n = params.width * params.height;
    let single = sums[p];
    let multiple = sums[n + p];
    return vec4<f32>((single.xyz + multiple.xyz) * params.scale, single.w);
}

struct DepthTested {
    @location(0) colour: vec4<f32>,
    @builtin(frag_depth) depth: f32,
};

// With the host's depth attachment: the fragment sits at the frame's front depth.
@fragment
fn fs_depth_tested(@builtin(position) at: vec4<f32>) -> DepthTested {
    let pixel = frame_pixel(at);
    if (pixel.z == 0u) { discard; }
    let depth = textureLoad(front_depth, pixel.xy, 0);
    // 1: neither hair nor head in this pixel.
    if (depth >= 1.0) { discard; }
    return DepthTested(hair_colour(pixel.xy), depth);
}

// Without one: the hair over whatever is there.
@fragment
fn fs_over(@builtin(position) at: vec4<f32>) -> @location(0) vec4<f32> {
    let pixel = frame_pixel(at);
    if (pixel.z == 0u) { discard; }
    return hair_colour(pixel.xy);
}
