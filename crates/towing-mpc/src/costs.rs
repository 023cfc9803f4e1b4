//! The cost terms the subproblems share, each written once: the ship's stage
//! terms of eq. (13) (with the regularisers, the terminal term and the one-sided
//! heading term of `docs/assumptions.md`), the obstacle terms (the distance cost
//! `phi` of eq. (13)-(14) and the hard clearance rows of the design document), the
//! ship's motion limits (drift, sternway, speed),
//! the tugs' move suppression of the centralized problem, and the heading
//! difference. A term feeds the [`QuadModel`] with its value and, where the
//! subproblem linearises, its rows `dr/du` over the step's increments.
//!
//! Rows: `rows[c]` is `d x_c / du` of a predicted state `x = [x, y, psi, u, v, r]`
//! over the QP's increments (zero where the state does not depend on an
//! increment); a value-only evaluation passes zero rows.

use crate::engine::{QuadModel, SlotRows};
use crate::obstacle::{DistanceCost, Obstacle};
use crate::ship::{ShipInput, ShipState};
use crate::ship_mpc::ShipMpcParams;
use crate::tug::TugInput;
use crate::HORIZON;
use towing_model::geometry::Lane;

/// `a - b` wrapped to `(-pi, pi]` (heading differences).
#[must_use]
pub fn angle_difference(a: f64, b: f64) -> f64 {
    use std::f64::consts::{PI, TAU};
    let d = (a - b).rem_euclid(TAU);
    if d > PI {
        d - TAU
    } else {
        d
    }
}

/// The hard clearance constraint of the design document, linearised, with an
/// exact L1 penalty on its slack (a [`SlotRows`] block, one slot per obstacle):
///
/// ```text
/// d_j(x_{h+1}) + (dd_j/du) du >= d_min - s_hj,   0 <= s_hj <= s_max,   cost += W s_hj
/// ```
///
/// one row and one slack per sample and obstacle slot. `d` is the distance of
/// [`crate::Obstacle::distance`] (from the obstacle's boundary, focal distance for
/// an ellipse, so `d >= d_min` keeps the vessel's centre outside the circle grown
/// by `d_min`, or the confocal ellipse with semi-major axis `a + d_min`), `d_min`
/// the own hull clearance (about half the own length). The penalty
/// `W max(0, d_min - d)` is part of the true cost, so the SCP merit is the exact
/// penalty function. Only the first `max_obstacles` obstacles get rows (all of
/// them enter the distance cost `phi`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClearanceParams {
    /// Obstacle slots (rows per sample), fixed at construction.
    pub max_obstacles: usize,
    /// `d_min` (m).
    pub min_distance: f64,
    /// `W`: L1 penalty on the slack (per m).
    pub penalty: f64,
    /// Upper bound of a slack (m).
    pub max_slack: f64,
}

impl ClearanceParams {
    /// `max_obstacles = 4`, `W = 1e4`, `s_max = 10 m`, the given `d_min`.
    #[must_use]
    pub fn with_min_distance(min_distance: f64) -> ClearanceParams {
        ClearanceParams {
            max_obstacles: 4,
            min_distance,
            penalty: 1e4,
            max_slack: 10.0,
        }
    }

    /// The penalty term of the true cost at distance `d`.
    #[must_use]
    pub fn penalty_at(&self, d: f64) -> f64 {
        self.penalty * (self.min_distance - d).max(0.0)
    }

    /// The block of rows over `per_step` increments per sample, about the
    /// states of `vessels` ([`crate::engine::Channel::moves`]).
    #[must_use]
    pub fn rows(&self, per_step: usize, vessels: u8) -> SlotRows {
        SlotRows::new(
            self.max_obstacles,
            (HORIZON, per_step),
            vessels,
            self.penalty,
            self.max_slack,
        )
    }

    /// The same row kind with one slot when `on`, none otherwise: the bank row
    /// ([`bank_terms`]). A problem without them keeps exactly the QP it had before they
    /// existed.
    #[must_use]
    pub fn single(&self, on: bool) -> ClearanceParams {
        self.slots(usize::from(on))
    }

    /// The same row kind with `n` slots: the tug's rows about the tow's own vessels
    /// ([`crate::TugMpcParams::tow_rows`]).
    #[must_use]
    pub fn slots(&self, n: usize) -> ClearanceParams {
        ClearanceParams {
            max_obstacles: n,
            ..*self
        }
    }
}

