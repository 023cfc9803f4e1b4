//! The paper scenario's distributed closed loop, schemes I and II, must not pass by luck:
//! with one regulariser of the ship's problem (`mpc.ship.weight_tension`, 0.01 per N^2,
//! `docs/assumptions.md`) set 10 % below to 10 % above its default in nine steps, every
//! run reaches its destination and settles there within 15 % of the paper's settling
//! time, and no hull corner goes beyond the bank. At ADMM's former penalty rho = 20, 9 of
//! 21 such runs of scheme I did not settle (`docs/assumptions.md`, "penalty ρ"); the
//! single default run, which the acceptance tests judge, had passed by luck.
#![allow(clippy::unwrap_used)]

use towing_control::{Architecture, AvoidanceScheme, Controller, ControllerConfig, Measurement};
use towing_model::{wrap_angle, Scenario, World, WorldInputs};

/// The paper's settling time of distributed scheme I (Table 7), and the margin the
/// acceptance tests allow.
const PAPER_SETTLING_S: f64 = 968.0;

/// When the ship settled at the destination (within half its length and 3 deg, at rest,
/// and staying so to the end), over 1200 s of the closed loop; and the largest bank
/// excess of any hull corner (m).
fn run(scheme: AvoidanceScheme, weight_tension: f64) -> (Option<f64>, f64) {
    let scenario = Scenario::paper().unwrap();
    let mut config = ControllerConfig::new(scenario.clone());
    config.tuning.architecture = Architecture::Distributed;
    config.tuning.scheme = scheme;
    config.tuning.sample_time_budget = 0.0;
    config.tuning.ship.weight_tension = weight_tension;
    let mut controller = Controller::new(config).unwrap();
    let mut world = World::new(&scenario, Default::default()).unwrap();
    let dest = scenario.route.destination;
    let (mut settled, mut aground) = (None, 0.0f64);
    for k in 0..12_000u32 {
        let t = f64::from(k) * 0.1;
        let m = Measurement::from_world(&world);
        let c = controller.step(t, &m).unwrap().command;
        let inputs = WorldInputs {
            tug_tau: c.tug_thrust,
            tension_cmd: c.tension,
        };
        world.step(&inputs, 0.1).unwrap();
        if let Some(e) = world.bank_excess() {
            aground = e.into_iter().fold(aground, f64::max);
        }
        let s = world.ship();
        let at_rest = (s.eta[0] - dest.x).hypot(s.eta[1] - dest.y)
            <= 0.5 * scenario.ship_data.length
            && wrap_angle(s.eta[2] - dest.psi).abs() <= 3f64.to_radians()
            && s.nu.iter().all(|v| v.abs() < 0.01);
        settled = match (at_rest, settled) {
            (false, _) => None,
            (true, None) => Some(world.time()),
            (true, since) => since,
        };
    }
    (settled, aground)
}

#[test]
fn the_paper_scenario_settles_under_a_perturbed_regulariser() {
    // One thread per scheme: the runs are independent and deterministic.
    let failures: Vec<String> = std::thread::scope(|s| {
        let handles: Vec<_> = [AvoidanceScheme::AlterAndCost, AvoidanceScheme::AlterOnly]
            .into_iter()
            .map(|scheme| {
                s.spawn(move || {
                    let mut failures = Vec::new();
                    for i in 0..9 {
                        let w = 0.009 + 0.00025 * f64::from(i);
                        let (settled, aground) = run(scheme, w);
                        let late = settled.is_none_or(|t| t > 1.15 * PAPER_SETTLING_S);
                        if late || aground > 0.0 {
                            failures.push(format!(
                                "{scheme:?}, weight_tension {w}: settled at {settled:?} s, bank excess {aground:.2} m"
                            ));
                        }
                    }
                    failures
                })
            })
            .collect();
        handles
            .into_iter()
            .flat_map(|h| h.join().unwrap())
            .collect()
    });
    assert!(failures.is_empty(), "{failures:#?}");
}
