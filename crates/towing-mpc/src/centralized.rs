//! The centralized MPC of Du, Negenborn, Reppa (2022), eq. (12)
//! (`docs/controller-design.md`, "Centralized MPC (12)"): one problem over the
//! ship's and both tugs' inputs, on the models, costs and constraints of the two
//! ADMM subproblems ([`crate::ShipMpc`], [`crate::TugMpc`]) without the ADMM terms,
//! so that the distributed and the centralized controller solve the same problem
//! (the paper's Table 7 comparison).
//!
//! Decision per sample `h`: `[F_1, F_2, alpha_1, alpha_2, X_1, Y_1, N_1, X_2, Y_2,
//! N_2]`, `10 H = 30` increments (index `10 h + k`), plus slacks.
//!
//! Problem (the choice made for (12) (iii), the configuration restriction):
//!
//! ```text
//! min  sum_h  J_S,h + J_1,h + J_2,h
//! s.t. g_ih(tau) = f_i(eta_S,h+1(tau_S), alpha_ih)     (i = 1, 2, every sample)
//!      the bounds, rate bounds and clearance rows of both subproblems
//! J_S,h = w_S1 |eta_S - eta_Sd|^2 + w_S2 |nu_S|^2 + w_S3 sum_j phi(d_j)
//!         + w_alpha (alpha_1^2 + alpha_2^2) + w_F (F_1^2 + F_2^2)
//! J_i,h = w_i1 |g_i - f_i|^2 + w_i2 |nu_i|^2 + w_i3 sum_j phi(d_j)
//! ```
//!
//! This is the problem the ADMM of [`crate::Admm`] decomposes: its subproblems
//! minimise `J_S` and `J_i` plus the augmented-Lagrangian terms of the consensus
//! constraint `g_i = f_i`. The configuration restriction is therefore a
//! constraint here, not a cost (the term `w_i1 |g_i - f_i|^2` is kept, as in
//! `J_i`; it vanishes, with its gradient, on the constraint, so it does not move
//! the optimum). It is imposed as the linearised equality with an exact L1
//! penalty on its slack, `|r + J du| <= s`, `cost += W_c sum s`, `W_c`
//! ([`CentralizedSettings::consensus_penalty`], default 1e3 per m and per rad)
//! larger than the constraint's multipliers, so the QP is always feasible and the
//! penalty is zero at a consistent plan. The SCP merit is the true cost plus
//! `W_c sum |g_i - f_i|_1` plus the clearance penalties.
//!
//! The tugs' predictions use the planned pulls (tension `F_ih`, bearing
//! `psi_S + alpha_ih` with `psi_S` the ship's predicted heading at the start of
//! sample `h`, [`TowlinePull::from_plan`], as in [`crate::Admm`]), so the tug
//! trajectories depend on the ship's inputs: the linearisation includes these
//! cross-sensitivities exactly (the tug model's pull Jacobian `E` chained with the
//! ship's condensed sensitivities).
//!
//! Relation to a converged ADMM: the ADMM's tug steps take the pulls as given,
//! and the ship's step takes the tugs' poses `g_i` as given, so neither sees the
//! cross term `d (J_i + lambda_i^T g_i) / d tau_S` through the pull, which the
//! centralized stationarity condition has. It nearly vanishes at a converged
//! ADMM: the pull acts on the tug as a body force and moment, as the thrust
//! `(X, Y, N)` does, and the tug's own step makes its Lagrangian stationary in
//! the thrust (interior thrust bounds), hence, to first order, in any load of
//! that kind. What is left is the line load turning in the tug's body frame
//! within the sample (world-fixed bearing) and active thrust bounds. Measured
//! (`tests::distributed_matches_centralized`, no obstacles): costs within
//! 1.5e-4 relative, first moves within 3e-3 N (tension), 2e-5 rad (angles),
//! 5e-3 N (thrust).
//!
//! Constraints: the ship's channels (bounds, rate bounds) and the tugs' thrust
//! channels of the engine's [`InputSpace`] (trust scales of the subproblems'
//! parameters); the clearance rows of the ship and of both tugs
//! ([`crate::ClearanceParams`] of each); the consensus rows ([`PairRows`]).
//!
//! Solve: steps of the SCP engine ([`crate::engine`]: one QP each, accept/reject
//! on the true merit, trust region) until an accepted step moves the first move
//! by less than [`CentralizedSettings::tolerance`], or the model predicts no
//! decrease in the trust region, or [`CentralizedSettings::max_iterations`], or
//! the sample's time [`Budget`] is spent.
//!
//! Allocation: none per sample (buffers and QPs made in [`Centralized::new`]).

// Index loops over (sample, channel) pairs: the indices also address the flat
// increment vector (`10 h + k`).
#![allow(clippy::needless_range_loop)]

use nalgebra::{RowSVector, SMatrix};
use serde::{Deserialize, Serialize};
use towing_model::{HullModel, ParamError, Scenario};

