// Deep opacity depth map (DODM) of Ren 2010 §5 (eq. 10) of the strand quads (strand_quads.wgsl): one
// light's orthographic map, rasterized in compute. Each invocation takes one segment's quad
// (the two triangles `quad_corner_of` gives every pass that draws strands) and visits the texel
// centres it covers, interpolating depth and alpha in the covering triangle as the fixed-function
// rasterizer does. Texel quads are a few texels in size: a hardware rasterizer is fast at them,
// lavapipe's spends ~1 µs per triangle, which made this pass most of an env-lit frame on a CPU.
//
// 1. splat_nearest: the nearest fiber depth z0 per texel (atomicMax of the bit-inverted depth, so
//    that a zeroed scratch buffer means "nothing drawn").
// 2. splat_layers: CUMULATIVE optical depths l(z_k) from z0 to the layer boundaries
//    z_k = k(k+1)d/2 (k = 1, 2, 3) behind z0, the fourth channel everything (z_4 = ∞): a
//    fragment at relative depth δ counts towards every boundary with z_k > δ. It adds its τ
//    to its own layer only, one atomic, and the resolve sums the layers front to back.
//    τ = −ln(1 − α) per fragment as in deep_opacity.wgsl, scaled by 1/κ when only a κ fraction
//    of the strands is drawn (stochastic simplification, §7; the quads are then also widened by
//    1/κ, spreading each fiber's optical depth, so the map keeps the coverage of those left
//    out). WGSL has no float atomics: the depths are summed in fixed point.
// 3. resolve: the scratch into the slot's layer of the two textures the view pass and the
//    summed-area tables read, zeroing the scratch for the next light.

#import strandlight::strand_quads::{SegmentFrame, quad_corner_of, segment_frame}

struct DodmParams {
    near: f32,
    far: f32,
    // d: depth of the first layer (world units).
    first_layer: f32,
    // 1/κ.
    tau_scale: f32,
    resolution: u32,
    // Segments in `windows` (the invocations that do work).
    segment_count: u32,
    window_count: u32,
    // Invocations per row of the dispatch grid (workgroups in x × 64).
    row_length: u32,
};

@group(1) @binding(0) var<uniform> dodm: DodmParams;
// The light's strand windows: (first segment, count).
@group(1) @binding(1) var<storage, read> windows: array<vec2<u32>>;
// Per texel: !bits(z0), 0 where nothing is drawn.
@group(1) @binding(2) var<storage, read_write> nearest_scratch: array<atomic<u32>>;
// Per texel: the optical depth in each of the four layers between the boundaries, in units of
// 1/TAU_UNITS (the resolve sums them into the cumulative depths).
@group(1) @binding(3) var<storage, read_write> layers_scratch: array<atomic<u32>>;

@group(2) @binding(0) var nearest_out: texture_storage_2d<r32float, write>;
@group(2) @binding(1) var optical_out: texture_storage_2d<rgba32float, write>;

// An opaque fiber still lets exp(−6.9) ≈ 0.1% through, which keeps τ finite.
const DODM_MAX_ALPHA: f32 = 0.999;
// Optical depth is summed in fixed point, 1/TAU_UNITS a unit (16 times finer than the
// summed-area tables' units). One fragment adds at most the tables' per-texel clamp
// MAX_TEXEL_TAU (summed_area.wgsl): more could change no value they read.
const TAU_UNITS: f32 = 4096.0;
const MAX_FRAGMENT_TAU: f32 = 16.0;

// The `i`-th segment of the light's windows.
fn window_segment(i: u32) -> u32 {
    var rest = i;
    for (var w = 0u; w < dodm.window_count; w++) {
        let window = windows[w];
        if (rest < window.y) { return window.x + rest; }
        rest -= window.y;
    }
    return 0u;
}

// A quad corner in texel coordinates (y down, as the viewport transform) with its depth and alpha.
struct Corner {
    xy: vec2<f32>,
    z: f32,
    alpha: f32,
};

fn quad_corner(f: SegmentFrame, at_end: bool, side: f32) -> Corner {
    let v = quad_corner_of(f, at_end, side);
    let ndc = v.clip.xyz / v.clip.w;
    let res = f32(dodm.resolution);
    return Corner(vec2<f32>(0.5 + 0.5 * ndc.x, 0.5 - 0.5 * ndc.y) * res, ndc.z, v.alpha);
}

