//! Voxelization of a hair model (Ren 2010 §6): per voxel the average fiber direction ω̄, the
//! direction deviation ν and the perpendicular attenuation coefficient σ_t⊥.
//!
//! * σ_t⊥ is the projected fiber cross-section per unit volume: a fiber piece of length ℓ and
//!   diameter d shadows light arriving perpendicular to it over an area ℓ·d, so
//!   σ_t⊥ = Σ ℓ·d / V_voxel (a density of n parallel fibers per unit area A crossing the voxel
//!   gives n·d/A — the closed form the tests check).
//! * ω̄ is the principal eigenvector of the length-weighted structure tensor Σ ℓ t tᵀ, which
//!   does not care whether a strand runs up or down; its sign is then chosen along the
//!   length-weighted sum of signed tangents (root → tip), so ω̄ keeps the majority orientation
//!   that the (not quite θ-symmetric) fiber averages need.
//! * ν inverts E[sin² r] = 1 − λ_max(E[t tᵀ]) under the attenuation-ratio model
//!   ([`super::direction_deviation`]).
//!
//! Strand segments are cut into pieces no longer than half a voxel side and each piece is
//! deposited in the voxel holding its midpoint (error below half a voxel in position, none in
//! total length). Strands are split across rayon tasks, each accumulating its own grid.
//! Dynamic hair rebuilds the volume every frame: [`HairVolume::build`] is what to time.

use glam::{DVec3, Vec3};
use rayon::prelude::*;

use super::direction_deviation::DirectionDeviation;
use super::fiber_tables::ForwardScatteringError;
use crate::hair::{Aabb, HairModel};

/// How to voxelize.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VoxelSettings {
    /// Voxels along the longest side of the hair's bounds (voxels are cubes). Ren's Table 1
    /// uses 74–90 on the longest side; 64 by default.
    pub voxels_longest_side: u32,
    /// Fiber diameter where the model has no thickness attribute (model units); `None` uses
    /// the renderer's default (`passes::strand_geometry::default_thickness`: 10⁻³ × bounds diagonal).
    pub default_diameter: Option<f32>,
}

impl Default for VoxelSettings {
    fn default() -> Self {
        Self {
            voxels_longest_side: 64,
            default_diameter: None,
        }
    }
}

impl VoxelSettings {
    pub fn validate(&self) -> Result<(), ForwardScatteringError> {
        if !(1..=1024).contains(&self.voxels_longest_side) {
            return Err(ForwardScatteringError::InvalidSetting {
                parameter: "voxels_longest_side",
                value: self.voxels_longest_side.to_string(),
                problem: "must be in 1..=1024".into(),
            });
        }
        if let Some(d) = self.default_diameter
            && !(d.is_finite() && d >= 0.0)
        {
            return Err(ForwardScatteringError::InvalidSetting {
                parameter: "default_diameter",
                value: d.to_string(),
                problem: "must be finite and ≥ 0".into(),
            });
        }
        Ok(())
    }
}

/// A regular grid of cubic voxels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VoxelGrid {
    /// Corner of voxel (0, 0, 0).
    pub origin: Vec3,
    /// Side of every voxel.
    pub voxel_size: f32,
    pub dims: [u32; 3],
}

impl VoxelGrid {
    /// Cubic voxels, `longest` along the longest side of `bounds`, the grid centred on them.
    /// Flat or point-like bounds still get voxels of positive size.
    pub fn around(bounds: Aabb, longest: u32, fallback_size: f32) -> Self {
        let size = bounds.size().max(Vec3::ZERO);
        let longest_side = size.max_element();
        let voxel_size = if longest_side > 0.0 {
            longest_side / longest.max(1) as f32
        } else {
            fallback_size.max(1e-6)
        };
        let dims = size
            .to_array()
            .map(|s| ((s / voxel_size).ceil() as u32).max(1));
        let extent = Vec3::new(dims[0] as f32, dims[1] as f32, dims[2] as f32) * voxel_size;
        Self {
            origin: bounds.center() - 0.5 * extent,
            voxel_size,
            dims,
        }
    }

