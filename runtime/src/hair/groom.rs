//! The project's own default hair: a procedural groom grown from a scalp.
//!
//! Roots are scattered over the top of an ellipsoid (a cap, with a higher hairline over the
//! face at +z). Each strand leaves its root combed away from the crown whorl, or from a parting
//! (then back, off the face), and bends toward −y (gravity) as it goes; a helix around that
//! curve gives waves or curls; strands are pulled
//! toward the strand at the centre of their clump, more toward the tip; finally the shape is
//! traced again with "follow the leader" steps of exactly `length / (points − 1)`, which makes
//! each strand exactly its drawn length and, with the scalp as a convex collider, keeps every
//! point outside the head. Y is up; units are the caller's (the defaults read as centimetres).
//!
//! The random numbers come from the tables crate's SplitMix64 so that a seed gives the same groom whatever
//! version of an RNG crate is linked: this model is embedded, and its bytes are tested.

use std::f32::consts::TAU;

use glam::Vec3;
use strandlight_tables::ParamError;
use strandlight_tables::error::check;
use strandlight_tables::split_mix::SplitMix64;

use super::{Attribute, HairError, HairModel};

/// The surface the hair grows from: the upper part of an ellipsoid.
#[derive(Clone, Debug, PartialEq)]
pub struct Scalp {
    pub center: Vec3,
    /// Semi-axes along x (ear to ear), y (up) and z (back to face).
    pub radii: Vec3,
    /// How far down from the top (+y) roots go, as the polar angle of the unit-sphere direction,
    /// in radians (π/2 = the equator).
    pub max_polar_angle: f32,
    /// The same limit straight over the face (+z); in between it blends with the azimuth.
    pub front_polar_angle: f32,
}

impl Scalp {
    /// The ellipsoid's implicit function: 1 on the surface, < 1 inside.
    pub fn implicit(&self, p: Vec3) -> f32 {
        ((p - self.center) / self.radii).length_squared()
    }

    fn gradient(&self, p: Vec3) -> Vec3 {
        2.0 * (p - self.center) / (self.radii * self.radii)
    }

    /// The whorl hair flows away from: the top of the scalp, a little toward the back (−z).
    pub fn crown(&self) -> Vec3 {
        self.center + self.radii * Vec3::new(0.0, 1.0, -0.3).normalize()
    }

    /// The outward unit normal at a surface point.
    pub fn normal(&self, p: Vec3) -> Vec3 {
        self.gradient(p).normalize()
    }

    /// The polar-angle limit for a unit-sphere direction `d` (front = +z).
    pub fn polar_limit(&self, d: Vec3) -> f32 {
        let horizontal = (d.x * d.x + d.z * d.z).sqrt();
        let toward_face = if horizontal > 0.0 {
            (d.z / horizontal).max(0.0)
        } else {
            0.0
        };
        self.max_polar_angle + (self.front_polar_angle - self.max_polar_angle) * toward_face
    }

    /// Whether a point on the ellipsoid lies in the haired region.
    pub fn covers(&self, p: Vec3) -> bool {
        let d = ((p - self.center) / self.radii).normalize();
        d.y.clamp(-1.0, 1.0).acos() <= self.polar_limit(d) + 1e-5
    }
}

/// Everything that shapes a groom.
#[derive(Clone, Debug, PartialEq)]
pub struct GroomParams {
    pub scalp: Scalp,
    pub strand_count: usize,
    pub points_per_strand: usize,
    /// Each strand's length is drawn uniformly from `[length_min, length_max]`.
    pub length_min: f32,
    pub length_max: f32,
    /// Helix radius around the strand's centre line (0 = straight); varies ±30 % per strand.
    pub curl_radius: f32,
    /// Helix turns per unit length. Keep `curl_frequency × length / (points − 1)` below about
    /// 0.15 (seven or more points per turn), or the polyline cannot show the curl.
    pub curl_frequency: f32,
    /// Number of clumps (0 = none) and how far (0–1) a tip is pulled onto its clump centre.
    pub clump_count: usize,
    pub clump_strength: f32,
    /// 0 = strands stay along the scalp normal, 1 = tips point straight down.
    pub gravity: f32,
    /// Root thickness; strands taper to 30 % of it at the tip.
    pub thickness: f32,
    /// A parting running from the front hairline to the crown at this x on the unit scalp
    /// (−1 ear to +1 ear; 0 a centre parting): hair on top flows away from it and back, off
    /// the face. None: every strand flows away from the crown whorl (the front falls forward).
    pub parting: Option<f32>,
    pub seed: u64,
}

