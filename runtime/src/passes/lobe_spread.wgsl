// Lobe spread (lobe_spread.rs), appended after convolution_transmittance.wgsl: an SRBF light's
// visibility as the mean of exp(−τ) over directions of its lobe, each τ marched along a sheared
// line through the light's own DODM columns.

const TWO_PI: f32 = 6.283185307;

fn lobe_spread_enabled() -> bool {
    return batch.spread.x > 0u;
}

// 1 − cos γ at quantile q of the SRBF exp(λ(cos γ − 1)) over the sphere.
fn srbf_quantile(q: f32, inv_lambda: f32) -> f32 {
    if (inv_lambda > 1e3) { return 2.0 * q; }
    let lambda = 1.0 / inv_lambda;
    let tail = 1.0 - exp(-2.0 * lambda);
    return min(-log(1.0 - q * tail) * inv_lambda, 2.0);
}

// Optical depth of column `texel` between the absolute depths z − far_offset and z − near_offset
// (world units behind the map's near plane; the column's front z0 from its nearest depth).
fn column_optical_depth(slot: u32, texel: vec2<i32>, z: f32, near_offset: f32, far_offset: f32) -> f32 {
    let light = env_lights[slot];
    let z0 = textureLoad(dodm_depth, texel, i32(slot), 0).r * (light.far - light.near);
    if (z0 >= z - near_offset) { return 0.0; }
    var l = box_mean(slot, texel, 0);
    if ((batch.flags & FLAG_SAT_TRANSMITTANCE) != 0u) {
        // One texel's transmittances back to its optical depths.
        l = -log(max(l, vec4<f32>(1.0 / SAT_TRANSMITTANCE_SCALE)));
    }
    let deep = layered_optical_depth(l, z - near_offset - z0, light.first_layer);
    let shallow = layered_optical_depth(l, max(z - far_offset - z0, 0.0), light.first_layer);
    return deep - shallow;
}

fn inside_map(p: vec2<f32>) -> bool {
    let res = f32(batch.resolution);
    return all(p >= vec2<f32>(0.0)) && all(p < vec2<f32>(res));
}

// τ from the point (at map position `p` in texels, depth `z`) toward the light along a line
// tilted by `shift` texels per unit of depth: the last `reach` before the point marched through
// the columns the line crosses, the rest read from the point's own column.
fn sheared_optical_depth(slot: u32, p: vec2<f32>, z: f32, shift: vec2<f32>) -> f32 {
    let reach = min(z, batch.spread_shape.x * env_lights[slot].first_layer);
    var tau = 0.0;
    if (z > reach) {
        tau = column_optical_depth(slot, vec2<i32>(p), z, reach, z);
    }
    let steps = batch.spread.z;
    var previous = 0.0;
    for (var i = 1u; i <= steps; i++) {
        let delta = reach * f32(i) / f32(steps);
        let q = p + shift * (0.5 * (previous + delta));
        if (!inside_map(q)) { break; }
        tau += column_optical_depth(slot, vec2<i32>(q), z, previous, delta);
        previous = delta;
    }
    return tau;
}

// Direction k of a lobe: the march's shift (texels per unit of depth toward the light) and the
// world direction it stands for.
struct SpreadDirection {
    shift: vec2<f32>,
    omega: vec3<f32>,
};

// The world directions of a light map's +x and +y texel axes (rows run down): its
// projection's first two rows.
fn map_axes(light: EnvLightGpu) -> mat2x3<f32> {
    let m = light.view_proj;
    let right = normalize(vec3<f32>(m[0].x, m[1].x, m[2].x));
    let down = -normalize(vec3<f32>(m[0].y, m[1].y, m[2].y));
    return mat2x3<f32>(right, down);
}

fn spread_direction(light: EnvLightGpu, axes: mat2x3<f32>, cos_g: f32, phi: f32) -> SpreadDirection {
    let sin_g = sqrt(max(0.0, 1.0 - cos_g * cos_g));
    let side = vec2<f32>(cos(phi), sin(phi));
    var d: SpreadDirection;
    d.shift = batch.spread_shape.y * (sin_g / cos_g) * light.texels_per_unit * side;
    d.omega = cos_g * light.direction.xyz + sin_g * (axes * side);
    return d;
}

// The lobe's visibility at `world`: the mean of exp(−τ) over its ring directions, each weighted
// by `spread_weight` (the fiber's response to it, where the module defines one; t and e are the
// fiber's tangent and the direction toward the eye).
fn lobe_spread_transmittance(slot: u32, world: vec3<f32>, t: vec3<f32>, e: vec3<f32>) -> f32 {
    let light = env_lights[slot];
    let clip = light.view_proj * vec4<f32>(world, 1.0);
    let uv = vec2<f32>(0.5 + 0.5 * clip.x, 0.5 - 0.5 * clip.y);
    let p = uv * f32(batch.resolution);
    if (!inside_map(p)) { return 1.0; }
    let z = clip.z * (light.far - light.near);
    let rings = batch.spread.x;
    let per_ring = batch.spread.y;
    let axes = map_axes(light);
    var sum = 0.0;
    var weights = 0.0;
    for (var r = 0u; r < rings; r++) {
        let cos_g = max(1.0 - srbf_quantile((f32(r) + 0.5) / f32(rings), light.direction.w), 0.05);
        for (var j = 0u; j < per_ring; j++) {
            // Alternate rings are turned by half a step, so the directions interleave.
            let phi = TWO_PI * (f32(j) + 0.5 * f32(r & 1u)) / f32(per_ring);
            let d = spread_direction(light, axes, cos_g, phi);
            let w = spread_weight(d.omega, t, e);
            sum += w * exp(-sheared_optical_depth(slot, p, z, d.shift));
            weights += w;
        }
    }
    if (weights <= 0.0) { return 1.0; }
    return sum / weights;
}
