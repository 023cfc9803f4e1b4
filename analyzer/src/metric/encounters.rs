//! COLREGS assessment of every target ship (Rules 13-17; scoring after Woerner et al.
//! 2018 at model scale, `crate::colregs`): the encounter over the obstacle rows within
//! twice the detection range of the ship (or its closest row if never that near), with
//! the controller's situations. Publishes each target's assessed situation for the
//! eq. (30) table ([`Shared::situations`]); a `violation` verdict fails the run.

use serde::{Deserialize, Serialize};

use super::{FinishContext, Metric, Metrics, ReportPart, RunContext, Shared};
use crate::colregs::{
    ControllerView, EncounterReport, EncounterSample, EncounterTracker, ScoringParams,
};
use crate::doc::{num, Block};
use crate::error::Result;
use crate::frames::{ControllerFrames, PlantBatch};
use crate::geometry::RouteCourse;
use crate::rows::{slot_index, ObstacleRows};
use crate::thresholds::Thresholds;
use crate::verdict::Reason;

/// The COLREGS section (top-level key of `metrics.json`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EncounterSection {
    /// One entry per target ship.
    pub colregs: Vec<EncounterReport>,
}

#[derive(Debug, Clone)]
struct Slot {
    slot: u32,
    name: String,
    /// Target ships only.
    tracker: Option<EncounterTracker>,
    /// Rows within the encounter window (twice the detection range).
    near: usize,
    /// The closest row (its sample if usable), for a target never near.
    closest: Option<(f64, Option<EncounterSample>)>,
}

/// One encounter tracker per target-ship slot.
#[derive(Debug, Clone)]
pub struct Encounters {
    ship_length: f64,
    detection: f64,
    safety_buffer: f64,
    /// Speed of a tow with her way off (the analyzer's `way_off_surge_m_s`), m/s.
    way_off: f64,
    /// The route's course, against which course changes are measured.
    course: RouteCourse,
    slots: Vec<Slot>,
    /// The reports, once concluded ([`Metric::share`]).
    reports: Option<Vec<EncounterReport>>,
}

impl Slot {
    fn push(&mut self, rows: &ObstacleRows<'_>, i: usize, (window, course): (f64, &RouteCourse)) {
        let Some(tracker) = &mut self.tracker else {
            return;
        };
        let [ox, oy, opsi, ospeed, _, _] = rows.obs(i);
        let p = rows.poses(i)[0];
        let dist = rows.dist(i);
        let sample = EncounterSample {
            t: rows.t[i],
            own: [p[0], p[1], p[2], rows.ship_speed(i)],
            target: [ox, oy, opsi, ospeed],
            altered: rows.altered[i],
            tow_range: dist[0].min(dist[1]).min(dist[2]),
            route_course: course.at([p[0], p[1]]),
        };
        let usable = sample
            .own
            .iter()
            .chain(&sample.target)
            .all(|v| v.is_finite());
        // Only the rows near the ship matter (detection, action, CPA): those within
        // twice the detection range, or the closest row if none.
        let d0 = dist[0];
        if d0 < window {
            self.near += 1;
            if usable {
                tracker.push(sample);
            }
        }
        if d0.is_finite() && self.closest.is_none_or(|(c, _)| d0 < c) {
            self.closest = Some((d0, usable.then_some(sample)));
        }
    }
}

/// The controller's situations and roles reported for `slot` (`None` without a
/// controller log or without a report for the slot).
fn view_of(ctrl: &ControllerFrames, slot: u32) -> Option<ControllerView> {
    if ctrl.solver.height() + ctrl.command.height() == 0 {
        return None;
    }
    let c = &ctrl.colregs;
    let mut v = ControllerView::default();
    for i in ctrl.colregs_indices() {
        if c.slot[i] == slot {
            v.situation_codes.push(c.situation_code[i]);
            v.roles.push(c.label(c.role_idx[i]).to_owned());
        }
    }
    (!v.situation_codes.is_empty()).then_some(v)
}

impl Encounters {
    /// Finishes every tracker (once): the reports, and each target's assessed situation.
    fn conclude(&mut self, ctrl: &ControllerFrames, shared: &mut Shared) {
        if self.reports.is_some() {
            return;
        }
        let mut reports = Vec::new();
        for st in std::mem::take(&mut self.slots) {
            let Some(mut tracker) = st.tracker else {
                continue;
            };
            if st.near == 0 {
                if let Some((_, Some(sample))) = st.closest {
                    tracker.push(sample);
                }
            }
            let view = view_of(ctrl, st.slot);
            let label = match tracker.finish(&st.name, st.slot, view.as_ref()) {
                Some(rep) => {
                    let label = rep
                        .situation_assessed
                        .clone()
                        .unwrap_or_else(|| "none".to_owned());
                    reports.push(rep);
                    label
                }
                None => "none".to_owned(),
            };
            shared.situations.insert(st.slot, label);
        }
        self.reports = Some(reports);
    }
}

impl Metric for Encounters {
    type Section = EncounterSection;

    fn new(run: &RunContext<'_>) -> Self {
        Encounters {
            ship_length: run.config.ship_size[0],
            detection: run.config.detection_distance_m,
            safety_buffer: run.config.safety_buffer_m,
            way_off: run.thresholds.way_off_surge_m_s,
            course: RouteCourse::new(&run.geometry.route, run.thresholds.route_course_lookahead_m),
            slots: Vec::new(),
            reports: None,
        }
    }

