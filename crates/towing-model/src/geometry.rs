//! Plane geometry shared by the plant, the MPC and the analyzer: a hull's footprint
//! ([`HullRect`]), the route as a polyline ([`Polyline`]) and the waterway around it
//! ([`Lane`]: the route plus its half width, the bank on either side).
//!
//! Points are `[north, east]` in m, headings from North, clockwise (NED, Fossen 2021,
//! section 2.2; `paper/NOTES.md` section 1: a body's forward unit vector is
//! `(cos psi, sin psi)`, its starboard unit vector `(-sin psi, cos psi)`).
//!
//! The waterway is the set of points within `half_width` of the route polyline (the
//! distance to the nearest point of any segment, so the lane has round ends and round
//! outer corners): the paper's `d_2` (Du et al. 2022, section 3.1, `theta_max =
//! arctan(d_2 / d_1)`) read as a bank on either side of the route. A hull is beyond the
//! bank when a corner of its footprint is ([`Lane::hull_excess`]).

use serde::{Deserialize, Serialize};

use crate::scenario::{Route, Scenario};

/// A point `[north, east]`, m.
pub type Point = [f64; 2];

/// Euclidean distance.
#[must_use]
pub fn dist(a: Point, b: Point) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// Coordinates of `p` in the frame of a course line through `origin` with direction
/// `course` (rad from North, clockwise): `(along, across)`, along positive ahead, across
/// positive to starboard of the line.
#[must_use]
pub fn line_coordinates(origin: Point, course: f64, p: Point) -> (f64, f64) {
    let (s, c) = course.sin_cos();
    let (dn, de) = (p[0] - origin[0], p[1] - origin[1]);
    (dn * c + de * s, -dn * s + de * c)
}

/// How far `p` lies to starboard of the line from `a` through `b` (m, negative to port),
/// with the line's unit starboard normal; `None` when `a` and `b` coincide. The
/// guidance's offset held while altered, the controller's lift of the tracked point to
/// it and the analyzer's offset from the route all measure it so.
#[must_use]
pub fn starboard_offset(a: Point, b: Point, p: Point) -> Option<(f64, Point)> {
    let r = (b[0] - a[0]).hypot(b[1] - a[1]);
    if r.is_nan() || r <= 0.0 {
        return None;
    }
    let n = [-(b[1] - a[1]) / r, (b[0] - a[0]) / r];
    Some(((p[0] - a[0]) * n[0] + (p[1] - a[1]) * n[1], n))
}

/// Own ship's heading line and a target at one sample: own position, own heading (rad from
/// North, clockwise), the target's position.
pub type LineSighting = (Point, f64, Point);

/// COLREGS Rule 8(d), a crossing target *past*: between two samples the target went from
/// one side of own ship's heading line to the other (each sample's line through that
/// sample's pose), lies ahead of her, and its own motion made the crossing: its
/// displacement across the earlier sample's line, held still, is in the crossing's
/// direction and at least half of the change of its side. The rest of the change is own
/// ship's turn and sideways motion, which alone never make a crossing (a tow turning away
/// from a target sweeps her heading line across it). The share is a ratio of rates, so
/// the verdict does not depend on where the samples fall: with the target and the line
/// closing on each other at similar rates, whether the target crosses the earlier line
/// held still within one step depends on the sampling phase (an analyzer at 0.1 s and a
/// controller at 1 s disagreed on random-12-0062). The one test of the guidance
/// (`towing_guidance::Sighting`) and of the analyzer's Rule 8 check.
#[must_use]
pub fn crossed_ahead(before: LineSighting, now: LineSighting) -> bool {
    let (origin0, course0, target0) = before;
    let (origin1, course1, target1) = now;
    let (_, side0) = line_coordinates(origin0, course0, target0);
    let (along, side1) = line_coordinates(origin1, course1, target1);
    let (_, own) = line_coordinates(origin0, course0, target1);
    let own_change = own - side0;
    let change = side1 - side0;
    side0 != 0.0
        && side0 * side1 <= 0.0
        && along > 0.0
        && own_change * change > 0.0
        && own_change.abs() >= 0.5 * change.abs()
}

