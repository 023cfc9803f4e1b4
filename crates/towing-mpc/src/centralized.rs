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
//! Constraints: the ship's box, rate bounds (first sample from the previous
//! command, then between samples) and the tugs' thrust boxes, each merged with
//! the trust region (per-variable scales of the subproblems' parameters); the
//! clearance rows of the ship and of both tugs ([`ClearanceParams`] of each);
//! before each step the plan is projected onto the bounds, as in the subproblems.
//!
//! Solve: SCP steps (one QP each, accept/reject on the true merit, trust region
//! as in [`crate::scp`]) until an accepted step moves the first move by less
//! than [`CentralizedSettings::tolerance`], or the model predicts no decrease in
//! the trust region, or [`CentralizedSettings::max_iterations`]. One QP per number
//! of obstacle slots in use, built at construction and updated in place.
//!
//! Allocation: none per sample (buffers and QPs made in [`Centralized::new`]).

// Index loops over (sample, channel) pairs: the indices also address the flat
// increment vector (`10 h + k`).
#![allow(clippy::needless_range_loop)]

use nalgebra::{RowSVector, SMatrix};
use towing_model::{HullModel, ParamError, Scenario};

use crate::admm::{AdmmBuildError, SampleInput};
use crate::formation::FormationMap;
use crate::params::PredictionParams;
use crate::qp::{Qp, QpBuildError, QpOutcome};
use crate::scp::{
    angle_difference, box_qp, load_model, obstacle_terms, set_box, Clearance, ClearanceParams,
    QuadModel, ScpReport, ScpSettings, TrustRegion, SLACK_SCALE,
};
use crate::ship::{ShipInput, ShipLinearisation, ShipModel, ShipState};
use crate::ship_mpc::{ship_stage_terms, ShipMpcParams};
use crate::tug::{TowlinePull, TugInput, TugLinearisation, TugModel, TugState};
use crate::tug_mpc::{TugMpcParams, HORIZON};

/// Inputs per sample: 4 ship, 3 + 3 tugs.
const PER_STEP: usize = 10;
/// Increments.
const NU: usize = PER_STEP * HORIZON;
/// Consensus residuals (2 tugs x H samples x 3).
const NC: usize = 2 * HORIZON * 3;
const RATE_ROWS: usize = 2 * 4 * (HORIZON - 1);

/// `d x / d u` of a predicted state w.r.t. all increments.
type Sens = SMatrix<f64, 6, NU>;

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
    /// `W_c`: L1 penalty of the configuration restriction (per m, per rad).
    pub consensus_penalty: f64,
    /// Largest consensus slack (m, rad); keeps the QP bounded.
    pub max_consensus_slack: f64,
    /// Trust region (scales: the subproblems' `trust_scale`).
    pub scp: ScpSettings,
    /// `w_dtau`: weight of the tugs' thrust changes
    /// `sum_i sum_h |tau_ih - tau_ih-1|^2` (per N^2 and (N m)^2), `tau_i,-1` the
    /// thrust applied in the previous sample; see [`thrust_rate_terms`].
    pub thrust_rate_weight: f64,
}

impl Default for CentralizedSettings {
    fn default() -> Self {
        CentralizedSettings {
            max_iterations: 60,
            tolerance: 1e-4,
            consensus_penalty: 1e3,
            max_consensus_slack: 10.0,
            scp: ScpSettings::default(),
            thrust_rate_weight: 0.01,
        }
    }
}

/// `w sum_h |tau_h - tau_h-1|^2` over one tug's plan, `tau_-1 = previous`, with
/// `column(h, c)` the increment variable of channel `c` of sample `h` (the
/// variables are increments of the plan, so the rows are unit vectors).
///
/// Why, and why only here: in the centralized problem the configuration
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
/// distributed controller does not need it (the ADMM's penalty `rho` keeps
/// the consensus soft within an iteration, and no such alternation was seen),
/// and there it slowed the ADMM's convergence on the paper instance tenfold,
/// so it is not in [`crate::TugMpc`]: with `w > 0` the two architectures solve
/// problems that differ by this term (`tests::distributed_matches_centralized`
/// sets it to 0).
fn thrust_rate_terms(
    quad: &mut QuadModel,
    weight: f64,
    plan: &[TugInput; HORIZON],
    previous: TugInput,
    column: impl Fn(usize, usize) -> usize,
) {
    if weight <= 0.0 {
        return;
    }
    for h in 0..HORIZON {
        let before = if h == 0 { previous } else { plan[h - 1] };
        for c in 0..3 {
            let mut row = [0.0; NU];
            if !quad.value_only {
                row[column(h, c)] = 1.0;
                if h > 0 {
                    row[column(h - 1, c)] = -1.0;
                }
            }
            quad.residual(plan[h][c] - before[c], weight, 0.0, &row);
        }
    }
}

