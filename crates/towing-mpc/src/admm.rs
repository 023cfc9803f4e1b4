//! The ADMM loop of Du, Negenborn, Reppa (2022), Algorithm 1 with eq. (22)-(29),
//! for one control sample (`docs/controller-design.md`, "ADMM").
//!
//! Per iteration `s = 1..S`:
//!
//! 1. each tug takes one SCP step of (25) ([`TugMpc`]`::step`) given
//!    `f_i(tau_S^{s-1})`: the tug references of the configuration map
//!    ([`FormationMap`]) along the ship's current predicted trajectory and towing
//!    angles, the towline pulls of the ship's current plan (tension `F_ih`, bearing
//!    `psi_S + alpha_ih` with `psi_S` the ship's heading at the start of sample `h`,
//!    [`TowlinePull::from_plan`]) and `lambda^{s-1}`;
//! 2. the ship takes one SCP step of (26) ([`ShipMpc`]`::step`) given
//!    `g_i(tau_Ti^s)`, the tugs' predicted poses, and `lambda^{s-1}`;
//! 3. `lambda_i += rho (g_i - f_i)` (27), with `f_i = f_i(tau_S^s)`;
//! 4. residuals `r_pri,i = |g_i - f_i|_2`, `r_dual,i = |f_i^s - f_i^{s-1}|_2` and
//!    the tolerances of (29) with `n_s = 3 H`; stop when both hold for both tugs,
//!    or after `max_iterations`.
//!
//! The dual residual is taken as printed in eq. (28), without the factor `rho`
//! of the standard ADMM dual residual `rho (f^s - f^{s-1})` (Boyd et al. 2010,
//! eq. (3.12)); with `rho` of order 1 the two differ little, and the printed form
//! keeps the stopping rule meaningful for `rho = 0`.
//!
//! Headings: the plant wraps headings to `(-pi, pi]`, the prediction models keep
//! them continuous. On entry each tug's heading is unwrapped to within `pi` of the
//! ship's (`psi_S + angle_difference(psi_i, psi_S)`), so `g_i` and `f_i`
//! (`psi_S + alpha_i`) are continuous and close; every heading difference (the
//! residuals, the multiplier update) is additionally wrapped with
//! [`angle_difference`], the subproblems' own rule.
//!
//! Warm start: [`Admm::shift`] moves every plan and multiplier one sample ahead
//! (the last sample repeated) for the next control sample. Without a shift since
//! the construction (or [`Admm::reset`]) the sample starts cold: the plans repeat
//! the previously applied command, the multipliers are zero. A sample that ends at
//! `max_iterations` without consensus leaves the multipliers as it found them: when
//! the subproblems cannot agree, the multiplier updates (27) grow without bound (the
//! dual iterates of ADMM diverge on an infeasible consensus, Boyd et al. 2010,
//! section 3.3), and carried into the next sample they drove the tugs' plans away
//! from the formation (multiplier norm 1-5 when converging, 200-1000 after a capped
//! sample; random-12-0032 and -0074, distributed: tug speeds 5 times cruise, tug-tug
//! overlaps and groundings, gone with this rule, `docs/assumptions.md`). A sample
//! ended by the time budget keeps its multipliers: the next sample goes on from them.
//!
//! Allocation: none per sample; the subproblems, multipliers, residual history
//! (fixed capacity [`MAX_ITERATIONS`]) are made at construction.

// Index loops over (tug, sample, component) triples address several arrays.
#![allow(clippy::needless_range_loop)]

use std::fmt;

use serde::{Deserialize, Serialize};
use towing_model::{HullModel, ParamError, Scenario};

use crate::costs::{angle_difference, Waterway};
use crate::engine::{Budget, ScpReport, ScpState};
use crate::formation::FormationMap;
use crate::obstacle::Obstacle;
use crate::params::PredictionParams;
use crate::qp::QpBuildError;
use crate::ship::{ShipInput, ShipModel, ShipState};
use crate::ship_mpc::{ShipMpc, ShipMpcParams, ShipStepData};
use crate::tug::{TowlinePull, TugInput, TugModel, TugState};
use crate::tug_mpc::{TugMpc, TugMpcParams, TugStepData};

