//! The window: winit's event loop, a wgpu surface, egui drawn through egui-wgpu, and scripted
//! input injected into egui's input like the mouse and keyboard. The window presents at its own
//! pace (about 30 frames a second while anything is changing, on events otherwise).

use crate::gpu_display::GpuDisplay;
use crate::pacing::FramePacing;
use crate::script::{Action, Script};
use crate::session::WindowCapture;
use crate::session::{Session, SessionReport};
use crate::window_capture::CaptureTarget;
use crate::worker::Worker;
use anyhow::{Context, bail};
use std::path::PathBuf;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};
use strandlight_runtime::gpu::{GpuContext, data_readbacks_so_far};
use strandlight_scene::env_frame::{install_shared_gpu, shared_gpu};
use strandlight_scene::frame_settings::FrameSettings;
use winit::application::ApplicationHandler;
use winit::event::WindowEvent;
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::window::{Window, WindowId};

/// Width of the side panel, points.
const PANEL_WIDTH: f64 = 320.0;

/// What `strandlight view` was asked to do.
pub struct ViewOptions {
    pub settings: FrameSettings,
    /// Holds `fits/` and `tables/` (shared with `render`).
    pub cache_dir: PathBuf,
    pub script: Option<PathBuf>,
    /// After the script (or the first converged image without one): save here and exit.
    pub screenshot: Option<PathBuf>,
    /// Exit after this many presented frames.
    pub frames: Option<u64>,
    /// Write the session's measurements here as JSON at exit.
    pub report: Option<PathBuf>,
    /// A scripted run that has not finished by then fails.
    pub timeout: Duration,
    /// When the command started: the report's first lit frame counts from here.
    pub started: Instant,
    pub window_device: WindowDevice,
}

/// Which device the window presents on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum WindowDevice {
    /// Shared on a hardware adapter, own on a software one.
    Auto,
    /// The renderer's device: the frame goes from the passes to the window on the GPU, nothing
    /// read back. On a software adapter's single queue the window waits for each of the
    /// renderer's submissions (1.3 s at 160×120 on lavapipe; docs/BENCHMARKS.md, "The
    /// viewer on one device").
    Shared,
    /// A device of its own: each new image is read back once by the render thread and uploaded
    /// to the window's device, so the window presents while a long pass runs.
    Own,
}

impl WindowDevice {
    /// `Shared` or `Own` on `adapter`.
    fn resolve(self, adapter: &wgpu::AdapterInfo) -> Self {
        match self {
            Self::Auto if adapter.device_type == wgpu::DeviceType::Cpu => Self::Own,
            Self::Auto => Self::Shared,
            chosen => chosen,
        }
    }
}

/// Opens the window and runs until it is closed or the script ends.
pub fn run(mut options: ViewOptions) -> anyhow::Result<()> {
    options.settings.check()?;
    // The panel names the fiber model it shows: the first request carries it already, so that
    // the window's first frame does not ask for the same frame again.
    options.settings.shading = Some(options.settings.shading());
    let mut script = options.script.as_deref().map(Script::read).transpose()?;
    if script.is_none() && options.screenshot.is_some() {
        script = Some(Script::converged_then_exit());
    }
    let readbacks_at_start = data_readbacks_so_far();
    let event_loop = EventLoop::<()>::with_user_event()
        .build()
        .context("opening a window: no display (on a headless machine run under xvfb-run -a)")?;
    // A shared device is made on the instance the window's surface comes from, so that one
    // device draws and presents (issue 62). A window with a device of its own keeps this
    // instance to itself: the renderer makes its device on another, because on one instance
    // lavapipe's devices share one rasterizer, and the window's presents waited for the
    // renderer's passes (up to 1.1 s at 160×120).
    let instance = window_instance(&event_loop);
    let adapter = pollster::block_on(GpuContext::preferred_adapter(&instance))?;
    let window_device = options.window_device.resolve(&adapter.get_info());
    if window_device == WindowDevice::Shared {
        install_shared_gpu(pollster::block_on(GpuContext::for_adapter(
            adapter.clone(),
            None,
        ))?)?;
    }
    let proxy = Mutex::new(event_loop.create_proxy());
    let wake: Box<dyn Fn() + Send + Sync> = Box::new(move || {
        let _ = proxy.lock().unwrap().send_event(());
    });
    let worker = Worker::spawn(
        options.cache_dir.clone(),
        !options.settings.head.is_none(),
        window_device == WindowDevice::Own,
        wake,
    );
    // The first frame is asked for now: the worker loads the scene and draws its first look
    // while the window and its device are made (a request from the first window frame came
    // 0.5 s after the start on lavapipe).
    worker.submit(Session::FIRST_JOB, options.settings.clone());
    let mut app = App {
        instance,
        adapter,
        window_device,
        readbacks_at_start,
        options,
        script,
        worker: Some(worker),
        window: None,
        session: None,
        egui: egui::Context::default(),
        started: Instant::now(),
        pacing: FramePacing::default(),
        repaint_asked: false,
        worker_news: false,
        outcome: Ok(()),
    };
    event_loop.run_app(&mut app)?;
    app.finish()
}

