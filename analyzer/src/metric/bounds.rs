//! Command bounds (Du et al. 2022, Tables 2 and 3; eq. (17)-(21)): the controller's
//! commanded tensions, tension rates, towing angles, angle rates and tug thrusts, and the
//! thrusts the plant received (its input rows of each batch, the column-wise path),
//! against the bounds of the run. Every violated bound fails the verdict.

use serde::{Deserialize, Serialize};

use super::{summary_row, FinishContext, Metric, Metrics, ReportPart, RunContext, Shared};
use crate::doc::{num, Block};
use crate::error::Result;
use crate::frames::{col, f64s, seconds, ControllerFrames, PlantBatch};
use crate::metrics::{check_bounds, BoundReport, CommandSeries, InputBoundCheck, Violations};
use crate::run::Bounds;
use crate::thresholds::Thresholds;
use crate::verdict::Reason;

/// Bound checks with the bounds used.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BoundSection {
    /// The bounds.
    pub bounds: Bounds,
    /// The violations.
    #[serde(flatten)]
    pub report: BoundReport,
}

/// The bounds section (top-level key of `metrics.json`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BoundsSection {
    /// Commands outside their bounds.
    pub bound_violations: BoundSection,
}

/// The plant inputs' check so far; the commands are checked at the end.
#[derive(Debug, Clone)]
pub struct BoundChecks {
    bounds: Bounds,
    inputs: InputBoundCheck,
}

/// The commands' checks (controller log, read whole).
fn command_report(ctrl: &ControllerFrames, bounds: &Bounds) -> Result<BoundReport> {
    if ctrl.command.height() == 0 {
        return Ok(check_bounds(None, None, bounds));
    }
    let c = &ctrl.command;
    let t = seconds(c)?;
    let tension = [col(c, "cmd_tension1")?, col(c, "cmd_tension2")?];
    let angle = [col(c, "cmd_angle1")?, col(c, "cmd_angle2")?];
    let thrust = [
        [
            col(c, "cmd_tug1_X")?,
            col(c, "cmd_tug1_Y")?,
            col(c, "cmd_tug1_N")?,
        ],
        [
            col(c, "cmd_tug2_X")?,
            col(c, "cmd_tug2_Y")?,
            col(c, "cmd_tug2_N")?,
        ],
    ];
    let series = CommandSeries {
        t: &t,
        tension: [&tension[0], &tension[1]],
        angle: [&angle[0], &angle[1]],
        thrust: [
            [&thrust[0][0], &thrust[0][1], &thrust[0][2]],
            [&thrust[1][0], &thrust[1][1], &thrust[1][2]],
        ],
    };
    Ok(check_bounds(Some(series), None, bounds))
}

/// The checks of a section with their names, bounds and units, in the report's order.
fn checks(s: &BoundSection) -> [(&'static str, String, &Violations, &'static str); 6] {
    let (bd, bv) = (&s.bounds, &s.report);
    [
        (
            "tension",
            format!("{} .. {} N", bd.min_tension_n, bd.max_tension_n),
            &bv.tension,
            "N",
        ),
        (
            "tension rate",
            format!("{} N/s", bd.tension_rate_n_per_s),
            &bv.tension_rate,
            "N/s",
        ),
        (
            "towing angle",
            format!("{:.1} deg", bd.max_towing_angle_rad.to_degrees()),
            &bv.towing_angle,
            "deg",
        ),
        (
            "towing angle rate",
            format!("{:.1} deg/s", bd.angle_rate_rad_per_s.to_degrees()),
            &bv.towing_angle_rate,
            "deg/s",
        ),
        (
            "tug thrust (commands)",
            format!("{:?}", bd.max_thrust),
            &bv.tug_thrust_command,
            "N or N m",
        ),
        (
            "tug thrust (plant inputs)",
            format!("{:?}", bd.max_thrust),
            &bv.tug_thrust_input,
            "N or N m",
        ),
    ]
}

impl Metric for BoundChecks {
    type Section = BoundsSection;

    fn new(run: &RunContext<'_>) -> Self {
        BoundChecks {
            bounds: run.config.bounds,
            inputs: InputBoundCheck::new(&run.config.bounds),
        }
    }

