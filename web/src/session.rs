//! What the page shows and how far it is: the bundle's scene, the settings the controls edit,
//! and the progressive plan of the current frame, one step per call to [`Session::step`]. It
//! holds no browser types, so it runs natively too (its test sums the steps on lavapipe and
//! compares them with `render_frame`).

use anyhow::Context;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use strandlight_runtime::camera::UpAxis;
use strandlight_runtime::env::{EnvRenderError, EnvRenderer, FrameSums, ViewTransparency};
use strandlight_runtime::env_light::EnvLight;
use strandlight_runtime::gpu::GpuContext;
use strandlight_runtime::gpu::LimitError;
use strandlight_runtime::hair::HairModel;
use strandlight_runtime::hair::yuksel::parse_hair;
use strandlight_runtime::multiple::{
    CpuForwardScattering, ForwardScatteringSource, GpuForwardScattering, MarchedForwardScattering,
};
use strandlight_scene::env_frame::{EnvFrame, gpu_march_volume, lights_call_without_source};
use strandlight_scene::env_light_sets::{frame_lights, light_luminance};
use strandlight_scene::env_scene::PreparedEnv;
use strandlight_scene::exposure::Exposure;
use strandlight_scene::frame_render::{env_frame, env_look, first_look, settings_camera};
use strandlight_scene::frame_settings::{
    CameraSettings, EnvLighting, ExactCamera, FrameSettings, Lighting, up_choice,
};
use strandlight_scene::orbit::Orbit;
use strandlight_scene::progressive::{Step, plan_steps};
use strandlight_scene::scene_tables::ScatteringMode;
use strandlight_scene::web_bundle::{BundleScene, HAIR_FILE, SCENE_FILE, SETTINGS_FILE};
use strandlight_tables::image_out::tonemap_channel;

/// The bundle's files, fetched: `settings.json`, `scene.json`, `hair.hair` and the tables by
/// their file names.
pub type BundleFiles = HashMap<String, Vec<u8>>;

/// How far the current frame is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Stage {
    /// Nothing drawn yet.
    Starting,
    Preview,
    Refining {
        done: usize,
        total: usize,
    },
    Converged,
}

/// A copy of the shown sums to read back (exposure metering, the converged frame).
pub struct Readback {
    pub buffer: wgpu::Buffer,
    pub key: (u64, usize),
    /// Pixels per image (the sums hold one, or two with multiple scattering).
    pub pixels: usize,
    size: [u32; 2],
    with_multiple: bool,
    /// The share of the lights' power the copied sums hold.
    power: f32,
}

/// The picture the canvas shows.
struct ShownSums {
    buffer: wgpu::Buffer,
    size: [u32; 2],
    with_multiple: bool,
    /// Share of the lights' power summed (1 for a preview, which is a frame of its own).
    power: f32,
}

pub struct Session {
    gpu: GpuContext,
    renderer: EnvRenderer,
    bundle: BundleScene,
    files: BundleFiles,
    /// The bundle's fit and the current preset's tables, as every front end prepares them.
    prepared: PreparedEnv,
    pub settings: FrameSettings,
    hair: HairModel,
    orbit: Orbit,
    pub exposure: Exposure,
    /// Linear RGB behind the hair (before exposure).
    background: [f32; 3],
    /// The frame: bumped by every change that restarts it.
    generation: u64,
    plan: Vec<Step>,
    next: usize,
    lights: Vec<EnvLight>,
    /// The running sum of the frame's light batches (the preview is a frame of its own).
    sums: Option<FrameSums>,
    shown: Option<ShownSums>,
    /// (generation, steps) of the picture last metered.
    metered: Option<(u64, usize)>,
    /// The exposure changed: meter the shown picture again.
    remeter: bool,
    stops: f32,
    /// The converged frame (single + multiple, linear, pre-multiplied RGBA).
    pub converged: Option<Vec<[f32; 4]>>,
    /// The latest picture read back (linear, scaled to the whole frame's power) and its size.
    read: Option<(Vec<[f32; 4]>, [u32; 2])>,
    /// Bumped whenever [`Self::picture`] would return another picture.
    pub picture_version: u64,
    /// The scene before a dropped hair, until the new hair's first step succeeds.
    fallback: Option<Fallback>,
    /// What the page changed to fit the device (smaller light maps), for the panel.
    pub notice: Option<String>,
    /// Why the last dropped hair was given up for the scene before it.
    pub rejected: Option<String>,
    last_memory: Vec<(String, u64)>,
    /// The hair voxelized for multiple scattering (per hair and tables).
    volume: Option<CpuForwardScattering>,
    march: March,
    /// Only the first look's tables are here (the rest are still being fetched): the frame
    /// stops after its preview until [`Self::add_tables`].
    first_look_only: bool,
    /// The first look's fit and coarse tables of the preset, kept once every table is here:
    /// every preview is drawn from them, as the viewer's are (the full fit's strongest lights
    /// leave the sky out). None where the bundle's files lack them.
    first_look: Option<PreparedEnv>,
}

