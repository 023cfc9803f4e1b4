//! Human-readable renderings of a [`ModelDescription`]: the FMU's
//! `documentation/index.html` (FMI 2.0 section 2.1.9 allows any documentation there) and a
//! Markdown table for the project's interface document. Both are generated from the same
//! table as `modelDescription.xml`, so they cannot drift from it.

use crate::description::{fmt_f64, ModelDescription, Variable, VariableKind};

/// The start value; an Enumeration's with its item's name (`1 (distributed)`).
fn start_text(md: &ModelDescription, v: &Variable) -> String {
    match &v.kind {
        VariableKind::Real { start, .. } => start.map(fmt_f64).unwrap_or_default(),
        VariableKind::Integer { start, .. } => start.map(|s| s.to_string()).unwrap_or_default(),
        VariableKind::Boolean { start } => start.map(|s| s.to_string()).unwrap_or_default(),
        VariableKind::String { start } => start
            .as_ref()
            .map(|s| format!("\"{s}\""))
            .unwrap_or_default(),
        VariableKind::Enumeration {
            declared_type,
            start,
        } => start
            .map(|s| {
                let item = md
                    .simple_type(declared_type)
                    .and_then(|t| t.items().iter().find(|i| i.value == s));
                match item {
                    Some(i) => format!("{s} ({})", i.name),
                    None => s.to_string(),
                }
            })
            .unwrap_or_default(),
    }
}

fn unit_text(v: &Variable) -> String {
    match &v.kind {
        VariableKind::Real {
            unit: Some(unit),
            display_unit,
            ..
        } => match display_unit {
            Some(d) => format!("{unit} (shown in {d})"),
            None => unit.clone(),
        },
        _ => String::new(),
    }
}

/// The type element, with the declared type in parentheses when there is one
/// (`Real (Angle)`, `Enumeration (Architecture)`).
fn type_text(v: &Variable) -> String {
    let base = v.kind.element();
    match v.kind.declared_type() {
        Some(t) => format!("{base} ({t})"),
        None => base.to_string(),
    }
}

fn html_escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

fn md_escape(s: &str) -> String {
    s.replace('|', "\\|").replace('\n', " ")
}

/// Markdown table of every variable: name, causality, variability, type (with the declared
/// type in parentheses, e.g. `Real (Angle)`), unit, start, value reference and description,
/// in ModelVariables order.
pub fn variables_markdown(md: &ModelDescription) -> String {
    let mut out = String::from(
        "| name | causality | variability | type | unit | start | vr | description |\n\
         |---|---|---|---|---|---|---|---|\n",
    );
    for v in &md.variables {
        out.push_str(&format!(
            "| `{}` | {} | {} | {} | {} | {} | {} | {} |\n",
            md_escape(&v.name),
            v.causality.as_str(),
            v.variability.as_str(),
            md_escape(&type_text(v)),
            md_escape(&unit_text(v)),
            md_escape(&start_text(md, v)),
            v.value_reference,
            md_escape(&v.description),
        ));
    }
    out.push_str(&enumerations_markdown(md));
    out.push_str("\nLog categories (`fmi2SetDebugLogging`):\n\n");
    for c in &md.log_categories {
        out.push_str(&format!("- `{}`: {}\n", c.name, md_escape(&c.description)));
    }
    out
}

/// The Enumeration types and their items (FMI 2.0 section 2.2.3), a list; empty without
/// any.
fn enumerations_markdown(md: &ModelDescription) -> String {
    let mut out = String::new();
    for t in md.type_definitions.iter().filter(|t| !t.items().is_empty()) {
        if out.is_empty() {
            out.push_str(
                "\nEnumeration types (values set and read with `fmi2SetInteger`/`fmi2GetInteger`):\n\n",
            );
        }
        let items: Vec<String> = t
            .items()
            .iter()
            .map(|i| match i.description.as_str() {
                "" => format!("{} `{}`", i.value, i.name),
                d => format!("{} `{}`: {}", i.value, i.name, md_escape(d)),
            })
            .collect();
        out.push_str(&format!("- `{}`: {}\n", t.name, items.join("; ")));
    }
    out
}

