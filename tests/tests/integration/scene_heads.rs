//! Heads written by writers this project did not write (pygltflib's glTF 2.0, Pixar's usd-core
//! `Mesh` prims) load where the writer's own transforms put them: `tests/scripts/write_heads.py`
//! computes, in strandlight's world (Y up, centimetres), each file's triangle count, area,
//! area-weighted centroid, bounds and enclosed volume, and the loaded mesh must agree. The
//! volume is signed by the winding, so a part wound inward (a mirrored glTF node, a
//! `leftHanded` USD prim, read the wrong way round) subtracts instead of adding. Damaged files
//! are refused with the file named.
//!
//! Needs `pip install pygltflib usd-core numpy` (skips without; fails under
//! `STRANDLIGHT_REQUIRE_TOOLS=1`).

use glam::DVec3;
use std::path::{Path, PathBuf};
use strandlight_runtime::hair::{GroomParams, generate_groom};
use strandlight_runtime::head::HeadSurface;
use strandlight_runtime::head::TriangleMesh;
use strandlight_scene::head_input::{HeadChoice, default_skin_albedo, load_head, load_mesh};
use strandlight_tests::scene_grooms::Writer;

fn out_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!(
        "strandlight-scene-heads-{name}-{}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// What the writer's script measured of one format's head.
struct Expected {
    triangles: usize,
    area: f64,
    centroid: DVec3,
    min: DVec3,
    max: DVec3,
    volume: f64,
}

fn expected(dir: &Path, format: &str) -> Expected {
    let text = std::fs::read(dir.join("expected.json")).expect("the writer wrote expected.json");
    let json: serde_json::Value = serde_json::from_slice(&text).unwrap();
    let v = &json[format];
    let vec = |key: &str| DVec3::from_array(std::array::from_fn(|c| v[key][c].as_f64().unwrap()));
    Expected {
        triangles: v["triangles"].as_u64().unwrap() as usize,
        area: v["area"].as_f64().unwrap(),
        centroid: vec("centroid"),
        min: vec("min"),
        max: vec("max"),
        volume: v["volume"].as_f64().unwrap(),
    }
}

/// The mesh's triangles as f64 corner triples.
fn triangles(mesh: &TriangleMesh) -> impl Iterator<Item = [DVec3; 3]> + '_ {
    mesh.indices
        .chunks_exact(3)
        .map(|t| [0, 1, 2].map(|k| mesh.positions[t[k] as usize].as_dvec3()))
}

fn assert_matches(mesh: &TriangleMesh, want: &Expected, file: &Path) {
    let name = file.display();
    assert_eq!(mesh.triangle_count(), want.triangles, "{name}: triangles");
    let (mut area, mut moment, mut volume) = (0.0, DVec3::ZERO, 0.0);
    for [a, b, c] in triangles(mesh) {
        let s = 0.5 * (b - a).cross(c - a).length();
        area += s;
        moment += s * (a + b + c) / 3.0;
        volume += a.dot(b.cross(c)) / 6.0;
    }
    let size = (want.max - want.min).length();
    let bounds = mesh.bounds();
    let checks = [
        ("area", (area - want.area).abs() / want.area),
        ("centroid", (moment / area - want.centroid).length() / size),
        ("min", (bounds.min.as_dvec3() - want.min).length() / size),
        ("max", (bounds.max.as_dvec3() - want.max).length() / size),
        ("volume", (volume - want.volume).abs() / want.volume),
    ];
    for (what, error) in checks {
        assert!(error < 1e-5, "{name}: {what} off by {error:.2e} (relative)");
    }
    // Each corner's normal on the side its triangle's winding faces.
    for (t, corners) in mesh.indices.chunks_exact(3).enumerate() {
        let [a, b, c] = [0, 1, 2].map(|k| mesh.positions[corners[k] as usize]);
        let face = (b - a).cross(c - a);
        for &i in corners {
            assert!(
                mesh.normals[i as usize].dot(face) > 0.0,
                "{name}: triangle {t}: the normal at vertex {i} faces away from the winding"
            );
        }
    }
    eprintln!(
        "{name}: {} triangles, area {area:.3} cm², volume {volume:.3} cm³, as the writer's",
        mesh.triangle_count()
    );
}

