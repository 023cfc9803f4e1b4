#![allow(clippy::unwrap_used)]

use super::*;

fn unit(name: &str) -> UnitDefinition {
    UnitDefinition::new(
        name,
        BaseUnit {
            m: 1,
            ..BaseUnit::default()
        },
    )
}

/// A small valid description: input u (vr 1), output y (vr 2, depends on u), tunable T,
/// fixed Integer n, Boolean flag, String label, calculated parameter rate.
fn sample() -> ModelDescription {
    ModelDescription {
        model_name: "Lag & Co".into(),
        model_identifier: "Lag".into(),
        description: "first-order <lag>".into(),
        author: "tests".into(),
        version: "1".into(),
        generation_tool: String::new(),
        units: vec![
            unit("m").with_display_unit("km", 0.001, 0.0),
            UnitDefinition::new(
                "s",
                BaseUnit {
                    s: 1,
                    ..BaseUnit::default()
                },
            ),
            UnitDefinition::new(
                "1/s",
                BaseUnit {
                    s: -1,
                    ..BaseUnit::default()
                },
            ),
        ],
        type_definitions: vec![],
        log_categories: LogCategory::standard(),
        default_experiment: DefaultExperiment {
            start_time: 0.0,
            stop_time: 10.0,
            tolerance: Some(1e-6),
            step_size: 1e-5,
        },
        variables: vec![
            Variable::real_input("u", 1, "m", 0.0, "input"),
            Variable::real_output("y", 2, "m", "output")
                .output_depends_on(&[1])
                .initial_depends_on(&[3])
                .with_display_unit("km"),
            Variable::real_parameter("T", 3, "s", 1.5, Variability::Tunable, "time constant")
                .with_real_range(1e-3, 1e3),
            Variable::integer_parameter("n", 1, 10, Variability::Fixed, "substeps")
                .with_integer_range(1, 1000),
            Variable::boolean_parameter("flag", 1, true, Variability::Tunable, ""),
            Variable::string_parameter("label", 1, "a\"b", "label"),
            Variable::real_calculated_parameter("rate", 4, "1/s", Variability::Tunable, "1/T")
                .initial_depends_on(&[3]),
            Variable::integer_output("count", 2, "steps"),
            Variable::boolean_output("ok", 2, "status"),
            Variable::integer_input("mode", 5, 0, "mode"),
            Variable::boolean_input("go", 6, false, "go"),
        ],
        can_get_and_set_fmu_state: true,
        can_serialize_fmu_state: true,
    }
}

/// `sample()` with type definitions: Real `Length` (m, shown in km, range), Real `Duration`
/// (s), Integer `Count` (quantity, range); y uses `Length`, T `Duration`, n `Count`.
fn typed_sample() -> ModelDescription {
    let mut md = sample();
    md.type_definitions = vec![
        SimpleType::real("Length", "Length", "m")
            .with_display_unit("km")
            .with_real_range(-1e3, 1e3)
            .with_description("a \"length\""),
        SimpleType::real("Duration", "Time", "s"),
        SimpleType::integer("Count", "Count").with_integer_range(0, 1000),
    ];
    md.variables[1] = md.variables[1].clone().with_declared_type("Length");
    md.variables[2] = md.variables[2].clone().with_declared_type("Duration");
    md.variables[3] = md.variables[3].clone().with_declared_type("Count");
    md
}

fn errors_of(md: &ModelDescription) -> Vec<String> {
    match md.validate() {
        Ok(()) => Vec::new(),
        Err(e) => e,
    }
}

/// Asserts that exactly the broken rule is reported and that a message names `needle`.
fn assert_error(md: &ModelDescription, needle: &str, fragment: &str) {
    let errors = errors_of(md);
    assert!(
        errors
            .iter()
            .any(|e| e.contains(needle) && e.contains(fragment)),
        "expected an error naming {needle:?} containing {fragment:?}, got {errors:?}"
    );
}

fn with_var(f: impl FnOnce(&mut Vec<Variable>)) -> ModelDescription {
    let mut md = sample();
    f(&mut md.variables);
    md
}

#[test]
fn sample_is_valid() {
    assert_eq!(errors_of(&sample()), Vec::<String>::new());
    assert_eq!(errors_of(&typed_sample()), Vec::<String>::new());
}

