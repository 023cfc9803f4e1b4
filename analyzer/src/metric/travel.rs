//! Ship travel (Du et al. 2022, section 4.2.3): the length of the ship's track over
//! every plant step. No verdict reason.

use serde::{Deserialize, Serialize};

use super::{StepFacts, summary_row, FinishContext, Metric, Metrics, ReportPart, RunContext, Shared};
use crate::error::Result;
use crate::metrics::TravelTracker;
use crate::step::PlantStep;

/// The travel section (top-level key of `metrics.json`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TravelSection {
    /// Length of the ship's track, m.
    pub ship_travel_m: f64,
}

/// The track length so far.
#[derive(Debug, Clone, Default)]
pub struct Travel {
    travel: TravelTracker,
}

impl Metric for Travel {
    type Section = TravelSection;

    fn new(_run: &RunContext<'_>) -> Self {
        Travel::default()
    }

    fn step(&mut self, s: &PlantStep<'_>, _facts: &mut StepFacts) {
        self.travel.push(s.vessels[0].x, s.vessels[0].y);
    }

    fn finish(self, _ctx: &FinishContext<'_>, _shared: &Shared) -> Result<TravelSection> {
        Ok(TravelSection {
            ship_travel_m: self.travel.value(),
        })
    }

    fn report(m: &TravelSection, _all: &Metrics) -> ReportPart {
        ReportPart {
            summary: vec![summary_row(
                "ship travel",
                format!("{:.2} m", m.ship_travel_m),
                "length of the ship's track",
            )],
            ..ReportPart::default()
        }
    }
}
