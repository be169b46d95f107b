//! One frame from [`FrameSettings`], in the two steps a viewer keeps apart: *prepare* (load the
//! hair; build the point-light fiber model, or fit and bake the environment's SRBF scene) and
//! *render* (camera, lights and look → pixels). `strandlight render` does both once; the viewer
//! prepares again only when a setting that preparation depends on changes.

use crate::env_frame::{EnvFrame, FrameRole};
use crate::env_scene::{EnvScene, EnvSceneRequest, PrepareProgress, prepare_env_scene_reporting};
use crate::environment::{LoadedEnv, load_env};
use crate::frame_settings::{
    EnvLighting, FrameSettings, PointLighting, Shadows, Transparency, up_choice,
};
use crate::hair_input::load_hair;
use crate::look::EnvLook;
use crate::point_shading::{PointShadingRequest, point_shading_model};
use crate::scene_tables::EnvShading;
use crate::steps::Steps;
use anyhow::Context;
use glam::{Quat, Vec3};
use std::path::Path;
use strandlight_precompute::bake_plan::{BakeResolution, FiberDescription};
use strandlight_runtime::camera::{Camera, UpAxis};
use strandlight_runtime::env_light::EnvLight;
use strandlight_runtime::gpu::GpuContext;
use strandlight_runtime::hair::HairModel;
use strandlight_runtime::passes::deep_opacity::{DomSettings, ShadowLookup};
use strandlight_runtime::passes::fiber_shading::ShadingModel;
use strandlight_runtime::passes::frame_params::{FrameParams, KajiyaKay};
use strandlight_runtime::render::{self, RenderOptions, ShadowMaps, render_frame_with_model};
use strandlight_tables::checksum::sha256_hex;
use strandlight_tables::colour::luminance_f32;

/// A loaded hair and a line naming where it came from.
pub struct LoadedHair {
    pub model: HairModel,
    pub source: String,
}

pub fn load_settings_hair(settings: &FrameSettings) -> anyhow::Result<LoadedHair> {
    let (model, source) = load_hair(settings.hair.as_deref())?;
    Ok(LoadedHair { model, source })
}

/// The camera of `settings` for `hair`.
pub fn settings_camera(settings: &FrameSettings, hair: &HairModel) -> anyhow::Result<Camera> {
    let [w, h] = settings.size;
    settings.camera.camera(hair, w, h)
}

/// The point-light fiber model and a line describing it.
pub struct PreparedPoint {
    pub shading: ShadingModel,
    pub description: String,
}

pub fn prepare_point(
    settings: &FrameSettings,
    point: &PointLighting,
) -> anyhow::Result<PreparedPoint> {
    let (shading, description) = point_shading_model(&PointShadingRequest {
        shading: settings.shading(),
        preset: &settings.preset,
        lut_size: point.lut_size,
        artist: settings.artist,
    })?;
    Ok(PreparedPoint {
        shading,
        description,
    })
}

/// The runtime's shadow and transparency choices of `point` for `hair` (defaults scale with
/// the hair's bounding box).
pub fn point_render_options(point: &PointLighting, hair: &HairModel) -> RenderOptions {
    let diagonal = hair.bounds().diagonal();
    let shadows = match point.shadows {
        Shadows::None => None,
        Shadows::Dom => Some(ShadowMaps::Deep {
            settings: DomSettings {
                resolution: point.dom_size,
                layers: point.dom_layers,
                spacing: point.dom_spacing.unwrap_or(diagonal * 0.01),
            },
            pcf: point.pcf_kernel,
        }),
        Shadows::Osm => Some(ShadowMaps::OpacitySlices {
            resolution: point.dom_size,
            slices: point.osm_slices,
            pcf: point.pcf_kernel,
        }),
        Shadows::Sm | Shadows::Adsm => {
            let kernel = point.pcf_kernel;
            // A fiber slanted across a texel spans about a texel in depth: two keep it from
            // shadowing itself.
            let texel = diagonal / point.dom_size.max(1) as f32;
            let bias = point.shadow_bias.unwrap_or(2.0 * texel);
            let lookup = match point.shadows {
                Shadows::Sm => ShadowLookup::Hard { kernel, bias },
                _ => ShadowLookup::Adsm {
                    kernel,
                    bias,
                    alpha: point.adsm_alpha,
                    spacing: point.adsm_spacing.unwrap_or(diagonal * 0.01),
                },
            };
            Some(ShadowMaps::Depth {
                resolution: point.dom_size,
                lookup,
            })
        }
    };
    let transparency = match point.transparency {
        Transparency::None | Transparency::Occupancy => render::Transparency::Opaque,
        Transparency::Sorted => render::Transparency::Sorted {
            bins: point.sort_bins,
        },
        Transparency::Subsets => render::Transparency::RandomSubsets {
            subsets: point.subsets,
        },
        Transparency::Kbuffer => render::Transparency::KBuffer { k: point.kbuffer_k },
        Transparency::Abuffer => render::Transparency::ABuffer {
            nodes_per_pixel: point.abuffer_nodes_per_pixel,
        },
        Transparency::Dbk => render::Transparency::Dbk {
            nodes_per_pixel: point.abuffer_nodes_per_pixel,
            delta: point.dbk_delta.unwrap_or(diagonal * 0.05),
        },
    };
    RenderOptions {
        shadows,
        transparency,
    }
}

