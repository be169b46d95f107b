//! The round trip of every load that succeeds (issue #39): what the reader loaded is written
//! back with the project's writer for that kind of data, loaded again, and compared with the
//! first load. A difference, a writer that refuses what the reader accepted, or a written file
//! that does not load is a finding like a panic.
//!
//! | target | written with | loaded again with | compared, bit for bit |
//! | --- | --- | --- | --- |
//! | `hair`, `tfx`, `ply`, `usda`, `usdc`, `usdz`, `abc` | `hair::yuksel::encode_hair` (`.tfx`, `.ply`, USD and Alembic have no writer here; `.hair` is the strand format the project writes that carries widths and colours) | `parse_hair` | strand offsets, positions, thickness, transparency, colour (an attribute the source lacks must come back as the `.hair` header default the writer documents); the info text |
//! | `data` | `hair::usc::encode_usc` | `parse_usc` | strand offsets and positions (all the format holds) |
//! | `hdr`, `exr` | `envmap_io::write_exr` (f32 RGB) | `envmap_io::load`, sanitizing off | size and every pixel; no bad pixel |
//! | `sltab` | `asset::write_asset_to`, in the storage it was read in | `asset::read_asset` | metadata (descriptions, axes, payload checksum) and every value |
//! | `srbf` | `SrbfSet::to_json` (what `save` writes) | `SrbfSet::from_json` | every field (the sets are equal and so is their JSON) |
//! | `glb`, `gltf` | `head_input::write_obj` (the head file the Mitsuba truth reads) | `head_input::load_obj` | every triangle's corners: position and normal (OBJ drops vertices no triangle uses, so corners, not the vertex list) |
//!
//! No tolerance anywhere, and none is needed: the writers store what is in memory exactly.
//! Positions, widths and colours are f32 in the model and f32 in `.hair` and `.data`. Radiance
//! files are decoded to f32 pixels, which are then written as f32 EXR, a lossless store of the
//! map in memory (re-encoding RGBE would quantise them to 8-bit mantissas again, which is not
//! what loading does to a map). A table read from f16 storage holds f16 values widened to f32,
//! which narrow back to the same halves; f32 storage is f32. JSON numbers are written in their
//! shortest exact form and parsed with `serde_json`'s `float_roundtrip`. The comparison is of
//! bit patterns (`to_bits`), so even a signed zero that flips is a finding.
//!
//! The one thing not called a finding: a model the `.hair` writer cannot represent (a strand
//! of more than 65 536 points) loaded from `.tfx`, `.ply`, USD or Alembic, whose formats have no
//! such limit.
//! It is counted in the report. From `.hair` itself, it is a finding.

use std::path::Path;

use glam::Vec3;
use strandlight_precompute::envmap_io::{self, LoadOptions};
use strandlight_runtime::hair::{self, Attribute, HairError, HairFormat, HairWriteOptions};
use strandlight_runtime::head::TriangleMesh;
use strandlight_scene::head_input::{load_obj, write_obj};
use strandlight_tables::asset;

use super::targets::{Loaded, ScratchFile};

/// What writing a load back and loading it again gave.
#[derive(Clone, Debug)]
pub enum Reloaded {
    Loaded(Box<Loaded>),
    /// The written format cannot hold the data (not a finding; see the module docs).
    NotRepresentable(String),
}

/// The writer and reader each target's loads go through, for the report.
pub fn describe(target: &str) -> &'static str {
    match target {
        "hair" | "tfx" | "ply" | "usda" | "usdc" | "usdz" | "abc" => {
            "hair::yuksel::encode_hair → parse_hair"
        }
        "data" => "hair::usc::encode_usc → parse_usc",
        "hdr" | "exr" => "envmap_io::write_exr (f32) → envmap_io::load",
        "sltab" => "asset::write_asset_to → asset::read_asset",
        "srbf" => "SrbfSet::to_json → SrbfSet::from_json",
        "glb" | "gltf" => "head_input::write_obj → load_obj",
        other => panic!("no round trip for target {other}"),
    }
}

/// The most bytes of the `.hair` header's info field the writer takes (it keeps one NUL).
const INFO_MAX: usize = 87;

