//! Everything that decides one rendered picture, as one serializable value: what `render` builds
//! from its flags, what the viewer edits live and writes beside every screenshot, and what
//! `render replay` reads back to reproduce that screenshot.

use crate::camera_choice::{CameraChoice, UpChoice};
pub use crate::env_lighting::{EnvLightSet, EnvLighting, FitSettings, ReferenceLighting};
use crate::head_input::{HeadChoice, default_skin_albedo};
use crate::point_shading::Shading;
use crate::scene_tables::EnvShading;
use anyhow::{Context, bail};
use glam::Vec3;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use strandlight_runtime::camera::{Camera, MAX_FOV_Y_DEGREES, Projection};
use strandlight_runtime::hair::HairModel;
use strandlight_runtime::lights::Light;
use strandlight_tables::artist::{ArtistModel, ArtistParams};

/// One picture: hair, camera, fiber and lighting.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FrameSettings {
    /// Hair file or `procedural:STYLE`; None: the procedural groom's default style.
    pub hair: Option<PathBuf>,
    /// Width and height in pixels.
    pub size: [u32; 2],
    pub camera: CameraSettings,
    /// Fiber model; None: Kajiya-Kay under point lights, Chiang (the path-traced truth's fiber)
    /// under an environment. Settings written before 6 Dec 2026 with None were Marschner's.
    pub shading: Option<Shading>,
    /// Melanin preset of the Marschner fiber (and the fiber whose tables an environment bakes).
    pub preset: String,
    /// Artist controls of `--shading artist`; None: the built-in light brown.
    pub artist: Option<ArtistParams>,
    /// Every fiber this many pixels wide; None: the file's thickness, projected.
    pub fiber_width_px: Option<f32>,
    pub lighting: Lighting,
    /// The head the hair grows from (issue 40): none, an ellipsoid fitted to the strand roots,
    /// or an OBJ mesh. Absent from settings written before it: none, as they were rendered.
    #[serde(default, skip_serializing_if = "HeadChoice::is_none")]
    pub head: HeadChoice,
    /// The head's skin: linear RGB diffuse albedo.
    #[serde(
        default = "default_skin_albedo",
        skip_serializing_if = "is_default_skin"
    )]
    pub skin_albedo: [f32; 3],
}

fn is_default_skin(albedo: &[f32; 3]) -> bool {
    *albedo == default_skin_albedo()
}

/// Where the camera is.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum CameraSettings {
    /// Framing the hair's bounds (`render --camera --up --eye`).
    Framed(CameraChoice),
    /// Exactly this view (the viewer's orbit camera, replayed as it was).
    Exact(ExactCamera),
}

/// A camera written out in full.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExactCamera {
    pub eye: [f32; 3],
    pub target: [f32; 3],
    pub up: [f32; 3],
    /// Vertical field of view in degrees; None: orthographic with `half_height`.
    pub fov_y_deg: Option<f32>,
    /// Half the visible height (orthographic only), world units.
    pub half_height: Option<f32>,
    pub near: f32,
    pub far: f32,
}

impl ExactCamera {
    pub fn of(camera: &Camera) -> Self {
        let (fov_y_deg, half_height) = match camera.projection {
            Projection::Perspective { fov_y } => (Some(fov_y.to_degrees()), None),
            Projection::Orthographic { half_height } => (None, Some(half_height)),
        };
        Self {
            eye: camera.eye.to_array(),
            target: camera.target.to_array(),
            up: camera.up.to_array(),
            fov_y_deg,
            half_height,
            near: camera.near,
            far: camera.far,
        }
    }

