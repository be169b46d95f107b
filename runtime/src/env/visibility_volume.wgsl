// SRBF lobe visibility from the visibility volume (visibility/volume.rs) in the env view
// shading: the 16 SH coefficients of T(ω) interpolated trilinearly at the shaded point once,
// then per lobe Σ c_lm (i_l/i_0)(λ) Y_lm(ξ) (visibility/spherical_harmonics.rs, same basis,
// same order, same band ratios).

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

// Trilinear, clamped at the border (VisibilityVolume::coefficients_at).
fn volume_coefficients(world: vec3<f32>) -> Sh16 {
    let last = vec3<f32>(volume.dims.xyz) - vec3<f32>(1.0);
    let f = clamp((world - volume.origin.xyz) / volume.spacing.x, vec3<f32>(0.0), last);
    let lower = min(floor(f), max(last - vec3<f32>(1.0), vec3<f32>(0.0)));
    let w = min(f - lower, vec3<f32>(1.0));
    let base = vec3<u32>(lower);
    var out: Sh16;
    for (var corner = 0u; corner < 8u; corner++) {
        let bits = vec3<u32>(corner & 1u, (corner >> 1u) & 1u, (corner >> 2u) & 1u);
        let wb = select(vec3<f32>(1.0) - w, w, bits == vec3<u32>(1u));
        let weight = wb.x * wb.y * wb.z;
        if (weight == 0.0) { continue; }
        let idx = min(base + bits, volume.dims.xyz - vec3<u32>(1u));
        let v = volume_vertex_index(idx) * 4u;
        for (var k = 0u; k < 4u; k++) {
            out.c[k] += weight * volume_sh[v + k];
        }
    }
    return out;
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

// The lobe-weighted visibility of the SRBF (ξ, 1/λ) from the point's coefficients, in [0, 1].
fn volume_lobe_visibility(c: Sh16, xi: vec3<f32>, inv_lambda: f32) -> f32 {
    let r = srbf_band_ratios(1.0 / inv_lambda);
    let y = sh_basis16(normalize(xi));
    // Coefficient bands: 0 | 1 1 1 | 2 2 2 2 2 | 3 3 3 3 3 3 3.
    let b0 = c.c[0] * y.c[0];
    let b1 = c.c[1] * y.c[1];
    let b2 = c.c[2] * y.c[2];
    let b3 = c.c[3] * y.c[3];
    let v = r.x * b0.x + r.y * (b0.y + b0.z + b0.w)
        + r.z * (b1.x + b1.y + b1.z + b1.w + b2.x)
        + r.w * (b2.y + b2.z + b2.w + b3.x + b3.y + b3.z + b3.w);
    return clamp(v, 0.0, 1.0);
}