    pub fn voxel_count(&self) -> usize {
        self.dims.iter().map(|&d| d as usize).product()
    }

    /// World extent of the grid.
    pub fn extent(&self) -> Vec3 {
        Vec3::new(
            self.dims[0] as f32,
            self.dims[1] as f32,
            self.dims[2] as f32,
        ) * self.voxel_size
    }

    pub fn linear_index(&self, [x, y, z]: [u32; 3]) -> usize {
        (z as usize * self.dims[1] as usize + y as usize) * self.dims[0] as usize + x as usize
    }

    /// The voxel holding `p`, or `None` outside the grid.
    pub fn voxel_of(&self, p: Vec3) -> Option<usize> {
        let q = (p - self.origin) / self.voxel_size;
        let mut idx = [0u32; 3];
        for k in 0..3 {
            let v = q[k];
            if !(v >= 0.0 && v < self.dims[k] as f32) {
                return None;
            }
            idx[k] = (v as u32).min(self.dims[k] - 1);
        }
        Some(self.linear_index(idx))
    }

    /// The voxel holding `p`, with points on or just beyond the border clamped in.
    pub fn voxel_clamped(&self, p: Vec3) -> usize {
        let q = (p - self.origin) / self.voxel_size;
        let idx: [u32; 3] = std::array::from_fn(|k| {
            let v = if q[k].is_finite() { q[k] } else { 0.0 };
            (v.max(0.0) as u32).min(self.dims[k] - 1)
        });
        self.linear_index(idx)
    }

    /// Parameter interval [t0, t1] (t ≥ 0) of the ray p + t·d inside the grid's box, if any.
    pub fn ray_interval(&self, p: Vec3, d: Vec3) -> Option<(f32, f32)> {
        let (lo, hi) = (self.origin, self.origin + self.extent());
        let (mut t0, mut t1) = (0.0f32, f32::INFINITY);
        for k in 0..3 {
            if d[k].abs() < 1e-12 {
                if p[k] < lo[k] || p[k] > hi[k] {
                    return None;
                }
                continue;
            }
            let (a, b) = ((lo[k] - p[k]) / d[k], (hi[k] - p[k]) / d[k]);
            t0 = t0.max(a.min(b));
            t1 = t1.min(a.max(b));
        }
        (t0 <= t1).then_some((t0, t1))
    }
}

/// The voxelized hair: one value of each quantity per voxel, x fastest, then y, then z.
#[derive(Clone, Debug)]
pub struct HairVolume {
    pub grid: VoxelGrid,
    /// σ_t⊥ (1 / model unit).
    pub sigma_perp: Vec<f32>,
    /// ω̄ (unit; +z in empty voxels).
    pub mean_direction: Vec<Vec3>,
    /// ν (radians, clamped to the attenuation-ratio table's range).
    pub deviation: Vec<f32>,
    /// Fiber length per voxel (model units), kept for tests and statistics.
    pub fiber_length: Vec<f32>,
    /// The length-weighted second moment E[t tᵀ] of the fiber tangents (xx, yy, zz, xy, xz,
    /// yz; zero in empty voxels): a ray along ω meets the voxel's fibers with
    /// E[(t·ω)²] = ωᵀ E[t tᵀ] ω, so light along the fibers passes where light across them is
    /// stopped (`crate::visibility`).
    pub tangent_moment: Vec<[f32; 6]>,
}

/// Per-voxel sums: length, length × diameter, structure tensor (xx, yy, zz, xy, xz, yz),
/// signed tangent × length.
#[derive(Clone, Copy, Default)]
struct VoxelSums {
    length: f64,
    cross_section: f64,
    tensor: [f64; 6],
    signed: [f64; 3],
}

