//! The fitted light set as a file: what the runtime loads. JSON (serde), written atomically.
//!
//! Directions follow [`crate::envmap`]'s convention (+Y up, image center toward −Z), in the
//! map's own frame (a frame turns the map, not its fit: `strandlight_scene::env_orientation`). A lobe's radiance is `amplitude · exp(λ(ω·ξ − 1))`.
//! For `kind = "directional"` (the median-cut baseline) each light is stored as a very narrow
//! lobe (λ = [`DIRECTIONAL_LAMBDA`]) whose integral `amplitude · srbf::integral(λ)` is the
//! light's power (∫ L dω of its region), so one format serves both; a renderer that wants delta
//! lights uses `power()` and the center.

use crate::compact_sources::CompactSource;
use crate::envmap::BadPixelCounts;
use crate::srbf_fit::{FitOptions, RoundRecord};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use strandlight_tables::atomic_write::write_atomically;
use strandlight_tables::srbf::{self, SrbfLobe};

pub const FORMAT: &str = "strandlight-srbf-set";
/// 2: compact sources (`sources`) beside the lobes; a version-1 reader would drop them silently.
/// 3: each source's angular variance (its shadow's softness); a version-2 set would render its
/// sources as points.
pub const FORMAT_VERSION: u32 = 3;
/// Bandwidth that stands for a directional light (support ≈ 2.1°).
pub const DIRECTIONAL_LAMBDA: f64 = 1.0e4;

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LightKind {
    Srbf,
    Directional,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SrbfSet {
    pub format: String,
    pub version: u32,
    pub kind: LightKind,
    pub lobes: Vec<SrbfLobe>,
    /// Compact sources taken out of the map before the fit, as directional lights; the lobes
    /// fit the map without them.
    #[serde(default)]
    pub sources: Vec<CompactSource>,
    /// The environment map's file name (no directories) and the SHA-256 of its bytes.
    pub source: String,
    pub source_sha256: String,
    pub options: FitOptions,
    /// Bad pixel values that `--sanitize` replaced (all zero when none were found).
    pub sanitized: BadPixelCounts,
    /// Size of the prefiltered grid the errors below are measured on.
    pub fit_grid: [usize; 2],
    /// √(Σ w‖fit − map‖² / Σ w‖map‖²) over RGB, w the pixel solid angle, on the fit grid; "map"
    /// is the map without its compact [`Self::sources`] (what the lobes fit).
    pub relative_l2_error: f64,
    /// The paper's criterion: Σ w‖fit − map‖² / Σ w‖map‖² (= relative_l2_error²).
    pub relative_mse: f64,
    /// The same relative MSE against the full-resolution map (without its compact sources,
    /// like `relative_mse`; a bright spot narrower than the fit grid's pixels that was not
    /// extracted counts fully here).
    pub full_resolution_relative_mse: f64,
    /// (∫ lobes dω + Σ source power) / ∫ map dω per channel, against the whole map. An L2 fit does not preserve power: a source narrower
    /// than any allowed lobe is fitted with about twice its power (for a point source the
    /// optimal lobe carries ∫G/‖G‖² = 2× its power), so sun maps come out too bright overall.
    pub power_ratio: [f64; 3],
    /// Relative MSE after each optimization round.
    pub history: Vec<RoundRecord>,
    pub seconds: f64,
}

#[derive(Debug, thiserror::Error)]
pub enum SrbfSetError {
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path}: not a valid SRBF set: {source}")]
    Json {
        path: PathBuf,
        source: serde_json::Error,
    },
    #[error(
        "{path}: format {format:?} version {version} is not {FORMAT:?} version {FORMAT_VERSION}"
    )]
    Version {
        path: PathBuf,
        format: String,
        version: u32,
    },
    #[error("{path}: lobe {index} is invalid: {problem}")]
    BadLobe {
        path: PathBuf,
        index: usize,
        problem: String,
    },
    #[error("{path}: compact source {index} is invalid: {problem}")]
    BadSource {
        path: PathBuf,
        index: usize,
        problem: String,
    },
}

impl SrbfSet {
    /// The bytes [`Self::save`] writes (pretty JSON), in memory: what [`Self::from_json`] reads.
    pub fn to_json(&self) -> Vec<u8> {
        serde_json::to_vec_pretty(self).expect("an SrbfSet always serializes")
    }

