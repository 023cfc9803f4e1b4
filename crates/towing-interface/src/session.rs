//! The scenario and log life cycle both FMUs share ([`RunSession`]): the String parameters
//! `scenario`, `log_file` and `run_id` (the session's registry, [`PARAMETERS`], which both
//! FMUs declare before their own), the resources folder, the scenario as loaded (with its
//! text, so a saved FMU state does not depend on the file still existing) and the MCAP log
//! (docs/logging.md), opened with the run description when initialization ends and finished
//! at `fmi2Terminate`, or at `fmi2FreeInstance` / `fmi2Reset` when terminate did not.

use crate::scenario::ScenarioFile;
use fmi2_slave::Logger;
use std::path::{Path, PathBuf};
use towing_log::writer::Batch;
use towing_log::{LogError, LogOptions, LogWriter, RunInfo, SharedLog};
use towing_model::registry::{self, Kind, Value};
use towing_model::Scenario;

/// A parameter of the session.
pub type Parameter = registry::Parameter<RunSession>;

/// Index of `scenario` in [`PARAMETERS`] (setting it reads the scenario again during
/// initialization).
pub const SCENARIO: usize = 0;

/// The session's parameters, the same in both FMUs (value references
/// [`crate::vr::session_parameter`]: `scenario` 1, `log_file` 2, `run_id` 3). Their names
/// are those of the interface contract (DESIGN.md), which masters set.
pub static PARAMETERS: &[Parameter] = &[
    Parameter {
        name: "scenario",
        old_name: None,
        description: "Path of the scenario file (TOML, docs/scenario-format.md); empty: the bundled paper scenario resources/paper.toml. Give both FMUs the same file: the plant takes the vessels, the traffic and the physics from it, the controller its prediction models, formation, route and waterway. Read at fmi2EnterInitializationMode, and again when set during initialization",
        kind: Kind::String {
            get: |s| &s.scenario_parameter,
            set: |s, v| {
                v.clone_into(&mut s.scenario_parameter);
                Ok(())
            },
        },
    },
    Parameter {
        name: "log_file",
        old_name: None,
        description: "Path of the MCAP log of this unit (docs/logging.md), created (replaced) at fmi2ExitInitializationMode and closed at fmi2Terminate; empty: no log",
        kind: Kind::String {
            get: |s| &s.log_file,
            set: |s, v| {
                s.set_log_file(v);
                Ok(())
            },
        },
    },
    Parameter {
        name: "run_id",
        old_name: None,
        description: "Identifier of the run, given by the user or the master (masters/closed_loop.py gives both FMUs the same generated one): written into the run description of the MCAP log (docs/logging.md), so the analyzer can tell whether a plant log and a controller log belong to the same run; empty: none. One line, no control characters",
        kind: Kind::String {
            get: |s| &s.run_id,
            set: |s, v| {
                if let Some(c) = v.chars().find(|c| c.is_control()) {
                    return Err(format!(
                        "must not contain control characters (it is one line of the log's run description), got {:?} with U+{:04X}",
                        v,
                        u32::from(c)
                    ));
                }
                v.clone_into(&mut s.run_id);
                Ok(())
            },
        },
    },
];

/// What the run description of an FMU's log holds besides the scenario
/// ([`RunSession::open_log`]).
#[derive(Debug, Clone, PartialEq)]
pub struct LogHeader<'a> {
    /// The model identifier.
    pub unit: &'a str,
    /// The model description's GUID.
    pub guid: &'a str,
    /// The FMU's version.
    pub version: &'a str,
    /// `fmi2SetupExperiment`'s start time (s).
    pub start_time: f64,
    /// The value of every parameter of the FMU's registry
    /// ([`crate::parameters::values_json`]); the session adds its own.
    pub parameters: serde_json::Map<String, serde_json::Value>,
}

