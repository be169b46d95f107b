//! The artist-friendly hair model of Sadeghi, Pritchett, Jensen, Tamstorf 2010 (eqs. 5–13).
//!
//! Four components, each with a color C_X and an intensity I_X (eq. 11), a longitudinal shift
//! α_X and width β_X, multiplied into a unit-**height** longitudinal Gaussian (eq. 5) so that a
//! width change never changes the highlight's brightness (the paper's decoupling claim, tested):
//!
//! | component | M'_X(θ_h)                 | N'_X(φ)                                   |
//! |-----------|---------------------------|-------------------------------------------|
//! | R         | g'(β_R², θ_h − α_R)       | cos(φ/2)                          (eq. 6) |
//! | TT        | g'(β_TT², θ_h − α_TT)     | g'(γ_TT², π − \|φ\|)              (eq. 7) |
//! | TRT − G   | g'(β_TRT², θ_h − α_TRT)   | cos(φ/2)                          (eq. 8) |
//! | glints    | g'(β_TRT², θ_h − α_TRT)   | I_g C_G g'(γ_g², G_angle − \|φ\|) (eq. 9) |
//!
//! with `f'_s = Σ_X C_X I_X M'_X N'_X / cos²θ_d` (eq. 12). The glints share the secondary
//! highlight's longitudinal lobe, color and intensity (eq. 10); `C_G` is the glint color
//! control the paper lists among the AFCs (default white, which is eq. 9 exactly). φ = φ_o − φ_i
//! with both directions pointing away from the fiber, so φ = 0 is backscattering and φ = π
//! straight transmission. The two glints sit at φ = ±G_angle; G_angle is deterministic here and
//! a per-fiber random value (the paper draws it from [30°, 45°]) goes through
//! [`ArtistModel::eval_with_glint_half_angle`].
//!
//! **Normalized copy (eq. 13).** `f_s^norm = f'_s / K` is what multiple scattering uses. The
//! paper writes K = ∫_Ω f'_s dθ dφ without saying which measure makes it an energy; we use the
//! one dual scattering itself uses: K is the mean, over incident directions uniform on the
//! sphere, of the scattered fraction `cos θ_i ∫_{S²} f'_s dω_o` (= ā_f + ā_b, Zinke eqs. 6 + 12):
//!
//! `K = (1/4π) ∫_{S²} ∫_{S²} f'_s cos θ_i dω_o dω_i`.
//!
//! The normalized model then returns on average exactly the energy it receives. K is computed
//! once in f64 in (θ_h, θ_d) coordinates, where the lobes separate: with the Jacobian 2 and the
//! φ_i integral 2π, `K = Σ_X C_X I_X Φ_X ∫ M'_X(θ_h) W(θ_h) dθ_h`, Φ_X = ∫ N'_X dφ and
//! `W(θ_h) = ∫ cos²θ_i cos θ_o / cos²θ_d dθ_d` over |θ_d| ≤ π/2 − |θ_h| (a bounded integrand:
//! cos θ_i cos θ_o = cos²θ_d − sin²θ_h). The tests check it against brute-force 3-D quadrature of
//! the normalized model. Eq. 13 divides per channel ([`Normalization::PerChannel`]), which makes
//! every channel's mean albedo 1; [`Normalization::SharedScale`] divides all channels by the
//! largest K instead, keeping the artist's color ratios. Because K is a mean over incident
//! inclinations, ā_f + ā_b exceeds 1 at some inclinations (by ~5% for the defaults) and a
//! transmission-dominated fiber can reach ā_f ≥ 1 there, where the backscattering series
//! diverges; [`Normalization::PeakPerChannel`] divides by the peak over inclinations instead.

use crate::angles::FiberAngles;
use crate::dual_scattering::{LobeDecomposition, inverse_cos2_guarded, peaked_rule};
use crate::error::{ParamError, check, check_non_negative};
use crate::hard_case_sweep::{SweepReport, SweepRng};
use crate::scattering::{Rgb, ScatteringFunction};
use serde::{Deserialize, Serialize};
use std::f64::consts::{FRAC_PI_2, PI};

/// Longitudinal widths are accepted in [MIN_WIDTH_DEG, MAX_WIDTH_DEG] degrees.
pub const MIN_WIDTH_DEG: f64 = 0.1;
pub const MAX_WIDTH_DEG: f64 = 60.0;
/// Longitudinal shifts are accepted in ±MAX_SHIFT_DEG degrees.
pub const MAX_SHIFT_DEG: f64 = 45.0;

