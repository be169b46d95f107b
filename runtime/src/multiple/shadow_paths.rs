//! Forward-scattering shadow paths through the voxelized hair (Ren 2010 §6, Zinke 2008 §3.1).
//!
//! Along the shadow ray from outside the volume to a sample point, in steps δ, a fiber is hit
//! with probability `P = 1 − exp(−σ_t⊥ α(ν, θ_ξ) δ)`; each hit multiplies the light by ā_f(θ_ξ)
//! and adds β̄_f²(θ_ξ) to the spread, θ_ξ the light's inclination to the voxel's mean fiber
//! direction. A path with k ≥ 1 hits delivers `T = d_f ∏ ā_f` with longitudinal variance
//! `4 Σ β̄_f²` (β̄_f² is in θ_h; the incident inclination moves twice as far) plus, for an SRBF
//! light, the variance the SRBF's own width brings to the first event (`srbf_spread` table);
//! a path with no hit is direct light: T = 1 (as `ForwardScatteringPath`), variance only the
//! SRBF's width seen by the fiber at the sample.
//!
//! **Expected value instead of random paths.** Ren traces a few random paths per sample and
//! box-filters the noise away. The quantities the view pass needs are expectations over those
//! very paths, and they obey exact one-step recursions. Hits in a step of optical depth
//! μ = σ_t⊥ α δ are taken as Poisson with mean μ — the limit of Ren's one-hit-per-step
//! P = 1 − e^{−μ} as δ → 0, without its O(μ) bias (one hit per step at most undercounts; at
//! half-voxel steps in dense hair that was 2–4 % of T_f). With f = e^{−μ(1−ā_f)} per channel:
//!
//! * P₀ ← P₀ e^{−μ}: probability of no hit yet (1 − P per step, as Ren);
//! * M ← f·M: E[∏ ā_f] over all paths (zero-hit paths count 1);
//! * V ← f·V + μ ā_f f β̄_f² M: E[∏ ā_f · Σβ̄_f²];
//! * W ← f·W + σ²_SRBF P₀ (f − e^{−μ}): E[∏ ā_f · σ²_SRBF(first hit) · 1{k ≥ 1}].
//!
//! Then `E[T_f] = P₀ + d_f (M − P₀)`, and σ̄_f² is the energy-weighted second moment of the path
//! mixture: `(P₀ σ²_direct + d_f (4V + W)) / E[T_f]` (channels weighted by T_f: the grid holds
//! one σ̄_f). This is the limit of infinitely many of Ren's random paths: no noise, one march per
//! sample instead of several, and deterministic (tests compare it with closed forms). The box
//! filter of one voxel width (§6) is kept, as an average over `filter_taps³` start points spread
//! over the voxel-sized box around the sample, because it smooths the nearest-voxel staircase.

use glam::Vec3;
use rayon::prelude::*;

use super::fiber_tables::{ForwardEvent, ForwardScatteringTables};
use super::hair_volume::HairVolume;
use crate::env_light::EnvLight;

/// What the march needs per voxel for one light: extinction along ξ and the event there.
pub struct LightMedium {
    /// σ_t⊥ · α(ν, θ_ξ) per voxel (0 where empty).
    pub extinction: Vec<f32>,
    /// ā_f, β̄_f² at θ_ξ per voxel (unused where empty).
    pub event: Vec<ForwardEvent>,
    /// σ²_SRBF(u·ξ, λ) per voxel (0 for a directional light).
    pub srbf_variance: Vec<f32>,
}

impl LightMedium {
    /// Table lookups for every occupied voxel under `light` (parallel over voxels).
    pub fn new(volume: &HairVolume, tables: &ForwardScatteringTables, light: &EnvLight) -> Self {
        let xi = light_direction(light);
        let srbf = light
            .lambda
            .map(|l| tables.srbf_spread.for_bandwidth(l as f64));
        let srbf_at = |s: f64| srbf.as_ref().map_or(0.0, |c| c.variance(s));
        let empty_srbf = srbf_at(0.0);
        let per_voxel: Vec<(f32, ForwardEvent, f32)> = (0..volume.sigma_perp.len())
            .into_par_iter()
            .with_min_len(1024)
            .map(|v| {
                let sigma = volume.sigma_perp[v];
                if !(sigma > 0.0) {
                    let none = ForwardEvent {
                        attenuation: [1.0; 3],
                        variance: [0.0; 3],
                    };
                    return (0.0, none, empty_srbf);
                }
                let s = volume.mean_direction[v].dot(xi).clamp(-1.0, 1.0) as f64;
                let alpha = tables.attenuation_ratio.at(volume.deviation[v] as f64, s);
                (sigma * alpha, tables.fiber_averages.at(s), srbf_at(s))
            })
            .collect();
        let mut medium = Self {
            extinction: Vec::with_capacity(per_voxel.len()),
            event: Vec::with_capacity(per_voxel.len()),
            srbf_variance: Vec::with_capacity(per_voxel.len()),
        };
        for (k, e, s) in per_voxel {
            medium.extinction.push(k);
            medium.event.push(e);
            medium.srbf_variance.push(s);
        }
        medium
    }
}

