//! The committed model description and the interface document must be what the Rust
//! variable table generates (`cargo xtask model-description` regenerates both), and the
//! parameters' start values must be the Rust defaults.
#![allow(clippy::unwrap_used, clippy::float_cmp)]

use fmi2_slave::{Causality, VariableKind};
use towing_control::ControllerConfig;
use towing_controller::variables::{model_description_xml, DESCRIPTION, VARIABLES};
use towing_interface::testing;
use towing_model::Scenario;

towing_interface::model_description_tests!(DESCRIPTION, VARIABLES);

#[test]
fn fmu_state_capabilities_are_declared() {
    let xml = model_description_xml();
    assert!(xml.contains("canGetAndSetFMUstate=\"true\""), "{xml}");
    assert!(xml.contains("canSerializeFMUstate=\"true\""), "{xml}");
    assert!(xml.contains(&DESCRIPTION.guid()));
}

fn start_real(name: &str) -> f64 {
    let v = DESCRIPTION
        .variables
        .iter()
        .find(|v| v.name == name)
        .unwrap_or_else(|| panic!("no variable {name}"));
    assert_eq!(v.causality, Causality::Parameter, "{name}");
    match v.kind {
        VariableKind::Real { start: Some(s), .. } => s,
        _ => panic!("{name} is not a Real with a start value"),
    }
}

fn start_integer(name: &str) -> i32 {
    let v = DESCRIPTION
        .variables
        .iter()
        .find(|v| v.name == name)
        .unwrap();
    match v.kind {
        VariableKind::Integer { start: Some(s), .. } => s,
        _ => panic!("{name} is not an Integer with a start value"),
    }
}

/// The start value and declared type of the Enumeration parameter `name`.
fn start_enumeration(name: &str) -> (i32, &'static str) {
    let v = DESCRIPTION
        .variables
        .iter()
        .find(|v| v.name == name)
        .unwrap();
    match &v.kind {
        VariableKind::Enumeration {
            start: Some(s),
            declared_type,
        } => (*s, declared_type.as_str()),
        _ => panic!("{name} is not an Enumeration with a start value"),
    }
}

fn start_boolean(name: &str) -> bool {
    let v = DESCRIPTION
        .variables
        .iter()
        .find(|v| v.name == name)
        .unwrap();
    match v.kind {
        VariableKind::Boolean { start: Some(s) } => s,
        _ => panic!("{name} is not a Boolean with a start value"),
    }
}

