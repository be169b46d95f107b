//! The render thread: the window hands it the latest settings and never waits for it. For each
//! request it draws a cheap preview (half size, the brightest lobes, small light maps, single
//! scattering), then refines the full frame one batch of lights at a time, publishing the running
//! sum after each batch. A newer request abandons the old one between batches. Table bakes run
//! on a thread of their own, and the previous tables keep lighting frames until they finish; with
//! no tables at all (a cold cache), coarse ones bake first, in seconds, for a lit preview.

use crate::progressive::{Accumulator, Step, plan_steps};
use anyhow::Context;
use glam::Vec3;
use std::path::PathBuf;
use std::sync::mpsc::{Receiver, Sender, TryRecvError, channel};
use std::sync::{Arc, Condvar, Mutex, MutexGuard};
use std::time::{Duration, Instant};
use strandlight_runtime::camera::Camera;
use strandlight_runtime::env::FrameSums;
use strandlight_runtime::hair::HairModel;
use strandlight_scene::env_frame::{frame_sums, prepare_env_renderer, shared_gpu};
use strandlight_scene::env_light_sets::{frame_lights, light_luminance};
use strandlight_scene::env_scene::{AlsoServe, PrepareProgress, PreparedEnv, prepare_env};
use strandlight_scene::frame_render::{
    FrameHair, Prepared, PreparedPoint, SubmittedFrame, coarse_preview_settings, env_look,
    first_look, load_settings_hair, prepare_point, settings_camera, submit_frame_into,
};
use strandlight_scene::frame_settings::{FrameSettings, Lighting, PointLighting, up_choice};
use strandlight_scene::steps::Steps;

use crate::frame::{FrameStats, GpuImage, Stage};
use crate::recompute::{TablesKey, tables_key};

/// The worker's latest image of a request.
#[derive(Clone)]
pub struct Shown {
    pub job: u64,
    pub settings: FrameSettings,
    /// On the renderer's device, where a window sharing it draws it; read back too for a
    /// window with a device of its own.
    pub image: Arc<GpuImage>,
    pub stage: Stage,
    pub stats: FrameStats,
    /// Rendered with the previous tables while this request's tables bake.
    pub stale_tables: bool,
    /// Those tables are the first look's coarse ones (a cold start).
    pub coarse_tables: bool,
    /// A preview drawn from the first look's fit and coarse tables, the full ones baked or not.
    pub first_look_tables: bool,
    /// Seconds from the request to this image.
    pub seconds: f64,
    /// The camera it was rendered with, the hair's front and bounding radius (for the orbit).
    pub camera: Camera,
    pub front: Vec3,
    pub radius: f32,
    /// The environment lighting it (for the background).
    pub env: Option<Arc<PreparedEnv>>,
}

/// A bake in progress.
#[derive(Clone, Debug)]
pub struct BakeStatus {
    pub what: String,
    /// 0..=1.
    pub fraction: f32,
    pub started: Instant,
}

/// Everything the window reads from the worker.
#[derive(Clone, Default)]
pub struct Status {
    pub shown: Option<Shown>,
    pub bake: Option<BakeStatus>,
    /// The last request that failed, and why (bad file, bad value, GPU error).
    pub error: Option<(u64, String)>,
    /// Seconds from each request to its preview and to its converged image (latest request).
    pub preview_seconds: Option<f64>,
    pub converged_seconds: Option<f64>,
}

struct Shared {
    request: Mutex<Option<(u64, FrameSettings)>>,
    wake_worker: Condvar,
    status: Mutex<Status>,
    quit: Mutex<bool>,
    wake_window: Box<dyn Fn() + Send + Sync>,
}

pub struct Worker {
    shared: Arc<Shared>,
    thread: Option<std::thread::JoinHandle<()>>,
}

impl Worker {
    /// Starts the thread; `wake_window` is called whenever the status changes. Its renderer
    /// is prepared for a first look with a head or not (the first request's).
    pub fn spawn(
        cache_dir: PathBuf,
        first_with_head: bool,
        read_back: bool,
        wake_window: Box<dyn Fn() + Send + Sync>,
    ) -> Self {
        let shared = Arc::new(Shared {
            request: Mutex::new(None),
            wake_worker: Condvar::new(),
            status: Mutex::new(Status::default()),
            quit: Mutex::new(false),
            wake_window,
        });
        // The device and pipelines are made while the window opens and the tables load; an
        // error here is the first frame's to report.
        std::thread::spawn(move || prepare_env_renderer(first_with_head).ok());
        let for_thread = shared.clone();
        let thread = std::thread::Builder::new()
            .name("strandlight render".into())
            .spawn(move || WorkerState::new(cache_dir, read_back, for_thread).run())
            .expect("spawn the render thread");
        Self {
            shared,
            thread: Some(thread),
        }
    }

