//! The browser side: a WebGPU device, the [`Session`] behind it, and the calls `index.html`
//! makes. The page's script drives it: one [`Page::tick`] per animation frame encodes at most
//! one step and collects the readbacks the browser has mapped — nothing here waits for the GPU,
//! so the main thread never blocks. A step is encoded only once the GPU has finished the one
//! before: on a slow device (SwiftShader) ticks outpace the GPU, and a drag that restarts the
//! frame at every mouse move would otherwise queue steps for cameras already left behind. The picture reaches the canvas as 8-bit RGBA through a 2D
//! context: headless Chromium's SwiftShader loses its device presenting a WebGPU canvas, and
//! the picture is read back anyway (exposure is metered on it).

use crate::session::{BundleFiles, Readback, Session, Stage};
use std::cell::RefCell;
use std::rc::Rc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use strandlight_runtime::gpu::GpuContext;
use strandlight_scene::exposure::Exposure;
use strandlight_scene::scene_tables::ScatteringMode;
use wasm_bindgen::prelude::*;

/// A readback the browser is mapping, and its outcome once the callback has run.
struct InFlight {
    readback: Readback,
    /// Shared with the map callback, which wgpu asks to be `Send`.
    mapped: Arc<Mutex<Option<Result<(), wgpu::BufferAsyncError>>>>,
}

/// The forward-scattering march's copies the browser is mapping: how many have mapped.
struct MarchInFlight {
    id: u64,
    buffers: Vec<wgpu::Buffer>,
    mapped: Arc<Mutex<Vec<Result<(), wgpu::BufferAsyncError>>>>,
}

#[wasm_bindgen]
pub struct Page {
    session: Session,
    in_flight: Option<InFlight>,
    march_in_flight: Option<MarchInFlight>,
    /// Whether the GPU is still running the last step encoded (cleared by wgpu's
    /// submitted-work-done callback, which it asks to be `Send`).
    step_running: Arc<AtomicBool>,
    /// A GPU validation error reported after the step that caused it.
    gpu_error: Rc<RefCell<Option<String>>>,
    /// The last problem (a bad file, an out-of-range value): shown, the scene kept.
    message: Option<String>,
    /// A failure that stops the frame.
    failed: Option<String>,
    /// How long opening the bundle held the page's thread (tables decoded and checked).
    load_ms: f64,
}

/// The bytes of a JavaScript `Map` of file name → `Uint8Array`.
fn bundle_files(files: &js_sys::Map) -> BundleFiles {
    let mut bundle = BundleFiles::new();
    files.for_each(&mut |value, key| {
        if let (Some(name), Ok(bytes)) = (key.as_string(), value.dyn_into::<js_sys::Uint8Array>()) {
            bundle.insert(name, bytes.to_vec());
        }
    });
    bundle
}

fn js_error(e: anyhow::Error) -> JsValue {
    JsValue::from_str(&format!("{e:#}"))
}

