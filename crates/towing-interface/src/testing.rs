//! In-process test helpers shared by the FMU crates' tests (feature `testing`, enabled as a
//! dev-dependency): instances on the repository's `scenarios/` folder, the checks of the
//! committed model descriptions, and the abuse checks of the `scenario` parameter that both
//! FMUs must pass.
#![allow(clippy::missing_panics_doc, clippy::expect_used)]

use crate::codec::{ModelVariable, VariableTable};
use fmi2_slave::description::ModelDescription;
use fmi2_slave::ffi::Fmi2Status;
use fmi2_slave::testing::{Exports, Fmu};
use fmi2_slave::{Fmi2Model, InstanceContext, Logger, ValueType};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// The repository (workspace) root.
#[must_use]
pub fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .canonicalize()
        .expect("the workspace root exists")
}

/// The repository's `scenarios/` folder as a resource URI: it holds `paper.toml`, like the
/// packaged FMU's `resources/`.
#[must_use]
pub fn resources_uri() -> String {
    format!("file://{}", workspace_root().join("scenarios").display()).replace(' ', "%20")
}

/// A freshly instantiated FMU (not initialized) with [`resources_uri`] as its resources.
#[must_use]
pub fn instantiate(exports: Exports, description: &ModelDescription, name: &str) -> Fmu {
    Fmu::try_new(exports, description, name, Some(&resources_uri()), false)
        .unwrap_or_else(|log| panic!("instantiate failed: {log:?}"))
}

/// Every Real output's value reference, in model-description order.
#[must_use]
pub fn real_outputs(description: &ModelDescription) -> Vec<u32> {
    description
        .variables
        .iter()
        .filter(|v| {
            v.causality == fmi2_slave::Causality::Output && v.value_type() == ValueType::Real
        })
        .map(|v| v.value_reference)
        .collect()
}

/// The last message `fmu` logged contains `needle` (all messages are shown when not).
pub fn assert_last_message_contains(fmu: &Fmu, needle: &str) {
    assert!(
        fmu.last_text().contains(needle),
        "last message lacks {needle:?}: {}",
        fmu.log_text()
    );
}

