//! Plane geometry in the NED frame: points are `[north, east]` in m, headings from North,
//! clockwise (Fossen 2021; `paper/NOTES.md` section 1: forward unit vector
//! `(cos psi, sin psi)`). The hull footprint, the route polyline and the waterway are the
//! plant's and the MPC's own ([`towing_model::geometry`], re-exported here), so the
//! analyzer judges contact and groundings with the geometry the plant reports them by.

use std::f64::consts::PI;

pub use towing_model::geometry::{
    abaft_and_opening, body_to_ned, crossed_ahead, dist, drawing_away, line_coordinates,
    segment_projection, HullRect, Lane, Polyline, Projection,
};

/// A point `[north, east]`, m.
pub type P2 = towing_model::geometry::Point;

/// A crossing of a target's course line (through `target` on `course`) by the point
/// `own`: `last_side` is own point's last non-zero side of the line (+ starboard of the
/// target), updated here; when the side changed since, own point's position along the
/// line (+ ahead of the target), else `None`. Rule 15's crossing ahead (the `rules`
/// metric) and "passed ahead" (the `colregs` scorer) read it.
#[must_use]
pub fn course_line_crossing(
    last_side: &mut Option<f64>,
    target: P2,
    course: f64,
    own: P2,
) -> Option<f64> {
    let (along, side) = line_coordinates(target, course, own);
    if side == 0.0 {
        return None;
    }
    let changed = last_side.replace(side).is_some_and(|p| p * side < 0.0);
    changed.then_some(along)
}

/// The course of the tow's manoeuvre, against which her course changes are measured:
/// following her route ([`Polyline::course_ahead`], `route_course_lookahead_m` ahead).
/// COLREGS Rule 17's "course" is that of the manoeuvre the vessel is engaged in, not
/// her compass heading when the other is sighted (Windsor-Roanoke, 1908; Cockcroft and
/// Lameijer, *A Guide to the Collision Avoidance Rules*, on Rule 17): a tow rounding a
/// bend of her route keeps her course, and a turn counts only as far as it leaves the
/// route's course (`docs/analyzer.md`, "Course changes"). Without a route (fewer than
/// two distinct points) the course is 0 and a change of it is a change of heading.
#[derive(Debug, Clone, PartialEq)]
pub struct RouteCourse {
    route: Option<Polyline>,
    lookahead: f64,
}

impl RouteCourse {
    /// The course of following `route` (points North, East, heading) seen `lookahead` m
    /// ahead.
    #[must_use]
    pub fn new(route: &[[f64; 3]], lookahead: f64) -> Self {
        RouteCourse {
            route: Polyline::from_route(route),
            lookahead,
        }
    }

    /// The route's course (rad) at `p`; 0 without a route or at a non-finite `p`.
    #[must_use]
    pub fn at(&self, p: P2) -> f64 {
        if !(p[0].is_finite() && p[1].is_finite()) {
            return 0.0;
        }
        self.route
            .as_ref()
            .and_then(|r| r.course_ahead(p, self.lookahead))
            .unwrap_or(0.0)
    }

    /// The route's course at `p` ([`RouteCourse::at`]) and how far `p` lies to starboard
    /// of the route (m, negative to port: its distance from the segment of its nearest
    /// point on the route, signed), from one projection; both 0 without a route or at a
    /// non-finite `p`.
    #[must_use]
    pub fn track(&self, p: P2) -> Track {
        let Some(route) = self
            .route
            .as_ref()
            .filter(|_| p[0].is_finite() && p[1].is_finite())
        else {
            return Track::default();
        };
        let at = route.project(p);
        Track {
            course: route.course_from(at.s, self.lookahead).unwrap_or(0.0),
            cross_track: route.offset_from(&at, p),
        }
    }
}

/// The ship against her route at a step ([`RouteCourse::track`]).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Track {
    /// The route's course, rad.
    pub course: f64,
    /// The offset to starboard of the route, m.
    pub cross_track: f64,
}

