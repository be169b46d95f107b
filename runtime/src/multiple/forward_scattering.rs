//! The CPU source of forward-scattering grids (Ren 2010 §6): voxelize once per hair state, then
//! march expected shadow paths from the vertices of a coarse sample grid (¼ of the voxel
//! resolution per axis, as the paper) toward every light, in parallel with rayon.
//!
//! The paper runs both steps in CUDA; [`super::gpu_shadow_paths`] marches on the GPU from the
//! same medium. `examples/forward_scattering_convergence.rs` times both and holds the
//! convergence study.

use glam::Vec3;
use rayon::prelude::*;

use super::fiber_tables::{ForwardScatteringError, ForwardScatteringTables};
use super::hair_volume::{HairVolume, VoxelSettings};
use super::light_sweep::LightSweep;
use super::shadow_paths::{
    LightMedium, MarchSettings, SampleAccumulator, light_direction, sample_value,
};
use crate::env_light::EnvLight;
use crate::hair::HairModel;
use crate::head::Head;

/// Everything that sets the grid's accuracy and cost.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ForwardScatteringSettings {
    pub voxels: VoxelSettings,
    /// Voxels per sample-grid cell along each axis (Ren: 4; 1 samples every voxel corner).
    pub coarse_factor: u32,
    /// Step δ as a fraction of the voxel side (Ren marches in ≤ half-voxel steps).
    pub step_fraction: f32,
    /// Start points per axis of the one-voxel box filter around each sample (1 = none).
    pub filter_taps: u32,
    /// Zinke's d_f (0.6–0.8 for human hair) for the SRBF lobes.
    pub density_forward: f64,
    /// d_f for the fit's compact sources ([`EnvLight::has_sharp_shadow`]), whose shadow
    /// paths cross the grid's measured density. At Zinke's 0.7 they drew 0.64–0.86 of the
    /// truth's multiple scattering on the maps with a dominant sun, at 1 (no correction)
    /// 0.80–1.01; the 16×16 error fell on 13 of the 15 map and preset pairs with compact
    /// sources, golf's eight lamps on light hair the exception (docs/BENCHMARKS.md, "Multiple
    /// scattering by melanin").
    pub compact_density_forward: f64,
    /// Compute each light's paths once on a light-aligned lattice of rays one voxel apart
    /// ([`super::light_sweep`]) and interpolate, instead of marching from every sample
    /// (`filter_taps` is then unused: the lateral interpolation is the filter). Faster for
    /// dense sample grids, slower for the coarse interactive one.
    pub light_sweep: bool,
    /// T_f also counts the direct light (zero-hit paths, T = 1), as `ForwardScatteringPath`.
    /// Off by default: the view pass adds T_f·I_G ON TOP of single scattering, which already
    /// carries the direct light, so T_f must be Zinke's scattered part (T_f − direct fraction).
    pub include_direct: bool,
}

impl Default for ForwardScatteringSettings {
    /// Ren's interactive setting: coarse grid ¼ of the voxels, half-voxel steps.
    fn default() -> Self {
        Self {
            voxels: VoxelSettings::default(),
            coarse_factor: 4,
            step_fraction: 0.5,
            filter_taps: 2,
            density_forward: strandlight_tables::dual_scattering::DEFAULT_DENSITY_FACTOR,
            compact_density_forward: 1.0,
            light_sweep: false,
            include_direct: false,
        }
    }
}

impl ForwardScatteringSettings {
    /// The interactive frame's setting on the CPU: samples every second voxel corner (Ren's
    /// 4 left the multiple-scattering part of a full frame 0.027–0.099 off the dense
    /// reference's on the eight shared maps, 15% dark on royal esplanade), computed by light
    /// sweeps, which at this density cost what Ren's coarse march did (0.92–0.99× the full
    /// frame on lavapipe, 0.76× on photo studio). Measured in docs/BENCHMARKS.md, "Where the
    /// error comes from, map by map" (its forward-scattering grid part). The GPU march cannot
    /// sweep: it runs this grid with `light_sweep` off.
    pub fn interactive() -> Self {
        Self {
            coarse_factor: 2,
            light_sweep: true,
            ..Self::default()
        }
    }

