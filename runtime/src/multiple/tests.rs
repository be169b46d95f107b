//! Voxelization and shadow paths against closed forms on synthetic hair, with hand-made tables
//! (constant ā_f, β̄_f², SRBF variance; α(0, θ) = cos θ), independent of the bake.

use glam::Vec3;
use strandlight_tables::table::{Axis, AxisMapping, Table};
use strandlight_tables::table_axes::{
    AXIS_ABS_SIN_THETA, AXIS_ABS_U_DOT_XI, AXIS_LAMBDA, AXIS_NU, AXIS_QUANTITY, AXIS_SIN_THETA,
};

use super::*;
use crate::env_light::EnvLight;
use crate::hair::{Attribute, HairModel};
use crate::multiple::ForwardScatteringSource;

const A_F: [f64; 3] = [0.9, 0.6, 0.3];
const BETA2_F: f64 = 0.01;
const SRBF_VARIANCE: f64 = 0.02;

fn tables() -> ForwardScatteringTables {
    let fiber = Table::from_fn(
        vec![
            Axis::with_mapping(AXIS_SIN_THETA, -1.0, 1.0, 33, AxisMapping::Arcsine),
            Axis::uniform(AXIS_QUANTITY, 0.0, 8.0, 9),
        ],
        3,
        |x, out| {
            for c in 0..3 {
                out[c] = match x[1].round() as usize {
                    0 => A_F[c] as f32,
                    4 => BETA2_F as f32,
                    _ => 0.0,
                };
            }
        },
    )
    .unwrap();
    // α(ν, θ) = cos θ: exact for aligned fibers, used for ν ≈ 0 layouts only.
    let ratio = Table::from_fn(
        vec![
            Axis::uniform(AXIS_NU, 0.0, 1.0, 5),
            Axis::with_mapping(AXIS_ABS_SIN_THETA, 0.0, 1.0, 65, AxisMapping::Arcsine),
        ],
        1,
        |x, out| out[0] = (1.0 - x[1] * x[1]).max(0.0).sqrt() as f32,
    )
    .unwrap();
    let spread = Table::from_fn(
        vec![
            Axis::with_mapping(AXIS_ABS_U_DOT_XI, 0.0, 1.0, 9, AxisMapping::Arcsine),
            Axis::uniform(AXIS_LAMBDA, 4.0, 400.0, 9),
        ],
        1,
        |_, out| out[0] = SRBF_VARIANCE as f32,
    )
    .unwrap();
    ForwardScatteringTables::from_tables(&fiber, &ratio, &spread).unwrap()
}

/// `strands` random walks of `points` points with isotropic steps of length `step`, starting
/// uniformly in an 8-cube, fibers of diameter `diameter`.
fn tangled_hair(
    rng: &mut Rng,
    strands: usize,
    points: usize,
    step: f32,
    diameter: f32,
) -> HairModel {
    let mut positions = Vec::new();
    let mut offsets = vec![0u32];
    for _ in 0..strands {
        let mut p = Vec3::new(rng.unit() as f32, rng.unit() as f32, rng.unit() as f32) * 8.0;
        for _ in 0..points {
            positions.push(p);
            let z = 2.0 * rng.unit() - 1.0;
            let a = 2.0 * std::f64::consts::PI * rng.unit();
            let s = (1.0 - z * z).sqrt();
            p += step * Vec3::new((s * a.cos()) as f32, (s * a.sin()) as f32, z as f32);
        }
        offsets.push(positions.len() as u32);
    }
    HairModel::new(
        positions,
        offsets,
        Some(Attribute::Uniform(diameter)),
        None,
        None,
    )
    .unwrap()
}

/// 16 × 16 strands along +y at x, z = 0.5, 1.5, …, 15.5 (spacing 1), y from 0 to 32 in unit
/// segments. With 8 voxels on the longest side (y) voxels are 4-cubes whose faces fall on
/// 0, 4, 8, …: each voxel holds exactly 16 fibers 4 long.
fn parallel_block(diameter: Option<f32>) -> HairModel {
    let mut points = Vec::new();
    let mut offsets = vec![0u32];
    for i in 0..16 {
        for k in 0..16 {
            for j in 0..=32 {
                points.push(Vec3::new(i as f32 + 0.5, j as f32, k as f32 + 0.5));
            }
            offsets.push(points.len() as u32);
        }
    }
    HairModel::new(
        points,
        offsets,
        diameter.map(Attribute::Uniform),
        None,
        None,
    )
    .unwrap()
}

