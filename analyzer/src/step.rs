//! One plant step as typed values: what every metric sees of a run, row by row.
//!
//! The analysis builds a [`PlantStep`] for every plant step of the log (the vessels, the
//! active obstacles, and the controller's last sample at or before the step, joined as
//! of the step's time) and hands it to each metric in time order. A metric keeps its own
//! O(1) state (or bounded state per obstacle) and never sees a DataFrame.

use crate::colregs::Situation;

/// State of one vessel at the end of a plant step (NED; body-frame velocities).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Vessel {
    /// North position of the body origin, m.
    pub x: f64,
    /// East position of the body origin, m.
    pub y: f64,
    /// Heading from North, clockwise, rad, wrapped to (-pi, pi].
    pub psi: f64,
    /// Surge velocity, m/s (forward).
    pub u: f64,
    /// Sway velocity, m/s (starboard).
    pub v: f64,
    /// Yaw rate, rad/s (clockwise).
    pub r: f64,
}

impl Vessel {
    /// Speed over ground, m/s.
    #[must_use]
    pub fn sog(&self) -> f64 {
        self.u.hypot(self.v)
    }

    /// Velocity over ground, North and East, m/s.
    #[must_use]
    pub fn vel_n(&self) -> [f64; 2] {
        let (s, c) = self.psi.sin_cos();
        [c * self.u - s * self.v, s * self.u + c * self.v]
    }
}

/// Kind of an obstacle slot.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ObstacleKind {
    /// A static hazard (circle).
    Static,
    /// A target ship (ellipse moving on a straight line).
    Ship,
}

/// One active obstacle at a plant step.
#[derive(Debug, Clone, PartialEq)]
pub struct Obstacle {
    /// Slot number, 1-based (the scenario's `[[obstacles]]` order).
    pub slot: u32,
    /// Name from the scenario.
    pub name: String,
    /// Static hazard or target ship.
    pub kind: ObstacleKind,
    /// North position of the centre, m.
    pub x: f64,
    /// East position of the centre, m.
    pub y: f64,
    /// Course of a target ship from North, clockwise, rad (0 for hazards).
    pub course: f64,
    /// Speed of a target ship, m/s (0 for hazards).
    pub speed: f64,
    /// Major axis (ship) or diameter (hazard), m.
    pub length: f64,
    /// Minor axis (ship) or diameter (hazard), m.
    pub width: f64,
}

/// The controller's encounter with one slot at a control sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ControlEncounter {
    /// Obstacle slot, 1-based.
    pub slot: u32,
    /// The guidance's situation (`None`: the log's code -1, no encounter).
    pub situation: Option<Situation>,
    /// The tow's role code (0 none, 1 give-way, 2 stand-on).
    pub role_code: i32,
}

/// The controller's last sample at or before a plant step.
#[derive(Debug, Clone, PartialEq)]
pub struct ControlSample {
    /// Time of the sample, s.
    pub t: f64,
    /// The guidance's reference was the altered waypoint.
    pub altered: bool,
    /// Index of the active waypoint, 1-based.
    pub active_waypoint: u32,
    /// Encounters reported at the sample, in slot order.
    pub encounters: Vec<ControlEncounter>,
}

/// One plant step: what every metric is handed, in time order.
#[derive(Debug, Clone, Copy)]
pub struct PlantStep<'a> {
    /// Plant time at the end of the step, s.
    pub t: f64,
    /// Ship, tug 1 (aft), tug 2 (forward).
    pub vessels: [Vessel; 3],
    /// Active obstacles (static hazards and activated target ships), in slot order.
    pub obstacles: &'a [Obstacle],
    /// The controller's last sample at or before `t` (`None` without a controller log,
    /// or before its first sample).
    pub control: Option<&'a ControlSample>,
}

/// What a metric knows of the run before the first step.
#[derive(Debug, Clone, PartialEq)]
pub struct RunGeometry {
    /// Length and width of the ship, tug 1 and tug 2, m.
    pub sizes: [[f64; 2]; 3],
    /// Route points (origin, waypoints, destination): North m, East m, heading rad.
    pub route: Vec<[f64; 3]>,
    /// The scenario's waterway half width, m (`None`: no `[waterway]`).
    pub half_width: Option<f64>,
    /// Detection distance `d_D` for target ships, m.
    pub detection_distance: f64,
}

/// The time a step stands for: since the previous step (0 for the first step, and for a
/// step not after the previous one). A plant step's `t` is the end of the step, so a
/// condition holding at the steps with `t` in `(a, b]` on a regular grid lasts `b - a`.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct StepClock {
    prev: Option<f64>,
}

impl StepClock {
    /// The time since the previous call's `t`, s.
    pub fn dt(&mut self, t: f64) -> f64 {
        let dt = self.prev.map_or(0.0, |p| (t - p).max(0.0));
        self.prev = Some(t);
        if dt.is_finite() {
            dt
        } else {
            0.0
        }
    }
}