#[test]
fn xml_type_definitions_order_and_attributes() {
    let x = typed_sample().to_xml();
    let pos = |s: &str| x.find(s).unwrap_or_else(|| panic!("{s} missing in\n{x}"));
    let order = [
        "<CoSimulation",
        "<UnitDefinitions>",
        "</UnitDefinitions>",
        "<TypeDefinitions>",
        "</TypeDefinitions>",
        "<LogCategories>",
        "<DefaultExperiment",
        "<ModelVariables>",
    ];
    for w in order.windows(2) {
        assert!(pos(w[0]) < pos(w[1]), "{} before {}", w[0], w[1]);
    }
    let types = "  <TypeDefinitions>\n    <SimpleType name=\"Length\" description=\"a &quot;length&quot;\">\n      <Real quantity=\"Length\" unit=\"m\" displayUnit=\"km\" min=\"-1000\" max=\"1000\"/>\n    </SimpleType>\n    <SimpleType name=\"Duration\">\n      <Real quantity=\"Time\" unit=\"s\"/>\n    </SimpleType>\n    <SimpleType name=\"Count\">\n      <Integer quantity=\"Count\" min=\"0\" max=\"1000\"/>\n    </SimpleType>\n  </TypeDefinitions>\n";
    assert!(x.contains(types), "{x}");
    // declaredType first; the variable keeps its own unit/displayUnit
    assert!(x.contains("initial=\"calculated\">\n      <Real declaredType=\"Length\" unit=\"m\" displayUnit=\"km\"/>"), "{x}");
    assert!(
        x.contains(
            "<Real declaredType=\"Duration\" unit=\"s\" min=\"0.001\" max=\"1000\" start=\"1.5\"/>"
        ),
        "{x}"
    );
    assert!(
        x.contains("<Integer declaredType=\"Count\" min=\"1\" max=\"1000\" start=\"10\"/>"),
        "{x}"
    );
    assert_eq!(x.matches("declaredType=").count(), 3);
    // no types: no TypeDefinitions element
    assert!(!sample().to_xml().contains("TypeDefinitions"));
    assert!(!sample().to_xml().contains("declaredType"));
    assert_ne!(typed_sample().guid(), sample().guid());
}

#[test]
fn xml_child_order_and_root_attributes() {
    let x = sample().to_xml();
    let pos = |s: &str| x.find(s).unwrap_or_else(|| panic!("{s} missing in\n{x}"));
    let order = [
        "<fmiModelDescription",
        "<CoSimulation",
        "<UnitDefinitions>",
        "<LogCategories>",
        "<DefaultExperiment",
        "<ModelVariables>",
        "<ModelStructure>",
        "</fmiModelDescription>",
    ];
    for w in order.windows(2) {
        assert!(pos(w[0]) < pos(w[1]), "{} before {}", w[0], w[1]);
    }
    assert!(x.starts_with("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"));
    assert!(x.contains("fmiVersion=\"2.0\""));
    assert!(x.contains("variableNamingConvention=\"structured\""));
    assert!(
        !x.contains("TypeDefinitions"),
        "empty TypeDefinitions are omitted"
    );
    assert!(!x.contains("VendorAnnotations"));
    assert!(
        !x.contains("generationTool"),
        "empty attributes are omitted"
    );
    for flag in [
        "modelIdentifier=\"Lag\"",
        "canHandleVariableCommunicationStepSize=\"true\"",
        "canGetAndSetFMUstate=\"true\"",
        "canSerializeFMUstate=\"true\"",
        "canNotUseMemoryManagementFunctions=\"true\"",
        "canBeInstantiatedOnlyOncePerProcess=\"false\"",
        "canInterpolateInputs=\"false\"",
        "maxOutputDerivativeOrder=\"0\"",
        "providesDirectionalDerivative=\"false\"",
        "needsExecutionTool=\"false\"",
    ] {
        assert!(x.contains(flag), "{flag} missing");
    }
    assert!(x.contains("<DefaultExperiment startTime=\"0\" stopTime=\"10\" tolerance=\"1e-6\" stepSize=\"1e-5\"/>"), "{x}");
}

#[test]
fn empty_units_and_categories_are_omitted() {
    let mut md = sample();
    md.units.clear();
    md.log_categories.clear();
    for v in &mut md.variables {
        if let VariableKind::Real {
            unit, display_unit, ..
        } = &mut v.kind
        {
            *unit = None;
            *display_unit = None;
        }
    }
    assert_eq!(errors_of(&md), Vec::<String>::new());
    let x = md.to_xml();
    assert!(!x.contains("UnitDefinitions"));
    assert!(!x.contains("LogCategories"));
}

#[test]
fn text_is_escaped() {
    let x = sample().to_xml();
    assert!(x.contains("modelName=\"Lag &amp; Co\""));
    assert!(x.contains("description=\"first-order &lt;lag&gt;\""));
    assert!(x.contains("start=\"a&quot;b\""));
    let mut md = sample();
    md.variables[0].description = "it's\tnew\nline".into();
    let x = md.to_xml();
    assert!(x.contains("description=\"it&apos;s&#9;new&#10;line\""));
}

