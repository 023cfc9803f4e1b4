//! Every channel schema stays within what Foxglove's JSON-schema parser reads
//! (`parseJsonSchema.ts` of Foxglove Studio's `mcap-support` package; the rules are listed
//! in docs/logging.md). A schema outside them makes Foxglove drop the whole topic, e.g.
//! `Error in topic /controller/solver (channel 4): Unsupported type ["string","null"] for
//! fallback` and `Error in topic /controller/prediction (channel 5): Unsupported type
//! "array" for array item ship`.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use serde_json::{Map, Value};
use towing_log::topics::{self, CONTROLLER_TOPICS, PLANT_TOPICS};

/// Keywords the parser reads: `type`, `properties`, `items`, `contentEncoding`, `oneOf`
/// (with `const` and `title` in its alternatives).
const READ: [&str; 5] = ["type", "properties", "items", "contentEncoding", "oneOf"];

/// Keywords the parser skips without harm: annotations and validation that do not change
/// a message's shape.
const SKIPPED: [&str; 12] = [
    "$schema",
    "title",
    "description",
    "format",
    "minimum",
    "maximum",
    "exclusiveMinimum",
    "exclusiveMaximum",
    "minItems",
    "maxItems",
    "required",
    "default",
];

/// The rules of Foxglove's `parseJsonSchema` as a checker: every violation found in the
/// schema of a message, each naming the field path.
struct Checker {
    violations: Vec<String>,
}

impl Checker {
    fn check(schema_name: &str, schema: &Value) -> Vec<String> {
        let mut c = Checker {
            violations: Vec::new(),
        };
        c.object(schema, schema_name);
        c.violations
    }

    fn fail(&mut self, path: &str, what: impl Into<String>) {
        self.violations.push(format!("{path}: {}", what.into()));
    }

    /// Keywords other than those read or harmlessly skipped (`$ref`, `$defs`, `anyOf`,
    /// `allOf`, `prefixItems`, `additionalProperties` with a schema, `enum`, ...) carry
    /// structure the parser ignores.
    fn keywords(&mut self, schema: &Map<String, Value>, path: &str) {
        for key in schema.keys() {
            let known = READ.contains(&key.as_str()) || SKIPPED.contains(&key.as_str());
            // `additionalProperties: false` only forbids fields; a schema there is a map.
            let closed = key == "additionalProperties" && schema[key] == Value::Bool(false);
            if !known && !closed {
                self.fail(path, format!("keyword `{key}` is not read by the parser"));
            }
        }
    }

    /// A schema of `"type": "object"` with `properties` (the root, a nested object, an
    /// array's object items).
    fn object(&mut self, schema: &Value, path: &str) {
        let Some(map) = schema.as_object() else {
            return self.fail(path, "not a JSON object");
        };
        self.keywords(map, path);
        if map.get("type") != Some(&Value::from("object")) {
            return self.fail(
                path,
                format!("expected \"type\": \"object\", got {:?}", map.get("type")),
            );
        }
        let Some(properties) = map.get("properties").and_then(Value::as_object) else {
            return self.fail(path, "an object needs `properties` (an object)");
        };
        for (name, field) in properties {
            self.field(field, &format!("{path}.{name}"));
        }
    }

    /// One property: an enum of numeric constants, or one of the parser's types.
    fn field(&mut self, field: &Value, path: &str) {
        let Some(map) = field.as_object() else {
            return self.fail(path, "not a JSON object");
        };
        if let Some(alternatives) = map.get("oneOf") {
            let numeric = alternatives.as_array().is_some_and(|a| {
                a.iter()
                    .all(|alt| alt.get("const").is_some_and(Value::is_number))
            });
            if !numeric {
                self.fail(path, "oneOf alternatives must all be numeric `const`s");
            }
            return;
        }
        self.keywords(map, path);
        match map.get("type").and_then(Value::as_str) {
            Some("boolean" | "number" | "integer") => {}
            Some("string") => self.string(map, path, &["base64"]),
            Some("object") => self.object(field, path),
            Some("array") => self.array(map, path),
            _ => self.fail(
                path,
                format!(
                    "unsupported type {} (one of boolean, string, number, integer, object, \
                     array; no null, no union of types)",
                    map.get("type")
                        .map_or("(none)".to_owned(), Value::to_string)
                ),
            ),
        }
    }

    /// A string, with no `contentEncoding` or one of `encodings`.
    fn string(&mut self, map: &Map<String, Value>, path: &str, encodings: &[&str]) {
        if let Some(e) = map.get("contentEncoding") {
            if !e.as_str().is_some_and(|e| encodings.contains(&e)) {
                self.fail(path, format!("unsupported contentEncoding {e}"));
            }
        }
    }