/// COLREGS Rule 8(d), a target *drawing away*: its own velocity `v_target` opens the
/// range from own ship (`v_target . (p_target - p_own) > 0`) and its track no longer
/// meets own ship's heading line (through `own` along `course`) ahead of her: it moves
/// away from the line on the side it lies, or parallel to it, or meets it astern of her.
/// Only the target's motion is used, so neither her braking nor her sternway makes it.
/// With the distance at which an encounter begins, the "gone" test of past and clear;
/// the one test of the guidance's release (`towing_guidance`) and of the analyzer's
/// Rule 8 check.
#[must_use]
pub fn drawing_away(own: Point, course: f64, target: Point, v_target: Point) -> bool {
    let (along, side) = line_coordinates(own, course, target);
    let (v_along, drift) = line_coordinates([0.0, 0.0], course, v_target);
    let opening = v_target[0] * (target[0] - own[0]) + v_target[1] * (target[1] - own[1]);
    let meets_ahead = drift != 0.0 && {
        let t = -side / drift;
        t >= 0.0 && along + t * v_along > 0.0
    };
    opening > 0.0 && !meets_ahead
}

/// A target *abaft the beam and opening*: it lies behind own ship's beam line (through
/// `own` square to `heading`) and the relative velocity `v_target - v_own` opens the
/// range (`(p_target - p_own) . (v_target - v_own) > 0`): past its closest approach and
/// drawing aft. COLREGS Rule 8(d)'s "past" in any situation (`docs/colregs.md`,
/// section 2); the analyzer's Rule 8 check and the controller's distance-cost mask
/// (section 4) use this one test.
#[must_use]
pub fn abaft_and_opening(
    own: Point,
    heading: f64,
    v_own: Point,
    target: Point,
    v_target: Point,
) -> bool {
    let (along, _) = line_coordinates(own, heading, target);
    let (dx, dy) = (target[0] - own[0], target[1] - own[1]);
    along < 0.0 && dx * (v_target[0] - v_own[0]) + dy * (v_target[1] - v_own[1]) > 0.0
}

/// Body point `(bx forward, by starboard)` of a vessel at `(x, y, psi)`, in NED
/// (the rotation `R(psi)` of Fossen 2021, eq. (2.18), in the plane).
#[must_use]
pub fn body_to_ned(x: f64, y: f64, psi: f64, bx: f64, by: f64) -> Point {
    let (s, c) = psi.sin_cos();
    [x + bx * c - by * s, y + bx * s + by * c]
}

/// A hull's footprint: a rectangle `length` x `width` centred at the body origin (the
/// position the state gives) and aligned with the heading. The vessels' data give
/// length and beam ([`crate::VesselData`]); the rectangle is the footprint every
/// judgement of contact uses (hull overlaps, groundings).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HullRect {
    /// Length overall (m).
    pub length: f64,
    /// Beam (m).
    pub width: f64,
}

impl HullRect {
    /// The footprint of a `length` x `width` hull.
    #[must_use]
    pub fn new(length: f64, width: f64) -> HullRect {
        HullRect { length, width }
    }

    /// The footprint of a vessel's data.
    #[must_use]
    pub fn of(data: &crate::VesselData) -> HullRect {
        HullRect::new(data.length, data.width)
    }

    /// The corners at the pose `(x, y, psi)`, in order bow-starboard, bow-port,
    /// stern-port, stern-starboard.
    #[must_use]
    pub fn corners(&self, x: f64, y: f64, psi: f64) -> [Point; 4] {
        let (a, b) = (self.length / 2.0, self.width / 2.0);
        [
            body_to_ned(x, y, psi, a, b),
            body_to_ned(x, y, psi, a, -b),
            body_to_ned(x, y, psi, -a, -b),
            body_to_ned(x, y, psi, -a, b),
        ]
    }

    /// The footprint's radius about the body origin (the corners' distance,
    /// `hypot(L/2, B/2)`): every point of the hull is within it of the position, at
    /// any heading.
    #[must_use]
    pub fn radius(&self) -> f64 {
        (self.length / 2.0).hypot(self.width / 2.0)
    }
}