#[test]
fn variables_attributes() {
    let x = sample().to_xml();
    // input: start, no initial
    assert!(x.contains("<ScalarVariable name=\"u\" valueReference=\"1\" description=\"input\" causality=\"input\" variability=\"continuous\">\n      <Real unit=\"m\" start=\"0\"/>"), "{x}");
    // output: calculated, no start
    assert!(x.contains("name=\"y\" valueReference=\"2\" description=\"output\" causality=\"output\" variability=\"continuous\" initial=\"calculated\">\n      <Real unit=\"m\" displayUnit=\"km\"/>"), "{x}");
    // parameter: explicit variability, exact, start
    assert!(x.contains("causality=\"parameter\" variability=\"tunable\" initial=\"exact\">\n      <Real unit=\"s\" min=\"0.001\" max=\"1000\" start=\"1.5\"/>"), "{x}");
    assert!(x.contains("<Integer min=\"1\" max=\"1000\" start=\"10\"/>"));
    assert!(x.contains("<Boolean start=\"true\"/>"));
    assert!(x.contains("<Unit name=\"m\">\n      <BaseUnit m=\"1\"/>\n      <DisplayUnit name=\"km\" factor=\"0.001\"/>"), "{x}");
    assert!(x.contains("<BaseUnit s=\"-1\"/>"));
}

#[test]
fn model_structure_uses_indices_not_value_references() {
    let x = sample().to_xml();
    // y is variable 2 and depends on u (index 1); count is 8, ok is 9.
    let outputs = "    <Outputs>\n      <Unknown index=\"2\" dependencies=\"1\"/>\n      <Unknown index=\"8\" dependencies=\"\"/>\n      <Unknown index=\"9\" dependencies=\"\"/>\n    </Outputs>\n";
    assert!(x.contains(outputs), "{x}");
    // initial unknowns: y (2, depends on T = index 3), rate (7, depends on T), count, ok.
    let initial = "    <InitialUnknowns>\n      <Unknown index=\"2\" dependencies=\"3\"/>\n      <Unknown index=\"7\" dependencies=\"3\"/>\n      <Unknown index=\"8\"/>\n      <Unknown index=\"9\"/>\n    </InitialUnknowns>\n";
    assert!(x.contains(initial), "{x}");
}

#[test]
fn exact_outputs_are_not_initial_unknowns_and_no_outputs_omits_element() {
    let md = with_var(|v| {
        let y = &mut v[1];
        y.initial = Some(Initial::Exact);
        y.initial_dependencies = None;
        if let VariableKind::Real { start, .. } = &mut y.kind {
            *start = Some(0.0);
        }
    });
    assert_eq!(errors_of(&md), Vec::<String>::new());
    let x = md.to_xml();
    assert!(!x.contains("<Unknown index=\"2\"/>"));
    assert!(
        x.contains("initial=\"exact\">\n      <Real unit=\"m\" displayUnit=\"km\" start=\"0\"/>")
    );
    let md = with_var(|v| v.retain(|v| v.causality != Causality::Output));
    let x = md.to_xml();
    assert!(!x.contains("<Outputs>"));
    assert!(x.contains("<ModelStructure>"));
}

#[test]
fn dependencies_are_sorted_indices() {
    let md = with_var(|v| {
        v[1].output_dependencies = Some(vec![5, 1]); // mode (Integer input, index 10), u (1)
    });
    assert_eq!(errors_of(&md), Vec::<String>::new());
    assert!(md
        .to_xml()
        .contains("<Unknown index=\"2\" dependencies=\"1 10\"/>"));
}

#[test]
fn guid_is_deterministic_formatted_and_content_sensitive() {
    let g = sample().guid();
    assert_eq!(g, sample().guid());
    assert_eq!(g.len(), 38);
    let b = g.as_bytes();
    assert_eq!((b[0], b[37]), (b'{', b'}'));
    for (i, c) in g[1..37].char_indices() {
        if [8, 13, 18, 23].contains(&i) {
            assert_eq!(c, '-');
        } else {
            assert!(c.is_ascii_hexdigit() && !c.is_ascii_uppercase(), "{g}");
        }
    }
    let mut other = sample();
    other.variables[0].description.push('!');
    assert_ne!(other.guid(), g);
    assert!(sample().to_xml().contains(&format!("guid=\"{g}\"")));
    // Golden value: FNV-1a 128 is platform independent.
    assert_eq!(fnv1a_128(b""), 0x6c62_272e_07bb_0142_62b8_2175_6295_c58d);
    assert_eq!(fnv1a_128(b"a"), 0xd228_cb69_6f1a_8caf_7891_2b70_4e4a_8964);
}