impl Default for GroomParams {
    /// A head-sized scalp (units read as centimetres) with 6,000 gently wavy, loosely clumped
    /// strands of 24 points, 18–26 long.
    fn default() -> Self {
        Self {
            scalp: Scalp {
                center: Vec3::ZERO,
                radii: Vec3::new(7.8, 9.5, 9.8),
                max_polar_angle: 105f32.to_radians(),
                front_polar_angle: 55f32.to_radians(),
            },
            strand_count: 6000,
            points_per_strand: 24,
            length_min: 18.0,
            length_max: 26.0,
            curl_radius: 0.4,
            curl_frequency: 0.1,
            clump_count: 150,
            clump_strength: 0.5,
            gravity: 0.85,
            thickness: 0.008,
            parting: None,
            seed: 1,
        }
    }
}

impl GroomParams {
    fn validate(&self) -> Result<(), ParamError> {
        // Sizes are capped well inside f32 range so that squared radii cannot overflow.
        const SIZE: f64 = 1e6;
        const PI: f64 = std::f64::consts::PI;
        let (scalp, c, r) = (&self.scalp, self.scalp.center, self.scalp.radii);
        let within = |lo: f64, hi: f64| move |v: f64| (lo..=hi).contains(&v);
        let above = |lo: f64, hi: f64| move |v: f64| v > lo && v <= hi;
        let strands = self.strand_count as f64;
        let points = self.points_per_strand as f64;
        type Check<'a> = (&'static str, f64, &'a dyn Fn(f64) -> bool, &'static str);
        let parting = self.parting.unwrap_or(0.0) as f64;
        #[rustfmt::skip]
        let checks: [Check; 20] = [
            ("scalp.center.x", c.x as f64, &within(-SIZE, SIZE), "must be in [-1e6, 1e6]"),
            ("scalp.center.y", c.y as f64, &within(-SIZE, SIZE), "must be in [-1e6, 1e6]"),
            ("scalp.center.z", c.z as f64, &within(-SIZE, SIZE), "must be in [-1e6, 1e6]"),
            ("scalp.radii.x", r.x as f64, &above(0.0, SIZE), "must be in (0, 1e6]"),
            ("scalp.radii.y", r.y as f64, &above(0.0, SIZE), "must be in (0, 1e6]"),
            ("scalp.radii.z", r.z as f64, &above(0.0, SIZE), "must be in (0, 1e6]"),
            ("scalp.max_polar_angle", scalp.max_polar_angle as f64, &above(0.0, PI), "must be in (0, π]"),
            ("scalp.front_polar_angle", scalp.front_polar_angle as f64, &above(0.0, PI), "must be in (0, π]"),
            ("strand_count", strands, &within(1.0, 1e7), "must be in 1..=10,000,000"),
            ("points_per_strand", points, &within(2.0, 1024.0), "must be in 2..=1024"),
            ("strand_count × points_per_strand", strands * points, &within(0.0, 1e8), "must be ≤ 1e8"),
            ("length_min", self.length_min as f64, &above(0.0, SIZE), "must be in (0, 1e6]"),
            ("length_max", self.length_max as f64, &within(self.length_min as f64, SIZE), "must be in [length_min, 1e6]"),
            ("curl_radius", self.curl_radius as f64, &within(0.0, SIZE), "must be in [0, 1e6]"),
            ("curl_frequency", self.curl_frequency as f64, &within(0.0, SIZE), "must be in [0, 1e6]"),
            ("clump_count", self.clump_count as f64, &within(0.0, strands), "must be ≤ strand_count"),
            ("clump_strength", self.clump_strength as f64, &within(0.0, 1.0), "must be in [0, 1]"),
            ("gravity", self.gravity as f64, &within(0.0, 1.0), "must be in [0, 1]"),
            ("thickness", self.thickness as f64, &within(0.0, SIZE), "must be in [0, 1e6]"),
            ("parting", parting, &within(-0.9, 0.9), "must be in [-0.9, 0.9]"),
        ];
        for (name, value, ok, requirement) in checks {
            check(name, value, ok, requirement)?;
        }
        Ok(())
    }
}

/// How steeply strands leave the scalp: the normal's weight against the (unit) comb direction.
const ROOT_LIFT: f32 = 0.35;

/// One strand's random choices, drawn in a fixed order.
struct StrandSeed {
    root: Vec3,
    length: f32,
    lean: Vec3,
    curl_radius: f32,
    curl_phase: f32,
}

