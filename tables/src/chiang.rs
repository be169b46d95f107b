//! Chiang, Bitterli, Tappan, Burley 2016, "A Practical and Controllable Hair and Fur Model for
//! Production Path Tracing", as pbrt-v4's `HairBxDF` and Mitsuba 3's `hair` BSDF define it —
//! the fiber of the project's path-traced ground truth — and its far-field average over the
//! fiber's width, which is what the tables of this project hold.
//!
//! # The near-field model (what Mitsuba evaluates)
//!
//! A ray from the viewer hits the fiber at offset h = sin γ_o across its width. Every path
//! through the cross section with p internal segments leaves in a lobe
//!
//! `f_p = M_p(θ_i, θ_o) · A_p(θ_o, h) · N_p(Δφ − Φ(p, h))`, p = 0 (R), 1 (TT), 2 (TRT),
//!
//! plus a residual for p ≥ 3, `M_3 · A_3 / (2π)`, uniform in azimuth. Mitsuba's `eval` returns
//! the sum (with the integrator's cosine already folded in: pbrt's `HairBxDF::f` is this sum
//! divided by |cos| to the surface normal, and its integrator multiplies that cosine back):
//! [`Chiang::near_field`]. Its pieces:
//!
//! * **M_p** is d'Eon et al. 2011's longitudinal term ([`crate::longitudinal::deon_longitudinal`],
//!   normalized so `∫ M cos θ_i dθ_i = 1`) with variance `v₀ = (0.726β_m + 0.812β_m² +
//!   3.7β_m²⁰)²`, v₁ = v₀/4, v₂ = v₃ = 4v₀. Mitsuba's `square_to_rough_fiber_pdf` is this M
//!   divided by 2π, and its `eval` multiplies the p < 3 lobes by 2π again, so the lobes carry
//!   M itself and the residual carries M/(2π). pbrt-v4 and Mitsuba evaluate I₀ with a 10-term
//!   series below 12 and a one-term asymptotic expansion above; [`BesselForm::PbrtMitsuba`]
//!   reproduces those (they differ from the exact d'Eon term by up to ≈ 0.6%), the default
//!   [`BesselForm::Exact`] is the overflow-safe exact form.
//! * **The scale tilt** α rotates the view inclination before M_p: θ_o − 2α for R, θ_o + α for
//!   TT, θ_o + 4α for TRT (pbrt's 2kα approximations; cos kept non-negative, i.e. reflected
//!   past the poles), none for the residual. With θ measured toward the tangent (this
//!   project's u, Mitsuba's local y), the lobes therefore peak at θ_h = (θ_i + θ_o)/2 =
//!   **+α, −α/2, −2α** ([`Chiang::lobe_shift`]; tested against the exact model's peak).
//! * **A_p**: Fresnel reflectance f at cos θ_o cos γ_o (the true incidence cosine on the
//!   cylinder), transmittance `T = exp(−σ_a · 2 cos γ_t / cos θ_t)` with sin θ_t = sin θ_o/η and
//!   sin γ_t = h/η′, η′ = √(η² − sin²θ_o)/cos θ_o (evaluated as h·cos θ_o/√(η² − sin²θ_o), which
//!   never divides by cos θ_o); A_0 = f, A_1 = (1 − f)²T, A_2 = A_1 T f, A_3 = A_2 f T/(1 − f T).
//! * **N_p**: the logistic of scale `s = √(π/8)(0.265β_n + 1.194β_n² + 5.372β_n²²)` trimmed to
//!   [−π, π], around the specular azimuth Φ(p, h) = 2pγ_t − 2γ_o + pπ, with Δφ = φ_light −
//!   φ_view (Mitsuba's `phi_o − phi_i`, where Mitsuba's `si.wi` points to the **viewer** and its
//!   `wo` to the **light**). The project's φ = φ_o − φ_i is −Δφ.
//!
//! Mitsuba's local frame: y = fiber tangent, z = the cylinder's surface normal at the hit, so
//! h = −x/√(x² + z²) of the view direction ([`Chiang::near_field_local`]).
//!
//! # The far-field model (what the tables hold)
//!
//! A pixel sees the fiber's whole width, so it averages the near-field value over h uniform in
//! [−1, 1]. With the project's convention `L_o = D ∫ S L_i cos θ_i dω_i` (crate docs), that
//! average is `∫ S cos θ_i dω_i`, so
//!
//! `S(θ_i, θ_o, φ) · cos θ_i = ½∫ value(h) dh = Σ_{p=0}^{3} M_p(θ_i, θ_o) · N̄_p(θ_o, φ)`,
//!
//! `N̄_p = ½∫ A_p N_p dh` for p < 3 and `N̄_3 = ½∫ A_3 dh / (2π)` ([`azimuthal`]). The h-average
//! depends only on the view (θ_o, φ), never on θ_i: it is computed once per fiber on a dense
//! (θ_o, φ) grid and interpolated ([`azimuthal::AzimuthalTable`], error measured in the tests),
//! while [`Chiang::eval_exact`] integrates it at every call. For σ_a = 0 the model conserves
//! energy exactly: ∫M_p cos θ_i dθ_i = 1, ∫N_p dφ = 1, Σ A_p = 1 (the white-furnace tests).
//! The model is not reciprocal (A_p and N̄_p belong to the view direction); S is even in φ.
//!
//! # As lobes for dual scattering ([`LobeDecomposition`])
//!
//! The fiber averages of [`crate::dual_scattering`] want `S ≈ Σ_p g(β_p², θ_h − α_p)
//! N_p(θ_d, φ)/cos²θ_d` with g a unit-area Gaussian in θ_h. For small variance d'Eon's M
//! tends to `δ(θ_i + θ_o)/cos θ_i` and a Gaussian of standard deviation β in θ_h has 2β in
//! θ_i, so `M_dEon(v) ≈ g(v/4, θ_h)/(2 cos θ_d)`: **β_p = √v_p / 2**, α_p as above, lobes R,
//! TT, TRT and the residual (α = 0, β = √v₃/2). Widths are clamped to [10⁻⁴, 3] rad: the
//! roughest fibers (β_m → 1, v₀ ≈ 27) have a d'Eon term that is flat over the sphere, which no
//! Gaussian in θ_h reproduces, and the clamp keeps the trait's width check (< π) satisfied.
//! The azimuthal term is `N̄_p(θ_o*, φ) / J_p(θ_o*)` at θ_o* = θ_d + α_p (the view inclination
//! at the lobe's centre, where θ_i = 2α_p − θ_o), with
//! `J_p(θ_o) = ∫ g(β_p², θ_h − α_p) cos²θ_i / cos²θ_d dθ_i` (≈ 2 for narrow lobes, less for
//! wide ones cut off at the poles), so that for every view the decomposition's
//! `∫ S cos θ_i dω_i` equals the exact model's lobe by lobe, up to the variation of N̄_p and
//! J_p across a lobe's width. Measured (tests): within 0.1% for views within 35° of the normal
//! plane, 1.5% at 57°; toward grazing views the Gaussians, cut off at the poles where d'Eon's
//! term wraps around them, lose up to 18% (brown fiber at 74°). The shape in θ is only the
//! Gaussian's. The exact model is not reciprocal, so its energy per *light* direction (what
//! dual scattering's ā_f + ā_b measure) differs from the per-view energy it conserves: a white
//! fiber lit at 86° sends out 1.34 of the light; the decomposition, nearly reciprocal by
//! construction, does not reproduce that excess.

