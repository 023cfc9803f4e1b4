//! A tug's local problem, eq. (25), as a [`Subproblem`] of the SCP engine
//! (`docs/controller-design.md`, "Tug local MPCs").
//!
//! Decision: the thrust plan `tau_Ti` over the horizon, `3 H = 9` increments
//! `du` (index `3 h + j`, `j` = X, Y, N). Given the tug's state, the towline pull per
//! sample from the coordination plan (tension, bearing), the reference poses `f_i`
//! (from [`crate::FormationMap`] along the coordination's predicted ship
//! trajectory), the multipliers `lambda_i` and `rho`, the step linearises the
//! rollout around the current plan (exact Jacobians of the discretised model) and
//! condenses the states (`x_{h+1} ~ x_{h+1} + sum_{k <= h} S_{h,k} du_k`,
//! `condense`), and minimises the quadratic model of
//!
//! ```text
//! sum_h  w_1 |eta_{h+1} - f_h|^2 + w_2 |nu_{h+1}|^2 + w_3 sum_j phi(d_j(p_{h+1}))
//!      + lambda_h^T (eta_{h+1} - f_h) + rho/2 |eta_{h+1} - f_h|^2
//! ```
//!
//! (heading difference wrapped to `(-pi, pi]`; the state after sample `h` is
//! compared with the reference of sample `h`, the layout of
//! [`crate::FormationMap::tug_references_into`]) under the thrust bounds
//! `|tau| <= tau_max` (19) and the hard clearance rows of the design document
//! with L1-penalised slacks ([`ClearanceParams`]).

// Index loops over (sample, channel) pairs: the indices also address the
// flat increment vector (`3 h + c`), clearer than zipped iterators.
#![allow(clippy::needless_range_loop)]

use nalgebra::Matrix6x3;

use crate::costs::{
    angle_difference, bank_terms, obstacle_terms, tug_yaw_rate_rows, tug_yaw_rate_terms, At,
    ClearanceParams, Waterway,
};
use crate::engine::{
    Block, BlockMut, Channel, InputSpace, QuadModel, RowSet, Scp, ScpSettings, SlotRows,
    Subproblem, ALL_VESSELS,
};
use crate::obstacle::{DistanceCost, Obstacle};
use crate::qp::QpBuildError;
use crate::tug::{TowlinePull, TugInput, TugLinearisation, TugModel, TugState};
use crate::{condense, HORIZON};

const N: usize = 3 * HORIZON;

/// Parameters of a tug's local problem.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TugMpcParams {
    /// `w_i1` on the position error `x, y` (1/m^2), eq. (16) (Table 3: 1).
    pub weight_position: f64,
    /// `w_i1` on the heading error (1/rad^2), eq. (16) (Table 3: 1).
    pub weight_heading: f64,
    /// `w_i2` on the surge speed (s^2/m^2), eq. (16) (Table 3: 6).
    pub weight_surge: f64,
    /// `w_i2` on the sway speed (s^2/m^2), eq. (16) (Table 3: 6).
    pub weight_sway: f64,
    /// `w_i2` on the yaw rate (s^2/rad^2), eq. (16) (Table 3: 6).
    pub weight_yaw_rate: f64,
    /// `w_i3` on the distance cost `phi` (m^2), eq. (16) (Table 3: 1).
    pub weight_distance: f64,
    /// `|X|, |Y|, |N|` limits (N, N, N m), eq. (19).
    pub thrust_limit: [f64; 3],
    /// Per-variable trust-region scale (N, N, N m): the box is `radius * scale`.
    pub trust_scale: [f64; 3],
    /// Trust region.
    pub scp: ScpSettings,
    /// `phi` of the distance term.
    pub distance: DistanceCost,
    /// Hard clearance rows (default `d_min = 0.6 m`, about half a TitoNeri plus
    /// a margin).
    pub clearance: ClearanceParams,
    /// Bank rows built into the problem ([`crate::ShipMpcParams::waterway_rows`]).
    pub waterway_rows: bool,
    /// Clearance rows about the tow's own vessels ([`TugStepData::own_ship`], and
    /// [`TugStepData::other_tug`] with [`Self::other_tug_row`]) built into the problem
    /// (the default; not in the paper); `false` (eq. (16) as printed) builds none.
    pub tow_rows: bool,
    /// With [`Self::tow_rows`], a row about the other tug too (default `false`: off).
    /// Tried 2026-12-06 and left off: it took the distributed runs with a collision over
    /// the random campaign down, but with the linear prediction model against the
    /// nonlinear plant the paper run no longer arrived (a round turn at target B, then
    /// a stall beside hazard c; `docs/assumptions.md`).
    pub other_tug_row: bool,
    /// Largest predicted yaw rate `|r|` (rad/s): two soft rows per sample with the
    /// clearance rows' L1 penalty (per rad/s), [`tug_yaw_rate_terms`]; default 0.5 rad/s
    /// (`docs/assumptions.md`); infinite (eq. (16) as printed): no rows. Not in the paper.
    pub max_yaw_rate: f64,
}

