//! The value-reference codec: every variable of the interface contract as a typed value
//! ([`ContractVariable`]), its value reference ([`ContractVariable::encode`], numbered by
//! [`crate::vr`]) and back ([`ContractVariable::decode`]), and the tables through which
//! each FMU decodes its own variables the same way ([`VariableTable`], [`ModelVariable`]).
//!
//! The FMU crates never compute with value references: their getters and setters decode
//! the reference through their table and match on the typed variable. A reference no table
//! entry has is an [`UnknownReference`], which the FMU returns as `fmi2Error` naming the
//! reference and the FMI type (never a panic, never `fmi2Fatal`).
//!
//! Values: the FMI Integer `obstacle[k].kind` is [`obstacle_kind_code`] of the slot's
//! [`ObstacleKind`] and [`obstacle_kind_from_code`] back, the only place the numbers 0, 1, 2
//! appear; [`StateComponent::of`] and [`ObstacleField::of`] read the Real fields the
//! variables name.

use fmi2_slave::LibraryLazy;
use std::collections::HashMap;
use std::fmt;

use fmi2_slave::ValueType;
use towing_model::{ObstacleKind, ObstacleSlot, VesselState, MAX_OBSTACLES};

use crate::vr;

/// A vessel of the tow, in value-reference order.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Vessel {
    /// The towed ship (CyberShip II).
    Ship,
    /// Tug 1, aft (TitoNeri).
    Tug1,
    /// Tug 2, forward (TitoNeri).
    Tug2,
}

/// A tug, in value-reference order.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Tug {
    /// Tug 1, aft, on towline 1.
    Tug1,
    /// Tug 2, forward, on towline 2.
    Tug2,
}

/// A towline, in value-reference order.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Towline {
    /// Towline 1: ship stern to tug 1's bow.
    Towline1,
    /// Towline 2: ship bow to tug 2's stern.
    Towline2,
}

/// A component of a vessel's state (`eta`, then `nu`), in value-reference order.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum StateComponent {
    /// North position (m).
    X,
    /// East position (m).
    Y,
    /// Heading (rad).
    Psi,
    /// Surge velocity (m/s).
    U,
    /// Sway velocity (m/s).
    V,
    /// Yaw rate (rad/s).
    R,
}

/// A component of a tug's thrust command (tug body frame), in value-reference order.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ForceComponent {
    /// Surge force (N).
    Surge,
    /// Sway force (N).
    Sway,
    /// Yaw moment (N m).
    Yaw,
}

/// A towline output of the plant, in value-reference order.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum TowlineField {
    /// Distance between the attachment points (m).
    Length,
    /// Towing angle alpha (rad).
    Angle,
    /// Mean tension of the last step (N).
    Tension,
    /// No force at the end of the last step (Boolean; the plant's only).
    Slack,
}

/// A field of an obstacle slot ([`ObstacleSlot`]), in value-reference order.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ObstacleField {
    /// Centre North (m).
    X,
    /// Centre East (m).
    Y,
    /// Course (rad).
    Psi,
    /// Speed (m/s).
    Speed,
    /// Major axis or diameter (m).
    Length,
    /// Minor axis or diameter (m).
    Width,
    /// What occupies the slot (Integer, [`obstacle_kind_code`]).
    Kind,
}

/// An obstacle slot, 0-based (`obstacle[k]` is slot `k - 1`), below [`MAX_OBSTACLES`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Slot(usize);

macro_rules! ordered {
    ($ty:ident: $($variant:ident => $name:literal),+ $(,)?) => {
        impl $ty {
            /// Every value, in value-reference order.
            pub const ALL: [$ty; [$($name),+].len()] = [$($ty::$variant),+];

            /// Position in [`Self::ALL`] (the offset in the value references).
            #[must_use]
            pub const fn index(self) -> usize {
                self as usize
            }

            /// Its part of the FMI name.
            #[must_use]
            pub const fn name(self) -> &'static str {
                match self {
                    $($ty::$variant => $name),+
                }
            }
        }
    };
}