/// The fraction along `a`-`b` (in `[0, 1]`) of the point of the segment nearest to `p`,
/// and the distance to it. A zero-length segment is its point.
#[must_use]
pub fn segment_projection(p: Point, a: Point, b: Point) -> (f64, f64) {
    let ab = [b[0] - a[0], b[1] - a[1]];
    let len2 = ab[0] * ab[0] + ab[1] * ab[1];
    let f = if len2 > 0.0 {
        (((p[0] - a[0]) * ab[0] + (p[1] - a[1]) * ab[1]) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let q = [a[0] + f * ab[0], a[1] + f * ab[1]];
    (f, dist(p, q))
}

/// A point's nearest point on a [`Polyline`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Projection {
    /// Arc length of the nearest point from the polyline's start, m.
    pub s: f64,
    /// Distance from the polyline, m.
    pub distance: f64,
    /// The nearest segment (points `segment`, `segment + 1`; 0 for a one-point
    /// polyline).
    pub segment: usize,
    /// The nearest point.
    pub point: Point,
}

/// The route as a polyline through its points (origin, waypoints, destination), with
/// the arc length at each point.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(from = "Vec<Point>", into = "Vec<Point>")]
pub struct Polyline {
    points: Vec<Point>,
    /// Arc length at each point, m (`cum[0] = 0`).
    cum: Vec<f64>,
}

impl From<Vec<Point>> for Polyline {
    fn from(points: Vec<Point>) -> Polyline {
        let mut cum = Vec::with_capacity(points.len());
        let mut total = 0.0;
        for (k, p) in points.iter().enumerate() {
            if k > 0 {
                total += dist(points[k - 1], *p);
            }
            cum.push(total);
        }
        Polyline { points, cum }
    }
}

impl From<Polyline> for Vec<Point> {
    fn from(p: Polyline) -> Vec<Point> {
        p.points
    }
}

impl Polyline {
    /// The polyline through `points`; `None` without a point.
    #[must_use]
    pub fn new(points: Vec<Point>) -> Option<Polyline> {
        (!points.is_empty()).then(|| Polyline::from(points))
    }

    /// The polyline through the positions of route points `[north, east, heading]`;
    /// `None` without a point.
    #[must_use]
    pub fn from_route(route: &[[f64; 3]]) -> Option<Polyline> {
        Polyline::new(route.iter().map(|p| [p[0], p[1]]).collect())
    }

    /// The polyline of a scenario's route.
    #[must_use]
    pub fn of_route(route: &Route) -> Polyline {
        Polyline::from(route.points().map(|p| [p.x, p.y]).collect::<Vec<_>>())
    }

    /// The points.
    #[must_use]
    pub fn points(&self) -> &[Point] {
        &self.points
    }

    /// Total length, m.
    #[must_use]
    pub fn length(&self) -> f64 {
        self.cum.last().copied().unwrap_or(0.0)
    }

    /// The last point (the destination).
    #[must_use]
    pub fn end(&self) -> Point {
        self.points[self.points.len() - 1]
    }

    /// The nearest point of any segment to `p` (the first segment on a tie). A
    /// one-point polyline projects every point onto that point (`s = 0`).
    #[must_use]
    pub fn project(&self, p: Point) -> Projection {
        let mut best = Projection {
            s: 0.0,
            distance: dist(p, self.points[0]),
            segment: 0,
            point: self.points[0],
        };
        for (k, w) in self.points.windows(2).enumerate() {
            let (f, d) = segment_projection(p, w[0], w[1]);
            if d < best.distance {
                best = Projection {
                    s: self.cum[k] + f * (self.cum[k + 1] - self.cum[k]),
                    distance: d,
                    segment: k,
                    point: [
                        w[0][0] + f * (w[1][0] - w[0][0]),
                        w[0][1] + f * (w[1][1] - w[0][1]),
                    ],
                };
            }
        }
        best
    }

    /// The point at arc length `s` along the polyline (clamped to `[0, length]`).
    #[must_use]
    pub fn point_at(&self, s: f64) -> Point {
        let s = s.clamp(0.0, self.length());
        let k = self
            .cum
            .partition_point(|&c| c < s)
            .clamp(1, self.points.len().max(2) - 1);
        match (self.points.get(k - 1), self.points.get(k)) {
            (Some(a), Some(b)) => {
                let span = self.cum[k] - self.cum[k - 1];
                let f = if span > 0.0 {
                    (s - self.cum[k - 1]) / span
                } else {
                    0.0
                };
                [a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1])]
            }
            _ => self.points[0],
        }
    }

    /// The course (rad from North, clockwise) of the manoeuvre of following the
    /// polyline, seen from `p`: the bearing from `p`'s nearest point on it to the point
    /// `lookahead` m farther along it, so a bend turns it over the `lookahead` before
    /// the bend; at the end, the last segment's course. `None` for a polyline without
    /// length. COLREGS Rule 17's "course" is this one, not the compass heading at the
    /// sighting (Windsor-Roanoke, 1908: "course and speed in following the nautical
    /// manoeuvre in which ... the vessel is at the time engaged"; Cockcroft and
    /// Lameijer, *A Guide to the Collision Avoidance Rules*, on Rule 17).
    #[must_use]
    pub fn course_ahead(&self, p: Point, lookahead: f64) -> Option<f64> {
        self.course_from(self.project(p).s, lookahead)
    }

    /// [`Polyline::course_ahead`] from the arc length `here` of a point's projection.
    #[must_use]
    pub fn course_from(&self, here: f64, lookahead: f64) -> Option<f64> {
        let length = self.length();
        if length.is_nan() || length <= 0.0 {
            return None;
        }
        let (from, to) = if here + 1e-9 < length {
            (
                self.point_at(here),
                self.point_at(here + lookahead.max(1e-6)),
            )
        } else {
            // At the end: the last segment of non-zero length.
            let last = self.cum.partition_point(|&c| c < length).max(1);
            (self.points[last - 1], self.end())
        };
        let (dn, de) = (to[0] - from[0], to[1] - from[1]);
        (dn != 0.0 || de != 0.0).then(|| de.atan2(dn))
    }

    /// Distance of `p` from the polyline (nearest point of any segment), m.
    #[must_use]
    pub fn distance(&self, p: Point) -> f64 {
        self.project(p).distance
    }

    /// The unit starboard normal of segment `k` (`(-sin chi, cos chi)` for the
    /// segment's course `chi`); `[0, 1]` for a zero-length segment or a one-point
    /// polyline.
    #[must_use]
    pub fn starboard_normal(&self, k: usize) -> Point {
        self.segment_offset(k, [0.0, 0.0])
            .map_or([0.0, 1.0], |(_, n)| n)
    }

    /// How far `p` lies to starboard of the projection `at`'s segment ([`starboard_offset`]);
    /// 0 for a zero-length segment or a one-point polyline.
    #[must_use]
    pub fn offset_from(&self, at: &Projection, p: Point) -> f64 {
        self.segment_offset(at.segment, p)
            .map_or(0.0, |(offset, _)| offset)
    }

    /// [`starboard_offset`] of `p` from segment `k`; `None` for a zero-length segment or
    /// none.
    fn segment_offset(&self, k: usize, p: Point) -> Option<(f64, Point)> {
        match (self.points.get(k), self.points.get(k + 1)) {
            (Some(&a), Some(&b)) => starboard_offset(a, b, p),
            _ => None,
        }
    }
}

