//! `strandlight summary`: what the toolkit knows, with a few values a person can sanity-check.

pub fn run() -> anyhow::Result<()> {
    println!("strandlight {}", env!("CARGO_PKG_VERSION"));
    Ok(())
}