fn cross2(a: vec2<f32>, b: vec2<f32>) -> f32 {
    return a.x * b.y - a.y * b.x;
}

// What the rasterizer interpolates at a covered texel centre.
struct Fragment {
    covered: bool,
    z: f32,
    alpha: f32,
};

// Triangle (a, b, c) at p: covered when p is inside or on an edge (either winding).
fn triangle_fragment(a: Corner, b: Corner, c: Corner, p: vec2<f32>) -> Fragment {
    let area = cross2(b.xy - a.xy, c.xy - a.xy);
    if (abs(area) < 1e-12) { return Fragment(false, 0.0, 0.0); }
    let wa = cross2(c.xy - b.xy, p - b.xy) / area;
    let wb = cross2(a.xy - c.xy, p - c.xy) / area;
    let wc = 1.0 - wa - wb;
    if (wa < 0.0 || wb < 0.0 || wc < 0.0) { return Fragment(false, 0.0, 0.0); }
    return Fragment(true, wa * a.z + wb * b.z + wc * c.z, wa * a.alpha + wb * b.alpha + wc * c.alpha);
}

// The quad's corners in the order of strand_quads.wgsl's two triangles (0,−)(1,−)(0,+) and
// (0,+)(1,−)(1,+): named, not an array, which the CPU driver would keep in memory.
struct Quad {
    c0: Corner,
    c1: Corner,
    c2: Corner,
    c3: Corner,
};

fn segment_quad(segment: u32) -> Quad {
    let f = segment_frame(segment);
    return Quad(
        quad_corner(f, false, -1.0),
        quad_corner(f, true, -1.0),
        quad_corner(f, false, 1.0),
        quad_corner(f, true, 1.0),
    );
}

// The quad at texel centre p: the first triangle, else the second (the diagonal counts once).
// The edge across the segment's end is open, so that a texel centre on a joint belongs to the
// next segment only (the rasterizer's fill rule does the same). Fragments outside the depth
// range are clipped, as the rasterizer does.
fn quad_fragment(q: Quad, p: vec2<f32>) -> Fragment {
    var f = triangle_fragment(q.c0, q.c1, q.c2, p);
    if (!f.covered) { f = triangle_fragment(q.c2, q.c1, q.c3, p); }
    if (cross2(q.c3.xy - q.c1.xy, p - q.c1.xy) == 0.0) { f.covered = false; }
    if (f.z < 0.0 || f.z > 1.0) { f.covered = false; }
    return f;
}

// The y extent (x: lowest, y: highest) of edge a–b inside the column strip [x0, x0 + 1], merged
// into `rows` (unchanged where the edge misses the strip).
fn edge_rows(a: vec2<f32>, b: vec2<f32>, x0: f32, rows: vec2<f32>) -> vec2<f32> {
    let dx = b.x - a.x;
    var t0 = 0.0;
    var t1 = 1.0;
    if (abs(dx) > 1e-12) {
        let ta = (x0 - a.x) / dx;
        let tb = (x0 + 1.0 - a.x) / dx;
        t0 = max(min(ta, tb), 0.0);
        t1 = min(max(ta, tb), 1.0);
    } else if (a.x < x0 || a.x > x0 + 1.0) {
        return rows;
    }
    if (t0 > t1) { return rows; }
    let y0 = mix(a.y, b.y, t0);
    let y1 = mix(a.y, b.y, t1);
    return vec2<f32>(min(rows.x, min(y0, y1)), max(rows.y, max(y0, y1)));
}

// The y extent of the quad's boundary inside the column strip [x0, x0 + 1]: a superset of the
// rows whose centres the quad can cover there, so a long diagonal segment costs its texels, not
// its bounding box.
fn column_rows(q: Quad, x0: f32) -> vec2<f32> {
    var rows = vec2<f32>(1e30, -1e30);
    rows = edge_rows(q.c0.xy, q.c1.xy, x0, rows);
    rows = edge_rows(q.c1.xy, q.c3.xy, x0, rows);
    rows = edge_rows(q.c3.xy, q.c2.xy, x0, rows);
    rows = edge_rows(q.c2.xy, q.c0.xy, x0, rows);
    return rows;
}

fn texel_index(x: i32, y: i32) -> u32 {
    return u32(y) * dodm.resolution + u32(x);
}

