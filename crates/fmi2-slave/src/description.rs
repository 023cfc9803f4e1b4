//! The model description (FMI 2.0 chapter 2.2) and its `modelDescription.xml` writer.
//!
//! Safe code only. A model crate builds one [`ModelDescription`] (in a
//! [`LibraryLazy`](crate::LibraryLazy) static, freed when a host unloads the library) from a
//! table of [`Variable`]s; the slave layer uses the same value at run time (value-reference
//! lookup, causality checks, log categories, GUID), and the packaging step writes
//! [`ModelDescription::to_xml`] into the FMU. The FMU never reads its own XML at run time.
//!
//! What the writer guarantees (checked by [`ModelDescription::validate`] and the unit
//! tests), following FMI 2.0 sections 2.2.1 to 2.2.8 and what fmpy's and fmi-rs's validators
//! enforce:
//!
//! * element order `CoSimulation`, `UnitDefinitions`, `TypeDefinitions`, `LogCategories`,
//!   `DefaultExperiment`, `ModelVariables`, `ModelStructure` (empty
//!   `UnitDefinitions`/`TypeDefinitions`/`LogCategories` omitted, no `VendorAnnotations`);
//! * a variable's `declaredType` names a `SimpleType` of the same kind whose units are
//!   declared; the variable still writes its own `unit`/`displayUnit` (which must agree
//!   with the type's); an `Enumeration` variable names an Enumeration type (its
//!   `declaredType` is required) and starts at one of its items' values (sections 2.2.3,
//!   2.2.7);
//! * `causality` and `variability` always written; `initial` written explicitly (the
//!   effective value) for every variable except inputs and the independent variable, which
//!   must not carry it;
//! * `ModelStructure/Outputs` = exactly the outputs, `InitialUnknowns` = exactly the outputs
//!   with `initial` approx/calculated plus every calculated parameter, both sorted by
//!   1-based `index`, with `dependencies` converted from value references to indices;
//! * numbers in round-trippable `xs:double` syntax, text XML-escaped.

use std::collections::{HashMap, HashSet};

/// The content of `modelDescription.xml` for an FMI 2.0 Co-Simulation FMU
/// (FMI 2.0 section 2.2.1, element `fmiModelDescription`).
#[derive(Debug, Clone, PartialEq)]
pub struct ModelDescription {
    /// `modelName`.
    pub model_name: String,
    /// `CoSimulation/@modelIdentifier`; also the shared-library name (`<id>.so`/`.dll`).
    /// Must be a C identifier.
    pub model_identifier: String,
    /// `description` (omitted when empty).
    pub description: String,
    /// `author` (omitted when empty).
    pub author: String,
    /// `version` (omitted when empty).
    pub version: String,
    /// `generationTool` (omitted when empty).
    pub generation_tool: String,
    /// `UnitDefinitions` (FMI 2.0 section 2.2.2). Every unit a variable uses must be here.
    pub units: Vec<UnitDefinition>,
    /// `TypeDefinitions` (FMI 2.0 section 2.2.3): named types that variables refer to with
    /// `declaredType`. Written after `UnitDefinitions`, omitted when empty.
    pub type_definitions: Vec<SimpleType>,
    /// `LogCategories` (FMI 2.0 section 2.2.4); the names `fmi2SetDebugLogging` accepts.
    pub log_categories: Vec<LogCategory>,
    /// `DefaultExperiment` (FMI 2.0 section 2.2.5); fmpy uses `step_size` as its step.
    pub default_experiment: DefaultExperiment,
    /// `ModelVariables` in order: the variable at position `i` has `index = i + 1`.
    pub variables: Vec<Variable>,
    /// `CoSimulation/@canGetAndSetFMUstate`. When false, `fmi2GetFMUstate`,
    /// `fmi2SetFMUstate` and the serialization functions return `fmi2Error` with a
    /// log line, without touching the model (its `Clone` is then never used).
    pub can_get_and_set_fmu_state: bool,
    /// `CoSimulation/@canSerializeFMUstate` (only meaningful with
    /// `can_get_and_set_fmu_state`). When false, the serialization functions
    /// return `fmi2Error` with a log line.
    pub can_serialize_fmu_state: bool,
}

/// `UnitDefinitions/Unit` (FMI 2.0 section 2.2.2).
#[derive(Debug, Clone, PartialEq)]
pub struct UnitDefinition {
    /// Unit name as used in `Real/@unit`, e.g. `"m/s"`.
    pub name: String,
    /// The SI decomposition of the unit.
    pub base: BaseUnit,
    /// Alternative units for display (`Real/@displayUnit`).
    pub display_units: Vec<DisplayUnit>,
}

impl UnitDefinition {
    /// A unit without display units.
    pub fn new(name: &str, base: BaseUnit) -> Self {
        UnitDefinition {
            name: name.to_string(),
            base,
            display_units: Vec::new(),
        }
    }

    /// Adds a display unit: `value_display = factor * value + offset`.
    pub fn with_display_unit(mut self, name: &str, factor: f64, offset: f64) -> Self {
        self.display_units.push(DisplayUnit {
            name: name.to_string(),
            factor,
            offset,
        });
        self
    }
}

/// `Unit/BaseUnit`: `value_SI = factor * value + offset`, SI unit
/// `kg^kg * m^m * s^s * A^a * K^k * mol^mol * cd^cd * rad^rad`.
///
/// `Default` gives a dimensionless unit with `factor = 1` and `offset = 0` (implemented by
/// hand because a derived `Default` would give `factor = 0`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BaseUnit {
    /// Exponent of kilogram.
    pub kg: i32,
    /// Exponent of metre.
    pub m: i32,
    /// Exponent of second.
    pub s: i32,
    /// Exponent of ampere.
    pub a: i32,
    /// Exponent of kelvin.
    pub k: i32,
    /// Exponent of mole.
    pub mol: i32,
    /// Exponent of candela.
    pub cd: i32,
    /// Exponent of radian.
    pub rad: i32,
    /// Scale to SI (default 1).
    pub factor: f64,
    /// Offset to SI (default 0).
    pub offset: f64,
}

impl Default for BaseUnit {
    fn default() -> Self {
        BaseUnit {
            kg: 0,
            m: 0,
            s: 0,
            a: 0,
            k: 0,
            mol: 0,
            cd: 0,
            rad: 0,
            factor: 1.0,
            offset: 0.0,
        }
    }
}

/// `Unit/DisplayUnit`: `value_display = factor * value_unit + offset`.
#[derive(Debug, Clone, PartialEq)]
pub struct DisplayUnit {
    /// Name used in `Real/@displayUnit`, e.g. `"deg"`.
    pub name: String,
    /// Scale (default 1 in the schema; must be finite and non-zero).
    pub factor: f64,
    /// Offset.
    pub offset: f64,
}

/// `TypeDefinitions/SimpleType` (FMI 2.0 section 2.2.3): a named set of default
/// attributes (quantity, unit, range) that a variable refers to with `declaredType`.
#[derive(Debug, Clone, PartialEq)]
pub struct SimpleType {
    /// `name`, unique among the types; what `declaredType` refers to.
    pub name: String,
    /// `description` (omitted when empty).
    pub description: String,
    /// The base type and its attributes (the child element).
    pub kind: SimpleTypeKind,
}

/// The child element of a [`SimpleType`]: Real, Integer and Enumeration types are
/// supported (FMI 2.0 section 2.2.3; Boolean and String types carry no attribute worth
/// declaring).
#[derive(Debug, Clone, PartialEq)]
pub enum SimpleTypeKind {
    /// `<Real>`.
    Real {
        /// `quantity`: physical quantity (free text, e.g. `"Angle"`).
        quantity: Option<String>,
        /// `unit`; must name a [`UnitDefinition`].
        unit: Option<String>,
        /// `displayUnit`; must name a [`DisplayUnit`] of `unit`.
        display_unit: Option<String>,
        /// Lower bound.
        min: Option<f64>,
        /// Upper bound.
        max: Option<f64>,
    },
    /// `<Integer>`.
    Integer {
        /// `quantity` (free text).
        quantity: Option<String>,
        /// Lower bound.
        min: Option<i32>,
        /// Upper bound.
        max: Option<i32>,
    },
    /// `<Enumeration>` with its `<Item>`s (FMI 2.0 section 2.2.3): the values a variable of
    /// this type may take, each with a name. Variables of the type are
    /// [`VariableKind::Enumeration`], read and written with `fmi2GetInteger` and
    /// `fmi2SetInteger` (section 2.1.7).
    Enumeration {
        /// `quantity` (free text).
        quantity: Option<String>,
        /// The items, at least one; names and values unique within the type.
        items: Vec<EnumerationItem>,
    },
}

/// `SimpleType/Enumeration/Item` (FMI 2.0 section 2.2.3): one value of an enumeration.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct EnumerationItem {
    /// `name`, unique within the enumeration.
    pub name: String,
    /// `value`, unique within the enumeration (FMI 2.0 requires it; FMI 1.0 numbered the
    /// items 1..n implicitly, which the values here usually follow).
    pub value: i32,
    /// `description` (omitted when empty).
    pub description: String,
}

impl EnumerationItem {
    /// An item.
    pub fn new(name: &str, value: i32, description: &str) -> Self {
        EnumerationItem {
            name: name.to_string(),
            value,
            description: description.to_string(),
        }
    }
}

