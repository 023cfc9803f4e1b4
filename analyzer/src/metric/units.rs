//! The units' own log messages (`/plant/log`, `/controller/log`): warnings (level 3) and
//! errors (level >= 4). Any error fails the verdict.

use serde::{Deserialize, Serialize};

use super::{summary_row, FinishContext, Metric, Metrics, ReportPart, RunContext, Shared};
use crate::error::Result;
use crate::thresholds::Thresholds;
use crate::verdict::Reason;

/// The unit-log section (top-level keys of `metrics.json`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct UnitLogSection {
    /// Warnings (level 3) the units logged.
    pub unit_warnings: usize,
    /// Errors (level >= 4) the units logged.
    pub unit_errors: usize,
}

/// Counts the unit log levels when the run is complete (they come with the files).
#[derive(Debug, Clone, Default)]
pub struct UnitLogs;

impl Metric for UnitLogs {
    type Section = UnitLogSection;

    fn new(_run: &RunContext<'_>) -> Self {
        UnitLogs
    }

    fn finish(self, ctx: &FinishContext<'_>, _shared: &Shared) -> Result<UnitLogSection> {
        let levels = ctx.unit_levels;
        Ok(UnitLogSection {
            unit_warnings: levels.iter().filter(|&&l| l == 3).count(),
            unit_errors: levels.iter().filter(|&&l| l >= 4).count(),
        })
    }

    fn report(m: &UnitLogSection, _all: &Metrics) -> ReportPart {
        ReportPart {
            summary: vec![summary_row(
                "unit warnings / errors",
                format!("{} / {}", m.unit_warnings, m.unit_errors),
                "/plant/log and /controller/log",
            )],
            ..ReportPart::default()
        }
    }

    fn reasons(m: &UnitLogSection, _thresholds: &Thresholds) -> Vec<Reason> {
        if m.unit_errors == 0 {
            return Vec::new();
        }
        vec![Reason::run(
            "unit_errors",
            None,
            format!("the units logged {} errors (level >= 4)", m.unit_errors),
        )]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unit_errors_fail_and_warnings_do_not() {
        let th = Thresholds::default();
        let warn = UnitLogSection {
            unit_warnings: 3,
            unit_errors: 0,
        };
        assert!(UnitLogs::reasons(&warn, &th).is_empty());
        let err = UnitLogSection {
            unit_warnings: 0,
            unit_errors: 2,
        };
        let r = UnitLogs::reasons(&err, &th);
        assert_eq!(r.len(), 1);
        assert_eq!(r[0].metric, "unit_errors");
        assert!(r[0].message.contains("2 errors"));
    }
}