ordered!(Vessel: Ship => "ship", Tug1 => "tug1", Tug2 => "tug2");
ordered!(Tug: Tug1 => "tug1", Tug2 => "tug2");
ordered!(Towline: Towline1 => "towline1", Towline2 => "towline2");
ordered!(StateComponent: X => "x", Y => "y", Psi => "psi", U => "u", V => "v", R => "r");
ordered!(ForceComponent: Surge => "force_surge", Sway => "force_sway", Yaw => "moment_yaw");
ordered!(TowlineField: Length => "length", Angle => "angle", Tension => "tension", Slack => "slack");
ordered!(
    ObstacleField: X => "x", Y => "y", Psi => "psi", Speed => "speed", Length => "length",
    Width => "width", Kind => "kind",
);

impl Tug {
    /// The vessel this tug is.
    #[must_use]
    pub const fn vessel(self) -> Vessel {
        match self {
            Tug::Tug1 => Vessel::Tug1,
            Tug::Tug2 => Vessel::Tug2,
        }
    }
}

impl Slot {
    /// Slot `index` (0-based); `None` from [`MAX_OBSTACLES`] on.
    #[must_use]
    pub const fn new(index: usize) -> Option<Slot> {
        if index < MAX_OBSTACLES {
            Some(Slot(index))
        } else {
            None
        }
    }

    /// Every slot, in order.
    pub fn all() -> impl Iterator<Item = Slot> {
        (0..MAX_OBSTACLES).map(Slot)
    }

    /// The 0-based index.
    #[must_use]
    pub const fn index(self) -> usize {
        self.0
    }
}

impl StateComponent {
    /// The component of `state` (`eta[0..3]`, `nu[0..3]`).
    #[must_use]
    pub fn of(self, state: &VesselState) -> f64 {
        let i = self.index();
        if i < 3 {
            state.eta[i]
        } else {
            state.nu[i - 3]
        }
    }
}

impl ObstacleField {
    /// The Real field of `slot`; `None` for [`ObstacleField::Kind`].
    #[must_use]
    pub fn of(self, slot: &ObstacleSlot) -> Option<f64> {
        Some(match self {
            ObstacleField::X => slot.x,
            ObstacleField::Y => slot.y,
            ObstacleField::Psi => slot.psi,
            ObstacleField::Speed => slot.speed,
            ObstacleField::Length => slot.length,
            ObstacleField::Width => slot.width,
            ObstacleField::Kind => return None,
        })
    }

    /// The Real field of `slot`, to write; `None` for [`ObstacleField::Kind`].
    pub fn of_mut(self, slot: &mut ObstacleSlot) -> Option<&mut f64> {
        match self {
            ObstacleField::X => Some(&mut slot.x),
            ObstacleField::Y => Some(&mut slot.y),
            ObstacleField::Psi => Some(&mut slot.psi),
            ObstacleField::Speed => Some(&mut slot.speed),
            ObstacleField::Length => Some(&mut slot.length),
            ObstacleField::Width => Some(&mut slot.width),
            ObstacleField::Kind => None,
        }
    }
}

/// Every variable a master connects between the two FMUs (DESIGN.md, "Interface
/// contract"). Which FMU outputs which: crate docs. The String parameters both FMUs
/// declare (`scenario`, `log_file`, `run_id`) are the session's
/// ([`crate::session::PARAMETERS`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ContractVariable {
    /// `ship.x` .. `tug2.r` (Real).
    VesselState(Vessel, StateComponent),
    /// `tug1.force_surge` .. `tug2.moment_yaw` (Real).
    TugForce(Tug, ForceComponent),
    /// `towline1.tension_cmd`, `towline2.tension_cmd` (Real).
    TensionCmd(Towline),
    /// `towline1.length` .. `towline2.slack` (Real; `slack` Boolean).
    Towline(Towline, TowlineField),
    /// `obstacle[1].x` .. `obstacle[8].kind` (Real; `kind` Integer).
    Obstacle(Slot, ObstacleField),
}

/// Every contract variable by value reference, built once.
static CONTRACT: LibraryLazy<VariableTable<ContractVariable>> =
    LibraryLazy::new(|| VariableTable::new("the interface contract", ContractVariable::all()));

