//! One run: the plant log and the controller log put together, with the scenario and the
//! parameters the metrics need.
//!
//! [`load_run`] tells the logs apart from the records before their first message
//! ([`peek_log`]: the `run` metadata, the scenario attachment, the channels), reads every
//! log but the plant's whole (the controller log: about a tenth of the plant's messages;
//! only its topics are kept), and takes the scenario and the controller's parameters. The
//! plant log itself is streamed later, once, by [`crate::analysis::analyze_run`].

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use towing_log::topics::metadata_keys;
use towing_model::Scenario;

use crate::error::{AnalyzerError, Result};
use crate::read::{peek_log, read_into, ControllerData, LogFile, LogLine, Peek, Unit};

/// What was read from one file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FileSummary {
    /// The file.
    pub path: PathBuf,
    /// `plant`, `controller` or `plant and controller`.
    pub unit: String,
    /// File size, bytes.
    pub bytes: u64,
    /// Messages per topic.
    pub messages: std::collections::BTreeMap<String, u64>,
    /// Messages that did not decode, per topic: count and first error.
    pub decode_errors: std::collections::BTreeMap<String, (u64, String)>,
    /// Channels whose schema name differs from the contract.
    pub schema_mismatches: Vec<String>,
    /// Why the file ended early, if it did.
    pub truncated: Option<String>,
    /// The `run` metadata record.
    pub metadata: std::collections::BTreeMap<String, String>,
}

/// Limits the commands are checked against (Du et al. 2022, Table 2 and 3; the
/// controller's parameters when its log has them).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Bounds {
    /// Smallest tension, N.
    pub min_tension_n: f64,
    /// Largest tension `F_max`, N (Table 2: 3 N).
    pub max_tension_n: f64,
    /// Largest tension rate, N/s (Table 3: 0.3 N/s).
    pub tension_rate_n_per_s: f64,
    /// Largest towing angle `alpha_max`, rad (Table 2: 30 deg).
    pub max_towing_angle_rad: f64,
    /// Largest towing-angle rate, rad/s (Table 3: 5 deg/s).
    pub angle_rate_rad_per_s: f64,
    /// Tug thrust limits |X| N, |Y| N, |N| N m (Table 2: 10).
    pub max_thrust: [f64; 3],
}

impl Default for Bounds {
    fn default() -> Self {
        Bounds {
            min_tension_n: 0.0,
            max_tension_n: 3.0,
            tension_rate_n_per_s: 0.3,
            max_towing_angle_rad: 30f64.to_radians(),
            angle_rate_rad_per_s: 5f64.to_radians(),
            max_thrust: [10.0; 3],
        }
    }
}

/// Sizes and settings taken from the scenario and the controller's parameters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunConfig {
    /// Scenario name.
    pub scenario_name: String,
    /// Where the scenario came from.
    pub scenario_source: String,
    /// Ship length and width, m.
    pub ship_size: [f64; 2],
    /// Tug 1 (aft) length and width, m.
    pub tug1_size: [f64; 2],
    /// Tug 2 (forward) length and width, m.
    pub tug2_size: [f64; 2],
    /// Desired towline lengths `l_tow1`, `l_tow2`, m.
    pub towline_desired_length: [f64; 2],
    /// Destination pose: North m, East m, heading rad.
    pub destination: [f64; 3],
    /// Route points (origin, waypoints, destination): North m, East m, heading rad.
    pub route: Vec<[f64; 3]>,
    /// Detection distance `d_D` for target ships, m (controller parameter, default 7 m).
    pub detection_distance_m: f64,
    /// Safety buffer `d_S0`, m (controller parameter, default 0.25 m).
    pub safety_buffer_m: f64,
    /// Control sample time `T_s`, s.
    pub sample_time_s: f64,
    /// Command limits.
    pub bounds: Bounds,
    /// Architecture code from the controller log (1 distributed, 2 centralized).
    pub architecture: Option<i32>,
    /// Avoidance scheme code (1 I, 2 II, 3 III).
    pub scheme: Option<i32>,
    /// Waterway half width, m: the controller parameter `waterway_half_width` when it is
    /// nonzero, else the scenario's `[waterway] half_width` (`None`: neither). Not
    /// written to `metrics.json` (its `config` predates the field); the metrics see it as
    /// [`crate::step::RunGeometry::half_width`].
    #[serde(skip)]
    pub waterway_half_width: Option<f64>,
}

