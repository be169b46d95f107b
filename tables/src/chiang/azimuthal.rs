//! The azimuthal half of the Chiang model: the attenuations A_p of one path through the fiber's
//! cross section, the trimmed logistic N_p around the specular azimuth Φ(p, h), and their
//! average over the fiber's width,
//!
//! `N̄_p(θ_o, φ) = ½ ∫_{−1}^{1} A_p(θ_o, h) N_p(Δφ − Φ(p, h)) dh`   (p = 0, 1, 2),
//! `N̄_3(θ_o)    = ½ ∫_{−1}^{1} A_3(θ_o, h) dh / (2π)`               (the residual),
//!
//! with Δφ = φ_light − φ_view (Mitsuba's and pbrt's `phi`; N̄ is even in it, so the sign of
//! the project's φ = φ_o − φ_i does not matter here).
//!
//! **Quadrature** ([`azimuthal_exact`]). The integral is taken over γ = asin h (dh = cos γ dγ),
//! where every factor is smooth: A_p has √(1 − h²) edges in h but not in γ. The peaks of
//! N_p(Δφ − Φ(p, γ)) sit at the roots of Φ(p, γ) ≡ Δφ (mod 2π): Φ is monotone in γ for
//! p = 0, 1 and has two caustic extrema at sin γ = ±√((4 − η′²)/3) for p = 2 (η′ < 2), so each
//! monotone piece is searched for roots by safeguarded Newton steps, and the rule gets
//! breakpoints at root ± w·{1, 3, 8, 20, 50} with w the peak's width in γ
//! (min(s/|Φ′|, √(2s/|Φ″|))), one 8-point Gauss–Legendre panel per gap (gaps wider than π/8
//! are split). Beyond 50 widths the logistic is below e⁻⁵⁰ of its peak. The tests compare
//! the rule with a uniform composite rule of 20 000 panels.
//!
//! **Table** ([`AzimuthalTable`]). The far-field S needs N̄ at every (θ_o, φ) of a bake; the
//! table holds N̄ on a uniform grid over θ_o ∈ [0, π/2] × φ ∈ [0, π] (N̄ is even in both) and
//! interpolates it bicubically (Catmull–Rom, mirrored across θ_o = 0, φ = 0 and φ = π,
//! extrapolated linearly past θ_o = π/2). The φ spacing follows the logistic scale s (features
//! of N̄ are never narrower than s: the R lobe's kink at φ = π and the TRT caustics are
//! smoothed to that width), see [`AzimuthalResolution::for_scale`].

use crate::quadrature::GaussLegendre;
use crate::scattering::Rgb;
use rayon::prelude::*;
use std::f64::consts::{FRAC_PI_2, PI};
use std::sync::OnceLock;

/// Number of lobes with an azimuthal distribution (R, TT, TRT); the residual is uniform in φ.
pub const P_MAX: usize = 3;

/// Unpolarized Fresnel reflectance of a dielectric of relative index `eta` > 1, light arriving
/// from outside at `cos_i` ∈ [0, 1] (1 at grazing incidence).
pub fn fresnel_dielectric(cos_i: f64, eta: f64) -> f64 {
    let cos_i = cos_i.clamp(0.0, 1.0);
    if cos_i == 0.0 {
        return 1.0;
    }
    let sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
    let cos_t = (1.0 - sin2_t).max(0.0).sqrt();
    let r_s = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    let r_p = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    0.5 * (r_s * r_s + r_p * r_p)
}

/// The trimmed logistic of scale `s` on [−π, π] (Chiang 2016 eq. 12), at an offset already
/// wrapped into [−π, π]: `e^{−|x|/s} / (s (1 + e^{−|x|/s})²) / tanh(π/(2s))`, the last factor
/// being the logistic's mass inside [−π, π].
pub fn trimmed_logistic(x: f64, s: f64) -> f64 {
    let e = (-x.abs() / s).exp();
    e / (s * (1.0 + e) * (1.0 + e)) / (PI / (2.0 * s)).tanh()
}

