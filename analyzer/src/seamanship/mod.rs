//! Seamanship and rule verdicts (issue 12, section 2; docs/analyzer.md, "Seamanship and
//! rule verdicts"): six pure trackers fed one [`PlantStep`] at a time, each with a plain
//! report and its verdict part (`reasons`), thresholds from [`Thresholds`].
//!
//! Every tracker has the same shape: `new(&RunGeometry, &Thresholds)`, `push(&PlantStep)`,
//! `finish() -> Report`, and a free `reasons(&Report, &Thresholds) -> Vec<Reason>`. They are
//! independent but for one explicit hand-off: [`ProgressTracker::push`] takes whether a
//! give-way encounter is open at the step, [`RulesTracker::give_way_open`] after the rules
//! tracker has seen the same step. [`Seamanship`] owns all six and does that wiring.
//!
//! Time: a plant step's `t` is the end of the step, so each step stands for the interval
//! since the previous step (the first step for none): a condition holding at the steps
//! with `t` in `(a, b]` on a regular grid lasts `b - a`.

pub mod astern;
pub mod drift;
pub mod geometry;
pub mod progress;
pub mod rules;
pub mod speed;
pub mod waterway;

use serde::{Deserialize, Serialize};

pub use astern::{AsternReport, AsternTracker};
pub use drift::{DriftReport, DriftTracker};
pub use progress::{ProgressReport, ProgressTracker};
pub use rules::{RulesReport, RulesTracker};
pub use speed::{SpeedReport, SpeedTracker};
pub use waterway::{WaterwayReport, WaterwayTracker};

use crate::step::{PlantStep, RunGeometry};
use crate::thresholds::Thresholds;
use crate::verdict::Reason;

/// Names of the vessels in [`PlantStep::vessels`] order.
pub const VESSEL_NAMES: [&str; 3] = ["ship", "tug1", "tug2"];

/// The time a step stands for: since the previous step (0 for the first step, and for a
/// step not after the previous one).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct StepClock {
    prev: Option<f64>,
}

impl StepClock {
    /// The time since the previous call's `t`, s.
    pub fn dt(&mut self, t: f64) -> f64 {
        let dt = self.prev.map_or(0.0, |p| (t - p).max(0.0));
        self.prev = Some(t);
        if dt.is_finite() {
            dt
        } else {
            0.0
        }
    }
}

/// All six metrics of a run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SeamanshipReport {
    /// Progress along the route, time to destination.
    pub progress: ProgressReport,
    /// Drift angle.
    pub drift: DriftReport,
    /// Speed over ground against cruise.
    pub speed: SpeedReport,
    /// Going astern.
    pub astern: AsternReport,
    /// Hulls beyond the waterway's half width.
    pub waterway: WaterwayReport,
    /// COLREGS checks per target ship.
    pub rules: RulesReport,
}

/// The six trackers of a run, fed together.
#[derive(Debug, Clone)]
pub struct Seamanship {
    progress: ProgressTracker,
    drift: DriftTracker,
    speed: SpeedTracker,
    astern: AsternTracker,
    waterway: WaterwayTracker,
    rules: RulesTracker,
}

impl Seamanship {
    /// The trackers of a run.
    #[must_use]
    pub fn new(geometry: &RunGeometry, thresholds: &Thresholds) -> Self {
        Seamanship {
            progress: ProgressTracker::new(geometry, thresholds),
            drift: DriftTracker::new(geometry, thresholds),
            speed: SpeedTracker::new(geometry, thresholds),
            astern: AsternTracker::new(geometry, thresholds),
            waterway: WaterwayTracker::new(geometry, thresholds),
            rules: RulesTracker::new(geometry, thresholds),
        }
    }

    /// The next step, to every tracker (the rules first: progress takes their give-way
    /// state at this step).
    pub fn push(&mut self, step: &PlantStep<'_>) {
        self.rules.push(step);
        self.progress.push(step, self.rules.give_way_open());
        self.drift.push(step);
        self.speed.push(step);
        self.astern.push(step);
        self.waterway.push(step);
    }

    /// The reports.
    #[must_use]
    pub fn finish(self) -> SeamanshipReport {
        SeamanshipReport {
            progress: self.progress.finish(),
            drift: self.drift.finish(),
            speed: self.speed.finish(),
            astern: self.astern.finish(),
            waterway: self.waterway.finish(),
            rules: self.rules.finish(),
        }
    }
}

/// Every reason of the six metrics: progress, drift, speed, astern, waterway, rules; each
/// metric's by time (reasons without a time last).
#[must_use]
pub fn reasons(report: &SeamanshipReport, thresholds: &Thresholds) -> Vec<Reason> {
    let mut out = Vec::new();
    for mut part in [
        progress::reasons(&report.progress, thresholds),
        drift::reasons(&report.drift, thresholds),
        speed::reasons(&report.speed, thresholds),
        astern::reasons(&report.astern, thresholds),
        waterway::reasons(&report.waterway, thresholds),
        rules::reasons(&report.rules, thresholds),
    ] {
        part.sort_by(|a, b| {
            a.t_s
                .unwrap_or(f64::INFINITY)
                .total_cmp(&b.t_s.unwrap_or(f64::INFINITY))
        });
        out.append(&mut part);
    }
    out
}