mod helper;

use crate::HORIZON;
pub use helper::TugRef;
use helper::{poses, Poses, Tug2};

/// Capacity of the residual history, and the largest `max_iterations` accepted.
pub const MAX_ITERATIONS: usize = 100;

/// `n_s` of eq. (29): the size of a tug's coupling variable, `3 H`.
const N_S: usize = 3 * HORIZON;

/// Parameters of the ADMM loop.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AdmmSettings {
    /// Penalty `rho` of eq. (22) (>= 0, finite).
    pub rho: f64,
    /// `S`: most iterations per sample (1..=[`MAX_ITERATIONS`]).
    pub max_iterations: usize,
    /// `eps_abs` of eq. (29) (> 0).
    pub eps_abs: f64,
    /// `eps_rel` of eq. (29) (>= 0).
    pub eps_rel: f64,
    /// Run the two tugs' steps of an iteration in parallel (tug 2 on a helper
    /// thread), as the paper's distributed architecture has each tug solve its
    /// own problem. The results are bit-identical either way (each tug's
    /// arithmetic is its own); only the wall time differs.
    pub parallel_tugs: bool,
}

impl Default for AdmmSettings {
    /// `eps_abs = eps_rel = 1e-3` (Table 3). `rho` and `S` are not given in the
    /// paper; `S = 30` was chosen by measurement on the tests' instances (the
    /// `rho_sweep` test in this module, run with `--ignored --nocapture`), `rho = 10`
    /// on the paper scenario's closed loop: at 20 its distributed scheme I run failed
    /// to settle in 9 of 21 runs with the ship's tension weight perturbed by up to
    /// 10 %, at 10 in none (`docs/assumptions.md`).
    fn default() -> Self {
        AdmmSettings {
            rho: 10.0,
            max_iterations: 30,
            eps_abs: 1e-3,
            eps_rel: 1e-3,
            parallel_tugs: true,
        }
    }
}

impl AdmmSettings {
    /// Checks the values (see the fields).
    pub fn validate(&self) -> Result<(), ParamError> {
        let bad = |field: &str, reason: String| ParamError {
            field: field.to_owned(),
            reason,
        };
        if !(self.rho.is_finite() && self.rho >= 0.0) {
            return Err(bad(
                "rho",
                format!("must be finite and >= 0, got {}", self.rho),
            ));
        }
        if self.max_iterations == 0 || self.max_iterations > MAX_ITERATIONS {
            return Err(bad(
                "max_iterations",
                format!(
                    "must be in 1..={MAX_ITERATIONS}, got {}",
                    self.max_iterations
                ),
            ));
        }
        if !(self.eps_abs.is_finite() && self.eps_abs > 0.0) {
            return Err(bad(
                "eps_abs",
                format!("must be finite and > 0, got {}", self.eps_abs),
            ));
        }
        if !(self.eps_rel.is_finite() && self.eps_rel >= 0.0) {
            return Err(bad(
                "eps_rel",
                format!("must be finite and >= 0, got {}", self.eps_rel),
            ));
        }
        Ok(())
    }
}

/// Why an [`Admm`] could not be built.
#[derive(Debug, Clone, PartialEq)]
pub enum AdmmBuildError {
    /// Bad settings or model parameters.
    Param(ParamError),
    /// A subproblem's QP could not be built.
    Qp(QpBuildError),
}

impl fmt::Display for AdmmBuildError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            AdmmBuildError::Param(e) => write!(f, "{}: {}", e.field, e.reason),
            AdmmBuildError::Qp(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for AdmmBuildError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            AdmmBuildError::Param(e) => Some(e),
            AdmmBuildError::Qp(e) => Some(e),
        }
    }
}

impl From<ParamError> for AdmmBuildError {
    fn from(e: ParamError) -> Self {
        AdmmBuildError::Param(e)
    }
}

impl From<QpBuildError> for AdmmBuildError {
    fn from(e: QpBuildError) -> Self {
        AdmmBuildError::Qp(e)
    }
}