use crate::admm::{AdmmBuildError, SampleInput};
use crate::costs::{
    angle_difference, bank_terms, obstacle_terms, ship_stage_terms, thrust_rate_terms,
    tug_yaw_rate_terms, At,
};
use crate::engine::{
    Block, BlockMut, Budget, InputSpace, Merit, PairRows, QuadModel, RowSet, Scp, ScpReport,
    ScpSettings, ScpState, SlotRows, Subproblem,
};
use crate::formation::FormationMap;
use crate::params::PredictionParams;
use crate::ship::{ShipInput, ShipLinearisation, ShipModel, ShipState};
use crate::ship_mpc::ShipMpcParams;
use crate::tug::{TowlinePull, TugInput, TugLinearisation, TugModel, TugState};
use crate::tug_mpc::TugMpcParams;
use crate::HORIZON;

/// Inputs per sample: 4 ship, 3 + 3 tugs.
const PER_STEP: usize = 10;
/// Increments.
const NU: usize = PER_STEP * HORIZON;
/// Consensus residuals (2 tugs x H samples x 3).
const NC: usize = 2 * HORIZON * 3;

/// `d x / d u` of a predicted state w.r.t. all increments.
type Sens = SMatrix<f64, 6, NU>;

/// The vessels' bits in [`crate::engine::Channel::moves`]: the ship's inputs move
/// all three (the tugs through the pulls), a tug's thrust its own tug only.
const SHIP: u8 = 1;
const TUG: [u8; 2] = [2, 4];
/// The pairs of the tow's own vessels kept apart (0 the ship, `1 + i` tug `i`): the
/// first vessel's reference point from the second's hull.
const TOW_PAIRS: [(usize, usize); 3] = [(1, 0), (2, 0), (1, 2)];

/// Index of ship channel `k` of sample `h`.
fn ship_var(h: usize, k: usize) -> usize {
    PER_STEP * h + k
}

/// Index of tug `i`'s channel `c` of sample `h`.
fn tug_var(i: usize, h: usize, c: usize) -> usize {
    PER_STEP * h + 4 + 3 * i + c
}

/// Index of the consensus residual of tug `i`, sample `h`, component `c`.
fn cons_index(i: usize, h: usize, c: usize) -> usize {
    3 * (HORIZON * i + h) + c
}

/// Parameters of the centralized SCP.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CentralizedSettings {
    /// Most SCP iterations (QPs) per sample.
    pub max_iterations: usize,
    /// Converged when an accepted step changes every first-move channel by less
    /// than this (N, rad, N m).
    pub tolerance: f64,
    /// Converged when an accepted step lowers the merit by less than this
    /// fraction of it (`max(1, |J|)`): the SCP converges linearly near a
    /// solution, so what is left is a few such steps' worth.
    pub cost_tolerance: f64,
    /// `W_c`: L1 penalty of the configuration restriction (per m, per rad).
    pub consensus_penalty: f64,
    /// Trust region (scales: the subproblems' `trust_scale`).
    pub scp: ScpSettings,
    /// `w_F`: weight of the tugs' force changes `sum_i sum_h (X_ih - X_ih-1)^2 +
    /// (Y_ih - Y_ih-1)^2` (1/N^2), `tau_i,-1` the thrust applied in the previous
    /// sample; see [`crate::costs`] (`thrust_rate_terms`).
    pub weight_force_rate: f64,
    /// `w_M`: the same for the yaw moment changes (1/(N m)^2).
    pub weight_moment_rate: f64,
}

impl Default for CentralizedSettings {
    fn default() -> Self {
        CentralizedSettings {
            max_iterations: 60,
            tolerance: 1e-3,
            cost_tolerance: 1e-5,
            consensus_penalty: 1e3,
            scp: ScpSettings::default(),
            weight_force_rate: 0.01,
            weight_moment_rate: 0.01,
        }
    }
}

impl CentralizedSettings {
    /// Checks the values.
    ///
    /// # Errors
    /// The first offending field and why.
    pub fn validate(&self) -> Result<(), ParamError> {
        let bad = |field: &str, reason: String| {
            Err(ParamError {
                field: field.to_owned(),
                reason,
            })
        };
        if self.max_iterations == 0 {
            return bad("max_iterations", "must be >= 1".into());
        }
        if !(self.consensus_penalty.is_finite() && self.consensus_penalty > 0.0) {
            return bad(
                "consensus_penalty",
                format!("must be finite and > 0, got {}", self.consensus_penalty),
            );
        }
        for (field, v) in [
            ("tolerance", self.tolerance),
            ("cost_tolerance", self.cost_tolerance),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return bad(field, format!("must be finite and >= 0, got {v}"));
            }
        }
        for (field, v) in [
            ("weight_force_rate", self.weight_force_rate),
            ("weight_moment_rate", self.weight_moment_rate),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return bad(field, format!("must be finite and >= 0, got {v}"));
            }
        }
        self.scp.validate()
    }
}

/// The plans of all three vessels.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Plan {
    ship: [ShipInput; HORIZON],
    tugs: [[TugInput; HORIZON]; 2],
}

