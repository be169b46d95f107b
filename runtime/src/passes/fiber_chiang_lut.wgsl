// Chiang et al. 2016 through its two point-light lookup tables (fiber_lut.wgsl), as the fiber
// model of strand_shading.wgsl. The far-field model (the near-field one averaged over the fiber's
// width) factors into a longitudinal term of the two inclinations and an azimuthal term of
// cos φ and the viewer's inclination, lobe by lobe (R, TT, TRT and the residual p ≥ 3):
//   S · cos θ_i = Σ_p M_p(sin θ_i, sin θ_o) · N̄_p(cos φ, sin θ_o).

#import strandlight::fiber_frame::fiber_frame
#import strandlight::fiber_lut::{bilinear, lut, lut_azimuth, m_value, n_value}

// Outgoing radiance per unit irradiance E of the light (strand_shading.wgsl multiplies by E): the
// integrand S · cos θ_i of L_o = ∫ S L_i cos θ_i dω_i for a light from one direction. The
// per-strand colour is not used: the fiber's colour is its absorption, baked in N̄.
fn fiber_radiance(t: vec3<f32>, l: vec3<f32>, e: vec3<f32>, color: vec3<f32>) -> vec3<f32> {
    let f = fiber_frame(t, l, e);
    let bm = bilinear(lut.m_axes[0], lut.m_axes[1], lut.m_strides, f.sin_theta_i, f.sin_theta_o);
    let bn = bilinear(lut.n_axes[0], lut.n_axes[1], lut.n_strides, lut_azimuth(f.cos_phi), f.sin_theta_o);
    var s = vec3<f32>(0.0);
    for (var p = 0u; p < 4u; p++) {
        s += m_value(bm, p) * n_value(bn, p);
    }
    return max(s, vec3<f32>(0.0));
}
