//! Route and clockwise waypoint altering: Du et al. (2022), eq. (10), (11) and the
//! remark on the choice of `theta` (`theta_max`).
//!
//! Eq. (10) as printed, `W_{p-1} + r (sin theta, cos theta)`, is not a rotation of
//! the segment (it ignores the segment's course). This crate uses the consistent
//! form of `paper/NOTES.md` section 1: the active waypoint `W_p` is rotated by
//! `+theta` (clockwise seen from above, i.e. to starboard in NED) about the
//! previous predefined waypoint `W_{p-1}`, on the circle of radius
//! `r = |W_p - W_{p-1}|`:
//!
//! `W_pN = W_{p-1} + r (cos(chi + theta), sin(chi + theta))`,
//! `chi = atan2(y_p - y_{p-1}, x_p - x_{p-1})` (the segment's course), and
//! `psi_pN = psi_p + theta` (eq. (11)).

use towing_model::Pose;

use crate::error::ParamError;
use crate::geometry::wrap_angle;

/// Eq. (10)-(11), consistent form: the waypoint `wp` rotated clockwise (to
/// starboard) by `theta` (rad) about `prev`, keeping its distance to `prev`; its
/// heading becomes `wp.psi + theta` (wrapped).
///
/// ```
/// use towing_guidance::rotate_waypoint;
/// use towing_model::Pose;
/// // A northbound segment of 10 m rotated by 90 deg points East.
/// let w = rotate_waypoint(Pose::new(0.0, 0.0, 0.0), Pose::new(10.0, 0.0, 0.0), 90f64.to_radians());
/// assert!(w.x.abs() < 1e-12 && (w.y - 10.0).abs() < 1e-12);
/// ```
#[must_use]
pub fn rotate_waypoint(prev: Pose, wp: Pose, theta: f64) -> Pose {
    let dx = wp.x - prev.x;
    let dy = wp.y - prev.y;
    let r = dx.hypot(dy);
    let chi = dy.atan2(dx);
    let (s, c) = (chi + theta).sin_cos();
    Pose {
        x: prev.x + r * c,
        y: prev.y + r * s,
        psi: wrap_angle(wp.psi + theta),
    }
}

/// The bound of the paper's remark on `theta` (Hepworth 2021):
/// `theta_max = arctan(d_2 / d_1)`, `d_1` the segment length (m), `d_2` the
/// distance from the route to the edge of the waterway (m).
///
/// Even at `theta = theta_max` the altered waypoint's offset from the route,
/// `d_1 sin(theta_max) = d_1 d_2 / sqrt(d_1^2 + d_2^2)`, is below `d_2`: the
/// waypoint stays strictly inside the waterway.
#[must_use]
pub fn theta_max(segment_length: f64, half_width: f64) -> f64 {
    half_width.atan2(segment_length)
}

/// Below this length (m) two route points count as coinciding.
const MIN_SEGMENT_LENGTH: f64 = 1.0e-6;

/// A predefined route: origin `W_P0`, waypoints, destination (the last point, which
/// is held). Headings are the waterway directions of Table 4, used by eq. (11).
#[derive(Debug, Clone, PartialEq)]
pub struct Route {
    points: Vec<Pose>,
}

impl Route {
    /// A route through `points` (origin first, destination last).
    ///
    /// # Errors
    /// Fewer than 2 points, a non-finite value, or two consecutive points closer
    /// than 1 µm (a segment without a course).
    pub fn new(points: Vec<Pose>) -> Result<Self, ParamError> {
        if points.len() < 2 {
            return Err(ParamError::RouteTooShort {
                count: points.len(),
            });
        }
        let mut points = points;
        for (index, p) in points.iter_mut().enumerate() {
            if !p.is_finite() {
                return Err(ParamError::NonFiniteRoutePoint { index });
            }
            p.psi = wrap_angle(p.psi);
        }
        for index in 1..points.len() {
            let length = (points[index].x - points[index - 1].x)
                .hypot(points[index].y - points[index - 1].y);
            if length < MIN_SEGMENT_LENGTH {
                return Err(ParamError::DegenerateSegment {
                    index: index - 1,
                    next: index,
                    length,
                });
            }
        }
        Ok(Self { points })
    }

    /// A route through positions only; each point's heading is the course of the
    /// segment that ends in it, the origin's that of the first segment.
    ///
    /// # Errors
    /// As [`Route::new`].
    pub fn from_positions(positions: &[[f64; 2]]) -> Result<Self, ParamError> {
        let mut points: Vec<Pose> = positions
            .iter()
            .map(|p| Pose::new(p[0], p[1], 0.0))
            .collect();
        for i in 1..points.len() {
            let chi = (points[i].y - points[i - 1].y).atan2(points[i].x - points[i - 1].x);
            points[i].psi = chi;
            if i == 1 {
                points[0].psi = chi;
            }
        }
        Self::new(points)
    }

    /// The paper's route, Table 4 (`paper/NOTES.md` section 2): origin
    /// `[-4.9, 7, 101.3 deg]`, eight waypoints, destination `[-43, 40, 180 deg]`.
    #[must_use]
    pub fn paper() -> Self {
        let table = [
            (-4.9, 7.0, 101.3),
            (-6.3, 14.0, 101.3),
            (-7.7, 21.0, 101.3),
            (-9.1, 28.0, 101.3),
            (-10.7, 36.0, 101.3),
            (-15.0, 40.0, 180.0),
            (-22.0, 40.0, 180.0),
            (-29.0, 40.0, 180.0),
            (-36.0, 40.0, 180.0),
            (-43.0, 40.0, 180.0),
        ];
        Self {
            points: table
                .iter()
                .map(|&(x, y, psi)| Pose::from_deg(x, y, psi))
                .collect(),
        }
    }

