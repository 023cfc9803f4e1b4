//! The metrics of Du, Negenborn, Reppa (2022), section 4.2, and the checks added here,
//! as pure functions of time series (no I/O, no dataframes), so each can be tested on
//! synthetic data with a known answer.
//!
//! Each metric of the plant log has two forms: the batch formula on whole series (the
//! definition, e.g. [`settling_time`]) and an incremental tracker with O(1) state fed one
//! plant step at a time while the log streams by (e.g. [`SettlingTracker`]); the tests
//! check that both agree on random data.

use std::borrow::Cow;

use serde::{Deserialize, Serialize};

use crate::geometry::{dist, wrap};
use crate::run::Bounds;

/// Pose and velocity series of one vessel (NED; body velocities), borrowed from a
/// DataFrame where possible.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct VesselTrack<'a> {
    /// North, m.
    pub x: Cow<'a, [f64]>,
    /// East, m.
    pub y: Cow<'a, [f64]>,
    /// Heading, rad.
    pub psi: Cow<'a, [f64]>,
    /// Surge, m/s.
    pub u: Cow<'a, [f64]>,
    /// Sway, m/s.
    pub v: Cow<'a, [f64]>,
    /// Yaw rate, rad/s.
    pub r: Cow<'a, [f64]>,
}

impl VesselTrack<'_> {
    /// Number of samples.
    #[must_use]
    pub fn len(&self) -> usize {
        self.x.len()
    }

    /// True when empty.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }
}

/// Median, 99th percentile and maximum (nearest-rank percentiles), ignoring NaN.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Stats {
    /// Median (nearest rank: the value at rank ceil(0.5 n)).
    pub median: f64,
    /// 99th percentile (the value at rank ceil(0.99 n)).
    pub p99: f64,
    /// Maximum.
    pub max: f64,
    /// Mean.
    pub mean: f64,
    /// Values counted.
    pub count: usize,
}

/// [`Stats`] of `values`; `None` when there is no finite value.
#[must_use]
pub fn stats(values: &[f64]) -> Option<Stats> {
    let mut v: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len();
    let rank = |q: f64| -> f64 {
        let k = ((q * n as f64).ceil() as usize).clamp(1, n);
        v[k - 1]
    };
    Some(Stats {
        median: rank(0.5),
        p99: rank(0.99),
        max: v[n - 1],
        mean: v.iter().sum::<f64>() / n as f64,
        count: n,
    })
}

/// Tolerances of the paper's settling time (section 4.2.3).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SettleCriteria {
    /// Distance to the destination, m: half the ship length.
    pub position_m: f64,
    /// Heading error, rad: 3 deg.
    pub heading_rad: f64,
    /// |u| and |v| bound, m/s: 0.01.
    pub speed_m_s: f64,
    /// |r| bound, rad/s: 0.01.
    pub yaw_rate_rad_s: f64,
}

impl SettleCriteria {
    /// The paper's criteria for a ship of length `ship_length`.
    #[must_use]
    pub fn paper(ship_length: f64) -> Self {
        SettleCriteria {
            position_m: ship_length / 2.0,
            heading_rad: 3f64.to_radians(),
            speed_m_s: 0.01,
            yaw_rate_rad_s: 0.01,
        }
    }
}

/// Settling time (Du et al. 2022, section 4.2.3): the first time after which the ship
/// stays within half its length of the destination, within 3 deg of the destination
/// heading, with |u|, |v| < 0.01 m/s and |r| < 0.01 rad/s, to the end of the log.
/// `None` if the last sample does not meet the criteria (never settled, or left again).
#[must_use]
pub fn settling_time(
    t: &[f64],
    ship: &VesselTrack<'_>,
    destination: [f64; 3],
    c: SettleCriteria,
) -> Option<f64> {
    let n = t.len().min(ship.len());
    let ok = |i: usize| {
        settled(
            [
                ship.x[i],
                ship.y[i],
                ship.psi[i],
                ship.u[i],
                ship.v[i],
                ship.r[i],
            ],
            destination,
            c,
        )
    };
    let mut first = None;
    for i in (0..n).rev() {
        if ok(i) {
            first = Some(i);
        } else {
            break;
        }
    }
    first.map(|i| t[i])
}