/// Grows the groom described by `params`. The same parameters give the same bytes.
pub fn generate_groom(params: &GroomParams) -> Result<HairModel, HairError> {
    params.validate()?;
    let mut rng = SplitMix64::new(params.seed);
    let seeds: Vec<StrandSeed> = (0..params.strand_count)
        .map(|_| draw_strand(&mut rng, params))
        .collect();
    let n = params.points_per_strand;

    // The drawn shape of every strand: centre line bent by gravity, plus the curl helix.
    let shapes: Vec<Vec<Vec3>> = seeds
        .iter()
        .map(|s| curled_center_line(s, params))
        .collect();

    // Clumps: the first `clump_count` strands are clump centres (their roots are uniformly
    // scattered already); every strand is pulled toward its nearest centre's shape.
    let centres = params.clump_count;
    let mut points = Vec::with_capacity(params.strand_count * n);
    let mut offsets = Vec::with_capacity(params.strand_count + 1);
    offsets.push(0u32);
    let mut target = vec![Vec3::ZERO; n];
    for (s, seed) in seeds.iter().enumerate() {
        target.copy_from_slice(&shapes[s]);
        if centres > 0 && params.clump_strength > 0.0 {
            let c = nearest_root(&seeds[..centres], seed.root);
            let guide = &shapes[c];
            for i in 1..n {
                let t = i as f32 / (n - 1) as f32;
                // Nothing at the root, the most at the tip: tips gather, roots stay put.
                let pull = params.clump_strength * t.powf(0.7) * (guide[i] - target[i]);
                target[i] += pull;
            }
        }
        follow_the_leader(
            &target,
            seed.length / (n - 1) as f32,
            &params.scalp,
            &mut points,
        );
        offsets.push(points.len() as u32);
    }
    let thickness = (0..params.strand_count)
        .flat_map(|_| (0..n).map(|i| params.thickness * (1.0 - 0.7 * i as f32 / (n - 1) as f32)))
        .collect();
    // Only parameters that overflow f32 (e.g. radii near 1e38) can fail here.
    HairModel::new(
        points,
        offsets,
        Some(Attribute::PerPoint(thickness)),
        None,
        None,
    )
}

fn draw_strand(rng: &mut SplitMix64, params: &GroomParams) -> StrandSeed {
    let scalp = &params.scalp;
    // Uniform on the unit-sphere cap, rejecting the part below the (front) hairline.
    let cos_max = scalp.max_polar_angle.max(scalp.front_polar_angle).cos();
    let d = loop {
        let cos_theta = 1.0 - rng.unit_f32() * (1.0 - cos_max);
        let phi = TAU * rng.unit_f32();
        let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
        let d = Vec3::new(sin_theta * phi.cos(), cos_theta, sin_theta * phi.sin());
        if cos_theta.clamp(-1.0, 1.0).acos() <= scalp.polar_limit(d) {
            break d;
        }
    };
    let root = scalp.center + scalp.radii * d;
    let lean = Vec3::new(
        rng.range_f32(-1.0, 1.0),
        rng.range_f32(-1.0, 1.0),
        rng.range_f32(-1.0, 1.0),
    );
    StrandSeed {
        root,
        length: rng.range_f32(params.length_min, params.length_max),
        lean,
        curl_radius: params.curl_radius * rng.range_f32(0.7, 1.3),
        curl_phase: TAU * rng.unit_f32(),
    }
}

/// Index of the seed whose root is nearest `p`.
fn nearest_root(seeds: &[StrandSeed], p: Vec3) -> usize {
    let mut best = (0, f32::INFINITY);
    for (i, s) in seeds.iter().enumerate() {
        let d = s.root.distance_squared(p);
        if d < best.1 {
            best = (i, d);
        }
    }
    best.0
}