    fn batch(&mut self, b: &PlantBatch) -> Result<()> {
        let Some(rows) = ObstacleRows::of(&b.obstacles)? else {
            return Ok(());
        };
        let window = 2.0 * self.detection;
        for i in 0..rows.len() {
            let (l, d, s0, way_off) = (self.ship_length, self.detection, self.safety_buffer, self.way_off);
            let k = slot_index(
                &mut self.slots,
                rows.slot[i],
                |s| s.slot,
                || Slot {
                    slot: u32::try_from(rows.slot[i]).unwrap_or(0),
                    name: rows.name(i).to_owned(),
                    tracker: (rows.kind[i] as i64 == 2).then(|| {
                        EncounterTracker::new(ScoringParams::model_scale(l, rows.obs(i)[4], (d, s0), way_off))
                    }),
                    near: 0,
                    closest: None,
                },
            );
            self.slots[k].push(&rows, i, (window, &self.course));
        }
        Ok(())
    }

    fn share(&mut self, ctx: &FinishContext<'_>, shared: &mut Shared) -> Result<()> {
        self.conclude(ctx.ctrl, shared);
        Ok(())
    }

    fn finish(mut self, ctx: &FinishContext<'_>, _shared: &Shared) -> Result<EncounterSection> {
        self.conclude(ctx.ctrl, &mut Shared::default());
        Ok(EncounterSection {
            colregs: self.reports.unwrap_or_default(),
        })
    }

    fn report(m: &EncounterSection, _all: &Metrics) -> ReportPart {
        let mut details = vec![Block::Heading(2, "COLREGS encounters".to_owned())];
        if let Some(e) = m.colregs.first() {
            let p = &e.params;
            details.push(Block::Para(format!(
                "Scoring after Woerner et al. (2018) at model scale (docs/analyzer.md): r_detect = {:.2} m ({:.2} L), r_min = {:.2} m ({:.2} L), r_nm = {:.2} m ({:.2} L), r_col = {:.2} m ({:.2} L) for the first target, L = {:.3} m the ship length; gamma_nm {}, gamma_col {}, w_r {}, w_theta {}, readily apparent course change {} deg. Side: sign of the target's bearing from the ship's bow at the CPA.",
                p.r_detect_m, p.ranges_in_ship_lengths[0], p.r_min_m, p.ranges_in_ship_lengths[1],
                p.r_nm_m, p.ranges_in_ship_lengths[2], p.r_col_m, p.ranges_in_ship_lengths[3],
                p.ship_length_m, p.gamma_nm, p.gamma_col, p.w_r, p.w_theta, p.dchi_apparent_deg
            )));
        }
        details.push(Block::Table {
            headers: [
                "target",
                "situation / role (controller)",
                "geometric",
                "detected (s)",
                "first action (s)",
                "course change (deg)",
                "CPA (s)",
                "range at CPA",
                "side",
                "passed",
                "verdict",
                "score",
            ]
            .map(String::from)
            .to_vec(),
            rows: m.colregs.iter().map(encounter_row).collect(),
        });
        ReportPart {
            details,
            ..ReportPart::default()
        }
    }

    fn reasons(m: &EncounterSection, _thresholds: &Thresholds) -> Vec<Reason> {
        let mut r: Vec<Reason> = m
            .colregs
            .iter()
            .filter(|e| e.verdict == "violation")
            .map(|e| {
                Reason::target(
                    "colregs",
                    &e.target,
                    Some(e.t_cpa_s),
                    format!(
                        "{} ({}): violation: {}",
                        e.situation_assessed.as_deref().unwrap_or("unclassified"),
                        e.rule
                            .map_or_else(|| "no rule".to_owned(), |r| format!("Rule {r}")),
                        e.reasons.join("; ")
                    ),
                )
            })
            .collect();
        r.sort_by(|a, b| a.t_s.unwrap_or(0.0).total_cmp(&b.t_s.unwrap_or(0.0)));
        r
    }
}

/// One row of the report's COLREGS table.
fn encounter_row(e: &EncounterReport) -> Vec<String> {
    vec![
        e.target.clone(),
        format!(
            "{} / {}",
            e.situation.as_deref().unwrap_or("-"),
            e.role.as_deref().unwrap_or("-")
        ),
        e.situation_geometric.clone().unwrap_or_else(|| "-".into()),
        num(e.t_detect_s, 1),
        format!(
            "{} ({})",
            num(e.t_first_action_s, 1),
            e.first_action.as_deref().unwrap_or("none")
        ),
        num(e.course_change_deg, 1),
        format!("{:.1}", e.t_cpa_s),
        format!("{:.3} m ({:.2} L)", e.r_cpa_m, e.r_cpa_ship_lengths),
        e.side.clone(),
        e.passed.clone(),
        if e.reasons.is_empty() || e.verdict == "compliant" {
            e.verdict.clone()
        } else {
            format!("{}: {}", e.verdict, e.reasons.join("; "))
        },
        e.rule
            .map_or_else(|| "-".into(), |r| format!("Rule {r}: {}", num(e.score, 2))),
    ]
}