/// The waterway as a constraint of the MPC (`docs/controller-design.md`, "The waterway"):
/// the scenario's lane (route and half width) and, per vessel (ship, tug 1, tug 2), the
/// clearance its reference point keeps from the bank: the hull's corner radius (every
/// corner then lies inside, [`Lane::hull_excess`] `<= 0`) plus a margin for the motion
/// within a sample.
#[derive(Debug, Clone, Copy)]
pub struct Waterway<'a> {
    /// The lane.
    pub lane: &'a Lane,
    /// Clearance from the bank of the ship, tug 1 and tug 2 (m).
    pub margin: [f64; 3],
}

/// A vessel's predicted position `pos` after sample `h`, with `d(x, y)/du = (row_x, row_y)`
/// over the QP's increments: where the obstacle and bank terms are evaluated.
#[derive(Debug, Clone, Copy)]
pub(crate) struct At<'r, const N: usize> {
    pub h: usize,
    pub pos: [f64; 2],
    pub row_x: &'r [f64; N],
    pub row_y: &'r [f64; N],
}

impl<const N: usize> At<'_, N> {
    /// `d f/du` of a function `f` of the position with gradient `grad` there.
    fn row(&self, grad: [f64; 2]) -> [f64; N] {
        let mut row = [0.0; N];
        for (r, (a, b)) in row.iter_mut().zip(self.row_x.iter().zip(self.row_y)) {
            *r = grad[0] * a + grad[1] * b;
        }
        row
    }
}

/// The bank row of vessel `vessel` (0 ship, 1 tug 1, 2 tug 2) at `at`:
/// `b(p) = half_width - d(p) >= margin - s`, `d` the distance from the route
/// ([`Lane::distance_and_gradient`]), linearised like the clearance rows
/// (`b + grad b . (row_x, row_y) du >= margin - s`, `grad b = -grad d`), with the exact L1
/// penalty `penalty` (per m) on the slack (Nocedal and Wright 2006, section 17.2) in the
/// true cost too.
pub(crate) fn bank_terms<const N: usize>(
    quad: &mut QuadModel,
    (waterway, vessel): (&Waterway<'_>, usize),
    penalty: f64,
    rows: Option<&mut SlotRows>,
    at: At<'_, N>,
) {
    let (d, grad) = waterway.lane.distance_and_gradient(at.pos);
    let clearance = waterway.lane.half_width - d;
    let margin = waterway.margin[vessel];
    soft_row(quad, rows, (at.h, 0), (clearance, margin, penalty), || {
        at.row([-grad[0], -grad[1]])
    });
}

/// One soft row `value + row^T du >= bound - s`, slot `j` of sample `h`: its exact
/// L1 penalty `penalty max(0, bound - value)` in the merit and, with `rows`, the
/// linearised row (built only then). The one place the bank, yaw-rate and motion
/// rows write themselves.
fn soft_row<const N: usize>(
    quad: &mut QuadModel,
    rows: Option<&mut SlotRows>,
    (h, j): (usize, usize),
    (value, bound, penalty): (f64, f64, f64),
    row: impl FnOnce() -> [f64; N],
) {
    quad.value += penalty * (bound - value).max(0.0);
    if let Some(r) = rows {
        r.record(h, j, value, bound, &row());
    }
}

/// A tug's yaw-rate limit `|r| <= max_rate` as two soft rows per sample (exact L1
/// penalty `penalty` per rad/s on the slack, [`SlotRows`]; Nocedal and Wright 2006,
/// section 17.2): the rows of [`tug_yaw_rate_rows`], filled by [`tug_yaw_rate_terms`].
/// The TitoNeri's yaw is nearly undamped (`d33` = 0.105 N m s, `I_z - N_rdot` = 2.31
/// kg m^2, `reference/vessels.md`): the 10 N m of eq. (19) held over one 1 s sample
/// spin it up by 4.3 rad/s, and a plan free to do so ran tugs up to 30 rad/s in the
/// closed loop (`docs/controller-design.md`, "Tug local MPCs"). A slack is at most
/// 100 rad/s (any spin the plant can reach). An infinite limit builds no rows.
#[must_use]
pub(crate) fn tug_yaw_rate_rows(
    max_rate: f64,
    penalty: f64,
    per_step: usize,
    vessels: u8,
) -> SlotRows {
    let slots = if max_rate.is_finite() { 2 } else { 0 };
    SlotRows::new(slots, (HORIZON, per_step), vessels, penalty, 100.0)
}

/// The penalty of the predicted yaw rate `r` after sample `h` against `max_rate`
/// and, with `rows`, its two linearised rows (`dr` = `d r / du`).
pub(crate) fn tug_yaw_rate_terms<const N: usize>(
    quad: &mut QuadModel,
    (max_rate, penalty): (f64, f64),
    mut rows: Option<&mut SlotRows>,
    h: usize,
    r: f64,
    dr: &[f64; N],
) {
    if !max_rate.is_finite() {
        return;
    }
    for (j, sign) in [1.0, -1.0].into_iter().enumerate() {
        soft_row::<N>(
            quad,
            rows.as_deref_mut(),
            (h, j),
            (sign * r, -max_rate, penalty),
            || std::array::from_fn(|k| sign * dr[k]),
        );
    }
}

/// Soft limits on the ship's predicted motion, the seamanship of
/// `docs/colregs.md` ("Seamanship") made constraints of the MPC: no drift angle
/// above `max_drift` under way, no sternway beyond `max_sternway`, no surge above
/// `max_speed`. Four linear rows per sample in the predicted surge `u` and sway `v`,
/// each with an exact L1 penalty on its slack (the [`SlotRows`] block of the engine;
/// Nocedal and Wright 2006, section 17.2):
///
/// ```text
/// tan(max_drift) u - v >= -sway_allowance     (drift to starboard)
/// tan(max_drift) u + v >= -sway_allowance     (drift to port)
/// u >= -max_sternway
/// -u >= -max_speed
/// ```
///
/// `|v| <= tan(max_drift) u + sway_allowance` is the drift angle `atan2(v, u)`
/// bounded by `max_drift` above the sway allowance; at rest it leaves the small
/// sideways motion a final approach needs. The rows are linear in the state, so the
/// linearisation is exact in the state and only the model's is approximate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MotionLimits {
    /// Largest drift angle (rad) under way.
    pub max_drift: f64,
    /// Sway speed (m/s) allowed whatever the surge.
    pub sway_allowance: f64,
    /// Largest surge astern (m/s, >= 0).
    pub max_sternway: f64,
    /// Largest surge ahead (m/s).
    pub max_speed: f64,
    /// `W`: L1 penalty on a slack (per m/s); 0 turns the limits off.
    pub penalty: f64,
    /// Upper bound of a slack (m/s).
    pub max_slack: f64,
}

