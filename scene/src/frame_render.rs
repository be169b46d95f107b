//! One frame from [`FrameSettings`], in the two steps a viewer keeps apart: *prepare* (load the
//! hair; build the point-light fiber model, or fit and bake the environment's SRBF scene) and
//! *render* ([`render_frame`]: camera, lights and look → pixels). `strandlight render` and the
//! demo do both once; the viewer prepares again only when a setting that preparation depends on
//! changes, and draws its preview and light batches through [`submit_frame_into`] (the same
//! frame, its batches added into one running sum that stays on the GPU). Every env-lit frame,
//! whoever draws it, is built by [`env_frame`].

use crate::env_frame::{EnvFrame, FrameRole, render_lights, shared_gpu, submit_lights_into};
use crate::env_light_sets::frame_lights;
use crate::env_scene::PreparedEnv;
use crate::frame_settings::{
    CameraSettings, EnvLighting, ExactCamera, FrameSettings, Lighting, PointLighting, Shadows,
    Transparency,
};
use crate::hair_input::{OPAQUE_FIBERS, fibers_for, load_hair, procedural_style};
use crate::head_input::load_head;
use crate::image_metrics::Image;
use crate::look::EnvLook;
use crate::point_shading::{PointShadingRequest, point_shading_model};
pub use crate::rendered_frame::{FrameDetails, RenderedFrame, SubmittedFrame};
use crate::scene_tables::ScatteringMode;
use anyhow::Context;
use strandlight_runtime::camera::Camera;
use strandlight_runtime::env::{FrameSums, ViewTransparency};
use strandlight_runtime::env_light::EnvLight;
use strandlight_runtime::gpu::GpuContext;
use strandlight_runtime::hair::HairModel;
use strandlight_runtime::head::Head;
use strandlight_runtime::host::{PointLitDrawer, PointLitFrame};
use strandlight_runtime::passes::convolution_depth::DodmSettings;
use strandlight_runtime::passes::deep_opacity::{DomSettings, ShadowLookup};
use strandlight_runtime::passes::fiber_shading::ShadingModel;
use strandlight_runtime::passes::frame_params::{FrameParams, KajiyaKay};
use strandlight_runtime::point_frame::{
    self, PassTiming, RenderOptions, ShadowMaps, render_frame_with_head,
};
use strandlight_tables::checksum::sha256_hex;

/// The hair of a frame, a line naming where it came from, and what identifies it in the
/// reference and truth caches.
pub struct FrameHair {
    pub model: HairModel,
    pub source: String,
    /// SHA-256 of the file's bytes (of the procedural groom's points), marked where the fibers
    /// were made opaque.
    pub identity: String,
}

/// The hair of `settings` as its fiber model renders it. Chiang fibers are the path tracer's
/// opaque cylinders, so a file's transparency is dropped for them, as `compare` and `truth` drop
/// it: `render` must reproduce the frames they measure.
pub fn load_settings_hair(settings: &FrameSettings) -> anyhow::Result<FrameHair> {
    let (model, source) = load_hair(settings.hair.as_deref())?;
    let file = match &settings.hair {
        Some(path) if procedural_style(path)?.is_none() => Some(path),
        _ => None,
    };
    let content = match file {
        Some(path) => {
            sha256_hex(&std::fs::read(path).with_context(|| format!("--hair {}", path.display()))?)
        }
        None => sha256_hex(model.points_bytes()),
    };
    let (model, identity) = fibers_for(settings.shading(), model, content);
    let source = match model.transparency().is_none() && identity.ends_with(OPAQUE_FIBERS) {
        true => {
            format!("{source} (opaque fibers: its transparency is ignored by the Chiang model)")
        }
        false => source,
    };
    Ok(FrameHair {
        model,
        source,
        identity,
    })
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
) -> anyhow::Result<point_frame::PointImage> {
    let inputs = point_frame_inputs(settings, point, hair, size)?;
    Ok(render_frame_with_head(
        gpu,
        hair,
        &inputs.params,
        &inputs.options,
        &prepared.shading,
        inputs.head.as_ref(),
    )?)
}

/// What a point-lit frame of `settings` draws besides the hair and its shading: the camera,
/// size and lights, the shadow maps and transparency, the head.
pub struct PointFrameInputs {
    pub params: FrameParams,
    pub options: RenderOptions,
    pub head: Option<Head>,
}

/// The [`PointFrameInputs`] of `settings` for `hair` at `size`: what `render lights` draws, and
/// what a host hands the runtime's `HairRenderer::draw_point_lit` (see [`point_lit_frame`]).
pub fn point_frame_inputs(
    settings: &FrameSettings,
    point: &PointLighting,
    hair: &HairModel,
    size: [u32; 2],
) -> anyhow::Result<PointFrameInputs> {
    let camera = settings_camera(settings, hair)?;
    let params = FrameParams {
        camera,
        width: size[0],
        height: size[1],
        lights: point.parsed_lights()?,
        shading: KajiyaKay::default(),
        width_override_px: settings.fiber_width_px,
    };
    Ok(PointFrameInputs {
        params,
        options: point_render_options(point, hair),
        // The head (issue 40): opaque in every light's maps and in the view, drawn as skin.
        head: load_head(&settings.head, hair, settings.skin_albedo)?,
    })
}

