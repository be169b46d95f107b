//! Parameters of the Chiang et al. 2016 hair model under the names Mitsuba 3's `hair` BSDF and
//! Cycles' Principled Hair use, their defaults, presets and validation.
//!
//! Defaults: roughness 0.3 along both directions, η = 1.55 and a 2° scale tilt (Mitsuba's and
//! pbrt-v4's defaults); the absorption of the project's `brown` preset (eumelanin 1.3, no
//! pheomelanin), so that [`ChiangParams::default`] and [`crate::marschner::MarschnerParams`]
//! describe the same hair. Mitsuba's own default adds pheomelanin 0.2.

use crate::absorption::{melanin_preset, preset_names, sigma_a_from_concentration};
use crate::error::{ParamError, check, check_non_negative};
use crate::scattering::Rgb;
use serde::{Deserialize, Serialize};

/// Largest |scale tilt| accepted, degrees. Real cuticle scales tilt 2°–4°; the TRT lobe is
/// shifted by 2α in θ_h, which must stay well inside (−90°, 90°).
pub const MAX_SCALE_TILT_DEGREES: f64 = 30.0;

/// Everything that defines a Chiang fiber (see the module docs for the defaults' sources).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ChiangParams {
    /// Eumelanin concentration (Mitsuba `eumelanin`), ≥ 0.
    pub eumelanin: f64,
    /// Pheomelanin concentration (Mitsuba `pheomelanin`), ≥ 0.
    pub pheomelanin: f64,
    /// σ_a per unit fiber radius, RGB (Mitsuba `sigma_a`). When given it replaces the melanin
    /// concentrations, which are then ignored.
    pub sigma_a: Option<Rgb>,
    /// β_m ∈ [0, 1] (Mitsuba `longitudinal_roughness`).
    pub longitudinal_roughness: f64,
    /// β_n ∈ [0, 1] (Mitsuba `azimuthal_roughness`).
    pub azimuthal_roughness: f64,
    /// η, the fiber's index of refraction relative to the outside (Mitsuba `int_ior` with
    /// `ext_ior` 1), in (1, 10].
    pub ior: f64,
    /// α, the cuticle scales' tilt in degrees (Mitsuba `scale_tilt`, Cycles' "offset").
    pub scale_tilt_degrees: f64,
}

impl Default for ChiangParams {
    fn default() -> Self {
        let brown = melanin_preset("brown").expect("built-in preset");
        Self {
            eumelanin: brown.eumelanin,
            pheomelanin: brown.pheomelanin,
            sigma_a: None,
            longitudinal_roughness: 0.3,
            azimuthal_roughness: 0.3,
            ior: 1.55,
            scale_tilt_degrees: 2.0,
        }
    }
}

impl ChiangParams {
    /// Defaults with the melanin concentrations of a named preset ("dark", "brown", "blonde",
    /// "red", "auburn", "white").
    pub fn with_preset(name: &str) -> Result<Self, ParamError> {
        let p = melanin_preset(name)?;
        Ok(Self {
            eumelanin: p.eumelanin,
            pheomelanin: p.pheomelanin,
            ..Self::default()
        })
    }

    /// Names accepted by [`Self::with_preset`].
    pub fn preset_names() -> String {
        preset_names()
    }

    /// σ_a per unit radius: the override if given, else from the melanin concentrations with
    /// the coefficients of [`crate::absorption`] (the ones Mitsuba and pbrt use).
    pub fn absorption(&self) -> Result<Rgb, ParamError> {
        match self.sigma_a {
            Some(s) => Ok(s),
            None => sigma_a_from_concentration(self.eumelanin, self.pheomelanin),
        }
    }

    /// Checks every parameter; the first problem is returned as a typed error naming it.
    pub fn validate(&self) -> Result<(), ParamError> {
        sigma_a_from_concentration(self.eumelanin, self.pheomelanin)?;
        if let Some(s) = self.sigma_a {
            for (c, name) in ["sigma_a.r", "sigma_a.g", "sigma_a.b"]
                .into_iter()
                .enumerate()
            {
                check_non_negative(name, s[c])?;
            }
        }
        for (name, v) in [
            ("longitudinal_roughness", self.longitudinal_roughness),
            ("azimuthal_roughness", self.azimuthal_roughness),
        ] {
            check(name, v, |v| (0.0..=1.0).contains(&v), "must be in [0, 1]")?;
        }
        check(
            "ior",
            self.ior,
            |v| v > 1.0 && v <= 10.0,
            "must be in (1, 10]",
        )?;
        check(
            "scale_tilt_degrees",
            self.scale_tilt_degrees,
            |v| v.abs() <= MAX_SCALE_TILT_DEGREES,
            "must be in [−30°, 30°]",
        )?;
        Ok(())
    }

    /// The four longitudinal variances v_p (p = R, TT, TRT, residual) of pbrt-v4 and Mitsuba:
    /// `v₀ = (0.726β_m + 0.812β_m² + 3.7β_m²⁰)²`, v₁ = v₀/4, v₂ = v₃ = 4v₀ (Chiang 2016 eq. 7).
    pub fn longitudinal_variances(&self) -> [f64; 4] {
        let b = self.longitudinal_roughness;
        let v0 = (0.726 * b + 0.812 * b * b + 3.7 * b.powi(20)).powi(2);
        [v0, 0.25 * v0, 4.0 * v0, 4.0 * v0]
    }

