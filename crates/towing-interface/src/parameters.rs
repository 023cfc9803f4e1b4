//! An FMU's parameter registry ([`towing_model::registry`]) as FMI variables, written once
//! for both FMUs: the value reference of each entry, the FMI type it is set and read with,
//! its model-description variable, the Enumeration types it declares, its values as the
//! JSON object of a log's run description, and its documentation. An FMU's parameters are
//! the session's ([`crate::session::PARAMETERS`]: `scenario`, `log_file`, `run_id`) and its
//! own registry's, in this order ([`variables`], [`enumerations`], [`markdown`]).
//!
//! Value references: the session's parameter `index` has `1 + index`
//! ([`crate::vr::session_parameter`]); parameter `index` of an FMU's registry has
//! `10 + index`, whatever its type ([`parameter_vr`]); below 100, so unique across the FMI
//! types together with the contract's (crate [`vr`](crate::vr)).

use fmi2_slave::description::{EnumerationItem, SimpleType, Variable, VariableKind};
use fmi2_slave::ValueType;
use towing_model::registry::{self, Enumeration, Kind, Parameter, Value};

use crate::session;
use crate::types::ModelInfo;
use crate::variables::parameter;
use crate::vr;

/// Value reference of the first parameter of an FMU's registry.
pub const FIRST_PARAMETER_VR: u32 = 10;

/// Value reference of parameter `index` of an FMU's registry: `10 + index`.
#[must_use]
pub const fn parameter_vr(index: usize) -> u32 {
    // A registry has far fewer than 90 entries (below the contract's 100).
    FIRST_PARAMETER_VR + index as u32
}

/// Value reference of the parameter `name` of `registry`.
#[must_use]
pub fn parameter_vr_of<T>(registry: &[Parameter<T>], name: &str) -> Option<u32> {
    registry
        .iter()
        .position(|p| p.name == name)
        .map(parameter_vr)
}

/// The FMI type a parameter is set and read with: an Enumeration's is Integer (FMI 2.0
/// section 2.1.7).
#[must_use]
pub fn value_type<T>(p: &Parameter<T>) -> ValueType {
    match p.kind {
        Kind::Real { .. } => ValueType::Real,
        Kind::Integer { .. } | Kind::Enumeration { .. } => ValueType::Integer,
        Kind::Boolean { .. } => ValueType::Boolean,
        Kind::String { .. } => ValueType::String,
    }
}

/// The model-description variable of `p` (value reference `vr`): a fixed parameter
/// (`initial="exact"`, FMI 2.0 section 2.2.7) of its type, unit (with the declared type of
/// that unit among `info`'s types), range and start value (the registry's default); an
/// Enumeration one declares its [`Enumeration`] type ([`enumerations`] lists them for the
/// `TypeDefinitions`).
#[must_use]
pub fn variable<T: Default>(info: &ModelInfo, p: &Parameter<T>, vr: u32) -> Variable {
    let defaults = T::default();
    let kind = match p.kind {
        Kind::Real {
            unit,
            min,
            max,
            get,
            ..
        } => {
            let mut kind = info.real_kind(unit, Some(get(&defaults)));
            if let VariableKind::Real {
                min: lo, max: hi, ..
            } = &mut kind
            {
                *lo = min.value();
                *hi = max.value();
            }
            kind
        }
        Kind::Integer { min, max, get, .. } => VariableKind::Integer {
            declared_type: None,
            start: Some(get(&defaults)),
            min: Some(min),
            max: Some(max),
        },
        Kind::Boolean { get, .. } => VariableKind::Boolean {
            start: Some(get(&defaults)),
        },
        Kind::Enumeration {
            enumeration, get, ..
        } => VariableKind::Enumeration {
            declared_type: enumeration.name.to_owned(),
            start: Some(get(&defaults)),
        },
        Kind::String { get, .. } => VariableKind::String {
            start: Some(get(&defaults).to_owned()),
        },
    };
    parameter(p.name, vr, kind, p.description)
}

/// The model-description variables of an FMU's parameters: the session's (value
/// references 1, 2, 3), then `registry`'s (`10 + index`).
#[must_use]
pub fn variables<T: Default>(info: &ModelInfo, registry: &[Parameter<T>]) -> Vec<Variable> {
    let session = session::PARAMETERS
        .iter()
        .enumerate()
        .map(|(i, p)| variable(info, p, vr::session_parameter(i)));
    let own = registry
        .iter()
        .enumerate()
        .map(|(i, p)| variable(info, p, parameter_vr(i)));
    session.chain(own).collect()
}