/// `x` wrapped into [−π, π].
pub fn wrap_pi(x: f64) -> f64 {
    x - 2.0 * PI * (x / (2.0 * PI)).round()
}

/// The view-dependent quantities of one inclination θ_o: everything the attenuations and the
/// specular azimuths need besides the offset γ.
#[derive(Debug, Clone, Copy)]
pub struct ViewGeometry {
    pub eta: f64,
    pub cos_o: f64,
    /// cos θ_t of the refracted ray (Bravais: sin θ_t = sin θ_o / η), never below √(1 − 1/η²).
    pub cos_theta_t: f64,
    /// 1/η′ = cos θ_o / √(η² − sin²θ_o), so that sin γ_t = h/η′ without dividing by cos θ_o
    /// (0 at grazing, where η′ → ∞).
    pub inv_eta_p: f64,
}

impl ViewGeometry {
    pub fn new(eta: f64, theta_o: f64) -> Self {
        Self::from_sin_cos(eta, theta_o.sin(), theta_o.cos().max(0.0))
    }

    /// From sin θ_o and cos θ_o ≥ 0 (as Mitsuba derives them from a direction).
    pub fn from_sin_cos(eta: f64, sin_o: f64, cos_o: f64) -> Self {
        let sin_t = sin_o / eta;
        Self {
            eta,
            cos_o,
            cos_theta_t: (1.0 - sin_t * sin_t).max(0.0).sqrt(),
            inv_eta_p: cos_o / (eta * eta - sin_o * sin_o).max(f64::MIN_POSITIVE).sqrt(),
        }
    }

    /// γ_t, the refracted offset angle, at sin γ = `h`.
    #[inline]
    pub fn gamma_t(&self, h: f64) -> f64 {
        (h * self.inv_eta_p).clamp(-1.0, 1.0).asin()
    }

    /// A_p for p = 0, 1, 2 and the residual p ≥ 3 (index 3) at offset h, per channel:
    /// `A_0 = f`, `A_1 = (1−f)² T`, `A_2 = A_1 T f`, `A_3 = A_2 f T / (1 − f T)` with f the
    /// Fresnel reflectance at cos θ_o cos γ and `T = exp(−σ_a 2 cos γ_t / cos θ_t)`.
    pub fn attenuations(&self, h: f64, sigma_a: &Rgb) -> [Rgb; 4] {
        let cos_gamma = (1.0 - h * h).max(0.0).sqrt();
        let f = fresnel_dielectric(self.cos_o * cos_gamma, self.eta);
        let sin_gamma_t = h * self.inv_eta_p;
        let cos_gamma_t = (1.0 - sin_gamma_t * sin_gamma_t).max(0.0).sqrt();
        let length = 2.0 * cos_gamma_t / self.cos_theta_t;
        let mut a = [[0.0; 3]; 4];
        for c in 0..3 {
            // σ_a is finite (validated), the length finite and ≥ 0: T ∈ [0, 1].
            let t = (-sigma_a[c] * length).exp();
            let a1 = (1.0 - f) * (1.0 - f) * t;
            let a2 = a1 * t * f;
            let ft = f * t;
            a[0][c] = f;
            a[1][c] = a1;
            a[2][c] = a2;
            // 1 − fT vanishes only where f = T = 1 (white fiber, grazing), where A_2 = 0 too.
            a[3][c] = if a2 > 0.0 { a2 * ft / (1.0 - ft) } else { 0.0 };
        }
        a
    }

    /// Φ(p, γ) = 2pγ_t − 2γ + pπ.
    #[inline]
    pub fn specular_azimuth(&self, p: usize, gamma: f64) -> f64 {
        let pf = p as f64;
        2.0 * pf * self.gamma_t(gamma.sin()) - 2.0 * gamma + pf * PI
    }

