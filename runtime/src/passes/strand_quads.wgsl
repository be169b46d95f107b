// Strands as camera-facing quads expanded from segments (wgpu lines are one pixel wide): the
// vertex stage shared by the passes that draw strands (their vertex entry points call
// `strand_draw_vertex`).
//
// Six vertices (two triangles) per segment, drawn either as one instance per segment
// (`draw(0..6, segments)`) or as one instance of six vertices per segment (`draw(6·first ..
// 6·end, 0..1)`: on lavapipe, whose vertex stage runs each instance on its own, 15% faster for
// the whole hair). A quad is
// max(width, 1) pixels wide; a fiber thinner than a pixel keeps the one-pixel quad and carries
// its coverage width/1px in alpha (Svoboda §1.2.3), so the alpha summed across the strand equals
// its width in pixels.

#define_import_path strandlight::strand_quads

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
    _pad_a: f32,
    _pad_b: f32,
    _pad_c: f32,
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
    // Invariant: the env view's depth prepass and the fragment count's Equal-depth pass
    // (view_visibility.rs) are different pipelines over this vertex stage and must produce
    // bit-identical depths.
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

// A segment as every pass sees it: its end points, their tangents and clip positions, and the
// screen-space normal its quad is widened along.
struct SegmentFrame {
    index: u32,
    start: vec3<f32>,
    end: vec3<f32>,
    start_tangent: vec3<f32>,
    end_tangent: vec3<f32>,
    start_clip: vec4<f32>,
    end_clip: vec4<f32>,
    // Unit perpendicular of the segment on screen (isotropic pixels).
    normal: vec2<f32>,
};

fn segment_frame(segment: u32) -> SegmentFrame {
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
    let clip0 = frame.view_proj * vec4<f32>(p0, 1.0);
    let clip1 = frame.view_proj * vec4<f32>(p1, 1.0);
    // Screen direction in pixels (isotropic), and its perpendicular.
    let half_viewport = 0.5 * frame.viewport;
    let s0 = clip0.xy / clip0.w * half_viewport;
    let s1 = clip1.xy / clip1.w * half_viewport;
    var d = s1 - s0;
    if (dot(d, d) < 1e-12) { d = vec2<f32>(1.0, 0.0); }
    d = normalize(d);
    return SegmentFrame(
        i0, p0, p1, normalize(p1 - before), normalize(after - p0), clip0, clip1,
        vec2<f32>(-d.y, d.x),
    );
}

// Corner (end `at_end`, side `side` = ±1) of the quad of segment `f`.
fn quad_corner_of(f: SegmentFrame, at_end: bool, side: f32) -> VertexOut {
    var index = f.index;
    var clip = f.start_clip;
    var world = f.start;
    var tangent = f.start_tangent;
    if (at_end) {
        index = f.index + 1u;
        clip = f.end_clip;
        world = f.end;
        tangent = f.end_tangent;
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
    let half_viewport = 0.5 * frame.viewport;
    let offset_px = f.normal * (side * 0.5 * quad_px);
    clip = vec4<f32>(clip.xy + offset_px / half_viewport * clip.w, clip.zw);

    var out: VertexOut;
    out.clip = clip;
    out.world = world;
    out.tangent = tangent;
    out.color = attr.color;
    out.alpha = alpha;
    return out;
}

// Corner `vertex` of segment `segment`'s quad: the body of every strand vertex entry point (the
// sorted pass draws segments in another order than their instance index).
fn strand_vertex(vertex: u32, segment: u32) -> VertexOut {
    let c = corner(vertex);
    return quad_corner_of(segment_frame(segment), c.x > 0.5, c.y);
}

// Vertex `vertex` of instance `segment` of either way of drawing the quads (six vertices per
// instance, or six per segment in one instance).
fn strand_draw_vertex(vertex: u32, segment: u32) -> VertexOut {
    return strand_vertex(vertex % 6u, segment + vertex / 6u);
}