/// A component with a longitudinal lobe: R and TRT − glints.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HighlightParams {
    /// C_X, linear RGB (values above 1 are allowed: the model may go beyond physics).
    pub color: [f64; 3],
    /// I_X, the peak value of the component before color (1/sr).
    pub intensity: f64,
    /// α_X, the longitudinal shift of the highlight, degrees.
    pub shift_deg: f64,
    /// β_X, the longitudinal width (standard deviation in θ_h), degrees.
    pub width_deg: f64,
}

/// The transmission (TT) component: a highlight plus its azimuthal width γ_TT.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TransmissionParams {
    pub color: [f64; 3],
    pub intensity: f64,
    pub shift_deg: f64,
    pub width_deg: f64,
    /// γ_TT, standard deviation of the forward lobe in φ around φ = π, degrees.
    pub azimuthal_width_deg: f64,
}

/// The glints (eq. 9): two peaks at φ = ±G_angle on the secondary highlight's cone.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GlintParams {
    /// C_G, multiplies the secondary color (white reproduces eq. 9).
    pub color: [f64; 3],
    /// I_g, intensity relative to the secondary highlight.
    pub relative_intensity: f64,
    /// γ_g, standard deviation of each glint in φ, degrees ("frequency of appearance").
    pub azimuthal_width_deg: f64,
    /// G_angle, half the angle between the two glints, degrees.
    pub half_angle_deg: f64,
}

/// Artist controls of the single-scattering model (Sadeghi 2010 §5.1.3).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ArtistParams {
    /// Primary highlight (R).
    pub r: HighlightParams,
    /// Transmission / backlit rim (TT).
    pub tt: TransmissionParams,
    /// Secondary highlight without glints (TRT − G).
    pub trt: HighlightParams,
    pub glints: GlintParams,
}

impl Default for ArtistParams {
    /// A light-brown fiber. Shifts and widths follow Marschner 2003's relations
    /// (α_R = −5°, α_TT = −α_R/2, α_TRT = −3α_R/2; β_R = 5°, β_TT = β_R/2, β_TRT = 2β_R); the
    /// glint half angle is the middle of the paper's [30°, 45°]. Colors, intensities and the
    /// azimuthal widths are this project's choices — the paper gives no numbers for them.
    fn default() -> Self {
        Self {
            r: HighlightParams {
                color: [1.0, 1.0, 1.0],
                intensity: 0.5,
                shift_deg: -5.0,
                width_deg: 5.0,
            },
            tt: TransmissionParams {
                color: [0.85, 0.62, 0.38],
                intensity: 1.0,
                shift_deg: 2.5,
                width_deg: 2.5,
                azimuthal_width_deg: 20.0,
            },
            trt: HighlightParams {
                color: [0.75, 0.52, 0.30],
                intensity: 0.35,
                shift_deg: 7.5,
                width_deg: 10.0,
            },
            glints: GlintParams {
                color: [1.0, 1.0, 1.0],
                relative_intensity: 0.5,
                azimuthal_width_deg: 3.0,
                half_angle_deg: 37.5,
            },
        }
    }
}

