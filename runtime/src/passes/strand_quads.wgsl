// Strands as camera-facing quads expanded from segments (wgpu lines are one pixel wide): the
// vertex stage shared by the passes that draw strands (prepended to their fragment shaders).
//
// One instance per segment, six vertices (two triangles) per instance. A quad is
// max(width, 1) pixels wide; a fiber thinner than a pixel keeps the one-pixel quad and carries
// its coverage width/1px in alpha (Svoboda §1.2.3), so the alpha summed across the strand equals
// its width in pixels.

struct Frame {
    view_proj: mat4x4<f32>,
    // xyz: eye position; w: 1 for a perspective camera, 0 for orthographic.
    eye: vec4<f32>,
    // xyz: direction toward the eye of an orthographic camera.
    toward_eye: vec4<f32>,
    viewport: vec2<f32>,
    // Pixels per world unit at clip-space w = 1: proj[1][1] · height / 2.
    focal_px: f32,
    // > 0: every fiber is this many pixels wide (the user's width), else the file's thickness.
    width_override_px: f32,
    kd: f32,
    ks: f32,
    shininess: f32,
    light_count: u32,
    // Light pass of stochastic simplification: fibers 1/κ times wider (1 elsewhere).
    width_scale: f32,
};

struct PointAttributes {
    color: vec3<f32>,
    // Fiber diameter in world units.
    thickness: f32,
    // 1 − the file's transparency.
    opacity: f32,
    _pad0: f32,
    _pad1: f32,
    _pad2: f32,
};

struct Light {
    // xyz: direction toward the light (w = 0) or position (w = 1 point, 2 spot).
    position_or_direction: vec4<f32>,
    intensity: vec4<f32>,
    // Spot: xyz the direction it shines, w the cosine of its half-angle.
    spot: vec4<f32>,
};

@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(1) var<storage, read> points: array<f32>;
// Per segment: its first point's index (low 30 bits); bit 30: first segment of its strand;
// bit 31: last segment of its strand.
@group(0) @binding(2) var<storage, read> segments: array<u32>;
@group(0) @binding(3) var<storage, read> attributes: array<PointAttributes>;
@group(0) @binding(4) var<storage, read> lights: array<Light>;

struct VertexOut {
    // Invariant: the env view's depth prepass and its Equal-depth shading pass are different
    // pipelines over this vertex stage and must produce bit-identical depths.
    @builtin(position) @invariant clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) tangent: vec3<f32>,
    @location(2) color: vec3<f32>,
    // Coverage × opacity.
    @location(3) alpha: f32,
};

fn point(i: u32) -> vec3<f32> {
    return vec3<f32>(points[3u * i], points[3u * i + 1u], points[3u * i + 2u]);
}

// Corner k of the two triangles (0,−)(1,−)(0,+) and (0,+)(1,−)(1,+): x = segment end, y = side.
fn corner(k: u32) -> vec2<f32> {
    var ends = array<f32, 6>(0.0, 1.0, 0.0, 0.0, 1.0, 1.0);
    var sides = array<f32, 6>(-1.0, -1.0, 1.0, 1.0, -1.0, 1.0);
    return vec2<f32>(ends[k], sides[k]);
}

// Corner `vertex` of segment `segment`'s quad: the body of every strand vertex entry point (the
// sorted pass draws segments in another order than their instance index).
fn strand_vertex(vertex: u32, segment: u32) -> VertexOut {
    let packed = segments[segment];
    let i0 = packed & 0x3fffffffu;
    let is_first = (packed & 0x40000000u) != 0u;
    let is_last = (packed & 0x80000000u) != 0u;
    let p0 = point(i0);
    let p1 = point(i0 + 1u);
    // Tangents at the two ends by central differences, one-sided at the strand's ends; the
    // rasterizer interpolates them along the segment.
    var before = p0;
    if (!is_first) { before = point(i0 - 1u); }
    var after = p1;
    if (!is_last) { after = point(i0 + 2u); }
    let t0 = normalize(p1 - before);
    let t1 = normalize(after - p0);

    let c = corner(vertex);
    let at_end = c.x > 0.5;
    let clip0 = frame.view_proj * vec4<f32>(p0, 1.0);
    let clip1 = frame.view_proj * vec4<f32>(p1, 1.0);
    // Screen direction in pixels (isotropic), and its perpendicular.
    let half_viewport = 0.5 * frame.viewport;
    let s0 = clip0.xy / clip0.w * half_viewport;
    let s1 = clip1.xy / clip1.w * half_viewport;
    var d = s1 - s0;
    if (dot(d, d) < 1e-12) { d = vec2<f32>(1.0, 0.0); }
    d = normalize(d);
    let normal = vec2<f32>(-d.y, d.x);

    var index = i0;
    var clip = clip0;
    var world = p0;
    var tangent = t0;
    if (at_end) {
        index = i0 + 1u;
        clip = clip1;
        world = p1;
        tangent = t1;
    }
    let attr = attributes[index];
    var width_px = attr.thickness * frame.focal_px / clip.w;
    if (frame.width_override_px > 0.0) { width_px = frame.width_override_px; }
    var quad_px = max(width_px, 1.0);
    var alpha = width_px / quad_px * attr.opacity;
    if (frame.width_scale != 1.0) {
        // Enlarged fiber (Ren 2010 §7): the QUAD (at least a pixel) grows by 1/κ, so the drawn
        // fibers cover the texels of those left out even when thinner than a texel; its optical
        // depth is spread over it, keeping −ln(1 − α)·quad_px summed across the fiber (the light
        // pass then scales τ by 1/κ: each drawn fiber carries the depth of 1/κ fibers).
        let scaled_quad_px = quad_px * frame.width_scale;
        let tau = -log(1.0 - min(alpha, 0.999));
        alpha = 1.0 - exp(-tau * quad_px / scaled_quad_px);
        quad_px = scaled_quad_px;
    }
    let offset_px = normal * (c.y * 0.5 * quad_px);
    clip = vec4<f32>(clip.xy + offset_px / half_viewport * clip.w, clip.zw);

    var out: VertexOut;
    out.clip = clip;
    out.world = world;
    out.tangent = tangent;
    out.color = attr.color;
    out.alpha = alpha;
    return out;
}

@vertex
fn vs_main(@builtin(vertex_index) vertex: u32, @builtin(instance_index) segment: u32) -> VertexOut {
    return strand_vertex(vertex, segment);
}