pub mod azimuthal;
pub mod params;
#[cfg(test)]
mod tests;

pub use azimuthal::{AzimuthalResolution, AzimuthalTable, ViewGeometry};
pub use params::ChiangParams;

use crate::angles::FiberAngles;
use crate::dual_scattering::{LobeDecomposition, inverse_cos2_guarded, peaked_rule};
use crate::error::ParamError;
use crate::longitudinal::{deon_longitudinal, shifted_incidence};
use crate::scattering::{Rgb, ScatteringFunction};
use crate::special::gaussian;
use azimuthal::{P_MAX, trimmed_logistic, wrap_pi};
use glam::DVec3;
use std::f64::consts::{FRAC_PI_2, PI};
use std::sync::{Arc, OnceLock};

/// Number of lobes: R, TT, TRT and the residual p ≥ 3.
pub const LOBES: usize = 4;
/// Lobe names in index order.
pub const LOBE_NAMES: [&str; LOBES] = ["R", "TT", "TRT", "residual"];

/// Smallest longitudinal variance used (β_m = 0 would be a delta): affects β_m < 1.4·10⁻⁵.
pub const MIN_VARIANCE: f64 = 1e-10;
/// Smallest logistic scale used (β_n = 0 would be a delta): affects β_n < 6·10⁻⁶.
pub const MIN_LOGISTIC_SCALE: f64 = 1e-6;
/// Floor of cos θ_i in `S = (S cos θ_i) / cos θ_i` (θ_i within 10⁻¹² rad of a pole).
pub const MIN_COS_THETA_I: f64 = 1e-12;
/// Bounds of the decomposition's lobe widths β_p, radians (see the module docs).
pub const MIN_LOBE_WIDTH: f64 = 1e-4;
pub const MAX_LOBE_WIDTH: f64 = 3.0;
/// Nodes of the θ_o grid over [−π/2, π/2] on which the decomposition's J_p is tabulated.
const CONE_NORM_NODES: usize = 721;

