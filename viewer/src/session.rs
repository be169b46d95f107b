//! One viewing session: the state the panel edits, the orbit, the worker it feeds, the image on
//! screen and the screenshots asked for. It draws one egui frame at a time and never waits for
//! the renderer.

use crate::display::{backdrop_pixels, composite, soft_backdrop_map};
use crate::frame::Stage;
use crate::gpu_display::DisplayRequest;
use crate::orbit::Orbit;
use crate::panel::{Panel, PanelOutcome};
use crate::recompute::{Backdrop, Display, Recompute, ViewState, recompute};
use crate::screenshot::{ScreenshotFiles, save};
use crate::script::{Action, WaitFor, merge_patch};
use crate::worker::{Shown, Status, Worker};
use std::path::PathBuf;
use std::sync::Arc;
use std::time::{Duration, Instant};
use strandlight_precompute::envmap::EnvMap;
use strandlight_runtime::gpu::data_readbacks_on_this_thread;
use strandlight_runtime::hair;
use strandlight_scene::camera_choice::CameraChoice;
use strandlight_scene::env_frame::shared_gpu;
use strandlight_scene::exposure::metered_stops;
use strandlight_scene::frame_settings::{CameraSettings, ExactCamera, FrameSettings, Lighting};
use strandlight_scene::head_input::HeadChoice;

/// Changes that need a rebake wait this long after the last edit (a slider being dragged).
const REBAKE_SETTLE: Duration = Duration::from_millis(400);

/// The readout panel's width in points: its monospace pass table fits without wrapping.
pub const READOUT_WIDTH: f32 = 260.0;

/// What a session has measured, for `--report`.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct SessionReport {
    pub frames_presented: u64,
    pub frames_presented_during_bakes: u64,
    pub longest_frame_gap_ms: f64,
    pub longest_frame_gap_during_bakes_ms: f64,
    pub bakes_seen: u64,
    /// Per request that converged: seconds to its preview and to the converged image.
    pub requests: Vec<RequestTiming>,
    /// Seconds from the command's start to the first presented frame with a rendered image,
    /// and whether that image came from the first look's coarse tables (a cold cache).
    pub first_lit_seconds: Option<f64>,
    pub first_lit_coarse_tables: Option<bool>,
    /// Pictures drawn with the first look's coarse tables, and pictures drawn with the tables
    /// of settings before a rebake (another map, fiber or colours; none since a rebake starts
    /// with a first look of its own).
    pub coarse_pictures: u64,
    pub pictures_from_previous_tables: u64,
    /// Env-lit previews shown, and those of them drawn from the first look's fit and tables.
    pub env_previews: u64,
    pub env_previews_from_first_look_tables: u64,
    pub screenshots: Vec<PathBuf>,
    /// Captures of the whole window (panel included), one per screenshot.
    pub window_captures: Vec<PathBuf>,
    /// Where the image sat in each window capture, physical pixels: [x0, y0, x1, y1] (the
    /// panel's width follows its controls, so the image moves between captures).
    pub window_capture_image_rects_px: Vec<[f32; 4]>,
    /// Where the image sat in the window when last drawn, physical pixels: [x0, y0, x1, y1].
    pub image_rect_px: [f32; 4],
    /// Where the timing readout sat when last drawn (None: hidden), beside the image, never on it.
    pub readout_rect_px: Option<[f32; 4]>,
    pub adapter: String,
    pub window_adapter: String,
    /// GPU→CPU copies of data (frames, depth, counters; not the pass timer's timestamps) made
    /// in the process from the command's start to the session's end, and those of them the
    /// screenshots made. The rest are the frame path's: none where the window shares the
    /// renderer's device and draws each frame where it is, one per new image where the window
    /// has a device of its own (`WindowDevice`).
    pub data_readbacks: u64,
    pub screenshot_readbacks: u64,
    /// The device the window presented on.
    pub window_device: Option<crate::WindowDevice>,
    pub errors: Vec<String>,
}

#[derive(Clone, Debug, serde::Serialize)]
pub struct RequestTiming {
    pub job: u64,
    pub lighting: String,
    pub size: [u32; 2],
    pub preview_seconds: Option<f64>,
    pub converged_seconds: f64,
}

/// A capture of the whole window that the next painted frame writes.
pub struct WindowCapture {
    pub path: PathBuf,
    /// Set by the paint that wrote it (or failed to).
    pub result: Option<anyhow::Result<()>>,
}

