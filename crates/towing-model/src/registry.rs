//! A registry of parameters: each parameter one entry with its name, type, unit,
//! range, description and accessors on the struct that holds its value
//! ([`Parameter`]). Each FMU has one (the plant's in `fmu-plant`, the controller's in
//! `towing_control::params`); from it come its FMI parameters, their model-description
//! variables, the checks the FMU and the Rust API apply (one function, one message),
//! and the parameter table of `docs/interface.md`. A new parameter is one entry.
//!
//! Names are grouped, `group.name`; every Real declares its unit (`1` for a
//! dimensionless number), one unit per name; a value that may come from the scenario
//! has a Boolean switch, never a sentinel value.

use std::fmt;

use crate::vessel::ParamError;

/// One end of a Real parameter's range.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Limit {
    /// No bound.
    None,
    /// `> x` (lower) .
    Above(f64),
    /// `>= x` (lower).
    AtLeast(f64),
    /// `< x` (upper).
    Below(f64),
    /// `<= x` (upper).
    AtMost(f64),
}

impl Limit {
    /// Whether `v` satisfies the bound.
    #[must_use]
    pub fn admits(self, v: f64) -> bool {
        match self {
            Limit::None => true,
            Limit::Above(x) => v > x,
            Limit::AtLeast(x) => v >= x,
            Limit::Below(x) => v < x,
            Limit::AtMost(x) => v <= x,
        }
    }

    /// The bound's value (the FMI `min`/`max` attribute), if any.
    #[must_use]
    pub fn value(self) -> Option<f64> {
        match self {
            Limit::None => None,
            Limit::Above(x) | Limit::AtLeast(x) | Limit::Below(x) | Limit::AtMost(x) => Some(x),
        }
    }
}

/// A parameter's type, range and accessors.
pub enum Kind<T: 'static> {
    /// An FMI Real.
    Real {
        /// Unit (FMI unit name; `1` for a dimensionless number).
        unit: &'static str,
        /// Lower bound.
        min: Limit,
        /// Upper bound.
        max: Limit,
        /// Reads the value.
        get: fn(&T) -> f64,
        /// Writes the value.
        set: fn(&mut T, f64),
    },
    /// An FMI Integer (a choice among codes, or a count).
    Integer {
        /// Smallest value.
        min: i32,
        /// Largest value.
        max: i32,
        /// Reads the value.
        get: fn(&T) -> i32,
        /// Writes the value (within `min..=max`).
        set: fn(&mut T, i32),
    },
    /// An FMI Boolean (a switch).
    Boolean {
        /// Reads the value.
        get: fn(&T) -> bool,
        /// Writes the value.
        set: fn(&mut T, bool),
    },
}

/// A parameter value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Value {
    /// A Real.
    Real(f64),
    /// An Integer.
    Integer(i32),
    /// A Boolean.
    Boolean(bool),
}

impl Value {
    fn type_name(self) -> &'static str {
        match self {
            Value::Real(_) => "Real",
            Value::Integer(_) => "Integer",
            Value::Boolean(_) => "Boolean",
        }
    }
}

/// One parameter (module docs).
pub struct Parameter<T: 'static> {
    /// The FMI name, `group.name`.
    pub name: &'static str,
    /// The name before the registry (docs/interface.md's renaming table);
    /// `None` for a parameter new with it.
    pub old_name: Option<&'static str>,
    /// Meaning, unit, default and its source.
    pub description: &'static str,
    /// Type, range, accessors.
    pub kind: Kind<T>,
}