    /// All points, origin first.
    #[must_use]
    pub fn points(&self) -> &[Pose] {
        &self.points
    }

    /// Index of the destination (the last point).
    #[must_use]
    pub fn last_index(&self) -> usize {
        self.points.len() - 1
    }

    /// Length of segment `p - 1 -> p` (m), `d_1` of `theta_max`; `p >= 1`.
    ///
    /// # Panics
    /// If `p` is 0 or beyond the destination.
    #[must_use]
    pub fn segment_length(&self, p: usize) -> f64 {
        let (a, b) = (self.points[p - 1], self.points[p]);
        (b.x - a.x).hypot(b.y - a.y)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn deg(d: f64) -> f64 {
        d.to_radians()
    }

    #[test]
    fn northbound_segment_rotates_to_the_east() {
        let prev = Pose::new(0.0, 0.0, 0.0);
        let wp = Pose::new(10.0, 0.0, 0.0);
        let theta = deg(15.0);
        let w = rotate_waypoint(prev, wp, theta);
        // East = starboard of a northbound segment.
        assert!(w.y > 0.0);
        assert!((w.x - 10.0 * theta.cos()).abs() < 1e-12);
        assert!((w.y - 10.0 * theta.sin()).abs() < 1e-12);
        // Same distance to W_{p-1}.
        assert!((w.x.hypot(w.y) - 10.0).abs() < 1e-12);
        // Heading +theta (eq. (11)).
        assert!((w.psi - theta).abs() < 1e-15);
    }

    #[test]
    fn southbound_segment_rotates_to_the_west() {
        // Starboard of a southbound segment is West.
        let w = rotate_waypoint(
            Pose::from_deg(0.0, 40.0, 180.0),
            Pose::from_deg(-7.0, 40.0, 180.0),
            deg(15.0),
        );
        assert!(w.y < 40.0);
        assert!((w.x + 7.0 * deg(15.0).cos()).abs() < 1e-12);
        assert!((w.y - (40.0 - 7.0 * deg(15.0).sin())).abs() < 1e-12);
        assert!((w.psi - deg(-165.0)).abs() < 1e-12);
    }

    #[test]
    fn paper_w_p2_rotated_by_15_deg() {
        // W_P1 = (-6.3, 14), W_P2 = (-7.7, 21, 101.3 deg). By hand: the segment
        // (dx, dy) = (-1.4, 7) rotated clockwise by 15 deg in NED is
        // (dx cos t - dy sin t, dx sin t + dy cos t)
        // = (-1.4 * 0.9659258 - 7 * 0.2588190, -1.4 * 0.2588190 + 7 * 0.9659258)
        // = (-3.1640295, 6.3991339), so W_P2N = (-9.4640295, 20.3991339) and
        // psi = 116.3 deg.
        let route = Route::paper();
        let w = rotate_waypoint(route.points()[1], route.points()[2], deg(15.0));
        assert!((w.x + 9.4640295).abs() < 1e-6, "{w:?}");
        assert!((w.y - 20.3991339).abs() < 1e-6, "{w:?}");
        assert!((w.psi - deg(116.3)).abs() < 1e-12);
        // r = sqrt(1.4^2 + 7^2) = 7.1386273 is kept.
        assert!((route.segment_length(2) - 7.1386273).abs() < 1e-6);
        let r = (w.x + 6.3).hypot(w.y - 14.0);
        assert!((r - 7.1386273).abs() < 1e-6);
    }

    #[test]
    fn theta_max_values() {
        // d_2 = d_1: 45 deg.
        assert!((theta_max(5.0, 5.0) - deg(45.0)).abs() < 1e-15);
        // Paper's segment W_P1 -> W_P2 (7.139 m) in a 5 m half width: 35.0 deg.
        assert!((theta_max(7.1386273, 5.0).to_degrees() - 35.0).abs() < 0.05);
        // The waypoint at theta_max stays inside the waterway.
        let (d1, d2) = (7.0, 1.0);
        let w = rotate_waypoint(Pose::default(), Pose::new(d1, 0.0, 0.0), theta_max(d1, d2));
        // 7 / sqrt(50) = 0.98995 m < 1 m.
        assert!(w.y < d2 && (w.y - 7.0 / 50f64.sqrt()).abs() < 1e-12);
    }

    #[test]
    fn route_validation() {
        assert!(matches!(
            Route::new(vec![Pose::default()]),
            Err(ParamError::RouteTooShort { count: 1 })
        ));
        assert!(matches!(
            Route::new(vec![Pose::default(), Pose::default()]),
            Err(ParamError::DegenerateSegment { .. })
        ));
        assert!(matches!(
            Route::new(vec![Pose::default(), Pose::new(f64::NAN, 0.0, 0.0)]),
            Err(ParamError::NonFiniteRoutePoint { index: 1 })
        ));
        let r = Route::from_positions(&[[0.0, 0.0], [0.0, 5.0], [-5.0, 5.0]]).unwrap();
        assert!((r.points()[0].psi - deg(90.0)).abs() < 1e-12);
        assert!((r.points()[1].psi - deg(90.0)).abs() < 1e-12);
        assert!((r.points()[2].psi - deg(180.0)).abs() < 1e-12);
        assert_eq!(Route::paper().last_index(), 9);
        assert_eq!(
            Route::new(Route::paper().points().to_vec()),
            Ok(Route::paper())
        );
    }
}
