//! The env view pass's transparency (Ren 2010 §8): fibers stacked in depth under one pixel,
//! drawn in a shuffled order, against front-to-back "over" compositing done here in f64 —
//! Σ_k c_k α Π_{j<k} (1 − α) — with each fiber's colour c_k from `Table::lookup`.

use crate::common::*;

use glam::{DVec3, Vec3};
use strandlight_runtime::env::{
    EnvRenderError, EnvRenderOptions, EnvTables, FragmentCounts, OccupancyError, ViewTransparency,
    render_env_frame,
};
use strandlight_runtime::env_light::EnvLight;
use strandlight_runtime::hair::{Attribute, HairModel};
use strandlight_runtime::passes::convolution_depth::DodmSettings;
use strandlight_tables::table::{Axis, Table};
use strandlight_tables::table_axes::{
    AXIS_COS_DPHI, AXIS_INV_LAMBDA, AXIS_U_DOT_WO, AXIS_U_DOT_XI,
};

/// The light: directional, toward +x (in the image plane), unit irradiance per channel.
const LIGHT: Vec3 = Vec3::X;
/// The pixel every strand crosses: world (0, 0) is the corner of pixels 31 and 32, so use the
/// centre of pixel (32, 31) at world (1/64, 1/64).
const PIXEL: (usize, usize) = (32, 31);
const CENTRE: Vec3 = Vec3::new(1.0 / 64.0, 1.0 / 64.0, 0.0);

/// A direct table (one-node fourth axis) that varies with u·ξ, so strands at different angles to
/// the light have different colours and the compositing order shows.
fn direct_table() -> Table {
    table_with_fourth_axis("w")
}

/// [`direct_table`] as an SRBF table: the same colours on a one-node 1/λ axis.
fn lobe_table() -> Table {
    table_with_fourth_axis(AXIS_INV_LAMBDA)
}

fn table_with_fourth_axis(name: &str) -> Table {
    let axes = vec![
        Axis::uniform(AXIS_U_DOT_XI, -1.0, 1.0, 33),
        Axis::uniform(AXIS_U_DOT_WO, -1.0, 1.0, 3),
        Axis::uniform(AXIS_COS_DPHI, -1.0, 1.0, 3),
        Axis::uniform(name, 0.0, 0.0, 1),
    ];
    Table::from_fn(axes, 3, |x, out| {
        out[0] = (1.0 + x[0]) as f32;
        out[1] = (2.0 - x[0] * x[0]) as f32;
        out[2] = (0.5 + 0.25 * x[0]) as f32;
    })
    .unwrap()
}

/// `layers` straight strands through CENTRE at depths z_k = 0.5 − 0.1·k (k = 0 nearest the
/// camera at +z), the k-th at 10° + 17°·k in the image plane, each 3 pixels wide (coverage 1) with
/// opacity `opacity`; listed in the file in a shuffled order. Returns the model and the strands'
/// tangents front to back.
fn stacked_strands(layers: usize, opacity: f32) -> (HairModel, Vec<DVec3>) {
    strands_spaced(layers, opacity, 0.1)
}

/// [`stacked_strands`] `spacing` apart in depth (0: all at one depth).
fn strands_spaced(layers: usize, opacity: f32, spacing: f32) -> (HairModel, Vec<DVec3>) {
    let tangents: Vec<Vec3> = (0..layers)
        .map(|k| {
            let a = (10.0 + 17.0 * k as f32).to_radians();
            Vec3::new(a.cos(), a.sin(), 0.0)
        })
        .collect();
    // A fixed permutation: the draw order must not matter.
    let mut order: Vec<usize> = (0..layers).collect();
    order.sort_by_key(|&k| (k * 7 + 3) % layers);
    let mut points = Vec::new();
    let mut offsets = vec![0u32];
    for &k in &order {
        let centre = CENTRE + Vec3::Z * (0.5 - spacing * k as f32);
        points.push(centre - tangents[k] * 0.3);
        points.push(centre + tangents[k] * 0.3);
        offsets.push(points.len() as u32);
    }
    let model = HairModel::new(
        points,
        offsets,
        Some(Attribute::Uniform(3.0 / 32.0)),
        Some(Attribute::Uniform(1.0 - opacity)),
        None,
    )
    .unwrap();
    (model, tangents.iter().map(|t| t.as_dvec3()).collect())
}