/// The waterway: the route polyline and its half width (module docs).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Lane {
    /// The route.
    pub centre: Polyline,
    /// Distance from the route to the bank on either side, m (> 0).
    pub half_width: f64,
}

impl Lane {
    /// The lane of `centre` with `half_width`.
    #[must_use]
    pub fn new(centre: Polyline, half_width: f64) -> Lane {
        Lane { centre, half_width }
    }

    /// The scenario's waterway around its route; `None` without a `[waterway]`.
    #[must_use]
    pub fn of_scenario(scenario: &Scenario) -> Option<Lane> {
        scenario
            .waterway
            .map(|w| Lane::new(Polyline::of_route(&scenario.route), w.half_width))
    }

    /// How far `p` is beyond the bank (its distance from the route less the half
    /// width; negative inside), m.
    #[must_use]
    pub fn excess(&self, p: Point) -> f64 {
        self.centre.distance(p) - self.half_width
    }

    /// How far the hull `hull` at `(x, y, psi)` reaches beyond the bank: the largest
    /// [`Lane::excess`] of its corners (negative: the whole footprint inside by that
    /// much). The lane is the set within `half_width` of a polyline; a rectangle with
    /// every corner inside can still poke its side out only at an inner bend sharper
    /// than the hull is long, which the routes here (legs of several ship lengths,
    /// turns under 90 deg) do not have.
    #[must_use]
    pub fn hull_excess(&self, hull: &HullRect, x: f64, y: f64, psi: f64) -> f64 {
        hull.corners(x, y, psi)
            .iter()
            .map(|&c| self.excess(c))
            .fold(f64::NEG_INFINITY, f64::max)
    }

