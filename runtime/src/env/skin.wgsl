// The head's skin in the env-lit view: a Lambertian surface
// of albedo `view.skin.rgb` under the batch's lights, each seen through the hair and the head
// as the fibers see it (effective_transmittance, with the head's depth maps), or through the
// visibility volume for SRBF lobes that read it. Radiance = albedo/π · Σ_j T_j · E_j(n), with
// E_j the irradiance of light j on the normal n:
//   directional: L_j · max(n·ω_j, 0) (L_j is the light's irradiance);
//   SRBF:        L_j · ∫ G(ω; ξ_j, λ_j) max(n·ω, 0) dω, Hill's fitted closed form (2016,
//                "Irradiance from a spherical Gaussian"), mirrored by head::srbf_irradiance in
//                Rust and tested there against f64 quadrature.
// Multiple scattering from the hair onto the skin is left out.

#define_import_path strandlight::skin

#import strandlight::convolution_transmittance::{batch, env_lights, shading_samples, effective_transmittance}
#import strandlight::env_shading::shades_from_volume
#import strandlight::view_binding::view
#import strandlight::visibility_volume::volume_lobe_visibility

// Broad lobes (λ < 3): the zonal harmonics l ≤ 2 (head::srbf_irradiance_sh2).
fn srbf_irradiance_sh2(c: f32, lambda: f32) -> f32 {
    let l = lambda;
    let e = exp(-2.0 * l);
    let i0 = (1.0 - e) / l;
    let i1 = 1.0 / l - 1.0 / (l * l) + e * (1.0 / l + 1.0 / (l * l));
    let m2 = (1.0 / l - 2.0 / (l * l) + 2.0 / (l * l * l))
        - e * (1.0 / l + 2.0 / (l * l) + 2.0 / (l * l * l));
    let i2 = (3.0 * m2 - i0) / 2.0;
    return 3.141592654 * (0.5 * i0 + i1 * c + 0.625 * i2 * (3.0 * c * c - 1.0) / 2.0);
}

// ∫ exp(λ(ω·ξ − 1)) max(n·ω, 0) dω for cos = n·ξ and λ = 1/inv_lambda.
fn srbf_irradiance(cos_n_xi: f32, inv_lambda: f32) -> f32 {
    let lambda = 1.0 / inv_lambda;
    if (lambda < 3.0) { return max(srbf_irradiance_sh2(cos_n_xi, lambda), 0.0); }
    let eml = exp(-lambda);
    let em2l = eml * eml;
    let scale = 1.0 + 2.0 * em2l - inv_lambda;
    let bias = (eml - em2l) * inv_lambda - em2l;
    let x = sqrt(max(1.0 - scale, 0.0));
    let x0 = 0.36 * cos_n_xi;
    let x1 = x / (4.0 * 0.36);
    var y = clamp(cos_n_xi, 0.0, 1.0);
    if (abs(x0) <= x1) {
        let n = x0 + x1;
        y = n * n / x;
    }
    let integral = 6.283185307 * inv_lambda * (1.0 - em2l);
    return max(scale * y + bias, 0.0) * integral;
}

// Skin radiance at `world` with normal `n` under the batch's lights.
fn shade_skin(world: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    let with_volume = shades_from_volume();
    // The light maps' lookup point is lifted off the surface by two of their texels, so that the
    // head's own depth in the maps does not shadow the skin it was drawn from (acne).
    var e = vec3<f32>(0.0);
    for (var slot = 0u; slot < batch.light_count; slot++) {
        let light = env_lights[slot];
        var visible: f32;
        if (with_volume && light.direction.w > 0.0) {
            // No lift: the volume's vertices inside the head hold what the surface sees outward
            // (visibility/volume.rs). The light maps of volume batches are placeholders, whose
            // texel size would lift the point out of the hair altogether.
            visible = volume_lobe_visibility(world, light.direction.xyz, light.direction.w);
        } else {
            let lift = 2.0 / max(light.texels_per_unit, 1e-6);
            visible = effective_transmittance(slot, world + n * lift);
        }
        if (visible <= 0.0) { continue; }
        for (var s = light.first_sample; s < light.first_sample + light.sample_count; s++) {
            let sample = shading_samples[s];
            let c = dot(n, sample.direction.xyz);
            var irradiance: f32;
            if (sample.direction.w > 0.0) {
                irradiance = srbf_irradiance(c, sample.direction.w);
            } else {
                irradiance = max(c, 0.0);
            }
            e += visible * irradiance * sample.rgb.xyz;
        }
    }
    return view.skin.rgb * e / 3.141592654;
}
