//! `strandlight summary`: prints [`strandlight_eval::summary`] as text or JSON.

use strandlight_eval::summary::{self, AlbedoRow, ModelSummary, PresetSummary, Summary};
use strandlight_tables::Rgb;

#[derive(clap::Args, Default)]
pub struct SummaryArgs {
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
}

pub fn run(args: SummaryArgs) -> anyhow::Result<()> {
    let summary = summary::compute()?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&summary)?);
    } else {
        print_text(&summary);
    }
    Ok(())
}

fn print_text(s: &Summary) {
    println!(
        "strandlight {} — fiber models on built-in defaults",
        s.version
    );
    println!(
        "S convention: L_o = D ∫ S(ω_i, ω_o) L_i cos θ_i dω_i; angles in degrees, S per RGB channel.\n"
    );
    s.models.iter().for_each(print_model);
    print_presets(&s.presets);
    print_furnace(s);
    print_albedo(&s.single_event_albedo_marschner);
    print_srbf(s);
}

fn rgb(v: &Rgb) -> String {
    format!("({:.4e}, {:.4e}, {:.4e})", v[0], v[1], v[2])
}

fn print_model(m: &ModelSummary) {
    println!("== {}", m.name);
    println!("   parameters: {}", m.parameters);
    for x in &m.samples {
        println!(
            "   S({:>5.1}, {:>6.1}, {:>5.1}) {:<26} = {}",
            x.theta_i_deg,
            x.theta_o_deg,
            x.phi_deg,
            x.configuration,
            rgb(&x.s)
        );
    }
    println!();
}

fn print_presets(presets: &[PresetSummary]) {
    println!("== absorption presets (σ_a per unit fiber radius = C_eu σ_eu + C_ph σ_ph)");
    for p in presets {
        println!(
            "   {:<8} C_eu {:>4.1}  C_ph {:>4.1}  σ_a = ({:.4}, {:.4}, {:.4})",
            p.name, p.eumelanin, p.pheomelanin, p.sigma_a[0], p.sigma_a[1], p.sigma_a[2]
        );
    }
    println!();
}

fn print_furnace(s: &Summary) {
    println!(
        "== white furnace, Marschner with σ_a = 0: ∫ S_p cos θ_o dω_o by {}",
        s.furnace_rule
    );
    for r in &s.white_furnace_marschner {
        println!(
            "   θ_i = {:>4.1}°: R {:.5}  TT {:.5}  TRT {:.5}  total {:.5} (twice the panels: {:.5})",
            r.theta_i_deg, r.r, r.tt, r.trt, r.total, r.total_refined
        );
    }
    println!("   (≈ 1 − what leaves after ≥ 2 internal reflections, which the model omits; M_p's");
    println!(
        "    spread in θ_d moves the total by a few percent either way: Marschner is not exactly"
    );
    println!(
        "    energy-conserving, see tables/src/marschner/tests.rs white_furnace_energy_per_lobe)\n"
    );
}

fn print_albedo(rows: &[AlbedoRow]) {
    println!("== dual scattering: single-event albedo ā_f + ā_b of Marschner at θ = 0° per preset");
    for r in rows {
        println!(
            "   {:<8} forward {}  backward {}  total {}",
            r.preset,
            rgb(&r.forward),
            rgb(&r.backward),
            rgb(&r.total)
        );
    }
    println!();
}

fn print_srbf(s: &Summary) {
    println!(
        "== SRBF ∫ exp(λ(cos γ − 1)) dω: closed form 2π(1 − e^(−2λ))/λ vs {}",
        s.srbf_rule
    );
    for r in &s.srbf_integral {
        println!(
            "   λ = {:>4}: closed form {:.12}  quadrature {:.12}  rel. diff {:+.2e}",
            r.lambda, r.closed_form, r.quadrature, r.relative_difference
        );
    }
}
