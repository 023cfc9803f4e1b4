//! Traffic: static hazards (circles) and target ships (ellipses) on straight
//! courses, as in Du et al. (2022), Table 5 and eq. (9) / (14) (circle obstacles of
//! radius `R_j`, ellipse obstacles with long axis `a_j`).
//!
//! Motion is exact and analytic: a target ship at `(x0, y0)` with course `chi`
//! and speed `U`, activated at `t_a`, is at `(x0, y0) + U (t - t_a) (cos chi, sin chi)`
//! for `t >= t_a`. Before `t_a` it does not exist: it reports its spawn position
//! and size with kind [`ObstacleKind::None`] and speed 0 (see `paper/NOTES.md` section 2 for why the
//! paper's targets B and C need a late activation).
//!
//! A target is activated by time (`activation_time`, known in advance) or by
//! range (`activation_range`: the ship came that close to the spawn position),
//! whichever comes first. Range activation depends on the run, so its time is
//! dynamic state kept by [`crate::World`]; [`TrafficObstacle::output_activated`] takes the
//! effective activation time, [`TrafficObstacle::output_at`] uses the time trigger only.

use serde::{Deserialize, Serialize};

use crate::vessel::ParamError;

/// What occupies an obstacle slot ([`ObstacleSlot::kind`]): the FMI Integer
/// `obstacle[k].kind` (0, 1, 2 in docs/interface.md) is this enum's code, converted only
/// by the value-reference codec of `towing-interface`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
pub enum ObstacleKind {
    /// An empty slot, or a target ship not yet active; its other fields are not read.
    #[default]
    None,
    /// A static hazard, a circle of diameter `length` = `width` (Du et al. 2022,
    /// eq. (9), first line).
    StaticCircle,
    /// A target ship, an ellipse with major axis `length` and minor axis `width` along
    /// its course `psi`, moving at `speed` (eq. (9), focal sum).
    VesselEllipse,
}

/// Shape and motion of an obstacle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ObstacleShape {
    /// A static hazard, a circle of the given diameter (m).
    Circle {
        /// Diameter `2 R_j` (m).
        diameter: f64,
    },
    /// A target ship, an ellipse with its major axis along the course.
    Vessel {
        /// Length = major axis `a_j` (m).
        length: f64,
        /// Width = minor axis (m).
        width: f64,
        /// Course `chi` over ground, from North, clockwise (rad, `(-pi, pi]`).
        course: f64,
        /// Speed over ground (m/s, >= 0).
        speed: f64,
        /// Time at which it appears and starts moving unless the range trigger
        /// fired earlier (s, >= 0; `f64::INFINITY`: never by time, only with an
        /// `activation_range`).
        activation_time: f64,
        /// Range trigger (m, > 0): it appears at the end of the first
        /// communication step (or at `t = 0`) at which the ship's centre is within
        /// this distance of the spawn position `(x, y)`; `None`: time only.
        activation_range: Option<f64>,
    },
}

/// One obstacle of a scenario's traffic (its `[[obstacles]]` entry): a static hazard or a
/// target ship, with its name, spawn position and motion. What it shows at a time `t` is
/// an [`ObstacleSlot`].
#[derive(Debug, Clone, PartialEq)]
pub struct TrafficObstacle {
    /// Name (unique within a scenario), e.g. `"A"`.
    pub name: String,
    /// Spawn position North (m).
    pub x: f64,
    /// Spawn position East (m).
    pub y: f64,
    /// Shape and motion.
    pub shape: ObstacleShape,
}

/// One obstacle slot at a time `t` (`obstacle[k].*` of docs/interface.md): what the plant
/// outputs about the `k`-th obstacle of the scenario and what the controller reads. The
/// one type on both ends of the connection.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct ObstacleSlot {
    /// Centre North (m).
    pub x: f64,
    /// Centre East (m).
    pub y: f64,
    /// Heading = course (rad); 0 for static obstacles and empty slots.
    pub psi: f64,
    /// Speed (m/s); 0 before activation, for static obstacles and empty slots.
    pub speed: f64,
    /// Length (m): ellipse major axis, or the circle's diameter.
    pub length: f64,
    /// Width (m): ellipse minor axis, or the circle's diameter.
    pub width: f64,
    /// What occupies the slot.
    pub kind: ObstacleKind,
}

impl ObstacleSlot {
    /// An empty slot: all zero, [`ObstacleKind::None`].
    pub const EMPTY: ObstacleSlot = ObstacleSlot {
        x: 0.0,
        y: 0.0,
        psi: 0.0,
        speed: 0.0,
        length: 0.0,
        width: 0.0,
        kind: ObstacleKind::None,
    };
}