/// The colour of a strand with tangent `t` under LIGHT, seen by the orthographic camera.
fn colour(table: &Table, t: DVec3) -> [f64; 3] {
    let (l, e) = (LIGHT.as_dvec3(), DVec3::Z);
    let (si, so) = (t.dot(l), t.dot(e));
    let (lp, ep) = (l - si * t, e - so * t);
    let cos_phi = (lp.dot(ep) / (lp.length() * ep.length())).clamp(-1.0, 1.0);
    table
        .lookup_rgb(&[si, so, cos_phi, 0.0])
        .unwrap()
        .map(|c| c as f64)
}

/// Front-to-back "over" of the first `kept` layers (RGB and alpha), in f64.
fn composite(table: &Table, tangents: &[DVec3], alpha: f64, kept: usize) -> [f64; 4] {
    let mut out = [0.0; 4];
    let mut seen = 1.0;
    for t in tangents.iter().take(kept) {
        let c = colour(table, *t);
        for i in 0..3 {
            out[i] += seen * alpha * c[i];
        }
        out[3] += seen * alpha;
        seen *= 1.0 - alpha;
    }
    out
}

fn render(
    model: &HairModel,
    table: &Table,
    transparency: ViewTransparency,
) -> Result<(Vec<[f32; 4]>, Option<FragmentCounts>), EnvRenderError> {
    render_sized(model, table, transparency, RES, RES)
}

fn render_sized(
    model: &HairModel,
    table: &Table,
    transparency: ViewTransparency,
    width: u32,
    height: u32,
) -> Result<(Vec<[f32; 4]>, Option<FragmentCounts>), EnvRenderError> {
    render_lit(
        model,
        table,
        transparency,
        &[Kind::Directional],
        width,
        height,
    )
}

/// The light of a test frame: directional (a compact source), directional standing for a region
/// of the map, or an SRBF lobe about the same direction (the table's one-node fourth axis reads
/// the same colours for any λ).
#[derive(Clone, Copy, PartialEq)]
enum Kind {
    Directional,
    Region,
    Srbf,
}

/// [`render`] under an SRBF lobe (`table`'s colours, [`lobe_table`]): what the layered view
/// shades per layer.
fn render_srbf(
    model: &HairModel,
    table: &Table,
    transparency: ViewTransparency,
) -> Result<(Vec<[f32; 4]>, Option<FragmentCounts>), EnvRenderError> {
    render_lit(model, table, transparency, &[Kind::Srbf], RES, RES)
}

/// The test frames' options: 64² light maps, 4 lights a batch, every strand in them.
fn options(transparency: ViewTransparency, shadowed: bool) -> EnvRenderOptions {
    EnvRenderOptions {
        dodm: DodmSettings {
            resolution: 64,
            first_layer: None,
            batch_size: 4,
        },
        kappa: 1.0,
        shadowed,
        transparency,
        ..Default::default()
    }
}

fn render_lit(
    model: &HairModel,
    table: &Table,
    transparency: ViewTransparency,
    kinds: &[Kind],
    width: u32,
    height: u32,
) -> Result<(Vec<[f32; 4]>, Option<FragmentCounts>), EnvRenderError> {
    let gpu = gpu();
    let options = EnvRenderOptions {
        count_fragments: true,
        ..options(transparency, false)
    };
    let tables = match kinds.contains(&Kind::Srbf) {
        false => EnvTables {
            direct: Some(table.clone().into()),
            ..Default::default()
        },
        true => EnvTables {
            srbf: Some(lobe_table().into()),
            ..Default::default()
        },
    };
    let lights: Vec<EnvLight> = kinds
        .iter()
        .map(|kind| match kind {
            Kind::Directional => EnvLight::directional(LIGHT, [1.0; 3]),
            Kind::Region => EnvLight {
                stands_for_region: true,
                ..EnvLight::directional(LIGHT, [1.0; 3])
            },
            Kind::Srbf => EnvLight::srbf(LIGHT, 100.0, [1.0; 3]),
        })
        .collect();
    let frame = render_env_frame(
        &gpu,
        model,
        &ortho_camera(),
        width,
        height,
        &lights,
        &tables,
        &options,
        None,
    )?;
    Ok((frame.pixels, frame.stats.fragments))
}

fn at_pixel(pixels: &[[f32; 4]]) -> [f64; 4] {
    pixels[PIXEL.1 * RES as usize + PIXEL.0].map(|c| c as f64)
}