    pub fn camera(&self) -> anyhow::Result<Camera> {
        let projection = match (self.fov_y_deg, self.half_height) {
            (Some(fov), None) if fov > 0.0 && fov <= MAX_FOV_Y_DEGREES => Projection::Perspective {
                fov_y: fov.to_radians(),
            },
            (None, Some(h)) if h > 0.0 && h.is_finite() => {
                Projection::Orthographic { half_height: h }
            }
            _ => bail!(
                "camera: give either fov_y_deg in (0, {MAX_FOV_Y_DEGREES}] or a positive half_height"
            ),
        };
        let camera = Camera {
            eye: Vec3::from(self.eye),
            target: Vec3::from(self.target),
            up: Vec3::from(self.up),
            projection,
            near: self.near,
            far: self.far,
        };
        let finite = [camera.eye, camera.target, camera.up]
            .iter()
            .all(|v| v.is_finite());
        let view = camera.target - camera.eye;
        if !finite
            || view.length() <= 0.0
            || camera.up.cross(view).length() <= 1e-6 * view.length() * camera.up.length()
        {
            bail!(
                "camera: eye {:?}, target {:?} and up {:?} must be finite, distinct and not collinear",
                self.eye,
                self.target,
                self.up
            );
        }
        if !(self.near > 0.0 && self.far > self.near && self.far.is_finite()) {
            bail!(
                "camera: near {} and far {} must satisfy 0 < near < far",
                self.near,
                self.far
            );
        }
        Ok(camera)
    }
}

impl CameraSettings {
    /// The camera for `model` at `width`/`height`.
    pub fn camera(&self, model: &HairModel, width: u32, height: u32) -> anyhow::Result<Camera> {
        match self {
            CameraSettings::Framed(choice) => choice.camera(model, width as f32 / height as f32),
            CameraSettings::Exact(exact) => exact.camera(),
        }
    }
}

/// What lights the hair.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Lighting {
    /// Directional, point and spot lights with the thesis techniques.
    Lights(PointLighting),
    /// An environment map fitted with SRBFs (Ren 2010).
    Environment(EnvLighting),
}

/// Shadows of point-lit frames.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum Shadows {
    #[default]
    None,
    /// Deep opacity maps (layers from each texel's nearest fiber).
    Dom,
    /// Opacity shadow maps (equal slices across the hair's depth range).
    Osm,
    /// Shadow maps with percentage-closer filtering.
    Sm,
    /// Approximate deep shadow maps (TressFX; a fiber count from the depth behind the nearest).
    Adsm,
}

/// Transparency of point-lit frames (`occupancy` is the env-lit view's).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum Transparency {
    /// Depth-tested, coverage blended in draw order.
    #[default]
    #[cfg_attr(feature = "cli", value(alias = "opaque"))]
    #[serde(alias = "opaque")]
    None,
    /// Segments bin-sorted back to front, blended without a depth test.
    Sorted,
    Abuffer,
    /// The k nearest fragments per pixel, the rest dropped (counted).
    Kbuffer,
    Dbk,
    /// Strands in k random subsets, each drawn opaque, the layers sorted per pixel.
    Subsets,
    /// With an environment only: every fiber weighted by its visibility through an occupancy map.
    Occupancy,
}