impl ContractVariable {
    /// Every contract variable, in value-reference order.
    pub fn all() -> impl Iterator<Item = ContractVariable> {
        use ContractVariable as C;
        let states = Vessel::ALL
            .into_iter()
            .flat_map(|v| StateComponent::ALL.map(|c| C::VesselState(v, c)));
        let forces = Tug::ALL
            .into_iter()
            .flat_map(|t| ForceComponent::ALL.map(|c| C::TugForce(t, c)));
        let towlines = Towline::ALL
            .into_iter()
            .flat_map(|l| TowlineField::ALL.map(|f| C::Towline(l, f)));
        let obstacles = Slot::all().flat_map(|s| ObstacleField::ALL.map(|f| C::Obstacle(s, f)));
        states
            .chain(forces)
            .chain(Towline::ALL.map(C::TensionCmd))
            .chain(towlines)
            .chain(obstacles)
    }

    /// The value reference (the numbering of [`crate::vr`]); unique among the contract's
    /// variables of every type.
    #[must_use]
    pub const fn encode(self) -> u32 {
        use ContractVariable as C;
        // The indices are below 10 (MAX_OBSTACLES = 8): the casts are exact.
        match self {
            C::VesselState(v, c) => vr::vessel_state(v.index() as u32, c.index() as u32),
            C::TugForce(t, c) => vr::tug_force(t.index() as u32, c.index() as u32),
            C::TensionCmd(l) => vr::tension_cmd(l.index() as u32),
            C::Towline(l, f) => vr::towline(l.index() as u32, f.index() as u32),
            C::Obstacle(s, f) => vr::obstacle(s.index() as u32, f.index() as u32),
        }
    }

    /// The contract variable of value reference `vr`.
    ///
    /// # Errors
    /// [`UnknownReference`] when no contract variable has it.
    pub fn decode(vr: u32) -> Result<ContractVariable, UnknownReference> {
        CONTRACT.decode_any(vr)
    }

    /// The FMI base type.
    #[must_use]
    pub const fn value_type(self) -> ValueType {
        use ContractVariable as C;
        match self {
            C::Towline(_, TowlineField::Slack) => ValueType::Boolean,
            C::Obstacle(_, ObstacleField::Kind) => ValueType::Integer,
            _ => ValueType::Real,
        }
    }

    /// The FMI name, e.g. `ship.psi`, `towline2.tension_cmd`, `obstacle[3].kind`.
    #[must_use]
    pub fn name(self) -> String {
        use ContractVariable as C;
        match self {
            C::VesselState(v, c) => format!("{}.{}", v.name(), c.name()),
            C::TugForce(t, c) => format!("{}.{}", t.name(), c.name()),
            C::TensionCmd(l) => format!("{}.tension_cmd", l.name()),
            C::Towline(l, f) => format!("{}.{}", l.name(), f.name()),
            C::Obstacle(s, f) => format!("obstacle[{}].{}", s.index() + 1, f.name()),
        }
    }
}

/// A value reference that names no variable of a type in a model (or in the contract).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct UnknownReference {
    /// The value reference asked for.
    pub value_reference: u32,
    /// The FMI type asked for; `None` when any type would do.
    pub value_type: Option<ValueType>,
    /// Whose variables: the model identifier, or `the interface contract`.
    pub model: &'static str,
}

impl fmt::Display for UnknownReference {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let vr = self.value_reference;
        match self.value_type {
            Some(ty) => write!(
                f,
                "unknown value reference {vr}: no {} variable of {} has it",
                ty.as_str(),
                self.model
            ),
            None => write!(
                f,
                "unknown value reference {vr}: no variable of {} has it",
                self.model
            ),
        }
    }
}

impl std::error::Error for UnknownReference {}

impl From<UnknownReference> for String {
    fn from(e: UnknownReference) -> String {
        e.to_string()
    }
}

/// A variable of one FMU as its getters and setters see it: what its [`VariableTable`]
/// decodes a value reference to.
pub trait ModelVariable: Copy + Eq + fmt::Debug + Send + Sync + 'static {
    /// The value reference.
    fn value_reference(self) -> u32;
    /// The FMI base type.
    fn value_type(self) -> ValueType;
    /// The contract variable it is, if any (its name is then the contract's).
    fn contract(self) -> Option<ContractVariable> {
        None
    }
}

impl ModelVariable for ContractVariable {
    fn value_reference(self) -> u32 {
        self.encode()
    }