/// True when the ship's state `[x, y, psi, u, v, r]` meets the settling criteria `c` for
/// `destination` (Du et al. 2022, section 4.2.3); a value that is not finite does not.
#[must_use]
pub fn settled(state: [f64; 6], destination: [f64; 3], c: SettleCriteria) -> bool {
    let [x, y, psi, u, v, r] = state;
    dist([x, y], [destination[0], destination[1]]) < c.position_m
        && wrap(psi - destination[2]).abs() < c.heading_rad
        && u.abs() < c.speed_m_s
        && v.abs() < c.speed_m_s
        && r.abs() < c.yaw_rate_rad_s
}

/// [`settling_time`] (Du et al. 2022, section 4.2.3) one sample at a time: the time since
/// which every sample met the criteria (O(1) state: reset by each sample that does not).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct SettlingTracker {
    since: Option<f64>,
}

impl SettlingTracker {
    /// The sample at `t` met the criteria (`ok`) or not.
    pub fn push(&mut self, t: f64, ok: bool) {
        if !ok {
            self.since = None;
        } else if self.since.is_none() {
            self.since = Some(t);
        }
    }

    /// The settling time so far (`None` if the last sample did not meet the criteria).
    #[must_use]
    pub fn value(&self) -> Option<f64> {
        self.since
    }
}

/// The largest value and its time, one sample at a time; the last of equal maxima wins, as
/// `Iterator::max_by` (used for [`max_elongation_error`], Du et al. 2022, section 4.2.3).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ArgMax {
    best: Option<(f64, f64)>,
}

impl ArgMax {
    /// A sample `value` at `t` (the caller leaves out what the batch formula filters).
    pub fn push(&mut self, value: f64, t: f64) {
        if self
            .best
            .is_none_or(|(b, _)| value.total_cmp(&b) != std::cmp::Ordering::Less)
        {
            self.best = Some((value, t));
        }
    }

    /// `(max, t)`.
    #[must_use]
    pub fn value(&self) -> Option<(f64, f64)> {
        self.best
    }
}

/// The smallest value and its time, one sample at a time; the first of equal minima wins, as
/// `Iterator::min_by` (used for [`min_with_time`], the minimum of Du et al. 2022, eq. (30)).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ArgMin {
    best: Option<(f64, f64)>,
}

impl ArgMin {
    /// A sample `value` at `t` (the caller leaves out what the batch formula filters).
    pub fn push(&mut self, value: f64, t: f64) {
        if self
            .best
            .is_none_or(|(b, _)| value.total_cmp(&b) == std::cmp::Ordering::Less)
        {
            self.best = Some((value, t));
        }
    }

    /// `(min, t)`.
    #[must_use]
    pub fn value(&self) -> Option<(f64, f64)> {
        self.best
    }
}

/// [`travel`] (the ship's total travelling distance, Du et al. 2022, section 4.2.3) one
/// position at a time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TravelTracker {
    prev: Option<(f64, f64)>,
    sum: f64,
}

impl Default for TravelTracker {
    fn default() -> Self {
        // `Iterator::sum` of f64 starts at -0.0: the same additions in the same order give
        // the same bits.
        TravelTracker {
            prev: None,
            sum: -0.0,
        }
    }
}

impl TravelTracker {
    /// The next position (North, East), m.
    pub fn push(&mut self, x: f64, y: f64) {
        if let Some((px, py)) = self.prev {
            let d = (x - px).hypot(y - py);
            if d.is_finite() {
                self.sum += d;
            }
        }
        self.prev = Some((x, y));
    }

    /// Length of the polyline so far, m.
    #[must_use]
    pub fn value(&self) -> f64 {
        self.sum
    }
}

/// Largest relative elongation error `|l - l_tow| / l_tow` (Du et al. 2022, section
/// 4.2.3) and when it happened: `(fraction, t)`.
#[must_use]
pub fn max_elongation_error(t: &[f64], length: &[f64], desired: f64) -> Option<(f64, f64)> {
    t.iter()
        .zip(length)
        .filter(|(_, l)| l.is_finite())
        .map(|(&t, &l)| ((l - desired).abs() / desired, t))
        .max_by(|a, b| a.0.total_cmp(&b.0))
}

