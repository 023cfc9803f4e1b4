//! The two towlines between the ship and the tugs, with forces from geometry.
//!
//! Towline 1 joins the ship's stern towing point to the aft tug's (tug 1's) bow
//! point; towline 2 joins the ship's bow point to the forward tug's (tug 2's) stern
//! point (Du et al. 2022, Fig. 1 and Table 2; `paper/NOTES.md` section 1). A taut
//! line with tension `T` pulls each end towards the other along the straight line
//! between the two attachment points: the force on the ship is `T e` with `e` the
//! unit vector from the ship's point to the tug's point, the force on the tug is
//! `-T e` (equal and opposite), and each body gets the moment `r x F` of its own
//! attachment point `r` (body frame, from CO). Nothing of the paper's
//! configuration vectors is copied: see below why.
//!
//! # Towing angle
//!
//! The towing angle is an *output* of the geometry, as the paper defines it in the
//! consistent form of `paper/NOTES.md`: with `psi_S` the ship's heading,
//!
//! - `alpha_2 = bearing(tug-2 point - ship bow point) - psi_S`,
//! - `alpha_1 = bearing(ship stern point - tug-1 point) - psi_S`,
//!
//! wrapped to `(-pi, pi]`, where `bearing(d) = atan2(d_East, d_North)`. Both are
//! the direction of the line, taken from aft to forward, relative to the ship's
//! heading: `alpha_i > 0` means the line is turned clockwise (to starboard). So a
//! forward tug displaced to starboard gives `alpha_2 > 0`, while an *aft* tug
//! displaced to starboard gives `alpha_1 < 0` (it is the port-displaced aft tug
//! whose line is turned to starboard). This is the sign that places the tugs of
//! eq. (4)-(6) in the consistent form of NOTES.md: tug 2 at
//! `bow + (l_tow2 + l_T2) (cos, sin)(psi_S + alpha_2)`, tug 1 at
//! `stern - (l_tow1 + l_T1) (cos, sin)(psi_S + alpha_1)`.
//!
//! # How this differs from the printed eq. (2) and (15)
//!
//! In the ship's body frame, with the ship's towing points at `x = x_g + l_2` (bow)
//! and `x = x_g - l_1` (stern) on the centre line, the geometry gives
//!
//! - towline 2: `tau_S2 = F_2 [cos a2, sin a2, (x_g + l_2) sin a2]`; this matches
//!   eq. (2)'s `B_S(alpha_2) F_2` (with `l_2` measured from CO instead of the CG);
//! - towline 1: the line runs aft, so the ship is pulled towards tug 1:
//!   `tau_S1 = -F_1 [cos a1, sin a1, -(l_1 - x_g) sin a1]`. Eq. (2) prints
//!   `+F_1 [cos a1, sin a1, l_1 sin a1]`: both the force direction and the moment
//!   sign differ. Eq. (15) prints `-B(alpha_1) F_1`, which fixes the force
//!   direction but keeps `-l_1 F_1 sin a1` as the moment where the geometry gives
//!   `+(l_1 - x_g) F_1 sin a1`: a line turned to starboard behind the stern pulls
//!   the stern to port and turns the bow to starboard.
//!
//! Similarly eq. (3) writes the tug's reaction with the tug angle `beta_i` of
//! eq. (7); here it is simply `-T e` at the tug's point, which is the same thing
//! for a straight line. The plant and the controller's prediction model must both
//! use this geometry (DESIGN.md, "Physics honesty").
//!
//! # Line models
//!
//! [`TowlineModel::IdealWinch`] is the paper's assumption `F'_i = F_i`: the winch
//! holds exactly the commanded tension, clamped to `[0, F_max]`. The line is slack
//! (zero force) when the command is `<= 0` or the attachment points are closer than
//! [`SLACK_DISTANCE`]. [`TowlineModel::Elastic`] adds the line's elasticity and a
//! winch with finite speed (module-level docs of the variant).

use crate::angle::wrap_angle;
use crate::vessel::{check_non_negative, check_positive, ParamError, VesselData};

