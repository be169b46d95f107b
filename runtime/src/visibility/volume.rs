//! [`VisibilityVolume`]: the transmittance toward every direction at the vertices of a grid
//! around the hair, as SH coefficients (bands 0–3), built once for a groom that does not move.
//!
//! Every vertex marches `directions` rays (a spherical Fibonacci
//! lattice) through the voxelized hair ([`HairVolume`]) and projects T(ω) = exp(−∫σ(ω) ds)
//! onto the SH basis. The extinction of a voxel along ω is its fibers' projected cross-section
//! per volume: a fiber piece of length ℓ and diameter d seen along ω covers ℓ·d·|sin(t, ω)|, so
//! σ(ω) = σ_t⊥ · E|sin| ≈ σ_t⊥ · √(1 − ωᵀ E[t tᵀ] ω) (exact for parallel fibers, 4% high for
//! fibers in every direction, where E|sin| = π/4 against √(2/3)). Expected transmittance
//! through a random medium of opaque fibers is that exponential: the statistical counterpart
//! of a ray through the real strands, which the path tracer traces.
//!
//! The stored coefficients are windowed against ringing
//! ([`super::spherical_harmonics::RINGING_WINDOW`]). Vertices in the hair's gaps march too: the
//! layered view shades a layer's mean fiber, which can lie between a pixel's front and back
//! hair, and a gap's vertex left at T = 1 lit it as if no hair were around (venice at 160×120:
//! 0.383 against the truth, 0.269 marching every vertex; the build time did not change
//! measurably, 1.6 s). Between vertices each lobe's visibility is blended trilinearly in its
//! logarithm (on the GPU as here, [`VisibilityVolume::lobe_visibility`]).
//!
//! The build goes direction by direction: each voxel's extinction along ω is evaluated once,
//! not at every step of every march through it, and a march leaps over the samples that fall
//! in empty voxels (a voxel's max-norm distance to the nearest fiber bounds how far): the
//! coefficients are bit for bit those of marching every sample of every direction alone
//! (tested). The default groom's volume (64 voxels, 128 directions) took 10.4 s before and
//! 6.3 s after in the test profile on 2 cores (6 Dec).

use glam::Vec3;
use rayon::prelude::*;

use super::spherical_harmonics::{
    SH_COEFFICIENTS, fibonacci_directions, lobe_visibility, sh_basis, windowed,
};
use crate::hair::HairModel;
use crate::head::Head;
use crate::multiple::{HairVolume, VoxelGrid, VoxelSettings};

/// The smallest visibility one vertex brings to the logarithmic blend of
/// [`VisibilityVolume::lobe_visibility`] (e⁻⁹: no lobe sees light through more), so that a
/// vertex deep in the hair, or one whose band-limited visibility rings to 0, does not black
/// out its neighbours'. The shader has the same constant.
pub const MIN_VERTEX_VISIBILITY: f32 = 1.2e-4;

/// How finely the visibility is sampled.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VisibilityVolumeSettings {
    /// Voxels along the longest side of the hair's bounds (the vertex grid has one more).
    pub voxels_longest_side: u32,
    /// Directions marched from each vertex (projected onto 16 SH coefficients).
    pub directions: u32,
}

impl Default for VisibilityVolumeSettings {
    fn default() -> Self {
        Self {
            voxels_longest_side: 64,
            directions: 128,
        }
    }
}

#[derive(Debug, thiserror::Error, PartialEq)]
pub enum VisibilityVolumeError {
    #[error("visibility volume: {setting} = {value} must be in {range}")]
    Setting {
        setting: &'static str,
        value: u32,
        range: &'static str,
    },
    #[error("visibility volume: the hair has no segment of positive length to shadow anything")]
    NoFiber,
}

impl VisibilityVolumeSettings {
    pub fn validate(&self) -> Result<(), VisibilityVolumeError> {
        if !(4..=256).contains(&self.voxels_longest_side) {
            return Err(VisibilityVolumeError::Setting {
                setting: "voxels_longest_side",
                value: self.voxels_longest_side,
                range: "4..=256",
            });
        }
        if !(16..=4096).contains(&self.directions) {
            return Err(VisibilityVolumeError::Setting {
                setting: "directions",
                value: self.directions,
                range: "16..=4096 (16 SH coefficients need at least 16)",
            });
        }
        Ok(())
    }
}

/// SH visibility at the vertices of a regular grid, x fastest, then y, then z.
#[derive(Clone, Debug, PartialEq)]
pub struct VisibilityVolume {
    /// World position of vertex (0, 0, 0).
    pub origin: Vec3,
    /// Distance between neighbouring vertices (the voxel side).
    pub spacing: f32,
    /// Vertices along x, y, z.
    pub dims: [u32; 3],
    pub coefficients: Vec<[f32; SH_COEFFICIENTS]>,
}

