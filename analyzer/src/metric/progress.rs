//! Progress along the route: the longest stall, the time to destination, and the
//! arrival deadline.
//!
//! Progress is the arc length of the ship's projection on the route polyline
//! ([`Polyline::project`]), kept as the best so far (monotone: going back does not undo
//! progress). A stall starts at a step with the best progress `s0`; it ends at the first
//! step at which the best progress exceeds `s0 + progress_min_m`, and the next stall
//! starts there. Only time farther than `destination_radius_m` from the destination
//! counts; reaching that circle ends the stall. This greedy split is O(1); it
//! underestimates the exact longest window without `progress_min_m` of progress by at
//! most the time the ship takes to cover `progress_min_m` around the stall.
//!
//! The time of a stall during which the tow is giving way to a target that is not yet
//! past and clear (COLREGS Rule 8(d), 16: it may keep its way off until then) is
//! excused: the verdict is on the longest stall less that time. Whether a give-way
//! encounter is open at a step is [`super::rules::RulesTracker::give_way_open`] after the
//! same step, handed to [`ProgressTracker::push`] explicitly.

use serde::{Deserialize, Serialize};

use super::{summary_row, FinishContext, Metric, Metrics, ReportPart, RunContext, Shared, StepFacts};
use crate::error::Result;

use crate::geometry::Polyline;
use crate::step::StepClock;
use crate::step::{PlantStep, RunGeometry};
use crate::thresholds::Thresholds;
use crate::verdict::Reason;

/// One stall: an interval without `progress_min_m` of progress.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Stall {
    /// Start of the stall, s.
    pub t_start_s: f64,
    /// Time stalled (outside the destination circle), s.
    pub duration_s: f64,
    /// Part of it while a give-way encounter was open, s.
    pub giving_way_s: f64,
}

impl Stall {
    /// The stall's time not excused by giving way, s.
    #[must_use]
    pub fn unexcused_s(&self) -> f64 {
        self.duration_s - self.giving_way_s
    }
}

/// The progress metric.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ProgressReport {
    /// Route length (polyline through origin, waypoints, destination), m; `None`
    /// without a route.
    pub route_length_m: Option<f64>,
    /// Best progress along the route at the end, m.
    pub best_progress_m: Option<f64>,
    /// The longest stall (by its whole duration).
    pub longest_stall: Option<Stall>,
    /// The stall with the longest time not excused by giving way (the verdict's).
    pub longest_unexcused_stall: Option<Stall>,
    /// First step's time, s.
    pub t_first_s: Option<f64>,
    /// First time the ship's centre is within `destination_radius_m` of the destination,
    /// s; `None` if never.
    pub t_arrival_s: Option<f64>,
    /// `t_arrival_s - t_first_s`, s.
    pub time_to_destination_s: Option<f64>,
    /// Latest arrival allowed: `t_first + route_length / arrival_speed_m_s +
    /// arrival_margin_s`, s.
    pub arrival_deadline_s: Option<f64>,
}

/// The progress tracker (O(1) state besides the route).
#[derive(Debug, Clone)]
pub struct ProgressTracker {
    route: Option<Polyline>,
    th: Thresholds,
    clock: StepClock,
    best: f64,
    /// The running stall and its start progress.
    current: Option<(Stall, f64)>,
    longest: Option<Stall>,
    longest_unexcused: Option<Stall>,
    t_first: Option<f64>,
    t_arrival: Option<f64>,
}

impl ProgressTracker {
    /// A tracker for the run's route.
    #[must_use]
    pub fn new(geometry: &RunGeometry, thresholds: &Thresholds) -> Self {
        ProgressTracker {
            route: Polyline::from_route(&geometry.route),
            th: *thresholds,
            clock: StepClock::default(),
            best: f64::NEG_INFINITY,
            current: None,
            longest: None,
            longest_unexcused: None,
            t_first: None,
            t_arrival: None,
        }
    }

    /// The next step; `giving_way`: a give-way encounter is open at this step
    /// ([`super::rules::RulesTracker::give_way_open`]).
    pub fn push(&mut self, step: &PlantStep<'_>, giving_way: bool) {
        let dt = self.clock.dt(step.t);
        let Some(route) = &self.route else {
            return;
        };
        self.t_first.get_or_insert(step.t);
        let ship = step.vessels[0];
        let p = [ship.x, ship.y];
        let s = route.project(p).s;
        self.best = self.best.max(s);
        let outside = crate::geometry::dist(p, route.end()) > self.th.destination_radius_m;
        if !outside {
            if self.t_arrival.is_none() {
                self.t_arrival = Some(step.t);
            }
            self.close();
            return;
        }
        let (stall, s0) = self.current.get_or_insert((
            Stall {
                t_start_s: step.t,
                duration_s: 0.0,
                giving_way_s: 0.0,
            },
            self.best,
        ));
        stall.duration_s += dt;
        if giving_way {
            stall.giving_way_s += dt;
        }
        if self.best > *s0 + self.th.progress_min_m {
            self.close();
            self.current = Some((
                Stall {
                    t_start_s: step.t,
                    duration_s: 0.0,
                    giving_way_s: 0.0,
                },
                self.best,
            ));
        }
    }