    /// The distance `d` of `p` from the route and its gradient `dd/dp`: the unit vector
    /// from the nearest point of the route to `p`. Inside a segment's span that is
    /// `+-` the segment's starboard normal and `d` the absolute lateral offset from
    /// it; beyond a segment's end, the direction from its end point. On the route
    /// itself (`d` below 1e-9 m) the gradient is the nearest segment's starboard
    /// normal (a one-sided derivative; the distance is not differentiable there).
    #[must_use]
    pub fn distance_and_gradient(&self, p: Point) -> (f64, Point) {
        let q = self.centre.project(p);
        let grad = if q.distance > 1e-9 {
            [
                (p[0] - q.point[0]) / q.distance,
                (p[1] - q.point[1]) / q.distance,
            ]
        } else {
            self.centre.starboard_normal(q.segment)
        };
        (q.distance, grad)
    }

    /// The water ahead of `p` on `course`: the run `s` in `[0, reach]` after which going
    /// on along the course brings `p + s (cos course, sin course)` within `margin` of
    /// the bank ([`Lane::excess`] at least `-margin`) and nearer to it, or `reach` if
    /// it does not within the reach (m). A point within the margin already has no room
    /// if the course takes it nearer the bank, and all the room it needs if the course
    /// takes it away (a tug astern of the route's start). Marched in steps of
    /// [`Lane::ROOM_STEP`], so a bank is found to within that step.
    #[must_use]
    pub fn room_ahead(&self, p: Point, course: f64, margin: f64, reach: f64) -> f64 {
        let (sin, cos) = course.sin_cos();
        let at = |s: f64| self.excess([p[0] + s * cos, p[1] + s * sin]);
        let steps = (reach.max(0.0) / Self::ROOM_STEP).ceil() as usize;
        let mut before = (0.0, at(0.0));
        for k in 1..=steps {
            let s = (k as f64 * Self::ROOM_STEP).min(reach);
            let e = at(s);
            if e >= -margin && e > before.1 {
                return before.0;
            }
            before = (s, e);
        }
        reach
    }

    /// The step of [`Lane::room_ahead`], m.
    pub const ROOM_STEP: f64 = 0.05;
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// Steps a target 8 m ahead of a ship heading North: the target moves West at
    /// `target_rate` (m/s) from `east0` m East, the ship's heading turns East at a
    /// rate that sweeps her line West across the target at `line_rate` (m/s) there,
    /// sampled every `dt` s; true when a crossing is found.
    fn crossing_found(east0: f64, target_rate: f64, line_rate: f64, dt: f64) -> bool {
        let at = |t: f64| {
            let psi = (line_rate * t / 8.0).atan();
            ([0.0, 0.0], psi, [8.0, east0 - target_rate * t])
        };
        let steps = (60.0 / dt).round() as usize;
        (1..=steps).any(|k| crossed_ahead(at((k - 1) as f64 * dt), at(k as f64 * dt)))
    }