    fn value_type(self) -> ValueType {
        ContractVariable::value_type(self)
    }

    fn contract(self) -> Option<ContractVariable> {
        Some(self)
    }
}

/// One FMU's variables by (FMI type, value reference), built once from the list of its
/// variables (an FMU keeps it in a `fmi2_slave::LibraryLazy`). The FMU's getters and setters decode every
/// reference through it.
#[derive(Debug)]
pub struct VariableTable<V> {
    model: &'static str,
    variables: Vec<V>,
    by_reference: HashMap<(ValueType, u32), V>,
}

impl<V: ModelVariable> VariableTable<V> {
    /// The table of `variables` of `model` (its model identifier, for messages). A second
    /// variable with the type and value reference of an earlier one is not reachable; the
    /// round-trip check of `testing` finds it.
    pub fn new(model: &'static str, variables: impl IntoIterator<Item = V>) -> Self {
        let variables: Vec<V> = variables.into_iter().collect();
        let mut by_reference = HashMap::with_capacity(variables.len());
        for &v in &variables {
            by_reference
                .entry((v.value_type(), v.value_reference()))
                .or_insert(v);
        }
        VariableTable {
            model,
            variables,
            by_reference,
        }
    }

    /// The variable of type `ty` with value reference `vr`.
    ///
    /// # Errors
    /// [`UnknownReference`] naming `vr`, `ty` and the model when there is none.
    pub fn decode(&self, ty: ValueType, vr: u32) -> Result<V, UnknownReference> {
        self.by_reference
            .get(&(ty, vr))
            .copied()
            .ok_or_else(|| self.unknown(ty, vr))
    }

    /// The variable with value reference `vr`, of whatever type (for tables whose
    /// references are unique across types, as the contract's).
    fn decode_any(&self, vr: u32) -> Result<V, UnknownReference> {
        [
            ValueType::Real,
            ValueType::Integer,
            ValueType::Boolean,
            ValueType::String,
        ]
        .into_iter()
        .find_map(|ty| self.by_reference.get(&(ty, vr)).copied())
        .ok_or(UnknownReference {
            value_reference: vr,
            value_type: None,
            model: self.model,
        })
    }

    /// The error of a reference this model has no variable of type `ty` for.
    #[must_use]
    pub fn unknown(&self, ty: ValueType, vr: u32) -> UnknownReference {
        UnknownReference {
            value_reference: vr,
            value_type: Some(ty),
            model: self.model,
        }
    }

    /// The error of a getter or setter of type `ty` that does not handle `variable` (which
    /// the table knows): a variable added to the table without its getter or setter.
    #[must_use]
    pub fn unhandled(&self, ty: ValueType, variable: V, what: &str) -> String {
        format!(
            "{} cannot {what} {variable:?} (value reference {}) as a {} variable",
            self.model,
            variable.value_reference(),
            ty.as_str()
        )
    }

    /// The model identifier.
    #[must_use]
    pub fn model(&self) -> &'static str {
        self.model
    }

    /// Every variable, in the order given.
    pub fn variables(&self) -> impl Iterator<Item = V> + '_ {
        self.variables.iter().copied()
    }
}

/// The FMI Integer `obstacle[k].kind` of `kind`: 0 none, 1 static circle, 2 vessel ellipse
/// (DESIGN.md, "Interface contract"; the `ObstacleKind` type of the model descriptions).
#[must_use]
pub const fn obstacle_kind_code(kind: ObstacleKind) -> i32 {
    match kind {
        ObstacleKind::None => 0,
        ObstacleKind::StaticCircle => 1,
        ObstacleKind::VesselEllipse => 2,
    }
}