/// How I₀ in d'Eon's longitudinal term is evaluated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum BesselForm {
    /// The exact, overflow-safe form of [`crate::longitudinal`].
    #[default]
    Exact,
    /// pbrt-v4's and Mitsuba 3's: I₀ by its first 11 series terms, ln I₀(x) above x = 12 by
    /// `x + ½(ln(1/(2πx)) + 1/(8x))`, and `ln 2` written 0.6931 (for the cross-check).
    PbrtMitsuba,
}

/// A validated Chiang fiber with its constants precomputed and its N̄ table built on first use.
#[derive(Debug, Clone)]
pub struct Chiang {
    params: ChiangParams,
    sigma_a: Rgb,
    variances: [f64; LOBES],
    scale: f64,
    /// α_p in θ_h, radians: α, −α/2, −2α, 0.
    shifts: [f64; LOBES],
    resolution: AzimuthalResolution,
    table: Arc<OnceLock<AzimuthalTable>>,
    cone_norms: Arc<OnceLock<Vec<[f64; LOBES]>>>,
}

impl Chiang {
    /// The fiber with the default N̄ grid ([`AzimuthalResolution::for_scale`]).
    pub fn new(params: ChiangParams) -> Result<Self, ParamError> {
        let s = params.logistic_scale().max(MIN_LOGISTIC_SCALE);
        Self::with_resolution(params, AzimuthalResolution::for_scale(s))
    }

    /// The fiber with an explicit N̄ grid (tests, references finer than a bake's).
    pub fn with_resolution(
        params: ChiangParams,
        resolution: AzimuthalResolution,
    ) -> Result<Self, ParamError> {
        params.validate()?;
        let sigma_a = params.absorption()?;
        let alpha = params.scale_tilt_degrees.to_radians();
        Ok(Self {
            sigma_a,
            variances: params.longitudinal_variances().map(|v| v.max(MIN_VARIANCE)),
            scale: params.logistic_scale().max(MIN_LOGISTIC_SCALE),
            shifts: [alpha, -0.5 * alpha, -2.0 * alpha, 0.0],
            resolution,
            table: Arc::new(OnceLock::new()),
            cone_norms: Arc::new(OnceLock::new()),
            params,
        })
    }

    pub fn params(&self) -> &ChiangParams {
        &self.params
    }

    /// σ_a per unit radius, RGB.
    pub fn absorption(&self) -> Rgb {
        self.sigma_a
    }

    /// The longitudinal variances v_p (floored at [`MIN_VARIANCE`]).
    pub fn variances(&self) -> [f64; LOBES] {
        self.variances
    }

    /// The logistic scale s (floored at [`MIN_LOGISTIC_SCALE`]).
    pub fn logistic_scale(&self) -> f64 {
        self.scale
    }

    /// θ_h of lobe p's peak, radians: +α, −α/2, −2α, 0 (see the module docs).
    pub fn lobe_shift(&self, p: usize) -> f64 {
        self.shifts[p]
    }

