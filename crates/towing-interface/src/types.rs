//! Units and declared types (`UnitDefinitions`, `TypeDefinitions`) and the model-description
//! skeleton both FMUs share. Connected variables have the same unit and declared type in
//! both FMUs because both take them from [`REAL_TYPES`].

use fmi2_slave::description::{
    BaseUnit, DefaultExperiment, DisplayUnit, LogCategory, ModelDescription, SimpleType,
    UnitDefinition, Variable, VariableKind,
};
use towing_model::registry::Enumeration;

/// A Real type: one `SimpleType` and its unit's `UnitDefinition`. Every Real variable with
/// a unit declares the type of its unit ([`ModelInfo::real_kind`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RealType {
    /// `SimpleType/@name`, what `declaredType` refers to.
    pub name: &'static str,
    /// `quantity` (the conventional Modelica name).
    pub quantity: &'static str,
    /// Unit name.
    pub unit: &'static str,
    /// Display unit in degrees (`deg`, `deg/s`), if any; factor 180/pi.
    pub display_unit: Option<&'static str>,
    /// SI decomposition of the unit.
    pub base: BaseUnit,
}

/// SI decomposition `kg^kg m^m s^s rad^rad`, factor 1.
const fn si(kg: i32, m: i32, s: i32, rad: i32) -> BaseUnit {
    BaseUnit {
        kg,
        m,
        s,
        a: 0,
        k: 0,
        mol: 0,
        cd: 0,
        rad,
        factor: 1.0,
        offset: 0.0,
    }
}

impl RealType {
    /// A type with quantity `name`.
    #[must_use]
    pub const fn new(
        name: &'static str,
        unit: &'static str,
        display_unit: Option<&'static str>,
        (kg, m, s, rad): (i32, i32, i32, i32),
    ) -> Self {
        RealType {
            name,
            quantity: name,
            unit,
            display_unit,
            base: si(kg, m, s, rad),
        }
    }

    /// The same type under a different quantity.
    #[must_use]
    pub const fn with_quantity(mut self, quantity: &'static str) -> Self {
        self.quantity = quantity;
        self
    }

    fn unit_definition(&self) -> UnitDefinition {
        UnitDefinition {
            name: self.unit.to_owned(),
            base: self.base,
            display_units: self
                .display_unit
                .map(|name| DisplayUnit {
                    name: name.to_owned(),
                    factor: 180.0 / std::f64::consts::PI,
                    offset: 0.0,
                })
                .into_iter()
                .collect(),
        }
    }

    fn simple_type(&self) -> SimpleType {
        let t = SimpleType::real(self.name, self.quantity, self.unit);
        match self.display_unit {
            Some(d) => t.with_display_unit(d),
            None => t,
        }
    }
}

/// The Real types of the connected variables (and of time), declared by both FMUs in this
/// order.
pub const REAL_TYPES: [RealType; 7] = [
    RealType::new("Length", "m", None, (0, 1, 0, 0)),
    RealType::new("Angle", "rad", Some("deg"), (0, 0, 0, 1)),
    RealType::new("Velocity", "m/s", None, (0, 1, -1, 0)),
    RealType::new("AngularVelocity", "rad/s", Some("deg/s"), (0, 0, -1, 1)),
    RealType::new("Force", "N", None, (1, 1, -2, 0)),
    RealType::new("Torque", "N.m", None, (1, 2, -2, 0)),
    RealType::new("Time", "s", None, (0, 0, 1, 0)),
];

/// The order of [`REAL_TYPES`]' units in `UnitDefinitions` (m, m/s, rad, rad/s, N, N.m, s):
/// the committed model descriptions', on which their GUIDs depend.
const UNIT_ORDER: [usize; 7] = [0, 2, 1, 3, 4, 5, 6];

/// Name of the Integer type of the `obstacle[k].kind` variables.
pub const OBSTACLE_KIND_TYPE: &str = "ObstacleKind";