/// The shown image, what it was made from, and the texture the display pass drew it into.
struct OnScreen {
    /// None until the window's display pass has drawn the picture.
    texture: Option<egui::TextureId>,
    job: u64,
    stage: Stage,
    /// Lit by the first look's coarse tables.
    coarse_tables: bool,
    display: Display,
    request: DisplayRequest,
    /// The request the window's display pass has yet to draw.
    undrawn: bool,
}

pub struct Session {
    /// When the command started (`ViewOptions::started`).
    started: Instant,
    pub state: ViewState,
    submitted: Option<(u64, FrameSettings)>,
    edited_at: Instant,
    next_job: u64,
    orbit: Option<Orbit>,
    worker: Worker,
    on_screen: Option<OnScreen>,
    last_good: FrameSettings,
    message: Option<String>,
    panel: Panel,
    screenshots: Vec<PathBuf>,
    window_captures: Vec<WindowCapture>,
    pub report: SessionReport,
    last_present: Option<Instant>,
    bake_was_running: bool,
    timed_jobs: Vec<u64>,
    handled_error: Option<u64>,
    image_rect: egui::Rect,
    background: Option<(BackgroundKey, Arc<Vec<[f32; 3]>>)>,
    /// The soft backdrop's blurred map, by the map's pixel hash: made once per map.
    soft_map: Option<(String, Arc<EnvMap>)>,
}

/// What the background behind the hair depends on.
#[derive(PartialEq)]
struct BackgroundKey {
    backdrop: Backdrop,
    camera: ExactCamera,
    size: [u32; 2],
    rotation_deg: f32,
    /// The map's pixel hash.
    map: String,
}

impl Session {
    /// The job of the first request, which `run` sends before the window opens, so that the
    /// worker loads the scene and draws its first look while the window and its device are made.
    pub const FIRST_JOB: u64 = 1;

    /// The session of a window whose worker was sent `settings` as [`Self::FIRST_JOB`].
    pub fn new(
        settings: FrameSettings,
        worker: Worker,
        window_adapter: String,
        started: Instant,
    ) -> Self {
        let last_good = settings.clone();
        Self {
            started,
            last_good: last_good.clone(),
            state: ViewState {
                settings,
                display: Display::default(),
            },
            submitted: Some((Self::FIRST_JOB, last_good.clone())),
            edited_at: Instant::now(),
            next_job: Self::FIRST_JOB + 1,
            orbit: None,
            worker,
            on_screen: None,
            message: None,
            panel: Panel::default(),
            screenshots: Vec::new(),
            window_captures: Vec::new(),
            report: SessionReport {
                window_adapter,
                ..Default::default()
            },
            last_present: None,
            bake_was_running: false,
            timed_jobs: Vec::new(),
            handled_error: None,
            image_rect: egui::Rect::from_min_size(egui::Pos2::ZERO, egui::vec2(640.0, 480.0)),
            background: None,
            soft_map: None,
        }
    }

    /// Something is still changing on screen (the window keeps presenting).
    pub fn busy(&self) -> bool {
        let status = self.worker.status();
        let refining = status
            .shown
            .as_ref()
            .is_none_or(|s| s.stage != Stage::Converged || s.stale_tables);
        status.bake.is_some() || refining || self.screenshots_pending() || self.unsubmitted()
    }

    /// The worker's picture is a further batch of the request on screen and nothing failed:
    /// news the window shows at its progress pace rather than at once.
    pub fn only_refined(&self) -> bool {
        let status = self.worker.status();
        status.error.is_none()
            && status.shown.as_ref().is_some_and(|shown| {
                matches!(shown.stage, Stage::Refining { .. })
                    && self.on_screen.as_ref().is_some_and(|o| o.job == shown.job)
            })
    }

    fn unsubmitted(&self) -> bool {
        self.submitted
            .as_ref()
            .is_none_or(|(_, s)| *s != self.state.settings)
    }

    /// The latest settings are on screen in full, with their own tables.
    pub fn converged(&self) -> bool {
        let status = self.worker.status();
        let latest = self.submitted.as_ref().map(|(id, _)| *id);
        status.bake.is_none()
            && !self.unsubmitted()
            && status.shown.as_ref().is_some_and(|s| {
                Some(s.job) == latest && s.stage == Stage::Converged && !s.stale_tables
            })
    }

    pub fn wait_done(&self, cond: WaitFor) -> bool {
        match cond {
            WaitFor::Converged => self.converged(),
            WaitFor::Tables => self.worker.status().bake.is_none(),
        }
    }