/// Light maps are not made smaller than this to fit a device's limits.
pub const SMALLEST_LIGHT_MAP: u32 = 64;

struct Fallback {
    name: String,
    hair: HairModel,
    settings: FrameSettings,
    orbit: Orbit,
}

impl Session {
    /// The session of a bundle.
    pub fn new(gpu: GpuContext, files: BundleFiles) -> anyhow::Result<Self> {
        let file = |name: &str| {
            files
                .get(name)
                .with_context(|| format!("the bundle has no {name}"))
        };
        let bundle = BundleScene::parse(file(SCENE_FILE)?)?;
        let settings: FrameSettings =
            serde_json::from_slice(file(SETTINGS_FILE)?).context(SETTINGS_FILE)?;
        settings.check().context(SETTINGS_FILE)?;
        // The pipelines first, the first look's among them: the browser's GPU process compiles
        // them while this thread decodes the groom and the tables.
        let renderer = EnvRenderer::new(&gpu);
        renderer.compile(ViewTransparency::Opaque, !settings.head.is_none(), true);
        let hair = parse_hair(file(HAIR_FILE)?, Path::new(HAIR_FILE))?.model;
        let up = up_choice(&settings).axis(&hair);
        // Every table, or the first look's while the page fetches the rest.
        let first_look_only = !Self::has_every_table(&bundle, &settings.preset, &files);
        let prepared = match first_look_only {
            false => bundle.prepared(&settings.preset, up, |f| files.get(f).cloned())?,
            true => bundle.prepared_first_look(&settings.preset, up, |f| files.get(f).cloned())?,
        };
        // While only the first look's tables are here, they are `prepared`.
        let first_look = match first_look_only {
            true => None,
            false => Self::first_look_of(&bundle, &settings.preset, up, &files)?,
        };
        let orbit = orbit_of(&settings, &hair)?;
        let mut session = Self {
            gpu,
            renderer,
            bundle,
            files,
            prepared,
            settings,
            hair,
            orbit,
            exposure: Exposure::Auto,
            background: [0.0; 3],
            generation: 0,
            plan: Vec::new(),
            next: 0,
            lights: Vec::new(),
            sums: None,
            shown: None,
            metered: None,
            remeter: false,
            stops: 0.0,
            converged: None,
            read: None,
            picture_version: 0,
            fallback: None,
            notice: None,
            rejected: None,
            volume: None,
            march: March::Idle,
            last_memory: Vec::new(),
            first_look_only,
            first_look,
        };
        session.restart()?;
        Ok(session)
    }

    /// GPU memory per resource of the last step encoded (bytes): what a test prints when a
    /// limit it expected was not reached.
    pub fn last_memory(&self) -> &[(String, u64)] {
        &self.last_memory
    }

    pub fn gpu(&self) -> &GpuContext {
        &self.gpu
    }

    pub fn bundle(&self) -> &BundleScene {
        &self.bundle
    }

