//! A registry of parameters: each parameter one entry with its name, type, unit,
//! range, description and accessors on the struct that holds its value
//! ([`Parameter`]). Each FMU has one (the plant's in `fmu-plant`, the controller's in
//! `towing_control::params`); from it come its FMI parameters, their model-description
//! variables, the checks the FMU and the Rust API apply (one function, one message),
//! and the parameter table of `docs/interface.md`. A new parameter is one entry.
//!
//! Names are grouped, `group.name`; every Real declares its unit (`1` for a
//! dimensionless number), one unit per name; a value that may come from the scenario
//! has a Boolean switch, never a sentinel value; a choice among named alternatives is an
//! [`Enumeration`] (an FMI 2.0 Enumeration type, section 2.2.3), never a bare code; a
//! text (a file path, a run identifier) is a String whose setter may refuse it.

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

/// One item of an [`Enumeration`]: FMI 2.0 section 2.2.3, `SimpleType/Enumeration/Item`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Item {
    /// `name`, unique within the enumeration (e.g. `distributed`).
    pub name: &'static str,
    /// `value`, unique within the enumeration: the FMI Integer a master sets and reads
    /// (`fmi2SetInteger`/`fmi2GetInteger`, section 2.1.7).
    pub value: i32,
    /// What the choice means, with its source.
    pub description: &'static str,
}

/// A choice among named items: an FMI 2.0 Enumeration type (section 2.2.3), the
/// `declaredType` of each [`Kind::Enumeration`] parameter that offers it. Items are
/// numbered 1..n unless a value is kept from an earlier interface.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Enumeration {
    /// The type's name (`SimpleType/@name`, e.g. `Architecture`).
    pub name: &'static str,
    /// What the choice is about.
    pub description: &'static str,
    /// The items, in order.
    pub items: &'static [Item],
}

impl Enumeration {
    /// The item of value `value`.
    #[must_use]
    pub fn item(&self, value: i32) -> Option<&'static Item> {
        self.items.iter().find(|i| i.value == value)
    }

    /// `1 distributed, 2 centralized`: the values and names, for messages.
    #[must_use]
    pub fn items_text(&self) -> String {
        self.items
            .iter()
            .map(|i| format!("{} {}", i.value, i.name))
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// Whether `value` is the value of an item; the reason names the items and `value`.
    ///
    /// # Errors
    /// `must be one of 1 distributed, 2 centralized, got 3`.
    pub fn check(&self, value: i32) -> Result<&'static Item, String> {
        self.item(value).ok_or_else(|| self.refusal(value))
    }

    /// The reason a value of no item is refused: `must be one of 1 distributed, 2
    /// centralized, got 3`.
    #[must_use]
    pub fn refusal(&self, value: i32) -> String {
        format!("must be one of {}, got {value}", self.items_text())
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
    /// An FMI Enumeration (FMI 2.0 sections 2.2.3, 2.2.7): one of the items of
    /// `enumeration`, set and read by its value as an FMI Integer ([`Value::Integer`]).
    Enumeration {
        /// The declared type: its items.
        enumeration: &'static Enumeration,
        /// Reads the value (an item's).
        get: fn(&T) -> i32,
        /// Writes the value; [`Parameter::set`] passes only an item's.
        set: fn(&mut T, i32),
    },
    /// An FMI String (a file path, an identifier).
    String {
        /// Reads the value.
        get: fn(&T) -> &str,
        /// Writes the value, or refuses it with the reason.
        set: fn(&mut T, &str) -> Result<(), String>,
    },
}

/// A parameter value, by the FMI type it is set and read with: an Enumeration's is its
/// item's value, an [`Value::Integer`] (FMI 2.0 section 2.1.7). Serde writes it tagged by
/// its type (an FMU state's parameter values).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Value {
    /// A Real.
    Real(f64),
    /// An Integer, or the value of an Enumeration's item.
    Integer(i32),
    /// A Boolean.
    Boolean(bool),
    /// A String.
    String(String),
}

