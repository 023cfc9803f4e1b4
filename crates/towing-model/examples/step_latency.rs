//! Times 100 000 individual 0.1 s `World::step` calls (nonlinear hull, default
//! integration step, 8 active obstacles) and prints the median, p99 and maximum
//! latency in microseconds (criterion reports no percentiles).
//!
//! `cargo run --release -p towing-model --example step_latency`

// An example reports on stdout.
#![allow(clippy::print_stdout)]

use std::time::Instant;

use towing_model::{HullModel, Scenario, World, WorldConfig, WorldInputs};

const SCENARIO: &str = include_str!("../benches/eight_obstacles.toml");
const STEPS: usize = 100_000;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let scenario = Scenario::from_toml_str(SCENARIO, "benches/eight_obstacles.toml")?;
    let config = WorldConfig {
        hull_model: HullModel::NonlinearDamping,
        ..WorldConfig::default()
    };
    let mut world = World::new(&scenario, config)?;
    let mut state: u64 = 2022;
    let mut unit = move || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    let inputs: Vec<WorldInputs> = (0..1024)
        .map(|_| {
            let mut i = WorldInputs::default();
            for tug in 0..2 {
                i.tug_tau[tug] = [3.0 + 2.0 * unit(), unit(), 0.2 * unit()];
                i.tension_cmd[tug] = 1.5 + 1.5 * unit();
            }
            i
        })
        .collect();
    let mut micros = Vec::with_capacity(STEPS);
    for k in 0..STEPS {
        let input = &inputs[k % inputs.len()];
        let start = Instant::now();
        world.step(input, 0.1)?;
        micros.push(start.elapsed().as_secs_f64() * 1e6);
    }
    micros.sort_by(f64::total_cmp);
    let at = |q: f64| micros[((micros.len() - 1) as f64 * q).round() as usize];
    println!(
        "{STEPS} steps of 0.1 s (simulated {:.0} s): median {:.2} us, p99 {:.2} us, max {:.2} us",
        world.time(),
        at(0.5),
        at(0.99),
        micros[micros.len() - 1]
    );
    Ok(())
}