    /// Builds the N̄ table now (otherwise the first far-field evaluation does).
    pub fn prepare(&self) -> &AzimuthalTable {
        self.table.get_or_init(|| {
            AzimuthalTable::new(self.params.ior, &self.sigma_a, self.scale, self.resolution)
        })
    }

    // -----------------------------------------------------------------------------------------
    // Longitudinal terms.

    /// M_p(θ_i, θ_o) as it enters `S cos θ_i = Σ M_p N̄_p`: d'Eon's term of variance v_p
    /// between θ_i and the tilted view inclination (untilted for the residual, p = 3).
    pub fn longitudinal(&self, p: usize, theta_i: f64, theta_o: f64) -> f64 {
        self.longitudinal_with(p, theta_i, theta_o, BesselForm::Exact)
    }

    pub fn longitudinal_with(&self, p: usize, theta_i: f64, theta_o: f64, form: BesselForm) -> f64 {
        let v = self.variances[p];
        match form {
            BesselForm::Exact => {
                deon_longitudinal(v, shifted_incidence(theta_o, self.shifts[p]), theta_i)
            }
            BesselForm::PbrtMitsuba => {
                // Mitsuba's `reframe_with_scales`: a rotation by −2α_p with |cos|.
                let r = -2.0 * self.shifts[p];
                let (so, co) = theta_o.sin_cos();
                let (sr, cr) = r.sin_cos();
                let sin_p = so * cr + co * sr;
                let cos_p = (co * cr - so * sr).abs();
                let (si, ci) = theta_i.sin_cos();
                deon_pbrt_mitsuba(v, sin_p, cos_p, si, ci.max(0.0))
            }
        }
    }

    /// All four M_p at once.
    pub fn longitudinal_all(&self, theta_i: f64, theta_o: f64) -> [f64; LOBES] {
        std::array::from_fn(|p| self.longitudinal(p, theta_i, theta_o))
    }

    // -----------------------------------------------------------------------------------------
    // Near field.

    /// Mitsuba's `eval` for a view ray hitting the fiber at offset `h` ∈ [−1, 1] (clamped):
    /// the lobe sum with Mitsuba's cosine factor included, exact d'Eon term. `angles` in the
    /// project's convention (θ_i light, θ_o view, φ = φ_o − φ_i).
    pub fn near_field(&self, h: f64, angles: &FiberAngles) -> Rgb {
        self.near_field_with(h, angles, BesselForm::Exact)
    }

    pub fn near_field_with(&self, h: f64, angles: &FiberAngles, form: BesselForm) -> Rgb {
        let h = if h.is_nan() { 0.0 } else { h.clamp(-1.0, 1.0) };
        let geom = ViewGeometry::new(self.params.ior, angles.theta_o);
        self.near_field_core(
            &geom,
            h.asin(),
            angles.theta_i,
            angles.theta_o,
            -angles.phi,
            form,
        )
    }

    /// Mitsuba's `eval(ctx, si, wo)` with `si.wi = view` and `wo = light`, both in Mitsuba's
    /// local frame (y = tangent, z = surface normal at the hit); h and γ come from `view` as
    /// Mitsuba derives them (γ = ±acos(z/√(x²+z²)), negative for x > 0). Neither vector needs
    /// to be normalized more than Mitsuba's do: sin θ is the y component.
    pub fn near_field_local(&self, view: DVec3, light: DVec3, form: BesselForm) -> Rgb {
        let sin_o = view.y.clamp(-1.0, 1.0);
        let cos_o = (1.0 - sin_o * sin_o).max(0.0).sqrt();
        let sin_i = light.y.clamp(-1.0, 1.0);
        let proj = (view.x * view.x + view.z * view.z).sqrt();
        let gamma = if proj == 0.0 {
            0.0
        } else {
            let g = (view.z / proj).clamp(-1.0, 1.0).acos();
            if view.x < 0.0 { g } else { -g }
        };
        let dphi = light.z.atan2(light.x) - view.z.atan2(view.x);
        let geom = ViewGeometry::from_sin_cos(self.params.ior, sin_o, cos_o);
        self.near_field_core(&geom, gamma, sin_i.asin(), sin_o.asin(), dphi, form)
    }