    pub fn save(&self, path: &Path) -> Result<(), SrbfSetError> {
        let json = self.to_json();
        write_atomically(path, |out| std::io::Write::write_all(out, &json)).map_err(|source| {
            SrbfSetError::Io {
                path: path.into(),
                source,
            }
        })
    }

    pub fn load(path: &Path) -> Result<SrbfSet, SrbfSetError> {
        let bytes = std::fs::read(path).map_err(|source| SrbfSetError::Io {
            path: path.into(),
            source,
        })?;
        Self::from_json(path, &bytes)
    }

    /// Parses and checks a set already in memory; `path` only names it in errors.
    pub fn from_json(path: &Path, bytes: &[u8]) -> Result<SrbfSet, SrbfSetError> {
        let set: SrbfSet = serde_json::from_slice(bytes).map_err(|source| SrbfSetError::Json {
            path: path.into(),
            source,
        })?;
        if set.format != FORMAT || set.version != FORMAT_VERSION {
            return Err(SrbfSetError::Version {
                path: path.into(),
                format: set.format,
                version: set.version,
            });
        }
        for (index, lobe) in set.lobes.iter().enumerate() {
            let bad = |problem: String| SrbfSetError::BadLobe {
                path: path.into(),
                index,
                problem,
            };
            let len = lobe.center().length();
            if !len.is_finite() || (len - 1.0).abs() > 1e-6 {
                return Err(bad(format!(
                    "center {:?} is not a unit vector",
                    lobe.center
                )));
            }
            if !(lobe.lambda.is_finite() && lobe.lambda > 0.0) {
                return Err(bad(format!(
                    "lambda {} must be finite and > 0",
                    lobe.lambda
                )));
            }
            if lobe.amplitude.iter().any(|a| !a.is_finite() || *a < 0.0) {
                return Err(bad(format!(
                    "amplitude {:?} must be finite and ≥ 0",
                    lobe.amplitude
                )));
            }
        }
        for (index, source) in set.sources.iter().enumerate() {
            let bad = |problem: String| SrbfSetError::BadSource {
                path: path.into(),
                index,
                problem,
            };
            let len = glam::DVec3::from(source.direction).length();
            if !len.is_finite() || (len - 1.0).abs() > 1e-6 {
                return Err(bad(format!(
                    "direction {:?} is not a unit vector",
                    source.direction
                )));
            }
            if source.power.iter().any(|p| !p.is_finite() || *p < 0.0) {
                return Err(bad(format!(
                    "power {:?} must be finite and ≥ 0",
                    source.power
                )));
            }
        }
        Ok(set)
    }
}

/// ∫ L dω of one lobe, per channel: its power as a light.
pub fn power(lobe: &SrbfLobe) -> [f64; 3] {
    lobe.amplitude.map(|a| a * srbf::integral(lobe.lambda))
}

/// (Σ lobe power + Σ source power) / ∫ map dω per channel.
fn power_ratio(
    map: &crate::envmap::EnvMap,
    lobes: &[SrbfLobe],
    sources: &[CompactSource],
) -> [f64; 3] {
    let map_power = map.integral();
    std::array::from_fn(|c| {
        let fit: f64 = lobes.iter().map(|l| power(l)[c]).sum::<f64>()
            + sources.iter().map(|s| s.power[c]).sum::<f64>();
        if map_power[c] > 0.0 {
            fit / map_power[c]
        } else {
            0.0
        }
    })
}

/// What a light set was made from.
#[derive(Clone)]
pub struct Source<'a> {
    pub map: &'a crate::envmap::EnvMap,
    /// File name (no directories) or `procedural:NAME`.
    pub name: String,
    pub sha256: String,
    pub sanitized: BadPixelCounts,
}

impl SrbfSet {
    /// Takes the compact sources out of the map (`options.sources`), runs the adaptive fit on
    /// the rest and measures its error independently (direct pixel sums, on the fit grid and on
    /// the full-resolution map without the sources).
    pub fn fit(
        source: &Source,
        options: &FitOptions,
        progress: &mut dyn FnMut(&RoundRecord),
    ) -> Result<SrbfSet, crate::srbf_fit::FitError> {
        let start = std::time::Instant::now();
        options.validate()?;
        let (sources, residual, _) = crate::compact_sources::extract_widening(
            source.map,
            &options.sources,
            options.wider_source_radius,
        );
        let (lobes, grid_map, history) = match crate::srbf_fit::fit(&residual, options, progress) {
            Ok(fit) => (fit.lobes, fit.grid_map, fit.history),
            // Nothing but the sources: no lobes.
            Err(crate::srbf_fit::FitError::BlackMap) if !sources.is_empty() => (
                Vec::new(),
                residual.downsampled(options.grid_width, options.grid_width / 2),
                Vec::new(),
            ),
            Err(e) => return Err(e),
        };
        let seconds = start.elapsed().as_secs_f64();
        let residual_source = Source {
            map: &residual,
            ..source.clone()
        };
        let mut set = Self::measured(
            &residual_source,
            options,
            LightKind::Srbf,
            lobes,
            &grid_map,
            history,
            seconds,
        );
        set.sources = sources;
        set.power_ratio = power_ratio(source.map, &set.lobes, &set.sources);
        Ok(set)
    }