    /// The reference renderer's setting: samples at every voxel corner, quarter-voxel steps,
    /// computed by light sweeps (see the convergence study in the example).
    pub fn dense_reference() -> Self {
        Self {
            coarse_factor: 1,
            step_fraction: 0.25,
            light_sweep: true,
            ..Self::default()
        }
    }

    pub fn validate(&self) -> Result<(), ForwardScatteringError> {
        self.voxels.validate()?;
        let bad = |parameter: &'static str, value: String, problem: &str| {
            Err(ForwardScatteringError::InvalidSetting {
                parameter,
                value,
                problem: problem.into(),
            })
        };
        if !(1..=64).contains(&self.coarse_factor) {
            return bad(
                "coarse_factor",
                self.coarse_factor.to_string(),
                "must be in 1..=64",
            );
        }
        if !(self.step_fraction > 0.0 && self.step_fraction <= 1.0) {
            return bad(
                "step_fraction",
                self.step_fraction.to_string(),
                "must be in (0, 1]",
            );
        }
        if !(1..=8).contains(&self.filter_taps) {
            return bad(
                "filter_taps",
                self.filter_taps.to_string(),
                "must be in 1..=8",
            );
        }
        for (name, value) in [
            ("density_forward", self.density_forward),
            ("compact_density_forward", self.compact_density_forward),
        ] {
            if !(value.is_finite() && (0.0..=1.0).contains(&value)) {
                return bad(name, value.to_string(), "must be in [0, 1]");
            }
        }
        Ok(())
    }

    /// The d_f of `light`'s shadow paths.
    pub fn density_forward_of(&self, light: &EnvLight) -> f64 {
        match light.has_sharp_shadow() {
            true => self.compact_density_forward,
            false => self.density_forward,
        }
    }

    fn march(&self, light: &EnvLight) -> MarchSettings {
        MarchSettings {
            step_fraction: self.step_fraction,
            filter_taps: self.filter_taps,
            density_forward: self.density_forward_of(light),
            include_direct: self.include_direct,
        }
    }
}

/// The sample grid's geometry (a `ForwardScatteringGrid` without values).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SampleGrid {
    pub origin: Vec3,
    pub spacing: Vec3,
    pub dims: [u32; 3],
}

impl SampleGrid {
    /// Vertices every `coarse_factor` voxels, spanning the whole voxel grid (which covers the
    /// hair's bounds): ⌈voxels/factor⌉ + 1 vertices per axis.
    pub fn over(volume: &HairVolume, coarse_factor: u32) -> Self {
        let g = &volume.grid;
        let dims = g.dims.map(|d| d.div_ceil(coarse_factor.max(1)) + 1);
        let extent = g.extent();
        let spacing = Vec3::new(
            extent.x / (dims[0] - 1) as f32,
            extent.y / (dims[1] - 1) as f32,
            extent.z / (dims[2] - 1) as f32,
        );
        Self {
            origin: g.origin,
            spacing,
            dims,
        }
    }

    pub fn vertex_count(&self) -> usize {
        self.dims.iter().map(|&d| d as usize).product()
    }

    /// Vertex positions in the grid's order (x fastest, then y, then z).
    pub fn positions(&self) -> Vec<Vec3> {
        let [nx, ny, nz] = self.dims;
        let mut out = Vec::with_capacity(self.vertex_count());
        for z in 0..nz {
            for y in 0..ny {
                for x in 0..nx {
                    out.push(self.origin + self.spacing * Vec3::new(x as f32, y as f32, z as f32));
                }
            }
        }
        out
    }
}

/// T_f and σ̄_f for batches of lights, computed on the CPU from a voxelized hair model.
#[derive(Clone, Debug)]
pub struct CpuForwardScattering {
    volume: HairVolume,
    tables: ForwardScatteringTables,
    settings: ForwardScatteringSettings,
    sample_grid: SampleGrid,
    positions: Vec<Vec3>,
    /// An opaque head (issue 40): a sample whose ray toward the light meets it gets T = 0.
    head: Option<Head>,
}

impl CpuForwardScattering {
    /// The head as the grid's opaque boundary: samples behind it from a light receive none of
    /// that light's forward-scattered radiance (exact ray test, [`Head::ray_hit`]); σ̄_f stays.
    pub fn with_head(mut self, head: Option<Head>) -> Self {
        self.head = head;
        self
    }