/// Wraps an angle to `(-pi, pi]`.
#[must_use]
pub fn wrap(a: f64) -> f64 {
    let mut w = a.rem_euclid(2.0 * PI);
    if w > PI {
        w -= 2.0 * PI;
    }
    w
}

/// A hull outline for maps: the rectangle with a pointed bow (the bow's tip on the centre
/// line, the shoulders at 80 % of the half length), so the heading reads at a glance.
#[must_use]
pub fn hull_outline(x: f64, y: f64, psi: f64, length: f64, width: f64) -> Vec<P2> {
    let (a, b) = (length / 2.0, width / 2.0);
    let shoulder = 0.6 * a;
    vec![
        body_to_ned(x, y, psi, a, 0.0),
        body_to_ned(x, y, psi, shoulder, -b),
        body_to_ned(x, y, psi, -a, -b),
        body_to_ned(x, y, psi, -a, b),
        body_to_ned(x, y, psi, shoulder, b),
    ]
}

/// `n` points on an ellipse (semi-axes `a` along the heading `psi`, `b` across).
#[must_use]
pub fn ellipse(x: f64, y: f64, psi: f64, a: f64, b: f64, n: usize) -> Vec<P2> {
    (0..n)
        .map(|k| {
            let th = 2.0 * PI * k as f64 / n as f64;
            body_to_ned(x, y, psi, a * th.cos(), b * th.sin())
        })
        .collect()
}

/// `n` points on a circle of radius `r`.
#[must_use]
pub fn circle(x: f64, y: f64, r: f64, n: usize) -> Vec<P2> {
    ellipse(x, y, 0.0, r, r, n)
}

/// True when a vessel's hull rectangle and a circle overlap (touching counts): the circle's
/// centre, taken into the body frame, is within `r` of the rectangle.
#[must_use]
pub fn rect_circle_overlap(hull: (f64, f64, f64, f64, f64), centre: P2, r: f64) -> bool {
    let (x, y, psi, length, width) = hull;
    let (dx, dy) = (centre[0] - x, centre[1] - y);
    let (s, c) = psi.sin_cos();
    let bx = dx * c + dy * s;
    let by = -dx * s + dy * c;
    let qx = bx.clamp(-length / 2.0, length / 2.0);
    let qy = by.clamp(-width / 2.0, width / 2.0);
    (bx - qx).hypot(by - qy) <= r
}

/// True when two convex polygons overlap (separating axis theorem; touching counts).
#[must_use]
pub fn convex_overlap(a: &[P2], b: &[P2]) -> bool {
    if a.len() < 3 || b.len() < 3 {
        return false;
    }
    for poly in [a, b] {
        for k in 0..poly.len() {
            let p = poly[k];
            let q = poly[(k + 1) % poly.len()];
            let axis = [q[1] - p[1], -(q[0] - p[0])];
            let project = |pts: &[P2]| {
                pts.iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                        let d = v[0] * axis[0] + v[1] * axis[1];
                        (lo.min(d), hi.max(d))
                    })
            };
            let (a_lo, a_hi) = project(a);
            let (b_lo, b_hi) = project(b);
            if a_hi < b_lo || b_hi < a_lo {
                return false;
            }
        }
    }
    true
}

/// Vertices used for ellipses in overlap tests: the polygon is circumscribed (its edges
/// touch the ellipse), so an overlap is never missed; it is at most `a (1/cos(pi/n) - 1)`
/// = 0.36 mm too large for the paper's 1.48 m targets.
pub const ELLIPSE_VERTICES: usize = 64;

/// The circumscribed polygon of an ellipse, for overlap tests.
#[must_use]
pub fn ellipse_polygon(x: f64, y: f64, psi: f64, a: f64, b: f64) -> Vec<P2> {
    let k = 1.0 / (PI / ELLIPSE_VERTICES as f64).cos();
    ellipse(x, y, psi, a * k, b * k, ELLIPSE_VERTICES)
}

