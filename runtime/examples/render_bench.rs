//! Issue #5's benchmark: straight.hair at Hunz's viewport (656 × 861), one directional light,
//! Kajiya-Kay shading; opaque, A-buffer and DBK, each without and with deep opacity maps.
//!
//! Each configuration renders once to warm up and `TIMED_RUNS` times timed, the configurations
//! interleaved round by round (load from others on a shared machine hits all alike); the table gives the
//! median of each pass, GPU memory from the renderer's own accounting, fragments stored/dropped
//! and the ratios of the same run. Hunz (2016) §6.3 measured, for the same model and viewport on
//! a GTX 960: A-buffer 12,959,208 fragments in 150.46 MB, DBK 4,518,344 fragments in 53.86 MB
//! (59.25 MB with its opaque fallback), the DBK-buffer the faster of the two.
//!
//! Run: `cargo run --release -p strandlight-runtime --example render_bench [TIMED_RUNS]`

use glam::Vec3;
use strandlight_runtime::camera::{Camera, UpAxis};
use strandlight_runtime::gpu::GpuContext;
use strandlight_runtime::hair::{self, HairModel};
use strandlight_runtime::lights::Light;
use strandlight_runtime::passes::abuffer::NODE_BYTES;
use strandlight_runtime::passes::deep_opacity::DomSettings;
use strandlight_runtime::passes::frame_params::{FrameParams, KajiyaKay};
use strandlight_runtime::point_frame::{
    PointImage, RenderOptions, ShadowMaps, Transparency, render_frame,
};

const WIDTH: u32 = 656;
const HEIGHT: u32 = 861;
const DEFAULT_TIMED_RUNS: usize = 7;
/// Headroom over the probed fragment count, so that nothing is dropped.
const HEADROOM: f64 = 1.05;

type BoxError = Box<dyn std::error::Error>;

fn median(values: &mut [f64]) -> f64 {
    values.sort_by(f64::total_cmp);
    let n = values.len();
    if n % 2 == 1 {
        values[n / 2]
    } else {
        0.5 * (values[n / 2 - 1] + values[n / 2])
    }
}

fn mb(bytes: u64) -> f64 {
    bytes as f64 / 1e6
}

/// Passes that build pipelines or upload the model: paid once in an application, every call
/// here, so they are reported apart from the frame time.
fn is_setup(pass: &str) -> bool {
    pass.contains("pipeline") || pass == "upload"
}

struct Measured {
    name: String,
    /// (pass, median ms) in the renderer's order.
    pass_ms: Vec<(String, f64)>,
    frame_ms: f64,
    frame_min_ms: f64,
    total_ms: f64,
    memory: Vec<(String, u64)>,
    stored: Option<u64>,
    dropped: Option<u64>,
    truncated: Option<u64>,
    capacity: Option<u64>,
    covered: usize,
}

impl Measured {
    fn memory_total(&self) -> u64 {
        self.memory.iter().map(|(_, b)| b).sum()
    }
    fn memory_of(&self, name: &str) -> u64 {
        self.memory
            .iter()
            .filter(|(n, _)| n == name)
            .map(|(_, b)| b)
            .sum()
    }
    /// Hunz's accounting: the nodes actually stored plus the head buffer.
    fn lists_used_bytes(&self) -> Option<u64> {
        self.stored
            .map(|s| s * NODE_BYTES + self.memory_of("abuffer heads"))
    }
}

/// Every timed render of one configuration.
struct Samples {
    name: String,
    options: RenderOptions,
    per_pass: Vec<(String, Vec<f64>)>,
    frame_ms: Vec<f64>,
    total_ms: Vec<f64>,
    last: Option<PointImage>,
}

impl Samples {
    fn new(name: String, options: RenderOptions) -> Self {
        Self {
            name,
            options,
            per_pass: Vec::new(),
            frame_ms: Vec::new(),
            total_ms: Vec::new(),
            last: None,
        }
    }

    fn record(&mut self, out: PointImage) {
        let timings = &out.stats.timings;
        if self.per_pass.is_empty() {
            self.per_pass = timings
                .iter()
                .map(|t| (t.pass.clone(), Vec::new()))
                .collect();
        }
        for (slot, t) in self.per_pass.iter_mut().zip(timings) {
            slot.1.push(t.milliseconds);
        }
        self.frame_ms.push(
            timings
                .iter()
                .filter(|t| !is_setup(&t.pass))
                .map(|t| t.milliseconds)
                .sum(),
        );
        self.total_ms
            .push(timings.iter().map(|t| t.milliseconds).sum());
        self.last = Some(out);
    }