    fn env(&self) -> anyhow::Result<&EnvLighting> {
        match &self.settings.lighting {
            Lighting::Environment(env) => Ok(env),
            Lighting::Lights(_) => anyhow::bail!("the page renders env-lit frames only"),
        }
    }

    fn env_mut(&mut self) -> &mut EnvLighting {
        match &mut self.settings.lighting {
            Lighting::Environment(env) => env,
            Lighting::Lights(_) => unreachable!("checked when the session was made"),
        }
    }

    /// The first look's fit and tables of `preset`, where `files` hold them (a corrupt one is
    /// an error).
    fn first_look_of(
        bundle: &BundleScene,
        preset: &str,
        up: UpAxis,
        files: &BundleFiles,
    ) -> anyhow::Result<Option<PreparedEnv>> {
        let held = (bundle.first_look.presets.get(preset))
            .is_some_and(|tables| tables.iter().all(|t| files.contains_key(&t.file)));
        held.then(|| bundle.prepared_first_look(preset, up, |f| files.get(f).cloned()))
            .transpose()
    }

    /// Whether `files` hold every table of `preset`.
    fn has_every_table(bundle: &BundleScene, preset: &str, files: &BundleFiles) -> bool {
        (bundle.presets.get(preset))
            .is_some_and(|tables| tables.iter().all(|t| files.contains_key(&t.file)))
    }

    /// The rest of the bundle's tables, fetched after the first look's: the frame goes on
    /// from its preview (drawn or not) to its batches.
    pub fn add_tables(&mut self, files: BundleFiles) -> anyhow::Result<()> {
        self.files.extend(files);
        if !self.first_look_only {
            return Ok(());
        }
        let (files, up) = (&self.files, self.prepared.up);
        let every_table =
            (self.bundle).prepared(&self.settings.preset, up, |f| files.get(f).cloned())?;
        self.first_look = Some(std::mem::replace(&mut self.prepared, every_table));
        self.first_look_only = false;
        self.plan = self.planned()?;
        Ok(())
    }

    /// The steps of the current settings' frame: a preview, then its batches (the preview
    /// alone while only the first look's tables are here).
    fn planned(&mut self) -> anyhow::Result<Vec<Step>> {
        let env = self.env()?.clone();
        // A dropped hair may stand on another axis than the bundle's.
        let up = up_choice(&self.settings).axis(&self.hair);
        self.prepared.up = up;
        if let Some(first_look) = &mut self.first_look {
            first_look.up = up;
        }
        self.lights = frame_lights(&self.prepared, &env)?;
        if self.first_look_only {
            return Ok(vec![Step::Preview]);
        }
        let powers: Vec<f32> = self.lights.iter().map(light_luminance).collect();
        let batch = env_look(&env)?.dodm.batch_size as usize;
        Ok(plan_steps(Some((&powers, batch))))
    }

    /// Plans the frame of the current settings from its first step; the old picture stays on
    /// the canvas until the new preview replaces it.
    fn restart(&mut self) -> anyhow::Result<()> {
        self.plan = self.planned()?;
        self.next = 0;
        self.generation += 1;
        self.sums = None;
        self.converged = None;
        Ok(())
    }

    /// How far the frame is on the GPU: the latest step whose picture was read back (so a
    /// preview counts once it has been drawn, not when it was sent).
    pub fn stage(&self) -> Stage {
        let batches = self.plan.len().saturating_sub(1);
        let done = match self.metered {
            Some((generation, steps)) if generation == self.generation => steps,
            _ => 0,
        };
        match done {
            _ if self.converged.is_some() => Stage::Converged,
            0 => Stage::Starting,
            1 => Stage::Preview,
            n => Stage::Refining {
                done: n - 1,
                total: batches,
            },
        }
    }

    /// Whether steps remain to encode.
    pub fn refining(&self) -> bool {
        self.next < self.plan.len()
    }