/// The info text written back: the loaded one cut to what the `.hair` writer takes. The field
/// is 88 bytes and the reader keeps all of them when none is NUL (and invalid UTF-8 grows when
/// replaced), so a loaded text may be longer than a written one can be. Free text, not strand
/// data: it is compared as cut.
fn writable_info(info: &str) -> &str {
    let mut end = info.len().min(INFO_MAX);
    while !info.is_char_boundary(end) {
        end -= 1;
    }
    &info[..end]
}

/// Writes `first` with the project's writer for its kind and loads the result again.
pub fn write_and_reload(first: &Loaded) -> Result<Reloaded, String> {
    match first {
        Loaded::Hair(h) => reload_hair(h),
        Loaded::EnvMap(e) => {
            let path = super::scratch_dir().join("fuzz-round-trip.exr");
            envmap_io::write_exr(&e.map, &path)
                .map_err(|e| format!("write_exr refused the loaded map: {e}"))?;
            let again = envmap_io::load(&path, LoadOptions { sanitize: false })
                .map_err(|e| format!("the map written by write_exr does not load: {e}"))?;
            Ok(Reloaded::Loaded(Box::new(Loaded::EnvMap(again))))
        }
        Loaded::Asset(a) => {
            static FILE: std::sync::OnceLock<ScratchFile> = std::sync::OnceLock::new();
            let file = FILE.get_or_init(|| ScratchFile::new("fuzz-round-trip.sltab"));
            let description = &a.metadata.description;
            let storage = a.metadata.payload.storage;
            file.rewrite(|f| asset::write_asset_to(f, file.path(), &a.table, description, storage))
                .map_err(|e| format!("write_asset_to refused the loaded asset: {e}"))?;
            let again = asset::read_asset(file.path())
                .map_err(|e| format!("the asset written by write_asset_to does not load: {e}"))?;
            Ok(Reloaded::Loaded(Box::new(Loaded::Asset(again))))
        }
        Loaded::Srbf(s) => {
            let again = strandlight_precompute::SrbfSet::from_json(
                Path::new("fuzz-round-trip.srbf.json"),
                &s.to_json(),
            )
            .map_err(|e| format!("the set written by to_json does not load: {e}"))?;
            Ok(Reloaded::Loaded(Box::new(Loaded::Srbf(again))))
        }
        Loaded::Head(mesh) => {
            let path = super::scratch_dir().join("fuzz-round-trip.obj");
            write_obj(mesh, &path).map_err(|e| format!("write_obj refused the head: {e:#}"))?;
            let again = load_obj(&path)
                .map_err(|e| format!("the head written by write_obj does not load: {e:#}"))?;
            Ok(Reloaded::Loaded(Box::new(Loaded::Head(again))))
        }
    }
}

fn reload_hair(first: &hair::LoadedHair) -> Result<Reloaded, String> {
    let model = &first.model;
    if first.report.format == HairFormat::UscHairSalon {
        let bytes = hair::usc::encode_usc(model);
        let again = hair::usc::parse_usc(&bytes, Path::new("fuzz-round-trip.data"))
            .map_err(|e| format!("the .data written by encode_usc does not load: {e}"))?;
        return Ok(Reloaded::Loaded(Box::new(Loaded::Hair(again))));
    }
    let offsets = model.strand_offsets();
    let ragged = offsets
        .windows(2)
        .any(|w| w[1] - w[0] != offsets[1] - offsets[0]);
    let options = HairWriteOptions {
        // Without the array where every strand has the same length, so both layouts are written.
        segments_array: ragged,
        info: writable_info(&first.report.info).to_string(),
    };
    let file = Path::new("fuzz-round-trip.hair");
    let bytes = match hair::yuksel::encode_hair(model, &options, file) {
        Ok(bytes) => bytes,
        Err(e @ HairError::NotRepresentable { .. })
            if first.report.format != HairFormat::Yuksel =>
        {
            return Ok(Reloaded::NotRepresentable(e.to_string()));
        }
        Err(e) => return Err(format!("encode_hair refused the loaded model: {e}")),
    };
    let again = hair::yuksel::parse_hair(&bytes, file)
        .map_err(|e| format!("the .hair written by encode_hair does not load: {e}"))?;
    Ok(Reloaded::Loaded(Box::new(Loaded::Hair(again))))
}

