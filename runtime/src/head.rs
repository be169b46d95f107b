//! The head the hair grows from (issue 40): an opaque, diffuse body that hides the fibers behind
//! it from the viewer and from every light. It is either an axis-aligned ellipsoid (the scene
//! layer fits one to the strand roots when no mesh is given) or a triangle mesh (an OBJ).
//!
//! The GPU passes draw it as triangles ([`Head::triangles`]: the ellipsoid is tessellated, with
//! its analytic normals); the CPU passes that march rays through the groom (the visibility
//! volume, the forward-scattering grid) and the tests ask [`Head::ray_hit`], exact for the
//! ellipsoid and brute force over the triangles (behind a bounding-box test) for a mesh.

use glam::{Vec3, Vec3A};
use obvhs::BvhBuildParams;
use obvhs::cwbvh::CwBvh;
use obvhs::cwbvh::builder::build_cwbvh_from_tris;
use obvhs::ray::{Ray, RayHit};
use obvhs::triangle::Triangle;
use std::sync::{Arc, OnceLock};
use std::time::Duration;

use crate::hair::Aabb;

/// Linear RGB albedo of the default skin (a light skin tone's diffuse reflectance).
pub const DEFAULT_SKIN_ALBEDO: [f32; 3] = [0.56, 0.38, 0.30];

/// Triangles with per-vertex normals (unit, outward where the mesh is closed and consistent).
/// Build a changed mesh anew ([`TriangleMesh::new`]) rather than editing one that has answered a
/// ray query: its BVH is built once, from the triangles it had then.
#[derive(Clone, Debug)]
pub struct TriangleMesh {
    pub positions: Vec<Vec3>,
    pub normals: Vec<Vec3>,
    /// Three per triangle.
    pub indices: Vec<u32>,
    /// The triangles' BVH, built on the first ray query: the visibility volume asks hundreds of
    /// millions of them (brute force over a 9,216-triangle head took 6 minutes there).
    bvh: OnceLock<Arc<MeshBvh>>,
}

impl PartialEq for TriangleMesh {
    fn eq(&self, other: &Self) -> bool {
        (&self.positions, &self.normals, &self.indices)
            == (&other.positions, &other.normals, &other.indices)
    }
}

/// obvhs's compressed wide BVH over a mesh's triangles.
struct MeshBvh(CwBvh);

impl std::fmt::Debug for MeshBvh {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "MeshBvh({} nodes)", self.0.nodes.len())
    }
}

impl TriangleMesh {
    pub fn new(positions: Vec<Vec3>, normals: Vec<Vec3>, indices: Vec<u32>) -> Self {
        Self {
            positions,
            normals,
            indices,
            bvh: OnceLock::new(),
        }
    }