impl Plan {
    /// From the flat increment layout ([`ship_var`], [`tug_var`]).
    fn of(flat: &[f64]) -> Plan {
        Plan {
            ship: std::array::from_fn(|h| std::array::from_fn(|k| flat[ship_var(h, k)])),
            tugs: std::array::from_fn(|i| {
                std::array::from_fn(|h| std::array::from_fn(|c| flat[tug_var(i, h, c)]))
            }),
        }
    }

    /// Into the flat layout.
    fn write(&self, flat: &mut [f64]) {
        for h in 0..HORIZON {
            for k in 0..4 {
                flat[ship_var(h, k)] = self.ship[h][k];
            }
            for i in 0..2 {
                for c in 0..3 {
                    flat[tug_var(i, h, c)] = self.tugs[i][h][c];
                }
            }
        }
    }
}

/// Predicted states of all three vessels (after samples 0..H).
#[derive(Debug, Clone, Copy)]
pub struct Trajectory {
    ship: [ShipState; HORIZON],
    tugs: [[TugState; HORIZON]; 2],
}

/// The cost of a plan, by vessel.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct CostBreakdown {
    /// `sum_h J_S,h` (with the ship's clearance penalties).
    pub ship: f64,
    /// `sum_h J_i,h` (with the tug's clearance penalties, and `w_i1 |g_i - f_i|^2`).
    pub tugs: [f64; 2],
    /// `sum |g_i - f_i|_1` over both tugs and all samples (heading wrapped).
    pub consensus_l1: f64,
    /// `max |g_i - f_i|` over components (m, rad).
    pub consensus_max: f64,
    /// The SCP merit: `J_S + J_1 + J_2 + W_c sum |g_i - f_i|_1`.
    pub merit: f64,
}

impl CostBreakdown {
    /// `J_S + J_1 + J_2`.
    #[must_use]
    pub fn total(&self) -> f64 {
        self.ship + self.tugs[0] + self.tugs[1]
    }
}

impl Merit for CostBreakdown {
    fn merit(&self) -> f64 {
        self.merit
    }
}

/// What one sample's SCP did.
#[derive(Debug, Clone, Copy)]
pub struct CentralizedReport {
    /// SCP iterations (QPs solved).
    pub iterations: usize,
    /// Whether the first move converged (module docs) before `max_iterations`.
    pub converged: bool,
    /// Whether the time budget ended the loop.
    pub budget_hit: bool,
    /// Whether the last QP gave no usable solution.
    pub failed: bool,
    /// QPs over the sample without a usable solution.
    pub failed_steps: usize,
    /// Merit of the final plan: `J_S + J_1 + J_2` + penalties.
    pub cost: f64,
    /// The final plan's cost by vessel.
    pub breakdown: CostBreakdown,
    /// The last SCP step.
    pub last_step: ScpReport,
    /// First move: tensions `F_1, F_2` (N).
    pub tension: [f64; 2],
    /// First move: towing angles `alpha_1, alpha_2` (rad).
    pub angle: [f64; 2],
    /// First move: thrust of tug 1 and tug 2.
    pub tug_thrust: [TugInput; 2],
}

/// Sensitivities of the three trajectories.
#[derive(Debug, Clone)]
struct Sensitivities {
    ship: [Sens; HORIZON],
    tugs: [[Sens; HORIZON]; 2],
}

fn sens_rows(s: &Sens) -> [[f64; NU]; 6] {
    std::array::from_fn(|c| std::array::from_fn(|v| s[(c, v)]))
}

/// The linearised rollouts of all three vessels.
#[derive(Debug, Clone)]
pub struct CentralLinearised {
    ship_lin: [ShipLinearisation; HORIZON],
    tug_lin: [[TugLinearisation; HORIZON]; 2],
    sens: Sensitivities,
    traj: Trajectory,
}

/// The centralized problem's soft rows: the consensus rows, then the clearance
/// rows of the ship, tug 1 and tug 2, the ship's motion limits, the bank rows of the
/// three vessels, the tugs' yaw-rate rows and the rows keeping the tow's own vessels
/// apart ([`CentralProblem::tow_terms`]).
#[derive(Debug, Clone)]
pub struct CentralRows {
    consensus: PairRows,
    clearance: [SlotRows; 3],
    motion: SlotRows,
    bank: [SlotRows; 3],
    yaw: [SlotRows; 2],
    tow: SlotRows,
}

impl RowSet for CentralRows {
    fn blocks(&self) -> impl Iterator<Item = Block<'_>> {
        std::iter::once(Block::Pairs(&self.consensus))
            .chain(self.clearance.iter().map(Block::Slots))
            .chain(std::iter::once(Block::Slots(&self.motion)))
            .chain(self.bank.iter().map(Block::Slots))
            .chain(self.yaw.iter().map(Block::Slots))
            .chain(std::iter::once(Block::Slots(&self.tow)))
    }
    fn blocks_mut(&mut self) -> impl Iterator<Item = BlockMut<'_>> {
        std::iter::once(BlockMut::Pairs(&mut self.consensus))
            .chain(self.clearance.iter_mut().map(BlockMut::Slots))
            .chain(std::iter::once(BlockMut::Slots(&mut self.motion)))
            .chain(self.bank.iter_mut().map(BlockMut::Slots))
            .chain(self.yaw.iter_mut().map(BlockMut::Slots))
            .chain(std::iter::once(BlockMut::Slots(&mut self.tow)))
    }
}