/// The strand's centre line (normal bending to −y under gravity) with the curl helix around it.
fn curled_center_line(seed: &StrandSeed, params: &GroomParams) -> Vec<Vec3> {
    let n = params.points_per_strand;
    let step = seed.length / (n - 1) as f32;
    let normal = params.scalp.normal(seed.root);
    let in_plane = |v: Vec3| v - v.dot(normal) * normal;
    // Combed hair leaves the scalp at a low angle, flowing away from the crown whorl or the
    // parting; a small random lean keeps neighbours from running exactly parallel.
    let flow = match params.parting {
        None => seed.root - params.scalp.crown(),
        Some(parting) => parted_flow(&params.scalp, seed.root, parting),
    };
    let comb = in_plane(flow)
        .try_normalize()
        .unwrap_or_else(|| in_plane(seed.lean).normalize_or(normal.any_orthonormal_vector()));
    let start = (comb + ROOT_LIFT * normal + 0.2 * in_plane(seed.lean)).normalize();
    let mut line = Vec::with_capacity(n);
    let mut tangents = Vec::with_capacity(n);
    let mut p = seed.root;
    for i in 0..n {
        let t = i as f32 / (n - 1) as f32;
        // Gravity wins gradually: the bend grows with the distance from the root.
        let bend = params.gravity * (1.0 - (1.0 - t) * (1.0 - t));
        let dir = (start * (1.0 - bend) + Vec3::NEG_Y * bend)
            .try_normalize()
            .unwrap_or(Vec3::NEG_Y);
        line.push(p);
        tangents.push(dir);
        p += step * dir;
    }
    if seed.curl_radius == 0.0 || params.curl_frequency == 0.0 {
        return line;
    }
    // Helix in a parallel-transported frame; its radius ramps up over the first fifth so the
    // root stays on the scalp.
    let mut u = tangents[0].any_orthonormal_vector();
    for i in 0..n {
        let tangent = tangents[i];
        u = (u - u.dot(tangent) * tangent)
            .try_normalize()
            .unwrap_or_else(|| tangent.any_orthonormal_vector());
        let v = tangent.cross(u);
        let s = i as f32 * step;
        let ramp = smoothstep((s / (0.2 * seed.length)).min(1.0));
        let angle = TAU * params.curl_frequency * s + seed.curl_phase;
        line[i] += seed.curl_radius * ramp * (angle.cos() * u + angle.sin() * v);
    }
    line
}

/// Where hair at `root` flows on a parted scalp: away from the parting and back, off the face;
/// low on the back and sides it hangs as it would from the crown. The weights are chosen by eye
/// (a head seen from the front shows its face between two curtains of hair).
fn parted_flow(scalp: &Scalp, root: Vec3, parting: f32) -> Vec3 {
    let d = ((root - scalp.center) / scalp.radii).normalize_or(Vec3::Y);
    let side = if d.x >= parting { 1.0 } else { -1.0 };
    // The nearer the face, the more a strand is swept back.
    let back = 0.5 + 1.5 * d.z.max(0.0);
    let parted = Vec3::new(side, 0.0, -back).normalize() * scalp.radii;
    let from_crown = (root - scalp.crown()).normalize_or(Vec3::NEG_Y) * scalp.radii;
    // The parting decides on top and over the face; the crown below the back's equator.
    let top = smoothstep(((d.y + d.z.max(0.0) + 0.2) / 0.8).clamp(0.0, 1.0));
    parted * top + from_crown * (1.0 - top)
}

fn smoothstep(x: f32) -> f32 {
    x * x * (3.0 - 2.0 * x)
}