/// Relative bearing of `to` seen from a vessel at `from` with heading `psi`, rad in
/// `(-pi, pi]`, positive to starboard.
#[must_use]
pub fn relative_bearing(from: P2, psi: f64, to: P2) -> f64 {
    wrap((to[1] - from[1]).atan2(to[0] - from[0]) - psi)
}

/// Time and distance of the closest point of approach of a target at `p_target` moving
/// with `v_target` to own ship at `p_own` moving with `v_own` (reference/colregs.md:
/// `t_cpa = -(p . v) / |v|^2`, `d_cpa = |p + t_cpa v|` with `p`, `v` the target's relative
/// position and velocity). `(inf, inf)` without relative motion (`|v|^2 < 1e-12`).
/// A negative `t_cpa`: the range is opening.
#[must_use]
pub fn cpa_tcpa(p_own: P2, v_own: P2, p_target: P2, v_target: P2) -> (f64, f64) {
    let p = [p_target[0] - p_own[0], p_target[1] - p_own[1]];
    let v = [v_target[0] - v_own[0], v_target[1] - v_own[1]];
    let v2 = v[0] * v[0] + v[1] * v[1];
    if v2 < 1e-12 {
        return (f64::INFINITY, f64::INFINITY);
    }
    let t = -(p[0] * v[0] + p[1] * v[1]) / v2;
    (t, (p[0] + t * v[0]).hypot(p[1] + t * v[1]))
}

/// Velocity `[north, east]` of a vessel on `course` (rad) at `speed` (m/s).
#[must_use]
pub fn course_velocity(course: f64, speed: f64) -> P2 {
    [speed * course.cos(), speed * course.sin()]
}

/// Points on the target ellipse used by [`hull_ellipse_clearance`].
pub const CLEARANCE_ELLIPSE_POINTS: usize = 64;

/// Distance from `p` to a hull rectangle (length x width centred at `(x, y)`, heading
/// `psi`), 0 inside.
#[must_use]
pub fn point_rect_distance(p: P2, hull: (f64, f64, f64, f64, f64)) -> f64 {
    let (x, y, psi, length, width) = hull;
    let (bx, by) = line_coordinates([x, y], psi, p);
    let qx = bx.clamp(-length / 2.0, length / 2.0);
    let qy = by.clamp(-width / 2.0, width / 2.0);
    (bx - qx).hypot(by - qy)
}

