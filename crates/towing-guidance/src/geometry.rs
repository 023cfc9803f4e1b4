//! Plane geometry in NED: angle wrapping, relative bearing, CPA / TCPA.
//!
//! Conventions (`paper/NOTES.md` section 1): `x` North, `y` East, headings and
//! bearings from North positive clockwise (to starboard), radians. The forward
//! unit vector of a vessel with heading `psi` is `(cos psi, sin psi)`.

use serde::{Deserialize, Serialize};

/// Relative speeds below this (m/s) count as "no relative motion": the CPA is
/// then undefined and [`cpa`] returns infinite TCPA and DCPA
/// (`reference/colregs.md`: "(infinity, infinity) when |v| ~ 0").
///
/// Assumption: 1e-6 m/s is far below any speed of the model-scale vessels
/// (0.01 to 0.2 m/s) and far above rounding noise of the velocities.
pub const MIN_RELATIVE_SPEED: f64 = 1.0e-6;

/// Wraps an angle to `(-pi, pi]` (radians): the plant's own function, so guidance and
/// plant agree on every heading.
pub use towing_model::wrap_angle;

/// Bearing of `point` seen from a vessel at `(x, y)` with heading `psi`, relative
/// to her bow, in `(-pi, pi]`: positive to starboard, negative to port, `pi` dead
/// astern. This is `reference/colregs.md`'s `beta` (given there in `[0, 360)` deg);
/// `beta = 112.5 deg` is 22.5 deg abaft the starboard beam.
#[must_use]
pub fn relative_bearing(x: f64, y: f64, psi: f64, point: [f64; 2]) -> f64 {
    wrap_angle((point[1] - y).atan2(point[0] - x) - psi)
}

/// Ground velocity in NED (m/s) of a vessel with heading `psi` and body-frame
/// surge `u` and sway `v` (Fossen 2021, eq. 2.40: `eta_dot = R(psi) nu`).
#[must_use]
pub fn body_to_ned(psi: f64, u: f64, v: f64) -> [f64; 2] {
    let (s, c) = psi.sin_cos();
    [c * u - s * v, s * u + c * v]
}

/// Closest point of approach of two vessels moving at constant velocity.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Cpa {
    /// Time to the CPA (s) from now; negative when the CPA is in the past (the
    /// range is opening); `+inf` without relative motion.
    pub tcpa: f64,
    /// Distance at the CPA (m), centre to centre; `+inf` without relative motion.
    pub dcpa: f64,
}

impl Cpa {
    /// True when the two are closing: the CPA is finite and not in the past.
    #[must_use]
    pub fn is_closing(&self) -> bool {
        self.tcpa.is_finite() && self.tcpa > 0.0
    }
}

/// CPA and TCPA (`reference/colregs.md`): with `p = p_target - p_own` and
/// `v = v_target - v_own`, `t_cpa = -(p . v) / |v|^2`, `d_cpa = |p + t_cpa v|`;
/// both infinite when `|v| < MIN_RELATIVE_SPEED`.
///
/// ```
/// use towing_guidance::cpa;
/// // Target 10 m North, coming South at 1 m/s; own ship still: CPA in 10 s, 0 m.
/// let c = cpa([0.0, 0.0], [0.0, 0.0], [10.0, 0.0], [-1.0, 0.0]);
/// assert!((c.tcpa - 10.0).abs() < 1e-12 && c.dcpa.abs() < 1e-12);
/// ```
#[must_use]
pub fn cpa(p_own: [f64; 2], v_own: [f64; 2], p_target: [f64; 2], v_target: [f64; 2]) -> Cpa {
    let p = [p_target[0] - p_own[0], p_target[1] - p_own[1]];
    let v = [v_target[0] - v_own[0], v_target[1] - v_own[1]];
    let vv = v[0] * v[0] + v[1] * v[1];
    if vv < MIN_RELATIVE_SPEED * MIN_RELATIVE_SPEED {
        return Cpa {
            tcpa: f64::INFINITY,
            dcpa: f64::INFINITY,
        };
    }
    let tcpa = -(p[0] * v[0] + p[1] * v[1]) / vv;
    let dcpa = (p[0] + tcpa * v[0]).hypot(p[1] + tcpa * v[1]);
    Cpa { tcpa, dcpa }
}