    /// Counts a presented frame.
    pub fn presented(&mut self) {
        let now = Instant::now();
        if self.report.first_lit_seconds.is_none()
            && let Some(on_screen) = self.on_screen.as_ref().filter(|o| o.texture.is_some())
        {
            self.report.first_lit_seconds = Some(now.duration_since(self.started).as_secs_f64());
            self.report.first_lit_coarse_tables = Some(on_screen.coarse_tables);
        }
        let baking = self.worker.status().bake.is_some();
        if let Some(last) = self.last_present {
            let gap = now.duration_since(last).as_secs_f64() * 1e3;
            self.report.longest_frame_gap_ms = self.report.longest_frame_gap_ms.max(gap);
            if baking && self.bake_was_running {
                self.report.longest_frame_gap_during_bakes_ms =
                    self.report.longest_frame_gap_during_bakes_ms.max(gap);
            }
        }
        if baking {
            self.report.frames_presented_during_bakes += 1;
            if !self.bake_was_running {
                self.report.bakes_seen += 1;
            }
        }
        self.bake_was_running = baking;
        self.report.frames_presented += 1;
        self.last_present = Some(now);
    }

    /// Applies a script's actions that are not input events.
    pub fn apply(&mut self, action: &Action) -> anyhow::Result<()> {
        match action {
            Action::Settings(patch) => {
                let mut value = serde_json::to_value(&self.state.settings)?;
                merge_patch(&mut value, patch);
                let settings: FrameSettings = serde_json::from_value(value)
                    .map_err(|e| anyhow::anyhow!("script settings patch {patch}: {e}"))?;
                self.edit(|s| s.settings = settings);
            }
            Action::Exposure(stops) => self.state.display.exposure_stops = *stops,
            Action::Screenshot(path) => self.screenshots.push(path.clone()),
            _ => {}
        }
        Ok(())
    }

    fn edit(&mut self, change: impl FnOnce(&mut ViewState)) {
        change(&mut self.state);
        self.edited_at = Instant::now();
    }

    /// One egui frame: panel, image, overlay; then requests, screenshots and errors.
    pub fn frame(&mut self, ui: &mut egui::Ui) {
        let ctx = &ui.ctx().clone();
        let status = self.worker.status().clone();
        self.take_error(&status);
        self.time_requests(&status);
        self.keys(ctx);
        let before = self.state.clone();
        let outcome = self.panel.show(ui, &mut self.state, &status, &self.message);
        if self.state != before {
            self.edited_at = Instant::now();
        }
        self.apply_panel(outcome);
        self.readout_panel(ui, &status);
        self.image_area(ui, &status);
        self.submit_when_due(ctx);
        self.save_screenshots(&status);
    }

    fn keys(&mut self, ctx: &egui::Context) {
        if ctx.egui_wants_keyboard_input() {
            return;
        }
        let (b, o, s, r) = ctx.input(|i| {
            (
                i.key_pressed(egui::Key::B),
                i.key_pressed(egui::Key::O),
                i.key_pressed(egui::Key::S),
                i.key_pressed(egui::Key::R),
            )
        });
        if b {
            self.state.display.backdrop = self.state.display.backdrop.next();
        }
        if o {
            self.state.display.overlay = !self.state.display.overlay;
        }
        if s {
            self.screenshots.push(default_screenshot_stem());
        }
        if r {
            self.reset_camera();
        }
        let dropped: Vec<PathBuf> = ctx.input(|i| {
            i.raw
                .dropped_files
                .iter()
                .map(|f| f.path().to_path_buf())
                .collect()
        });
        for path in dropped {
            self.open(path);
        }
    }

    fn reset_camera(&mut self) {
        self.orbit = None;
        self.edit(|s| s.settings.camera = CameraSettings::Framed(CameraChoice::default()));
    }

    /// A dropped or picked file by its extension: hair, an environment map or a head mesh.
    fn open(&mut self, path: PathBuf) {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .unwrap_or("")
            .to_ascii_lowercase();
        match ext.as_str() {
            e if hair::EXTENSIONS.contains(&e) => {
                self.orbit = None;
                self.edit(|s| {
                    s.settings.hair = Some(path);
                    s.settings.camera = CameraSettings::Framed(CameraChoice::default());
                });
            }
            "hdr" | "exr" => {
                let map = path.display().to_string();
                self.edit(|s| s.settings.light_with_environment(map));
            }
            // A USD file stays a groom: hair is what a dropped scene file usually brings.
            "obj" | "glb" | "gltf" => self.edit(|s| s.settings.head = HeadChoice::mesh(path)),
            _ => {
                self.message = Some(format!(
                    "{}: not a hair file (.hair, .tfx, .data, .ply, .usda, .usdc, .usdz, .usd, .abc), an environment map (.hdr, .exr) or a head mesh (.obj, .glb, .gltf)",
                    path.display()
                ))
            }
        }
    }