/// The session's parameters of an FMU instance ([`PARAMETERS`]), the scenario they loaded
/// and the log they opened.
///
/// A clone (the FMU-state copies the layer keeps) shares the log: the log is the instance's
/// own, not part of the FMU state (nor are `log_file` and `run_id`).
#[derive(Debug, Clone, Default)]
pub struct RunSession {
    scenario_parameter: String,
    log_file: String,
    run_id: String,
    resource_dir: Option<PathBuf>,
    loaded: Option<ScenarioFile>,
    log: SharedLog,
}

impl RunSession {
    /// A session of an instance whose resources folder is `resource_dir`: every parameter
    /// empty (the bundled scenario, no log, no run identifier), nothing loaded.
    #[must_use]
    pub fn new(resource_dir: Option<&Path>) -> Self {
        RunSession {
            resource_dir: resource_dir.map(Path::to_path_buf),
            ..RunSession::default()
        }
    }

    /// The `scenario` parameter.
    #[must_use]
    pub fn scenario_parameter(&self) -> &str {
        &self.scenario_parameter
    }

    /// Sets the `scenario` parameter and returns the previous value (to restore when the
    /// new one cannot be loaded); nothing is read here.
    pub fn replace_scenario_parameter(&mut self, value: &str) -> String {
        std::mem::replace(&mut self.scenario_parameter, value.to_owned())
    }

    /// The `log_file` parameter.
    #[must_use]
    pub fn log_file(&self) -> &str {
        &self.log_file
    }

    /// Sets the `log_file` parameter (the log is created when initialization ends).
    pub fn set_log_file(&mut self, value: &str) {
        value.clone_into(&mut self.log_file);
    }

    /// The `run_id` parameter.
    #[must_use]
    pub fn run_id(&self) -> &str {
        &self.run_id
    }

    /// The value of the session's parameter `index` ([`PARAMETERS`]).
    ///
    /// # Panics
    /// `index` out of [`PARAMETERS`] (the FMU's variable table only makes valid ones).
    #[must_use]
    pub fn parameter(&self, index: usize) -> String {
        match PARAMETERS[index].get(self) {
            Value::String(v) => v,
            other => unreachable!("the session's parameters are Strings, got {other:?}"),
        }
    }

    /// Sets the session's parameter `index` ([`PARAMETERS`]) to `value`, or refuses it
    /// (`parameter `run_id`: ...`). Returns the previous `scenario` when `index` is
    /// [`SCENARIO`]: the FMU reads the scenario again during initialization and, when that
    /// fails, restores it ([`RunSession::replace_scenario_parameter`]).
    ///
    /// # Errors
    /// The parameter's refusal, naming it and the reason.
    pub fn set_parameter(&mut self, index: usize, value: &str) -> Result<Option<String>, String> {
        let previous = (index == SCENARIO).then(|| self.scenario_parameter.clone());
        PARAMETERS[index]
            .set(self, Value::String(value.to_owned()))
            .map_err(|e| format!("parameter `{}`: {}", e.field, e.reason))?;
        Ok(previous)
    }

    /// Reads the scenario the `scenario` parameter names (or the bundled one), hands it to
    /// `build` (what the FMU makes of it) and, when that succeeds, keeps it as the loaded
    /// scenario; nothing changes on an error.
    ///
    /// # Errors
    /// The file's error ([`ScenarioFile::load`]) or `build`'s.
    pub fn load<T>(
        &mut self,
        build: impl FnOnce(&ScenarioFile) -> Result<T, String>,
    ) -> Result<T, String> {
        let file = ScenarioFile::load(&self.scenario_parameter, self.resource_dir.as_deref())?;
        let built = build(&file)?;
        self.loaded = Some(file);
        Ok(built)
    }

    /// Restores the `scenario` parameter and the loaded scenario of a saved FMU state (the
    /// log, `log_file` and the resources folder stay this instance's).
    pub fn restore(&mut self, scenario_parameter: String, loaded: Option<ScenarioFile>) {
        self.scenario_parameter = scenario_parameter;
        self.loaded = loaded;
    }

