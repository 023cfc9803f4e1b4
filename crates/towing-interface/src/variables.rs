//! Builders of the connected variables for one end of a connection, and the generic
//! parameter, input and output builders both FMUs use for their own variables.
//!
//! The measurements (vessel states, towline values, obstacle slots) are computed by the
//! plant from the scenario at initialization (`initial="calculated"`, initial dependency on
//! the session's `scenario`, [`vr::SCENARIO`]); the commands (tug forces, tension commands) are the controller's outputs and
//! hold their start value 0 until its first step (`initial="exact"`). Every input starts at
//! 0. The descriptions say what the variable means to the FMU that declares it.

use crate::codec::{
    ContractVariable, ForceComponent, ObstacleField, Slot, StateComponent, Towline, TowlineField,
    Tug, Vessel,
};
use crate::types::{real_kind, OBSTACLE_KIND_TYPE};
use crate::{vr, VESSELS};
use fmi2_slave::description::{Causality, Initial, Variability, Variable, VariableKind};

/// Which end of a connection an FMU is for a group of variables.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Direction {
    /// The FMU computes the variables (`causality="output"`).
    Output,
    /// The FMU reads the variables (`causality="input"`).
    Input,
}

/// A connected Real field (its name is the codec's: [`ContractVariable::name`]): unit, and
/// its description in the FMU that outputs it and in the one that reads it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Field {
    /// Unit (one of [`REAL_TYPES`](crate::types::REAL_TYPES)).
    pub unit: &'static str,
    /// Meaning where it is an output.
    pub output: &'static str,
    /// Meaning where it is an input.
    pub input: &'static str,
}

impl Field {
    const fn new(unit: &'static str, output: &'static str, input: &'static str) -> Self {
        Field {
            unit,
            output,
            input,
        }
    }

    const fn same(unit: &'static str, meaning: &'static str) -> Self {
        Field::new(unit, meaning, meaning)
    }

    fn meaning(&self, direction: Direction) -> &'static str {
        match direction {
            Direction::Output => self.output,
            Direction::Input => self.input,
        }
    }
}

/// A vessel's states x, y, psi, u, v, r (NED position, heading, body-frame velocities), by
/// [`StateComponent::index`].
pub const STATES: [Field; 6] = [
    Field::same("m", "North position of the body origin (NED)"),
    Field::same("m", "East position of the body origin (NED)"),
    Field::new(
        "rad",
        "heading from North, clockwise positive, wrapped to (-pi, pi]",
        "heading from North, clockwise positive",
    ),
    Field::same("m/s", "surge velocity (body frame)"),
    Field::same("m/s", "sway velocity (body frame, starboard positive)"),
    Field::same("rad/s", "yaw rate (clockwise positive)"),
];

/// A tug's force commands (tug body frame), by [`ForceComponent::index`].
pub const TUG_FORCES: [Field; 3] = [
    Field::new("N",
        "commanded thruster force along the tug's body x axis (MPC thrust plus the inner loop, within the thrust limits)",
        "thruster force along the tug's body x axis",
    ),
    Field::new("N",
        "commanded thruster force along the tug's body y axis (starboard; MPC thrust plus the inner loop, within the thrust limits)",
        "thruster force along the tug's body y axis (starboard)",
    ),
    Field::new("N.m",
        "commanded thruster moment about the tug's body z axis (clockwise positive; MPC thrust plus the inner loop, within the thrust limits)",
        "thruster moment about the tug's body z axis (clockwise positive)",
    ),
];

/// Obstacle slot fields by [`ObstacleField::index`] (the Real ones; `kind` is the Integer
/// [`ObstacleField::Kind`]).
pub const OBSTACLE_FIELDS: [Field; 6] = [
    Field::same("m", "North position of the obstacle centre"),
    Field::same("m", "East position of the obstacle centre"),
    Field::new(
        "rad",
        "course of a target ship (0 for static hazards)",
        "course of a target ship (ignored for static hazards)",
    ),
    Field::new(
        "m/s",
        "speed of a target ship (0 for static hazards and before activation)",
        "speed of a target ship (ignored for static hazards)",
    ),
    Field::same(
        "m",
        "major axis of a target ship's ellipse; diameter of a static circle",
    ),
    Field::same(
        "m",
        "minor axis of a target ship's ellipse; diameter of a static circle",
    ),
];

/// A variable of `causality` with `initial` unset and no dependencies, continuous when Real
/// and discrete otherwise; the builders below adjust it.
fn variable(
    name: String,
    vr: u32,
    causality: Causality,
    kind: VariableKind,
    description: String,
) -> Variable {
    let variability = match kind {
        VariableKind::Real { .. } => Variability::Continuous,
        _ => Variability::Discrete,
    };
    Variable {
        name,
        value_reference: vr,
        description,
        causality,
        variability,
        initial: None,
        kind,
        output_dependencies: None,
        initial_dependencies: None,
    }
}