/// Below this attachment distance (m) the ideal-winch line is slack: the direction
/// of the line is undefined when the two points meet.
pub const SLACK_DISTANCE: f64 = 0.01;

/// How the towline transmits force.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum TowlineModel {
    /// The paper's ideal winch (`F' = F`, Du et al. 2022, below eq. (3)): tension =
    /// commanded tension clamped to `[0, winch_max_tension]`; slack when the command
    /// is `<= 0` or the points are closer than [`SLACK_DISTANCE`]. Default.
    #[default]
    IdealWinch,
    /// Elastic line on a speed-limited winch. State: the paid-out unstretched
    /// length `l0` (m), starting at the initial attachment distance. With `d` the
    /// attachment distance and `d_dot` its rate,
    /// `T = max(0, stiffness (d - l0) + damping d_dot)` when `d > l0`, else 0
    /// (slack), and the winch pays out or reels in at
    /// `dl0/dt = clamp(winch_gain (T - T_cmd), -winch_speed_max, winch_speed_max)`
    /// with `T_cmd` the command clamped to `[0, winch_max_tension]` (it cannot reel
    /// in below `l0 = 0`). The line can briefly exceed `winch_max_tension` while the
    /// winch pays out. The paper does not model the line (text below eq. (3));
    /// every constant here is an assumption, defaults in
    /// [`ElasticTowlineParams::default`].
    Elastic {
        /// Axial stiffness `k` (N/m).
        stiffness: f64,
        /// Axial damping `c` (N s/m).
        damping: f64,
        /// Winch tension-control gain (m/(N s)).
        winch_gain: f64,
        /// Winch speed limit (m/s).
        winch_speed_max: f64,
    },
}

impl TowlineModel {
    /// The elastic model with the default constants ([`ElasticTowlineParams::default`]).
    #[must_use]
    pub fn elastic_default() -> TowlineModel {
        ElasticTowlineParams::default().into()
    }

    /// Checks the constants: finite, stiffness > 0, the others >= 0.
    pub fn validate(&self) -> Result<(), ParamError> {
        match *self {
            TowlineModel::IdealWinch => Ok(()),
            TowlineModel::Elastic {
                stiffness,
                damping,
                winch_gain,
                winch_speed_max,
            } => ElasticTowlineParams {
                stiffness,
                damping,
                winch_gain,
                winch_speed_max,
            }
            .validate(),
        }
    }
}

/// The constants of [`TowlineModel::Elastic`], as a struct (scenario section
/// `[simulation.elastic_towline]`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ElasticTowlineParams {
    /// Axial stiffness `k` (N/m).
    pub stiffness: f64,
    /// Axial damping `c` (N s/m).
    pub damping: f64,
    /// Winch tension-control gain (m/(N s)).
    pub winch_gain: f64,
    /// Winch speed limit (m/s).
    pub winch_speed_max: f64,
}

impl Default for ElasticTowlineParams {
    /// Assumptions (the paper gives no line data):
    /// - `stiffness = 100 N/m`: the 3 N maximum pull stretches the line 3 cm, 3 % of
    ///   the 1 m line, the order of the paper's towline elongation errors (Table 7);
    /// - `damping = 5 N s/m`: damps the ship-tug axial oscillation (about 0.5 Hz with
    ///   the vessels' surge masses, damping ratio about 0.08) in a few periods;
    /// - `winch_gain = 0.1 m/(N s)`: tension error decays with rate `k * gain = 10 1/s`,
    ///   fast against the 1 s control step;
    /// - `winch_speed_max = 0.2 m/s`: of the order of the vessels' speeds, so a tug
    ///   closing in faster than this makes the line go slack.
    fn default() -> Self {
        ElasticTowlineParams {
            stiffness: 100.0,
            damping: 5.0,
            winch_gain: 0.1,
            winch_speed_max: 0.2,
        }
    }
}

impl ElasticTowlineParams {
    /// Checks the constants: finite, stiffness > 0, the others >= 0.
    pub fn validate(&self) -> Result<(), ParamError> {
        check_positive("stiffness", self.stiffness, "N/m")?;
        check_non_negative("damping", self.damping, "N s/m")?;
        check_non_negative("winch_gain", self.winch_gain, "m/(N s)")?;
        check_non_negative("winch_speed_max", self.winch_speed_max, "m/s")?;
        Ok(())
    }
}