impl Value {
    fn type_name(&self) -> &'static str {
        match self {
            Value::Real(_) => "Real",
            Value::Integer(_) => "Integer",
            Value::Boolean(_) => "Boolean",
            Value::String(_) => "String",
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

    /// The FMI type name (`Real`, `Integer`, `Boolean`, `Enumeration`, `String`).
    #[must_use]
    pub fn type_name(&self) -> &'static str {
        match self.kind {
            Kind::Real { .. } => "Real",
            Kind::Integer { .. } => "Integer",
            Kind::Boolean { .. } => "Boolean",
            Kind::Enumeration { .. } => "Enumeration",
            Kind::String { .. } => "String",
        }
    }

    /// The value in `tuning` (an Enumeration's as its item's value).
    #[must_use]
    pub fn get(&self, tuning: &T) -> Value {
        match self.kind {
            Kind::Real { get, .. } => Value::Real(get(tuning)),
            Kind::Integer { get, .. } | Kind::Enumeration { get, .. } => {
                Value::Integer(get(tuning))
            }
            Kind::Boolean { get, .. } => Value::Boolean(get(tuning)),
            Kind::String { get, .. } => Value::String(get(tuning).to_owned()),
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

    /// Writes `value` into `tuning`. A Real's or an Integer's range is not checked here
    /// (see [`Parameter::check`]); an Enumeration's value must be an item's (its setter
    /// could not hold another), and a String's setter may refuse the text.
    ///
    /// # Errors
    /// A value of another type, a value of no item, a text the setter refuses (its
    /// reason).
    pub fn set(&self, tuning: &mut T, value: Value) -> Result<(), ParamError> {
        match (self.kind, value) {
            (Kind::Real { set, .. }, Value::Real(v)) => set(tuning, v),
            (Kind::Integer { set, .. }, Value::Integer(v)) => set(tuning, v),
            (Kind::Boolean { set, .. }, Value::Boolean(v)) => set(tuning, v),
            (
                Kind::Enumeration {
                    enumeration, set, ..
                },
                Value::Integer(v),
            ) => {
                enumeration
                    .check(v)
                    .map_err(|reason| ParamError::new(self.name, reason))?;
                set(tuning, v);
            }
            (Kind::String { set, .. }, Value::String(v)) => {
                set(tuning, &v).map_err(|reason| ParamError::new(self.name, reason))?;
            }
            (_, value) => return Err(self.wrong_type(&value)),
        }
        Ok(())
    }

    fn wrong_type(&self, value: &Value) -> ParamError {
        ParamError::new(
            self.name,
            format!(
                "expects a {} value, got a {} value",
                self.type_name(),
                value.type_name()
            ),
        )
    }

    /// Checks `value` against the parameter's type and range (an Enumeration's: its
    /// items); the message names the parameter, the range (the items) and the value
    /// (with its unit). A String's text is its setter's to judge ([`Parameter::set`]).
    ///
    /// # Errors
    /// A value of another type, not finite, out of range, or of no item.
    pub fn check(&self, value: &Value) -> Result<(), ParamError> {
        match (self.kind, value) {
            (Kind::Real { unit, min, max, .. }, &Value::Real(v)) => {
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
            (Kind::Integer { min, max, .. }, &Value::Integer(v)) => {
                if (min..=max).contains(&v) {
                    Ok(())
                } else {
                    Err(ParamError::new(
                        self.name,
                        format!("must be in {min}..={max}, got {v}"),
                    ))
                }
            }
            (Kind::Enumeration { enumeration, .. }, &Value::Integer(v)) => enumeration
                .check(v)
                .map(drop)
                .map_err(|reason| ParamError::new(self.name, reason)),
            (Kind::Boolean { .. }, Value::Boolean(_)) | (Kind::String { .. }, Value::String(_)) => {
                Ok(())
            }
            _ => Err(self.wrong_type(value)),
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

impl<T> Kind<T> {
    /// The Enumeration type of an Enumeration parameter.
    #[must_use]
    pub fn enumeration(&self) -> Option<&'static Enumeration> {
        match self {
            Kind::Enumeration { enumeration, .. } => Some(enumeration),
            _ => None,
        }
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
            Kind::Enumeration { enumeration, .. } => f
                .debug_struct("Enumeration")
                .field("type", &enumeration.name)
                .finish_non_exhaustive(),
            Kind::String { .. } => f.write_str("String"),
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

/// One parameter as the documentation shows it ([`doc_rows`], [`markdown_of`]).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DocRow {
    /// The group ([`Parameter::group`]).
    pub group: &'static str,
    /// The name.
    pub name: &'static str,
    /// The FMI type ([`Parameter::type_name`]; an Enumeration's with its type's name).
    pub type_name: String,
    /// The unit (Reals only).
    pub unit: String,
    /// The range, the items or the values.
    pub range: String,
    /// The default (the start value; an Enumeration's with its item's name).
    pub default: String,
    /// The description.
    pub description: &'static str,
    /// The name before the registry.
    pub old_name: Option<&'static str>,
}

/// The documentation rows of `registry`, in its order.
#[must_use]
pub fn doc_rows<T: Default>(registry: &[Parameter<T>]) -> Vec<DocRow> {
    registry
        .iter()
        .map(|p| {
            let (type_name, unit, range) = match p.kind {
                Kind::Real { unit, min, max, .. } => {
                    ("Real".to_owned(), unit.to_owned(), range_cell(min, max))
                }
                Kind::Integer { min, max, .. } => (
                    "Integer".to_owned(),
                    String::new(),
                    format!("{min}..={max}"),
                ),
                Kind::Boolean { .. } => (
                    "Boolean".to_owned(),
                    String::new(),
                    "true, false".to_owned(),
                ),
                Kind::Enumeration { enumeration, .. } => {
                    let items: Vec<String> = enumeration
                        .items
                        .iter()
                        .map(|i| format!("{} `{}`", i.value, i.name))
                        .collect();
                    (
                        format!("Enumeration (`{}`)", enumeration.name),
                        String::new(),
                        items.join(", "),
                    )
                }
                Kind::String { .. } => ("String".to_owned(), String::new(), "text".to_owned()),
            };
            let default = match (p.kind, p.default_value()) {
                (Kind::Enumeration { enumeration, .. }, Value::Integer(v)) => {
                    match enumeration.item(v) {
                        Some(item) => format!("{v} (`{}`)", item.name),
                        None => format!("{v}"),
                    }
                }
                (_, Value::Real(v)) => format!("{v}"),
                (_, Value::Integer(v)) => format!("{v}"),
                (_, Value::Boolean(v)) => format!("{v}"),
                (_, Value::String(v)) => format!("\"{v}\""),
            };
            DocRow {
                group: p.group(),
                name: p.name,
                type_name,
                unit,
                range,
                default,
                description: p.description,
                old_name: p.old_name,
            }
        })
        .collect()
}

/// The Markdown documentation of `registry` ([`markdown_of`] its [`doc_rows`]).
#[must_use]
pub fn markdown<T: Default>(registry: &[Parameter<T>]) -> String {
    markdown_of(&doc_rows(registry))
}

/// The Markdown documentation of parameters (of one registry or several): a table per
/// group (name, type, unit, range, default, description) in order of first appearance,
/// and the table from each name before the registry to its name now (`docs/interface.md`,
/// generated by `cargo xtask model-description`).
#[must_use]
pub fn markdown_of(rows: &[DocRow]) -> String {
    let mut out = String::new();
    let mut groups: Vec<&str> = Vec::new();
    for r in rows {
        if !groups.contains(&r.group) {
            groups.push(r.group);
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
        for r in rows.iter().filter(|r| r.group == group) {
            out.push_str(&format!(
                "| `{}` | {} | {} | {} | {} | {} |\n",
                r.name,
                r.type_name,
                r.unit,
                r.range,
                r.default,
                r.description.replace('|', "\\|")
            ));
        }
    }
    out.push_str("\n#### Names before the registry\n\n| before | now |\n|---|---|\n");
    let mut renamed: Vec<(&str, Vec<&str>)> = Vec::new();
    for r in rows {
        let Some(old) = r.old_name else { continue };
        match renamed.iter_mut().find(|(o, _)| *o == old) {
            Some((_, now)) => now.push(r.name),
            None => renamed.push((old, vec![r.name])),
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

    struct Holder {
        x: f64,
        n: i32,
        mode: i32,
        label: String,
    }

    impl Default for Holder {
        fn default() -> Self {
            Holder {
                x: 0.0,
                n: 0,
                mode: 2,
                label: String::new(),
            }
        }
    }

    const MODE: Enumeration = Enumeration {
        name: "Mode",
        description: "how",
        items: &[
            Item {
                name: "slow",
                value: 1,
                description: "slowly",
            },
            Item {
                name: "fast",
                value: 2,
                description: "fast | furious",
            },
        ],
    };

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
        Parameter {
            name: "mode",
            old_name: Some("speed"),
            description: "the mode",
            kind: Kind::Enumeration {
                enumeration: &MODE,
                get: |h| h.mode,
                set: |h, v| h.mode = v,
            },
        },
        Parameter {
            name: "b.label",
            old_name: None,
            description: "a label",
            kind: Kind::String {
                get: |h| &h.label,
                set: |h, v| {
                    if v.contains('\n') {
                        return Err("must be one line".to_owned());
                    }
                    v.clone_into(&mut h.label);
                    Ok(())
                },
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

    #[test]
    fn enumerations_take_only_their_items_by_value() {
        let mode = find(REGISTRY, "mode").unwrap();
        assert_eq!(mode.type_name(), "Enumeration");
        assert_eq!(mode.group(), "");
        assert_eq!(mode.default_value(), Value::Integer(2));
        assert!(mode.check(&Value::Integer(1)).is_ok());
        for bad in [0, 3, -1] {
            assert_eq!(
                mode.check(&Value::Integer(bad)).unwrap_err().to_string(),
                format!("mode: must be one of 1 slow, 2 fast, got {bad}")
            );
        }
        let mut h = Holder::default();
        // The setter never sees a value of no item.
        assert_eq!(
            mode.set(&mut h, Value::Integer(3)).unwrap_err().to_string(),
            "mode: must be one of 1 slow, 2 fast, got 3"
        );
        assert_eq!(h.mode, 2);
        mode.set(&mut h, Value::Integer(1)).unwrap();
        assert_eq!(mode.get(&h), Value::Integer(1));
        assert_eq!(
            mode.check(&Value::Real(1.0)).unwrap_err().to_string(),
            "mode: expects a Enumeration value, got a Real value"
        );
        assert_eq!(MODE.item(2).map(|i| i.name), Some("fast"));
        assert_eq!(MODE.item(0), None);
    }

    #[test]
    fn strings_are_refused_by_their_setter_with_its_reason() {
        let label = find(REGISTRY, "b.label").unwrap();
        let mut h = Holder::default();
        assert_eq!(label.default_value(), Value::String(String::new()));
        label
            .set(&mut h, Value::String("run 7".to_owned()))
            .unwrap();
        assert_eq!(label.get(&h), Value::String("run 7".to_owned()));
        let e = label
            .set(&mut h, Value::String("a\nb".to_owned()))
            .unwrap_err();
        assert_eq!(e.to_string(), "b.label: must be one line");
        assert_eq!(h.label, "run 7");
        assert!(label.check(&Value::String("anything".to_owned())).is_ok());
        assert!(label.check(&Value::Integer(1)).is_err());
    }

    #[test]
    fn markdown_shows_items_defaults_and_old_names() {
        let md = markdown(REGISTRY);
        assert!(
            md.contains(
                "| `mode` | Enumeration (`Mode`) |  | 1 `slow`, 2 `fast` | 2 (`fast`) | the mode |"
            ),
            "{md}"
        );
        assert!(
            md.contains("| `b.label` | String |  | text | \"\" | a label |"),
            "{md}"
        );
        assert!(
            md.contains("| `a.x` | Real | s | (0, 60] | 0 | x |"),
            "{md}"
        );
        assert!(md.contains("| `speed` | `mode` |"), "{md}");
        // Two registries in one document: groups in order of first appearance.
        let mut rows = doc_rows(&REGISTRY[2..]);
        rows.extend(doc_rows(&REGISTRY[..2]));
        let both = markdown_of(&rows);
        let at = |s: &str| both.find(s).unwrap();
        assert!(at("#### `(ungrouped)`") < at("#### `b`"));
        assert!(at("#### `b`") < at("#### `a`"));
    }
}
