// Sampling strandlight's exported lookup tables (`strandlight bake --export ktx2`).
//
// Each table is one KTX2 texture plus a JSON sidecar. The sidecar's `wgsl.uniform` holds the
// four StrandLutAxis values to put in a StrandLut uniform; its `sampling` section spells out
// the same formula as this file. Bind the texture with a sampler that filters linearly in
// every direction (min, mag; mipmaps: nearest, there is one level) and clamps to the edge.
// rgba16float / r16float filter everywhere; rgba32float / r32float need the
// `float32-filterable` feature (wgpu: Features::FLOAT32_FILTERABLE).
//
// Coordinates are the table's own, in axis order. For the env tables:
//   x = u·ξ (sine of the light's inclination from the fiber's normal plane; u the tangent),
//   y = u·ω_o (the same for the view direction),
//   z = cos(φ_ξ − φ_o) (the azimuth between the two, projected on the normal plane),
//   w = 1/λ (the SRBF's inverse bandwidth; 0 for the direct tables) or σ̄_f (multiple table).
// Out-of-range coordinates clamp to the table's edge, as on the CPU.

struct StrandLutAxis {
    // In the warped space: min of the axis and 1 / (max − min).
    min: f32,
    inv_range: f32,
    // Nodes − 1 (0 for a one-node axis).
    last_index: f32,
    // 1 / exponent of a power-spaced axis (1 otherwise).
    inv_exponent: f32,
    // 0: w = x; 1: w = asin(x) (nodes uniform in the angle of a sine); 2: w = −acos(x) (of a cosine).
    warp: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
};

struct StrandLut {
    axes: array<StrandLutAxis, 4>,
};

// The continuous node position f ∈ [0, n − 1] of coordinate x on an axis: node i at f = i.
fn strandlight_lut_position(a: StrandLutAxis, x: f32) -> f32 {
    if (a.last_index < 1.0) { return 0.0; }
    var w = x;
    if (a.warp == 1u) { w = asin(clamp(x, -1.0, 1.0)); }
    if (a.warp == 2u) { w = -acos(clamp(x, -1.0, 1.0)); }
    var t = clamp((w - a.min) * a.inv_range, 0.0, 1.0);
    if (a.inv_exponent != 1.0) { t = pow(t, a.inv_exponent); }
    return t * a.last_index;
}

// A table of three or four axes (a 3D texture): multilinear in all four, like the CPU's
// Table::lookup. Node i of an axis with n nodes is the centre of texel i, at (i + 0.5) / n;
// the hardware interpolates axes 0–2 inside one slab of the fourth axis, and the two slabs
// around the fourth coordinate are blended here. A three-axis table has a one-node fourth axis.
fn strandlight_lut_3d(tex: texture_3d<f32>, samp: sampler, lut: StrandLut, coords: vec4<f32>) -> vec4<f32> {
    let size = vec3<f32>(textureDimensions(tex));
    let f0 = strandlight_lut_position(lut.axes[0], coords.x);
    let f1 = strandlight_lut_position(lut.axes[1], coords.y);
    let f2 = strandlight_lut_position(lut.axes[2], coords.z);
    let f3 = strandlight_lut_position(lut.axes[3], coords.w);
    let slab = min(floor(f3), max(lut.axes[3].last_index - 1.0, 0.0));
    let upper_weight = f3 - slab;
    let n0 = lut.axes[0].last_index + 1.0;
    let xy = (vec2<f32>(f2, f1) + 0.5) / size.xy;
    let lower = textureSampleLevel(tex, samp, vec3<f32>(xy, (slab * n0 + f0 + 0.5) / size.z), 0.0);
    if (upper_weight == 0.0) { return lower; }
    let upper = textureSampleLevel(tex, samp, vec3<f32>(xy, ((slab + 1.0) * n0 + f0 + 0.5) / size.z), 0.0);
    return mix(lower, upper, upper_weight);
}

// The lower node of the cell holding x (x) and the upper node's weight (y).
fn strandlight_lut_cell(a: StrandLutAxis, x: f32) -> vec2<f32> {
    let f = strandlight_lut_position(a, x);
    let lower = min(floor(f), max(a.last_index - 1.0, 0.0));
    return vec2<f32>(lower, f - lower);
}

// strandlight_lut_3d without the hardware filter: the 16 nodes around the coordinates,
// weighted here. One-node axes get weight 0 on their (absent) upper node.
fn strandlight_lut_3d_exact(tex: texture_3d<f32>, lut: StrandLut, coords: vec4<f32>) -> vec4<f32> {
    var c = array<vec2<f32>, 4>(
        strandlight_lut_cell(lut.axes[0], coords.x),
        strandlight_lut_cell(lut.axes[1], coords.y),
        strandlight_lut_cell(lut.axes[2], coords.z),
        strandlight_lut_cell(lut.axes[3], coords.w),
    );
    let n0 = u32(lut.axes[0].last_index) + 1u;
    var acc = vec4<f32>(0.0);
    for (var corner = 0u; corner < 16u; corner++) {
        var weight = 1.0;
        var node = vec4<u32>(0u);
        for (var k = 0u; k < 4u; k++) {
            let upper = (corner >> k) & 1u;
            weight *= select(1.0 - c[k].y, c[k].y, upper == 1u);
            node[k] = u32(c[k].x) + upper;
        }
        if (weight == 0.0) { continue; }
        let texel = vec3<u32>(node.z, node.y, node.w * n0 + node.x);
        acc += weight * textureLoad(tex, texel, 0);
    }
    return acc;
}

// A table of one or two axes (a 2D texture): texel (x, y) = (node of axis 1, node of axis 0).
// A one-axis table is exported as if a one-node axis came first: pass its coordinate in `.y`.
fn strandlight_lut_2d(tex: texture_2d<f32>, samp: sampler, lut: StrandLut, coords: vec2<f32>) -> vec4<f32> {
    let size = vec2<f32>(textureDimensions(tex));
    let f = vec2<f32>(
        strandlight_lut_position(lut.axes[1], coords.y),
        strandlight_lut_position(lut.axes[0], coords.x),
    );
    return textureSampleLevel(tex, samp, (f + 0.5) / size, 0.0);
}

// strandlight_lut_2d without the hardware filter: the 4 nodes around the coordinates.
fn strandlight_lut_2d_exact(tex: texture_2d<f32>, lut: StrandLut, coords: vec2<f32>) -> vec4<f32> {
    let cx = strandlight_lut_cell(lut.axes[1], coords.y);
    let cy = strandlight_lut_cell(lut.axes[0], coords.x);
    var acc = vec4<f32>(0.0);
    for (var corner = 0u; corner < 4u; corner++) {
        let ux = corner & 1u;
        let uy = (corner >> 1u) & 1u;
        let weight = select(1.0 - cx.y, cx.y, ux == 1u) * select(1.0 - cy.y, cy.y, uy == 1u);
        if (weight == 0.0) { continue; }
        acc += weight * textureLoad(tex, vec2<u32>(u32(cx.x) + ux, u32(cy.x) + uy), 0);
    }
    return acc;
}