impl From<ElasticTowlineParams> for TowlineModel {
    fn from(p: ElasticTowlineParams) -> Self {
        TowlineModel::Elastic {
            stiffness: p.stiffness,
            damping: p.damping,
            winch_gain: p.winch_gain,
            winch_speed_max: p.winch_speed_max,
        }
    }
}

/// What the plant reports about one towline.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct TowlineOutput {
    /// Distance between the two attachment points, `l_el` (m).
    pub length: f64,
    /// Towing angle `alpha_i` (rad, `(-pi, pi]`), see the module docs. 0 when the
    /// two points coincide.
    pub angle: f64,
    /// Tension applied by the line (N) as of the end of the last step: for the
    /// ideal winch the clamped command of the last step (0 if slack), for the
    /// elastic line `max(0, k (d - l0) + c d_dot)` of the current state. Never a
    /// direct function of the current input.
    pub tension: f64,
    /// True when the line transmits no force.
    pub slack: bool,
}

/// Position in NED of a body point `(x_b, 0)` of a vessel at `eta`.
#[must_use]
pub fn attachment_point(eta: &[f64; 3], x_b: f64) -> [f64; 2] {
    let (s, c) = eta[2].sin_cos();
    [eta[0] + c * x_b, eta[1] + s * x_b]
}

/// Geometry of one line at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LineGeometry {
    /// Ship attachment point, NED (m).
    pub ship_point: [f64; 2],
    /// Tug attachment point, NED (m).
    pub tug_point: [f64; 2],
    /// Attachment distance `d` (m).
    pub length: f64,
    /// `d_dot` (m/s), 0 when the points coincide.
    pub length_rate: f64,
    /// Unit vector from the ship's point to the tug's point (NED); zero when the
    /// points coincide.
    pub direction: [f64; 2],
}

/// Generalised loads of one line with tension `T`, each in its vessel's body frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LineLoads {
    /// `[X, Y, N]` on the ship (N, N, N m).
    pub on_ship: [f64; 3],
    /// `[X, Y, N]` on the tug (N, N, N m).
    pub on_tug: [f64; 3],
    /// Force on the ship in NED (N); the tug gets the opposite.
    pub force_on_ship_ned: [f64; 2],
}

/// One vessel's pose and velocity with `sin`/`cos` of the heading computed once.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Kin {
    pub x: f64,
    pub y: f64,
    pub c: f64,
    pub s: f64,
    pub u: f64,
    pub v: f64,
    pub r: f64,
}

impl Kin {
    #[inline]
    pub(crate) fn new(eta: [f64; 3], nu: [f64; 3]) -> Kin {
        let (s, c) = eta[2].sin_cos();
        Kin {
            x: eta[0],
            y: eta[1],
            c,
            s,
            u: nu[0],
            v: nu[1],
            r: nu[2],
        }
    }

    /// NED position and velocity of the body point `(xa, 0)`.
    #[inline]
    fn point(&self, xa: f64) -> ([f64; 2], [f64; 2]) {
        let vb = self.v + self.r * xa;
        (
            [self.x + self.c * xa, self.y + self.s * xa],
            [self.c * self.u - self.s * vb, self.s * self.u + self.c * vb],
        )
    }

    /// Body-frame `[X, Y, N]` of an NED force applied at body point `(xa, 0)`:
    /// `F_b = R(psi)^T F_n`, `N = x F_y - y F_x` with `y = 0`.
    #[inline]
    fn load(&self, xa: f64, f: [f64; 2]) -> [f64; 3] {
        let fx = self.c * f[0] + self.s * f[1];
        let fy = -self.s * f[0] + self.c * f[1];
        [fx, fy, xa * fy]
    }
}