    /// dΦ/dγ = 2p cos γ/(η′ cos γ_t) − 2.
    #[inline]
    fn specular_azimuth_slope(&self, p: usize, gamma: f64) -> f64 {
        let k = self.inv_eta_p;
        let sg = gamma.sin();
        let cos_gt = (1.0 - k * k * sg * sg).max(f64::MIN_POSITIVE).sqrt();
        2.0 * p as f64 * k * gamma.cos() / cos_gt - 2.0
    }

    /// d²Φ/dγ² = 2p k sin γ (k² − 1)/cos³γ_t, k = 1/η′.
    #[inline]
    fn specular_azimuth_curvature(&self, p: usize, gamma: f64) -> f64 {
        let k = self.inv_eta_p;
        let sg = gamma.sin();
        let cos_gt = (1.0 - k * k * sg * sg).max(f64::MIN_POSITIVE).sqrt();
        2.0 * p as f64 * k * sg * (k * k - 1.0) / (cos_gt * cos_gt * cos_gt)
    }

    /// The offsets γ ∈ (0, π/2) of the TRT caustics (dΦ/dγ = 0), if η′ < 2.
    fn trt_caustic(&self) -> Option<f64> {
        let k2 = self.inv_eta_p * self.inv_eta_p;
        if 4.0 * k2 <= 1.0 {
            return None;
        }
        let sin2 = ((4.0 * k2 - 1.0) / (3.0 * k2)).clamp(0.0, 1.0);
        Some(sin2.sqrt().asin())
    }
}

/// The 8-point Gauss–Legendre rule on [−1, 1].
fn gl8() -> &'static GaussLegendre {
    static RULE: OnceLock<GaussLegendre> = OnceLock::new();
    RULE.get_or_init(|| GaussLegendre::new(8, -1.0, 1.0))
}

/// Multiples of a peak's width at which the rule is cut.
const PEAK_CUTS: [f64; 6] = [0.0, 1.0, 3.0, 8.0, 20.0, 50.0];
/// Longest gap one 8-point panel covers where the integrand is smooth (A_p cos γ, tails).
const MAX_PANEL: f64 = PI / 8.0;

/// The monotone pieces of Φ(p, ·) over [−π/2, π/2].
fn monotone_pieces(geom: &ViewGeometry, p: usize) -> Vec<(f64, f64)> {
    match (p, geom.trt_caustic()) {
        (2, Some(gc)) if gc > 1e-9 && gc < FRAC_PI_2 - 1e-9 => {
            vec![(-FRAC_PI_2, -gc), (-gc, gc), (gc, FRAC_PI_2)]
        }
        _ => vec![(-FRAC_PI_2, FRAC_PI_2)],
    }
}

/// γ in [a, b] with Φ(p, γ) = target, Φ monotone there and target between its end values:
/// Newton steps kept inside a shrinking bracket (bisection when a step leaves it).
fn solve_monotone(geom: &ViewGeometry, p: usize, a: f64, b: f64, target: f64) -> f64 {
    let fa = geom.specular_azimuth(p, a) - target;
    let (mut lo, mut hi) = if fa <= 0.0 { (a, b) } else { (b, a) };
    // Invariant: Φ(lo) − target ≤ 0 ≤ Φ(hi) − target.
    let mut x = 0.5 * (a + b);
    for _ in 0..100 {
        let f = geom.specular_azimuth(p, x) - target;
        if f == 0.0 {
            return x;
        }
        if f < 0.0 {
            lo = x;
        } else {
            hi = x;
        }
        let d = geom.specular_azimuth_slope(p, x);
        let newton = x - f / d;
        let inside = (newton - lo) * (newton - hi) < 0.0;
        let next = if inside && d != 0.0 {
            newton
        } else {
            0.5 * (lo + hi)
        };
        if (next - x).abs() < 1e-14 || (hi - lo).abs() < 1e-14 {
            return next;
        }
        x = next;
    }
    x
}

