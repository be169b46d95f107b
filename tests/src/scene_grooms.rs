//! Grooms written by writers this project did not write: Pixar's `usd-core` (BasisCurves as
//! `.usda`, `.usdc`, `.usdz`) and PyAlembic, PyPI `alembic3d` (ICurves in an Ogawa `.abc`),
//! each with the `expected.json` its script computed with the writer's own library. The scripts
//! are in `tests/scripts/`; the comparison is `tests/tests/integration/scene_grooms.rs`, and the fuzzer seeds
//! its USD and Alembic targets from the same files.

use std::path::{Path, PathBuf};
use std::process::Command;

use strandlight_tables::outside_tools::{python, require_python_modules};

/// A Python writer of test grooms (and heads).
#[derive(Clone, Copy, Debug)]
pub enum Writer {
    /// `write_usd_groom.py`: groom.usda, groom.usdc, groom.usdz, expected.json.
    UsdCore,
    /// `write_alembic_groom.py`: groom.abc, expected.json.
    Alembic,
    /// `write_heads.py`: head.glb, head.gltf + head.bin (pygltflib), head.usda, head.usdc,
    /// head.usdz (usd-core), expected.json.
    Heads,
}

impl Writer {
    fn script(self) -> PathBuf {
        let name = match self {
            Writer::UsdCore => "write_usd_groom.py",
            Writer::Alembic => "write_alembic_groom.py",
            Writer::Heads => "write_heads.py",
        };
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("scripts")
            .join(name)
    }

    fn modules(self) -> (&'static [&'static str], &'static str) {
        match self {
            Writer::UsdCore => (&["pxr"], "pip install usd-core"),
            Writer::Alembic => (&["alembic3d", "imath"], "pip install alembic3d"),
            Writer::Heads => (
                &["pygltflib", "pxr", "numpy"],
                "pip install pygltflib usd-core numpy",
            ),
        }
    }

    /// Runs the writer into `dir` (created) with `args` after it; false (with the skip printed,
    /// or a panic under `STRANDLIGHT_REQUIRE_TOOLS=1`) when Python lacks its modules.
    pub fn write(self, dir: &Path, args: &[&str]) -> bool {
        let (modules, install) = self.modules();
        if !require_python_modules(modules, install) {
            return false;
        }
        std::fs::create_dir_all(dir).expect("the output folder can be created");
        let script = self.script();
        let run = Command::new(python())
            .arg(&script)
            .arg(dir)
            .args(args)
            .output()
            .expect("the Python interpreter runs");
        assert!(
            run.status.success(),
            "{} failed: {}",
            script.display(),
            String::from_utf8_lossy(&run.stderr)
        );
        true
    }
}

/// One strand as the writer's script computed it.
#[derive(Clone, Debug)]
pub struct ExpectedStrand {
    pub points: Vec<[f64; 3]>,
    pub width: f64,
    /// Per point, when the groom has colours.
    pub colors: Option<Vec<[f64; 3]>>,
}

/// The strands of `expected.json` in `dir`.
pub fn expected(dir: &Path) -> Vec<ExpectedStrand> {
    let text = std::fs::read(dir.join("expected.json")).expect("the writer wrote expected.json");
    let json: serde_json::Value = serde_json::from_slice(&text).expect("expected.json is JSON");
    let triples = |v: &serde_json::Value| -> Vec<[f64; 3]> {
        v.as_array()
            .expect("an array of points")
            .iter()
            .map(|p| std::array::from_fn(|c| p[c].as_f64().expect("a number")))
            .collect()
    };
    json["strands"]
        .as_array()
        .expect("strands")
        .iter()
        .map(|s| ExpectedStrand {
            points: triples(&s["points"]),
            width: s["width"].as_f64().expect("a width"),
            colors: (!s["colors"].is_null())
                .then(|| triples(&s["colors"]))
                .filter(|c| !c.is_empty()),
        })
        .collect()
}