    fn summarize(mut self) -> Result<Measured, BoxError> {
        let last = self.last.ok_or("no timed run")?;
        let f = last.stats.fragments;
        let frame_min = self.frame_ms.iter().copied().fold(f64::INFINITY, f64::min);
        Ok(Measured {
            name: self.name,
            pass_ms: self
                .per_pass
                .into_iter()
                .map(|(p, mut v)| (p, median(&mut v)))
                .collect(),
            frame_ms: median(&mut self.frame_ms),
            frame_min_ms: frame_min,
            total_ms: median(&mut self.total_ms),
            memory: last.stats.memory_bytes.clone(),
            stored: f.map(|f| f.stored),
            dropped: f.map(|f| f.dropped),
            truncated: f.map(|f| f.truncated),
            capacity: f.map(|f| f.capacity),
            covered: last.pixels.iter().filter(|p| p[3] > 0.0).count(),
        })
    }
}

/// One warm-up render per configuration, then `timed_runs` rounds that render every
/// configuration in turn, so that load from other processes on a shared machine falls on all
/// configurations alike rather than on whichever ran during it.
fn measure_interleaved(
    gpu: &GpuContext,
    model: &HairModel,
    frame: &FrameParams,
    configs: Vec<(String, RenderOptions)>,
    timed_runs: usize,
) -> Result<Vec<Measured>, BoxError> {
    let mut samples: Vec<Samples> = configs
        .into_iter()
        .map(|(name, options)| Samples::new(name, options))
        .collect();
    for s in &samples {
        render_frame(gpu, model, frame, &s.options)?;
    }
    for round in 0..timed_runs {
        eprintln!("round {} of {timed_runs} ...", round + 1);
        for s in &mut samples {
            let out = render_frame(gpu, model, frame, &s.options)?;
            s.record(out);
        }
    }
    samples.into_iter().map(Samples::summarize).collect()
}

/// Total fragments (stored + dropped) one list-building render produces, with the largest
/// node buffer the adapter allows.
fn probe_fragments(
    gpu: &GpuContext,
    model: &HairModel,
    frame: &FrameParams,
    transparency: Transparency,
) -> Result<u64, BoxError> {
    let out = render_frame(
        gpu,
        model,
        frame,
        &RenderOptions {
            shadows: None,
            transparency,
            ..Default::default()
        },
    )?;
    let f = out
        .stats
        .fragments
        .ok_or("list probe returned no fragment counts")?;
    Ok(f.stored + f.dropped)
}

fn nodes_per_pixel_for(fragments: u64) -> u32 {
    let pixels = WIDTH as f64 * HEIGHT as f64;
    ((fragments as f64 * HEADROOM) / pixels).ceil().max(1.0) as u32
}

fn main() -> Result<(), BoxError> {
    let timed_runs: usize = match std::env::args().nth(1) {
        Some(s) => s
            .parse()
            .ok()
            .filter(|&n| n > 0)
            .ok_or_else(|| format!("timed runs {s:?}: expected a positive whole number"))?,
        None => DEFAULT_TIMED_RUNS,
    };
    let Some(path) = strandlight_tables::shared_data::shared_file("hair/straight.hair") else {
        println!("render_bench: skipped (hair/straight.hair is not in the shared data folder)");
        return Ok(());
    };
    let loaded = hair::load(&path)?;
    let model = loaded.model;
    let bounds = model.bounds();
    let up = UpAxis::detect(&model);
    let frame = directionally_lit_frame(&model, up);
    let diagonal = bounds.diagonal();
    // The CLI's defaults: 4 layers 1% of the diagonal apart at 512², DBK Δ 5% of the diagonal.
    let dom = DomSettings {
        resolution: 512,
        layers: 4,
        spacing: diagonal * 0.01,
    };
    let delta = diagonal * 0.05;

    let gpu = GpuContext::new_headless()?;
    println!("adapter: {}", gpu.report);
    println!(
        "hair: {} ({} strands, {} points), up axis {up:?} (gravity heuristic), bounds {} .. {}",
        path.display(),
        model.strand_count(),
        model.point_count(),
        bounds.min,
        bounds.max
    );
    let Light::Directional {
        direction: light_direction,
        ..
    } = frame.lights[0]
    else {
        unreachable!("directionally_lit_frame has one directional light")
    };
    println!(
        "camera: perspective {:.0}° vertical, eye {}, looking at {}, up {}; light toward {light_direction}",
        strandlight_runtime::camera::DEFAULT_FOV_Y_DEGREES,
        frame.camera.eye,
        frame.camera.target,
        frame.camera.up
    );
    let [abuffer_npp, dbk_npp] = list_sizes(&gpu, &model, &frame, delta)?;
    println!(
        "runs: 1 warm-up + {timed_runs} timed per configuration, interleaved (round-robin); medians; timing = CPU wall clock around submit + wait for idle"
    );
    let configs = configs(dom, abuffer_npp, dbk_npp, delta);
    let results = measure_interleaved(&gpu, &model, &frame, configs, timed_runs)?;
    print_table(&results);
    print_ratios(&results);
    Ok(())
}