fn assert_close(got: [f64; 4], want: [f64; 4], tolerance: f64, what: &str) {
    for c in 0..4 {
        let scale = want[c].abs().max(1e-3);
        assert!(
            (got[c] - want[c]).abs() <= tolerance * scale,
            "{what}: channel {c}: got {:?}, want {:?}",
            got,
            want
        );
    }
}

#[test]
fn occupancy_view_composites_stacked_fibers_front_to_back_in_any_draw_order() {
    let (layers, opacity) = (8, 0.4);
    let (model, tangents) = stacked_strands(layers, opacity);
    let table = direct_table();
    let (pixels, counts) = render(
        &model,
        &table,
        ViewTransparency::Occupancy {
            visibility_cutoff: 0.0,
        },
    )
    .unwrap();
    let want = composite(&table, &tangents, opacity as f64, layers);
    let got = at_pixel(&pixels);
    println!("occupancy view: got {got:?}, front-to-back over {want:?}");
    // Per fragment the occupancy map rounds τ = −ln(1 − α) to 1/4096: well below 1e-3.
    assert_close(got, want, 1e-3, "occupancy view");
    // The draw order reversed (the layers' order in the file) gives the same pixel.
    let reversed = composite(
        &table,
        &tangents.iter().rev().cloned().collect::<Vec<_>>(),
        0.4,
        layers,
    );
    assert!(
        (reversed[0] - want[0]).abs() > 0.05 * want[0],
        "the scene must tell the orders apart: {reversed:?} vs {want:?}"
    );
    let counts = counts.unwrap();
    assert_eq!(
        counts.shaded, counts.rasterized,
        "a zero cutoff culls nothing: {counts:?}"
    );
}

#[test]
fn occupancy_view_weights_add_up_to_the_coverage_where_fibers_share_a_slice() {
    // Six fibers at one depth share a slice: the map cannot order them, gives each its full
    // α, and the weights would add up to 6α = 1.8. Rescaled, the pixel holds its coverage
    // 1 − (1 − α)⁶ and each fiber a sixth of it.
    let (layers, opacity) = (6, 0.3);
    let (model, tangents) = strands_spaced(layers, opacity, 0.0);
    let table = direct_table();
    let coverage = 1.0 - (1.0 - opacity as f64).powi(layers as i32);
    let mut want = [0.0, 0.0, 0.0, coverage];
    for t in &tangents {
        let c = colour(&table, *t);
        for i in 0..3 {
            want[i] += coverage / layers as f64 * c[i];
        }
    }
    let (pixels, _) = render(&model, &table, ViewTransparency::occupancy()).unwrap();
    let got = at_pixel(&pixels);
    println!("occupancy view: got {got:?}, want {want:?}");
    assert_close(got, want, 2e-3, "occupancy view, one slice");
    // The layered view gathers those weights: its pixel holds the same coverage.
    let (pixels, _) = render_srbf(&model, &table, ViewTransparency::layered()).unwrap();
    let alpha = at_pixel(&pixels)[3];
    println!("layered view: alpha {alpha}, coverage {coverage}");
    assert!(
        (alpha - coverage).abs() <= 2e-3 * coverage,
        "layered view: {alpha} vs {coverage}"
    );
}

#[test]
fn occupancy_view_stops_shading_fragments_below_the_visibility_cutoff() {
    // Visibility through k layers of opacity 0.7 is 0.3^k: 0.09 at k = 2, 0.027 at k = 3, so a
    // cutoff of 0.05 keeps the three nearest layers and culls the rest (2.7% of the pixel).
    let (layers, opacity, cutoff) = (6, 0.7, 0.05);
    let (model, tangents) = stacked_strands(layers, opacity);
    let table = direct_table();
    let (pixels, counts) = render(
        &model,
        &table,
        ViewTransparency::Occupancy {
            visibility_cutoff: cutoff,
        },
    )
    .unwrap();
    let got = at_pixel(&pixels);
    let kept = composite(&table, &tangents, opacity as f64, 3);
    let all = composite(&table, &tangents, opacity as f64, layers);
    println!("cutoff {cutoff}: got {got:?}; three layers {kept:?}; all {all:?}; {counts:?}");
    assert_close(got, kept, 1e-3, "culled view");
    assert!(
        (all[3] - kept[3]) > 0.02,
        "the cut must be measurable: {all:?} vs {kept:?}"
    );
    let counts = counts.unwrap();
    assert!(
        counts.shaded < counts.rasterized,
        "culled fragments are not shaded: {counts:?}"
    );
}