/// Whether `second` (loaded from what was written of `first`) holds the same data; the first
/// difference otherwise.
pub fn compare(first: &Loaded, second: &Loaded) -> Result<(), String> {
    match (first, second) {
        (Loaded::Hair(a), Loaded::Hair(b)) => compare_hair(a, b),
        (Loaded::EnvMap(a), Loaded::EnvMap(b)) => compare_maps(&a.map, &b.map),
        (Loaded::Asset(a), Loaded::Asset(b)) => compare_assets(a, b),
        (Loaded::Srbf(a), Loaded::Srbf(b)) => {
            let (x, y) = (a.to_json(), b.to_json());
            if a == b && x == y {
                return Ok(());
            }
            let (x, y) = (String::from_utf8_lossy(&x), String::from_utf8_lossy(&y));
            let line = x
                .lines()
                .zip(y.lines())
                .position(|(p, q)| p != q)
                .unwrap_or(x.lines().count().min(y.lines().count()));
            Err(format!(
                "SRBF sets differ at line {} of their JSON: {:?} then {:?}",
                line + 1,
                x.lines().nth(line).unwrap_or("(end)"),
                y.lines().nth(line).unwrap_or("(end)")
            ))
        }
        (Loaded::Head(a), Loaded::Head(b)) => compare_heads(a, b),
        _ => Err("loaded again as another kind of data".into()),
    }
}

/// Every triangle's corners, position and normal, bit for bit.
fn compare_heads(a: &TriangleMesh, b: &TriangleMesh) -> Result<(), String> {
    let corners = |m: &TriangleMesh, of: fn(&TriangleMesh) -> &[Vec3]| -> Vec<Vec3> {
        m.indices.iter().map(|&i| of(m)[i as usize]).collect()
    };
    for (what, of) in [
        (
            "position",
            (|m: &TriangleMesh| &m.positions[..]) as fn(&TriangleMesh) -> &[Vec3],
        ),
        ("normal", |m: &TriangleMesh| &m.normals[..]),
    ] {
        let (x, y) = (corners(a, of), corners(b, of));
        if let Some(i) = first_difference(&x, &y) {
            return Err(format!(
                "head: triangle {} corner {}: {what} {:?} then {:?}",
                i / 3,
                i % 3,
                x.get(i),
                y.get(i)
            ));
        }
    }
    Ok(())
}

/// The bit patterns of a value, for comparisons that tell −0 from +0 and see every ulp.
trait Bits: Copy + std::fmt::Debug {
    fn bits(self) -> [u32; 3];
}

impl Bits for f32 {
    fn bits(self) -> [u32; 3] {
        [self.to_bits(), 0, 0]
    }
}

impl Bits for Vec3 {
    fn bits(self) -> [u32; 3] {
        self.to_array().map(f32::to_bits)
    }
}

/// The index of the first value whose bits differ, or of the end of the shorter slice.
fn first_difference<T: Bits>(a: &[T], b: &[T]) -> Option<usize> {
    let n = a.len().min(b.len());
    (0..n)
        .find(|&i| a[i].bits() != b[i].bits())
        .or((a.len() != b.len()).then_some(n))
}

fn compare_attribute<T: Bits>(
    name: &str,
    first: Option<&Attribute<T>>,
    second: Option<&Attribute<T>>,
) -> Result<(), String> {
    let differs = |detail: String| Err(format!("{name}: {detail}"));
    match (first, second) {
        (None, None) => Ok(()),
        (Some(Attribute::Uniform(a)), Some(Attribute::Uniform(b))) => {
            if a.bits() == b.bits() {
                Ok(())
            } else {
                differs(format!("uniform {a:?} then {b:?}"))
            }
        }
        (Some(Attribute::PerPoint(a)), Some(Attribute::PerPoint(b))) => {
            match first_difference(a, b) {
                None => Ok(()),
                Some(i) => differs(format!(
                    "point {i} of {}: {:?} then {:?} (of {})",
                    a.len(),
                    a.get(i),
                    b.get(i),
                    b.len()
                )),
            }
        }
        (a, b) => differs(format!("{} then {}", shape(a), shape(b))),
    }
}

