//! The brute-force reference image, cached by everything it depends on (it may take minutes):
//! `DIR/KEY.exr` (linear RGBA) beside `DIR/KEY.json` (the inputs and the measured time), both
//! written atomically and sealed by a SHA-256 sidecar. A hit needs both files intact and the
//! same inputs recorded in the JSON; a damaged entry is reported and rendered again.

use anyhow::Context;
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use serde_json::Value;
use std::path::{Path, PathBuf};
use strandlight_scene::image_metrics::Image;
use strandlight_scene::sealed_file::{Unsealed, read_sealed, seal, write_sealed};
use strandlight_tables::checksum::sha256_hex;
use strandlight_tables::image_out::write_exr;

/// What is stored beside the image.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ReferenceRecord {
    /// Everything the image depends on (hair file hash, camera, size, map hash, light count,
    /// fiber and table settings, scattering mode, program version).
    pub inputs: Value,
    /// Its shadow maps: the compact sources and the cube texels (with power).
    pub lights: usize,
    /// Frame time of the reference render.
    pub milliseconds: f64,
}

/// A record a cache entry is found by: it names every input of its image.
pub trait CachedRecord: Serialize + DeserializeOwned {
    /// Everything the image depends on; the entry's key is its hash.
    fn inputs(&self) -> &Value;
    /// What the image is, written into the EXR's comment.
    fn description() -> &'static str;
}

impl CachedRecord for ReferenceRecord {
    fn inputs(&self) -> &Value {
        &self.inputs
    }
    fn description() -> &'static str {
        "strandlight brute-force reference"
    }
}

pub struct ReferenceCache {
    pub dir: PathBuf,
}

impl ReferenceCache {
    pub fn new(dir: impl Into<PathBuf>) -> Self {
        Self { dir: dir.into() }
    }

    pub fn key(inputs: &Value) -> String {
        sha256_hex(inputs.to_string().as_bytes())[..32].to_string()
    }

    fn paths(&self, inputs: &Value) -> (PathBuf, PathBuf) {
        let key = Self::key(inputs);
        (
            self.dir.join(format!("{key}.exr")),
            self.dir.join(format!("{key}.json")),
        )
    }

    /// The cached image for `inputs`, or None (absent, damaged or recorded for other inputs).
    pub fn load<R: CachedRecord>(&self, inputs: &Value) -> Option<(Image, R)> {
        let (exr_path, json_path) = self.paths(inputs);
        let record: R = serde_json::from_slice(&intact(&json_path)?).ok()?;
        if record.inputs() != inputs {
            return None;
        }
        intact(&exr_path)?;
        match read_rgba_exr(&exr_path) {
            Ok(image) => Some((image, record)),
            Err(e) => {
                eprintln!("reference cache: ignoring {}: {e:#}", exr_path.display());
                None
            }
        }
    }

    /// Stores the image (EXR first, then the JSON that makes it a hit), each sealed.
    pub fn store<R: CachedRecord>(&self, image: &Image, record: &R) -> anyhow::Result<PathBuf> {
        std::fs::create_dir_all(&self.dir)
            .with_context(|| format!("cannot create the cache folder {}", self.dir.display()))?;
        let (exr_path, json_path) = self.paths(record.inputs());
        write_exr(
            &exr_path,
            image.width,
            image.height,
            &image.pixels,
            R::description(),
        )?;
        seal(&exr_path).with_context(|| format!("sealing {}", exr_path.display()))?;
        let json = serde_json::to_vec_pretty(record)?;
        write_sealed(&json_path, &json).with_context(|| json_path.display().to_string())?;
        Ok(exr_path)
    }
}

/// The bytes of a sealed cache file, None when absent or (with a warning) damaged.
fn intact(path: &Path) -> Option<Vec<u8>> {
    match read_sealed(path) {
        Ok(bytes) => Some(bytes),
        Err(Unsealed::Missing) => None,
        Err(Unsealed::Damaged) => {
            eprintln!(
                "warning: the cached reference file {} does not match its checksum; rendering again",
                path.display()
            );
            None
        }
    }
}

/// A linear RGBA EXR as written by `strandlight_tables::image_out::write_exr`.
pub fn read_rgba_exr(path: &Path) -> anyhow::Result<strandlight_scene::image_metrics::Image> {
    use exr::prelude::*;
    let image = read_first_rgba_layer_from_file(
        path,
        |resolution, _| {
            (
                resolution.width(),
                vec![[0f32; 4]; resolution.width() * resolution.height()],
            )
        },
        |(w, pixels), position, (r, g, b, a): (f32, f32, f32, f32)| {
            pixels[position.y() * *w + position.x()] = [r, g, b, a]
        },
    )
    .with_context(|| format!("{}: not a readable RGBA EXR", path.display()))?;
    let size = image.layer_data.size;
    let (_, pixels) = image.layer_data.channel_data.pixels;
    Ok(strandlight_scene::image_metrics::Image::new(
        size.width() as u32,
        size.height() as u32,
        pixels,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn stores_and_finds_by_inputs_only() {
        let dir = std::env::temp_dir().join(format!("strandlight-refcache-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let cache = ReferenceCache::new(&dir);
        let inputs = json!({ "hair_sha256": "ab", "size": [3, 2], "lights": 6144 });
        let image = Image::new(
            3,
            2,
            (0..6)
                .map(|i| [i as f32, 0.5, -1.0, 0.25 * i as f32])
                .collect(),
        );
        assert!(cache.load::<ReferenceRecord>(&inputs).is_none());
        let record = ReferenceRecord {
            inputs: inputs.clone(),
            lights: 6144,
            milliseconds: 1234.5,
        };
        cache.store(&image, &record).unwrap();
        let (back, rec) = cache.load::<ReferenceRecord>(&inputs).unwrap();
        assert_eq!(back, image, "f32 EXR round trip is exact");
        assert_eq!(rec, record);
        assert!(
            cache
                .load::<ReferenceRecord>(
                    &json!({ "hair_sha256": "ab", "size": [3, 2], "lights": 96 })
                )
                .is_none()
        );
        // A damaged image or record is a miss, not a crash and not a wrong picture: every single
        // byte flip of the EXR is refused, including those its own decoder would accept (flips
        // in header attributes, offsets, padding).
        let (exr_path, json_path) = cache.paths(&inputs);
        let original = std::fs::read(&exr_path).unwrap();
        let mut decoder_accepted = 0;
        for at in 0..original.len() {
            let mut flipped = original.clone();
            flipped[at] ^= 0x01;
            std::fs::write(&exr_path, &flipped).unwrap();
            decoder_accepted += usize::from(read_rgba_exr(&exr_path).is_ok());
            assert!(
                cache.load::<ReferenceRecord>(&inputs).is_none(),
                "a reference image flipped at byte {at} was served"
            );
        }
        println!(
            "{} flips of a {}-byte EXR refused; the decoder alone accepted {decoder_accepted}",
            original.len(),
            original.len()
        );
        assert!(
            decoder_accepted > 0,
            "no flip gets past the decoder alone: the seal is untested"
        );
        std::fs::write(&exr_path, &original).unwrap();
        assert!(cache.load::<ReferenceRecord>(&inputs).is_some());
        let json = std::fs::read(&json_path).unwrap();
        std::fs::write(&json_path, &json[..json.len() - 3]).unwrap();
        assert!(
            cache.load::<ReferenceRecord>(&inputs).is_none(),
            "a truncated record was served"
        );
        std::fs::write(&exr_path, b"not an exr").unwrap();
        assert!(cache.load::<ReferenceRecord>(&inputs).is_none());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
