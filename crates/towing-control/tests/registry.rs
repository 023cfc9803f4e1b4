//! No configuration the registry accepts can panic the controller: random values
//! within every parameter's range (any item of an Enumeration; each Real
//! log-uniform between its lower bound, or a hundredth of its default, and its
//! upper bound, or a hundred times its default), a controller built from them when
//! `validate` passes, and samples of the paper scenario's closed loop through
//! `Controller::step`.
#![allow(clippy::unwrap_used)]

use proptest::prelude::*;
use towing_control::params::{Kind, Limit, Value, PARAMETERS};
use towing_control::{Controller, ControllerConfig, Measurement};
use towing_model::{Scenario, World, WorldInputs};

/// A value in `[lo, hi]` from `u` in `[0, 1]`, log-uniform when both are positive.
fn spread(lo: f64, hi: f64, u: f64) -> f64 {
    if lo > 0.0 && hi > lo {
        (lo.ln() + u * (hi.ln() - lo.ln())).exp()
    } else {
        lo + u * (hi - lo)
    }
}

/// The value of parameter `p` drawn from `u` (and `b` for a switch).
fn draw(kind: Kind, default: Value, u: f64, b: bool) -> Value {
    match (kind, default) {
        (Kind::Real { min, max, .. }, Value::Real(d)) => {
            let scale = if d > 0.0 { d } else { 1.0 };
            let lo = min.value().unwrap_or(0.0).max(scale / 100.0).min(scale);
            let hi = max.value().unwrap_or(scale * 100.0).min(scale * 100.0);
            let mut v = spread(lo, hi, u);
            // Open bounds are excluded.
            if let Limit::Below(x) = max {
                v = v.min(x * (1.0 - 1e-9));
            }
            if let Limit::Above(x) = min {
                v = v.max(x + scale * 1e-6);
            }
            Value::Real(v)
        }
        (Kind::Integer { min, max, .. }, _) => {
            Value::Integer(min + ((u * f64::from(max - min + 1)) as i32).min(max - min))
        }
        (Kind::Boolean { .. }, _) => Value::Boolean(b),
        (Kind::Enumeration { enumeration, .. }, _) => {
            let n = enumeration.items.len();
            Value::Integer(enumeration.items[((u * n as f64) as usize).min(n - 1)].value)
        }
        (_, other) => other,
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(40))]
    #[test]
    fn no_accepted_configuration_panics_in_a_sample(
        draws in proptest::collection::vec((0.0f64..1.0, any::<bool>()), PARAMETERS.len()),
    ) {
        let scenario = Scenario::paper().unwrap();
        let mut config = ControllerConfig::new(scenario.clone());
        for (p, (u, b)) in PARAMETERS.iter().zip(&draws) {
            let value = draw(p.kind, p.default_value(), *u, *b);
            prop_assert!(p.check(&value).is_ok(), "{} = {value:?} outside its own range", p.name);
            config.set(p.name, value).unwrap();
        }
        // Keep each case short: a coarse prediction step is as valid as a fine one.
        config.tuning.prediction.integration_step =
            config.tuning.prediction.integration_step.max(config.tuning.prediction.sample_time / 20.0);
        if config.validate().is_err() {
            // Refused (a rule between parameters): nothing to run.
            return Ok(());
        }
        let mut controller = Controller::new(config).unwrap();
        let mut world = World::new(&scenario, scenario.world_config).unwrap();
        for _ in 0..30 {
            let m = Measurement::from_world(&world);
            let step = controller.step(world.time(), &m).unwrap();
            let c = step.command;
            prop_assert!(c.tension.iter().chain(c.tug_thrust.iter().flatten()).all(|v| v.is_finite()));
            if world.step(&WorldInputs { tug_tau: c.tug_thrust, tension_cmd: c.tension }, 0.1).is_err() {
                break;
            }
        }
    }
}