/// Length of the polyline through the positions, m (the paper's "total travelling
/// distance" of the ship, Table 7 discussion).
#[must_use]
pub fn travel(x: &[f64], y: &[f64]) -> f64 {
    x.windows(2)
        .zip(y.windows(2))
        .map(|(xs, ys)| (xs[1] - xs[0]).hypot(ys[1] - ys[0]))
        .filter(|d| d.is_finite())
        .sum()
}

/// Smallest value and its time: `(min, t)`.
#[must_use]
pub fn min_with_time(t: &[f64], d: &[f64]) -> Option<(f64, f64)> {
    t.iter()
        .zip(d)
        .filter(|(_, d)| d.is_finite())
        .map(|(&t, &d)| (d, t))
        .min_by(|a, b| a.0.total_cmp(&b.0))
}

/// One hull-overlap event: a maximal run of consecutive overlapping samples of one pair.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CollisionEvent {
    /// First body (`ship`, `tug1`, `tug2`).
    pub a: String,
    /// Second body (a vessel or an obstacle's name).
    pub b: String,
    /// First overlapping sample, s.
    pub t_start_s: f64,
    /// Last overlapping sample, s.
    pub t_end_s: f64,
    /// Overlapping samples.
    pub samples: usize,
}

/// The overlap events of one pair from its per-sample overlap flags (rising edges start an
/// event, the run's last sample ends it).
#[must_use]
pub fn overlap_events(t: &[f64], overlap: &[bool], a: &str, b: &str) -> Vec<CollisionEvent> {
    let mut events = Vec::new();
    let mut current: Option<CollisionEvent> = None;
    for (&t, &o) in t.iter().zip(overlap) {
        match (&mut current, o) {
            (Some(e), true) => {
                e.t_end_s = t;
                e.samples += 1;
            }
            (None, true) => {
                current = Some(CollisionEvent {
                    a: a.to_owned(),
                    b: b.to_owned(),
                    t_start_s: t,
                    t_end_s: t,
                    samples: 1,
                });
            }
            (Some(_), false) => events.extend(current.take()),
            (None, false) => {}
        }
    }
    events.extend(current);
    events
}

/// [`overlap_events`] one sample at a time, for one pair.
#[derive(Debug, Clone, PartialEq)]
pub struct OverlapTracker {
    a: String,
    b: String,
    current: Option<CollisionEvent>,
    events: Vec<CollisionEvent>,
}

impl OverlapTracker {
    /// The tracker of the pair `a`, `b`.
    #[must_use]
    pub fn new(a: &str, b: &str) -> Self {
        OverlapTracker {
            a: a.to_owned(),
            b: b.to_owned(),
            current: None,
            events: Vec::new(),
        }
    }

    /// The sample at `t` overlaps or not.
    pub fn push(&mut self, t: f64, overlap: bool) {
        match (&mut self.current, overlap) {
            (Some(e), true) => {
                e.t_end_s = t;
                e.samples += 1;
            }
            (None, true) => {
                self.current = Some(CollisionEvent {
                    a: self.a.clone(),
                    b: self.b.clone(),
                    t_start_s: t,
                    t_end_s: t,
                    samples: 1,
                });
            }
            (Some(_), false) => self.events.extend(self.current.take()),
            (None, false) => {}
        }
    }

    /// The events, the one still running at the end included.
    #[must_use]
    pub fn finish(mut self) -> Vec<CollisionEvent> {
        self.events.extend(self.current.take());
        self.events
    }
}

/// Violations of one bound.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
pub struct Violations {
    /// Samples (or sample pairs, for rates) outside the bound.
    pub count: usize,
    /// Samples checked.
    pub checked: usize,
    /// Largest excess over the bound (in the bound's unit: N, N/s, deg, deg/s, N or N m).
    pub worst_excess: f64,
    /// Time of the first violation, s.
    pub first_t_s: Option<f64>,
}

