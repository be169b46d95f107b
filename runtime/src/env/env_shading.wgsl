// The env-lit shading of one fiber point (Ren 2010 §3.1, §5, §6): it loops over the batch's
// light slots (one shadow map each) and each slot's shading samples (the light itself, or the
// reference's sub-texel lights sharing the slot's visibility), and sums
//   single:   T̃_j(x) · I(u·ξ_j, u·ω_o, cos Δφ, 1/λ_j) · L_j
//   multiple: power_j · T_f,j(x) · I_G(u·ξ_j, u·ω_o, cos Δφ, σ̄_f,j(x))
// For directional lights `I` is the direct table S·cos θ_i and L_j the irradiance
// (table_lookup.wgsl).
#define_import_path strandlight::env_shading

#import strandlight::convolution_transmittance::{batch, env_lights, shading_samples, effective_transmittance, FLAG_GRID, FLAG_UNSHADOWED}
#import strandlight::fiber_frame::fiber_frame
#import strandlight::strand_quads::frame
#import strandlight::table_lookup::{single_lookup, multiple_lookup}
#import strandlight::view_binding::{view, grid_values}
#import strandlight::view_layers::{NO_LAYER_LIGHTS, load_fixed}
#import strandlight::visibility_volume::{volume_enabled, volume_lobe_visibility}

fn grid_vertex(slot: u32, i: vec3<u32>) -> vec4<f32> {
    let d = view.dims.xyz;
    return grid_values[((slot * d.z + i.z) * d.y + i.y) * d.x + i.x];
}

// [T_r, T_g, T_b, σ̄_f] of light `slot` at `world`: trilinear, clamped at the border.
fn forward_scattering(slot: u32, world: vec3<f32>) -> vec4<f32> {
    let d = view.dims.xyz;
    let last = vec3<f32>(d) - vec3<f32>(1.0);
    let f = clamp((world - view.origin.xyz) / view.spacing.xyz, vec3<f32>(0.0), last);
    let lower = min(floor(f), max(last - vec3<f32>(1.0), vec3<f32>(0.0)));
    let w = select(f - lower, vec3<f32>(0.0), last < vec3<f32>(1.0));
    let i = vec3<u32>(lower);
    let step = vec3<u32>(select(vec3<f32>(1.0), vec3<f32>(0.0), last < vec3<f32>(1.0)));
    var acc = vec4<f32>(0.0);
    for (var corner = 0u; corner < 8u; corner++) {
        let bits = vec3<u32>(corner & 1u, (corner >> 1u) & 1u, (corner >> 2u) & 1u);
        let wb = select(vec3<f32>(1.0) - w, w, bits == vec3<u32>(1u));
        acc += wb.x * wb.y * wb.z * grid_vertex(slot, i + bits * step);
    }
    return acc;
}

struct EnvOut {
    @location(0) single: vec4<f32>,
    @location(1) multiple: vec4<f32>,
};

fn toward_eye(world: vec3<f32>) -> vec3<f32> {
    if (frame.eye.w > 0.5) { return normalize(frame.eye.xyz - world); }
    return frame.toward_eye.xyz;
}

// SRBF lobes integrate the visibility volume's T over the lobe instead of reading their light
// maps (visibility_volume.wgsl); directional lights keep their maps.
fn shades_from_volume() -> bool {
    return volume_enabled() && (batch.flags & FLAG_UNSHADOWED) == 0u;
}

// Single and multiple scattering of the fiber at `world` along `tangent` under the batch's
// lights, times `weight` (pre-multiplied; the weight is also the alpha written). A layer of the
// layered view passes `layer_lights`, the word of its fibers' Σw·v for light slot 0
// (view_layers.wgsl); NO_LAYER_LIGHTS reads each light's visibility at `world`.
fn shade(world: vec3<f32>, tangent: vec3<f32>, weight: f32, layer_lights: u32) -> EnvOut {
    let with_grid = (batch.flags & FLAG_GRID) != 0u;
    return shade_lights(world, tangent, weight, layer_lights, with_grid, shades_from_volume());
}

// `shade` for a frame of single scattering whose lights all read their light maps (no grid, no
// visibility volume): with both known false when the pipeline is compiled, their code goes,
// and a software adapter compiles and runs a smaller shader (a first look).
fn shade_single_from_light_maps(world: vec3<f32>, tangent: vec3<f32>, weight: f32) -> EnvOut {
    return shade_lights(world, tangent, weight, NO_LAYER_LIGHTS, false, false);
}

fn shade_lights(
    world: vec3<f32>,
    tangent: vec3<f32>,
    weight: f32,
    layer_lights: u32,
    with_grid: bool,
    with_volume: bool,
) -> EnvOut {
    let t = normalize(tangent);
    let e = toward_eye(world);
    var single = vec3<f32>(0.0);
    var multiple = vec3<f32>(0.0);
    for (var slot = 0u; slot < batch.light_count; slot++) {
        let light = env_lights[slot];
        var visible: f32;
        if (layer_lights != NO_LAYER_LIGHTS) {
            visible = clamp(load_fixed(layer_lights + slot) / weight, 0.0, 1.0);
        } else if (with_volume && light.direction.w > 0.0) {
            visible = volume_lobe_visibility(world, light.direction.xyz, light.direction.w);
        } else {
            visible = effective_transmittance(slot, world);
        }
        var g = vec4<f32>(0.0);
        if (with_grid) { g = forward_scattering(slot, world); }
        for (var s = light.first_sample; s < light.first_sample + light.sample_count; s++) {
            let sample = shading_samples[s];
            let f = fiber_frame(t, sample.direction.xyz, e);
            let coords = vec4<f32>(f.sin_theta_i, f.sin_theta_o, f.cos_phi, sample.direction.w);
            single += visible * single_lookup(coords) * sample.rgb.xyz;
            if (with_grid) {
                let cm = vec4<f32>(coords.xyz, g.w);
                multiple += sample.power.xyz * g.xyz * multiple_lookup(cm);
            }
        }
    }
    var out: EnvOut;
    out.single = vec4<f32>(single * weight, weight);
    out.multiple = vec4<f32>(multiple * weight, weight);
    return out;
}