struct App {
    /// The instance and adapter the window's surface and device are made on (the renderer's
    /// too when the device is shared).
    instance: wgpu::Instance,
    adapter: wgpu::Adapter,
    /// Shared or Own, resolved.
    window_device: WindowDevice,
    /// [`data_readbacks_so_far`] when the command started.
    readbacks_at_start: u64,
    options: ViewOptions,
    script: Option<Script>,
    worker: Option<Worker>,
    window: Option<WindowGpu>,
    session: Option<Session>,
    egui: egui::Context,
    started: Instant,
    pacing: FramePacing,
    repaint_asked: bool,
    /// The worker changed its status since the last frame.
    worker_news: bool,
    outcome: anyhow::Result<()>,
}

/// The window, its surface and egui's renderer on the renderer's device or a device of its own
/// ([`WindowDevice`]), and the display pass that draws each frame for egui.
struct WindowGpu {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    device: wgpu::Device,
    queue: wgpu::Queue,
    config: wgpu::SurfaceConfiguration,
    renderer: egui_wgpu::Renderer,
    egui_input: egui_winit::State,
    display: GpuDisplay,
}

/// The instance a window's surface can be made on: the display's handle, Vulkan, Metal or DX12
/// (the passes need compute; WGPU_BACKEND overrides).
fn window_instance(event_loop: &EventLoop<()>) -> wgpu::Instance {
    let mut desc = wgpu::InstanceDescriptor::new_with_display_handle_from_env(Box::new(
        event_loop.owned_display_handle(),
    ));
    desc.backends = wgpu::Backends::from_env().unwrap_or(wgpu::Backends::PRIMARY);
    wgpu::Instance::new(desc)
}