/// Breakpoints of lobe p's integrand in γ for the azimuth offset `dphi` (Mitsuba's Δφ).
fn breakpoints(geom: &ViewGeometry, p: usize, dphi: f64, s: f64) -> Vec<f64> {
    let mut cuts = vec![-FRAC_PI_2, FRAC_PI_2];
    let reach = 50.0 * s;
    for (a, b) in monotone_pieces(geom, p) {
        cuts.push(a);
        cuts.push(b);
        let (pa, pb) = (geom.specular_azimuth(p, a), geom.specular_azimuth(p, b));
        let (lo, hi) = (pa.min(pb), pa.max(pb));
        let j_min = ((lo - reach - dphi) / (2.0 * PI)).ceil() as i64;
        let j_max = ((hi + reach - dphi) / (2.0 * PI)).floor() as i64;
        // The wrapped logistic has a kink where the offset is ±π: a plain cut at each root.
        let k_min = ((lo - dphi - PI) / (2.0 * PI)).ceil() as i64;
        let k_max = ((hi - dphi - PI) / (2.0 * PI)).floor() as i64;
        for k in k_min..=k_max {
            let target = dphi + PI + 2.0 * PI * k as f64;
            cuts.push(solve_monotone(geom, p, a, b, target));
        }
        for j in j_min..=j_max {
            let target = dphi + 2.0 * PI * j as f64;
            // A target just past the piece's range peaks at its end.
            let root = if target <= lo {
                if pa <= pb { a } else { b }
            } else if target >= hi {
                if pa >= pb { a } else { b }
            } else {
                solve_monotone(geom, p, a, b, target)
            };
            let slope = geom.specular_azimuth_slope(p, root).abs();
            let curvature = geom.specular_azimuth_curvature(p, root).abs();
            let w = (s / slope.max(1e-300))
                .min((2.0 * s / curvature.max(1e-300)).sqrt())
                .clamp(1e-12, PI);
            for m in PEAK_CUTS {
                cuts.push(root - m * w);
                cuts.push(root + m * w);
            }
        }
    }
    let mut cuts: Vec<f64> = cuts
        .into_iter()
        .filter(|x| x.is_finite() && (-FRAC_PI_2..=FRAC_PI_2).contains(x))
        .collect();
    cuts.sort_by(|x, y| x.total_cmp(y));
    cuts.dedup_by(|x, y| (*x - *y).abs() < 1e-15);
    cuts
}

/// Calls `f(x, w)` for every node x and weight w of the rule with one or more 8-point panels
/// per gap between consecutive cuts.
fn for_each_node(cuts: &[f64], mut f: impl FnMut(f64, f64)) {
    let rule = gl8();
    for w in cuts.windows(2) {
        let (a, b) = (w[0], w[1]);
        let panels = ((b - a) / MAX_PANEL).ceil().max(1.0) as usize;
        let step = (b - a) / panels as f64;
        for k in 0..panels {
            let (mid, half) = (a + (k as f64 + 0.5) * step, 0.5 * step);
            for (&x, &wt) in rule.nodes.iter().zip(&rule.weights) {
                f(mid + half * x, wt * half);
            }
        }
    }
}

/// N̄_p for p = 0, 1, 2 and the residual's ½∫A_3 dh/(2π) (index 3), per channel, at one
/// inclination and azimuth offset, by the breakpoint rule of the module docs.
pub fn azimuthal_exact(geom: &ViewGeometry, sigma_a: &Rgb, s: f64, dphi: f64) -> [Rgb; 4] {
    let [r, tt, trt] = azimuthal_lobes(geom, sigma_a, s, dphi);
    [r, tt, trt, residual_exact(geom, sigma_a)]
}

