//! Waterway: how far the hulls of the three vessels go beyond the scenario's half width.
//!
//! For every hull corner (the footprint [`HullRect`]: length x width centred at the body
//! origin, oriented by the heading) of the ship and the two tugs, the distance from the
//! route polyline (nearest point of any segment) minus the half width is its excess
//! ([`Lane::hull_excess`]: the plant's own judgement, `World::bank_excess`, which sets its
//! `aground.*` outputs and logs a grounding event). A vessel with a corner beyond
//! `half_width + waterway_tolerance_m` is aground: a grounding event is a maximal run of
//! consecutive steps with that vessel aground (as the hull-overlap events of the
//! `collisions` metric), counted per vessel, and any grounding fails the run. With the
//! default tolerance 0 the events are the plant's grounding episodes. Without a
//! `[waterway]` (or a route) the metric reports "no waterway" and never gives a reason.

use serde::{Deserialize, Serialize};

use super::{summary_row, FinishContext, Metric, Metrics, ReportPart, RunContext, Shared, StepFacts};
use crate::doc::Block;
use crate::error::Result;

use crate::geometry::{HullRect, Lane, Polyline};
use crate::rows::VESSELS;
use crate::step::StepClock;
use crate::step::{PlantStep, RunGeometry};
use crate::thresholds::Thresholds;
use crate::verdict::Reason;

/// One grounding: a vessel's hull beyond the bank over consecutive steps.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Grounding {
    /// The vessel (`ship`, `tug1`, `tug2`).
    pub vessel: String,
    /// First step aground, s.
    pub t_start_s: f64,
    /// Last step aground, s.
    pub t_end_s: f64,
    /// Steps aground.
    pub samples: usize,
    /// Largest corner excess beyond the half width during the event, m.
    pub max_excess_m: f64,
}

/// The waterway metric.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WaterwayReport {
    /// The scenario's half width, m (`None`: no waterway).
    pub half_width_m: Option<f64>,
    /// `no waterway` when there is none to judge.
    pub note: Option<String>,
    /// Largest distance of a hull corner from the route beyond the half width, m
    /// (negative: every corner stayed inside by that much).
    pub max_excess_m: Option<f64>,
    /// Its time, s.
    pub t_max_s: Option<f64>,
    /// The vessel with that corner.
    pub max_vessel: Option<String>,
    /// Time with any corner of any vessel beyond the half width, s.
    pub time_outside_s: f64,
    /// Grounding events (beyond half width + tolerance), in order of their start.
    pub groundings: Vec<Grounding>,
    /// Grounding events per vessel: ship, tug 1, tug 2.
    #[serde(default)]
    pub groundings_per_vessel: [usize; 3],
}

/// The waterway tracker (O(1) besides the route and the events).
#[derive(Debug, Clone)]
pub struct WaterwayTracker {
    lane: Option<Lane>,
    hulls: [HullRect; 3],
    tolerance: f64,
    clock: StepClock,
    max: Option<(f64, f64, usize)>,
    time_outside: f64,
    current: [Option<Grounding>; 3],
    events: Vec<Grounding>,
}

impl WaterwayTracker {
    /// A tracker of the run's route and half width.
    #[must_use]
    pub fn new(geometry: &RunGeometry, thresholds: &Thresholds) -> Self {
        WaterwayTracker {
            lane: Polyline::from_route(&geometry.route)
                .zip(geometry.half_width)
                .map(|(centre, hw)| Lane::new(centre, hw)),
            hulls: geometry.sizes.map(|[l, w]| HullRect::new(l, w)),
            tolerance: thresholds.waterway_tolerance_m,
            clock: StepClock::default(),
            max: None,
            time_outside: 0.0,
            current: [None, None, None],
            events: Vec::new(),
        }
    }

    /// The next step.
    pub fn push(&mut self, step: &PlantStep<'_>) {
        let dt = self.clock.dt(step.t);
        let Some(lane) = &self.lane else {
            return;
        };
        let mut outside = false;
        for (k, v) in step.vessels.iter().enumerate() {
            let excess = lane.hull_excess(&self.hulls[k], v.x, v.y, v.psi);
            outside |= excess > 0.0;
            if self.max.is_none_or(|(m, _, _)| excess > m) {
                self.max = Some((excess, step.t, k));
            }
            let aground = excess > self.tolerance;
            match (&mut self.current[k], aground) {
                (Some(g), true) => {
                    g.t_end_s = step.t;
                    g.samples += 1;
                    g.max_excess_m = g.max_excess_m.max(excess);
                }
                (None, true) => {
                    self.current[k] = Some(Grounding {
                        vessel: VESSELS[k].to_owned(),
                        t_start_s: step.t,
                        t_end_s: step.t,
                        samples: 1,
                        max_excess_m: excess,
                    });
                }
                (Some(_), false) => self.events.extend(self.current[k].take()),
                (None, false) => {}
            }
        }
        if outside {
            self.time_outside += dt;
        }
    }