    fn apply_panel(&mut self, outcome: PanelOutcome) {
        if let Some(path) = outcome.open {
            self.open(path);
        }
        if outcome.screenshot {
            self.screenshots.push(default_screenshot_stem());
        }
        if outcome.reset_camera {
            self.reset_camera();
        }
    }

    /// A failed request: its message in the panel, and the last settings that rendered back.
    fn take_error(&mut self, status: &Status) {
        let latest = self.submitted.as_ref().map(|(id, _)| *id);
        if let Some((job, error)) = &status.error
            && Some(*job) == latest
            && self.handled_error != Some(*job)
        {
            self.handled_error = Some(*job);
            self.message = Some(error.clone());
            self.report.errors.push(error.clone());
            // Back to what rendered last; it differs from the failed request, so it is sent.
            self.state.settings = self.last_good.clone();
        }
        if let Some(shown) = &status.shown
            && Some(shown.job) == latest
            && !shown.stale_tables
        {
            self.last_good = shown.settings.clone();
        }
    }

    fn time_requests(&mut self, status: &Status) {
        let (Some(shown), Some(converged)) = (&status.shown, status.converged_seconds) else {
            return;
        };
        if shown.stage != Stage::Converged || self.timed_jobs.contains(&shown.job) {
            return;
        }
        self.timed_jobs.push(shown.job);
        self.report.adapter = shown.stats.adapter.clone();
        self.report.requests.push(RequestTiming {
            job: shown.job,
            lighting: match &shown.settings.lighting {
                Lighting::Lights(p) => format!("lights {:?}", p.lights),
                Lighting::Environment(e) => format!("environment {}", e.map),
            },
            size: shown.settings.size,
            preview_seconds: status.preview_seconds,
            converged_seconds: converged,
        });
    }

    /// Sends the settings to the worker: at once for a new frame, after the edits settle for a
    /// rebake (a slider drag would otherwise start a bake per step).
    fn submit_when_due(&mut self, ctx: &egui::Context) {
        if !self.unsubmitted() {
            return;
        }
        let cost = match &self.submitted {
            None => Recompute::Hair,
            Some((_, old)) => recompute(
                &ViewState {
                    settings: old.clone(),
                    display: self.state.display,
                },
                &self.state,
            ),
        };
        let dragging = ctx.input(|i| i.pointer.any_down());
        if self.submitted.is_some()
            && cost >= Recompute::Tables
            && (dragging || self.edited_at.elapsed() < REBAKE_SETTLE)
        {
            ctx.request_repaint_after(REBAKE_SETTLE);
            return;
        }
        let job = self.next_job;
        self.next_job += 1;
        self.worker.submit(job, self.state.settings.clone());
        self.submitted = Some((job, self.state.settings.clone()));
    }

    /// The picture the window's display pass should draw before this frame's UI, when it
    /// changed: a new image from the worker, or new display settings.
    pub fn picture_to_draw(&mut self) -> Option<DisplayRequest> {
        let shown = self.worker.status().shown.clone()?;
        let unchanged = self.on_screen.as_ref().is_some_and(|o| {
            o.job == shown.job
                && o.stage == shown.stage
                && Arc::ptr_eq(&o.request.image, &shown.image)
                && o.display == self.state.display
        });
        if !unchanged {
            self.report.coarse_pictures += shown.coarse_tables as u64;
            self.report.pictures_from_previous_tables +=
                (shown.stale_tables && !shown.coarse_tables) as u64;
            if shown.stage == Stage::Preview && shown.env.is_some() {
                self.report.env_previews += 1;
                self.report.env_previews_from_first_look_tables += shown.first_look_tables as u64;
            }
            let backdrop = self.background_of(&shown, shown.image.size);
            let request = DisplayRequest {
                image: shown.image.clone(),
                exposure_stops: self.state.display.exposure_stops,
                backdrop,
            };
            self.on_screen = Some(OnScreen {
                texture: self.on_screen.as_ref().and_then(|o| o.texture),
                job: shown.job,
                stage: shown.stage,
                coarse_tables: shown.coarse_tables,
                display: self.state.display,
                request,
                undrawn: true,
            });
        }
        let on_screen = self.on_screen.as_mut()?;
        on_screen.undrawn.then(|| on_screen.request.clone())
    }