fn check_color(names: [&'static str; 3], color: [f64; 3]) -> Result<(), ParamError> {
    for c in 0..3 {
        check_non_negative(names[c], color[c])?;
    }
    Ok(())
}

fn check_highlight(
    names: ([&'static str; 3], &'static str, &'static str, &'static str),
    color: [f64; 3],
    intensity: f64,
    shift: f64,
    width: f64,
) -> Result<(), ParamError> {
    check_color(names.0, color)?;
    check_non_negative(names.1, intensity)?;
    check(
        names.2,
        shift,
        |s| s.abs() <= MAX_SHIFT_DEG,
        "must be in [−45°, 45°]",
    )?;
    check(
        names.3,
        width,
        |w| (MIN_WIDTH_DEG..=MAX_WIDTH_DEG).contains(&w),
        "must be in [0.1°, 60°]",
    )?;
    Ok(())
}

impl ArtistParams {
    pub fn validate(&self) -> Result<(), ParamError> {
        check_highlight(
            (
                [
                    "artist.r.color[0]",
                    "artist.r.color[1]",
                    "artist.r.color[2]",
                ],
                "artist.r.intensity",
                "artist.r.shift_deg",
                "artist.r.width_deg",
            ),
            self.r.color,
            self.r.intensity,
            self.r.shift_deg,
            self.r.width_deg,
        )?;
        check_highlight(
            (
                [
                    "artist.tt.color[0]",
                    "artist.tt.color[1]",
                    "artist.tt.color[2]",
                ],
                "artist.tt.intensity",
                "artist.tt.shift_deg",
                "artist.tt.width_deg",
            ),
            self.tt.color,
            self.tt.intensity,
            self.tt.shift_deg,
            self.tt.width_deg,
        )?;
        check(
            "artist.tt.azimuthal_width_deg",
            self.tt.azimuthal_width_deg,
            |w| (0.1..=180.0).contains(&w),
            "must be in [0.1°, 180°]",
        )?;
        check_highlight(
            (
                [
                    "artist.trt.color[0]",
                    "artist.trt.color[1]",
                    "artist.trt.color[2]",
                ],
                "artist.trt.intensity",
                "artist.trt.shift_deg",
                "artist.trt.width_deg",
            ),
            self.trt.color,
            self.trt.intensity,
            self.trt.shift_deg,
            self.trt.width_deg,
        )?;
        check_color(
            [
                "artist.glints.color[0]",
                "artist.glints.color[1]",
                "artist.glints.color[2]",
            ],
            self.glints.color,
        )?;
        check_non_negative(
            "artist.glints.relative_intensity",
            self.glints.relative_intensity,
        )?;
        check(
            "artist.glints.azimuthal_width_deg",
            self.glints.azimuthal_width_deg,
            |w| (0.1..=180.0).contains(&w),
            "must be in [0.1°, 180°]",
        )?;
        check(
            "artist.glints.half_angle_deg",
            self.glints.half_angle_deg,
            |g| (0.0..=180.0).contains(&g),
            "must be in [0°, 180°]",
        )?;
        Ok(())
    }
}

/// The four components, in [`LobeDecomposition`] order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ArtistLobe {
    R = 0,
    Tt = 1,
    TrtMinusGlints = 2,
    Glints = 3,
}

impl ArtistLobe {
    pub const ALL: [ArtistLobe; 4] = [Self::R, Self::Tt, Self::TrtMinusGlints, Self::Glints];
}

/// Unit-height Gaussian g'(σ², x) = exp(−x²/(2σ²)) (eq. 5).
#[inline]
fn unit_height_gaussian(sigma: f64, x: f64) -> f64 {
    (-0.5 * (x / sigma).powi(2)).exp()
}

/// The artist-friendly scattering function with validated parameters (angles in radians).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArtistModel {
    params: ArtistParams,
    /// Per lobe: color × intensity (RGB), α, β (radians).
    weight: [Rgb; 4],
    alpha: [f64; 4],
    beta: [f64; 4],
    gamma_tt: f64,
    gamma_g: f64,
    glint_half_angle: f64,
}

impl ArtistModel {
    pub fn new(params: ArtistParams) -> Result<Self, ParamError> {
        params.validate()?;
        let scale = |c: [f64; 3], i: f64| c.map(|x| x * i);
        let glint_color: Rgb =
            std::array::from_fn(|c| params.trt.color[c] * params.glints.color[c]);
        let rad = f64::to_radians;
        Ok(Self {
            params,
            weight: [
                scale(params.r.color, params.r.intensity),
                scale(params.tt.color, params.tt.intensity),
                scale(params.trt.color, params.trt.intensity),
                scale(
                    glint_color,
                    params.trt.intensity * params.glints.relative_intensity,
                ),
            ],
            alpha: [
                rad(params.r.shift_deg),
                rad(params.tt.shift_deg),
                rad(params.trt.shift_deg),
                rad(params.trt.shift_deg),
            ],
            beta: [
                rad(params.r.width_deg),
                rad(params.tt.width_deg),
                rad(params.trt.width_deg),
                rad(params.trt.width_deg),
            ],
            gamma_tt: rad(params.tt.azimuthal_width_deg),
            gamma_g: rad(params.glints.azimuthal_width_deg),
            glint_half_angle: rad(params.glints.half_angle_deg),
        })
    }

    pub fn params(&self) -> &ArtistParams {
        &self.params
    }

    /// M'_X(θ_h), unit height (eq. 5).
    pub fn longitudinal(&self, lobe: ArtistLobe, theta_h: f64) -> f64 {
        let p = lobe as usize;
        unit_height_gaussian(self.beta[p], theta_h - self.alpha[p])
    }

