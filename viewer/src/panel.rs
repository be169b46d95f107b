//! The side panel (every choice `render` offers, the artist controls, display and screenshot)
//! and the readout beside the image (adapter, frame time per pass, GPU memory, lights and batches).
//! Each group says what its changes cost ([`Recompute::label`]).

use crate::frame::{FrameStats, Stage};
use crate::recompute::{Backdrop, Recompute, ViewState};
use crate::worker::Status;
use egui_file_dialog::FileDialog;
use std::path::PathBuf;
use strandlight_runtime::hair::{self, GroomStyle};
use strandlight_runtime::passes::deep_opacity::MAX_LAYERS;
use strandlight_scene::frame_settings::{
    EnvLighting, Lighting, PointLighting, Shadows, Transparency,
};
use strandlight_scene::hair_input::{PROCEDURAL_PREFIX, procedural_style};
use strandlight_scene::head_input::HeadChoice;
use strandlight_scene::look::{EnvTransparency, LobeVisibilityArg};
use strandlight_scene::point_shading::Shading;
use strandlight_scene::scene_tables::ScatteringMode;
use strandlight_tables::artist::ArtistParams;

const PRESETS: [&str; 6] = ["white", "blonde", "red", "auburn", "brown", "dark"];
const MAPS: [&str; 2] = ["procedural:sun_and_sky", "procedural:studio"];

/// What the panel asks of the session besides settings edits.
#[derive(Default)]
pub struct PanelOutcome {
    pub open: Option<PathBuf>,
    pub screenshot: bool,
    pub reset_camera: bool,
}

#[derive(Default)]
pub struct Panel {
    dialog: Option<FileDialog>,
    /// Lobes when "all" is unticked.
    lobes: usize,
}

impl Panel {
    pub fn show(
        &mut self,
        root: &mut egui::Ui,
        state: &mut ViewState,
        status: &Status,
        message: &Option<String>,
    ) -> PanelOutcome {
        let mut outcome = PanelOutcome::default();
        let ctx = root.ctx().clone();
        egui::Panel::left("controls")
            .default_size(300.0)
            .show(root, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| {
                    self.status_lines(ui, status, message);
                    self.scene(ui, state, &mut outcome);
                    lighting(ui, state, &mut self.lobes, status);
                    artist(ui, state);
                    display(ui, state, &mut outcome);
                });
            });
        if let Some(dialog) = &mut self.dialog {
            dialog.update(&ctx);
            if let Some(path) = dialog.take_picked() {
                outcome.open = Some(path);
                self.dialog = None;
            }
        }
        outcome
    }

    fn status_lines(&self, ui: &mut egui::Ui, status: &Status, message: &Option<String>) {
        if let Some(bake) = &status.bake {
            ui.label(format!(
                "baking in the background ({:.0} s); the old tables stay on screen",
                bake.started.elapsed().as_secs_f32()
            ));
            ui.add(egui::ProgressBar::new(bake.fraction).text(&bake.what));
        }
        if let Some(shown) = &status.shown {
            let (fraction, text) = match shown.stage {
                Stage::Preview => (0.0, "preview".to_string()),
                Stage::Refining { done, total } => (
                    done as f32 / total as f32,
                    format!("refining: {done}/{total} light batches"),
                ),
                Stage::Converged => (1.0, format!("converged in {:.2} s", shown.seconds)),
            };
            ui.add(egui::ProgressBar::new(fraction).text(text));
        }
        if let Some(m) = message {
            ui.colored_label(egui::Color32::LIGHT_RED, m);
        }
        ui.separator();
    }

    fn scene(&mut self, ui: &mut egui::Ui, state: &mut ViewState, outcome: &mut PanelOutcome) {
        let s = &mut state.settings;
        ui.heading("Scene");
        ui.label(format!(
            "hair: {}",
            s.hair.as_ref().map_or(
                format!("{PROCEDURAL_PREFIX}{}", GroomStyle::default().name()),
                |p| { p.display().to_string() }
            )
        ));
        ui.horizontal(|ui| {
            if ui.button("Open hair or map…").clicked() {
                let mut dialog = FileDialog::new()
                    .add_file_filter_extensions(
                        "hair and maps",
                        hair::EXTENSIONS
                            .iter()
                            .chain(&["hdr", "exr", "obj"])
                            .copied()
                            .collect(),
                    )
                    .default_file_filter("hair and maps");
                dialog.pick_file();
                self.dialog = Some(dialog);
            }
        });
        if groom_style(ui, &mut s.hair) {
            outcome.reset_camera = true;
        }
        ui.small(
            "or drop a .hair/.tfx/.data/.ply/.usd*/.abc, .hdr/.exr or head .obj file on the window",
        );
        head(ui, &mut s.head);
        let mut shading = s.shading();
        egui::ComboBox::from_label("fiber model")
            .selected_text(format!("{shading:?}"))
            .show_ui(ui, |ui| {
                for m in [
                    Shading::KajiyaKay,
                    Shading::Marschner,
                    Shading::Chiang,
                    Shading::Artist,
                ] {
                    let allowed = !(m == Shading::KajiyaKay
                        && matches!(s.lighting, Lighting::Environment(_)));
                    ui.add_enabled_ui(allowed, |ui| {
                        ui.selectable_value(&mut shading, m, format!("{m:?}"));
                    });
                }
            });
        s.shading = Some(shading);
        egui::ComboBox::from_label("melanin preset")
            .selected_text(&s.preset)
            .show_ui(ui, |ui| {
                for p in PRESETS {
                    ui.selectable_value(&mut s.preset, p.to_string(), p);
                }
            });
        ui.separator();
    }
}