/// The plans of all three vessels.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Plan {
    ship: [ShipInput; HORIZON],
    tugs: [[TugInput; HORIZON]; 2],
}

/// Predicted states of all three vessels (after samples 0..H).
#[derive(Debug, Clone, Copy)]
struct Trajectory {
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
}

impl CostBreakdown {
    /// `J_S + J_1 + J_2`.
    #[must_use]
    pub fn total(&self) -> f64 {
        self.ship + self.tugs[0] + self.tugs[1]
    }
}

/// What one sample's SCP did.
#[derive(Debug, Clone, Copy)]
pub struct CentralizedReport {
    /// SCP iterations (QPs solved).
    pub iterations: usize,
    /// Whether the first move converged (module docs) before `max_iterations`.
    pub converged: bool,
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

/// One QP layout: the QP, the clearance rows of ship, tug 1, tug 2, the first
/// rate row, the first consensus row and the `A` slots of the consensus rows.
#[derive(Debug)]
struct Layout {
    qp: Qp,
    clearance: [Clearance; 3],
    rate_row: usize,
    cons_row: usize,
    cons_slots: Vec<usize>,
}

impl Layout {
    /// Extra rows (after the box): rate rows, then per consensus residual `m` the
    /// rows `2 m`, `2 m + 1` over the increments of samples `0..=h` and the slack
    /// `NU + m`, then the three clearance blocks. Variables: increments, consensus
    /// slacks, clearance slacks.
    fn new(cp: [ClearanceParams; 3]) -> Result<Layout, QpBuildError> {
        let mut entries = Vec::new();
        for h in 1..HORIZON {
            for k in 0..4 {
                let row = 2 * (4 * (h - 1) + k);
                let (cur, prev) = (ship_var(h, k), ship_var(h - 1, k));
                entries.extend([(row, cur), (row, prev), (row + 1, cur), (row + 1, prev)]);
            }
        }
        let n_rate = entries.len();
        for i in 0..2 {
            for h in 0..HORIZON {
                for c in 0..3 {
                    let m = cons_index(i, h, c);
                    for sign in 0..2 {
                        let row = RATE_ROWS + 2 * m + sign;
                        entries.extend((0..PER_STEP * (h + 1)).map(|v| (row, v)));
                        entries.push((row, NU + m));
                    }
                }
            }
        }
        let n_cons = entries.len() - n_rate;
        let ns = cp.map(|p| Clearance::slacks(&p, HORIZON));
        let mut first_row = RATE_ROWS + 2 * NC;
        let mut first_slack = NU + NC;
        let mut blocks = [(0, 0, 0); 3];
        for (b, (p, n)) in blocks.iter_mut().zip(cp.iter().zip(ns)) {
            let e = Clearance::entries_at(p, PER_STEP, HORIZON, first_row, first_slack);
            *b = (first_row, first_slack, e.len());
            entries.extend(e);
            first_row += n;
            first_slack += n;
        }
        let n = first_slack;
        let (mut qp, slots) = box_qp(n, NU, first_row, &entries)?;
        for (slot, v) in slots[..n_rate]
            .iter()
            .zip([1.0, -1.0, -1.0, 1.0].iter().cycle())
        {
            qp.a_mut()[*slot] = *v;
        }
        let rate_row = 2 * n;
        let cons_slots = slots[n_rate..n_rate + n_cons].to_vec();
        let mut at = n_rate + n_cons;
        let clearance = std::array::from_fn(|v| {
            let (row, slack, len) = blocks[v];
            let c = Clearance::new_at(
                cp[v],
                PER_STEP,
                HORIZON,
                rate_row + row,
                slots[at..at + len].to_vec(),
                slack,
            );
            at += len;
            c
        });
        Ok(Layout {
            qp,
            clearance,
            rate_row,
            cons_row: rate_row + RATE_ROWS,
            cons_slots,
        })
    }
}

/// The models and parameters (immutable during a solve).
#[derive(Debug)]
struct Problem {
    ship: ShipModel,
    tugs: [TugModel; 2],
    formation: FormationMap,
    ship_params: ShipMpcParams,
    tug_params: TugMpcParams,
    settings: CentralizedSettings,
}

/// The consensus residuals `r = g - f` and their rows `dr/du`.
#[derive(Debug, Clone)]
struct Consensus {
    r: [f64; NC],
    rows: [[f64; NU]; NC],
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

impl Problem {
    /// Projects `plan` onto the bounds and rate bounds (as the subproblems do).
    fn project(&self, plan: &mut Plan, previous: &ShipInput) {
        self.ship_params.project(&mut plan.ship, previous);
        let lim = self.tug_params.thrust_limit;
        for tau in plan.tugs.iter_mut().flatten() {
            for (t, l) in tau.iter_mut().zip(lim) {
                *t = t.clamp(-l, l);
            }
        }
    }

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
    fn rollout(&self, x0: &Start, plan: &Plan, out: &mut Trajectory) {
        self.ship.rollout_into(&x0.ship, &plan.ship, &mut out.ship);
        for i in 0..2 {
            let pulls = Problem::pulls(x0.ship[2], &out.ship, &plan.ship, i);
            self.tugs[i].rollout_into(&x0.tugs[i], &plan.tugs[i], &pulls, &mut out.tugs[i]);
        }
    }

