// SRBF lobe visibility from the visibility volume (visibility/volume.rs) in the env view
// shading: per lobe, each of the 8 vertices around the shaded point gives Σ c_lm (i_l/i_0)(λ)
// Y_lm(ξ) (visibility/spherical_harmonics.rs, same basis, same order, same band ratios), and
// the point takes their trilinear mean in the logarithm (VisibilityVolume::lobe_visibility:
// transmittance falls exponentially into the hair, and a mean of the values themselves lit the
// surface fibers as if half outside).

#define_import_path strandlight::visibility_volume

struct VolumeParams {
    // xyz: world position of vertex (0,0,0); w: 1 when SRBF lobes read the volume.
    origin: vec4<f32>,
    // xyz: vertices per axis.
    dims: vec4<u32>,
    // x: distance between vertices.
    spacing: vec4<f32>,
};

@group(3) @binding(6) var<uniform> volume: VolumeParams;
// Four vec4 (16 coefficients) per vertex, x fastest.
@group(3) @binding(7) var<storage, read> volume_sh: array<vec4<f32>>;

struct Sh16 {
    c: array<vec4<f32>, 4>,
};

fn volume_enabled() -> bool {
    return volume.origin.w > 0.5;
}

fn volume_vertex_index(i: vec3<u32>) -> u32 {
    let d = volume.dims.xyz;
    return (i.z * d.y + i.y) * d.x + i.x;
}

fn sh_basis16(d: vec3<f32>) -> Sh16 {
    let x = d.x;
    let y = d.y;
    let z = d.z;
    var b: Sh16;
    b.c[0] = vec4<f32>(0.2820948, 0.4886025 * y, 0.4886025 * z, 0.4886025 * x);
    b.c[1] = vec4<f32>(1.0925485 * x * y, 1.0925485 * y * z, 0.3153916 * (3.0 * z * z - 1.0),
        1.0925485 * x * z);
    b.c[2] = vec4<f32>(0.5462742 * (x * x - y * y), 0.5900436 * y * (3.0 * x * x - y * y),
        2.8906114 * x * y * z, 0.4570458 * y * (5.0 * z * z - 1.0));
    b.c[3] = vec4<f32>(0.3731763 * z * (5.0 * z * z - 3.0), 0.4570458 * x * (5.0 * z * z - 1.0),
        1.4453057 * z * (x * x - y * y), 0.5900436 * x * (x * x - 3.0 * y * y));
    return b;
}

// (i_l/i_0)(λ), l = 0..3 (srbf_band_ratios).
fn srbf_band_ratios(lambda_in: f32) -> vec4<f32> {
    let l = max(lambda_in, 0.0);
    if (l < 0.5) {
        let l2 = l * l;
        return vec4<f32>(
            1.0,
            l / 3.0 * (1.0 - l2 / 15.0 + 2.0 * l2 * l2 / 315.0),
            l2 / 15.0 * (1.0 - 2.0 * l2 / 21.0 + l2 * l2 / 105.0),
            l2 * l / 105.0 * (1.0 - l2 / 9.0));
    }
    var coth = 1.0;
    if (l <= 20.0) { coth = 1.0 / tanh(l); }
    let r1 = coth - 1.0 / l;
    let r2 = 1.0 - 3.0 * r1 / l;
    let r3 = r1 - 5.0 * r2 / l;
    return vec4<f32>(1.0, r1, r2, r3);
}

// The SRBF (ξ, 1/λ) as SH weights: Y_lm(ξ) (i_l/i_0)(λ). Coefficient bands:
// 0 | 1 1 1 | 2 2 2 2 2 | 3 3 3 3 3 3 3.
fn lobe_weights(xi: vec3<f32>, inv_lambda: f32) -> Sh16 {
    let r = srbf_band_ratios(1.0 / inv_lambda);
    var y = sh_basis16(normalize(xi));
    y.c[0] *= vec4<f32>(r.x, r.y, r.y, r.y);
    y.c[1] *= vec4<f32>(r.z);
    y.c[2] *= vec4<f32>(r.z, r.w, r.w, r.w);
    y.c[3] *= vec4<f32>(r.w);
    return y;
}

// The smallest visibility a vertex brings to the logarithmic blend (visibility/volume.rs,
// MIN_VERTEX_VISIBILITY).
const MIN_VERTEX_VISIBILITY: f32 = 1.2e-4;

// The lobe-weighted visibility of the SRBF (ξ, 1/λ) at `world`, in [0, 1]: the vertices'
// visibilities blended trilinearly in the logarithm, clamped at the border as
// volume_vertex_index's callers (VisibilityVolume::lobe_visibility).
fn volume_lobe_visibility(world: vec3<f32>, xi: vec3<f32>, inv_lambda: f32) -> f32 {
    let y = lobe_weights(xi, inv_lambda);
    let last = vec3<f32>(volume.dims.xyz) - vec3<f32>(1.0);
    let f = clamp((world - volume.origin.xyz) / volume.spacing.x, vec3<f32>(0.0), last);
    let lower = min(floor(f), max(last - vec3<f32>(1.0), vec3<f32>(0.0)));
    let w = min(f - lower, vec3<f32>(1.0));
    let base = vec3<u32>(lower);
    var log_v = 0.0;
    for (var corner = 0u; corner < 8u; corner++) {
        let bits = vec3<u32>(corner & 1u, (corner >> 1u) & 1u, (corner >> 2u) & 1u);
        let wb = select(vec3<f32>(1.0) - w, w, bits == vec3<u32>(1u));
        let weight = wb.x * wb.y * wb.z;
        if (weight == 0.0) { continue; }
        let idx = min(base + bits, volume.dims.xyz - vec3<u32>(1u));
        let v = volume_vertex_index(idx) * 4u;
        let d = dot(volume_sh[v], y.c[0]) + dot(volume_sh[v + 1u], y.c[1])
            + dot(volume_sh[v + 2u], y.c[2]) + dot(volume_sh[v + 3u], y.c[3]);
        log_v += weight * log(clamp(d, MIN_VERTEX_VISIBILITY, 1.0));
    }
    return exp(log_v);
}