/// The text of the repository file `rel`.
#[must_use]
pub fn read_repository_file(rel: &str) -> String {
    let path = workspace_root().join(rel);
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// `description` is consistent (the checks `fmi2-slave` runs at instantiation).
pub fn assert_description_is_consistent(description: &ModelDescription) {
    if let Err(errors) = description.validate() {
        panic!(
            "{} is inconsistent: {errors:?}",
            description.model_identifier
        );
    }
}

/// The committed `modelDescription/<modelIdentifier>.xml` is what `description` generates.
pub fn assert_committed_model_description_matches(description: &ModelDescription) {
    let rel = format!("modelDescription/{}.xml", description.model_identifier);
    assert!(
        read_repository_file(&rel) == description.to_xml(),
        "{rel} is stale: run `cargo xtask model-description`"
    );
}

/// docs/interface.md holds the variable table `description` generates.
pub fn assert_interface_document_lists_the_variables(description: &ModelDescription) {
    let doc = read_repository_file("docs/interface.md");
    let table = fmi2_slave::doc::variables_markdown(description);
    assert!(
        doc.contains(&table),
        "docs/interface.md does not hold the current {} table: run `cargo xtask model-description`",
        description.model_identifier
    );
}

/// Every name of DESIGN.md's contract ([`contract_names`](crate::contract_names)) is
/// declared.
pub fn assert_contract_names_are_declared(description: &ModelDescription) {
    for name in crate::contract_names() {
        assert!(
            description.variables.iter().any(|v| v.name == name),
            "missing contract variable {name}"
        );
    }
}

/// Every variable of `description` decodes through `table` to itself: a variable of its
/// value reference and FMI type (a contract variable of its name), and the table holds no
/// variable the description lacks.
pub fn assert_every_variable_decodes_to_itself<V: ModelVariable>(
    description: &ModelDescription,
    table: &VariableTable<V>,
) {
    for var in &description.variables {
        let (ty, vr) = (var.value_type(), var.value_reference);
        let decoded = table
            .decode(ty, vr)
            .unwrap_or_else(|e| panic!("{}: {e}", var.name));
        assert_eq!(decoded.value_reference(), vr, "{}", var.name);
        assert_eq!(decoded.value_type(), ty, "{}", var.name);
        if let Some(contract) = decoded.contract() {
            assert_eq!(contract.name(), var.name);
        }
    }
    let extra: Vec<V> = table
        .variables()
        .filter(|v| {
            description
                .find(v.value_type(), v.value_reference())
                .is_none()
        })
        .collect();
    assert!(extra.is_empty(), "not in the model description: {extra:?}");
    assert_eq!(table.variables().count(), description.variables.len());
}

/// A value reference no variable of `description` has, of any type.
fn unused_reference(description: &ModelDescription) -> u32 {
    (900_000..)
        .find(|&vr| {
            description
                .variables
                .iter()
                .all(|v| v.value_reference != vr)
        })
        .expect("a free value reference")
}

/// A value reference unknown to `description` is `fmi2Error` in the getter and the setter
/// of every FMI type, the message naming the reference and the type (never `fmi2Fatal`).
pub fn assert_unknown_references_are_errors(exports: Exports, description: &ModelDescription) {
    let vr = unused_reference(description);
    for ty in [
        ValueType::Real,
        ValueType::Integer,
        ValueType::Boolean,
        ValueType::String,
    ] {
        for set in [false, true] {
            // In initialization mode, where getters and setters are both allowed.
            let fmu = instantiate(exports, description, "unknown");
            assert_eq!(fmu.setup(0.0, None), Fmi2Status::Ok);
            assert_eq!(fmu.enter_init(), Fmi2Status::Ok, "{}", fmu.log_text());
            let status = match (ty, set) {
                (ValueType::Real, false) => fmu.try_get_real(vr).0,
                (ValueType::Real, true) => fmu.set_real(vr, 1.0),
                (ValueType::Integer, false) => fmu.try_get_integer(vr).0,
                (ValueType::Integer, true) => fmu.set_integer(vr, 1),
                (ValueType::Boolean, false) => fmu.try_get_boolean(vr).0,
                (ValueType::Boolean, true) => fmu.set_boolean(vr, true),
                (ValueType::String, false) => fmu.try_get_string(vr).0,
                (ValueType::String, true) => fmu.set_string(vr, "x"),
            };
            assert_eq!(status, Fmi2Status::Error, "{ty:?} set {set}");
            assert_last_message_contains(&fmu, &format!("unknown value reference {vr}"));
            assert_last_message_contains(&fmu, ty.as_str());
        }
    }
}

/// The model's own getters and setters (called directly, past the layer's checks) refuse a
/// value reference unknown to `description` of every FMI type with an error naming the
/// reference, the type and the model: the FMU's variable table decodes it, nothing panics.
pub fn assert_model_refuses_unknown_references<M: Fmi2Model>(description: &ModelDescription) {
    let vr = unused_reference(description);
    let logger = Logger::silent("unknown");
    let ctx = InstanceContext {
        instance_name: "unknown",
        resource_dir: None,
        logger: &logger,
    };
    let mut model = M::instantiate(&ctx).expect("instantiate");
    let errors = [
        (ValueType::Real, model.get_real(vr).err()),
        (ValueType::Real, model.set_real(&logger, vr, 1.0).err()),
        (ValueType::Integer, model.get_integer(vr).err()),
        (ValueType::Integer, model.set_integer(&logger, vr, 1).err()),
        (ValueType::Boolean, model.get_boolean(vr).err()),
        (
            ValueType::Boolean,
            model.set_boolean(&logger, vr, true).err(),
        ),
        (ValueType::String, model.get_string(vr).err()),
        (ValueType::String, model.set_string(&logger, vr, "x").err()),
    ];
    for (ty, error) in errors {
        let e = error.unwrap_or_else(|| panic!("{ty:?} value reference {vr} was accepted"));
        let expected = format!(
            "unknown value reference {vr}: no {} variable of {} has it",
            ty.as_str(),
            description.model_identifier
        );
        assert_eq!(e, expected);
    }
}

/// Without a resources folder and with an empty `scenario`, entering initialization is
/// refused with a message saying to set `scenario`.
pub fn assert_no_resources_and_no_scenario_is_refused(
    exports: Exports,
    description: &ModelDescription,
) {
    let fmu = Fmu::try_new(exports, description, "bare", None, false)
        .unwrap_or_else(|log| panic!("instantiate failed: {log:?}"));
    assert_eq!(fmu.setup(0.0, None), Fmi2Status::Ok);
    assert_eq!(fmu.enter_init(), Fmi2Status::Error);
    assert_last_message_contains(&fmu, "set scenario");
}

/// A `scenario` naming a file that does not exist is refused at initialization with a
/// message naming the file.
pub fn assert_missing_scenario_file_is_named(exports: Exports, description: &ModelDescription) {
    let missing = "/nonexistent/dir/s.toml";
    let fmu = instantiate(exports, description, "missing");
    assert_eq!(fmu.set_string(crate::vr::SCENARIO, missing), Fmi2Status::Ok);
    assert_eq!(fmu.setup(0.0, None), Fmi2Status::Ok);
    assert_eq!(fmu.enter_init(), Fmi2Status::Error);
    assert_last_message_contains(&fmu, missing);
}

/// `run_id` (value reference 3) is set and read with fmi2SetString/fmi2GetString, before
/// and during initialization; one with a control character is refused naming the
/// parameter and the reason, and the previous value is kept.
pub fn assert_run_id_is_kept_and_checked(exports: Exports, description: &ModelDescription) {
    let run_id = crate::vr::RUN_ID;
    let fmu = instantiate(exports, description, "run_id");
    assert_eq!(
        fmu.set_string(run_id, "campaign 3 / run 12"),
        Fmi2Status::Ok
    );
    assert_eq!(fmu.setup(0.0, None), Fmi2Status::Ok);
    assert_eq!(fmu.enter_init(), Fmi2Status::Ok, "{}", fmu.log_text());
    assert_eq!(fmu.get_string(run_id), "campaign 3 / run 12");
    assert_eq!(fmu.set_string(run_id, "a\tb"), Fmi2Status::Error);
    assert_last_message_contains(
        &fmu,
        "parameter `run_id`: must not contain control characters",
    );
    let fmu = instantiate(exports, description, "run_id2");
    assert_eq!(fmu.set_string(run_id, "line\nbreak"), Fmi2Status::Error);
    assert_eq!(
        fmu.setup(0.0, None),
        Fmi2Status::Error,
        "the instance is in error"
    );
    let fmu = instantiate(exports, description, "run_id3");
    assert_eq!(fmu.setup(0.0, None), Fmi2Status::Ok);
    assert_eq!(fmu.enter_init(), Fmi2Status::Ok, "{}", fmu.log_text());
    assert_eq!(fmu.get_string(run_id), "", "empty by default");
}

/// The model-description tests of an FMU crate, on the `static` [`ModelDescription`]
/// `$description` and the FMU's [`VariableTable`] `$table`: consistent, equal to the
/// committed `modelDescription/<id>.xml`, its variable table in docs/interface.md, every
/// contract name declared, and every variable decoding to itself.
#[macro_export]
macro_rules! model_description_tests {
    ($description:expr, $table:expr) => {
        #[test]
        fn every_variable_decodes_to_itself() {
            $crate::testing::assert_every_variable_decodes_to_itself(&$description, &$table);
        }

        #[test]
        fn description_is_consistent() {
            $crate::testing::assert_description_is_consistent(&$description);
        }

        #[test]
        fn committed_model_description_matches_the_variable_table() {
            $crate::testing::assert_committed_model_description_matches(&$description);
        }

        #[test]
        fn interface_document_lists_the_generated_variable_table() {
            $crate::testing::assert_interface_document_lists_the_variables(&$description);
        }

        #[test]
        fn contract_names_of_design_md_are_present() {
            $crate::testing::assert_contract_names_are_declared(&$description);
        }
    };
}

/// An MCAP log's messages by topic: (log time ns, JSON payload).
pub type LogMessages = HashMap<String, Vec<(u64, Vec<u8>)>>;

/// Every message of a complete MCAP log by topic, and the last log time; asserts that log
/// times never decrease (docs/logging.md).
#[must_use]
pub fn read_log_messages(bytes: &[u8]) -> (LogMessages, u64) {
    let mut by_topic = LogMessages::new();
    let mut last = 0;
    for m in mcap::MessageStream::new(bytes).expect("an MCAP file") {
        let m = m.expect("a readable message");
        assert!(m.log_time >= last, "log times must not decrease");
        last = m.log_time;
        by_topic
            .entry(m.channel.topic.clone())
            .or_default()
            .push((m.log_time, m.data.to_vec()));
    }
    (by_topic, last)
}

/// `fmu` has `log_file` set to a path in a folder that does not exist: initialization
/// ends in fmi2Error with a message naming the parameter, the path and the reason.
pub fn assert_uncreatable_log_file_is_named(fmu: &Fmu, path: &str) {
    assert_eq!(fmu.setup(0.0, None), Fmi2Status::Ok);
    assert_eq!(fmu.enter_init(), Fmi2Status::Ok);
    assert_eq!(fmu.exit_init(), Fmi2Status::Error);
    let text = fmu.last_text();
    assert!(
        text.contains("`log_file`") && text.contains(path) && text.contains("No such file"),
        "{text}"
    );
}

/// Set in the child process of [`rerun_in_child`].
const CHILD: &str = "TOWING_TEST_CHILD";

/// For a test that needs a process of its own (one whose file size is limited,
/// [`limit_file_size`]): in the test's own process, runs the test `name` (its path in the
/// test binary, e.g. `a_log_write_failure_is_reported_by_the_next_step_every_time`) again
/// in a child process of the same binary, asserts that it passed and returns `false`; in
/// the child, returns `true`, and the test does its work. The child ignores SIGXFSZ, so a
/// write beyond the limit fails with EFBIG instead of killing it.
#[must_use]
pub fn rerun_in_child(name: &str) -> bool {
    if std::env::var_os(CHILD).is_some() {
        return true;
    }
    let exe = std::env::current_exe().expect("the test binary's path");
    let out = std::process::Command::new("sh")
        .args(["-c", "trap '' XFSZ; exec \"$0\" \"$@\""])
        .arg(exe)
        .args(["--exact", name, "--nocapture", "--test-threads", "1"])
        .env(CHILD, "1")
        .output()
        .expect("the test binary runs again");
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success() && text.contains("1 passed"),
        "the child run of {name} failed ({}):\n{text}\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    false
}

/// Limits the size of every file this process writes to `bytes` (`None`: no limit), with
/// `prlimit`: a write beyond it fails (EFBIG), as on a full disk. Only in a child of
/// [`rerun_in_child`].
pub fn limit_file_size(bytes: Option<u64>) {
    assert!(
        std::env::var_os(CHILD).is_some(),
        "only in a child process of rerun_in_child"
    );
    let limit = bytes.map_or_else(|| "unlimited".to_owned(), |b| b.to_string());
    let status = std::process::Command::new("prlimit")
        .arg(format!("--pid={}", std::process::id()))
        .arg(format!("--fsize={limit}:"))
        .status()
        .expect("prlimit runs");
    assert!(status.success(), "prlimit --fsize={limit}");
}