    fn near_field_core(
        &self,
        geom: &ViewGeometry,
        gamma_o: f64,
        theta_i: f64,
        theta_o: f64,
        dphi: f64,
        form: BesselForm,
    ) -> Rgb {
        let a = geom.attenuations(gamma_o.sin(), &self.sigma_a);
        let mut value = [0.0; 3];
        for (p, a_p) in a.iter().enumerate() {
            let m = self.longitudinal_with(p, theta_i, theta_o, form);
            if m == 0.0 {
                continue;
            }
            let n = if p < P_MAX {
                let x = wrap_pi(dphi - geom.specular_azimuth(p, gamma_o));
                trimmed_logistic(x, self.scale)
            } else {
                1.0 / (2.0 * PI)
            };
            for c in 0..3 {
                value[c] += m * a_p[c] * n;
            }
        }
        value
    }

    // -----------------------------------------------------------------------------------------
    // Far field.

    /// N̄_p(θ_o, φ) for p = 0, 1, 2 and N̄_3 (with its 1/(2π)), per channel, interpolated.
    pub fn azimuthal(&self, theta_o: f64, phi: f64) -> [Rgb; LOBES] {
        self.prepare().at(theta_o, phi)
    }

    /// The same by quadrature at this point (no table).
    pub fn azimuthal_exact(&self, theta_o: f64, phi: f64) -> [Rgb; LOBES] {
        let geom = ViewGeometry::new(self.params.ior, theta_o);
        azimuthal::azimuthal_exact(&geom, &self.sigma_a, self.scale, -phi)
    }

    /// S·cos θ_i = Σ_p M_p N̄_p with the tabulated N̄ (what a direct table holds).
    pub fn eval_cos_weighted(&self, angles: &FiberAngles) -> Rgb {
        let n = self.azimuthal(angles.theta_o, angles.phi);
        self.combine(angles, &n)
    }

    /// S·cos θ_i with N̄ integrated at this point.
    pub fn eval_cos_weighted_exact(&self, angles: &FiberAngles) -> Rgb {
        let n = self.azimuthal_exact(angles.theta_o, angles.phi);
        self.combine(angles, &n)
    }

    /// S with N̄ integrated at this point (slow; the reference for the table).
    pub fn eval_exact(&self, angles: &FiberAngles) -> Rgb {
        let k = 1.0 / angles.theta_i.cos().max(MIN_COS_THETA_I);
        self.eval_cos_weighted_exact(angles).map(|v| v * k)
    }

    fn combine(&self, angles: &FiberAngles, n: &[Rgb; LOBES]) -> Rgb {
        let mut out = [0.0; 3];
        for (p, n_p) in n.iter().enumerate() {
            if n_p.iter().all(|&v| v == 0.0) {
                continue;
            }
            let m = self.longitudinal(p, angles.theta_i, angles.theta_o);
            for c in 0..3 {
                out[c] += m * n_p[c];
            }
        }
        out
    }

    // -----------------------------------------------------------------------------------------
    // Decomposition.

    /// β_p of the decomposition: √v_p/2, clamped to [MIN_LOBE_WIDTH, MAX_LOBE_WIDTH].
    pub fn lobe_width(&self, p: usize) -> f64 {
        (0.5 * self.variances[p].sqrt()).clamp(MIN_LOBE_WIDTH, MAX_LOBE_WIDTH)
    }

    /// J_p(θ_o) = ∫ g(β_p², θ_h − α_p) cos²θ_i / cos²θ_d dθ_i (see the module docs).
    pub fn cone_norm(&self, p: usize, theta_o: f64) -> f64 {
        let table = self.cone_norms.get_or_init(|| {
            (0..CONE_NORM_NODES)
                .map(|k| {
                    let t = -FRAC_PI_2 + PI * k as f64 / (CONE_NORM_NODES - 1) as f64;
                    std::array::from_fn(|q| self.cone_norm_direct(q, t))
                })
                .collect()
        });
        let u = ((theta_o + FRAC_PI_2) / PI).clamp(0.0, 1.0) * (CONE_NORM_NODES - 1) as f64;
        let i = (u.floor() as usize).min(CONE_NORM_NODES - 2);
        let t = u - i as f64;
        table[i][p] + t * (table[i + 1][p] - table[i][p])
    }

