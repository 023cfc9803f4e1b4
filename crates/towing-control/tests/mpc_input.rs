//! `Controller::last_mpc_input`: the exact input of the last sample's MPC, so that a
//! fresh solver replaying the recorded inputs reproduces the loop's commands bit for
//! bit (what the side-by-side baseline, `examples/record_centralized.rs`, relies on).
#![allow(clippy::unwrap_used)]

use towing_control::{centralized_mpc, Architecture, Controller, ControllerConfig, Measurement};
use towing_model::{Scenario, World, WorldInputs};
use towing_mpc::HORIZON;

#[test]
fn replaying_the_recorded_inputs_reproduces_the_centralized_loop() {
    let scenario = Scenario::paper().unwrap();
    let mut world = World::new(&scenario, scenario.world_config).unwrap();
    let mut config = ControllerConfig::new(scenario.clone());
    config.tuning.architecture = Architecture::Centralized;
    let mut controller = Controller::new(config.clone()).unwrap();
    assert!(controller.last_mpc_input().is_none());
    // Scheme I keeps the distance weights, so the MPC's parameters are the config's.
    let mut replay = centralized_mpc(&config).unwrap();
    for sample in 0..12 {
        let m = Measurement::from_world(&world);
        let before = *controller.applied();
        let report = controller.sample(&m).unwrap();
        let input = *controller.last_mpc_input().unwrap();
        assert_eq!(input.ship, m.ship);
        assert_eq!(input.tugs, m.tugs);
        assert_eq!(input.previous, before);
        assert_eq!(input.reference, [report.reference; HORIZON]);
        assert_eq!(input.heading_floor, report.heading_floor);
        assert!(
            !input.obstacles().is_empty(),
            "the paper scenario has obstacles"
        );
        assert!(report.fallback.is_none());
        let r = replay.solve_sample(&input.as_sample_input());
        assert!(!r.failed);
        assert_eq!(
            replay.ship_plan()[0],
            controller.applied().ship,
            "sample {sample}"
        );
        assert_eq!(
            [replay.tug_plan(0)[0], replay.tug_plan(1)[0]],
            controller.applied().tugs,
            "sample {sample}"
        );
        replay.shift();
        for n in 0..10 {
            let m = Measurement::from_world(&world);
            let c = controller.command_at(f64::from(n) * 0.1, &m).unwrap();
            world
                .step(
                    &WorldInputs {
                        tug_tau: c.tug_thrust,
                        tension_cmd: c.tension,
                    },
                    0.1,
                )
                .unwrap();
        }
    }
}