/// The hair from the front under one directional light from the viewer's upper right front,
/// as the CLI's default light is for a Y-up file: 0.5 right, 0.7 up, 1 toward the eye.
fn directionally_lit_frame(model: &HairModel, up: UpAxis) -> FrameParams {
    let aspect = WIDTH as f32 / HEIGHT as f32;
    let camera = Camera::framing_front(model.bounds(), aspect, false, up);
    let toward_eye = camera.toward_eye();
    let right = (camera.target - camera.eye).cross(camera.up).normalize();
    let screen_up = right.cross(camera.target - camera.eye).normalize();
    let light_direction: Vec3 = (0.5 * right + 0.7 * screen_up + toward_eye).normalize();
    FrameParams {
        camera,
        width: WIDTH,
        height: HEIGHT,
        lights: vec![Light::Directional {
            direction: light_direction,
            intensity: 2.0,
        }],
        shading: KajiyaKay::default(),
        width_override_px: None,
    }
}

/// Nodes per pixel of the A-buffer and the DBK-buffer (Δ `delta`), sized from a probe with the
/// largest node buffer the adapter allows.
fn list_sizes(
    gpu: &GpuContext,
    model: &HairModel,
    frame: &FrameParams,
    delta: f32,
) -> Result<[u32; 2], BoxError> {
    let max_npp = (gpu.device.limits().max_storage_buffer_binding_size / NODE_BYTES)
        / (WIDTH as u64 * HEIGHT as u64);
    let max_npp = max_npp.max(1) as u32;
    let all = probe_fragments(
        gpu,
        model,
        frame,
        Transparency::ABuffer {
            nodes_per_pixel: Some(max_npp),
        },
    )?;
    let dbk = probe_fragments(
        gpu,
        model,
        frame,
        Transparency::Dbk {
            nodes_per_pixel: Some(max_npp),
            delta,
        },
    )?;
    let abuffer_npp = nodes_per_pixel_for(all);
    let dbk_npp = nodes_per_pixel_for(dbk);
    println!(
        "probe (node buffer for {max_npp} nodes/pixel): A-buffer {all} fragments → {abuffer_npp} nodes/pixel; DBK (Δ = {delta:.4}, 5% of the diagonal) {dbk} fragments → {dbk_npp} nodes/pixel"
    );
    Ok([abuffer_npp, dbk_npp])
}

/// Opaque, A-buffer and DBK, each without shadows and with the CLI's deep opacity maps.
fn configs(
    dom: DomSettings,
    abuffer_npp: u32,
    dbk_npp: u32,
    delta: f32,
) -> Vec<(String, RenderOptions)> {
    [
        None,
        Some(ShadowMaps::Deep {
            settings: dom,
            pcf: 1,
        }),
    ]
    .into_iter()
    .flat_map(|shadows| {
        let tag = if shadows.is_some() { " + DOM" } else { "" };
        [
            (format!("opaque{tag}"), Transparency::Opaque),
            (
                format!("A-buffer{tag}"),
                Transparency::ABuffer {
                    nodes_per_pixel: Some(abuffer_npp),
                },
            ),
            (
                format!("DBK{tag}"),
                Transparency::Dbk {
                    nodes_per_pixel: Some(dbk_npp),
                    delta,
                },
            ),
        ]
        .map(|(name, transparency)| {
            (
                name,
                RenderOptions {
                    shadows,
                    transparency,
                    ..Default::default()
                },
            )
        })
    })
    .collect()
}

