// Kajiya-Kay shading of the strand quads (strand_quads.wgsl) under several point lights,
// written with pre-multiplied alpha.

// Kajiya-Kay with t the tangent, l toward the light, e toward the eye:
//   L = E · (kd · color · sin(t, l) + ks · max(0, sin(t, l) sin(t, e) − (t·l)(t·e))^p),
// the specular term being cos of the angle between e and the cone of mirror directions.
fn kajiya_kay(t: vec3<f32>, l: vec3<f32>, e: vec3<f32>, color: vec3<f32>) -> vec3<f32> {
    let tl = dot(t, l);
    let te = dot(t, e);
    let sin_tl = sqrt(max(0.0, 1.0 - tl * tl));
    let sin_te = sqrt(max(0.0, 1.0 - te * te));
    let cone = max(0.0, sin_tl * sin_te - tl * te);
    return frame.kd * color * sin_tl + vec3<f32>(frame.ks * pow(cone, frame.shininess));
}

// Direction toward the light and the irradiance it brings to `world`.
fn light_at(light: Light, world: vec3<f32>) -> vec4<f32> {
    let kind = light.position_or_direction.w;
    if (kind < 0.5) {
        return vec4<f32>(light.position_or_direction.xyz, light.intensity.x);
    }
    let to_light = light.position_or_direction.xyz - world;
    let d2 = max(dot(to_light, to_light), 1e-12);
    let l = to_light * inverseSqrt(d2);
    var e = light.intensity.x / d2;
    if (kind > 1.5 && dot(-l, light.spot.xyz) < light.spot.w) { e = 0.0; }
    return vec4<f32>(l, e);
}

@fragment
fn fs_main(in: VertexOut) -> @location(0) vec4<f32> {
    let t = normalize(in.tangent);
    var e = frame.toward_eye.xyz;
    if (frame.eye.w > 0.5) { e = normalize(frame.eye.xyz - in.world); }
    var radiance = vec3<f32>(0.0);
    for (var i = 0u; i < frame.light_count; i++) {
        let li = light_at(lights[i], in.world);
        radiance += li.w * kajiya_kay(t, li.xyz, e, in.color);
    }
    // Pre-multiplied alpha (Svoboda §2.5): blending is "one, one − source alpha".
    return vec4<f32>(radiance * in.alpha, in.alpha);
}