impl Violations {
    /// Checks `magnitude` at `t` against `bound`.
    pub fn check(&mut self, t: f64, magnitude: f64, bound: f64) {
        self.check_excess(t, magnitude - bound, bound);
    }

    /// The violations of `self` and then `next`, as if checked in that order.
    #[must_use]
    pub fn then(self, next: Violations) -> Violations {
        Violations {
            count: self.count + next.count,
            checked: self.checked + next.checked,
            worst_excess: self.worst_excess.max(next.worst_excess),
            first_t_s: self.first_t_s.or(next.first_t_s),
        }
    }

    fn check_excess(&mut self, t: f64, excess: f64, bound: f64) {
        self.checked += 1;
        // Tolerance: rounding of the logged decimal text and of the solver's bound.
        if excess > 1e-9 + 1e-6 * bound.abs() {
            self.count += 1;
            self.worst_excess = self.worst_excess.max(excess);
            if self.first_t_s.is_none() {
                self.first_t_s = Some(t);
            }
        }
    }
}

/// Commands outside the bounds of Du et al. (2022), Tables 2 and 3 (eq. (17)-(21)).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
pub struct BoundReport {
    /// Commanded tension outside `[min, max]`, both lines (N).
    pub tension: Violations,
    /// |change of commanded tension| / dt above the rate bound (N/s).
    pub tension_rate: Violations,
    /// |commanded towing angle| above `alpha_max` (deg).
    pub towing_angle: Violations,
    /// |change of towing angle| / dt above the rate bound (deg/s).
    pub towing_angle_rate: Violations,
    /// A commanded tug thrust component above its limit (controller log, per sample).
    pub tug_thrust_command: Violations,
    /// A tug thrust component the plant received above its limit (plant log, per step).
    pub tug_thrust_input: Violations,
    /// Sum of the counts.
    pub total: usize,
}