fn shape<T>(a: Option<&Attribute<T>>) -> &'static str {
    match a {
        None => "absent",
        Some(Attribute::Uniform(_)) => "uniform",
        Some(Attribute::PerPoint(_)) => "per point",
    }
}

fn compare_hair(first: &hair::LoadedHair, second: &hair::LoadedHair) -> Result<(), String> {
    let (a, b) = (&first.model, &second.model);
    let report = &second.report;
    if report.degenerate_segments_merged != 0 || report.short_strands_dropped != 0 {
        return Err(format!(
            "loading the written file cleaned it again: {} segments merged, {} strands dropped",
            report.degenerate_segments_merged, report.short_strands_dropped
        ));
    }
    if a.strand_offsets() != b.strand_offsets() {
        let (x, y) = (a.strand_offsets(), b.strand_offsets());
        let s = (0..x.len().min(y.len()))
            .find(|&i| x[i] != y[i])
            .unwrap_or(x.len().min(y.len()));
        return Err(format!(
            "strands: {} strands of {} points then {} of {}; offset {s}: {:?} then {:?}",
            a.strand_count(),
            a.point_count(),
            b.strand_count(),
            b.point_count(),
            x.get(s),
            y.get(s)
        ));
    }
    if let Some(i) = first_difference(a.points(), b.points()) {
        return Err(format!(
            "position of point {i}: {:?} then {:?}",
            a.points().get(i),
            b.points().get(i)
        ));
    }
    // `.hair` stores every attribute: one the source lacks comes back as the header default
    // the writer documents (thickness 1, transparency 0, colour white).
    let yuksel = report.format == HairFormat::Yuksel;
    let or_default =
        |x: Option<Attribute<f32>>, d: f32| x.or(yuksel.then_some(Attribute::Uniform(d)));
    let thickness = or_default(a.thickness().cloned(), 1.0);
    let transparency = or_default(a.transparency().cloned(), 0.0);
    let color = a
        .color()
        .cloned()
        .or(yuksel.then_some(Attribute::Uniform(Vec3::ONE)));
    compare_attribute("thickness", thickness.as_ref(), b.thickness())?;
    compare_attribute("transparency", transparency.as_ref(), b.transparency())?;
    compare_attribute("colour", color.as_ref(), b.color())?;
    if yuksel && report.info != writable_info(&first.report.info) {
        return Err(format!(
            "info text {:?} then {:?}",
            writable_info(&first.report.info),
            report.info
        ));
    }
    Ok(())
}

fn compare_maps(
    a: &strandlight_precompute::EnvMap,
    b: &strandlight_precompute::EnvMap,
) -> Result<(), String> {
    if (a.width(), a.height()) != (b.width(), b.height()) {
        return Err(format!(
            "size {}×{} then {}×{}",
            a.width(),
            a.height(),
            b.width(),
            b.height()
        ));
    }
    let bits = |p: &[f32; 3]| p.map(f32::to_bits);
    match (a.pixels().iter().zip(b.pixels())).position(|(p, q)| bits(p) != bits(q)) {
        None => Ok(()),
        Some(i) => Err(format!(
            "pixel ({}, {}): {:?} then {:?}",
            i % a.width(),
            i / a.width(),
            a.pixels()[i],
            b.pixels()[i]
        )),
    }
}

fn compare_assets(a: &asset::TableAsset, b: &asset::TableAsset) -> Result<(), String> {
    if a.metadata.description != b.metadata.description {
        return Err(format!(
            "description {:?} then {:?}",
            a.metadata.description, b.metadata.description
        ));
    }
    if a.metadata.payload != b.metadata.payload {
        return Err(format!(
            "payload {:?} then {:?}",
            a.metadata.payload, b.metadata.payload
        ));
    }
    if a.table.axes() != b.table.axes() || a.table.channels() != b.table.channels() {
        return Err(format!(
            "table shape {:?} × {} then {:?} × {}",
            a.table.axes(),
            a.table.channels(),
            b.table.axes(),
            b.table.channels()
        ));
    }
    match first_difference(a.table.values(), b.table.values()) {
        None => Ok(()),
        Some(i) => Err(format!(
            "table value {i}: {:?} then {:?}",
            a.table.values().get(i),
            b.table.values().get(i)
        )),
    }
}

