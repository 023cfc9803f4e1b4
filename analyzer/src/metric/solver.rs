//! The solver's statistics from the controller log (read whole: percentiles need every
//! sample): wall time per control sample, ADMM iterations (centralized: SCP loops), the
//! fraction of samples that met the stopping rule, and the fallbacks to the shifted
//! previous plan with their reasons. No verdict reason: a fallback is the controller's
//! designed recovery, and wall time is not a property of the run.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use super::{summary_row, FinishContext, Metric, Metrics, ReportPart, RunContext, Shared};
use crate::doc::Block;
use crate::error::{AnalyzerError, Result};
use crate::frames::{bools, f64s, i64s};
use crate::metrics::{stats, Stats};

/// The solver section (top-level keys of `metrics.json`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SolverSection {
    /// Wall time per control sample, ms.
    pub sample_time_ms: Option<Stats>,
    /// ADMM iterations per sample (centralized: SCP loops).
    pub admm_iterations: Option<Stats>,
    /// Fraction of samples whose ADMM met the stopping rule.
    pub admm_converged_fraction: Option<f64>,
    /// Samples whose plan fell back to the shifted previous plan.
    pub fallbacks: u64,
    /// Fallback reasons and their counts.
    pub fallback_reasons: BTreeMap<String, u64>,
}

/// Nothing per step: the solver table is read when the run is complete.
#[derive(Debug, Clone, Default)]
pub struct Solver;

/// `median .., p99 .., max .. (n = ..)` with `prec` decimals, or a dash.
fn stats_text(s: Option<&Stats>, prec: usize) -> String {
    s.map_or_else(
        || "-".to_owned(),
        |s| {
            format!(
                "median {:.prec$}, p99 {:.prec$}, max {:.prec$} (n = {})",
                s.median, s.p99, s.max, s.count
            )
        },
    )
}

impl Metric for Solver {
    type Section = SolverSection;

    fn new(_run: &RunContext<'_>) -> Self {
        Solver
    }

    fn finish(self, ctx: &FinishContext<'_>, _shared: &Shared) -> Result<SolverSection> {
        let s = &ctx.ctrl.solver;
        if s.height() == 0 {
            return Ok(SolverSection {
                sample_time_ms: None,
                admm_iterations: None,
                admm_converged_fraction: None,
                fallbacks: 0,
                fallback_reasons: BTreeMap::new(),
            });
        }
        let ms = f64s(s, "compute_time_ms")?;
        let it = f64s(s, "iterations")?;
        let conv = bools(s, "converged")?;
        let n = conv.len().max(1) as f64;
        let conv_frac = conv.iter().filter(|c| **c == Some(true)).count() as f64 / n;
        let mut reasons: BTreeMap<String, u64> = BTreeMap::new();
        let reasons_col = s
            .column("fallback")
            .and_then(|c| c.str())
            .map_err(|e| AnalyzerError::frame("solver", e))?;
        for r in reasons_col.iter().flatten().filter(|r| !r.is_empty()) {
            *reasons.entry(r.to_owned()).or_insert(0) += 1;
        }
        let counted: u64 = reasons.values().sum();
        let cumulative = i64s(s, "fallbacks")?
            .last()
            .copied()
            .and_then(|v| u64::try_from(v).ok())
            .unwrap_or(0);
        Ok(SolverSection {
            sample_time_ms: stats(&ms),
            admm_iterations: stats(&it),
            admm_converged_fraction: Some(conv_frac),
            fallbacks: counted.max(cumulative),
            fallback_reasons: reasons,
        })
    }

    fn report(m: &SolverSection, _all: &Metrics) -> ReportPart {
        let mut details = Vec::new();
        if !m.fallback_reasons.is_empty() {
            details.push(Block::Heading(2, "Fallbacks".to_owned()));
            details.push(Block::Table {
                headers: vec!["reason".into(), "samples".into()],
                rows: m
                    .fallback_reasons
                    .iter()
                    .map(|(r, n)| vec![r.clone(), n.to_string()])
                    .collect(),
            });
        }
        ReportPart {
            summary: vec![
                summary_row(
                    "sample computation time",
                    stats_text(m.sample_time_ms.as_ref(), 2) + " ms",
                    "wall time per control sample (controller log)",
                ),
                [
                    "ADMM iterations".to_owned(),
                    stats_text(m.admm_iterations.as_ref(), 0),
                    format!(
                        "per control sample; converged in {}",
                        m.admm_converged_fraction.map_or_else(
                            || "-".to_owned(),
                            |f| format!("{:.1} % of samples", f * 100.0)
                        )
                    ),
                ],
                summary_row(
                    "fallbacks",
                    m.fallbacks.to_string(),
                    "samples whose plan was replaced by the shifted previous plan",
                ),
            ],
            details,
            ..ReportPart::default()
        }
    }
}