    /// N'_X(φ) without color (eqs. 6–9; the glints include I_g but not C_G).
    pub fn azimuthal(&self, lobe: ArtistLobe, phi: f64) -> f64 {
        self.azimuthal_with_glint_angle(lobe, phi, self.glint_half_angle)
    }

    fn azimuthal_with_glint_angle(&self, lobe: ArtistLobe, phi: f64, glint_half_angle: f64) -> f64 {
        let phi = crate::angles::wrap_angle(phi).abs();
        match lobe {
            ArtistLobe::R | ArtistLobe::TrtMinusGlints => (0.5 * phi).cos(),
            ArtistLobe::Tt => unit_height_gaussian(self.gamma_tt, PI - phi),
            // I_g is folded into `weight`, so this is the unit-height shape only.
            ArtistLobe::Glints => unit_height_gaussian(self.gamma_g, glint_half_angle - phi),
        }
    }

    /// f'_X = C_X I_X M'_X N'_X (eq. 11), without the 1/cos²θ_d of eq. 12.
    pub fn lobe_value(&self, lobe: ArtistLobe, angles: &FiberAngles) -> Rgb {
        let m = self.longitudinal(lobe, angles.theta_h());
        let n = self.azimuthal(lobe, angles.phi);
        self.weight[lobe as usize].map(|w| w * m * n)
    }

    /// f'_s with this fiber's own glint half angle (radians), e.g. the per-strand random value
    /// the paper draws from [30°, 45°].
    pub fn eval_with_glint_half_angle(&self, angles: &FiberAngles, glint_half_angle: f64) -> Rgb {
        let inv = inverse_cos2_guarded(angles.theta_d());
        let theta_h = angles.theta_h();
        let mut s = [0.0; 3];
        for lobe in ArtistLobe::ALL {
            let p = lobe as usize;
            let mn = unit_height_gaussian(self.beta[p], theta_h - self.alpha[p])
                * self.azimuthal_with_glint_angle(lobe, angles.phi, glint_half_angle)
                * inv;
            for (s_c, w_c) in s.iter_mut().zip(&self.weight[p]) {
                *s_c += w_c * mn;
            }
        }
        s
    }

    /// Per-channel K of eq. 13 (see the module docs for the measure).
    pub fn normalization_integral(&self) -> Rgb {
        let mut k = [0.0; 3];
        for lobe in ArtistLobe::ALL {
            let p = lobe as usize;
            if self.weight[p].iter().all(|&w| w == 0.0) {
                continue;
            }
            let phi_integral = self.azimuthal_integral(lobe);
            let rule = peaked_rule(
                -FRAC_PI_2,
                FRAC_PI_2,
                &[(self.alpha[p], self.beta[p])],
                &[0.0],
                8,
            );
            let longitudinal: f64 = rule
                .nodes
                .iter()
                .zip(&rule.weights)
                .map(|(&th, &w)| w * self.longitudinal(lobe, th) * inclination_weight(th))
                .sum();
            for (k_c, w_c) in k.iter_mut().zip(&self.weight[p]) {
                *k_c += w_c * phi_integral * longitudinal;
            }
        }
        k
    }

    /// Φ_X = ∫_{−π}^{π} N'_X dφ.
    fn azimuthal_integral(&self, lobe: ArtistLobe) -> f64 {
        let peaks = match lobe {
            ArtistLobe::Tt => vec![(PI, self.gamma_tt), (-PI, self.gamma_tt)],
            ArtistLobe::Glints => vec![
                (self.glint_half_angle, self.gamma_g),
                (-self.glint_half_angle, self.gamma_g),
            ],
            _ => vec![],
        };
        let rule = peaked_rule(-PI, PI, &peaks, &[0.0], 8);
        rule.nodes
            .iter()
            .zip(&rule.weights)
            .map(|(&phi, &w)| w * self.azimuthal(lobe, phi))
            .sum()
    }

    /// The energy-normalized copy used for multiple scattering (eq. 13).
    pub fn normalized(&self, mode: Normalization) -> NormalizedArtist {
        let k = self.normalization_integral();
        let inverse = |x: f64| if x > 0.0 { 1.0 / x } else { 0.0 };
        let scale = match mode {
            Normalization::PerChannel => k.map(inverse),
            Normalization::SharedScale => [inverse(k.iter().copied().fold(0.0, f64::max)); 3],
            Normalization::PeakPerChannel => self.peak_total_attenuation().map(inverse),
        };
        NormalizedArtist {
            model: *self,
            integral: k,
            scale,
        }
    }

