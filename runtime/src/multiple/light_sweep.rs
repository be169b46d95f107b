//! The same expected shadow paths as [`super::shadow_paths::march`], computed for a whole
//! volume at once: a lattice of rays parallel to ξ, one voxel apart, each marched once from
//! the light's side through the hair, keeping the path expectations (P₀, E[∏ā_f], V, W) at
//! every step. A point's value is the trilinear interpolation of those expectations between
//! the four rays around it and the two steps around its depth, finished as one path would be.
//!
//! Interpolating the expectations (not T_f or σ̄_f) is exact for the mixture they describe —
//! the point receives the average of its neighbouring paths — and the lateral interpolation
//! over one voxel is the §6 one-voxel box filter (a tent, in fact). Cost: (extent/h)² rays ×
//! (depth/δ) steps per light, independent of how many points are asked for, so dense sample
//! grids (the reference renderer's) cost little more than coarse ones; per-vertex marching
//! costs vertices × taps³ × steps and wins only for the coarse interactive grid.

use glam::Vec3;
use rayon::prelude::*;

use super::hair_volume::HairVolume;
use super::shadow_paths::{ExpectedShadowPath, LightMedium};

/// The path expectations stored per lattice node (f32 to keep memory at 40 bytes a node).
#[derive(Clone, Copy, Debug, Default)]
struct StoredPath {
    no_hit: f32,
    product: [f32; 3],
    weighted_variance: [f32; 3],
    weighted_first_variance: [f32; 3],
    plain_variance: f32,
}

impl StoredPath {
    fn from(p: &ExpectedShadowPath) -> Self {
        Self {
            no_hit: p.no_hit as f32,
            product: p.product.map(|x| x as f32),
            weighted_variance: p.weighted_variance.map(|x| x as f32),
            weighted_first_variance: p.weighted_first_variance.map(|x| x as f32),
            plain_variance: p.plain_variance as f32,
        }
    }

    fn add_scaled(&self, w: f64, out: &mut ExpectedShadowPath) {
        out.no_hit += w * self.no_hit as f64;
        for c in 0..3 {
            out.product[c] += w * self.product[c] as f64;
            out.weighted_variance[c] += w * self.weighted_variance[c] as f64;
            out.weighted_first_variance[c] += w * self.weighted_first_variance[c] as f64;
        }
        out.plain_variance += w * self.plain_variance as f64;
    }
}

/// Path expectations on a light-aligned lattice for one light.
pub struct LightSweep {
    xi: Vec3,
    e1: Vec3,
    e2: Vec3,
    /// Lattice origin in (e1, e2) and the light-side depth w_top along ξ.
    u0: f32,
    v0: f32,
    w_top: f32,
    lateral: f32,
    delta: f32,
    /// Nodes along e1, e2 and depth.
    dims: [usize; 3],
    nodes: Vec<StoredPath>,
}

impl LightSweep {
    /// Marches every lattice ray through `volume` (parallel over rays). `lateral` is the ray
    /// spacing and the depth between stored nodes; each node interval is marched in
    /// `substeps` steps (model units > 0, substeps ≥ 1). Storing every voxel rather than every
    /// step keeps the lattice at 40 bytes per voxel-sized cell: its size, not the marching,
    /// sets the cost (memory traffic).
    pub fn new(
        volume: &HairVolume,
        medium: &LightMedium,
        xi: Vec3,
        lateral: f32,
        substeps: u32,
    ) -> Self {
        let substeps = substeps.max(1);
        let delta = lateral;
        let step = delta / substeps as f32;
        let (e1, e2) = xi.any_orthonormal_pair();
        let g = &volume.grid;
        let (lo, hi) = (g.origin, g.origin + g.extent());
        let mut min = Vec3::splat(f32::INFINITY);
        let mut max = Vec3::splat(f32::NEG_INFINITY);
        for corner in 0..8 {
            let p = Vec3::new(
                if corner & 1 == 1 { hi.x } else { lo.x },
                if corner & 2 == 2 { hi.y } else { lo.y },
                if corner & 4 == 4 { hi.z } else { lo.z },
            );
            let q = Vec3::new(p.dot(e1), p.dot(e2), p.dot(xi));
            min = min.min(q);
            max = max.max(q);
        }
        // One node of margin around the box so that interpolation at its faces sees outside
        // (direct-light) rays on the far side.
        let (u0, v0) = (min.x - lateral, min.y - lateral);
        let nu = ((max.x - min.x) / lateral).ceil() as usize + 3;
        let nv = ((max.y - min.y) / lateral).ceil() as usize + 3;
        let w_top = max.z + delta;
        let nw = ((w_top - (min.z - delta)) / delta).ceil() as usize + 1;
        let mut nodes = vec![StoredPath::default(); nu * nv * nw];
        nodes
            .par_chunks_mut(nw)
            .enumerate()
            .for_each(|(ray, column)| {
                let (i, j) = (ray % nu, ray / nu);
                let base = e1 * (u0 + i as f32 * lateral) + e2 * (v0 + j as f32 * lateral);
                let mut path = ExpectedShadowPath::default();
                column[0] = StoredPath::from(&path);
                for (k, node) in column.iter_mut().enumerate().skip(1) {
                    for sub in 0..substeps {
                        let w_mid = w_top - (k - 1) as f32 * delta - (sub as f32 + 0.5) * step;
                        if let Some(v) = g.voxel_of(base + xi * w_mid) {
                            let ext = medium.extinction[v];
                            if ext > 0.0 {
                                path.step(
                                    ext as f64,
                                    step as f64,
                                    &medium.event[v],
                                    medium.srbf_variance[v] as f64,
                                );
                            }
                        }
                    }
                    *node = StoredPath::from(&path);
                }
            });
        Self {
            xi,
            e1,
            e2,
            u0,
            v0,
            w_top,
            lateral,
            delta,
            dims: [nu, nv, nw],
            nodes,
        }
    }

    /// Rays × steps marched.
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// The interpolated path expectations at `p` (clamped to the lattice).
    pub fn path_at(&self, p: Vec3) -> ExpectedShadowPath {
        let [nu, nv, nw] = self.dims;
        let coords = [
            (p.dot(self.e1) - self.u0) / self.lateral,
            (p.dot(self.e2) - self.v0) / self.lateral,
            (self.w_top - p.dot(self.xi)) / self.delta,
        ];
        let n = [nu, nv, nw];
        let cell: [(usize, f64); 3] = std::array::from_fn(|a| {
            let x = if coords[a].is_finite() {
                coords[a]
            } else {
                0.0
            };
            let x = x.clamp(0.0, (n[a] - 1) as f32) as f64;
            let i = (x.floor() as usize).min(n[a] - 2);
            (i, x - i as f64)
        });
        let mut out = ExpectedShadowPath {
            no_hit: 0.0,
            product: [0.0; 3],
            weighted_variance: [0.0; 3],
            weighted_first_variance: [0.0; 3],
            plain_variance: 0.0,
            expected_hits: 0.0,
        };
        for corner in 0..8 {
            let d = [corner & 1, corner >> 1 & 1, corner >> 2 & 1];
            let mut w = 1.0;
            for a in 0..3 {
                w *= if d[a] == 1 {
                    cell[a].1
                } else {
                    1.0 - cell[a].1
                };
            }
            if w == 0.0 {
                continue;
            }
            let (i, j, k) = (cell[0].0 + d[0], cell[1].0 + d[1], cell[2].0 + d[2]);
            self.nodes[(j * nu + i) * nw + k].add_scaled(w, &mut out);
        }
        out
    }
}