// The segment of invocation `id` (none past the windows' end).
fn invocation_segment(id: vec3<u32>) -> i32 {
    let i = id.y * dodm.row_length + id.x;
    if (i >= dodm.segment_count) { return -1; }
    return i32(window_segment(i));
}

// Adds `units` to bin `i`, saturating: a wrap (which the old value tells) is followed by a max,
// and an add to a saturated bin always wraps, so a bin that ever wrapped ends saturated whatever
// the order of the adds.
fn add_optical_depth(i: u32, units: u32) {
    let old = atomicAdd(&layers_scratch[i], units);
    if (old > 0xffffffffu - units) { atomicMax(&layers_scratch[i], 0xffffffffu); }
}

// Visits every texel centre the quad covers: `stage` 0 records the nearest depth, 1 adds the
// optical depths.
fn splat(segment: u32, stage: u32) {
    let q = segment_quad(segment);
    let last = i32(dodm.resolution) - 1;
    let min_x = min(min(q.c0.xy.x, q.c1.xy.x), min(q.c2.xy.x, q.c3.xy.x));
    let max_x = max(max(q.c0.xy.x, q.c1.xy.x), max(q.c2.xy.x, q.c3.xy.x));
    // Texel centres x + 0.5 within [min_x, max_x].
    let x_first = max(i32(ceil(min_x - 0.5)), 0);
    let x_last = min(i32(floor(max_x - 0.5)), last);
    for (var x = x_first; x <= x_last; x++) {
        let rows = column_rows(q, f32(x));
        let y_first = max(i32(ceil(rows.x - 0.5)), 0);
        let y_last = min(i32(floor(rows.y - 0.5)), last);
        for (var y = y_first; y <= y_last; y++) {
            let f = quad_fragment(q, vec2<f32>(f32(x) + 0.5, f32(y) + 0.5));
            if (!f.covered) { continue; }
            let t = texel_index(x, y);
            if (stage == 0u) {
                atomicMax(&nearest_scratch[t], ~bitcast<u32>(f.z));
                continue;
            }
            let z0 = bitcast<f32>(~atomicLoad(&nearest_scratch[t]));
            let delta = max(f.z - z0, 0.0) * (dodm.far - dodm.near);
            let tau = -log(1.0 - min(f.alpha, DODM_MAX_ALPHA)) * dodm.tau_scale;
            let units = u32(round(min(tau, MAX_FRAGMENT_TAU) * TAU_UNITS));
            if (units == 0u) { continue; }
            // The layer [z_k, z_k+1) holding δ (z_0 = 0; the last is unbounded).
            var bin = 3u;
            for (var k = 2u; k < 3u; k--) {
                if (f32((k + 1u) * (k + 2u) / 2u) * dodm.first_layer > delta) { bin = k; }
            }
            add_optical_depth(4u * t + bin, units);
        }
    }
}

@compute @workgroup_size(64)
fn splat_nearest(@builtin(global_invocation_id) id: vec3<u32>) {
    let segment = invocation_segment(id);
    if (segment >= 0) { splat(u32(segment), 0u); }
}

@compute @workgroup_size(64)
fn splat_layers(@builtin(global_invocation_id) id: vec3<u32>) {
    let segment = invocation_segment(id);
    if (segment >= 0) { splat(u32(segment), 1u); }
}

@compute @workgroup_size(8, 8)
fn resolve(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= dodm.resolution || id.y >= dodm.resolution) { return; }
    let t = texel_index(i32(id.x), i32(id.y));
    let inverted = atomicExchange(&nearest_scratch[t], 0u);
    var z0 = 1.0;
    if (inverted != 0u) { z0 = bitcast<f32>(~inverted); }
    // Each layer's optical depth, summed into those in front: l_k = Σ_{j ≤ k} layer_j.
    var l = vec4<f32>(0.0);
    var cumulative = 0.0;
    for (var k = 0u; k < 4u; k++) {
        cumulative += f32(atomicExchange(&layers_scratch[4u * t + k], 0u)) / TAU_UNITS;
        l[k] = cumulative;
    }
    textureStore(nearest_out, vec2<u32>(id.xy), vec4<f32>(z0, 0.0, 0.0, 0.0));
    textureStore(optical_out, vec2<u32>(id.xy), l);
}