fn settings(voxels: u32, taps: u32, step: f32) -> ForwardScatteringSettings {
    ForwardScatteringSettings {
        voxels: VoxelSettings {
            voxels_longest_side: voxels,
            default_diameter: None,
        },
        coarse_factor: 4,
        step_fraction: step,
        filter_taps: taps,
        density_forward: 0.7,
        compact_density_forward: 0.7,
        include_direct: true,
        light_sweep: false,
    }
}

/// xorshift in [0, 1).
struct Rng(u64);
impl Rng {
    fn unit(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    fn normal(&mut self) -> f64 {
        let (u1, u2) = (self.unit().max(1e-300), self.unit());
        (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
    }
}

#[test]
fn parallel_block_voxelizes_to_the_closed_form() {
    let d = 0.15f32;
    let volume =
        HairVolume::build(&parallel_block(Some(d)), &settings(8, 1, 0.5).voxels, 1.0).unwrap();
    println!(
        "grid {:?}, origin {}, voxel {}",
        volume.grid.dims, volume.grid.origin, volume.grid.voxel_size
    );
    assert_eq!(volume.grid.dims, [4, 8, 4]);
    // n fibers × d per area: 16 fibers through a 4 × 4 face → σ_t⊥ = 16·d/16 = d.
    let want = 16.0 * d / 16.0;
    let (mut worst_sigma, mut worst_dir, mut worst_nu) = (0.0f32, 0.0f32, 0.0f32);
    for v in 0..volume.sigma_perp.len() {
        worst_sigma = worst_sigma.max((volume.sigma_perp[v] / want - 1.0).abs());
        worst_dir = worst_dir.max((volume.mean_direction[v] - Vec3::Y).length());
        worst_nu = worst_nu.max(volume.deviation[v]);
    }
    println!(
        "σ_t⊥ want {want}: worst relative error {worst_sigma:.2e}; |ω̄ − y| ≤ {worst_dir:.2e}; ν ≤ {worst_nu:.2e}"
    );
    assert!(worst_sigma < 1e-5);
    assert!(worst_dir < 1e-5);
    assert!(worst_nu < 1e-3);
    // Without a thickness attribute the renderer's default diameter (10⁻³ × diagonal) is used.
    let model = parallel_block(None);
    let default_d = crate::passes::strand_geometry::default_thickness(&model);
    let v = HairVolume::build(&model, &settings(8, 1, 0.5).voxels, 1.0).unwrap();
    println!("default diameter {default_d}: σ_t⊥ {}", v.sigma_perp[0]);
    assert!((v.sigma_perp[0] / default_d - 1.0).abs() < 1e-5);
}

#[test]
fn fibers_drawn_around_an_axis_give_back_their_deviation() {
    // 20 000 short straight fibers in one voxel, directions ū = z moved by N(0, ν²) offsets
    // through the exponential map — the attenuation-ratio table's model. Half point down.
    for &nu in &[0.1f64, 0.3, 0.6] {
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
        let mut points = Vec::new();
        let mut offsets = vec![0u32];
        for n in 0..20_000 {
            let (x, y) = (nu * rng.normal(), nu * rng.normal());
            let r = (x * x + y * y).sqrt();
            let t = if r > 0.0 {
                Vec3::new(
                    (r.sin() * x / r) as f32,
                    (r.sin() * y / r) as f32,
                    r.cos() as f32,
                )
            } else {
                Vec3::Z
            };
            let t = if n % 2 == 0 { t } else { -t };
            let c = Vec3::new(rng.unit() as f32, rng.unit() as f32, rng.unit() as f32);
            points.push(c - 0.01 * t);
            points.push(c + 0.01 * t);
            offsets.push(points.len() as u32);
        }
        let model =
            HairModel::new(points, offsets, Some(Attribute::Uniform(0.001)), None, None).unwrap();
        let volume = HairVolume::build(&model, &settings(1, 1, 0.5).voxels, 1.0).unwrap();
        assert_eq!(volume.grid.voxel_count(), 1);
        let (got, dir) = (volume.deviation[0] as f64, volume.mean_direction[0]);
        println!("ν = {nu}: recovered {got:.4}, ω̄ = {dir}");
        assert!((got - nu).abs() < 0.03 * nu.max(0.3), "{nu} → {got}");
        assert!(dir.z.abs() > 0.99);
    }
}

#[test]
fn random_directions_give_a_large_deviation() {
    // Random walks with isotropic steps: E[sin² r] = 2/3, beyond the table's ν range.
    let mut rng = Rng(12345);
    let model = tangled_hair(&mut rng, 400, 200, 0.1, 0.01);
    let volume = HairVolume::build(&model, &settings(4, 1, 0.5).voxels, 1.0).unwrap();
    let occupied: Vec<f32> = (0..volume.deviation.len())
        .filter(|&v| volume.fiber_length[v] > 5.0)
        .map(|v| volume.deviation[v])
        .collect();
    let min = occupied.iter().cloned().fold(f32::INFINITY, f32::min);
    println!(
        "{} well-filled voxels, smallest ν {min:.3} rad (table ν_max 1.0)",
        occupied.len()
    );
    assert!(!occupied.is_empty());
    assert!(min > 0.7);
}

/// Expected-value closed forms for N ~ Poisson(μ) hits, each keeping a and adding β²:
/// P₀ = e^{−μ}, E[a^N] = e^{−μ(1−a)}, E[a^N N] = μ a e^{−μ(1−a)}.
fn poisson_closed_form(mu: f64, srbf: f64, d_f: f64) -> ([f64; 3], f64) {
    let p0 = (-mu).exp();
    let mut t = [0.0; 3];
    let (mut num, mut den) = (0.0, 0.0);
    for c in 0..3 {
        let m = (-mu * (1.0 - A_F[c])).exp();
        t[c] = p0 + d_f * (m - p0);
        num += p0 * srbf + d_f * (4.0 * BETA2_F * mu * A_F[c] * m + srbf * (m - p0));
        den += t[c];
    }
    (t, (num / den).sqrt())
}

#[test]
fn slab_attenuation_matches_the_expected_value_closed_form() {
    let d = 0.15f32;
    let model = parallel_block(Some(d));
    let light = EnvLight::directional(Vec3::X, [1.0; 3]);
    let srbf = EnvLight::srbf(Vec3::X, 100.0, [1.0; 3]);
    // Sample at x = 4: the shadow ray toward +x crosses 12 units of uniform fibers (θ = 0).
    let point = Vec3::new(4.0, 13.0, 6.0);
    let mu = d as f64 * 12.0;
    for &step in &[0.5f32, 0.05] {
        // Piecewise-constant voxels and Poisson hits per step: exact whatever the step.
        let source = CpuForwardScattering::new(&model, tables(), settings(8, 1, step)).unwrap();
        for (l, srbf_var) in [(light, 0.0), (srbf, SRBF_VARIANCE)] {
            let got = source.values_at(&l, &[point])[0];
            let (want, sigma) = poisson_closed_form(mu, srbf_var, 0.7);
            println!(
                "step {step} voxel, λ {:?}: T_f {:?} σ̄_f {:.6}; closed form {want:.6?} σ̄ {sigma:.6}; expected hits σαL = {mu:.3}",
                l.lambda,
                &got[..3],
                got[3]
            );
            for c in 0..3 {
                assert!((got[c] as f64 - want[c]).abs() < 2e-6, "channel {c}");
            }
            assert!((got[3] as f64 / sigma - 1.0).abs() < 2e-6);
        }
    }
    // The renderer's default: only paths with ≥ 1 hit, T = d_f (E[a^N] − P₀) (Zinke's global
    // term without the direct fraction), σ̄_f weighted by those paths alone.
    let scattered = CpuForwardScattering::new(
        &model,
        tables(),
        ForwardScatteringSettings {
            include_direct: false,
            ..settings(8, 1, 0.5)
        },
    )
    .unwrap();
    let got = scattered.values_at(&srbf, &[point])[0];
    let p0 = (-mu).exp();
    let (mut num, mut den) = (0.0, 0.0);
    for c in 0..3 {
        let m = (-mu * (1.0 - A_F[c])).exp();
        let want = 0.7 * (m - p0);
        println!(
            "scattered only: channel {c} T_f {} closed form {want:.6}",
            got[c]
        );
        assert!((got[c] as f64 - want).abs() < 2e-6, "channel {c}");
        num += 0.7 * (4.0 * BETA2_F * mu * A_F[c] * m + SRBF_VARIANCE * (m - p0));
        den += want;
    }
    assert!((got[3] as f64 / (num / den).sqrt() - 1.0).abs() < 2e-6);
}

/// A compact source's paths take `compact_density_forward`, an SRBF lobe's `density_forward`:
/// each equals the slab's closed form at its own d_f (seen failing with one d_f for both).
#[test]
fn compact_sources_and_lobes_take_their_own_density_factor() {
    let d = 0.15f32;
    let model = parallel_block(Some(d));
    let point = Vec3::new(4.0, 13.0, 6.0);
    let mu = d as f64 * 12.0;
    let source = CpuForwardScattering::new(
        &model,
        tables(),
        ForwardScatteringSettings {
            density_forward: 0.7,
            compact_density_forward: 1.0,
            ..settings(8, 1, 0.5)
        },
    )
    .unwrap();
    let sun = EnvLight::directional(Vec3::X, [1.0; 3]);
    let lobe = EnvLight::srbf(Vec3::X, 100.0, [1.0; 3]);
    assert!(sun.has_sharp_shadow() && !lobe.has_sharp_shadow());
    for (light, srbf_var, d_f) in [(sun, 0.0, 1.0), (lobe, SRBF_VARIANCE, 0.7)] {
        let got = source.values_at(&light, &[point])[0];
        let (want, sigma) = poisson_closed_form(mu, srbf_var, d_f);
        println!(
            "d_f {d_f}: T_f {:?} σ̄_f {}; closed form {want:.6?} σ̄ {sigma:.6}",
            &got[..3],
            got[3]
        );
        for c in 0..3 {
            assert!(
                (got[c] as f64 - want[c]).abs() < 2e-6,
                "d_f {d_f}, channel {c}"
            );
        }
        assert!((got[3] as f64 / sigma - 1.0).abs() < 2e-6, "d_f {d_f}");
    }
}

#[test]
fn expected_hits_equal_sigma_alpha_length() {
    // Independent of the transmittance bookkeeping: the optical depth Σ kδ is k·L; at an
    // oblique angle θ to the fibers α = cos θ and the path is longer.
    let d = 0.15f32;
    let source =
        CpuForwardScattering::new(&parallel_block(Some(d)), tables(), settings(8, 1, 0.05))
            .unwrap();
    let theta = 0.5f32;
    let xi = Vec3::new(theta.cos(), theta.sin(), 0.0);
    let medium = shadow_paths::LightMedium::new(
        source.volume(),
        &tables(),
        &EnvLight::directional(xi, [1.0; 3]),
    );
    let point = Vec3::new(4.0, 10.0, 6.0);
    let path = shadow_paths::march(source.volume(), &medium, point, xi, 0.2);
    let length = 12.0 / theta.cos(); // leaves through the x = 16 face (y stays below 32)
    let want = d as f64 * (theta as f64).cos() * length as f64;
    println!(
        "expected hits {:.5}, σ_t⊥ α L = {want:.5}",
        path.expected_hits
    );
    assert!((path.expected_hits / want - 1.0).abs() < 1e-4);
}

#[test]
fn light_along_the_fibers_is_not_attenuated() {
    // α(0, 90°) = 0: aligned fibers show no cross-section to light along their axis.
    let source =
        CpuForwardScattering::new(&parallel_block(Some(0.15)), tables(), settings(8, 2, 0.5))
            .unwrap();
    let v = source.values_at(
        &EnvLight::directional(Vec3::Y, [1.0; 3]),
        &[Vec3::new(8.0, 3.0, 8.0)],
    )[0];
    println!("light along the fibers: {v:?}");
    assert!(v.iter().all(|x| x.is_finite()));
    assert!(v[..3].iter().all(|&t| (t - 1.0).abs() < 1e-6));
    assert!(v[3].abs() < 1e-6);
}

#[test]
fn empty_regions_and_outside_points_are_lit_directly() {
    // Two blocks of fibers with a gap: x ∈ [0, 4] and [12, 16]. A sample in the gap lit from
    // +z (no fiber above it) and a sample far outside get T_f = 1 and σ̄_f = 0.
    let mut points = Vec::new();
    let mut offsets = vec![0u32];
    for &x0 in &[0.5f32, 12.5] {
        for i in 0..4 {
            for k in 0..16 {
                for j in 0..=16 {
                    points.push(Vec3::new(x0 + i as f32, j as f32, k as f32 + 0.5));
                }
                offsets.push(points.len() as u32);
            }
        }
    }
    let model = HairModel::new(points, offsets, Some(Attribute::Uniform(0.2)), None, None).unwrap();
    let source = CpuForwardScattering::new(&model, tables(), settings(16, 2, 0.5)).unwrap();
    let light = EnvLight::directional(Vec3::Z, [1.0; 3]);
    let probes = [
        Vec3::new(8.0, 8.0, 8.0),
        Vec3::new(100.0, -50.0, 3.0),
        Vec3::new(2.0, 8.0, 8.0),
    ];
    let v = source.values_at(&light, &probes);
    println!(
        "gap {:?}, outside {:?}, inside a block (lit along z, α = 1) {:?}",
        v[0], v[1], v[2]
    );
    for probe in &v[..2] {
        assert_eq!(probe[..3], [1.0; 3]);
        assert_eq!(probe[3], 0.0);
    }
    assert!(v[2][0] < 1.0 && v[2][2] < v[2][0]);
    // A light from the gap's side (+x from x = 8 reaches the second block) is attenuated.
    let from_x = source.values_at(
        &EnvLight::directional(Vec3::X, [1.0; 3]),
        &[Vec3::new(8.0, 8.0, 8.0)],
    )[0];
    println!("gap lit from +x through the second block: {from_x:?}");
    assert!(from_x[0] < 1.0);
}

#[test]
fn degenerate_hair_gives_finite_values() {
    // Zero-length strands only (every point of a strand equal), and a single point overall.
    let cases = [
        (
            vec![
                Vec3::ONE,
                Vec3::ONE,
                Vec3::new(2.0, 1.0, 1.0),
                Vec3::new(2.0, 1.0, 1.0),
            ],
            vec![0u32, 2, 4],
        ),
        (vec![Vec3::ZERO; 3], vec![0u32, 3]),
    ];
    for (points, offsets) in cases {
        let model = HairModel::new(points, offsets, None, None, None).unwrap();
        let with_direct = ForwardScatteringSettings {
            include_direct: true,
            ..Default::default()
        };
        let source = CpuForwardScattering::new(&model, tables(), with_direct).unwrap();
        let lights = [
            EnvLight::directional(Vec3::new(0.3, 0.4, 0.5), [1.0; 3]),
            EnvLight::srbf(Vec3::new(-1.0, 0.0, 0.0), 50.0, [1.0; 3]),
        ];
        // The renderer's default counts only forward-scattered light: none without fibers.
        let scattered =
            CpuForwardScattering::new(&model, tables(), ForwardScatteringSettings::default())
                .unwrap()
                .grid(&lights)
                .unwrap();
        assert!(
            scattered
                .values
                .iter()
                .all(|v| v[..3] == [0.0; 3] && v[3].is_finite())
        );
        let grid = source.grid(&lights).unwrap();
        let volume = source.volume();
        println!(
            "grid {:?} voxel size {} σ_max {}, first value {:?}",
            volume.grid.dims,
            volume.grid.voxel_size,
            volume.sigma_perp.iter().cloned().fold(0.0, f32::max),
            grid.values[0]
        );
        assert!(volume.sigma_perp.iter().all(|&s| s == 0.0));
        assert!(grid.values.iter().all(|v| v.iter().all(|x| x.is_finite())));
        assert!(grid.values.iter().all(|v| v[..3] == [1.0; 3]));
        // Direct SRBF light keeps the SRBF's own width.
        let n = grid.values.len() / 2;
        assert!((grid.values[n][3] as f64 - SRBF_VARIANCE.sqrt()).abs() < 1e-6);
    }
}

#[test]
fn the_grid_covers_the_hair_and_holds_every_light() {
    let model = parallel_block(Some(0.15));
    let source = CpuForwardScattering::new(&model, tables(), settings(8, 2, 0.5)).unwrap();
    let lights = [
        EnvLight::directional(Vec3::X, [1.0; 3]),
        EnvLight::directional(Vec3::new(-1.0, 0.2, 0.3), [1.0; 3]),
        EnvLight::srbf(Vec3::Z, 64.0, [1.0; 3]),
    ];
    let grid = source.grid(&lights).unwrap();
    let n = grid.dims.iter().product::<u32>() as usize;
    println!(
        "dims {:?} origin {} spacing {}",
        grid.dims, grid.origin, grid.spacing
    );
    assert_eq!(grid.values.len(), n * lights.len());
    let far = grid.origin
        + grid.spacing
            * Vec3::new(
                grid.dims[0] as f32 - 1.0,
                grid.dims[1] as f32 - 1.0,
                grid.dims[2] as f32 - 1.0,
            );
    let b = model.bounds();
    assert!(grid.origin.cmple(b.min + 1e-4).all() && far.cmpge(b.max - 1e-4).all());
    // Vertex values are what values_at gives at the vertex; interpolation reproduces them.
    let p = grid.origin + grid.spacing * Vec3::new(1.0, 1.0, 1.0);
    for (l, light) in lights.iter().enumerate() {
        let direct = source.values_at(light, &[p])[0];
        let interpolated = interpolate_grid(&grid, l, p).unwrap();
        for c in 0..4 {
            assert!(
                (direct[c] - interpolated[c]).abs() < 1e-5,
                "light {l}: {direct:?} vs {interpolated:?}"
            );
        }
    }
    assert_eq!(interpolate_grid(&grid, lights.len(), p), None);
}

#[test]
fn bad_settings_are_typed_errors() {
    let model = parallel_block(None);
    for s in [
        ForwardScatteringSettings {
            coarse_factor: 0,
            ..Default::default()
        },
        ForwardScatteringSettings {
            step_fraction: f32::NAN,
            ..Default::default()
        },
        ForwardScatteringSettings {
            density_forward: 1.5,
            ..Default::default()
        },
        ForwardScatteringSettings {
            compact_density_forward: -0.1,
            ..Default::default()
        },
        ForwardScatteringSettings {
            voxels: VoxelSettings {
                voxels_longest_side: 0,
                default_diameter: None,
            },
            ..Default::default()
        },
    ] {
        let err = CpuForwardScattering::new(&model, tables(), s).unwrap_err();
        println!("{err}");
        assert!(matches!(err, ForwardScatteringError::InvalidSetting { .. }));
    }
}

/// The GPU's march beside the CPU's sweep: the same voxels resampled under other settings give
/// what a fresh voxelization under them gives; other voxels are refused.
#[test]
fn a_voxelized_hair_resampled_under_other_settings_matches_a_fresh_one() {
    let model = tangled_hair(&mut Rng(7), 40, 12, 0.1, 0.01);
    let sweep = ForwardScatteringSettings {
        light_sweep: true,
        ..settings(24, 2, 0.5)
    };
    let march = ForwardScatteringSettings {
        light_sweep: false,
        coarse_factor: 2,
        ..sweep
    };
    let cpu = CpuForwardScattering::new(&model, tables(), sweep).unwrap();
    let resampled = cpu.clone().with_settings(march).unwrap();
    let fresh = CpuForwardScattering::new(&model, tables(), march).unwrap();
    assert_eq!(resampled.settings(), fresh.settings());
    assert_eq!(
        resampled.sample_grid().positions(),
        fresh.sample_grid().positions()
    );
    let light = EnvLight::srbf(Vec3::new(0.3, 0.9, 0.2), 40.0, [1.0; 3]);
    let probes: Vec<Vec3> = fresh
        .sample_grid()
        .positions()
        .into_iter()
        .step_by(7)
        .collect();
    assert_eq!(
        resampled.values_at(&light, &probes),
        fresh.values_at(&light, &probes)
    );
    let other_voxels = ForwardScatteringSettings {
        voxels: VoxelSettings {
            voxels_longest_side: 32,
            default_diameter: None,
        },
        ..march
    };
    let err = cpu.with_settings(other_voxels).unwrap_err();
    assert!(
        matches!(
            err,
            ForwardScatteringError::InvalidSetting {
                parameter: "voxels",
                ..
            }
        ),
        "{err}"
    );
}

#[test]
fn light_sweep_matches_the_slab_closed_form() {
    let d = 0.15f32;
    let point = Vec3::new(4.0, 13.0, 6.0);
    let mu = d as f64 * 12.0;
    let s = ForwardScatteringSettings {
        light_sweep: true,
        ..settings(8, 1, 0.05)
    };
    let source = CpuForwardScattering::new(&parallel_block(Some(d)), tables(), s).unwrap();
    for (l, srbf_var) in [
        (EnvLight::directional(Vec3::X, [1.0; 3]), 0.0),
        (EnvLight::srbf(Vec3::X, 100.0, [1.0; 3]), SRBF_VARIANCE),
    ] {
        let got = source.values_at(&l, &[point])[0];
        let (want, sigma) = poisson_closed_form(mu, srbf_var, 0.7);
        println!(
            "sweep: T_f {:?} σ̄_f {:.6}; closed form {want:.6?} σ̄ {sigma:.6}",
            &got[..3],
            got[3]
        );
        for c in 0..3 {
            assert!((got[c] as f64 - want[c]).abs() < 1e-3, "channel {c}");
        }
        assert!((got[3] as f64 / sigma - 1.0).abs() < 1e-3);
    }
    // Between two stored depths (nodes one voxel = 4 units apart, σ_t⊥h = 0.6) the sweep
    // interpolates linearly: the error is the chord-vs-exponential gap.
    let off_node = Vec3::new(5.3, 13.0, 6.0);
    let got = source.values_at(&EnvLight::directional(Vec3::X, [1.0; 3]), &[off_node])[0];
    let (want, _) = poisson_closed_form(d as f64 * (16.0 - 5.3), 0.0, 0.7);
    println!(
        "sweep between depth nodes: T_f {:?} vs closed form {want:.5?}",
        &got[..3]
    );
    for c in 0..3 {
        assert!((got[c] as f64 - want[c]).abs() < 0.02, "channel {c}");
    }
}

#[test]
fn light_sweep_agrees_with_per_point_marching_on_tangled_hair() {
    // Random walks in a box, oblique light: the two ways of computing the same expected paths
    // differ only by their filters (tent over one voxel vs 2³ taps over one voxel).
    let mut rng = Rng(777);
    let model = tangled_hair(&mut rng, 300, 100, 0.15, 0.02);
    let light = EnvLight::directional(Vec3::new(0.3, -0.5, 0.8), [1.0; 3]);
    let probes: Vec<Vec3> = model.points().iter().step_by(97).copied().collect();
    let march = CpuForwardScattering::new(&model, tables(), settings(16, 4, 0.25)).unwrap();
    let sweep = CpuForwardScattering::new(
        &model,
        tables(),
        ForwardScatteringSettings {
            light_sweep: true,
            ..settings(16, 4, 0.25)
        },
    )
    .unwrap();
    let (a, b) = (
        march.values_at(&light, &probes),
        sweep.values_at(&light, &probes),
    );
    let (mut sum, mut max, mut mean) = (0.0f64, 0.0f64, 0.0f64);
    for (x, y) in a.iter().zip(&b) {
        let dt = (x[0] - y[0]).abs() as f64;
        sum += dt * dt;
        max = max.max(dt);
        mean += x[0] as f64;
    }
    let rms = (sum / a.len() as f64).sqrt();
    println!(
        "{} probes: mean T_f(red) {:.4}, RMS |Δ| {rms:.4}, max {max:.4}",
        a.len(),
        mean / a.len() as f64
    );
    assert!(rms < 0.03 && max < 0.15);
}

#[test]
fn gpu_march_matches_the_cpu_march() {
    // Tangled hair (random walks), 18 lights (two dispatches of at most 16), SRBF and
    // directional, one along a grid axis (the ray-box test's parallel branch), with and without
    // the direct paths. Both sources march the same f32 positions through the same medium; the
    // recursion runs in f64 on the CPU and f32 on the GPU.
    let mut rng = Rng(4242);
    let model = tangled_hair(&mut rng, 200, 60, 0.2, 0.1);
    let mut lights = vec![
        EnvLight::directional(Vec3::Z, [1.0; 3]),
        EnvLight::srbf(Vec3::X, 30.0, [1.0; 3]),
    ];
    while lights.len() < 18 {
        let d = Vec3::new(rng.unit() as f32, rng.unit() as f32, rng.unit() as f32) * 2.0 - 1.0;
        lights.push(match lights.len() % 2 {
            0 => EnvLight::directional(d, [1.0; 3]),
            _ => EnvLight::srbf(d, 10.0 + 50.0 * rng.unit() as f32, [1.0; 3]),
        });
    }
    let gpu = crate::gpu::GpuContext::new_headless().unwrap_or_else(|e| panic!("{e}"));
    for include_direct in [true, false] {
        // The compact sources' d_f differs from the lobes': each light carries its own.
        let s = ForwardScatteringSettings {
            coarse_factor: 2,
            include_direct,
            compact_density_forward: 1.0,
            ..settings(16, 2, 0.5)
        };
        let cpu = CpuForwardScattering::new(&model, tables(), s).unwrap();
        let want = cpu.grid(&lights).unwrap();
        let got = GpuForwardScattering::new(&gpu, cpu)
            .unwrap()
            .grid(&lights)
            .unwrap();
        assert_eq!((got.dims, got.values.len()), (want.dims, want.values.len()));
        let (mut worst_t, mut worst_sigma, mut mean_t) = (0.0f32, 0.0f32, 0.0f32);
        for (g, w) in got.values.iter().zip(&want.values) {
            for c in 0..3 {
                worst_t = worst_t.max((g[c] - w[c]).abs());
                mean_t += w[c] / (3 * want.values.len()) as f32;
            }
            worst_sigma = worst_sigma.max((g[3] - w[3]).abs());
        }
        println!(
            "include_direct {include_direct}: {} values, mean T_f {mean_t:.4}, max |ΔT_f| {worst_t:.2e}, max |Δσ̄_f| {worst_sigma:.2e} rad",
            want.values.len()
        );
        // The hair must matter: it takes light away from the direct paths and scatters some.
        assert!(
            if include_direct {
                mean_t < 0.9
            } else {
                mean_t > 0.05
            },
            "mean T_f {mean_t}"
        );
        assert!(worst_t < 1e-4 && worst_sigma < 1e-4);
    }
}

#[test]
fn the_grid_and_its_paths_do_not_depend_on_the_thread_count() {
    // The precomputed grid is part of a frame's inputs: a picture must not change with the
    // machine's core count. Voxel sums, marched and swept paths compared bit for bit.
    let mut rng = Rng(4242);
    let model = tangled_hair(&mut rng, 600, 60, 0.15, 0.02);
    let light = EnvLight::directional(Vec3::new(0.3, -0.5, 0.8), [1.0; 3]);
    let probes: Vec<Vec3> = model.points().iter().step_by(13).copied().collect();
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| {
                let volume = HairVolume::build(
                    &model,
                    &VoxelSettings {
                        voxels_longest_side: 24,
                        default_diameter: None,
                    },
                    1.0,
                )
                .unwrap();
                let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                let mut out = bits(&volume.sigma_perp);
                out.extend(bits(&volume.deviation));
                out.extend(
                    volume
                        .mean_direction
                        .iter()
                        .flat_map(|d| bits(&d.to_array())),
                );
                for light_sweep in [false, true] {
                    let grid = CpuForwardScattering::new(
                        &model,
                        tables(),
                        ForwardScatteringSettings {
                            light_sweep,
                            ..settings(16, 4, 0.25)
                        },
                    )
                    .unwrap();
                    out.extend(grid.values_at(&light, &probes).iter().flat_map(|v| bits(v)));
                }
                out
            })
    };
    let one = run(1);
    assert!(one.iter().any(|&b| b != 0), "the grid holds something");
    for threads in [2, 8] {
        assert!(
            run(threads) == one,
            "{threads} threads give other bits than 1"
        );
    }
}

