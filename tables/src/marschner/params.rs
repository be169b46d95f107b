//! Parameters of the Marschner 2003 model, their defaults, presets and validation.
//!
//! Angles are stored in **degrees** (what people write in a JSON file); the model converts once
//! in [`super::Marschner::new`]. Defaults follow Marschner et al. 2003 Table 1 and Hunz 2016
//! Table 1: η = 1.55, α_R = −5°, β_R = 7.5°, α_TT = −α_R/2, α_TRT = −3α_R/2, β_TT = β_R/2,
//! β_TRT = 2β_R; caustic width w_c = 15° (range 10°–25°), glint scale k_G = 0.5 (range
//! 0.5–5), caustic fade range Δη′ = 0.3 (range 0.2–0.4), caustic intensity limit Δh_M = 0.5,
//! eccentricity a = 1 (range 0.85–1).

use crate::absorption::{preset_names, preset_sigma_a};
use crate::error::{ParamError, check, check_non_negative};
use crate::longitudinal::LongitudinalModel;
use crate::scattering::Rgb;
use serde::{Deserialize, Serialize};

/// Everything that defines a Marschner fiber. See the module docs for the defaults' sources.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MarschnerParams {
    /// Index of refraction of the fiber (> 1).
    pub eta: f64,
    /// Absorption coefficient per unit fiber radius, RGB (see [`crate::absorption`]).
    pub sigma_a: Rgb,
    /// Longitudinal shifts α_R, α_TT, α_TRT in degrees (cuticle tilt; negative = toward root).
    pub alpha_deg: [f64; 3],
    /// Longitudinal widths β_R, β_TT, β_TRT in degrees (standard deviation in θ_h).
    pub beta_deg: [f64; 3],
    /// Gaussian in θ_h (Marschner) or d'Eon 2011's term.
    pub longitudinal_model: LongitudinalModel,
    /// Marschner 2003 normalizes M_p to unit area over θ_h, so over θ_o (= 2θ_h − θ_i) it has
    /// area 2 and a white fiber scatters about twice the light it receives. `true` (default)
    /// halves M_p so a white fiber conserves energy (what dual scattering and the multiple-
    /// scattering tables need); `false` gives the published scale.
    pub energy_conserving: bool,
    /// Replace the TRT caustics by glints (Marschner 2003 §4.3, Hunz Algorithm 1).
    pub smooth_caustics: bool,
    /// Azimuthal width w_c of the caustic glints, degrees.
    pub caustic_width_deg: f64,
    /// Glint scale factor k_G.
    pub glint_scale: f64,
    /// Fade range Δη′ over which the merged caustic fades out above η′ = 2.
    pub caustic_fade_range: f64,
    /// Caustic intensity limit Δh_M.
    pub caustic_intensity_limit: f64,
    /// Ratio a of minor to major axis of the cross section, in (1/√2, 1]; 1 = circular.
    /// Marschner validated the approximation for 0.85 ≤ a ≤ 1.
    pub eccentricity: f64,
}

impl MarschnerParams {
    /// The per-lobe shifts and widths of Marschner 2003 Table 1, from α_R and β_R.
    pub fn lobes_from_r(alpha_r_deg: f64, beta_r_deg: f64) -> ([f64; 3], [f64; 3]) {
        (
            [alpha_r_deg, -alpha_r_deg / 2.0, -3.0 * alpha_r_deg / 2.0],
            [beta_r_deg, beta_r_deg / 2.0, 2.0 * beta_r_deg],
        )
    }

    /// Defaults with the absorption of a named melanin preset ("dark", "brown", "blonde",
    /// "red", "white", ...).
    pub fn with_preset(name: &str) -> Result<Self, ParamError> {
        Ok(Self {
            sigma_a: preset_sigma_a(name)?,
            ..Self::default()
        })
    }

    /// Names accepted by [`Self::with_preset`].
    pub fn preset_names() -> String {
        preset_names()
    }

