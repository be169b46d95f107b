//! An environment-lit frame's lighting, as part of [`crate::frame_settings::FrameSettings`]:
//! the map, how it becomes lights, and the renderer's choices under it. Every env-lit frame the
//! product draws is one of these: the method's (the SRBF fit), and the frames it is measured
//! against (the DOM reference's cube of lights, the median-cut baseline), so `render`,
//! `compare`, `bench`, the viewer and the page cannot describe one frame two ways.

use crate::look::{EnvTransparency, LookArgs, ViewArgs};
use crate::scene_tables::ScatteringMode;
use anyhow::bail;
use serde::{Deserialize, Serialize};
use strandlight_precompute::FitOptions;
use strandlight_precompute::compact_sources::{
    DEFAULT_WIDER_RADIUS_DEGREES, SourceOptions, wider_radius,
};
use strandlight_runtime::passes::convolution_depth::{DodmSettings, MAX_DODM_RESOLUTION};

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EnvLighting {
    /// A .hdr/.exr map or `procedural:NAME`.
    pub map: String,
    pub scattering: ScatteringMode,
    /// Fraction of the strands drawn into the light maps (Ren §7).
    pub kappa: f32,
    /// Use only the N most powerful SRBF lobes (a fit's compact sources are always kept);
    /// None: all of them.
    pub lobes: Option<usize>,
    /// The environment turned about the hair's up axis, degrees (the convention:
    /// `crate::env_orientation`): every light set is turned exactly, nothing is refitted.
    pub rotation_deg: f32,
    /// Convolution optical depth map resolution (square); a dominant compact source's is four
    /// times it (`DodmSettings::fine_resolution`).
    pub dodm_size: u32,
    pub transparency: EnvTransparency,
    pub view: ViewArgs,
    /// What the map becomes: the SRBF fit (the method), or a light set it is measured against.
    #[serde(default, skip_serializing_if = "EnvLightSet::is_fit")]
    pub light_set: EnvLightSet,
    /// How the SRBF fit is made.
    #[serde(default, skip_serializing_if = "FitSettings::is_default")]
    pub fit: FitSettings,
    /// Replace the map's NaN/negative pixels by 0 and +Inf by its largest finite value
    /// (otherwise such a map is refused).
    #[serde(default, skip_serializing_if = "is_false")]
    pub sanitize: bool,
    /// Nodes per direction axis of the tables; None: the paper's resolution.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub table_resolution: Option<usize>,
    /// False: every single-scattering transmittance is 1, a diagnostic (what is left is the
    /// lighting and the tables' error alone).
    #[serde(default = "yes", skip_serializing_if = "is_true")]
    pub shadowed: bool,
}

fn is_false(b: &bool) -> bool {
    !*b
}

fn is_true(b: &bool) -> bool {
    *b
}

fn yes() -> bool {
    true
}

/// What an environment map becomes for a frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum EnvLightSet {
    /// The SRBF fit (Ren 2010), its compact sources (suns, lamps) as directional lights.
    #[default]
    Fit,
    /// The brute-force DOM reference: the compact sources exactly, the rest one directional
    /// light per texel of a cube of `face`² texels a face (6·face² lights), every strand in
    /// every light map and the dense multiple-scattering grid.
    Reference {
        face: usize,
        /// The map shaded at the texels of a finer cube (a multiple of `face`), visibility
        /// interpolated between the `face` cube's maps; None: at the texel lights only.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        shading_face: Option<usize>,
        #[serde(default, skip_serializing_if = "ReferenceLighting::is_map")]
        lighting: ReferenceLighting,
    },
    /// Median cut (Debevec 2005): `lights` directional lights, Ren's equal-time baseline;
    /// `exact_sources`: the compact sources exactly and median cut over the rest.
    MedianCut { lights: usize, exact_sources: bool },
}

/// What a brute-force reference lights the hair with.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ReferenceLighting {
    /// The map: every error figure is against it.
    #[default]
    Map,
    /// The fit's own lighting: against the map's reference it measures the fit alone, and the
    /// SRBF frame against it the tables and the renderer (`bench`'s error decomposition).
    /// Shaded at the texel lights only.
    Fit,
}

impl ReferenceLighting {
    fn is_map(&self) -> bool {
        *self == Self::Map
    }
}

impl EnvLightSet {
    pub fn is_fit(&self) -> bool {
        *self == Self::Fit
    }

    /// The brute-force reference: its lights stand for the map; the renderer draws every strand
    /// into every map and marches the dense grid.
    pub fn is_reference(&self) -> bool {
        matches!(self, Self::Reference { .. })
    }

    fn check(&self) -> anyhow::Result<()> {
        match *self {
            Self::Fit => {}
            Self::Reference {
                face, shading_face, ..
            } => {
                if face == 0 {
                    bail!("a reference cube of 0 texels a face: use at least 1");
                }
                if let Some(m) = shading_face
                    && (m < face || !m.is_multiple_of(face))
                {
                    bail!(
                        "reference shading cube of {m}² texels a face: must split every one of the {face}² texels (a multiple of {face})"
                    );
                }
            }
            Self::MedianCut { lights, .. } => {
                if lights == 0 {
                    bail!("median cut with 0 lights: use at least 1");
                }
            }
        }
        Ok(())
    }
}