/// The procedural groom's style (`procedural:NAME`); true when the user picked one.
fn groom_style(ui: &mut egui::Ui, hair: &mut Option<PathBuf>) -> bool {
    let current = match hair {
        None => Some(GroomStyle::default()),
        Some(path) => procedural_style(path).ok().flatten(),
    };
    let mut picked = false;
    egui::ComboBox::from_label("procedural groom")
        .selected_text(current.map_or("(a file)", GroomStyle::name))
        .show_ui(ui, |ui| {
            for style in GroomStyle::ALL {
                if ui
                    .selectable_label(current == Some(style), style.name())
                    .clicked()
                {
                    *hair = Some(format!("{PROCEDURAL_PREFIX}{}", style.name()).into());
                    picked = true;
                }
            }
        });
    picked
}

/// The head the hair grows from: none, the ellipsoid fitted to the roots, or the mesh the flags or
/// a dropped .obj gave.
fn head(ui: &mut egui::Ui, head: &mut HeadChoice) {
    let mut choices = vec![HeadChoice::None, HeadChoice::Ellipsoid];
    if let HeadChoice::Mesh(_) = head {
        choices.push(head.clone());
    }
    egui::ComboBox::from_label(format!("head ({})", Recompute::ShadowMaps.label()))
        .selected_text(head.to_string())
        .show_ui(ui, |ui| {
            for choice in choices {
                let text = choice.to_string();
                ui.selectable_value(head, choice, text);
            }
        });
}

fn lighting(ui: &mut egui::Ui, state: &mut ViewState, lobes: &mut usize, status: &Status) {
    let s = &mut state.settings;
    ui.heading("Lighting");
    let mut env = matches!(s.lighting, Lighting::Environment(_));
    ui.horizontal(|ui| {
        ui.radio_value(&mut env, true, "environment (SRBF)");
        ui.radio_value(&mut env, false, "point / directional / spot");
    });
    match (&s.lighting, env) {
        (Lighting::Lights(_), true) => s.light_with_environment(MAPS[0].into()),
        (Lighting::Environment(_), false) => {
            s.lighting = Lighting::Lights(PointLighting::default())
        }
        _ => {}
    }
    let total_lobes = status
        .shown
        .as_ref()
        .and_then(|sh| sh.env.as_ref())
        .map_or(64, |e| e.scene.fit.lobes.len());
    match &mut s.lighting {
        Lighting::Environment(e) => env_controls(ui, e, lobes, total_lobes),
        Lighting::Lights(p) => point_controls(ui, p),
    }
    ui.separator();
}

