// Forward-scattering shadow paths on the GPU: the expected-value march of shadow_paths.rs (the
// recursions and why they replace Ren's random paths are in that file's notes), one invocation
// per (sample, light), in f32. The per-voxel medium (extinction and fiber event under each light)
// comes from the CPU's table lookups, so both sources march the very same medium.
// Layouts: medium[(light · voxels + v) · 2 + {0, 1}] = [k, ā_f.rgb], [β̄_f².rgb, σ²_SRBF];
// values[light · samples + sample] = [T_r, T_g, T_b, σ̄_f].

struct MarchParams {
    origin: vec3<f32>,
    voxel_size: f32,
    dims: vec3<u32>,
    samples: u32,
    lights: u32,
    // Start points per axis of the one-voxel box filter.
    taps: u32,
    step_fraction: f32,
    // 1: T_f counts the zero-hit (direct) paths too.
    include_direct: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
    _pad3: u32,
};

@group(0) @binding(0) var<uniform> params: MarchParams;
@group(0) @binding(1) var<storage, read> medium: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read> sample_points: array<vec4<f32>>;
// xyz: toward the light; w: its d_f (Zinke's density factor).
@group(0) @binding(3) var<storage, read> light_directions: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read_write> values: array<vec4<f32>>;

struct ShadowPath {
    no_hit: f32,
    product: vec3<f32>,
    weighted_variance: vec3<f32>,
    weighted_first_variance: vec3<f32>,
    plain_variance: f32,
};

fn voxel_count() -> u32 {
    return params.dims.x * params.dims.y * params.dims.z;
}

fn linear_index(i: vec3<u32>) -> u32 {
    return (i.z * params.dims.y + i.y) * params.dims.x + i.x;
}

// The voxel holding p, or −1 outside the grid (written so that a NaN coordinate is outside).
fn voxel_of(p: vec3<f32>) -> i32 {
    let q = (p - params.origin) / params.voxel_size;
    let inside = (q >= vec3<f32>(0.0)) & (q < vec3<f32>(params.dims));
    if (!all(inside)) {
        return -1;
    }
    return i32(linear_index(min(vec3<u32>(q), params.dims - 1u)));
}

fn voxel_clamped(p: vec3<f32>) -> u32 {
    let q = max((p - params.origin) / params.voxel_size, vec3<f32>(0.0));
    return linear_index(min(vec3<u32>(q), params.dims - 1u));
}

// [t0, t1, 1] of the ray p + t·d (t ≥ 0) inside the grid's box, or z = 0 when it misses.
fn ray_interval(p: vec3<f32>, d: vec3<f32>) -> vec3<f32> {
    let lo = params.origin;
    let hi = params.origin + vec3<f32>(params.dims) * params.voxel_size;
    var t0 = 0.0;
    var t1 = 3.0e38;
    for (var k = 0u; k < 3u; k++) {
        if (abs(d[k]) < 1e-12) {
            if (p[k] < lo[k] || p[k] > hi[k]) {
                return vec3<f32>(0.0);
            }
            continue;
        }
        let a = (lo[k] - p[k]) / d[k];
        let b = (hi[k] - p[k]) / d[k];
        t0 = max(t0, min(a, b));
        t1 = min(t1, max(a, b));
    }
    return vec3<f32>(t0, t1, select(0.0, 1.0, t0 <= t1));
}

// One step of optical depth mu through a voxel whose hits do (a, b2) and bring the SRBF
// variance first_variance when they are the first (shadow_paths.rs, ExpectedShadowPath::step).
fn step_path(path: ptr<function, ShadowPath>, mu: f32, a: vec3<f32>, b2: vec3<f32>, first_variance: f32) {
    let none = exp(-mu);
    let f = exp(-mu * (vec3<f32>(1.0) - a));
    (*path).weighted_first_variance = f * (*path).weighted_first_variance
        + first_variance * (*path).no_hit * (f - vec3<f32>(none));
    (*path).weighted_variance = f * (*path).weighted_variance + mu * a * f * b2 * (*path).product;
    (*path).product *= f;
    (*path).no_hit *= none;
    (*path).plain_variance += mu * (b2.x + b2.y + b2.z) / 3.0;
}

// From outside the volume to `point`, toward the light, from the light's side inward.
fn march(point: vec3<f32>, xi: vec3<f32>, light: u32, max_step: f32) -> ShadowPath {
    var path = ShadowPath(1.0, vec3<f32>(1.0), vec3<f32>(0.0), vec3<f32>(0.0), 0.0);
    let interval = ray_interval(point, xi);
    let length = interval.y - interval.x;
    if (interval.z == 0.0 || !(length > 0.0) || !(max_step > 0.0)) {
        return path;
    }
    let steps = u32(max(ceil(length / max_step), 1.0));
    let delta = length / f32(steps);
    let base = light * voxel_count();
    for (var k = 0u; k < steps; k++) {
        let t = interval.y - (f32(k) + 0.5) * delta;
        let v = voxel_of(point + xi * t);
        if (v < 0) {
            continue;
        }
        let m0 = medium[(base + u32(v)) * 2u];
        if (m0.x > 0.0) {
            let m1 = medium[(base + u32(v)) * 2u + 1u];
            step_path(&path, m0.x * delta, m0.yzw, m1.xyz, m1.w);
        }
    }
    return path;
}

@compute @workgroup_size(64)
fn march_samples(@builtin(global_invocation_id) id: vec3<u32>) {
    let sample = id.x;
    let light = id.y;
    if (sample >= params.samples || light >= params.lights) {
        return;
    }
    let xi = light_directions[light].xyz;
    let h = params.voxel_size;
    let taps = max(params.taps, 1u);
    let df = light_directions[light].w;
    var transmittance = vec3<f32>(0.0);
    var variance_numerator = vec3<f32>(0.0);
    var plain_variance = 0.0;
    for (var i = 0u; i < taps * taps * taps; i++) {
        let ijk = vec3<u32>(i % taps, (i / taps) % taps, i / (taps * taps));
        let offset = ((vec3<f32>(ijk) + 0.5) / f32(taps) - 0.5) * h;
        let p = sample_points[sample].xyz + offset;
        let path = march(p, xi, light, params.step_fraction * h);
        let direct_variance = medium[(light * voxel_count() + voxel_clamped(p)) * 2u + 1u].w;
        let scattered = df * max(path.product - vec3<f32>(path.no_hit), vec3<f32>(0.0));
        let spread = df * (4.0 * path.weighted_variance + path.weighted_first_variance);
        if (params.include_direct != 0u) {
            transmittance += path.no_hit + scattered;
            variance_numerator += path.no_hit * direct_variance + spread;
        } else {
            transmittance += scattered;
            variance_numerator += spread;
        }
        plain_variance += 4.0 * path.plain_variance + direct_variance;
    }
    let n = f32(taps * taps * taps);
    let total = transmittance.x + transmittance.y + transmittance.z;
    var variance = plain_variance / n;
    if (total > 1e-20) {
        variance = (variance_numerator.x + variance_numerator.y + variance_numerator.z) / total;
    }
    values[light * params.samples + sample] = vec4<f32>(transmittance / n, sqrt(max(variance, 0.0)));
}