/// The point-lit frame a host draws with the runtime's
/// [`HairRenderer::draw_point_lit`](strandlight_runtime::host::HairRenderer::draw_point_lit):
/// `inputs` and `prepared`'s shading for `hair`.
pub fn point_lit_frame<'a>(
    hair: &'a HairModel,
    prepared: &'a PreparedPoint,
    inputs: &'a PointFrameInputs,
) -> PointLitFrame<'a> {
    PointLitFrame {
        model: hair,
        params: &inputs.params,
        options: &inputs.options,
        shading: &prepared.shading,
        head: inputs.head.as_ref(),
    }
}

/// How an env-lit frame of `env` looks.
pub fn env_look(env: &EnvLighting) -> anyhow::Result<EnvLook> {
    Ok(EnvLook {
        shadowed: env.shadowed,
        dodm: DodmSettings::at_resolution(env.dodm_size),
        ..env.look_args().look()?
    })
}

/// The renderer's settings for a frame of `env`: the brute-force reference's, or the method's.
pub fn frame_role(env: &EnvLighting) -> FrameRole {
    match env.light_set.is_reference() {
        true => FrameRole::Reference,
        false => FrameRole::Interactive { kappa: env.kappa },
    }
}

/// The scattering a frame of `env` renders: single where it asks for single or where the
/// scene has no multiple-scattering table (dark hair).
pub fn frame_mode(env: &EnvLighting, prepared: &PreparedEnv) -> ScatteringMode {
    match (env.scattering, prepared.scene.mode) {
        (ScatteringMode::Full, ScatteringMode::Full) => ScatteringMode::Full,
        _ => ScatteringMode::Single,
    }
}

/// THE env-lit frame: `part` of the frame of `settings` for `hair`, lit as `prepared` (from the
/// same settings' [`prepare_env`], or a web page's bundle). Everything an env-lit frame is drawn
/// from is built here: `render`, `compare`, `bench`, the viewer and the page.
pub fn env_frame<'a>(
    settings: &FrameSettings,
    hair: &'a HairModel,
    prepared: &'a PreparedEnv,
    part: FramePart,
    count_fragments: bool,
) -> anyhow::Result<EnvFrame<'a>> {
    let Lighting::Environment(env) = &settings.lighting else {
        anyhow::bail!("an env-lit frame needs environment lighting");
    };
    let all = frame_lights(prepared, env)?;
    let mode = frame_mode(env, prepared);
    let EnvPart { lights, look, mode } = env_part(env, all, mode, part, count_fragments)?;
    let [width, height] = part.size(settings.size);
    Ok(EnvFrame {
        hair,
        camera: settings_camera(settings, hair)?,
        width,
        height,
        lights,
        tables: &prepared.scene.tables,
        shading: prepared.shading,
        mode,
        role: frame_role(env),
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
/// Nodes per direction axis of the tables a first look is drawn with while a cold cache bakes
/// the full ones: single scattering's two tables bake in 0.66 s (32 nodes: 2.5 s), and the
/// preview they draw is 0.022 from the one of the demo's 32-node tables (relative RMSE over the
/// hair; 8 nodes 0.049 in 0.53 s, 6 nodes 0.072 in 0.49 s:
/// docs/history/benchmarks-2026-12-05-to-12-06.md, "The first look").
pub const PREVIEW_TABLE_NODES: usize = 12;
/// Most SRBF lobes of the map's fit a first look is drawn with (the compact sources are fitted
/// as always). The preview draws only its [`PREVIEW_LIGHTS`] strongest lights: of the full
/// fit's 30–64 lobes those are the compact sources and a lobe or two, and the sky is missing
/// (0.22–0.47 of the whole frame's light). A fit of 6 lobes spreads the map over few lights,
/// and fits in 0.2–0.5 s where the full fit takes 0.9–4.5 s on a cold cache; its first look is
/// 0.25–0.36 from the whole frame over 16×16 blocks where the full fit's was 0.51–0.74 (four
/// maps, 800×600; docs/BENCHMARKS.md, "The viewer's first look").
pub const FIRST_LOOK_FIT_LOBES: usize = 6;

/// `settings` as a first look draws them on a cold cache ([`FramePart::Preview`]): an
/// environment fitted with at most [`FIRST_LOOK_FIT_LOBES`] lobes, single scattering from
/// tables of [`PREVIEW_TABLE_NODES`] nodes (fit and tables cached apart from the full ones).
/// Point lights have no tables to wait for: unchanged.
pub fn coarse_preview_settings(settings: &FrameSettings) -> FrameSettings {
    let mut coarse = settings.clone();
    if let Lighting::Environment(env) = &mut coarse.lighting {
        env.scattering = ScatteringMode::Single;
        env.table_resolution = Some(PREVIEW_TABLE_NODES);
        env.fit.max_lobes = env.fit.max_lobes.min(FIRST_LOOK_FIT_LOBES);
    }
    coarse
}

/// A first look draws every this many strands, each this many times as thick. The viewer's
/// first lit frame at 800×600 on lavapipe, tables cached: 0.96–1.03 s drawing every strand,
/// 0.72–0.76 s every fourth; that first look differs from the unthinned one by 0.18 over
/// 16×16 blocks (every second strand: 0.09), and the full frame replaces it (docs/BENCHMARKS.md,
/// "The viewer's first look").
pub const FIRST_LOOK_THINNING: usize = 4;
/// ... and keeps every this many points of each strand (and its last). The default groom's
/// first look, its lights' maps and visibility drawn from half the segments: the view
/// visibility pass 133–144 → 91 ms and the light pass 63–65 → 46–49 ms at 800×600 on lavapipe
/// (first lit 0.75–0.82 → 0.69–0.79 s, three runs alternating); against the whole frame it
/// reads as it did (0.356 over 16×16 blocks at both; every third point: 0.347).
pub const FIRST_LOOK_POINT_STEP: usize = 2;

/// The settings and groom a first look of `settings` is drawn with ([`FramePart::Preview`]): a
/// thinned groom ([`HairModel::thinned`], [`HairModel::with_fewer_points`]) seen by the full
/// groom's camera, so the picture does not move when the full frame replaces it. A head fitted
/// to the roots (`--head ellipsoid`) is fitted to the kept strands' roots, an even sample of
/// them.
pub fn first_look(
    settings: &FrameSettings,
    hair: &HairModel,
) -> anyhow::Result<(FrameSettings, HairModel)> {
    let camera = ExactCamera::of(&settings_camera(settings, hair)?);
    let settings = FrameSettings {
        camera: CameraSettings::Exact(camera),
        ..settings.clone()
    };
    let hair = hair.thinned(FIRST_LOOK_THINNING);
    Ok((settings, hair.with_fewer_points(FIRST_LOOK_POINT_STEP)))
}

/// Which part of a settings' frame to render.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FramePart {
    /// The whole frame at the settings' size.
    Whole,
    /// A cheap first look at half size: for an environment the [`PREVIEW_LIGHTS`] most
    /// powerful lights, light maps of at most [`PREVIEW_MAP_RESOLUTION`]², the opaque view of
    /// one-pixel quads (no exact coverage) and single scattering.
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
        (Lighting::Environment(_), Prepared::Env(prepared)) => {
            render_env_part(settings, hair, prepared, part, count_fragments)
        }
        _ => anyhow::bail!("the frame's lighting was prepared for other settings"),
    }
}