/// ½∫A_3 dh / (2π) per channel: A_3 is smooth in γ; 16 panels of 8 nodes.
pub fn residual_exact(geom: &ViewGeometry, sigma_a: &Rgb) -> Rgb {
    let cuts: Vec<f64> = (0..=16)
        .map(|k| -FRAC_PI_2 + PI * k as f64 / 16.0)
        .collect();
    let mut out = [0.0; 3];
    for_each_node(&cuts, |gamma, w| {
        let a = geom.attenuations(gamma.sin(), sigma_a)[3];
        for c in 0..3 {
            out[c] += 0.5 / (2.0 * PI) * w * a[c] * gamma.cos();
        }
    });
    out
}

/// N̄_p of the three lobes, all channels at once (they share the rule and the attenuations).
pub fn azimuthal_lobes(geom: &ViewGeometry, sigma_a: &Rgb, s: f64, dphi: f64) -> [Rgb; 3] {
    let mut out = [[0.0; 3]; 3];
    for (p, out_p) in out.iter_mut().enumerate() {
        let cuts = breakpoints(geom, p, dphi, s);
        for_each_node(&cuts, |gamma, w| {
            let n = trimmed_logistic(wrap_pi(dphi - geom.specular_azimuth(p, gamma)), s);
            if n == 0.0 {
                return;
            }
            let a = geom.attenuations(gamma.sin(), sigma_a)[p];
            let k = 0.5 * w * n * gamma.cos();
            for c in 0..3 {
                out_p[c] += k * a[c];
            }
        });
    }
    out
}

/// Grid sizes of an [`AzimuthalTable`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AzimuthalResolution {
    /// Nodes over θ_o ∈ [0, π/2] (θ = (π/2) sin((π/2)u), u uniform).
    pub theta: usize,
    /// Nodes over φ ∈ [0, π].
    pub phi: usize,
}

/// Most φ nodes the automatic choice takes (N̄ of azimuthal roughness below ≈ 0.04 has
/// features narrower than π/4096 / 0.25 and is interpolated less accurately; see the tests).
pub const MAX_PHI_NODES: usize = 4097;

impl AzimuthalResolution {
    /// The default for logistic scale `s`: 46 θ_o nodes (3.1° apart at normal views, 0.06° at
    /// grazing) and φ steps of s/4
    /// (at least 181 nodes, 1°, at most [`MAX_PHI_NODES`]). Measured in the tests: the
    /// interpolation error is below 10⁻³ of the lobe's maximum at the default roughness.
    pub fn for_scale(s: f64) -> Self {
        let phi = ((PI / (0.25 * s)).ceil() as usize + 1).clamp(181, MAX_PHI_NODES);
        Self { theta: 46, phi }
    }

    /// `factor` times the intervals on both axes.
    pub fn refined(self, factor: usize) -> Self {
        Self {
            theta: (self.theta - 1) * factor + 1,
            phi: (self.phi - 1) * factor + 1,
        }
    }
}

/// N̄_p (p = 0, 1, 2) on a (θ_o, φ) grid and N̄_3 on the θ_o grid, interpolated bicubically.
#[derive(Debug, Clone)]
pub struct AzimuthalTable {
    resolution: AzimuthalResolution,
    /// `[theta][phi] -> [lobe][channel]`, row-major.
    lobes: Vec<[Rgb; 3]>,
    residual: Vec<Rgb>,
}

impl AzimuthalTable {
    /// Fills every node with [`azimuthal_lobes`] (in parallel over θ_o).
    pub fn new(eta: f64, sigma_a: &Rgb, s: f64, resolution: AzimuthalResolution) -> Self {
        let (nt, np) = (resolution.theta.max(4), resolution.phi.max(4));
        let resolution = AzimuthalResolution { theta: nt, phi: np };
        let rows: Vec<(Vec<[Rgb; 3]>, Rgb)> = (0..nt)
            .into_par_iter()
            .map(|i| {
                let geom = ViewGeometry::new(eta, theta_node(i, nt));
                let row = (0..np)
                    .map(|j| azimuthal_lobes(&geom, sigma_a, s, phi_node(j, np)))
                    .collect();
                (row, residual_exact(&geom, sigma_a))
            })
            .collect();
        let mut lobes = Vec::with_capacity(nt * np);
        let mut residual = Vec::with_capacity(nt);
        for (row, r) in rows {
            lobes.extend(row);
            residual.push(r);
        }
        Self {
            resolution,
            lobes,
            residual,
        }
    }