#[test]
fn numbers_are_valid_round_trip_xs_double() {
    fn is_xs_double(s: &str) -> bool {
        let s = s.strip_prefix('-').unwrap_or(s);
        let (mantissa, exp) = match s.split_once('e') {
            Some((m, e)) => (m, Some(e)),
            None => (s, None),
        };
        let mantissa_ok = match mantissa.split_once('.') {
            Some((a, b)) => {
                !a.is_empty()
                    && a.bytes().all(|c| c.is_ascii_digit())
                    && b.bytes().all(|c| c.is_ascii_digit())
            }
            None => !mantissa.is_empty() && mantissa.bytes().all(|c| c.is_ascii_digit()),
        };
        let exp_ok = exp.is_none_or(|e| {
            let e = e.strip_prefix('-').unwrap_or(e);
            !e.is_empty() && e.bytes().all(|c| c.is_ascii_digit())
        });
        mantissa_ok && exp_ok
    }
    for x in [
        0.0,
        -0.0,
        1.0,
        0.1,
        1e-5,
        -2.5e-7,
        1e-4,
        123456.789,
        1e15,
        1.5e20,
        f64::MAX,
        f64::MIN_POSITIVE,
        5e-324,
        std::f64::consts::PI,
    ] {
        let s = fmt_f64(x);
        assert!(is_xs_double(&s), "{x} -> {s}");
        assert_eq!(s.parse::<f64>().unwrap().to_bits(), x.to_bits(), "{s}");
    }
    assert_eq!(fmt_f64(1e-5), "1e-5");
    assert_eq!(fmt_f64(0.5), "0.5");
    assert_eq!(fmt_f64(f64::NAN), "NaN");
    assert_eq!(fmt_f64(f64::NEG_INFINITY), "-INF");
}

#[test]
fn find_by_type_and_value_reference() {
    let md = sample();
    assert_eq!(
        md.find(ValueType::Real, 2).map(|v| v.name.as_str()),
        Some("y")
    );
    assert_eq!(
        md.find(ValueType::Integer, 2).map(|v| v.name.as_str()),
        Some("count")
    );
    assert_eq!(
        md.find(ValueType::String, 1).map(|v| v.name.as_str()),
        Some("label")
    );
    assert!(md.find(ValueType::String, 2).is_none());
}

// ---- one test per validate() rule -------------------------------------------------------

#[test]
fn rule_model_name_and_identifier() {
    let mut md = sample();
    md.model_name.clear();
    md.model_identifier = "2 bad".into();
    assert_error(&md, "modelName", "empty");
    assert_error(&md, "'2 bad'", "not a C identifier");
}

#[test]
fn rule_control_characters() {
    let md = with_var(|v| v[0].description = "bell\u{7}".into());
    assert_error(&md, "'u'", "control character");
}

#[test]
fn rule_default_experiment() {
    let mut md = sample();
    md.default_experiment.stop_time = -1.0;
    md.default_experiment.step_size = 0.0;
    md.default_experiment.tolerance = Some(f64::NAN);
    assert_error(&md, "stopTime", "greater than startTime");
    assert_error(&md, "stepSize", "> 0");
    assert_error(&md, "tolerance", "> 0");
}

#[test]
fn rule_units_and_categories_unique() {
    let mut md = sample();
    md.units.push(unit("m"));
    md.units[0].display_units.push(DisplayUnit {
        name: "km".into(),
        factor: 0.0,
        offset: 0.0,
    });
    md.log_categories
        .push(LogCategory::new("logCalls", "again"));
    assert_error(&md, "unit 'm'", "declared twice");
    assert_error(&md, "display unit 'km'", "declared twice");
    assert_error(&md, "display unit 'km'", "non-zero");
    assert_error(&md, "'logCalls'", "declared twice");
}

#[test]
fn rule_unique_names() {
    let md = with_var(|v| v[2].name = "u".into());
    assert_error(&md, "'u'", "not unique");
}

#[test]
fn rule_unique_value_reference_per_type() {
    let md = with_var(|v| v[2].value_reference = 1);
    assert_error(&md, "'T'", "Real value reference 1 is already used by 'u'");
    // the same vr on different types is fine (sample uses vr 1 for four types)
    assert_eq!(errors_of(&sample()), Vec::<String>::new());
}