#[inline]
pub(crate) fn geometry_kin(ship: &Kin, xs: f64, tug: &Kin, xt: f64) -> LineGeometry {
    let (ps, vs) = ship.point(xs);
    let (pt, vt) = tug.point(xt);
    let dx = pt[0] - ps[0];
    let dy = pt[1] - ps[1];
    let d = (dx * dx + dy * dy).sqrt();
    let (direction, length_rate) = if d > 0.0 {
        let e = [dx / d, dy / d];
        (e, e[0] * (vt[0] - vs[0]) + e[1] * (vt[1] - vs[1]))
    } else {
        ([0.0, 0.0], 0.0)
    };
    LineGeometry {
        ship_point: ps,
        tug_point: pt,
        length: d,
        length_rate,
        direction,
    }
}

#[inline]
pub(crate) fn loads_kin(
    geometry: &LineGeometry,
    ship: &Kin,
    xs: f64,
    tug: &Kin,
    xt: f64,
    tension: f64,
) -> LineLoads {
    let f = [
        tension * geometry.direction[0],
        tension * geometry.direction[1],
    ];
    LineLoads {
        on_ship: ship.load(xs, f),
        on_tug: tug.load(xt, [-f[0], -f[1]]),
        force_on_ship_ned: f,
    }
}

/// Geometry of a line from the ship's body point `(ship_point_x, 0)` to the tug's
/// body point `(tug_point_x, 0)`, for vessels at `(eta, nu)`.
#[must_use]
pub fn line_geometry(
    ship_eta: &[f64; 3],
    ship_nu: &[f64; 3],
    ship_point_x: f64,
    tug_eta: &[f64; 3],
    tug_nu: &[f64; 3],
    tug_point_x: f64,
) -> LineGeometry {
    geometry_kin(
        &Kin::new(*ship_eta, *ship_nu),
        ship_point_x,
        &Kin::new(*tug_eta, *tug_nu),
        tug_point_x,
    )
}

/// Loads of a line with tension `tension` (N) and the given geometry: `T e` at the
/// ship's point, `-T e` at the tug's point, moments `r x F` in each body frame.
#[must_use]
pub fn line_loads(
    geometry: &LineGeometry,
    ship_psi: f64,
    ship_point_x: f64,
    tug_psi: f64,
    tug_point_x: f64,
    tension: f64,
) -> LineLoads {
    let ship = Kin::new([0.0, 0.0, ship_psi], [0.0; 3]);
    let tug = Kin::new([0.0, 0.0, tug_psi], [0.0; 3]);
    loads_kin(geometry, &ship, ship_point_x, &tug, tug_point_x, tension)
}

/// Towing angle of towline `line` (0 = towline 1, aft; 1 = towline 2, forward) from
/// its attachment points and the ship's heading (module docs). 0 when the points
/// coincide.
///
/// # Panics
/// If `line > 1`.
#[must_use]
pub fn towing_angle(line: usize, ship_point: [f64; 2], tug_point: [f64; 2], ship_psi: f64) -> f64 {
    let (dx, dy) = match line {
        0 => (ship_point[0] - tug_point[0], ship_point[1] - tug_point[1]),
        1 => (tug_point[0] - ship_point[0], tug_point[1] - ship_point[1]),
        _ => panic!("towline index {line} out of range (0 = towline 1, 1 = towline 2)"),
    };
    if dx == 0.0 && dy == 0.0 {
        return 0.0;
    }
    wrap_angle(dy.atan2(dx) - ship_psi)
}

