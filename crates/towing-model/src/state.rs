//! Plain state types shared by the scenario and the world: a pose on a route ([`Pose`])
//! and a vessel's pose and velocity ([`VesselState`]). Conventions as in the crate docs
//! (NED, `psi` from North, clockwise positive, radians).

use serde::{Deserialize, Serialize};

use crate::angle::wrap_angle;

/// A pose in NED: `x` North (m), `y` East (m), `psi` heading from North, clockwise
/// (rad, `(-pi, pi]`); the paper's `eta = [x, y, psi]` (Du et al. 2022, eq. (1)). The
/// route's points of a scenario and the guidance's waypoints.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Pose {
    /// North (m).
    pub x: f64,
    /// East (m).
    pub y: f64,
    /// Heading (rad, `(-pi, pi]`).
    pub psi: f64,
}

impl Pose {
    /// A pose from metres and radians.
    #[must_use]
    pub const fn new(x: f64, y: f64, psi: f64) -> Self {
        Self { x, y, psi }
    }

    /// A pose from metres and a heading in degrees (for tables such as the paper's
    /// Table 4), the heading wrapped to `(-pi, pi]`.
    #[must_use]
    pub fn from_deg(x: f64, y: f64, psi_deg: f64) -> Self {
        Self::new(x, y, wrap_angle(psi_deg.to_radians()))
    }

    /// Position `(x, y)` (m).
    #[must_use]
    pub fn position(&self) -> [f64; 2] {
        [self.x, self.y]
    }

    /// `[x, y, psi]`, the paper's `eta`.
    #[must_use]
    pub fn eta(&self) -> [f64; 3] {
        [self.x, self.y, self.psi]
    }

    /// True when `x`, `y` and `psi` are all finite.
    #[must_use]
    pub fn is_finite(&self) -> bool {
        self.x.is_finite() && self.y.is_finite() && self.psi.is_finite()
    }
}

/// Pose and velocity of one vessel: `eta = [x North (m), y East (m), psi (rad,
/// (-pi, pi])]`, `nu = [u (m/s), v (m/s), r (rad/s)]` in the body frame. Plain
/// arrays so users need no linear-algebra crate; `nalgebra::Vector3::from(eta)`
/// converts.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct VesselState {
    /// `[x, y, psi]`, NED position (m) and heading (rad).
    pub eta: [f64; 3],
    /// `[u, v, r]`, body velocities (m/s, m/s, rad/s).
    pub nu: [f64; 3],
}
