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
//
// With `frame.exact_coverage` (the env view), a thin fiber covers each pixel by the length of
// its centre line inside the pixel's square times its width: the box filter of a thin line,
// which is what the path tracer's box pixel filter integrates. One sample at the pixel's centre
// of a one-pixel quad is that only on average: it gives a fiber crossing a pixel's corner the
// whole pixel's width, and one passing just beside the centre nothing. Its quad then reaches
// every pixel the line crosses (1/2 to √2/2 px beyond the line on every side), and the
// fragment stage clips the segment to its pixel (`exact_fragment`); pixels the quad reaches but
// the line does not get coverage 0 and are discarded.

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
    // 1: thin fibers' coverage is exact per pixel (above); 0: one-pixel quads.
    exact_coverage: u32,
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
    // Coverage × opacity (exact coverage of a thin fiber: width in pixels × opacity, the
    // coverage of one pixel's length of it, until `exact_fragment` clips).
    @location(3) alpha: f32,
    // Exact coverage of a thin fiber, in framebuffer pixels (x right, y down, as
    // @builtin(position)): its segment's end points p_i, p_i+1; the strand's two points before
    // (p_i−2, p_i−1) and after (p_i+2, p_i+3); which of those exist and whether the line is
    // thin (LINE_* bits; 0 for a one-pixel or wider quad).
    @location(4) @interpolate(flat) segment_px: vec4<f32>,
    @location(5) @interpolate(flat) before_px: vec4<f32>,
    @location(6) @interpolate(flat) after_px: vec4<f32>,
    @location(7) @interpolate(flat) line_flags: u32,
};

const LINE_THIN: u32 = 1u;
// p_i−1, p_i−2, p_i+2, p_i+3 exist (are points of the same strand).
const LINE_HAS_BEFORE_1: u32 = 2u;
const LINE_HAS_BEFORE_2: u32 = 4u;
const LINE_HAS_AFTER_1: u32 = 8u;
const LINE_HAS_AFTER_2: u32 = 16u;

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
    // Its entry in `segments`, and its first point's index.
    index_in_table: u32,
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
        segment, i0, p0, p1, normalize(p1 - before), normalize(after - p0), clip0, clip1,
        vec2<f32>(-d.y, d.x),
    );
}

// How far beyond a thin fiber's line its quad reaches, pixels, for a line along the unit
// vector d (on screen): a pixel's square projects onto any unit vector n as an interval of
// half-length (|n.x| + |n.y|)/2 about its centre, so a square the segment crosses has its
// centre within that of the line (n ⊥ d) and of the segment's ends along it (n = d), and
// |d.x| + |d.y| = |n.x| + |n.y| for n ⊥ d. From 1/2 px (a line along an axis) to √2/2
// (a diagonal); the margin keeps the centres on the quad's edge inside it.
fn thin_line_reach_px(d: vec2<f32>) -> f32 {
    return 0.5 * (abs(d.x) + abs(d.y)) + 1e-3;
}

fn fiber_width_px(index: u32, clip_w: f32) -> f32 {
    if (frame.width_override_px > 0.0) { return frame.width_override_px; }
    return attributes[index].thickness * frame.focal_px / clip_w;
}

// A segment whose coverage is clipped per pixel: exact coverage asked for (never with the light
// pass's widening: QuadStyle) and the fiber thinner than a pixel at both ends (wider fibers keep
// their quads).
fn is_thin_line(f: SegmentFrame) -> bool {
    if (frame.exact_coverage == 0u) { return false; }
    let start = fiber_width_px(f.index, f.start_clip.w);
    return max(start, fiber_width_px(f.index + 1u, f.end_clip.w)) < 1.0;
}

fn framebuffer_px(clip: vec4<f32>) -> vec2<f32> {
    let ndc = clip.xy / clip.w;
    return vec2<f32>(0.5 + 0.5 * ndc.x, 0.5 - 0.5 * ndc.y) * frame.viewport;
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
    let width_px = fiber_width_px(index, clip.w);
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
    var offset_px = f.normal * (side * 0.5 * quad_px);
    let thin_line = is_thin_line(f);
    if (thin_line) {
        let along = vec2<f32>(f.normal.y, -f.normal.x);
        offset_px = (f.normal * side + along * select(-1.0, 1.0, at_end)) * thin_line_reach_px(along);
        alpha = width_px * attr.opacity;
    }
    let half_viewport = 0.5 * frame.viewport;
    clip = vec4<f32>(clip.xy + offset_px / half_viewport * clip.w, clip.zw);

    var out: VertexOut;
    out.clip = clip;
    out.world = world;
    out.tangent = tangent;
    out.color = attr.color;
    out.alpha = alpha;
    out.line_flags = 0u;
    if (thin_line) {
        let line = line_around(f);
        out.segment_px = line.segment_px;
        out.before_px = line.before_px;
        out.after_px = line.after_px;
        out.line_flags = line.line_flags;
    }
    return out;
}

// A thin line's points in pixels, for `exact_fragment` (VertexOut's fields of the same names).
struct LineAround {
    segment_px: vec4<f32>,
    before_px: vec4<f32>,
    after_px: vec4<f32>,
    line_flags: u32,
};