    /// The logistic scale s of the azimuthal lobes (Chiang 2016 eq. 8):
    /// `s = √(π/8) (0.265β_n + 1.194β_n² + 5.372β_n²²)`.
    pub fn logistic_scale(&self) -> f64 {
        let b = self.azimuthal_roughness;
        (std::f64::consts::PI / 8.0).sqrt() * (0.265 * b + 1.194 * b * b + 5.372 * b.powi(22))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_validate_and_match_the_brown_preset() {
        let p = ChiangParams::default();
        p.validate().unwrap();
        assert_eq!(p, ChiangParams::with_preset("brown").unwrap());
        assert_eq!(
            (
                p.longitudinal_roughness,
                p.azimuthal_roughness,
                p.ior,
                p.scale_tilt_degrees
            ),
            (0.3, 0.3, 1.55, 2.0)
        );
        // 1.3 × 0.419 by hand.
        assert!((p.absorption().unwrap()[0] - 0.5447).abs() < 1e-12);
    }

    #[test]
    fn variances_and_scale_follow_the_published_fits() {
        let p = ChiangParams::default();
        let v = p.longitudinal_variances();
        // By hand at β = 0.3: 0.726·0.3 + 0.812·0.09 + 3.7·0.3²⁰ = 0.2178 + 0.07308 + 1.29e-10.
        let root = 0.2178 + 0.07308 + 3.7 * 0.3f64.powi(20);
        assert!((v[0] - root * root).abs() < 1e-15);
        assert_eq!([v[1], v[2], v[3]], [v[0] / 4.0, 4.0 * v[0], 4.0 * v[0]]);
        // √(π/8) (0.265·0.3 + 1.194·0.09 + 5.372·0.3²²) = 0.626657 · 0.18696.
        let s = 0.626_657_068_657_750_1 * (0.0795 + 0.10746 + 5.372 * 0.3f64.powi(22));
        assert!(
            (p.logistic_scale() - s).abs() < 1e-12,
            "{}",
            p.logistic_scale()
        );
    }

    #[test]
    fn invalid_parameters_are_typed_errors_naming_the_parameter() {
        let base = ChiangParams::default();
        let cases = [
            (
                ChiangParams {
                    eumelanin: -1.0,
                    ..base.clone()
                },
                "eumelanin",
            ),
            (
                ChiangParams {
                    pheomelanin: f64::NAN,
                    ..base.clone()
                },
                "pheomelanin",
            ),
            (
                ChiangParams {
                    sigma_a: Some([0.1, -0.1, 0.2]),
                    ..base.clone()
                },
                "sigma_a.g",
            ),
            (
                ChiangParams {
                    longitudinal_roughness: 1.5,
                    ..base.clone()
                },
                "longitudinal_roughness",
            ),
            (
                ChiangParams {
                    azimuthal_roughness: -0.1,
                    ..base.clone()
                },
                "azimuthal_roughness",
            ),
            (
                ChiangParams {
                    ior: 1.0,
                    ..base.clone()
                },
                "ior",
            ),
            (
                ChiangParams {
                    scale_tilt_degrees: 40.0,
                    ..base.clone()
                },
                "scale_tilt_degrees",
            ),
        ];
        for (p, want) in cases {
            let err = p.validate().unwrap_err();
            let name = match &err {
                ParamError::NotFinite { name, .. } | ParamError::OutOfRange { name, .. } => *name,
                other => panic!("unexpected {other:?}"),
            };
            assert_eq!(name, want, "{err}");
        }
    }

    #[test]
    fn presets_sigma_a_override_and_json() {
        let dark = ChiangParams::with_preset("dark").unwrap();
        assert_eq!((dark.eumelanin, dark.pheomelanin), (8.0, 0.0));
        assert!(matches!(
            ChiangParams::with_preset("teal"),
            Err(ParamError::UnknownPreset { .. })
        ));
        let custom = ChiangParams {
            sigma_a: Some([0.5, 0.25, 2.0]),
            ..dark.clone()
        };
        assert_eq!(custom.absorption().unwrap(), [0.5, 0.25, 2.0]);
        let s = serde_json::to_string(&custom).unwrap();
        assert_eq!(serde_json::from_str::<ChiangParams>(&s).unwrap(), custom);
        let partial: ChiangParams = serde_json::from_str(r#"{"ior": 1.6}"#).unwrap();
        assert_eq!(partial.ior, 1.6);
        assert_eq!(partial.sigma_a, None);
        let e = serde_json::from_str::<ChiangParams>(r#"{"int_ior": 1.6}"#).unwrap_err();
        assert!(e.to_string().contains("unknown field `int_ior`"), "{e}");
        // The names Mitsuba's `hair` plugin reads are the ones a serialized value carries.
        let v = serde_json::to_value(ChiangParams::default()).unwrap();
        for key in [
            "eumelanin",
            "pheomelanin",
            "sigma_a",
            "longitudinal_roughness",
            "azimuthal_roughness",
            "ior",
            "scale_tilt_degrees",
        ] {
            assert!(v.get(key).is_some(), "{key}");
        }
    }
}