/// [`render_frame`] for a front end that shows the frame where it is (the viewer): `part` of
/// the frame of `settings`, added into `sums` (an env-lit part) or drawn into them (a point-lit
/// frame, whole; `sums` fresh), on [`shared_gpu`], with nothing read back. `sums` has
/// [`FramePart::size`] of the part.
pub fn submit_frame_into(
    settings: &FrameSettings,
    hair: &HairModel,
    prepared: Prepared,
    part: FramePart,
    sums: &FrameSums,
) -> anyhow::Result<SubmittedFrame> {
    match (&settings.lighting, prepared) {
        (Lighting::Lights(point), Prepared::Point(prepared)) => {
            if let FramePart::Lights { .. } = part {
                anyhow::bail!("a point-lit frame is rendered whole, not by light batches");
            }
            let gpu = shared_gpu()?;
            static DRAWER: std::sync::OnceLock<PointLitDrawer> = std::sync::OnceLock::new();
            let drawer = DRAWER.get_or_init(|| PointLitDrawer::new(gpu));
            let inputs = point_frame_inputs(settings, point, hair, sums.size())?;
            let stats = drawer.draw_into(gpu, &point_lit_frame(hair, prepared, &inputs), sums)?;
            Ok(SubmittedFrame {
                milliseconds: point_frame_milliseconds(&stats.timings),
                passes: stats.timings,
                memory: stats.memory_bytes,
                adapter: stats.adapter.to_string(),
                timing_method: stats.timing_method.to_string(),
                lights: point.lights.len(),
                with_multiple: false,
            })
        }
        (Lighting::Environment(_), Prepared::Env(prepared)) => {
            submit_lights_into(&env_frame(settings, hair, prepared, part, false)?, sums)
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
            look.exact_coverage = false;
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
    hair: &HairModel,
    prepared: &PreparedEnv,
    part: FramePart,
    count_fragments: bool,
) -> anyhow::Result<RenderedFrame> {
    render_lights(&env_frame(settings, hair, prepared, part, count_fragments)?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::point_shading::Shading;
    use glam::Vec3;
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
