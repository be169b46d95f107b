//! The name of every table axis that a baked asset carries, in one place: the bakers
//! (`strandlight_precompute`) write these names and the runtime checks them before it indexes a
//! table, so a table of the wrong kind is refused instead of read with the wrong meaning.
//!
//! The strings are stored in baked assets and caches: changing one makes every existing asset
//! unreadable. Conventions (docs `DESIGN.md`, "Fiber frame" and "Table axes"): `u` is the fiber
//! tangent (root to tip); for a direction ω, `sin θ = u·ω` is the sine of the inclination from
//! the fiber's normal plane, θ ∈ [−π/2, π/2]; φ is the azimuth in the normal plane.

// --- Env tables (Ren 2010 §4, §6): the convolution table I, the direct table and I_G ---
// Axes 0–2 are shared by the three; axis 3 tells them apart.

/// u·ξ ∈ [−1, 1]: sine of the inclination of the light's centre direction ξ (an SRBF's centre,
/// or a directional light's direction). Axis 0 of every env table.
pub const AXIS_U_DOT_XI: &str = "u_dot_xi";
/// u·ω_o ∈ [−1, 1]: sine of the inclination of the view direction ω_o. Axis 1 of every env
/// table.
pub const AXIS_U_DOT_WO: &str = "u_dot_wo";
/// cos(φ_ξ − φ_o) ∈ [−1, 1]: cosine of the azimuth between the light's centre and the view
/// direction. Axis 2 of every env table.
pub const AXIS_COS_DPHI: &str = "cos_dphi";
/// 1/λ ∈ [1/λ_max, 1/λ_min] (default [1/64, 1/16]): the inverse SRBF bandwidth, axis 3 of the
/// convolution table I. The direct table (directional lights) has one node here, at 0.
pub const AXIS_INV_LAMBDA: &str = "inv_lambda";
/// σ̄_f ∈ [0, σ̄_f,max] radians (default max 1): the forward-scattering spread's longitudinal
/// standard deviation, axis 3 of the multiple-scattering table I_G (Ren 2010 eq. 11).
pub const AXIS_SIGMA_F: &str = "sigma_f";

// --- Forward-scattering tables of the multiple-scattering grid (Ren 2010 §6) ---

/// ν ∈ [0, ν_max] radians (default max 1): the direction deviation of the fibers in a voxel,
/// axis 0 of the attenuation ratio α(ν, θ).
pub const AXIS_NU: &str = "nu";
/// |sin θ| ∈ [0, 1]: the light's inclination from the voxel's mean fiber direction, axis 1 of
/// the attenuation ratio (α is even in θ).
pub const AXIS_ABS_SIN_THETA: &str = "abs_sin_theta";
/// |u·ξ| ∈ [0, 1]: an SRBF centre's inclination, axis 0 of the SRBF spread table σ²(θ_ξ, λ)
/// (even in u·ξ).
pub const AXIS_ABS_U_DOT_XI: &str = "abs_u_dot_xi";
/// λ ∈ [λ_min, λ_max]: the SRBF bandwidth, axis 1 of the SRBF spread table.
pub const AXIS_LAMBDA: &str = "lambda";

// --- Dual-scattering fiber averages (Zinke 2008) ---

/// sin θ ∈ [−1, 1]: the inclination of the fiber averages, axis 0 of `fiber_averages`.
pub const AXIS_SIN_THETA: &str = "sin_theta";
/// A discrete index, one node per quantity (axis 1 of `fiber_averages`: the nine averages
/// a_f, a_b, α_f, α_b, β²_f, β²_b, A_b, Δ_b, σ²_b; axis 2 of the point-light M table: M_R,
/// M_TT, M_TRT, cos θ_d).
pub const AXIS_QUANTITY: &str = "quantity";

// --- Point-light lookup tables (Hunz 2016 Algorithm 2) ---

/// sin θ_i ∈ [−1, 1]: the light's inclination, axis 0 of the M table.
pub const AXIS_SIN_THETA_I: &str = "sin_theta_i";
/// sin θ_o ∈ [−1, 1]: the view's inclination, axis 1 of the M table.
pub const AXIS_SIN_THETA_O: &str = "sin_theta_o";
/// cos φ ∈ [−1, 1] (φ = φ_o − φ_i ∈ [0, π]): axis 0 of an N table indexed by the azimuth's
/// cosine.
pub const AXIS_COS_PHI: &str = "cos_phi";
/// cos(φ/2) ∈ [0, 1]: axis 0 of an N table indexed by the half azimuth (finer near φ = π,
/// where the TT lobe is narrow).
pub const AXIS_COS_HALF_PHI: &str = "cos_half_phi";
/// cos θ_d ∈ [0, 1] (θ_d = (θ_o − θ_i)/2): axis 1 of the N table.
pub const AXIS_COS_THETA_D: &str = "cos_theta_d";
/// The lobe index 0, 1, 2 (R, TT, TRT): axis 2 of the N table.
pub const AXIS_LOBE: &str = "lobe";

#[cfg(test)]
mod tests {
    use super::*;

    /// Baked assets store these strings: a rename must be a deliberate format change.
    #[test]
    fn axis_names_are_the_ones_baked_assets_carry() {
        let names = [
            AXIS_U_DOT_XI,
            AXIS_U_DOT_WO,
            AXIS_COS_DPHI,
            AXIS_INV_LAMBDA,
            AXIS_SIGMA_F,
            AXIS_NU,
            AXIS_ABS_SIN_THETA,
            AXIS_ABS_U_DOT_XI,
            AXIS_LAMBDA,
            AXIS_SIN_THETA,
            AXIS_QUANTITY,
            AXIS_SIN_THETA_I,
            AXIS_SIN_THETA_O,
            AXIS_COS_PHI,
            AXIS_COS_HALF_PHI,
            AXIS_COS_THETA_D,
            AXIS_LOBE,
        ];
        assert_eq!(
            names,
            [
                "u_dot_xi",
                "u_dot_wo",
                "cos_dphi",
                "inv_lambda",
                "sigma_f",
                "nu",
                "abs_sin_theta",
                "abs_u_dot_xi",
                "lambda",
                "sin_theta",
                "quantity",
                "sin_theta_i",
                "sin_theta_o",
                "cos_phi",
                "cos_half_phi",
                "cos_theta_d",
                "lobe",
            ]
        );
    }
}
