//! Towline elongation error (Du et al. 2022, section 4.2.3): the largest
//! `|l - l_tow| / l_tow` of towline 1 and 2 and when. Reads the towline rows of each
//! batch on their own time base (the column-wise path). No verdict reason.

use serde::{Deserialize, Serialize};

use super::{summary_row, FinishContext, Metric, Metrics, ReportPart, RunContext, Shared};
use crate::error::Result;
use crate::frames::{col, seconds, PlantBatch};
use crate::metrics::ArgMax;

/// The elongation section (top-level keys of `metrics.json`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ElongationSection {
    /// Largest `|l - l_tow| / l_tow` of towline 1 and 2, fractions.
    pub max_towline_elongation_error: [Option<f64>; 2],
    /// When each maximum happened, s.
    pub max_towline_elongation_error_t_s: [Option<f64>; 2],
    /// Desired towline lengths, m.
    pub towline_desired_length_m: [f64; 2],
}

/// The largest elongation error per towline so far.
#[derive(Debug, Clone)]
pub struct Elongation {
    desired: [f64; 2],
    max: [ArgMax; 2],
}

/// A fraction as a percentage, or a dash.
#[must_use]
pub fn pct(v: Option<f64>) -> String {
    v.map_or_else(|| "-".to_owned(), |v| format!("{:.2} %", v * 100.0))
}

impl Metric for Elongation {
    type Section = ElongationSection;

    fn new(run: &RunContext<'_>) -> Self {
        Elongation {
            desired: run.config.towline_desired_length,
            max: [ArgMax::default(); 2],
        }
    }

    fn batch(&mut self, b: &PlantBatch) -> Result<()> {
        let df = &b.towlines;
        let t = seconds(df)?;
        for k in 0..2 {
            let len = col(df, &format!("line{}_length", k + 1))?;
            let desired = self.desired[k];
            for i in 0..t.len() {
                // Du et al. (2022), section 4.2.3: |l - l_tow| / l_tow.
                if len[i].is_finite() {
                    self.max[k].push((len[i] - desired).abs() / desired, t[i]);
                }
            }
        }
        Ok(())
    }

    fn finish(self, _ctx: &FinishContext<'_>, _shared: &Shared) -> Result<ElongationSection> {
        let v = self.max.map(|m| m.value());
        Ok(ElongationSection {
            max_towline_elongation_error: v.map(|m| m.map(|(e, _)| e)),
            max_towline_elongation_error_t_s: v.map(|m| m.map(|(_, t)| t)),
            towline_desired_length_m: self.desired,
        })
    }

    fn report(m: &ElongationSection, _all: &Metrics) -> ReportPart {
        let e = &m.max_towline_elongation_error;
        ReportPart {
            summary: vec![summary_row(
                "max towline elongation error",
                format!("{} / {}", pct(e[0]), pct(e[1])),
                "max |l - l_tow| / l_tow, towline 1 / 2",
            )],
            ..ReportPart::default()
        }
    }
}