    /// The display pass drew the picture into `texture`.
    pub fn picture_drawn(&mut self, texture: egui::TextureId) {
        if let Some(o) = &mut self.on_screen {
            o.texture = Some(texture);
            o.undrawn = false;
        }
    }

    /// The map behind the hair, computed once per view (the refinement steps of one request
    /// share it).
    fn background_of(&mut self, shown: &Shown, size: [u32; 2]) -> Option<Arc<Vec<[f32; 3]>>> {
        if self.state.display.backdrop == Backdrop::Black {
            return None;
        }
        let (prepared, Lighting::Environment(lighting)) =
            (shown.env.as_ref()?, &shown.settings.lighting)
        else {
            return None;
        };
        let env = prepared.env.as_ref()?;
        let key = BackgroundKey {
            backdrop: self.state.display.backdrop,
            camera: ExactCamera::of(&shown.camera),
            size,
            rotation_deg: lighting.rotation_deg,
            map: env.sha256.clone(),
        };
        if let Some((cached, pixels)) = &self.background
            && *cached == key
        {
            return Some(pixels.clone());
        }
        let blurred = match &self.soft_map {
            Some((sha, map)) if *sha == key.map => map.clone(),
            _ => {
                let map = Arc::new(soft_backdrop_map(&env.map));
                self.soft_map = Some((key.map.clone(), map.clone()));
                map
            }
        };
        let pixels = Arc::new(backdrop_pixels(
            key.backdrop,
            &env.map,
            &blurred,
            &shown.camera,
            key.size,
            prepared.up,
            key.rotation_deg,
        )?);
        self.background = Some((key, pixels.clone()));
        Some(pixels)
    }

    /// The readout right of the image, where it cannot cover the hair.
    fn readout_panel(&mut self, ui: &mut egui::Ui, status: &Status) {
        if !self.state.display.overlay {
            self.report.readout_rect_px = None;
            return;
        }
        let exposure = self.state.display.exposure_stops;
        // Exact: a panel of wrapping text shrinks to egui's 96-point minimum otherwise.
        let response = egui::Panel::right("readout")
            .exact_size(READOUT_WIDTH)
            .show(ui, |ui| crate::panel::readout(ui, status, exposure));
        let rect = response.response.rect;
        let ppp = ui.ctx().pixels_per_point();
        self.report.readout_rect_px =
            Some([rect.min.x, rect.min.y, rect.max.x, rect.max.y].map(|v| v * ppp));
    }