/// A Real [`VariableKind`] of unit `unit` (empty: dimensionless) with the declared type and
/// display unit of that unit among `types`, no range.
fn real_kind_among<'a>(
    types: impl IntoIterator<Item = &'a RealType>,
    unit: &str,
    start: Option<f64>,
) -> VariableKind {
    let ty = types.into_iter().find(|t| t.unit == unit);
    VariableKind::Real {
        declared_type: ty.map(|t| t.name.to_owned()),
        unit: (!unit.is_empty()).then(|| unit.to_owned()),
        display_unit: ty.and_then(|t| t.display_unit).map(str::to_owned),
        start,
        min: None,
        max: None,
    }
}

/// A Real [`VariableKind`] of a unit of [`REAL_TYPES`].
#[must_use]
pub fn real_kind(unit: &str, start: Option<f64>) -> VariableKind {
    real_kind_among(&REAL_TYPES, unit, start)
}

/// What differs between the two FMUs' model descriptions besides the variables.
#[derive(Debug, Clone, Copy)]
pub struct ModelInfo {
    /// `modelName` and `modelIdentifier`.
    pub model_identifier: &'static str,
    /// `description`.
    pub description: &'static str,
    /// Cargo package (`CARGO_PKG_NAME`), for `generationTool`.
    pub package: &'static str,
    /// Cargo package version (`CARGO_PKG_VERSION`): `version` and `generationTool`.
    pub version: &'static str,
    /// Description of the `logEvents` log category.
    pub log_events: &'static str,
    /// Real types after [`REAL_TYPES`] (and their units).
    pub extra_types: &'static [RealType],
    /// `canGetAndSetFMUstate` and `canSerializeFMUstate`.
    pub fmu_state: bool,
}

impl ModelInfo {
    fn real_types(&self) -> impl Iterator<Item = &RealType> {
        REAL_TYPES.iter().chain(self.extra_types)
    }

    /// A Real [`VariableKind`] of `unit` (empty: dimensionless), with the declared type of
    /// that unit among this model's types (none if it has none).
    #[must_use]
    pub fn real_kind(&self, unit: &str, start: Option<f64>) -> VariableKind {
        real_kind_among(self.real_types(), unit, start)
    }

    /// The model description with `variables` in this order: units and Real types of
    /// [`REAL_TYPES`] and [`extra_types`](Self::extra_types), the Integer type
    /// [`OBSTACLE_KIND_TYPE`], the Enumeration types of the parameters (`enumerations`,
    /// [`crate::parameters::enumerations`]), the standard log categories and `logEvents`,
    /// a default experiment of 1200 s in steps of 0.1 s.
    #[must_use]
    pub fn model_description(
        &self,
        variables: Vec<Variable>,
        enumerations: &[&Enumeration],
    ) -> ModelDescription {
        let mut type_definitions: Vec<SimpleType> =
            self.real_types().map(RealType::simple_type).collect();
        type_definitions.push(
            SimpleType::integer(OBSTACLE_KIND_TYPE, "ObstacleKind")
                .with_integer_range(0, 2)
                .with_description("0 none, 1 static circle, 2 vessel ellipse"),
        );
        type_definitions.extend(
            enumerations
                .iter()
                .map(|e| crate::parameters::simple_type(e)),
        );
        let mut log_categories = LogCategory::standard();
        log_categories.push(LogCategory::new("logEvents", self.log_events));
        ModelDescription {
            model_name: self.model_identifier.to_owned(),
            model_identifier: self.model_identifier.to_owned(),
            description: self.description.to_owned(),
            author: "Towing co-simulation developers".to_owned(),
            version: self.version.to_owned(),
            generation_tool: format!("{} {} (fmi2-slave)", self.package, self.version),
            units: UNIT_ORDER
                .iter()
                .map(|&i| &REAL_TYPES[i])
                .chain(self.extra_types)
                .map(RealType::unit_definition)
                .collect(),
            type_definitions,
            log_categories,
            default_experiment: DefaultExperiment {
                start_time: 0.0,
                stop_time: 1200.0,
                tolerance: None,
                step_size: 0.1,
            },
            variables,
            can_get_and_set_fmu_state: self.fmu_state,
            can_serialize_fmu_state: self.fmu_state,
        }
    }
}
