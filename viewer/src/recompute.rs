//! What a change of the viewer's state costs: nothing (display only), a new frame, new light maps,
//! new tables (a background bake) or a new hair. The panel labels its controls with it, and the
//! tests below pin the labels to what [`recompute`] decides.

use strandlight_scene::frame_settings::{FrameSettings, Lighting};
use strandlight_scene::point_shading::Shading;

/// Cheapest first.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Recompute {
    /// Exposure, background: the last image is tonemapped again.
    Nothing,
    /// Camera, view-pass choices, shader constants (the point-lit artist controls): the frame is
    /// rendered again.
    Frame,
    /// What the light passes draw: lights, environment rotation, lobes, κ, map resolutions,
    /// shadow method. (The runtime draws its light maps every frame today, so this costs what
    /// `Frame` costs; it names what a shadow-map cache would have to drop.)
    ShadowMaps,
    /// Fiber tables, lookup textures or the fit of another map: baked on a background thread
    /// (cached on disk like `bake`) while the old tables stay on screen.
    Tables,
    /// Another hair file.
    Hair,
}

impl Recompute {
    /// The panel's word for it.
    pub fn label(self) -> &'static str {
        match self {
            Recompute::Nothing => "display only",
            Recompute::Frame => "shader constants: instant",
            Recompute::ShadowMaps => "light maps: instant",
            Recompute::Tables => "needs a table rebake",
            Recompute::Hair => "reloads the hair",
        }
    }
}

/// How the window shows a frame, besides the frame itself.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Display {
    /// Stops of exposure; None: automatic (the hair's bright pixels land mid-curve).
    pub exposure_stops: Option<f32>,
    /// What is drawn behind the hair.
    pub backdrop: Backdrop,
    /// The adapter, timing and memory readout beside the image.
    pub overlay: bool,
}

impl Default for Display {
    fn default() -> Self {
        Self {
            exposure_stops: None,
            backdrop: Backdrop::Soft,
            overlay: true,
        }
    }
}

/// What the window draws behind the hair (display only; `render` writes the hair over black).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Backdrop {
    /// The environment blurred and two stops darker than the hair's exposure: the sky a person
    /// knows, behind hair that still reads against it (the default).
    #[default]
    Soft,
    /// The environment as the lights see it, at the hair's exposure.
    Environment,
    /// Nothing: the hair over black, as `render` writes it.
    Black,
}

impl Backdrop {
    pub const ALL: [Backdrop; 3] = [Self::Soft, Self::Environment, Self::Black];

    pub fn name(self) -> &'static str {
        match self {
            Self::Soft => "soft",
            Self::Environment => "environment",
            Self::Black => "black",
        }
    }

    /// The one after this, for the B key.
    pub fn next(self) -> Self {
        let i = Self::ALL.iter().position(|b| *b == self).unwrap_or(0);
        Self::ALL[(i + 1) % Self::ALL.len()]
    }
}

/// Everything the window shows.
#[derive(Clone, Debug, PartialEq)]
pub struct ViewState {
    pub settings: FrameSettings,
    pub display: Display,
}

/// The inputs of a table bake or lookup-texture build: a change here is [`Recompute::Tables`].
#[derive(Clone, Debug, PartialEq)]
pub enum TablesKey {
    Lights {
        shading: Shading,
        /// Only the lookup textures (Marschner's, Chiang's) depend on these.
        lookup_tables: Option<(String, usize)>,
    },
    Environment {
        map: String,
        preset: String,
        shading: Shading,
        artist: Option<String>,
        scattering: &'static str,
    },
}

impl TablesKey {
    /// Both keys light a fiber alike in single scattering: they differ at most in scattering.
    pub fn same_single_scattering(&self, other: &TablesKey) -> bool {
        self.without_scattering() == other.without_scattering()
    }

    fn without_scattering(&self) -> TablesKey {
        let mut key = self.clone();
        if let TablesKey::Environment { scattering, .. } = &mut key {
            *scattering = "";
        }
        key
    }
}

pub fn tables_key(settings: &FrameSettings) -> TablesKey {
    let shading = settings.shading();
    match &settings.lighting {
        Lighting::Lights(point) => TablesKey::Lights {
            shading,
            lookup_tables: matches!(shading, Shading::Marschner | Shading::Chiang)
                .then(|| (settings.preset.clone(), point.lut_size)),
        },
        Lighting::Environment(env) => TablesKey::Environment {
            map: env.map.clone(),
            preset: settings.preset.clone(),
            shading,
            // The env tables hold the artist colours: any control change is a rebake.
            artist: (shading == Shading::Artist).then(|| format!("{:?}", settings.artist)),
            scattering: env.scattering.name(),
        },
    }
}

/// What the light passes depend on: the lights, the map choices and the head, opaque in every map.
fn light_maps_key(settings: &FrameSettings) -> String {
    let head = format!("{} {:?}", settings.head, settings.skin_albedo);
    let lights = match &settings.lighting {
        Lighting::Lights(p) => format!(
            "{:?} {:?} {} {:?} {} {} {} {:?} {} {:?}",
            p.lights,
            p.shadows,
            p.dom_layers,
            p.dom_spacing,
            p.dom_size,
            p.osm_slices,
            p.pcf_kernel,
            p.shadow_bias,
            p.adsm_alpha,
            p.adsm_spacing
        ),
        Lighting::Environment(e) => format!(
            "{} {:?} {} {}",
            e.kappa, e.lobes, e.rotation_deg, e.dodm_size
        ),
    };
    format!("{lights} {head}")
}