impl Default for TugMpcParams {
    fn default() -> Self {
        TugMpcParams {
            weight_position: 1.0,
            weight_heading: 1.0,
            weight_surge: 6.0,
            weight_sway: 6.0,
            weight_yaw_rate: 6.0,
            weight_distance: 1.0,
            thrust_limit: [10.0; 3],
            trust_scale: [10.0, 10.0, 1.0],
            scp: ScpSettings::default(),
            distance: DistanceCost::default(),
            clearance: ClearanceParams::with_min_distance(0.6),
            waterway_rows: false,
            tow_rows: true,
            other_tug_row: false,
            max_yaw_rate: 0.5,
        }
    }
}

impl TugMpcParams {
    /// The pose-error weights `[x, y, psi]` and the velocity weights `[u, v, r]`.
    #[must_use]
    pub fn state_weights(&self) -> ([f64; 3], [f64; 3]) {
        (
            [
                self.weight_position,
                self.weight_position,
                self.weight_heading,
            ],
            [self.weight_surge, self.weight_sway, self.weight_yaw_rate],
        )
    }

    /// Slots of the rows about the tow's own vessels: the own ship's, and the other
    /// tug's with [`Self::other_tug_row`]; none without [`Self::tow_rows`].
    #[must_use]
    pub fn tow_slots(&self) -> usize {
        usize::from(self.tow_rows) * (1 + usize::from(self.other_tug_row))
    }

    /// The yaw-rate limit and its penalty ([`tug_yaw_rate_terms`]).
    #[must_use]
    pub fn yaw_rate_limit(&self) -> (f64, f64) {
        (self.max_yaw_rate, self.clearance.penalty)
    }

    /// The yaw-rate rows over `per_step` increments per sample, about `vessels`.
    #[must_use]
    pub fn yaw_rate_rows(&self, per_step: usize, vessels: u8) -> SlotRows {
        let (max_rate, penalty) = self.yaw_rate_limit();
        tug_yaw_rate_rows(max_rate, penalty, per_step, vessels)
    }

    /// The three input channels of a sample (`X, Y, N`): bounded, no rate bound.
    #[must_use]
    pub fn channels(&self) -> [Channel; 3] {
        std::array::from_fn(|c| {
            Channel::bounded(
                -self.thrust_limit[c],
                self.thrust_limit[c],
                self.trust_scale[c],
            )
        })
    }
}

