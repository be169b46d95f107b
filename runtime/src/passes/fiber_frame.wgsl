// The fiber-frame quantities the physically based models need, from the tangent t, the direction
// toward the light l and toward the eye e (all unit): sin θ_i = t·l, sin θ_o = t·e, and cos φ
// between the projections of l and e on the normal plane. Where either projection vanishes
// (a direction along the fiber) φ is undefined; cos φ = 1 there, as the CPU's
// atan2(0, 0) = 0 gives.
#define_import_path strandlight::fiber_frame

struct FiberFrame {
    sin_theta_i: f32,
    sin_theta_o: f32,
    cos_phi: f32,
    // |sin φ| (φ ∈ [0, π]): with cos φ it gives φ = atan2(sin φ, cos φ), accurate at every φ where
    // acos(cos φ) loses digits near 0 and π.
    sin_phi: f32,
};

fn fiber_frame(t: vec3<f32>, l: vec3<f32>, e: vec3<f32>) -> FiberFrame {
    let sin_i = clamp(dot(t, l), -1.0, 1.0);
    let sin_o = clamp(dot(t, e), -1.0, 1.0);
    let lp = l - sin_i * t;
    let ep = e - sin_o * t;
    let norms = dot(lp, lp) * dot(ep, ep);
    var cos_phi = 1.0;
    var sin_phi = 0.0;
    if (norms > 1e-20) {
        let inv = inverseSqrt(norms);
        cos_phi = clamp(dot(lp, ep) * inv, -1.0, 1.0);
        sin_phi = min(length(cross(lp, ep)) * inv, 1.0);
    }
    return FiberFrame(sin_i, sin_o, cos_phi, sin_phi);
}