/// `1 distributed, 2 centralized`: the items' values and names, for messages.
pub fn items_text(items: &[EnumerationItem]) -> String {
    items
        .iter()
        .map(|i| format!("{} {}", i.value, i.name))
        .collect::<Vec<_>>()
        .join(", ")
}

impl SimpleTypeKind {
    /// The base type through which variables of this type are accessed (an Enumeration's
    /// is Integer: FMI 2.0 section 2.1.7).
    pub fn value_type(&self) -> ValueType {
        match self {
            SimpleTypeKind::Real { .. } => ValueType::Real,
            SimpleTypeKind::Integer { .. } | SimpleTypeKind::Enumeration { .. } => {
                ValueType::Integer
            }
        }
    }

    /// The XML element: `Real`, `Integer` or `Enumeration`.
    pub fn element(&self) -> &'static str {
        match self {
            SimpleTypeKind::Real { .. } => "Real",
            SimpleTypeKind::Integer { .. } => "Integer",
            SimpleTypeKind::Enumeration { .. } => "Enumeration",
        }
    }
}

impl SimpleType {
    /// A Real type; `quantity` and `unit` take `""` for "none".
    pub fn real(name: &str, quantity: &str, unit: &str) -> Self {
        SimpleType {
            name: name.to_string(),
            description: String::new(),
            kind: SimpleTypeKind::Real {
                quantity: opt_unit(quantity),
                unit: opt_unit(unit),
                display_unit: None,
                min: None,
                max: None,
            },
        }
    }

    /// An Integer type; `quantity` takes `""` for "none".
    pub fn integer(name: &str, quantity: &str) -> Self {
        SimpleType {
            name: name.to_string(),
            description: String::new(),
            kind: SimpleTypeKind::Integer {
                quantity: opt_unit(quantity),
                min: None,
                max: None,
            },
        }
    }

    /// An Enumeration type (FMI 2.0 section 2.2.3); `quantity` takes `""` for "none".
    pub fn enumeration(name: &str, quantity: &str, items: Vec<EnumerationItem>) -> Self {
        SimpleType {
            name: name.to_string(),
            description: String::new(),
            kind: SimpleTypeKind::Enumeration {
                quantity: opt_unit(quantity),
                items,
            },
        }
    }

    /// The items of an Enumeration type (none for other types).
    pub fn items(&self) -> &[EnumerationItem] {
        match &self.kind {
            SimpleTypeKind::Enumeration { items, .. } => items,
            _ => &[],
        }
    }

    /// Sets `description`.
    pub fn with_description(mut self, description: &str) -> Self {
        self.description = description.to_string();
        self
    }

    /// Sets the Real `displayUnit`.
    ///
    /// # Panics
    /// If the type is not Real (a programming error in the type table).
    pub fn with_display_unit(mut self, display_unit: &str) -> Self {
        match &mut self.kind {
            SimpleTypeKind::Real {
                display_unit: d, ..
            } => *d = Some(display_unit.to_string()),
            _ => panic!("with_display_unit on non-Real type '{}'", self.name),
        }
        self
    }

    /// Sets the Real `min` and `max`.
    ///
    /// # Panics
    /// If the type is not Real (a programming error in the type table).
    pub fn with_real_range(mut self, min: f64, max: f64) -> Self {
        match &mut self.kind {
            SimpleTypeKind::Real {
                min: lo, max: hi, ..
            } => {
                *lo = Some(min);
                *hi = Some(max);
            }
            _ => panic!("with_real_range on non-Real type '{}'", self.name),
        }
        self
    }

    /// Sets the Integer `min` and `max`.
    ///
    /// # Panics
    /// If the type is not Integer (a programming error in the type table).
    pub fn with_integer_range(mut self, min: i32, max: i32) -> Self {
        match &mut self.kind {
            SimpleTypeKind::Integer {
                min: lo, max: hi, ..
            } => {
                *lo = Some(min);
                *hi = Some(max);
            }
            _ => panic!("with_integer_range on non-Integer type '{}'", self.name),
        }
        self
    }

    /// The base type.
    pub fn value_type(&self) -> ValueType {
        self.kind.value_type()
    }
}

/// `LogCategories/Category` (FMI 2.0 section 2.2.4).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LogCategory {
    /// Name passed to the logger and accepted by `fmi2SetDebugLogging`.
    pub name: String,
    /// Human-readable explanation.
    pub description: String,
}

impl LogCategory {
    /// A category.
    pub fn new(name: &str, description: &str) -> Self {
        LogCategory {
            name: name.to_string(),
            description: description.to_string(),
        }
    }

    /// The categories this layer itself logs under (FMI 2.0 section 2.2.4 recommends the
    /// `logStatus*` names): `logStatusWarning`, `logStatusDiscard`, `logStatusError`,
    /// `logStatusFatal` (messages of those statuses are always sent) and `logCalls` (one
    /// info line per FMI call when enabled). A model appends its own categories.
    pub fn standard() -> Vec<LogCategory> {
        vec![
            LogCategory::new("logStatusWarning", "Messages with status fmi2Warning"),
            LogCategory::new("logStatusDiscard", "Messages with status fmi2Discard"),
            LogCategory::new("logStatusError", "Messages with status fmi2Error"),
            LogCategory::new("logStatusFatal", "Messages with status fmi2Fatal"),
            LogCategory::new("logCalls", "Every FMI function call (debug)"),
        ]
    }
}

/// `DefaultExperiment` (FMI 2.0 section 2.2.5).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DefaultExperiment {
    /// `startTime` in s.
    pub start_time: f64,
    /// `stopTime` in s (must exceed `start_time`).
    pub stop_time: f64,
    /// `tolerance` (omitted when `None`).
    pub tolerance: Option<f64>,
    /// `stepSize` in s (> 0); the communication step fmpy uses.
    pub step_size: f64,
}

/// `ScalarVariable/@causality` (FMI 2.0 section 2.2.7).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Causality {
    /// Set by the master before initialization (and, if tunable, between steps).
    Parameter,
    /// Computed from parameters during initialization.
    CalculatedParameter,
    /// Set by the master; needs a start value and no `initial`.
    Input,
    /// Computed by the FMU; listed in `ModelStructure/Outputs`.
    Output,
    /// Internal, readable only.
    Local,
    /// The independent variable (time); Real, continuous, no start.
    Independent,
}

impl Causality {
    /// The XML spelling.
    pub fn as_str(self) -> &'static str {
        match self {
            Causality::Parameter => "parameter",
            Causality::CalculatedParameter => "calculatedParameter",
            Causality::Input => "input",
            Causality::Output => "output",
            Causality::Local => "local",
            Causality::Independent => "independent",
        }
    }
}

/// `ScalarVariable/@variability` (FMI 2.0 section 2.2.7).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Variability {
    /// Never changes.
    Constant,
    /// Changes only before `fmi2ExitInitializationMode`.
    Fixed,
    /// May also change in step-complete state (parameters only).
    Tunable,
    /// Changes at communication points / events.
    Discrete,
    /// Real only.
    Continuous,
}

impl Variability {
    /// The XML spelling.
    pub fn as_str(self) -> &'static str {
        match self {
            Variability::Constant => "constant",
            Variability::Fixed => "fixed",
            Variability::Tunable => "tunable",
            Variability::Discrete => "discrete",
            Variability::Continuous => "continuous",
        }
    }
}

/// `ScalarVariable/@initial` (FMI 2.0 section 2.2.7).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Initial {
    /// Initialized with the start value.
    Exact,
    /// Start value is an iteration guess.
    Approx,
    /// Computed by the FMU; no start value.
    Calculated,
}

impl Initial {
    /// The XML spelling.
    pub fn as_str(self) -> &'static str {
        match self {
            Initial::Exact => "exact",
            Initial::Approx => "approx",
            Initial::Calculated => "calculated",
        }
    }
}

/// The four FMI 2.0 base types; value references are unique per type.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ValueType {
    /// `fmi2Real` (f64).
    Real,
    /// `fmi2Integer` (i32).
    Integer,
    /// `fmi2Boolean` (bool).
    Boolean,
    /// `fmi2String` (UTF-8).
    String,
}

impl ValueType {
    /// The XML element name (`Real`, `Integer`, `Boolean`, `String`).
    pub fn as_str(self) -> &'static str {
        match self {
            ValueType::Real => "Real",
            ValueType::Integer => "Integer",
            ValueType::Boolean => "Boolean",
            ValueType::String => "String",
        }
    }
}

