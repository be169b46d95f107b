//! The lights of an environment-lit frame: SRBF lobes (with a bandwidth λ) and directional
//! lights (the fit's compact sources, the reference's and median cut's samples), and how they
//! group into shadow batches. Every pass that shades or shadows them imports them from here.

use glam::Vec3;
use strandlight_tables::colour::luminance_f32;

/// One light of an environment.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EnvLight {
    /// Unit vector toward the light (the SRBF centre ξ).
    pub direction: Vec3,
    /// SRBF bandwidth λ; `None` for a directional light.
    pub lambda: Option<f32>,
    /// SRBF amplitude L_j (radiance) for an SRBF; for a directional light its irradiance at
    /// normal incidence (the radiance it stands for × the solid angle it covers).
    pub rgb: [f32; 3],
    /// Directional lights only: the direction of the shadow map this light's visibility is read
    /// from, shared by every light of one run of consecutive lights with the same value (one
    /// light pass for the run; see [`ShadowGroup`]). `None`: its own map, along `direction`.
    /// The reference uses it to shade a cube texel's light over finer sub-texels whose
    /// visibility is the texel's (`precompute/src/env_lights.rs`).
    pub shadowed_from: Option<Vec3>,
    /// Draw every strand into this light's map whatever the frame's κ. SRBFs default to κ's
    /// thinning (Ren §7); directional lights (the reference's, the baseline's, a sun's) draw
    /// every strand. (Marking the most powerful lobes so, adaptive κ, lost its one point on the
    /// front to the layered view: docs/history/benchmarks-2026-12-02-to-12-04.md, "The view:
    /// layers".)
    pub every_strand: bool,
    /// Directional lights only: per-axis variance (rad²) of the directions the light stands
    /// for (an extended compact source: a softbox, a sun's disc). Its visibility is averaged
    /// over a box matched to it, as an SRBF's is over its lobe
    /// ([`TransmittanceFilter`](crate::env::TransmittanceFilter)); 0 reads one texel.
    pub angular_variance: f32,
    /// Directional lights only: it stands for a region of the map (a reference's cube texel, a
    /// median-cut region), not a compact source (a sun, a lamp). A region's own shadow is soft at
    /// fiber scale, so the layered view reads it at a layer's mean position, as it does SRBF
    /// lobes'; a compact source's is sharp, so a layer reads its fibers' mean visibility
    /// ([`ViewTransparency::Layered`]).
    ///
    /// [`ViewTransparency::Layered`]: crate::env::ViewTransparency::Layered
    pub stands_for_region: bool,
    /// A compact source's share of its environment's power (0 where unknown). A source
    /// holding at least [`FINE_MAP_POWER_SHARE`] draws its map at
    /// [`DodmSettings::fine_resolution`](crate::passes::convolution_depth::DodmSettings::fine_resolution):
    /// its sharp shadow decides that much of the frame.
    pub power_share: f32,
}

/// The power share from which a compact source's map is drawn finer
/// ([`EnvLight::has_fine_map`]). Measured on straight.hair at 160×120 against the truth
/// (docs/history/benchmarks-2026-12-05-to-12-06.md, "Fine maps for dominant suns"): quarry's
/// sun, 50% of the power, takes the frame from 0.274 to 0.226 relative RMSE at 4× the map's
/// side, a held-out low sun 0.297 to 0.288 (a held-out high sun loses 0.009); sources of 2–7%
/// each (spruit's sun, golf's and studio's lamps) gain at most 0.01 at 1.5–5× the cost.
pub const FINE_MAP_POWER_SHARE: f32 = 0.25;

impl EnvLight {
    pub fn srbf(direction: Vec3, lambda: f32, amplitude: [f32; 3]) -> Self {
        Self {
            direction: direction.normalize(),
            lambda: Some(lambda),
            rgb: amplitude,
            shadowed_from: None,
            every_strand: false,
            angular_variance: 0.0,
            stands_for_region: false,
            power_share: 0.0,
        }
    }