/// Clearance between a hull rectangle `hull` = `(x, y, psi, length, width)` and a target
/// ellipse `ellipse` = `(x, y, course, length, width)` (axes are full lengths): the
/// smallest distance from the rectangle to [`CLEARANCE_ELLIPSE_POINTS`] points on the
/// ellipse, 0 when they overlap (a point of the ellipse inside the rectangle, or a corner
/// of the rectangle inside the ellipse). The points are on the ellipse, so the clearance
/// is at most the sagitta `a (1 - cos(pi / 64))` (0.9 mm for a 1.48 m target) too large.
/// No allocation.
#[must_use]
pub fn hull_ellipse_clearance(
    hull: (f64, f64, f64, f64, f64),
    ellipse: (f64, f64, f64, f64, f64),
) -> f64 {
    let (ex, ey, epsi, el, ew) = ellipse;
    let (a, b) = (el / 2.0, ew / 2.0);
    let corners = HullRect::new(hull.3, hull.4).corners(hull.0, hull.1, hull.2);
    if a > 0.0
        && b > 0.0
        && corners.iter().any(|&c| {
            let (u, v) = line_coordinates([ex, ey], epsi, c);
            (u / a).powi(2) + (v / b).powi(2) <= 1.0
        })
    {
        return 0.0;
    }
    let mut best = f64::INFINITY;
    for k in 0..CLEARANCE_ELLIPSE_POINTS {
        let th = 2.0 * PI * k as f64 / CLEARANCE_ELLIPSE_POINTS as f64;
        let q = body_to_ned(ex, ey, epsi, a * th.cos(), b * th.sin());
        best = best.min(point_rect_distance(q, hull));
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrap_range() {
        assert!((wrap(3.0 * PI) - PI).abs() < 1e-12);
        assert!((wrap(-PI) - PI).abs() < 1e-12);
        assert!((wrap(0.5) - 0.5).abs() < 1e-12);
        assert!((wrap(-0.5 - 2.0 * PI) + 0.5).abs() < 1e-12);
    }

    #[test]
    fn starboard_is_positive_bearing() {
        // Heading North, a point due East is 90 deg to starboard.
        let b = relative_bearing([0.0, 0.0], 0.0, [0.0, 5.0]);
        assert!((b - PI / 2.0).abs() < 1e-12);
        // Heading East, a point due North is on the port beam.
        let b = relative_bearing([0.0, 0.0], PI / 2.0, [5.0, 0.0]);
        assert!((b + PI / 2.0).abs() < 1e-12);
    }

    #[test]
    fn rect_circle() {
        let hull = (0.0, 0.0, 0.0, 2.0, 1.0);
        assert!(rect_circle_overlap(hull, [1.4, 0.0], 0.5));
        assert!(!rect_circle_overlap(hull, [1.6, 0.0], 0.5));
        assert!(!rect_circle_overlap(hull, [0.0, 1.01], 0.5));
        assert!(rect_circle_overlap(hull, [0.0, 0.99], 0.5));
    }

    #[test]
    fn sat_overlap() {
        let hull = HullRect::new(2.0, 1.0);
        let a = hull.corners(0.0, 0.0, 0.0);
        let b = hull.corners(0.0, 1.2, 0.3);
        let c = hull.corners(0.0, 3.0, 0.0);
        assert!(convex_overlap(&a, &b));
        assert!(!convex_overlap(&a, &c));
        let e = ellipse_polygon(0.0, 1.6, 0.0, 0.74, 0.24);
        assert!(!convex_overlap(&a, &e)); // gap 1.6 - 0.5 - 0.24 = 0.86 m... east side
        let e = ellipse_polygon(0.0, 0.7, 0.0, 0.74, 0.24);
        assert!(convex_overlap(&a, &e));
    }
}

#[cfg(test)]
mod route_tests {
    use super::*;

    #[test]
    fn cpa_of_a_crossing() {
        // Own ship North at 1 m/s from the origin, target from (10, 10) West at 1 m/s:
        // they meet at (10, 0) at t = 10.
        let (t, d) = cpa_tcpa([0.0, 0.0], [1.0, 0.0], [10.0, 10.0], [0.0, -1.0]);
        assert!((t - 10.0).abs() < 1e-12 && d.abs() < 1e-9);
        let (t, d) = cpa_tcpa([0.0, 0.0], [1.0, 0.0], [0.0, 5.0], [1.0, 0.0]);
        assert!(t.is_infinite() && d.is_infinite());
    }

    #[test]
    fn line_coordinates_starboard_positive() {
        let (a, c) = line_coordinates([0.0, 0.0], 0.0, [2.0, 3.0]);
        assert!((a - 2.0).abs() < 1e-12 && (c - 3.0).abs() < 1e-12);
        let (a, c) = line_coordinates([0.0, 0.0], PI / 2.0, [2.0, 3.0]);
        assert!((a - 3.0).abs() < 1e-12 && (c + 2.0).abs() < 1e-12);
    }

    #[test]
    fn clearance_side_by_side_and_overlap() {
        // Ship 1 x 0.2 heading North at the origin, target 1.48 x 0.48 heading North 1 m
        // to starboard: gap 1 - 0.1 - 0.24 = 0.66 m.
        let c = hull_ellipse_clearance((0.0, 0.0, 0.0, 1.0, 0.2), (0.0, 1.0, 0.0, 1.48, 0.48));
        assert!((c - 0.66).abs() < 1e-9, "{c}");
        let c = hull_ellipse_clearance((0.0, 0.0, 0.0, 1.0, 0.2), (0.0, 0.3, 0.0, 1.48, 0.48));
        assert_eq!(c, 0.0);
    }
}