/// The layered view's pixel, in f64: each fiber's weight α(1 − α)^k (k in front of it) goes to
/// the layer of the share of the coverage in front of it, ⌊L·(1 − (1 − α)^k)/C⌋ of L layers
/// (C the pixel's coverage); each layer shades the weighted mean of its tangents.
fn layered(table: &Table, tangents: &[DVec3], alpha: f64, layers: usize) -> [f64; 4] {
    let coverage = 1.0 - (1.0 - alpha).powi(tangents.len() as i32);
    let mut sums = vec![(0.0, DVec3::ZERO); layers];
    for (k, t) in tangents.iter().enumerate() {
        let seen = (1.0 - alpha).powi(k as i32);
        let layer = (((1.0 - seen) / coverage * layers as f64) as usize).min(layers - 1);
        sums[layer].0 += alpha * seen;
        sums[layer].1 += alpha * seen * *t;
    }
    let mut out = [0.0; 4];
    for (w, wt) in sums.into_iter().filter(|(w, _)| *w > 0.0) {
        let c = colour(table, wt.normalize());
        for i in 0..3 {
            out[i] += w * c[i];
        }
        out[3] += w;
    }
    out
}

#[test]
fn layered_view_with_one_fiber_a_layer_composites_front_to_back() {
    // α = 0.1 over 4 fibers: the coverage in front of fiber k is 0, 29, 55 and 79% of the
    // pixel's, so each fiber has a layer of its own and the layers are the fibers.
    let (layers, opacity) = (4, 0.1);
    let (model, tangents) = stacked_strands(layers, opacity);
    let table = direct_table();
    let (pixels, _) = render_srbf(&model, &table, ViewTransparency::layered()).unwrap();
    let want = composite(&table, &tangents, opacity as f64, layers);
    let got = at_pixel(&pixels);
    println!("layered view: got {got:?}, front-to-back over {want:?}");
    // The slabs round each τ = −ln(1 − α) to 1/4096: 1e-3 of the pixel's coverage here.
    assert_close(got, want, 1.5e-3, "layered view, one fiber a layer");
}

#[test]
fn layered_view_shades_each_layer_at_its_fibers_mean_tangent() {
    // 12 fibers of α = 0.3 in 4 layers: several fibers share a layer, whose colour is that of
    // their weighted mean tangent (the over operator would differ: see the assertion below).
    let (layers, opacity) = (12, 0.3);
    let (model, tangents) = stacked_strands(layers, opacity);
    let table = direct_table();
    let (pixels, counts) = render_srbf(&model, &table, ViewTransparency::layered()).unwrap();
    let want = layered(&table, &tangents, opacity as f64, 4);
    let over = composite(&table, &tangents, opacity as f64, layers);
    let got = at_pixel(&pixels);
    println!("layered view: got {got:?}, layered in f64 {want:?}, over {over:?}");
    assert_close(got, want, 1e-3, "layered view");
    assert!(
        (0..3).any(|c| (over[c] - want[c]).abs() > 0.02 * want[c]),
        "the scene must tell the layers from the fibers: {over:?} vs {want:?}"
    );
    // Where the fibers cross, a batch shades 4 layers instead of 12 fragments.
    let counts = counts.unwrap();
    assert!(
        counts.shaded + 8 <= counts.rasterized,
        "a batch shades layers, not fragments: {counts:?}"
    );
}

/// A shadowed frame of fibers of one colour (`COLOUR`) under one compact source at LIGHT: each
/// fiber is lit through those between it and the light (its deep opacity map's transmittance,
/// sharp at fiber scale).
fn render_shadowed(model: &HairModel, transparency: ViewTransparency) -> Vec<[f32; 4]> {
    render_shadowed_from(model, transparency, LIGHT)
}

/// [`render_shadowed`] with the compact source toward `light`.
fn render_shadowed_from(
    model: &HairModel,
    transparency: ViewTransparency,
    light: Vec3,
) -> Vec<[f32; 4]> {
    let options = options(transparency, true);
    let axes = direct_table().axes().to_vec();
    let table = Table::from_fn(axes, 3, |_, out| out.copy_from_slice(&COLOUR)).unwrap();
    let tables = EnvTables {
        direct: Some(table.into()),
        ..Default::default()
    };
    let sun = [EnvLight::directional(light, [1.0; 3])];
    let camera = ortho_camera();
    let frame = render_env_frame(
        &gpu(),
        model,
        &camera,
        RES,
        RES,
        &sun,
        &tables,
        &options,
        None,
    );
    frame.unwrap().pixels
}