/// Changes the last bit of one value of `loaded` (a position, a pixel, a table value, the SRBF
/// set's `seconds`): what a writer or reader that loses one ulp would do. For the test that the
/// round-trip check can fail.
pub fn corrupt(loaded: &mut Loaded) {
    let flip = |v: f32| f32::from_bits(v.to_bits() ^ 1);
    match loaded {
        Loaded::Hair(h) => {
            let m = &h.model;
            let mut points = m.points().to_vec();
            let last = points.len() - 1;
            points[last].x = flip(points[last].x);
            h.model = hair::HairModel::new(
                points,
                m.strand_offsets().to_vec(),
                m.thickness().cloned(),
                m.transparency().cloned(),
                m.color().cloned(),
            )
            .expect("one ulp keeps a point finite");
        }
        Loaded::EnvMap(e) => {
            let mut pixels = e.map.pixels().to_vec();
            pixels[0][1] = flip(pixels[0][1]);
            e.map =
                strandlight_precompute::EnvMap::from_pixels(e.map.width(), e.map.height(), pixels);
        }
        Loaded::Asset(a) => {
            let t = &a.table;
            let mut values = t.values().to_vec();
            values[0] = flip(values[0]);
            a.table =
                strandlight_tables::table::Table::new(t.axes().to_vec(), t.channels(), values)
                    .expect("the same shape")
                    .into();
        }
        Loaded::Srbf(s) => s.seconds = f64::from_bits(s.seconds.to_bits() ^ 1),
        Loaded::Head(m) => {
            let mut positions = m.positions.clone();
            let first = m.indices[0] as usize;
            positions[first].x = flip(positions[first].x);
            *m = TriangleMesh::new(positions, m.normals.clone(), m.indices.clone());
        }
    }
}

/// A 64-bit hash of everything the round trip of `loaded` depends on: the writers and readers
/// are deterministic, so a load with the fingerprint of one that round-tripped already would
/// round-trip the same (mutants often load to the same data: an edit in a comment, in padding,
/// in bytes the reader skips). The harness writes such a load back only once.
pub fn fingerprint(loaded: &Loaded) -> u64 {
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    let f32_bits = |h: &mut std::collections::hash_map::DefaultHasher, v: &[f32]| {
        v.iter().for_each(|x| x.to_bits().hash(h))
    };
    match loaded {
        Loaded::Hair(x) => {
            let m = &x.model;
            (0u8, format!("{:?}", x.report.format), &x.report.info).hash(&mut h);
            m.strand_offsets().hash(&mut h);
            m.points().iter().for_each(|p| p.bits().hash(&mut h));
            for a in [m.thickness(), m.transparency()] {
                match a {
                    None => 0u8.hash(&mut h),
                    Some(Attribute::Uniform(v)) => (1u8, v.to_bits()).hash(&mut h),
                    Some(Attribute::PerPoint(v)) => {
                        2u8.hash(&mut h);
                        f32_bits(&mut h, v)
                    }
                }
            }
            match m.color() {
                None => 0u8.hash(&mut h),
                Some(Attribute::Uniform(v)) => (1u8, v.bits()).hash(&mut h),
                Some(Attribute::PerPoint(v)) => {
                    2u8.hash(&mut h);
                    v.iter().for_each(|c| c.bits().hash(&mut h))
                }
            }
        }
        Loaded::EnvMap(e) => {
            (1u8, e.map.width(), e.map.height()).hash(&mut h);
            f32_bits(&mut h, e.map.pixels().as_flattened());
        }
        Loaded::Asset(a) => {
            (2u8, format!("{:?}", a.metadata)).hash(&mut h);
            f32_bits(&mut h, a.table.values());
        }
        Loaded::Srbf(s) => (3u8, s.to_json()).hash(&mut h),
        Loaded::Head(m) => {
            (4u8, &m.indices).hash(&mut h);
            m.positions.iter().for_each(|p| p.bits().hash(&mut h));
            m.normals.iter().for_each(|n| n.bits().hash(&mut h));
        }
    }
    h.finish()
}
