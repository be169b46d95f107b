//! Absorption coefficients σ_a of hair from melanin concentrations.
//!
//! **Unit.** σ_a is per unit fiber *radius*: a ray crossing the unit circle of the fiber's
//! cross section at offset h travels `2 cos γ_t / cos θ_t` radii inside it, and is attenuated
//! by `exp(−σ_a · 2 cos γ_t / cos θ_t)`. This is the unit of pbrt-v3/v4's hair BSDF and of
//! Chiang et al. 2016; Marschner 2003's σ_a is the same quantity ("absorption per unit
//! radius"). Hunz (eq. 52) drops the `1/cos θ_t`; we keep it.
//!
//! **Melanin model.** σ_a = C_eu · σ_eu + C_ph · σ_ph with per-unit-concentration RGB
//! coefficients σ_eu = (0.419, 0.697, 1.37) and σ_ph = (0.187, 0.4, 1.05), the values used by
//! Chiang, Bitterli, Tappan, Burley 2016 ("A Practical and Controllable Hair and Fur Model for
//! Production Path Tracing", §4.2) and pbrt-v3 §9.9 (`SigmaAFromConcentration`), derived from
//! the melanin absorption spectra that d'Eon et al. 2011 used.
//!
//! **Presets.** The eumelanin concentrations 8 (black/dark), 1.3 (brown) and 0.3 (blonde) are
//! those of pbrt-v3's hair test scenes. `red` (C_eu = 0.3, C_ph = 2.0) and `auburn` are this
//! project's own choice of a pheomelanin-dominated mix, not a published measurement.

use crate::error::{ParamError, check_non_negative};
use crate::scattering::Rgb;

/// σ_a per unit concentration of eumelanin (brown-black pigment), per unit fiber radius.
pub const EUMELANIN_SIGMA_A: Rgb = [0.419, 0.697, 1.37];
/// σ_a per unit concentration of pheomelanin (red-yellow pigment), per unit fiber radius.
pub const PHEOMELANIN_SIGMA_A: Rgb = [0.187, 0.4, 1.05];

/// Melanin concentrations of a named hair color.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MelaninPreset {
    pub name: &'static str,
    pub eumelanin: f64,
    pub pheomelanin: f64,
}

/// The known presets, in the order they are listed in errors.
pub const PRESETS: &[MelaninPreset] = &[
    MelaninPreset {
        name: "white",
        eumelanin: 0.0,
        pheomelanin: 0.0,
    },
    MelaninPreset {
        name: "blonde",
        eumelanin: 0.3,
        pheomelanin: 0.0,
    },
    MelaninPreset {
        name: "red",
        eumelanin: 0.3,
        pheomelanin: 2.0,
    },
    MelaninPreset {
        name: "auburn",
        eumelanin: 1.0,
        pheomelanin: 1.5,
    },
    MelaninPreset {
        name: "brown",
        eumelanin: 1.3,
        pheomelanin: 0.0,
    },
    MelaninPreset {
        name: "dark",
        eumelanin: 8.0,
        pheomelanin: 0.0,
    },
];

/// σ_a = C_eu σ_eu + C_ph σ_ph; concentrations must be finite and ≥ 0.
pub fn sigma_a_from_concentration(eumelanin: f64, pheomelanin: f64) -> Result<Rgb, ParamError> {
    let eu = check_non_negative("eumelanin", eumelanin)?;
    let ph = check_non_negative("pheomelanin", pheomelanin)?;
    Ok(std::array::from_fn(|c| {
        eu * EUMELANIN_SIGMA_A[c] + ph * PHEOMELANIN_SIGMA_A[c]
    }))
}

/// Names of the presets, comma-separated (for help texts and errors).
pub fn preset_names() -> String {
    PRESETS
        .iter()
        .map(|p| p.name)
        .collect::<Vec<_>>()
        .join(", ")
}

/// Looks up a preset by name (case-insensitive; "black" is accepted for "dark").
pub fn melanin_preset(name: &str) -> Result<MelaninPreset, ParamError> {
    let key = name.trim().to_ascii_lowercase();
    let key = if key == "black" {
        "dark".to_string()
    } else {
        key
    };
    PRESETS
        .iter()
        .find(|p| p.name == key)
        .copied()
        .ok_or_else(|| ParamError::UnknownPreset {
            name: name.to_string(),
            known: preset_names(),
        })
}

/// σ_a of a named preset (see the module docs for the unit and the sources).
pub fn preset_sigma_a(name: &str) -> Result<Rgb, ParamError> {
    let p = melanin_preset(name)?;
    sigma_a_from_concentration(p.eumelanin, p.pheomelanin)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn presets_are_ordered_by_darkness_and_white_is_clear() {
        assert_eq!(preset_sigma_a("white").unwrap(), [0.0; 3]);
        let blonde = preset_sigma_a("blonde").unwrap();
        let brown = preset_sigma_a("brown").unwrap();
        let dark = preset_sigma_a("dark").unwrap();
        let red = preset_sigma_a("red").unwrap();
        // 1.3 × 0.419 = 0.5447 by hand.
        assert!((brown[0] - 0.5447).abs() < 1e-12);
        for c in 0..3 {
            assert!(blonde[c] < brown[c] && brown[c] < dark[c]);
        }
        // Melanin absorbs blue most: hair transmits red more than blue.
        for s in [blonde, brown, dark, red] {
            assert!(s[0] < s[1] && s[1] < s[2], "{s:?}");
        }
        // Red hair: relatively less red absorption than brown hair (more red than green left).
        assert!(red[1] / red[0] > brown[1] / brown[0]);
        assert_eq!(preset_sigma_a("Black").unwrap(), dark);
        eprintln!("σ_a presets: blonde {blonde:?} brown {brown:?} dark {dark:?} red {red:?}");
    }

    #[test]
    fn unknown_preset_lists_known_names() {
        match preset_sigma_a("green") {
            Err(ParamError::UnknownPreset { name, known }) => {
                assert_eq!(name, "green");
                for n in ["dark", "brown", "blonde", "red", "white"] {
                    assert!(known.contains(n), "{known}");
                }
            }
            other => panic!("expected UnknownPreset, got {other:?}"),
        }
    }

    #[test]
    fn bad_concentrations_are_typed_errors() {
        assert!(matches!(
            sigma_a_from_concentration(-1.0, 0.0),
            Err(ParamError::OutOfRange {
                name: "eumelanin",
                ..
            })
        ));
        assert!(matches!(
            sigma_a_from_concentration(0.0, f64::NAN),
            Err(ParamError::NotFinite {
                name: "pheomelanin",
                ..
            })
        ));
    }
}