/// The head as the grid's opaque boundary (issue 40): in the parallel block, a sphere between a
/// sample and the light leaves it T = 0, exactly where the ray meets it (f64 roots); a sample
/// beside the sphere, or lit from the other side, keeps the value it has without the head.
#[test]
fn the_head_blocks_the_forward_scattered_light_where_its_ray_meets_it() {
    use crate::head::Head;
    let model = parallel_block(Some(0.05));
    let plain = CpuForwardScattering::new(&model, tables(), settings(16, 2, 0.5)).unwrap();
    let head = Head::ellipsoid(Vec3::new(8.0, 16.0, 12.0), Vec3::splat(2.5));
    let with_head = plain.clone().with_head(Some(head.clone()));
    let light = EnvLight::directional(Vec3::Z, [1.0; 3]);
    let behind = Vec3::new(8.0, 16.0, 4.0);
    let beside = Vec3::new(8.0, 20.0, 4.0);
    let probes = [behind, beside];
    let (a, b) = (
        plain.values_at(&light, &probes),
        with_head.values_at(&light, &probes),
    );
    assert!(head.ray_hit(behind, Vec3::Z, f32::INFINITY).is_some());
    assert!(head.ray_hit(beside, Vec3::Z, f32::INFINITY).is_none());
    assert!(a[0][0] > 0.0, "{a:?}");
    assert_eq!(b[0][..3], [0.0; 3], "behind the head");
    assert_eq!(b[1], a[1], "beside the head");
    // Lit from −z the same sample is in front of the head.
    let below = EnvLight::directional(-Vec3::Z, [1.0; 3]);
    assert_eq!(
        with_head.values_at(&below, &[behind]),
        plain.values_at(&below, &[behind])
    );
}