impl RunConfig {
    /// What every metric knows of the run before the first step.
    #[must_use]
    pub fn geometry(&self) -> crate::step::RunGeometry {
        crate::step::RunGeometry {
            sizes: [self.ship_size, self.tug1_size, self.tug2_size],
            route: self.route.clone(),
            half_width: self.waterway_half_width,
            detection_distance: self.detection_distance_m,
        }
    }
}

/// A run ready for analysis: the controller's data and the settings; the plant log is
/// streamed by the analysis.
#[derive(Debug, Clone)]
pub struct Run {
    /// The files read, in the order given (the plant log's entry is completed by the
    /// analysis), then the files left out.
    pub files: Vec<FileSummary>,
    /// The plant log.
    pub plant_path: PathBuf,
    /// Index of the plant log in `files`.
    pub plant_file: usize,
    /// Controller topics (empty when no controller log was given).
    pub controller: ControllerData,
    /// Warnings and errors logged by the units (the plant log's are added by the
    /// analysis).
    pub logs: Vec<LogLine>,
    /// Sizes and settings.
    pub config: RunConfig,
    /// Notes for the report (missing controller log, default scenario, ...).
    pub notes: Vec<String>,
    /// The logs given.
    paths: Vec<PathBuf>,
    /// The plant log was read whole too (it holds controller topics, or was re-read).
    plant_read_whole: bool,
    /// The scenario came from the plant log.
    plant_scenario: bool,
    /// Index in `paths` of the controller log, if any.
    controller_path: Option<usize>,
}

impl Run {
    /// True when any file ended early (so far: the plant log's end is known after the
    /// analysis).
    pub fn truncated(&self) -> bool {
        self.files.iter().any(|f| f.truncated.is_some())
    }

    /// The controller log, when it is not the plant log itself (a merged log).
    #[must_use]
    pub fn controller_log(&self) -> Option<&Path> {
        self.controller_path
            .map(|k| self.paths[k].as_path())
            .filter(|p| *p != self.plant_path)
    }

