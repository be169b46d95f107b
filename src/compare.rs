//! `strandlight compare`: SRBF lights vs the brute-force reference vs the equal-time median-cut
//! baseline ([`strandlight_eval::compare`]); prints the report as JSON with `--json`.

use strandlight_eval::compare::{CompareArgs, execute, prepare};
use strandlight_scene::env_frame::render_lights;
use strandlight_scene::steps::Steps;

pub fn run(args: CompareArgs) -> anyhow::Result<()> {
    let mut steps = Steps::new(args.json);
    let scene = prepare(&args, &mut steps)?;
    let report = execute(&args, &scene, &mut steps, &render_lights)?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    }
    Ok(())
}
