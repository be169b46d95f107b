//! One frame from [`FrameSettings`], in the two steps a viewer keeps apart: *prepare* (load the
//! hair; build the point-light fiber model, or fit and bake the environment's SRBF scene) and
//! *render* ([`render_frame`]: camera, lights and look → pixels). `strandlight render` and the
//! demo do both once; the viewer prepares again only when a setting that preparation depends on
//! changes, and renders its preview and light batches through the same [`render_frame`].

use crate::env_frame::{EnvFrame, FrameRole, env_adapter, render_lights, shared_gpu};
use crate::env_scene::{EnvScene, EnvSceneRequest, PrepareProgress, prepare_env_scene_reporting};
use crate::environment::{LoadedEnv, load_env};
use crate::frame_settings::{
    EnvLighting, FrameSettings, Lighting, PointLighting, Shadows, Transparency, up_choice,
};
use crate::hair_input::{load_hair, opaque_if_physical};
use crate::head_input::load_head;
use crate::image_metrics::Image;
use crate::look::EnvLook;
use crate::point_shading::{PointShadingRequest, point_shading_model};
use crate::scene_tables::{EnvShading, ScatteringMode};
use crate::steps::Steps;
use anyhow::Context;
use glam::{Quat, Vec3};
use std::path::Path;
use strandlight_precompute::bake_plan::{BakeResolution, FiberDescription};
use strandlight_runtime::camera::{Camera, UpAxis};
use strandlight_runtime::env::{FragmentCounts, ViewTransparency};
use strandlight_runtime::env_light::EnvLight;
use strandlight_runtime::gpu::GpuContext;
use strandlight_runtime::hair::HairModel;
use strandlight_runtime::passes::deep_opacity::{DomSettings, ShadowLookup};
use strandlight_runtime::passes::fiber_shading::ShadingModel;
use strandlight_runtime::passes::frame_params::{FrameParams, KajiyaKay};
use strandlight_runtime::point_frame::{
    self, PassTiming, RenderOptions, RenderStats, ShadowMaps, TIMING_METHOD, render_frame_with_head,
};
use strandlight_tables::checksum::sha256_hex;
use strandlight_tables::colour::luminance_f32;

/// A loaded hair and a line naming where it came from.
pub struct LoadedHair {
    pub model: HairModel,
    pub source: String,
}

/// The hair of `settings` as its fiber model renders it. Chiang fibers are the path tracer's
/// opaque cylinders, so a file's transparency is dropped for them, as `compare` and `truth` drop
/// it: `render` must reproduce the frames they measure.
pub fn load_settings_hair(settings: &FrameSettings) -> anyhow::Result<LoadedHair> {
    let (model, source) = load_hair(settings.hair.as_deref())?;
    let (model, dropped) = opaque_if_physical(settings.shading(), model);
    let source = if dropped {
        format!("{source} (opaque fibers: its transparency is ignored by the Chiang model)")
    } else {
        source
    };
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
        Transparency::None | Transparency::Occupancy => point_frame::Transparency::Opaque,
        Transparency::Sorted => point_frame::Transparency::Sorted {
            bins: point.sort_bins,
        },
        Transparency::Subsets => point_frame::Transparency::RandomSubsets {
            subsets: point.subsets,
        },
        Transparency::Kbuffer => point_frame::Transparency::KBuffer { k: point.kbuffer_k },
        Transparency::Abuffer => point_frame::Transparency::ABuffer {
            nodes_per_pixel: point.abuffer_nodes_per_pixel,
        },
        Transparency::Dbk => point_frame::Transparency::Dbk {
            nodes_per_pixel: point.abuffer_nodes_per_pixel,
            delta: point.dbk_delta.unwrap_or(diagonal * 0.05),
        },
    };
    RenderOptions {
        shadows,
        transparency,
        ..Default::default()
    }
}

/// A point-lit frame of `settings` at `size`.
fn render_point(
    gpu: &GpuContext,
    settings: &FrameSettings,
    point: &PointLighting,
    hair: &HairModel,
    prepared: &PreparedPoint,
    size: [u32; 2],
) -> anyhow::Result<point_frame::Frame> {
    let camera = settings_camera(settings, hair)?;
    let frame = FrameParams {
        camera,
        width: size[0],
        height: size[1],
        lights: point.parsed_lights()?,
        shading: KajiyaKay::default(),
        width_override_px: settings.fiber_width_px,
    };
    // The head (issue 40): opaque in every light's maps and in the view, drawn as skin.
    let head = load_head(&settings.head, hair, settings.skin_albedo)?;
    Ok(render_frame_with_head(
        gpu,
        hair,
        &frame,
        &point_render_options(point, hair),
        &prepared.shading,
        head.as_ref(),
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
    select_lights(&prepared.scene.lights, prepared.up, env)
}

/// [`frame_lights`] from a scene's `lights` and the hair's `up` axis (a web page has no
/// [`PreparedEnv`], only the fit's lights).
pub fn select_lights(lights: &[EnvLight], up: UpAxis, env: &EnvLighting) -> Vec<EnvLight> {
    let luminance = light_luminance;
    let mut lights = lights.to_vec();
    lights.sort_by(|a, b| luminance(b).total_cmp(&luminance(a)));
    let mut srbf_kept = 0;
    lights.retain(|l| {
        let keep = l.lambda.is_none() || env.lobes.is_none_or(|n| srbf_kept < n);
        srbf_kept += usize::from(l.lambda.is_some() && keep);
        keep
    });
    let turn = Quat::from_axis_angle(up.vector(), env.rotation_deg.to_radians());
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
fn env_frame<'a>(
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
        head: load_head(&settings.head, hair, settings.skin_albedo)?,
    })
}