    /// The files, comma separated (for messages).
    #[must_use]
    pub fn file_list(&self) -> String {
        self.paths
            .iter()
            .map(|p| p.display().to_string())
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// Whether the streamed plant log `log` showed what its first records did not: controller
    /// messages or the scenario attachment after its first message. Then the run must be
    /// loaded again with the plant log read whole ([`Run::reload`]).
    ///
    /// # Errors
    /// The plant log holds controller messages and another log is the controller's.
    pub fn needs_whole_read(&self, log: &LogFile) -> Result<bool> {
        if self.plant_read_whole {
            return Ok(false);
        }
        if log.has_controller() {
            if let Some(k) = self.controller_path {
                return Err(AnalyzerError::DuplicateUnit {
                    unit: "controller",
                    first: self.paths[k].clone(),
                    second: self.plant_path.clone(),
                });
            }
            return Ok(true);
        }
        Ok(log.scenario_text.is_some() && !self.plant_scenario)
    }

    /// The run loaded again with the plant log read whole first.
    ///
    /// # Errors
    /// As [`load_run`].
    pub fn reload(&self, progress: &indicatif::MultiProgress) -> Result<Run> {
        load(&self.paths, progress, Some(&self.plant_path))
    }

    /// The files (the plant log's summary from its streamed read), the notes and the units'
    /// log levels, once the plant log `log` has been streamed.
    #[must_use]
    pub fn complete(self, log: LogFile) -> (Vec<FileSummary>, Vec<String>, Vec<i32>) {
        let mut files = self.files;
        files[self.plant_file] = summarize(&log);
        let mut logs = self.logs;
        logs.extend(log.logs);
        logs.sort_by_key(|l| l.t_ns);
        let mut notes = self.notes;
        if log.decoded.out_of_order > 0 {
            notes.push(format!(
                "{}: {} messages are older than the message before them; the log is \
                 streamed in batches, so an as-of join across a batch boundary may differ \
                 from a whole-log sort",
                log.path.display(),
                log.decoded.out_of_order
            ));
        }
        (files, notes, logs.iter().map(|l| l.level).collect())
    }
}

/// Reads the logs of one run (any order) and puts them together; the plant log is only
/// peeked at (it is streamed by the analysis).
///
/// # Errors
/// Any file that cannot be used (see [`crate::read::read_log`]), two logs of the same
/// unit, no plant log, or an attached scenario that does not parse.
pub fn load_run(paths: &[PathBuf], progress: &indicatif::MultiProgress) -> Result<Run> {
    load(paths, progress, None)
}

/// [`load_run`]; `plant_whole`: the plant log, to be read whole too.
fn load(
    paths: &[PathBuf],
    progress: &indicatif::MultiProgress,
    plant_whole: Option<&Path>,
) -> Result<Run> {
    if paths.is_empty() {
        return Err(AnalyzerError::Usage(
            "no log given: analyzer report --out DIR PLANT.mcap CONTROLLER.mcap".to_owned(),
        ));
    }
    let peeks = paths
        .iter()
        .map(|p| peek_log(p))
        .collect::<Result<Vec<Peek>>>()?;
    crate::same_run::check_run_ids(&peeks)?;
    // The plant log: peeked as one (or as both units).
    let peeked_plant = peeks.iter().enumerate().filter_map(|(k, peek)| {
        let is_plant = matches!(peek.unit, Some(Unit::Plant | Unit::Both))
            || plant_whole == Some(peek.path.as_path());
        is_plant.then_some(k)
    });
    let plant = sole_log("plant", paths, None, peeked_plant)?;
    let (logs, empty) = read_whole(paths, &peeks, plant, plant_whole, progress)?;
    // A log read whole may hold the plant's states where its first records did not say.
    let read_plant = logs
        .iter()
        .filter(|(k, log)| log.has_plant() && plant != Some(*k))
        .map(|(k, _)| *k);
    let Some(plant) = sole_log("plant", paths, plant, read_plant)? else {
        return Err(no_plant_log(&logs, &empty));
    };
    let read_controller = logs
        .iter()
        .filter(|(_, log)| log.has_controller())
        .map(|(k, _)| *k);
    let controller_path = sole_log("controller", paths, None, read_controller)?;
    let plant_read_whole = logs.iter().any(|(k, _)| *k == plant);

    // The scenario: the plant log's (as peeked, or read whole), else the controller's.
    let mut notes = Vec::new();
    let plant_text = logs
        .iter()
        .find(|(k, _)| *k == plant)
        .and_then(|(_, l)| l.scenario_text.as_deref())
        .or(peeks[plant].scenario_text.as_deref());
    let controller_log = controller_path.and_then(|c| logs.iter().find(|(k, _)| *k == c));
    let mut sources = vec![(paths[plant].as_path(), plant_text)];
    if let Some((_, l)) = controller_log {
        sources.push((l.path.as_path(), l.scenario_text.as_deref()));
    }
    let (scenario, scenario_source) = scenario_of(&sources, &mut notes)?;
    let plant_scenario = plant_text.is_some();
    let params = controller_log
        .and_then(|(_, l)| l.metadata.get(metadata_keys::PARAMETERS))
        .and_then(|p| serde_json::from_str::<serde_json::Value>(p).ok());
    if controller_path.is_none() {
        notes.push(
            "no controller log: COLREGS situations, commands, solver statistics and bound \
             checks of the commands are missing"
                .to_owned(),
        );
    }

    let (mut files, plant_file) = file_summaries(paths, &peeks, &logs, plant);
    let (controller, unit_logs) = take_controller(logs, controller_path, plant);
    let config = run_config(&scenario, scenario_source, params.as_ref(), &controller);
    for (path, reason) in empty {
        notes.push(format!(
            "{} is truncated before any usable message and was left out",
            path.display()
        ));
        files.push(left_out_summary(path, reason));
    }
    Ok(Run {
        files,
        plant_path: paths[plant].clone(),
        plant_file,
        controller,
        logs: unit_logs,
        config,
        notes,
        paths: paths.to_vec(),
        plant_read_whole,
        plant_scenario,
        controller_path,
    })
}

/// The one log (index into `paths`) of `unit`: `found` (already known, if any), else the
/// first of `candidates` (indices into `paths`, in order).
///
/// # Errors
/// [`AnalyzerError::DuplicateUnit`] naming the first two logs of the unit.
fn sole_log(
    unit: &'static str,
    paths: &[PathBuf],
    mut found: Option<usize>,
    candidates: impl IntoIterator<Item = usize>,
) -> Result<Option<usize>> {
    for k in candidates {
        if let Some(first) = found {
            return Err(AnalyzerError::DuplicateUnit {
                unit,
                first: paths[first].clone(),
                second: paths[k].clone(),
            });
        }
        found = Some(k);
    }
    Ok(found)
}

/// Logs read whole, each with its index into the paths given.
type ReadLogs = Vec<(usize, LogFile)>;

/// Logs cut before their first message: the path and where it ends.
type LeftOut = Vec<(PathBuf, String)>;

/// Reads every log but the plant log (`plant`, as peeked) whole, keeping the controller's
/// topics; the plant log too when it is a merged log or `plant_whole`. Also returns the
/// other logs cut before their first message (path, reason): the others may still make a
/// report.
///
/// # Errors
/// A log that cannot be read (the plant log cut before its first message included).
fn read_whole(
    paths: &[PathBuf],
    peeks: &[Peek],
    plant: Option<usize>,
    plant_whole: Option<&Path>,
    progress: &indicatif::MultiProgress,
) -> Result<(ReadLogs, LeftOut)> {
    let mut logs: ReadLogs = Vec::new();
    let mut empty = Vec::new();
    for (k, path) in paths.iter().enumerate() {
        let whole = plant != Some(k)
            || peeks[k].unit == Some(Unit::Both)
            || plant_whole == Some(path.as_path());
        if !whole {
            continue;
        }
        let bar = progress.add(crate::progress::bytes_bar(path));
        let mut controller = ControllerData::default();
        let log = read_into(path, &bar, &mut controller);
        bar.finish_and_clear();
        match log {
            Ok(mut log) => {
                log.controller = controller;
                logs.push((k, log));
            }
            // A log cut before its first message: the others may still make a report.
            Err(AnalyzerError::TruncatedEmpty { path, reason }) if plant != Some(k) => {
                empty.push((path, reason));
            }
            Err(e) => return Err(e),
        }
    }
    Ok((logs, empty))
}

/// The error when no log holds the plant's states: the first log cut before its first
/// message, else [`AnalyzerError::NoPlantLog`] listing the logs read.
fn no_plant_log(logs: &[(usize, LogFile)], empty: &[(PathBuf, String)]) -> AnalyzerError {
    if let Some((path, reason)) = empty.first() {
        return AnalyzerError::TruncatedEmpty {
            path: path.clone(),
            reason: reason.clone(),
        };
    }
    let files = logs
        .iter()
        .map(|(_, l)| l.path.display().to_string())
        .collect::<Vec<_>>()
        .join(", ");
    AnalyzerError::NoPlantLog { files }
}

/// The files read, in the order given, and the index of the plant log's entry among them
/// (from its peek; replaced after its stream).
fn file_summaries(
    paths: &[PathBuf],
    peeks: &[Peek],
    logs: &[(usize, LogFile)],
    plant: usize,
) -> (Vec<FileSummary>, usize) {
    let mut files = Vec::new();
    let mut plant_file = 0;
    for k in 0..paths.len() {
        if k == plant {
            plant_file = files.len();
            files.push(FileSummary {
                path: paths[k].clone(),
                unit: Unit::Plant.name().to_owned(),
                bytes: peeks[k].bytes,
                messages: std::collections::BTreeMap::new(),
                decode_errors: std::collections::BTreeMap::new(),
                schema_mismatches: Vec::new(),
                truncated: None,
                metadata: peeks[k].metadata.clone(),
            });
        } else if let Some((_, log)) = logs.iter().find(|(j, _)| *j == k) {
            files.push(summarize(log));
        }
    }
    (files, plant_file)
}

/// The controller log's topics (empty without one) and the unit logs of the logs read
/// whole but the plant log (its unit logs come with its stream).
fn take_controller(
    logs: Vec<(usize, LogFile)>,
    controller_path: Option<usize>,
    plant: usize,
) -> (ControllerData, Vec<LogLine>) {
    let mut controller = ControllerData::default();
    let mut unit_logs = Vec::new();
    for (k, log) in logs {
        if Some(k) == controller_path {
            controller = log.controller;
        }
        if k != plant {
            unit_logs.extend(log.logs);
        }
    }
    (controller, unit_logs)
}

/// The entry of a log left out because it is cut before its first message (`reason`).
fn left_out_summary(path: PathBuf, reason: String) -> FileSummary {
    FileSummary {
        path,
        unit: "unknown (truncated)".to_owned(),
        bytes: 0,
        messages: std::collections::BTreeMap::new(),
        decode_errors: std::collections::BTreeMap::new(),
        schema_mismatches: Vec::new(),
        truncated: Some(reason),
        metadata: std::collections::BTreeMap::new(),
    }
}

fn median_step_s(t_ns: &[i64]) -> Option<f64> {
    let mut d: Vec<i64> = t_ns.windows(2).map(|w| w[1] - w[0]).collect();
    if d.is_empty() {
        return None;
    }
    d.sort_unstable();
    Some(d[d.len() / 2] as f64 * 1e-9)
}

/// The run's sizes and settings: the scenario's, with the controller's parameters
/// (`params`, the log's `parameters` metadata) and solver reports where they say more.
fn run_config(
    scenario: &Scenario,
    scenario_source: String,
    params: Option<&serde_json::Value>,
    controller: &ControllerData,
) -> RunConfig {
    // A parameter by its registry name (docs/interface.md), else by the name it had
    // before the registry (logs of earlier versions); Booleans read as 0 / 1.
    let param = |name: &str, old: &str| -> Option<f64> {
        let p = params?;
        let v = p.get(name).or_else(|| p.get(old))?;
        v.as_f64()
            .or_else(|| v.as_bool().map(f64::from))
            .or_else(|| v.as_str()?.trim().parse().ok())
    };
    let defaults = Bounds::default();
    let bounds = Bounds {
        min_tension_n: 0.0,
        max_tension_n: param("mpc.ship.max_tension", "max_tension")
            .unwrap_or(defaults.max_tension_n),
        tension_rate_n_per_s: param("mpc.ship.tension_rate", "tension_rate")
            .unwrap_or(defaults.tension_rate_n_per_s),
        max_towing_angle_rad: param("mpc.ship.max_towing_angle", "max_towing_angle")
            .unwrap_or(defaults.max_towing_angle_rad),
        angle_rate_rad_per_s: param("mpc.ship.towing_angle_rate", "angle_rate")
            .unwrap_or(defaults.angle_rate_rad_per_s),
        max_thrust: [
            param("mpc.tug.max_force_surge", "max_thrust_surge").unwrap_or(defaults.max_thrust[0]),
            param("mpc.tug.max_force_sway", "max_thrust_sway").unwrap_or(defaults.max_thrust[1]),
            param("mpc.tug.max_moment_yaw", "max_yaw_moment").unwrap_or(defaults.max_thrust[2]),
        ],
    };
    let solver = &controller.solver;
    let architecture = solver
        .architecture
        .last()
        .copied()
        .or_else(|| param("architecture", "architecture").map(|v| v as i32));
    let scheme = solver
        .scheme
        .last()
        .copied()
        .or_else(|| param("avoidance_scheme", "avoidance_scheme").map(|v| v as i32));
    let sample_time_s = param("mpc.sample_time", "sample_time")
        .or_else(|| median_step_s(&controller.solver.t_ns))
        .unwrap_or(1.0);

    let pose = |p: &towing_model::scenario::Pose| [p.x, p.y, p.psi];
    let config = RunConfig {
        scenario_name: scenario.name.clone(),
        scenario_source,
        ship_size: [scenario.ship_data.length, scenario.ship_data.width],
        tug1_size: [scenario.tug_data[0].length, scenario.tug_data[0].width],
        tug2_size: [scenario.tug_data[1].length, scenario.tug_data[1].width],
        towline_desired_length: scenario.towline_desired_length,
        destination: pose(&scenario.route.destination),
        route: scenario.route.points().map(pose).collect(),
        detection_distance_m: param("guidance.detection_distance", "detection_distance")
            .unwrap_or(7.0),
        safety_buffer_m: param("guidance.safety_buffer", "safety_buffer").unwrap_or(0.25),
        sample_time_s,
        bounds,
        architecture,
        scheme,
        waterway_half_width: if param("waterway.from_scenario", "").is_some_and(|v| v == 0.0) {
            param("waterway.half_width", "")
        } else {
            param("", "waterway_half_width").filter(|w| *w > 0.0)
        }
        .or_else(|| scenario.waterway.as_ref().map(|w| w.half_width)),
    };
    config
}

/// The scenario attached to the plant log, else the controller's (`sources`: each log
/// and its attachment's text, in that order), else the bundled paper scenario (with a
/// note).
fn scenario_of(
    sources: &[(&Path, Option<&str>)],
    notes: &mut Vec<String>,
) -> Result<(Scenario, String)> {
    for (path, text) in sources {
        if let Some(text) = text {
            let origin = format!("{} (attachment scenario.toml)", path.display());
            let scenario =
                Scenario::from_toml_str(text, &origin).map_err(|e| AnalyzerError::Scenario {
                    path: path.to_path_buf(),
                    reason: e.to_string(),
                })?;
            return Ok((scenario, origin));
        }
    }
    notes.push(
        "no scenario attachment in the logs: vessel sizes, route and destination are the \
         bundled paper scenario's"
            .to_owned(),
    );
    let scenario = Scenario::paper().map_err(|e| AnalyzerError::Scenario {
        path: Path::new("scenarios/paper.toml").to_owned(),
        reason: e.to_string(),
    })?;
    Ok((
        scenario,
        "bundled paper scenario (no attachment)".to_owned(),
    ))
}

fn summarize(log: &LogFile) -> FileSummary {
    FileSummary {
        path: log.path.clone(),
        unit: log.unit.name().to_owned(),
        bytes: log.bytes,
        messages: log.message_counts.clone(),
        decode_errors: log
            .decode_errors
            .iter()
            .map(|(k, v)| (k.clone(), (v.count, v.first.clone())))
            .collect(),
        schema_mismatches: log.schema_mismatches.clone(),
        truncated: log.truncated.clone(),
        metadata: log.metadata.clone(),
    }
}
