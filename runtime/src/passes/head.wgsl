// The head (runtime/src/head.rs) as the env-lit frame rasterizes it: an opaque triangle mesh
// drawn (1) into the view's depth with its world position and normal, so that the hair behind it
// fails the depth test and the deferred view pass shades the skin, and (2) into one depth map
// per light slot, with the slot's light-map camera, so that the lobe's transmittance is zero
// behind it (convolution_transmittance.wgsl, head_transmittance).

struct HeadCamera {
    view_proj: mat4x4<f32>,
    // xyz: eye position; w: 1 for a perspective camera, 0 for orthographic.
    eye: vec4<f32>,
    // xyz: direction toward the eye of an orthographic camera.
    toward_eye: vec4<f32>,
};

@group(0) @binding(0) var<uniform> head_camera: HeadCamera;

struct HeadVertex {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
};

struct HeadOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
};

@vertex
fn vs_head(v: HeadVertex) -> HeadOut {
    var out: HeadOut;
    out.clip = head_camera.view_proj * vec4<f32>(v.position, 1.0);
    out.world = v.position;
    out.normal = v.normal;
    return out;
}

struct HeadSurface {
    // xyz: world position; w: 1 where the pixel shows the head.
    @location(0) position: vec4<f32>,
    // xyz: unit normal, turned toward the viewer (a mesh's winding and closure are unknown).
    @location(1) normal: vec4<f32>,
};

@fragment
fn fs_head_surface(in: HeadOut) -> HeadSurface {
    var n = normalize(in.normal);
    var e = head_camera.toward_eye.xyz;
    if (head_camera.eye.w > 0.5) { e = normalize(head_camera.eye.xyz - in.world); }
    // An open mesh seen from inside, or a flipped normal: light the side the viewer sees. Not
    // at the silhouette of a closed surface, where the interpolated normal may look slightly
    // away and must stay as it is.
    if (dot(n, e) < -0.5) { n = -n; }
    return HeadSurface(vec4<f32>(in.world, 1.0), vec4<f32>(n, 0.0));
}

// The head's depth in the light map's 0..1 range (the DODM's z convention).
@fragment
fn fs_head_depth(in: HeadOut) -> @location(0) vec4<f32> {
    return vec4<f32>(in.clip.z, 0.0, 0.0, 0.0);
}