/// The SH coefficients of T = 1 in every direction.
pub fn unoccluded_coefficients() -> [f32; SH_COEFFICIENTS] {
    let mut c = [0.0; SH_COEFFICIENTS];
    c[0] = 1.0 / sh_basis(Vec3::Z)[0];
    c
}

/// Optical depth beyond which a march stops (T < 10⁻⁵).
const OPAQUE_DEPTH: f32 = 11.5;

/// The extinction of `voxel` along the unit vector `w`: σ_t⊥ · √(1 − wᵀ E[t tᵀ] w).
fn extinction_along(hair: &HairVolume, voxel: usize, w: Vec3) -> f32 {
    let s = hair.sigma_perp[voxel];
    if s == 0.0 {
        return 0.0;
    }
    let m = &hair.tangent_moment[voxel];
    let along = w.x * w.x * m[0]
        + w.y * w.y * m[1]
        + w.z * w.z * m[2]
        + 2.0 * (w.x * w.y * m[3] + w.x * w.z * m[4] + w.y * w.z * m[5]);
    s * (1.0 - along).max(0.0).sqrt()
}

impl VisibilityVolume {
    /// Marches and projects the visibility of `model` (fibers of the file's thickness, or the
    /// renderer's default where it has none).
    pub fn build(
        model: &HairModel,
        settings: &VisibilityVolumeSettings,
    ) -> Result<Self, VisibilityVolumeError> {
        Self::build_with_head(model, settings, None)
    }

    /// [`Self::build`] with an opaque head: a march whose ray meets the head is dark (the head
    /// is exact here, not voxelized: [`Head::ray_hit`]).
    pub fn build_with_head(
        model: &HairModel,
        settings: &VisibilityVolumeSettings,
        head: Option<&Head>,
    ) -> Result<Self, VisibilityVolumeError> {
        settings.validate()?;
        let voxels = VoxelSettings {
            voxels_longest_side: settings.voxels_longest_side,
            default_diameter: None,
        };
        // ν is not used here: any table range does.
        let hair = HairVolume::build(model, &voxels, 1.0)
            .expect("voxel settings validated above are in range");
        if hair.occupied_voxels() == 0 {
            return Err(VisibilityVolumeError::NoFiber);
        }
        let mut volume = Self::from_hair_volume(&hair, settings.directions as usize, head);
        for c in &mut volume.coefficients {
            *c = windowed(c);
        }
        Ok(volume)
    }

    /// Direction by direction: each voxel's extinction along ω is computed once for the whole
    /// grid (not once per step of every march through it), then every vertex marches through
    /// that one number per voxel. Each vertex still sums its directions in lattice order in
    /// f64, so the coefficients are those of `project` over per-vertex `march`es, bit for
    /// bit (tested below).
    fn from_hair_volume(hair: &HairVolume, directions: usize, head: Option<&Head>) -> Self {
        let grid = hair.grid;
        let dims = grid.dims.map(|d| d + 1);
        let lattice = fibonacci_directions(directions);
        let vertex_count = dims.iter().map(|&d| d as usize).product::<usize>();
        let step = 0.5 * grid.voxel_size;
        let position = |v: usize| {
            let [i, j, k] = unflatten(v, dims);
            grid.origin + Vec3::new(i as f32, j as f32, k as f32) * grid.voxel_size
        };
        // A vertex inside the head is read only in the cells it shares with vertices
        // outside, by the skin and the fibers at the scalp: it carries what the surface
        // sees outward, the hair alone. (Dark in every direction, it darkened the skin
        // under the hair; the skin's cosine removes the directions into the head.)
        let inside: Vec<bool> = (0..vertex_count)
            .into_par_iter()
            .map(|v| head.is_some_and(|h| h.contains(position(v))))
            .collect();
        let mut sums = vec![[0.0f64; SH_COEFFICIENTS]; vertex_count];
        let mut extinction_or_reach = vec![0.0f32; grid.voxel_count()];
        let reach = empty_reach(hair);
        for &w in &lattice {
            let basis = sh_basis(w);
            let medium = MarchMedium::along(hair, &reach, w, &mut extinction_or_reach);
            sums.par_iter_mut().enumerate().for_each(|(v, sum)| {
                let p = position(v);
                let t = match head {
                    Some(h) if !inside[v] && h.ray_hit(p, w, f32::INFINITY).is_some() => 0.0,
                    _ => medium.march(p, w, step),
                };
                for (s, y) in sum.iter_mut().zip(basis) {
                    *s += t as f64 * y as f64;
                }
            });
        }
        let weight = 4.0 * std::f64::consts::PI / lattice.len() as f64;
        Self {
            origin: grid.origin,
            spacing: grid.voxel_size,
            dims,
            coefficients: sums
                .into_iter()
                .map(|s| s.map(|c| (c * weight) as f32))
                .collect(),
        }
    }