/// The [`ObstacleKind`] of the FMI Integer `obstacle[k].kind`.
///
/// # Errors
/// A message naming the code and the valid ones, for any code but 0, 1, 2.
pub fn obstacle_kind_from_code(code: i32) -> Result<ObstacleKind, String> {
    [
        ObstacleKind::None,
        ObstacleKind::StaticCircle,
        ObstacleKind::VesselEllipse,
    ]
    .into_iter()
    .find(|&kind| obstacle_kind_code(kind) == code)
    .ok_or_else(|| {
        format!("unknown obstacle kind {code} (0 none, 1 static circle, 2 vessel ellipse)")
    })
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn every_contract_variable_decodes_to_itself() {
        let all: Vec<ContractVariable> = ContractVariable::all().collect();
        // 18 states, 6 forces, 2 tension commands, 8 towline fields, 7 fields of 8 slots.
        assert_eq!(all.len(), 18 + 6 + 2 + 8 + 7 * MAX_OBSTACLES);
        for &v in &all {
            assert_eq!(ContractVariable::decode(v.encode()), Ok(v), "{}", v.name());
        }
        let mut refs: Vec<u32> = all.iter().map(|v| v.encode()).collect();
        assert!(
            refs.windows(2).all(|w| w[0] < w[1]),
            "value-reference order"
        );
        refs.dedup();
        assert_eq!(refs.len(), all.len(), "unique value references");
    }

    #[test]
    fn value_references_are_those_of_the_committed_model_descriptions() {
        use ContractVariable as C;
        let slot = |k| Slot::new(k).unwrap();
        for (v, vr) in [
            (C::VesselState(Vessel::Ship, StateComponent::X), 100),
            (C::VesselState(Vessel::Tug2, StateComponent::R), 125),
            (C::TugForce(Tug::Tug1, ForceComponent::Surge), 200),
            (C::TugForce(Tug::Tug2, ForceComponent::Yaw), 212),
            (C::TensionCmd(Towline::Towline2), 221),
            (C::Towline(Towline::Towline1, TowlineField::Length), 300),
            (C::Towline(Towline::Towline2, TowlineField::Slack), 313),
            (C::Obstacle(slot(0), ObstacleField::X), 1000),
            (C::Obstacle(slot(7), ObstacleField::Kind), 1076),
        ] {
            assert_eq!(v.encode(), vr, "{}", v.name());
        }
        assert_eq!(
            C::Obstacle(slot(2), ObstacleField::Kind).name(),
            "obstacle[3].kind"
        );
        assert_eq!(
            C::TensionCmd(Towline::Towline1).name(),
            "towline1.tension_cmd"
        );
        assert_eq!(Slot::new(MAX_OBSTACLES), None);
    }

    #[test]
    fn unknown_references_are_named_with_their_type() {
        // 1, 2, 3: the session's parameters, not the contract's.
        for vr in [0, 1, 3, 99, 126, 222, 314, 1007, 1080, u32::MAX] {
            let e = ContractVariable::decode(vr).unwrap_err();
            assert_eq!(
                e.to_string(),
                format!(
                    "unknown value reference {vr}: no variable of the interface contract has it"
                )
            );
        }
        let table = VariableTable::new("TowingPlant", ContractVariable::all());
        let e = table.decode(ValueType::Integer, 100).unwrap_err();
        assert_eq!(
            e.to_string(),
            "unknown value reference 100: no Integer variable of TowingPlant has it"
        );
    }

    #[test]
    fn obstacle_kinds_round_trip_and_other_codes_are_refused() {
        for code in 0..3 {
            let kind = obstacle_kind_from_code(code);
            assert_eq!(kind.map(obstacle_kind_code), Ok(code));
        }
        for code in [-1, 3, i32::MAX] {
            let e = obstacle_kind_from_code(code).unwrap_err();
            assert!(e.contains(&format!("unknown obstacle kind {code}")), "{e}");
        }
    }

    #[test]
    fn fields_read_the_slot_and_the_state() {
        let slot = ObstacleSlot {
            x: 1.0,
            y: 2.0,
            psi: 3.0,
            speed: 4.0,
            length: 5.0,
            width: 6.0,
            kind: ObstacleKind::StaticCircle,
        };
        let values: Vec<Option<f64>> = ObstacleField::ALL.iter().map(|f| f.of(&slot)).collect();
        assert_eq!(
            values,
            [1.0, 2.0, 3.0, 4.0, 5.0, 6.0]
                .map(Some)
                .into_iter()
                .chain([None])
                .collect::<Vec<_>>()
        );
        let state = VesselState {
            eta: [1.0, 2.0, 3.0],
            nu: [4.0, 5.0, 6.0],
        };
        let values: Vec<f64> = StateComponent::ALL.iter().map(|c| c.of(&state)).collect();
        assert_eq!(values, [1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
    }
}