fn line_around(f: SegmentFrame) -> LineAround {
    let packed = segments[f.index_in_table];
    var line = LineAround(
        vec4<f32>(framebuffer_px(f.start_clip), framebuffer_px(f.end_clip)),
        vec4<f32>(0.0),
        vec4<f32>(0.0),
        LINE_THIN,
    );
    if ((packed & 0x40000000u) == 0u) {
        line.line_flags |= LINE_HAS_BEFORE_1;
        line.before_px = vec4<f32>(0.0, 0.0, point_px(f.index - 1u));
        if ((segments[f.index_in_table - 1u] & 0x40000000u) == 0u) {
            line.line_flags |= LINE_HAS_BEFORE_2;
            line.before_px = vec4<f32>(point_px(f.index - 2u), line.before_px.zw);
        }
    }
    if ((packed & 0x80000000u) == 0u) {
        line.line_flags |= LINE_HAS_AFTER_1;
        line.after_px = vec4<f32>(point_px(f.index + 2u), 0.0, 0.0);
        if ((segments[f.index_in_table + 1u] & 0x80000000u) == 0u) {
            line.line_flags |= LINE_HAS_AFTER_2;
            line.after_px = vec4<f32>(line.after_px.xy, point_px(f.index + 3u));
        }
    }
    return line;
}

fn point_px(i: u32) -> vec2<f32> {
    return framebuffer_px(frame.view_proj * vec4<f32>(point(i), 1.0));
}

// The length of segment a→b inside the box [lo, hi] (Liang–Barsky clipping).
fn length_in_box(a: vec2<f32>, b: vec2<f32>, lo: vec2<f32>, hi: vec2<f32>) -> f32 {
    let d = b - a;
    var t0 = 0.0;
    var t1 = 1.0;
    for (var axis = 0u; axis < 2u; axis++) {
        if (abs(d[axis]) < 1e-12) {
            if (a[axis] < lo[axis] || a[axis] > hi[axis]) { return 0.0; }
        } else {
            let ta = (lo[axis] - a[axis]) / d[axis];
            let tb = (hi[axis] - a[axis]) / d[axis];
            t0 = max(t0, min(ta, tb));
            t1 = min(t1, max(ta, tb));
        }
    }
    return max(t1 - t0, 0.0) * length(d);
}

// The fragment with its exact coverage of its pixel in `alpha` (other fragments as drawn):
// what every pass of the env view reads. A thin line covers the pixel by its length in the
// pixel × its width. A pixel's fragments compose as 1 − Π(1 − α), right for fibers that lie at
// random in it, but a strand's own pieces in one pixel lie end to end and their coverage adds:
// each piece takes its share, by length, of the optical depth −ln(1 − α_strand) of the strand's
// pieces in the pixel (those of the two segments either side of it joined to it inside the
// pixel, which is every piece unless the strand runs through the pixel in more than three
// segments), so that they compose to α_strand. A fragment of alpha 0 lies in the quad's reach
// but off the line, and is to be discarded.
fn exact_fragment(in: VertexOut) -> VertexOut {
    var out = in;
    if ((in.line_flags & LINE_THIN) == 0u) { return out; }
    let lo = floor(in.clip.xy);
    let hi = lo + 1.0;
    let own = length_in_box(in.segment_px.xy, in.segment_px.zw, lo, hi);
    if (own <= 0.0) {
        out.alpha = 0.0;
        return out;
    }
    // The strand's pieces joined to this one inside the pixel (a strand that leaves the pixel
    // and comes back composes as two fibers).
    var strand = own;
    if ((in.line_flags & LINE_HAS_BEFORE_1) != 0u && inside(in.segment_px.xy, lo, hi)) {
        strand += length_in_box(in.before_px.zw, in.segment_px.xy, lo, hi);
        if ((in.line_flags & LINE_HAS_BEFORE_2) != 0u && inside(in.before_px.zw, lo, hi)) {
            strand += length_in_box(in.before_px.xy, in.before_px.zw, lo, hi);
        }
    }
    if ((in.line_flags & LINE_HAS_AFTER_1) != 0u && inside(in.segment_px.zw, lo, hi)) {
        strand += length_in_box(in.segment_px.zw, in.after_px.xy, lo, hi);
        if ((in.line_flags & LINE_HAS_AFTER_2) != 0u && inside(in.after_px.xy, lo, hi)) {
            strand += length_in_box(in.after_px.xy, in.after_px.zw, lo, hi);
        }
    }
    if (strand == own) {
        out.alpha = min(in.alpha * own, EXACT_MAX_ALPHA);
        return out;
    }
    let strand_alpha = min(in.alpha * strand, EXACT_MAX_ALPHA);
    out.alpha = 1.0 - pow(1.0 - strand_alpha, own / strand);
    return out;
}

fn inside(p: vec2<f32>, lo: vec2<f32>, hi: vec2<f32>) -> bool {
    return all(p >= lo) && all(p <= hi);
}

// A strand's coverage of one pixel at most (so that its optical depth stays finite).
const EXACT_MAX_ALPHA: f32 = 0.999;

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

// The fragment a view pass draws: `drawn` with its exact coverage (`exact_fragment`), discarded
// where the pixel is in its quad's reach but off its line (it covers nothing there).
fn covered_fragment(drawn: VertexOut) -> VertexOut {
    let in = exact_fragment(drawn);
    if ((in.line_flags & LINE_THIN) != 0u && in.alpha <= 0.0) { discard; }
    return in;
}