    /// The mesh with smooth normals computed from its faces (area-weighted) where it has none.
    pub fn with_computed_normals(positions: Vec<Vec3>, indices: Vec<u32>) -> Self {
        let mut normals = vec![Vec3::ZERO; positions.len()];
        for t in indices.chunks_exact(3) {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| positions[i as usize]);
            let n = (b - a).cross(c - a);
            for &i in t {
                normals[i as usize] += n;
            }
        }
        let normals = normals
            .into_iter()
            .map(|n| n.normalize_or(Vec3::Y))
            .collect();
        Self::new(positions, normals, indices)
    }

    /// One mesh holding every triangle of `meshes` (a character's skin, eyes and lashes read
    /// from separate files), in the order given.
    pub fn merged(meshes: impl IntoIterator<Item = TriangleMesh>) -> Self {
        let (mut positions, mut normals, mut indices) = (Vec::new(), Vec::new(), Vec::new());
        for mesh in meshes {
            let base = positions.len() as u32;
            indices.extend(mesh.indices.iter().map(|i| base + i));
            positions.extend(mesh.positions);
            normals.extend(mesh.normals);
        }
        Self::new(positions, normals, indices)
    }

    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }

    pub fn bounds(&self) -> Aabb {
        Aabb::from_points(&self.positions)
    }

    /// The nearest hit in (1e-4·|d|, t_max) of the ray `origin + t·dir` (Möller–Trumbore, both
    /// faces, on the triangles the BVH's boxes let through).
    fn ray_hit(&self, origin: Vec3, dir: Vec3, t_max: f32) -> Option<f32> {
        let bvh = &self.bvh.get_or_init(|| Arc::new(self.build_bvh())).0;
        let ray = Ray::new(origin.into(), dir.into(), 0.0, t_max);
        let mut hit = RayHit::none();
        bvh.ray_traverse(ray, &mut hit, |_, id| {
            let triangle = bvh.primitive_indices[id] as usize;
            self.triangle_hit(triangle, origin, dir, t_max)
                .unwrap_or(f32::INFINITY)
        })
        .then_some(hit.t)
    }

    fn build_bvh(&self) -> MeshBvh {
        let triangles: Vec<Triangle> = (0..self.triangle_count())
            .map(|t| {
                let [v0, v1, v2] = self.corners(t).map(Vec3A::from);
                Triangle { v0, v1, v2 }
            })
            .collect();
        MeshBvh(build_cwbvh_from_tris(
            &triangles,
            BvhBuildParams::medium_build(),
            &mut Duration::default(),
        ))
    }

    fn corners(&self, triangle: usize) -> [Vec3; 3] {
        let t = &self.indices[3 * triangle..3 * triangle + 3];
        [t[0], t[1], t[2]].map(|i| self.positions[i as usize])
    }

    /// Möller–Trumbore: the hit of triangle `triangle` in (1e-4, t_max), either face.
    fn triangle_hit(&self, triangle: usize, origin: Vec3, dir: Vec3, t_max: f32) -> Option<f32> {
        let [a, b, c] = self.corners(triangle);
        let (e1, e2) = (b - a, c - a);
        let p = dir.cross(e2);
        let det = e1.dot(p);
        if det.abs() < 1e-12 {
            return None;
        }
        let inv = 1.0 / det;
        let s = origin - a;
        let u = s.dot(p) * inv;
        if !(0.0..=1.0).contains(&u) {
            return None;
        }
        let q = s.cross(e1);
        let v = dir.dot(q) * inv;
        if v < 0.0 || u + v > 1.0 {
            return None;
        }
        let hit = e2.dot(q) * inv;
        (hit > 1e-4 && hit < t_max).then_some(hit)
    }

    /// [`Self::ray_hit`] over every triangle, for the tests of the BVH.
    #[cfg(test)]
    fn ray_hit_brute_force(&self, origin: Vec3, dir: Vec3, t_max: f32) -> Option<f32> {
        (0..self.triangle_count())
            .filter_map(|t| self.triangle_hit(t, origin, dir, t_max))
            .min_by(f32::total_cmp)
    }
}

/// The head's surface.
#[derive(Clone, Debug, PartialEq)]
pub enum HeadSurface {
    /// `((p − center) / radii)² = 1`.
    Ellipsoid {
        center: Vec3,
        radii: Vec3,
    },
    Mesh(TriangleMesh),
}

/// An opaque diffuse head.
#[derive(Clone, Debug, PartialEq)]
pub struct Head {
    pub surface: HeadSurface,
    /// Linear RGB diffuse albedo (Lambertian skin).
    pub albedo: [f32; 3],
}

/// Rings and segments of the ellipsoid's tessellation: 128 × 64 quads, whose flat facets stand
/// off the true surface by at most r·(1 − cos(π/128)) ≈ 3·10⁻⁴ r.
const ELLIPSOID_SEGMENTS: u32 = 128;
const ELLIPSOID_RINGS: u32 = 64;

impl Head {
    pub fn ellipsoid(center: Vec3, radii: Vec3) -> Self {
        Self {
            surface: HeadSurface::Ellipsoid { center, radii },
            albedo: DEFAULT_SKIN_ALBEDO,
        }
    }

    pub fn bounds(&self) -> Aabb {
        match &self.surface {
            HeadSurface::Ellipsoid { center, radii } => Aabb {
                min: *center - *radii,
                max: *center + *radii,
            },
            HeadSurface::Mesh(mesh) => mesh.bounds(),
        }
    }

