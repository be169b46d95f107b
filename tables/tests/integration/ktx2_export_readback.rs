//! The KTX2 export read back by a reader this project did not write (the `ktx2` crate) and
//! compared value for value with the `.sltab` table it came from: bit for bit in float, and
//! against `half`'s own rounding of each f32 value in half. The documented sampling formula
//! (texel centres, two slabs of the fourth axis) is then emulated on the texels read back and
//! compared with `Table::lookup`, the runtime's lookup.

use half::f16;
use ktx2::dfd::{Basic, Block};
use ktx2::{Format, Reader};
use serde_json::Value;
use std::path::{Path, PathBuf};
use strandlight_tables::asset::{
    AssetDescription, CreationInfo, Generator, Storage, TableAsset, read_asset, write_asset,
};
use strandlight_tables::lut_export::{
    LutExportError, TexelStorage, WGSL_FILE, export_ktx2, write_wgsl,
};
use strandlight_tables::table::{Axis, AxisMapping, Table};

fn scratch(label: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("strandlight-ktx2-{label}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A deterministic value spread over 12 decades (half's subnormals included) and both signs.
fn value(k: usize) -> f32 {
    let h = (k as u64 + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    let mantissa = (h >> 40) as f64 / (1u64 << 24) as f64;
    let decade = (h >> 20) % 12;
    let sign = if h & 1 == 0 { 1.0 } else { -1.0 };
    (sign * (0.5 + mantissa) * 10f64.powi(decade as i32 - 8)) as f32
}

/// Env-table-like axes (arcsine, arccosine, uniform) with distinct counts, so that any
/// transposition of the layout lands values on the wrong texels.
fn env_like_axes(counts: &[usize]) -> Vec<Axis> {
    let kinds = [
        ("u_dot_xi", -1.0, 1.0, AxisMapping::Arcsine),
        ("u_dot_wo", -1.0, 1.0, AxisMapping::Arcsine),
        ("cos_dphi", -1.0, 1.0, AxisMapping::Arccosine),
        ("inv_lambda", 1.0 / 64.0, 1.0 / 16.0, AxisMapping::Uniform),
    ];
    counts
        .iter()
        .zip(kinds)
        .map(|(&n, (name, lo, hi, m))| {
            Axis::with_mapping(name, lo, if n == 1 { lo } else { hi }, n, m)
        })
        .collect()
}

fn asset(dir: &Path, name: &str, counts: &[usize], channels: usize) -> TableAsset {
    let axes = env_like_axes(counts);
    let n: usize = counts.iter().product::<usize>() * channels;
    let table = Table::new(axes, channels, (0..n).map(value).collect()).unwrap();
    let description = AssetDescription {
        name: name.into(),
        quantity: "test values".into(),
        scattering_function: "none".into(),
        fiber_parameters: serde_json::json!({}),
        generator: Generator {
            name: "test".into(),
            version: "0".into(),
        },
        created: CreationInfo {
            unix_time_s: 0,
            command_line: None,
            notes: None,
        },
        inputs_key: None,
    };
    let path = dir.join(format!("{name}.sltab"));
    write_asset(&path, &table, &description, Storage::F32).unwrap();
    read_asset(&path).unwrap()
}

/// The texel of node `index`, written out from the documented rule (not the crate's code).
fn documented_texel(counts: &[usize], index: &[usize]) -> [usize; 3] {
    match index.len() {
        1 => [index[0], 0, 0],
        2 => [index[1], index[0], 0],
        3 => [index[2], index[1], index[0]],
        _ => [index[2], index[1], index[3] * counts[0] + index[0]],
    }
}

/// Every component of every texel, decoded by `half` or from f32 bits, x fastest.
fn decode(reader: &Reader<Vec<u8>>) -> Vec<f32> {
    let level = reader.levels().next().unwrap();
    assert_eq!(level.data.len() as u64, level.uncompressed_byte_length);
    match reader.header().type_size {
        2 => level
            .data
            .chunks_exact(2)
            .map(|b| f16::from_le_bytes([b[0], b[1]]).to_f32())
            .collect(),
        _ => level
            .data
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes(b.try_into().unwrap()))
            .collect(),
    }
}

fn node_indices(counts: &[usize]) -> Vec<Vec<usize>> {
    let mut all = vec![vec![]];
    for &n in counts {
        all = all
            .into_iter()
            .flat_map(|prefix| {
                (0..n).map(move |i| {
                    let mut v = prefix.clone();
                    v.push(i);
                    v
                })
            })
            .collect();
    }
    all
}

/// Reads the export of `asset` back with the `ktx2` crate and checks it value for value.
fn check_round_trip(asset: &TableAsset, dir: &Path, storage: TexelStorage) -> Vec<f32> {
    let exported = export_ktx2(asset, dir, storage).unwrap();
    let reader = Reader::new(std::fs::read(&exported.texture).unwrap()).unwrap();
    let header = reader.header();
    let table = &asset.table;
    let counts = table.shape();
    let channels = table.channels();
    let format = match (storage, channels) {
        (TexelStorage::Half, 1) => Format::R16_SFLOAT,
        (TexelStorage::Half, _) => Format::R16G16B16A16_SFLOAT,
        (TexelStorage::Float, 1) => Format::R32_SFLOAT,
        (TexelStorage::Float, _) => Format::R32G32B32A32_SFLOAT,
    };
    assert_eq!(header.format, Some(format));
    let (expected_dfd, type_size) = Basic::from_format(format).unwrap();
    assert_eq!(header.type_size, type_size);
    assert_eq!(
        reader.dfd_blocks(),
        &[Block::Basic(expected_dfd)],
        "the DFD is the one the ktx2 crate generates for {format:?}"
    );
    assert_eq!(header.level_count, 1);
    assert_eq!(header.layer_count, 0);
    assert_eq!(header.face_count, 1);
    assert!(reader.writer().unwrap().starts_with("strandlight "));
    let depth = match counts.len() {
        1 | 2 => 0,
        3 => counts[0],
        _ => counts[0] * counts[3],
    };
    let (w, h) = match counts.len() {
        1 => (counts[0], 1),
        2 => (counts[1], counts[0]),
        _ => (counts[2], counts[1]),
    };
    assert_eq!(
        (header.pixel_width, header.pixel_height, header.pixel_depth),
        (w as u32, h as u32, depth as u32)
    );

    let components = if channels == 1 { 1 } else { 4 };
    let texels = decode(&reader);
    assert_eq!(texels.len(), w * h * depth.max(1) * components);
    for index in node_indices(&counts) {
        let [x, y, z] = documented_texel(&counts, &index);
        let at = ((z * h + y) * w + x) * components;
        let want = table.node(&index).unwrap();
        for c in 0..components {
            let got = texels[at + c];
            let expected = match (c < channels, storage) {
                (false, _) => 1.0,
                (true, TexelStorage::Float) => want[c],
                (true, TexelStorage::Half) => f16::from_f32(want[c]).to_f32(),
            };
            assert_eq!(
                got.to_bits(),
                expected.to_bits(),
                "node {index:?} channel {c}: texel {got}, table {}",
                if c < channels { want[c] } else { 1.0 }
            );
        }
    }
    texels
}

#[test]
fn every_table_shape_reads_back_value_for_value_in_half_and_float() {
    let dir = scratch("shapes");
    for (name, counts, channels) in [
        ("four_axes_rgb", &[5, 6, 7, 3][..], 3),
        ("direct_like", &[4, 5, 6, 1][..], 3),
        ("three_axes_scalar", &[3, 4, 5][..], 1),
        ("two_axes_rgb", &[6, 9][..], 3),
        ("one_axis_scalar", &[11][..], 1),
    ] {
        let asset = asset(&dir, name, counts, channels);
        for storage in [TexelStorage::Half, TexelStorage::Float] {
            check_round_trip(&asset, &dir, storage);
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// One texel component, clamped to the edge, from the read-back texels.
fn fetch(texels: &[f32], size: [usize; 3], texel: [i64; 3], c: usize) -> f64 {
    let clamp = |v: i64, n: usize| v.clamp(0, n.max(1) as i64 - 1) as usize;
    let [x, y, z] = [
        clamp(texel[0], size[0]),
        clamp(texel[1], size[1]),
        clamp(texel[2], size[2]),
    ];
    texels[((z * size[1] + y) * size[0] + x) * 4 + c] as f64
}

/// A linear-filtering, clamp-to-edge sampler at normalized coordinates, in f64.
fn trilinear(texels: &[f32], size: [usize; 3], uvw: [f64; 3], c: usize) -> f64 {
    let p: Vec<f64> = (0..3).map(|k| uvw[k] * size[k] as f64 - 0.5).collect();
    let base: Vec<i64> = p.iter().map(|v| v.floor() as i64).collect();
    let frac: Vec<f64> = p.iter().zip(&base).map(|(v, b)| v - *b as f64).collect();
    let mut acc = 0.0;
    for corner in 0..8 {
        let mut weight = 1.0;
        let mut texel = [0i64; 3];
        for k in 0..3 {
            let upper = corner >> k & 1 == 1;
            weight *= if upper { frac[k] } else { 1.0 - frac[k] };
            texel[k] = base[k] + upper as i64;
        }
        if weight != 0.0 {
            acc += weight * fetch(texels, size, texel, c);
        }
    }
    acc
}

/// The sidecar's formula on the read-back texels reproduces `Table::lookup` off the grid.
#[test]
fn the_documented_sampling_formula_reproduces_the_table_lookup() {
    let dir = scratch("formula");
    let asset = asset(&dir, "formula", &[5, 6, 7, 3], 3);
    let texels = check_round_trip(&asset, &dir, TexelStorage::Float);
    let sidecar: Value =
        serde_json::from_slice(&std::fs::read(dir.join("formula.json")).unwrap()).unwrap();
    let size = [
        sidecar["texture"]["width"].as_u64().unwrap() as usize,
        sidecar["texture"]["height"].as_u64().unwrap() as usize,
        sidecar["texture"]["depth"].as_u64().unwrap() as usize,
    ];
    let axes = asset.table.axes();
    let n: Vec<f64> = axes.iter().map(|a| a.count as f64).collect();
    let table_max = asset
        .table
        .values()
        .iter()
        .fold(0.0f64, |m, v| m.max(v.abs() as f64));
    let mut worst = 0.0f64;
    for k in 0..500 {
        // Coordinates over and a little beyond each axis's range (clamped).
        let coords: Vec<f64> = axes
            .iter()
            .enumerate()
            .map(|(a, axis)| {
                let t = (value(7 * k + a).abs() as f64).fract() * 1.1 - 0.05;
                axis.min + (axis.max - axis.min) * t
            })
            .collect();
        let f: Vec<f64> = axes
            .iter()
            .zip(&coords)
            .map(|(a, &x)| a.position(x).unwrap())
            .collect();
        let slab = f[3].floor().min((n[3] - 2.0).max(0.0));
        let weight = f[3] - slab;
        let u = (f[2] + 0.5) / n[2];
        let v = (f[1] + 0.5) / n[1];
        let w = |s: f64| (s * n[0] + f[0] + 0.5) / (n[0] * n[3]);
        let want = asset.table.lookup_rgb(&coords).unwrap();
        for (c, &lookup) in want.iter().enumerate() {
            let lower = trilinear(&texels, size, [u, v, w(slab)], c);
            let upper = trilinear(&texels, size, [u, v, w(slab + 1.0)], c);
            let got = (1.0 - weight) * lower + weight * upper;
            let error = (got - lookup as f64).abs() / table_max;
            worst = worst.max(error);
            assert!(
                error <= 1e-6,
                "{coords:?} channel {c}: formula {got}, lookup {lookup}"
            );
        }
    }
    eprintln!("formula vs lookup: 500 points, worst error {worst:.2e} of the table maximum");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_sidecar_and_wgsl_describe_the_texture() {
    let dir = scratch("sidecar");
    let asset = asset(&dir, "described", &[5, 6, 7, 3], 3);
    let exported = export_ktx2(&asset, &dir, TexelStorage::Half).unwrap();
    let sidecar: Value =
        serde_json::from_slice(&std::fs::read(&exported.sidecar).unwrap()).unwrap();
    assert_eq!(sidecar["texture"]["file"], "described.ktx2");
    assert_eq!(sidecar["texture"]["webgpu_format"], "rgba16float");
    assert_eq!(sidecar["texture"]["dimension"], "3d");
    assert_eq!(
        (
            &sidecar["texture"]["width"],
            &sidecar["texture"]["height"],
            &sidecar["texture"]["depth"]
        ),
        (&Value::from(7), &Value::from(6), &Value::from(15))
    );
    let axes = sidecar["axes"].as_array().unwrap();
    assert_eq!(axes.len(), 4);
    assert_eq!(axes[2]["name"], "cos_dphi");
    assert_eq!(axes[2]["mapping"]["kind"], "arccosine");
    assert_eq!(axes[3]["count"], 3);
    assert!(axes[0]["meaning"].as_str().unwrap().contains("u·ξ"));
    let uniform = sidecar["wgsl"]["uniform"].as_array().unwrap();
    assert_eq!(uniform.len(), 4);
    assert_eq!(uniform[2]["warp"], 2);
    assert_eq!(uniform[3]["last_index"], 2.0);
    let rounding = &sidecar["half_rounding"]["max_relative_error"];
    assert!(rounding.as_f64().unwrap() <= 2f64.powi(-11), "{rounding}");

    let wgsl = write_wgsl(&dir).unwrap();
    assert_eq!(wgsl, dir.join(WGSL_FILE));
    let text = std::fs::read_to_string(wgsl).unwrap();
    for function in [
        "strandlight_lut_3d",
        "strandlight_lut_2d",
        "strandlight_lut_3d_exact",
        "strandlight_lut_2d_exact",
    ] {
        assert!(text.contains(&format!("fn {function}(")), "{function}");
    }
    assert_eq!(
        sidecar["wgsl"]["exact_function"],
        "strandlight_lut_3d_exact"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn refusals_name_the_file_and_leave_nothing_behind() {
    let dir = scratch("refusals");
    let mut big = asset(&dir, "big", &[3, 4], 1);
    let mut values = big.table.values().to_vec();
    values[5] = 7.0e4;
    big.table = Table::new(big.table.axes().to_vec(), 1, values)
        .unwrap()
        .into();
    let err = export_ktx2(&big, &dir, TexelStorage::Half).unwrap_err();
    assert!(
        matches!(&err, LutExportError::HalfOverflow { node, .. } if node == &vec![1, 1]),
        "{err}"
    );
    assert!(err.to_string().contains("big.ktx2") && err.to_string().contains("float"));
    assert!(!dir.join("big.ktx2").exists());
    export_ktx2(&big, &dir, TexelStorage::Float).unwrap();

    let five = asset(&dir, "five", &[2, 2, 2, 2], 1);
    let five = TableAsset {
        table: Table::new(
            [five.table.axes(), &[Axis::uniform("extra", 0.0, 1.0, 2)]].concat(),
            1,
            vec![0.5; 32],
        )
        .unwrap()
        .into(),
        ..five
    };
    let err = export_ktx2(&five, &dir, TexelStorage::Float).unwrap_err();
    assert!(
        matches!(err, LutExportError::TooManyAxes { axes: 5, .. }),
        "{err}"
    );

    let blocked = dir.join("not-a-folder");
    std::fs::write(&blocked, b"file").unwrap();
    let err = export_ktx2(&big, &blocked, TexelStorage::Float).unwrap_err();
    assert!(err.to_string().contains("not-a-folder"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}