impl VoxelSums {
    fn deposit(&mut self, length: f64, diameter: f64, t: DVec3) {
        self.length += length;
        self.cross_section += length * diameter;
        let w = length;
        self.tensor[0] += w * t.x * t.x;
        self.tensor[1] += w * t.y * t.y;
        self.tensor[2] += w * t.z * t.z;
        self.tensor[3] += w * t.x * t.y;
        self.tensor[4] += w * t.x * t.z;
        self.tensor[5] += w * t.y * t.z;
        self.signed[0] += w * t.x;
        self.signed[1] += w * t.y;
        self.signed[2] += w * t.z;
    }
}

/// Principal eigenvector of a symmetric positive semi-definite 3×3 matrix (power iteration,
/// started from the signed mean when it has weight, else from the heaviest diagonal axis).
fn principal_direction(m: &[f64; 6], start: DVec3) -> DVec3 {
    let apply = |v: DVec3| {
        DVec3::new(
            m[0] * v.x + m[3] * v.y + m[4] * v.z,
            m[3] * v.x + m[1] * v.y + m[5] * v.z,
            m[4] * v.x + m[5] * v.y + m[2] * v.z,
        )
    };
    let diag = [m[0], m[1], m[2]];
    let heaviest = (0..3)
        .max_by(|&a, &b| diag[a].total_cmp(&diag[b]))
        .unwrap_or(2);
    let axis = [DVec3::X, DVec3::Y, DVec3::Z][heaviest];
    // Start off any eigenvector-orthogonal plane by mixing in the heaviest axis.
    let mut v = (start.normalize_or_zero() + 0.5 * axis).normalize_or(axis);
    for _ in 0..64 {
        let next = apply(v);
        let len = next.length();
        if !(len > 1e-300) {
            return axis;
        }
        let next = next / len;
        if (next - v).length_squared() < 1e-24 {
            return next;
        }
        v = next;
    }
    v
}

impl HairVolume {
    /// Voxelizes `model`. `nu_max` is the attenuation-ratio table's largest ν (deviations clamp
    /// to it). Fibers' diameters come from the model's thickness attribute when it has one.
    pub fn build(
        model: &HairModel,
        settings: &VoxelSettings,
        nu_max: f64,
    ) -> Result<Self, ForwardScatteringError> {
        settings.validate()?;
        let default_diameter = settings
            .default_diameter
            .unwrap_or_else(|| crate::passes::strand_geometry::default_thickness(model));
        let grid = VoxelGrid::around(
            model.bounds(),
            settings.voxels_longest_side,
            default_diameter,
        );
        let sums = accumulate(model, &grid, default_diameter);
        Ok(Self::from_sums(grid, &sums, nu_max))
    }

    fn from_sums(grid: VoxelGrid, sums: &[VoxelSums], nu_max: f64) -> Self {
        let deviation_model = DirectionDeviation::new(nu_max, 257);
        let volume = (grid.voxel_size as f64).powi(3);
        let per_voxel: Vec<(f32, Vec3, f32, f32, [f32; 6])> = sums
            .par_iter()
            .map(|s| {
                if !(s.length > 0.0) {
                    return (0.0, Vec3::Z, 0.0, 0.0, [0.0; 6]);
                }
                let m = s.tensor.map(|v| v / s.length);
                let signed = DVec3::from_array(s.signed);
                let mut dir = principal_direction(&m, signed);
                if dir.dot(signed) < 0.0 {
                    dir = -dir;
                }
                let lambda_max = dir.x * (m[0] * dir.x + m[3] * dir.y + m[4] * dir.z)
                    + dir.y * (m[3] * dir.x + m[1] * dir.y + m[5] * dir.z)
                    + dir.z * (m[4] * dir.x + m[5] * dir.y + m[2] * dir.z);
                let nu = deviation_model.nu_from_mean_sin2((1.0 - lambda_max).max(0.0));
                (
                    (s.cross_section / volume) as f32,
                    dir.as_vec3(),
                    nu as f32,
                    s.length as f32,
                    m.map(|v| v as f32),
                )
            })
            .collect();
        let mut out = Self {
            grid,
            sigma_perp: Vec::with_capacity(sums.len()),
            mean_direction: Vec::with_capacity(sums.len()),
            deviation: Vec::with_capacity(sums.len()),
            fiber_length: Vec::with_capacity(sums.len()),
            tangent_moment: Vec::with_capacity(sums.len()),
        };
        for (s, d, nu, l, m) in per_voxel {
            out.sigma_perp.push(s);
            out.mean_direction.push(d);
            out.deviation.push(nu);
            out.fiber_length.push(l);
            out.tangent_moment.push(m);
        }
        out
    }

