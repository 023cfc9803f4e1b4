//! The run itself: analyzer version, scenario, architecture and scheme, what was read
//! (plant steps, control samples, the time span) and whether a log ended early. Fails
//! the verdict when a log was truncated (the metrics cover only what was read).

use serde::{Deserialize, Serialize};

use super::{StepFacts, FinishContext, Metric, Metrics, ReportPart, RunContext, Shared};
use crate::doc::Block;
use crate::error::Result;
use crate::step::PlantStep;
use crate::thresholds::Thresholds;
use crate::verdict::Reason;

/// A code with its name (architecture, scheme).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Code {
    /// The controller's code.
    pub code: i32,
    /// Its name (`distributed`, `centralized`; `I`, `II`, `III`).
    pub name: String,
}

/// Name of an architecture code.
#[must_use]
pub fn architecture_name(code: i32) -> String {
    match code {
        1 => "distributed".to_owned(),
        2 => "centralized".to_owned(),
        c => format!("architecture {c}"),
    }
}

/// Name of an avoidance-scheme code.
#[must_use]
pub fn scheme_name(code: i32) -> String {
    match code {
        1 => "I".to_owned(),
        2 => "II".to_owned(),
        3 => "III".to_owned(),
        c => format!("scheme {c}"),
    }
}

/// Truncated file and why.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Truncation {
    /// The file.
    pub file: String,
    /// The reader's reason.
    pub reason: String,
}

/// The run's section (top-level keys of `metrics.json`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunSection {
    /// Version of the analyzer.
    pub analyzer_version: String,
    /// Scenario name.
    pub scenario: String,
    /// Where the scenario came from.
    pub scenario_source: String,
    /// Control architecture (controller log).
    pub architecture: Option<Code>,
    /// Avoidance scheme (controller log).
    pub scheme: Option<Code>,
    /// True when any log ended early.
    pub truncated: bool,
    /// Which files ended early, and why.
    pub truncated_files: Vec<Truncation>,
    /// Notes on missing inputs.
    pub notes: Vec<String>,
    /// First plant time, s.
    pub start_s: f64,
    /// Last plant time, s.
    pub end_s: f64,
    /// Plant steps read.
    pub plant_steps: usize,
    /// Control samples read.
    pub control_samples: usize,
}

/// Counts the steps and their time span.
#[derive(Debug, Clone, Default)]
pub struct RunInfo {
    steps: usize,
    t_span: Option<(f64, f64)>,
}

impl Metric for RunInfo {
    type Section = RunSection;

    fn new(_run: &RunContext<'_>) -> Self {
        RunInfo::default()
    }

    fn step(&mut self, s: &PlantStep<'_>, _facts: &mut StepFacts) {
        self.steps += 1;
        self.t_span = Some(self.t_span.map_or((s.t, s.t), |(a, _)| (a, s.t)));
    }

    fn finish(self, ctx: &FinishContext<'_>, _shared: &Shared) -> Result<RunSection> {
        let config = ctx.config;
        let truncated_files: Vec<Truncation> = ctx
            .files
            .iter()
            .filter_map(|f| {
                f.truncated.as_ref().map(|r| Truncation {
                    file: f.path.display().to_string(),
                    reason: r.clone(),
                })
            })
            .collect();
        Ok(RunSection {
            analyzer_version: env!("CARGO_PKG_VERSION").to_owned(),
            scenario: config.scenario_name.clone(),
            scenario_source: config.scenario_source.clone(),
            architecture: config.architecture.map(|c| Code {
                code: c,
                name: architecture_name(c),
            }),
            scheme: config.scheme.map(|c| Code {
                code: c,
                name: scheme_name(c),
            }),
            truncated: !truncated_files.is_empty(),
            truncated_files,
            notes: ctx.notes.to_vec(),
            start_s: self.t_span.map_or(0.0, |s| s.0),
            end_s: self.t_span.map_or(0.0, |s| s.1),
            plant_steps: self.steps,
            control_samples: ctx.ctrl.controller_height(),
        })
    }

    fn report(m: &RunSection, all: &Metrics) -> ReportPart {
        let mut head = vec![Block::Heading(
            1,
            format!("Towing run: scenario {}", m.scenario),
        )];
        let arch = m.architecture.as_ref().map_or_else(
            || "unknown (no controller log)".to_owned(),
            |a| format!("{} ({})", a.name, a.code),
        );
        let scheme = m.scheme.as_ref().map_or_else(
            || "unknown".to_owned(),
            |s| format!("{} ({})", s.name, s.code),
        );
        for t in &m.truncated_files {
            head.push(Block::Para(format!(
                "WARNING: {} is truncated: {}. The report covers what was read ({:.1} s to {:.1} s).",
                t.file, t.reason, m.start_s, m.end_s
            )));
        }
        head.push(Block::List(vec![
            format!("architecture: {arch}; avoidance scheme: {scheme}"),
            format!("scenario: {} ({})", m.scenario, m.scenario_source),
            format!(
                "simulated {:.1} s to {:.1} s: {} plant steps, {} control samples",
                m.start_s, m.end_s, m.plant_steps, m.control_samples
            ),
            format!(
                "files: {}",
                all.files
                    .iter()
                    .map(|f| format!("{} ({}, {} bytes)", f.path.display(), f.unit, f.bytes))
                    .collect::<Vec<_>>()
                    .join("; ")
            ),
        ]));
        if !m.notes.is_empty() {
            head.push(Block::List(
                m.notes.iter().map(|n| format!("note: {n}")).collect(),
            ));
        }
        ReportPart {
            head,
            ..ReportPart::default()
        }
    }

    fn reasons(m: &RunSection, _thresholds: &Thresholds) -> Vec<Reason> {
        m.truncated_files
            .iter()
            .map(|t| {
                Reason::run(
                    "truncated",
                    Some(m.end_s),
                    format!(
                        "{} ended early ({}); the metrics cover what was read",
                        t.file, t.reason
                    ),
                )
            })
            .collect()
    }
}
