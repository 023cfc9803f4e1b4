//! Obstacles and their distances: Du et al. (2022), eq. (9) (distance), eq. (14)
//! (safe distance), Fig. 5.
//!
//! # Reading of eq. (9) and eq. (14)
//!
//! The extracted eq. (9) is garbled. What survives: a static obstacle is a circle
//! and its distance is `|P O_j|`, own vessel position `P` to the centre `O_j`; a
//! target ship is an ellipse, and the formula lists `|P F_j1|` and `|P F_j2|`, the
//! distances to its two foci. We read the ellipse distance as the **focal sum**
//! `d = |P F_1| + |P F_2|` ("an ellipse through its foci"): it is the quantity
//! whose level sets are ellipses confocal with the target, and it is the reading
//! under which eq. (14)'s ellipse safe distance `2 (L + a_j + d_S0)` is consistent:
//! the focal sum equals `2 a` on the target's own outline and `2 s` at a point of
//! the major axis at distance `s` from the centre, so `d = 2 (L + a + d_S0)` is the
//! confocal ellipse whose tips lie `L + d_S0` beyond the target's bow and stern.
//!
//! `a_j` ("the length of the long axis") is taken as the **semi-major axis**
//! `a = length / 2`, for three reasons: (i) with `a` the semi-axis, a round target
//! (`length = width`, foci at the centre) has focal sum `2 |P O|`, and eq. (14)'s
//! ellipse line `2 (L + a + d_S0)` becomes exactly twice the circle line
//! `L + R + d_S0` with `R = a`: one rule for both shapes; (ii) the clearance beyond
//! the target's ends is then `L + d_S0`, the same as beyond a circle's rim;
//! (iii) with the full length the clearance would grow by half a target length
//! along the axis only, for no stated reason. Focal points sit on the major axis
//! at `centre ± c (cos psi, sin psi)`, `c = sqrt(a^2 - b^2)`, `b = width / 2`.
//!
//! Because the focal sum is about twice a range, comparing it and a circle's centre
//! distance with one detection distance `d_D` (eq. (8)) would detect ships at half
//! the range of hazards. This crate therefore compares the **range-equivalent
//! distance** with `d_D`: the centre distance for a circle and half the focal sum
//! (the semi-major axis of the confocal ellipse through `P`) for a ship. Both are
//! metres of range, equal the centre distance for a round obstacle and tend to it
//! far away. [`ActiveObstacle::distance_eq9`] and [`ActiveObstacle::safe_distance_eq14`] keep
//! the paper's own units for the MPC's cost (eq. (13)).

use serde::{Deserialize, Serialize};

use towing_model::{ObstacleKind, ObstacleSlot};

use crate::error::InputError;
use crate::geometry::dist;

/// A target ship as an ellipse along its heading (Fig. 5).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Ellipse {
    /// Centre `(x North, y East)` (m).
    pub centre: [f64; 2],
    /// Heading = course (rad).
    pub psi: f64,
    /// Speed over ground (m/s).
    pub speed: f64,
    /// Semi-major axis `a = length / 2` (m); the paper's `a_j` (see the module doc).
    pub semi_major: f64,
    /// Semi-minor axis `b = width / 2` (m), `b <= a`.
    pub semi_minor: f64,
}

impl Ellipse {
    /// Focal distance `c = sqrt(a^2 - b^2)` (m).
    #[must_use]
    pub fn focal_distance(&self) -> f64 {
        (self.semi_major * self.semi_major - self.semi_minor * self.semi_minor)
            .max(0.0)
            .sqrt()
    }

    /// The foci `F_1 = centre + c (cos psi, sin psi)` (forward) and
    /// `F_2 = centre - c (cos psi, sin psi)` (aft), on the major axis (Fig. 5).
    #[must_use]
    pub fn foci(&self) -> [[f64; 2]; 2] {
        let c = self.focal_distance();
        let (s, co) = self.psi.sin_cos();
        [
            [self.centre[0] + c * co, self.centre[1] + c * s],
            [self.centre[0] - c * co, self.centre[1] - c * s],
        ]
    }

    /// Focal sum `|P F_1| + |P F_2|` (m), eq. (9) for an ellipse obstacle. It is
    /// `2 a` on the outline, less inside, more outside, and
    /// `2 |P O| <= sum <= 2 sqrt(|P O|^2 + c^2)`.
    #[must_use]
    pub fn focal_sum(&self, point: [f64; 2]) -> f64 {
        let [f1, f2] = self.foci();
        dist(point, f1) + dist(point, f2)
    }