    /// A volume whose every vertex holds `c` (tests and diagnostics).
    pub fn uniform(origin: Vec3, spacing: f32, dims: [u32; 3], c: [f32; SH_COEFFICIENTS]) -> Self {
        let n = dims.iter().map(|&d| d as usize).product();
        Self {
            origin,
            spacing,
            dims,
            coefficients: vec![c; n],
        }
    }

    /// The visibility at `p` of the SRBF lobe (ξ, λ), lobe-weighted: each of the 8 vertices
    /// around `p` gives its own, and `p` takes their trilinear mean in the logarithm (clamped
    /// at the border). Transmittance falls exponentially into the hair, which this blend
    /// follows exactly where the density is even; a mean of the values lit the fibers on the
    /// hair's surface, half a voxel from vertices outside it, as if half outside (straight.hair
    /// single scattering under venice, brown: 1.17 of the truth's light, 1.08 blended so).
    pub fn lobe_visibility(&self, p: Vec3, xi: Vec3, lambda: f32) -> f32 {
        let last = Vec3::from_array(self.dims.map(|d| d as f32 - 1.0));
        let f = ((p - self.origin) / self.spacing).clamp(Vec3::ZERO, last);
        let lower = f.floor().min((last - 1.0).max(Vec3::ZERO));
        let w = (f - lower).min(Vec3::ONE);
        let base = lower.to_array().map(|x| x as u32);
        let mut log_v = 0.0f32;
        for corner in 0..8u32 {
            let bits = [corner & 1, (corner >> 1) & 1, (corner >> 2) & 1];
            let mut weight = 1.0;
            let mut idx = [0u32; 3];
            for a in 0..3 {
                idx[a] = (base[a] + bits[a]).min(self.dims[a] - 1);
                weight *= if bits[a] == 1 { w[a] } else { 1.0 - w[a] };
            }
            if weight == 0.0 {
                continue;
            }
            let v = lobe_visibility(&self.coefficients[flatten(idx, self.dims)], xi, lambda);
            log_v += weight * v.max(MIN_VERTEX_VISIBILITY).ln();
        }
        log_v.exp()
    }

    /// The coefficients as bytes, vertex after vertex (the GPU buffer).
    pub fn bytes(&self) -> &[u8] {
        bytemuck::cast_slice(&self.coefficients)
    }
}

fn unflatten(v: usize, dims: [u32; 3]) -> [u32; 3] {
    let (nx, ny) = (dims[0] as usize, dims[1] as usize);
    [
        (v % nx) as u32,
        ((v / nx) % ny) as u32,
        (v / (nx * ny)) as u32,
    ]
}

fn flatten([i, j, k]: [u32; 3], dims: [u32; 3]) -> usize {
    (k as usize * dims[1] as usize + j as usize) * dims[0] as usize + i as usize
}

/// exp(−∫σ(w) ds) from `p` along `w` to the grid's border: the midpoint rule at
/// t₀ + (n + ½)·`step`, every sample looked up (the definition [`MarchMedium::march`] must equal
/// bit for bit: the samples it skips add exactly zero).
#[cfg(test)]
fn march(hair: &HairVolume, p: Vec3, w: Vec3, step: f32) -> f32 {
    let Some(ray) = VoxelRay::new(&hair.grid, p, w) else {
        return 1.0;
    };
    let mut depth = 0.0;
    for n in 0.. {
        let t = ray.t0 + (n as f32 + 0.5) * step;
        if t >= ray.t1 {
            break;
        }
        if let Some(voxel) = ray.voxel_at(t) {
            depth += extinction_along(hair, voxel, w) * step;
            if depth > OPAQUE_DEPTH {
                return 0.0;
            }
        }
    }
    (-depth).exp()
}

/// A ray p + t·w through the grid, in voxel units (q₀ + t·dq), over its interval [t₀, t₁]
/// inside the grid.
struct VoxelRay {
    q0: Vec3,
    dq: Vec3,
    t0: f32,
    t1: f32,
    dims: [u32; 3],
}