    /// Replaces whatever request is waiting (the latest settings win).
    pub fn submit(&self, job: u64, settings: FrameSettings) {
        *self.shared.request.lock().unwrap() = Some((job, settings));
        self.shared.wake_worker.notify_all();
    }

    pub fn status(&self) -> MutexGuard<'_, Status> {
        self.shared.status.lock().unwrap()
    }
}

impl Drop for Worker {
    fn drop(&mut self) {
        *self.shared.quit.lock().unwrap() = true;
        self.shared.wake_worker.notify_all();
        // A render in flight finishes its batch; a bake thread is left to the process exit.
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

/// A request being refined.
struct Job {
    id: u64,
    settings: FrameSettings,
    started: Instant,
    steps: Vec<Step>,
    next: usize,
    accumulator: Accumulator,
    /// The running sum of the batches drawn so far, on the renderers' device.
    sums: Option<FrameSums>,
    stale_tables: bool,
}

type BakeResult = Result<PreparedEnv, String>;

/// The longest the full bake waits for the first look to be drawn.
const FIRST_LOOK_WAIT: Duration = Duration::from_secs(10);

/// What the bake thread sends: for a first look its coarse tables, then the full ones.
struct Baked {
    coarse: bool,
    result: BakeResult,
}

/// What a loaded hair depends on: its file, and whether its fibers are physical (opaque).
type HairKey = (Option<PathBuf>, bool);

struct WorkerState {
    cache_dir: PathBuf,
    /// Read each image back for a window on a device of its own.
    read_back: bool,
    shared: Arc<Shared>,
    hair: Option<(HairKey, Arc<FrameHair>)>,
    point: Option<(String, Arc<PreparedPoint>)>,
    env: Option<(TablesKey, Arc<PreparedEnv>)>,
    /// `env` holds only the first look's coarse tables: previews, no batches.
    env_is_coarse: bool,
    /// The first look's fit and coarse tables of the latest bake, kept once the full tables
    /// arrive: every preview while their single scattering matches is drawn from them. The full
    /// fit's strongest lights are its compact sources and a lobe or two, and drew 0.22–0.47 of
    /// the frame's light, the sky missing (docs/BENCHMARKS.md, "The viewer's first look").
    first_look_env: Option<(TablesKey, Arc<PreparedEnv>)>,
    /// Tells the bake thread the first look is drawn, so that its full bake starts then: on a
    /// software adapter the bake's threads and the GPU share the same cores.
    first_look_drawn: Option<Sender<()>>,
    /// The bake under way starts with a first look's coarse tables, not yet arrived: env-lit
    /// requests wait for them rather than draw with `env`, another settings' tables.
    awaiting_first_look: bool,
    baking: Option<(TablesKey, Receiver<Baked>)>,
    job: Option<Job>,
}

impl WorkerState {
    fn new(cache_dir: PathBuf, read_back: bool, shared: Arc<Shared>) -> Self {
        Self {
            cache_dir,
            read_back,
            shared,
            hair: None,
            point: None,
            env: None,
            env_is_coarse: false,
            first_look_env: None,
            first_look_drawn: None,
            awaiting_first_look: false,
            baking: None,
            job: None,
        }
    }

    fn run(mut self) {
        loop {
            if *self.shared.quit.lock().unwrap() {
                return;
            }
            if let Some((id, settings)) = self.take_request() {
                self.start(id, settings);
            }
            self.poll_bake();
            if self.job.as_ref().is_some_and(|j| j.next < j.steps.len()) {
                self.step();
            } else {
                self.wait_for_work();
            }
        }
    }

    fn take_request(&self) -> Option<(u64, FrameSettings)> {
        self.shared.request.lock().unwrap().take()
    }

    /// Sleeps until a request arrives, or a bake may have finished.
    fn wait_for_work(&self) {
        let guard = self.shared.request.lock().unwrap();
        if guard.is_none() {
            let _ = self
                .shared
                .wake_worker
                .wait_timeout(guard, Duration::from_millis(50));
        }
    }

    fn publish(&self, change: impl FnOnce(&mut Status)) {
        change(&mut self.shared.status.lock().unwrap());
        (self.shared.wake_window)();
    }

    fn fail(&mut self, id: u64, error: anyhow::Error) {
        self.job = None;
        self.publish(|s| s.error = Some((id, format!("{error:#}"))));
    }

    fn start(&mut self, id: u64, settings: FrameSettings) {
        // A request planned again when its tables arrive keeps its start and its first look:
        // the preview it showed is not drawn again (at 800×600 on lavapipe that was 0.6 s
        // before the first batch).
        let restarted = self.job.as_ref().filter(|j| j.id == id);
        let started = restarted.map_or_else(Instant::now, |j| j.started);
        let previewed = restarted.is_some_and(|j| j.accumulator.has_shown());
        if restarted.is_none() {
            self.publish(|s| {
                s.preview_seconds = None;
                s.converged_seconds = None;
            });
        }
        match self.plan(&settings) {
            Ok(Some((mut steps, stale_tables))) => {
                if previewed && steps.len() > 1 {
                    steps.retain(|s| *s != Step::Preview);
                }
                let mut accumulator = Accumulator::default();
                accumulator.expect_batches(
                    steps
                        .iter()
                        .filter(|s| matches!(s, Step::Batch { .. }))
                        .count(),
                );
                self.job = Some(Job {
                    id,
                    settings,
                    started,
                    steps,
                    next: 0,
                    accumulator,
                    sums: None,
                    stale_tables,
                });
            }
            // Waits for its tables: planned again when the bake ends.
            Ok(None) => {
                self.job = Some(Job {
                    id,
                    settings,
                    started,
                    steps: Vec::new(),
                    next: 0,
                    accumulator: Accumulator::default(),
                    sums: None,
                    stale_tables: true,
                })
            }
            Err(e) => self.fail(id, e),
        }
    }

    /// The steps of `settings`, and whether they use the previous tables; None while there are
    /// no tables to use yet.
    fn plan(&mut self, settings: &FrameSettings) -> anyhow::Result<Option<(Vec<Step>, bool)>> {
        settings.check()?;
        let hair = self.hair(settings)?;
        match &settings.lighting {
            Lighting::Lights(point) => {
                self.prepared_point(settings, point)?;
                Ok(Some((plan_steps(None), false)))
            }
            Lighting::Environment(env) => {
                let key = tables_key(settings);
                let current =
                    !self.env_is_coarse && self.env.as_ref().is_some_and(|(k, _)| *k == key);
                if !current && self.baking.as_ref().is_none_or(|(k, _)| *k != key) {
                    self.start_bake(settings.clone(), hair, key);
                }
                let Some((_, prepared)) = self.env.as_ref().filter(|_| !self.awaiting_first_look)
                else {
                    return Ok(None);
                };
                if self.env_is_coarse {
                    return Ok(Some((vec![Step::Preview], true)));
                }
                let powers: Vec<f32> = frame_lights(prepared, env)?
                    .iter()
                    .map(light_luminance)
                    .collect();
                let batch = env_look(env)?.dodm.batch_size as usize;
                Ok(Some((plan_steps(Some((&powers, batch))), !current)))
            }
        }
    }

    fn hair(&mut self, settings: &FrameSettings) -> anyhow::Result<Arc<FrameHair>> {
        // Whether the fibers are physical decides whether the file's transparency is kept.
        let key = (settings.hair.clone(), settings.shading().physical_fibers());
        if let Some((k, hair)) = &self.hair
            && *k == key
        {
            return Ok(hair.clone());
        }
        let hair = Arc::new(load_settings_hair(settings)?);
        self.hair = Some((key, hair.clone()));
        Ok(hair)
    }

    fn prepared_point(
        &mut self,
        settings: &FrameSettings,
        point: &PointLighting,
    ) -> anyhow::Result<Arc<PreparedPoint>> {
        // The artist controls are shader constants here: cheap to rebuild, not a table.
        let key = format!("{:?} {:?}", tables_key(settings), settings.artist);
        if let Some((k, p)) = &self.point
            && *k == key
        {
            return Ok(p.clone());
        }
        let prepared = Arc::new(prepare_point(settings, point)?);
        self.point = Some((key, prepared.clone()));
        Ok(prepared)
    }

    fn start_bake(&mut self, settings: FrameSettings, hair: Arc<FrameHair>, key: TablesKey) {
        // Coarse tables first, for a preview in seconds, whenever the frame would otherwise
        // wait with nothing to draw (a cold start; with the full tables cached too, loading
        // them took as long: 1.88 s to the first lit frame against 1.68 s through the coarse
        // ones, 800×600 on lavapipe) or be drawn with another map's, fiber's or colours'
        // tables (a rebake). A change of scattering alone keeps the tables it has: the first
        // look's are single scattering either way.
        let first_look = self
            .env
            .as_ref()
            .is_none_or(|(current, _)| !current.same_single_scattering(&key));
        let (send, receive) = channel();
        let (drawn, wait_for_first_look) = channel();
        self.first_look_drawn = first_look.then_some(drawn);
        self.awaiting_first_look = first_look;
        let shared = self.shared.clone();
        let cache_dir = self.cache_dir.clone();
        let map = match &settings.lighting {
            Lighting::Environment(env) => env.map.clone(),
            Lighting::Lights(_) => String::new(),
        };
        let what = format!("{map} ({:?})", settings.shading());
        self.publish(|s| {
            s.bake = Some(BakeStatus {
                what: format!("fitting {what}"),
                fraction: 0.0,
                started: Instant::now(),
            })
        });
        std::thread::spawn(move || {
            let mut steps = Steps::new(true);
            let mut progress = |p: PrepareProgress| {
                let (text, fraction) = match p {
                    PrepareProgress::Fitting => (format!("fitting {what}"), 0.0),
                    PrepareProgress::Baking { done, total, table } => (
                        format!("baked {table} ({done}/{total}) for {what}"),
                        done as f32 / total.max(1) as f32,
                    ),
                };
                if let Some(bake) = &mut shared.status.lock().unwrap().bake {
                    bake.what = text;
                    bake.fraction = fraction;
                }
                (shared.wake_window)();
            };
            let mut bake = |settings: &FrameSettings, coarse: bool| {
                let result = prepare_env(
                    settings,
                    &hair.model,
                    &cache_dir,
                    AlsoServe::default(),
                    &mut steps,
                    &mut progress,
                )
                .map_err(|e| format!("{e:#}"));
                let baked = result.is_ok();
                // None: the request was left behind (nothing listens any more).
                send.send(Baked { coarse, result }).is_ok().then_some(baked)
            };
            if first_look {
                match bake(&coarse_preview_settings(&settings), true) {
                    None => return,
                    // A first look that never comes (a new request) holds nothing up long.
                    Some(true) => {
                        let _ = wait_for_first_look.recv_timeout(FIRST_LOOK_WAIT);
                    }
                    Some(false) => {}
                }
            }
            bake(&settings, false);
        });
        self.baking = Some((key, receive));
    }

    /// Installs finished tables and plans the waiting request again with them.
    fn poll_bake(&mut self) {
        let Some((key, receive)) = &self.baking else {
            return;
        };
        let (coarse, result) = match receive.try_recv() {
            Err(TryRecvError::Empty) => return,
            Ok(Baked { coarse, result }) => (coarse, result),
            Err(TryRecvError::Disconnected) => (false, Err("the bake thread stopped".into())),
        };
        let key = key.clone();
        // Env-lit requests wait for tables; a point-lit one carries on untouched.
        let env_job = self
            .job
            .as_ref()
            .filter(|j| matches!(j.settings.lighting, Lighting::Environment(_)))
            .map(|j| (j.id, j.settings.clone()));
        if coarse {
            // The full bake goes on; a failed coarse one leaves the request waiting for it, or
            // drawn with the tables it had.
            self.awaiting_first_look = false;
            if let Ok(prepared) = result {
                let prepared = Arc::new(prepared);
                self.first_look_env = Some((key.clone(), prepared.clone()));
                self.env = Some((key, prepared));
                self.env_is_coarse = true;
            }
            if let Some((id, settings)) = env_job {
                self.start(id, settings);
            }
            return;
        }
        self.baking = None;
        self.awaiting_first_look = false;
        self.publish(|s| s.bake = None);
        match result {
            Ok(prepared) => {
                self.env = Some((key, Arc::new(prepared)));
                self.env_is_coarse = false;
                if let Some((id, settings)) = env_job {
                    self.start(id, settings);
                }
            }
            Err(e) => {
                if let Some((id, _)) = env_job {
                    self.fail(id, anyhow::anyhow!("preparing the environment: {e}"));
                }
            }
        }
    }

    fn step(&mut self) {
        let job = self.job.as_mut().expect("a job to step");
        let step = job.steps[job.next];
        job.next += 1;
        let id = job.id;
        match self.render_step(step) {
            Ok(()) => {}
            Err(e) => self.fail(id, e),
        }
    }

    fn render_step(&mut self, step: Step) -> anyhow::Result<()> {
        let job = self.job.as_ref().expect("a job");
        let settings = job.settings.clone();
        let hair = self.hair(&settings)?;
        let point;
        let env_used = match &settings.lighting {
            Lighting::Lights(_) => None,
            Lighting::Environment(_) => {
                let (_, prepared) = self.env.as_ref().context("no tables yet")?;
                Some(prepared.clone())
            }
        };
        // A preview is drawn from the first look's tables where they light these settings.
        let first_look_env = match step {
            Step::Preview => env_used
                .as_ref()
                .and(self.first_look_env.as_ref())
                .filter(|(key, _)| key.same_single_scattering(&tables_key(&settings))),
            _ => None,
        };
        let first_look_tables = first_look_env.is_some();
        let drawn_env = first_look_env
            .map(|(_, env)| env.clone())
            .or(env_used.clone());
        let prepared = match (&settings.lighting, &drawn_env) {
            (Lighting::Environment(_), Some(env)) => Prepared::Env(env),
            (Lighting::Lights(lights), _) => {
                point = self.prepared_point(&settings, lights)?;
                Prepared::Point(&point)
            }
            (Lighting::Environment(_), None) => unreachable!("set just above"),
        };
        // Each step leaves its image on the GPU, where a window on the same device draws it.
        // Nothing is read back here but for a window with a device of its own (below).
        let (submitted, image) = match (step, prepared) {
            // Batches add up on the GPU, in the renderer's own batch-sum pass; the window gets
            // a copy of the sum so far.
            (Step::Batch { .. }, Prepared::Env(_)) => {
                let job = self.job.as_mut().expect("a job");
                let sums = match &mut job.sums {
                    Some(sums) => sums,
                    None => {
                        let [width, height] = step.part().size(settings.size);
                        job.sums.insert(frame_sums(width, height)?)
                    }
                };
                let submitted =
                    submit_frame_into(&settings, &hair.model, prepared, step.part(), sums)?;
                let image = GpuImage::copy_of(shared_gpu()?, sums, submitted.with_multiple);
                (submitted, image)
            }
            // The first look draws a fraction of the strands, each as much thicker.
            (Step::Preview, Prepared::Env(_)) => {
                let (look_settings, look_hair) = first_look(&settings, &hair.model)?;
                submit_whole(&look_settings, &look_hair, prepared, step)?
            }
            _ => submit_whole(&settings, &hair.model, prepared, step)?,
        };
        let image = match self.read_back {
            true => image.with_read_back(shared_gpu()?)?,
            false => image,
        };
        let stats = FrameStats {
            lights: submitted.lights,
            passes: submitted.passes,
            memory: submitted.memory,
            batches: 1,
            adapter: submitted.adapter,
            timing_method: submitted.timing_method,
        };
        let camera = settings_camera(&settings, &hair.model)?;
        let front = up_choice(&settings).axis(&hair.model).toward_front();
        let radius = 0.5 * hair.model.bounds().diagonal();
        let coarse_tables = env_used.is_some() && self.env_is_coarse;
        let job = self.job.as_mut().expect("a job");
        let shown_stage = job.accumulator.add(step, image, stats);
        let (image, stats) = job.accumulator.shown();
        let seconds = job.started.elapsed().as_secs_f64();
        let shown = Shown {
            job: job.id,
            settings: job.settings.clone(),
            image,
            stage: shown_stage,
            stats,
            stale_tables: job.stale_tables,
            coarse_tables,
            first_look_tables,
            seconds,
            camera,
            front,
            radius,
            env: env_used,
        };
        let converged = shown_stage == Stage::Converged && !job.stale_tables;
        if coarse_tables && let Some(drawn) = self.first_look_drawn.take() {
            let _ = drawn.send(());
        }
        self.publish(|s| {
            if shown.stage == Stage::Preview {
                s.preview_seconds = Some(seconds);
            }
            if converged {
                s.converged_seconds = Some(seconds);
            }
            s.error = None;
            s.shown = Some(shown);
        });
        Ok(())
    }
}

/// `step` of the frame of `settings` drawn whole into sums of its own, which become the image.
fn submit_whole(
    settings: &FrameSettings,
    hair: &HairModel,
    prepared: Prepared,
    step: Step,
) -> anyhow::Result<(SubmittedFrame, GpuImage)> {
    let [width, height] = step.part().size(settings.size);
    let sums = frame_sums(width, height)?;
    let submitted = submit_frame_into(settings, hair, prepared, step.part(), &sums)?;
    let image = GpuImage::of_finished(sums, submitted.with_multiple);
    Ok((submitted, image))
}