    fn batch(&mut self, b: &PlantBatch) -> Result<()> {
        let c = &b.inputs;
        if c.height() == 0 {
            return Ok(());
        }
        let t = seconds(c)?;
        let cols = [
            "in_tug1_X",
            "in_tug1_Y",
            "in_tug1_N",
            "in_tug2_X",
            "in_tug2_Y",
            "in_tug2_N",
        ]
        .iter()
        .map(|n| f64s(c, n))
        .collect::<Result<Vec<_>>>()?;
        for i in 0..t.len() {
            self.inputs.push(
                t[i],
                [
                    [cols[0][i], cols[1][i], cols[2][i]],
                    [cols[3][i], cols[4][i], cols[5][i]],
                ],
            );
        }
        Ok(())
    }

    fn finish(self, ctx: &FinishContext<'_>, _shared: &Shared) -> Result<BoundsSection> {
        let report = command_report(ctx.ctrl, &self.bounds)?.with_inputs(self.inputs.result());
        Ok(BoundsSection {
            bound_violations: BoundSection {
                bounds: self.bounds,
                report,
            },
        })
    }

    fn report(m: &BoundsSection, _all: &Metrics) -> ReportPart {
        let s = &m.bound_violations;
        let rows = checks(s)
            .into_iter()
            .map(|(name, bound, v, unit)| {
                vec![
                    name.to_owned(),
                    bound,
                    format!("{} of {}", v.count, v.checked),
                    if v.count > 0 {
                        format!("{:.4} {unit}", v.worst_excess)
                    } else {
                        "-".to_owned()
                    },
                    num(v.first_t_s, 1),
                ]
            })
            .collect();
        ReportPart {
            summary: vec![summary_row(
                "bound violations",
                s.report.total.to_string(),
                "commands outside the tension, tension rate, towing angle, angle rate and thrust bounds",
            )],
            details: vec![
                Block::Heading(2, "Bounds".to_owned()),
                Block::Table {
                    headers: ["command", "bound", "violations", "worst excess", "first (s)"]
                        .map(String::from)
                        .to_vec(),
                    rows,
                },
            ],
            ..ReportPart::default()
        }
    }

    fn reasons(m: &BoundsSection, _thresholds: &Thresholds) -> Vec<Reason> {
        let mut r: Vec<Reason> = checks(&m.bound_violations)
            .into_iter()
            .filter(|(_, _, v, _)| v.count > 0)
            .map(|(name, bound, v, unit)| {
                Reason::run(
                    "bound_violations",
                    v.first_t_s,
                    format!(
                        "{name}: {} of {} samples beyond {bound}, worst excess {:.4} {unit}",
                        v.count, v.checked, v.worst_excess
                    ),
                )
            })
            .collect();
        r.sort_by(|a, b| a.t_s.unwrap_or(0.0).total_cmp(&b.t_s.unwrap_or(0.0)));
        r
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_violated_bound_is_one_reason_at_its_first_violation() {
        let report = BoundReport {
            tension_rate: Violations {
                count: 2,
                checked: 10,
                worst_excess: 0.05,
                first_t_s: Some(40.0),
            },
            towing_angle: Violations {
                count: 1,
                checked: 10,
                worst_excess: 1.0,
                first_t_s: Some(12.0),
            },
            ..BoundReport::default()
        };
        let m = BoundsSection {
            bound_violations: BoundSection {
                bounds: Bounds::default(),
                report,
            },
        };
        let r = BoundChecks::reasons(&m, &Thresholds::default());
        assert_eq!(r.len(), 2);
        assert_eq!(r[0].t_s, Some(12.0), "by time");
        assert!(
            r[0].message.starts_with("towing angle: 1 of 10"),
            "{}",
            r[0].message
        );
        assert!(r.iter().all(|r| r.metric == "bound_violations"));
        let clean = BoundsSection {
            bound_violations: BoundSection {
                bounds: Bounds::default(),
                report: BoundReport::default(),
            },
        };
        assert!(BoundChecks::reasons(&clean, &Thresholds::default()).is_empty());
    }
}