#[test]
fn rule_structured_names() {
    for bad in [
        "1x", "a..b", "a.", "a[0]", "a[01]", "a[]", "a[1", "a b", "", "der(x", "a-b", "''", "'\\z'",
    ] {
        assert!(check_structured_name(bad).is_err(), "{bad:?} accepted");
        let md = with_var(|v| v[0].name = bad.to_string());
        let errors = errors_of(&md);
        assert!(!errors.is_empty(), "{bad:?}");
    }
    for good in [
        "x",
        "_x1",
        "ship.eta[1]",
        "obstacle[12].x",
        "a[1,2].b",
        "der(x)",
        "der(a.b,2)",
        "'quoted name'",
        "a.'q.1'[3]",
        "'\\n\\''",
    ] {
        assert_eq!(check_structured_name(good), Ok(()), "{good:?}");
    }
    let md = with_var(|v| v[0].name = "ship eta".into());
    assert_error(&md, "'ship eta'", "structured name");
}

#[test]
fn rule_causality_variability_combinations() {
    let md = with_var(|v| v[2].variability = Variability::Continuous);
    assert_error(
        &md,
        "'T'",
        "causality=\"parameter\" with variability=\"continuous\"",
    );
    let md = with_var(|v| v[0].variability = Variability::Tunable);
    assert_error(
        &md,
        "'u'",
        "causality=\"input\" with variability=\"tunable\"",
    );
    let md = with_var(|v| v[1].variability = Variability::Fixed);
    assert_error(
        &md,
        "'y'",
        "causality=\"output\" with variability=\"fixed\"",
    );
}

#[test]
fn rule_only_real_continuous() {
    let md = with_var(|v| v[7].variability = Variability::Continuous);
    assert_error(&md, "'count'", "only Real variables can be continuous");
}

#[test]
fn rule_no_initial_on_inputs() {
    let md = with_var(|v| v[0].initial = Some(Initial::Exact));
    assert_error(&md, "'u'", "must not define initial");
}

#[test]
fn rule_initial_legal_for_combination() {
    let md = with_var(|v| {
        v[2].initial = Some(Initial::Calculated);
    });
    assert_error(&md, "'T'", "initial=\"calculated\" is not allowed");
    let md = with_var(|v| v[6].initial = Some(Initial::Exact));
    assert_error(&md, "'rate'", "initial=\"exact\" is not allowed");
}

#[test]
fn rule_start_required() {
    let md = with_var(|v| {
        if let VariableKind::Real { start, .. } = &mut v[0].kind {
            *start = None;
        }
        if let VariableKind::String { start } = &mut v[5].kind {
            *start = None;
        }
    });
    assert_error(&md, "'u'", "start value is required");
    assert_error(&md, "'label'", "start value is required");
}

#[test]
fn rule_start_forbidden_when_calculated() {
    let md = with_var(|v| {
        if let VariableKind::Real { start, .. } = &mut v[1].kind {
            *start = Some(1.0);
        }
    });
    assert_error(&md, "'y'", "must not have a start value");
}

#[test]
fn rule_independent_variable() {
    let time = Variable {
        name: "time".into(),
        value_reference: 100,
        description: String::new(),
        causality: Causality::Independent,
        variability: Variability::Continuous,
        initial: None,
        kind: VariableKind::Real {
            declared_type: None,
            unit: None,
            display_unit: None,
            start: None,
            min: None,
            max: None,
        },
        output_dependencies: None,
        initial_dependencies: None,
    };
    let md = with_var(|v| v.push(time.clone()));
    assert_eq!(errors_of(&md), Vec::<String>::new());
    let x = md.to_xml();
    assert!(x.contains("causality=\"independent\" variability=\"continuous\">"));
    let md = with_var(|v| {
        let mut t2 = time.clone();
        t2.name = "time2".into();
        t2.value_reference = 101;
        if let VariableKind::Real { start, .. } = &mut t2.kind {
            *start = Some(0.0);
        }
        v.push(time.clone());
        v.push(t2);
    });
    assert_error(&md, "'time2'", "already an independent variable 'time'");
    assert_error(&md, "'time2'", "must not have a start value");
}

#[test]
fn rule_finite_numbers_and_ranges() {
    let md = with_var(|v| {
        if let VariableKind::Real { start, .. } = &mut v[0].kind {
            *start = Some(f64::INFINITY);
        }
    });
    assert_error(&md, "'u'", "not finite");
    let md = with_var(|v| {
        if let VariableKind::Real { start, .. } = &mut v[2].kind {
            *start = Some(1e4);
        }
    });
    assert_error(&md, "'T'", "above max");
    let md = with_var(|v| v[3] = v[3].clone().with_integer_range(5, 1));
    assert_error(&md, "'n'", "min 5 is greater than max 1");
    assert_error(&md, "'n'", "above max");
}

#[test]
fn rule_units_declared() {
    let md = with_var(|v| v[0] = Variable::real_input("u", 1, "furlong", 0.0, ""));
    assert_error(&md, "'u'", "unit 'furlong' is not declared");
    let md = with_var(|v| v[1] = v[1].clone().with_display_unit("mile"));
    assert_error(
        &md,
        "'y'",
        "displayUnit 'mile' is not declared for unit 'm'",
    );
    let md = with_var(|v| v[0] = Variable::real_input("u", 1, "", 0.0, "").with_display_unit("km"));
    assert_error(&md, "'u'", "without a unit");
}