/// A self-contained HTML page describing the FMU and every variable.
pub fn documentation_html(md: &ModelDescription) -> String {
    let mut rows = String::new();
    for v in &md.variables {
        rows.push_str(&format!(
            "<tr><td><code>{}</code></td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>\n",
            html_escape(&v.name),
            v.causality.as_str(),
            v.variability.as_str(),
            html_escape(&type_text(v)),
            html_escape(&unit_text(v)),
            html_escape(&start_text(md, v)),
            v.value_reference,
            html_escape(&v.description),
        ));
    }
    let categories: String = md
        .log_categories
        .iter()
        .map(|c| {
            format!(
                "<li><code>{}</code>: {}</li>\n",
                html_escape(&c.name),
                html_escape(&c.description)
            )
        })
        .collect();
    let e = &md.default_experiment;
    format!(
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>{name}</title>\n\
<style>body{{font-family:sans-serif;max-width:80em;margin:2em auto}}table{{border-collapse:collapse}}\
td,th{{border:1px solid #bbb;padding:0.2em 0.5em;text-align:left;vertical-align:top}}</style>\n</head>\n<body>\n\
<h1>{name}</h1>\n<p>{description}</p>\n\
<p>FMI 2.0 Co-Simulation, modelIdentifier <code>{id}</code>, version {version}, GUID <code>{guid}</code>, \
generated by {tool}.</p>\n\
<p>Default experiment: start {start} s, stop {stop} s, communication step {step} s.</p>\n\
<p>Frames: NED world frame (x North, y East, heading from North, clockwise positive); \
body frame x forward, y starboard. Angles in radians.</p>\n\
<h2>Variables</h2>\n<table>\n<tr><th>name</th><th>causality</th><th>variability</th><th>type</th>\
<th>unit</th><th>start</th><th>vr</th><th>description</th></tr>\n{rows}</table>\n\
<h2>Log categories</h2>\n<ul>\n{categories}</ul>\n</body>\n</html>\n",
        name = html_escape(&md.model_name),
        description = html_escape(&md.description),
        id = html_escape(&md.model_identifier),
        version = html_escape(&md.version),
        guid = md.guid(),
        tool = html_escape(&md.generation_tool),
        start = fmt_f64(e.start_time),
        stop = fmt_f64(e.stop_time),
        step = fmt_f64(e.step_size),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::description::{
        BaseUnit, Causality, DefaultExperiment, LogCategory, SimpleType, UnitDefinition,
        Variability,
    };

    fn md() -> ModelDescription {
        ModelDescription {
            model_name: "M<&>".into(),
            model_identifier: "M".into(),
            description: "d".into(),
            author: String::new(),
            version: "1".into(),
            generation_tool: "t".into(),
            units: vec![UnitDefinition::new(
                "rad",
                BaseUnit {
                    rad: 1,
                    ..BaseUnit::default()
                },
            )],
            type_definitions: vec![SimpleType::real("Angle", "Angle", "rad")],
            log_categories: LogCategory::standard(),
            default_experiment: DefaultExperiment {
                start_time: 0.0,
                stop_time: 1.0,
                tolerance: None,
                step_size: 0.1,
            },
            variables: vec![
                Variable::real_parameter("a|b", 1, "", 0.5, Variability::Fixed, "x < y"),
                Variable::real_input("psi", 2, "rad", 0.0, "heading").with_declared_type("Angle"),
            ],
            can_get_and_set_fmu_state: true,
            can_serialize_fmu_state: true,
        }
    }

    #[test]
    fn markdown_lists_every_variable_and_escapes_pipes() {
        let m = md();
        let text = variables_markdown(&m);
        assert!(text.contains("| `a\\|b` | parameter | fixed | Real |  | 0.5 | 1 | x < y |"));
        assert!(
            text.contains("| `psi` | input | continuous | Real (Angle) | rad | 0 | 2 | heading |")
        );
        assert!(text.contains("`logStatusError`"));
        assert_eq!(m.variables[0].causality, Causality::Parameter);
    }

    #[test]
    fn enumerations_show_their_type_start_item_and_items() {
        use crate::description::EnumerationItem;
        let mut m = md();
        m.type_definitions.push(SimpleType::enumeration(
            "Method",
            "",
            vec![
                EnumerationItem::new("euler", 1, "explicit Euler"),
                EnumerationItem::new("heun", 2, "a | b"),
            ],
        ));
        m.variables.push(Variable::enumeration_parameter(
            "method",
            3,
            "Method",
            2,
            Variability::Fixed,
            "integration",
        ));
        let text = variables_markdown(&m);
        assert!(
            text.contains(
                "| `method` | parameter | fixed | Enumeration (Method) |  | 2 (heun) | 3 | integration |"
            ),
            "{text}"
        );
        assert!(
            text.contains("- `Method`: 1 `euler`: explicit Euler; 2 `heun`: a \\| b\n"),
            "{text}"
        );
        // Without an Enumeration type, no list.
        assert!(!variables_markdown(&md()).contains("Enumeration types"));
    }

    #[test]
    fn html_escapes_and_carries_the_guid() {
        let m = md();
        let html = documentation_html(&m);
        assert!(html.contains("<h1>M&lt;&amp;&gt;</h1>"));
        assert!(html.contains("x &lt; y"));
        assert!(html.contains("<td>Real (Angle)</td><td>rad</td>"));
        assert!(html.contains(&m.guid()));
    }
}
