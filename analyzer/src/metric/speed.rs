//! Speed over ground: the cruise speed (the median speed over ground of the plant steps
//! with the ship under way, `sog >= under_way_speed_m_s`), the largest speed over ground,
//! and the largest as a multiple of cruise.
//!
//! The median comes from a fixed histogram of [`SOG_BINS`] bins of
//! [`SOG_BIN_M_S`] (0.1 mm/s) from 0 to 1 m/s (speeds above go to an overflow bin, whose
//! median reads 1 m/s): bounded memory (40 kB) whatever the log's length, and exact to
//! half a bin (0.05 mm/s, 0.08 % of the tow's 0.065 m/s). It is the lower median (the
//! `ceil(n / 2)`-th smallest sample), reported as its bin's centre. Samples are counted
//! per plant step (the plant's step is fixed).

use serde::{Deserialize, Serialize};

use super::{summary_row, FinishContext, Metric, Metrics, ReportPart, RunContext, Shared, StepFacts};
use crate::error::Result;

use crate::step::{PlantStep, RunGeometry};
use crate::thresholds::Thresholds;
use crate::verdict::Reason;

/// Width of a speed bin of the cruise histogram, m/s.
pub const SOG_BIN_M_S: f64 = 1e-4;
/// Bins of the cruise histogram (0 to 1 m/s).
pub const SOG_BINS: usize = 10_000;

/// The speed-over-ground metric.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SpeedReport {
    /// Cruise speed: median speed over ground while under way, m/s (`None`: never under
    /// way).
    pub cruise_m_s: Option<f64>,
    /// Resolution of the cruise speed (histogram bin), m/s.
    pub cruise_resolution_m_s: f64,
    /// Largest speed over ground of the ship, m/s.
    pub max_sog_m_s: Option<f64>,
    /// Its time, s.
    pub t_max_s: Option<f64>,
    /// `max_sog_m_s / cruise_m_s`.
    pub max_cruise_ratio: Option<f64>,
    /// Plant steps under way.
    pub steps_under_way: u64,
}

/// The speed tracker (a fixed histogram: bounded memory).
#[derive(Debug, Clone)]
pub struct SpeedTracker {
    th: Thresholds,
    /// `SOG_BINS` bins and the overflow bin.
    bins: Vec<u32>,
    n: u64,
    max: Option<(f64, f64)>,
}

impl SpeedTracker {
    /// A tracker.
    #[must_use]
    pub fn new(_geometry: &RunGeometry, thresholds: &Thresholds) -> Self {
        SpeedTracker {
            th: *thresholds,
            bins: vec![0; SOG_BINS + 1],
            n: 0,
            max: None,
        }
    }

    /// The next step.
    pub fn push(&mut self, step: &PlantStep<'_>) {
        let sog = step.vessels[0].sog();
        if !sog.is_finite() {
            return;
        }
        if self.max.is_none_or(|(m, _)| sog > m) {
            self.max = Some((sog, step.t));
        }
        if sog >= self.th.under_way_speed_m_s {
            // sog >= 0, so the cast saturates only above the range (to the overflow bin).
            let k = ((sog / SOG_BIN_M_S) as usize).min(SOG_BINS);
            self.bins[k] = self.bins[k].saturating_add(1);
            self.n += 1;
        }
    }

    /// The lower median of the histogram, m/s.
    fn median(&self) -> Option<f64> {
        if self.n == 0 {
            return None;
        }
        let rank = self.n.div_ceil(2);
        let mut seen = 0u64;
        for (k, &c) in self.bins.iter().enumerate() {
            seen += u64::from(c);
            if seen >= rank {
                return Some(if k == SOG_BINS {
                    SOG_BINS as f64 * SOG_BIN_M_S
                } else {
                    (k as f64 + 0.5) * SOG_BIN_M_S
                });
            }
        }
        None
    }

    /// The report.
    #[must_use]
    pub fn finish(self) -> SpeedReport {
        let cruise = self.median();
        SpeedReport {
            cruise_m_s: cruise,
            cruise_resolution_m_s: SOG_BIN_M_S,
            max_sog_m_s: self.max.map(|m| m.0),
            t_max_s: self.max.map(|m| m.1),
            max_cruise_ratio: cruise.zip(self.max).map(|(c, (m, _))| m / c),
            steps_under_way: self.n,
        }
    }
}

/// The verdict: the largest speed over ground above `sog_max_cruise_ratio` x cruise.
#[must_use]
pub fn reasons(report: &SpeedReport, thresholds: &Thresholds) -> Vec<Reason> {
    match (
        report.max_cruise_ratio,
        report.cruise_m_s,
        report.max_sog_m_s,
    ) {
        (Some(r), Some(c), Some(m)) if r > thresholds.sog_max_cruise_ratio => {
            vec![Reason::run(
                "speed",
                report.t_max_s,
                format!(
                    "speed over ground {m:.3} m/s = {r:.2} x cruise {c:.4} m/s, above {} x",
                    thresholds.sog_max_cruise_ratio
                ),
            )]
        }
        _ => Vec::new(),
    }
}

impl Metric for SpeedTracker {
    type Section = SpeedReport;

    fn new(run: &RunContext<'_>) -> Self {
        SpeedTracker::new(run.geometry, run.thresholds)
    }

    fn step(&mut self, s: &PlantStep<'_>, _facts: &mut StepFacts) {
        self.push(s);
    }

    fn finish(self, _ctx: &FinishContext<'_>, _shared: &Shared) -> Result<SpeedReport> {
        Ok(SpeedTracker::finish(self))
    }

    fn report(m: &SpeedReport, _all: &Metrics) -> ReportPart {
        let value = match (m.cruise_m_s, m.max_sog_m_s, m.max_cruise_ratio) {
            (Some(c), Some(v), Some(r)) => format!("{v:.3} m/s = {r:.2} x cruise ({c:.3} m/s)"),
            _ => "never under way".to_owned(),
        };
        ReportPart {
            summary: vec![summary_row(
                "speed over ground",
                value,
                "the ship's largest speed over ground against its cruise (median while under way)",
            )],
            ..ReportPart::default()
        }
    }

    fn reasons(m: &SpeedReport, thresholds: &Thresholds) -> Vec<Reason> {
        reasons(m, thresholds)
    }
}