/// A point-lit frame of `settings` at `size` (the viewer's previews ask for a smaller one).
pub fn render_point(
    gpu: &GpuContext,
    settings: &FrameSettings,
    point: &PointLighting,
    hair: &HairModel,
    prepared: &PreparedPoint,
    size: [u32; 2],
) -> anyhow::Result<render::Frame> {
    let camera = settings_camera(settings, hair)?;
    let frame = FrameParams {
        camera,
        width: size[0],
        height: size[1],
        lights: point.parsed_lights()?,
        shading: KajiyaKay::default(),
        width_override_px: settings.fiber_width_px,
    };
    Ok(render_frame_with_model(
        gpu,
        hair,
        &frame,
        &point_render_options(point, hair),
        &prepared.shading,
    )?)
}

/// An environment's fit and tables, ready to light frames.
pub struct PreparedEnv {
    pub env: LoadedEnv,
    pub scene: EnvScene,
    pub shading: EnvShading,
    /// The hair's up axis, onto which the map's +y is turned.
    pub up: UpAxis,
}

/// The cache folder of a fiber's tables: custom artist controls get one of their own, named by
/// their hash, so switching back and forth serves both from the cache.
pub fn env_table_set(settings: &FrameSettings, shading: EnvShading) -> String {
    let base = format!("{}-{:?}", settings.preset, shading).to_lowercase();
    match (shading, settings.artist) {
        (EnvShading::Artist, Some(params)) => {
            let json = serde_json::to_vec(&params).expect("artist controls serialize");
            format!("{base}-{}", &sha256_hex(&json)[..12])
        }
        _ => base,
    }
}

/// Loads the map, fits it and bakes the fiber's tables (both cached under `cache_dir`).
pub fn prepare_env(
    settings: &FrameSettings,
    env: &EnvLighting,
    hair: &HairModel,
    cache_dir: &Path,
    steps: &mut Steps,
    progress: &mut dyn FnMut(PrepareProgress),
) -> anyhow::Result<PreparedEnv> {
    let shading = settings.env_shading()?;
    let loaded = steps.run(
        "environment",
        || load_env(&env.map, false),
        |e| format!("{} {}x{}", e.name, e.map.width(), e.map.height()),
    )?;
    let mut fiber = FiberDescription::preset(&settings.preset)
        .with_context(|| format!("--preset {:?}", settings.preset))?;
    if let Some(artist) = settings.artist {
        fiber.artist = artist;
    }
    let up = up_choice(settings).axis(hair);
    let table_set = env_table_set(settings, shading);
    let request = EnvSceneRequest {
        env: &loaded,
        fiber: &fiber,
        shading,
        scattering: env.scattering,
        resolution: BakeResolution::default(),
        cache_dir,
        table_set: &table_set,
        up,
    };
    let scene = prepare_env_scene_reporting(&request, steps, progress)?;
    Ok(PreparedEnv {
        env: loaded,
        scene,
        shading,
        up,
    })
}

/// The lights of a frame: the `env.lobes` most powerful SRBFs (all when None) and every
/// compact source, turned `env.rotation_deg` about the up axis, most powerful first.
pub fn frame_lights(prepared: &PreparedEnv, env: &EnvLighting) -> Vec<EnvLight> {
    let luminance = light_luminance;
    let mut lights = prepared.scene.lights.clone();
    lights.sort_by(|a, b| luminance(b).total_cmp(&luminance(a)));
    let mut srbf_kept = 0;
    lights.retain(|l| {
        let keep = l.lambda.is_none() || env.lobes.is_none_or(|n| srbf_kept < n);
        srbf_kept += usize::from(l.lambda.is_some() && keep);
        keep
    });
    let turn = Quat::from_axis_angle(prepared.up.vector(), env.rotation_deg.to_radians());
    for light in &mut lights {
        light.direction = (turn * light.direction).normalize_or(Vec3::Y);
    }
    lights
}

/// The luminance of a light's power (Rec. 709 weights).
pub fn light_luminance(light: &EnvLight) -> f32 {
    luminance_f32(light.power())
}

/// How an env-lit frame of `env` looks.
pub fn env_look(env: &EnvLighting) -> anyhow::Result<EnvLook> {
    let mut look = env.look_args().look()?;
    look.dodm.resolution = env.dodm_size;
    Ok(look)
}

/// An env-lit frame of `settings` under `lights` (all or some of [`frame_lights`]) at `size`.
pub fn env_frame<'a>(
    settings: &FrameSettings,
    env: &EnvLighting,
    hair: &'a HairModel,
    prepared: &'a PreparedEnv,
    lights: &'a [EnvLight],
    size: [u32; 2],
    look: EnvLook,
) -> anyhow::Result<EnvFrame<'a>> {
    Ok(EnvFrame {
        hair,
        camera: settings_camera(settings, hair)?,
        width: size[0],
        height: size[1],
        lights,
        tables: &prepared.scene.tables,
        shading: prepared.shading,
        mode: prepared.scene.mode,
        role: FrameRole::Interactive { kappa: env.kappa },
        look,
    })
}
