//! Drift angle: the angle between the ship's course over ground (the body velocity
//! rotated by the heading, [`crate::step::Vessel::vel_n`]) and its heading, while its speed
//! over ground is at least `under_way_speed_m_s` (below it the course over ground is
//! noise). A ship moving with `v = u` drifts 45 deg; one moving sideways, 90 deg.

use serde::{Deserialize, Serialize};

use super::{summary_row, FinishContext, Metric, Metrics, ReportPart, RunContext, Shared, StepFacts};
use crate::error::Result;

use crate::step::StepClock;
use crate::geometry::wrap;
use crate::step::{PlantStep, RunGeometry};
use crate::thresholds::Thresholds;
use crate::verdict::Reason;

/// The drift metric.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DriftReport {
    /// Largest drift angle under way, deg in `[0, 180]`; `None`: never under way.
    pub max_drift_deg: Option<f64>,
    /// Time of the largest drift angle, s.
    pub t_max_s: Option<f64>,
    /// Time under way with a drift angle above `drift_max_deg`, s.
    pub time_above_s: f64,
    /// Time under way, s.
    pub time_under_way_s: f64,
}

/// The drift tracker (O(1)).
#[derive(Debug, Clone)]
pub struct DriftTracker {
    th: Thresholds,
    clock: StepClock,
    max: Option<(f64, f64)>,
    time_above: f64,
    time_under_way: f64,
}

/// Drift angle of a velocity over ground `vel_n` against heading `psi`, deg in `[0, 180]`.
#[must_use]
pub fn drift_angle_deg(vel_n: [f64; 2], psi: f64) -> f64 {
    wrap(vel_n[1].atan2(vel_n[0]) - psi).abs().to_degrees()
}

impl DriftTracker {
    /// A tracker.
    #[must_use]
    pub fn new(_geometry: &RunGeometry, thresholds: &Thresholds) -> Self {
        DriftTracker {
            th: *thresholds,
            clock: StepClock::default(),
            max: None,
            time_above: 0.0,
            time_under_way: 0.0,
        }
    }

    /// The next step (its time since the previous step is counted by its state).
    pub fn push(&mut self, step: &PlantStep<'_>) {
        let dt = self.clock.dt(step.t);
        let ship = step.vessels[0];
        if ship.sog() < self.th.under_way_speed_m_s {
            return;
        }
        let drift = drift_angle_deg(ship.vel_n(), ship.psi);
        self.time_under_way += dt;
        if drift > self.th.drift_max_deg {
            self.time_above += dt;
        }
        if self.max.is_none_or(|(m, _)| drift > m) {
            self.max = Some((drift, step.t));
        }
    }

    /// The report.
    #[must_use]
    pub fn finish(self) -> DriftReport {
        DriftReport {
            max_drift_deg: self.max.map(|m| m.0),
            t_max_s: self.max.map(|m| m.1),
            time_above_s: self.time_above,
            time_under_way_s: self.time_under_way,
        }
    }
}

/// The verdict: the largest drift angle above `drift_max_deg`.
#[must_use]
pub fn reasons(report: &DriftReport, thresholds: &Thresholds) -> Vec<Reason> {
    match (report.max_drift_deg, report.t_max_s) {
        (Some(m), t) if m > thresholds.drift_max_deg => vec![Reason::run(
            "drift",
            t,
            format!(
                "drift angle {m:.1} deg above {} deg ({:.1} s above it)",
                thresholds.drift_max_deg, report.time_above_s
            ),
        )],
        _ => Vec::new(),
    }
}

impl Metric for DriftTracker {
    type Section = DriftReport;

    fn new(run: &RunContext<'_>) -> Self {
        DriftTracker::new(run.geometry, run.thresholds)
    }

    fn step(&mut self, s: &PlantStep<'_>, _facts: &mut StepFacts) {
        self.push(s);
    }

    fn finish(self, _ctx: &FinishContext<'_>, _shared: &Shared) -> Result<DriftReport> {
        Ok(DriftTracker::finish(self))
    }

    fn report(m: &DriftReport, all: &Metrics) -> ReportPart {
        let value = match (m.max_drift_deg, m.t_max_s) {
            (Some(d), Some(t)) => format!("{d:.1} deg at {t:.1} s; {:.1} s above {} deg", m.time_above_s, all.thresholds.drift_max_deg),
            _ => "never under way".to_owned(),
        };
        ReportPart {
            summary: vec![summary_row(
                "drift angle",
                value,
                "largest angle between the ship's course over ground and its heading while under way",
            )],
            ..ReportPart::default()
        }
    }

    fn reasons(m: &DriftReport, thresholds: &Thresholds) -> Vec<Reason> {
        reasons(m, thresholds)
    }
}