#[test]
fn rule_type_names_unique_and_non_empty() {
    let mut md = typed_sample();
    md.type_definitions
        .push(SimpleType::integer("Length", "").with_description("again"));
    assert_error(&md, "type 'Length'", "declared twice");
    let mut md = typed_sample();
    md.type_definitions.push(SimpleType::real("", "Mass", ""));
    assert_error(&md, "type definition", "empty name");
}

#[test]
fn rule_declared_type_exists_with_the_same_base_type() {
    let md = {
        let mut md = typed_sample();
        md.variables[0] = md.variables[0].clone().with_declared_type("Speed");
        md
    };
    assert_error(
        &md,
        "'u'",
        "declaredType 'Speed' is not defined in TypeDefinitions",
    );
    let md = {
        let mut md = typed_sample();
        md.variables[3] = md.variables[3].clone().with_declared_type("Length");
        md
    };
    assert_error(
        &md,
        "'n'",
        "declaredType 'Length' is a Real type but the variable is Integer",
    );
    // also without any TypeDefinitions at all
    let md = with_var(|v| v[7] = v[7].clone().with_declared_type("Count"));
    assert_error(&md, "'count'", "declaredType 'Count' is not defined");
}

#[test]
fn rule_type_units_declared() {
    let mut md = typed_sample();
    md.type_definitions
        .push(SimpleType::real("Distance", "Length", "furlong"));
    md.type_definitions
        .push(SimpleType::real("Span", "Length", "m").with_display_unit("mile"));
    md.type_definitions
        .push(SimpleType::real("Ratio", "", "").with_display_unit("%"));
    assert_error(
        &md,
        "type 'Distance'",
        "unit 'furlong' is not declared in UnitDefinitions",
    );
    assert_error(
        &md,
        "type 'Span'",
        "displayUnit 'mile' is not declared for unit 'm'",
    );
    assert_error(&md, "type 'Ratio'", "displayUnit '%' given without a unit");
    // a variable without its own unit inherits the type's for its displayUnit
    let mut md = typed_sample();
    md.variables[0] = Variable::real_input("u", 1, "", 0.0, "")
        .with_declared_type("Length")
        .with_display_unit("km");
    assert_eq!(errors_of(&md), Vec::<String>::new());
    md.variables[0] = md.variables[0].clone().with_display_unit("mile");
    assert_error(
        &md,
        "'u'",
        "displayUnit 'mile' is not declared for unit 'm'",
    );
}

#[test]
fn rule_variable_unit_agrees_with_its_type() {
    let mut md = typed_sample();
    md.variables[6] = md.variables[6].clone().with_declared_type("Duration");
    assert_error(
        &md,
        "'rate'",
        "unit '1/s' differs from unit 's' of its declaredType 'Duration'",
    );
    // a variable without a unit, or a type without one, is fine
    let mut md = typed_sample();
    md.type_definitions.push(SimpleType::real("Any", "", ""));
    md.variables[6] = md.variables[6].clone().with_declared_type("Any");
    md.variables[0] = Variable::real_input("u", 1, "", 0.0, "").with_declared_type("Length");
    assert_eq!(errors_of(&md), Vec::<String>::new());
}

#[test]
fn rule_type_ranges() {
    let mut md = typed_sample();
    md.type_definitions
        .push(SimpleType::integer("Bad", "").with_integer_range(3, 1));
    md.type_definitions
        .push(SimpleType::real("Wide", "", "").with_real_range(0.0, f64::INFINITY));
    assert_error(&md, "type 'Bad'", "min 3 is greater than max 1");
    assert_error(&md, "type 'Wide'", "max inf is not finite");
}

#[test]
fn rule_dependencies_refer_to_existing_eligible_variables() {
    let md = with_var(|v| v[1].output_dependencies = Some(vec![99]));
    assert_error(&md, "'y'", "output dependency on value reference 99");
    // T (vr 3) is a parameter, not an input: not eligible for an output dependency.
    let md = with_var(|v| v[1].output_dependencies = Some(vec![3]));
    assert_error(&md, "'y'", "no eligible variable");
    // Integer input mode and Boolean input go sharing vr 5: ambiguous.
    let md = with_var(|v| {
        v[10].value_reference = 5;
        v[1].output_dependencies = Some(vec![5]);
    });
    assert_error(&md, "'y'", "ambiguous, both 'mode' and 'go' have it");
    let md = with_var(|v| v[1].output_dependencies = Some(vec![1, 1]));
    assert_error(&md, "'y'", "listed twice");
    let md = with_var(|v| v[6].initial_dependencies = Some(vec![4]));
    assert_error(&md, "'rate'", "initial dependency on value reference 4");
    // an output is not a known during initialization; u (input, vr 1) is the only match
    let md = with_var(|v| v[6].initial_dependencies = Some(vec![2]));
    assert_error(
        &md,
        "'rate'",
        "initial dependency on value reference 2: no eligible",
    );
    // initial dependency on an input of another type (Integer mode, vr 5)
    let md = with_var(|v| v[6].initial_dependencies = Some(vec![5]));
    assert_eq!(errors_of(&md), Vec::<String>::new());
}