/// The default light when none is given: from the upper right front.
pub const DEFAULT_LIGHT: &str = "directional:0.5,0.7,1:2";

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PointLighting {
    /// `directional:X,Y,Z[:I]`, `point:X,Y,Z[:I]`, `spot:X,Y,Z:DX,DY,DZ:HALF_ANGLE[:I]`.
    pub lights: Vec<String>,
    pub shadows: Shadows,
    pub transparency: Transparency,
    /// Deep opacity map layers (1..=8).
    pub dom_layers: u32,
    /// Layer spacing in world units; None: 1% of the hair's bounding-box diagonal.
    pub dom_spacing: Option<f32>,
    /// Deep or opacity shadow map resolution (square).
    pub dom_size: u32,
    /// Opacity shadow map slices (1..=8).
    #[serde(default = "default_osm_slices")]
    pub osm_slices: u32,
    /// Shadow map and ADSM filter: texels per side (odd, 1..=9).
    #[serde(default = "default_pcf_kernel")]
    pub pcf_kernel: u32,
    /// Shadow map and ADSM bias along the light, world units; None: two light-map texels.
    #[serde(default)]
    pub shadow_bias: Option<f32>,
    /// ADSM: opacity of one fiber, in (0, 1).
    #[serde(default = "default_adsm_alpha")]
    pub adsm_alpha: f32,
    /// ADSM: world units between fibers along the light; None: 1% of the hair's diagonal.
    #[serde(default)]
    pub adsm_spacing: Option<f32>,
    /// Sorted blending: depth bins of the counting sort.
    #[serde(default = "default_sort_bins")]
    pub sort_bins: u32,
    /// K-buffer: fragments kept per pixel.
    #[serde(default = "default_kbuffer_k")]
    pub kbuffer_k: u32,
    /// Random subsets: how many.
    #[serde(default = "default_subsets")]
    pub subsets: u32,
    /// A-buffer and DBK node pool, nodes per pixel; None: sized to the fragments the
    /// technique stores (a counting build first).
    #[serde(default)]
    pub abuffer_nodes_per_pixel: Option<u32>,
    /// DBK layer depth Δ in world units; None: 5% of the hair's bounding-box diagonal.
    pub dbk_delta: Option<f32>,
    /// Nodes per axis of the Marschner lookup textures.
    pub lut_size: usize,
}

/// Opacity shadow map slices: Kim 2003's smallest count (two layer passes).
pub const DEFAULT_OSM_SLICES: u32 = 16;

fn default_osm_slices() -> u32 {
    DEFAULT_OSM_SLICES
}

fn default_subsets() -> u32 {
    strandlight_runtime::passes::random_subsets::DEFAULT_SUBSETS
}

fn default_sort_bins() -> u32 {
    strandlight_runtime::passes::sorted_blend::DEFAULT_SORT_BINS
}

/// Hunz §6 keeps k = 8 fragments per pixel.
pub const DEFAULT_KBUFFER_K: u32 = 8;

fn default_kbuffer_k() -> u32 {
    DEFAULT_KBUFFER_K
}

/// Hunz §6 filters shadow maps and ADSM with 3×3 PCF.
pub const DEFAULT_PCF_KERNEL: u32 = 3;

fn default_pcf_kernel() -> u32 {
    DEFAULT_PCF_KERNEL
}

/// ADSM's fiber opacity (see docs/BENCHMARKS.md, "Shadow techniques", for how it was chosen).
pub const DEFAULT_ADSM_ALPHA: f32 = 0.4;

fn default_adsm_alpha() -> f32 {
    DEFAULT_ADSM_ALPHA
}

impl Default for PointLighting {
    fn default() -> Self {
        Self {
            lights: vec![DEFAULT_LIGHT.to_string()],
            shadows: Shadows::None,
            transparency: Transparency::None,
            dom_layers: 4,
            dom_spacing: None,
            dom_size: 512,
            osm_slices: DEFAULT_OSM_SLICES,
            pcf_kernel: DEFAULT_PCF_KERNEL,
            sort_bins: default_sort_bins(),
            kbuffer_k: DEFAULT_KBUFFER_K,
            subsets: default_subsets(),
            shadow_bias: None,
            adsm_alpha: DEFAULT_ADSM_ALPHA,
            adsm_spacing: None,
            abuffer_nodes_per_pixel: None,
            dbk_delta: None,
            lut_size: 128,
        }
    }
}

impl FrameSettings {
    /// The procedural groom, framed from the front, at `size`, under `lighting`.
    pub fn new(lighting: Lighting, size: [u32; 2]) -> Self {
        Self {
            hair: None,
            size,
            camera: CameraSettings::Framed(CameraChoice::default()),
            shading: None,
            preset: "brown".into(),
            artist: None,
            fiber_width_px: None,
            lighting,
            head: HeadChoice::None,
            skin_albedo: default_skin_albedo(),
        }
    }