    pub fn directional(direction: Vec3, irradiance: [f32; 3]) -> Self {
        Self {
            direction: direction.normalize(),
            lambda: None,
            rgb: irradiance,
            shadowed_from: None,
            every_strand: true,
            angular_variance: 0.0,
            stands_for_region: false,
            power_share: 0.0,
        }
    }

    /// A directional light standing for directions spread by `variance` (rad² per axis) about
    /// `direction`: [`EnvLight::angular_variance`].
    pub fn extended(direction: Vec3, irradiance: [f32; 3], variance: f32) -> Self {
        Self {
            angular_variance: variance,
            ..Self::directional(direction, irradiance)
        }
    }

    /// A directional light whose visibility is that of the shadow map along `shadowed_from`.
    pub fn directional_shadowed_from(
        direction: Vec3,
        irradiance: [f32; 3],
        shadowed_from: Vec3,
    ) -> Self {
        Self {
            shadowed_from: Some(shadowed_from.normalize()),
            ..Self::directional(direction, irradiance)
        }
    }

    /// Whether stochastic simplification thins this light's map (κ < 1 draws only its window
    /// of the strands): a light not marked [`EnvLight::every_strand`].
    pub fn is_simplified(&self) -> bool {
        !self.every_strand
    }

    /// A compact source: a directional light that does not stand for a region of the map
    /// ([`EnvLight::stands_for_region`]), whose shadow is sharp at fiber scale.
    pub fn has_sharp_shadow(&self) -> bool {
        self.lambda.is_none() && !self.stands_for_region
    }

    /// A compact source holding at least [`FINE_MAP_POWER_SHARE`] of the power: its map is
    /// drawn at the fine resolution, in a batch of its own kind.
    pub fn has_fine_map(&self) -> bool {
        self.has_sharp_shadow() && self.every_strand && self.power_share >= FINE_MAP_POWER_SHARE
    }

    /// The direction of the light pass whose map shadows this light.
    pub fn shadow_direction(&self) -> Vec3 {
        self.shadowed_from.unwrap_or(self.direction)
    }

    /// [`EnvLight::power`]'s luminance (Rec. 709 weights): how lights are ranked by strength.
    pub fn luminous_power(&self) -> f32 {
        luminance_f32(self.power())
    }

    /// What the light delivers to a fiber facing it, before shadowing: for an SRBF its
    /// amplitude × ∫G dω = L_j · 2π/λ · (1 − e^{−2λ}); for a directional light its irradiance.
    /// The multiple-scattering term (normalized spread function ψ_f) is weighted by this.
    pub fn power(&self) -> [f32; 3] {
        match self.lambda {
            None => self.rgb,
            Some(lambda) => {
                let l = lambda as f64;
                let integral = 2.0 * std::f64::consts::PI / l * -(-2.0 * l).exp_m1();
                self.rgb.map(|c| (c as f64 * integral) as f32)
            }
        }
    }
}

/// Consecutive lights that share one shadow map (one DODM slot, one light pass, one
/// forward-scattering grid block): a run of directional lights with the same
/// [`EnvLight::shadowed_from`], or any other light alone.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadowGroup<'a> {
    /// The light pass's direction.
    pub direction: Vec3,
    /// The lights shaded with its visibility (at least one).
    pub lights: &'a [EnvLight],
}

impl ShadowGroup<'_> {
    /// One light standing for the group where only the map's direction matters (the light
    /// pass, the forward-scattering march): the first light moved to the map's direction.
    pub fn representative(&self) -> EnvLight {
        EnvLight {
            direction: self.direction,
            shadowed_from: None,
            ..self.lights[0]
        }
    }
}

/// `lights` cut into [`ShadowGroup`]s, in order.
pub fn shadow_groups(lights: &[EnvLight]) -> Vec<ShadowGroup<'_>> {
    let shares = |a: &EnvLight, b: &EnvLight| {
        a.lambda.is_none() && a.shadowed_from.is_some() && a.shadowed_from == b.shadowed_from
    };
    lights
        .chunk_by(shares)
        .map(|run| ShadowGroup {
            direction: run[0].shadow_direction(),
            lights: run,
        })
        .collect()
}