impl WindowGpu {
    fn new(
        event_loop: &ActiveEventLoop,
        egui: &egui::Context,
        size: [u32; 2],
        (instance, adapter): (&wgpu::Instance, &wgpu::Adapter),
        device_choice: WindowDevice,
    ) -> anyhow::Result<(Self, String)> {
        let attributes = Window::default_attributes()
            .with_title("strandlight")
            .with_inner_size(winit::dpi::LogicalSize::new(
                size[0] as f64 + PANEL_WIDTH + crate::session::READOUT_WIDTH as f64 + 16.0,
                (size[1] as f64 + 16.0).max(560.0),
            ));
        let window = Arc::new(event_loop.create_window(attributes)?);
        let surface = instance.create_surface(window.clone())?;
        let shared = device_choice != WindowDevice::Own;
        // A window of its own may present from another adapter than the renderer's (a machine
        // whose preferred GPU drives no display); a shared device must present from its own.
        let adapter = match adapter.is_surface_supported(&surface) {
            true => adapter.clone(),
            false if shared => bail!(
                "the renderer's adapter {} cannot present to this window (try --window-device own)",
                adapter.get_info().name
            ),
            false => pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
                compatible_surface: Some(&surface),
                ..Default::default()
            }))
            .context("no adapter can present to this window")?,
        };
        let info = adapter.get_info();
        let adapter_name = format!("{} ({:?}, {:?})", info.name, info.backend, info.device_type);
        let (device, queue) = match shared {
            true => {
                let gpu = shared_gpu()?;
                (gpu.device.clone(), gpu.queue.clone())
            }
            false => {
                let own = pollster::block_on(GpuContext::for_adapter(adapter.clone(), None))?;
                (own.device, own.queue)
            }
        };
        let physical = window.inner_size();
        let mut config = surface
            .get_default_config(&adapter, physical.width.max(1), physical.height.max(1))
            .context("the window's surface has no configuration on this adapter")?;
        let caps = surface.get_capabilities(&adapter);
        config.format = caps
            .formats
            .iter()
            .copied()
            .find(|f| !f.is_srgb())
            .unwrap_or(caps.formats[0]);
        surface.configure(&device, &config);
        let renderer = egui_wgpu::Renderer::new(
            &device,
            config.format,
            egui_wgpu::RendererOptions::default(),
        );
        let egui_input = egui_winit::State::new(
            egui.clone(),
            egui::ViewportId::ROOT,
            &window,
            Some(window.scale_factor() as f32),
            None,
            Some(device.limits().max_texture_dimension_2d as usize),
        );
        Ok((
            Self {
                display: GpuDisplay::new(&device, !shared),
                window,
                surface,
                device,
                queue,
                config,
                renderer,
                egui_input,
            },
            adapter_name,
        ))
    }

    fn resize(&mut self, width: u32, height: u32) {
        if width > 0 && height > 0 {
            self.config.width = width;
            self.config.height = height;
            self.surface.configure(&self.device, &self.config);
        }
    }

    /// Draws egui's output, and into `captures` too when it has any; false when no frame
    /// could be acquired (it is tried again, captures included).
    fn paint(
        &mut self,
        egui: &egui::Context,
        mut output: egui::FullOutput,
        captures: &mut [WindowCapture],
    ) -> bool {
        let presented = self.paint_frame(egui, &mut output, captures);
        for id in &output.textures_delta.free {
            self.renderer.free_texture(id);
        }
        // Every delta is applied now (egui checks that none is dropped unapplied).
        output.textures_delta.clear();
        presented
    }

    fn paint_frame(
        &mut self,
        egui: &egui::Context,
        output: &mut egui::FullOutput,
        captures: &mut [WindowCapture],
    ) -> bool {
        self.egui_input
            .handle_platform_output(&self.window, std::mem::take(&mut output.platform_output));
        let jobs = egui.tessellate(std::mem::take(&mut output.shapes), output.pixels_per_point);
        for (id, delta) in &output.textures_delta.set {
            for delta in delta {
                self.renderer
                    .update_texture(&self.device, &self.queue, *id, delta);
            }
        }
        let frame = match self.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(f)
            | wgpu::CurrentSurfaceTexture::Suboptimal(f) => f,
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                self.surface.configure(&self.device, &self.config);
                return false;
            }
            _ => return false,
        };
        let view = frame.texture.create_view(&Default::default());
        let screen = egui_wgpu::ScreenDescriptor {
            size_in_pixels: [self.config.width, self.config.height],
            pixels_per_point: output.pixels_per_point,
        };
        let mut encoder = self.device.create_command_encoder(&Default::default());
        let extra =
            self.renderer
                .update_buffers(&self.device, &self.queue, &mut encoder, &jobs, &screen);
        self.draw_egui(&mut encoder, &view, &jobs, &screen);
        let target = match captures.is_empty() {
            true => None,
            false => Some(CaptureTarget::new(
                &self.device,
                self.config.width,
                self.config.height,
                self.config.format,
            )),
        };
        if let Some(Ok(target)) = &target {
            self.draw_egui(&mut encoder, &target.view(), &jobs, &screen);
            target.encode_copy(&mut encoder);
        }
        self.queue
            .submit(extra.into_iter().chain([encoder.finish()]));
        self.queue.present(frame);
        if let Some(target) = target {
            let rgb = target.and_then(|t| Ok((t.read_rgb(&self.device)?, t)));
            for capture in captures.iter_mut() {
                capture.result = Some(match &rgb {
                    Ok((rgb, t)) => t.write_png(&capture.path, rgb),
                    Err(e) => Err(anyhow::anyhow!("{e:#}")),
                });
            }
        }
        true
    }

    fn draw_egui(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        jobs: &[egui::ClippedPrimitive],
        screen: &egui_wgpu::ScreenDescriptor,
    ) {
        let pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("egui"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: target,
                resolve_target: None,
                depth_slice: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                    store: wgpu::StoreOp::Store,
                },
            })],
            ..Default::default()
        });
        let mut pass = pass.forget_lifetime();
        self.renderer.render(&mut pass, jobs, screen);
    }
}