    /// The triangles the GPU draws.
    pub fn triangles(&self) -> std::borrow::Cow<'_, TriangleMesh> {
        match &self.surface {
            HeadSurface::Ellipsoid { center, radii } => {
                std::borrow::Cow::Owned(tessellate_ellipsoid(*center, *radii))
            }
            HeadSurface::Mesh(mesh) => std::borrow::Cow::Borrowed(mesh),
        }
    }

    /// The distance along the unit vector `dir` from `origin` to the nearest surface hit in
    /// (0, t_max), if any. A ray starting inside the ellipsoid hits its far side.
    pub fn ray_hit(&self, origin: Vec3, dir: Vec3, t_max: f32) -> Option<f32> {
        if !ray_meets_box(self.bounds(), origin, dir, t_max) {
            return None;
        }
        match &self.surface {
            HeadSurface::Ellipsoid { center, radii } => {
                ray_ellipsoid(*center, *radii, origin, dir, t_max)
            }
            HeadSurface::Mesh(mesh) => mesh.ray_hit(origin, dir, t_max),
        }
    }

    /// Whether `p` is inside the ellipsoid, or (mesh) inside by the parity of a ray's crossings.
    pub fn contains(&self, p: Vec3) -> bool {
        match &self.surface {
            HeadSurface::Ellipsoid { center, radii } => {
                ((p - *center) / *radii).length_squared() < 1.0
            }
            HeadSurface::Mesh(mesh) => {
                let b = mesh.bounds();
                if p.cmplt(b.min).any() || p.cmpgt(b.max).any() {
                    return false;
                }
                // An oblique direction, unlikely to graze an edge of an axis-aligned mesh.
                let dir = Vec3::new(0.5773, 0.5774, 0.5773).normalize();
                let mut count = 0;
                let mut from = p;
                let mut left = b.diagonal() * 2.0;
                while let Some(t) = mesh.ray_hit(from, dir, left) {
                    count += 1;
                    from += dir * (t + 1e-4);
                    left -= t + 1e-4;
                }
                count % 2 == 1
            }
        }
    }

    /// A fingerprint of the surface and albedo, for caches keyed by the scene.
    pub fn fingerprint(&self) -> u64 {
        use std::hash::{Hash, Hasher};
        let mut h = std::collections::hash_map::DefaultHasher::new();
        let mut floats = |v: &[f32]| v.iter().for_each(|f| f.to_bits().hash(&mut h));
        floats(&self.albedo);
        match &self.surface {
            HeadSurface::Ellipsoid { center, radii } => {
                floats(&center.to_array());
                floats(&radii.to_array());
            }
            HeadSurface::Mesh(mesh) => {
                mesh.positions.iter().for_each(|p| floats(&p.to_array()));
                let idx: Vec<f32> = mesh.indices.iter().map(|&i| f32::from_bits(i)).collect();
                floats(&idx);
            }
        }
        h.finish()
    }
}

/// Slab test: whether the ray reaches `b` within (0, t_max).
fn ray_meets_box(b: Aabb, origin: Vec3, dir: Vec3, t_max: f32) -> bool {
    let inv = dir.recip();
    let t0 = (b.min - origin) * inv;
    let t1 = (b.max - origin) * inv;
    let near = t0.min(t1).max_element();
    let far = t0.max(t1).min_element();
    // NaN (a zero direction component on the slab's plane) compares false: keep testing.
    !(near > far || far < 0.0 || near > t_max)
}

/// The nearest positive root of |(o + t·d − c) / r|² = 1 below `t_max` (f64: the roots of a
/// near-grazing ray lose their digits in f32).
fn ray_ellipsoid(center: Vec3, radii: Vec3, origin: Vec3, dir: Vec3, t_max: f32) -> Option<f32> {
    let o = ((origin - center) / radii).as_dvec3();
    let d = (dir / radii).as_dvec3();
    let a = d.length_squared();
    let b = o.dot(d);
    let c = o.length_squared() - 1.0;
    let disc = b * b - a * c;
    if disc < 0.0 || a == 0.0 {
        return None;
    }
    let s = disc.sqrt();
    let (t0, t1) = ((-b - s) / a, (-b + s) / a);
    let t = if t0 > 1e-6 { t0 } else { t1 };
    (t > 1e-6 && t < t_max as f64).then_some(t as f32)
}