    /// Checks every parameter; the first problem is returned as a typed error naming it.
    pub fn validate(&self) -> Result<(), ParamError> {
        check(
            "eta",
            self.eta,
            |v| v > 1.0 && v <= 10.0,
            "must be in (1, 10]",
        )?;
        for (c, name) in ["sigma_a.r", "sigma_a.g", "sigma_a.b"]
            .into_iter()
            .enumerate()
        {
            check_non_negative(name, self.sigma_a[c])?;
        }
        let alpha_names = ["alpha_deg.R", "alpha_deg.TT", "alpha_deg.TRT"];
        let beta_names = ["beta_deg.R", "beta_deg.TT", "beta_deg.TRT"];
        for p in 0..3 {
            check(
                alpha_names[p],
                self.alpha_deg[p],
                |v| v.abs() <= 45.0,
                "must be in [−45°, 45°]",
            )?;
            check(
                beta_names[p],
                self.beta_deg[p],
                |v| v > 0.0 && v <= 90.0,
                "must be in (0°, 90°]",
            )?;
        }
        check(
            "caustic_width_deg",
            self.caustic_width_deg,
            |v| v > 0.0 && v <= 180.0,
            "must be in (0°, 180°]",
        )?;
        check_non_negative("glint_scale", self.glint_scale)?;
        check(
            "caustic_fade_range",
            self.caustic_fade_range,
            |v| v > 0.0,
            "must be > 0",
        )?;
        check(
            "caustic_intensity_limit",
            self.caustic_intensity_limit,
            |v| (0.0..=2.0).contains(&v),
            "must be in [0, 2] (an interval of h in [−1, 1])",
        )?;
        check(
            "eccentricity",
            self.eccentricity,
            |v| v > std::f64::consts::FRAC_1_SQRT_2 && v <= 1.0,
            "must be in (1/√2, 1] (the elliptical index η₁* exceeds 1 only there)",
        )?;
        Ok(())
    }
}

impl Default for MarschnerParams {
    fn default() -> Self {
        let (alpha_deg, beta_deg) = Self::lobes_from_r(-5.0, 7.5);
        Self {
            eta: 1.55,
            sigma_a: preset_sigma_a("brown").expect("built-in preset"),
            alpha_deg,
            beta_deg,
            longitudinal_model: LongitudinalModel::Gaussian,
            energy_conserving: true,
            smooth_caustics: true,
            caustic_width_deg: 15.0,
            glint_scale: 0.5,
            caustic_fade_range: 0.3,
            caustic_intensity_limit: 0.5,
            eccentricity: 1.0,
        }
    }
}

/// Marschner 2003 §4.4's indices for an elliptical fiber of axis ratio `a`, seen along the
/// major (η₁*) and minor (η₂*) axis:
/// `η₁* = 2(η − 1)a² − η + 2`, `η₂* = 2(η − 1)a⁻² − η + 2`.
///
/// Hunz 2016 eq. 59 prints `η₂* = 2(η − 1)a⁻² + η + 2`, which gives 3η for a circle; the sign
/// of η must be minus so that both reduce to η at a = 1 (tested below).
pub fn elliptical_indices(eta: f64, a: f64) -> (f64, f64) {
    let k = 2.0 * (eta - 1.0);
    (k * a * a - eta + 2.0, k / (a * a) - eta + 2.0)
}