impl App {
    /// One frame: script actions into egui's input, the session's UI, paint, exit checks.
    fn redraw(&mut self, event_loop: &ActiveEventLoop) {
        let (Some(gpu), Some(session)) = (&mut self.window, &mut self.session) else {
            return;
        };
        let frame_started = self.pacing.frame_started();
        self.worker_news = false;
        let mut input = gpu.egui_input.take_egui_input(&gpu.window);
        let actions = match &mut self.script {
            Some(script) => script.advance(&|cond| session.wait_done(cond)),
            None => Vec::new(),
        };
        let image_rect = session.image_rect();
        for action in &actions {
            inject(&mut input, action, image_rect);
            if let Err(e) = session.apply(action) {
                self.outcome = Err(e);
                event_loop.exit();
            }
        }
        // A new frame or new display settings: drawn for egui on the GPU before the UI shows it.
        if let Some(picture) = session.picture_to_draw() {
            let texture = gpu
                .display
                .show(&gpu.device, &gpu.queue, &mut gpu.renderer, &picture);
            session.picture_drawn(texture);
        }
        let output = self.egui.run_ui(input, |ui| session.frame(ui));
        let repaint = output
            .viewport_output
            .get(&egui::ViewportId::ROOT)
            .is_some_and(|v| v.repaint_delay.is_zero());
        let mut captures = session.take_window_captures();
        if gpu.paint(&self.egui, output, &mut captures) {
            session.presented();
        }
        session.window_captures_done(captures);
        // egui asks for a repaint while anything animates; about_to_wait paces it.
        self.repaint_asked = repaint;
        self.pacing.frame_ended(frame_started);
        self.check_exit(event_loop);
    }

    fn check_exit(&mut self, event_loop: &ActiveEventLoop) {
        let Some(session) = &self.session else { return };
        if let Some(n) = self.options.frames
            && session.report.frames_presented >= n
        {
            event_loop.exit();
        }
        let Some(script) = &self.script else { return };
        if script.finished() && !session.screenshots_pending() {
            if let Some(stem) = self.options.screenshot.take() {
                self.session
                    .as_mut()
                    .expect("checked")
                    .apply(&Action::Screenshot(stem))
                    .expect("a screenshot action");
                return;
            }
            event_loop.exit();
        } else if self.started.elapsed() > self.options.timeout {
            self.outcome = Err(anyhow::anyhow!(
                "--script did not finish within {} s (at {})",
                self.options.timeout.as_secs(),
                script.position()
            ));
            event_loop.exit();
        }
    }

    fn finish(mut self) -> anyhow::Result<()> {
        let mut report = self.session.take().map(|s| s.report).unwrap_or_default();
        // Stop the renderer before the window's device goes.
        drop(self.worker.take());
        report.data_readbacks = data_readbacks_so_far() - self.readbacks_at_start;
        report.window_device = Some(self.window_device);
        if let Some(path) = &self.options.report {
            write_report(path, &report)?;
        }
        std::mem::replace(&mut self.outcome, Ok(()))?;
        if (self.options.screenshot.is_some() || self.options.script.is_some())
            && let Some(e) = report.errors.first()
        {
            bail!("the scripted session met an error: {e}");
        }
        Ok(())
    }
}