/// Type-specific attributes of a scalar variable (the child element of `ScalarVariable`).
#[derive(Debug, Clone, PartialEq)]
pub enum VariableKind {
    /// `<Real>`.
    Real {
        /// `declaredType`: must name a Real [`SimpleType`].
        declared_type: Option<String>,
        /// Must name a [`UnitDefinition`]; must equal the declared type's unit if both are given.
        unit: Option<String>,
        /// Must name a [`DisplayUnit`] of `unit`.
        display_unit: Option<String>,
        /// Start value.
        start: Option<f64>,
        /// Lower bound.
        min: Option<f64>,
        /// Upper bound.
        max: Option<f64>,
    },
    /// `<Integer>`.
    Integer {
        /// `declaredType`: must name an Integer [`SimpleType`].
        declared_type: Option<String>,
        /// Start value.
        start: Option<i32>,
        /// Lower bound.
        min: Option<i32>,
        /// Upper bound.
        max: Option<i32>,
    },
    /// `<Boolean>`.
    Boolean {
        /// Start value.
        start: Option<bool>,
    },
    /// `<String>`.
    String {
        /// Start value.
        start: Option<String>,
    },
    /// `<Enumeration>` (FMI 2.0 section 2.2.7): a value among the items of its declared
    /// type, accessed with `fmi2GetInteger`/`fmi2SetInteger` (section 2.1.7); its value
    /// reference shares the Integer numbering ("Integer/Enumeration", section 2.2.7).
    Enumeration {
        /// `declaredType` (required): must name an Enumeration [`SimpleType`].
        declared_type: String,
        /// Start value: the value of one of the type's items.
        start: Option<i32>,
    },
}

impl VariableKind {
    /// The base type through which the variable is accessed (an Enumeration's is Integer:
    /// FMI 2.0 section 2.1.7).
    pub fn value_type(&self) -> ValueType {
        match self {
            VariableKind::Real { .. } => ValueType::Real,
            VariableKind::Integer { .. } | VariableKind::Enumeration { .. } => ValueType::Integer,
            VariableKind::Boolean { .. } => ValueType::Boolean,
            VariableKind::String { .. } => ValueType::String,
        }
    }

    /// The XML element: `Real`, `Integer`, `Boolean`, `String` or `Enumeration`.
    pub fn element(&self) -> &'static str {
        match self {
            VariableKind::Enumeration { .. } => "Enumeration",
            other => other.value_type().as_str(),
        }
    }

    /// The `declaredType` (Real, Integer and Enumeration only; an Enumeration always has
    /// one).
    pub fn declared_type(&self) -> Option<&str> {
        match self {
            VariableKind::Real { declared_type, .. }
            | VariableKind::Integer { declared_type, .. } => declared_type.as_deref(),
            VariableKind::Enumeration { declared_type, .. } => Some(declared_type),
            VariableKind::Boolean { .. } | VariableKind::String { .. } => None,
        }
    }

    /// Whether a start value is given.
    pub fn has_start(&self) -> bool {
        match self {
            VariableKind::Real { start, .. } => start.is_some(),
            VariableKind::Integer { start, .. } | VariableKind::Enumeration { start, .. } => {
                start.is_some()
            }
            VariableKind::Boolean { start } => start.is_some(),
            VariableKind::String { start } => start.is_some(),
        }
    }
}

/// `ModelVariables/ScalarVariable` (FMI 2.0 section 2.2.7) plus its `ModelStructure` entry.
///
/// Build variables with the table-style constructors; each documents the causality,
/// variability and `initial` it picks:
///
/// | constructor | causality | variability | initial | start | dependencies |
/// |---|---|---|---|---|---|
/// | [`real_input`](Self::real_input) | input | continuous | (none) | given | |
/// | [`real_output`](Self::real_output) | output | continuous | calculated | none | outputs `""`, initial omitted |
/// | [`real_parameter`](Self::real_parameter) | parameter | given | exact | given | |
/// | [`real_calculated_parameter`](Self::real_calculated_parameter) | calculatedParameter | given | calculated | none | initial omitted |
/// | [`integer_input`](Self::integer_input), [`boolean_input`](Self::boolean_input) | input | discrete | (none) | given | |
/// | [`integer_output`](Self::integer_output), [`boolean_output`](Self::boolean_output) | output | discrete | calculated | none | outputs `""`, initial omitted |
/// | [`integer_parameter`](Self::integer_parameter), [`boolean_parameter`](Self::boolean_parameter) | parameter | given | exact | given | |
/// | [`string_parameter`](Self::string_parameter) | parameter | fixed | exact | given | |
/// | [`enumeration_parameter`](Self::enumeration_parameter) | parameter | given | exact | given | |
///
/// `unit` arguments take `""` for "no unit". Refine with the builder methods
/// ([`initial_depends_on`](Self::initial_depends_on),
/// [`output_depends_on`](Self::output_depends_on), [`with_display_unit`](Self::with_display_unit),
/// [`with_declared_type`](Self::with_declared_type),
/// [`with_real_range`](Self::with_real_range), [`with_integer_range`](Self::with_integer_range),
/// [`with_variability`](Self::with_variability)) or write the struct literally.
#[derive(Debug, Clone, PartialEq)]
pub struct Variable {
    /// Structured name (FMI 2.0 section 2.2.9), e.g. `ship.x` or `obstacle[1].x`.
    pub name: String,
    /// `valueReference`, unique per [`ValueType`].
    pub value_reference: u32,
    /// `description` (omitted when empty).
    pub description: String,
    /// `causality`.
    pub causality: Causality,
    /// `variability`.
    pub variability: Variability,
    /// `initial`; `None` means the FMI default for the causality/variability pair.
    pub initial: Option<Initial>,
    /// Type and type-specific attributes.
    pub kind: VariableKind,
    /// Outputs only: value references of the inputs this output depends on directly (feedthrough).
    /// Some(vec![]) writes dependencies="" (no direct feedthrough); None omits the attribute.
    pub output_dependencies: Option<Vec<u32>>,
    /// InitialUnknowns only: value references of the knowns (parameters, inputs) this unknown depends on
    /// during initialization. Some(vec![]) writes dependencies=""; None omits the attribute.
    pub initial_dependencies: Option<Vec<u32>>,
}

fn opt_unit(unit: &str) -> Option<String> {
    if unit.is_empty() {
        None
    } else {
        Some(unit.to_string())
    }
}

impl Variable {
    fn base(
        name: &str,
        vr: u32,
        description: &str,
        causality: Causality,
        variability: Variability,
        initial: Option<Initial>,
        kind: VariableKind,
    ) -> Self {
        let output_dependencies = if causality == Causality::Output {
            Some(Vec::new())
        } else {
            None
        };
        Variable {
            name: name.to_string(),
            value_reference: vr,
            description: description.to_string(),
            causality,
            variability,
            initial,
            kind,
            output_dependencies,
            initial_dependencies: None,
        }
    }

    fn real_kind(unit: &str, start: Option<f64>) -> VariableKind {
        VariableKind::Real {
            declared_type: None,
            unit: opt_unit(unit),
            display_unit: None,
            start,
            min: None,
            max: None,
        }
    }

    /// A continuous Real input with a start value (no `initial`, as FMI 2.0 requires).
    pub fn real_input(name: &str, vr: u32, unit: &str, start: f64, description: &str) -> Self {
        Self::base(
            name,
            vr,
            description,
            Causality::Input,
            Variability::Continuous,
            None,
            Self::real_kind(unit, Some(start)),
        )
    }

    /// A continuous, calculated Real output without direct feedthrough
    /// (`output_dependencies = Some(vec![])`) and with `initial_dependencies = None`
    /// (depends on all knowns); refine with [`output_depends_on`](Self::output_depends_on)
    /// and [`initial_depends_on`](Self::initial_depends_on).
    pub fn real_output(name: &str, vr: u32, unit: &str, description: &str) -> Self {
        Self::base(
            name,
            vr,
            description,
            Causality::Output,
            Variability::Continuous,
            Some(Initial::Calculated),
            Self::real_kind(unit, None),
        )
    }

    /// A Real parameter (`variability` fixed or tunable, `initial="exact"`).
    pub fn real_parameter(
        name: &str,
        vr: u32,
        unit: &str,
        start: f64,
        variability: Variability,
        description: &str,
    ) -> Self {
        Self::base(
            name,
            vr,
            description,
            Causality::Parameter,
            variability,
            Some(Initial::Exact),
            Self::real_kind(unit, Some(start)),
        )
    }

    /// A Real calculated parameter (`initial="calculated"`, no start); listed in
    /// `InitialUnknowns`.
    pub fn real_calculated_parameter(
        name: &str,
        vr: u32,
        unit: &str,
        variability: Variability,
        description: &str,
    ) -> Self {
        Self::base(
            name,
            vr,
            description,
            Causality::CalculatedParameter,
            variability,
            Some(Initial::Calculated),
            Self::real_kind(unit, None),
        )
    }

    /// A discrete Integer input with a start value.
    pub fn integer_input(name: &str, vr: u32, start: i32, description: &str) -> Self {
        Self::base(
            name,
            vr,
            description,
            Causality::Input,
            Variability::Discrete,
            None,
            VariableKind::Integer {
                declared_type: None,
                start: Some(start),
                min: None,
                max: None,
            },
        )
    }

    /// An Integer parameter (`initial="exact"`).
    pub fn integer_parameter(
        name: &str,
        vr: u32,
        start: i32,
        variability: Variability,
        description: &str,
    ) -> Self {
        Self::base(
            name,
            vr,
            description,
            Causality::Parameter,
            variability,
            Some(Initial::Exact),
            VariableKind::Integer {
                declared_type: None,
                start: Some(start),
                min: None,
                max: None,
            },
        )
    }

    /// A discrete, calculated Integer output without direct feedthrough.
    pub fn integer_output(name: &str, vr: u32, description: &str) -> Self {
        Self::base(
            name,
            vr,
            description,
            Causality::Output,
            Variability::Discrete,
            Some(Initial::Calculated),
            VariableKind::Integer {
                declared_type: None,
                start: None,
                min: None,
                max: None,
            },
        )
    }

