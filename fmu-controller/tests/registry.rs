//! The FMU and the Rust API refuse the same configurations with the same reason:
//! every parameter of the registry set out of its range through `fmi2Set*` and
//! through `ControllerConfig::set`, and a rule between parameters broken through
//! `fmi2ExitInitializationMode` and `Controller::new`.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod support;

use fmi2_slave::ffi::Fmi2Status;
use support::*;
use towing_control::params::{Kind, Limit, Value, PARAMETERS};
use towing_control::{Controller, ControllerConfig};
use towing_controller::variables as vars;
use towing_model::Scenario;

/// Values out of a parameter's range (and non-finite ones for a Real, which the FMI
/// layer refuses for every Real variable before the model's registry sees them; for an
/// Enumeration, values next to its items').
fn invalid_values(kind: Kind) -> Vec<Value> {
    match kind {
        Kind::Real { min, max, .. } => {
            let mut v = vec![f64::NAN, f64::INFINITY, f64::NEG_INFINITY];
            match min {
                Limit::Above(x) => v.push(x),
                Limit::AtLeast(x) => v.push(x - 1.0),
                _ => {}
            }
            match max {
                Limit::Below(x) => v.push(x),
                Limit::AtMost(x) => v.push(x + 1.0),
                _ => {}
            }
            v.into_iter().map(Value::Real).collect()
        }
        Kind::Integer { min, max, .. } => vec![Value::Integer(min - 1), Value::Integer(max + 1)],
        Kind::Enumeration { enumeration, .. } => {
            let values = enumeration.items.iter().map(|i| i.value);
            let (lo, hi) = (values.clone().min().unwrap(), values.max().unwrap());
            vec![
                Value::Integer(lo - 1),
                Value::Integer(hi + 1),
                Value::Integer(0),
            ]
        }
        Kind::Boolean { .. } | Kind::String { .. } => vec![],
    }
}

#[test]
fn every_value_the_fmu_refuses_the_rust_api_refuses_with_the_same_reason() {
    let mut checked = 0;
    for p in PARAMETERS {
        for value in invalid_values(p.kind) {
            let mut config = ControllerConfig::new(Scenario::paper().unwrap());
            let reason = config
                .set(p.name, value.clone())
                .expect_err(&format!("{} = {value:?} accepted", p.name))
                .to_string();
            let fmu = controller(p.name);
            let vr = vars::parameter_vr_of(p.name).unwrap();
            let status = match value {
                Value::Real(v) => fmu.set_real(vr, v),
                Value::Integer(v) => fmu.set_integer(vr, v),
                Value::Boolean(v) => fmu.set_boolean(vr, v),
                Value::String(ref v) => fmu.set_string(vr, v),
            };
            assert_eq!(status, Fmi2Status::Error, "{} = {value:?}", p.name);
            if matches!(value, Value::Real(v) if !v.is_finite()) {
                // the FMI layer refuses a non-finite Real before the model sees it
                assert!(reason.contains("must be finite"), "{reason}");
                assert!(
                    fmu.last_text().contains(&format!("variable '{}'", p.name))
                        && fmu.last_text().contains("is not finite"),
                    "{}",
                    fmu.last_text()
                );
                checked += 1;
                continue;
            }
            assert!(
                fmu.last_text().ends_with(&reason),
                "{} = {value:?}: FMU said {:?}, Rust {reason:?}",
                p.name,
                fmu.last_text()
            );
            checked += 1;
        }
    }
    assert!(checked > 2 * PARAMETERS.len(), "{checked}");
}

#[test]
fn a_broken_rule_between_parameters_is_refused_alike() {
    let mut config = ControllerConfig::new(Scenario::paper().unwrap());
    config.tuning.ship.min_tension = 2.5;
    config.tuning.ship.max_tension = 2.0;
    let reason = Controller::new(config).unwrap_err().to_string();
    assert!(reason.contains("mpc.ship.min_tension"), "{reason}");
    let fmu = controller("relation");
    set_states(&fmu, &paper_states());
    let vr = |n| vars::parameter_vr_of(n).unwrap();
    assert_eq!(
        fmu.set_real(vr("mpc.ship.min_tension"), 2.5),
        Fmi2Status::Ok
    );
    assert_eq!(
        fmu.set_real(vr("mpc.ship.max_tension"), 2.0),
        Fmi2Status::Ok
    );
    assert_eq!(fmu.setup(0.0, None), Fmi2Status::Ok);
    assert_eq!(fmu.enter_init(), Fmi2Status::Ok);
    assert_eq!(fmu.exit_init(), Fmi2Status::Error);
    assert!(
        fmu.last_text().ends_with(&reason),
        "{} vs {reason}",
        fmu.last_text()
    );
}