    /// Encodes the next step of the plan (one frame's work: a preview or one light batch). A
    /// dropped hair whose first step fails (the GPU's limits, say) gives way to the scene
    /// before it, and [`Self::rejected`] says why.
    pub fn step(&mut self) -> anyhow::Result<()> {
        match (self.encode_fitting(), self.fallback.take()) {
            (Ok(()), _) => Ok(()),
            (Err(e), None) => Err(e),
            (Err(e), Some(before)) => {
                self.hair = before.hair;
                self.settings = before.settings;
                self.orbit = before.orbit;
                self.forget_march();
                self.restart()?;
                let why = e.context(format!("{}: kept the scene before it", before.name));
                self.rejected = Some(format!("{why:#}"));
                Ok(())
            }
        }
    }

    /// [`Self::encode_step`], halving the light maps while they (their DODM layers or
    /// summed-area tables) exceed the device's limits
    /// (WebGPU's defaults: 128 MiB a storage binding, 256 MiB a buffer), down to
    /// [`SMALLEST_LIGHT_MAP`]; the frame restarts at the smaller size and [`Self::notice`] says so.
    fn encode_fitting(&mut self) -> anyhow::Result<()> {
        loop {
            let error = match self.encode_step() {
                Ok(()) => return Ok(()),
                Err(e) => e,
            };
            let light_maps = match error.downcast_ref::<EnvRenderError>() {
                Some(EnvRenderError::Limit(
                    LimitError::BufferSize { what, .. }
                    | LimitError::StorageBinding { what, .. }
                    | LimitError::Texture2d { what, .. }
                    | LimitError::TextureLayers { what, .. },
                )) => what.starts_with("DODM"),
                _ => false,
            };
            let size = self.env()?.dodm_size;
            if !light_maps || size <= SMALLEST_LIGHT_MAP {
                return Err(error);
            }
            let smaller = (size / 2).max(SMALLEST_LIGHT_MAP);
            self.notice = Some(format!(
                "light maps {size}² → {smaller}² to fit this device's limits ({error:#})"
            ));
            self.env_mut().dodm_size = smaller;
            self.restart()?;
        }
    }

    fn encode_step(&mut self) -> anyhow::Result<()> {
        let Some(&step) = self.plan.get(self.next) else {
            return Ok(());
        };
        // A preview is the viewer's first look: a thinned groom seen by the whole groom's camera.
        let first_look = match step {
            Step::Preview => Some(first_look(&self.settings, &self.hair)?),
            _ => None,
        };
        let (settings, hair) = match &first_look {
            Some((settings, hair)) => (settings, hair),
            None => (&self.settings, &self.hair),
        };
        let prepared = match (step, &self.first_look) {
            (Step::Preview, Some(first_look)) => first_look,
            _ => &self.prepared,
        };
        let frame = env_frame(settings, hair, prepared, step.part(), false)?;
        let [width, height] = [frame.width, frame.height];
        // Multiple scattering's grid is marched for all the frame's lights before the first
        // batch that needs it; until the page has read it back, the step waits.
        let marched = match frame.mode {
            ScatteringMode::Single => None,
            ScatteringMode::Full => {
                let march = (&self.gpu, &mut self.march, &mut self.volume);
                match advance_march(march, &self.lights, &frame)? {
                    Some(marched) => Some(marched),
                    None => return Ok(()),
                }
            }
        };
        let call = lights_call_without_source(&frame)?;
        let source = marched
            .as_deref()
            .map(|m| m as &dyn ForwardScatteringSource);
        let light_part = (frame.lights.as_slice(), frame.look.simplified_lights_before);
        let shown = match step {
            Step::Batch { power_after, .. } => {
                let sums = match &mut self.sums {
                    Some(sums) => sums,
                    None => self.sums.insert(FrameSums::new(&self.gpu, width, height)?),
                };
                let stats = self.renderer.encode_part_into(
                    &self.gpu,
                    frame.hair,
                    &frame.camera,
                    light_part,
                    &call.tables,
                    &call.options,
                    source,
                    frame.head.as_ref(),
                    sums,
                )?;
                self.last_memory = stats.memory_per_batch;
                ShownSums {
                    buffer: sums.buffer().clone(),
                    size: [width, height],
                    with_multiple: source.is_some(),
                    power: power_after,
                }
            }
            Step::Preview | Step::Full => {
                let encoded = self.renderer.encode_part(
                    &self.gpu,
                    frame.hair,
                    &frame.camera,
                    width,
                    height,
                    light_part,
                    &call.tables,
                    &call.options,
                    source,
                    frame.head.as_ref(),
                )?;
                self.last_memory = encoded.stats.memory_per_batch;
                ShownSums {
                    buffer: encoded.sums,
                    size: [width, height],
                    with_multiple: encoded.with_multiple,
                    power: 1.0,
                }
            }
        };
        self.shown = Some(shown);
        self.next += 1;
        Ok(())
    }