/// The data of one step (module docs). Per sample `h`: `pulls[h]` held over sample
/// `h`, `reference[h]`, `lambda[h]` for the state after sample `h`.
#[derive(Debug, Clone, Copy)]
pub struct TugStepData<'a> {
    /// The tug's current state.
    pub state: TugState,
    /// Towline tension and bearing per sample (coordination plan).
    pub pulls: [TowlinePull; HORIZON],
    /// Reference poses `f_i` `[x, y, psi]`.
    pub reference: [[f64; 3]; HORIZON],
    /// Multipliers `lambda_i`.
    pub lambda: [[f64; 3]; HORIZON],
    /// ADMM penalty `rho` (>= 0).
    pub rho: f64,
    /// Static obstacles.
    pub obstacles: &'a [Obstacle],
    /// Obstacles left out of the distance cost ([`crate::SampleInput::distance_cost_off`]).
    pub distance_cost_off: u64,
    /// The waterway ([`crate::SampleInput::waterway`]).
    pub waterway: Option<Waterway<'a>>,
    /// The tow's own ship as the coordination predicts it
    /// ([`crate::FormationMap::ship_obstacle`]), kept at the clearance distance by a row
    /// of its own (with [`TugMpcParams::tow_rows`]) and no distance cost: the tug
    /// works next to it, its line keeps it at the formation's distance, and only a tug
    /// driven onto the hull (dodging a target, or overrun) must be stopped. `None`: no
    /// such row (a tug alone).
    pub own_ship: Option<Obstacle>,
    /// The tow's other tug ([`crate::FormationMap::tug_obstacle`]), kept clear the same
    /// way: the formation keeps the tugs a ship's length and two lines apart, and only
    /// a formation folded at close quarters (the ship turned short round, a tug dodging
    /// a target) brings them together, which nothing else in the tug's problem sees.
    /// `None`: no such row.
    pub other_tug: Option<Obstacle>,
}

/// A tug's local problem (module docs).
#[derive(Debug)]
pub struct TugProblem {
    model: TugModel,
    params: TugMpcParams,
    space: InputSpace,
}

/// The linearised rollout of a tug: per sample the linearised step (without the
/// pull sensitivities), the condensed sensitivities and the nominal states.
#[derive(Debug, Clone)]
pub struct TugLinearised {
    steps: [TugLinearisation; HORIZON],
    sens: [[Matrix6x3<f64>; HORIZON]; HORIZON],
    states: [TugState; HORIZON],
}

/// A tug problem's soft rows: the clearance rows and the bank.
#[derive(Debug, Clone)]
pub struct TugRows {
    clearance: SlotRows,
    tow: SlotRows,
    bank: SlotRows,
    yaw: SlotRows,
}

impl RowSet for TugRows {
    fn blocks(&self) -> impl Iterator<Item = Block<'_>> {
        [
            Block::Slots(&self.clearance),
            Block::Slots(&self.tow),
            Block::Slots(&self.bank),
            Block::Slots(&self.yaw),
        ]
        .into_iter()
    }
    fn blocks_mut(&mut self) -> impl Iterator<Item = BlockMut<'_>> {
        [
            BlockMut::Slots(&mut self.clearance),
            BlockMut::Slots(&mut self.tow),
            BlockMut::Slots(&mut self.bank),
            BlockMut::Slots(&mut self.yaw),
        ]
        .into_iter()
    }
}

/// A flat plan (`3 h + c`) as thrusts per sample.
#[must_use]
pub fn tug_inputs(plan: &[f64]) -> [TugInput; HORIZON] {
    std::array::from_fn(|h| std::array::from_fn(|c| plan[3 * h + c]))
}

impl TugProblem {
    /// The problem for `model`.
    #[must_use]
    pub fn new(model: TugModel, params: TugMpcParams) -> TugProblem {
        TugProblem {
            space: InputSpace::new(params.channels().to_vec(), HORIZON),
            model,
            params,
        }
    }

    /// The prediction model.
    #[must_use]
    pub fn model(&self) -> &TugModel {
        &self.model
    }

    /// The parameters.
    #[must_use]
    pub fn params(&self) -> &TugMpcParams {
        &self.params
    }
}

impl Subproblem for TugProblem {
    type Data<'a> = TugStepData<'a>;
    type Trajectory = [TugState; HORIZON];
    type Linearisation = TugLinearised;
    type Key = (TugState, [TowlinePull; HORIZON]);
    type Rows = TugRows;
    type Cost = f64;

    fn space(&self) -> &InputSpace {
        &self.space
    }

