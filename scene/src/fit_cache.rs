//! The SRBF fit of an environment, cached on disk by the map's content and every fit option.

use crate::environment::LoadedEnv;
use crate::sealed_file::{Unsealed, read_sealed, seal};
use anyhow::Context;
use serde_json::json;
use std::path::{Path, PathBuf};
use strandlight_precompute::FitOptions;
use strandlight_precompute::srbf_set::SrbfSet;
use strandlight_tables::checksum::sha256_hex;

/// A fitted set and whether it came from the cache.
pub struct FitOutcome {
    pub set: SrbfSet,
    pub cached: bool,
    pub path: PathBuf,
}

/// The cache key of a fit: the map's content and every fit option.
pub fn fit_key(env: &LoadedEnv, options: &FitOptions) -> String {
    sha256_hex(json!({ "map_sha256": env.sha256, "options": options, "generator": env!("CARGO_PKG_VERSION") }).to_string().as_bytes())
}

/// The SRBF fit of `env`, served from `cache_dir/fits/KEY.srbf.json` when the map and options
/// are unchanged and the file still matches the digest sealed beside it, else computed and
/// stored there (a damaged entry is reported and refitted).
pub fn fit_cached(
    env: &LoadedEnv,
    options: &FitOptions,
    cache_dir: &Path,
) -> anyhow::Result<FitOutcome> {
    let dir = cache_dir.join("fits");
    std::fs::create_dir_all(&dir)
        .with_context(|| format!("cannot create the cache folder {}", dir.display()))?;
    let path = dir.join(format!("{}.srbf.json", &fit_key(env, options)[..32]));
    if let Some(set) = cached_fit(&path, env, options) {
        return Ok(FitOutcome {
            set,
            cached: true,
            path,
        });
    }
    let set = SrbfSet::fit(&env.source(), options, &mut |_| {})
        .with_context(|| format!("fitting SRBFs to {}", env.name))?;
    set.save(&path)?;
    seal(&path).with_context(|| format!("sealing the cache entry {}", path.display()))?;
    Ok(FitOutcome {
        set,
        cached: false,
        path,
    })
}

/// The set stored at `path` if it is intact and was fitted to this map with these options.
fn cached_fit(path: &Path, env: &LoadedEnv, options: &FitOptions) -> Option<SrbfSet> {
    let bytes = match read_sealed(path) {
        Ok(bytes) => bytes,
        Err(Unsealed::Missing) => return None,
        Err(Unsealed::Damaged) => {
            eprintln!(
                "warning: the cached fit {} does not match its checksum; fitting again",
                path.display()
            );
            return None;
        }
    };
    let set = SrbfSet::from_json(path, &bytes).ok()?;
    let same_options =
        serde_json::to_value(&set.options).ok() == serde_json::to_value(options).ok();
    (set.source_sha256 == env.sha256 && same_options).then_some(set)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::environment::map_pixels_sha256;
    use strandlight_precompute::{EnvMap, procedural_env};
    #[test]
    fn fits_are_cached_by_map_and_options() {
        let dir = std::env::temp_dir().join(format!("strandlight-fitcache-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        // A map made of one known lobe: a tiny fit converges in a fraction of a second.
        let lobe = strandlight_tables::srbf::SrbfLobe {
            center: [0.0, 1.0, 0.0],
            lambda: 20.0,
            amplitude: [1.0, 0.5, 0.25],
        };
        let map = procedural_env::from_srbf_lobes(64, &[lobe]);
        let env = LoadedEnv {
            sha256: map_pixels_sha256(&map),
            map,
            name: "one-lobe".into(),
            sanitized: Default::default(),
        };
        let options = FitOptions {
            initial_lobes: 1,
            max_lobes: 2,
            grid_width: 64,
            lambda_max: 64.0, // λ ≤ grid_width²/64
            iterations_per_round: 20,
            final_iterations: 20,
            ..FitOptions::default()
        };
        let first = fit_cached(&env, &options, &dir).unwrap();
        assert!(!first.cached);
        let again = fit_cached(&env, &options, &dir).unwrap();
        assert!(again.cached);
        assert_eq!(again.set.lobes, first.set.lobes);
        let other = fit_cached(
            &env,
            &FitOptions {
                max_lobes: 1,
                ..options.clone()
            },
            &dir,
        )
        .unwrap();
        assert!(!other.cached, "other options must refit");
        assert!(!first.set.lobes.is_empty());
        // A changed map (one pixel) refits too.
        let mut pixels = env.map.pixels().to_vec();
        pixels[0][0] += 1.0;
        let map2 = EnvMap::from_pixels(env.map.width(), env.map.height(), pixels);
        let env2 = LoadedEnv {
            sha256: map_pixels_sha256(&map2),
            map: map2,
            name: "one-lobe".into(),
            sanitized: Default::default(),
        };
        assert!(
            !fit_cached(&env2, &options, &dir).unwrap().cached,
            "a changed map must refit"
        );
        // A damaged entry (a flipped digit in a lobe) is refitted, not served.
        let mut bytes = std::fs::read(&first.path).unwrap();
        let digit = bytes
            .iter()
            .rposition(|b| b.is_ascii_digit() && *b != b'9')
            .unwrap();
        bytes[digit] += 1;
        std::fs::write(&first.path, &bytes).unwrap();
        let refit = fit_cached(&env, &options, &dir).unwrap();
        assert!(!refit.cached, "a damaged cache entry was served");
        assert_eq!(
            refit.set.lobes, first.set.lobes,
            "the refit reproduces the first fit"
        );
        assert!(
            fit_cached(&env, &options, &dir).unwrap().cached,
            "the refit was sealed again"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