    /// The picture of the latest frame read back: its radiance exposed, over the background,
    /// through the PNG's tonemap (`tonemap_channel`, so the page shows what `render` writes),
    /// as 8-bit RGBA rows from the top, and its size (half the frame's for a preview).
    pub fn picture(&self) -> Option<(Vec<u8>, [u32; 2])> {
        let (image, size) = self.read.as_ref()?;
        let exposure = self.stops.exp2();
        let bytes = image
            .iter()
            .flat_map(|p| {
                let behind = 1.0 - p[3].clamp(0.0, 1.0);
                let [r, g, b] = [0, 1, 2]
                    .map(|k| tonemap_channel(exposure * (p[k] + self.background[k] * behind)));
                [r, g, b, 255]
            })
            .collect();
        Some((bytes, *size))
    }

    /// A copy of the shown sums to map, when the shown picture has not been metered yet.
    pub fn readback(&self) -> Option<Readback> {
        let shown = self.shown.as_ref()?;
        let key = (self.generation, self.next);
        if self.metered == Some(key) && !self.remeter {
            return None;
        }
        let buffer = mappable_copy(&self.gpu, &shown.buffer);
        Some(Readback {
            buffer,
            key,
            pixels: (shown.size[0] * shown.size[1]) as usize,
            size: shown.size,
            with_multiple: shown.with_multiple,
            power: shown.power,
        })
    }

    /// The sums read back for `key`: meters the exposure on them and, after the last step,
    /// keeps them as the converged frame. Stale readbacks (of a restarted frame) are dropped.
    pub fn readback_done(&mut self, readback: &Readback, sums: &[[f32; 4]]) {
        let key = readback.key;
        let older = self.metered.is_some_and(|m| m.0 == key.0 && m.1 > key.1);
        if key.0 != self.generation || older {
            return;
        }
        let pixels = readback.pixels;
        let scale = 1.0 / readback.power.max(f32::MIN_POSITIVE);
        let image: Vec<[f32; 4]> = (0..pixels)
            .map(|i| {
                let s = sums[i];
                let m = match readback.with_multiple {
                    true => sums[i + pixels],
                    false => [0.0; 4],
                };
                [
                    (s[0] + m[0]) * scale,
                    (s[1] + m[1]) * scale,
                    (s[2] + m[2]) * scale,
                    s[3],
                ]
            })
            .collect();
        self.stops = self.exposure.stops_for(&image);
        self.metered = Some(key);
        self.remeter = false;
        if key.1 == self.plan.len() && !self.first_look_only {
            self.converged = Some(image.clone());
        }
        self.read = Some((image, readback.size));
        self.picture_version += 1;
    }

    /// The march's copies to map, once every dispatch is submitted (None otherwise, or when
    /// the grid is read already).
    pub fn march_readback(&self) -> Option<(u64, Vec<wgpu::Buffer>)> {
        match &self.march {
            March::Marching {
                id,
                staged,
                dispatches,
                ..
            } if staged.len() == *dispatches => Some((*id, staged.clone())),
            _ => None,
        }
    }

