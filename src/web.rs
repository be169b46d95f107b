//! `strandlight web`: a static site that renders the demo's scene (or a replayed settings file)
//! in a browser through WebGPU — the page's wasm module and glue, its HTML, and the bundle of
//! `strandlight_scene::web_bundle`. `strandlight serve` serves a folder on localhost.

use crate::demo::{CACHE_DIR, DEMO_ENVIRONMENT, DEMO_HEAD, DEMO_PRESET, DEMO_SHADING, ENVMAP_DIR};
use anyhow::Context;
use std::path::{Path, PathBuf};
use strandlight_runtime::hair::yuksel::{HairWriteOptions, encode_hair};
use strandlight_scene::env_scene::{AlsoServe, PreparedEnv, prepare_env};
use strandlight_scene::environment::ensure_procedural_envmap;
use strandlight_scene::frame_render::{coarse_preview_settings, load_settings_hair};
use strandlight_scene::frame_settings::{EnvLighting, FrameSettings, Lighting};
use strandlight_scene::look::{ForwardDevice, LobeVisibilityArg};
use strandlight_scene::scene_tables::ScatteringMode;
use strandlight_scene::steps::Steps;
use strandlight_scene::web_bundle::{
    BundledPreset, HAIR_FILE, SCENE_FILE, SETTINGS_FILE, TABLES_DIR, bundle_scene,
};
use strandlight_tables::atomic_write::write_atomically;

/// Where `scripts/web.sh` leaves the page's wasm module and glue (wasm-bindgen's output).
pub const DEFAULT_PAGE_DIR: &str = "target/web/pkg";
/// The page's HTML (its controls and the harness's hooks), beside the crate that drives it.
const INDEX_HTML: &str = include_str!("../web/index.html");
/// The files of the wasm-bindgen output the page loads.
const PAGE_FILES: [&str; 2] = ["strandlight_web.js", "strandlight_web_bg.wasm"];

#[derive(clap::Args, Debug)]
pub struct WebArgs {
    /// The site's folder (created; its bundle is replaced).
    #[arg(long, default_value = "site")]
    pub out: PathBuf,
    /// A settings file to start from (`render replay`'s); default: the demo's scene.
    #[arg(long)]
    pub replay: Option<PathBuf>,
    /// Image size WxH in pixels (default: the settings').
    #[arg(long)]
    pub size: Option<String>,
    /// Fiber presets whose tables the page can switch between (the first is shown first).
    #[arg(long, value_delimiter = ',', default_value = DEMO_PRESET)]
    pub preset: Vec<String>,
    /// The built page (wasm-bindgen's output of the `strandlight-web` crate).
    #[arg(long, default_value = DEFAULT_PAGE_DIR)]
    pub page: PathBuf,
}

#[derive(clap::Args, Debug)]
pub struct ServeArgs {
    /// The folder to serve.
    #[arg(default_value = "site")]
    pub dir: PathBuf,
    /// TCP port on 127.0.0.1 (0: any free port, printed).
    #[arg(long, default_value_t = 8000)]
    pub port: u16,
}