    /// Number of voxels holding any fiber.
    pub fn occupied_voxels(&self) -> usize {
        self.fiber_length.iter().filter(|&&l| l > 0.0).count()
    }
}

/// The fiber length segment `segment` leaves in `voxel`: its pieces (at most half a voxel
/// long) whose midpoints fall there, consecutive ones merged. 16 bytes: the segment's diameter
/// and tangent are looked up again when the deposit is added.
struct Deposit {
    voxel: u32,
    segment: u32,
    length: f64,
}

/// Strands whose deposits are computed in parallel and then summed, per block: bounds the
/// deposits held at once (a few MB) while keeping the threads busy.
const STRANDS_PER_BLOCK: usize = 4096;

/// Per-voxel sums of every strand's pieces. The pieces are cut in parallel but added in strand
/// order on one thread, so the f64 sums (and the grid) are bit-identical for any thread count.
fn accumulate(model: &HairModel, grid: &VoxelGrid, default_diameter: f32) -> Vec<VoxelSums> {
    let mut sums = vec![VoxelSums::default(); grid.voxel_count()];
    let strands = model.strand_count();
    for block_start in (0..strands).step_by(STRANDS_PER_BLOCK) {
        let block = block_start..(block_start + STRANDS_PER_BLOCK).min(strands);
        let deposits: Vec<Vec<Deposit>> = block
            .into_par_iter()
            .map(|s| strand_deposits(model, s, grid))
            .collect();
        for d in deposits.iter().flatten() {
            let (diameter, tangent) = segment_fiber(model, d.segment as usize, default_diameter);
            sums[d.voxel as usize].deposit(d.length, diameter, tangent);
        }
    }
    sums
}

/// Diameter and unit tangent of the segment from point `i` to `i + 1` (not of zero length).
fn segment_fiber(model: &HairModel, i: usize, default_diameter: f32) -> (f64, DVec3) {
    let points = model.points();
    let diameter = match model.thickness() {
        Some(t) => 0.5 * (t.at(i) as f64 + t.at(i + 1) as f64),
        None => default_diameter as f64,
    };
    (
        diameter,
        (points[i + 1].as_dvec3() - points[i].as_dvec3()).normalize(),
    )
}

/// Strand `s` cut into pieces of at most half a voxel, each deposited in the voxel of its
/// midpoint.
fn strand_deposits(model: &HairModel, s: usize, grid: &VoxelGrid) -> Vec<Deposit> {
    let max_piece = 0.5 * grid.voxel_size as f64;
    let offsets = model.strand_offsets();
    let points = model.points();
    let (start, end) = (offsets[s] as usize, offsets[s + 1] as usize);
    let mut out: Vec<Deposit> = Vec::with_capacity(end - start);
    for i in start..end.saturating_sub(1) {
        let (a, b) = (points[i].as_dvec3(), points[i + 1].as_dvec3());
        let length = (b - a).length();
        if !(length > 0.0) {
            continue; // zero-length segment: no fiber to shadow anything
        }
        let pieces = (length / max_piece).ceil().max(1.0) as usize;
        let piece = length / pieces as f64;
        for k in 0..pieces {
            let mid = a + (b - a) * ((k as f64 + 0.5) / pieces as f64);
            let voxel = grid.voxel_clamped(mid.as_vec3()) as u32;
            match out.last_mut() {
                Some(last) if last.voxel == voxel && last.segment == i as u32 => {
                    last.length += piece
                }
                _ => out.push(Deposit {
                    voxel,
                    segment: i as u32,
                    length: piece,
                }),
            }
        }
    }
    out
}
