//! Plane geometry in the NED frame: points are `[north, east]` in m, headings from North,
//! clockwise (Fossen 2021; `paper/NOTES.md` section 1: forward unit vector
//! `(cos psi, sin psi)`).

use std::f64::consts::PI;

/// A point `[north, east]`, m.
pub type P2 = [f64; 2];

/// Wraps an angle to `(-pi, pi]`.
#[must_use]
pub fn wrap(a: f64) -> f64 {
    let mut w = a.rem_euclid(2.0 * PI);
    if w > PI {
        w -= 2.0 * PI;
    }
    w
}

/// Body point `(bx forward, by starboard)` of a vessel at `(x, y, psi)`, in NED.
#[must_use]
pub fn body_to_ned(x: f64, y: f64, psi: f64, bx: f64, by: f64) -> P2 {
    let (s, c) = psi.sin_cos();
    [x + bx * c - by * s, y + bx * s + by * c]
}

/// The hull rectangle of a vessel (length x width centred at its body origin), corners
/// in order bow-starboard, bow-port, stern-port, stern-starboard.
#[must_use]
pub fn hull_rect(x: f64, y: f64, psi: f64, length: f64, width: f64) -> [P2; 4] {
    let (a, b) = (length / 2.0, width / 2.0);
    [
        body_to_ned(x, y, psi, a, b),
        body_to_ned(x, y, psi, a, -b),
        body_to_ned(x, y, psi, -a, -b),
        body_to_ned(x, y, psi, -a, b),
    ]
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

/// Euclidean distance.
#[must_use]
pub fn dist(a: P2, b: P2) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
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
    fn hull_corners_follow_heading() {
        // Heading East: the bow is East of the centre.
        let h = hull_rect(0.0, 0.0, PI / 2.0, 2.0, 1.0);
        assert!((h[0][1] - 1.0).abs() < 1e-12 && (h[0][0] + 0.5).abs() < 1e-12);
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
        let a = hull_rect(0.0, 0.0, 0.0, 2.0, 1.0);
        let b = hull_rect(0.0, 1.2, 0.3, 2.0, 1.0);
        let c = hull_rect(0.0, 3.0, 0.0, 2.0, 1.0);
        assert!(convex_overlap(&a, &b));
        assert!(!convex_overlap(&a, &c));
        let e = ellipse_polygon(0.0, 1.6, 0.0, 0.74, 0.24);
        assert!(!convex_overlap(&a, &e)); // gap 1.6 - 0.5 - 0.24 = 0.86 m... east side
        let e = ellipse_polygon(0.0, 0.7, 0.0, 0.74, 0.24);
        assert!(convex_overlap(&a, &e));
    }
}