    /// Ground velocity in NED (m/s).
    #[must_use]
    pub fn velocity(&self) -> [f64; 2] {
        let (s, c) = self.psi.sin_cos();
        [self.speed * c, self.speed * s]
    }
}

/// A validated, active obstacle: what an [`ObstacleSlot`] of kind
/// [`ObstacleKind::StaticCircle`] or [`ObstacleKind::VesselEllipse`] becomes
/// ([`ActiveObstacle::from_slot`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum ActiveObstacle {
    /// Static hazard.
    Circle {
        /// Centre `(x North, y East)` (m).
        centre: [f64; 2],
        /// Radius `R_j` (m).
        radius: f64,
    },
    /// Target ship.
    Vessel(Ellipse),
}

impl ActiveObstacle {
    /// Checks an obstacle slot and returns the obstacle, or `None` for
    /// [`ObstacleKind::None`] (whose other fields are not looked at).
    ///
    /// Circles: `R = max(length, width) / 2` (the plant reports the diameter in
    /// both; the larger one is the conservative choice if they differ).
    /// Ships: `a = length / 2`, `b = width / 2`, `0 <= width <= length`.
    ///
    /// # Errors
    /// A non-finite field, non-positive length, negative width or speed, or a ship
    /// wider than long: refused, never clamped.
    pub fn from_slot(slot: &ObstacleSlot) -> Result<Option<Self>, InputError> {
        if slot.kind == ObstacleKind::None {
            return Ok(None);
        }
        let fields = [
            ("x", slot.x),
            ("y", slot.y),
            ("psi", slot.psi),
            ("speed", slot.speed),
            ("length", slot.length),
            ("width", slot.width),
        ];
        for (name, value) in fields {
            if !value.is_finite() {
                return Err(InputError::NonFiniteObstacle { field: name });
            }
        }
        if slot.length <= 0.0 || slot.width < 0.0 {
            return Err(InputError::BadObstacleSize {
                length: slot.length,
                width: slot.width,
            });
        }
        let centre = [slot.x, slot.y];
        Ok(Some(match slot.kind {
            ObstacleKind::StaticCircle => Self::Circle {
                centre,
                radius: 0.5 * slot.length.max(slot.width),
            },
            _ => {
                if slot.width > slot.length {
                    return Err(InputError::BadObstacleSize {
                        length: slot.length,
                        width: slot.width,
                    });
                }
                if slot.speed < 0.0 {
                    return Err(InputError::NegativeSpeed { speed: slot.speed });
                }
                Self::Vessel(Ellipse {
                    centre,
                    psi: slot.psi,
                    speed: slot.speed,
                    semi_major: 0.5 * slot.length,
                    semi_minor: 0.5 * slot.width,
                })
            }
        }))
    }

    /// Its [`ObstacleKind`].
    #[must_use]
    pub fn kind(&self) -> ObstacleKind {
        match self {
            Self::Circle { .. } => ObstacleKind::StaticCircle,
            Self::Vessel(_) => ObstacleKind::VesselEllipse,
        }
    }

    /// Centre (m).
    #[must_use]
    pub fn centre(&self) -> [f64; 2] {
        match self {
            Self::Circle { centre, .. } => *centre,
            Self::Vessel(e) => e.centre,
        }
    }

    /// Eq. (9): `|P O_j|` for a circle, the focal sum `|P F_1| + |P F_2|` for a ship
    /// (m). The unit of comparison with [`ActiveObstacle::safe_distance_eq14`].
    #[must_use]
    pub fn distance_eq9(&self, point: [f64; 2]) -> f64 {
        match self {
            Self::Circle { centre, .. } => dist(point, *centre),
            Self::Vessel(e) => e.focal_sum(point),
        }
    }

    /// Range-equivalent distance (m): `|P O_j|` for a circle, half the focal sum for
    /// a ship. The quantity compared with the detection distance `d_D` (eq. (8));
    /// see the module doc for why.
    #[must_use]
    pub fn range(&self, point: [f64; 2]) -> f64 {
        match self {
            Self::Circle { centre, .. } => dist(point, *centre),
            Self::Vessel(e) => 0.5 * e.focal_sum(point),
        }
    }