/// Irradiance on a Lambertian surface of normal n from an SRBF of unit amplitude,
/// ∫ exp(λ(ω·ξ − 1)) max(n·ω, 0) dω, for `cos_n_xi` = n·ξ: Hill's fitted closed form (2016,
/// "Irradiance from a spherical Gaussian", as in MJP's SG series), scaled by the SRBF's exact
/// integral 2π/λ·(1 − e^{−2λ}). `skin.wgsl` computes the same in f32; the tests below hold it
/// to f64 quadrature.
pub fn srbf_irradiance(cos_n_xi: f64, lambda: f64) -> f64 {
    if lambda < BROAD_LOBE_LAMBDA {
        return srbf_irradiance_sh2(cos_n_xi, lambda).max(0.0);
    }
    let inv_lambda = 1.0 / lambda;
    let eml = (-lambda).exp();
    let em2l = eml * eml;
    let scale = 1.0 + 2.0 * em2l - inv_lambda;
    let bias = (eml - em2l) * inv_lambda - em2l;
    let x = (1.0 - scale).max(0.0).sqrt();
    let x0 = 0.36 * cos_n_xi;
    let x1 = x / (4.0 * 0.36);
    let y = if x0.abs() <= x1 {
        (x0 + x1) * (x0 + x1) / x
    } else {
        cos_n_xi.clamp(0.0, 1.0)
    };
    let integral = std::f64::consts::TAU * inv_lambda * -(-2.0 * lambda).exp_m1();
    (scale * y + bias).max(0.0) * integral
}

/// Below this λ Hill's fit fails (its scale goes negative: 34 % of the lobe's integral off at
/// λ = 0.5) and the lobe is broad enough for the clamped cosine's first three zonal harmonics:
/// measured against quadrature, the larger error of the two at λ = 3 is 0.35 %.
pub const BROAD_LOBE_LAMBDA: f64 = 3.0;

/// The SRBF's irradiance through its zonal harmonics l ≤ 2 (Funk–Hecke):
/// E(c) = Σ (2l+1)/(4π) · g_l · A_l · P_l(c), g_l = 2π∫ e^{λ(μ−1)} P_l(μ) dμ (closed forms),
/// A_l = π, 2π/3, π/4 for the clamped cosine.
pub fn srbf_irradiance_sh2(c: f64, lambda: f64) -> f64 {
    let l = lambda;
    let e = (-2.0 * l).exp();
    let i0 = -(-2.0 * l).exp_m1() / l;
    let i1 = 1.0 / l - 1.0 / (l * l) + e * (1.0 / l + 1.0 / (l * l));
    let m2 = (1.0 / l - 2.0 / (l * l) + 2.0 / (l * l * l))
        - e * (1.0 / l + 2.0 / (l * l) + 2.0 / (l * l * l));
    let i2 = (3.0 * m2 - i0) / 2.0;
    // (2l+1)/(4π) · 2π · A_l: 1/2·π, 3/2·2π/3, 5/2·π/4.
    std::f64::consts::PI * (0.5 * i0 + i1 * c + 0.625 * i2 * (3.0 * c * c - 1.0) / 2.0)
}

