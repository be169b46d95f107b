// Marschner through its two point-light lookup tables (fiber_lut.wgsl; Hunz 2016 Algorithm 2),
// as the fiber model of strand_shading.wgsl:
//   S = Σ_p M_p(sin θ_i, sin θ_o) · N_p(cos φ, cos θ_d) / max(cos²θ_d, 1e-8),
// cos θ_d being the M table's fourth quantity.

#import strandlight::fiber_frame::{FiberFrame, fiber_frame}
#import strandlight::fiber_lut::{bilinear, lut, lut_azimuth, m_value, n_value}

// S (1/sr, RGB) at a fiber frame.
fn marschner_lut_s(f: FiberFrame) -> vec3<f32> {
    let bm = bilinear(lut.m_axes[0], lut.m_axes[1], lut.m_strides, f.sin_theta_i, f.sin_theta_o);
    let cos_d = clamp(m_value(bm, 3u), 0.0, 1.0);
    let bn = bilinear(lut.n_axes[0], lut.n_axes[1], lut.n_strides, lut_azimuth(f.cos_phi), cos_d);
    var s = vec3<f32>(0.0);
    for (var p = 0u; p < 3u; p++) {
        s += m_value(bm, p) * n_value(bn, p);
    }
    return s / max(cos_d * cos_d, lut.min_cos2_theta_d);
}

// Outgoing radiance per unit irradiance E of the light (strand_shading.wgsl multiplies by E):
// L = S · cos θ_i, the integrand of L_o = ∫ S L_i cos θ_i dω_i for a light from one direction.
// The per-strand colour is not used: the fiber's colour is its absorption, baked in N.
fn fiber_radiance(t: vec3<f32>, l: vec3<f32>, e: vec3<f32>, color: vec3<f32>) -> vec3<f32> {
    let f = fiber_frame(t, l, e);
    let cos_i = sqrt(max(0.0, 1.0 - f.sin_theta_i * f.sin_theta_i));
    return marschner_lut_s(f) * cos_i;
}