fn env_controls(ui: &mut egui::Ui, e: &mut EnvLighting, lobes: &mut usize, total: usize) {
    egui::ComboBox::from_label("map")
        .selected_text(&e.map)
        .show_ui(ui, |ui| {
            for m in MAPS {
                ui.selectable_value(&mut e.map, m.to_string(), m);
            }
        });
    ui.label(Recompute::Tables.label());
    ui.horizontal(|ui| {
        ui.radio_value(&mut e.scattering, ScatteringMode::Single, "single");
        ui.radio_value(&mut e.scattering, ScatteringMode::Full, "single + multiple");
    });
    ui.label(Recompute::ShadowMaps.label());
    // The page's range; a turn outside it (a settings file's −30°) is kept as it is, never
    // clamped: a slider that clamped drew a replayed 211° at 180°.
    ui.add(
        egui::Slider::new(&mut e.rotation_deg, 0.0..=360.0)
            .clamping(egui::SliderClamping::Never)
            .text("rotate map °"),
    );
    let mut all = e.lobes.is_none();
    ui.horizontal(|ui| {
        ui.checkbox(&mut all, "all lobes");
        if *lobes == 0 {
            *lobes = e.lobes.unwrap_or(total.min(16)).max(1);
        }
        ui.add_enabled(
            !all,
            egui::Slider::new(lobes, 1..=total.max(1)).text("lobes"),
        );
    });
    e.lobes = (!all).then_some(*lobes);
    ui.add(
        egui::Slider::new(&mut e.kappa, 0.02..=1.0)
            .logarithmic(true)
            .text("κ (strands in light maps)"),
    );
    egui::ComboBox::from_label("DODM resolution")
        .selected_text(e.dodm_size.to_string())
        .show_ui(ui, |ui| {
            for r in [128, 256, 512, 1024] {
                ui.selectable_value(&mut e.dodm_size, r, r.to_string());
            }
        });
    ui.label(Recompute::Frame.label());
    ui.horizontal(|ui| {
        ui.radio_value(&mut e.transparency, EnvTransparency::Opaque, "opaque");
        ui.radio_value(&mut e.transparency, EnvTransparency::Layered, "layered")
            .on_hover_text("every fiber weighted through the occupancy map, shaded in 4 layers");
        ui.radio_value(&mut e.transparency, EnvTransparency::Occupancy, "occupancy");
    });
    ui.horizontal(|ui| {
        ui.label("lobe visibility");
        ui.radio_value(&mut e.view.lobe_visibility, LobeVisibilityArg::Auto, "auto")
            .on_hover_text("the volume; light maps under a head");
        ui.radio_value(
            &mut e.view.lobe_visibility,
            LobeVisibilityArg::LightMaps,
            "light maps",
        );
        ui.radio_value(
            &mut e.view.lobe_visibility,
            LobeVisibilityArg::Volume,
            "volume",
        );
    });
}

fn point_controls(ui: &mut egui::Ui, p: &mut PointLighting) {
    ui.label(format!(
        "{} (edit a spec, Enter to apply)",
        Recompute::ShadowMaps.label()
    ));
    let mut remove = None;
    for (i, spec) in p.lights.iter_mut().enumerate() {
        ui.horizontal(|ui| {
            let mut text = spec.clone();
            let response = ui.text_edit_singleline(&mut text);
            if response.lost_focus() && strandlight_runtime::lights::Light::parse(&text).is_ok() {
                *spec = text;
            }
            if ui.small_button("✕").clicked() {
                remove = Some(i);
            }
        });
    }
    if let Some(i) = remove.filter(|_| p.lights.len() > 1) {
        p.lights.remove(i);
    }
    if ui.button("add a point light").clicked() {
        p.lights.push("point:0,1,2:4".into());
    }
    ui.horizontal_wrapped(|ui| {
        ui.label("shadows");
        ui.radio_value(&mut p.shadows, Shadows::None, "none");
        ui.radio_value(&mut p.shadows, Shadows::Dom, "deep opacity maps");
        ui.radio_value(&mut p.shadows, Shadows::Osm, "opacity shadow maps");
        ui.radio_value(&mut p.shadows, Shadows::Sm, "shadow maps");
        ui.radio_value(&mut p.shadows, Shadows::Adsm, "ADSM");
    });
    if p.shadows == Shadows::Dom {
        ui.add(egui::Slider::new(&mut p.dom_layers, 1..=MAX_LAYERS).text("DOM layers"));
    }
    if p.shadows == Shadows::Osm {
        ui.add(egui::Slider::new(&mut p.osm_slices, 1..=MAX_LAYERS).text("OSM slices"));
    }
    if matches!(p.shadows, Shadows::Sm | Shadows::Adsm) {
        ui.add(
            egui::Slider::new(&mut p.pcf_kernel, 1..=9)
                .step_by(2.0)
                .text("PCF kernel"),
        );
    }
    if p.shadows == Shadows::Adsm {
        ui.add(egui::Slider::new(&mut p.adsm_alpha, 0.01..=0.95).text("ADSM fiber opacity"));
    }
    if p.shadows != Shadows::None {
        egui::ComboBox::from_label("map resolution")
            .selected_text(p.dom_size.to_string())
            .show_ui(ui, |ui| {
                for r in [256, 512, 1024, 2048] {
                    ui.selectable_value(&mut p.dom_size, r, r.to_string());
                }
            });
    }
    ui.label(Recompute::Frame.label());
    ui.horizontal_wrapped(|ui| {
        ui.label("transparency");
        ui.radio_value(&mut p.transparency, Transparency::None, "opaque");
        ui.radio_value(&mut p.transparency, Transparency::Sorted, "sorted");
        ui.radio_value(&mut p.transparency, Transparency::Abuffer, "A-buffer");
        ui.radio_value(&mut p.transparency, Transparency::Kbuffer, "K-buffer");
        ui.radio_value(&mut p.transparency, Transparency::Dbk, "DBK");
        ui.radio_value(&mut p.transparency, Transparency::Subsets, "random subsets");
    });
    match p.transparency {
        Transparency::Sorted => {
            ui.add(
                egui::Slider::new(&mut p.sort_bins, 1..=4096)
                    .logarithmic(true)
                    .text("depth bins"),
            );
        }
        Transparency::Kbuffer => {
            ui.add(egui::Slider::new(&mut p.kbuffer_k, 1..=64).text("k"));
        }
        Transparency::Subsets => {
            ui.add(egui::Slider::new(&mut p.subsets, 1..=16).text("subsets"));
        }
        _ => {}
    }
}