/// A UV sphere scaled to the ellipsoid, with the ellipsoid's normals (∇ of its implicit
/// function), poles shared.
pub fn tessellate_ellipsoid(center: Vec3, radii: Vec3) -> TriangleMesh {
    let (segments, rings) = (ELLIPSOID_SEGMENTS, ELLIPSOID_RINGS);
    let mut positions = Vec::new();
    let mut normals = Vec::new();
    for ring in 0..=rings {
        let polar = std::f32::consts::PI * ring as f32 / rings as f32;
        for seg in 0..=segments {
            let azimuth = std::f32::consts::TAU * seg as f32 / segments as f32;
            let unit = Vec3::new(
                polar.sin() * azimuth.cos(),
                polar.cos(),
                polar.sin() * azimuth.sin(),
            );
            positions.push(center + unit * radii);
            normals.push((unit / radii).normalize());
        }
    }
    let row = segments + 1;
    let mut indices = Vec::new();
    for ring in 0..rings {
        for seg in 0..segments {
            let a = ring * row + seg;
            let b = a + row;
            indices.extend_from_slice(&[a, b, a + 1, a + 1, b, b + 1]);
        }
    }
    TriangleMesh::new(positions, normals, indices)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two meshes merged keep each one's triangles where they were: a ray through the part only
    /// the second covers meets the second's triangle (an index not offset past the first
    /// mesh's vertices would draw it from the first's corners instead).
    #[test]
    fn merged_meshes_keep_every_triangle_in_place() {
        let triangle = |z: f32, x0: f32| {
            TriangleMesh::with_computed_normals(
                vec![
                    Vec3::new(x0, 0.0, z),
                    Vec3::new(x0 + 1.0, 0.0, z),
                    Vec3::new(x0, 1.0, z),
                ],
                vec![0, 1, 2],
            )
        };
        let merged = TriangleMesh::merged([triangle(0.0, 0.0), triangle(1.0, 5.0)]);
        assert_eq!(merged.triangle_count(), 2);
        assert_eq!(merged.normals.len(), merged.positions.len());
        let down = Vec3::new(0.0, 0.0, -1.0);
        let first = merged.ray_hit(Vec3::new(0.2, 0.2, 3.0), down, 10.0);
        let second = merged.ray_hit(Vec3::new(5.2, 0.2, 3.0), down, 10.0);
        assert!((first.unwrap() - 3.0).abs() < 1e-5, "{first:?}");
        assert!((second.unwrap() - 2.0).abs() < 1e-5, "{second:?}");
        assert_eq!(merged.ray_hit(Vec3::new(3.0, 0.2, 3.0), down, 10.0), None);
    }

    /// ∫ exp(λ(ω·ξ − 1)) max(n·ω, 0) dω by quadrature in f64: ξ at the pole, n tilted by θ_n in
    /// the xz plane; Gauss-free midpoint rule, 800 × 1600 cells in (cos θ, φ) (exact area
    /// measure), fine enough for λ ≤ 100 (the lobe spans > 20 cells).
    fn srbf_irradiance_quadrature(cos_n_xi: f64, lambda: f64) -> f64 {
        let sin_n = (1.0 - cos_n_xi * cos_n_xi).max(0.0).sqrt();
        let n = glam::DVec3::new(sin_n, 0.0, cos_n_xi);
        let (nu, nphi) = (800, 1600);
        // Cells concentrated near the pole where the lobe lives: u = cos θ from 1 down to −1
        // through u = 1 − 2s², a change of variable with du = −4s ds.
        let mut sum = 0.0;
        for i in 0..nu {
            let s = (i as f64 + 0.5) / nu as f64;
            let u = 1.0 - 2.0 * s * s;
            let du = 4.0 * s / nu as f64;
            let r = (1.0 - u * u).max(0.0).sqrt();
            let g = (lambda * (u - 1.0)).exp();
            for j in 0..nphi {
                let phi = std::f64::consts::TAU * (j as f64 + 0.5) / nphi as f64;
                let w = glam::DVec3::new(r * phi.cos(), r * phi.sin(), u);
                sum += g * n.dot(w).max(0.0) * du * std::f64::consts::TAU / nphi as f64;
            }
        }
        sum
    }

    /// Hill's fit (zonal harmonics below λ = 3) against quadrature over normals all round the
    /// lobe, λ from a broad 0.5 to a sharp 100: within 2 % of the SRBF's integral (the
    /// irradiance of the lobe at normal incidence, its largest value) everywhere. Measured
    /// worst: printed.
    #[test]
    fn the_srbf_irradiance_closed_form_matches_quadrature() {
        let mut worst: f64 = 0.0;
        for &lambda in &[0.5, 1.0, 2.0, 5.0, 10.0, 30.0, 100.0] {
            let peak = std::f64::consts::TAU / lambda * -(-2.0f64 * lambda).exp_m1();
            for k in 0..=20 {
                let c = 1.0 - 2.0 * k as f64 / 20.0;
                let exact = srbf_irradiance_quadrature(c, lambda);
                let fit = srbf_irradiance(c, lambda);
                let err = (fit - exact).abs() / peak;
                worst = worst.max(err);
                assert!(
                    err < 0.02,
                    "λ {lambda} cos {c}: fit {fit} vs quadrature {exact}"
                );
            }
        }
        println!("worst error relative to the lobe's integral: {worst:.4}");
        // A sharp lobe is a directional light: E → ∫G · max(cos, 0).
        let lambda = 100.0;
        let peak = std::f64::consts::TAU / lambda;
        assert!((srbf_irradiance(0.6, lambda) / peak - 0.6).abs() < 0.01);
    }

    #[test]
    fn the_ellipsoid_ray_hit_matches_its_implicit_function() {
        let head = Head::ellipsoid(Vec3::new(1.0, 2.0, 3.0), Vec3::new(2.0, 3.0, 4.0));
        // From far along +x toward the centre: the hit is at x = 1 + 2.
        let o = Vec3::new(10.0, 2.0, 3.0);
        let t = head.ray_hit(o, -Vec3::X, 100.0).unwrap();
        assert!((t - 7.0).abs() < 1e-4, "{t}");
        // Aslant: the hit point satisfies the implicit equation.
        let d = Vec3::new(-1.0, -0.3, -0.2).normalize();
        let t = head.ray_hit(o, d, 100.0).unwrap();
        let p = o + t * d;
        let q = ((p - Vec3::new(1.0, 2.0, 3.0)) / Vec3::new(2.0, 3.0, 4.0)).length_squared();
        assert!((q - 1.0).abs() < 1e-4, "{q}");
        // Away from it, or stopped short: no hit.
        assert!(head.ray_hit(o, Vec3::X, 100.0).is_none());
        assert!(head.ray_hit(o, -Vec3::X, 6.9).is_none());
        assert!(head.contains(Vec3::new(1.0, 2.0, 3.0)));
        assert!(!head.contains(o));
    }

    #[test]
    fn the_tessellated_ellipsoid_as_a_mesh_answers_like_the_ellipsoid() {
        let (c, r) = (Vec3::new(0.0, 1.0, 0.0), Vec3::new(7.8, 9.5, 9.8));
        let exact = Head::ellipsoid(c, r);
        let mesh = Head {
            surface: HeadSurface::Mesh(tessellate_ellipsoid(c, r)),
            albedo: DEFAULT_SKIN_ALBEDO,
        };
        let mut rng = strandlight_tables::split_mix::SplitMix64::new(7);
        for _ in 0..200 {
            let u = |rng: &mut strandlight_tables::split_mix::SplitMix64| rng.range_f32(-1.0, 1.0);
            let o = Vec3::new(u(&mut rng), u(&mut rng), u(&mut rng)) * 20.0;
            let d = Vec3::new(u(&mut rng), u(&mut rng), u(&mut rng)).normalize();
            let (a, b) = (exact.ray_hit(o, d, 100.0), mesh.ray_hit(o, d, 100.0));
            match (a, b) {
                (Some(a), Some(b)) => assert!((a - b).abs() < 0.02, "{a} {b}"),
                (None, None) => {}
                // A ray grazing the surface may miss the facets: both hits near the silhouette.
                (Some(t), None) | (None, Some(t)) => {
                    let p = o + t * d;
                    let n = ((p - c) / (r * r)).normalize();
                    assert!(
                        n.dot(d).abs() < 0.1,
                        "a miss away from the silhouette at {p}"
                    );
                }
            }
            assert_eq!(exact.contains(o), mesh.contains(o), "{o}");
        }
    }

    /// The BVH finds the nearest hit brute force finds, for rays from outside, from inside and
    /// cut short by t_max, on a mesh with thin, overlapping and degenerate triangles.
    #[test]
    fn the_bvh_answers_every_ray_as_brute_force() {
        let sphere = tessellate_ellipsoid(Vec3::new(0.5, -1.0, 2.0), Vec3::new(3.0, 4.0, 2.5));
        let mut positions = sphere.positions.clone();
        let mut indices = sphere.indices.clone();
        let n = positions.len() as u32;
        positions.extend([
            Vec3::ZERO,
            Vec3::new(5.0, 0.0, 0.0),
            Vec3::new(5.0, 0.01, 0.0),
        ]);
        positions.extend([Vec3::ONE, Vec3::ONE, Vec3::ONE]);
        indices.extend([n, n + 1, n + 2, n + 3, n + 4, n + 5]);
        let mesh = TriangleMesh::with_computed_normals(positions, indices);
        let mut rng = strandlight_tables::split_mix::SplitMix64::new(11);
        let mut hits = 0;
        for i in 0..3000 {
            let u = |rng: &mut strandlight_tables::split_mix::SplitMix64| rng.range_f32(-1.0, 1.0);
            let scale = if i % 3 == 0 { 1.0 } else { 8.0 };
            let o = Vec3::new(u(&mut rng), u(&mut rng), u(&mut rng)) * scale;
            let d = Vec3::new(u(&mut rng), u(&mut rng), u(&mut rng)).normalize();
            let t_max = if i % 4 == 0 { 2.0 } else { f32::INFINITY };
            let (fast, slow) = (
                mesh.ray_hit(o, d, t_max),
                mesh.ray_hit_brute_force(o, d, t_max),
            );
            assert_eq!(fast, slow, "ray {i}: {o} + t {d}, t_max {t_max}");
            hits += fast.is_some() as usize;
        }
        assert!(hits > 500, "{hits} of 3000 rays hit");
    }
}