impl VoxelRay {
    fn new(grid: &VoxelGrid, p: Vec3, w: Vec3) -> Option<Self> {
        let (t0, t1) = grid.ray_interval(p, w)?;
        let inverse = 1.0 / grid.voxel_size;
        Some(Self {
            q0: (p - grid.origin) * inverse,
            dq: w * inverse,
            t0,
            t1,
            dims: grid.dims,
        })
    }

    /// The voxel (linear index) holding the ray's point at `t`, if inside the grid.
    fn voxel_at(&self, t: f32) -> Option<usize> {
        let q = self.q0 + t * self.dq;
        let [nx, ny, nz] = self.dims;
        let inside =
            q.cmpge(Vec3::ZERO).all() && q.cmplt(Vec3::new(nx as f32, ny as f32, nz as f32)).all();
        inside.then(|| (q.z as usize * ny as usize + q.y as usize) * nx as usize + q.x as usize)
    }
}

/// What a march along one direction reads, one number per voxel: its extinction along that
/// direction where it holds fibers, else minus its [`empty_reach`], which lets the march leap
/// over empty space (every sample it leaps over would have added exactly zero).
struct MarchMedium<'a> {
    grid: &'a VoxelGrid,
    extinction_or_reach: &'a [f32],
}

impl<'a> MarchMedium<'a> {
    /// `extinction_or_reach` filled for `w` (sized to the grid by the caller).
    fn along(
        hair: &'a HairVolume,
        reach: &[u8],
        w: Vec3,
        extinction_or_reach: &'a mut [f32],
    ) -> Self {
        extinction_or_reach
            .par_iter_mut()
            .enumerate()
            .for_each(|(voxel, e)| {
                *e = match reach[voxel] {
                    0 => extinction_along(hair, voxel, w),
                    r => -f32::from(r),
                }
            });
        Self {
            grid: &hair.grid,
            extinction_or_reach,
        }
    }

    /// exp(−∫σ(w) ds) from `p` along `w` to the grid's border: the midpoint rule at
    /// t₀ + (n + ½)·`step`, samples in empty space skipped.
    fn march(&self, p: Vec3, w: Vec3, step: f32) -> f32 {
        let Some(ray) = VoxelRay::new(self.grid, p, w) else {
            return 1.0;
        };
        // Voxels (max-norm) the sample moves per step, a hair over to stay on the safe side.
        let moved_per_step = step * ray.dq.abs().max_element() * 1.0001;
        let mut depth = 0.0;
        let mut n = 0u32;
        loop {
            let t = ray.t0 + (n as f32 + 0.5) * step;
            if t >= ray.t1 {
                break;
            }
            n += 1;
            let Some(voxel) = ray.voxel_at(t) else {
                continue;
            };
            let e = self.extinction_or_reach[voxel];
            if e >= 0.0 {
                depth += e * step;
                if depth > OPAQUE_DEPTH {
                    return 0.0;
                }
            } else if e < -1.0 {
                // Samples less than reach − 1 voxels away (max-norm) lie in empty voxels; the
                // floor of that distance over the margin-widened move is how many.
                n += ((-e - 1.0) / moved_per_step) as u32;
            }
        }
        (-depth).exp()
    }
}

/// The most an empty-space leap is allowed to cover, in voxels.
const MAX_EMPTY_REACH: u8 = 16;

/// Each voxel's distance in voxels (max-norm, capped at [`MAX_EMPTY_REACH`]) to the nearest
/// voxel holding fibers: 0 in a voxel with fibers. Any point less than `reach − 1` voxels from
/// a point of this voxel lies in an empty voxel. Separable: the max-norm distance is a min–max
/// along x, then y, then z.
fn empty_reach(hair: &HairVolume) -> Vec<u8> {
    let grid = &hair.grid;
    let dims = grid.dims;
    let mut reach: Vec<u8> = hair
        .sigma_perp
        .iter()
        .map(|&s| if s > 0.0 { 0 } else { MAX_EMPTY_REACH })
        .collect();
    for axis in 0..3 {
        let before = reach.clone();
        reach.par_iter_mut().enumerate().for_each(|(v, r)| {
            let [i, j, k] = unflatten(v, dims);
            let at = [i, j, k][axis] as i64;
            let span = i64::from(MAX_EMPTY_REACH);
            let lo = (at - span).max(0);
            let hi = (at + span).min(dims[axis] as i64 - 1);
            for other in lo..=hi {
                let mut idx = [i, j, k];
                idx[axis] = other as u32;
                let via = before[grid.linear_index(idx)].max((other - at).unsigned_abs() as u8);
                *r = (*r).min(via);
            }
        });
    }
    reach
}

#[cfg(test)]
mod tests {
    use super::super::spherical_harmonics::project;
    use super::*;
    use crate::hair::HairModel;

