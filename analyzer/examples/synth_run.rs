//! Writes a synthetic run (the paper's route and traffic, a kinematic tow) as a plant and a
//! controller MCAP log, for trying and timing the analyzer:
//!
//! ```sh
//! cargo run --release -p analyzer --example synth_run -- out/synth 12000
//! target/release/analyzer report --out out/synth/report out/synth/plant.mcap out/synth/controller.mcap
//! ```
//!
//! Arguments: output directory, plant steps of 0.1 s (default 12000), and `noscene` to
//! leave out the scene, `/tf` and prediction topics.

use std::path::PathBuf;
use std::process::ExitCode;

use analyzer::synth::SynthRun;

#[allow(clippy::print_stdout)]
fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let dir = PathBuf::from(args.first().map_or("out/synth", String::as_str));
    let steps = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(12_000);
    let mut run = SynthRun::paper(steps);
    run.scene = !args.iter().any(|a| a == "noscene");
    if let Err(e) = std::fs::create_dir_all(&dir) {
        eprintln!("{}: {e}", dir.display());
        return ExitCode::FAILURE;
    }
    let (plant, controller) = (dir.join("plant.mcap"), dir.join("controller.mcap"));
    match run.write(&plant, &controller) {
        Ok(()) => {
            println!(
                "wrote {} and {} ({} steps; expected settling time {:?} s, route {:.3} m)",
                plant.display(),
                controller.display(),
                steps,
                run.expected_settling_time(),
                run.route_length()
            );
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("{e}");
            ExitCode::FAILURE
        }
    }
}