    /// The image, scaled to fit, taking orbit drags, pans and zoom.
    fn image_area(&mut self, ui: &mut egui::Ui, status: &Status) {
        egui::CentralPanel::default()
            .frame(egui::Frame::NONE.fill(egui::Color32::from_gray(20)))
            .show(ui, |ui| {
                let available = ui.available_rect_before_wrap();
                let [w, h] = self.state.settings.size;
                let scale = (available.width() / w as f32).min(available.height() / h as f32);
                let size = egui::vec2(w as f32 * scale, h as f32 * scale);
                let rect = egui::Rect::from_center_size(available.center(), size);
                self.image_rect = rect;
                let ppp = ui.ctx().pixels_per_point();
                self.report.image_rect_px =
                    [rect.min.x, rect.min.y, rect.max.x, rect.max.y].map(|v| v * ppp);
                let response = ui.allocate_rect(rect, egui::Sense::click_and_drag());
                if let Some(texture) = self.on_screen.as_ref().and_then(|o| o.texture) {
                    ui.painter().image(
                        texture,
                        rect,
                        egui::Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0)),
                        egui::Color32::WHITE,
                    );
                }
                self.camera_input(ui, &response, status, size.y / scale);
                crate::panel::waiting_text(ui, rect, status);
            });
    }

    fn camera_input(
        &mut self,
        ui: &egui::Ui,
        response: &egui::Response,
        status: &Status,
        image_height: f32,
    ) {
        let scroll = if response.hovered() {
            ui.input(|i| i.smooth_scroll_delta.y)
        } else {
            0.0
        };
        let orbit_drag = response.dragged_by(egui::PointerButton::Primary);
        let pan_drag = response.dragged_by(egui::PointerButton::Secondary)
            || response.dragged_by(egui::PointerButton::Middle);
        if !(orbit_drag || pan_drag || scroll != 0.0) {
            return;
        }
        if self.orbit.is_none() {
            let Some(shown) = &status.shown else { return };
            self.orbit = Some(Orbit::from_camera(&shown.camera, shown.front, shown.radius));
        }
        let orbit = self.orbit.as_mut().expect("set above");
        let delta = response.drag_delta() / (response.rect.height() / image_height);
        if orbit_drag {
            orbit.rotate(delta.x, delta.y);
        }
        if pan_drag {
            orbit.pan(delta.x, delta.y, image_height);
        }
        if scroll != 0.0 {
            orbit.zoom(scroll / 50.0);
        }
        let camera = ExactCamera::of(&orbit.camera());
        self.edit(|s| s.settings.camera = CameraSettings::Exact(camera));
    }

    /// Saves the screenshots asked for once the latest settings have converged.
    fn save_screenshots(&mut self, status: &Status) {
        if self.screenshots.is_empty() || !self.converged() {
            return;
        }
        let (Some(on_screen), Some(shown)) = (&self.on_screen, &status.shown) else {
            return;
        };
        if on_screen.job != shown.job || on_screen.stage != Stage::Converged {
            return;
        }
        let request = on_screen.request.clone();
        for stem in std::mem::take(&mut self.screenshots) {
            let before = data_readbacks_on_this_thread();
            let saved = save_picture(&stem, &shown.settings, &self.state.display, &request);
            self.report.screenshot_readbacks += data_readbacks_on_this_thread() - before;
            match saved {
                Ok(files) => {
                    let ScreenshotFiles {
                        png,
                        exr,
                        sidecar,
                        window,
                    } = files;
                    self.window_captures.push(WindowCapture {
                        path: window.clone(),
                        result: None,
                    });
                    self.message = Some(format!(
                        "saved {}, {}, {} and {}",
                        png.display(),
                        exr.display(),
                        sidecar.display(),
                        window.display()
                    ));
                    self.report.screenshots.push(png);
                }
                Err(e) => {
                    let e = format!("screenshot {}: {e:#}", stem.display());
                    self.report.errors.push(e.clone());
                    self.message = Some(e);
                }
            }
        }
    }

    /// Where the image was drawn last frame (scripted pointer positions are fractions of it).
    pub fn image_rect(&self) -> egui::Rect {
        self.image_rect
    }

    pub fn screenshots_pending(&self) -> bool {
        !self.screenshots.is_empty() || !self.window_captures.is_empty()
    }

    /// The window captures the next paint should write.
    pub fn take_window_captures(&mut self) -> Vec<WindowCapture> {
        std::mem::take(&mut self.window_captures)
    }

    /// Back from the paint: written, failed, or (no frame was presented) still to do.
    pub fn window_captures_done(&mut self, captures: Vec<WindowCapture>) {
        for capture in captures {
            match capture.result {
                None => self.window_captures.push(capture),
                Some(Ok(())) => {
                    self.report.window_captures.push(capture.path);
                    self.report
                        .window_capture_image_rects_px
                        .push(self.report.image_rect_px);
                }
                Some(Err(e)) => {
                    let e = format!("window capture {}: {e:#}", capture.path.display());
                    self.report.errors.push(e.clone());
                    self.message = Some(e);
                }
            }
        }
    }
}

/// The screenshot of `request`'s picture: the frame read back (the one readback), exposed as
/// the window shows it (automatic exposure metered on the CPU, which the display pass's meter
/// matches within 1/1000 of a stop) and composited over the same backdrop.
fn save_picture(
    stem: &std::path::Path,
    settings: &FrameSettings,
    display: &crate::recompute::Display,
    request: &DisplayRequest,
) -> anyhow::Result<ScreenshotFiles> {
    let image = request.image.read(shared_gpu()?)?;
    let stops = match request.exposure_stops {
        Some(stops) => stops,
        None => metered_stops(&image.pixels).unwrap_or(0.0),
    };
    let behind = request.backdrop.as_deref().map(|b| b.as_slice());
    let composited = composite(&image, stops, behind);
    save(stem, settings, display, stops, &image, &composited)
}

/// `out/view-<unix seconds>`.
fn default_screenshot_stem() -> PathBuf {
    let seconds = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    PathBuf::from(format!("out/view-{seconds}"))
}