    /// A discrete Boolean input with a start value.
    pub fn boolean_input(name: &str, vr: u32, start: bool, description: &str) -> Self {
        Self::base(
            name,
            vr,
            description,
            Causality::Input,
            Variability::Discrete,
            None,
            VariableKind::Boolean { start: Some(start) },
        )
    }

    /// A Boolean parameter (`initial="exact"`).
    pub fn boolean_parameter(
        name: &str,
        vr: u32,
        start: bool,
        variability: Variability,
        description: &str,
    ) -> Self {
        Self::base(
            name,
            vr,
            description,
            Causality::Parameter,
            variability,
            Some(Initial::Exact),
            VariableKind::Boolean { start: Some(start) },
        )
    }

    /// A discrete, calculated Boolean output without direct feedthrough.
    pub fn boolean_output(name: &str, vr: u32, description: &str) -> Self {
        Self::base(
            name,
            vr,
            description,
            Causality::Output,
            Variability::Discrete,
            Some(Initial::Calculated),
            VariableKind::Boolean { start: None },
        )
    }

    /// An Enumeration parameter (`initial="exact"`) of the Enumeration type
    /// `declared_type`, starting at the item of value `start` (FMI 2.0 section 2.2.7).
    pub fn enumeration_parameter(
        name: &str,
        vr: u32,
        declared_type: &str,
        start: i32,
        variability: Variability,
        description: &str,
    ) -> Self {
        Self::base(
            name,
            vr,
            description,
            Causality::Parameter,
            variability,
            Some(Initial::Exact),
            VariableKind::Enumeration {
                declared_type: declared_type.to_string(),
                start: Some(start),
            },
        )
    }

    /// A fixed String parameter (`initial="exact"`); use
    /// [`with_variability`](Self::with_variability) for a tunable one.
    pub fn string_parameter(name: &str, vr: u32, start: &str, description: &str) -> Self {
        Self::base(
            name,
            vr,
            description,
            Causality::Parameter,
            Variability::Fixed,
            Some(Initial::Exact),
            VariableKind::String {
                start: Some(start.to_string()),
            },
        )
    }

    /// Sets `initial_dependencies` (value references of the parameters/inputs this initial
    /// unknown depends on; `&[]` writes `dependencies=""`).
    pub fn initial_depends_on(mut self, vrs: &[u32]) -> Self {
        self.initial_dependencies = Some(vrs.to_vec());
        self
    }

    /// Sets `output_dependencies` (value references of the inputs with direct feedthrough
    /// to this output; `&[]` writes `dependencies=""`).
    pub fn output_depends_on(mut self, vrs: &[u32]) -> Self {
        self.output_dependencies = Some(vrs.to_vec());
        self
    }

    /// Sets `variability`.
    pub fn with_variability(mut self, variability: Variability) -> Self {
        self.variability = variability;
        self
    }

    /// Sets the Real `displayUnit`.
    ///
    /// # Panics
    /// If the variable is not Real (a programming error in the variable table).
    pub fn with_display_unit(mut self, display_unit: &str) -> Self {
        match &mut self.kind {
            VariableKind::Real {
                display_unit: d, ..
            } => *d = Some(display_unit.to_string()),
            _ => panic!("with_display_unit on non-Real variable '{}'", self.name),
        }
        self
    }

    /// Sets `declaredType` (the name of a [`SimpleType`] of the same kind).
    ///
    /// # Panics
    /// If the variable is neither Real, Integer nor Enumeration (a programming error in the
    /// variable table).
    pub fn with_declared_type(mut self, name: &str) -> Self {
        match &mut self.kind {
            VariableKind::Real { declared_type, .. }
            | VariableKind::Integer { declared_type, .. } => {
                *declared_type = Some(name.to_string());
            }
            VariableKind::Enumeration { declared_type, .. } => name.clone_into(declared_type),
            VariableKind::Boolean { .. } | VariableKind::String { .. } => panic!(
                "with_declared_type on non-Real/Integer variable '{}'",
                self.name
            ),
        }
        self
    }

    /// Sets the Real `min` and `max`.
    ///
    /// # Panics
    /// If the variable is not Real (a programming error in the variable table).
    pub fn with_real_range(mut self, min: f64, max: f64) -> Self {
        match &mut self.kind {
            VariableKind::Real {
                min: lo, max: hi, ..
            } => {
                *lo = Some(min);
                *hi = Some(max);
            }
            _ => panic!("with_real_range on non-Real variable '{}'", self.name),
        }
        self
    }

    /// Sets the Integer `min` and `max`.
    ///
    /// # Panics
    /// If the variable is not Integer (a programming error in the variable table).
    pub fn with_integer_range(mut self, min: i32, max: i32) -> Self {
        match &mut self.kind {
            VariableKind::Integer {
                min: lo, max: hi, ..
            } => {
                *lo = Some(min);
                *hi = Some(max);
            }
            _ => panic!("with_integer_range on non-Integer variable '{}'", self.name),
        }
        self
    }

    /// The base type.
    pub fn value_type(&self) -> ValueType {
        self.kind.value_type()
    }

    /// `initial` as written to the XML: the explicit value, or the FMI 2.0 default for the
    /// causality/variability pair (section 2.2.7); `None` for inputs and the independent
    /// variable, which have no `initial`.
    pub fn effective_initial(&self) -> Option<Initial> {
        if matches!(self.causality, Causality::Input | Causality::Independent) {
            return None;
        }
        self.initial
            .or_else(|| default_initial(self.causality, self.variability))
    }
}

/// The default `initial` of FMI 2.0 section 2.2.7 (table "initial default").
fn default_initial(causality: Causality, variability: Variability) -> Option<Initial> {
    use Causality as C;
    use Variability as V;
    match (causality, variability) {
        (C::Parameter, _) => Some(Initial::Exact),
        (C::CalculatedParameter, _) => Some(Initial::Calculated),
        (C::Output | C::Local, V::Constant) => Some(Initial::Exact),
        (C::Output | C::Local, _) => Some(Initial::Calculated),
        (C::Input | C::Independent, _) => None,
    }
}

/// Variables an output may depend on directly (FMI 2.0 section 2.2.8, `Outputs`): inputs
/// and the independent variable.
fn output_known(v: &Variable) -> bool {
    matches!(v.causality, Causality::Input | Causality::Independent)
}

/// Knowns an initial unknown may depend on (FMI 2.0 section 2.2.8, `InitialUnknowns`):
/// inputs, parameters (always `initial="exact"`) and the independent variable.
fn initial_known(v: &Variable) -> bool {
    matches!(
        v.causality,
        Causality::Input | Causality::Parameter | Causality::Independent
    )
}

/// The legal causality/variability pairs of FMI 2.0 section 2.2.7.
fn combination_legal(causality: Causality, variability: Variability) -> bool {
    use Causality as C;
    use Variability as V;
    match causality {
        C::Parameter | C::CalculatedParameter => matches!(variability, V::Fixed | V::Tunable),
        C::Input => matches!(variability, V::Discrete | V::Continuous),
        C::Output => matches!(variability, V::Constant | V::Discrete | V::Continuous),
        C::Local => true,
        C::Independent => variability == V::Continuous,
    }
}

/// The `initial` values allowed for a causality/variability pair (FMI 2.0 section 2.2.7).
fn initial_allowed(causality: Causality, variability: Variability, initial: Initial) -> bool {
    use Causality as C;
    use Initial as I;
    use Variability as V;
    match (causality, variability) {
        (C::Parameter, _) => initial == I::Exact,
        (C::CalculatedParameter, _) => matches!(initial, I::Calculated | I::Approx),
        (C::Output | C::Local, V::Constant) => initial == I::Exact,
        (C::Local, V::Fixed | V::Tunable) => matches!(initial, I::Calculated | I::Approx),
        (C::Output | C::Local, _) => true,
        (C::Input | C::Independent, _) => false,
    }
}

fn bool_text(b: bool) -> &'static str {
    if b {
        "true"
    } else {
        "false"
    }
}

impl ModelDescription {
    /// The complete `modelDescription.xml`, including [`guid`](Self::guid).
    pub fn to_xml(&self) -> String {
        self.write_xml(&self.guid())
    }

    /// Deterministic GUID: the 128-bit FNV-1a hash of the XML written with `guid=""`,
    /// formatted `{xxxxxxxx-xxxx-xxxx-xxxx-xxxxxxxxxxxx}` (lower-case hex). The same
    /// description gives the same GUID in every process and on every platform; any change
    /// to the XML changes it.
    pub fn guid(&self) -> String {
        let hash = fnv1a_128(self.write_xml("").as_bytes());
        let hex = format!("{hash:032x}");
        format!(
            "{{{}-{}-{}-{}-{}}}",
            &hex[0..8],
            &hex[8..12],
            &hex[12..16],
            &hex[16..20],
            &hex[20..32]
        )
    }

    /// The variable of type `ty` with value reference `vr` (linear search).
    pub fn find(&self, ty: ValueType, vr: u32) -> Option<&Variable> {
        self.variables
            .iter()
            .find(|v| v.value_type() == ty && v.value_reference == vr)
    }