/// Traces `target` from its root with steps of exactly `step` (Müller et al. 2012's follow the
/// leader), turning any step that would enter the scalp into the scalp's tangent plane. The
/// scalp is convex, so a step with ∇f·d ≥ 0 never lowers f: no point goes inside.
fn follow_the_leader(target: &[Vec3], step: f32, scalp: &Scalp, out: &mut Vec<Vec3>) {
    let mut p = target[0];
    let mut dir = scalp.normal(p);
    out.push(p);
    for &goal in &target[1..] {
        dir = (goal - p).try_normalize().unwrap_or(dir);
        let g = scalp.gradient(p);
        if scalp.implicit(p + step * dir) < scalp.implicit(p).max(1.0) && dir.dot(g) < 0.0 {
            let gn = g.normalize();
            dir = (dir - dir.dot(gn) * gn)
                .try_normalize()
                .unwrap_or_else(|| gn.any_orthonormal_vector());
        }
        p += step * dir;
        out.push(p);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn small() -> GroomParams {
        GroomParams {
            strand_count: 800,
            points_per_strand: 16,
            clump_count: 40,
            ..GroomParams::default()
        }
    }

    #[test]
    fn same_seed_same_bytes_other_seed_other_bytes() {
        let a = generate_groom(&small()).unwrap();
        let b = generate_groom(&small()).unwrap();
        let c = generate_groom(&GroomParams { seed: 2, ..small() }).unwrap();
        assert_eq!(a.points_bytes(), b.points_bytes());
        assert_eq!(a, b);
        let differing = a
            .points()
            .iter()
            .zip(c.points())
            .filter(|(p, q)| p != q)
            .count();
        eprintln!(
            "seed 1 vs 2: {differing} of {} points differ",
            a.point_count()
        );
        assert!(differing > a.point_count() * 9 / 10);
    }

    #[test]
    fn counts_roots_lengths_and_no_point_inside_the_head() {
        let params = small();
        let m = generate_groom(&params).unwrap();
        assert_eq!(m.strand_count(), params.strand_count);
        assert_eq!(
            m.point_count(),
            params.strand_count * params.points_per_strand
        );
        let scalp = &params.scalp;
        let (mut worst_root, mut min_inside, mut lengths) = (0f64, f64::INFINITY, Vec::new());
        for strand in m.strands() {
            let root = strand[0];
            // On the ellipsoid, in f64: ((x-c)/r)² summed is 1.
            let q = (root - scalp.center).as_dvec3() / scalp.radii.as_dvec3();
            worst_root = worst_root.max((q.length_squared() - 1.0).abs());
            assert!(scalp.covers(root), "root {root} outside the haired region");
            for &p in &strand[1..] {
                let q = (p - scalp.center).as_dvec3() / scalp.radii.as_dvec3();
                min_inside = min_inside.min(q.length_squared());
            }
            lengths.push(
                strand
                    .windows(2)
                    .map(|w| w[0].as_dvec3().distance(w[1].as_dvec3()))
                    .sum::<f64>(),
            );
        }
        let (lo, hi) = lengths
            .iter()
            .fold((f64::INFINITY, 0f64), |(lo, hi), &l| (lo.min(l), hi.max(l)));
        eprintln!(
            "roots: max |f−1| = {worst_root:.2e}; min f over other points = {min_inside:.6}; lengths {lo:.4}..{hi:.4} (asked {}..{})",
            params.length_min, params.length_max
        );
        assert!(worst_root < 1e-5);
        assert!(min_inside > 1.0 - 1e-4);
        assert!(
            lo >= params.length_min as f64 * (1.0 - 1e-4)
                && hi <= params.length_max as f64 * (1.0 + 1e-4)
        );
        // The lengths actually spread over the range (uniform draws: expect near both ends).
        assert!(
            lo < params.length_min as f64 + 0.05 * (params.length_max - params.length_min) as f64
        );
        assert!(
            hi > params.length_max as f64 - 0.05 * (params.length_max - params.length_min) as f64
        );
    }

    #[test]
    fn gravity_and_curl_do_what_they_say() {
        let straight = GroomParams {
            curl_radius: 0.0,
            clump_count: 0,
            ..small()
        };
        let up = generate_groom(&GroomParams {
            gravity: 0.0,
            ..straight.clone()
        })
        .unwrap();
        let down = generate_groom(&GroomParams {
            gravity: 1.0,
            ..straight.clone()
        })
        .unwrap();
        let mean_tip_y = |m: &HairModel| {
            m.strands().map(|s| s[s.len() - 1].y as f64).sum::<f64>() / m.strand_count() as f64
        };
        eprintln!(
            "mean tip y: gravity 0 → {:.3}, gravity 1 → {:.3}",
            mean_tip_y(&up),
            mean_tip_y(&down)
        );
        assert!(mean_tip_y(&down) < mean_tip_y(&up) - 5.0);

        // Without curl a strand is nearly straight when gravity is off: chord ≈ length.
        // With curl the chord is shorter than the arc.
        let chord_ratio = |m: &HairModel| {
            m.strands()
                .map(|s| {
                    let arc: f32 = s.windows(2).map(|w| w[0].distance(w[1])).sum();
                    (s[0].distance(s[s.len() - 1]) / arc) as f64
                })
                .sum::<f64>()
                / m.strand_count() as f64
        };
        // 64 points over ~22 units at 0.15 turns/unit: about 19 points per turn.
        let curly = generate_groom(&GroomParams {
            gravity: 0.0,
            curl_radius: 1.0,
            curl_frequency: 0.15,
            points_per_strand: 64,
            ..straight
        })
        .unwrap();
        eprintln!(
            "mean chord/arc: straight {:.4}, curly {:.4}",
            chord_ratio(&up),
            chord_ratio(&curly)
        );
        assert!(chord_ratio(&up) > 0.97);
        assert!(chord_ratio(&curly) < chord_ratio(&up) - 0.1);
    }

    #[test]
    fn clumping_brings_neighbours_together() {
        let base = GroomParams {
            clump_count: 30,
            ..small()
        };
        let spread = |m: &HairModel| {
            // Mean distance from each tip to the tip of the nearest other strand.
            let tips: Vec<Vec3> = m.strands().map(|s| s[s.len() - 1]).collect();
            tips.iter()
                .enumerate()
                .map(|(i, a)| {
                    tips.iter()
                        .enumerate()
                        .filter(|(j, _)| *j != i)
                        .map(|(_, b)| a.distance(*b))
                        .fold(f32::INFINITY, f32::min) as f64
                })
                .sum::<f64>()
                / tips.len() as f64
        };
        let loose = generate_groom(&GroomParams {
            clump_strength: 0.0,
            ..base.clone()
        })
        .unwrap();
        let tight = generate_groom(&GroomParams {
            clump_strength: 0.9,
            ..base
        })
        .unwrap();
        eprintln!(
            "mean nearest-tip distance: no clumping {:.4}, clump 0.9 {:.4}",
            spread(&loose),
            spread(&tight)
        );
        assert!(spread(&tight) < 0.5 * spread(&loose));
    }

    #[test]
    fn follow_the_leader_slides_around_the_head_instead_of_through_it() {
        // A target line from the top of a unit sphere straight down through its centre.
        let scalp = Scalp {
            center: Vec3::ZERO,
            radii: Vec3::ONE,
            ..small().scalp
        };
        let target: Vec<Vec3> = (0..41)
            .map(|i| Vec3::new(0.01, 1.0 - 0.1 * i as f32, 0.0))
            .collect();
        let mut out = Vec::new();
        follow_the_leader(&target, 0.1, &scalp, &mut out);
        let min_f = out
            .iter()
            .map(|p| p.as_dvec3().length_squared())
            .fold(f64::INFINITY, f64::min);
        let worst_step = out
            .windows(2)
            .map(|w| (w[0].as_dvec3().distance(w[1].as_dvec3()) - 0.1).abs())
            .fold(0.0, f64::max);
        let tip = out[out.len() - 1];
        eprintln!(
            "through-the-head target: min |p|² = {min_f:.6}, worst step error {worst_step:.2e}, tip {tip}"
        );
        assert!(min_f > 1.0 - 1e-5);
        assert!(worst_step < 1e-6);
        assert!(
            tip.y < 0.0,
            "the strand should have slid past the equator: {tip}"
        );
    }

    #[test]
    fn bad_parameters_are_named() {
        let bad = |p: GroomParams, name: &str| match generate_groom(&p) {
            Err(HairError::Param(
                ParamError::OutOfRange { name: n, .. } | ParamError::NotFinite { name: n, .. },
            )) => assert_eq!(n, name),
            other => panic!("expected an error naming {name}, got {other:?}"),
        };
        bad(
            GroomParams {
                strand_count: 0,
                ..small()
            },
            "strand_count",
        );
        bad(
            GroomParams {
                points_per_strand: 1,
                ..small()
            },
            "points_per_strand",
        );
        bad(
            GroomParams {
                curl_radius: 1e30,
                ..small()
            },
            "curl_radius",
        );
        let huge_head = Scalp {
            radii: Vec3::splat(1e20),
            ..small().scalp
        };
        bad(
            GroomParams {
                scalp: huge_head,
                ..small()
            },
            "scalp.radii.x",
        );
        bad(
            GroomParams {
                length_max: 1.0,
                ..small()
            },
            "length_max",
        );
        bad(
            GroomParams {
                gravity: f32::NAN,
                ..small()
            },
            "gravity",
        );
        bad(
            GroomParams {
                clump_strength: 1.5,
                ..small()
            },
            "clump_strength",
        );
        bad(
            GroomParams {
                clump_count: 10_000,
                ..small()
            },
            "clump_count",
        );
        let mut p = small();
        p.scalp.radii.y = 0.0;
        bad(p, "scalp.radii.y");
        bad(
            GroomParams {
                parting: Some(1.5),
                ..small()
            },
            "parting",
        );
    }

    #[test]
    fn default_groom_looks_like_hair() {
        let m = generate_groom(&GroomParams::default()).unwrap();
        let s = m.summary();
        eprintln!("default groom: {s}");
        assert_eq!((s.strands, s.points), (6000, 6000 * 24));
        // Hair hangs below the top of the head and spreads about a head's width.
        assert!(s.bounds.min.y < -10.0 && s.bounds.max.y < 12.0, "{s}");
        assert!(s.bounds.size().x > 15.0 && s.bounds.size().x < 40.0, "{s}");
    }
}
