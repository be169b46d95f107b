// The artist-friendly model of Sadeghi et al. 2010 (eqs. 5–12) in closed form, as the fiber model
// of strand_shading.wgsl:
//   S = Σ_X C_X I_X g'(β_X², θ_h − α_X) N'_X(φ) / max(|cos θ_d|, 1e-4)²
// with g'(σ², x) = exp(−x²/(2σ²)) of unit height, N'_R = N'_TRT−G = cos(φ/2),
// N'_TT = g'(γ_TT², π − |φ|), N'_G = g'(γ_G², G_angle − |φ|) (I_g and C_G folded into its weight),
// θ_h = (θ_i + θ_o)/2, θ_d = (θ_o − θ_i)/2, φ ∈ [0, π].

#import strandlight::fiber_frame::{FiberFrame, fiber_frame}

struct ArtistLobes {
    // Per lobe (R, TT, TRT − G, glints): colour × intensity in xyz.
    weight: array<vec4<f32>, 4>,
    // Longitudinal shift α and width β per lobe, radians.
    alpha: vec4<f32>,
    beta: vec4<f32>,
    gamma_tt: f32,
    gamma_glint: f32,
    glint_half_angle: f32,
    min_cos_theta_d: f32,
};

@group(2) @binding(0) var<uniform> artist: ArtistLobes;

fn unit_height_gaussian(sigma: f32, x: f32) -> f32 {
    let z = x / sigma;
    return exp(-0.5 * z * z);
}

const ARTIST_PI: f32 = 3.14159265358979;

fn artist_s(f: FiberFrame) -> vec3<f32> {
    // atan2 rather than asin/acos: the glint and highlight Gaussians are a few degrees wide, so
    // their relative error is (angle offset / width²) × the angle's absolute error.
    let cos_i = sqrt(max(0.0, 1.0 - f.sin_theta_i * f.sin_theta_i));
    let cos_o = sqrt(max(0.0, 1.0 - f.sin_theta_o * f.sin_theta_o));
    let theta_i = atan2(f.sin_theta_i, cos_i);
    let theta_o = atan2(f.sin_theta_o, cos_o);
    let theta_h = 0.5 * (theta_i + theta_o);
    let cos_d = max(abs(cos(0.5 * (theta_o - theta_i))), artist.min_cos_theta_d);
    let phi = atan2(f.sin_phi, f.cos_phi);
    let half_phi_cos = cos(0.5 * phi);
    let azimuthal = vec4<f32>(
        half_phi_cos,
        unit_height_gaussian(artist.gamma_tt, ARTIST_PI - phi),
        half_phi_cos,
        unit_height_gaussian(artist.gamma_glint, artist.glint_half_angle - phi),
    );
    var s = vec3<f32>(0.0);
    for (var p = 0u; p < 4u; p++) {
        let m = unit_height_gaussian(artist.beta[p], theta_h - artist.alpha[p]);
        s += artist.weight[p].xyz * (m * azimuthal[p]);
    }
    return s / (cos_d * cos_d);
}

// Outgoing radiance per unit irradiance E of the light (strand_shading.wgsl multiplies by E):
// L = S · cos θ_i. The per-strand colour is not used: the artist's colours are the model's.
fn fiber_radiance(t: vec3<f32>, l: vec3<f32>, e: vec3<f32>, color: vec3<f32>) -> vec3<f32> {
    let f = fiber_frame(t, l, e);
    let cos_i = sqrt(max(0.0, 1.0 - f.sin_theta_i * f.sin_theta_i));
    return artist_s(f) * cos_i;
}