    /// The median-cut baseline with `count` directional lights, in the same format.
    pub fn directional(source: &Source, count: usize, options: &FitOptions) -> SrbfSet {
        let start = std::time::Instant::now();
        let lights = crate::median_cut::median_cut(source.map, count.max(1));
        let norm = srbf::integral(DIRECTIONAL_LAMBDA);
        let lobes = lights
            .iter()
            .map(|l| SrbfLobe {
                center: l.direction.to_array(),
                lambda: DIRECTIONAL_LAMBDA,
                amplitude: l.power.map(|p| p / norm),
            })
            .collect();
        let seconds = start.elapsed().as_secs_f64();
        let grid = source
            .map
            .downsampled(options.grid_width, options.grid_width / 2);
        Self::measured(
            source,
            options,
            LightKind::Directional,
            lobes,
            &grid,
            Vec::new(),
            seconds,
        )
    }

    fn measured(
        source: &Source,
        options: &FitOptions,
        kind: LightKind,
        lobes: Vec<SrbfLobe>,
        grid_map: &crate::envmap::EnvMap,
        history: Vec<RoundRecord>,
        seconds: f64,
    ) -> SrbfSet {
        use crate::srbf_objective::relative_mse_by_pixels;
        let relative_mse = relative_mse_by_pixels(grid_map, &lobes);
        let full_resolution_relative_mse = relative_mse_by_pixels(source.map, &lobes);
        let power_ratio = power_ratio(source.map, &lobes, &[]);
        SrbfSet {
            format: FORMAT.into(),
            version: FORMAT_VERSION,
            kind,
            lobes,
            sources: Vec::new(),
            source: source.name.clone(),
            source_sha256: source.sha256.clone(),
            options: options.clone(),
            sanitized: source.sanitized,
            fit_grid: [grid_map.width(), grid_map.height()],
            relative_l2_error: relative_mse.sqrt(),
            relative_mse,
            full_resolution_relative_mse,
            power_ratio,
            history,
            seconds,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn small_set() -> SrbfSet {
        SrbfSet {
            format: FORMAT.into(),
            version: FORMAT_VERSION,
            kind: LightKind::Srbf,
            lobes: vec![SrbfLobe {
                center: [0.6, 0.0, -0.8],
                lambda: 120.0,
                amplitude: [1.5, 0.1 + 0.2, 1.0 / 3.0],
            }],
            sources: vec![CompactSource {
                direction: [0.0, 0.6, 0.8],
                power: [2.0, 1.5, 1.0],
                power_share: 0.4,
                angular_variance: 1e-4,
            }],
            source: "studio \"small\".hdr".into(),
            source_sha256: "0".repeat(64),
            options: FitOptions::default(),
            sanitized: BadPixelCounts::default(),
            fit_grid: [64, 32],
            relative_l2_error: 0.1,
            relative_mse: 0.01,
            full_resolution_relative_mse: -0.0,
            power_ratio: [1.0, f64::MIN_POSITIVE, 1e300],
            history: vec![RoundRecord {
                lobes: 1,
                relative_mse: 0.01,
                evaluations: 100,
            }],
            seconds: 0.5,
        }
    }

    #[test]
    fn to_json_is_what_save_writes_and_loads_back_bit_for_bit() {
        let set = small_set();
        let json = set.to_json();
        let again = SrbfSet::from_json(Path::new("memory.json"), &json).unwrap();
        assert_eq!(again, set);
        // Bit for bit, signed zero and the extremes included.
        assert_eq!(again.to_json(), json);
        assert_eq!(
            again.full_resolution_relative_mse.to_bits(),
            (-0.0f64).to_bits()
        );
        let dir = std::env::temp_dir().join(format!("strandlight-srbf-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("set.json");
        set.save(&path).unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), json);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