/// The command applied in the previous sample.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct AppliedCommand {
    /// `[F_1, F_2, alpha_1, alpha_2]`: the rate bounds (20)-(21) of the first sample.
    pub ship: ShipInput,
    /// `tau_T1, tau_T2`: the tugs have no rate bound (eq. (19) only); used as the
    /// cold-start plan.
    pub tugs: [TugInput; 2],
}

/// The data of one control sample.
#[derive(Debug, Clone, Copy)]
pub struct SampleInput<'a> {
    /// The ship's current state (heading as the plant gives it).
    pub ship: ShipState,
    /// The tugs' current states (0 = tug 1 aft, 1 = tug 2 forward).
    pub tugs: [TugState; 2],
    /// The command applied in the previous sample.
    pub previous: AppliedCommand,
    /// `eta_Sd` per sample (for the state after sample `h`), from guidance.
    pub reference: [[f64; 3]; HORIZON],
    /// Static obstacles.
    pub obstacles: &'a [Obstacle],
    /// Obstacles left out of the distance cost `phi` (bit `j` for `obstacles[j]`);
    /// their clearance rows stay. The controller sets it for the targets the tow
    /// stands on (COLREGS Rule 17(a)(i): keep course and speed) until Rule 17 allows
    /// action: pushed off by `phi`, the tow turned away from a vessel overtaking it.
    pub distance_cost_off: u64,
    /// The lowest heading the ship may take over the horizon (rad): COLREGS,
    /// no turn to port while giving way or standing on
    /// ([`crate::ShipMpcParams::port_turn_weight`]); `None`: no such limit.
    pub heading_floor: Option<f64>,
    /// The largest surge speed (m/s) the ship's plan may take over the horizon, below
    /// [`crate::MotionLimits::max_speed`] (the way off while giving way:
    /// [`crate::MotionLimits::capped`]); `None`: the motion limits' own.
    pub max_surge: Option<f64>,
    /// The waterway every vessel of the tow keeps inside ([`Waterway`]); `None`: open
    /// water.
    pub waterway: Option<Waterway<'a>>,
}

/// Residuals and tolerances of one iteration (per tug).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct IterationRecord {
    /// `|g_i - f_i|_2`.
    pub r_pri: [f64; 2],
    /// `|f_i^s - f_i^{s-1}|_2` (eq. (28) as printed, module docs).
    pub r_dual: [f64; 2],
    /// `eps_pri,i` of eq. (29).
    pub eps_pri: [f64; 2],
    /// `eps_dual,i` of eq. (29).
    pub eps_dual: [f64; 2],
}

impl IterationRecord {
    /// Whether (28) holds for both tugs.
    #[must_use]
    pub fn satisfied(&self) -> bool {
        (0..2).all(|i| self.r_pri[i] <= self.eps_pri[i] && self.r_dual[i] <= self.eps_dual[i])
    }
}

/// What one sample's loop did.
#[derive(Debug, Clone, Copy)]
pub struct AdmmReport {
    /// Iterations run (1..=`max_iterations`).
    pub iterations: usize,
    /// Whether the stopping rule (28)-(29) ended the loop.
    pub converged: bool,
    /// Whether the time budget ended the loop.
    pub budget_hit: bool,
    /// Final primal residuals.
    pub r_pri: [f64; 2],
    /// Final dual residuals.
    pub r_dual: [f64; 2],
    /// Final primal tolerances.
    pub eps_pri: [f64; 2],
    /// Final dual tolerances.
    pub eps_dual: [f64; 2],
    /// Per iteration (the first `iterations` entries are set).
    pub history: [IterationRecord; MAX_ITERATIONS],
    /// The last SCP step of tug 1, tug 2 and the ship.
    pub last_steps: [ScpReport; 3],
    /// Subproblem steps over the loop whose QP gave no usable solution (the
    /// plan was kept).
    pub failed_steps: usize,
    /// First move: tensions `F_1, F_2` (N).
    pub tension: [f64; 2],
    /// First move: towing angles `alpha_1, alpha_2` (rad).
    pub angle: [f64; 2],
    /// First move: thrust of tug 1 and tug 2.
    pub tug_thrust: [TugInput; 2],
}

