//! Settling time (Du et al. 2022, section 4.2.3): the first time after which the ship
//! stays within L/2 of the destination, 3 deg of its heading, |u|, |v| < 0.01 m/s and
//! |r| < 0.01 rad/s; and the ship's state at the end of the log. No verdict reason (the
//! paper's metric is a figure of merit, not a pass/fail bound).

use serde::{Deserialize, Serialize};

use super::{StepFacts, summary_row, FinishContext, Metric, Metrics, ReportPart, RunContext, Shared};
use crate::doc::Block;
use crate::error::Result;
use crate::geometry::wrap;
use crate::metrics::{settled, SettleCriteria, SettlingTracker};
use crate::step::PlantStep;

/// Ship pose at the end of the log relative to the destination.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FinalState {
    /// Time, s.
    pub t_s: f64,
    /// Distance to the destination, m.
    pub distance_to_destination_m: f64,
    /// Heading error, deg.
    pub heading_error_deg: f64,
    /// Speed over ground, m/s.
    pub speed_m_s: f64,
}

/// The settling section (top-level keys of `metrics.json`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SettlingSection {
    /// Settling time (Du et al. 2022, section 4.2.3), s; null if never settled.
    pub settling_time_s: Option<f64>,
    /// The settling criteria used.
    pub settling_criteria: SettleCriteria,
    /// The ship at the end of the log.
    pub final_state: Option<FinalState>,
}

/// The settling tracker and the last step.
#[derive(Debug, Clone)]
pub struct Settling {
    criteria: SettleCriteria,
    destination: [f64; 3],
    settle: SettlingTracker,
    /// The last plant step: t, ship x, y, psi, u, v.
    last: Option<[f64; 6]>,
}

impl Metric for Settling {
    type Section = SettlingSection;

    fn new(run: &RunContext<'_>) -> Self {
        Settling {
            criteria: SettleCriteria::paper(run.config.ship_size[0]),
            destination: run.config.destination,
            settle: SettlingTracker::default(),
            last: None,
        }
    }

    fn step(&mut self, s: &PlantStep<'_>, _facts: &mut StepFacts) {
        let v = s.vessels[0];
        let ship = [v.x, v.y, v.psi, v.u, v.v, v.r];
        self.settle
            .push(s.t, settled(ship, self.destination, self.criteria));
        self.last = Some([s.t, v.x, v.y, v.psi, v.u, v.v]);
    }

    fn finish(self, _ctx: &FinishContext<'_>, _shared: &Shared) -> Result<SettlingSection> {
        let d = self.destination;
        Ok(SettlingSection {
            settling_time_s: self.settle.value(),
            settling_criteria: self.criteria,
            final_state: self.last.map(|[t, x, y, psi, u, v]| FinalState {
                t_s: t,
                distance_to_destination_m: (x - d[0]).hypot(y - d[1]),
                heading_error_deg: wrap(psi - d[2]).to_degrees(),
                speed_m_s: u.hypot(v),
            }),
        })
    }

    fn report(m: &SettlingSection, _all: &Metrics) -> ReportPart {
        ReportPart {
            summary: vec![summary_row(
                "settling time",
                m.settling_time_s
                    .map_or_else(|| "never settled".to_owned(), |t| format!("{t:.1} s")),
                "first time after which the ship stays within L/2 of the destination, 3 deg of its heading, |u|,|v| < 0.01 m/s, |r| < 0.01 rad/s (paper, section 4.2.3)",
            )],
            after_summary: m
                .final_state
                .iter()
                .map(|f| {
                    Block::Para(format!(
                        "At the end of the log ({:.1} s) the ship is {:.3} m from the destination, heading error {:.2} deg, speed {:.4} m/s.",
                        f.t_s, f.distance_to_destination_m, f.heading_error_deg, f.speed_m_s
                    ))
                })
                .collect(),
            ..ReportPart::default()
        }
    }
}