/// Unit direction toward the light; a degenerate direction falls back to +z (no NaN).
pub fn light_direction(light: &EnvLight) -> Vec3 {
    let d = light.direction;
    if d.is_finite() {
        d.normalize_or(Vec3::Z)
    } else {
        Vec3::Z
    }
}

/// The expectations of one shadow path (see the module notes), per channel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ExpectedShadowPath {
    /// P₀: probability that no fiber was hit.
    pub no_hit: f64,
    /// E[∏ ā_f] (zero-hit paths count 1).
    pub product: [f64; 3],
    /// E[∏ ā_f · Σ β̄_f²].
    pub weighted_variance: [f64; 3],
    /// E[∏ ā_f · σ²_SRBF(first hit) · 1{hit}].
    pub weighted_first_variance: [f64; 3],
    /// E[Σ β̄_f²] unweighted (channel mean): σ̄_f where nothing gets through.
    pub plain_variance: f64,
    /// E[number of hits] = Σ P.
    pub expected_hits: f64,
}

impl Default for ExpectedShadowPath {
    fn default() -> Self {
        Self {
            no_hit: 1.0,
            product: [1.0; 3],
            weighted_variance: [0.0; 3],
            weighted_first_variance: [0.0; 3],
            plain_variance: 0.0,
            expected_hits: 0.0,
        }
    }
}

impl ExpectedShadowPath {
    /// One step of length δ through a voxel of extinction `k` (= σ_t⊥ α), where a hit does
    /// `event` and, if it is the first, brings the SRBF variance `first_variance`. The hits in
    /// the step are Poisson with mean kδ (the continuum limit of Ren's one hit with probability
    /// P = 1 − e^{−kδ}), so the update is exact for piecewise-constant voxels whatever δ:
    /// E[a^N] = e^{−kδ(1−a)}, E[N a^N] = kδ a e^{−kδ(1−a)}, P(N = 0) = e^{−kδ} = 1 − P.
    pub fn step(&mut self, k: f64, delta: f64, event: &ForwardEvent, first_variance: f64) {
        if !(k > 0.0 && delta > 0.0) {
            return;
        }
        let mu = k * delta;
        let none = (-mu).exp();
        let mut mean_beta2 = 0.0;
        for c in 0..3 {
            let a = event.attenuation[c] as f64;
            let b2 = event.variance[c] as f64;
            let f = (-mu * (1.0 - a)).exp();
            self.weighted_first_variance[c] =
                f * self.weighted_first_variance[c] + first_variance * self.no_hit * (f - none);
            self.weighted_variance[c] =
                f * self.weighted_variance[c] + mu * a * f * b2 * self.product[c];
            self.product[c] *= f;
            mean_beta2 += b2 / 3.0;
        }
        self.no_hit *= none;
        self.plain_variance += mu * mean_beta2;
        self.expected_hits += mu;
    }

    /// E\[T_f\] per channel: P₀ + d_f (E[∏ā_f] − P₀).
    pub fn transmittance(&self, density_forward: f64) -> [f64; 3] {
        self.product
            .map(|m| self.no_hit + density_forward * (m - self.no_hit).max(0.0))
    }

    /// The forward-SCATTERED part of E\[T_f\]: d_f (E[∏ā_f] − P₀), paths with at least one hit.
    /// Zinke 2008's global term is (T_f − direct fraction): the directly transmitted light is
    /// single scattering's (shadowed by the DODM, with d_b·S_back in `marschner_full`, Ren §7),
    /// so counting it again in the multiple term would light every exposed fiber twice.
    pub fn scattered_transmittance(&self, density_forward: f64) -> [f64; 3] {
        self.product
            .map(|m| density_forward * (m - self.no_hit).max(0.0))
    }

    /// Numerators of the energy-weighted variance of the incident inclination, per channel
    /// (rad²), with `direct_variance` the spread of direct light (the SRBF's, or 0).
    pub fn variance_numerator(&self, density_forward: f64, direct_variance: f64) -> [f64; 3] {
        std::array::from_fn(|c| {
            self.no_hit * direct_variance
                + density_forward
                    * (4.0 * self.weighted_variance[c] + self.weighted_first_variance[c])
        })
    }
}