    /// The report (events still running at the last step included).
    #[must_use]
    pub fn finish(mut self) -> WaterwayReport {
        for c in &mut self.current {
            self.events.extend(c.take());
        }
        self.events
            .sort_by(|a, b| a.t_start_s.total_cmp(&b.t_start_s));
        let mut per_vessel = [0; 3];
        for g in &self.events {
            if let Some(k) = VESSELS.iter().position(|&v| v == g.vessel) {
                per_vessel[k] += 1;
            }
        }
        let judged = self.lane.is_some();
        WaterwayReport {
            half_width_m: self.lane.as_ref().map(|l| l.half_width),
            note: (!judged).then(|| "no waterway".to_owned()),
            max_excess_m: self.max.map(|m| m.0),
            t_max_s: self.max.map(|m| m.1),
            max_vessel: self.max.map(|m| VESSELS[m.2].to_owned()),
            time_outside_s: self.time_outside,
            groundings: self.events,
            groundings_per_vessel: per_vessel,
        }
    }
}

/// The verdict: one reason per grounding.
#[must_use]
pub fn reasons(report: &WaterwayReport, thresholds: &Thresholds) -> Vec<Reason> {
    let hw = report.half_width_m.unwrap_or(0.0);
    report
        .groundings
        .iter()
        .map(|g| {
            Reason::run(
                "waterway",
                Some(g.t_start_s),
                format!(
                    "{} aground until {:.1} s: a hull corner {:.2} m beyond the half width \
                     {hw} m (tolerance {} m)",
                    g.vessel, g.t_end_s, g.max_excess_m, thresholds.waterway_tolerance_m
                ),
            )
        })
        .collect()
}

impl Metric for WaterwayTracker {
    type Section = WaterwayReport;

    fn new(run: &RunContext<'_>) -> Self {
        WaterwayTracker::new(run.geometry, run.thresholds)
    }

    fn step(&mut self, s: &PlantStep<'_>, _facts: &mut StepFacts) {
        self.push(s);
    }

    fn finish(self, _ctx: &FinishContext<'_>, _shared: &Shared) -> Result<WaterwayReport> {
        Ok(WaterwayTracker::finish(self))
    }

    fn report(m: &WaterwayReport, _all: &Metrics) -> ReportPart {
        let value = match (&m.note, m.max_excess_m, m.t_max_s, &m.max_vessel) {
            (Some(note), ..) => note.clone(),
            (None, Some(e), Some(t), Some(v)) => format!(
                "{e:.2} m ({v}, {t:.1} s); {:.1} s outside; {} grounding(s) (ship / tug1 / tug2: {} / {} / {})",
                m.time_outside_s,
                m.groundings.len(),
                m.groundings_per_vessel[0],
                m.groundings_per_vessel[1],
                m.groundings_per_vessel[2]
            ),
            _ => "-".to_owned(),
        };
        let details = if m.groundings.is_empty() {
            Vec::new()
        } else {
            vec![
                Block::Heading(3, "Groundings".to_owned()),
                Block::Table {
                    headers: ["vessel", "from (s)", "to (s)", "largest excess (m)"]
                        .map(str::to_owned)
                        .to_vec(),
                    rows: m
                        .groundings
                        .iter()
                        .map(|g| {
                            vec![
                                g.vessel.clone(),
                                format!("{:.1}", g.t_start_s),
                                format!("{:.1}", g.t_end_s),
                                format!("{:.2}", g.max_excess_m),
                            ]
                        })
                        .collect(),
                },
            ]
        };
        ReportPart {
            summary: vec![summary_row(
                "waterway",
                value,
                "largest distance of a hull corner beyond the half width (negative: inside); a hull beyond the bank is a grounding",
            )],
            details,
            ..ReportPart::default()
        }
    }

    fn reasons(m: &WaterwayReport, thresholds: &Thresholds) -> Vec<Reason> {
        reasons(m, thresholds)
    }
}
