//! Point-light lookup textures of the Chiang et al. 2016 fiber (`strandlight_tables::chiang`),
//! the far-field model the path-traced ground truth renders. Its width-averaged S factors,
//! lobe by lobe, into a longitudinal term of the two inclinations and an azimuthal term of the
//! view alone:
//!
//! `S · cos θ_i = Σ_{p=0}^{3} M_p(sin θ_i, sin θ_o) · N̄_p(cos φ, sin θ_o)`   (RGB),
//!
//! p = R, TT, TRT and the residual p ≥ 3. There is no 1/cos²θ_d and no division at all: the
//! shader's result is the radiance leaving the fiber per unit irradiance of the light.
//!
//! # Layout (what a shader needs, nothing more)
//!
//! Both tables are [`Table`]s: row-major, the last axis fastest, channels innermost. The
//! continuous axes are spaced uniformly in the **angle**, not in its sine or cosine (the
//! table's `AxisMapping`, which [`Table::gpu_axes`] hands to a shader as `warp`):
//!
//! * a `sin_theta_*` axis (mapping `Arcsine`) holds x = sin θ with θ uniform on [−π/2, π/2]:
//!   node k of n at `sin(−π/2 + π·k/(n − 1))`; a lookup at x has position
//!   `u = (asin(x) + π/2)/π · (n − 1)`;
//! * a `cos_phi` axis (mapping `Arccosine`) holds cos φ with φ uniform on [0, π] (node k at
//!   `cos(π − π·k/(n − 1))`, i.e. from cos φ = −1 up to 1); position
//!   `u = (π − acos(x))/π · (n − 1)`; a `cos_half_phi` axis (mapping `Uniform`) holds
//!   cos(φ/2) ∈ [0, 1], position `u = x·(n − 1)`.
//!
//! A lookup clamps u to [0, n − 1], takes the cell `i = min(floor(u), n − 2)` and weight `u − i`
//! on node i + 1, bilinearly over the two continuous axes; the third axis is an index, never
//! interpolated. Why angles: d'Eon's M_p grows toward the poles (its peak on the specular cone
//! rises from 1/√(2πv) at θ = 0 to 1/v at ±90°) over a width √v in θ, which a grid uniform in
//! sin θ covers with ever fewer nodes (at 128 nodes, 10° per cell at 80° against 1.4° here);
//! and N̄_R's fold at φ = π has a width s in φ, i.e. s²/2 in cos φ.
//!
//! * **`chiang_lut_m`** — axes `sin_theta_i` (u·ω_i, `LutResolution::sin_theta_i` nodes),
//!   `sin_theta_o` (u·ω_o, `sin_theta_o` nodes), `quantity` (4 nodes:
//!   0 = M_R, 1 = M_TT, 2 = M_TRT, 3 = M_residual); **1 channel**. Element
//!   `(i, j, q)` is at `(i·n_o + j)·4 + q`. M_p is d'Eon's longitudinal term (units 1/rad,
//!   `∫ M_p cos θ_i dθ_i = 1`) with the cuticle tilt applied for p ≤ 2 (its peak at
//!   θ_h = +α, −α/2, −2α) and none for the residual.
//! * **`chiang_lut_n`** — axes `cos_phi` (`LutResolution::azimuth` nodes; or `cos_half_phi` =
//!   cos(φ/2) = √(½(1 + cos φ)) when `LutResolution::azimuth_axis` says so — the axis's name
//!   tells which), `sin_theta_o` (u·ω_o, `sin_theta_o` nodes, the M table's count; the
//!   `cos_theta_d` count of [`LutResolution`] is not used), `lobe` (4 nodes: 0 = R,
//!   1 = TT, 2 = TRT, 3 = residual); **3 channels** (RGB). Element `(a, j, l, c)` is at
//!   `((a·n_o + j)·4 + l)·3 + c`. For l ≤ 2 it is `N̄_l = ½∫_{−1}^{1} A_l(h) N_l(φ − Φ(l, h)) dh`
//!   (units 1/rad); for l = 3 it is `½∫A_3 dh / (2π)`, the same at every azimuth node.
//!
//! # The shader
//!
//! With u the unit tangent (root to tip), ω_i toward the light, ω_o toward the viewer:
//! `s_i = u·ω_i`, `s_o = u·ω_o`, and `cos φ` = the cosine between the projections of ω_i and
//! ω_o on the plane normal to u (`dot(normalize(ω_i − s_i u), normalize(ω_o − s_o u))`, 1 where
//! a projection vanishes); cos(φ/2) = `sqrt(clamp(0.5 + 0.5 cos φ, 0, 1))` for a
//! `cos_half_phi` table. Then
//!
//! ```text
//! out = Σ_{p=0..3} bilinear(M, s_i, s_o)[p] · bilinear(N, azimuth, s_o)[p]     // RGB
//! radiance += E · out                     // E: the light's irradiance normal to its direction
//! ```
//!
//! Nothing in either table depends on the sign of φ (the model is even in φ) or needs θ_d.
//! [`reconstruct_chiang`] is exactly this on the CPU; [`check_chiang_luts`] measures it
//! against the model.