    /// A slab of straight fibers along x: `rows` × `rows` strands on a square lattice of pitch
    /// `pitch` in y and z, each `length` long, of diameter `d`.
    fn slab(rows: usize, pitch: f32, length: f32, d: f32) -> HairModel {
        let mut points = Vec::new();
        let mut offsets = vec![0u32];
        for j in 0..rows {
            for k in 0..rows {
                let (y, z) = (j as f32 * pitch, k as f32 * pitch);
                for s in 0..=8 {
                    points.push(Vec3::new(length * s as f32 / 8.0, y, z));
                }
                offsets.push(points.len() as u32);
            }
        }
        let strands = offsets.len() - 1;
        HairModel::new(
            points,
            offsets,
            Some(crate::hair::Attribute::Uniform(d)),
            None,
            None,
        )
        .inspect(|m| assert_eq!(m.strand_count(), strands))
        .expect("a valid slab")
    }

    /// A grid of `n`³ voxels of side `size` at the origin, every voxel holding fibers along x
    /// with σ_t⊥ = `sigma`.
    fn uniform_fibers_along_x(n: u32, size: f32, sigma: f32) -> HairVolume {
        let grid = crate::multiple::VoxelGrid {
            origin: Vec3::ZERO,
            voxel_size: size,
            dims: [n; 3],
        };
        let count = grid.voxel_count();
        HairVolume {
            grid,
            sigma_perp: vec![sigma; count],
            mean_direction: vec![Vec3::X; count],
            deviation: vec![0.0; count],
            fiber_length: vec![1.0; count],
            tangent_moment: vec![[1.0, 0.0, 0.0, 0.0, 0.0, 0.0]; count],
        }
    }

    #[test]
    fn a_march_follows_the_closed_form_across_and_aslant_and_passes_along_the_fibers() {
        let (n, size, sigma) = (20, 0.1, 1.5);
        let hair = uniform_fibers_along_x(n, size, sigma);
        let step = 0.5 * size;
        let p = Vec3::splat(1.0); // the cube's centre: 1.0 to every face
        let across = march(&hair, p, Vec3::Z, step);
        assert!(
            (across - (-sigma * 1.0f32).exp()).abs() < 1e-5,
            "across {across}"
        );
        let along = march(&hair, p, Vec3::X, step);
        assert_eq!(along, 1.0);
        // 30° off the fibers in the x–z plane: the path to the x face is 1/cos 30°, and σ·sin 30°.
        let a = 30f32.to_radians();
        let w = Vec3::new(a.cos(), 0.0, a.sin());
        let aslant = march(&hair, p, w, step);
        let expected = (-sigma * a.sin() / a.cos()).exp();
        // The last midpoint step may overhang the border by up to half a step.
        assert!(
            (aslant.ln() - expected.ln()).abs() < sigma * a.sin() * step,
            "aslant {aslant} vs {expected}"
        );
        // Fibers in every direction (E[t tᵀ] = I/3): √(2/3) of σ_t⊥.
        let mut iso = hair.clone();
        iso.tangent_moment =
            vec![[1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0, 0.0, 0.0, 0.0]; hair.grid.voxel_count()];
        let t = march(&iso, p, Vec3::Y, step);
        assert!((t - (-sigma * (2.0f32 / 3.0).sqrt()).exp()).abs() < 1e-5);
    }

    #[test]
    fn the_projected_visibility_of_a_uniform_block_matches_its_directional_march() {
        // Every vertex inside the block: the SH of T(ω) evaluated through a wide lobe equals the
        // lobe-weighted mean of the marched T (brute force over 20 000 directions).
        let hair = uniform_fibers_along_x(16, 0.125, 1.2);
        let volume = VisibilityVolume::from_hair_volume(&hair, 512, None);
        let p = Vec3::splat(1.0);
        let dirs = fibonacci_directions(20_000);
        for (xi, lambda) in [
            (Vec3::Z, 2.0f32),
            (Vec3::X, 2.0),
            (Vec3::new(1.0, 1.0, 0.3), 1.0),
        ] {
            let xi = xi.normalize();
            let (mut num, mut den) = (0.0f64, 0.0f64);
            for &d in &dirs {
                let g = ((lambda * (d.dot(xi) - 1.0)) as f64).exp();
                num += g * march(&hair, p, d, 0.0625) as f64;
                den += g;
            }
            let brute = (num / den) as f32;
            let sh = volume.lobe_visibility(p, xi, lambda);
            // Bands 0–3 of a smooth T through a wide lobe.
            assert!(
                (sh - brute).abs() < 0.03,
                "ξ {xi} λ {lambda}: SH {sh} vs march {brute}"
            );
        }
    }

