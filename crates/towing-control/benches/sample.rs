//! One control sample (reference system plus the MPC to convergence) on the
//! paper scenario near an encounter: the closed loop (the plant's `World`, 0.1 s
//! communication steps) runs through target A's crossing, 100 s to 200 s, and
//! only `Controller::sample` is timed; the plant steps in between are not.
//! Both architectures. `cargo bench -p towing-control --bench sample`.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::time::{Duration, Instant};

use criterion::{criterion_group, criterion_main, Criterion};
use towing_control::{Architecture, Controller, ControllerConfig, Measurement};
use towing_model::{Scenario, World, WorldInputs};

const STEP: f64 = 0.1;
const WINDOW: (f64, f64) = (100.0, 200.0);

/// The closed loop, advanced one control sample at a time.
struct Loop {
    architecture: Architecture,
    world: World,
    controller: Controller,
}

impl Loop {
    fn new(architecture: Architecture) -> Loop {
        let scenario = Scenario::paper().unwrap();
        let world = World::new(&scenario, scenario.world_config).unwrap();
        let mut config = ControllerConfig::new(scenario.clone());
        config.tuning.architecture = architecture;
        let controller = Controller::new(config).unwrap();
        let mut l = Loop {
            architecture,
            world,
            controller,
        };
        while l.world.time() < WINDOW.0 - 1e-9 {
            l.sample();
        }
        l
    }

    /// One sample's ten communication steps through the controller's clock
    /// ([`Controller::step`]); returns the time of the step that sampled.
    fn sample(&mut self) -> Duration {
        let mut spent = Duration::ZERO;
        for _ in 0..10 {
            let m = Measurement::from_world(&self.world);
            let start = Instant::now();
            let step = self.controller.step(self.world.time(), &m).unwrap();
            if step.sample.is_some() {
                spent = start.elapsed();
            }
            let c = step.command;
            self.world
                .step(
                    &WorldInputs {
                        tug_tau: c.tug_thrust,
                        tension_cmd: c.tension,
                    },
                    STEP,
                )
                .unwrap();
        }
        spent
    }
}

fn bench(c: &mut Criterion) {
    for (name, arch) in [
        (
            "sample_near_encounter_distributed",
            Architecture::Distributed,
        ),
        (
            "sample_near_encounter_centralized",
            Architecture::Centralized,
        ),
    ] {
        let mut l = Loop::new(arch);
        c.bench_function(name, |b| {
            b.iter_custom(|iters| {
                let mut total = Duration::ZERO;
                for _ in 0..iters {
                    if l.world.time() >= WINDOW.1 {
                        l = Loop::new(l.architecture);
                    }
                    total += l.sample();
                }
                total
            });
        });
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(60).measurement_time(Duration::from_secs(8));
    targets = bench
}
criterion_main!(benches);