/// Each parameter against the field of `ControllerConfig::new(Scenario::paper())` it sets,
/// written out independently of the registry, and every registry entry declared.
#[test]
fn parameter_start_values_are_the_rust_defaults() {
    let c = ControllerConfig::new(Scenario::paper().unwrap());
    let t = &c.tuning;
    let expected: Vec<(&str, f64)> = vec![
        ("mpc.sample_time", t.prediction.sample_time),
        ("mpc.prediction_step", t.prediction.integration_step),
        ("mpc.sample_time_budget", 0.0),
        ("guidance.altering_angle", t.guidance.altering_angle),
        ("mpc.ship.weight_position", t.ship.weight_position),
        ("mpc.ship.weight_heading", t.ship.weight_heading),
        ("mpc.ship.weight_surge", t.ship.weight_surge),
        ("mpc.ship.weight_sway", t.ship.weight_sway),
        ("mpc.ship.weight_yaw_rate", t.ship.weight_yaw_rate),
        ("mpc.ship.weight_distance", t.ship.weight_distance),
        ("mpc.tug.weight_position", t.tug.weight_position),
        ("mpc.tug.weight_surge", t.tug.weight_surge),
        ("mpc.tug.weight_distance", t.tug.weight_distance),
        ("admm.eps_abs", t.admm.eps_abs),
        ("admm.eps_rel", t.admm.eps_rel),
        ("mpc.ship.max_tension", t.ship.max_tension),
        ("mpc.ship.max_towing_angle", t.ship.max_angle),
        ("mpc.ship.tension_rate", t.ship.tension_rate),
        ("mpc.ship.towing_angle_rate", t.ship.angle_rate),
        ("mpc.tug.max_force_surge", t.tug.thrust_limit[0]),
        ("mpc.tug.max_force_sway", t.tug.thrust_limit[1]),
        ("mpc.tug.max_moment_yaw", t.tug.thrust_limit[2]),
        ("admm.rho", t.admm.rho),
        ("guidance.detection_distance", t.guidance.detection_distance),
        (
            "guidance.static_detection_distance",
            t.guidance.static_detection_distance,
        ),
        ("guidance.safety_buffer", t.guidance.safety_buffer),
        ("guidance.acceptance_radius", t.guidance.acceptance_radius),
        ("mpc.ship.min_tension", t.ship.min_tension),
        ("mpc.ship.weight_towing_angle", t.ship.weight_towing_angle),
        ("mpc.ship.weight_tension", t.ship.weight_tension),
        ("inner_loop.bandwidth_surge", t.inner.gain[0]),
        ("inner_loop.bandwidth_sway", t.inner.gain[1]),
        ("inner_loop.bandwidth_yaw", t.inner.gain[2]),
        ("tracking.lookahead", t.tracking.lookahead),
        ("tracking.los_distance", t.tracking.los_distance),
        ("tracking.give_way_lookahead", t.tracking.give_way_lookahead),
        ("tracking.port_turn_margin", t.tracking.port_turn_margin),
        ("mpc.ship.weight_port_turn", t.ship.weight_port_turn),
        (
            "centralized.weight_force_rate",
            t.centralized.weight_force_rate,
        ),
        ("waterway.half_width", 5.0),
    ];
    for (name, value) in &expected {
        assert_eq!(start_real(name), *value, "start value of {name}");
    }
    // Table 3 values, as the brief of the FMU states them.
    assert_eq!(start_real("mpc.ship.weight_surge"), 75.0);
    assert_eq!(start_real("mpc.tug.weight_surge"), 6.0);
    assert!((start_real("guidance.altering_angle") - 15f64.to_radians()).abs() < 1e-15);
    assert!((start_real("mpc.ship.tension_rate") - 0.3).abs() < 1e-15);
    // Values from the scenario are switched, not sentinels.
    assert!(start_boolean("mpc.hull_from_scenario"));
    assert!(start_boolean("waterway.from_scenario"));
    assert!(c.guidance().waterway_half_width.is_some());

    assert_eq!(
        start_enumeration("architecture"),
        (t.architecture.code(), "Architecture")
    );
    assert_eq!(
        start_enumeration("avoidance_scheme"),
        (t.scheme.code(), "AvoidanceScheme")
    );
    assert_eq!(
        start_enumeration("mpc.hull_model"),
        (t.hull.code(), "HullModel")
    );
    assert_eq!(
        start_integer("admm.max_iterations"),
        i32::try_from(t.admm.max_iterations).unwrap()
    );
    let n_params = DESCRIPTION
        .variables
        .iter()
        .filter(|v| v.causality == Causality::Parameter)
        .count();
    // The session's 3 Strings + every registry entry.
    assert_eq!(n_params, 3 + towing_control::PARAMETERS.len());
}

/// Every name a master connects by must exist in both FMUs with the same type and unit.
#[test]
fn connection_names_match_the_plant() {
    let plant = testing::read_repository_file("modelDescription/TowingPlant.xml");
    let mut checked = 0;
    for v in &DESCRIPTION.variables {
        if !matches!(v.causality, Causality::Input | Causality::Output) {
            continue;
        }
        let needle = format!("name=\"{}\"", v.name);
        let Some(pos) = plant.find(&needle) else {
            continue;
        };
        let end = plant[pos..].find("</ScalarVariable>").unwrap() + pos;
        let element = &plant[pos..end];
        let wanted = if v.causality == Causality::Input {
            "causality=\"output\""
        } else {
            "causality=\"input\""
        };
        assert!(element.contains(wanted), "{}: {element}", v.name);
        assert!(
            element.contains(&format!("valueReference=\"{}\"", v.value_reference)),
            "{}: value reference differs from the plant's: {element}",
            v.name
        );
        let t = v.kind.declared_type().unwrap();
        assert!(
            element.contains(&format!("declaredType=\"{t}\"")),
            "{}: {element}",
            v.name
        );
        match &v.kind {
            VariableKind::Real { unit, .. } => {
                assert!(element.contains("<Real"), "{}", v.name);
                let u = unit.as_deref().unwrap();
                assert!(
                    element.contains(&format!("unit=\"{u}\"")),
                    "{}: {element}",
                    v.name
                );
            }
            VariableKind::Integer { .. } => assert!(element.contains("<Integer"), "{}", v.name),
            _ => panic!("{} has an unexpected type", v.name),
        }
        checked += 1;
    }
    // 18 vessel states + 6 towline values + 8 * 7 obstacle fields + 8 commands.
    assert_eq!(checked, 18 + 6 + 56 + 8);
}