/// Initial states (tug headings unwrapped next to the ship's).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Start {
    ship: ShipState,
    tugs: [TugState; 2],
}

impl Start {
    fn of(input: &SampleInput<'_>) -> Start {
        let mut tugs = input.tugs;
        for x in &mut tugs {
            x[2] = input.ship[2] + angle_difference(x[2], input.ship[2]);
        }
        Start {
            ship: input.ship,
            tugs,
        }
    }
}

/// The data of one step: the sample's input and its start.
#[derive(Debug, Clone, Copy)]
pub struct CentralData<'a> {
    input: SampleInput<'a>,
    start: Start,
}

impl<'a> CentralData<'a> {
    /// The data of `input`.
    #[must_use]
    pub fn of(input: &SampleInput<'a>) -> CentralData<'a> {
        CentralData {
            input: *input,
            start: Start::of(input),
        }
    }
}

/// The centralized problem (module docs): models, parameters, input space.
#[derive(Debug)]
pub struct CentralProblem {
    ship: ShipModel,
    tugs: [TugModel; 2],
    formation: FormationMap,
    ship_params: ShipMpcParams,
    tug_params: TugMpcParams,
    settings: CentralizedSettings,
    space: InputSpace,
}

impl CentralProblem {
    /// The pulls on tug `i` of `ship_plan` along `ship_states` from heading `psi0`.
    fn pulls(
        psi0: f64,
        ship_states: &[ShipState; HORIZON],
        ship_plan: &[ShipInput; HORIZON],
        i: usize,
    ) -> [TowlinePull; HORIZON] {
        std::array::from_fn(|h| {
            let psi = if h == 0 { psi0 } else { ship_states[h - 1][2] };
            TowlinePull::from_plan(ship_plan[h][i], psi, ship_plan[h][2 + i])
        })
    }

    /// Nonlinear rollout of all three vessels.
    fn roll(&self, x0: &Start, plan: &Plan, out: &mut Trajectory) {
        self.ship.rollout_into(&x0.ship, &plan.ship, &mut out.ship);
        for i in 0..2 {
            let pulls = CentralProblem::pulls(x0.ship[2], &out.ship, &plan.ship, i);
            self.tugs[i].rollout_into(&x0.tugs[i], &plan.tugs[i], &pulls, &mut out.tugs[i]);
        }
    }

    /// The ship's terms of sample `h` (with its clearance and motion rows).
    #[allow(clippy::too_many_arguments)] // the pieces of one stage; one call site
    fn ship_terms(
        &self,
        quad: &mut QuadModel,
        x: &ShipState,
        u: &ShipInput,
        h: usize,
        rows: &[[f64; NU]; 6],
        soft: Option<&mut CentralRows>,
        input: &SampleInput<'_>,
    ) {
        let (clearance, motion, bank) = match soft {
            Some(r) => (
                Some(&mut r.clearance[0]),
                Some(&mut r.motion),
                Some(&mut r.bank[0]),
            ),
            None => (None, None, None),
        };
        let sp = &self.ship_params;
        ship_stage_terms(
            quad,
            sp,
            x,
            input.reference[h],
            u,
            rows,
            clearance
                .is_some()
                .then(|| std::array::from_fn(|k| ship_var(h, k))),
            h + 1 == HORIZON,
            input.heading_floor,
        );
        sp.motion
            .capped(input.max_surge)
            .terms(quad, motion, h, x, rows);
        let at = At {
            h,
            pos: [x[0], x[1]],
            row_x: &rows[0],
            row_y: &rows[1],
        };
        obstacle_terms(
            quad,
            input.obstacles,
            input.distance_cost_off,
            &sp.distance,
            sp.weight_distance,
            &sp.clearance,
            clearance,
            at,
        );
        if let Some(waterway) = &input.waterway {
            bank_terms(quad, (waterway, 0), sp.clearance.penalty, bank, at);
        }
    }