#[test]
fn gltf_and_usd_heads_load_where_their_writers_put_them() {
    let dir = out_dir("load");
    if !Writer::Heads.write(&dir, &[]) {
        return;
    }
    let hair = generate_groom(&GroomParams::default()).unwrap();
    for (file, format) in [
        ("head.glb", "gltf"),
        ("head.gltf", "gltf"),
        ("head-embedded.gltf", "gltf"),
        ("head.usda", "usd"),
        ("head.usdc", "usd"),
        ("head.usdz", "usd"),
    ] {
        let path = dir.join(file);
        let mesh = load_mesh(&path).unwrap_or_else(|e| panic!("{e:#}"));
        assert_matches(&mesh, &expected(&dir, format), &path);
        // As `--head FILE` and a settings file's head reach render, compare, view and truth.
        let choice = HeadChoice::parse(&path.display().to_string()).unwrap();
        let head = load_head(&choice, &hair, default_skin_albedo())
            .unwrap()
            .expect("a head");
        assert!(matches!(&head.surface, HeadSurface::Mesh(m) if *m == mesh));
    }
    // Files of both kinds in one head, as `--head skin.glb,eyes.usda`: every triangle of each.
    let (glb, usda) = (dir.join("head.glb"), dir.join("head.usda"));
    let both = HeadChoice::parse(&format!("{},{}", glb.display(), usda.display())).unwrap();
    let head = load_head(&both, &hair, default_skin_albedo())
        .unwrap()
        .expect("a head");
    let HeadSurface::Mesh(merged) = &head.surface else {
        panic!("a mesh head")
    };
    let parts = [load_mesh(&glb).unwrap(), load_mesh(&usda).unwrap()];
    assert_eq!(
        merged.triangle_count(),
        parts[0].triangle_count() + parts[1].triangle_count()
    );
    assert_eq!(*merged, TriangleMesh::merged(parts));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `load_mesh`'s error for `path`, which must name the file and say `problem`.
fn assert_refused(path: &Path, problem: &str) {
    let error = match load_mesh(path) {
        Ok(_) => panic!("{} loaded", path.display()),
        Err(e) => format!("{e:#}"),
    };
    assert!(
        error.contains(&path.display().to_string()) && error.contains(problem),
        "{}: expected an error naming it and saying {problem:?}, got: {error}",
        path.display()
    );
}

#[test]
fn damaged_heads_are_refused_with_the_file_named() {
    let dir = out_dir("damaged");
    if !Writer::Heads.write(&dir, &[]) {
        return;
    }
    let glb = std::fs::read(dir.join("head.glb")).unwrap();
    let truncated = dir.join("truncated.glb");
    std::fs::write(&truncated, &glb[..glb.len() / 2]).unwrap();
    assert_refused(&truncated, "not a readable glTF 2.0 file");

    // A .gltf whose buffer file is not beside it.
    let alone = dir.join("alone");
    std::fs::create_dir_all(&alone).unwrap();
    std::fs::copy(dir.join("head.gltf"), alone.join("head.gltf")).unwrap();
    assert_refused(&alone.join("head.gltf"), "which is not a file");
    // A buffer that names a device, which would be read forever.
    let text = std::fs::read_to_string(dir.join("head.gltf")).unwrap();
    let endless = dir.join("endless.gltf");
    std::fs::write(&endless, text.replace("\"head.bin\"", "\"/dev/zero\"")).unwrap();
    assert_refused(&endless, "names /dev/zero, which is not a file");

    // 40 nodes, each a child of the two before it: 10⁸ paths from the root.
    let shared: Vec<String> = (0..40)
        .map(|k| match k {
            38 => r#"{"children":[39]}"#.to_string(),
            39 => "{}".to_string(),
            k => format!(r#"{{"children":[{},{}]}}"#, k + 1, k + 2),
        })
        .collect();
    let tangled = dir.join("tangled.gltf");
    std::fs::write(
        &tangled,
        format!(
            r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],"nodes":[{}]}}"#,
            shared.join(",")
        ),
    )
    .unwrap();
    assert_refused(&tangled, "node visits");

    let usda = |name: &str, body: &str| {
        let path = dir.join(name);
        std::fs::write(&path, format!("#usda 1.0\n\n{body}\n")).unwrap();
        path
    };
    let out_of_range = usda(
        "out_of_range.usda",
        r#"def Mesh "Face" {
    point3f[] points = [(0, 0, 0), (1, 0, 0), (0, 1, 0)]
    int[] faceVertexCounts = [3]
    int[] faceVertexIndices = [0, 1, 7]
}"#,
    );
    assert_refused(&out_of_range, "face 0 names point 7 of 3");
    let short = usda(
        "short.usda",
        r#"def Mesh "Face" {
    point3f[] points = [(0, 0, 0), (1, 0, 0), (0, 1, 0)]
    int[] faceVertexCounts = [3, 4]
    int[] faceVertexIndices = [0, 1, 2, 0]
}"#,
    );
    assert_refused(&short, "face 1 has 4 corners");
    let curves_only = usda(
        "curves_only.usda",
        r#"def BasisCurves "Hair" {
    uniform token type = "linear"
    int[] curveVertexCounts = [2]
    point3f[] points = [(0, 0, 0), (0, 0, 1)]
}"#,
    );
    assert_refused(&curves_only, "no rendered Mesh prim");
    assert_refused(&dir.join("missing.glb"), "cannot read the head");
    std::fs::remove_dir_all(&dir).unwrap();
}