    /// Checks internal consistency; every problem is one message naming the offending
    /// variable, unit or attribute. Checked: model name and C-identifier
    /// `model_identifier`; XML-representable text; default experiment; units (unique,
    /// finite non-zero factors) and log categories (unique); per variable: non-empty
    /// structured name (FMI 2.0 section 2.2.9, 1-based array indices), unique name, unique
    /// value reference per type, legal causality/variability pair, only Real continuous,
    /// legal `initial`, no `initial` on inputs, start present exactly when required
    /// (exact/approx/input) and absent when calculated or independent, finite numbers with
    /// `min <= start <= max`, declared unit and display unit, at most one independent
    /// variable; type definitions (unique non-empty names, declared units and display units,
    /// finite `min <= max`; an Enumeration's items: at least one, names and values unique);
    /// a variable's `declaredType` names an existing type of the same kind (an Enumeration
    /// variable an Enumeration type), a unit given by both the variable and its type
    /// agrees, and an Enumeration's start is the value of one of its type's items
    /// (FMI 2.0 sections 2.2.3, 2.2.7); dependencies only on outputs/initial unknowns,
    /// referring to exactly one
    /// existing eligible variable (inputs for outputs; inputs and parameters for initial
    /// unknowns; the independent variable for both), without duplicates.
    ///
    /// Dependencies are value references, and value references are unique only per type.
    /// A value reference that names eligible variables of two types is therefore
    /// *ambiguous* and rejected; give variables that appear in dependency lists value
    /// references that are unique across types (simplest: unique across all variables).
    pub fn validate(&self) -> Result<(), Vec<String>> {
        let mut errors = Vec::new();
        self.validate_header(&mut errors);
        self.validate_units(&mut errors);
        self.validate_types(&mut errors);
        self.validate_variables(&mut errors);
        self.validate_dependencies(&mut errors);
        if errors.is_empty() {
            Ok(())
        } else {
            Err(errors)
        }
    }

    fn validate_header(&self, errors: &mut Vec<String>) {
        if self.model_name.is_empty() {
            errors.push("modelName is empty".to_string());
        }
        if !is_c_identifier(&self.model_identifier) {
            errors.push(format!(
                "modelIdentifier '{}' is not a C identifier ([A-Za-z_][A-Za-z0-9_]*)",
                self.model_identifier
            ));
        }
        for (what, text) in [
            ("modelName", &self.model_name),
            ("modelIdentifier", &self.model_identifier),
            ("description", &self.description),
            ("author", &self.author),
            ("version", &self.version),
            ("generationTool", &self.generation_tool),
        ] {
            check_text(errors, &format!("model attribute {what}"), text);
        }
        let de = &self.default_experiment;
        if !de.start_time.is_finite() || !de.stop_time.is_finite() {
            errors.push("DefaultExperiment: startTime and stopTime must be finite".to_string());
        } else if de.stop_time <= de.start_time {
            errors.push(format!(
                "DefaultExperiment: stopTime {} must be greater than startTime {}",
                de.stop_time, de.start_time
            ));
        }
        if !(de.step_size.is_finite() && de.step_size > 0.0) {
            errors.push(format!(
                "DefaultExperiment: stepSize {} must be finite and > 0",
                de.step_size
            ));
        }
        if let Some(tol) = de.tolerance {
            if !(tol.is_finite() && tol > 0.0) {
                errors.push(format!(
                    "DefaultExperiment: tolerance {tol} must be finite and > 0"
                ));
            }
        }
        let mut categories = HashSet::new();
        for cat in &self.log_categories {
            if cat.name.is_empty() {
                errors.push("log category with empty name".to_string());
            } else if !categories.insert(cat.name.as_str()) {
                errors.push(format!("log category '{}' is declared twice", cat.name));
            }
            check_text(errors, &format!("log category '{}'", cat.name), &cat.name);
            check_text(
                errors,
                &format!("description of log category '{}'", cat.name),
                &cat.description,
            );
        }
    }

    fn validate_units(&self, errors: &mut Vec<String>) {
        let mut names = HashSet::new();
        for unit in &self.units {
            if unit.name.is_empty() {
                errors.push("unit with empty name".to_string());
            } else if !names.insert(unit.name.as_str()) {
                errors.push(format!("unit '{}' is declared twice", unit.name));
            }
            check_text(errors, &format!("unit '{}'", unit.name), &unit.name);
            if !(unit.base.factor.is_finite()
                && unit.base.factor != 0.0
                && unit.base.offset.is_finite())
            {
                errors.push(format!(
                    "unit '{}': BaseUnit factor must be finite and non-zero, offset finite",
                    unit.name
                ));
            }
            let mut display_names = HashSet::new();
            for du in &unit.display_units {
                if du.name.is_empty() {
                    errors.push(format!(
                        "unit '{}': display unit with empty name",
                        unit.name
                    ));
                } else if !display_names.insert(du.name.as_str()) {
                    errors.push(format!(
                        "unit '{}': display unit '{}' is declared twice",
                        unit.name, du.name
                    ));
                }
                check_text(errors, &format!("display unit '{}'", du.name), &du.name);
                if !(du.factor.is_finite() && du.factor != 0.0 && du.offset.is_finite()) {
                    errors.push(format!(
                        "unit '{}': display unit '{}' factor must be finite and non-zero, offset finite",
                        unit.name, du.name
                    ));
                }
            }
        }
    }

    fn validate_types(&self, errors: &mut Vec<String>) {
        let mut names = HashSet::new();
        for t in &self.type_definitions {
            let n = t.name.as_str();
            if n.is_empty() {
                errors.push(format!(
                    "type definition with empty name ({} type)",
                    t.kind.element()
                ));
            } else if !names.insert(n) {
                errors.push(format!("type '{n}' is declared twice"));
            }
            let who = format!("type '{n}'");
            check_text(errors, &who, n);
            check_text(errors, &format!("description of {who}"), &t.description);
            match &t.kind {
                SimpleTypeKind::Real {
                    quantity,
                    unit,
                    display_unit,
                    min,
                    max,
                } => {
                    if let Some(q) = quantity {
                        check_text(errors, &format!("quantity of {who}"), q);
                    }
                    for (what, x) in [("min", min), ("max", max)] {
                        if let Some(x) = x {
                            if !x.is_finite() {
                                errors.push(format!("{who}: {what} {x} is not finite"));
                            }
                        }
                    }
                    check_range(errors, &who, None, *min, *max);
                    if let Some(u) = unit {
                        if self.unit_definition(u).is_none() {
                            errors.push(format!(
                                "{who}: unit '{u}' is not declared in UnitDefinitions"
                            ));
                        }
                    }
                    if let Some(du) = display_unit {
                        self.check_display_unit(errors, &who, unit.as_deref(), du);
                    }
                }
                SimpleTypeKind::Integer { quantity, min, max } => {
                    if let Some(q) = quantity {
                        check_text(errors, &format!("quantity of {who}"), q);
                    }
                    check_range(errors, &who, None, *min, *max);
                }
                SimpleTypeKind::Enumeration { quantity, items } => {
                    if let Some(q) = quantity {
                        check_text(errors, &format!("quantity of {who}"), q);
                    }
                    check_items(errors, &who, items);
                }
            }
        }
    }

    fn unit_definition(&self, name: &str) -> Option<&UnitDefinition> {
        self.units.iter().find(|d| d.name == name)
    }

    /// The type definition named `name`.
    pub fn simple_type(&self, name: &str) -> Option<&SimpleType> {
        self.type_definitions.iter().find(|t| t.name == name)
    }

    /// Checks that `display_unit` is a display unit of `unit` (an undeclared `unit` is
    /// reported elsewhere); `who` names the variable or type.
    fn check_display_unit(
        &self,
        errors: &mut Vec<String>,
        who: &str,
        unit: Option<&str>,
        display_unit: &str,
    ) {
        match unit {
            None => errors.push(format!(
                "{who}: displayUnit '{display_unit}' given without a unit"
            )),
            Some(u) => {
                if let Some(def) = self.unit_definition(u) {
                    if !def.display_units.iter().any(|d| d.name == display_unit) {
                        errors.push(format!(
                            "{who}: displayUnit '{display_unit}' is not declared for unit '{u}'"
                        ));
                    }
                }
            }
        }
    }

    /// The variable's declared type, if it names an existing type of the variable's base
    /// type; otherwise reports the problem and returns `None`.
    fn check_declared_type(&self, errors: &mut Vec<String>, v: &Variable) -> Option<&SimpleType> {
        let name = v.kind.declared_type()?;
        let n = v.name.as_str();
        match self.simple_type(name) {
            None => {
                errors.push(format!(
                    "variable '{n}': declaredType '{name}' is not defined in TypeDefinitions"
                ));
                None
            }
            Some(t) if t.kind.element() != v.kind.element() => {
                errors.push(format!(
                    "variable '{n}': declaredType '{name}' is a {} type but the variable is {}",
                    t.kind.element(),
                    v.kind.element()
                ));
                None
            }
            Some(t) => Some(t),
        }
    }

