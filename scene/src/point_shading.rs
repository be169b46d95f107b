//! The fiber model of a point-lit frame, built from a user's choice: Kajiya-Kay, Marschner or
//! Chiang through their lookup textures (baked here: the runtime does not link the tabulation
//! code), or the artist-friendly model with controls from a JSON file.

use anyhow::Context;
use std::path::Path;
use strandlight_precompute::chiang_luts::{bake_chiang_lut_m, bake_chiang_lut_n};
use strandlight_precompute::point_light_luts::{LutResolution, bake_lut_m, bake_lut_n};
use strandlight_runtime::passes::fiber_shading::{ChiangLuts, MarschnerLuts, ShadingModel};
use strandlight_runtime::passes::frame_params::KajiyaKay;
use strandlight_tables::artist::{ArtistModel, ArtistParams};
use strandlight_tables::chiang::{Chiang, ChiangParams};
use strandlight_tables::marschner::{Marschner, MarschnerParams};

#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[cfg_attr(any(feature = "cli", test), derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum Shading {
    KajiyaKay,
    Marschner,
    Artist,
    /// Chiang et al. 2016, the model of pbrt-v4, Mitsuba 3 and Cycles' Principled Hair (and of
    /// the path-traced ground truth).
    Chiang,
}

impl Shading {
    /// Whether fibers are physical, opaque cylinders (a file's transparency ignored), as the
    /// path tracer renders them.
    pub fn physical_fibers(self) -> bool {
        self == Shading::Chiang
    }
}

/// What a point-lit frame's fiber model is made from.
pub struct PointShadingRequest<'a> {
    pub shading: Shading,
    /// Melanin preset of the Marschner or Chiang fiber.
    pub preset: &'a str,
    /// Nodes per axis of the Marschner or Chiang lookup textures.
    pub lut_size: usize,
    /// Artist controls; None: the built-in defaults.
    pub artist: Option<ArtistParams>,
}

/// The model and a line describing it. Errors name the setting at fault (`--preset`,
/// `--lut-size`, `--artist-params`).
pub fn point_shading_model(
    request: &PointShadingRequest,
) -> anyhow::Result<(ShadingModel, String)> {
    match request.shading {
        Shading::KajiyaKay => Ok((
            ShadingModel::KajiyaKay,
            format!("Kajiya-Kay {:?}", KajiyaKay::default()),
        )),
        Shading::Marschner => marschner_luts(request.preset, request.lut_size),
        Shading::Chiang => chiang_luts(request.preset, request.lut_size),
        Shading::Artist => artist(request.artist),
    }
}

fn marschner_luts(preset: &str, lut_size: usize) -> anyhow::Result<(ShadingModel, String)> {
    let params =
        MarschnerParams::with_preset(preset).with_context(|| format!("--preset {preset:?}"))?;
    let model = Marschner::new(params)?;
    let resolution = LutResolution::square(lut_size);
    let lut_m =
        bake_lut_m(&model, &resolution).with_context(|| format!("--lut-size {lut_size}"))?;
    let lut_n =
        bake_lut_n(&model, &resolution).with_context(|| format!("--lut-size {lut_size}"))?;
    let description = format!(
        "Marschner (preset {preset}) through {lut_size}² lookup tables (Hunz 2016 Algorithm 2)"
    );
    Ok((
        ShadingModel::MarschnerLut(MarschnerLuts::new(lut_m, lut_n)?),
        description,
    ))
}

fn chiang_luts(preset: &str, lut_size: usize) -> anyhow::Result<(ShadingModel, String)> {
    let params =
        ChiangParams::with_preset(preset).with_context(|| format!("--preset {preset:?}"))?;
    let model = Chiang::new(params)?;
    let resolution = LutResolution::square(lut_size);
    let lut_m =
        bake_chiang_lut_m(&model, &resolution).with_context(|| format!("--lut-size {lut_size}"))?;
    let lut_n =
        bake_chiang_lut_n(&model, &resolution).with_context(|| format!("--lut-size {lut_size}"))?;
    let description = format!("Chiang 2016 (preset {preset}) through {lut_size}² lookup tables");
    Ok((
        ShadingModel::ChiangLut(ChiangLuts::new(lut_m, lut_n)?),
        description,
    ))
}

/// Artist controls from a JSON file (`--artist-params`), errors naming the file.
pub fn read_artist_params(path: &Path) -> anyhow::Result<ArtistParams> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("--artist-params {}", path.display()))?;
    let params: ArtistParams = serde_json::from_str(&text)
        .with_context(|| format!("--artist-params {}", path.display()))?;
    ArtistModel::new(params).with_context(|| format!("--artist-params {}", path.display()))?;
    Ok(params)
}

fn artist(params: Option<ArtistParams>) -> anyhow::Result<(ShadingModel, String)> {
    let from = match params {
        None => "default controls",
        Some(_) => "custom controls",
    };
    let model = ArtistModel::new(params.unwrap_or_default()).context("artist controls")?;
    Ok((
        ShadingModel::Artist(model),
        format!("artist-friendly (Sadeghi 2010), {from}"),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn request(shading: Shading) -> PointShadingRequest<'static> {
        PointShadingRequest {
            shading,
            preset: "brown",
            lut_size: 16,
            artist: None,
        }
    }

    #[test]
    fn shading_choices_build_their_models_and_name_bad_parameters() {
        let (model, text) = point_shading_model(&request(Shading::Marschner)).unwrap();
        match model {
            ShadingModel::MarschnerLut(luts) => {
                assert_eq!(luts.lut_m().shape(), vec![16, 16, 4]);
                assert_eq!(luts.lut_n().shape(), vec![16, 16, 3]);
            }
            other => panic!("{}", other.name()),
        }
        assert!(text.contains("brown") && text.contains("16²"), "{text}");
        assert!(matches!(
            point_shading_model(&request(Shading::Artist)).unwrap().0,
            ShadingModel::Artist(_)
        ));
        match point_shading_model(&request(Shading::Chiang)).unwrap().0 {
            ShadingModel::ChiangLut(luts) => {
                assert_eq!(luts.lut_m().shape(), vec![16, 16, 4]);
                assert_eq!(luts.lut_n().shape(), vec![16, 16, 4]);
            }
            other => panic!("{}", other.name()),
        }
        let e = point_shading_model(&PointShadingRequest {
            preset: "purple",
            ..request(Shading::Marschner)
        })
        .unwrap_err();
        assert!(format!("{e:#}").contains("--preset \"purple\""), "{e:#}");
        let e = point_shading_model(&PointShadingRequest {
            lut_size: 1,
            ..request(Shading::Marschner)
        })
        .unwrap_err();
        assert!(format!("{e:#}").contains("--lut-size 1"), "{e:#}");
        let missing = Path::new("/nonexistent/artist.json");
        let e = read_artist_params(missing).unwrap_err();
        assert!(format!("{e:#}").contains("artist.json"), "{e:#}");
    }
}