    /// Two bundles of fibers with empty space between them, where a march leaps.
    fn two_bundles() -> HairModel {
        let (near, far) = (slab(4, 0.06, 1.5, 0.01), slab(4, 0.06, 1.5, 0.01));
        let offset = Vec3::new(0.0, 1.4, 1.2);
        let points: Vec<Vec3> = near
            .points()
            .iter()
            .copied()
            .chain(far.points().iter().map(|&p| p + offset))
            .collect();
        let per_strand = 9;
        let offsets = (0..=points.len() / per_strand)
            .map(|s| (s * per_strand) as u32)
            .collect();
        let d = Some(crate::hair::Attribute::Uniform(0.01));
        HairModel::new(points, offsets, d, None, None).unwrap()
    }

    /// The direction-major build with its leaps over empty space is the per-vertex definition,
    /// reordered: every vertex's directions marched one by one, sampling every step (`march`,
    /// the head's hit test as documented), and projected (`project`) give the same coefficients
    /// to the bit, with a head across part of the grid and empty space between two bundles.
    #[test]
    fn the_build_equals_each_vertex_marched_and_projected_alone() {
        let model = two_bundles();
        let head = crate::head::Head::ellipsoid(Vec3::new(0.7, 0.9, 0.4), Vec3::splat(0.3));
        let voxels = VoxelSettings {
            voxels_longest_side: 12,
            default_diameter: None,
        };
        let hair = HairVolume::build(&model, &voxels, 1.0).unwrap();
        let leaps = empty_reach(&hair).iter().filter(|&&r| r > 2).count();
        assert!(
            leaps > 100,
            "{leaps} voxels to leap from: the test checks no leap"
        );
        let directions = 48;
        let built = VisibilityVolume::from_hair_volume(&hair, directions, Some(&head));
        let lattice = fibonacci_directions(directions);
        let step = 0.5 * hair.grid.voxel_size;
        let mut hidden = 0;
        for (v, c) in built.coefficients.iter().enumerate() {
            let [i, j, k] = unflatten(v, built.dims);
            let p = built.origin + Vec3::new(i as f32, j as f32, k as f32) * built.spacing;
            let inside = head.contains(p);
            let t = lattice.iter().map(|&w| {
                if !inside && head.ray_hit(p, w, f32::INFINITY).is_some() {
                    hidden += 1;
                    0.0
                } else {
                    march(&hair, p, w, step)
                }
            });
            assert_eq!(*c, project(&lattice, t), "vertex {v} at {p}");
        }
        assert!(
            hidden > 0,
            "the head hid no direction: the test checks nothing of it"
        );
    }

    #[test]
    fn the_volume_shadows_the_slab_from_across_and_not_from_along_its_fibers() {
        let model = slab(30, 0.05, 2.0, 0.006);
        let v = VisibilityVolume::build(
            &model,
            &VisibilityVolumeSettings {
                voxels_longest_side: 32,
                directions: 256,
            },
        )
        .unwrap();
        let inside = Vec3::new(1.0, 0.725, 0.725);
        // Bands 0–3 resolve the two caps of free sight along the fibers (T > ½ within 16° of
        // ±x here) only smeared: compare through a lobe as wide as they are.
        let across = v.lobe_visibility(inside, Vec3::Z, 10.0);
        let along = v.lobe_visibility(inside, Vec3::X, 10.0);
        let outside = v.lobe_visibility(Vec3::new(1.0, 0.725, 20.0), Vec3::Z, 50.0);
        assert!(across < 0.3, "across {across}");
        assert!(along > 1.5 * across, "along {along} vs across {across}");
        assert!(
            outside > 0.9,
            "beyond the grid the top face's vertex holds: {outside}"
        );
    }

    /// The head in the volume (issue 40): a vertex with the sphere between it and a lobe sees
    /// (almost) nothing of the lobe, the same vertex toward the open side, or without the head,
    /// sees it. A 16-coefficient SH smooths the head's 30° disc, so the bounds are loose; they
    /// fail when the march ignores the head (then both sides read ~1).
    #[test]
    fn the_head_darkens_the_lobes_it_hides() {
        let model = slab(2, 0.05, 2.0, 0.001);
        let head = crate::head::Head::ellipsoid(Vec3::new(1.0, 0.0, 0.6), Vec3::splat(0.4));
        let settings = VisibilityVolumeSettings::default();
        let with = VisibilityVolume::build_with_head(&model, &settings, Some(&head)).unwrap();
        let without = VisibilityVolume::build(&model, &settings).unwrap();
        let p = Vec3::new(1.0, 0.0, 0.0);
        assert!(head.ray_hit(p, Vec3::Z, f32::INFINITY).is_some());
        let toward_head = with.lobe_visibility(p, Vec3::Z, 50.0);
        let away = with.lobe_visibility(p, -Vec3::Z, 50.0);
        let free = without.lobe_visibility(p, Vec3::Z, 50.0);
        println!("toward the head {toward_head}, away {away}, no head {free}");
        assert!(toward_head < 0.5, "{toward_head}");
        assert!(away > 0.8 && free > 0.8, "{away} {free}");
    }