use crate::point_light_luts::{
    AzimuthAxis, LutAccuracy, LutError, LutResolution, stratified_points_for_lobes,
};
use rayon::prelude::*;
use strandlight_tables::angles::FiberAngles;
use strandlight_tables::chiang::{Chiang, LOBES};
use strandlight_tables::dual_scattering::LobeDecomposition;
use strandlight_tables::scattering::Rgb;
use strandlight_tables::table::{Axis, AxisMapping, Table, TableError};
use strandlight_tables::table_axes::{
    AXIS_LOBE, AXIS_QUANTITY, AXIS_SIN_THETA_I, AXIS_SIN_THETA_O,
};

/// Both lookup textures of one Chiang fiber.
#[derive(Debug, Clone, PartialEq)]
pub struct ChiangLuts {
    pub m: Table,
    pub n: Table,
}

impl ChiangLuts {
    pub fn bake(model: &Chiang, resolution: &LutResolution) -> Result<Self, LutError> {
        Ok(Self {
            m: bake_chiang_lut_m(model, resolution)?,
            n: bake_chiang_lut_n(model, resolution)?,
        })
    }

    /// S·cos θ_i at fiber angles, as the shader computes it.
    pub fn eval(&self, theta_i: f64, theta_o: f64, phi: f64) -> Result<Rgb, TableError> {
        reconstruct_chiang(&self.m, &self.n, theta_i.sin(), theta_o.sin(), phi.cos())
    }

    pub fn bytes(&self) -> usize {
        self.m.as_bytes().len() + self.n.as_bytes().len()
    }
}

/// The M texture: M_R, M_TT, M_TRT, M_residual over (sin θ_i, sin θ_o).
pub fn bake_chiang_lut_m(model: &Chiang, resolution: &LutResolution) -> Result<Table, LutError> {
    resolution.validate()?;
    let axes = vec![
        sine_axis(AXIS_SIN_THETA_I, resolution.sin_theta_i),
        sine_axis(AXIS_SIN_THETA_O, resolution.sin_theta_o),
        Axis::uniform(AXIS_QUANTITY, 0.0, (LOBES - 1) as f64, LOBES),
    ];
    let table = Table::from_fn(axes, 1, |x, out| {
        let theta_i = x[0].clamp(-1.0, 1.0).asin();
        let theta_o = x[1].clamp(-1.0, 1.0).asin();
        let p = (x[2].round() as usize).min(LOBES - 1);
        out[0] = model.longitudinal(p, theta_i, theta_o) as f32;
    })?;
    refuse_non_finite("chiang_lut_m", table)
}

/// The N texture: N̄_R, N̄_TT, N̄_TRT, N̄_residual (RGB) over (cos φ or cos(φ/2), sin θ_o), each
/// node integrated over the fiber's width by quadrature (not read from the model's own grid).
pub fn bake_chiang_lut_n(model: &Chiang, resolution: &LutResolution) -> Result<Table, LutError> {
    resolution.validate()?;
    let azimuth = resolution.azimuth_axis;
    let azimuth_axis = match azimuth {
        AzimuthAxis::CosPhi => Axis::with_mapping(
            azimuth.name(),
            -1.0,
            1.0,
            resolution.azimuth,
            AxisMapping::Arccosine,
        ),
        AzimuthAxis::CosHalfPhi => Axis::uniform(azimuth.name(), 0.0, 1.0, resolution.azimuth),
    };
    let axes = vec![
        azimuth_axis,
        sine_axis(AXIS_SIN_THETA_O, resolution.sin_theta_o),
        Axis::uniform(AXIS_LOBE, 0.0, (LOBES - 1) as f64, LOBES),
    ];
    let (na, no) = (resolution.azimuth, resolution.sin_theta_o);
    let (az_axis, o_axis) = (axes[0].clone(), axes[1].clone());
    let values: Vec<f32> = (0..na * no)
        .into_par_iter()
        .flat_map_iter(|k| {
            let phi = azimuth.phi(az_axis.node(k / no));
            let theta_o = o_axis.node(k % no).clamp(-1.0, 1.0).asin();
            let n = model.azimuthal_exact(theta_o, phi);
            n.into_iter().flatten().map(|v| v as f32)
        })
        .collect();
    refuse_non_finite("chiang_lut_n", Table::new(axes, 3, values)?)
}