    /// The rows keeping the tow's own vessels apart at sample `h` ([`TOW_PAIRS`]), as the
    /// tugs' local problems keep them (`TugStepData::own_ship`, `other_tug`): a vessel's
    /// reference point at least `d_min` from the other's hull ellipse
    /// ([`FormationMap::hull`] at its predicted pose). The row moves with both vessels:
    /// with `grad` the distance's gradient at the point `p` and `c`, `psi` the hull's
    /// centre and heading, `dd = grad . (dp - dc) + (grad_x (p - c)_y - grad_y (p - c)_x)
    /// dpsi` (a common translation leaves the distance unchanged; turning the hull by
    /// `dpsi` about `c` is turning the point by `-dpsi` about it).
    fn tow_terms(
        &self,
        quad: &mut QuadModel,
        traj: &Trajectory,
        sens: Option<&Sensitivities>,
        mut tow: Option<&mut SlotRows>,
        h: usize,
    ) {
        let tp = &self.tug_params;
        let state = |v: usize| {
            if v == 0 {
                &traj.ship[h]
            } else {
                &traj.tugs[v - 1][h]
            }
        };
        // Each vessel's sensitivity rows once (a vessel is in two pairs); only with rows to
        // record.
        let rows: Option<[[[f64; NU]; 6]; 3]> = tow.as_ref().map(|_| {
            std::array::from_fn(|v| {
                sens.map_or([[0.0; NU]; 6], |s| {
                    sens_rows(if v == 0 {
                        &s.ship[h]
                    } else {
                        &s.tugs[v - 1][h]
                    })
                })
            })
        });
        for (j, (a, b)) in TOW_PAIRS.into_iter().enumerate() {
            let (xa, xb) = (state(a), state(b));
            let hull = self.formation.hull(b, [xb[0], xb[1], xb[2]], [0.0; 2]);
            let (d, grad) = hull.distance([xa[0], xa[1]]);
            quad.value += tp.clearance.penalty_at(d);
            if let (Some(t), Some(rows)) = (tow.as_deref_mut(), &rows) {
                let (ra, rb) = (&rows[a], &rows[b]);
                let turn = grad[0] * (xa[1] - xb[1]) - grad[1] * (xa[0] - xb[0]);
                let row: [f64; NU] = std::array::from_fn(|k| {
                    grad[0] * (ra[0][k] - rb[0][k])
                        + grad[1] * (ra[1][k] - rb[1][k])
                        + turn * rb[2][k]
                });
                t.record(h, j, d, tp.clearance.min_distance, &row);
            }
        }
    }

    /// The cost terms of `traj` reached with `plan`; with `lin` the model rows
    /// too (consensus and clearance rows recorded).
    fn accumulate(
        &self,
        quad: &mut QuadModel,
        traj: &Trajectory,
        plan: &Plan,
        lin: Option<(&Sensitivities, &mut CentralRows)>,
        input: &SampleInput<'_>,
    ) -> CostBreakdown {
        let tp = &self.tug_params;
        let (wp, wv) = tp.state_weights();
        let (sens, mut rows_out) = match lin {
            Some((s, r)) => (Some(s), Some(r)),
            None => (None, None),
        };
        let mut out = CostBreakdown::default();
        let zero = [[0.0; NU]; 6];
        for h in 0..HORIZON {
            // The ship.
            let start = quad.value;
            let rows = sens.map_or(zero, |s| sens_rows(&s.ship[h]));
            let x = &traj.ship[h];
            let soft = rows_out.as_deref_mut();
            self.ship_terms(quad, x, &plan.ship[h], h, &rows, soft, input);
            out.ship += quad.value - start;
            // The tugs.
            let eta_s = [x[0], x[1], x[2]];
            for i in 0..2 {
                let start = quad.value;
                let g = &traj.tugs[i][h];
                let rows = sens.map_or(zero, |s| sens_rows(&s.tugs[i][h]));
                let (f, jac) =
                    self.formation
                        .tug_reference_linearised(eta_s, plan.ship[h][2 + i], i);
                let res = [g[0] - f[0], g[1] - f[1], angle_difference(g[2], f[2])];
                for c in 0..3 {
                    let m = cons_index(i, h, c);
                    out.consensus_l1 += res[c].abs();
                    out.consensus_max = out.consensus_max.max(res[c].abs());
                    let mut row = [0.0; NU];
                    if let Some(s) = sens {
                        // d(g - f)/du = dg/du - J_eta d eta_S/du - J_alpha e_alpha.
                        let ship = &s.ship[h];
                        for v in 0..NU {
                            row[v] = rows[c][v]
                                - (jac[(c, 0)] * ship[(0, v)]
                                    + jac[(c, 1)] * ship[(1, v)]
                                    + jac[(c, 2)] * ship[(2, v)]);
                        }
                        row[ship_var(h, 2 + i)] -= jac[(c, 3)];
                    }
                    if let Some(r) = rows_out.as_deref_mut() {
                        r.consensus.record(m, res[c], &row);
                    }
                    quad.residual(res[c], wp[c], 0.0, &row);
                    quad.residual(g[3 + c], wv[c], 0.0, &rows[3 + c]);
                }
                if h == 0 {
                    thrust_rate_terms::<NU>(
                        quad,
                        [
                            self.settings.weight_force_rate,
                            self.settings.weight_force_rate,
                            self.settings.weight_moment_rate,
                        ],
                        &plan.tugs[i],
                        input.previous.tugs[i],
                        |h, c| tug_var(i, h, c),
                    );
                }
                let at = At {
                    h,
                    pos: [g[0], g[1]],
                    row_x: &rows[0],
                    row_y: &rows[1],
                };
                obstacle_terms(
                    quad,
                    input.obstacles,
                    input.distance_cost_off,
                    &tp.distance,
                    tp.weight_distance,
                    &tp.clearance,
                    rows_out.as_deref_mut().map(|r| &mut r.clearance[1 + i]),
                    at,
                );
                if let Some(waterway) = &input.waterway {
                    let bank = rows_out.as_deref_mut().map(|r| &mut r.bank[1 + i]);
                    bank_terms(quad, (waterway, 1 + i), tp.clearance.penalty, bank, at);
                }
                let yaw = rows_out.as_deref_mut().map(|r| &mut r.yaw[i]);
                tug_yaw_rate_terms(quad, tp.yaw_rate_limit(), yaw, h, g[5], &rows[5]);
                out.tugs[i] += quad.value - start;
            }
            if tp.tow_rows {
                let start = quad.value;
                let tow = rows_out.as_deref_mut().map(|r| &mut r.tow);
                self.tow_terms(quad, traj, sens, tow, h);
                out.tugs[0] += quad.value - start;
            }
        }
        out.merit = out.total() + self.settings.consensus_penalty * out.consensus_l1;
        out
    }