    /// `fmi2SetFMUstate`: takes the `scenario` parameter and the loaded scenario of
    /// `saved` (the session of the FMU state), keeping this instance's own log, `log_file`,
    /// `run_id` and resources folder: the log is not part of the FMU state, so an instance
    /// goes on writing its own file whichever instance the state came from.
    pub fn restore_from(&mut self, saved: &RunSession) {
        self.restore(saved.scenario_parameter.clone(), saved.loaded.clone());
    }

    /// The scenario as loaded: origin, text and parsed scenario.
    #[must_use]
    pub fn loaded(&self) -> Option<&ScenarioFile> {
        self.loaded.as_ref()
    }

    /// The parsed scenario, once loaded.
    #[must_use]
    pub fn scenario(&self) -> Option<&Scenario> {
        self.loaded.as_ref().map(|f| &f.scenario)
    }

    /// Creates the log `log_file` names (nothing when it is empty), writes the run
    /// description (`header`, the `scenario` parameter, `run_id`, the loaded scenario's name
    /// and text, the session's parameters among the FMU's) and what `setup` writes (channels, messages at the start time), then hands the
    /// writer to its own thread. A log of an earlier initialization (after `fmi2Reset`) was
    /// finished by [`release`](Self::release).
    ///
    /// # Errors
    /// `parameter `log_file`: ...` naming the path and the reason when the file cannot be
    /// created or written; no scenario loaded.
    pub fn open_log(
        &mut self,
        log: &Logger,
        header: LogHeader<'_>,
        setup: impl FnOnce(&mut LogWriter) -> Result<(), LogError>,
    ) -> Result<(), String> {
        if self.log_file.is_empty() {
            return Ok(());
        }
        let loaded = self
            .loaded
            .as_ref()
            .ok_or_else(|| "no scenario is loaded".to_owned())?;
        let mut parameters = header.parameters;
        parameters.extend(crate::parameters::values_json(PARAMETERS, self));
        let info = RunInfo {
            unit: header.unit,
            guid: header.guid,
            version: header.version,
            scenario: &self.scenario_parameter,
            scenario_name: &loaded.scenario.name,
            run_id: &self.run_id,
            start_time: header.start_time,
            parameters: serde_json::Value::Object(parameters),
            scenario_text: &loaded.text,
        };
        self.log = SharedLog::open(&self.log_file, LogOptions::default(), &info, setup)
            .map_err(|e| format!("parameter `log_file`: {e}"))?;
        log.info("logEvents", &format!("MCAP log {} created", self.log_file));
        Ok(())
    }

    /// The log (no log while `log_file` is empty or before initialization ends).
    #[must_use]
    pub fn log(&self) -> &SharedLog {
        &self.log
    }

    /// At every step: hands the batch `messages` makes (called only while the log is
    /// active; `None`: nothing to write this step) to the log, or else waits for the
    /// messages of earlier steps. Returns a logging failure not reported yet, once, for the
    /// FMU to report as `fmi2Warning`: the failure of a step's messages comes back at the
    /// next step, whatever the writer thread's timing ([`SharedLog::batch`]).
    pub fn log_step(&self, messages: impl FnOnce() -> Option<Batch>) -> Option<String> {
        if self.log.is_active() {
            if let Some(batch) = messages() {
                return self.log.batch(batch);
            }
        }
        self.log.settle()
    }

    /// `fmi2Terminate`: finishes the log.
    ///
    /// # Errors
    /// `closing the log: ...` when the file could not be completed.
    pub fn terminate(&mut self) -> Result<(), String> {
        self.log
            .finish()
            .map(drop)
            .map_err(|e| format!("closing the log: {e}"))
    }

    /// `fmi2FreeInstance` and `fmi2Reset`: finishes the log if terminate did not, reporting
    /// a failure through `log` (neither function can return it).
    pub fn release(&mut self, log: &Logger) {
        if let Err(e) = self.log.finish() {
            log.error(&format!("closing the log: {e}"));
        }
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    fn scenarios() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios")
    }