impl Default for MotionLimits {
    /// `max_drift = 22 deg`, `sway_allowance = 0.005 m/s`, `max_sternway = 0.01 m/s`,
    /// `max_speed = 0.11 m/s`, `W = 1e4`, `s_max = 1 m/s`: inside the seamanship
    /// bounds (30 deg at 0.05 m/s and more, 0.03 m/s astern, 1.3 times a cruise of
    /// about 0.09 m/s) by the margin a 3 s horizon's prediction error needs
    /// (`docs/assumptions.md`).
    fn default() -> Self {
        MotionLimits {
            max_drift: 22f64.to_radians(),
            sway_allowance: 0.005,
            max_sternway: 0.01,
            max_speed: 0.11,
            penalty: 1e4,
            max_slack: 1.0,
        }
    }
}

impl MotionLimits {
    /// Rows per sample.
    pub const SLOTS: usize = 4;

    /// The block of rows over `per_step` increments per sample, about the ship
    /// (`vessels`, [`crate::engine::Channel::moves`]).
    #[must_use]
    pub fn rows(&self, per_step: usize, vessels: u8) -> SlotRows {
        SlotRows::new(
            Self::SLOTS,
            (HORIZON, per_step),
            vessels,
            self.penalty,
            self.max_slack,
        )
    }

    /// These limits with the surge limit lowered to `max_surge` (when given and
    /// lower): the way off while the tow gives way (`docs/colregs.md`).
    #[must_use]
    pub fn capped(&self, max_surge: Option<f64>) -> MotionLimits {
        MotionLimits {
            max_speed: max_surge.map_or(self.max_speed, |m| m.min(self.max_speed)),
            ..*self
        }
    }

    /// The rows' values `g(x)`, bounds `b` (`g >= b`) and `dg/d(u, v)`.
    fn limits(&self) -> [(f64, [f64; 2]); 4] {
        let t = self.max_drift.tan();
        [
            (-self.sway_allowance, [t, -1.0]),
            (-self.sway_allowance, [t, 1.0]),
            (-self.max_sternway, [1.0, 0.0]),
            (-self.max_speed, [-1.0, 0.0]),
        ]
    }