/// What a frame's lighting was prepared into (borrowed: the viewer keeps each kind cached).
#[derive(Clone, Copy)]
pub enum Prepared<'a> {
    Point(&'a PreparedPoint),
    Env(&'a PreparedEnv),
}

/// The viewer's preview draws this many of the most powerful lights.
pub const PREVIEW_LIGHTS: usize = 8;
/// The preview's light maps are at most this many texels across.
pub const PREVIEW_MAP_RESOLUTION: u32 = 128;

/// Which part of a settings' frame to render.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FramePart {
    /// The whole frame at the settings' size.
    Whole,
    /// A cheap first look at half size: for an environment the [`PREVIEW_LIGHTS`] most
    /// powerful lights, light maps of at most [`PREVIEW_MAP_RESOLUTION`]², the opaque view and
    /// single scattering.
    Preview,
    /// Lights `first..first + count` of the env-lit frame ([`frame_lights`]' order): parts that
    /// partition the lights sum to the whole frame.
    Lights { first: usize, count: usize },
}

impl FramePart {
    /// The image size of this part of a frame of `full` size.
    pub fn size(self, full: [u32; 2]) -> [u32; 2] {
        match self {
            FramePart::Preview => full.map(|s| (s / 2).max(1)),
            _ => full,
        }
    }
}

/// A rendered frame (or part of one) and what it cost.
pub struct RenderedFrame {
    pub image: Image,
    /// Frame time without the one-time setup passes.
    pub milliseconds: f64,
    pub passes: Vec<PassTiming>,
    /// GPU memory per resource while it renders (per light batch for an environment), bytes.
    pub memory: Vec<(String, u64)>,
    pub adapter: String,
    pub timing_method: String,
    pub details: FrameDetails,
}

/// What only one kind of lighting reports.
pub enum FrameDetails {
    Point(RenderStats),
    Env {
        /// The lights drawn, in the hair's world frame.
        lights: Vec<EnvLight>,
        /// The scattering rendered (dark hair without a multiple table falls back to single).
        mode: ScatteringMode,
        /// With `count_fragments`.
        fragments: Option<FragmentCounts>,
    },
}

impl RenderedFrame {
    /// Lights drawn: point lights, or SRBF lobes and directional sources.
    pub fn light_count(&self, settings: &FrameSettings) -> usize {
        match (&self.details, &settings.lighting) {
            (FrameDetails::Env { lights, .. }, _) => lights.len(),
            (FrameDetails::Point(_), Lighting::Lights(point)) => point.lights.len(),
            (FrameDetails::Point(_), _) => 0,
        }
    }
}

/// THE frame function: `part` of the frame of `settings` for `hair`, lit as `prepared` (from
/// the same settings' [`prepare_point`] or [`prepare_env`]). `count_fragments` asks an env-lit
/// frame to count its rasterized and shaded fragments (slower; reports only).
pub fn render_frame(
    settings: &FrameSettings,
    hair: &HairModel,
    prepared: Prepared,
    part: FramePart,
    count_fragments: bool,
) -> anyhow::Result<RenderedFrame> {
    let size = part.size(settings.size);
    match (&settings.lighting, prepared) {
        (Lighting::Lights(point), Prepared::Point(prepared)) => {
            if let FramePart::Lights { .. } = part {
                anyhow::bail!("a point-lit frame is rendered whole, not by light batches");
            }
            let gpu = shared_gpu()?;
            let frame = render_point(gpu, settings, point, hair, prepared, size)?;
            Ok(RenderedFrame {
                image: Image {
                    width: frame.width,
                    height: frame.height,
                    pixels: frame.pixels,
                },
                milliseconds: point_frame_milliseconds(&frame.stats.timings),
                passes: frame.stats.timings.clone(),
                memory: frame.stats.memory_bytes.clone(),
                adapter: frame.stats.adapter.to_string(),
                timing_method: frame.stats.timing_method.to_string(),
                details: FrameDetails::Point(frame.stats),
            })
        }
        (Lighting::Environment(env), Prepared::Env(prepared)) => {
            render_env_part(settings, env, hair, prepared, part, count_fragments)
        }
        _ => anyhow::bail!("the frame's lighting was prepared for other settings"),
    }
}