pub fn recompute(old: &ViewState, new: &ViewState) -> Recompute {
    let (a, b) = (&old.settings, &new.settings);
    if a.hair != b.hair {
        Recompute::Hair
    } else if tables_key(a) != tables_key(b) {
        Recompute::Tables
    } else if light_maps_key(a) != light_maps_key(b) {
        Recompute::ShadowMaps
    } else if a != b {
        Recompute::Frame
    } else {
        Recompute::Nothing
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use strandlight_scene::frame_settings::{EnvLighting, PointLighting, Shadows};
    use strandlight_scene::head_input::HeadChoice;
    use strandlight_scene::scene_tables::ScatteringMode;

    fn state(lighting: Lighting, shading: Shading) -> ViewState {
        let mut settings = FrameSettings::new(lighting, [64, 48]);
        settings.shading = Some(shading);
        ViewState {
            settings,
            display: Display::default(),
        }
    }

    fn env() -> Lighting {
        Lighting::Environment(EnvLighting::new("procedural:studio"))
    }

    fn lights() -> Lighting {
        Lighting::Lights(PointLighting::default())
    }

    fn cost(start: &ViewState, change: impl FnOnce(&mut ViewState)) -> Recompute {
        let mut next = start.clone();
        change(&mut next);
        recompute(start, &next)
    }

    fn brighter_highlight(s: &mut ViewState) {
        let mut a = s.settings.artist.unwrap_or_default();
        a.r.intensity *= 2.0;
        s.settings.artist = Some(a);
    }

    fn env_of(s: &mut ViewState) -> &mut EnvLighting {
        match &mut s.settings.lighting {
            Lighting::Environment(e) => e,
            Lighting::Lights(_) => unreachable!(),
        }
    }

    #[test]
    fn artist_controls_are_constants_under_lights_and_a_rebake_under_an_environment() {
        let point = state(lights(), Shading::Artist);
        assert_eq!(cost(&point, brighter_highlight), Recompute::Frame);
        let lit = state(env(), Shading::Artist);
        assert_eq!(cost(&lit, brighter_highlight), Recompute::Tables);
        // Under Marschner the artist controls are not read at all.
        let marschner = state(env(), Shading::Marschner);
        assert!(cost(&marschner, brighter_highlight) < Recompute::ShadowMaps);
    }

    #[test]
    fn each_kind_of_change_costs_what_it_should() {
        let lit = state(env(), Shading::Marschner);
        assert_eq!(
            cost(&lit, |s| s.display.exposure_stops = Some(2.0)),
            Recompute::Nothing
        );
        assert_eq!(
            cost(&lit, |s| s.display.backdrop = Backdrop::Black),
            Recompute::Nothing
        );
        assert_eq!(
            cost(&lit, |s| s.display.overlay = false),
            Recompute::Nothing
        );
        assert_eq!(cost(&lit, |s| s.settings.size = [32, 24]), Recompute::Frame);
        assert_eq!(
            cost(&lit, |s| env_of(s).rotation_deg = 90.0),
            Recompute::ShadowMaps
        );
        assert_eq!(
            cost(&lit, |s| env_of(s).lobes = Some(8)),
            Recompute::ShadowMaps
        );
        assert_eq!(cost(&lit, |s| env_of(s).kappa = 1.0), Recompute::ShadowMaps);
        assert_eq!(
            cost(&lit, |s| s.settings.head = HeadChoice::Ellipsoid),
            Recompute::ShadowMaps
        );
        assert_eq!(
            cost(&lit, |s| env_of(s).scattering = ScatteringMode::Single),
            Recompute::Tables
        );
        assert_eq!(
            cost(&lit, |s| env_of(s).map = "procedural:sun_and_sky".into()),
            Recompute::Tables
        );
        assert_eq!(
            cost(&lit, |s| s.settings.preset = "blonde".into()),
            Recompute::Tables
        );
        assert_eq!(
            cost(&lit, |s| s.settings.hair = Some("a.hair".into())),
            Recompute::Hair
        );
        let point = state(lights(), Shading::KajiyaKay);
        assert_eq!(
            cost(&point, |s| {
                if let Lighting::Lights(p) = &mut s.settings.lighting {
                    p.shadows = Shadows::Dom
                }
            }),
            Recompute::ShadowMaps
        );
        // Kajiya-Kay has no lookup textures: the preset is not read.
        assert_eq!(
            cost(&point, |s| s.settings.preset = "blonde".into()),
            Recompute::Frame
        );
        let marschner = state(lights(), Shading::Marschner);
        assert_eq!(
            cost(&marschner, |s| s.settings.preset = "blonde".into()),
            Recompute::Tables
        );
        assert_eq!(
            cost(&point, |s| s.settings.lighting = env()),
            Recompute::Tables
        );
    }
}