/// The Enumeration types an FMU's parameters (the session's and `registry`'s) declare,
/// each once, in order of first use.
#[must_use]
pub fn enumerations<T>(registry: &[Parameter<T>]) -> Vec<&'static Enumeration> {
    let mut out: Vec<&'static Enumeration> = Vec::new();
    let kinds = session::PARAMETERS
        .iter()
        .map(|p| p.kind.enumeration())
        .chain(registry.iter().map(|p| p.kind.enumeration()));
    for enumeration in kinds.flatten() {
        if !out.iter().any(|e| e.name == enumeration.name) {
            out.push(enumeration);
        }
    }
    out
}

/// The documentation of an FMU's parameters (the session's, then `registry`'s): the
/// tables of `docs/interface.md` ([`registry::markdown_of`]).
#[must_use]
pub fn markdown<T: Default>(registry: &[Parameter<T>]) -> String {
    let mut rows = registry::doc_rows(session::PARAMETERS);
    rows.extend(registry::doc_rows(registry));
    registry::markdown_of(&rows)
}

/// The `SimpleType` of `enumeration` (FMI 2.0 section 2.2.3): its items with their values
/// and descriptions.
#[must_use]
pub fn simple_type(enumeration: &Enumeration) -> SimpleType {
    let items = enumeration
        .items
        .iter()
        .map(|i| EnumerationItem::new(i.name, i.value, i.description))
        .collect();
    SimpleType::enumeration(enumeration.name, "", items).with_description(enumeration.description)
}

/// The value of every parameter of `registry` in `values`, by name, as JSON (a number, a
/// Boolean, a string; an Enumeration's item value as a number): the FMU's part of the
/// `parameters` object of its log's run description (docs/logging.md).
#[must_use]
pub fn values_json<T>(
    registry: &[Parameter<T>],
    values: &T,
) -> serde_json::Map<String, serde_json::Value> {
    registry
        .iter()
        .map(|p| {
            let value = match p.get(values) {
                Value::Real(v) => v.into(),
                Value::Integer(v) => v.into(),
                Value::Boolean(v) => v.into(),
                Value::String(v) => v.into(),
            };
            (p.name.to_owned(), value)
        })
        .collect()
}

/// The value of every parameter of `registry` in `of`, in the registry's order: the
/// parameters' part of an FMU state, restored by [`from_values`].
#[must_use]
pub fn values<T>(registry: &[Parameter<T>], of: &T) -> Vec<Value> {
    registry.iter().map(|p| p.get(of)).collect()
}