/// Commands of the controller, per sample.
#[derive(Debug, Clone, Copy)]
pub struct CommandSeries<'a> {
    /// Sample times, s.
    pub t: &'a [f64],
    /// Commanded tensions of lines 1 and 2, N.
    pub tension: [&'a [f64]; 2],
    /// Towing angles of lines 1 and 2, rad.
    pub angle: [&'a [f64]; 2],
    /// Thrust of tug 1 and tug 2: surge N, sway N, yaw N m.
    pub thrust: [[&'a [f64]; 3]; 2],
}

/// The plant's received thrusts: times (s) and tug 1, tug 2 surge N, sway N, yaw N m.
pub type InputSeries<'a> = (&'a [f64], [[&'a [f64]; 3]; 2]);

/// Checks the controller's commands (per sample) and the plant's received thrusts (per
/// step) against `bounds`. Rates are taken between consecutive samples, so the first
/// sample's change from the pre-start value is not checked (it is not logged).
#[must_use]
pub fn check_bounds(
    cmd: Option<CommandSeries<'_>>,
    inputs: Option<InputSeries<'_>>,
    bounds: &Bounds,
) -> BoundReport {
    let mut rep = BoundReport::default();
    if let Some(c) = cmd {
        let n = c.t.len();
        for line in 0..2 {
            let f = c.tension[line];
            let a = c.angle[line];
            for i in 0..n.min(f.len()).min(a.len()) {
                let t = c.t[i];
                let excess = (f[i] - bounds.max_tension_n).max(bounds.min_tension_n - f[i]);
                rep.tension.check_excess(t, excess, bounds.max_tension_n);
                rep.towing_angle.check(
                    t,
                    a[i].abs().to_degrees(),
                    bounds.max_towing_angle_rad.to_degrees(),
                );
                if i > 0 {
                    let dt = c.t[i] - c.t[i - 1];
                    if dt > 0.0 {
                        rep.tension_rate.check(
                            t,
                            (f[i] - f[i - 1]).abs() / dt,
                            bounds.tension_rate_n_per_s,
                        );
                        rep.towing_angle_rate.check(
                            t,
                            ((a[i] - a[i - 1]).abs() / dt).to_degrees(),
                            bounds.angle_rate_rad_per_s.to_degrees(),
                        );
                    }
                }
            }
        }
        for tug in c.thrust {
            for (k, series) in tug.iter().enumerate() {
                for (i, v) in series.iter().enumerate().take(n) {
                    rep.tug_thrust_command
                        .check(c.t[i], v.abs(), bounds.max_thrust[k]);
                }
            }
        }
    }
    if let Some((t, thrust)) = inputs {
        for tug in thrust {
            for (k, series) in tug.iter().enumerate() {
                for (i, v) in series.iter().enumerate().take(t.len()) {
                    rep.tug_thrust_input
                        .check(t[i], v.abs(), bounds.max_thrust[k]);
                }
            }
        }
    }
    rep.total = rep.tension.count
        + rep.tension_rate.count
        + rep.towing_angle.count
        + rep.towing_angle_rate.count
        + rep.tug_thrust_command.count
        + rep.tug_thrust_input.count;
    rep
}

impl BoundReport {
    /// The report with `inputs` as the received thrusts' check, the total updated.
    #[must_use]
    pub fn with_inputs(mut self, inputs: Violations) -> Self {
        self.tug_thrust_input = inputs;
        self.total = self.tension.count
            + self.tension_rate.count
            + self.towing_angle.count
            + self.towing_angle_rate.count
            + self.tug_thrust_command.count
            + self.tug_thrust_input.count;
        self
    }
}

/// The check of the plant's received thrusts of [`check_bounds`] against the thrust limits
/// (Du et al. 2022, Table 2; eq. (17)-(21)), one plant step at a time (per tug and
/// component, merged in the batch check's order).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct InputBoundCheck {
    per: [[Violations; 3]; 2],
    limits: [f64; 3],
}

impl InputBoundCheck {
    /// Checks against `bounds.max_thrust`.
    #[must_use]
    pub fn new(bounds: &Bounds) -> Self {
        InputBoundCheck {
            per: Default::default(),
            limits: bounds.max_thrust,
        }
    }

    /// The thrusts of tug 1 and tug 2 (surge N, sway N, yaw N m) received at `t`.
    pub fn push(&mut self, t: f64, thrust: [[f64; 3]; 2]) {
        for (tug, values) in thrust.iter().enumerate() {
            for (k, v) in values.iter().enumerate() {
                self.per[tug][k].check(t, v.abs(), self.limits[k]);
            }
        }
    }

    /// The violations of every component.
    #[must_use]
    pub fn result(&self) -> Violations {
        self.per
            .iter()
            .flatten()
            .fold(Violations::default(), |acc, v| acc.then(*v))
    }
}

/// Rates of change per second between consecutive samples (`NaN` first), for the plots.
#[must_use]
pub fn rates(t: &[f64], v: &[f64]) -> Vec<f64> {
    let mut out = Vec::with_capacity(v.len());
    for i in 0..v.len().min(t.len()) {
        if i == 0 {
            out.push(f64::NAN);
        } else {
            let dt = t[i] - t[i - 1];
            out.push(if dt > 0.0 {
                (v[i] - v[i - 1]) / dt
            } else {
                f64::NAN
            });
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn track(n: usize, f: impl Fn(usize) -> [f64; 6]) -> VesselTrack<'static> {
        let rows: Vec<[f64; 6]> = (0..n).map(f).collect();
        let c = |k: usize| Cow::Owned(rows.iter().map(|r| r[k]).collect());
        VesselTrack {
            x: c(0),
            y: c(1),
            psi: c(2),
            u: c(3),
            v: c(4),
            r: c(5),
        }
    }

    #[test]
    fn stats_nearest_rank() {
        let v: Vec<f64> = (1..=100).map(f64::from).collect();
        let s = stats(&v).expect("stats");
        assert_eq!(s.median, 50.0);
        assert_eq!(s.p99, 99.0);
        assert_eq!(s.max, 100.0);
        assert_eq!(s.count, 100);
        assert!(stats(&[f64::NAN]).is_none());
    }

    #[test]
    fn settles_at_known_time() {
        // Approaches the destination (0, 0, 180 deg) at 0.05 m/s, stops at t = 100 s 0.2 m
        // short, then sits still; a brief excursion at t = 60 s must not count.
        let dt = 0.1;
        let n = 2000;
        let t: Vec<f64> = (0..n).map(|i| i as f64 * dt).collect();
        let dest = [0.0, 0.0, std::f64::consts::PI];
        let ship = track(n, |i| {
            let t = i as f64 * dt;
            let moving = t < 100.0;
            let x = if moving { 5.2 - 0.05 * t } else { 0.2 };
            let u = if moving { 0.05 } else { 0.0 };
            [x, 0.0, std::f64::consts::PI, u, 0.0, 0.0]
        });
        let c = SettleCriteria::paper(1.255);
        let ts = settling_time(&t, &ship, dest, c).expect("settles");
        assert!((ts - 100.0).abs() < 1e-9, "{ts}");
        // Heading 4 deg off after 150 s: it settles only when the heading comes back.
        let ship2 = track(n, |i| {
            let t = i as f64 * dt;
            let psi = if (150.0..160.0).contains(&t) {
                std::f64::consts::PI - 4f64.to_radians()
            } else {
                std::f64::consts::PI
            };
            [0.1, 0.0, psi, 0.0, 0.0, 0.0]
        });
        let ts2 = settling_time(&t, &ship2, dest, c).expect("settles");
        assert!((ts2 - 160.0).abs() < 1e-9, "{ts2}");
        // Still moving at the end: never settled.
        let ship3 = track(n, |_| [0.1, 0.0, std::f64::consts::PI, 0.02, 0.0, 0.0]);
        assert!(settling_time(&t, &ship3, dest, c).is_none());
    }

    #[test]
    fn elongation_known() {
        let t = [0.0, 1.0, 2.0, 3.0];
        let l = [1.0, 1.0579, 0.95, 1.01];
        let (e, at) = max_elongation_error(&t, &l, 1.0).expect("some");
        assert!((e - 0.0579).abs() < 1e-12);
        assert_eq!(at, 1.0);
    }

    #[test]
    fn travel_of_a_square() {
        let x = [0.0, 1.0, 1.0, 0.0];
        let y = [0.0, 0.0, 2.0, 2.0];
        assert!((travel(&x, &y) - 4.0).abs() < 1e-12);
    }

    #[test]
    fn events_from_flags() {
        let t: Vec<f64> = (0..10).map(f64::from).collect();
        let o = [
            false, true, true, false, false, true, false, false, true, true,
        ];
        let e = overlap_events(&t, &o, "ship", "a");
        assert_eq!(e.len(), 3);
        assert_eq!((e[0].t_start_s, e[0].t_end_s, e[0].samples), (1.0, 2.0, 2));
        assert_eq!((e[2].t_start_s, e[2].t_end_s), (8.0, 9.0));
    }

    #[test]
    fn bounds_found() {
        let t = [0.0, 1.0, 2.0, 3.0];
        let f1 = [1.0, 1.3, 1.7, 3.2]; // rate 0.4 at t=2, 1.5 at t=3; 3.2 > 3
        let f2 = [1.0, 1.0, 1.0, -0.1]; // below 0 at t=3, rate 1.1
        let a1 = [0.0, 0.05, 0.1, 0.6]; // 0.6 rad = 34 deg, rate 28.6 deg/s
        let a2 = [0.0; 4];
        let z = [0.0; 4];
        let big = [0.0, 10.5, 0.0, 0.0];
        let cmd = CommandSeries {
            t: &t,
            tension: [&f1, &f2],
            angle: [&a1, &a2],
            thrust: [[&big, &z, &z], [&z, &z, &z]],
        };
        let r = check_bounds(Some(cmd), None, &Bounds::default());
        assert_eq!(r.tension.count, 2);
        assert!((r.tension.worst_excess - 0.2).abs() < 1e-9);
        assert_eq!(r.tension_rate.count, 3);
        assert_eq!(r.towing_angle.count, 1);
        assert_eq!(r.towing_angle_rate.count, 1);
        assert_eq!(r.tug_thrust_command.count, 1);
        assert_eq!(r.total, 8);
        // Within every bound: nothing.
        let ok = [1.0, 1.2, 1.4, 1.6];
        let cmd = CommandSeries {
            t: &t,
            tension: [&ok, &ok],
            angle: [&a2, &a2],
            thrust: [[&z, &z, &z], [&z, &z, &z]],
        };
        assert_eq!(check_bounds(Some(cmd), None, &Bounds::default()).total, 0);
    }

    use crate::decimate::tests::rng;

    #[test]
    fn incremental_metrics_equal_the_batch_formulas_on_random_data() {
        for seed in 0..200u64 {
            let mut r = rng(seed);
            let n = (r() * 400.0) as usize;
            let t: Vec<f64> = (0..n).map(|i| i as f64 * 0.1).collect();
            // Values on a coarse grid (ties), with NaN now and then.
            let mut val = |scale: f64| {
                if r() < 0.03 {
                    f64::NAN
                } else {
                    (r() * 8.0).floor() * scale
                }
            };
            // Near the destination (0, 0, 0), mostly inside the criteria.
            let rows: Vec<[f64; 6]> = (0..n)
                .map(|_| {
                    [
                        val(0.1),
                        val(0.1),
                        val(0.01),
                        val(0.002),
                        val(0.002),
                        val(0.002),
                    ]
                })
                .collect();
            let ship = track(n, |i| rows[i]);
            let c = SettleCriteria::paper(1.255);
            let dest = [0.0, 0.0, 0.0];
            let mut settle = SettlingTracker::default();
            let mut trav = TravelTracker::default();
            let mut emax = ArgMax::default();
            let mut dmin = ArgMin::default();
            let mut ov = OverlapTracker::new("ship", "a");
            let flags: Vec<bool> = ship.x.iter().map(|x| *x < 0.35).collect();
            for i in 0..n {
                let s = [
                    ship.x[i],
                    ship.y[i],
                    ship.psi[i],
                    ship.u[i],
                    ship.v[i],
                    ship.r[i],
                ];
                settle.push(t[i], settled(s, dest, c));
                trav.push(ship.x[i], ship.y[i]);
                if ship.y[i].is_finite() {
                    emax.push((ship.y[i] - 0.3).abs() / 0.3, t[i]);
                    dmin.push(ship.y[i], t[i]);
                }
                ov.push(t[i], flags[i]);
            }
            assert_eq!(
                settle.value(),
                settling_time(&t, &ship, dest, c),
                "seed {seed}"
            );
            assert_eq!(trav.value().to_bits(), travel(&ship.x, &ship.y).to_bits());
            assert_eq!(emax.value(), max_elongation_error(&t, &ship.y, 0.3));
            assert_eq!(dmin.value(), min_with_time(&t, &ship.y));
            assert_eq!(ov.finish(), overlap_events(&t, &flags, "ship", "a"));
        }
    }

    #[test]
    fn input_check_per_step_equals_the_batch_check() {
        for seed in 0..100u64 {
            let mut r = rng(seed);
            let n = (r() * 300.0) as usize;
            let t: Vec<f64> = (0..n).map(|i| i as f64 * 0.1).collect();
            let cols: Vec<Vec<f64>> = (0..6)
                .map(|_| (0..n).map(|_| (r() - 0.5) * 22.0).collect())
                .collect();
            let mut inc = InputBoundCheck::new(&Bounds::default());
            for i in 0..n {
                inc.push(
                    t[i],
                    [
                        [cols[0][i], cols[1][i], cols[2][i]],
                        [cols[3][i], cols[4][i], cols[5][i]],
                    ],
                );
            }
            let thrust = [
                [cols[0].as_slice(), &cols[1], &cols[2]],
                [cols[3].as_slice(), &cols[4], &cols[5]],
            ];
            let batch = check_bounds(None, Some((&t, thrust)), &Bounds::default());
            assert_eq!(inc.result(), batch.tug_thrust_input, "seed {seed}");
            let merged = BoundReport::default().with_inputs(inc.result());
            assert_eq!(merged, batch);
        }
    }
}