fn write_report(path: &std::path::Path, report: &SessionReport) -> anyhow::Result<()> {
    let json = serde_json::to_string_pretty(report)?;
    std::fs::write(path, json).with_context(|| format!("--report {}", path.display()))
}

/// A script action as the input events a person's mouse or keyboard would produce.
fn inject(input: &mut egui::RawInput, action: &Action, image: egui::Rect) {
    let at = |f: [f32; 2]| image.min + egui::vec2(f[0] * image.width(), f[1] * image.height());
    match action {
        Action::Pointer { at: f, button } => {
            let pos = at(*f);
            input.events.push(egui::Event::PointerMoved(pos));
            if let Some((primary, pressed)) = button {
                input.events.push(egui::Event::PointerButton {
                    pos,
                    button: if *primary {
                        egui::PointerButton::Primary
                    } else {
                        egui::PointerButton::Secondary
                    },
                    pressed: *pressed,
                    modifiers: Default::default(),
                });
            }
        }
        Action::Scroll(steps) => input.events.push(egui::Event::MouseWheel {
            unit: egui::MouseWheelUnit::Line,
            delta: egui::vec2(0.0, *steps),
            phase: egui::TouchPhase::Move,
            modifiers: Default::default(),
        }),
        Action::Key(key) => {
            for pressed in [true, false] {
                input.events.push(egui::Event::Key {
                    key: *key,
                    physical_key: None,
                    pressed,
                    repeat: false,
                    modifiers: Default::default(),
                });
            }
        }
        _ => {}
    }
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.window.is_some() {
            return;
        }
        let gpu_of = (&self.instance, &self.adapter);
        let size = self.options.settings.size;
        match WindowGpu::new(event_loop, &self.egui, size, gpu_of, self.window_device) {
            Ok((gpu, adapter)) => {
                gpu.window.request_redraw();
                self.window = Some(gpu);
                let worker = self.worker.take().expect("the worker starts once");
                self.session = Some(Session::new(
                    self.options.settings.clone(),
                    worker,
                    adapter,
                    self.options.started,
                ));
            }
            Err(e) => {
                self.outcome = Err(e.context("opening the window"));
                event_loop.exit();
            }
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        let Some(gpu) = &mut self.window else { return };
        if let WindowEvent::DroppedFile(_) = &event {
            self.repaint_asked = true;
        }
        let response = gpu.egui_input.on_window_event(&gpu.window, &event);
        // egui-winit asks a repaint for every event, the redraw itself included: taken as is,
        // each frame would ask the next and the window would repaint every BUSY_FRAME for ever.
        let input = !matches!(event, WindowEvent::RedrawRequested);
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(size) => gpu.resize(size.width, size.height),
            WindowEvent::RedrawRequested => self.redraw(event_loop),
            _ => {}
        }
        // Input is shown at the next paced frame (at most BUSY_FRAME later).
        self.repaint_asked |= input && response.repaint;
    }

    /// The worker changed its status: shown at the next paced frame.
    fn user_event(&mut self, _: &ActiveEventLoop, _: ()) {
        self.worker_news = true;
    }

    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        let (Some(gpu), Some(session)) = (&self.window, &self.session) else {
            return;
        };
        let script = self.script.as_ref().filter(|s| !s.finished());
        // A refinement's next batch waits for the progress pace; any other news is shown now.
        let news = self.worker_news && !session.only_refined();
        let changing = self.repaint_asked || news || script.is_some_and(|s| !s.waiting());
        if changing || script.is_some() || session.busy() || self.worker_news {
            let due = self.pacing.next_frame(changing);
            if Instant::now() >= due {
                gpu.window.request_redraw();
            } else {
                event_loop.set_control_flow(ControlFlow::WaitUntil(due));
            }
        } else {
            event_loop.set_control_flow(ControlFlow::Wait);
        }
    }
}