    /// The values of march `id` read back, one list per copy of [`Self::march_readback`]: the
    /// grid the batches read. The values of an earlier march are dropped.
    pub fn march_done(&mut self, id: u64, marched: Vec<Vec<[f32; 4]>>) -> anyhow::Result<()> {
        let March::Marching {
            id: current,
            lights,
            ..
        } = &self.march
        else {
            return Ok(());
        };
        if *current != id {
            return Ok(());
        }
        let lights = lights.clone();
        let Some(volume) = &self.volume else {
            return Ok(());
        };
        let on_gpu = GpuForwardScattering::new(&self.gpu, volume.clone())?;
        let grid = on_gpu.grid_from_values(&lights, marched);
        self.march = March::Done(Arc::new(MarchedForwardScattering { lights, grid }));
        Ok(())
    }

    /// Single or single + multiple scattering (the latter where the bundle has its tables).
    pub fn set_scattering(&mut self, mode: ScatteringMode) -> anyhow::Result<()> {
        anyhow::ensure!(
            mode == ScatteringMode::Single || self.bundle.mode == ScatteringMode::Full,
            "this site has no multiple-scattering tables (`strandlight web` bakes them for \
             settings with full scattering and hair light enough to need them)"
        );
        self.env_mut().scattering = mode;
        self.restart()
    }

    /// The exposure applied now, in stops.
    pub fn stops(&self) -> f32 {
        self.stops
    }

    /// Sets the exposure and meters it again on the shown picture.
    pub fn set_exposure(&mut self, exposure: Exposure) {
        self.exposure = exposure;
        self.remeter = true;
    }

    /// Linear RGB behind the hair.
    pub fn set_background(&mut self, rgb: [f32; 3]) {
        self.background = rgb;
        self.picture_version += 1;
    }

    pub fn set_rotation(&mut self, degrees: f32) -> anyhow::Result<()> {
        self.env_mut().rotation_deg = degrees;
        self.restart()
    }

    /// The number of SRBF lobes drawn (0: all).
    pub fn set_lobes(&mut self, lobes: usize) -> anyhow::Result<()> {
        self.env_mut().lobes = (lobes > 0).then_some(lobes);
        self.restart()
    }

    pub fn set_kappa(&mut self, kappa: f32) -> anyhow::Result<()> {
        anyhow::ensure!(
            kappa.is_finite() && kappa > 0.0 && kappa <= 1.0,
            "κ = {kappa} must be in (0, 1]"
        );
        self.env_mut().kappa = kappa;
        self.restart()
    }

    /// Switches to another fiber preset baked into the bundle.
    pub fn set_preset(&mut self, preset: &str) -> anyhow::Result<()> {
        let files = &self.files;
        let up = self.prepared.up;
        // Both or neither: a bad table leaves the page on its preset.
        let prepared = (self.bundle).prepared(preset, up, |f| files.get(f).cloned())?;
        self.first_look = Self::first_look_of(&self.bundle, preset, up, files)?;
        self.prepared = prepared;
        self.settings.preset = preset.into();
        self.restart()
    }

    /// Orbit (drag), pan (drag with a modifier) and zoom (wheel steps).
    pub fn rotate(&mut self, dx: f32, dy: f32) -> anyhow::Result<()> {
        self.orbit.rotate(dx, dy);
        self.camera_moved()
    }

    pub fn pan(&mut self, dx: f32, dy: f32) -> anyhow::Result<()> {
        let height = self.settings.size[1] as f32;
        self.orbit.pan(dx, dy, height);
        self.camera_moved()
    }

    pub fn zoom(&mut self, steps: f32) -> anyhow::Result<()> {
        self.orbit.zoom(steps);
        self.camera_moved()
    }

    fn camera_moved(&mut self) -> anyhow::Result<()> {
        self.settings.camera = CameraSettings::Exact(ExactCamera::of(&self.orbit.camera()));
        self.restart()
    }