const COLOUR: [f32; 3] = [1.0, 0.5, 0.25];

#[test]
fn layered_view_lights_a_layer_by_its_fibers_mean_visibility_of_a_compact_source() {
    // The stack of the tests above in one colour, shadowed: shading per fiber (the occupancy
    // view) sums Σ w·v·colour exactly. The layered view must read each layer's Σ w·v, not the
    // visibility at the layer's mean position (a sharp shadow's visibility is not linear in
    // position). The sun shines from in front of the stack (toward the camera, +z), so that the
    // fibers nearer the camera shadow those behind: from +x alone the fibers' centre lines lay
    // on the edges of its map's texels, where the last bit of rounding chose a texel, and the
    // per-fiber reference read 0.94 or 0.98 of the light as the light turned by 0.06°.
    let (layers, opacity) = (12, 0.3);
    let (model, _) = stacked_strands(layers, opacity);
    let per_fiber = ViewTransparency::Occupancy {
        visibility_cutoff: ViewTransparency::DEFAULT_CUTOFF,
    };
    let light = Vec3::new(1.0, 0.02, 0.8).normalize();
    let want = at_pixel(&render_shadowed_from(&model, per_fiber, light));
    let got = at_pixel(&render_shadowed_from(
        &model,
        ViewTransparency::layered(),
        light,
    ));
    println!("layered view, compact source: got {got:?}, per fiber {want:?}");
    // A quarter of the light is shadowed.
    let lit = want[3] * COLOUR[0] as f64;
    assert!(want[0] < 0.8 * lit, "{want:?}: lit in full {lit}");
    assert_close(got, want, 2e-3, "layered view, compact source");
}

#[test]
fn layered_view_sees_a_compact_sources_shadow_fall_across_the_middle_of_a_segment() {
    // The layered view's gather reads a compact source's visibility at samples along each
    // segment (segment_light_visibility.rs), not per fragment. A fiber of two long segments
    // (26 pixels each) along y, in column 32; a thicker one nearer the light (+x) casts a
    // shadow 3 pixels wide across the middle of its upper segment, where neither of the
    // segment's ends is: sampled at its ends alone, the segment would be lit all along. The
    // occupancy view, which evaluates the light's map per fragment, is the reference.
    let x = 1.0 / 64.0;
    let points = vec![
        Vec3::new(x, -0.8, 0.0),
        Vec3::new(x, 0.0, 0.0),
        Vec3::new(x, 0.8, 0.0),
        Vec3::new(0.3, 0.4, -0.3),
        Vec3::new(0.4, 0.4, 0.3),
    ];
    let thickness = vec![3.0 / 32.0, 3.0 / 32.0, 3.0 / 32.0, 0.2, 0.2];
    let model = HairModel::new(
        points,
        vec![0, 3, 5],
        Some(Attribute::PerPoint(thickness)),
        None,
        None,
    )
    .unwrap();
    let column = |pixels: &[[f32; 4]]| -> Vec<f64> {
        (0..RES as usize)
            .map(|row| pixels[row * RES as usize + 32])
            .filter(|p| p[3] > 0.99)
            .map(|p| p[0] as f64)
            .collect()
    };
    let per_fiber = ViewTransparency::Occupancy {
        visibility_cutoff: ViewTransparency::DEFAULT_CUTOFF,
    };
    let want = column(&render_shadowed(&model, per_fiber));
    let got = column(&render_shadowed(&model, ViewTransparency::layered()));
    let darkest = |c: &[f64]| c.iter().cloned().fold(f64::INFINITY, f64::min);
    let lit = COLOUR[0] as f64;
    let sum = |c: &[f64]| c.iter().sum::<f64>();
    println!(
        "shadow across a segment: {} pixels, darkest {:.3} (per fiber {:.3}) of {lit}, sum {:.3} \
         (per fiber {:.3})",
        got.len(),
        darkest(&got),
        darkest(&want),
        sum(&got),
        sum(&want)
    );
    assert!(
        want.len() >= 40 && got.len() == want.len(),
        "{want:?} {got:?}"
    );
    assert!(
        darkest(&want) < 0.5 * lit,
        "the reference sees the shadow: {want:?}"
    );
    assert!(
        darkest(&got) < 0.5 * lit,
        "the layered view misses the shadow: {got:?}"
    );
    let row_of_darkest = |c: &[f64]| (0..c.len()).min_by(|&a, &b| c[a].total_cmp(&c[b]));
    let rows = (
        row_of_darkest(&got).unwrap(),
        row_of_darkest(&want).unwrap(),
    );
    assert!(
        rows.0.abs_diff(rows.1) <= 2,
        "the shadow falls at row {rows:?}"
    );
    // Between two samples the visibility is blended linearly: each of the shadow's two edges
    // is blurred over at most one interval (2 pixels at most on screen).
    assert!(
        (sum(&got) - sum(&want)).abs() < 2.0 * 2.0 * lit,
        "the shadow's light along the fiber: {got:?} against {want:?}"
    );
}