    /// The penalty of the predicted state `x` (after sample `h`) and, with `rows`,
    /// its linearised rows (`dx[c]` = `d x_c / du` over the QP's increments).
    pub(crate) fn terms<const N: usize>(
        &self,
        quad: &mut QuadModel,
        mut rows: Option<&mut SlotRows>,
        h: usize,
        x: &ShipState,
        dx: &[[f64; N]; 6],
    ) {
        if self.penalty <= 0.0 {
            return;
        }
        for (j, (bound, g)) in self.limits().into_iter().enumerate() {
            let value = g[0] * x[3] + g[1] * x[4];
            soft_row::<N>(
                quad,
                rows.as_deref_mut(),
                (h, j),
                (value, bound, self.penalty),
                || std::array::from_fn(|k| g[0] * dx[3][k] + g[1] * dx[4][k]),
            );
        }
    }
}

/// The obstacle terms of one predicted position `at` (the state after sample
/// `at.h`; moving obstacles as predicted then, [`Obstacle::after`]): the distance
/// cost `w phi(d)` of every obstacle but those of `distance_cost_off` (bit `j` for
/// `obstacles[j]`) and, for the first `params.max_obstacles`, the clearance penalty
/// and (with `clearance`) the linearised row.
#[allow(clippy::too_many_arguments)] // the pieces of one term; three call sites
pub(crate) fn obstacle_terms<const N: usize>(
    quad: &mut QuadModel,
    obstacles: &[Obstacle],
    distance_cost_off: u64,
    distance: &DistanceCost,
    w: f64,
    params: &ClearanceParams,
    mut clearance: Option<&mut SlotRows>,
    at: At<'_, N>,
) {
    let h = at.h;
    for (j, obstacle) in obstacles.iter().enumerate() {
        let (d, grad) = obstacle.after(h + 1).distance(at.pos);
        let row = at.row(grad);
        if j >= 64 || (distance_cost_off >> j) & 1 == 0 {
            let (phi, slope, curvature) = distance.eval(d);
            quad.curved(phi, slope, curvature, w, &row);
        }
        if j < params.max_obstacles {
            quad.value += params.penalty_at(d);
            if let Some(c) = clearance.as_deref_mut() {
                c.record(h, j, d, params.min_distance, &row);
            }
        }
    }
}

/// The ship's own terms of eq. (13) at one predicted state `x` (after sample
/// `h`) reached with the sample's input `u`, shared by the coordination and the
/// centralized problems: `w_S1 |eta - eta_d|^2` (heading wrapped), the velocity
/// term (`w_S2`, the yaw rate optionally weighted apart), the optional
/// regularisers of the tensions and angles, the one-sided heading term below a
/// COLREGS heading floor and, on the last sample, the optional terminal term.
/// `rows[c]` is `d x_c / du` over the QP's variables, `columns` the QP columns of
/// `u` (`None`: value only).
#[allow(clippy::too_many_arguments)] // the pieces of one stage; two call sites
pub(crate) fn ship_stage_terms<const N: usize>(
    quad: &mut QuadModel,
    params: &ShipMpcParams,
    x: &ShipState,
    reference: [f64; 3],
    u: &ShipInput,
    rows: &[[f64; N]; 6],
    columns: Option<[usize; 4]>,
    last: bool,
    heading_floor: Option<f64>,
) {
    if let Some(floor) = heading_floor {
        // One-sided: zero (with its gradient) at or to starboard of the floor.
        let e = angle_difference(x[2], floor);
        if e < 0.0 {
            quad.curved(e * e, 2.0 * e, 2.0, params.weight_port_turn, &rows[2]);
        }
    }
    let err = [
        x[0] - reference[0],
        x[1] - reference[1],
        angle_difference(x[2], reference[2]),
    ];
    let (wp, wv) = params.state_weights();
    for c in 0..3 {
        quad.residual(err[c], wp[c], 0.0, &rows[c]);
        quad.residual(x[3 + c], wv[c], 0.0, &rows[3 + c]);
    }
    let wu = [
        params.weight_tension,
        params.weight_tension,
        params.weight_towing_angle,
        params.weight_towing_angle,
    ];
    for (k, w) in wu.into_iter().enumerate() {
        if w > 0.0 {
            let mut row = [0.0; N];
            if let Some(cols) = columns {
                row[cols[k]] = 1.0;
            }
            quad.residual(u[k], w, 0.0, &row);
        }
    }
    if let (true, Some(t)) = (last, params.terminal) {
        terminal_terms(quad, t.weight, t.horizon, x, &err, rows);
    }
}