fn pass_ms(m: &Measured, pass: &str) -> Option<f64> {
    m.pass_ms.iter().find(|(p, _)| p == pass).map(|(_, ms)| *ms)
}

fn cell(v: Option<f64>) -> String {
    v.map_or("–".to_string(), |v| format!("{v:.1}"))
}

fn count(v: Option<u64>) -> String {
    v.map_or("–".to_string(), |v| v.to_string())
}

fn print_table(results: &[Measured]) {
    println!();
    println!(
        "| configuration | deep opacity ms | strands ms | lists build+resolve+readback ms | readback ms | frame ms (no setup) | fastest frame ms | total ms (incl. pipelines, upload) | GPU MB total | node buffer MB (capacity) | lists used MB (stored × {NODE_BYTES} B + heads) | fragments stored | dropped | truncated at resolve | covered pixels |"
    );
    println!("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    for m in results {
        println!(
            "| {} | {} | {} | {} | {} | {:.1} | {:.1} | {:.1} | {:.2} | {} | {} | {} | {} | {} | {} |",
            m.name,
            cell(pass_ms(m, "deep opacity")),
            cell(pass_ms(m, "strands")),
            cell(pass_ms(m, "abuffer build + resolve")),
            cell(pass_ms(m, "readback")),
            m.frame_ms,
            m.frame_min_ms,
            m.total_ms,
            mb(m.memory_total()),
            m.capacity.map_or("–".to_string(), |c| format!(
                "{:.2} ({c} nodes)",
                mb(m.memory_of("abuffer nodes"))
            )),
            m.lists_used_bytes()
                .map_or("–".to_string(), |b| format!("{:.2}", mb(b))),
            count(m.stored),
            count(m.dropped),
            count(m.truncated),
            m.covered
        );
    }
    println!();
    println!("GPU memory breakdown (MB):");
    println!();
    let mut names: Vec<&str> = Vec::new();
    for m in results {
        for (n, _) in &m.memory {
            if !names.contains(&n.as_str()) {
                names.push(n);
            }
        }
    }
    print!("| buffer / texture |");
    for m in results {
        print!(" {} |", m.name);
    }
    println!();
    print!("|---|");
    for _ in results {
        print!("---:|");
    }
    println!();
    for n in names {
        print!("| {n} |");
        for m in results {
            let b = m.memory_of(n);
            if b == 0 {
                print!(" – |");
            } else {
                print!(" {:.2} |", mb(b));
            }
        }
        println!();
    }
}

fn print_ratios(results: &[Measured]) {
    let find = |name: &str| results.iter().find(|m| m.name == name);
    println!();
    println!("Ratios (same run):");
    println!();
    println!(
        "| shadows | A-buffer / opaque frame time | DBK / A-buffer frame time | DBK / A-buffer GPU memory (total) | DBK / A-buffer lists used | DBK / A-buffer fragments stored |"
    );
    println!("|---|---:|---:|---:|---:|---:|");
    for tag in ["", " + DOM"] {
        let (Some(o), Some(a), Some(d)) = (
            find(&format!("opaque{tag}")),
            find(&format!("A-buffer{tag}")),
            find(&format!("DBK{tag}")),
        ) else {
            continue;
        };
        let ratio = |x: f64, y: f64| format!("{:.2}", x / y);
        println!(
            "| {} | {} | {} | {} | {} | {} |",
            if tag.is_empty() { "none" } else { "DOM" },
            ratio(a.frame_ms, o.frame_ms),
            ratio(d.frame_ms, a.frame_ms),
            ratio(d.memory_total() as f64, a.memory_total() as f64),
            match (d.lists_used_bytes(), a.lists_used_bytes()) {
                (Some(x), Some(y)) => ratio(x as f64, y as f64),
                _ => "–".into(),
            },
            match (d.stored, a.stored) {
                (Some(x), Some(y)) => ratio(x as f64, y as f64),
                _ => "–".into(),
            },
        );
    }
    println!();
    println!(
        "Hunz 2016 §6.3 (GTX 960, straight.hair from the side, 656 × 861): A-buffer 12,959,208 fragments, 150.46 MB; DBK 4,518,344 fragments, 53.86 MB with heads (59.25 MB with the opaque fallback): DBK / A-buffer memory 0.36, fragments 0.35; DBK the faster."
    );
}