    /// Linearises the rollouts of `plan` from `start`: trajectories and the
    /// sensitivities of all three to all increments (module docs).
    fn linearise_plan(&self, start: &Start, plan: &Plan, lin: &mut CentralLinearised) {
        self.ship
            .linearise_rollout_into(&start.ship, &plan.ship, &mut lin.ship_lin);
        let mut d = Sens::zeros();
        for h in 0..HORIZON {
            let l = &lin.ship_lin[h];
            let mut next = l.a * d;
            for k in 0..4 {
                next.column_mut(ship_var(h, k)).copy_from(&l.b.column(k));
            }
            lin.sens.ship[h] = next;
            lin.traj.ship[h] = l.x_next;
            d = next;
        }
        for i in 0..2 {
            let pulls = CentralProblem::pulls(start.ship[2], &lin.traj.ship, &plan.ship, i);
            self.tugs[i].linearise_rollout_into(
                &start.tugs[i],
                &plan.tugs[i],
                &pulls,
                &mut lin.tug_lin[i],
            );
            let mut d = Sens::zeros();
            for h in 0..HORIZON {
                let l = &lin.tug_lin[i][h];
                let mut next = l.a * d;
                for c in 0..3 {
                    next.column_mut(tug_var(i, h, c)).copy_from(&l.b.column(c));
                }
                // Tension F_ih; bearing psi_S(h) + alpha_ih.
                let mut tension = RowSVector::<f64, NU>::zeros();
                tension[ship_var(h, i)] = 1.0;
                let mut bearing = if h > 0 {
                    lin.sens.ship[h - 1].row(2).into_owned()
                } else {
                    RowSVector::<f64, NU>::zeros()
                };
                bearing[ship_var(h, 2 + i)] += 1.0;
                next += l.e.column(0) * tension + l.e.column(1) * bearing;
                lin.sens.tugs[i][h] = next;
                lin.traj.tugs[i][h] = l.x_next;
                d = next;
            }
        }
    }
}

impl Subproblem for CentralProblem {
    type Data<'a> = CentralData<'a>;
    type Trajectory = Trajectory;
    type Linearisation = CentralLinearised;
    type Key = Start;
    type Rows = CentralRows;
    type Cost = CostBreakdown;

    fn space(&self) -> &InputSpace {
        &self.space
    }

    fn prepare(&mut self, data: &CentralData<'_>) {
        let sample_time = self.ship.params().sample_time;
        let (way_off, previous) = (data.input.max_surge.is_some(), &data.input.previous.ship);
        (self.ship_params).floor_tensions(&mut self.space, way_off, previous, sample_time);
    }

    fn rows(&self) -> CentralRows {
        // Row m = cons_index(i, h, c): sample h, about tug i and the ship.
        let rows = (0..NC)
            .map(|m| ((m / 3) % HORIZON, SHIP | TUG[m / (3 * HORIZON)]))
            .collect();
        CentralRows {
            consensus: PairRows::new(rows, NU, self.settings.consensus_penalty),
            clearance: [
                self.ship_params.clearance.rows(PER_STEP, SHIP),
                self.tug_params.clearance.rows(PER_STEP, TUG[0]),
                self.tug_params.clearance.rows(PER_STEP, TUG[1]),
            ],
            motion: self.ship_params.motion.rows(PER_STEP, SHIP),
            bank: [
                (self
                    .ship_params
                    .clearance
                    .single(self.ship_params.waterway_rows))
                .rows(PER_STEP, SHIP),
                (self
                    .tug_params
                    .clearance
                    .single(self.tug_params.waterway_rows))
                .rows(PER_STEP, TUG[0]),
                (self
                    .tug_params
                    .clearance
                    .single(self.tug_params.waterway_rows))
                .rows(PER_STEP, TUG[1]),
            ],
            yaw: [
                self.tug_params.yaw_rate_rows(PER_STEP, TUG[0]),
                self.tug_params.yaw_rate_rows(PER_STEP, TUG[1]),
            ],
            tow: (self.tug_params.clearance)
                .slots(TOW_PAIRS.len() * usize::from(self.tug_params.tow_rows))
                .rows(PER_STEP, SHIP | TUG[0] | TUG[1]),
        }
    }