    fn validate_variables(&self, errors: &mut Vec<String>) {
        let mut names: HashSet<&str> = HashSet::new();
        let mut refs: HashMap<(ValueType, u32), &str> = HashMap::new();
        let mut independent: Option<&str> = None;
        for v in &self.variables {
            let n = v.name.as_str();
            if n.is_empty() {
                errors.push(format!(
                    "variable with value reference {} has an empty name",
                    v.value_reference
                ));
            } else if let Err(e) = check_structured_name(n) {
                errors.push(format!(
                    "variable '{n}': name is not a legal structured name: {e}"
                ));
            }
            if !n.is_empty() && !names.insert(n) {
                errors.push(format!("variable '{n}': name is not unique"));
            }
            check_text(
                errors,
                &format!("description of variable '{n}'"),
                &v.description,
            );
            let ty = v.value_type();
            if let Some(other) = refs.insert((ty, v.value_reference), n) {
                errors.push(format!(
                    "variable '{n}': {} value reference {} is already used by '{other}'",
                    ty.as_str(),
                    v.value_reference
                ));
            }
            if !combination_legal(v.causality, v.variability) {
                errors.push(format!(
                    "variable '{n}': causality=\"{}\" with variability=\"{}\" is not allowed",
                    v.causality.as_str(),
                    v.variability.as_str()
                ));
            }
            if v.variability == Variability::Continuous && ty != ValueType::Real {
                errors.push(format!(
                    "variable '{n}': only Real variables can be continuous ({} is)",
                    ty.as_str()
                ));
            }
            if let Some(initial) = v.initial {
                if matches!(v.causality, Causality::Input | Causality::Independent) {
                    errors.push(format!(
                        "variable '{n}': causality=\"{}\" must not define initial (has \"{}\")",
                        v.causality.as_str(),
                        initial.as_str()
                    ));
                } else if !initial_allowed(v.causality, v.variability, initial) {
                    errors.push(format!(
                        "variable '{n}': initial=\"{}\" is not allowed with causality=\"{}\" and variability=\"{}\"",
                        initial.as_str(),
                        v.causality.as_str(),
                        v.variability.as_str()
                    ));
                }
            }
            let effective = v.effective_initial();
            let needs_start = matches!(effective, Some(Initial::Exact | Initial::Approx))
                || v.causality == Causality::Input;
            let forbids_start =
                effective == Some(Initial::Calculated) || v.causality == Causality::Independent;
            if needs_start && !v.kind.has_start() {
                errors.push(format!(
                    "variable '{n}': a start value is required (causality=\"{}\", initial={})",
                    v.causality.as_str(),
                    effective.map_or("none", Initial::as_str)
                ));
            }
            if forbids_start && v.kind.has_start() {
                errors.push(format!(
                    "variable '{n}': must not have a start value (causality=\"{}\", initial={})",
                    v.causality.as_str(),
                    effective.map_or("none", Initial::as_str)
                ));
            }
            if v.causality == Causality::Independent {
                if ty != ValueType::Real {
                    errors.push(format!(
                        "variable '{n}': the independent variable must be Real"
                    ));
                }
                if let Some(first) = independent {
                    errors.push(format!(
                        "variable '{n}': there is already an independent variable '{first}'"
                    ));
                }
                independent = Some(n);
            }
            self.validate_kind(v, errors);
        }
    }

    fn validate_kind(&self, v: &Variable, errors: &mut Vec<String>) {
        let n = v.name.as_str();
        let who = format!("variable '{n}'");
        let declared = self.check_declared_type(errors, v);
        match &v.kind {
            VariableKind::Real {
                declared_type: _,
                unit,
                display_unit,
                start,
                min,
                max,
            } => {
                for (what, x) in [("start", start), ("min", min), ("max", max)] {
                    if let Some(x) = x {
                        if !x.is_finite() {
                            errors.push(format!("variable '{n}': {what} {x} is not finite"));
                        }
                    }
                }
                check_range(errors, &who, *start, *min, *max);
                if let Some(u) = unit {
                    if self.unit_definition(u).is_none() {
                        errors.push(format!(
                            "variable '{n}': unit '{u}' is not declared in UnitDefinitions"
                        ));
                    }
                }
                let type_unit = match declared.map(|t| &t.kind) {
                    Some(SimpleTypeKind::Real { unit: Some(tu), .. }) => Some(tu.as_str()),
                    _ => None,
                };
                if let (Some(u), Some(tu), Some(t)) = (unit, type_unit, declared) {
                    if u != tu {
                        errors.push(format!(
                            "variable '{n}': unit '{u}' differs from unit '{tu}' of its declaredType '{}'",
                            t.name
                        ));
                    }
                }
                if let Some(du) = display_unit {
                    // A variable without its own unit inherits the declared type's.
                    self.check_display_unit(errors, &who, unit.as_deref().or(type_unit), du);
                }
            }
            VariableKind::Integer {
                declared_type: _,
                start,
                min,
                max,
            } => {
                check_range(errors, &who, *start, *min, *max);
            }
            VariableKind::Boolean { .. } => {}
            VariableKind::String { start } => {
                if let Some(s) = start {
                    check_text(errors, &format!("start of variable '{n}'"), s);
                }
            }
            VariableKind::Enumeration { start, .. } => {
                if let (Some(s), Some(t)) = (start, declared) {
                    if !t.items().iter().any(|i| i.value == *s) {
                        errors.push(format!(
                            "variable '{n}': start {s} is not an item of its declaredType '{}' ({})",
                            t.name,
                            items_text(t.items())
                        ));
                    }
                }
            }
        }
    }

    fn validate_dependencies(&self, errors: &mut Vec<String>) {
        let initial_unknowns: HashSet<usize> = self.initial_unknown_positions().collect();
        for (pos, v) in self.variables.iter().enumerate() {
            let n = v.name.as_str();
            if let Some(deps) = &v.output_dependencies {
                if v.causality != Causality::Output {
                    errors.push(format!(
                        "variable '{n}': output_dependencies given but causality is \"{}\", not output",
                        v.causality.as_str()
                    ));
                } else {
                    self.check_dep_list(errors, n, "output", deps, output_known);
                }
            }
            if let Some(deps) = &v.initial_dependencies {
                if !initial_unknowns.contains(&pos) {
                    errors.push(format!(
                        "variable '{n}': initial_dependencies given but it is not an initial unknown \
                         (only outputs with initial approx/calculated and calculated parameters are)"
                    ));
                } else {
                    self.check_dep_list(errors, n, "initial", deps, initial_known);
                }
            }
        }
    }

    fn check_dep_list(
        &self,
        errors: &mut Vec<String>,
        name: &str,
        what: &str,
        deps: &[u32],
        eligible: impl Fn(&Variable) -> bool,
    ) {
        let mut seen = HashSet::new();
        for &vr in deps {
            if !seen.insert(vr) {
                errors.push(format!(
                    "variable '{name}': {what} dependency on value reference {vr} is listed twice"
                ));
                continue;
            }
            if let Err(e) = self.resolve_dependency(vr, &eligible) {
                errors.push(format!(
                    "variable '{name}': {what} dependency on value reference {vr}: {e}"
                ));
            }
        }
    }

    /// The 1-based index of the single eligible variable with value reference `vr`.
    fn resolve_dependency(
        &self,
        vr: u32,
        eligible: &impl Fn(&Variable) -> bool,
    ) -> Result<usize, String> {
        let mut found = self
            .variables
            .iter()
            .enumerate()
            .filter(|(_, v)| v.value_reference == vr && eligible(v));
        match (found.next(), found.next()) {
            (Some((pos, _)), None) => Ok(pos + 1),
            (None, _) => Err("no eligible variable has this value reference".to_string()),
            (Some((_, a)), Some((_, b))) => Err(format!(
                "ambiguous, both '{}' and '{}' have it",
                a.name, b.name
            )),
        }
    }

