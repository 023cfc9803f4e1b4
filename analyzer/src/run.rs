//! One run: the plant log and the controller log put together, with the scenario and the
//! parameters the metrics need.

use std::path::{Path, PathBuf};

use serde::Serialize;
use towing_log::topics::metadata_keys;
use towing_model::Scenario;

use crate::error::{AnalyzerError, Result};
use crate::read::{read_log, ControllerData, LogFile, LogLine, PlantData};

/// What was read from one file.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FileSummary {
    /// The file.
    pub path: PathBuf,
    /// `plant`, `controller` or `plant and controller`.
    pub unit: &'static str,
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
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
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
#[derive(Debug, Clone, PartialEq, Serialize)]
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
}

/// A run ready for analysis.
#[derive(Debug, Clone)]
pub struct Run {
    /// The files read.
    pub files: Vec<FileSummary>,
    /// Plant topics.
    pub plant: PlantData,
    /// Controller topics (empty when no controller log was given).
    pub controller: ControllerData,
    /// Warnings and errors logged by the units.
    pub logs: Vec<LogLine>,
    /// Sizes and settings.
    pub config: RunConfig,
    /// Notes for the report (missing controller log, default scenario, ...).
    pub notes: Vec<String>,
}

impl Run {
    /// True when any file ended early.
    pub fn truncated(&self) -> bool {
        self.files.iter().any(|f| f.truncated.is_some())
    }
}

/// Reads the logs of one run (any order) and puts them together.
///
/// # Errors
/// Any file that cannot be used (see [`read_log`]), two logs of the same unit, no plant
/// log, or an attached scenario that does not parse.
pub fn load_run(paths: &[PathBuf], progress: &indicatif::MultiProgress) -> Result<Run> {
    if paths.is_empty() {
        return Err(AnalyzerError::Usage(
            "no log given: analyzer report --out DIR PLANT.mcap CONTROLLER.mcap".to_owned(),
        ));
    }
    let mut logs = Vec::with_capacity(paths.len());
    let mut empty = Vec::new();
    for path in paths {
        let bar = progress.add(crate::progress::bytes_bar(path));
        let log = read_log(path, &bar);
        bar.finish_and_clear();
        match log {
            Ok(log) => logs.push(log),
            // A log cut before its first message: the others may still make a report.
            Err(AnalyzerError::TruncatedEmpty { path, reason }) => empty.push((path, reason)),
            Err(e) => return Err(e),
        }
    }
    if logs.is_empty() || !logs.iter().any(LogFile::has_plant) {
        if let Some((path, reason)) = empty.first() {
            return Err(AnalyzerError::TruncatedEmpty {
                path: path.clone(),
                reason: reason.clone(),
            });
        }
    }
    let mut run = assemble(logs)?;
    for (path, reason) in empty {
        run.notes.push(format!(
            "{} is truncated before any usable message and was left out",
            path.display()
        ));
        run.files.push(FileSummary {
            path,
            unit: "unknown (truncated)",
            bytes: 0,
            messages: std::collections::BTreeMap::new(),
            decode_errors: std::collections::BTreeMap::new(),
            schema_mismatches: Vec::new(),
            truncated: Some(reason),
            metadata: std::collections::BTreeMap::new(),
        });
    }
    Ok(run)
}