    fn buffers(&self) -> (Trajectory, CentralLinearised) {
        let zeros = [[0.0; 6]; HORIZON];
        let traj = Trajectory {
            ship: zeros,
            tugs: [zeros; 2],
        };
        (
            traj,
            CentralLinearised {
                ship_lin: [ShipLinearisation::default(); HORIZON],
                tug_lin: [[TugLinearisation::default(); HORIZON]; 2],
                sens: Sensitivities {
                    ship: [Sens::zeros(); HORIZON],
                    tugs: [[Sens::zeros(); HORIZON]; 2],
                },
                traj,
            },
        )
    }

    fn previous(&self, data: &CentralData<'_>, out: &mut [f64]) {
        let p = &data.input.previous;
        out[..4].copy_from_slice(&p.ship);
        out[4..7].copy_from_slice(&p.tugs[0]);
        out[7..10].copy_from_slice(&p.tugs[1]);
    }

    fn key(&self, data: &CentralData<'_>) -> Start {
        data.start
    }

    fn rollout(&self, data: &CentralData<'_>, plan: &[f64], out: &mut Trajectory) {
        self.roll(&data.start, &Plan::of(plan), out);
    }

    fn linearise(&self, data: &CentralData<'_>, plan: &[f64], lin: &mut CentralLinearised) {
        self.linearise_plan(&data.start, &Plan::of(plan), lin);
    }

    fn nominal(lin: &CentralLinearised) -> &Trajectory {
        &lin.traj
    }

    fn terms(
        &self,
        quad: &mut QuadModel,
        traj: &Trajectory,
        plan: &[f64],
        model: Option<(&CentralLinearised, &mut CentralRows)>,
        data: &CentralData<'_>,
    ) -> CostBreakdown {
        let lin = model.map(|(l, r)| (&l.sens, r));
        self.accumulate(quad, traj, &Plan::of(plan), lin, &data.input)
    }
}

/// The centralized MPC (module docs).
#[derive(Debug)]
pub struct Centralized {
    scp: Scp<CentralProblem>,
    warm: bool,
}

/// What a [`Centralized`] carries from one control sample to the next (its warm start).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CentralizedState {
    /// The plan and trust radius.
    pub scp: ScpState,
    /// Whether the next sample starts from the plan (else cold).
    pub warm: bool,
}

impl Centralized {
    /// The problem over the given models (`tugs[i]` must model the tug on line
    /// `i`), both tugs with `tug_params`.
    ///
    /// # Errors
    /// Bad settings, a tug on the wrong line, a QP that cannot be built.
    pub fn new(
        ship: ShipModel,
        tugs: [TugModel; 2],
        formation: FormationMap,
        ship_params: ShipMpcParams,
        tug_params: TugMpcParams,
        settings: CentralizedSettings,
    ) -> Result<Centralized, AdmmBuildError> {
        for (i, tug) in tugs.iter().enumerate() {
            if tug.line() != i {
                return Err(AdmmBuildError::Param(ParamError {
                    field: format!("tugs[{i}]"),
                    reason: format!("models the tug on line {}", tug.line()),
                }));
            }
        }
        settings.validate()?;
        let mut channels = ship_params.channels(ship.params().sample_time).to_vec();
        for tug in TUG {
            channels.extend(tug_params.channels().map(|c| c.moving(tug)));
        }
        let problem = CentralProblem {
            ship,
            tugs,
            formation,
            ship_params,
            tug_params,
            settings,
            space: InputSpace::new(channels, HORIZON),
        };
        Ok(Centralized {
            scp: Scp::with_problem(problem, settings.scp)?,
            warm: false,
        })
    }

    /// The problem for a scenario's vessels.
    ///
    /// # Errors
    /// As [`Centralized::new`], and bad model parameters.
    pub fn from_scenario(
        scenario: &Scenario,
        hull: HullModel,
        params: PredictionParams,
        ship_params: ShipMpcParams,
        tug_params: TugMpcParams,
        settings: CentralizedSettings,
    ) -> Result<Centralized, AdmmBuildError> {
        Centralized::new(
            ShipModel::from_scenario(scenario, hull, params)?,
            [
                TugModel::from_scenario(scenario, 0, hull, params)?,
                TugModel::from_scenario(scenario, 1, hull, params)?,
            ],
            FormationMap::from_scenario(scenario)?,
            ship_params,
            tug_params,
            settings,
        )
    }

    /// The ship's prediction model.
    #[must_use]
    pub fn ship_model(&self) -> &ShipModel {
        &self.scp.problem().ship
    }

    /// The settings.
    #[must_use]
    pub fn settings(&self) -> &CentralizedSettings {
        &self.scp.problem().settings
    }

    /// The ship's plan `[F_1, F_2, alpha_1, alpha_2]` per sample.
    #[must_use]
    pub fn ship_plan(&self) -> [ShipInput; HORIZON] {
        Plan::of(self.scp.plan()).ship
    }

    /// Tug `i`'s thrust plan.
    ///
    /// # Panics
    /// If `i > 1`.
    #[must_use]
    pub fn tug_plan(&self, i: usize) -> [TugInput; HORIZON] {
        Plan::of(self.scp.plan()).tugs[i]
    }