    /// Positions (0-based) of the `InitialUnknowns`: outputs with initial approx or
    /// calculated, and calculated parameters (FMI 2.0 section 2.2.8).
    fn initial_unknown_positions(&self) -> impl Iterator<Item = usize> + '_ {
        self.variables.iter().enumerate().filter_map(|(pos, v)| {
            let is_unknown = (v.causality == Causality::Output
                && matches!(
                    v.effective_initial(),
                    Some(Initial::Approx | Initial::Calculated)
                ))
                || v.causality == Causality::CalculatedParameter;
            is_unknown.then_some(pos)
        })
    }

    /// Dependency indices, sorted; unresolvable entries (reported by `validate`) skipped.
    fn dependency_indices(&self, deps: &[u32], eligible: impl Fn(&Variable) -> bool) -> String {
        let mut indices: Vec<usize> = deps
            .iter()
            .filter_map(|&vr| self.resolve_dependency(vr, &eligible).ok())
            .collect();
        indices.sort_unstable();
        indices.dedup();
        indices
            .iter()
            .map(|i| i.to_string())
            .collect::<Vec<_>>()
            .join(" ")
    }

    fn write_xml(&self, guid: &str) -> String {
        let mut x = String::with_capacity(4096 + 256 * self.variables.len());
        x.push_str("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
        x.push_str("<fmiModelDescription");
        x.push_str("\n  fmiVersion=\"2.0\"");
        attr_nl(&mut x, "modelName", &self.model_name);
        attr_nl(&mut x, "guid", guid);
        for (name, value) in [
            ("description", &self.description),
            ("author", &self.author),
            ("version", &self.version),
            ("generationTool", &self.generation_tool),
        ] {
            if !value.is_empty() {
                attr_nl(&mut x, name, value);
            }
        }
        x.push_str("\n  variableNamingConvention=\"structured\">\n");

        x.push_str("  <CoSimulation");
        attr(&mut x, "modelIdentifier", &self.model_identifier);
        for (name, value) in [
            ("needsExecutionTool", "false"),
            ("canHandleVariableCommunicationStepSize", "true"),
            ("canInterpolateInputs", "false"),
            ("maxOutputDerivativeOrder", "0"),
            ("canRunAsynchronuously", "false"),
            ("canBeInstantiatedOnlyOncePerProcess", "false"),
            ("canNotUseMemoryManagementFunctions", "true"),
            (
                "canGetAndSetFMUstate",
                bool_text(self.can_get_and_set_fmu_state),
            ),
            (
                "canSerializeFMUstate",
                bool_text(self.can_serialize_fmu_state && self.can_get_and_set_fmu_state),
            ),
            ("providesDirectionalDerivative", "false"),
        ] {
            attr(&mut x, name, value);
        }
        x.push_str("/>\n");

        if !self.units.is_empty() {
            x.push_str("  <UnitDefinitions>\n");
            for unit in &self.units {
                self.write_unit(&mut x, unit);
            }
            x.push_str("  </UnitDefinitions>\n");
        }

        if !self.type_definitions.is_empty() {
            x.push_str("  <TypeDefinitions>\n");
            for t in &self.type_definitions {
                write_simple_type(&mut x, t);
            }
            x.push_str("  </TypeDefinitions>\n");
        }

        if !self.log_categories.is_empty() {
            x.push_str("  <LogCategories>\n");
            for cat in &self.log_categories {
                x.push_str("    <Category");
                attr(&mut x, "name", &cat.name);
                if !cat.description.is_empty() {
                    attr(&mut x, "description", &cat.description);
                }
                x.push_str("/>\n");
            }
            x.push_str("  </LogCategories>\n");
        }

        let de = &self.default_experiment;
        x.push_str("  <DefaultExperiment");
        attr(&mut x, "startTime", &fmt_f64(de.start_time));
        attr(&mut x, "stopTime", &fmt_f64(de.stop_time));
        if let Some(tol) = de.tolerance {
            attr(&mut x, "tolerance", &fmt_f64(tol));
        }
        attr(&mut x, "stepSize", &fmt_f64(de.step_size));
        x.push_str("/>\n");

        x.push_str("  <ModelVariables>\n");
        for (pos, v) in self.variables.iter().enumerate() {
            write_variable(&mut x, pos + 1, v);
        }
        x.push_str("  </ModelVariables>\n");

        self.write_model_structure(&mut x);
        x.push_str("</fmiModelDescription>\n");
        x
    }

    fn write_unit(&self, x: &mut String, unit: &UnitDefinition) {
        x.push_str("    <Unit");
        attr(x, "name", &unit.name);
        x.push_str(">\n      <BaseUnit");
        let b = &unit.base;
        for (name, exp) in [
            ("kg", b.kg),
            ("m", b.m),
            ("s", b.s),
            ("A", b.a),
            ("K", b.k),
            ("mol", b.mol),
            ("cd", b.cd),
            ("rad", b.rad),
        ] {
            if exp != 0 {
                attr(x, name, &exp.to_string());
            }
        }
        if b.factor != 1.0 {
            attr(x, "factor", &fmt_f64(b.factor));
        }
        if b.offset != 0.0 {
            attr(x, "offset", &fmt_f64(b.offset));
        }
        x.push_str("/>\n");
        for du in &unit.display_units {
            x.push_str("      <DisplayUnit");
            attr(x, "name", &du.name);
            if du.factor != 1.0 {
                attr(x, "factor", &fmt_f64(du.factor));
            }
            if du.offset != 0.0 {
                attr(x, "offset", &fmt_f64(du.offset));
            }
            x.push_str("/>\n");
        }
        x.push_str("    </Unit>\n");
    }

    fn write_model_structure(&self, x: &mut String) {
        x.push_str("  <ModelStructure>\n");
        let outputs: Vec<(usize, &Variable)> = self
            .variables
            .iter()
            .enumerate()
            .filter(|(_, v)| v.causality == Causality::Output)
            .collect();
        if !outputs.is_empty() {
            x.push_str("    <Outputs>\n");
            for (pos, v) in outputs {
                x.push_str("      <Unknown");
                attr(x, "index", &(pos + 1).to_string());
                if let Some(deps) = &v.output_dependencies {
                    let d = self.dependency_indices(deps, output_known);
                    attr(x, "dependencies", &d);
                }
                x.push_str("/>\n");
            }
            x.push_str("    </Outputs>\n");
        }
        let unknowns: Vec<usize> = self.initial_unknown_positions().collect();
        if !unknowns.is_empty() {
            x.push_str("    <InitialUnknowns>\n");
            for pos in unknowns {
                let v = &self.variables[pos];
                x.push_str("      <Unknown");
                attr(x, "index", &(pos + 1).to_string());
                if let Some(deps) = &v.initial_dependencies {
                    let d = self.dependency_indices(deps, initial_known);
                    attr(x, "dependencies", &d);
                }
                x.push_str("/>\n");
            }
            x.push_str("    </InitialUnknowns>\n");
        }
        x.push_str("  </ModelStructure>\n");
    }
}

fn write_simple_type(x: &mut String, t: &SimpleType) {
    x.push_str("    <SimpleType");
    attr(x, "name", &t.name);
    if !t.description.is_empty() {
        attr(x, "description", &t.description);
    }
    x.push_str(">\n      <");
    x.push_str(t.kind.element());
    match &t.kind {
        SimpleTypeKind::Real {
            quantity,
            unit,
            display_unit,
            min,
            max,
        } => {
            for (name, value) in [
                ("quantity", quantity),
                ("unit", unit),
                ("displayUnit", display_unit),
            ] {
                if let Some(value) = value {
                    attr(x, name, value);
                }
            }
            if let Some(m) = min {
                attr(x, "min", &fmt_f64(*m));
            }
            if let Some(m) = max {
                attr(x, "max", &fmt_f64(*m));
            }
        }
        SimpleTypeKind::Integer { quantity, min, max } => {
            if let Some(q) = quantity {
                attr(x, "quantity", q);
            }
            if let Some(m) = min {
                attr(x, "min", &m.to_string());
            }
            if let Some(m) = max {
                attr(x, "max", &m.to_string());
            }
        }
        SimpleTypeKind::Enumeration { quantity, items } => {
            if let Some(q) = quantity {
                attr(x, "quantity", q);
            }
            x.push_str(">\n");
            for item in items {
                x.push_str("        <Item");
                attr(x, "name", &item.name);
                attr(x, "value", &item.value.to_string());
                if !item.description.is_empty() {
                    attr(x, "description", &item.description);
                }
                x.push_str("/>\n");
            }
            x.push_str("      </Enumeration>\n    </SimpleType>\n");
            return;
        }
    }
    x.push_str("/>\n    </SimpleType>\n");
}

fn write_variable(x: &mut String, index: usize, v: &Variable) {
    x.push_str("    <!-- ");
    x.push_str(&index.to_string());
    x.push_str(" -->\n    <ScalarVariable");
    attr(x, "name", &v.name);
    attr(x, "valueReference", &v.value_reference.to_string());
    if !v.description.is_empty() {
        attr(x, "description", &v.description);
    }
    attr(x, "causality", v.causality.as_str());
    attr(x, "variability", v.variability.as_str());
    if let Some(initial) = v.effective_initial() {
        attr(x, "initial", initial.as_str());
    }
    x.push_str(">\n      <");
    x.push_str(v.kind.element());
    if let Some(t) = v.kind.declared_type() {
        attr(x, "declaredType", t);
    }
    match &v.kind {
        VariableKind::Real {
            declared_type: _,
            unit,
            display_unit,
            start,
            min,
            max,
        } => {
            if let Some(u) = unit {
                attr(x, "unit", u);
            }
            if let Some(d) = display_unit {
                attr(x, "displayUnit", d);
            }
            if let Some(m) = min {
                attr(x, "min", &fmt_f64(*m));
            }
            if let Some(m) = max {
                attr(x, "max", &fmt_f64(*m));
            }
            if let Some(s) = start {
                attr(x, "start", &fmt_f64(*s));
            }
        }
        VariableKind::Integer {
            declared_type: _,
            start,
            min,
            max,
        } => {
            if let Some(m) = min {
                attr(x, "min", &m.to_string());
            }
            if let Some(m) = max {
                attr(x, "max", &m.to_string());
            }
            if let Some(s) = start {
                attr(x, "start", &s.to_string());
            }
        }
        VariableKind::Boolean { start } => {
            if let Some(s) = start {
                attr(x, "start", if *s { "true" } else { "false" });
            }
        }
        VariableKind::String { start } => {
            if let Some(s) = start {
                attr(x, "start", s);
            }
        }
        VariableKind::Enumeration { start, .. } => {
            if let Some(s) = start {
                attr(x, "start", &s.to_string());
            }
        }
    }
    x.push_str("/>\n    </ScalarVariable>\n");
}