/// A sine axis over [−1, 1] with nodes uniform in the angle.
fn sine_axis(name: &str, count: usize) -> Axis {
    Axis::with_mapping(name, -1.0, 1.0, count, AxisMapping::Arcsine)
}

fn refuse_non_finite(name: &'static str, table: Table) -> Result<Table, LutError> {
    match table.stats().first_non_finite {
        None => Ok(table),
        Some((node, channel)) => Err(LutError::NonFinite {
            table: name,
            node,
            channel,
        }),
    }
}

/// S·cos θ_i from the two tables exactly as the shader computes it (see the module docs):
/// `sin_theta_i = u·ω_i`, `sin_theta_o = u·ω_o`, `cos_phi` between the projections.
/// Out-of-range inputs clamp to the texture edge; NaN is an error naming the axis.
pub fn reconstruct_chiang(
    lut_m: &Table,
    lut_n: &Table,
    sin_theta_i: f64,
    sin_theta_o: f64,
    cos_phi: f64,
) -> Result<Rgb, TableError> {
    let azimuth = AzimuthAxis::of_table(lut_n)?.coordinate(cos_phi);
    let mut s = [0.0; 3];
    for p in 0..LOBES {
        let m = lut_m.lookup_scalar(&[sin_theta_i, sin_theta_o, p as f64])? as f64;
        let n = lut_n.lookup_rgb(&[azimuth, sin_theta_o, p as f64])?;
        for c in 0..3 {
            s[c] += m * n[c] as f64;
        }
    }
    Ok(s)
}

/// The stratified points of [`stratified_points_for_lobes`] with Chiang's lobes (shift α_p,
/// width √v_p/2 in θ_h).
pub fn chiang_points(
    model: &Chiang,
    count: usize,
    max_inclination: f64,
    seed: u64,
) -> Vec<FiberAngles> {
    let lobes = [0, 1, 2].map(|p| model.lobe_shift_width(p));
    stratified_points_for_lobes(lobes, count, max_inclination, seed)
}