    /// The skin under the hair (issue 40): a point on the head's surface, below a layer of
    /// fibers rooted on it, sees the sky through that layer as a point beside it without the head
    /// does. Fails when the vertices inside the head are dark in every direction (then the skin
    /// under the hair read about half the hair's transmittance).
    #[test]
    fn the_skin_under_the_hair_sees_through_the_hair_alone() {
        let model = slab(8, 0.03, 2.0, 0.01);
        let settings = VisibilityVolumeSettings::default();
        let without = VisibilityVolume::build(&model, &settings).unwrap();
        // The layer on the skin: roots on the scalp. (With a gap of a voxel and a half between
        // them, the point reads 0.024 against 0.030: the volume is coarse at the scalp, and
        // frames with a head use light maps by default, `LobeVisibilityArg::Auto`.)
        let head = crate::head::Head::ellipsoid(Vec3::new(1.0, 0.105, -0.6), Vec3::splat(0.6));
        let with = VisibilityVolume::build_with_head(&model, &settings, Some(&head)).unwrap();
        let skin = Vec3::new(1.0, 0.105, 0.0);
        let through_hair = with.lobe_visibility(skin, Vec3::Z, 20.0);
        let no_head = without.lobe_visibility(skin, Vec3::Z, 20.0);
        println!("skin under the hair {through_hair}, without the head {no_head}");
        assert!(no_head < 0.9, "the layer shadows: {no_head}");
        assert!(
            (through_hair - no_head).abs() < 0.15 * no_head,
            "{through_hair} vs {no_head}"
        );
    }

    #[test]
    fn bad_settings_are_refused_by_name() {
        let s = VisibilityVolumeSettings {
            directions: 8,
            ..Default::default()
        };
        assert!(matches!(
            s.validate(),
            Err(VisibilityVolumeError::Setting {
                setting: "directions",
                ..
            })
        ));
        let s = VisibilityVolumeSettings {
            voxels_longest_side: 100_000,
            ..Default::default()
        };
        assert!(matches!(
            s.validate(),
            Err(VisibilityVolumeError::Setting {
                setting: "voxels_longest_side",
                ..
            })
        ));
    }

    /// A slab of parallel fibers at random places (a Poisson medium of opaque cylinders, as the
    /// path tracer's shadow rays see straight hair), `per_cm2` fibers per unit of its cross-section,
    /// `depth` thick along z, 6 × 6 wide, its front face at z = depth/2.
    fn random_slab(per_cm2: f64, diameter: f32, depth: f32) -> HairModel {
        let (width, height) = (6.0f32, 6.0f32);
        let count = (per_cm2 * (width * depth) as f64).round() as usize;
        let mut rng = strandlight_tables::split_mix::SplitMix64::new(7);
        let (mut points, mut offsets) = (Vec::new(), vec![0u32]);
        for _ in 0..count {
            let x = (rng.unit_f32() - 0.5) * width;
            let z = (rng.unit_f32() - 0.5) * depth;
            for k in 0..6 {
                points.push(Vec3::new(x, height * (0.5 - k as f32 / 5.0), z));
            }
            offsets.push(points.len() as u32);
        }
        let d = Some(crate::hair::Attribute::Uniform(diameter));
        HairModel::new(points, offsets, d, None, None).unwrap()
    }

    /// The lobe-weighted transmittance at `p` inside the slab of [`random_slab`] (extinction
    /// `sigma` per unit length across the fibers): ∫ G T / ∫ G with
    /// T(ω) = exp(−σ |sin(y, ω)| L(ω)), L the path to the slab's faces, by brute force.
    fn slab_closed_form(p: Vec3, xi: Vec3, lambda: f32, sigma: f32, depth: f32) -> f32 {
        let half = Vec3::new(3.0, 3.0, 0.5 * depth);
        let (mut num, mut den) = (0.0f64, 0.0f64);
        for w in fibonacci_directions(20_000) {
            let g = ((lambda * (w.dot(xi) - 1.0)) as f64).exp();
            let exit = (0..3)
                .filter(|&a| w[a].abs() > 1e-6)
                .map(|a| (half[a] * w[a].signum() - p[a]) / w[a])
                .fold(f32::INFINITY, f32::min);
            let t = (-sigma * (1.0 - w.y * w.y).max(0.0).sqrt() * exit).exp();
            num += g * t as f64;
            den += g;
        }
        (num / den) as f32
    }