impl TrafficObstacle {
    /// True when the obstacle exists at time `t` by the time trigger alone
    /// (static: always; ship: `t >= activation_time`). Range activation is not
    /// known here; see [`crate::World::activation_time`].
    #[must_use]
    pub fn is_active(&self, t: f64) -> bool {
        match self.shape {
            ObstacleShape::Circle { .. } => true,
            ObstacleShape::Vessel {
                activation_time, ..
            } => t >= activation_time,
        }
    }

    /// The time trigger of a target ship (s; `f64::INFINITY` when only the range
    /// triggers it); `None` for a static obstacle.
    #[must_use]
    pub fn activation_time(&self) -> Option<f64> {
        match self.shape {
            ObstacleShape::Circle { .. } => None,
            ObstacleShape::Vessel {
                activation_time, ..
            } => Some(activation_time),
        }
    }

    /// The range trigger of a target ship (m); `None` for a static obstacle or a
    /// target activated by time only.
    #[must_use]
    pub fn activation_range(&self) -> Option<f64> {
        match self.shape {
            ObstacleShape::Circle { .. } => None,
            ObstacleShape::Vessel {
                activation_range, ..
            } => activation_range,
        }
    }

    /// State at time `t` (s), exact, with the time trigger only (as if the range
    /// trigger never fired).
    #[must_use]
    pub fn output_at(&self, t: f64) -> ObstacleSlot {
        let by_time = self.activation_time().filter(|&t_a| t >= t_a);
        self.output_activated(t, by_time)
    }

    /// State at time `t` (s), exact, of an obstacle whose effective activation
    /// time is `activated_at` (`None`: not activated yet). A target ship exists
    /// when `activated_at = Some(t_a)` with `t >= t_a` and is then at
    /// `(x, y) + speed (t - t_a) (cos, sin)(course)`. Static obstacles ignore
    /// `activated_at`.
    #[must_use]
    pub fn output_activated(&self, t: f64, activated_at: Option<f64>) -> ObstacleSlot {
        match self.shape {
            ObstacleShape::Circle { diameter } => ObstacleSlot {
                x: self.x,
                y: self.y,
                psi: 0.0,
                speed: 0.0,
                length: diameter,
                width: diameter,
                kind: ObstacleKind::StaticCircle,
            },
            ObstacleShape::Vessel {
                length,
                width,
                course,
                speed,
                ..
            } => {
                if let Some(t_a) = activated_at.filter(|&t_a| t >= t_a) {
                    let run = speed * (t - t_a);
                    let (s, c) = course.sin_cos();
                    ObstacleSlot {
                        x: self.x + run * c,
                        y: self.y + run * s,
                        psi: course,
                        speed,
                        length,
                        width,
                        kind: ObstacleKind::VesselEllipse,
                    }
                } else {
                    ObstacleSlot {
                        x: self.x,
                        y: self.y,
                        psi: course,
                        speed: 0.0,
                        length,
                        width,
                        kind: ObstacleKind::None,
                    }
                }
            }
        }
    }

