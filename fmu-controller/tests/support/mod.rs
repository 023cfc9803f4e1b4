//! Shared set-up of the controller's in-process tests: an instance on the repository's
//! `scenarios/` folder (holding `paper.toml` like the packaged FMU's `resources/`) and the
//! paper scenario's initial states as plant-like inputs.
#![allow(dead_code, clippy::unwrap_used, clippy::expect_used)]

use fmi2_slave::ffi::Fmi2Status;
use fmi2_slave::testing::{Exports, Fmu};
use std::path::{Path, PathBuf};
use towing_controller::variables::{self as vars, DESCRIPTION};
use towing_model::Scenario;

pub fn exports() -> Exports {
    fmi2_slave::exports_of!(towing_controller)
}

pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .unwrap()
        .to_path_buf()
}

/// The repository's `scenarios/` folder as a resource URI.
pub fn resources_uri() -> String {
    format!("file://{}", root().join("scenarios").display()).replace(' ', "%20")
}

/// A freshly instantiated controller (not initialized).
pub fn controller(name: &str) -> Fmu {
    Fmu::try_new(exports(), &DESCRIPTION, name, Some(&resources_uri()), false)
        .unwrap_or_else(|log| panic!("instantiate failed: {log:?}"))
}

/// The paper scenario's initial vessel states: `[vessel][x, y, psi, u, v, r]`.
pub fn paper_states() -> [[f64; 6]; 3] {
    let s = Scenario::paper().unwrap();
    let state =
        |v: &towing_model::VesselState| [v.eta[0], v.eta[1], v.eta[2], v.nu[0], v.nu[1], v.nu[2]];
    [state(&s.ship), state(&s.tugs[0]), state(&s.tugs[1])]
}

/// Sets the vessel state inputs to `states`.
pub fn set_states(fmu: &Fmu, states: &[[f64; 6]; 3]) {
    let mut vrs = Vec::new();
    let mut values = Vec::new();
    for (vessel, s) in states.iter().enumerate() {
        for (c, &x) in s.iter().enumerate() {
            vrs.push(vars::vessel_state(vessel as u32, c as u32));
            values.push(x);
        }
    }
    assert_eq!(
        fmu.set_reals(&vrs, &values),
        Fmi2Status::Ok,
        "{}",
        fmu.log_text()
    );
}

/// Sets obstacle slot `slot` (0-based): `[x, y, psi, speed, length, width]` and kind.
pub fn set_obstacle(fmu: &Fmu, slot: u32, fields: [f64; 6], kind: i32) {
    let vrs: Vec<u32> = (0..6).map(|j| vars::obstacle_input(slot, j)).collect();
    assert_eq!(
        fmu.set_reals(&vrs, &fields),
        Fmi2Status::Ok,
        "{}",
        fmu.log_text()
    );
    assert_eq!(
        fmu.set_integer(vars::obstacle_input(slot, vars::OBSTACLE_KIND), kind),
        Fmi2Status::Ok
    );
}

/// An initialized controller with the paper scenario's initial states as inputs.
pub fn initialized(name: &str) -> Fmu {
    let fmu = controller(name);
    set_states(&fmu, &paper_states());
    fmu.init(0.0, None);
    fmu
}

/// The command outputs: tug1 X, Y, N, tug2 X, Y, N, tension 1, tension 2.
pub const COMMANDS: [u32; 8] = [
    vars::tug_force(0, 0),
    vars::tug_force(0, 1),
    vars::tug_force(0, 2),
    vars::tug_force(1, 0),
    vars::tug_force(1, 1),
    vars::tug_force(1, 2),
    vars::tension_cmd(0),
    vars::tension_cmd(1),
];

pub fn commands(fmu: &Fmu) -> Vec<f64> {
    let (s, v) = fmu.try_get_reals(&COMMANDS);
    assert_eq!(s, Fmi2Status::Ok);
    v
}

/// Every command finite, tensions in `[0, max_tension]`, thrusts within the limits
/// (the parameters' defaults).
pub fn assert_commands_within_bounds(fmu: &Fmu) {
    let v = commands(fmu);
    let param = |name: &str| {
        let var = DESCRIPTION
            .variables
            .iter()
            .find(|v| v.name == name)
            .unwrap();
        fmu.get_real(var.value_reference)
    };
    let limits = [
        param("max_thrust_surge"),
        param("max_thrust_sway"),
        param("max_yaw_moment"),
    ];
    let max_tension = param("max_tension");
    for (i, x) in v.iter().enumerate() {
        assert!(x.is_finite(), "command {} is not finite: {x}", COMMANDS[i]);
    }
    for tug in 0..2 {
        for c in 0..3 {
            let x = v[3 * tug + c];
            assert!(
                x.abs() <= limits[c] + 1e-9,
                "tug{} component {c}: {x} exceeds {}",
                tug + 1,
                limits[c]
            );
        }
    }
    for line in 0..2 {
        let f = v[6 + line];
        assert!(
            (0.0..=max_tension + 1e-9).contains(&f),
            "towline{} tension_cmd {f} outside [0, {max_tension}]",
            line + 1
        );
    }
}