    pub fn resolution(&self) -> AzimuthalResolution {
        self.resolution
    }

    /// N̄_0..2 and N̄_3 at any θ_o (even; clamped to |θ_o| ≤ π/2) and φ (even, 2π-periodic).
    pub fn at(&self, theta_o: f64, phi: f64) -> [Rgb; 4] {
        let (nt, np) = (self.resolution.theta, self.resolution.phi);
        let t = theta_position(theta_o) * (nt - 1) as f64;
        let f = (wrap_pi(phi).abs() / PI) * (np - 1) as f64;
        let (it, ft) = cell(t, nt);
        let (ip, fp) = cell(f, np);
        let wt = catmull_rom_weights(ft);
        let wp = catmull_rom_weights(fp);
        let mut out = [[0.0; 3]; 4];
        for (a, &wa) in wt.iter().enumerate() {
            let ti = mirrored_index(it as isize - 1 + a as isize, nt);
            let row = &self.lobes[ti * np..(ti + 1) * np];
            for (b, &wb) in wp.iter().enumerate() {
                let v = &row[mirrored_index(ip as isize - 1 + b as isize, np)];
                let w = wa * wb;
                for l in 0..3 {
                    for c in 0..3 {
                        out[l][c] += w * v[l][c];
                    }
                }
            }
            for (o, r) in out[3].iter_mut().zip(&self.residual[ti]) {
                *o += wa * r;
            }
        }
        for lobe in out.iter_mut() {
            for v in lobe.iter_mut() {
                *v = v.max(0.0);
            }
        }
        out
    }
}

/// θ_o node i of n: θ = (π/2) sin((π/2) u), u = i/(n − 1) uniform. The spacing shrinks
/// quadratically toward grazing views, where N̄ changes fastest (the Fresnel factor tends to 1
/// and η′ to ∞); θ(u) is odd about u = 0 and even about u = 1, so mirrored ghost nodes are
/// exact at both ends.
fn theta_node(i: usize, n: usize) -> f64 {
    FRAC_PI_2 * (FRAC_PI_2 * i as f64 / (n - 1) as f64).sin()
}

/// u ∈ [0, 1] of |θ_o| on that grid.
fn theta_position(theta_o: f64) -> f64 {
    (theta_o.abs() / FRAC_PI_2).min(1.0).asin() / FRAC_PI_2
}

fn phi_node(j: usize, n: usize) -> f64 {
    PI * j as f64 / (n - 1) as f64
}

/// Lower node and fraction of position `u` ∈ [0, n − 1].
fn cell(u: f64, n: usize) -> (usize, f64) {
    let i = (u.floor().max(0.0) as usize).min(n - 2);
    (i, (u - i as f64).clamp(0.0, 1.0))
}

/// Node k of n, mirrored across both ends (φ = 0 and π: N̄ is even and 2π-periodic; θ_o:
/// see [`theta_node`]).
fn mirrored_index(k: isize, n: usize) -> usize {
    let last = (n - 1) as isize;
    let k = k.abs();
    (if k > last { 2 * last - k } else { k }) as usize
}

/// Catmull–Rom weights of the four nodes around a cell at fraction t.
fn catmull_rom_weights(t: f64) -> [f64; 4] {
    let t2 = t * t;
    let t3 = t2 * t;
    [
        0.5 * (-t3 + 2.0 * t2 - t),
        0.5 * (3.0 * t3 - 5.0 * t2 + 2.0),
        0.5 * (-3.0 * t3 + 4.0 * t2 + t),
        0.5 * (t3 - t2),
    ]
}