    /// T = 0 at the samples `points` whose ray toward `xi` meets the head (the GPU's march
    /// applies it to its values too).
    pub(crate) fn block_by_head(&self, xi: Vec3, points: &[Vec3], values: &mut [[f32; 4]]) {
        let Some(head) = &self.head else { return };
        values
            .par_iter_mut()
            .zip(points.par_iter())
            .filter(|(_, p)| head.ray_hit(**p, xi, f32::INFINITY).is_some())
            .for_each(|(v, _)| {
                v[0] = 0.0;
                v[1] = 0.0;
                v[2] = 0.0;
            });
    }

    /// Voxelizes `model` and checks the tables and settings.
    pub fn new(
        model: &HairModel,
        tables: ForwardScatteringTables,
        settings: ForwardScatteringSettings,
    ) -> Result<Self, ForwardScatteringError> {
        settings.validate()?;
        let volume = HairVolume::build(model, &settings.voxels, tables.attenuation_ratio.nu_max())?;
        Ok(Self::from_volume(volume, tables, settings))
    }

    /// From an already voxelized model (dynamic hair: rebuild the volume, keep the tables).
    pub fn from_volume(
        volume: HairVolume,
        tables: ForwardScatteringTables,
        settings: ForwardScatteringSettings,
    ) -> Self {
        let sample_grid = SampleGrid::over(&volume, settings.coarse_factor);
        let positions = sample_grid.positions();
        Self {
            volume,
            tables,
            settings,
            sample_grid,
            positions,
            head: None,
        }
    }

    /// The same voxelized hair sampled under other `settings` (the GPU's march beside the CPU's
    /// sweep); their voxels must be the ones it was voxelized with.
    pub fn with_settings(
        self,
        settings: ForwardScatteringSettings,
    ) -> Result<Self, ForwardScatteringError> {
        settings.validate()?;
        if settings.voxels != self.settings.voxels {
            return Err(ForwardScatteringError::InvalidSetting {
                parameter: "voxels",
                value: format!("{:?}", settings.voxels),
                problem: format!(
                    "the hair was voxelized with {:?}; voxelize it again instead",
                    self.settings.voxels
                ),
            });
        }
        Ok(Self::from_volume(self.volume, self.tables, settings).with_head(self.head))
    }

    pub fn volume(&self) -> &HairVolume {
        &self.volume
    }

    pub fn settings(&self) -> &ForwardScatteringSettings {
        &self.settings
    }

    pub fn sample_grid(&self) -> &SampleGrid {
        &self.sample_grid
    }

    /// The sample grid's vertex positions, in the grid's order.
    pub fn sample_points(&self) -> &[Vec3] {
        &self.positions
    }

    /// The per-voxel medium under `light` (table lookups; what both sources march).
    pub fn medium(&self, light: &EnvLight) -> LightMedium {
        LightMedium::new(&self.volume, &self.tables, light)
    }

    /// [T_r, T_g, T_b, σ̄_f] at arbitrary points for one light (no grid interpolation): the
    /// convergence study and tests probe fixed points with it.
    /// Uses the light sweep when the settings ask for it.
    pub fn values_at(&self, light: &EnvLight, points: &[Vec3]) -> Vec<[f32; 4]> {
        let mut values = self.unblocked_values_at(light, points);
        self.block_by_head(light_direction(light), points, &mut values);
        values
    }

    fn unblocked_values_at(&self, light: &EnvLight, points: &[Vec3]) -> Vec<[f32; 4]> {
        let medium = self.medium(light);
        let xi = light_direction(light);
        let march = self.settings.march(light);
        if self.settings.light_sweep {
            let h = self.volume.grid.voxel_size;
            let substeps = (1.0 / march.step_fraction).ceil() as u32;
            let sweep = LightSweep::new(&self.volume, &medium, xi, h, substeps);
            return points
                .par_iter()
                .with_min_len(64)
                .map(|&p| {
                    let mut acc = SampleAccumulator::default();
                    let direct = medium.srbf_variance[self.volume.grid.voxel_clamped(p)] as f64;
                    acc.add(
                        &sweep.path_at(p),
                        march.density_forward,
                        direct,
                        march.include_direct,
                    );
                    acc.value()
                })
                .collect();
        }
        points
            .par_iter()
            .map(|&p| sample_value(&self.volume, &medium, p, xi, &march))
            .collect()
    }
}