    /// An array: `items` one schema (no tuple) of a scalar type or an object; not an
    /// array (no arrays of arrays), not a base64 string.
    fn array(&mut self, map: &Map<String, Value>, path: &str) {
        let Some(items) = map.get("items").and_then(Value::as_object) else {
            return self.fail(path, "an array needs `items`, one schema object");
        };
        let path = format!("{path}[]");
        self.keywords(items, &path);
        match items.get("type").and_then(Value::as_str) {
            Some("boolean" | "number" | "integer") => {}
            Some("string") => self.string(items, &path, &[]),
            Some("object") => self.object(&Value::Object(items.clone()), &path),
            _ => self.fail(
                &path,
                format!(
                    "unsupported type {} for an array item (boolean, string, number, \
                     integer or object; no arrays of arrays)",
                    items
                        .get("type")
                        .map_or("(none)".to_owned(), Value::to_string)
                ),
            ),
        }
    }
}

fn contract() -> Vec<(&'static str, Value)> {
    topics::contract_schemas()
        .unwrap()
        .into_iter()
        .map(|(name, data)| (name, serde_json::from_slice(&data).unwrap()))
        .collect()
}

#[test]
fn every_registered_channel_schema_is_one_foxglove_can_parse() {
    let schemas = contract();
    let mut violations = Vec::new();
    for (topic, schema_name) in PLANT_TOPICS.iter().chain(CONTROLLER_TOPICS.iter()) {
        let Some((_, schema)) = schemas.iter().find(|(n, _)| n == schema_name) else {
            panic!("{topic}: no schema {schema_name} among the contract's types");
        };
        for v in Checker::check(schema_name, schema) {
            violations.push(format!("{topic}: {v}"));
        }
    }
    // The types no topic uses yet are held to the same rules.
    for (name, schema) in &schemas {
        violations.extend(Checker::check(name, schema));
    }
    assert!(violations.is_empty(), "{}", violations.join("\n"));
}

#[test]
fn the_checker_refuses_what_foxglove_refused() {
    // What schemars made of `fallback: Option<String>` and `ship: Vec<[f64; 3]>`.
    let solver = serde_json::json!({
        "type": "object",
        "properties": {"fallback": {"type": ["string", "null"]}, "t": {"type": "number"}}
    });
    let v = Checker::check("towing.Solver", &solver);
    assert_eq!(v.len(), 1, "{v:?}");
    assert!(
        v[0].starts_with("towing.Solver.fallback: unsupported type"),
        "{v:?}"
    );
    let prediction = serde_json::json!({
        "type": "object",
        "properties": {"ship": {"type": "array", "items": {
            "type": "array", "items": {"type": "number"}, "minItems": 3, "maxItems": 3
        }}}
    });
    let v = Checker::check("towing.Prediction", &prediction);
    assert_eq!(v.len(), 1, "{v:?}");
    assert!(
        v[0].contains("towing.Prediction.ship[]: unsupported type \"array\""),
        "{v:?}"
    );
    // And the other constructs the parser does not read.
    for (bad, why) in [
        (serde_json::json!({"$ref": "#/$defs/X"}), "keyword `$ref`"),
        (
            serde_json::json!({"anyOf": [{"type": "number"}, {"type": "null"}]}),
            "keyword `anyOf`",
        ),
        (
            serde_json::json!({"type": "null"}),
            "unsupported type \"null\"",
        ),
        (
            serde_json::json!({"type": "object", "additionalProperties": {"type": "number"}}),
            "keyword `additionalProperties`",
        ),
        (
            serde_json::json!({"type": "array", "prefixItems": [{"type": "number"}]}),
            "keyword `prefixItems`",
        ),
        (
            serde_json::json!({"type": "string", "contentEncoding": "base32"}),
            "contentEncoding",
        ),
        (
            serde_json::json!({"oneOf": [{"const": "a"}, {"const": 2}]}),
            "oneOf alternatives",
        ),
    ] {
        let schema = serde_json::json!({"type": "object", "properties": {"x": bad}});
        let v = Checker::check("X", &schema);
        assert!(v.iter().any(|v| v.contains(why)), "{why}: {v:?}");
    }
    // Foxglove's own constructs pass: a numeric enum, base64 bytes, arrays of objects.
    let good = serde_json::json!({
        "type": "object", "title": "foxglove.Log",
        "properties": {
            "level": {"oneOf": [{"title": "INFO", "const": 2}, {"title": "WARNING", "const": 3}]},
            "data": {"type": "string", "contentEncoding": "base64"},
            "points": {"type": "array", "items": {"type": "object", "properties": {
                "x": {"type": "number", "format": "double"}
            }, "required": ["x"]}}
        },
        "required": ["level"]
    });
    assert_eq!(Checker::check("foxglove.Log", &good), Vec::<String>::new());
}