/// The GPU's march stops at the head as the CPU's does: with the head, the GPU grid equals the
/// CPU grid (T = 0 at the same samples, the rest as marched), and the head blocks some samples.
#[test]
fn the_gpu_march_is_blocked_by_the_head_where_the_cpu_is() {
    use crate::head::Head;
    let model = parallel_block(Some(0.05));
    let head = Head::ellipsoid(Vec3::new(8.0, 16.0, 12.0), Vec3::splat(2.5));
    let s = ForwardScatteringSettings {
        coarse_factor: 2,
        ..settings(16, 2, 0.5)
    };
    let cpu = CpuForwardScattering::new(&model, tables(), s)
        .unwrap()
        .with_head(Some(head));
    let lights = [
        EnvLight::directional(Vec3::Z, [1.0; 3]),
        EnvLight::srbf(Vec3::new(0.3, -0.2, 1.0), 20.0, [1.0; 3]),
    ];
    let want = cpu.grid(&lights).unwrap();
    let gpu = crate::gpu::GpuContext::new_headless().unwrap_or_else(|e| panic!("{e}"));
    let got = GpuForwardScattering::new(&gpu, cpu)
        .unwrap()
        .grid(&lights)
        .unwrap();
    assert_eq!(got.values.len(), want.values.len());
    let mut blocked = 0;
    for (g, w) in got.values.iter().zip(&want.values) {
        if w[..3] == [0.0; 3] {
            assert_eq!(g[..3], [0.0; 3], "blocked on the CPU, not on the GPU");
            blocked += 1;
        }
        for c in 0..4 {
            assert!((g[c] - w[c]).abs() < 1e-4, "{g:?} vs {w:?}");
        }
    }
    assert!(blocked > 4, "{blocked} samples behind the head");
}