/// Euclidean distance between two points (m).
#[must_use]
pub(crate) fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// Distance (m) from `p` to the segment `a`-`b`.
#[must_use]
pub fn segment_distance(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let d = [b[0] - a[0], b[1] - a[1]];
    let dd = d[0] * d[0] + d[1] * d[1];
    if dd == 0.0 {
        return dist(p, a);
    }
    let t = (((p[0] - a[0]) * d[0] + (p[1] - a[1]) * d[1]) / dd).clamp(0.0, 1.0);
    dist(p, [a[0] + t * d[0], a[1] + t * d[1]])
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use std::f64::consts::{PI, TAU};

    fn deg(d: f64) -> f64 {
        d.to_radians()
    }

    #[test]
    fn wrap_boundaries() {
        assert_eq!(wrap_angle(PI), PI);
        assert_eq!(wrap_angle(-PI), PI);
        assert_eq!(wrap_angle(TAU), 0.0);
        assert!((wrap_angle(-PI - 0.1) - (PI - 0.1)).abs() < 1e-12);
        assert!((wrap_angle(PI + 0.1) - (-PI + 0.1)).abs() < 1e-12);
        assert!(wrap_angle(f64::NAN).is_nan());
    }

    #[test]
    fn relative_bearing_signs() {
        // Own ship at the origin heading North.
        assert!((relative_bearing(0.0, 0.0, 0.0, [1.0, 1.0]) - deg(45.0)).abs() < 1e-12);
        assert!((relative_bearing(0.0, 0.0, 0.0, [1.0, -1.0]) + deg(45.0)).abs() < 1e-12);
        assert_eq!(relative_bearing(0.0, 0.0, 0.0, [-1.0, 0.0]), PI);
        // Heading East: a point to the South is on the starboard beam.
        let b = relative_bearing(0.0, 0.0, deg(90.0), [-5.0, 0.0]);
        assert!((b - deg(90.0)).abs() < 1e-12);
    }

    #[test]
    fn body_to_ned_rotates_clockwise() {
        // Heading East, surging at 1 m/s: moving East.
        let v = body_to_ned(deg(90.0), 1.0, 0.0);
        assert!(v[0].abs() < 1e-15 && (v[1] - 1.0).abs() < 1e-15);
        // Heading North, swaying to starboard: moving East.
        let v = body_to_ned(0.0, 0.0, 1.0);
        assert!(v[0].abs() < 1e-15 && (v[1] - 1.0).abs() < 1e-15);
    }

    #[test]
    fn segment_distance_cases() {
        let (a, b) = ([0.0, 0.0], [10.0, 0.0]);
        assert_eq!(segment_distance([5.0, 3.0], a, b), 3.0);
        assert_eq!(segment_distance([-3.0, 4.0], a, b), 5.0);
        assert_eq!(segment_distance([13.0, -4.0], a, b), 5.0);
        assert_eq!(segment_distance([1.0, 1.0], a, a), 2f64.sqrt());
    }

    #[test]
    fn cpa_crossing_hand_computed() {
        // Own ship at the origin, North at 1 m/s; target at (10, 10) heading West
        // at 1 m/s. Relative p = (10, 10), v = (-1, -1): t = 20 / 2 = 10 s, they
        // meet at (10, 0): d = 0.
        let c = cpa([0.0, 0.0], [1.0, 0.0], [10.0, 10.0], [0.0, -1.0]);
        assert!((c.tcpa - 10.0).abs() < 1e-12);
        assert!(c.dcpa.abs() < 1e-12);
        assert!(c.is_closing());
    }

    #[test]
    fn cpa_passing_abeam_hand_computed() {
        // Target 8 m ahead, 3 m to starboard, on a reciprocal course at 0.5 m/s;
        // own 0.5 m/s North. p = (8, 3), v = (-1, 0): t = 8 s, d = 3 m.
        let c = cpa([0.0, 0.0], [0.5, 0.0], [8.0, 3.0], [-0.5, 0.0]);
        assert!((c.tcpa - 8.0).abs() < 1e-12);
        assert!((c.dcpa - 3.0).abs() < 1e-12);
    }

    #[test]
    fn cpa_in_the_past_and_oblique() {
        // Target astern moving away: p = (-4, 0), v = (-1, 0): t = -4 s, d = 0.
        let c = cpa([0.0, 0.0], [0.0, 0.0], [-4.0, 0.0], [-1.0, 0.0]);
        assert!((c.tcpa + 4.0).abs() < 1e-12);
        assert!(!c.is_closing());
        // p = (3, 4), v = (0, -2): t = 8 / 4 = 2 s, p + t v = (3, 0): d = 3 m.
        let c = cpa([1.0, 1.0], [0.0, 1.0], [4.0, 5.0], [0.0, -1.0]);
        assert!((c.tcpa - 2.0).abs() < 1e-12);
        assert!((c.dcpa - 3.0).abs() < 1e-12);
    }

    #[test]
    fn cpa_without_relative_motion_is_infinite() {
        let c = cpa([0.0, 0.0], [0.3, 0.1], [5.0, 5.0], [0.3, 0.1]);
        assert_eq!(c.tcpa, f64::INFINITY);
        assert_eq!(c.dcpa, f64::INFINITY);
        assert!(!c.is_closing());
        // Just above the threshold it is finite.
        let c = cpa([0.0, 0.0], [0.0, 0.0], [5.0, 0.0], [-2.0e-6, 0.0]);
        assert!(c.tcpa.is_finite() && (c.tcpa - 2.5e6).abs() < 1e-3);
    }

    proptest! {
        #[test]
        fn wrap_in_range(a in -1.0e4f64..1.0e4) {
            let w = wrap_angle(a);
            prop_assert!(w > -PI && w <= PI);
            prop_assert!((w.sin() - a.sin()).abs() < 1e-9 && (w.cos() - a.cos()).abs() < 1e-9);
        }

        #[test]
        fn dcpa_is_the_minimum_range(
            px in -50.0f64..50.0, py in -50.0f64..50.0,
            vx in -2.0f64..2.0, vy in -2.0f64..2.0,
            t in -100.0f64..100.0,
        ) {
            prop_assume!(vx.hypot(vy) > 1e-3);
            let c = cpa([0.0, 0.0], [0.0, 0.0], [px, py], [vx, vy]);
            let range_t = (px + t * vx).hypot(py + t * vy);
            prop_assert!(c.dcpa <= range_t + 1e-9);
            prop_assert!(c.dcpa <= px.hypot(py) + 1e-9);
        }
    }
}
