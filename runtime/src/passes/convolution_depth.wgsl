// Deep opacity depth map (DODM) of Ren 2010 §5 (eq. 10), appended to strand_quads.wgsl and drawn
// from one light's orthographic camera after a depth prepass that left the nearest fiber depth
// z0 per texel. The four channels hold CUMULATIVE optical depths l(z_k) from z0 to the layer
// boundaries z_k = k(k+1)d/2 (k = 1, 2, 3) behind z0, the fourth channel everything (z_4 = ∞):
// a fragment at relative depth δ adds its τ to every boundary with z_k > δ. τ = −ln(1 − α) per
// fragment as in deep_opacity.wgsl, scaled by 1/κ when only a κ fraction of the strands is drawn
// (stochastic simplification, §7; the vertex stage has then also widened the fibers by 1/κ,
// spreading each one's optical depth, so the map keeps the coverage of those left out).

struct DodmParams {
    near: f32,
    far: f32,
    // d: depth of the first layer (world units).
    first_layer: f32,
    // 1/κ.
    tau_scale: f32,
};

@group(1) @binding(0) var nearest_depth: texture_depth_2d;
@group(1) @binding(1) var<uniform> dodm: DodmParams;

// An opaque fiber still lets exp(−6.9) ≈ 0.1% through, which keeps τ finite.
const DODM_MAX_ALPHA: f32 = 0.999;

@fragment
fn fs_dodm(in: VertexOut) -> @location(0) vec4<f32> {
    let z0 = textureLoad(nearest_depth, vec2<i32>(in.clip.xy), 0);
    let delta = max(in.clip.z - z0, 0.0) * (dodm.far - dodm.near);
    let tau = -log(1.0 - min(in.alpha, DODM_MAX_ALPHA)) * dodm.tau_scale;
    var out = vec4<f32>(0.0, 0.0, 0.0, tau);
    for (var k = 0u; k < 3u; k++) {
        let boundary = f32((k + 1u) * (k + 2u) / 2u) * dodm.first_layer;
        if (boundary > delta) { out[k] = tau; }
    }
    return out;
}
