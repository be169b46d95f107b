//! Lobe spread: an SRBF light's visibility averaged over directions of its lobe, each traced
//! through the light's own convolution optical depth map, instead of Ren's one filtered
//! visibility per lobe (docs/BENCHMARKS.md, "Lobe spread").
//!
//! The DODM of a light is a volume in the light's frame: per texel the nearest fiber depth z0
//! and the cumulative optical depth at four depths behind it. A direction ω tilted by γ from
//! the light's centre ξ leaves the shaded point x along a sheared line through that volume: at
//! a distance Δ toward the light it lies Δ·tan γ to the side. Marching that line and reading,
//! per step, the optical depth its column holds between the step's two absolute depths gives
//! τ(ω) without a light pass of its own (`lobe_spread.wgsl`). The lobe's visibility is then the
//! mean of exp(−τ(ω_k)) over directions stratified by the SRBF G(γ) = exp(λ(cos γ − 1)):
//! `rings` rings at the quantiles (i + ½)/rings of 1 − cos γ, `per_ring` directions on each.
//!
//! Unlike the box filter of [`super::transmittance_filter`], whose radius grows only with the
//! depth behind the point's own first fiber, this also shadows a lit point beside a shadow's
//! edge (occluders in neighbouring columns), and it averages transmittance per direction, not
//! optical depth over a box. The march covers the last `reach` first layers before the point;
//! beyond it the point's own column stands for every direction.
//!
//! The tilt is `cone_scale` × tan γ. Where the map resolves the hair's depth (a slab thinner
//! than the last layer boundary, `lobe_spread_follows_the_cone_integral_beside_a_slot`) the
//! geometry's own tilt, scale 1, follows the cone integral best. On a groom, scale 1 makes the
//! hair 5–40% brighter than the brute-force reference (by how far it marches). Why is not settled: the map lumps every
//! fiber deeper than 10 first layers behind a column's front at that boundary, but a march that
//! fell back to the centre column wherever its line ran deeper than that was as bright. 0.3 was
//! chosen on one map (venice, κ = 1) and checked on the others (docs/BENCHMARKS.md, "Lobe
//! spread"): a calibration, not a derivation.

/// How the lobe's visibility is spread over its directions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LobeSpread {
    /// Rings of directions around the SRBF centre (quantiles of the lobe's 1 − cos γ).
    pub rings: u32,
    /// Directions per ring.
    pub per_ring: u32,
    /// Steps of each direction's march.
    pub steps: u32,
    /// Depth marched before the point, in first layers d of the DODM.
    pub reach_layers: f32,
    /// Tilt of the marched lines: tan γ times this.
    pub cone_scale: f32,
    /// Weigh each direction by the fiber's response to it (the single table at its narrowest
    /// width), so the visibility is averaged over the lobe times the fiber, not the lobe alone.
    pub fiber_weighted: bool,
}

impl Default for LobeSpread {
    fn default() -> Self {
        Self {
            rings: 1,
            per_ring: 6,
            steps: 4,
            reach_layers: 20.0,
            cone_scale: 0.3,
            fiber_weighted: false,
        }
    }
}

#[derive(Debug, thiserror::Error)]
#[error("lobe spread: {0}")]
pub struct LobeSpreadError(String);

impl LobeSpread {
    pub fn validate(&self) -> Result<(), LobeSpreadError> {
        let within = |name: &str, value: u32, max: u32| {
            if (1..=max).contains(&value) {
                Ok(())
            } else {
                Err(LobeSpreadError(format!("{value} {name}: must be 1–{max}")))
            }
        };
        within("rings", self.rings, 8)?;
        within("directions per ring", self.per_ring, 16)?;
        within("steps", self.steps, 64)?;
        let positive = |name: &str, value: f32, max: f32| {
            if value > 0.0 && value <= max {
                Ok(())
            } else {
                Err(LobeSpreadError(format!(
                    "{name} {value}: must be in (0, {max}]"
                )))
            }
        };
        positive("reach (first layers)", self.reach_layers, 1000.0)?;
        positive("cone scale", self.cone_scale, 4.0)
    }
}

/// The spread as the batch uniform carries it (`BatchParams` in `convolution_transmittance.wgsl`):
/// counts (rings, per ring, steps, fiber weighting 0/1; all 0 when off) and shape (reach in
/// first layers, cone scale).
pub fn spread_uniform(spread: Option<LobeSpread>) -> ([u32; 4], [f32; 4]) {
    match spread {
        None => ([0; 4], [0.0; 4]),
        Some(s) => (
            [s.rings, s.per_ring, s.steps, u32::from(s.fiber_weighted)],
            [s.reach_layers, s.cone_scale, 0.0, 0.0],
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn settings_out_of_range_are_refused_by_name() {
        assert!(LobeSpread::default().validate().is_ok());
        let bad = [
            LobeSpread {
                rings: 0,
                ..Default::default()
            },
            LobeSpread {
                per_ring: 17,
                ..Default::default()
            },
            LobeSpread {
                steps: 0,
                ..Default::default()
            },
            LobeSpread {
                reach_layers: f32::NAN,
                ..Default::default()
            },
            LobeSpread {
                cone_scale: -1.0,
                ..Default::default()
            },
        ];
        let names = ["rings", "per ring", "steps", "reach", "cone scale"];
        for (spread, name) in bad.iter().zip(names) {
            let error = spread.validate().unwrap_err().to_string();
            assert!(error.contains(name), "{error} should name {name}");
        }
    }
}