    /// Under the hair's surface the volume sees through a random slab of opaque fibers as the
    /// closed form does (issue 65: the truth's shadow ray stops at the first fiber, and
    /// T = e^{−σ_t⊥ L} is the chance that no fiber stands in the way). Checked through lobes
    /// along the surface's normal, 0.05 and 0.1 deep (0.4 and 0.8 mean free paths), where the
    /// volume reads 0.646–0.694 and 0.417–0.467 against 0.647–0.669 and 0.421–0.448 (λ 8–128);
    /// fibers 20% thicker (or thinner) in the volume than in the closed form read 0.597 (0.691)
    /// against 0.647 and fail. Where bands 0–3 cannot follow the transmittance the volume stays
    /// off; the test prints those figures (`-- --nocapture`; docs/BENCHMARKS.md, "Multiple
    /// scattering by melanin", its "Blonde on every map"): on the surface itself, 60° from the
    /// normal and along the fibers.
    #[test]
    fn under_the_surface_a_random_slab_is_seen_through_as_its_closed_form() {
        let (per_cm2, diameter, depth) = (1000.0, 0.008f32, 1.0f32);
        let sigma = (per_cm2 * diameter as f64) as f32;
        let model = random_slab(per_cm2, diameter, depth);
        let volume = VisibilityVolume::build(&model, &VisibilityVolumeSettings::default()).unwrap();
        for lambda in [8.0f32, 32.0, 128.0] {
            for below in [0.05f32, 0.1] {
                let p = Vec3::new(0.1, 0.2, 0.5 * depth - below);
                let got = volume.lobe_visibility(p, Vec3::Z, lambda);
                let expected = slab_closed_form(p, Vec3::Z, lambda, sigma, depth);
                assert!(
                    (got - expected).abs() < 0.03,
                    "λ {lambda}, {below} under the surface: the volume sees {got:.3}, the closed form {expected:.3}"
                );
            }
        }
        let sixty = Vec3::new(60f32.to_radians().sin(), 0.0, 0.5);
        for (name, xi) in [
            ("normal", Vec3::Z),
            ("60° from it", sixty),
            ("along", Vec3::Y),
        ] {
            for below in [0.0f32, 0.05, 0.1, 0.2] {
                let p = Vec3::new(0.1, 0.2, 0.5 * depth - below);
                let got = volume.lobe_visibility(p, xi, 32.0);
                let expected = slab_closed_form(p, xi, 32.0, sigma, depth);
                println!(
                    "λ 32 {name:12} {below:4} under the surface: volume {got:.3}, closed form {expected:.3}"
                );
            }
        }
    }

    #[test]
    fn the_blend_between_vertices_follows_an_exponential_falloff() {
        // Each vertex sees T = e^{−a·x} toward every direction (band 0 only); between vertices
        // the blend gives e^{−a·x} at the point itself, where a mean of the vertices' values
        // would not (0.5·(1 + e⁻²) = 0.57 halfway across a voxel of optical depth 2, against
        // e⁻¹ = 0.37). Every vertex here is above MIN_VERTEX_VISIBILITY.
        let dims = [3, 4, 2];
        let a = 2.0f32;
        let mut v = VisibilityVolume::uniform(Vec3::new(1.0, 2.0, 3.0), 0.5, dims, [0.0; 16]);
        let y00 = 0.5 / std::f32::consts::PI.sqrt();
        for (n, c) in v.coefficients.iter_mut().enumerate() {
            let [i, j, k] = unflatten(n, dims);
            let depth = i as f32 + 0.5 * j as f32 + 0.25 * k as f32;
            c[0] = (-a * depth).exp() / y00;
        }
        for p in [Vec3::new(1.3, 2.9, 3.2), Vec3::new(1.75, 3.1, 3.4)] {
            let f = (p - v.origin) / v.spacing;
            let expected = (-a * (f.x + 0.5 * f.y + 0.25 * f.z)).exp();
            for (xi, lambda) in [(Vec3::Z, 10.0), (Vec3::new(1.0, -2.0, 0.5), 100.0)] {
                let got = v.lobe_visibility(p, xi, lambda);
                assert!(
                    (got / expected - 1.0).abs() < 1e-4,
                    "at {p}: {got} against e^(−a·x) = {expected}"
                );
            }
        }
    }
}