    /// The cost terms of `traj` reached with `plan`; with `lin` the model rows
    /// too (consensus rows into `cons`, clearance rows recorded).
    #[allow(clippy::too_many_arguments)]
    fn accumulate(
        &self,
        quad: &mut QuadModel,
        traj: &Trajectory,
        plan: &Plan,
        lin: Option<(&Sensitivities, &mut [Clearance; 3])>,
        cons: &mut Consensus,
        input: &SampleInput<'_>,
    ) -> CostBreakdown {
        let sp = &self.ship_params;
        let tp = &self.tug_params;
        let with_rows = lin.is_some();
        let (sens, mut clearance) = match lin {
            Some((s, c)) => (Some(s), Some(c)),
            None => (None, None),
        };
        let mut out = CostBreakdown::default();
        let zero = [[0.0; NU]; 6];
        for h in 0..HORIZON {
            // The ship.
            let start = quad.value;
            let rows = sens.map_or(zero, |s| sens_rows(&s.ship[h]));
            let x = &traj.ship[h];
            let r = input.reference[h];
            ship_stage_terms(
                quad,
                sp,
                x,
                r,
                &plan.ship[h],
                &rows,
                with_rows.then(|| std::array::from_fn(|k| ship_var(h, k))),
                h + 1 == HORIZON,
                input.heading_floor,
            );
            obstacle_terms(
                quad,
                input.obstacles,
                &sp.distance,
                sp.weights[2],
                &sp.clearance,
                clearance.as_deref_mut().map(|c| &mut c[0]),
                h,
                [x[0], x[1]],
                &rows[0],
                &rows[1],
            );
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
                    cons.r[m] = res[c];
                    out.consensus_l1 += res[c].abs();
                    out.consensus_max = out.consensus_max.max(res[c].abs());
                    let row = &mut cons.rows[m];
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
                    quad.residual(res[c], tp.weights[0], 0.0, &cons.rows[m]);
                    quad.residual(g[3 + c], tp.weights[1], 0.0, &rows[3 + c]);
                }
                if h == 0 {
                    thrust_rate_terms(
                        quad,
                        self.settings.thrust_rate_weight,
                        &plan.tugs[i],
                        input.previous.tugs[i],
                        |h, c| tug_var(i, h, c),
                    );
                }
                obstacle_terms(
                    quad,
                    input.obstacles,
                    &tp.distance,
                    tp.weights[2],
                    &tp.clearance,
                    clearance.as_deref_mut().map(|c| &mut c[1 + i]),
                    h,
                    [g[0], g[1]],
                    &rows[0],
                    &rows[1],
                );
                out.tugs[i] += quad.value - start;
            }
        }
        out
    }

    /// The merit of a breakdown.
    fn merit(&self, b: &CostBreakdown) -> f64 {
        b.total() + self.settings.consensus_penalty * b.consensus_l1
    }
}