#[test]
fn layered_view_shades_lights_standing_for_regions_per_layer() {
    // The same scene under a light standing for a region of the map (a reference texel, a
    // median-cut region: its true shadow is soft at fiber scale) is shaded per layer, as an
    // SRBF lobe is; between two of them, a compact source is batched apart (its layers read
    // their fibers' mean visibility, all 1 unshadowed), so the frame is three layered pixels.
    let (layers, opacity) = (12, 0.3);
    let (model, tangents) = stacked_strands(layers, opacity);
    let table = direct_table();
    let want = layered(&table, &tangents, opacity as f64, 4);
    let over = composite(&table, &tangents, opacity as f64, layers);
    let region = |kinds: &[Kind]| {
        let (pixels, _) =
            render_lit(&model, &table, ViewTransparency::layered(), kinds, RES, RES).unwrap();
        at_pixel(&pixels)
    };
    let got = region(&[Kind::Region]);
    println!("layered view, region light: got {got:?}, layered {want:?}, over {over:?}");
    assert_close(got, want, 1e-3, "layered view, region light");
    let mixed = region(&[Kind::Region, Kind::Directional, Kind::Region]);
    let mixed_want: [f64; 4] = std::array::from_fn(|c| 3.0 * want[c]);
    println!("layered view, region, sun, region: got {mixed:?}, want {mixed_want:?}");
    let rgb = |p: [f64; 4]| [p[0], p[1], p[2], 0.0];
    assert_close(
        rgb(mixed),
        rgb(mixed_want),
        3e-3,
        "layered view, mixed lights",
    );
}

#[test]
fn opaque_view_shows_the_nearest_fiber_with_the_coverage_of_all() {
    let (layers, opacity) = (5, 0.6);
    let (model, tangents) = stacked_strands(layers, opacity);
    let table = direct_table();
    let (pixels, counts) = render(&model, &table, ViewTransparency::Opaque).unwrap();
    // The nearest fiber's colour at the pixel's total coverage 1 − (1 − α)^N.
    let coverage = 1.0 - (1.0 - opacity as f64).powi(layers as i32);
    let front = colour(&table, tangents[0]);
    let want = [
        front[0] * coverage,
        front[1] * coverage,
        front[2] * coverage,
        coverage,
    ];
    assert_close(at_pixel(&pixels), want, 1e-4, "opaque view");
    let counts = counts.unwrap();
    // Only the nearest fragment of each covered pixel is shaded.
    let covered = pixels.iter().filter(|p| p[3] > 0.0).count() as u64;
    println!("opaque: {counts:?}, {covered} covered pixels");
    assert!(
        counts.shaded >= covered && counts.shaded < counts.rasterized,
        "{counts:?}"
    );
}

#[test]
fn transparency_settings_and_limits_are_typed_errors() {
    let (model, _) = stacked_strands(2, 0.5);
    let table = direct_table();
    for cutoff in [-0.1, 1.0, f32::NAN] {
        let e = render(
            &model,
            &table,
            ViewTransparency::Occupancy {
                visibility_cutoff: cutoff,
            },
        )
        .unwrap_err();
        assert!(
            matches!(e, EnvRenderError::Transparency(OccupancyError::Cutoff(_))),
            "cutoff {cutoff}: {e}"
        );
    }
    // The largest image the adapter allows needs an occupancy map over its binding limit.
    let max = gpu().device.limits().max_texture_dimension_2d;
    let e = render_sized(&model, &table, ViewTransparency::occupancy(), max, max).unwrap_err();
    println!("{max}×{max}: {e}");
    assert!(
        matches!(
            e,
            EnvRenderError::Transparency(OccupancyError::TooLarge { .. })
        ),
        "{e}"
    );
}