/// A parameter (`variability="fixed"`, `initial="exact"`).
#[must_use]
pub fn parameter(name: &str, vr: u32, kind: VariableKind, description: &str) -> Variable {
    Variable {
        variability: Variability::Fixed,
        initial: Some(Initial::Exact),
        ..variable(
            name.to_owned(),
            vr,
            Causality::Parameter,
            kind,
            description.to_owned(),
        )
    }
}

/// An input (its start value is in `kind`).
#[must_use]
pub fn input(name: String, vr: u32, kind: VariableKind, description: String) -> Variable {
    variable(name, vr, Causality::Input, kind, description)
}

/// An output with `initial="exact"`: it holds its start value until the first `fmi2DoStep`
/// computes it, and has no direct feedthrough from the inputs.
#[must_use]
pub fn exact_output(name: String, vr: u32, kind: VariableKind, description: String) -> Variable {
    Variable {
        initial: Some(Initial::Exact),
        output_dependencies: Some(vec![]),
        ..variable(name, vr, Causality::Output, kind, description)
    }
}

/// An output with `initial="calculated"` (no start value in `kind`), no direct feedthrough
/// from the inputs, its initial value depending on `initial_dependencies`.
#[must_use]
pub fn calculated_output(
    name: String,
    vr: u32,
    kind: VariableKind,
    description: String,
    initial_dependencies: Vec<u32>,
) -> Variable {
    Variable {
        initial: Some(Initial::Calculated),
        output_dependencies: Some(vec![]),
        initial_dependencies: Some(initial_dependencies),
        ..variable(name, vr, Causality::Output, kind, description)
    }
}

/// A measurement `var` (plant output, controller input) of `unit`.
fn measurement(
    direction: Direction,
    var: ContractVariable,
    unit: &str,
    description: String,
) -> Variable {
    let (name, vr) = (var.name(), var.encode());
    match direction {
        Direction::Output => calculated_output(
            name,
            vr,
            real_kind(unit, None),
            description,
            vec![vr::SCENARIO],
        ),
        Direction::Input => input(name, vr, real_kind(unit, Some(0.0)), description),
    }
}

/// A command `var` (controller output, plant input) of `unit`, start 0.
fn command(
    direction: Direction,
    var: ContractVariable,
    unit: &str,
    description: String,
) -> Variable {
    let (name, vr) = (var.name(), var.encode());
    let kind = real_kind(unit, Some(0.0));
    match direction {
        Direction::Output => exact_output(name, vr, kind, description),
        Direction::Input => input(name, vr, kind, description),
    }
}

/// The commands: `tug1.force_surge` .. `tug2.moment_yaw`, then `towline1.tension_cmd`,
/// `towline2.tension_cmd`.
#[must_use]
pub fn commands(direction: Direction) -> Vec<Variable> {
    let mut v = Vec::new();
    for tug in Tug::ALL {
        let (_, what) = VESSELS[tug.vessel().index()];
        for c in ForceComponent::ALL {
            let field = &TUG_FORCES[c.index()];
            v.push(command(
                direction,
                ContractVariable::TugForce(tug, c),
                field.unit,
                format!("{what} {}", field.meaning(direction)),
            ));
        }
    }
    for line in Towline::ALL {
        let n = line.index() + 1;
        v.push(command(
            direction,
            ContractVariable::TensionCmd(line),
            "N",
            match direction {
                Direction::Output => format!(
                    "commanded towline {n} tension of the last sample, held until the next (within [min_tension, max_tension])"
                ),
                Direction::Input => format!(
                    "commanded towline {n} tension (winch pull; values <= 0 leave the line slack)"
                ),
            },
        ));
    }
    v
}

/// The vessel states `ship.x` .. `tug2.r`.
#[must_use]
pub fn vessel_states(direction: Direction) -> Vec<Variable> {
    let mut v = Vec::new();
    for vessel in Vessel::ALL {
        let (_, what) = VESSELS[vessel.index()];
        for c in StateComponent::ALL {
            let field = &STATES[c.index()];
            let meaning = field.meaning(direction);
            v.push(measurement(
                direction,
                ContractVariable::VesselState(vessel, c),
                field.unit,
                match direction {
                    Direction::Output => format!("{what}: {meaning}"),
                    Direction::Input => format!("measured {what}: {meaning}"),
                },
            ));
        }
    }
    v
}