    #[test]
    fn starboard_offset_is_the_signed_distance_from_the_line() {
        // A northbound line: East is starboard.
        let (offset, n) = starboard_offset([0.0, 0.0], [10.0, 0.0], [4.0, 1.5]).unwrap();
        assert_eq!((offset, n), (1.5, [0.0, 1.0]));
        // Eastbound: South is starboard; the same as the across coordinate of
        // `line_coordinates`.
        let (offset, _) = starboard_offset([0.0, 0.0], [0.0, 5.0], [2.0, 7.0]).unwrap();
        assert!((offset - -2.0).abs() < 1e-15);
        assert!((line_coordinates([0.0, 0.0], PI / 2.0, [2.0, 7.0]).1 - offset).abs() < 1e-15);
        assert_eq!(starboard_offset([1.0, 1.0], [1.0, 1.0], [0.0, 0.0]), None);
    }

    #[test]
    fn a_target_draws_away_only_once_its_track_no_longer_meets_the_heading_line_ahead() {
        // Own ship at the origin heading North; the target 9 m ahead, 0.5 m to starboard.
        let ahead = [9.0, 0.5];
        let v = |course_deg: f64| {
            let (s, c) = course_deg.to_radians().sin_cos();
            [0.07 * c, 0.07 * s]
        };
        // Crossing to port ahead of her, moving away (random-12-0238 at its release):
        // the range opens but its track still meets her heading line 9 m ahead.
        assert!(!drawing_away([0.0, 0.0], 0.0, ahead, v(-30.0)));
        // Moving away to starboard, or straight ahead of her along the line: clear.
        assert!(drawing_away([0.0, 0.0], 0.0, ahead, v(30.0)));
        assert!(drawing_away([0.0, 0.0], 0.0, [9.0, 0.0], v(0.0)));
        // Coming towards her: the range closes.
        assert!(!drawing_away([0.0, 0.0], 0.0, ahead, v(180.0)));
        // Abaft her beam on the starboard quarter, crossing her line astern: clear.
        assert!(drawing_away([0.0, 0.0], 0.0, [-3.0, 2.0], v(-150.0)));
        // On her port bow drawing away to port, whatever her own speed: clear.
        assert!(drawing_away([0.0, 0.0], 0.0, [6.0, -4.0], v(-60.0)));
    }

    #[test]
    fn a_target_is_abaft_and_opening_only_behind_the_beam_with_the_range_opening() {
        // Own ship at the origin heading North at 0.1 m/s; a head-on target passing
        // port to port at 0.1 m/s (course South), 2 m to port.
        let (own, v_own, v_south) = ([0.0, 0.0], [0.1, 0.0], [-0.1, 0.0]);
        // Forward of the beam, closing: not yet.
        assert!(!abaft_and_opening(own, 0.0, v_own, [3.0, -2.0], v_south));
        // Abaft the beam: past its closest approach, the range opening.
        assert!(abaft_and_opening(own, 0.0, v_own, [-0.5, -2.0], v_south));
        // Abaft the beam but closing (an overtaking vessel coming up on the quarter).
        assert!(!abaft_and_opening(
            own,
            0.0,
            v_own,
            [-3.0, -2.0],
            [0.2, 0.0]
        ));
        // The heading, not the course made good, defines the beam: the same point is
        // forward of the beam of a ship heading South-West and abaft it heading East.
        assert!(!abaft_and_opening(
            own,
            1.25 * PI,
            v_own,
            [-0.5, -2.0],
            v_south
        ));
        assert!(abaft_and_opening(
            own,
            0.5 * PI,
            v_own,
            [-0.5, -2.0],
            v_south
        ));
    }

