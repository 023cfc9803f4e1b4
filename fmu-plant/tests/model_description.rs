//! The committed model description and the interface document must be what the Rust
//! variable table generates (`cargo xtask model-description` regenerates both).
#![allow(clippy::unwrap_used)]

use std::path::Path;
use towing_plant::variables::DESCRIPTION;

fn read(rel: &str) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join(rel);
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

#[test]
fn description_is_consistent() {
    DESCRIPTION.validate().unwrap();
}

#[test]
fn committed_model_description_matches_the_variable_table() {
    assert!(
        read("modelDescription/TowingPlant.xml") == DESCRIPTION.to_xml(),
        "modelDescription/TowingPlant.xml is stale: run `cargo xtask model-description`"
    );
}

#[test]
fn interface_document_lists_the_generated_variable_table() {
    let doc = read("docs/interface.md");
    let table = fmi2_slave::doc::variables_markdown(&DESCRIPTION);
    assert!(
        doc.contains(&table),
        "docs/interface.md does not hold the current variable table: run `cargo xtask model-description`"
    );
}

#[test]
fn contract_names_of_design_md_are_present() {
    let names: Vec<&str> = DESCRIPTION
        .variables
        .iter()
        .map(|v| v.name.as_str())
        .collect();
    let mut expected = vec![];
    for tug in ["tug1", "tug2"] {
        for f in ["force_surge", "force_sway", "moment_yaw"] {
            expected.push(format!("{tug}.{f}"));
        }
    }
    for vessel in ["ship", "tug1", "tug2"] {
        for s in ["x", "y", "psi", "u", "v", "r"] {
            expected.push(format!("{vessel}.{s}"));
        }
    }
    for line in ["towline1", "towline2"] {
        for f in ["tension_cmd", "length", "angle", "tension"] {
            expected.push(format!("{line}.{f}"));
        }
    }
    for k in 1..=towing_model::MAX_OBSTACLES {
        for f in ["x", "y", "psi", "speed", "length", "width", "kind"] {
            expected.push(format!("obstacle[{k}].{f}"));
        }
    }
    expected.push("scenario".into());
    for e in &expected {
        assert!(names.contains(&e.as_str()), "missing contract variable {e}");
    }
}