/// Pose `[x, y, psi]` of the tug of towline `line` (0 = tug 1 aft, 1 = tug 2
/// forward) in formation: its towing point at distance `desired_length` (m) from
/// the ship's towing point along the direction `psi_S + towing_angle`, heading
/// `psi_S + towing_angle` (rad). This is Du et al. (2022) eq. (4)-(6) in the
/// consistent form of `paper/NOTES.md` section 1 (tug angle `beta_i = 0` in
/// eq. (7)): tug 2 at `bow + (l_tow2 + l_T2) (cos, sin)(psi_S + alpha_2)`, tug 1 at
/// `stern - (l_tow1 + l_T1) (cos, sin)(psi_S + alpha_1)`, with `l_T` taken from
/// the tug's towing point (`l_T1 = bow_tow_point_x`, `l_T2 = -stern_tow_point_x`).
///
/// # Panics
/// If `line > 1`.
#[must_use]
pub fn formation_pose(
    line: usize,
    ship_eta: &[f64; 3],
    ship: &VesselData,
    tug: &VesselData,
    desired_length: f64,
    towing_angle: f64,
) -> [f64; 3] {
    let heading = ship_eta[2] + towing_angle;
    let (s, c) = heading.sin_cos();
    match line {
        0 => {
            let p = attachment_point(ship_eta, ship.stern_tow_point_x);
            let offset = desired_length + tug.bow_tow_point_x;
            [p[0] - offset * c, p[1] - offset * s, wrap_angle(heading)]
        }
        1 => {
            let p = attachment_point(ship_eta, ship.bow_tow_point_x);
            let offset = desired_length - tug.stern_tow_point_x;
            [p[0] + offset * c, p[1] + offset * s, wrap_angle(heading)]
        }
        _ => panic!("towline index {line} out of range (0 = towline 1, 1 = towline 2)"),
    }
}

/// Commanded tension clamped to the winch's range `[0, winch_max]` (N). The
/// caller guarantees a finite command.
#[inline]
#[must_use]
pub fn clamp_command(command: f64, winch_max: f64) -> f64 {
    command.max(0.0).min(winch_max.max(0.0))
}

/// Ideal-winch tension (N) for a clamped command and an attachment distance.
#[inline]
#[must_use]
pub fn ideal_winch_tension(command_clamped: f64, length: f64) -> f64 {
    if command_clamped > 0.0 && length >= SLACK_DISTANCE {
        command_clamped
    } else {
        0.0
    }
}

/// Elastic-line tension (N): `max(0, k (d - l0) + c d_dot)` when `d > l0`, else 0.
#[inline]
#[must_use]
pub fn elastic_tension(
    params: &ElasticTowlineParams,
    length: f64,
    length_rate: f64,
    l0: f64,
) -> f64 {
    if length > l0 {
        (params.stiffness * (length - l0) + params.damping * length_rate).max(0.0)
    } else {
        0.0
    }
}

/// Winch pay-out rate `dl0/dt` (m/s) of the elastic model.
#[inline]
#[must_use]
pub fn winch_rate(
    params: &ElasticTowlineParams,
    tension: f64,
    command_clamped: f64,
    l0: f64,
) -> f64 {
    let rate = (params.winch_gain * (tension - command_clamped))
        .max(-params.winch_speed_max)
        .min(params.winch_speed_max);
    if l0 <= 0.0 && rate < 0.0 {
        0.0
    } else {
        rate
    }
}