/// Initial states (tug headings unwrapped next to the ship's).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Start {
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

/// The centralized MPC (module docs).
#[derive(Debug)]
pub struct Centralized {
    problem: Problem,
    /// One layout per number of obstacle slots per sample in use (the last one,
    /// with every vessel's full count, records the linearisation).
    layouts: Vec<Layout>,
    trust: TrustRegion,
    plan: Plan,
    candidate: Plan,
    traj: Trajectory,
    candidate_traj: Trajectory,
    ship_lin: [ShipLinearisation; HORIZON],
    tug_lin: [[TugLinearisation; HORIZON]; 2],
    sens: Sensitivities,
    /// The `(start, plan)` of the linearisation in `sens` (reused after a
    /// rejected step).
    lin_key: Option<(Start, Plan)>,
    cons: Consensus,
    quad: QuadModel,
    warm: bool,
}

impl Centralized {
    /// The problem over the given models (`tugs[i]` must model the tug on line
    /// `i`), both tugs with `tug_params`.
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
        let bad = |field: &str, reason: String| {
            AdmmBuildError::Param(ParamError {
                field: field.to_owned(),
                reason,
            })
        };
        if settings.max_iterations == 0 {
            return Err(bad("max_iterations", "must be >= 1".into()));
        }
        if !(settings.consensus_penalty.is_finite() && settings.consensus_penalty > 0.0) {
            return Err(bad(
                "consensus_penalty",
                format!("must be finite and > 0, got {}", settings.consensus_penalty),
            ));
        }
        if !(settings.max_consensus_slack.is_finite() && settings.max_consensus_slack > 0.0) {
            return Err(bad(
                "max_consensus_slack",
                format!(
                    "must be finite and > 0, got {}",
                    settings.max_consensus_slack
                ),
            ));
        }
        let (ms, mt) = (
            ship_params.clearance.max_obstacles,
            tug_params.clearance.max_obstacles,
        );
        let layouts = (0..=ms.max(mt))
            .map(|c| {
                let cs = ClearanceParams {
                    max_obstacles: c.min(ms),
                    ..ship_params.clearance
                };
                let ct = ClearanceParams {
                    max_obstacles: c.min(mt),
                    ..tug_params.clearance
                };
                Layout::new([cs, ct, ct])
            })
            .collect::<Result<Vec<_>, QpBuildError>>()?;
        let zeros = [[0.0; 6]; HORIZON];
        Ok(Centralized {
            problem: Problem {
                ship,
                tugs,
                formation,
                ship_params,
                tug_params,
                settings,
            },
            layouts,
            trust: TrustRegion::new(settings.scp),
            plan: Plan {
                ship: [[0.0; 4]; HORIZON],
                tugs: [[[0.0; 3]; HORIZON]; 2],
            },
            candidate: Plan {
                ship: [[0.0; 4]; HORIZON],
                tugs: [[[0.0; 3]; HORIZON]; 2],
            },
            traj: Trajectory {
                ship: zeros,
                tugs: [zeros; 2],
            },
            candidate_traj: Trajectory {
                ship: zeros,
                tugs: [zeros; 2],
            },
            ship_lin: [ShipLinearisation::default(); HORIZON],
            tug_lin: [[TugLinearisation::default(); HORIZON]; 2],
            sens: Sensitivities {
                ship: [Sens::zeros(); HORIZON],
                tugs: [[Sens::zeros(); HORIZON]; 2],
            },
            lin_key: None,
            cons: Consensus {
                r: [0.0; NC],
                rows: [[0.0; NU]; NC],
            },
            quad: QuadModel::new(NU),
            warm: false,
        })
    }

    /// The problem for a scenario's vessels.
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
        &self.problem.ship
    }

    /// The settings.
    #[must_use]
    pub fn settings(&self) -> &CentralizedSettings {
        &self.problem.settings
    }

    /// The ship's plan `[F_1, F_2, alpha_1, alpha_2]` per sample.
    #[must_use]
    pub fn ship_plan(&self) -> &[ShipInput; HORIZON] {
        &self.plan.ship
    }

    /// Tug `i`'s thrust plan.
    ///
    /// # Panics
    /// If `i > 1`.
    #[must_use]
    pub fn tug_plan(&self, i: usize) -> &[TugInput; HORIZON] {
        &self.plan.tugs[i]
    }

    /// The ship's predicted states of the plan (as of the last solve).
    #[must_use]
    pub fn ship_predicted(&self) -> &[ShipState; HORIZON] {
        &self.traj.ship
    }

    /// Tug `i`'s predicted states of the plan (as of the last solve; headings
    /// unwrapped next to the ship's).
    ///
    /// # Panics
    /// If `i > 1`.
    #[must_use]
    pub fn tug_predicted(&self, i: usize) -> &[TugState; HORIZON] {
        &self.traj.tugs[i]
    }

    /// The trust region.
    #[must_use]
    pub fn trust_region(&self) -> &TrustRegion {
        &self.trust
    }

    /// Next sample starts cold (the previous command repeated); trust region back
    /// to its start.
    pub fn reset(&mut self) {
        self.warm = false;
        self.trust.reset();
        self.lin_key = None;
    }

    /// Warm start for the next sample: the plans one sample ahead, the last
    /// sample repeated.
    pub fn shift(&mut self) {
        fn shifted<T: Copy>(a: &[T; HORIZON]) -> [T; HORIZON] {
            std::array::from_fn(|h| a[(h + 1).min(HORIZON - 1)])
        }
        self.plan.ship = shifted(&self.plan.ship);
        for i in 0..2 {
            self.plan.tugs[i] = shifted(&self.plan.tugs[i]);
        }
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
        let plan = Plan {
            ship: *ship_plan,
            tugs: *tug_plans,
        };
        let mut traj = self.traj;
        self.problem.rollout(&Start::of(input), &plan, &mut traj);
        let mut quad = QuadModel::new(0);
        quad.reset(true);
        let mut cons = self.cons.clone();
        self.problem
            .accumulate(&mut quad, &traj, &plan, None, &mut cons, input)
    }

    /// Linearises the rollouts of the plan from `start`: trajectories and the
    /// sensitivities of all three to all increments (module docs).
    fn linearise(&mut self, start: &Start) {
        let key = (*start, self.plan);
        if self.lin_key == Some(key) {
            return;
        }
        let p = &self.problem;
        p.ship
            .linearise_rollout_into(&start.ship, &self.plan.ship, &mut self.ship_lin);
        let mut d = Sens::zeros();
        for h in 0..HORIZON {
            let l = &self.ship_lin[h];
            let mut next = l.a * d;
            for k in 0..4 {
                next.column_mut(ship_var(h, k)).copy_from(&l.b.column(k));
            }
            self.sens.ship[h] = next;
            self.traj.ship[h] = l.x_next;
            d = next;
        }
        for i in 0..2 {
            let pulls = Problem::pulls(start.ship[2], &self.traj.ship, &self.plan.ship, i);
            p.tugs[i].linearise_rollout_into(
                &start.tugs[i],
                &self.plan.tugs[i],
                &pulls,
                &mut self.tug_lin[i],
            );
            let mut d = Sens::zeros();
            for h in 0..HORIZON {
                let l = &self.tug_lin[i][h];
                let mut next = l.a * d;
                for c in 0..3 {
                    next.column_mut(tug_var(i, h, c)).copy_from(&l.b.column(c));
                }
                // Tension F_ih; bearing psi_S(h) + alpha_ih.
                let mut tension = RowSVector::<f64, NU>::zeros();
                tension[ship_var(h, i)] = 1.0;
                let mut bearing = if h > 0 {
                    self.sens.ship[h - 1].row(2).into_owned()
                } else {
                    RowSVector::<f64, NU>::zeros()
                };
                bearing[ship_var(h, 2 + i)] += 1.0;
                next += l.e.column(0) * tension + l.e.column(1) * bearing;
                self.sens.tugs[i][h] = next;
                self.traj.tugs[i][h] = l.x_next;
                d = next;
            }
        }
        self.lin_key = Some(key);
    }

    /// One SCP step from the current plan. Returns the report and the largest
    /// change of a first-move channel (0 if rejected).
    fn step(&mut self, input: &SampleInput<'_>, start: &Start) -> (ScpReport, f64) {
        self.problem.project(&mut self.plan, &input.previous.ship);
        self.linearise(start);
        let full = self.layouts.len() - 1;
        self.quad.reset(false);
        for c in &mut self.layouts[full].clearance {
            c.clear();
        }
        let breakdown = self.problem.accumulate(
            &mut self.quad,
            &self.traj,
            &self.plan,
            Some((&self.sens, &mut self.layouts[full].clearance)),
            &mut self.cons,
            input,
        );
        let p = &self.problem;
        let cost_before = p.merit(&breakdown);
        // Boxes: bounds, trust region, first-sample rates.
        let radius = self.trust.radius();
        let (mut lo, mut hi) = ([0.0; NU], [0.0; NU]);
        for k in 0..4 {
            let (l0, h0, rate) = p.ship_params.channel_limits(k);
            let tr = radius * p.ship_params.trust_scale[k / 2];
            let prev = input.previous.ship[k].clamp(l0, h0);
            for h in 0..HORIZON {
                let u = self.plan.ship[h][k];
                let (mut l, mut r) = ((l0 - u).max(-tr), (h0 - u).min(tr));
                if h == 0 {
                    l = l.max(prev - rate - u);
                    r = r.min(prev + rate - u);
                }
                lo[ship_var(h, k)] = l.min(0.0);
                hi[ship_var(h, k)] = r.max(0.0);
            }
        }
        let lim = p.tug_params.thrust_limit;
        for i in 0..2 {
            for h in 0..HORIZON {
                for c in 0..3 {
                    let tr = radius * p.tug_params.trust_scale[c];
                    let u = self.plan.tugs[i][h][c];
                    lo[tug_var(i, h, c)] = (-lim[c] - u).max(-tr).min(0.0);
                    hi[tug_var(i, h, c)] = (lim[c] - u).min(tr).max(0.0);
                }
            }
        }
        let mut used = 0;
        for c in &mut self.layouts[full].clearance {
            c.drop_redundant(&lo, &hi);
            used = used.max(c.slots_used());
        }
        if used < full {
            let (small, large) = self.layouts.split_at_mut(full);
            for (s, l) in small[used].clearance.iter_mut().zip(&large[0].clearance) {
                s.copy_from(l);
            }
        }
        let layout = &mut self.layouts[used];
        let qp = &mut layout.qp;
        load_model(qp, &self.quad);
        for c in &layout.clearance {
            c.load(qp);
        }
        for j in 0..NU {
            set_box(qp, j, lo[j], hi[j]);
        }
        for k in 0..4 {
            let rate = p.ship_params.channel_limits(k).2;
            for h in 1..HORIZON {
                let diff = self.plan.ship[h][k] - self.plan.ship[h - 1][k];
                let row = layout.rate_row + 2 * (4 * (h - 1) + k);
                qp.b_mut()[row] = (rate - diff).max(0.0);
                qp.b_mut()[row + 1] = (rate + diff).max(0.0);
            }
        }
        // Consensus rows: r + J du - s / SC <= 0 and -(r + J du) - s / SC <= 0.
        let w_c = p.settings.consensus_penalty;
        let mut at = 0;
        for i in 0..2 {
            for h in 0..HORIZON {
                for c in 0..3 {
                    let m = cons_index(i, h, c);
                    let width = PER_STEP * (h + 1);
                    for sign in [1.0, -1.0] {
                        let a = qp.a_mut();
                        for v in 0..width {
                            a[layout.cons_slots[at + v]] = sign * self.cons.rows[m][v];
                        }
                        a[layout.cons_slots[at + width]] = -1.0 / SLACK_SCALE;
                        at += width + 1;
                        let row = layout.cons_row + 2 * m + usize::from(sign < 0.0);
                        qp.b_mut()[row] = -sign * self.cons.r[m];
                    }
                    set_box(
                        qp,
                        NU + m,
                        0.0,
                        p.settings.max_consensus_slack * SLACK_SCALE,
                    );
                    qp.q_mut()[NU + m] = w_c / SLACK_SCALE;
                }
            }
        }
        let outcome = qp.solve();
        let iterations = qp.iterations();
        if !outcome.is_usable() {
            self.trust.fail();
            return (
                ScpReport::rejected(outcome, cost_before, self.trust.radius(), iterations),
                0.0,
            );
        }
        let du = qp.solution();
        let mut predicted = self.quad.predicted_decrease(&du[..NU]);
        for c in &layout.clearance {
            predicted += c.predicted_decrease(du);
        }
        // The penalty's decrease from the linear model itself, |r| - |r + J du|,
        // not from the slacks: their solver tolerance (about 1e-6 each, times W_c)
        // would swamp small steps and keep the trust ratio near 0.6.
        for m in 0..NC {
            let lin: f64 = self.cons.r[m]
                + self.cons.rows[m]
                    .iter()
                    .zip(&du[..NU])
                    .map(|(a, b)| a * b)
                    .sum::<f64>();
            predicted += w_c * (self.cons.r[m].abs() - lin.abs());
        }
        for h in 0..HORIZON {
            for k in 0..4 {
                self.candidate.ship[h][k] = self.plan.ship[h][k] + du[ship_var(h, k)];
            }
            for i in 0..2 {
                for c in 0..3 {
                    self.candidate.tugs[i][h][c] = self.plan.tugs[i][h][c] + du[tug_var(i, h, c)];
                }
            }
        }
        // Removes the solver's tolerance on the constraints.
        p.project(&mut self.candidate, &input.previous.ship);
        p.rollout(start, &self.candidate, &mut self.candidate_traj);
        self.quad.reset(true);
        let b = p.accumulate(
            &mut self.quad,
            &self.candidate_traj,
            &self.candidate,
            None,
            &mut self.cons,
            input,
        );
        let cost_candidate = p.merit(&b);
        let (accepted, ratio) = self.trust.judge(cost_before, cost_candidate, predicted);
        let mut change: f64 = 0.0;
        if accepted {
            for k in 0..4 {
                change = change.max((self.candidate.ship[0][k] - self.plan.ship[0][k]).abs());
            }
            for i in 0..2 {
                for c in 0..3 {
                    change =
                        change.max((self.candidate.tugs[i][0][c] - self.plan.tugs[i][0][c]).abs());
                }
            }
            self.plan = self.candidate;
            self.traj = self.candidate_traj;
        }
        let report = ScpReport::judged(
            outcome,
            [cost_before, cost_candidate, predicted],
            accepted,
            ratio,
            self.trust.radius(),
            iterations,
        );
        (report, change)
    }

    /// The SCP for one sample (module docs).
    pub fn solve_sample(&mut self, input: &SampleInput<'_>) -> CentralizedReport {
        if !self.warm {
            self.plan.ship = [input.previous.ship; HORIZON];
            for i in 0..2 {
                self.plan.tugs[i] = [input.previous.tugs[i]; HORIZON];
            }
        }
        let start = Start::of(input);
        // A trust region shrunk by the previous sample's last steps would make
        // this sample crawl from the start: at least the initial radius.
        if self.trust.radius() < self.problem.settings.scp.initial_radius {
            self.trust.reset();
        }
        let mut iterations = 0;
        let mut failed_steps = 0;
        let mut converged = false;
        let mut last = None;
        while iterations < self.problem.settings.max_iterations {
            let (report, change) = self.step(input, &start);
            iterations += 1;
            let usable = report.qp.is_usable();
            failed_steps += usize::from(!usable);
            last = Some(report);
            // Nothing left to gain by the model's own measure: a predicted decrease
            // below 1e-6 of the cost (or an exactly stationary step).
            let stationary = usable
                && ((!report.accepted && report.ratio == 1.0)
                    || report.predicted_decrease <= 1e-6 * report.cost_before.abs().max(1.0));
            if (report.accepted && change < self.problem.settings.tolerance) || stationary {
                converged = true;
                break;
            }
        }
        // The final plan's trajectories and cost.
        self.problem.rollout(&start, &self.plan, &mut self.traj);
        self.quad.reset(true);
        let breakdown = self.problem.accumulate(
            &mut self.quad,
            &self.traj,
            &self.plan,
            None,
            &mut self.cons,
            input,
        );
        let last_step = last.unwrap_or_else(|| {
            ScpReport::rejected(
                QpOutcome::Failed(crate::QpFailure::Other),
                f64::NAN,
                self.trust.radius(),
                0,
            )
        });
        let first = self.plan.ship[0];
        CentralizedReport {
            iterations,
            converged,
            failed: !last_step.qp.is_usable(),
            failed_steps,
            cost: self.problem.merit(&breakdown),
            breakdown,
            last_step,
            tension: [first[0], first[1]],
            angle: [first[2], first[3]],
            tug_thrust: [self.plan.tugs[0][0], self.plan.tugs[1][0]],
        }
    }
}

#[cfg(test)]
mod tests;
