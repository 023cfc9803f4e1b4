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
fn fmu_state_capabilities_are_declared_false() {
    let xml = model_description_xml();
    assert!(xml.contains("canGetAndSetFMUstate=\"false\""), "{xml}");
    assert!(xml.contains("canSerializeFMUstate=\"false\""), "{xml}");
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

/// Each parameter against the field of `ControllerConfig::new(Scenario::paper())` it sets,
/// written out independently of the variable table.
#[test]
fn parameter_start_values_are_the_rust_defaults() {
    let c = ControllerConfig::new(Scenario::paper().unwrap());
    let ts = c.prediction.sample_time;
    let expected: Vec<(&str, f64)> = vec![
        ("sample_time", ts),
        ("prediction_step", c.prediction.integration_step),
        ("altering_angle", c.guidance.altering_angle),
        ("w_S1", c.ship.weight_position),
        ("w_S2", c.ship.weight_surge),
        ("w_S3", c.ship.weight_distance),
        ("w_T1", c.tug.weight_position),
        ("w_T2", c.tug.weight_surge),
        ("w_T3", c.tug.weight_distance),
        ("eps_abs", c.admm.eps_abs),
        ("eps_rel", c.admm.eps_rel),
        ("max_tension", c.ship.max_tension),
        ("max_towing_angle", c.ship.max_angle),
        ("tension_rate", c.ship.tension_rate),
        ("angle_rate", c.ship.angle_rate),
        ("max_thrust_surge", c.tug.thrust_limit[0]),
        ("max_thrust_sway", c.tug.thrust_limit[1]),
        ("max_yaw_moment", c.tug.thrust_limit[2]),
        ("rho", c.admm.rho),
        ("detection_distance", c.guidance.detection_distance),
        (
            "static_detection_distance",
            c.guidance.static_detection_distance,
        ),
        ("safety_buffer", c.guidance.safety_buffer),
        ("acceptance_radius", c.guidance.acceptance_radius),
        ("min_tension", c.ship.min_tension),
        ("angle_weight", c.ship.weight_towing_angle),
        ("tension_weight", c.ship.weight_tension),
        ("inner_loop_gain_surge", c.inner.gain[0]),
        ("inner_loop_gain_sway", c.inner.gain[1]),
        ("inner_loop_gain_yaw", c.inner.gain[2]),
        ("w_S2_yaw", c.ship.weight_yaw_rate),
        ("lookahead", c.tracking.lookahead),
        ("los_distance", c.tracking.los_distance),
        ("give_way_lookahead", c.tracking.give_way_lookahead),
        ("port_turn_margin", c.tracking.port_turn_margin),
        ("port_turn_weight", c.ship.weight_port_turn),
        (
            "centralized_thrust_rate_weight",
            c.centralized.weight_force_rate,
        ),
    ];
    for (name, value) in &expected {
        assert_eq!(start_real(name), *value, "start value of {name}");
    }
    // 0 means "from the scenario" (the paper scenario has a waterway).
    assert_eq!(start_real("waterway_half_width"), 0.0);
    assert!(c.guidance.waterway_half_width.is_some());
    // Table 3 values, as the brief of the FMU states them.
    assert_eq!(start_real("w_S2"), 75.0);
    assert_eq!(start_real("w_T2"), 6.0);
    assert!((start_real("altering_angle") - 15f64.to_radians()).abs() < 1e-15);
    assert!((start_real("tension_rate") - 0.3).abs() < 1e-15);

    assert_eq!(start_integer("hull_model"), 0);
    assert_eq!(start_integer("architecture"), c.architecture.code());
    assert_eq!(start_integer("avoidance_scheme"), c.scheme.code());
    assert_eq!(
        start_integer("max_iterations"),
        i32::try_from(c.admm.max_iterations).unwrap()
    );
    assert_eq!(
        start_integer("prediction_horizon"),
        i32::try_from(towing_mpc::HORIZON).unwrap()
    );
    let n_params = DESCRIPTION
        .variables
        .iter()
        .filter(|v| v.causality == Causality::Parameter)
        .count();
    // 2 String + 5 Integer + the Reals above and waterway_half_width.
    assert_eq!(n_params, 2 + 5 + expected.len() + 1);
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