    /// J_p(θ_o) by quadrature.
    pub fn cone_norm_direct(&self, p: usize, theta_o: f64) -> f64 {
        let (alpha, beta) = (self.shifts[p], self.lobe_width(p));
        let rule = peaked_rule(
            -FRAC_PI_2,
            FRAC_PI_2,
            &[(2.0 * alpha - theta_o, 2.0 * beta)],
            &[],
            4,
        );
        rule.integrate(|theta_i| {
            let theta_h = 0.5 * (theta_i + theta_o);
            let theta_d = 0.5 * (theta_o - theta_i);
            gaussian(beta * beta, theta_h - alpha)
                * theta_i.cos().powi(2)
                * inverse_cos2_guarded(theta_d)
        })
    }
}

impl ScatteringFunction for Chiang {
    fn name(&self) -> &'static str {
        "chiang"
    }

    /// S = (Σ_p M_p N̄_p) / cos θ_i with the tabulated N̄ (cos θ_i floored at
    /// [`MIN_COS_THETA_I`]).
    fn eval(&self, angles: &FiberAngles) -> Rgb {
        let k = 1.0 / angles.theta_i.cos().max(MIN_COS_THETA_I);
        self.eval_cos_weighted(angles).map(|v| v * k)
    }
}

impl LobeDecomposition for Chiang {
    fn lobe_count(&self) -> usize {
        LOBES
    }

    /// (α_p, β_p): the tilt's shift in θ_h and √v_p/2 (clamped).
    fn lobe_shift_width(&self, p: usize) -> (f64, f64) {
        if p < LOBES {
            (self.shifts[p], self.lobe_width(p))
        } else {
            (0.0, 0.0)
        }
    }

    /// N̄_p(θ_d + α_p, φ) / J_p(θ_d + α_p).
    fn lobe_azimuthal(&self, p: usize, theta_d: f64, phi: f64) -> Rgb {
        if p >= LOBES {
            return [0.0; 3];
        }
        let theta_o = (theta_d + self.shifts[p]).clamp(-FRAC_PI_2, FRAC_PI_2);
        let n = self.azimuthal(theta_o, phi)[p];
        let j = self.cone_norm(p, theta_o);
        if !(j > 0.0) {
            return [0.0; 3];
        }
        n.map(|v| v / j)
    }
}

/// d'Eon's M (without Mitsuba's 1/(2π)) exactly as pbrt-v4 and Mitsuba 3 compute it, from the
/// sines and cosines of the two inclinations (`cos_*` ≥ 0).
pub fn deon_pbrt_mitsuba(v: f64, sin_a: f64, cos_a: f64, sin_b: f64, cos_b: f64) -> f64 {
    let kappa = 1.0 / v;
    let c = sin_a * sin_b * kappa;
    let s = cos_a * cos_b * kappa;
    if kappa > 10.0 {
        (-c + log_i0_pbrt(s) - kappa + PBRT_LN_2 + (kappa / 2.0).ln()).exp()
    } else {
        (-c).exp() * i0_pbrt(s) * kappa / (2.0 * kappa.sinh())
    }
}

/// ln 2 as pbrt-v4 and Mitsuba write it in the rough-fiber density (`0.6931f`).
#[allow(clippy::approx_constant)]
const PBRT_LN_2: f64 = 0.6931;

/// pbrt's and Mitsuba's I₀: the series Σ_{k=0}^{10} (x²/4)^k/(k!)².
fn i0_pbrt(x: f64) -> f64 {
    let (mut sum, x2) = (1.0, x * x);
    let (mut xi, mut denom) = (x2, 4.0);
    for i in 1..=10 {
        sum += xi / denom;
        xi *= x2;
        let f = (i + 1) as f64;
        denom *= 4.0 * f * f;
    }
    sum
}

/// pbrt's and Mitsuba's ln I₀: the asymptotic `x + ½(ln(1/(2πx)) + 1/(8x))` above 12.
fn log_i0_pbrt(x: f64) -> f64 {
    if x > 12.0 {
        x + 0.5 * ((1.0 / (2.0 * PI * x)).ln() + 1.0 / (8.0 * x))
    } else {
        i0_pbrt(x).ln()
    }
}
