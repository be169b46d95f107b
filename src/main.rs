//! `strandlight`: the command-line front end. Parsing, progress and dispatch only; the work
//! lives in the library crates.

mod render;
mod summary;

use clap::{Parser, Subcommand};

#[derive(Parser)]
#[command(
    name = "strandlight",
    version,
    about = "Strand hair under environment lighting (Ren et al. 2010)"
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand)]
enum Command {
    /// Print the fiber models, their default parameters and sample values (the default).
    Summary,
    /// Render a hair model headless under point lights to EXR (linear) and PNG (tonemapped).
    Render(render::RenderArgs),
}

fn main() -> anyhow::Result<()> {
    let cli = Cli::parse();
    match cli.command.unwrap_or(Command::Summary) {
        Command::Summary => summary::run(),
        Command::Render(args) => render::run(args),
    }
}
