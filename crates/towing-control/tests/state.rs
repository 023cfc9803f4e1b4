//! `Controller::snapshot` / `Controller::restore`: a controller rebuilt from its
//! configuration and restored from a snapshot (here after a round trip through the bytes
//! of an FMU state's encoding, MessagePack) goes on bit for bit like the one the snapshot
//! was taken of, with either architecture; a state that does not fit is refused.
#![allow(clippy::unwrap_used)]

use towing_control::{Architecture, Controller, ControllerConfig, ControllerState, Measurement};
use towing_model::{Scenario, World, WorldInputs};

/// Steps the closed loop (controller every 0.1 s, samples on its own clock) from `t0`
/// for `steps` steps; returns the bits of every command and sample report.
fn run(controller: &mut Controller, world: &mut World, t0: f64, steps: u32) -> Vec<u64> {
    let mut bits = Vec::new();
    for k in 0..steps {
        let t = t0 + f64::from(k) * 0.1;
        let m = Measurement::from_world(world);
        let step = controller.step(t, &m).unwrap();
        let c = step.command;
        bits.extend(
            c.tug_thrust
                .iter()
                .flatten()
                .chain(&c.tension)
                .map(|v| v.to_bits()),
        );
        if let Some(r) = step.sample {
            assert!(r.fallback.is_none(), "t = {t}: {:?}", r.fallback);
            let p = &r.prediction;
            let values = p
                .ship
                .iter()
                .flatten()
                .chain(p.tugs.iter().flatten().flatten());
            bits.extend(values.chain(&r.r_pri).chain(&r.r_dual).map(|v| v.to_bits()));
            bits.extend(
                r.reference
                    .iter()
                    .chain(&r.desired_angle)
                    .map(|v| v.to_bits()),
            );
            bits.push(r.iterations as u64);
            bits.push(u64::from(r.converged));
            bits.push(r.heading_floor.map_or(0, f64::to_bits));
            bits.push(r.guidance.active_waypoint as u64);
        }
        let inputs = WorldInputs {
            tug_tau: c.tug_thrust,
            tension_cmd: c.tension,
        };
        world.step(&inputs, 0.1).unwrap();
    }
    bits
}

fn config(architecture: Architecture) -> ControllerConfig {
    let mut config = ControllerConfig::new(Scenario::paper().unwrap());
    config.tuning.architecture = architecture;
    // Wall-clock budgets would make the iterations depend on the machine's speed.
    config.tuning.sample_time_budget = 0.0;
    config
}

#[test]
fn a_restored_controller_continues_bit_for_bit() {
    for architecture in [Architecture::Distributed, Architecture::Centralized] {
        let config = config(architecture);
        let scenario = &config.scenario;
        let mut world = World::new(scenario, scenario.world_config).unwrap();
        let mut controller = Controller::new(config.clone()).unwrap();
        // 60 s: past the first samples, the guidance on its first leg.
        run(&mut controller, &mut world, 0.0, 600);
        let bytes = rmp_serde::to_vec_named(&controller.snapshot()).unwrap();
        let mut world_copy = world.clone();
        let expected = run(&mut controller, &mut world, 60.0, 150);

        let state: ControllerState = rmp_serde::from_slice(&bytes).unwrap();
        let mut fresh = Controller::new(config.clone()).unwrap();
        fresh.restore(&state).unwrap();
        let again = run(&mut fresh, &mut world_copy, 60.0, 150);
        assert_eq!(expected.len(), again.len());
        assert!(
            expected == again,
            "{architecture:?}: the restored run differs"
        );

        // Without the state, a fresh controller does not continue the same way: the
        // comparison above can fail.
        let mut cold = Controller::new(config.clone()).unwrap();
        cold.set_start_time(60.0);
        let mut world_cold = world.clone();
        assert_ne!(
            run(&mut cold, &mut world_cold, 60.0, 10)[..10],
            expected[..10]
        );
    }
}

#[test]
fn a_state_that_does_not_fit_is_refused_and_changes_nothing() {
    let distributed = Controller::new(config(Architecture::Distributed)).unwrap();
    let mut centralized = Controller::new(config(Architecture::Centralized)).unwrap();
    let before = rmp_serde::to_vec_named(&centralized.snapshot()).unwrap();
    let e = centralized.restore(&distributed.snapshot()).unwrap_err();
    assert_eq!(
        e,
        "the state is of the distributed (ADMM) MPC, this controller's is centralized"
    );
    let mut other = config(Architecture::Distributed);
    other.tuning.prediction.sample_time = 0.5;
    let mut half = Controller::new(other).unwrap();
    let e = half.restore(&distributed.snapshot()).unwrap_err();
    assert_eq!(
        e,
        "the state's sample time is 1000000000 ns, this controller's 500000000 ns"
    );
    assert_eq!(
        rmp_serde::to_vec_named(&centralized.snapshot()).unwrap(),
        before
    );
}