    #[test]
    fn the_course_ahead_turns_over_the_lookahead_before_a_bend() {
        let route = Polyline::new(vec![[0.0, 0.0], [10.0, 0.0], [10.0, 10.0]]).unwrap();
        let deg = |p: Point, l: f64| route.course_ahead(p, l).unwrap().to_degrees();
        assert!(deg([2.0, 0.0], 3.0).abs() < 1e-9);
        // Off the route, the course is still the route's.
        assert!(deg([2.0, 3.0], 3.0).abs() < 1e-9);
        // 1 m before the bend: towards the point 2 m into the next leg.
        assert!((deg([9.0, 0.0], 3.0) - 2f64.atan2(1.0).to_degrees()).abs() < 1e-9);
        assert!((deg([10.0, 5.0], 3.0) - 90.0).abs() < 1e-9);
        // At and beyond the end: the last leg's course.
        assert!((deg([10.0, 10.0], 3.0) - 90.0).abs() < 1e-9);
        assert!((deg([10.0, 12.0], 3.0) - 90.0).abs() < 1e-9);
        assert_eq!(route.point_at(15.0), [10.0, 5.0]);
        assert!(Polyline::new(vec![[1.0, 1.0]])
            .unwrap()
            .course_ahead([0.0, 0.0], 3.0)
            .is_none());
    }

    #[test]
    fn a_crossing_is_the_targets_own_whatever_the_step_and_its_phase() {
        for dt in [0.1, 0.5, 1.0] {
            for east0 in [0.3, 0.3137, 0.35, 0.377] {
                // Target alone, or faster across than the line: crossed.
                assert!(crossing_found(east0, 0.05, 0.0, dt), "{dt} {east0}");
                assert!(crossing_found(east0, 0.03, 0.02, dt), "{dt} {east0}");
                // The line swept across a still or slower target: not crossed.
                assert!(!crossing_found(east0, 0.0, 0.05, dt), "{dt} {east0}");
                assert!(!crossing_found(east0, 0.02, 0.03, dt), "{dt} {east0}");
            }
        }
        // Behind the ship: never.
        let astern = |t: f64| ([0.0, 0.0], 0.0, [-8.0, 0.3 - 0.05 * t]);
        assert!(!(1..=60).any(|k| crossed_ahead(astern(f64::from(k - 1)), astern(f64::from(k)))));
    }

    fn l_lane() -> Lane {
        Lane::new(
            Polyline::new(vec![[0.0, 0.0], [10.0, 0.0], [10.0, 10.0]]).unwrap(),
            2.0,
        )
    }

    #[test]
    fn hull_corners_follow_heading() {
        // Heading East: the bow is East of the centre, starboard is South.
        let h = HullRect::new(2.0, 1.0).corners(0.0, 0.0, PI / 2.0);
        assert!((h[0][1] - 1.0).abs() < 1e-12 && (h[0][0] + 0.5).abs() < 1e-12);
        assert!((HullRect::new(2.0, 1.0).radius() - 1.25f64.sqrt()).abs() < 1e-12);
    }

    #[test]
    fn projection_on_an_l_shaped_route() {
        let p = l_lane().centre;
        assert_eq!(p.length(), 20.0);
        let q = p.project([5.0, -2.0]);
        assert!((q.s - 5.0).abs() < 1e-12 && (q.distance - 2.0).abs() < 1e-12);
        assert_eq!((q.segment, q.point), (0, [5.0, 0.0]));
        let q = p.project([12.0, 4.0]);
        assert!((q.s - 14.0).abs() < 1e-12 && (q.distance - 2.0).abs() < 1e-12);
        assert_eq!(q.segment, 1);
        assert!((p.distance([-3.0, 4.0]) - 5.0).abs() < 1e-12);
    }

    #[test]
    fn excess_and_hull_excess() {
        let lane = l_lane();
        assert!((lane.excess([5.0, 1.5]) + 0.5).abs() < 1e-12);
        assert!((lane.excess([5.0, -3.0]) - 1.0).abs() < 1e-12);
        // A 2 x 1 hull heading North 1.2 m to port of the first leg: its port corners
        // are 1.7 m off, inside; 1.8 m off, its port side is 0.3 m beyond the bank.
        let hull = HullRect::new(2.0, 1.0);
        assert!((lane.hull_excess(&hull, 5.0, -1.2, 0.0) + 0.3).abs() < 1e-12);
        assert!((lane.hull_excess(&hull, 5.0, -2.3, 0.0) - 0.8).abs() < 1e-12);
        // Turned across the lane, the bow reaches further.
        assert!(lane.hull_excess(&hull, 5.0, -1.2, -PI / 2.0) > 0.0);
    }