/// The terminal term `w |e_H + tau eta_dot_H|^2` ([`crate::TerminalCost`]): the
/// pose error `err` extrapolated `tau` seconds with the predicted velocity over
/// ground `eta_dot = R(psi) nu` (Fossen 2021, eq. (2.19)).
fn terminal_terms<const N: usize>(
    quad: &mut QuadModel,
    weight: f64,
    tau: f64,
    x: &ShipState,
    err: &[f64; 3],
    rows: &[[f64; N]; 6],
) {
    let (sn, cs) = x[2].sin_cos();
    let xdot = [cs * x[3] - sn * x[4], sn * x[3] + cs * x[4], x[5]];
    // d eta_dot / d(psi, u, v, r).
    let d_psi = [-sn * x[3] - cs * x[4], cs * x[3] - sn * x[4], 0.0];
    let d_nu = [[cs, -sn, 0.0], [sn, cs, 0.0], [0.0, 0.0, 1.0]];
    for c in 0..3 {
        let mut row = [0.0; N];
        for (v, slot) in row.iter_mut().enumerate() {
            *slot = rows[c][v]
                + tau
                    * (d_psi[c] * rows[2][v]
                        + d_nu[c][0] * rows[3][v]
                        + d_nu[c][1] * rows[4][v]
                        + d_nu[c][2] * rows[5][v]);
        }
        quad.residual(err[c] + tau * xdot[c], weight, 0.0, &row);
    }
}

/// `sum_h sum_c w_c (tau_hc - tau_h-1,c)^2` over one tug's plan (`w = [w_F, w_F,
/// w_M]`: the forces' and the moment's weights), `tau_-1 = previous`, with
/// `column(h, c)` the increment variable of channel `c` of sample `h` (the
/// variables are increments of the plan, so the rows are unit vectors).
///
/// Why, and why only in the centralized problem: there the configuration
/// restriction `g_i = f_i` holds at every sample, three equalities per sample
/// against a tug's three thrusts, so the tugs' thrusts are slaved to the ship's
/// plan, and the cost of (16) has no input term. A TitoNeri's sway force and
/// yaw moment have a combination that barely moves the pose at the sample
/// instants of a 3-step horizon; nothing fixed it, and in the closed loop tug
/// 1's sway thrust alternated in sign from sample to sample and grew from 1.8 N
/// to 7 N within 40 s, until the tow crept off its destination (scheme III) or
/// swung to port while giving way (scheme I) (`docs/controller-design.md`).
/// A move-suppression term is the standard remedy (Maciejowski 2002, Predictive
/// Control with Constraints, section 3.1, the weight on input changes). The
/// distributed controller does without it (the ADMM's penalty `rho` keeps
/// the consensus soft within an iteration; the alternation shows there only in a
/// transient while a towing angle swings at its rate limit), and there it slowed
/// the ADMM's convergence on the paper instance tenfold and, tried again, made
/// the encounter suites worse (`docs/controller-design.md`), so it is not in the
/// tug problem: with `w > 0` the two architectures solve
/// problems that differ by this term (`distributed_matches_centralized` sets it
/// to 0).
pub(crate) fn thrust_rate_terms<const N: usize>(
    quad: &mut QuadModel,
    weight: [f64; 3],
    plan: &[TugInput; HORIZON],
    previous: TugInput,
    column: impl Fn(usize, usize) -> usize,
) {
    for h in 0..HORIZON {
        let before = if h == 0 { previous } else { plan[h - 1] };
        for c in (0..3).filter(|&c| weight[c] > 0.0) {
            let mut row = [0.0; N];
            if !quad.value_only {
                row[column(h, c)] = 1.0;
                if h > 0 {
                    row[column(h - 1, c)] = -1.0;
                }
            }
            quad.residual(plan[h][c] - before[c], weight[c], 0.0, &row);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn angle_difference_wraps() {
        use std::f64::consts::PI;
        assert!((angle_difference(PI - 0.1, -PI + 0.1) + 0.2).abs() < 1e-12);
        assert!((angle_difference(0.3, 0.1) - 0.2).abs() < 1e-12);
        assert!((angle_difference(7.0, 0.0) - (7.0 - 2.0 * PI)).abs() < 1e-12);
    }
}