impl<T> Parameter<T> {
    /// The group: the name up to its last `.` (empty for `architecture` and
    /// `avoidance_scheme`).
    #[must_use]
    pub fn group(&self) -> &'static str {
        self.name.rfind('.').map_or("", |i| &self.name[..i])
    }

    /// The FMI type name (`Real`, `Integer`, `Boolean`).
    #[must_use]
    pub fn type_name(&self) -> &'static str {
        match self.kind {
            Kind::Real { .. } => "Real",
            Kind::Integer { .. } => "Integer",
            Kind::Boolean { .. } => "Boolean",
        }
    }

    /// The value in `tuning`.
    #[must_use]
    pub fn get(&self, tuning: &T) -> Value {
        match self.kind {
            Kind::Real { get, .. } => Value::Real(get(tuning)),
            Kind::Integer { get, .. } => Value::Integer(get(tuning)),
            Kind::Boolean { get, .. } => Value::Boolean(get(tuning)),
        }
    }

    /// The value in `T::default()` (the parameter's start value).
    #[must_use]
    pub fn default_value(&self) -> Value
    where
        T: Default,
    {
        self.get(&T::default())
    }

    /// Writes `value` into `tuning` (not checked: see [`Parameter::check`]).
    ///
    /// # Errors
    /// A value of another type.
    pub fn set(&self, tuning: &mut T, value: Value) -> Result<(), ParamError> {
        match (self.kind, value) {
            (Kind::Real { set, .. }, Value::Real(v)) => set(tuning, v),
            (Kind::Integer { set, .. }, Value::Integer(v)) => set(tuning, v),
            (Kind::Boolean { set, .. }, Value::Boolean(v)) => set(tuning, v),
            _ => return Err(self.wrong_type(value)),
        }
        Ok(())
    }

    fn wrong_type(&self, value: Value) -> ParamError {
        ParamError::new(
            self.name,
            format!(
                "expects a {} value, got a {} value",
                self.type_name(),
                value.type_name()
            ),
        )
    }

    /// Checks `value` against the parameter's type and range; the message names
    /// the parameter, the range and the value (with its unit).
    ///
    /// # Errors
    /// A value of another type, not finite, or out of range.
    pub fn check(&self, value: &Value) -> Result<(), ParamError> {
        match (self.kind, *value) {
            (Kind::Real { unit, min, max, .. }, Value::Real(v)) => {
                if v.is_finite() && min.admits(v) && max.admits(v) {
                    Ok(())
                } else {
                    Err(ParamError::new(
                        self.name,
                        format!(
                            "must be finite and {}, got {v} {unit}",
                            range_text(min, max, unit)
                        ),
                    ))
                }
            }
            (Kind::Integer { min, max, .. }, Value::Integer(v)) => {
                if (min..=max).contains(&v) {
                    Ok(())
                } else {
                    Err(ParamError::new(
                        self.name,
                        format!("must be in {min}..={max}, got {v}"),
                    ))
                }
            }
            (Kind::Boolean { .. }, Value::Boolean(_)) => Ok(()),
            _ => Err(self.wrong_type(*value)),
        }
    }
}

/// `> 0 s`, `in (0, 1.5708) rad`, `>= 0 1/m2`.
fn range_text(min: Limit, max: Limit, unit: &str) -> String {
    let lower = match min {
        Limit::Above(x) => Some(("(", x)),
        Limit::AtLeast(x) => Some(("[", x)),
        _ => None,
    };
    let upper = match max {
        Limit::Below(x) => Some((")", x)),
        Limit::AtMost(x) => Some(("]", x)),
        _ => None,
    };
    match (lower, upper) {
        (Some((l, a)), Some((r, b))) => format!("in {l}{a}, {b}{r} {unit}"),
        (Some(("(", a)), None) => format!("> {a} {unit}"),
        (Some((_, a)), None) => format!(">= {a} {unit}"),
        (None, Some((")", b))) => format!("< {b} {unit}"),
        (None, Some((_, b))) => format!("<= {b} {unit}"),
        (None, None) => format!("in {unit}"),
    }
}

impl<T> Clone for Kind<T> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<T> Copy for Kind<T> {}

impl<T> fmt::Debug for Kind<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Kind::Real { unit, min, max, .. } => f
                .debug_struct("Real")
                .field("unit", unit)
                .field("min", min)
                .field("max", max)
                .finish_non_exhaustive(),
            Kind::Integer { min, max, .. } => f
                .debug_struct("Integer")
                .field("min", min)
                .field("max", max)
                .finish_non_exhaustive(),
            Kind::Boolean { .. } => f.write_str("Boolean"),
        }
    }
}

impl<T> fmt::Debug for Parameter<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Parameter")
            .field("name", &self.name)
            .field("kind", &self.kind)
            .finish_non_exhaustive()
    }
}