    /// Reads the JSON sidecar a viewer screenshot wrote (or any settings file).
    pub fn read(path: &Path) -> anyhow::Result<Self> {
        let text = std::fs::read_to_string(path)
            .with_context(|| format!("reading settings {}", path.display()))?;
        let settings: Self = serde_json::from_str(&text)
            .with_context(|| format!("settings {}: not a frame-settings JSON", path.display()))?;
        settings
            .check()
            .with_context(|| format!("settings {}", path.display()))?;
        Ok(settings)
    }

    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("settings serialize")
    }

    /// The fiber model, with the default of the lighting.
    pub fn shading(&self) -> Shading {
        self.shading.unwrap_or(match self.lighting {
            Lighting::Lights(_) => Shading::KajiyaKay,
            Lighting::Environment(_) => Shading::Chiang,
        })
    }

    /// Lit by the map `map`: the map is swapped in an existing environment (its other choices
    /// kept), or an environment replaces the lights; Kajiya-Kay, which has no env tables, gives
    /// way to the environment's default model.
    pub fn light_with_environment(&mut self, map: String) {
        match &mut self.lighting {
            Lighting::Environment(env) => env.map = map,
            Lighting::Lights(_) => {
                self.lighting = Lighting::Environment(EnvLighting::new(map));
                if self.shading == Some(Shading::KajiyaKay) {
                    self.shading = None;
                }
            }
        }
    }

    /// The env renderer's fiber model (it reads one RGB 4D table: Marschner, Chiang or artist).
    pub fn env_shading(&self) -> anyhow::Result<EnvShading> {
        match self.shading() {
            Shading::Marschner => Ok(EnvShading::Marschner),
            Shading::Chiang => Ok(EnvShading::Chiang),
            Shading::Artist => Ok(EnvShading::Artist),
            Shading::KajiyaKay => bail!(
                "--shading kajiya-kay under an environment: the env renderer reads one RGB 4D table (Marschner I_M, Chiang's or the artist I_A); use --shading marschner, chiang or artist"
            ),
        }
    }

    /// Every value in range, before anything is loaded or rendered. Errors name the setting.
    pub fn check(&self) -> anyhow::Result<()> {
        let [w, h] = self.size;
        if w == 0 || h == 0 {
            bail!("--size {w}x{h}: both sides must be at least 1 pixel");
        }
        if let Some(w) = self.fiber_width_px
            && !(w.is_finite() && w > 0.0)
        {
            bail!("--fiber-width-px {w}: must be a positive number of pixels");
        }
        if let CameraSettings::Exact(exact) = &self.camera {
            exact.camera()?;
        }
        if self.skin_albedo.iter().any(|a| !(0.0..=1.0).contains(a)) {
            bail!(
                "--skin {:?}: each channel of the skin's albedo must be in [0, 1]",
                self.skin_albedo
            );
        }
        if let Some(params) = self.artist {
            ArtistModel::new(params).context("artist controls")?;
        }
        match &self.lighting {
            Lighting::Lights(point) => point.check(),
            Lighting::Environment(env) => {
                self.env_shading()?;
                env.check()
            }
        }
    }
}

impl PointLighting {
    fn check(&self) -> anyhow::Result<()> {
        if self.transparency == Transparency::Occupancy {
            bail!(
                "--transparency occupancy is the view of `render env` (environment lighting); with point lights use none, sorted, abuffer, kbuffer, dbk or subsets"
            );
        }
        if self.lights.is_empty() {
            bail!("--light: at least one light is needed");
        }
        for spec in &self.lights {
            Light::parse(spec)?;
        }
        if let Some(d) = self.dbk_delta
            && !(d.is_finite() && d >= 0.0)
        {
            bail!("--dbk-delta {d}: must be a non-negative number of world units");
        }
        Ok(())
    }

    pub fn parsed_lights(&self) -> anyhow::Result<Vec<Light>> {
        Ok(self
            .lights
            .iter()
            .map(|s| Light::parse(s))
            .collect::<Result<Vec<_>, _>>()?)
    }
}