    /// Ends the running stall, keeping it if it is the longest.
    fn close(&mut self) {
        if let Some((stall, _)) = self.current.take() {
            if self.longest.is_none_or(|l| stall.duration_s > l.duration_s) {
                self.longest = Some(stall);
            }
            if self
                .longest_unexcused
                .is_none_or(|l| stall.unexcused_s() > l.unexcused_s())
            {
                self.longest_unexcused = Some(stall);
            }
        }
    }

    /// The report (a stall still running at the last step counts up to it).
    #[must_use]
    pub fn finish(mut self) -> ProgressReport {
        self.close();
        let length = self.route.as_ref().map(Polyline::length);
        let deadline = match (self.t_first, length) {
            (Some(t0), Some(l)) => {
                Some(t0 + l / self.th.arrival_speed_m_s + self.th.arrival_margin_s)
            }
            _ => None,
        };
        ProgressReport {
            route_length_m: length,
            best_progress_m: self.t_first.map(|_| self.best),
            longest_stall: self.longest,
            longest_unexcused_stall: self.longest_unexcused,
            t_first_s: self.t_first,
            t_arrival_s: self.t_arrival,
            time_to_destination_s: self.t_arrival.zip(self.t_first).map(|(a, f)| a - f),
            arrival_deadline_s: deadline,
        }
    }
}

/// The verdict: a stall whose time not excused by giving way exceeds `stall_max_s`;
/// arrival after the deadline, or never (with a route and at least one step).
#[must_use]
pub fn reasons(report: &ProgressReport, thresholds: &Thresholds) -> Vec<Reason> {
    let mut out = Vec::new();
    if let Some(s) = report.longest_unexcused_stall {
        if s.unexcused_s() > thresholds.stall_max_s {
            out.push(Reason::run(
                "progress",
                Some(s.t_start_s),
                format!(
                    "stalled {:.1} s (of which {:.1} s giving way) without {} m of progress \
                     along the route, limit {} s",
                    s.duration_s, s.giving_way_s, thresholds.progress_min_m, thresholds.stall_max_s
                ),
            ));
        }
    }
    if let Some(deadline) = report.arrival_deadline_s {
        match report.t_arrival_s {
            Some(t) if t <= deadline => {}
            Some(t) => out.push(Reason::run(
                "progress",
                Some(t),
                format!(
                    "arrived at {t:.1} s, after the deadline {deadline:.1} s (route {:.1} m at \
                     {} m/s + {} s)",
                    report.route_length_m.unwrap_or(0.0),
                    thresholds.arrival_speed_m_s,
                    thresholds.arrival_margin_s
                ),
            )),
            None => out.push(Reason::run(
                "progress",
                None,
                format!(
                    "never within {} m of the destination (deadline {deadline:.1} s)",
                    thresholds.destination_radius_m
                ),
            )),
        }
    }
    out
}

impl Metric for ProgressTracker {
    type Section = ProgressReport;

    fn new(run: &RunContext<'_>) -> Self {
        ProgressTracker::new(run.geometry, run.thresholds)
    }

    /// Registered after `rules`, whose give-way state at this step excuses a stall.
    fn step(&mut self, s: &PlantStep<'_>, facts: &mut StepFacts) {
        self.push(s, facts.giving_way);
    }

    fn finish(self, _ctx: &FinishContext<'_>, _shared: &Shared) -> Result<ProgressReport> {
        Ok(ProgressTracker::finish(self))
    }

    fn report(m: &ProgressReport, _all: &Metrics) -> ReportPart {
        let stall = m.longest_stall.map_or_else(
            || "none".to_owned(),
            |s| {
                format!(
                    "{:.1} s from {:.1} s ({:.1} s of it giving way)",
                    s.duration_s, s.t_start_s, s.giving_way_s
                )
            },
        );
        let arrival = match (m.time_to_destination_s, m.arrival_deadline_s) {
            (Some(a), Some(d)) => format!("{a:.1} s (latest allowed: {d:.1} s)"),
            (None, Some(d)) => format!("not reached (latest allowed: {d:.1} s)"),
            _ => "no route".to_owned(),
        };
        ReportPart {
            summary: vec![
                summary_row(
                    "longest stall",
                    stall,
                    "longest time without the least progress along the route, away from the destination",
                ),
                summary_row("time to destination", arrival, "first time the ship's centre is near the destination"),
            ],
            ..ReportPart::default()
        }
    }

    fn reasons(m: &ProgressReport, thresholds: &Thresholds) -> Vec<Reason> {
        reasons(m, thresholds)
    }
}