/// The Markdown documentation of `registry`: a table per group (name, type, unit,
/// range, default, description) and the table from each name before the registry to
/// its name now (`docs/interface.md`, generated by `cargo xtask model-description`).
#[must_use]
pub fn markdown<T: Default>(registry: &[Parameter<T>]) -> String {
    let mut out = String::new();
    let mut groups: Vec<&str> = Vec::new();
    for p in registry {
        if !groups.contains(&p.group()) {
            groups.push(p.group());
        }
    }
    for group in groups {
        let title = if group.is_empty() {
            "(ungrouped)"
        } else {
            group
        };
        out.push_str(&format!(
            "\n#### `{title}`\n\n| name | type | unit | range | default | description |\n|---|---|---|---|---|---|\n"
        ));
        for p in registry.iter().filter(|p| p.group() == group) {
            let (unit, range) = match p.kind {
                Kind::Real { unit, min, max, .. } => (unit.to_owned(), range_cell(min, max)),
                Kind::Integer { min, max, .. } => (String::new(), format!("{min}..={max}")),
                Kind::Boolean { .. } => (String::new(), "true, false".to_owned()),
            };
            let default = match p.default_value() {
                Value::Real(v) => format!("{v}"),
                Value::Integer(v) => format!("{v}"),
                Value::Boolean(v) => format!("{v}"),
            };
            out.push_str(&format!(
                "| `{}` | {} | {unit} | {range} | {default} | {} |\n",
                p.name,
                p.type_name(),
                p.description.replace('|', "\\|")
            ));
        }
    }
    out.push_str("\n#### Names before the registry\n\n| before | now |\n|---|---|\n");
    let mut renamed: Vec<(&str, Vec<&str>)> = Vec::new();
    for p in registry {
        let Some(old) = p.old_name else { continue };
        match renamed.iter_mut().find(|(o, _)| *o == old) {
            Some((_, now)) => now.push(p.name),
            None => renamed.push((old, vec![p.name])),
        }
    }
    for (old, now) in renamed {
        let now: Vec<String> = now.iter().map(|n| format!("`{n}`")).collect();
        out.push_str(&format!("| `{old}` | {} |\n", now.join(", ")));
    }
    out
}

/// `(0, 60]`, `>= 0`, any.
fn range_cell(min: Limit, max: Limit) -> String {
    let lower = match min {
        Limit::Above(x) => Some(format!("({x}")),
        Limit::AtLeast(x) => Some(format!("[{x}")),
        _ => None,
    };
    let upper = match max {
        Limit::Below(x) => Some(format!("{x})")),
        Limit::AtMost(x) => Some(format!("{x}]")),
        _ => None,
    };
    match (lower, upper) {
        (Some(l), Some(u)) => format!("{l}, {u}"),
        (Some(l), None) => format!("{l}, inf)"),
        (None, Some(u)) => format!("(-inf, {u}"),
        (None, None) => "any".to_owned(),
    }
}

/// The parameter named `name` of `registry`.
#[must_use]
pub fn find<'a, T>(registry: &'a [Parameter<T>], name: &str) -> Option<&'a Parameter<T>> {
    registry.iter().find(|p| p.name == name)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Default)]
    struct Holder {
        x: f64,
        n: i32,
    }

    const REGISTRY: &[Parameter<Holder>] = &[
        Parameter {
            name: "a.x",
            old_name: None,
            description: "x",
            kind: Kind::Real {
                unit: "s",
                min: Limit::Above(0.0),
                max: Limit::AtMost(60.0),
                get: |h| h.x,
                set: |h, v| h.x = v,
            },
        },
        Parameter {
            name: "a.n",
            old_name: None,
            description: "n",
            kind: Kind::Integer {
                min: 1,
                max: 100,
                get: |h| h.n,
                set: |h, v| h.n = v,
            },
        },
    ];

    #[test]
    fn checks_name_the_parameter_the_range_and_the_value() {
        let x = find(REGISTRY, "a.x").unwrap();
        assert_eq!(x.group(), "a");
        assert_eq!(
            x.check(&Value::Real(0.0)).unwrap_err().to_string(),
            "a.x: must be finite and in (0, 60] s, got 0 s"
        );
        assert!(x.check(&Value::Real(f64::NAN)).is_err());
        assert!(x.check(&Value::Real(60.0)).is_ok());
        let n = find(REGISTRY, "a.n").unwrap();
        assert_eq!(
            n.check(&Value::Integer(0)).unwrap_err().to_string(),
            "a.n: must be in 1..=100, got 0"
        );
        assert_eq!(
            n.check(&Value::Boolean(true)).unwrap_err().to_string(),
            "a.n: expects a Integer value, got a Boolean value"
        );
        let mut h = Holder::default();
        n.set(&mut h, Value::Integer(7)).unwrap();
        assert_eq!(n.get(&h), Value::Integer(7));
        assert_eq!(x.default_value(), Value::Real(0.0));
    }
}