/// The defaults of `registry` with `values` (from [`values`]) set, each checked as when a
/// master sets it.
///
/// # Errors
/// Another number of values than parameters, or a value the parameter refuses (named).
pub fn from_values<T: Default>(registry: &[Parameter<T>], values: &[Value]) -> Result<T, String> {
    if values.len() != registry.len() {
        return Err(format!(
            "{} parameter values, the registry has {} parameters",
            values.len(),
            registry.len()
        ));
    }
    let mut out = T::default();
    for (p, v) in registry.iter().zip(values) {
        p.check(v)
            .and_then(|()| p.set(&mut out, v.clone()))
            .map_err(|e| format!("parameter `{}`: {}", e.field, e.reason))?;
    }
    Ok(out)
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use fmi2_slave::description::{Causality, Variability};
    use towing_model::registry::Limit;

    struct Holder {
        speed: f64,
        count: i32,
        on: bool,
        mode: i32,
        label: String,
    }

    impl Default for Holder {
        fn default() -> Self {
            Holder {
                speed: 1.5,
                count: 3,
                on: true,
                mode: 2,
                label: "x".to_owned(),
            }
        }
    }

    const HULL: &Enumeration = &towing_model::HullModel::ENUMERATION;

    const REGISTRY: &[Parameter<Holder>] = &[
        Parameter {
            name: "a.speed",
            old_name: None,
            description: "speed",
            kind: Kind::Real {
                unit: "m/s",
                min: Limit::Above(0.0),
                max: Limit::None,
                get: |h| h.speed,
                set: |h, v| h.speed = v,
            },
        },
        Parameter {
            name: "a.count",
            old_name: None,
            description: "count",
            kind: Kind::Integer {
                min: 1,
                max: 9,
                get: |h| h.count,
                set: |h, v| h.count = v,
            },
        },
        Parameter {
            name: "a.on",
            old_name: None,
            description: "on",
            kind: Kind::Boolean {
                get: |h| h.on,
                set: |h, v| h.on = v,
            },
        },
        Parameter {
            name: "a.mode",
            old_name: None,
            description: "mode",
            kind: Kind::Enumeration {
                enumeration: HULL,
                get: |h| h.mode,
                set: |h, v| h.mode = v,
            },
        },
        Parameter {
            name: "b.hull",
            old_name: None,
            description: "the same type again",
            kind: Kind::Enumeration {
                enumeration: HULL,
                get: |h| h.mode,
                set: |h, v| h.mode = v,
            },
        },
        Parameter {
            name: "a.label",
            old_name: None,
            description: "label",
            kind: Kind::String {
                get: |h| &h.label,
                set: |h, v| {
                    v.clone_into(&mut h.label);
                    Ok(())
                },
            },
        },
    ];

    const INFO: ModelInfo = ModelInfo {
        model_identifier: "Test",
        description: "test",
        package: "p",
        version: "0",
        log_events: "events",
        extra_types: &[],
        fmu_state: false,
    };

    #[test]
    fn every_kind_becomes_a_fixed_parameter_of_its_fmi_type() {
        let vars: Vec<Variable> = REGISTRY
            .iter()
            .enumerate()
            .map(|(i, p)| variable(&INFO, p, parameter_vr(i)))
            .collect();
        for (v, p) in vars.iter().zip(REGISTRY) {
            assert_eq!(v.causality, Causality::Parameter, "{}", v.name);
            assert_eq!(v.variability, Variability::Fixed, "{}", v.name);
            assert_eq!(v.value_type(), value_type(p), "{}", v.name);
        }
        assert_eq!(
            vars[0].kind,
            VariableKind::Real {
                declared_type: Some("Velocity".to_owned()),
                unit: Some("m/s".to_owned()),
                display_unit: None,
                start: Some(1.5),
                min: Some(0.0),
                max: None,
            }
        );
        assert_eq!(
            vars[1].kind,
            VariableKind::Integer {
                declared_type: None,
                start: Some(3),
                min: Some(1),
                max: Some(9),
            }
        );
        assert_eq!(vars[2].kind, VariableKind::Boolean { start: Some(true) });
        assert_eq!(
            vars[3].kind,
            VariableKind::Enumeration {
                declared_type: "HullModel".to_owned(),
                start: Some(2),
            }
        );
        assert_eq!(value_type(&REGISTRY[3]), ValueType::Integer);
        assert_eq!(
            vars[5].kind,
            VariableKind::String {
                start: Some("x".to_owned())
            }
        );
        assert_eq!(vars[5].value_reference, 15);
        assert_eq!(parameter_vr_of(REGISTRY, "a.on"), Some(12));
        assert_eq!(parameter_vr_of(REGISTRY, "none"), None);
    }

    #[test]
    fn enumeration_types_are_declared_once_and_make_a_valid_description() {
        let types = enumerations(REGISTRY);
        assert_eq!(types.len(), 1, "a.mode and b.hull share HullModel");
        let t = simple_type(types[0]);
        assert_eq!(t.name, "HullModel");
        assert_eq!(t.description, HULL.description);
        let items: Vec<(&str, i32)> = t
            .items()
            .iter()
            .map(|i| (i.name.as_str(), i.value))
            .collect();
        assert_eq!(items, [("linear_damping", 1), ("nonlinear_damping", 2)]);
        assert_eq!(t.items()[1].description, HULL.items[1].description);
        let vars = REGISTRY
            .iter()
            .enumerate()
            .map(|(i, p)| variable(&INFO, p, parameter_vr(i)))
            .collect();
        let md = INFO.model_description(vars, &types);
        assert_eq!(md.validate(), Ok(()));
        assert!(md
            .to_xml()
            .contains("<Enumeration declaredType=\"HullModel\" start=\"2\"/>"));
        // Without the type the description is refused: the builder checks the link.
        let md = INFO.model_description(md.variables.clone(), &[]);
        assert!(md.validate().unwrap_err()[0].contains("declaredType 'HullModel' is not defined"));
    }

    #[test]
    fn values_are_json_of_their_type() {
        let h = Holder {
            mode: 1,
            ..Holder::default()
        };
        let json = serde_json::Value::Object(values_json(REGISTRY, &h));
        assert_eq!(
            json,
            serde_json::json!({
                "a.speed": 1.5, "a.count": 3, "a.on": true, "a.mode": 1, "b.hull": 1,
                "a.label": "x"
            })
        );
    }

    #[test]
    fn an_fmus_parameters_are_the_sessions_then_its_own() {
        let vars = variables(&INFO, REGISTRY);
        let names: Vec<(&str, u32, ValueType)> = vars
            .iter()
            .map(|v| (v.name.as_str(), v.value_reference, v.value_type()))
            .collect();
        assert_eq!(
            names[..4],
            [
                ("scenario", 1, ValueType::String),
                ("log_file", 2, ValueType::String),
                ("run_id", 3, ValueType::String),
                ("a.speed", 10, ValueType::Real),
            ]
        );
        assert_eq!(vars.len(), 3 + REGISTRY.len());
        let doc = markdown(REGISTRY);
        let at = |s: &str| {
            doc.find(s)
                .unwrap_or_else(|| panic!("{s} missing in {doc}"))
        };
        assert!(at("| `scenario` | String |") < at("| `a.speed` | Real |"));
        assert!(
            doc.contains("| `run_id` | String |  | text | \"\" |"),
            "{doc}"
        );
    }
}
