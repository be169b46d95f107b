// Kajiya-Kay as the fiber model of strand_shading.wgsl (uses the Frame constants kd, ks,
// shininess).

#import strandlight::strand_quads::frame

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

// Outgoing radiance per unit light irradiance E (strand_shading.wgsl multiplies by E): for Kajiya-Kay the
// diffuse term's sin(t, l) is the cos θ_i of the other models.
fn fiber_radiance(t: vec3<f32>, l: vec3<f32>, e: vec3<f32>, color: vec3<f32>) -> vec3<f32> {
    return kajiya_kay(t, l, e, color);
}