pub fn run(args: WebArgs) -> anyhow::Result<()> {
    let mut steps = Steps::new(false);
    for file in PAGE_FILES {
        let path = args.page.join(file);
        anyhow::ensure!(
            path.is_file(),
            "{} is missing: build the page first with `scripts/web.sh` (or pass --page DIR)",
            path.display()
        );
    }
    let mut settings = match &args.replay {
        Some(path) => FrameSettings::read(path)?,
        None => web_settings()?,
    };
    if let Some(size) = &args.size {
        settings.size = parse_size(size)?;
    }
    settings.check()?;
    let Lighting::Environment(env) = &mut settings.lighting else {
        anyhow::bail!("the page renders env-lit frames; the settings are point-lit");
    };
    if env.scattering == ScatteringMode::Full && env.view.forward_scattering != ForwardDevice::Gpu {
        // So that `render replay` of the bundle's settings renders the page's frame.
        steps.say(
            "the page marches multiple scattering on the GPU: the bundle's settings say so"
                .to_string(),
        );
        env.view.forward_scattering = ForwardDevice::Gpu;
    }
    let hair = steps.run(
        "hair",
        || load_settings_hair(&settings),
        |h| format!("{} ({} strands)", h.source, h.model.strand_count()),
    )?;
    let mut prepared = Vec::new();
    for preset in &args.preset {
        let full = prepare_preset(&settings, &hair.model, preset, &mut steps)?;
        let coarse = coarse_preview_settings(&settings);
        let first_look = prepare_preset(&coarse, &hair.model, preset, &mut steps)?;
        prepared.push((preset.clone(), full, first_look));
    }
    let first_preset = &args.preset[0];
    settings.preset = first_preset.clone();
    let presets: Vec<BundledPreset> = (prepared.iter())
        .map(|(name, full, first_look)| BundledPreset {
            name: name.clone(),
            full,
            first_look,
        })
        .collect();
    let (scene, tables) = bundle_scene(&prepared[0].1.map()?.name, &presets)?;
    let out = &args.out;
    let written = steps.run(
        "site",
        || {
            write_site(out, &args.page, &settings, &hair.model, &scene, &tables)
                .with_context(|| format!("writing the site to {}", out.display()))
        },
        |bytes| format!("{} ({:.1} MB)", out.display(), *bytes as f64 / 1e6),
    )?;
    for (preset, entries) in &scene.presets {
        for t in entries {
            steps.say(format!(
                "{preset}: {} as {:?}, {:.2} MB, max error {:.1e} of the table's largest value",
                t.name,
                t.storage,
                t.bytes as f64 / 1e6,
                t.max_relative_error
            ));
        }
    }
    steps.say(format!(
        "{:.1} MB in all; serve it with `strandlight serve {}` and open http://127.0.0.1:8000/",
        written as f64 / 1e6,
        out.display()
    ));
    Ok(())
}

/// The demo's scene as the page starts it: single + multiple scattering with the grid marched
/// on the GPU (as the page marches it), light maps for every lobe (the visibility volume is
/// built on the CPU, which in a page would block its only thread), the nearest fiber per pixel.
fn web_settings() -> anyhow::Result<FrameSettings> {
    let (path, _) = ensure_procedural_envmap(Path::new(ENVMAP_DIR), DEMO_ENVIRONMENT)?;
    let mut lighting = EnvLighting {
        scattering: ScatteringMode::Full,
        ..EnvLighting::new(path.to_string_lossy())
    };
    lighting.view.lobe_visibility = LobeVisibilityArg::LightMaps;
    lighting.view.forward_scattering = ForwardDevice::Gpu;
    Ok(FrameSettings {
        shading: Some(DEMO_SHADING),
        preset: DEMO_PRESET.into(),
        head: DEMO_HEAD,
        ..FrameSettings::new(Lighting::Environment(lighting), [640, 480])
    })
}

fn parse_size(text: &str) -> anyhow::Result<[u32; 2]> {
    let parsed = text.split_once('x').and_then(|(w, h)| {
        let (w, h) = (w.parse::<u32>().ok()?, h.parse::<u32>().ok()?);
        (w > 0 && h > 0 && w <= 4096 && h <= 4096).then_some([w, h])
    });
    parsed.with_context(|| format!("--size {text:?}: expected WxH, each in 1..=4096"))
}

/// The fit and `preset`'s tables as `render` prepares them, in its cache: `render replay` of the
/// bundle's settings draws with the bundle's tables.
fn prepare_preset(
    settings: &FrameSettings,
    hair: &strandlight_runtime::hair::HairModel,
    preset: &str,
    steps: &mut Steps,
) -> anyhow::Result<PreparedEnv> {
    steps.say(format!("preset {preset}"));
    let settings = FrameSettings {
        preset: preset.to_string(),
        ..settings.clone()
    };
    prepare_env(
        &settings,
        hair,
        Path::new(CACHE_DIR),
        AlsoServe::default(),
        steps,
        &mut |_| {},
    )
}

