// Group 3 of the env view passes (view_binding.rs): what the view reads besides lights and
// tables: the batch's forward-scattering grid and the frame's visibility (the occupancy map,
// the nearest fibers and their coverage, the head seen from the view). The visibility volume's
// bindings 6 and 7 are visibility_volume.wgsl's.
#define_import_path strandlight::view_binding

struct ViewParams {
    // Grid: xyz the world position of vertex (0,0,0).
    origin: vec4<f32>,
    // Grid: xyz the spacing between vertices.
    spacing: vec4<f32>,
    // Grid: xyz the vertices per axis.
    dims: vec4<u32>,
    // Image width and height (occupancy records).
    width: u32,
    height: u32,
    // Fragments seen less than this stop before shading (transparent view).
    visibility_cutoff: f32,
    // u32 per pixel of `occupancy_map` (occupancy_map.wgsl).
    record_words: u32,
    // rgb: the head's skin albedo; w: 1 where the frame has a head (skin.wgsl).
    skin: vec4<f32>,
    // Clip space to world: the layered view puts each layer's fibers back on its pixel's ray.
    clip_to_world: mat4x4<f32>,
    // The layered view's per-layer light visibility (view_layers.wgsl): x its first word in
    // `occupancy_map`, y the light slots per layer, z 1 when this batch's layers read it.
    layer_lights: vec4<u32>,
};

@group(3) @binding(0) var<uniform> view: ViewParams;
@group(3) @binding(1) var<storage, read> grid_values: array<vec4<f32>>;
@group(3) @binding(2) var<storage, read_write> occupancy_map: array<atomic<u32>>;
// Red: the optical depth Σ −ln(1 − α) of all the pixel's fragments (opaque view).
@group(3) @binding(3) var coverage: texture_2d<f32>;
// The nearest fiber of each pixel (opaque view, fs_nearest_surface): xyz its world position,
// w 1 where the pixel holds hair; and its (unnormalized) tangent.
@group(3) @binding(4) var nearest_position: texture_2d<f32>;
@group(3) @binding(5) var nearest_tangent: texture_2d<f32>;
// The head seen from the view (head.wgsl): xyz its world position, w 1 on the head; its normal.
@group(3) @binding(8) var head_position: texture_2d<f32>;
@group(3) @binding(9) var head_normal: texture_2d<f32>;