/// Sadeghi's controls: shader constants under point lights, baked into the tables under an
/// environment.
fn artist(ui: &mut egui::Ui, state: &mut ViewState) {
    let s = &mut state.settings;
    if s.shading() != Shading::Artist {
        return;
    }
    let cost = match s.lighting {
        Lighting::Lights(_) => Recompute::Frame,
        Lighting::Environment(_) => Recompute::Tables,
    };
    ui.heading("Artist controls (Sadeghi 2010)");
    ui.label(cost.label());
    let mut a = s.artist.unwrap_or_default();
    lobe(
        ui,
        "primary highlight R",
        &mut a.r.color,
        &mut a.r.intensity,
        &mut a.r.shift_deg,
        &mut a.r.width_deg,
    );
    lobe(
        ui,
        "transmission TT",
        &mut a.tt.color,
        &mut a.tt.intensity,
        &mut a.tt.shift_deg,
        &mut a.tt.width_deg,
    );
    ui.add(
        egui::Slider::new(&mut a.tt.azimuthal_width_deg, 1.0..=90.0).text("TT azimuthal width °"),
    );
    lobe(
        ui,
        "secondary highlight TRT",
        &mut a.trt.color,
        &mut a.trt.intensity,
        &mut a.trt.shift_deg,
        &mut a.trt.width_deg,
    );
    ui.add(egui::Slider::new(&mut a.glints.relative_intensity, 0.0..=5.0).text("glint intensity"));
    ui.add(egui::Slider::new(&mut a.glints.half_angle_deg, 30.0..=45.0).text("glint half angle °"));
    if ui.button("default controls").clicked() {
        a = ArtistParams::default();
    }
    s.artist = (a != ArtistParams::default()).then_some(a);
    ui.separator();
}

fn lobe(
    ui: &mut egui::Ui,
    name: &str,
    color: &mut [f64; 3],
    intensity: &mut f64,
    shift: &mut f64,
    width: &mut f64,
) {
    ui.horizontal(|ui| {
        let mut rgb = color.map(|c| c as f32);
        if ui.color_edit_button_rgb(&mut rgb).changed() {
            *color = rgb.map(f64::from);
        }
        ui.label(name);
    });
    ui.add(egui::Slider::new(intensity, 0.0..=5.0).text("intensity"));
    ui.add(egui::Slider::new(shift, -15.0..=15.0).text("longitudinal shift °"));
    ui.add(egui::Slider::new(width, 0.5..=30.0).text("longitudinal width °"));
}

fn display(ui: &mut egui::Ui, state: &mut ViewState, outcome: &mut PanelOutcome) {
    let d = &mut state.display;
    ui.heading("Display");
    ui.label(Recompute::Nothing.label());
    let mut auto = d.exposure_stops.is_none();
    ui.checkbox(&mut auto, "automatic exposure");
    let mut stops = d.exposure_stops.unwrap_or(0.0);
    ui.add_enabled(
        !auto,
        egui::Slider::new(&mut stops, -10.0..=10.0).text("exposure (stops)"),
    );
    d.exposure_stops = (!auto).then_some(stops);
    ui.horizontal_wrapped(|ui| {
        ui.label("backdrop (B)");
        for backdrop in Backdrop::ALL {
            ui.radio_value(&mut d.backdrop, backdrop, backdrop.name());
        }
    });
    ui.checkbox(&mut d.overlay, "timing readout (O)");
    ui.horizontal(|ui| {
        outcome.screenshot = ui.button("Screenshot (S)").clicked();
        outcome.reset_camera = outcome.reset_camera || ui.button("Reset camera (R)").clicked();
    });
    ui.small("drag: orbit · right drag: pan · scroll: zoom");
}