    /// Checks the values (paths relative to the obstacle, as in the scenario file):
    /// finite position, diameter / length / width > 0, width <= length, course
    /// finite, speed >= 0, activation time finite and >= 0 (or `+inf` together
    /// with an activation range), activation range finite and > 0.
    pub fn validate(&self) -> Result<(), ParamError> {
        use crate::vessel::{
            check_coordinate, check_finite, check_length, check_non_negative, check_speed,
        };
        if self.name.trim().is_empty() {
            return Err(ParamError::new("name", "must not be empty"));
        }
        check_coordinate("x", self.x)?;
        check_coordinate("y", self.y)?;
        match self.shape {
            ObstacleShape::Circle { diameter } => check_length("diameter", diameter)?,
            ObstacleShape::Vessel {
                length,
                width,
                course,
                speed,
                activation_time,
                activation_range,
            } => {
                check_length("length", length)?;
                check_length("width", width)?;
                if width > length {
                    return Err(ParamError::new(
                        "width",
                        format!(
                            "must not exceed length ({length} m; length is the ellipse's major axis), got {width} m"
                        ),
                    ));
                }
                check_finite("course_deg", course)?;
                check_non_negative("speed", speed, "m/s")?;
                check_speed("speed", speed)?;
                if let Some(range) = activation_range {
                    check_length("activation_range", range)?;
                }
                // +inf is "never by time": allowed only when the range triggers it.
                if !(activation_time == f64::INFINITY && activation_range.is_some()) {
                    check_non_negative("activation_time", activation_time, "s")?;
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn target(activation_time: f64) -> TrafficObstacle {
        TrafficObstacle {
            name: "B".into(),
            x: -22.0,
            y: 40.75,
            shape: ObstacleShape::Vessel {
                length: 1.48,
                width: 0.48,
                course: 0.0,
                speed: 0.07,
                activation_time,
                activation_range: None,
            },
        }
    }

    fn set_triggers(o: &mut TrafficObstacle, time: f64, range: Option<f64>) {
        if let ObstacleShape::Vessel {
            activation_time,
            activation_range,
            ..
        } = &mut o.shape
        {
            *activation_time = time;
            *activation_range = range;
        }
    }

    #[test]
    fn output_activated_moves_from_the_given_activation_time() {
        // Range-only target: never active by time, active from whatever time the
        // world says it was activated.
        let mut b = target(0.0);
        set_triggers(&mut b, f64::INFINITY, Some(14.0));
        assert_eq!(b.output_at(1e6).kind, ObstacleKind::None);
        assert!(!b.is_active(1e6));
        assert_eq!(b.output_activated(500.0, None).kind, ObstacleKind::None);
        // Not yet at 399 s when activated at 400 s.
        assert_eq!(
            b.output_activated(399.0, Some(400.0)).kind,
            ObstacleKind::None
        );
        let at = b.output_activated(400.0, Some(400.0));
        assert_eq!(
            (at.kind, at.x, at.y, at.speed),
            (ObstacleKind::VesselEllipse, -22.0, 40.75, 0.07)
        );
        let later = b.output_activated(500.0, Some(400.0));
        assert!((later.x - (-22.0 + 7.0)).abs() < 1e-12);
        assert_eq!(b.activation_time(), Some(f64::INFINITY));
        assert_eq!(b.activation_range(), Some(14.0));
    }

    #[test]
    fn activation_range_validation() {
        for (time, range, ok) in [
            (f64::INFINITY, Some(14.0), true),
            (5.0, Some(14.0), true),
            (f64::INFINITY, None, false),
            (f64::NAN, Some(14.0), false),
            (0.0, Some(0.0), false),
            (0.0, Some(-1.0), false),
            (0.0, Some(f64::INFINITY), false),
            (0.0, Some(f64::NAN), false),
        ] {
            let mut o = target(0.0);
            set_triggers(&mut o, time, range);
            match o.validate() {
                Ok(()) => assert!(ok, "{time} {range:?} accepted"),
                Err(e) => {
                    assert!(!ok, "{time} {range:?} refused: {e:?}");
                    let field = if range.is_some_and(|r| !(r.is_finite() && r > 0.0)) {
                        "activation_range"
                    } else {
                        "activation_time"
                    };
                    assert_eq!(e.field, field);
                }
            }
        }
    }

    #[test]
    fn target_ship_is_inactive_before_activation_and_moves_exactly_after() {
        let b = target(405.0);
        let before = b.output_at(404.9);
        assert_eq!(before.kind, ObstacleKind::None);
        assert_eq!((before.x, before.y, before.speed), (-22.0, 40.75, 0.0));
        assert_eq!((before.length, before.width), (1.48, 0.48));
        let at = b.output_at(405.0);
        assert_eq!(at.kind, ObstacleKind::VesselEllipse);
        assert_eq!((at.x, at.y), (-22.0, 40.75));
        let later = b.output_at(505.0);
        assert!((later.x - (-22.0 + 7.0)).abs() < 1e-12);
        assert!((later.y - 40.75).abs() < 1e-12);
        assert_eq!(later.speed, 0.07);
        assert!(!b.is_active(0.0) && b.is_active(405.0));
    }

    #[test]
    fn course_east_moves_east() {
        let mut o = target(0.0);
        if let ObstacleShape::Vessel { course, .. } = &mut o.shape {
            *course = std::f64::consts::FRAC_PI_2;
        }
        let out = o.output_at(10.0);
        assert!((out.x + 22.0).abs() < 1e-12 && (out.y - 41.45).abs() < 1e-12);
        assert_eq!(out.psi, std::f64::consts::FRAC_PI_2);
    }

    #[test]
    fn static_circle_reports_its_diameter() {
        let a = TrafficObstacle {
            name: "a".into(),
            x: -10.0,
            y: 15.0,
            shape: ObstacleShape::Circle { diameter: 1.0 },
        };
        let out = a.output_at(1234.0);
        assert_eq!(
            out,
            ObstacleSlot {
                x: -10.0,
                y: 15.0,
                psi: 0.0,
                speed: 0.0,
                length: 1.0,
                width: 1.0,
                kind: ObstacleKind::StaticCircle
            }
        );
    }

    #[test]
    fn validation() {
        let mut o = target(0.0);
        if let ObstacleShape::Vessel { width, .. } = &mut o.shape {
            *width = 2.0;
        }
        assert_eq!(o.validate().unwrap_err().field, "width");
        let mut o = target(0.0);
        if let ObstacleShape::Vessel { speed, .. } = &mut o.shape {
            *speed = -0.1;
        }
        assert_eq!(o.validate().unwrap_err().field, "speed");
        let mut o = target(0.0);
        if let ObstacleShape::Vessel {
            activation_time, ..
        } = &mut o.shape
        {
            *activation_time = -1.0;
        }
        assert_eq!(o.validate().unwrap_err().field, "activation_time");
    }
}