impl AdmmReport {
    /// The records of the iterations run.
    #[must_use]
    pub fn history(&self) -> &[IterationRecord] {
        &self.history[..self.iterations]
    }

    /// Whether the last step of any subproblem had no usable QP solution.
    #[must_use]
    pub fn last_step_failed(&self) -> bool {
        self.last_steps.iter().any(|r| !r.qp.is_usable())
    }
}

/// What an [`Admm`] carries from one control sample to the next (its warm start): the
/// three subproblems' [`ScpState`]s and the multipliers. `f_prev` is not in it: each
/// sample sets it anew before reading it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AdmmState {
    /// The coordination problem's plan and trust radius.
    pub ship: ScpState,
    /// Tug 1's and tug 2's.
    pub tugs: [ScpState; 2],
    /// The multipliers `lambda_i`.
    pub lambda: [[[f64; 3]; HORIZON]; 2],
    /// Whether the next sample starts from the plans (else cold).
    pub warm: bool,
}

/// The distributed MPC for one control sample (module docs).
#[derive(Debug)]
pub struct Admm {
    settings: AdmmSettings,
    ship: ShipMpc,
    tug1: TugMpc,
    /// Tug 2's problem, on a helper thread with [`AdmmSettings::parallel_tugs`].
    tug2: Tug2,
    formation: FormationMap,
    lambda: [[[f64; 3]; HORIZON]; 2],
    f_prev: [[[f64; 3]; HORIZON]; 2],
    warm: bool,
}

impl Admm {
    /// The loop over the given subproblems (`tugs[i]` must model the tug on line
    /// `i`); the map is taken from the ship problem.
    pub fn new(
        ship: ShipMpc,
        tugs: [TugMpc; 2],
        settings: AdmmSettings,
    ) -> Result<Admm, ParamError> {
        settings.validate()?;
        for (i, tug) in tugs.iter().enumerate() {
            if tug.problem().model().line() != i {
                return Err(ParamError {
                    field: format!("tugs[{i}]"),
                    reason: format!("models the tug on line {}", tug.problem().model().line()),
                });
            }
        }
        let formation = *ship.problem().formation();
        let [tug1, tug2] = tugs;
        Ok(Admm {
            settings,
            ship,
            tug1,
            tug2: Tug2::new(tug2, settings.parallel_tugs),
            formation,
            lambda: [[[0.0; 3]; HORIZON]; 2],
            f_prev: [[[0.0; 3]; HORIZON]; 2],
            warm: false,
        })
    }

    /// The loop for a scenario's vessels with the default subproblem parameters.
    pub fn from_scenario(
        scenario: &Scenario,
        hull: HullModel,
        params: PredictionParams,
        settings: AdmmSettings,
    ) -> Result<Admm, AdmmBuildError> {
        Admm::from_scenario_with(
            scenario,
            hull,
            params,
            ShipMpcParams::default(),
            TugMpcParams::default(),
            settings,
        )
    }

    /// The loop for a scenario's vessels with the given subproblem parameters
    /// (both tugs with `tug_params`).
    pub fn from_scenario_with(
        scenario: &Scenario,
        hull: HullModel,
        params: PredictionParams,
        ship_params: ShipMpcParams,
        tug_params: TugMpcParams,
        settings: AdmmSettings,
    ) -> Result<Admm, AdmmBuildError> {
        let ship = ShipMpc::new(
            ShipModel::from_scenario(scenario, hull, params)?,
            FormationMap::from_scenario(scenario)?,
            ship_params,
        )?;
        let tug = |i| -> Result<TugMpc, AdmmBuildError> {
            Ok(TugMpc::new(
                TugModel::from_scenario(scenario, i, hull, params)?,
                tug_params,
            )?)
        };
        Ok(Admm::new(ship, [tug(0)?, tug(1)?], settings)?)
    }

    /// The settings.
    #[must_use]
    pub fn settings(&self) -> &AdmmSettings {
        &self.settings
    }