/// What the image area shows before the first frame: the worker's stage, centred.
pub fn waiting_text(ui: &egui::Ui, rect: egui::Rect, status: &Status) {
    if status.shown.is_some() {
        return;
    }
    let text = if status.bake.is_some() {
        "fitting and baking…"
    } else {
        "starting…"
    };
    ui.painter().text(
        rect.center(),
        egui::Align2::CENTER_CENTER,
        text,
        egui::FontId::proportional(16.0),
        egui::Color32::WHITE,
    );
}

/// Adapter, stage, per-pass times, GPU memory, lights and the exposure (`exposure`: manual
/// stops; None: automatic, metered on the GPU), in their own panel right of the image so that
/// they never cover the hair.
pub fn readout(ui: &mut egui::Ui, status: &Status, exposure: Option<f32>) {
    let Some(shown) = &status.shown else { return };
    let st = &shown.stats;
    let mut lines = vec![
        st.adapter.clone(),
        format!(
            "{}{}",
            match shown.stage {
                Stage::Preview => "preview".to_string(),
                Stage::Refining { done, total } => format!("refining {done}/{total}"),
                Stage::Converged => "converged".to_string(),
            },
            match (shown.coarse_tables, shown.stale_tables) {
                (true, _) => " (coarse tables while the full ones bake)",
                (false, true) => " (previous tables)",
                (false, false) => "",
            }
        ),
    ];
    if let Some(p) = status.preview_seconds {
        lines.push(format!("first preview {:.2} s", p));
    }
    if let Some(c) = status.converged_seconds {
        lines.push(format!("converged {:.2} s", c));
    }
    lines.extend(pass_time_lines(st));
    let memory: u64 = st.memory.iter().map(|(_, b)| b).sum();
    lines.push(format!("GPU memory {:.1} MB", memory as f64 / 1e6));
    let mut memory_items = st.memory.clone();
    memory_items.sort_by_key(|item| std::cmp::Reverse(item.1));
    for (name, bytes) in memory_items.iter().take(4) {
        lines.push(format!("  {name:<20} {:>7.1} MB", *bytes as f64 / 1e6));
    }
    lines.push(match exposure {
        Some(stops) => format!("exposure {stops:+.2} stops"),
        None => "exposure auto (hair's 90th percentile)".into(),
    });
    ui.add(
        egui::Label::new(egui::RichText::new(lines.join("\n")).monospace().size(10.0))
            .wrap_mode(egui::TextWrapMode::Wrap),
    );
}

/// The frame's total and its six slowest passes: wall clock, and the GPU's own time where the
/// adapter has timestamp queries.
fn pass_time_lines(st: &FrameStats) -> Vec<String> {
    let wall: f64 = st.passes.iter().map(|t| t.milliseconds).sum();
    let gpu: f64 = st.passes.iter().filter_map(|t| t.gpu_milliseconds).sum();
    let has_gpu = st.passes.iter().any(|t| t.gpu_milliseconds.is_some());
    let mut lines = vec![format!(
        "{} lights in {} batch{}: {wall:.0} ms wall{}",
        st.lights,
        st.batches,
        if st.batches == 1 { "" } else { "es" },
        if has_gpu {
            format!(", {gpu:.0} ms GPU (timestamp queries)")
        } else {
            " (no timestamp queries: CPU timing)".to_string()
        }
    )];
    let mut passes = st.passes.clone();
    passes.sort_by(|a, b| b.milliseconds.total_cmp(&a.milliseconds));
    lines.push(format!("  {:<22} {:>8} {:>8}", "pass", "wall ms", "GPU ms"));
    for t in passes.iter().take(6) {
        let gpu = t
            .gpu_milliseconds
            .map_or("-".to_string(), |g| format!("{g:.1}"));
        lines.push(format!("  {:<22} {:>8.1} {gpu:>8}", t.pass, t.milliseconds));
    }
    lines
}
