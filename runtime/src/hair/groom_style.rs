//! The procedural groom's named styles: what `--hair procedural:NAME` and the viewer's panel
//! choose. Each is a [`GroomParams`] on the same head-sized scalp (centimetres, Y up, face
//! at +z), so a head fitted to its roots is the scalp it grew from.

use super::groom::GroomParams;

/// A named procedural groom.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum GroomStyle {
    /// Long, nearly straight hair from a side parting, falling past the shoulders.
    #[default]
    StraightLong,
    /// Chin-length waves from a centre parting.
    WavyBob,
    /// Short tight curls combed back from a centre parting.
    Curly,
}

impl GroomStyle {
    pub const ALL: [GroomStyle; 3] = [Self::StraightLong, Self::WavyBob, Self::Curly];

    /// The style's name in `procedural:NAME`, the panel and the settings files.
    pub fn name(self) -> &'static str {
        match self {
            Self::StraightLong => "straight-long",
            Self::WavyBob => "wavy-bob",
            Self::Curly => "curly",
        }
    }

    /// The style called `name`, if any.
    pub fn named(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|s| s.name() == name)
    }

    /// The groom's parameters.
    pub fn params(self) -> GroomParams {
        let mut base = GroomParams::default();
        // A forehead: the hairline over the face at 45° from the top (the base's 55° hides it).
        base.scalp.front_polar_angle = 45f32.to_radians();
        match self {
            Self::StraightLong => GroomParams {
                length_min: 26.0,
                length_max: 34.0,
                curl_radius: 0.15,
                curl_frequency: 0.08,
                clump_count: 200,
                clump_strength: 0.35,
                gravity: 0.9,
                parting: Some(0.25),
                ..base
            },
            Self::WavyBob => GroomParams {
                length_min: 12.0,
                length_max: 17.0,
                curl_radius: 0.6,
                // 0.17 turns/cm × 17 cm / 23 steps = 0.13 turns a step: seven points a turn.
                curl_frequency: 0.17,
                clump_count: 150,
                clump_strength: 0.5,
                gravity: 0.8,
                parting: Some(0.0),
                ..base
            },
            Self::Curly => GroomParams {
                points_per_strand: 48,
                length_min: 10.0,
                length_max: 16.0,
                curl_radius: 1.0,
                // 0.4 × 16 / 47 = 0.14 turns a step.
                curl_frequency: 0.4,
                clump_count: 300,
                clump_strength: 0.5,
                gravity: 0.45,
                parting: Some(0.0),
                ..base
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hair::{HairModel, generate_groom};
    use glam::Vec3;

    /// The share of strands with a point in front of the face: over the face's disc as the
    /// default camera sees it from +z (within half the head's width and from 0.6 of its height
    /// below the centre to 0.4 above), and nearer the camera than the head's centre.
    fn share_over_the_face(params: &GroomParams, model: &HairModel) -> f64 {
        let (c, r) = (params.scalp.center, params.scalp.radii);
        let over_face = |p: &Vec3| {
            let q = (*p - c) / r;
            q.x.abs() < 0.5 && q.y > -0.6 && q.y < 0.4 && q.z > 0.0
        };
        let veiling = model.strands().filter(|s| s.iter().any(over_face)).count();
        veiling as f64 / model.strand_count() as f64
    }

    #[test]
    fn each_style_has_a_name_and_a_valid_groom() {
        for style in GroomStyle::ALL {
            assert_eq!(GroomStyle::named(style.name()), Some(style));
            let model = generate_groom(&style.params()).unwrap();
            eprintln!("{}: {}", style.name(), model.summary());
            assert_eq!(model.strand_count(), style.params().strand_count);
        }
        assert_eq!(GroomStyle::named("mohawk"), None);
    }

    #[test]
    fn the_styles_leave_the_face_clear_where_combing_from_the_crown_veils_it() {
        let crown = GroomParams::default();
        let veiled = share_over_the_face(&crown, &generate_groom(&crown).unwrap());
        eprintln!(
            "combed from the crown: {:.3} of strands over the face",
            veiled
        );
        assert!(
            veiled > 0.05,
            "the check should see a veiled face: {veiled}"
        );
        for style in GroomStyle::ALL {
            let params = style.params();
            let share = share_over_the_face(&params, &generate_groom(&params).unwrap());
            eprintln!("{}: {share:.4} of strands over the face", style.name());
            assert!(share < 0.005, "{}: {share}", style.name());
        }
    }

    #[test]
    fn hair_on_top_flows_away_from_the_parting() {
        for style in GroomStyle::ALL {
            let params = style.params();
            let Some(parting) = params.parting else {
                continue;
            };
            let (c, r) = (params.scalp.center, params.scalp.radii);
            let model = generate_groom(&params).unwrap();
            let (mut top, mut away) = (0, 0);
            for strand in model.strands() {
                let root = (strand[0] - c) / r;
                // On top, clear of the parting itself.
                if root.y < 0.8 || (root.x - parting).abs() < 0.05 {
                    continue;
                }
                top += 1;
                let sideways = strand[3].x - strand[0].x;
                if sideways * (root.x - parting) > 0.0 {
                    away += 1;
                }
            }
            let share = away as f64 / top as f64;
            eprintln!(
                "{}: {away} of {top} top strands flow away from the parting",
                style.name()
            );
            assert!(top > 100 && share > 0.95, "{}: {share}", style.name());
        }
    }
}