    /// Eq. (14): safe distance of an own vessel of length `own_length` (m) with
    /// buffer `d_s0` (m): `L + R_j + d_S0` for a circle, `2 (L + a_j + d_S0)` for a
    /// ship, in the units of [`ActiveObstacle::distance_eq9`].
    #[must_use]
    pub fn safe_distance_eq14(&self, own_length: f64, d_s0: f64) -> f64 {
        match self {
            Self::Circle { radius, .. } => own_length + radius + d_s0,
            Self::Vessel(e) => 2.0 * (own_length + e.semi_major + d_s0),
        }
    }

    /// Eq. (14) in the units of [`ActiveObstacle::range`]: `L + R_j + d_S0` or
    /// `L + a_j + d_S0` (m).
    #[must_use]
    pub fn safe_range(&self, own_length: f64, d_s0: f64) -> f64 {
        match self {
            Self::Circle { radius, .. } => own_length + radius + d_s0,
            Self::Vessel(e) => own_length + e.semi_major + d_s0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn ship(length: f64, width: f64, psi: f64) -> Ellipse {
        Ellipse {
            centre: [2.0, -3.0],
            psi,
            speed: 0.07,
            semi_major: 0.5 * length,
            semi_minor: 0.5 * width,
        }
    }

    /// Point of the ellipse scaled by `scale` at parameter `t`.
    fn ellipse_point(e: &Ellipse, t: f64, scale: f64) -> [f64; 2] {
        let (s, c) = e.psi.sin_cos();
        let along = scale * e.semi_major * t.cos();
        let across = scale * e.semi_minor * t.sin();
        // Major axis (c, s), minor axis to starboard (-s, c).
        [
            e.centre[0] + along * c - across * s,
            e.centre[1] + along * s + across * c,
        ]
    }

    #[test]
    fn paper_target_foci() {
        // Table 5 target: 1.48 m x 0.48 m heading North: a = 0.74, b = 0.24,
        // c = sqrt(0.74^2 - 0.24^2) = sqrt(0.49) = 0.7.
        let e = ship(1.48, 0.48, 0.0);
        assert!((e.focal_distance() - 0.7).abs() < 1e-12);
        let [f1, f2] = e.foci();
        assert!((f1[0] - 2.7).abs() < 1e-12 && (f1[1] + 3.0).abs() < 1e-12);
        assert!((f2[0] - 1.3).abs() < 1e-12 && (f2[1] + 3.0).abs() < 1e-12);
    }

    #[test]
    fn focal_sum_on_major_and_minor_axis() {
        // Heading East: major axis along y. A point 3 m ahead of the centre on the
        // axis: (3 - c) + (3 + c) = 6 = 2 s.
        let e = ship(1.48, 0.48, std::f64::consts::FRAC_PI_2);
        let p = [e.centre[0], e.centre[1] + 3.0];
        assert!((e.focal_sum(p) - 6.0).abs() < 1e-12);
        // On the minor axis at 2.4 m: 2 sqrt(2.4^2 + 0.7^2) = 2 * 2.5 = 5.
        let p = [e.centre[0] - 2.4, e.centre[1]];
        assert!((e.focal_sum(p) - 5.0).abs() < 1e-12);
        // At the bow tip the focal sum is 2 a = length.
        let p = [e.centre[0], e.centre[1] + 0.74];
        assert!((e.focal_sum(p) - 1.48).abs() < 1e-12);
    }

    #[test]
    fn round_vessel_degenerates_to_twice_the_centre_distance() {
        let e = ship(1.0, 1.0, 0.3);
        assert_eq!(e.focal_distance(), 0.0);
        let p = [5.0, 1.0];
        let d = dist(p, e.centre);
        assert!((e.focal_sum(p) - 2.0 * d).abs() < 1e-12);
        let o = ActiveObstacle::Vessel(e);
        assert!((o.range(p) - d).abs() < 1e-12);
        // Eq. (14) then is twice the circle line with R = a.
        let c = ActiveObstacle::Circle {
            centre: e.centre,
            radius: 0.5,
        };
        assert!(
            (o.safe_distance_eq14(1.255, 0.25) - 2.0 * c.safe_distance_eq14(1.255, 0.25)).abs()
                < 1e-12
        );
        assert!((o.safe_range(1.255, 0.25) - c.safe_range(1.255, 0.25)).abs() < 1e-12);
    }

    #[test]
    fn eq14_values() {
        let c = ActiveObstacle::Circle {
            centre: [0.0, 0.0],
            radius: 0.5,
        };
        assert!((c.safe_distance_eq14(1.255, 0.25) - 2.005).abs() < 1e-12);
        let v = ActiveObstacle::Vessel(ship(1.48, 0.48, 0.0));
        assert!((v.safe_distance_eq14(1.255, 0.25) - 4.49).abs() < 1e-12);
        assert!((v.safe_range(1.255, 0.25) - 2.245).abs() < 1e-12);
        // The eq. (14) level set is where the ship's CG is L + d_S0 beyond the bow:
        let bow_clear = [v.centre()[0] + 0.74 + 1.255 + 0.25, v.centre()[1]];
        assert!((v.distance_eq9(bow_clear) - v.safe_distance_eq14(1.255, 0.25)).abs() < 1e-12);
    }

    #[test]
    fn slot_validation() {
        let ok = ObstacleSlot {
            x: 1.0,
            y: 2.0,
            psi: 0.0,
            speed: 0.07,
            length: 1.48,
            width: 0.48,
            kind: ObstacleKind::VesselEllipse,
        };
        let check = |slot: ObstacleSlot| ActiveObstacle::from_slot(&slot);
        assert!(matches!(check(ok), Ok(Some(ActiveObstacle::Vessel(_)))));
        let none = ObstacleSlot {
            x: f64::NAN,
            kind: ObstacleKind::None,
            ..ok
        };
        assert_eq!(check(none), Ok(None));
        assert!(matches!(
            check(ObstacleSlot {
                y: f64::INFINITY,
                ..ok
            }),
            Err(InputError::NonFiniteObstacle { field: "y" })
        ));
        assert!(check(ObstacleSlot { width: 2.0, ..ok }).is_err());
        assert!(check(ObstacleSlot { length: 0.0, ..ok }).is_err());
        assert!(check(ObstacleSlot { speed: -0.1, ..ok }).is_err());
        // A circle uses the larger of its two sizes as the diameter.
        let circle = ObstacleSlot {
            kind: ObstacleKind::StaticCircle,
            length: 1.0,
            width: 1.2,
            ..ok
        };
        assert_eq!(
            check(circle),
            Ok(Some(ActiveObstacle::Circle {
                centre: [1.0, 2.0],
                radius: 0.6
            }))
        );
    }

    proptest! {
        #[test]
        fn focal_sum_is_2a_on_the_outline(
            length in 0.1f64..5.0, ratio in 0.0f64..1.0, psi in -4.0f64..4.0, t in -4.0f64..4.0,
        ) {
            let e = ship(length, ratio * length, psi);
            let p = ellipse_point(&e, t, 1.0);
            prop_assert!((e.focal_sum(p) - length).abs() < 1e-9 * length.max(1.0));
        }

        #[test]
        fn focal_sum_outside_exceeds_2a_inside_below(
            length in 0.1f64..5.0, ratio in 0.0f64..0.99, psi in -4.0f64..4.0,
            t in -4.0f64..4.0, scale in 0.0f64..10.0,
        ) {
            prop_assume!((scale - 1.0).abs() > 1e-3);
            let e = ship(length, ratio * length, psi);
            let p = ellipse_point(&e, t, scale);
            let s = e.focal_sum(p);
            if scale > 1.0 {
                prop_assert!(s > length);
            } else {
                prop_assert!(s < length + 1e-12);
            }
        }

        #[test]
        fn focal_sum_bounded_by_centre_distance(
            length in 0.1f64..5.0, ratio in 0.0f64..1.0, psi in -4.0f64..4.0,
            px in -20.0f64..20.0, py in -20.0f64..20.0,
        ) {
            let e = ship(length, ratio * length, psi);
            let p = [px, py];
            let d = dist(p, e.centre);
            let c = e.focal_distance();
            let s = e.focal_sum(p);
            prop_assert!(s >= 2.0 * d - 1e-9);
            prop_assert!(s <= 2.0 * (d * d + c * c).sqrt() + 1e-9);
            // So the range-equivalent distance is never below the centre distance,
            // and exceeds it by at most c.
            let r = ActiveObstacle::Vessel(e).range(p);
            prop_assert!(r >= d - 1e-9 && r <= d + c + 1e-9);
        }
    }
}