impl ForwardScatteringSource for CpuForwardScattering {
    /// One light after another (each light's medium is built in parallel over voxels, then its
    /// samples are marched in parallel): memory stays at one light's medium.
    fn grid(&self, lights: &[EnvLight]) -> Result<ForwardScatteringGrid, ForwardScatteringError> {
        let n = self.positions.len();
        let mut values = Vec::with_capacity(n * lights.len());
        for light in lights {
            values.extend(self.values_at(light, &self.positions));
        }
        Ok(ForwardScatteringGrid {
            origin: self.sample_grid.origin,
            spacing: self.sample_grid.spacing,
            dims: self.sample_grid.dims,
            values,
        })
    }

    fn device(&self) -> &'static str {
        "CPU"
    }
}

/// Trilinear value of light `light` of `grid` at `p`, clamped at the border (what the view
/// pass does on the GPU; used by the CPU tests and the convergence study). `None` when the
/// grid has no block for `light` or no vertices.
pub fn interpolate_grid(grid: &ForwardScatteringGrid, light: usize, p: Vec3) -> Option<[f32; 4]> {
    let [nx, ny, nz] = grid.dims.map(|d| d as usize);
    let block = nx * ny * nz;
    if block == 0 {
        return None;
    }
    let values = grid.values.get(light * block..(light + 1) * block)?;
    let q = (p - grid.origin) / grid.spacing;
    let cell = |k: usize, n: usize| -> (usize, f32) {
        let v = if q[k].is_finite() {
            q[k].clamp(0.0, (n - 1) as f32)
        } else {
            0.0
        };
        let i = (v.floor() as usize).min(n.saturating_sub(2));
        (i, if n > 1 { v - i as f32 } else { 0.0 })
    };
    let ((x, fx), (y, fy), (z, fz)) = (cell(0, nx), cell(1, ny), cell(2, nz));
    let mut out = [0.0f32; 4];
    for corner in 0..8 {
        let (dx, dy, dz) = (corner & 1, corner >> 1 & 1, corner >> 2 & 1);
        let w = (if dx == 1 { fx } else { 1.0 - fx })
            * (if dy == 1 { fy } else { 1.0 - fy })
            * (if dz == 1 { fz } else { 1.0 - fz });
        if w == 0.0 {
            continue;
        }
        let (ix, iy, iz) = (
            (x + dx).min(nx - 1),
            (y + dy).min(ny - 1),
            (z + dz).min(nz - 1),
        );
        let v = values[(iz * ny + iy) * nx + ix];
        for c in 0..4 {
            out[c] += w * v[c];
        }
    }
    Some(out)
}

/// The forward-scattering attenuation T_f (RGB) and spread σ̄_f (radians, the standard
/// deviation of the incident inclination) of Ren §6, sampled on a regular grid over the hair
/// per light, as the view pass reads them: `values[light][z][y][x] = [T_r, T_g, T_b, σ̄_f]`,
/// trilinearly interpolated between grid vertices, clamped at the border.
#[derive(Clone, Debug, PartialEq)]
pub struct ForwardScatteringGrid {
    /// World position of vertex (0, 0, 0).
    pub origin: Vec3,
    /// World distance between neighbouring vertices along x, y, z.
    pub spacing: Vec3,
    /// Vertices along x, y, z.
    pub dims: [u32; 3],
    /// One block of dims.x·dims.y·dims.z values per light, in the order of the lights asked for.
    pub values: Vec<[f32; 4]>,
}

/// Computes [`ForwardScatteringGrid`]s for batches of lights (the multiple-scattering module
/// implements it on the CPU and on the GPU; a frame asks once per batch).
pub trait ForwardScatteringSource {
    /// The grid (with values for every light in `lights`, in order).
    fn grid(&self, lights: &[EnvLight]) -> Result<ForwardScatteringGrid, ForwardScatteringError>;

    /// Where the march runs ("CPU", "GPU"): names the pass in the frame's timings.
    fn device(&self) -> &'static str;
}
