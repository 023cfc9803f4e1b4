//! The numbering of the contract's value references, the same in both FMUs and unique
//! across the FMI base types (so [`ContractVariable::decode`](crate::ContractVariable::decode)
//! needs no type). [`ContractVariable::encode`](crate::ContractVariable::encode) follows it;
//! the FMUs decode through [`crate::codec`], never with these numbers. The functions here
//! take 0-based indices (tests and masters use them to address a variable):
//!
//! | range | what |
//! |---|---|
//! | 1, 2, 3 | the session's String parameters `scenario`, `log_file`, `run_id` ([`session_parameter`], [`crate::session::PARAMETERS`]) |
//! | 10.. | each FMU's own parameters, `10 + index` ([`crate::parameters::parameter_vr`]), below 100 |
//! | 100 + 10 vessel + c | vessel states (ship 100.., tug1 110.., tug2 120..; c: x, y, psi, u, v, r) |
//! | 200 + 10 tug + c, 220 + line | commands: tug forces (tug1 200.., tug2 210..), tension commands |
//! | 300 + 10 line + field | towline values (towline1 300.., towline2 310..) |
//! | 1000 + 10 (k - 1) + j | obstacle slot k = 1..=8, field j |

/// The session's String parameter `index` ([`crate::session::PARAMETERS`]): `1 + index`.
#[must_use]
pub const fn session_parameter(index: usize) -> u32 {
    // Three session parameters: the cast is exact.
    1 + index as u32
}

/// `scenario` (String parameter): path of the scenario file; empty = bundled paper scenario.
pub const SCENARIO: u32 = session_parameter(0);

/// `log_file` (String parameter): path of the MCAP log (docs/logging.md); empty = no log.
pub const LOG_FILE: u32 = session_parameter(1);

/// `run_id` (String parameter): the run's identifier, written into the log's run
/// description; empty = none.
pub const RUN_ID: u32 = session_parameter(2);

/// Vessel state: vessel 0 ship, 1 tug1, 2 tug2; component 0..6 = x, y, psi, u, v, r.
pub const fn vessel_state(vessel: u32, component: u32) -> u32 {
    100 + 10 * vessel + component
}

/// Tug force command: tug 0 (tug1) or 1 (tug2); component 0 surge force, 1 sway force,
/// 2 yaw moment.
pub const fn tug_force(tug: u32, component: u32) -> u32 {
    200 + 10 * tug + component
}

/// Tension command of towline 0 (towline1) or 1 (towline2).
pub const fn tension_cmd(line: u32) -> u32 {
    220 + line
}

/// Towline value of line 0 or 1: field 0 length, 1 angle, 2 tension, 3 slack (Boolean,
/// plant only).
pub const fn towline(line: u32, field: u32) -> u32 {
    300 + 10 * line + field
}

/// Obstacle slot value, `slot` 0-based; field index of
/// [`ObstacleField`](crate::codec::ObstacleField) (x, y, psi, speed, length, width, then
/// [`OBSTACLE_KIND`]).
pub const fn obstacle(slot: u32, field: u32) -> u32 {
    1000 + 10 * slot + field
}

/// Field index of the Integer `obstacle[k].kind` within a slot.
pub const OBSTACLE_KIND: u32 = 6;