/// The up axis `settings` frames the hair with (Exact cameras carry their own up; the
/// environment's +y still turns onto the file's up axis).
pub fn up_choice(settings: &FrameSettings) -> UpChoice {
    match settings.camera {
        CameraSettings::Framed(choice) => choice.up,
        CameraSettings::Exact(_) => UpChoice::Auto,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn settings_survive_a_json_round_trip_exactly() {
        let mut settings = FrameSettings::new(
            Lighting::Environment(EnvLighting::new("procedural:studio")),
            [64, 48],
        );
        settings.camera = CameraSettings::Exact(ExactCamera {
            eye: [0.1, 0.2, 3.000_000_2],
            target: [0.0, 0.0, 0.0],
            up: [0.0, 1.0, 0.0],
            fov_y_deg: Some(31.7),
            half_height: None,
            near: 0.01,
            far: 100.0,
        });
        settings.artist = Some(ArtistParams::default());
        let back: FrameSettings = serde_json::from_str(&settings.to_json()).unwrap();
        assert_eq!(back, settings);
    }

    #[test]
    fn settings_written_before_the_head_read_as_no_head_and_write_back_the_same() {
        let settings = FrameSettings::new(
            Lighting::Environment(EnvLighting::new("procedural:studio")),
            [64, 48],
        );
        // The JSON of a settings value has no head keys while the head is none and the skin the
        // default, exactly as every settings file written before them.
        let old = settings.to_json();
        assert!(!old.contains("head") && !old.contains("skin"), "{old}");
        let back: FrameSettings = serde_json::from_str(&old).unwrap();
        assert_eq!(back.head, HeadChoice::None);
        assert_eq!(back.skin_albedo, default_skin_albedo());
        let mut with_head = settings.clone();
        with_head.head = HeadChoice::mesh("heads/a.obj");
        with_head.skin_albedo = [0.2, 0.1, 0.05];
        let json = with_head.to_json();
        let back: FrameSettings = serde_json::from_str(&json).unwrap();
        assert_eq!(back, with_head);
        with_head.skin_albedo = [1.5, 0.1, 0.05];
        let error = format!("{:#}", with_head.check().unwrap_err());
        assert!(error.contains("--skin"), "{error}");
    }

    #[test]
    fn bad_values_are_refused_with_the_setting_named() {
        let env = |f: &dyn Fn(&mut EnvLighting)| {
            let mut e = EnvLighting::new("procedural:studio");
            f(&mut e);
            let s = FrameSettings::new(Lighting::Environment(e), [8, 8]);
            format!("{:#}", s.check().unwrap_err())
        };
        assert!(env(&|e| e.kappa = 0.0).contains("--kappa"));
        assert!(env(&|e| e.lobes = Some(0)).contains("--strongest-lobes"));
        assert!(env(&|e| e.dodm_size = 4).contains("--light-map-size"));
        assert!(env(&|e| e.rotation_deg = f32::NAN).contains("--rotate"));
        let mut s = FrameSettings::new(Lighting::Lights(PointLighting::default()), [8, 8]);
        s.shading = Some(Shading::KajiyaKay);
        s.check().unwrap();
        s.lighting = Lighting::Environment(EnvLighting::new("procedural:studio"));
        assert!(format!("{:#}", s.check().unwrap_err()).contains("kajiya-kay"));
        s.size = [0, 8];
        assert!(format!("{:#}", s.check().unwrap_err()).contains("--size"));
        let mut exact = ExactCamera::of(&Camera {
            eye: Vec3::Z,
            target: Vec3::ZERO,
            up: Vec3::Y,
            projection: Projection::Perspective { fov_y: 0.5 },
            near: 0.1,
            far: 10.0,
        });
        exact.camera().unwrap();
        exact.up = [0.0, 0.0, 1.0];
        let e = exact.camera().unwrap_err().to_string();
        assert!(
            e.contains("not collinear"),
            "up along the view is refused: {e}"
        );
    }
}
