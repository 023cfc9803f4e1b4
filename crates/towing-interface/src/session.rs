//! The scenario and log life cycle both FMUs share ([`RunSession`]): the `scenario` and
//! `log_file` parameters, the resources folder, the scenario as loaded (with its text, so a
//! saved FMU state does not depend on the file still existing) and the MCAP log
//! (docs/logging.md), opened with the run description when initialization ends and finished
//! at `fmi2Terminate`, or at `fmi2FreeInstance` / `fmi2Reset` when terminate did not.

use crate::scenario::ScenarioFile;
use fmi2_slave::Logger;
use std::path::{Path, PathBuf};
use towing_log::{LogError, LogOptions, LogWriter, RunInfo, SharedLog};
use towing_model::Scenario;

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

/// The `scenario` and `log_file` parameters of an FMU instance, the scenario they loaded
/// and the log they opened.
///
/// A clone (the FMU-state copies the layer keeps) shares the log: the log is the instance's
/// own, not part of the FMU state.
#[derive(Debug, Clone, Default)]
pub struct RunSession {
    scenario_parameter: String,
    log_file: String,
    resource_dir: Option<PathBuf>,
    loaded: Option<ScenarioFile>,
    log: SharedLog,
}

impl RunSession {
    /// A session of an instance whose resources folder is `resource_dir`: both parameters
    /// empty (the bundled scenario, no log), nothing loaded.
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
    /// description (`header`, the `scenario` parameter, the loaded scenario's name and text)
    /// and what `setup` writes (channels, messages at the start time), then hands the
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
        parameters.insert("scenario".into(), self.scenario_parameter.as_str().into());
        parameters.insert("log_file".into(), self.log_file.as_str().into());
        let info = RunInfo {
            unit: header.unit,
            guid: header.guid,
            version: header.version,
            scenario: &self.scenario_parameter,
            scenario_name: &loaded.scenario.name,
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
}