/// Elastic constants of a model, `None` for the ideal winch.
#[must_use]
pub fn elastic_params(model: &TowlineModel) -> Option<ElasticTowlineParams> {
    match *model {
        TowlineModel::IdealWinch => None,
        TowlineModel::Elastic {
            stiffness,
            damping,
            winch_gain,
            winch_speed_max,
        } => Some(ElasticTowlineParams {
            stiffness,
            damping,
            winch_gain,
            winch_speed_max,
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::FRAC_PI_2;

    const XS_STERN: f64 = 0.046 - 0.67;
    const XS_BOW: f64 = 0.046 + 0.585;

    #[test]
    fn forward_tug_to_starboard_gives_positive_alpha2() {
        // Ship at origin heading North; tug 2 ahead and to starboard (East).
        let ship = [0.0, 0.0, 0.0];
        let tug = [2.0, 0.5, 0.3];
        let g = line_geometry(&ship, &[0.0; 3], XS_BOW, &tug, &[0.0; 3], -0.5);
        let a = towing_angle(1, g.ship_point, g.tug_point, ship[2]);
        assert!(a > 0.0, "{a}");
        let expected = (g.tug_point[1] - g.ship_point[1]).atan2(g.tug_point[0] - g.ship_point[0]);
        assert!((a - expected).abs() < 1e-15);
    }

    #[test]
    fn aft_tug_sign_follows_the_line_direction() {
        let ship = [0.0, 0.0, 0.0];
        // Aft tug displaced to port (West): the line, taken aft -> forward, is
        // turned to starboard: alpha_1 > 0 (the NOTES.md placement with alpha_1 > 0).
        let port = [-2.0, -0.5, 0.0];
        let g = line_geometry(&ship, &[0.0; 3], XS_STERN, &port, &[0.0; 3], 0.5);
        assert!(towing_angle(0, g.ship_point, g.tug_point, 0.0) > 0.0);
        // Displaced to starboard: alpha_1 < 0.
        let stbd = [-2.0, 0.5, 0.0];
        let g = line_geometry(&ship, &[0.0; 3], XS_STERN, &stbd, &[0.0; 3], 0.5);
        assert!(towing_angle(0, g.ship_point, g.tug_point, 0.0) < 0.0);
    }

    #[test]
    fn angle_is_relative_to_ship_heading_and_wrapped() {
        // Ship heading 170 deg, line 2 pointing at bearing -170 deg: alpha = +20 deg.
        let psi = 170f64.to_radians();
        let bow = [0.0, 0.0];
        let b = (-170f64).to_radians();
        let tug = [b.cos(), b.sin()];
        let a = towing_angle(1, bow, tug, psi);
        assert!((a - 20f64.to_radians()).abs() < 1e-12, "{}", a.to_degrees());
        assert_eq!(towing_angle(1, bow, bow, psi), 0.0);
    }

    /// r x F by hand: ship heading East (psi = 90 deg), line 2 pulls due North-East.
    #[test]
    fn moments_are_r_cross_f_and_reaction_is_opposite() {
        let ship_eta = [1.0, 2.0, FRAC_PI_2];
        let tug_eta = [3.0, 4.0, 0.25];
        let g = line_geometry(&ship_eta, &[0.0; 3], XS_BOW, &tug_eta, &[0.0; 3], -0.5);
        let t = 2.0;
        let loads = line_loads(&g, ship_eta[2], XS_BOW, tug_eta[2], -0.5, t);
        // Hand calculation. Ship bow point: (1, 2) + 0.631 (cos 90, sin 90) = (1, 2.631).
        assert!((g.ship_point[0] - 1.0).abs() < 1e-12 && (g.ship_point[1] - 2.631).abs() < 1e-12);
        // Tug stern point: (3, 4) - 0.5 (cos 0.25, sin 0.25).
        let tp = [3.0 - 0.5 * 0.25f64.cos(), 4.0 - 0.5 * 0.25f64.sin()];
        assert!((g.tug_point[0] - tp[0]).abs() < 1e-12 && (g.tug_point[1] - tp[1]).abs() < 1e-12);
        let (dx, dy) = (tp[0] - 1.0, tp[1] - 2.631);
        let d = (dx * dx + dy * dy).sqrt();
        let f = [t * dx / d, t * dy / d];
        // Body frame of the ship (psi = 90 deg): x_b = East, y_b = South.
        let fb = [f[1], -f[0]];
        assert!((loads.on_ship[0] - fb[0]).abs() < 1e-12);
        assert!((loads.on_ship[1] - fb[1]).abs() < 1e-12);
        // N = x F_y - y F_x with r = (0.631, 0).
        assert!((loads.on_ship[2] - 0.631 * fb[1]).abs() < 1e-12);
        // A North-East pull at a bow pointing East turns the ship to port (N < 0).
        assert!(loads.on_ship[2] < 0.0);
        // Reaction: the tug's NED force is -f; its moment is r_t x (-f) in its frame.
        let (s, c) = 0.25f64.sin_cos();
        let ft = [-f[0], -f[1]];
        let ftb = [c * ft[0] + s * ft[1], -s * ft[0] + c * ft[1]];
        assert!((loads.on_tug[0] - ftb[0]).abs() < 1e-12);
        assert!((loads.on_tug[1] - ftb[1]).abs() < 1e-12);
        assert!((loads.on_tug[2] - (-0.5) * ftb[1]).abs() < 1e-12);
        // Net NED force is zero and the tension is along the line.
        assert!((loads.force_on_ship_ned[0] - f[0]).abs() < 1e-12);
        let along = f[0] * dx / d + f[1] * dy / d;
        assert!((along - t).abs() < 1e-12);
    }

    /// Eq. (2)/(15) comparison for towline 1 (module docs): a line turned to
    /// starboard behind the stern turns the bow to starboard (N > 0).
    #[test]
    fn aft_line_moment_sign_differs_from_printed_eq_15() {
        let ship = VesselData::cybership2();
        let a1 = 20f64.to_radians();
        let stern = attachment_point(&[0.0, 0.0, 0.0], ship.stern_tow_point_x);
        let tug_point = [stern[0] - a1.cos(), stern[1] - a1.sin()];
        let tug_eta = [
            tug_point[0] - 0.5 * a1.cos(),
            tug_point[1] - 0.5 * a1.sin(),
            a1,
        ];
        let g = line_geometry(
            &[0.0; 3],
            &[0.0; 3],
            ship.stern_tow_point_x,
            &tug_eta,
            &[0.0; 3],
            0.5,
        );
        assert!((towing_angle(0, g.ship_point, g.tug_point, 0.0) - a1).abs() < 1e-12);
        let f1 = 3.0;
        let loads = line_loads(&g, 0.0, ship.stern_tow_point_x, a1, 0.5, f1);
        let l1_from_co = -ship.stern_tow_point_x;
        let geometric = [-f1 * a1.cos(), -f1 * a1.sin(), l1_from_co * f1 * a1.sin()];
        for (got, want) in loads.on_ship.iter().zip(geometric) {
            assert!((got - want).abs() < 1e-12, "{loads:?}");
        }
        let printed_eq15_moment = -0.67 * f1 * a1.sin();
        assert!(loads.on_ship[2] > 0.0 && printed_eq15_moment < 0.0);
    }

    #[test]
    fn length_rate_from_point_velocities() {
        // Tug moving away along the line at 0.3 m/s; ship yawing moves its bow
        // point sideways, which does not change d to first order when the line is
        // along the ship's axis.
        let ship_eta = [0.0, 0.0, 0.0];
        let tug_eta = [0.631 + 1.5, 0.0, 0.0];
        let g = line_geometry(
            &ship_eta,
            &[0.0, 0.0, 0.2],
            XS_BOW,
            &tug_eta,
            &[0.3, 0.0, 0.0],
            -0.5,
        );
        assert!((g.length - 1.0).abs() < 1e-12);
        assert!((g.length_rate - 0.3).abs() < 1e-12);
    }

    #[test]
    fn line_models() {
        assert_eq!(clamp_command(5.0, 3.0), 3.0);
        assert_eq!(clamp_command(-1.0, 3.0), 0.0);
        assert_eq!(ideal_winch_tension(2.0, 1.0), 2.0);
        assert_eq!(ideal_winch_tension(2.0, 0.009), 0.0);
        assert_eq!(ideal_winch_tension(0.0, 1.0), 0.0);
        let p = ElasticTowlineParams::default();
        assert_eq!(elastic_tension(&p, 1.02, 0.0, 1.0), 100.0 * (1.02 - 1.0));
        assert_eq!(elastic_tension(&p, 1.02, -1.0, 1.0), 0.0);
        assert_eq!(elastic_tension(&p, 0.9, 1.0, 1.0), 0.0);
        assert!((winch_rate(&p, 2.5, 2.0, 1.0) - 0.05).abs() < 1e-15);
        assert_eq!(winch_rate(&p, 0.0, 3.0, 1.0), -0.2);
        assert_eq!(winch_rate(&p, 0.0, 3.0, 0.0), 0.0);
        assert!(TowlineModel::elastic_default().validate().is_ok());
        let bad = TowlineModel::Elastic {
            stiffness: 0.0,
            damping: 5.0,
            winch_gain: 0.1,
            winch_speed_max: 0.2,
        };
        assert_eq!(bad.validate().unwrap_err().field, "stiffness");
    }
}