    fn rows(&self) -> TugRows {
        TugRows {
            clearance: self.params.clearance.rows(3, ALL_VESSELS),
            tow: (self.params.clearance)
                .slots(self.params.tow_slots())
                .rows(3, ALL_VESSELS),
            bank: (self.params.clearance)
                .single(self.params.waterway_rows)
                .rows(3, ALL_VESSELS),
            yaw: self.params.yaw_rate_rows(3, ALL_VESSELS),
        }
    }

    fn buffers(&self) -> (Self::Trajectory, TugLinearised) {
        (
            [[0.0; 6]; HORIZON],
            TugLinearised {
                steps: [TugLinearisation::default(); HORIZON],
                sens: [[Matrix6x3::zeros(); HORIZON]; HORIZON],
                states: [[0.0; 6]; HORIZON],
            },
        )
    }

    /// No rate bounds: the previous command does not matter.
    fn previous(&self, _data: &TugStepData<'_>, out: &mut [f64]) {
        out.fill(0.0);
    }

    fn key(&self, data: &TugStepData<'_>) -> Self::Key {
        (data.state, data.pulls)
    }

    fn rollout(&self, data: &TugStepData<'_>, plan: &[f64], out: &mut Self::Trajectory) {
        self.model
            .rollout_into(&data.state, &tug_inputs(plan), &data.pulls, out);
    }

    fn linearise(&self, data: &TugStepData<'_>, plan: &[f64], lin: &mut TugLinearised) {
        self.model.linearise_thrust_rollout_into(
            &data.state,
            &tug_inputs(plan),
            &data.pulls,
            &mut lin.steps,
        );
        condense(
            std::array::from_fn(|h| &lin.steps[h].a),
            std::array::from_fn(|h| &lin.steps[h].b),
            &mut lin.sens,
        );
        for h in 0..HORIZON {
            lin.states[h] = lin.steps[h].x_next;
        }
    }

    fn nominal(lin: &TugLinearised) -> &Self::Trajectory {
        &lin.states
    }

    fn terms(
        &self,
        quad: &mut QuadModel,
        traj: &Self::Trajectory,
        _plan: &[f64],
        model: Option<(&TugLinearised, &mut TugRows)>,
        data: &TugStepData<'_>,
    ) -> f64 {
        let (sens, rows) = match model {
            Some((lin, rows)) => (Some(&lin.sens), Some(rows)),
            None => (None, None),
        };
        let vessel = 1 + self.model.line();
        accumulate(quad, &self.params, vessel, traj, sens, rows, data);
        quad.value
    }
}

/// A tug's local MPC: the SCP engine over [`TugProblem`].
pub type TugMpc = Scp<TugProblem>;

impl Scp<TugProblem> {
    /// The problem for `model`, the plan at zero thrust.
    ///
    /// # Errors
    /// A QP that cannot be built.
    pub fn new(model: TugModel, params: TugMpcParams) -> Result<TugMpc, QpBuildError> {
        Scp::with_problem(TugProblem::new(model, params), params.scp)
    }

    /// The plan as thrusts per sample.
    #[must_use]
    pub fn inputs(&self) -> [TugInput; HORIZON] {
        tug_inputs(self.plan())
    }

    /// Replaces the plan (warm start); it is clamped to the bounds at the next step.
    pub fn set_inputs(&mut self, plan: [TugInput; HORIZON]) {
        self.set_plan(plan.as_flattened());
    }
}