    /// The ship's predicted states of the plan (as of the last solve).
    #[must_use]
    pub fn ship_predicted(&self) -> &[ShipState; HORIZON] {
        &self.scp.predicted().ship
    }

    /// Tug `i`'s predicted states of the plan (as of the last solve; headings
    /// unwrapped next to the ship's).
    ///
    /// # Panics
    /// If `i > 1`.
    #[must_use]
    pub fn tug_predicted(&self, i: usize) -> &[TugState; HORIZON] {
        &self.scp.predicted().tugs[i]
    }

    /// The trust region.
    #[must_use]
    pub fn trust_region(&self) -> &crate::engine::TrustRegion {
        self.scp.trust_region()
    }

    /// The state to carry over ([`CentralizedState`]).
    #[must_use]
    pub fn snapshot(&self) -> CentralizedState {
        CentralizedState {
            scp: self.scp.snapshot(self.warm),
            warm: self.warm,
        }
    }

    /// Goes on from `state` (a [`snapshot`](Self::snapshot) of the same problem).
    ///
    /// # Errors
    /// A plan or radius that does not fit (nothing changes then).
    pub fn restore(&mut self, state: &CentralizedState) -> Result<(), String> {
        self.scp
            .restore(&state.scp)
            .map_err(|e| format!("centralized problem: {e}"))?;
        self.warm = state.warm;
        Ok(())
    }

    /// Next sample starts cold (the previous command repeated); trust region back
    /// to its start.
    pub fn reset(&mut self) {
        self.warm = false;
        self.scp.trust_region_mut().reset();
        self.scp.forget_linearisation();
    }

    /// Warm start for the next sample: the plans one sample ahead, the last
    /// sample repeated.
    pub fn shift(&mut self) {
        self.scp.shift();
        self.warm = true;
    }

    /// The cost of the given plans for `input` (nonlinear rollouts; the plans are
    /// taken as they are, not projected): to compare other controllers' plans on
    /// this problem.
    #[must_use]
    pub fn evaluate(
        &self,
        input: &SampleInput<'_>,
        ship_plan: &[ShipInput; HORIZON],
        tug_plans: &[[TugInput; HORIZON]; 2],
    ) -> CostBreakdown {
        let mut flat = [0.0; NU];
        Plan {
            ship: *ship_plan,
            tugs: *tug_plans,
        }
        .write(&mut flat);
        self.scp.cost(&flat, &CentralData::of(input))
    }

    /// The SCP for one sample (module docs), within `budget`.
    pub fn solve_sample(&mut self, input: &SampleInput<'_>) -> CentralizedReport {
        self.solve_within(input, Budget::unlimited())
    }

    /// [`Centralized::solve_sample`] stopping once `budget` is spent (after at
    /// least one step).
    pub fn solve_within(&mut self, input: &SampleInput<'_>, budget: Budget) -> CentralizedReport {
        if !self.warm {
            let mut flat = [0.0; NU];
            Plan {
                ship: [input.previous.ship; HORIZON],
                tugs: input.previous.tugs.map(|t| [t; HORIZON]),
            }
            .write(&mut flat);
            self.scp.set_plan(&flat);
        }
        let data = CentralData::of(input);
        let settings = *self.settings();
        // A trust region shrunk by the previous sample's last steps would make
        // this sample crawl from the start.
        self.scp.trust_region_mut().reopen();
        let mut iterations = 0;
        let mut failed_steps = 0;
        let mut converged = false;
        let mut budget_hit = false;
        let mut last = ScpReport::never_run();
        while iterations < settings.max_iterations {
            if iterations > 0 && budget.spent() {
                budget_hit = true;
                break;
            }
            let report = self.scp.step(&data);
            iterations += 1;
            let usable = report.qp.is_usable();
            failed_steps += usize::from(!usable);
            last = report;
            // Nothing left to gain by the model's own measure: a predicted decrease
            // below 1e-6 of the cost (or an exactly stationary step).
            let stationary = usable
                && ((!report.accepted && report.ratio == 1.0)
                    || report.predicted_decrease <= 1e-6 * report.cost_before.abs().max(1.0));
            let settled = report.accepted
                && (report.first_move_change < settings.tolerance
                    || report.cost_before - report.cost_after
                        < settings.cost_tolerance * report.cost_before.abs().max(1.0));
            if settled || stationary {
                converged = true;
                break;
            }
        }
        // The final plan's trajectories and cost.
        let breakdown = self.scp.settle(&data);
        let plan = Plan::of(self.scp.plan());
        let first = plan.ship[0];
        CentralizedReport {
            iterations,
            converged,
            budget_hit,
            failed: !last.qp.is_usable(),
            failed_steps,
            cost: breakdown.merit,
            breakdown,
            last_step: last,
            tension: [first[0], first[1]],
            angle: [first[2], first[3]],
            tug_thrust: [plan.tugs[0][0], plan.tugs[1][0]],
        }
    }
}

#[cfg(test)]
mod tests;