    #[test]
    fn a_failed_build_keeps_nothing_and_a_successful_one_keeps_the_text() {
        let mut session = RunSession::new(Some(&scenarios()));
        let e = session.load(|_| Err::<(), _>("refused".to_owned()));
        assert_eq!(e, Err("refused".to_owned()));
        assert!(session.loaded().is_none());
        let name = session.load(|f| Ok(f.scenario.name.clone())).unwrap();
        assert_eq!(name, "paper");
        assert!(session.loaded().unwrap().text.contains("[ship]"));
        assert_eq!(session.scenario().map(|s| s.name.as_str()), Some("paper"));
    }

    #[test]
    fn without_log_file_no_log_is_opened_and_terminate_is_quiet() {
        let mut session = RunSession::new(Some(&scenarios()));
        session.load(|_| Ok(())).unwrap();
        let logger = Logger::silent("s");
        let header = LogHeader {
            unit: "TowingPlant",
            guid: "{0}",
            version: "0",
            start_time: 0.0,
            parameters: serde_json::Map::new(),
        };
        session.open_log(&logger, header, |_| Ok(())).unwrap();
        assert!(!session.log().is_active());
        assert_eq!(session.terminate(), Ok(()));
    }

    #[test]
    fn a_log_without_a_loaded_scenario_is_refused() {
        let mut session = RunSession::new(None);
        session.set_log_file("/tmp/never-written.mcap");
        let header = LogHeader {
            unit: "TowingPlant",
            guid: "{0}",
            version: "0",
            start_time: 0.0,
            parameters: serde_json::Map::new(),
        };
        let e = session.open_log(&Logger::silent("s"), header, |_| Ok(()));
        assert_eq!(e, Err("no scenario is loaded".to_owned()));
    }

    #[test]
    fn the_session_parameters_are_strings_with_value_references_1_to_3() {
        let names: Vec<&str> = PARAMETERS.iter().map(|p| p.name).collect();
        assert_eq!(names, ["scenario", "log_file", "run_id"]);
        assert_eq!(PARAMETERS[SCENARIO].name, "scenario");
        let vrs: Vec<u32> = (0..PARAMETERS.len())
            .map(crate::vr::session_parameter)
            .collect();
        assert_eq!(
            vrs,
            [crate::vr::SCENARIO, crate::vr::LOG_FILE, crate::vr::RUN_ID]
        );
        assert_eq!(vrs, [1, 2, 3]);
        for p in PARAMETERS {
            assert_eq!(p.type_name(), "String", "{}", p.name);
            assert_eq!(
                p.default_value(),
                Value::String(String::new()),
                "{}",
                p.name
            );
        }
    }

    #[test]
    fn setting_a_parameter_returns_the_previous_scenario_and_run_id_refuses_control_characters() {
        let mut session = RunSession::new(None);
        assert_eq!(
            session.set_parameter(SCENARIO, "a.toml"),
            Ok(Some(String::new()))
        );
        assert_eq!(
            session.set_parameter(SCENARIO, "b.toml"),
            Ok(Some("a.toml".to_owned()))
        );
        assert_eq!(session.scenario_parameter(), "b.toml");
        assert_eq!(session.set_parameter(1, "/tmp/x.mcap"), Ok(None));
        assert_eq!(session.log_file(), "/tmp/x.mcap");
        assert_eq!(session.set_parameter(2, "2024-05-01 run 7 ✓"), Ok(None));
        assert_eq!(session.run_id(), "2024-05-01 run 7 ✓");
        assert_eq!(session.parameter(2), "2024-05-01 run 7 ✓");
        let e = session.set_parameter(2, "a\nb").unwrap_err();
        assert_eq!(
            e,
            "parameter `run_id`: must not contain control characters (it is one line of the log's run description), got \"a\\nb\" with U+000A"
        );
        assert_eq!(
            session.run_id(),
            "2024-05-01 run 7 ✓",
            "the old value is kept"
        );
        let values = crate::parameters::values_json(PARAMETERS, &session);
        assert_eq!(values["scenario"], "b.toml");
        assert_eq!(values["run_id"], "2024-05-01 run 7 ✓");
    }
}