/// The cost terms of the states `states` (after samples 0..H); with `sens` the
/// model rows too.
fn accumulate(
    quad: &mut QuadModel,
    params: &TugMpcParams,
    vessel: usize,
    states: &[TugState; HORIZON],
    sens: Option<&[[Matrix6x3<f64>; HORIZON]; HORIZON]>,
    mut slots: Option<&mut TugRows>,
    data: &TugStepData<'_>,
) {
    let (wp, wv) = params.state_weights();
    let w3 = params.weight_distance;
    let mut rows = [[0.0; N]; 6];
    for (h, x) in states.iter().enumerate() {
        if let Some(sens) = sens {
            for (c, row) in rows.iter_mut().enumerate() {
                row.fill(0.0);
                for (k, s) in sens[h][..=h].iter().enumerate() {
                    for j in 0..3 {
                        row[3 * k + j] = s[(c, j)];
                    }
                }
            }
        }
        let f = data.reference[h];
        let err = [x[0] - f[0], x[1] - f[1], angle_difference(x[2], f[2])];
        for c in 0..3 {
            quad.residual(err[c], wp[c] + 0.5 * data.rho, data.lambda[h][c], &rows[c]);
            quad.residual(x[3 + c], wv[c], 0.0, &rows[3 + c]);
        }
        let at = At {
            h,
            pos: [x[0], x[1]],
            row_x: &rows[0],
            row_y: &rows[1],
        };
        obstacle_terms(
            quad,
            data.obstacles,
            data.distance_cost_off,
            &params.distance,
            w3,
            &params.clearance,
            slots.as_deref_mut().map(|r| &mut r.clearance),
            at,
        );
        // The tow's own vessels present, in slot order (the second entry of a single one
        // is a copy, left out).
        let other_tug = data.other_tug.filter(|_| params.other_tug_row);
        let tow = match (data.own_ship, other_tug) {
            (Some(a), Some(b)) => Some(([a, b], 2)),
            (Some(a), None) | (None, Some(a)) => Some(([a, a], 1)),
            (None, None) => None,
        };
        if let (true, Some((tow, n))) = (params.tow_rows, tow) {
            obstacle_terms(
                quad,
                &tow[..n],
                0b11,
                &params.distance,
                0.0,
                &params.clearance,
                slots.as_deref_mut().map(|r| &mut r.tow),
                at,
            );
        }
        if let Some(waterway) = &data.waterway {
            let bank = slots.as_deref_mut().map(|r| &mut r.bank);
            bank_terms(quad, (waterway, vessel), params.clearance.penalty, bank, at);
        }
        let yaw = slots.as_deref_mut().map(|r| &mut r.yaw);
        tug_yaw_rate_terms(quad, params.yaw_rate_limit(), yaw, h, x[5], &rows[5]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use towing_model::{HullModel, Scenario};

    use crate::PredictionParams;

    fn tug_mpc() -> TugMpc {
        tug_mpc_with(TugMpcParams::default())
    }

    fn data_ahead(obstacles: &[Obstacle]) -> TugStepData<'_> {
        // At rest at the origin heading North, slack line, reference 1 m ahead.
        TugStepData {
            state: [0.0; 6],
            pulls: [TowlinePull::default(); HORIZON],
            reference: [[1.0, 0.0, 0.0]; HORIZON],
            lambda: [[0.0; 3]; HORIZON],
            rho: 1.0,
            obstacles,
            distance_cost_off: 0,
            waterway: None,
            own_ship: None,
            other_tug: None,
        }
    }

    fn within_bounds(mpc: &TugMpc) -> bool {
        let lim = mpc.problem().params().thrust_limit;
        mpc.inputs()
            .iter()
            .all(|t| t.iter().zip(lim).all(|(v, l)| v.abs() <= l + 1e-9))
    }

    #[test]
    fn converges_to_a_reference_ahead() {
        let mut mpc = tug_mpc();
        let data = data_ahead(&[]);
        // Start from a poor plan (sway and yaw thrust): several nonlinear steps.
        mpc.set_inputs([[0.0, 8.0, -5.0]; HORIZON]);
        let initial = mpc.cost(mpc.plan(), &data);
        let mut last = initial;
        let mut accepted = 0;
        for _ in 0..30 {
            let report = mpc.step(&data);
            assert!(report.qp.is_usable(), "{report:?}");
            assert!(within_bounds(&mpc));
            // The true cost never rises; it falls on accepted steps.
            let now = mpc.cost(mpc.plan(), &data);
            assert!((now - report.cost_after).abs() <= 1e-9 * now.max(1.0));
            if report.accepted {
                accepted += 1;
                assert!(now < last, "{now} >= {last}");
            } else {
                assert_eq!(now, last);
            }
            last = now;
        }
        assert!(accepted >= 2, "{accepted}");
        assert!(last < 0.5 * initial, "{last} vs {initial}");
        // The first move pushes the tug forward.
        assert!(mpc.inputs()[0][0] > 0.5, "{:?}", mpc.inputs());
        assert!(mpc.predicted()[HORIZON - 1][0] > 0.1);
        // Converged: one more step changes (almost) nothing.
        let report = mpc.step(&data);
        assert!(report.cost_before - report.cost_after <= 1e-4 * report.cost_before.max(1.0));
    }

    /// Multipliers act on the pose error: a positive lambda on x rewards a
    /// smaller x, so the plan pushes less forward.
    #[test]
    fn multipliers_shift_the_plan() {
        let mut free = tug_mpc();
        let mut priced = tug_mpc();
        let data = data_ahead(&[]);
        let mut with_lambda = data;
        with_lambda.lambda = [[2.0, 0.0, 0.0]; HORIZON];
        for _ in 0..30 {
            free.step(&data);
            priced.step(&with_lambda);
        }
        assert!(priced.inputs()[0][0] < free.inputs()[0][0]);
    }

    /// An obstacle just ahead of the reference holds the tug back.
    #[test]
    fn obstacle_holds_back() {
        let mut free = tug_mpc();
        let mut blocked = tug_mpc();
        let obstacles = [Obstacle::Circle {
            centre: [3.5, 0.0],
            radius: 0.5,
        }];
        let data = data_ahead(&[]);
        let data_obs = data_ahead(&obstacles);
        for _ in 0..30 {
            free.step(&data);
            let r = blocked.step(&data_obs);
            assert!(within_bounds(&blocked) && r.qp.is_usable());
        }
        assert!(blocked.predicted()[HORIZON - 1][0] < free.predicted()[HORIZON - 1][0]);
    }

    /// Scheme II (no distance cost): an obstacle between the tug and its
    /// reference. Without clearance rows the plan runs into it; with them every
    /// predicted position keeps `d >= d_min` (to the linearisation's accuracy).
    #[test]
    fn clearance_rows_keep_the_distance() {
        let obstacles = [Obstacle::Circle {
            centre: [1.2, 0.0],
            radius: 0.3,
        }];
        let run = |max_obstacles: usize| {
            let defaults = TugMpcParams::default();
            let params = TugMpcParams {
                weight_distance: 0.0,
                clearance: ClearanceParams {
                    max_obstacles,
                    ..defaults.clearance
                },
                ..defaults
            };
            let mut mpc = tug_mpc_with(params);
            let mut data = data_ahead(&obstacles);
            data.reference = [[1.5, 0.0, 0.0]; HORIZON];
            let mut last = f64::INFINITY;
            for _ in 0..40 {
                let report = mpc.step(&data);
                assert!(report.qp.is_usable(), "{report:?}");
                assert!(within_bounds(&mpc));
                assert!(report.cost_after <= last);
                last = report.cost_after;
            }
            mpc.predicted()
                .iter()
                .map(|x| obstacles[0].distance([x[0], x[1]]).0)
                .fold(f64::INFINITY, f64::min)
        };
        let d_min = TugMpcParams::default().clearance.min_distance;
        let free = run(0);
        let kept = run(4);
        assert!(free < d_min - 0.05, "{free}");
        assert!(kept >= d_min - 1e-3, "{kept}");
    }

    fn tug_mpc_with(params: TugMpcParams) -> TugMpc {
        let scenario = Scenario::paper().unwrap();
        let model = TugModel::from_scenario(
            &scenario,
            1,
            HullModel::NonlinearDamping,
            PredictionParams::default(),
        )
        .unwrap();
        TugMpc::new(model, params).unwrap()
    }

    /// The closest the tug's plan comes to `vessel` (placed in the data by `place`)
    /// over 40 steps towards a reference just beyond it, with the tow rows on or off.
    fn closest_approach(
        vessel: Obstacle,
        place: fn(&mut TugStepData<'_>, Option<Obstacle>),
        present: bool,
        row: bool,
    ) -> f64 {
        let mut mpc = tug_mpc_with(TugMpcParams {
            tow_rows: row,
            other_tug_row: true,
            ..TugMpcParams::default()
        });
        let mut data = data_ahead(&[]);
        data.reference = [[1.5, 0.0, 0.0]; HORIZON];
        place(&mut data, present.then_some(vessel));
        for _ in 0..40 {
            let report = mpc.step(&data);
            assert!(report.qp.is_usable(), "{report:?}");
            assert!(within_bounds(&mpc));
        }
        mpc.predicted()
            .iter()
            .map(|x| vessel.distance([x[0], x[1]]).0)
            .fold(f64::INFINITY, f64::min)
    }

    /// The plan runs onto `vessel` without it in the data or with the rows off, and
    /// keeps `d_min` from it with both.
    fn assert_kept_clear_of(vessel: Obstacle, place: fn(&mut TugStepData<'_>, Option<Obstacle>)) {
        let d_min = TugMpcParams::default().clearance.min_distance;
        let free = closest_approach(vessel, place, false, true);
        let off = closest_approach(vessel, place, true, false);
        let kept = closest_approach(vessel, place, true, true);
        assert!(free < d_min - 0.05, "{free}");
        assert!(off < d_min - 0.05, "{off}");
        assert!(kept >= d_min - 1e-3, "{kept}");
    }

    /// A reference across the tow's own ship (a towing angle swung through the hull): the
    /// own-ship row keeps the tug's plan at `d_min` from the hull ellipse, with no distance
    /// cost of its own; without the ship in the data, or with the row off, the plan runs
    /// onto the hull.
    #[test]
    fn the_own_ship_row_keeps_the_tug_off_the_hull() {
        let scenario = Scenario::paper().unwrap();
        let ship = crate::FormationMap::from_scenario(&scenario)
            .unwrap()
            .ship_obstacle(
                &[1.4, 0.0, 1.5, 0.0, 0.0, 0.0],
                &[[1.4, 0.0, 1.5, 0.0, 0.0, 0.0]; HORIZON],
            );
        assert_kept_clear_of(ship, |data, ship| data.own_ship = ship);
    }

    /// A reference across the other tug (the formation folded): the same with the
    /// other tug's row, the other tug lying across the track.
    #[test]
    fn the_other_tug_row_keeps_the_tugs_apart() {
        let scenario = Scenario::paper().unwrap();
        let other = crate::FormationMap::from_scenario(&scenario)
            .unwrap()
            .tug_obstacle(1, &[1.4, 0.0, 1.5, 0.0, 0.0, 0.0], 1.0);
        assert_kept_clear_of(other, |data, other| data.other_tug = other);
    }

    /// A heading reference a half turn away: without the limit the plan spins the tug up
    /// (the 10 N m moment against a yaw damping of 0.105 N m s); with it every predicted
    /// yaw rate stays within `max_yaw_rate`, and the plan still turns the right way.
    #[test]
    fn the_yaw_rate_rows_keep_the_tug_from_spinning_up() {
        let run = |max_yaw_rate: f64| {
            let mut mpc = tug_mpc_with(TugMpcParams {
                max_yaw_rate,
                ..TugMpcParams::default()
            });
            let mut data = data_ahead(&[]);
            data.reference = [[0.0, 0.0, 3.0]; HORIZON];
            let mut fastest = 0.0f64;
            let mut heading = 0.0;
            for _ in 0..40 {
                let report = mpc.step(&data);
                assert!(report.qp.is_usable(), "{report:?}");
                assert!(within_bounds(&mpc));
                fastest = mpc
                    .predicted()
                    .iter()
                    .map(|x| x[5].abs())
                    .fold(fastest, f64::max);
                heading = mpc.predicted()[HORIZON - 1][2];
            }
            (fastest, heading)
        };
        let limit = 0.5;
        let (free, _) = run(f64::INFINITY);
        let (held, heading) = run(limit);
        assert!(free > 2.0 * limit, "{free}");
        assert!(held <= limit + 1e-3, "{held}");
        assert!(heading > 0.1, "{heading}");
    }
}