    /// The coordination problem (plan, predicted states).
    #[must_use]
    pub fn ship(&self) -> &ShipMpc {
        &self.ship
    }

    /// Tug `i`'s local problem (tug 2's behind the helper thread's lock while
    /// the borrow lasts).
    ///
    /// # Panics
    /// If `i > 1`.
    #[must_use]
    pub fn tug(&self, i: usize) -> TugRef<'_> {
        match i {
            0 => TugRef::Here(&self.tug1),
            1 => self.tug2.get(),
            _ => panic!("tug index {i} out of range (0 = tug 1, 1 = tug 2)"),
        }
    }

    /// The multipliers `lambda_i` (per sample, `[x, y, psi]`).
    #[must_use]
    pub fn lambda(&self) -> &[[[f64; 3]; HORIZON]; 2] {
        &self.lambda
    }

    /// The state to carry over ([`AdmmState`]).
    #[must_use]
    pub fn snapshot(&self) -> AdmmState {
        let warm = self.warm;
        AdmmState {
            ship: self.ship.snapshot(warm),
            tugs: [self.tug1.snapshot(warm), self.tug2.get().snapshot(warm)],
            lambda: self.lambda,
            warm,
        }
    }

    /// Goes on from `state` (a [`snapshot`](Self::snapshot) of a loop over the same
    /// problems).
    ///
    /// # Errors
    /// A subproblem's state that does not fit, named (nothing changes then).
    pub fn restore(&mut self, state: &AdmmState) -> Result<(), String> {
        fn name(what: &'static str) -> impl Fn(String) -> String {
            move |e| format!("{what}: {e}")
        }
        self.ship.fits(&state.ship).map_err(name("ship problem"))?;
        self.tug1
            .fits(&state.tugs[0])
            .map_err(name("tug 1 problem"))?;
        let mut tug2 = self.tug2.get_mut();
        tug2.fits(&state.tugs[1]).map_err(name("tug 2 problem"))?;
        tug2.restore(&state.tugs[1])?;
        drop(tug2);
        self.ship.restore(&state.ship)?;
        self.tug1.restore(&state.tugs[0])?;
        self.lambda = state.lambda;
        self.warm = state.warm;
        Ok(())
    }

    /// Next sample starts cold (module docs); trust regions back to their start.
    pub fn reset(&mut self) {
        self.lambda = [[[0.0; 3]; HORIZON]; 2];
        self.warm = false;
        self.ship.trust_region_mut().reset();
        self.tug1.trust_region_mut().reset();
        self.tug2.get_mut().trust_region_mut().reset();
    }

    /// Warm start for the next sample: plans and multipliers one sample ahead,
    /// the last sample repeated.
    pub fn shift(&mut self) {
        fn shifted<T: Copy>(a: &[T; HORIZON]) -> [T; HORIZON] {
            std::array::from_fn(|h| a[(h + 1).min(HORIZON - 1)])
        }
        self.ship.shift();
        self.tug1.shift();
        self.tug2.get_mut().shift();
        for i in 0..2 {
            self.lambda[i] = shifted(&self.lambda[i]);
            self.f_prev[i] = shifted(&self.f_prev[i]);
        }
        self.warm = true;
    }

    /// Algorithm 1 for one sample (module docs). Failed subproblem solves are
    /// counted in the report; the loop goes on with the kept plan.
    pub fn solve_sample(&mut self, input: &SampleInput<'_>) -> AdmmReport {
        self.solve_within(input, Budget::unlimited())
    }

    /// [`Admm::solve_sample`] stopping once `budget` is spent (after at least one
    /// iteration): the last iterate is applied, as at `max_iterations`.
    pub fn solve_within(&mut self, input: &SampleInput<'_>, budget: Budget) -> AdmmReport {
        if !self.warm {
            self.ship.set_inputs([input.previous.ship; HORIZON]);
            self.tug1.set_inputs([input.previous.tugs[0]; HORIZON]);
            self.tug2
                .get_mut()
                .set_inputs([input.previous.tugs[1]; HORIZON]);
            self.lambda = [[[0.0; 3]; HORIZON]; 2];
        }
        let saved = self.lambda;
        let report = Core {
            settings: self.settings,
            ship: &mut self.ship,
            tug1: &mut self.tug1,
            tug2: &mut self.tug2,
            formation: &self.formation,
            lambda: &mut self.lambda,
            f_prev: &mut self.f_prev,
        }
        .run(input, budget);
        // A sample that the iteration cap ends without consensus leaves the multipliers
        // as it found them (module docs, "Warm start").
        if !report.converged && !report.budget_hit {
            self.lambda = saved;
        }
        report
    }
}

