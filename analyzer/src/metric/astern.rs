//! Going astern: the ship's most negative surge speed and the time it spends moving
//! astern (surge below [`ASTERN_SURGE_M_S`], a dead band for the plant's numerical noise
//! about zero).

use serde::{Deserialize, Serialize};

use super::{summary_row, FinishContext, Metric, Metrics, ReportPart, RunContext, Shared, StepFacts};
use crate::error::Result;

use crate::step::StepClock;
use crate::step::{PlantStep, RunGeometry};
use crate::thresholds::Thresholds;
use crate::verdict::Reason;

/// The ship counts as moving astern below this surge speed, m/s.
pub const ASTERN_SURGE_M_S: f64 = -0.005;

/// The astern metric.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AsternReport {
    /// Most negative surge speed of the ship, m/s (`None`: no step).
    pub min_surge_m_s: Option<f64>,
    /// Its time, s.
    pub t_min_s: Option<f64>,
    /// Time with surge below -0.005 m/s, s.
    pub time_astern_s: f64,
}

/// The astern tracker (O(1)).
#[derive(Debug, Clone)]
pub struct AsternTracker {
    clock: StepClock,
    min: Option<(f64, f64)>,
    time_astern: f64,
}

impl AsternTracker {
    /// A tracker.
    #[must_use]
    pub fn new(_geometry: &RunGeometry, _thresholds: &Thresholds) -> Self {
        AsternTracker {
            clock: StepClock::default(),
            min: None,
            time_astern: 0.0,
        }
    }

    /// The next step.
    pub fn push(&mut self, step: &PlantStep<'_>) {
        let dt = self.clock.dt(step.t);
        let u = step.vessels[0].u;
        if u < ASTERN_SURGE_M_S {
            self.time_astern += dt;
        }
        if self.min.is_none_or(|(m, _)| u < m) {
            self.min = Some((u, step.t));
        }
    }

    /// The report.
    #[must_use]
    pub fn finish(self) -> AsternReport {
        AsternReport {
            min_surge_m_s: self.min.map(|m| m.0),
            t_min_s: self.min.map(|m| m.1),
            time_astern_s: self.time_astern,
        }
    }
}

/// The verdict: astern faster than `astern_max_m_s`.
#[must_use]
pub fn reasons(report: &AsternReport, thresholds: &Thresholds) -> Vec<Reason> {
    match report.min_surge_m_s {
        Some(u) if -u > thresholds.astern_max_m_s => vec![Reason::run(
            "astern",
            report.t_min_s,
            format!(
                "surge {u:.3} m/s: astern faster than {} m/s ({:.1} s astern)",
                thresholds.astern_max_m_s, report.time_astern_s
            ),
        )],
        _ => Vec::new(),
    }
}

impl Metric for AsternTracker {
    type Section = AsternReport;

    fn new(run: &RunContext<'_>) -> Self {
        AsternTracker::new(run.geometry, run.thresholds)
    }

    fn step(&mut self, s: &PlantStep<'_>, _facts: &mut StepFacts) {
        self.push(s);
    }

    fn finish(self, _ctx: &FinishContext<'_>, _shared: &Shared) -> Result<AsternReport> {
        Ok(AsternTracker::finish(self))
    }

    fn report(m: &AsternReport, _all: &Metrics) -> ReportPart {
        let value = match (m.min_surge_m_s, m.t_min_s) {
            (Some(u), Some(t)) => format!("{u:.3} m/s at {t:.1} s; {:.1} s astern", m.time_astern_s),
            _ => "-".to_owned(),
        };
        ReportPart {
            summary: vec![summary_row(
                "surge astern",
                value,
                "the ship's most negative surge speed, and the time it moved astern",
            )],
            ..ReportPart::default()
        }
    }

    fn reasons(m: &AsternReport, thresholds: &Thresholds) -> Vec<Reason> {
        reasons(m, thresholds)
    }
}