/// Accuracy of the reconstructed S·cos θ_i against the model's (its own N̄ grid, within
/// 1.3·10⁻⁴ of the quadrature at the default roughness); the same measures as
/// [`crate::point_light_luts::check_luts`], on S·cos θ_i (what the shader returns; S itself
/// grows like 1/cos θ_i toward the poles).
pub fn check_chiang_luts(
    name: &str,
    luts: &ChiangLuts,
    model: &Chiang,
    points: &[FiberAngles],
) -> Result<LutAccuracy, TableError> {
    let pairs: Vec<(Rgb, Rgb)> = points
        .par_iter()
        .map(|a| {
            Ok((
                luts.eval(a.theta_i, a.theta_o, a.phi)?,
                model.eval_cos_weighted(a),
            ))
        })
        .collect::<Result<_, TableError>>()?;
    Ok(LutAccuracy::of_pairs(name, &pairs, points))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{FRAC_PI_2, PI};
    use strandlight_tables::chiang::ChiangParams;

    fn brown() -> Chiang {
        Chiang::new(ChiangParams::default()).unwrap()
    }

    #[test]
    fn tables_hold_the_model_at_their_nodes() {
        let model = brown();
        let res = LutResolution::square(9);
        let luts = ChiangLuts::bake(&model, &res).unwrap();
        assert_eq!(luts.m.shape(), vec![9, 9, 4]);
        assert_eq!(luts.n.shape(), vec![9, 9, 4]);
        assert_eq!(luts.n.channels(), 3);
        let angle = |i: usize| -FRAC_PI_2 + PI * i as f64 / 8.0;
        for i in 0..9 {
            for j in 0..9 {
                let (ti, to) = (angle(i), angle(j));
                for p in 0..4 {
                    let m = luts.m.node(&[i, j, p]).unwrap()[0] as f64;
                    let want = model.longitudinal(p, ti, to);
                    assert!((m - want).abs() <= 1e-6 * want.abs() + 1e-30, "M_{p}");
                    let phi = PI - PI * i as f64 / 8.0;
                    let n = luts.n.node(&[i, j, p]).unwrap();
                    let want = model.azimuthal_exact(to, phi)[p];
                    for c in 0..3 {
                        assert!(
                            (n[c] as f64 - want[c]).abs() <= 1e-6 * want[c].abs() + 1e-30,
                            "N̄_{p} at ({i}, {j}): {} vs {}",
                            n[c],
                            want[c]
                        );
                    }
                }
            }
        }
        // The residual is the same at every azimuth.
        for a in 1..9 {
            assert_eq!(
                luts.n.node(&[a, 4, 3]).unwrap(),
                luts.n.node(&[0, 4, 3]).unwrap()
            );
        }
    }

    fn accuracy(model: &Chiang, n: usize, limit_deg: f64, axis: AzimuthAxis) -> LutAccuracy {
        let res = LutResolution {
            azimuth_axis: axis,
            ..LutResolution::square(n)
        };
        let luts = ChiangLuts::bake(model, &res).unwrap();
        let points = chiang_points(model, 8000, limit_deg.to_radians(), 5);
        check_chiang_luts("brown", &luts, model, &points).unwrap()
    }

    /// The default 128² textures against the model, and the error falling with size. Bilinear
    /// interpolation is second order: 4× less error per doubling where the function is smooth
    /// (demanded: 2.5× in RMS). Measured at 128², |θ| ≤ 80°: max 4.0·10⁻³, RMS 4.1·10⁻⁴ of
    /// the largest S·cos θ_i, the worst beside the TT peak (φ ≈ 175°); the bounds leave ~3×.
    #[test]
    fn error_is_reported_bounded_and_falls_with_size() {
        let model = brown();
        for (limit, axis, rms_bound, max_bound) in [
            (60.0, AzimuthAxis::CosPhi, 2e-3, 1.5e-2),
            (80.0, AzimuthAxis::CosPhi, 2e-3, 1.5e-2),
            (90.0, AzimuthAxis::CosPhi, 2e-3, 1.5e-2),
            (90.0, AzimuthAxis::CosHalfPhi, 2e-3, 1.5e-2),
        ] {
            let mut previous: Option<LutAccuracy> = None;
            for n in [32, 64, 128] {
                let acc = accuracy(&model, n, limit, axis);
                let w = acc.worst_point.map(f64::to_degrees);
                eprintln!(
                    "chiang {n}² |θ| ≤ {limit}° {axis:?}: max {:.2e} rms {:.2e} max rel {:.2e} of S·cos θ_i (max {:.3}; worst at θ_i {:.1}°, θ_o {:.1}°, φ {:.1}°)",
                    acc.max_abs_error,
                    acc.rms_abs_error,
                    acc.max_rel_error,
                    acc.reference_max,
                    w[0],
                    w[1],
                    w[2]
                );
                if let Some(prev) = &previous {
                    assert!(acc.rms_abs_error * 2.5 < prev.rms_abs_error, "{n}");
                }
                if n == 128 {
                    assert!(
                        acc.rms_abs_error < rms_bound && acc.max_abs_error < max_bound,
                        "{acc:?}"
                    );
                }
                previous = Some(acc);
            }
        }
    }

    #[test]
    fn extreme_fibers_give_finite_non_negative_values_everywhere() {
        let fibers = [
            ChiangParams::with_preset("white").unwrap(),
            ChiangParams::with_preset("dark").unwrap(),
            ChiangParams {
                sigma_a: Some([1e4; 3]),
                ..ChiangParams::default()
            },
            ChiangParams {
                longitudinal_roughness: 0.01,
                azimuthal_roughness: 1.0,
                scale_tilt_degrees: 30.0,
                ..ChiangParams::default()
            },
            ChiangParams {
                longitudinal_roughness: 1.0,
                azimuthal_roughness: 0.02,
                ior: 2.5,
                ..ChiangParams::default()
            },
        ];
        let coords: Vec<f64> = (0..=20)
            .map(|k| -1.0 + k as f64 / 10.0)
            .chain([-1.5, 1.5, 0.99999])
            .collect();
        for params in fibers {
            let model = Chiang::new(params.clone()).unwrap();
            let luts = ChiangLuts::bake(&model, &LutResolution::square(24)).unwrap();
            for t in [&luts.m, &luts.n] {
                let s = t.stats();
                assert_eq!((s.nan_count, s.infinite_count), (0, 0), "{params:?}");
                assert!(s.min >= 0.0, "{params:?}: {}", s.min);
            }
            for &si in &coords {
                for &so in &coords {
                    for &cp in &coords {
                        let s = reconstruct_chiang(&luts.m, &luts.n, si, so, cp).unwrap();
                        assert!(s.iter().all(|v| v.is_finite() && *v >= 0.0), "{params:?}");
                    }
                }
            }
        }
        // NaN inputs are errors naming the axis.
        let luts = ChiangLuts::bake(&brown(), &LutResolution::square(8)).unwrap();
        let err = luts.eval(f64::NAN, 0.1, 0.2).unwrap_err();
        assert!(err.to_string().contains("sin_theta_i"), "{err}");
        let err = luts.eval(0.1, 0.2, f64::NAN).unwrap_err();
        assert!(err.to_string().contains("cos_phi"), "{err}");
        // Evenness in φ survives the cos φ parameterisation.
        let (a, b) = (
            luts.eval(0.3, -0.2, 1.0).unwrap(),
            luts.eval(0.3, -0.2, -1.0).unwrap(),
        );
        assert_eq!(a, b);
        assert!(luts.eval(0.3, -0.2, PI).unwrap()[0] > 0.0);
    }
}