/// One sample's loop over the borrowed parts of an [`Admm`].
struct Core<'a> {
    settings: AdmmSettings,
    ship: &'a mut ShipMpc,
    tug1: &'a mut TugMpc,
    tug2: &'a mut Tug2,
    formation: &'a FormationMap,
    lambda: &'a mut [[[f64; 3]; HORIZON]; 2],
    f_prev: &'a mut [[[f64; 3]; HORIZON]; 2],
}

/// The ship's plan and predicted states, and the tug references along them.
struct ShipSide {
    plan: [ShipInput; HORIZON],
    states: [ShipState; HORIZON],
    f: [[[f64; 3]; HORIZON]; 2],
}

impl Core<'_> {
    /// Algorithm 1 for one sample (module docs).
    fn run(&mut self, input: &SampleInput<'_>, budget: Budget) -> AdmmReport {
        // Tug headings unwrapped next to the ship's.
        let mut tug_states = input.tugs;
        for x in &mut tug_states {
            x[2] = input.ship[2] + angle_difference(x[2], input.ship[2]);
        }
        // f^0: the references along the current ship plan.
        let plan = self.ship.inputs();
        let states = self
            .ship
            .problem()
            .model()
            .rollout::<HORIZON>(&input.ship, &plan);
        let mut side = self.ship_side(plan, states);
        *self.f_prev = side.f;
        // The trust regions reopened, as the centralized problem's: kept at the
        // 1e-4 a hard sample had shrunk it to, the ship's plan hardly moved for the
        // first ten iterations of every later sample while the tugs' plans and the
        // multipliers ran away from it (a random encounter: r_pri up to 7 m, tug 2
        // driven into the ship). The tugs' too: with the ship's alone, 22 instead
        // of 26 of the first 100 random encounters passed.
        self.ship.trust_region_mut().reopen();
        self.tug1.trust_region_mut().reopen();
        self.tug2.get_mut().trust_region_mut().reopen();
        let mut history = [IterationRecord::default(); MAX_ITERATIONS];
        let mut last_steps = [ScpReport::never_run(); 3];
        let (mut failed_steps, mut iterations) = (0, 0);
        let (mut converged, mut budget_hit) = (false, false);
        while iterations < self.settings.max_iterations {
            if iterations > 0 && budget.spent() {
                budget_hit = true;
                break;
            }
            // (1) tug steps given f^{s-1}, the pulls of the ship plan, lambda^{s-1}.
            let (steps, g) = self.tug_steps(input, &tug_states, &side);
            // (2) ship step given g^s and lambda^{s-1}.
            let ship = self.ship.step(&ShipStepData {
                state: input.ship,
                previous: input.previous.ship,
                reference: input.reference,
                tug_poses: g,
                lambda: *self.lambda,
                rho: self.settings.rho,
                obstacles: input.obstacles,
                distance_cost_off: input.distance_cost_off,
                heading_floor: input.heading_floor,
                max_surge: input.max_surge,
                waterway: input.waterway,
            });
            last_steps = [steps[0], steps[1], ship];
            failed_steps += last_steps.iter().filter(|r| !r.qp.is_usable()).count();
            side = self.ship_side(self.ship.inputs(), *self.ship.predicted());
            // (3) multipliers, (4) residuals and tolerances.
            let record = self.update_multipliers(&g, &side.f);
            *self.f_prev = side.f;
            history[iterations] = record;
            iterations += 1;
            if record.satisfied() {
                converged = true;
                break;
            }
        }
        let last = history[iterations - 1];
        let first = side.plan[0];
        AdmmReport {
            iterations,
            converged,
            budget_hit,
            r_pri: last.r_pri,
            r_dual: last.r_dual,
            eps_pri: last.eps_pri,
            eps_dual: last.eps_dual,
            history,
            last_steps,
            failed_steps,
            tension: [first[0], first[1]],
            angle: [first[2], first[3]],
            tug_thrust: [self.tug1.inputs()[0], self.tug2.get().inputs()[0]],
        }
    }

    /// The ship side of an iteration: its plan, states and the references `f_i`.
    fn ship_side(&self, plan: [ShipInput; HORIZON], states: [ShipState; HORIZON]) -> ShipSide {
        let mut f = [[[0.0; 3]; HORIZON]; 2];
        for (i, fi) in f.iter_mut().enumerate() {
            self.formation.tug_references_into(i, &states, &plan, fi);
        }
        ShipSide { plan, states, f }
    }

    /// Both tugs' steps of one iteration (tug 2's possibly in parallel): their
    /// reports and predicted poses `g_i`.
    fn tug_steps(
        &mut self,
        input: &SampleInput<'_>,
        tug_states: &[TugState; 2],
        side: &ShipSide,
    ) -> ([ScpReport; 2], [Poses; 2]) {
        let own_ship = self.formation.ship_obstacle(&input.ship, &side.states);
        let sample_time = self.tug1.problem().model().params().sample_time;
        let tug = |i: usize| (self.formation).tug_obstacle(i, &tug_states[i], sample_time);
        let tugs = [tug(0), tug(1)];
        let data = |i: usize| TugStepData {
            state: tug_states[i],
            pulls: std::array::from_fn(|h| {
                let psi = if h == 0 {
                    input.ship[2]
                } else {
                    side.states[h - 1][2]
                };
                TowlinePull::from_plan(side.plan[h][i], psi, side.plan[h][2 + i])
            }),
            reference: side.f[i],
            lambda: self.lambda[i],
            rho: self.settings.rho,
            obstacles: input.obstacles,
            distance_cost_off: input.distance_cost_off,
            waterway: input.waterway,
            own_ship: Some(own_ship),
            other_tug: Some(tugs[1 - i]),
        };
        self.tug2.start(&data(1));
        let first = self.tug1.step(&data(0));
        let g1 = poses(self.tug1);
        let (second, g2) = self.tug2.finish();
        ([first, second], [g1, g2])
    }

    /// `lambda_i += rho (g_i - f_i)` (27) and the residuals and tolerances of
    /// (28)-(29).
    fn update_multipliers(&mut self, g: &[Poses; 2], f: &[Poses; 2]) -> IterationRecord {
        let s = self.settings;
        let mut record = IterationRecord::default();
        for i in 0..2 {
            let (mut pri, mut dual, mut gn, mut fn_, mut ln) = (0.0, 0.0, 0.0, 0.0, 0.0);
            for h in 0..HORIZON {
                let r = difference(&g[i][h], &f[i][h]);
                let d = difference(&f[i][h], &self.f_prev[i][h]);
                for c in 0..3 {
                    self.lambda[i][h][c] += s.rho * r[c];
                    pri += r[c] * r[c];
                    dual += d[c] * d[c];
                    gn += g[i][h][c] * g[i][h][c];
                    fn_ += f[i][h][c] * f[i][h][c];
                    ln += self.lambda[i][h][c] * self.lambda[i][h][c];
                }
            }
            let base = (N_S as f64).sqrt() * s.eps_abs;
            record.r_pri[i] = pri.sqrt();
            record.r_dual[i] = dual.sqrt();
            record.eps_pri[i] = base + s.eps_rel * gn.sqrt().max(fn_.sqrt());
            record.eps_dual[i] = base + s.eps_rel * ln.sqrt();
        }
        record
    }
}

/// `a - b`, the heading wrapped.
fn difference(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], angle_difference(a[2], b[2])]
}

#[cfg(test)]
pub(crate) mod tests;