/// η*(φ_h) = ½((η₁* + η₂*) + cos(2φ_h)(η₁* − η₂*)) (Marschner 2003 eq. 13; Hunz eq. 58), where
/// φ_h is the half azimuth measured from the major axis.
pub fn elliptical_index(eta: f64, a: f64, phi_h: f64) -> f64 {
    let (e1, e2) = elliptical_indices(eta, a);
    0.5 * ((e1 + e2) + (2.0 * phi_h).cos() * (e1 - e2))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_follow_marschner_table_1_and_validate() {
        let p = MarschnerParams::default();
        p.validate().unwrap();
        assert_eq!(p.alpha_deg, [-5.0, 2.5, 7.5]);
        assert_eq!(p.beta_deg, [7.5, 3.75, 15.0]);
        assert_eq!(p.eta, 1.55);
    }

    /// The defaults with one change.
    fn changed(change: impl FnOnce(&mut MarschnerParams)) -> MarschnerParams {
        let mut p = MarschnerParams::default();
        change(&mut p);
        p
    }

    /// `p` fails validation with an error that names `want`: `NotFinite` where `not_finite`,
    /// else `OutOfRange`.
    fn assert_rejected(p: MarschnerParams, want: &str, not_finite: bool) {
        let err = p.validate().unwrap_err();
        let name = match &err {
            ParamError::NotFinite { name, .. } => {
                assert!(not_finite, "{err}");
                *name
            }
            ParamError::OutOfRange { name, .. } => {
                assert!(!not_finite, "{err}");
                *name
            }
            other => panic!("unexpected {other:?}"),
        };
        assert_eq!(name, want, "{err}");
        eprintln!("rejected: {err}");
    }

    #[test]
    fn invalid_parameters_are_typed_errors_naming_the_parameter() {
        assert_rejected(changed(|p| p.eta = 1.0), "eta", false);
        assert_rejected(changed(|p| p.eta = 0.5), "eta", false);
        assert_rejected(changed(|p| p.eta = f64::NAN), "eta", true);
        assert_rejected(
            changed(|p| p.sigma_a = [0.1, -0.2, 0.3]),
            "sigma_a.g",
            false,
        );
        assert_rejected(
            changed(|p| p.sigma_a = [0.1, 0.2, f64::INFINITY]),
            "sigma_a.b",
            true,
        );
        assert_rejected(
            changed(|p| p.beta_deg = [7.5, 0.0, 15.0]),
            "beta_deg.TT",
            false,
        );
        assert_rejected(
            changed(|p| p.beta_deg = [-1.0, 3.0, 15.0]),
            "beta_deg.R",
            false,
        );
        assert_rejected(
            changed(|p| p.alpha_deg = [f64::NAN, 0.0, 0.0]),
            "alpha_deg.R",
            true,
        );
        assert_rejected(
            changed(|p| p.caustic_width_deg = -15.0),
            "caustic_width_deg",
            false,
        );
        assert_rejected(changed(|p| p.glint_scale = -0.5), "glint_scale", false);
        assert_rejected(
            changed(|p| p.caustic_fade_range = 0.0),
            "caustic_fade_range",
            false,
        );
        assert_rejected(
            changed(|p| p.caustic_intensity_limit = -0.1),
            "caustic_intensity_limit",
            false,
        );
        assert_rejected(changed(|p| p.eccentricity = 0.6), "eccentricity", false);
        assert_rejected(changed(|p| p.eccentricity = 1.2), "eccentricity", false);
    }

    #[test]
    fn presets_and_unknown_preset() {
        let dark = MarschnerParams::with_preset("dark").unwrap();
        assert_eq!(dark.sigma_a, preset_sigma_a("dark").unwrap());
        assert!(matches!(
            MarschnerParams::with_preset("teal"),
            Err(ParamError::UnknownPreset { .. })
        ));
    }

    #[test]
    fn json_round_trip_and_partial_files_use_defaults() {
        let p = MarschnerParams {
            eta: 1.6,
            // Exactly representable values: serde_json's default float parser may be 1 ulp off.
            sigma_a: [0.5, 0.25, 2.0],
            longitudinal_model: LongitudinalModel::DEon,
            ..MarschnerParams::default()
        };
        let s = serde_json::to_string_pretty(&p).unwrap();
        assert_eq!(serde_json::from_str::<MarschnerParams>(&s).unwrap(), p);
        let partial: MarschnerParams = serde_json::from_str(r#"{"eta": 1.7}"#).unwrap();
        assert_eq!(partial.eta, 1.7);
        assert_eq!(partial.beta_deg, MarschnerParams::default().beta_deg);
        let e = serde_json::from_str::<MarschnerParams>(r#"{"etta": 1.7}"#).unwrap_err();
        assert!(e.to_string().contains("unknown field `etta`"), "{e}");
    }

    /// The sign check of DESIGN.md: both elliptical indices reduce to η for a circle, whereas
    /// Hunz's printed η₂* = 2(η−1)/a² + η + 2 would give 3η.
    #[test]
    fn elliptical_index_reduces_to_eta_for_a_circle() {
        for &eta in &[1.2, 1.55, 2.0, 3.0] {
            let (e1, e2) = elliptical_indices(eta, 1.0);
            assert!((e1 - eta).abs() < 1e-15 && (e2 - eta).abs() < 1e-15);
            let hunz_printed = 2.0 * (eta - 1.0) + eta + 2.0;
            assert!((hunz_printed - 3.0 * eta).abs() < 1e-12);
            for k in 0..8 {
                assert!((elliptical_index(eta, 1.0, k as f64 * 0.4) - eta).abs() < 1e-14);
            }
        }
        // Flattening raises the index seen along the minor axis and lowers it along the major.
        let (e1, e2) = elliptical_indices(1.55, 0.85);
        eprintln!("η=1.55, a=0.85: η₁*={e1:.4}, η₂*={e2:.4}");
        assert!(e1 < 1.55 && e2 > 1.55 && e1 > 1.0);
    }
}