#[test]
fn rule_dependencies_only_where_meaningful() {
    let md = with_var(|v| v[0].output_dependencies = Some(vec![]));
    assert_error(&md, "'u'", "not output");
    let md = with_var(|v| v[2] = v[2].clone().initial_depends_on(&[]));
    assert_error(&md, "'T'", "not an initial unknown");
}

#[test]
#[should_panic(expected = "with_real_range on non-Real variable 'n'")]
fn builder_misuse_panics_with_the_name() {
    let _ =
        Variable::integer_parameter("n", 1, 1, Variability::Fixed, "").with_real_range(0.0, 1.0);
}

#[test]
#[should_panic(expected = "with_declared_type on non-Real/Integer variable 'flag'")]
fn declared_type_on_boolean_panics_with_the_name() {
    let _ = Variable::boolean_parameter("flag", 1, true, Variability::Fixed, "")
        .with_declared_type("Count");
}

#[test]
#[should_panic(expected = "with_declared_type on non-Real/Integer variable 'label'")]
fn declared_type_on_string_panics_with_the_name() {
    let _ = Variable::string_parameter("label", 1, "", "").with_declared_type("Count");
}

#[test]
#[should_panic(expected = "with_display_unit on non-Real type 'Count'")]
fn simple_type_builder_misuse_panics_with_the_name() {
    let _ = SimpleType::integer("Count", "").with_display_unit("km");
}

#[test]
fn with_declared_type_sets_real_and_integer() {
    let v = Variable::real_output("y", 2, "m", "").with_declared_type("Length");
    assert_eq!(v.kind.declared_type(), Some("Length"));
    let v = Variable::integer_output("k", 2, "").with_declared_type("Count");
    assert_eq!(v.kind.declared_type(), Some("Count"));
    assert_eq!(
        Variable::integer_output("k", 2, "").kind.declared_type(),
        None
    );
}

// ---- Enumerations (FMI 2.0 sections 2.2.3 and 2.2.7) ---------------------------------

/// `typed_sample()` with the Enumeration type `Method` (1 `euler`, 2 `heun`) and the
/// tunable Enumeration parameter `method` (Integer/Enumeration value reference 7, start 2).
fn enum_sample() -> ModelDescription {
    let mut md = typed_sample();
    md.type_definitions.push(
        SimpleType::enumeration(
            "Method",
            "",
            vec![
                EnumerationItem::new("euler", 1, "explicit Euler"),
                EnumerationItem::new("heun", 2, "Heun's <method>"),
            ],
        )
        .with_description("integration method"),
    );
    md.variables.push(Variable::enumeration_parameter(
        "method",
        7,
        "Method",
        2,
        Variability::Tunable,
        "integration method",
    ));
    md
}

#[test]
fn enumeration_types_and_variables_are_written_as_fmi_2_0_says() {
    let md = enum_sample();
    assert_eq!(errors_of(&md), Vec::<String>::new());
    let x = md.to_xml();
    let ty = "    <SimpleType name=\"Method\" description=\"integration method\">\n      <Enumeration>\n        <Item name=\"euler\" value=\"1\" description=\"explicit Euler\"/>\n        <Item name=\"heun\" value=\"2\" description=\"Heun&apos;s &lt;method&gt;\"/>\n      </Enumeration>\n    </SimpleType>\n  </TypeDefinitions>\n";
    assert!(x.contains(ty), "{x}");
    assert!(
        x.contains("<ScalarVariable name=\"method\" valueReference=\"7\" description=\"integration method\" causality=\"parameter\" variability=\"tunable\" initial=\"exact\">\n      <Enumeration declaredType=\"Method\" start=\"2\"/>\n    </ScalarVariable>"),
        "{x}"
    );
    let quantity = SimpleType::enumeration("Q", "Choice", vec![EnumerationItem::new("a", 1, "")]);
    let mut md = enum_sample();
    md.type_definitions.push(quantity);
    assert!(md
        .to_xml()
        .contains("<Enumeration quantity=\"Choice\">\n        <Item name=\"a\" value=\"1\"/>"));
}

