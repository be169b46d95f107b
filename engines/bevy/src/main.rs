//! strandlight's exported LUTs in Bevy: a groom drawn by a Bevy `Material` that samples the KTX2
//! convolution table through `strandlight_lut.wgsl` under an environment fit's SRBF lights, and
//! compared with strandlight's own unshadowed frame of the same scene. See README.md and
//! scripts/bevy-example.sh, which runs the three steps:
//!
//! ```text
//! strandlight-bevy scene   --hair H.hair --env MAP --size WxH --fiber-width-px F --out settings.json
//! strandlight-bevy render  --settings settings.json --fit FIT.srbf.json --lut DIR/ktx2 [--table chiang]
//!                          [--deliberate-error mirror|swap-axes] --out bevy.exr
//! strandlight-bevy compare --settings settings.json --strandlight S.exr --bevy bevy.exr --png SIDE.png
//!                          [--max-rmse R] [--max-error E]
//! ```

mod compare;
mod render;
mod scene;

use anyhow::{Context, bail};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// Relative RMSE over the straight one-fiber pixels that passes (README.md, "Tolerance").
const DEFAULT_MAX_RMSE: f64 = 0.005;
/// Largest per-pixel error (of the pixel's brightest channel) there that passes.
const DEFAULT_MAX_ERROR: f64 = 0.02;

fn main() {
    if let Err(e) = run() {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}

fn options(args: &[String]) -> anyhow::Result<HashMap<String, String>> {
    let mut map = HashMap::new();
    let mut it = args.iter();
    while let Some(k) = it.next() {
        let key = k
            .strip_prefix("--")
            .with_context(|| format!("unexpected argument {k}"))?;
        let value = it.next().with_context(|| format!("{k} needs a value"))?;
        map.insert(key.to_string(), value.clone());
    }
    Ok(map)
}

fn get<'a>(o: &'a HashMap<String, String>, key: &str) -> anyhow::Result<&'a str> {
    o.get(key)
        .map(String::as_str)
        .with_context(|| format!("--{key} is required"))
}

fn run() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(command) = args.first() else {
        bail!("usage: strandlight-bevy scene|render|compare OPTIONS (see src/main.rs)");
    };
    let o = options(&args[1..])?;
    match command.as_str() {
        "scene" => {
            let hair_path = std::fs::canonicalize(get(&o, "hair")?).context("--hair")?;
            let hair = scene::Hair::read_yuksel(&hair_path)?;
            let size = get(&o, "size")?
                .split_once('x')
                .and_then(|(w, h)| Some([w.parse().ok()?, h.parse().ok()?]))
                .context("--size WxH")?;
            let width: f32 = o.get("fiber-width-px").map_or(Ok(1.0), |s| s.parse())?;
            let env = get(&o, "env")?;
            let map = if env.starts_with("procedural:") {
                env.to_string()
            } else {
                std::fs::canonicalize(env)
                    .context("--env")?
                    .display()
                    .to_string()
            };
            let json = scene::settings_json(&hair_path, &hair, &map, size, width);
            let out = PathBuf::from(get(&o, "out")?);
            std::fs::write(&out, serde_json::to_string_pretty(&json)?)?;
            println!(
                "wrote {} ({} strands, {} points, {} up)",
                out.display(),
                hair.offsets.len() - 1,
                hair.points.len(),
                if hair.z_up() { "Z" } else { "Y" }
            );
        }
        "render" => {
            let settings = scene::read_settings(Path::new(get(&o, "settings")?))?;
            let hair = scene::Hair::read_yuksel(&settings.hair)?;
            let lobes = scene::read_fit(
                Path::new(get(&o, "fit")?),
                hair.z_up(),
                settings.rotation_deg,
            )?;
            let error = render::DeliberateError::parse(
                o.get("deliberate-error").map_or("none", String::as_str),
            )?;
            let [w, h] = settings.size;
            let lut_dir = PathBuf::from(get(&o, "lut")?);
            let table = o.get("table").map_or("chiang", String::as_str).to_string();
            let n = lobes.len();
            let start = std::time::Instant::now();
            let pixels = render::render(settings, hair, lobes, &lut_dir, &table, error)?;
            let image = compare::Image {
                width: w as usize,
                height: h as usize,
                rgba: pixels
                    .chunks_exact(4)
                    .map(|p| [p[0], p[1], p[2], p[3]])
                    .collect(),
            };
            let out = PathBuf::from(get(&o, "out")?);
            compare::write_exr(&out, &image)?;
            println!(
                "bevy: {n} SRBF lobes from {}/{table}.ktx2, {} hair pixels, {:.1} s (app start to read-back), deliberate error: {error:?} → {}",
                lut_dir.display(),
                image.rgba.iter().filter(|p| p[3] > 0.5).count(),
                start.elapsed().as_secs_f64(),
                out.display()
            );
        }
        "compare" => {
            let settings = scene::read_settings(Path::new(get(&o, "settings")?))?;
            let hair = scene::Hair::read_yuksel(&settings.hair)?;
            let s = compare::read_exr(Path::new(get(&o, "strandlight")?))?;
            let b = compare::read_exr(Path::new(get(&o, "bevy")?))?;
            if (s.width, s.height) != (b.width, b.height) {
                bail!(
                    "sizes differ: {}x{} and {}x{}",
                    s.width,
                    s.height,
                    b.width,
                    b.height
                );
            }
            let max_rmse: f64 = o
                .get("max-rmse")
                .map_or(Ok(DEFAULT_MAX_RMSE), |v| v.parse())?;
            let max_error: f64 = o
                .get("max-error")
                .map_or(Ok(DEFAULT_MAX_ERROR), |v| v.parse())?;
            let geometry = compare::pixel_geometry(&hair, &settings);
            let (f, mask) = compare::compare(&s, &b, &geometry);
            compare::write_side_by_side(Path::new(get(&o, "png")?), &s, &b, &mask)?;
            println!(
                "hair pixels: strandlight {}, bevy {}; one-fiber pixels (both draw it, strandlight covers ≥ {}, no other fiber within {} px): {}",
                f.strandlight_hair_pixels,
                f.bevy_hair_pixels,
                compare::MIN_COVERAGE,
                compare::REACH_PX,
                f.one_fiber.pixels
            );
            let line = |name: &str, e: &compare::Errors| {
                println!(
                    "{name}: {} pixels, relative RMSE {:.2e}, per-pixel error p50 {:.2e} p99 {:.2e} max {:.2e} (at {}, {}), Σbevy/Σstrandlight {:.5}",
                    e.pixels,
                    e.relative_rmse,
                    e.p50,
                    e.p99,
                    e.max,
                    e.worst_at.0,
                    e.worst_at.1,
                    e.mean_ratio
                )
            };
            line("all one-fiber pixels", &f.one_fiber);
            line(
                &format!(
                    "straight (tangent turns < {}°/px, > {} px from strand ends)",
                    compare::STRAIGHT_DEG_PER_PX,
                    compare::REACH_PX
                ),
                &f.straight,
            );
            println!(
                "tolerance on the straight pixels: relative RMSE ≤ {max_rmse:.1e}, max per-pixel error ≤ {max_error:.1e}"
            );
            println!("wrote {}", get(&o, "png")?);
            let e = &f.straight;
            let pass = e.pixels >= 100 && e.relative_rmse <= max_rmse && e.max <= max_error;
            if !pass {
                println!("FAIL: the Bevy frame does not match strandlight's");
                std::process::exit(1);
            }
            println!("PASS");
        }
        other => bail!("unknown command {other}: scene, render or compare"),
    }
    Ok(())
}
