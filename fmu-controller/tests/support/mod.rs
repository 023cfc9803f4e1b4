//! Shared set-up of the controller's in-process tests: an instance on the repository's
//! `scenarios/` folder (holding `paper.toml` like the packaged FMU's `resources/`) and the
//! paper scenario's initial states as plant-like inputs.
#![allow(dead_code, clippy::unwrap_used, clippy::expect_used)]

use fmi2_slave::ffi::Fmi2Status;
use fmi2_slave::testing::{Exports, Fmu};
use towing_controller::variables::{self as vars, DESCRIPTION};
pub use towing_interface::COMMANDS;
use towing_model::Scenario;

pub fn exports() -> Exports {
    fmi2_slave::exports_of!(towing_controller)
}

/// A freshly instantiated controller (not initialized).
pub fn controller(name: &str) -> Fmu {
    towing_interface::testing::instantiate(exports(), &DESCRIPTION, name)
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
    let vrs: Vec<u32> = (0..6).map(|j| vars::obstacle(slot, j)).collect();
    assert_eq!(
        fmu.set_reals(&vrs, &fields),
        Fmi2Status::Ok,
        "{}",
        fmu.log_text()
    );
    assert_eq!(
        fmu.set_integer(vars::obstacle(slot, vars::OBSTACLE_KIND), kind),
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
        param("mpc.tug.max_force_surge"),
        param("mpc.tug.max_force_sway"),
        param("mpc.tug.max_moment_yaw"),
    ];
    let max_tension = param("mpc.ship.max_tension");
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