    /// Per channel, the largest `ā_f(θ) + ā_b(θ) = cos θ ∫ f'_s dω_o` over incident inclinations
    /// (θ on a ¼° grid; the maximum is smooth, so the grid underestimates it by ~1e-5).
    pub fn peak_total_attenuation(&self) -> Rgb {
        // N'_X does not depend on θ_d: its hemisphere integrals are constants per lobe.
        let halves: Vec<[Rgb; 2]> = (0..4)
            .map(|p| crate::dual_scattering::azimuthal_hemisphere_integrals(self, p, 0.0))
            .collect();
        let mut peak = [0.0f64; 3];
        let n = 721;
        for k in 0..n {
            let theta = -FRAC_PI_2 + PI * k as f64 / (n - 1) as f64;
            let a = crate::dual_scattering::fiber_averages_with(self, theta, |p, _| halves[p]);
            for (c, peak_c) in peak.iter_mut().enumerate() {
                *peak_c = peak_c.max(a.a_f[c] + a.a_b[c]);
            }
        }
        peak
    }
}

/// W(θ_h) = ∫ cos²θ_i cos θ_o / cos²θ_d dθ_d over |θ_d| ≤ h = π/2 − |θ_h|, in closed form.
/// With cos θ_i cos θ_o = cos²θ_d − sin²θ_h and cos θ_i = cos θ_h cos θ_d + sin θ_h sin θ_d, the
/// odd terms in θ_d cancel and `W = 2 cos θ_h sin h − 2 sin²θ_h cos θ_h ln(sec h + tan h)`, i.e.
/// `W = 2 cos²θ_h − 2 sin²θ_h cos θ_h ln cot(|θ_h|/2)`. It behaves like 2 − 2θ_h² ln(2/|θ_h|)
/// near 0 (not smooth there, hence the quadrature split at θ_h = 0).
pub fn inclination_weight(theta_h: f64) -> f64 {
    let t = theta_h.abs().min(FRAC_PI_2);
    if t == 0.0 {
        return 2.0;
    }
    let (s, c) = t.sin_cos();
    let log_cot = (1.0 / (0.5 * t).tan()).ln();
    (2.0 * c * c - 2.0 * s * s * c * log_cot).max(0.0)
}

impl ScatteringFunction for ArtistModel {
    fn name(&self) -> &'static str {
        "artist"
    }

    /// f'_s (eq. 12).
    fn eval(&self, angles: &FiberAngles) -> Rgb {
        self.eval_with_glint_half_angle(angles, self.glint_half_angle)
    }
}

impl LobeDecomposition for ArtistModel {
    fn lobe_count(&self) -> usize {
        4
    }

    fn lobe_shift_width(&self, p: usize) -> (f64, f64) {
        (self.alpha[p], self.beta[p])
    }

    /// C_X I_X N'_X √(2π) β_X: the unit-height M'_X equals √(2π) β_X times the unit-area
    /// Gaussian the trait's M_p is.
    fn lobe_azimuthal(&self, p: usize, _theta_d: f64, phi: f64) -> Rgb {
        let n = self.azimuthal(ArtistLobe::ALL[p], phi) * (2.0 * PI).sqrt() * self.beta[p];
        self.weight[p].map(|w| w * n)
    }

    fn lobe_azimuthal_peaks(&self, p: usize, _theta_d: f64) -> Vec<(f64, f64)> {
        match ArtistLobe::ALL[p] {
            ArtistLobe::Tt => vec![(PI, self.gamma_tt), (-PI, self.gamma_tt)],
            ArtistLobe::Glints => vec![
                (self.glint_half_angle, self.gamma_g),
                (-self.glint_half_angle, self.gamma_g),
            ],
            _ => vec![],
        }
    }
}

/// How eq. 13's division applies to the three channels.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Normalization {
    /// Each channel divided by its own K: every channel's mean albedo becomes 1 (eq. 13 as
    /// written for a color-valued f'_s).
    #[default]
    PerChannel,
    /// All channels divided by the largest K: the brightest channel's mean albedo becomes 1
    /// and the others keep their ratio to it (multiple scattering keeps the hair's color).
    SharedScale,
    /// Each channel divided by its largest ā_f(θ) + ā_b(θ) over inclinations instead of the
    /// mean: no inclination returns more than it receives, so ā_f < 1 wherever anything is
    /// scattered backward and the backscattering series always converges. The mean albedo is
    /// then below 1 (by the variation of ā_f + ā_b with θ, ~5% for the defaults).
    PeakPerChannel,
}