/// Marches from outside the volume to `point` toward the light `xi` with steps ≤ `max_step`.
pub fn march(
    volume: &HairVolume,
    medium: &LightMedium,
    point: Vec3,
    xi: Vec3,
    max_step: f32,
) -> ExpectedShadowPath {
    let mut path = ExpectedShadowPath::default();
    let Some((t0, t1)) = volume.grid.ray_interval(point, xi) else {
        return path; // the ray never enters the hair's box: direct light
    };
    let length = t1 - t0;
    if !(length > 0.0) || !(max_step > 0.0) {
        return path;
    }
    let steps = (length / max_step).ceil().max(1.0) as usize;
    let delta = length / steps as f32;
    // From the light's side inward, so the first hit is the one nearest the light.
    for k in 0..steps {
        let t = t1 - (k as f32 + 0.5) * delta;
        let Some(v) = volume.grid.voxel_of(point + xi * t) else {
            continue;
        };
        let ext = medium.extinction[v];
        if ext > 0.0 {
            path.step(
                ext as f64,
                delta as f64,
                &medium.event[v],
                medium.srbf_variance[v] as f64,
            );
        }
    }
    path
}

/// Shadow-path settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MarchSettings {
    /// Step δ as a fraction of the voxel side (≤ 0.5 per Ren's half-voxel).
    pub step_fraction: f32,
    /// Start points per axis of the one-voxel box filter (1 = no filter).
    pub filter_taps: u32,
    /// d_f of Zinke eq. 5.
    pub density_forward: f64,
    /// Count direct (zero-hit) light in T_f (as `ForwardScatteringPath` does) or only the
    /// forward-scattered paths (Zinke's global multiple scattering; the renderer's default).
    pub include_direct: bool,
}

/// Sums the paths that make one sample (box-filter taps, interpolated neighbours) and turns
/// them into [T_r, T_g, T_b, σ̄_f].
#[derive(Clone, Copy, Debug, Default)]
pub struct SampleAccumulator {
    transmittance: [f64; 3],
    variance_numerator: [f64; 3],
    plain_variance: f64,
    paths: f64,
}

impl SampleAccumulator {
    /// Adds one path; `direct_variance` is the spread of direct light at the sample (the
    /// SRBF's own width seen by the fiber there, 0 for a directional light).
    /// With `include_direct` false only the scattered paths count (see
    /// [`ExpectedShadowPath::scattered_transmittance`]).
    pub fn add(
        &mut self,
        path: &ExpectedShadowPath,
        density_forward: f64,
        direct_variance: f64,
        include_direct: bool,
    ) {
        let (t, num) = if include_direct {
            (
                path.transmittance(density_forward),
                path.variance_numerator(density_forward, direct_variance),
            )
        } else {
            (
                path.scattered_transmittance(density_forward),
                path.variance_numerator(density_forward, 0.0),
            )
        };
        for c in 0..3 {
            self.transmittance[c] += t[c];
            self.variance_numerator[c] += num[c];
        }
        self.plain_variance += 4.0 * path.plain_variance + direct_variance;
        self.paths += 1.0;
    }

    /// Mean T_f per channel and σ̄_f = √(energy-weighted variance); where nothing gets through
    /// (T_f = 0 in every channel) σ̄_f falls back to the unweighted expected spread.
    pub fn value(&self) -> [f32; 4] {
        let n = self.paths.max(1.0);
        let total: f64 = self.transmittance.iter().sum();
        let variance = if total > 1e-20 {
            self.variance_numerator.iter().sum::<f64>() / total
        } else {
            self.plain_variance / n
        };
        [
            (self.transmittance[0] / n) as f32,
            (self.transmittance[1] / n) as f32,
            (self.transmittance[2] / n) as f32,
            variance.max(0.0).sqrt() as f32,
        ]
    }
}

/// [T_r, T_g, T_b, σ̄_f] at one sample point for one light: the mean of `filter_taps³` paths
/// started over the voxel-sized box around the point (§6's one-voxel box filter).
pub fn sample_value(
    volume: &HairVolume,
    medium: &LightMedium,
    point: Vec3,
    xi: Vec3,
    settings: &MarchSettings,
) -> [f32; 4] {
    let taps = settings.filter_taps.max(1);
    let h = volume.grid.voxel_size;
    let step = settings.step_fraction * h;
    let mut acc = SampleAccumulator::default();
    for i in 0..taps.pow(3) {
        let ijk = [i % taps, (i / taps) % taps, i / (taps * taps)];
        let offset = Vec3::from_array(ijk.map(|j| ((j as f32 + 0.5) / taps as f32 - 0.5) * h));
        let p = point + offset;
        let path = march(volume, medium, p, xi, step);
        let direct_variance = medium.srbf_variance[volume.grid.voxel_clamped(p)] as f64;
        acc.add(
            &path,
            settings.density_forward,
            direct_variance,
            settings.include_direct,
        );
    }
    acc.value()
}

/// Values for every point in `points` under one light (parallel over points).
pub fn sample_light(
    volume: &HairVolume,
    tables: &ForwardScatteringTables,
    light: &EnvLight,
    points: &[Vec3],
    settings: &MarchSettings,
) -> Vec<[f32; 4]> {
    let medium = LightMedium::new(volume, tables, light);
    let xi = light_direction(light);
    points
        .par_iter()
        .with_min_len(16)
        .map(|&p| sample_value(volume, &medium, p, xi, settings))
        .collect()
}