/// Milliseconds of a point-lit frame: its passes without the one-time setup (the hair's upload
/// and pipeline creation), as [`crate::env_frame::frame_milliseconds`] does for env-lit frames.
fn point_frame_milliseconds(passes: &[PassTiming]) -> f64 {
    passes
        .iter()
        .filter(|t| t.pass != "upload" && !t.pass.ends_with("pipeline"))
        .map(|t| t.milliseconds)
        .sum()
}

/// What `part` of an env-lit frame draws: its lights, look and scattering.
pub struct EnvPart {
    pub lights: Vec<EnvLight>,
    pub look: EnvLook,
    pub mode: ScatteringMode,
}

/// `part` of the env-lit frame of `env` whose lights are `all` ([`frame_lights`]' order) and
/// whose scene renders in `mode`.
pub fn env_part(
    env: &EnvLighting,
    all: Vec<EnvLight>,
    mode: ScatteringMode,
    part: FramePart,
    count_fragments: bool,
) -> anyhow::Result<EnvPart> {
    let look = EnvLook {
        count_fragments,
        ..env_look(env)?
    };
    Ok(match part {
        FramePart::Whole => EnvPart {
            lights: all,
            look,
            mode,
        },
        FramePart::Preview => {
            let mut look = look;
            look.dodm.resolution = look.dodm.resolution.min(PREVIEW_MAP_RESOLUTION);
            look.transparency = ViewTransparency::Opaque;
            let lights = all[..all.len().min(PREVIEW_LIGHTS)].to_vec();
            EnvPart {
                lights,
                look,
                mode: ScatteringMode::Single,
            }
        }
        FramePart::Lights { first, count } => {
            let Some(lights) = all.get(first..first + count) else {
                anyhow::bail!(
                    "lights {first}..{} of a frame of {}",
                    first + count,
                    all.len()
                );
            };
            // κ's windows continue from the lights before this batch, so the batches sum to
            // the whole frame's one call.
            let look = EnvLook {
                simplified_lights_before: all[..first].iter().filter(|l| l.is_simplified()).count()
                    as u32,
                ..look
            };
            EnvPart {
                lights: lights.to_vec(),
                look,
                mode,
            }
        }
    })
}

fn render_env_part(
    settings: &FrameSettings,
    env: &EnvLighting,
    hair: &HairModel,
    prepared: &PreparedEnv,
    part: FramePart,
    count_fragments: bool,
) -> anyhow::Result<RenderedFrame> {
    let all = frame_lights(prepared, env);
    let EnvPart { lights, look, mode } =
        env_part(env, all, prepared.scene.mode, part, count_fragments)?;
    let size = part.size(settings.size);
    let mut frame = env_frame(settings, env, hair, prepared, &lights, size, look)?;
    frame.mode = mode;
    let rendered = render_lights(&frame)?;
    Ok(RenderedFrame {
        image: rendered.image,
        milliseconds: rendered.milliseconds,
        passes: rendered.passes,
        memory: rendered.memory_per_batch,
        adapter: env_adapter()?,
        timing_method: TIMING_METHOD.into(),
        details: FrameDetails::Env {
            lights,
            mode,
            fragments: rendered.fragments,
        },
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::point_shading::Shading;
    use strandlight_runtime::hair::{Attribute, HairWriteOptions, write_hair};

    /// A `.hair` file of two half-transparent strands, under a fresh name in the temp folder.
    fn half_transparent_hair() -> std::path::PathBuf {
        let strand = |x: f32| [Vec3::new(x, 0.0, 0.0), Vec3::new(x, -1.0, 0.0)];
        let model = HairModel::new(
            [strand(0.0), strand(0.1)].concat(),
            vec![0, 2, 4],
            Some(Attribute::Uniform(0.01)),
            Some(Attribute::Uniform(0.5)),
            None,
        )
        .expect("a valid model");
        let path = std::env::temp_dir().join(format!(
            "strandlight-physical-fibers-{}.hair",
            std::process::id()
        ));
        write_hair(&model, &path, &HairWriteOptions::default()).expect("written");
        path
    }

    #[test]
    fn chiang_fibers_are_opaque_and_the_others_keep_the_files_transparency() {
        let path = half_transparent_hair();
        let mut settings = FrameSettings::new(
            Lighting::Environment(EnvLighting::new("procedural:studio")),
            [8, 8],
        );
        settings.hair = Some(path.clone());
        let transparency = |shading: Shading, settings: &mut FrameSettings| {
            settings.shading = Some(shading);
            let hair = load_settings_hair(settings).expect("loads");
            hair.model.transparency().cloned()
        };
        let chiang = transparency(Shading::Chiang, &mut settings);
        let marschner = transparency(Shading::Marschner, &mut settings);
        std::fs::remove_file(&path).ok();
        assert_eq!(chiang, None);
        assert_eq!(marschner, Some(Attribute::Uniform(0.5)));
    }
}