    /// A `.hair` file dropped on the page. A file that does not load, or whose frame cannot be
    /// set up, leaves the current scene as it was and says why.
    pub fn load_hair(&mut self, name: &str, bytes: &[u8]) -> anyhow::Result<()> {
        anyhow::ensure!(
            name.to_ascii_lowercase().ends_with(".hair"),
            "{name}: the page reads .hair files (cyHairFile); other formats need the desktop tool"
        );
        let model = parse_hair(bytes, Path::new(name))?.model;
        let mut settings = self.settings.clone();
        settings.hair = Some(PathBuf::from(name));
        settings.camera = CameraSettings::Framed(Default::default());
        let orbit = orbit_of(&settings, &model)?;
        let hair = std::mem::replace(&mut self.hair, model);
        let settings = std::mem::replace(&mut self.settings, settings);
        let orbit = std::mem::replace(&mut self.orbit, orbit);
        self.fallback = Some(Fallback {
            name: name.into(),
            hair,
            settings,
            orbit,
        });
        self.forget_march();
        self.restart()
    }

    /// Another hair or other tables: another volume, another grid.
    fn forget_march(&mut self) {
        self.volume = None;
        self.march = March::Idle;
    }

    /// The settings, as `render replay` reads them.
    pub fn settings_json(&self) -> String {
        serde_json::to_string_pretty(&self.settings).expect("settings serialize")
    }
}

/// Multiple scattering's grid for a frame's lights, marched on the GPU one dispatch a step and
/// read back by the page before the batches that need it.
enum March {
    Idle,
    /// The mappable copies of the dispatches submitted so far.
    Marching {
        /// Tells a readback of this march from one of an earlier march.
        id: u64,
        lights: Vec<EnvLight>,
        staged: Vec<wgpu::Buffer>,
        dispatches: usize,
    },
    Done(Arc<MarchedForwardScattering>),
}

/// The marched grid of `lights` when it is ready; else the next dispatch submitted (or nothing
/// while the page reads the last ones back) and `None`. The hair's voxel volume is built on
/// first use and kept until the hair or the tables change.
fn advance_march(
    (gpu, march, volume): (&GpuContext, &mut March, &mut Option<CpuForwardScattering>),
    lights: &[EnvLight],
    frame: &EnvFrame,
) -> anyhow::Result<Option<Arc<MarchedForwardScattering>>> {
    let mut id = 0;
    match march {
        March::Done(done) if done.lights == lights => return Ok(Some(done.clone())),
        March::Marching {
            lights: marching, ..
        } if marching == lights => {}
        March::Marching { id: earlier, .. } => {
            id = *earlier + 1;
            *march = March::Idle;
        }
        March::Done(_) => *march = March::Idle,
        March::Idle => {}
    }
    let Some(volume) = volume else {
        // Voxelizing the groom is this tick's work; the first dispatch waits for the next.
        *volume = Some(gpu_march_volume(frame)?);
        return Ok(None);
    };
    let on_gpu = GpuForwardScattering::new(gpu, volume.clone())?;
    if matches!(march, March::Idle) {
        // One light a dispatch and a tick: each light's per-voxel medium is looked up on the
        // CPU, and sixteen of them in one tick held the page's thread for most of a second.
        *march = March::Marching {
            id,
            lights: lights.to_vec(),
            staged: Vec::new(),
            dispatches: lights.len(),
        };
    }
    let March::Marching {
        lights: marching,
        staged,
        dispatches,
        ..
    } = march
    else {
        unreachable!("idle became marching above")
    };
    if staged.len() < *dispatches {
        let light = staged.len();
        for values in on_gpu.encode_march(&marching[light..=light]) {
            staged.push(mappable_copy(gpu, &values));
        }
    }
    Ok(None)
}

/// A copy of `source` the CPU can map.
fn mappable_copy(gpu: &GpuContext, source: &wgpu::Buffer) -> wgpu::Buffer {
    let copy = gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("page readback"),
        size: source.size(),
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    encoder.copy_buffer_to_buffer(source, 0, &copy, 0, source.size());
    gpu.queue.submit([encoder.finish()]);
    copy
}

/// The orbit through the settings' camera.
fn orbit_of(settings: &FrameSettings, hair: &HairModel) -> anyhow::Result<Orbit> {
    let camera = settings_camera(settings, hair)?;
    let front = up_choice(settings).axis(hair).toward_front();
    Ok(Orbit::from_camera(
        &camera,
        front,
        0.5 * hair.bounds().diagonal(),
    ))
}