/// `towlineN.length`, `.angle`, `.tension` of `line` (the plant adds the Boolean `slack`).
#[must_use]
pub fn towline(line: Towline, direction: Direction) -> Vec<Variable> {
    let n = line.index() + 1;
    let ends = match line {
        Towline::Towline1 => "ship stern point to the aft tug's bow point",
        Towline::Towline2 => "ship bow point to the forward tug's stern point",
    };
    // Field, unit, meaning to the controller (which reads them but does not use them).
    let fields = [
        (
            TowlineField::Length,
            "m",
            "distance between the attachment points",
        ),
        (TowlineField::Angle, "rad", "measured towing angle alpha"),
        (TowlineField::Tension, "N", "measured tension"),
    ];
    let mut v: Vec<Variable> = fields
        .iter()
        .map(|&(field, unit, input_meaning)| {
            let description = match (direction, field) {
                (Direction::Output, TowlineField::Length) => {
                    format!("distance between the towline {n} attachment points ({ends})")
                }
                (Direction::Output, TowlineField::Angle) => format!(
                    "towing angle alpha_{n} (Du et al. 2022, eq. (4)-(6), consistent form of docs/interface.md): towline direction relative to the ship heading"
                ),
                (Direction::Output, _) => format!(
                    "tension applied by towline {n} during the last communication step (mean over the substeps)"
                ),
                (Direction::Input, _) => format!(
                    "towline {n} {input_meaning} (plant output; accepted for connection by name, not used: the MPC predicts the lines from the formation geometry)"
                ),
            };
            measurement(
                direction,
                ContractVariable::Towline(line, field),
                unit,
                description,
            )
        })
        .collect();
    // The tension is that of the last step: at initialization it does not depend on the
    // scenario.
    if direction == Direction::Output {
        v[2].initial_dependencies = Some(vec![]);
    }
    v
}

/// The obstacle slots `obstacle[1].x` .. `obstacle[8].kind`.
#[must_use]
pub fn obstacles(direction: Direction) -> Vec<Variable> {
    let mut v = Vec::new();
    for slot in Slot::all() {
        let k = slot.index() + 1;
        // The Real fields; `kind`, the last, follows.
        for (field, meaning) in ObstacleField::ALL.iter().zip(&OBSTACLE_FIELDS) {
            v.push(measurement(
                direction,
                ContractVariable::Obstacle(slot, *field),
                meaning.unit,
                format!("obstacle slot {k}: {}", meaning.meaning(direction)),
            ));
        }
        let kind_var = ContractVariable::Obstacle(slot, ObstacleField::Kind);
        let (name, kind_vr) = (kind_var.name(), kind_var.encode());
        let kind = |start| VariableKind::Integer {
            declared_type: Some(OBSTACLE_KIND_TYPE.to_owned()),
            start,
            min: Some(0),
            max: Some(2),
        };
        v.push(match direction {
            Direction::Output => calculated_output(
                name,
                kind_vr,
                kind(None),
                format!("obstacle slot {k}: 0 none (empty slot or target ship not yet active), 1 static circle, 2 vessel ellipse"),
                vec![vr::SCENARIO],
            ),
            Direction::Input => input(
                name,
                kind_vr,
                kind(Some(0)),
                format!("obstacle slot {k}: 0 none (ignored), 1 static circle, 2 vessel ellipse"),
            ),
        });
    }
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(v: &[Variable]) -> Vec<&str> {
        v.iter().map(|v| v.name.as_str()).collect()
    }

    /// Both ends declare the same names, value references, types and units.
    #[test]
    fn both_directions_declare_the_same_connections() {
        let groups: [fn(Direction) -> Vec<Variable>; 5] = [
            commands,
            vessel_states,
            |d| towline(Towline::Towline1, d),
            |d| towline(Towline::Towline2, d),
            obstacles,
        ];
        for group in groups {
            let out = group(Direction::Output);
            let inp = group(Direction::Input);
            assert_eq!(names(&out), names(&inp));
            for (o, i) in out.iter().zip(&inp) {
                assert_eq!(o.value_reference, i.value_reference, "{}", o.name);
                assert_eq!(o.causality, Causality::Output);
                assert_eq!(i.causality, Causality::Input);
                assert_eq!(o.kind.declared_type(), i.kind.declared_type(), "{}", o.name);
                assert_eq!(o.variability, i.variability, "{}", o.name);
            }
        }
    }

    #[test]
    fn every_contract_name_has_a_builder() {
        let mut all = Vec::new();
        for d in [Direction::Output, Direction::Input] {
            all.extend(commands(d));
            all.extend(vessel_states(d));
            all.extend(towline(Towline::Towline1, d));
            all.extend(towline(Towline::Towline2, d));
            all.extend(obstacles(d));
        }
        let session: Vec<&str> = crate::session::PARAMETERS.iter().map(|p| p.name).collect();
        assert_eq!(session, ["scenario", "log_file", "run_id"]);
        for name in crate::contract_names() {
            assert!(
                all.iter().any(|v| v.name == name) || session.contains(&name.as_str()),
                "{name}"
            );
        }
    }
}