/// Checks `min <= max` and `min <= start <= max`; `who` names the variable or type.
fn check_range<T: PartialOrd + std::fmt::Display + Copy>(
    errors: &mut Vec<String>,
    who: &str,
    start: Option<T>,
    min: Option<T>,
    max: Option<T>,
) {
    if let (Some(lo), Some(hi)) = (min, max) {
        if lo > hi {
            errors.push(format!("{who}: min {lo} is greater than max {hi}"));
        }
    }
    if let Some(s) = start {
        if let Some(lo) = min {
            if s < lo {
                errors.push(format!("{who}: start {s} is below min {lo}"));
            }
        }
        if let Some(hi) = max {
            if s > hi {
                errors.push(format!("{who}: start {s} is above max {hi}"));
            }
        }
    }
}

/// The items of an Enumeration type (FMI 2.0 section 2.2.3): at least one (the schema's
/// `Item` is a required, unbounded sequence), each with a non-empty name, names and
/// values unique within the type, XML-representable text.
fn check_items(errors: &mut Vec<String>, who: &str, items: &[EnumerationItem]) {
    if items.is_empty() {
        errors.push(format!("{who}: an Enumeration needs at least one Item"));
    }
    let mut names = HashSet::new();
    let mut values = HashMap::new();
    for item in items {
        if item.name.is_empty() {
            errors.push(format!(
                "{who}: item of value {} has an empty name",
                item.value
            ));
        } else if !names.insert(item.name.as_str()) {
            errors.push(format!("{who}: item name '{}' is used twice", item.name));
        }
        if let Some(other) = values.insert(item.value, item.name.as_str()) {
            errors.push(format!(
                "{who}: items '{other}' and '{}' have the same value {}",
                item.name, item.value
            ));
        }
        check_text(
            errors,
            &format!("item '{}' of {who}", item.name),
            &item.name,
        );
        check_text(
            errors,
            &format!("description of item '{}' of {who}", item.name),
            &item.description,
        );
    }
}

/// XML 1.0 cannot carry control characters other than tab, LF and CR.
fn check_text(errors: &mut Vec<String>, what: &str, text: &str) {
    if text
        .chars()
        .any(|c| (c as u32) < 0x20 && !matches!(c, '\t' | '\n' | '\r'))
    {
        errors.push(format!(
            "{what} contains a control character that XML 1.0 cannot represent"
        ));
    }
}

fn is_c_identifier(s: &str) -> bool {
    let mut chars = s.chars();
    match chars.next() {
        Some(c) if c.is_ascii_alphabetic() || c == '_' => {}
        _ => return false,
    }
    chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// 128-bit FNV-1a (offset basis and prime from the FNV reference).
fn fnv1a_128(bytes: &[u8]) -> u128 {
    const OFFSET: u128 = 0x6c62_272e_07bb_0142_62b8_2175_6295_c58d;
    const PRIME: u128 = 0x0000_0000_0100_0000_0000_0000_0000_013b;
    let mut hash = OFFSET;
    for &b in bytes {
        hash ^= u128::from(b);
        hash = hash.wrapping_mul(PRIME);
    }
    hash
}

/// Formats a double as a round-trippable `xs:double`: Rust's shortest round-trip
/// representation, positional for `1e-4 <= |x| < 1e15` (and 0), scientific (`1e-5`,
/// `1.5e20`) otherwise; non-finite values as `NaN`, `INF`, `-INF` (which `validate` rejects
/// anyway).
pub(crate) fn fmt_f64(x: f64) -> String {
    if x.is_nan() {
        "NaN".to_string()
    } else if x.is_infinite() {
        if x > 0.0 { "INF" } else { "-INF" }.to_string()
    } else if x == 0.0 || (1e-4..1e15).contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// Appends ` name="value"` with the value XML-escaped.
fn attr(x: &mut String, name: &str, value: &str) {
    x.push(' ');
    x.push_str(name);
    x.push_str("=\"");
    escape_into(x, value);
    x.push('"');
}

/// Appends an attribute on its own line (root element layout).
fn attr_nl(x: &mut String, name: &str, value: &str) {
    x.push_str("\n  ");
    x.push_str(name);
    x.push_str("=\"");
    escape_into(x, value);
    x.push('"');
}

fn escape_into(x: &mut String, value: &str) {
    for c in value.chars() {
        match c {
            '&' => x.push_str("&amp;"),
            '<' => x.push_str("&lt;"),
            '>' => x.push_str("&gt;"),
            '"' => x.push_str("&quot;"),
            '\'' => x.push_str("&apos;"),
            '\t' => x.push_str("&#9;"),
            '\n' => x.push_str("&#10;"),
            '\r' => x.push_str("&#13;"),
            c if (c as u32) < 0x20 => x.push('\u{FFFD}'),
            c => x.push(c),
        }
    }
}

/// Checks a name against the FMI 2.0 structured naming convention (section 2.2.9):
///
/// ```text
/// name         = identifier | "der(" identifier ["," unsignedInteger] ")"
/// identifier   = B-name [arrayIndices] {"." B-name [arrayIndices]}
/// B-name       = nondigit {digit | nondigit} | Q-name
/// arrayIndices = "[" unsignedInteger {"," unsignedInteger} "]"
/// Q-name       = "'" (Q-char | escape) {Q-char | escape} "'"
/// ```
///
/// Array indices are additionally required to be 1-based (no `0`, no leading zeros).
pub fn check_structured_name(name: &str) -> Result<(), String> {
    let b = name.as_bytes();
    let mut p = NameParser { b, i: 0 };
    if b.starts_with(b"der(") {
        p.i = 4;
        p.identifier()?;
        if p.peek() == Some(b',') {
            p.i += 1;
            p.unsigned()?;
        }
        p.expect(b')')?;
    } else {
        p.identifier()?;
    }
    if p.i != b.len() {
        return Err(format!(
            "unexpected '{}' at position {}",
            char::from(b[p.i]),
            p.i + 1
        ));
    }
    Ok(())
}

struct NameParser<'a> {
    b: &'a [u8],
    i: usize,
}

impl NameParser<'_> {
    fn peek(&self) -> Option<u8> {
        self.b.get(self.i).copied()
    }

    fn expect(&mut self, c: u8) -> Result<(), String> {
        if self.peek() == Some(c) {
            self.i += 1;
            Ok(())
        } else {
            Err(format!(
                "expected '{}' at position {}",
                char::from(c),
                self.i + 1
            ))
        }
    }

    fn identifier(&mut self) -> Result<(), String> {
        loop {
            self.bname()?;
            if self.peek() == Some(b'[') {
                self.i += 1;
                self.index()?;
                while self.peek() == Some(b',') {
                    self.i += 1;
                    self.index()?;
                }
                self.expect(b']')?;
            }
            if self.peek() == Some(b'.') {
                self.i += 1;
            } else {
                return Ok(());
            }
        }
    }

    fn bname(&mut self) -> Result<(), String> {
        match self.peek() {
            Some(c) if c.is_ascii_alphabetic() || c == b'_' => {
                self.i += 1;
                while matches!(self.peek(), Some(c) if c.is_ascii_alphanumeric() || c == b'_') {
                    self.i += 1;
                }
                Ok(())
            }
            Some(b'\'') => self.qname(),
            Some(c) => Err(format!(
                "expected a letter, '_' or a quoted name at position {}, found '{}'",
                self.i + 1,
                char::from(c)
            )),
            None => Err(format!(
                "expected a letter, '_' or a quoted name at position {}, found the end",
                self.i + 1
            )),
        }
    }

    fn qname(&mut self) -> Result<(), String> {
        let start = self.i;
        self.i += 1;
        let mut count = 0;
        loop {
            match self.peek() {
                Some(b'\'') if count > 0 => {
                    self.i += 1;
                    return Ok(());
                }
                Some(b'\\') => {
                    match self.b.get(self.i + 1) {
                        Some(
                            b'\'' | b'"' | b'?' | b'\\' | b'a' | b'b' | b'f' | b'n' | b'r' | b't'
                            | b'v',
                        ) => {}
                        _ => return Err(format!("invalid escape at position {}", self.i + 1)),
                    }
                    self.i += 2;
                }
                Some(c)
                    if c.is_ascii_alphanumeric()
                        || b"_!#$%&()*+,-./:;<>=?@[]^{}|~ ".contains(&c) =>
                {
                    self.i += 1;
                }
                _ => {
                    return Err(format!(
                        "unterminated or invalid quoted name starting at position {}",
                        start + 1
                    ))
                }
            }
            count += 1;
        }
    }

    fn unsigned(&mut self) -> Result<u64, String> {
        let start = self.i;
        while matches!(self.peek(), Some(c) if c.is_ascii_digit()) {
            self.i += 1;
        }
        if start == self.i {
            return Err(format!("expected a number at position {}", start + 1));
        }
        let digits = &self.b[start..self.i];
        std::str::from_utf8(digits)
            .ok()
            .and_then(|s| s.parse::<u64>().ok())
            .ok_or_else(|| format!("number too large at position {}", start + 1))
    }

    fn index(&mut self) -> Result<(), String> {
        let start = self.i;
        let n = self.unsigned()?;
        if n == 0 || self.b[start] == b'0' {
            return Err(format!(
                "array index at position {} must be 1-based without leading zeros",
                start + 1
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests;