/// How the SRBF fit is made: the knobs a user may turn, the rest [`FitOptions::default`].
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FitSettings {
    /// Most SRBF lobes the fit may use.
    pub max_lobes: usize,
    /// The fit's target relative MSE Σw‖fit−map‖²/Σw‖map‖² (lobes are added until it is met
    /// or max_lobes is reached; default: the paper's 15%).
    pub target_error: f64,
    /// The fit's largest SRBF bandwidth λ (its narrowest lobe).
    pub lambda_max: f64,
    /// Most compact bright sources (suns, lamps) the fit takes out as directional lights
    /// rendered beside the SRBFs; 0: SRBFs alone, as the paper.
    pub sources: usize,
    /// Angular radius of a compact source's disc, degrees.
    pub source_radius: f64,
    /// Least share of the remaining map's squared norm a compact source must hold.
    pub source_min_share: f64,
    /// The sources are taken at this wider radius (degrees) where they hold ≥ 10 points more of
    /// the map's power (extended lamps, a wide sun; 0: never).
    pub wider_source_radius: f64,
}

impl Default for FitSettings {
    fn default() -> Self {
        let fit = FitOptions::default();
        let sources = SourceOptions::default();
        Self {
            max_lobes: fit.max_lobes,
            target_error: fit.target_relative_mse,
            lambda_max: fit.lambda_max,
            sources: sources.max_sources,
            source_radius: sources.radius_degrees,
            source_min_share: sources.min_norm_share,
            wider_source_radius: DEFAULT_WIDER_RADIUS_DEGREES,
        }
    }
}

impl FitSettings {
    pub fn is_default(&self) -> bool {
        *self == Self::default()
    }

    /// The fit's options.
    pub fn options(&self) -> FitOptions {
        let defaults = FitOptions::default();
        FitOptions {
            max_lobes: self.max_lobes,
            initial_lobes: self.max_lobes.min(defaults.initial_lobes),
            sources: SourceOptions {
                max_sources: self.sources,
                radius_degrees: self.source_radius,
                min_norm_share: self.source_min_share,
            },
            wider_source_radius: wider_radius(self.wider_source_radius),
            target_relative_mse: self.target_error,
            lambda_max: self.lambda_max,
            ..defaults
        }
    }

    fn check(&self) -> anyhow::Result<()> {
        if self.max_lobes == 0 {
            bail!("max_lobes 0: at least one SRBF lobe is needed");
        }
        if !(self.source_radius > 0.0 && self.source_radius <= 20.0) {
            bail!(
                "source_radius {}: a compact source's angular radius in degrees, in (0, 20]",
                self.source_radius
            );
        }
        if let Some(r) = wider_radius(self.wider_source_radius)
            && !(r > self.source_radius && r <= 20.0)
        {
            bail!(
                "wider_source_radius {r}: must be wider than source_radius ({}) and at most 20 degrees (0: never)",
                self.source_radius
            );
        }
        if !(self.source_min_share > 0.0 && self.source_min_share <= 1.0) {
            bail!(
                "source_min_share {}: a share of the map's squared norm, in (0, 1]",
                self.source_min_share
            );
        }
        self.options()
            .validate()
            .map_err(|e| anyhow::anyhow!("the fit's settings: {e}"))
    }
}

impl EnvLighting {
    pub fn new(map: impl Into<String>) -> Self {
        Self {
            map: map.into(),
            scattering: ScatteringMode::Full,
            kappa: 0.1,
            lobes: None,
            rotation_deg: 0.0,
            dodm_size: DodmSettings::default().resolution,
            transparency: EnvTransparency::default(),
            view: ViewArgs::default(),
            light_set: EnvLightSet::Fit,
            fit: FitSettings::default(),
            sanitize: false,
            table_resolution: None,
            shadowed: true,
        }
    }

    pub fn look_args(&self) -> LookArgs {
        LookArgs {
            transparency: self.transparency,
            view: self.view,
        }
    }

    /// Every value in range; errors name the setting.
    pub fn check(&self) -> anyhow::Result<()> {
        if !(self.kappa > 0.0 && self.kappa <= 1.0) {
            bail!("--kappa {}: must lie in (0, 1]", self.kappa);
        }
        if self.lobes == Some(0) {
            bail!("--strongest-lobes 0: use at least one SRBF lobe (or leave it out for all)");
        }
        if !self.rotation_deg.is_finite() {
            bail!("--rotate {}: must be a finite angle", self.rotation_deg);
        }
        if !(16..=MAX_DODM_RESOLUTION).contains(&self.dodm_size) {
            bail!(
                "--light-map-size {}: must lie in 16..={MAX_DODM_RESOLUTION} texels",
                self.dodm_size
            );
        }
        if let Some(n) = self.table_resolution
            && !(2..=256).contains(&n)
        {
            bail!("table_resolution {n}: use 2 to 256 nodes per direction axis");
        }
        self.light_set.check()?;
        self.fit.check()?;
        self.look_args().look()?;
        Ok(())
    }
}