#[test]
fn enumeration_variables_are_accessed_as_integers() {
    let md = enum_sample();
    let v = md.find(ValueType::Integer, 7).unwrap();
    assert_eq!(v.name, "method");
    assert_eq!(v.value_type(), ValueType::Integer);
    assert_eq!(v.kind.element(), "Enumeration");
    assert_eq!(v.kind.declared_type(), Some("Method"));
    assert!(md.find(ValueType::Real, 7).is_none());
    // Integer and Enumeration share one value-reference numbering (FMI 2.0 section 2.2.7).
    let mut md = enum_sample();
    md.variables.last_mut().unwrap().value_reference = 1;
    assert_error(
        &md,
        "'method'",
        "Integer value reference 1 is already used by 'n'",
    );
}

#[test]
fn rule_enumeration_declared_type_exists_and_is_an_enumeration() {
    let mut md = enum_sample();
    md.variables.last_mut().unwrap().kind = VariableKind::Enumeration {
        declared_type: "Scheme".into(),
        start: Some(1),
    };
    assert_error(
        &md,
        "'method'",
        "declaredType 'Scheme' is not defined in TypeDefinitions",
    );
    let mut md = enum_sample();
    md.variables.last_mut().unwrap().kind = VariableKind::Enumeration {
        declared_type: "Count".into(),
        start: Some(1),
    };
    assert_error(
        &md,
        "'method'",
        "declaredType 'Count' is a Integer type but the variable is Enumeration",
    );
    // An Integer variable cannot declare an Enumeration type either.
    let mut md = enum_sample();
    md.variables[3] = md.variables[3].clone().with_declared_type("Method");
    assert_error(
        &md,
        "'n'",
        "declaredType 'Method' is a Enumeration type but the variable is Integer",
    );
}

#[test]
fn rule_enumeration_start_is_one_of_the_items() {
    for bad in [0, 3, -1] {
        let mut md = enum_sample();
        md.variables.last_mut().unwrap().kind = VariableKind::Enumeration {
            declared_type: "Method".into(),
            start: Some(bad),
        };
        assert_error(
            &md,
            "'method'",
            &format!("start {bad} is not an item of its declaredType 'Method' (1 euler, 2 heun)"),
        );
    }
    // A parameter needs its start, an Enumeration one too.
    let mut md = enum_sample();
    md.variables.last_mut().unwrap().kind = VariableKind::Enumeration {
        declared_type: "Method".into(),
        start: None,
    };
    assert_error(&md, "'method'", "a start value is required");
}

#[test]
fn rule_enumeration_items_are_present_named_and_unique() {
    let with_items = |items: Vec<EnumerationItem>| {
        let mut md = enum_sample();
        md.type_definitions
            .push(SimpleType::enumeration("E", "", items));
        md
    };
    assert_error(
        &with_items(vec![]),
        "type 'E'",
        "an Enumeration needs at least one Item",
    );
    assert_error(
        &with_items(vec![EnumerationItem::new("", 1, "")]),
        "type 'E'",
        "item of value 1 has an empty name",
    );
    assert_error(
        &with_items(vec![
            EnumerationItem::new("a", 1, ""),
            EnumerationItem::new("a", 2, ""),
        ]),
        "type 'E'",
        "item name 'a' is used twice",
    );
    assert_error(
        &with_items(vec![
            EnumerationItem::new("a", 1, ""),
            EnumerationItem::new("b", 1, ""),
        ]),
        "type 'E'",
        "items 'a' and 'b' have the same value 1",
    );
    assert_error(
        &with_items(vec![EnumerationItem::new("a", 1, "bell\u{7}")]),
        "description of item 'a' of type 'E'",
        "control character",
    );
    // Values need not be 1..n (FMI 2.0 gives each item its value).
    assert_eq!(
        errors_of(&with_items(vec![
            EnumerationItem::new("minus", -1, ""),
            EnumerationItem::new("ten", 10, ""),
        ])),
        Vec::<String>::new()
    );
}

#[test]
fn with_declared_type_renames_an_enumerations_type() {
    let v = Variable::enumeration_parameter("m", 1, "A", 1, Variability::Fixed, "")
        .with_declared_type("B");
    assert_eq!(v.kind.declared_type(), Some("B"));
    assert_eq!(items_text(&[EnumerationItem::new("x", 4, "")]), "4 x");
}

#[test]
#[should_panic(expected = "with_integer_range on non-Integer type 'Method'")]
fn integer_range_on_an_enumeration_type_panics_with_the_name() {
    let _ = SimpleType::enumeration("Method", "", vec![]).with_integer_range(0, 1);
}