/// `f_s^norm = f'_s · scale`, scale = 1/K per channel (or shared, or 1/peak).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NormalizedArtist {
    model: ArtistModel,
    integral: Rgb,
    scale: Rgb,
}

impl NormalizedArtist {
    /// K of eq. 13 per channel, as computed (before the shared/per-channel choice).
    pub fn integral(&self) -> Rgb {
        self.integral
    }

    pub fn scale(&self) -> Rgb {
        self.scale
    }

    pub fn model(&self) -> &ArtistModel {
        &self.model
    }
}

impl ScatteringFunction for NormalizedArtist {
    fn name(&self) -> &'static str {
        "artist-normalized"
    }

    fn eval(&self, angles: &FiberAngles) -> Rgb {
        let s = self.model.eval(angles);
        std::array::from_fn(|c| s[c] * self.scale[c])
    }
}

impl LobeDecomposition for NormalizedArtist {
    fn lobe_count(&self) -> usize {
        4
    }

    fn lobe_shift_width(&self, p: usize) -> (f64, f64) {
        self.model.lobe_shift_width(p)
    }

    fn lobe_azimuthal(&self, p: usize, theta_d: f64, phi: f64) -> Rgb {
        let n = self.model.lobe_azimuthal(p, theta_d, phi);
        std::array::from_fn(|c| n[c] * self.scale[c])
    }

    fn lobe_azimuthal_peaks(&self, p: usize, theta_d: f64) -> Vec<(f64, f64)> {
        self.model.lobe_azimuthal_peaks(p, theta_d)
    }
}

/// Random valid parameters for sweeps: widths from 0.5° to 30°, shifts ±15°, intensities from
/// 1e-6 to 1e3 (or 0), colors often exactly 0 or 1 or very dark.
pub fn random_params(rng: &mut SweepRng) -> ArtistParams {
    let intensity = |rng: &mut SweepRng| {
        if rng.uniform() < 0.1 {
            0.0
        } else {
            rng.log_range(1e-6, 1e3)
        }
    };
    let width = |rng: &mut SweepRng| rng.log_range(0.5, 30.0);
    let shift = |rng: &mut SweepRng| rng.range(-15.0, 15.0);
    ArtistParams {
        r: HighlightParams {
            color: rng.hard_color(),
            intensity: intensity(rng),
            shift_deg: shift(rng),
            width_deg: width(rng),
        },
        tt: TransmissionParams {
            color: rng.hard_color(),
            intensity: intensity(rng),
            shift_deg: shift(rng),
            width_deg: width(rng),
            azimuthal_width_deg: rng.log_range(0.5, 60.0),
        },
        trt: HighlightParams {
            color: rng.hard_color(),
            intensity: intensity(rng),
            shift_deg: shift(rng),
            width_deg: width(rng),
        },
        glints: GlintParams {
            color: rng.hard_color(),
            relative_intensity: intensity(rng),
            azimuthal_width_deg: rng.log_range(0.5, 20.0),
            half_angle_deg: rng.range(30.0, 45.0),
        },
    }
}

/// Evaluates f'_s, each lobe, the per-strand glint variant and the normalized copy for random
/// parameters (see [`random_params`]) at angles concentrated near ±90°; `samples` scalar values.
pub fn hard_case_sweep(samples: u64, seed: u64) -> SweepReport {
    let mut report = SweepReport::new("artist");
    let mut rng = SweepRng::new(seed);
    let per_model = 20_000u64;
    while report.samples < samples {
        let model = ArtistModel::new(random_params(&mut rng))
            .expect("random_params yields valid parameters");
        let normalized = model.normalized(Normalization::PerChannel);
        report.record_rgb(normalized.integral());
        report.record_rgb(normalized.scale());
        for _ in 0..per_model / 9 {
            let a = FiberAngles::new(
                rng.hard_inclination(),
                rng.hard_inclination(),
                rng.hard_azimuth(),
            );
            report.record_rgb(model.eval(&a));
            report.record_rgb(normalized.eval(&a));
            let g = rng.range(30f64.to_radians(), 45f64.to_radians());
            report.record_rgb(model.eval_with_glint_half_angle(&a, g));
        }
    }
    report
}

#[cfg(test)]
mod tests;