/// Writes the page and the bundle; returns the bytes written.
fn write_site(
    out: &Path,
    page: &Path,
    settings: &FrameSettings,
    hair: &strandlight_runtime::hair::HairModel,
    scene: &strandlight_scene::web_bundle::BundleScene,
    tables: &[(String, Vec<u8>)],
) -> anyhow::Result<u64> {
    let bundle = out.join("bundle");
    if bundle.exists() {
        std::fs::remove_dir_all(&bundle)
            .with_context(|| format!("cannot replace {}", bundle.display()))?;
    }
    std::fs::create_dir_all(bundle.join(TABLES_DIR))?;
    let mut files: Vec<(PathBuf, Vec<u8>)> = vec![
        (out.join("index.html"), INDEX_HTML.as_bytes().to_vec()),
        (
            bundle.join(SETTINGS_FILE),
            serde_json::to_vec_pretty(settings)?,
        ),
        (bundle.join(SCENE_FILE), serde_json::to_vec_pretty(scene)?),
    ];
    let hair_path = bundle.join(HAIR_FILE);
    let options = HairWriteOptions {
        segments_array: true,
        info: "strandlight web bundle".into(),
    };
    files.push((hair_path.clone(), encode_hair(hair, &options, &hair_path)?));
    for (name, bytes) in tables {
        files.push((bundle.join(TABLES_DIR).join(name), bytes.clone()));
    }
    for name in PAGE_FILES {
        let from = page.join(name);
        let bytes = std::fs::read(&from).with_context(|| format!("reading {}", from.display()))?;
        files.push((out.join(name), bytes));
    }
    let mut total = 0;
    for (path, bytes) in &files {
        write_atomically(path, |out: &mut std::io::BufWriter<std::fs::File>| {
            std::io::Write::write_all(out, bytes)
        })
        .with_context(|| format!("writing {}", path.display()))?;
        total += bytes.len() as u64;
    }
    Ok(total)
}

/// Serves `dir` on 127.0.0.1 until interrupted: GET of the files under it, one request per
/// connection, a thread each (wasm with its MIME type, which browsers need to compile it while
/// it downloads). Hand-written after tiny_http 0.12 stalled a page's parallel fetches of its
/// tables now and then (2 of 11 files never answered, with and without keep-alive).
pub fn serve(args: ServeArgs) -> anyhow::Result<()> {
    let root = args
        .dir
        .canonicalize()
        .with_context(|| format!("{} is not a folder to serve", args.dir.display()))?;
    let listener = std::net::TcpListener::bind(("127.0.0.1", args.port))
        .with_context(|| format!("cannot listen on 127.0.0.1:{}", args.port))?;
    println!(
        "serving {} at http://{}/",
        root.display(),
        listener.local_addr()?
    );
    for stream in listener.incoming() {
        let Ok(stream) = stream else { continue };
        let root = root.clone();
        std::thread::spawn(move || {
            let _ = answer(&root, stream);
        });
    }
    Ok(())
}

/// Reads one request from `stream` and answers it with the file, 404 or 405.
fn answer(root: &Path, mut stream: std::net::TcpStream) -> std::io::Result<()> {
    use std::io::{BufRead, Write};
    let mut reader = std::io::BufReader::new(stream.try_clone()?);
    let mut request_line = String::new();
    reader.read_line(&mut request_line)?;
    // The headers are read to their end and ignored.
    let mut header = String::new();
    while reader.read_line(&mut header)? > 2 {
        header.clear();
    }
    let mut parts = request_line.split_whitespace();
    let (method, url) = (parts.next().unwrap_or(""), parts.next().unwrap_or("/"));
    let (status, content_type, body) = match method {
        "GET" | "HEAD" => match file_of(root, url) {
            Some(path) => match std::fs::read(&path) {
                Ok(bytes) => ("200 OK", mime_type(&path), bytes),
                Err(_) => ("404 Not Found", "text/plain", b"not found".to_vec()),
            },
            None => ("404 Not Found", "text/plain", b"not found".to_vec()),
        },
        _ => ("405 Method Not Allowed", "text/plain", Vec::new()),
    };
    write!(
        stream,
        "HTTP/1.1 {status}\r\nContent-Type: {content_type}\r\nContent-Length: {}\r\n\
         Connection: close\r\n\r\n",
        body.len()
    )?;
    if method != "HEAD" {
        stream.write_all(&body)?;
    }
    stream.flush()
}

/// The file under `root` that `url` names (`/` is `index.html`); None for anything that would
/// leave the root.
fn file_of(root: &Path, url: &str) -> Option<PathBuf> {
    let path = url.split(['?', '#']).next().unwrap_or("/");
    let relative = match path.trim_start_matches('/') {
        "" => "index.html",
        relative => relative,
    };
    let safe = Path::new(relative)
        .components()
        .all(|c| matches!(c, std::path::Component::Normal(_)));
    safe.then(|| root.join(relative))
}

fn mime_type(path: &Path) -> &'static str {
    match path.extension().and_then(|e| e.to_str()) {
        Some("html") => "text/html; charset=utf-8",
        Some("js") => "text/javascript",
        Some("wasm") => "application/wasm",
        Some("json") => "application/json",
        _ => "application/octet-stream",
    }
}