#[wasm_bindgen]
impl Page {
    /// Opens WebGPU (with its default limits) and the bundle in `files` (file name → bytes).
    pub async fn create(files: js_sys::Map) -> Result<Page, JsValue> {
        let bundle = bundle_files(&files);
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor {
            backends: wgpu::Backends::BROWSER_WEBGPU,
            ..wgpu::InstanceDescriptor::new_without_display_handle()
        });
        let adapter = instance
            .request_adapter(&Default::default())
            .await
            .map_err(|e| JsValue::from_str(&format!("no WebGPU adapter: {e}")))?;
        let gpu = GpuContext::for_adapter(adapter, Some(wgpu::Limits::default()))
            .await
            .map_err(|e| JsValue::from_str(&e.to_string()))?;
        gpu.device.set_device_lost_callback(|reason, message| {
            web_sys::console::error_1(
                &format!("WebGPU device lost ({reason:?}): {message}").into(),
            );
        });
        gpu.device
            .on_uncaptured_error(Arc::new(|error: wgpu::Error| {
                web_sys::console::error_1(&format!("WebGPU: {error}").into());
            }));
        let opening = web_time::Instant::now();
        let session = Session::new(gpu, bundle).map_err(js_error)?;
        let load_ms = opening.elapsed().as_secs_f64() * 1e3;
        Ok(Page {
            load_ms,
            session,
            in_flight: None,
            march_in_flight: None,
            step_running: Arc::new(AtomicBool::new(false)),
            gpu_error: Rc::new(RefCell::new(None)),
            message: None,
            failed: None,
        })
    }

    /// The rest of the bundle's files (file name → bytes), fetched after those `create` opened
    /// (the first look's tables): the frame goes on from its preview to its batches.
    pub fn add_files(&mut self, files: js_sys::Map) {
        let opening = web_time::Instant::now();
        if let Err(e) = self.session.add_tables(bundle_files(&files)) {
            self.failed = Some(format!("{e:#}"));
        }
        self.load_ms += opening.elapsed().as_secs_f64() * 1e3;
    }

    /// How long opening the bundle held the page's thread (ms).
    pub fn load_ms(&self) -> f64 {
        self.load_ms
    }

    /// One animation frame: the next step (if any), the picture, the readbacks.
    pub fn tick(&mut self) {
        if let Some(error) = self.gpu_error.borrow_mut().take() {
            self.failed = Some(format!("the GPU reported an error: {error}"));
        }
        let gpu_free = !self.step_running.load(Ordering::Acquire);
        if self.failed.is_none() && self.session.refining() && gpu_free {
            let scope = self
                .session
                .gpu()
                .device
                .push_error_scope(wgpu::ErrorFilter::Validation);
            let stepped = self.session.step();
            self.step_running.store(true, Ordering::Release);
            let running = self.step_running.clone();
            self.session
                .gpu()
                .queue
                .on_submitted_work_done(move || running.store(false, Ordering::Release));
            let report = self.gpu_error.clone();
            wasm_bindgen_futures::spawn_local(async move {
                if let Some(error) = scope.pop().await {
                    web_sys::console::error_1(&format!("{error}").into());
                    report.borrow_mut().get_or_insert(error.to_string());
                }
            });
            if let Err(e) = stepped {
                self.failed = Some(format!("{e:#}"));
            }
            if let Some(why) = self.session.rejected.take() {
                self.message = Some(why);
            }
        }
        self.collect_march();
        self.collect_readback();
    }

    /// The picture as 8-bit RGBA (see [`Session::picture`]); empty before the first.
    pub fn picture(&self) -> Vec<u8> {
        self.session
            .picture()
            .map(|(bytes, _)| bytes)
            .unwrap_or_default()
    }

    /// The picture's width and height.
    pub fn picture_size(&self) -> Vec<u32> {
        self.session
            .picture()
            .map_or(vec![0, 0], |(_, size)| size.to_vec())
    }

    /// Changes whenever [`Self::picture`] would return another picture.
    pub fn picture_version(&self) -> f64 {
        self.session.picture_version as f64
    }

    /// Maps the forward-scattering march's copies once the session has submitted them all, and
    /// hands their values over when the browser has mapped every one.
    fn collect_march(&mut self) {
        if let Some(flight) = &self.march_in_flight {
            let outcomes = flight.mapped.lock().map(|m| m.clone()).unwrap_or_default();
            if outcomes.len() < flight.buffers.len() {
                return;
            }
            let flight = self.march_in_flight.take().expect("checked above");
            if let Some(Err(e)) = outcomes.into_iter().find(Result::is_err) {
                self.failed = Some(format!("reading the forward-scattering grid back: {e}"));
                return;
            }
            let mut values = Vec::new();
            for buffer in &flight.buffers {
                match buffer.slice(..).get_mapped_range() {
                    Ok(view) => values.push(bytemuck::pod_collect_to_vec(&view)),
                    Err(e) => {
                        self.failed =
                            Some(format!("reading the forward-scattering grid back: {e}"));
                        return;
                    }
                }
                buffer.unmap();
            }
            if let Err(e) = self.session.march_done(flight.id, values) {
                self.failed = Some(format!("{e:#}"));
            }
            return;
        }
        if let Some((id, buffers)) = self.session.march_readback() {
            let mapped = Arc::new(Mutex::new(Vec::new()));
            for buffer in &buffers {
                let report = mapped.clone();
                buffer.slice(..).map_async(wgpu::MapMode::Read, move |r| {
                    if let Ok(mut outcomes) = report.lock() {
                        outcomes.push(r);
                    }
                });
            }
            self.march_in_flight = Some(MarchInFlight {
                id,
                buffers,
                mapped,
            });
        }
    }

    /// Starts a readback of the shown picture when none is in flight, and hands a mapped one
    /// to the session.
    fn collect_readback(&mut self) {
        let done = self
            .in_flight
            .as_ref()
            .and_then(|f| f.mapped.lock().ok()?.take());
        match (done, self.in_flight.take()) {
            (Some(Ok(())), Some(flight)) => {
                let readback = flight.readback;
                let bytes = readback
                    .buffer
                    .slice(..)
                    .get_mapped_range()
                    .map(|v| v.to_vec());
                readback.buffer.unmap();
                match bytes {
                    Ok(bytes) => {
                        let sums: Vec<[f32; 4]> = bytemuck::pod_collect_to_vec(&bytes);
                        self.session.readback_done(&readback, &sums);
                    }
                    Err(e) => self.failed = Some(format!("reading the frame back: {e}")),
                }
            }
            (Some(Err(e)), Some(_)) => {
                let gpu = self.gpu_error.borrow().clone().unwrap_or_default();
                self.failed = Some(format!("reading the frame back: {e} {gpu}"))
            }
            (None, flight) => self.in_flight = flight,
            (Some(_), None) => {}
        }
        if self.in_flight.is_none()
            && let Some(readback) = self.session.readback()
        {
            let mapped = Arc::new(Mutex::new(None));
            let report = mapped.clone();
            readback
                .buffer
                .slice(..)
                .map_async(wgpu::MapMode::Read, move |r| {
                    if let Ok(mut slot) = report.lock() {
                        *slot = Some(r);
                    }
                });
            self.in_flight = Some(InFlight { readback, mapped });
        }
    }

    /// "starting", "preview", "refining 3/12", "converged" or "error: …" (the page puts it at
    /// the end of its title, where a harness reads it).
    pub fn status(&self) -> String {
        if let Some(failed) = &self.failed {
            return format!("error: {failed}");
        }
        match self.session.stage() {
            Stage::Starting => "starting".into(),
            Stage::Preview => "preview".into(),
            Stage::Refining { done, total } => format!("refining {done}/{total}"),
            Stage::Converged => "converged".into(),
        }
    }

    /// The last problem that left the scene as it was (a bad file), or "".
    pub fn message(&self) -> String {
        self.message.clone().unwrap_or_default()
    }

    /// What the page changed to fit the device (smaller light maps), or "".
    pub fn notice(&self) -> String {
        self.session.notice.clone().unwrap_or_default()
    }

    /// The converged frame: linear, pre-multiplied RGBA f32, row-major from the top.
    pub fn converged_frame(&self) -> Option<Vec<f32>> {
        self.session
            .converged
            .as_ref()
            .map(|p| bytemuck::cast_slice(p).to_vec())
    }

    pub fn frame_size(&self) -> Vec<u32> {
        self.session.settings.size.to_vec()
    }

    /// The adapter, the bundle's environment and presets, the exposure: for the panel.
    pub fn describe(&self) -> String {
        let bundle = self.session.bundle();
        let report = serde_json::json!({
            "adapter": self.session.gpu().report.to_string(),
            "environment": bundle.environment,
            "presets": bundle.presets.keys().collect::<Vec<_>>(),
            "preset": self.session.settings.preset,
            "lobes": bundle.fit.lobes.len(),
            "multiple": bundle.mode == ScatteringMode::Full,
            "stops": self.session.stops(),
            "timestamps": self.session.gpu().pass_timer.is_some(),
        });
        report.to_string()
    }

    pub fn settings_json(&self) -> String {
        self.session.settings_json()
    }

    fn apply(&mut self, result: anyhow::Result<()>) {
        match result {
            Ok(()) => {
                self.message = None;
                self.failed = None;
            }
            Err(e) => self.message = Some(format!("{e:#}")),
        }
    }

    pub fn rotate(&mut self, dx: f32, dy: f32) {
        let r = self.session.rotate(dx, dy);
        self.apply(r);
    }

    pub fn pan(&mut self, dx: f32, dy: f32) {
        let r = self.session.pan(dx, dy);
        self.apply(r);
    }

    pub fn zoom(&mut self, steps: f32) {
        let r = self.session.zoom(steps);
        self.apply(r);
    }

    pub fn set_rotation(&mut self, degrees: f32) {
        let r = self.session.set_rotation(degrees);
        self.apply(r);
    }

    pub fn set_lobes(&mut self, lobes: u32) {
        let r = self.session.set_lobes(lobes as usize);
        self.apply(r);
    }

    pub fn set_kappa(&mut self, kappa: f32) {
        let r = self.session.set_kappa(kappa);
        self.apply(r);
    }

    /// `single` or `full` (single + multiple scattering).
    pub fn set_scattering(&mut self, mode: &str) {
        let mode = match mode {
            "full" => ScatteringMode::Full,
            _ => ScatteringMode::Single,
        };
        let r = self.session.set_scattering(mode);
        self.apply(r);
    }

    pub fn set_preset(&mut self, preset: &str) {
        let r = self.session.set_preset(preset);
        self.apply(r);
    }

    /// `auto` or a number of stops.
    pub fn set_exposure(&mut self, text: &str) {
        match text.parse::<Exposure>() {
            Ok(exposure) => self.session.set_exposure(exposure),
            Err(e) => self.message = Some(e),
        }
    }

    /// Linear RGB behind the hair.
    pub fn set_background(&mut self, r: f32, g: f32, b: f32) {
        self.session.set_background([r, g, b]);
    }

    /// A file dropped on the page or picked: a `.hair` groom.
    pub fn load_hair(&mut self, name: &str, bytes: &[u8]) {
        let r = self.session.load_hair(name, bytes);
        self.apply(r);
    }
}

#[wasm_bindgen(start)]
fn main() {
    std::panic::set_hook(Box::new(|info| {
        let text = format!("strandlight — error: panic: {info}");
        if let Some(document) = web_sys::window().and_then(|w| w.document()) {
            document.set_title(&text);
        }
        web_sys::console::error_1(&text.into());
    }));
}