/// Puts logs already read together (see [`load_run`]).
///
/// # Errors
/// Two logs of the same unit, no plant log, or an attached scenario that does not parse.
pub fn assemble(logs: Vec<LogFile>) -> Result<Run> {
    let mut plant_file: Option<usize> = None;
    let mut controller_file: Option<usize> = None;
    for (k, log) in logs.iter().enumerate() {
        if log.has_plant() {
            if let Some(first) = plant_file {
                return Err(AnalyzerError::DuplicateUnit {
                    unit: "plant",
                    first: logs[first].path.clone(),
                    second: log.path.clone(),
                });
            }
            plant_file = Some(k);
        }
        if log.has_controller() {
            if let Some(first) = controller_file {
                return Err(AnalyzerError::DuplicateUnit {
                    unit: "controller",
                    first: logs[first].path.clone(),
                    second: log.path.clone(),
                });
            }
            controller_file = Some(k);
        }
    }
    let files_list = logs
        .iter()
        .map(|l| l.path.display().to_string())
        .collect::<Vec<_>>()
        .join(", ");
    let Some(plant_idx) = plant_file else {
        return Err(AnalyzerError::NoPlantLog { files: files_list });
    };

    let mut notes = Vec::new();
    let (scenario, scenario_source) = scenario_of(&logs, plant_idx, controller_file, &mut notes)?;
    let params = controller_file
        .and_then(|k| logs[k].metadata.get(metadata_keys::PARAMETERS))
        .and_then(|p| serde_json::from_str::<serde_json::Value>(p).ok());
    if controller_file.is_none() {
        notes.push(
            "no controller log: COLREGS situations, commands, solver statistics and bound \
             checks of the commands are missing"
                .to_owned(),
        );
    }

    let files = logs.iter().map(summarize).collect();
    let mut plant = PlantData::default();
    let mut controller = ControllerData::default();
    let mut unit_logs = Vec::new();
    for (k, log) in logs.into_iter().enumerate() {
        unit_logs.extend(log.logs);
        if k == plant_idx {
            plant = log.plant;
        }
        if Some(k) == controller_file {
            controller = log.controller;
        }
    }
    unit_logs.sort_by_key(|l| l.t_ns);

    let param = |name: &str| -> Option<f64> {
        let v = params.as_ref()?.get(name)?;
        v.as_f64().or_else(|| v.as_str()?.trim().parse().ok())
    };
    let defaults = Bounds::default();
    let bounds = Bounds {
        min_tension_n: 0.0,
        max_tension_n: param("max_tension").unwrap_or(defaults.max_tension_n),
        tension_rate_n_per_s: param("tension_rate").unwrap_or(defaults.tension_rate_n_per_s),
        max_towing_angle_rad: param("max_towing_angle").unwrap_or(defaults.max_towing_angle_rad),
        angle_rate_rad_per_s: param("angle_rate").unwrap_or(defaults.angle_rate_rad_per_s),
        max_thrust: [
            param("max_thrust_surge").unwrap_or(defaults.max_thrust[0]),
            param("max_thrust_sway").unwrap_or(defaults.max_thrust[1]),
            param("max_yaw_moment").unwrap_or(defaults.max_thrust[2]),
        ],
    };
    let solver = &controller.solver;
    let architecture = solver
        .architecture
        .last()
        .copied()
        .or_else(|| param("architecture").map(|v| v as i32));
    let scheme = solver
        .scheme
        .last()
        .copied()
        .or_else(|| param("avoidance_scheme").map(|v| v as i32));
    let sample_time_s = param("sample_time")
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
        detection_distance_m: param("detection_distance").unwrap_or(7.0),
        safety_buffer_m: param("safety_buffer").unwrap_or(0.25),
        sample_time_s,
        bounds,
        architecture,
        scheme,
    };
    Ok(Run {
        files,
        plant,
        controller,
        logs: unit_logs,
        config,
        notes,
    })
}

fn median_step_s(t_ns: &[i64]) -> Option<f64> {
    let mut d: Vec<i64> = t_ns.windows(2).map(|w| w[1] - w[0]).collect();
    if d.is_empty() {
        return None;
    }
    d.sort_unstable();
    Some(d[d.len() / 2] as f64 * 1e-9)
}

/// The scenario attached to the plant log, else the controller's, else the bundled paper
/// scenario (with a note).
fn scenario_of(
    logs: &[LogFile],
    plant: usize,
    controller: Option<usize>,
    notes: &mut Vec<String>,
) -> Result<(Scenario, String)> {
    for k in std::iter::once(plant).chain(controller) {
        let log = &logs[k];
        if let Some(text) = &log.scenario_text {
            let origin = format!("{} (attachment scenario.toml)", log.path.display());
            let scenario =
                Scenario::from_toml_str(text, &origin).map_err(|e| AnalyzerError::Scenario {
                    path: log.path.clone(),
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
        unit: log.unit.name(),
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