    #[test]
    fn room_ahead_is_the_run_to_the_bank_less_the_margin() {
        let lane = l_lane();
        // On the first leg (North), 0.5 m to starboard, heading East (course 90 deg):
        // the bank is 1.5 m away, 1.0 m with a 0.5 m margin.
        let east = PI / 2.0;
        let room = lane.room_ahead([5.0, 0.5], east, 0.5, 3.0);
        assert!((room - 1.0).abs() <= Lane::ROOM_STEP + 1e-12, "{room}");
        // 30 deg off the leg, the run to the same bank doubles.
        let room = lane.room_ahead([5.0, 0.5], PI / 6.0, 0.5, 3.0);
        assert!((room - 2.0).abs() <= Lane::ROOM_STEP + 1e-12, "{room}");
        // Along the leg, no bank within the reach.
        assert_eq!(lane.room_ahead([5.0, 0.5], 0.0, 0.5, 3.0), 3.0);
        // Already within the margin: no room going nearer the bank, all of it going away.
        assert_eq!(lane.room_ahead([5.0, 1.8], east, 0.5, 3.0), 0.0);
        assert_eq!(lane.room_ahead([5.0, 1.8], -east, 0.5, 3.0), 3.0);
        // Astern of the route's start, heading along it: away from the end cap.
        assert_eq!(lane.room_ahead([-2.5, 0.0], 0.0, 0.5, 3.0), 3.0);
    }

    #[test]
    fn gradient_is_the_outward_unit_vector() {
        let lane = l_lane();
        // Port of the first leg (heading North): the starboard normal is East, so
        // outward to port is West.
        let (d, g) = lane.distance_and_gradient([5.0, -1.0]);
        assert!((d - 1.0).abs() < 1e-12 && (g[1] + 1.0).abs() < 1e-12 && g[0].abs() < 1e-12);
        let (d, g) = lane.distance_and_gradient([5.0, 0.0]);
        assert!(d == 0.0 && g == [0.0, 1.0]);
        // Beyond the start: away from the origin point.
        let (d, g) = lane.distance_and_gradient([-3.0, -4.0]);
        assert!(
            (d - 5.0).abs() < 1e-12 && (g[0] + 0.6).abs() < 1e-12 && (g[1] + 0.8).abs() < 1e-12
        );
        // Matches finite differences off the route.
        let p = [7.0, 1.3];
        let e = 1e-6;
        let fd = [
            (lane.distance_and_gradient([p[0] + e, p[1]]).0
                - lane.distance_and_gradient([p[0] - e, p[1]]).0)
                / (2.0 * e),
            (lane.distance_and_gradient([p[0], p[1] + e]).0
                - lane.distance_and_gradient([p[0], p[1] - e]).0)
                / (2.0 * e),
        ];
        let g = lane.distance_and_gradient(p).1;
        assert!((fd[0] - g[0]).abs() < 1e-6 && (fd[1] - g[1]).abs() < 1e-6);
    }

    #[test]
    fn lane_round_trips_through_json() {
        let lane = l_lane();
        let text = serde_json::to_string(&lane).unwrap();
        assert_eq!(
            text,
            r#"{"centre":[[0.0,0.0],[10.0,0.0],[10.0,10.0]],"half_width":2.0}"#
        );
        let back: Lane = serde_json::from_str(&text).unwrap();
        assert_eq!(back, lane);
    }

    #[test]
    fn the_paper_lane() {
        let s = Scenario::paper().unwrap();
        let lane = Lane::of_scenario(&s).unwrap();
        assert_eq!(lane.half_width, 5.0);
        assert_eq!(lane.centre.points().len(), s.route.waypoints.len() + 2);
        assert!((lane.centre.length() - s.route.length()).abs() < 1e-9);
    }
}
