//! The optimisation engine: one sequential convex programming (SCP) step for any
//! subproblem, on one working memory (OpEn's cache / engine / optimizer split:
//! Sopasakis, Fresk, Patrinos 2020; Clarabel's one algorithm with pluggable
//! parts).
//!
//! - A [`Subproblem`] (the tug problem (25), the coordination problem (26), the
//!   centralized problem (12)) says what it optimises: its input channels
//!   ([`InputSpace`]: bounds, rate bounds, trust scales), its prediction (rollout
//!   and exact linearisation), its cost terms ([`QuadModel`], fed by
//!   [`crate::costs`]) and its soft constraints ([`RowSet`]).
//! - [`Scp`] holds the working memory (plan, candidate, trajectories,
//!   linearisation, quadratic model, trust region, the QPs) and takes one step:
//!
//!   1. project the plan onto the bounds and rate bounds;
//!   2. linearise the rollout around it (reused when neither the plan nor the
//!      data it depends on changed, i.e. after a rejected step);
//!   3. build the quadratic model of the merit and record the soft rows;
//!   4. box each increment (bounds, trust region, first-sample rate band), drop
//!      the soft rows the boxes imply and pick the smallest QP layout that holds
//!      the rest; write the model, boxes, rate rows and soft rows;
//!   5. solve (Clarabel); on failure shrink the trust region and keep the plan;
//!   6. project the candidate, roll it out, evaluate the true merit and judge
//!      the step on the ratio of actual to predicted decrease ([`TrustRegion`]).
//!
//! - The optimizers sit on top: [`crate::Admm`] (Algorithm 1: one step of each
//!   subproblem per iteration, then the multipliers) and [`crate::Centralized`]
//!   (steps until the first move settles), both with an optional time budget
//!   ([`Budget`]).
//!
//! Allocation: everything is allocated in [`Scp::new`]; a step writes into the
//! buffers and into Clarabel's preallocated data (`update_P/q/A/b`, then `solve`).

mod layout;
mod quad;
mod rows;
mod space;
mod trust;

use std::fmt::Debug;

use serde::{Deserialize, Serialize};
use std::time::{Duration, Instant};

pub use quad::QuadModel;
pub use rows::{Block, BlockMut, PairRows, RowSet, SlotRows};
pub use space::{Channel, InputSpace, ALL_VESSELS};
pub use trust::{ScpSettings, TrustRegion};

pub(crate) use layout::Layouts;

use nalgebra::{Matrix6, SMatrix};

use crate::qp::{QpBuildError, QpFailure, QpOutcome};

/// Condensing (state elimination) of a linearised horizon: with
/// `x_{h+1} = A_h x_h + B_h u_h`, the sensitivity of the predicted state `h` to
/// input `k` is `S[h][k] = B_h` for `k = h` and `A_h S[h-1][k]` for `k < h` (zero
/// for `k > h`); `a[h]`, `b[h]` are the Jacobians of step `h` of the discretised
/// model (Maciejowski 2002, Predictive Control with Constraints, section 3.1).
pub(crate) fn condense<const M: usize, const H: usize>(
    a: [&Matrix6<f64>; H],
    b: [&SMatrix<f64, 6, M>; H],
    sens: &mut [[SMatrix<f64, 6, M>; H]; H],
) {
    for h in 0..H {
        let (before, rest) = sens.split_at_mut(h);
        let row = &mut rest[0];
        row[h] = *b[h];
        if let Some(previous) = before.last() {
            for (s, p) in row[..h].iter_mut().zip(&previous[..h]) {
                *s = a[h] * p;
            }
        }
    }
}

/// What one SCP step did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScpReport {
    /// How the QP ended.
    pub qp: QpOutcome,
    /// Whether the plan was replaced by the candidate.
    pub accepted: bool,
    /// True merit of the plan before the step.
    pub cost_before: f64,
    /// True merit of the plan after the step (= `cost_before` if rejected).
    pub cost_after: f64,
    /// Decrease predicted by the quadratic model (0 if the QP failed).
    pub predicted_decrease: f64,
    /// Actual over predicted decrease (NaN if the QP failed; 1 if nothing was
    /// predicted: converged).
    pub ratio: f64,
    /// Trust radius after the update.
    pub radius: f64,
    /// Interior-point iterations.
    pub qp_iterations: u32,
    /// Largest change of a first-sample channel (0 unless accepted).
    pub first_move_change: f64,
}

impl ScpReport {
    /// The report of a step whose QP gave no usable solution (`outcome`): the
    /// plan is kept.
    pub(crate) fn rejected(
        outcome: QpOutcome,
        cost_before: f64,
        radius: f64,
        qp_iterations: u32,
    ) -> ScpReport {
        ScpReport {
            qp: outcome,
            accepted: false,
            cost_before,
            cost_after: cost_before,
            predicted_decrease: 0.0,
            ratio: f64::NAN,
            radius,
            qp_iterations,
            first_move_change: 0.0,
        }
    }

    /// A step that never ran (a report slot before the first step).
    pub(crate) fn never_run() -> ScpReport {
        ScpReport::rejected(QpOutcome::Failed(QpFailure::Other), f64::NAN, 0.0, 0)
    }
}

/// A time budget for one control sample: the optimizers stop iterating once it
/// is spent and keep the best iterate that satisfies every bound (the plans are
/// projected onto the bounds before and after every step, so every iterate
/// does). `None`: no limit, and a run is deterministic.
#[derive(Debug, Clone, Copy)]
pub struct Budget {
    deadline: Option<Instant>,
}

impl Budget {
    /// No limit.
    #[must_use]
    pub fn unlimited() -> Budget {
        Budget { deadline: None }
    }

    /// `limit` from `start` (`None`: no limit).
    #[must_use]
    pub fn from(start: Instant, limit: Option<Duration>) -> Budget {
        Budget {
            deadline: limit.map(|l| start + l),
        }
    }

    /// Whether the budget is spent (never without a limit; the clock is read only
    /// with one).
    #[must_use]
    pub fn spent(&self) -> bool {
        self.deadline.is_some_and(|d| Instant::now() >= d)
    }
}

/// A subproblem of the SCP (module docs).
pub trait Subproblem: Debug {
    /// The data of one step (state, references, multipliers, obstacles, ...).
    type Data<'a>;
    /// Predicted trajectories of a plan.
    type Trajectory: Copy + Debug;
    /// A linearised rollout: the nominal trajectory and its sensitivities to the
    /// increments.
    type Linearisation: Debug;
    /// What a linearisation depends on besides the plan.
    type Key: Copy + PartialEq + Debug;
    /// The soft constraint rows.
    type Rows: RowSet;
    /// The cost of a plan (its merit and whatever the subproblem reports of it).
    type Cost: Merit + Copy + Debug;

    /// The decision variables.
    fn space(&self) -> &InputSpace;
    /// Sets what the decision variables' bounds take from this step's data (before
    /// the step reads [`Subproblem::space`]); by default nothing does.
    fn prepare(&mut self, _data: &Self::Data<'_>) {}
    /// The soft rows, sized for the largest layout.
    fn rows(&self) -> Self::Rows;
    /// An empty trajectory and linearisation (buffers).
    fn buffers(&self) -> (Self::Trajectory, Self::Linearisation);
    /// The command the first sample's rate bounds are measured from, per channel.
    fn previous(&self, data: &Self::Data<'_>, out: &mut [f64]);
    /// The data a linearisation depends on.
    fn key(&self, data: &Self::Data<'_>) -> Self::Key;
    /// The nonlinear rollout of `plan`.
    fn rollout(&self, data: &Self::Data<'_>, plan: &[f64], out: &mut Self::Trajectory);
    /// The linearised rollout of `plan`.
    fn linearise(&self, data: &Self::Data<'_>, plan: &[f64], lin: &mut Self::Linearisation);
    /// The nominal trajectory of a linearisation.
    fn nominal(lin: &Self::Linearisation) -> &Self::Trajectory;
    /// The cost of `plan` along `traj`: its terms added to `quad` and, with
    /// `model`, their rows in the increments and the soft rows recorded.
    fn terms(
        &self,
        quad: &mut QuadModel,
        traj: &Self::Trajectory,
        plan: &[f64],
        model: Option<(&Self::Linearisation, &mut Self::Rows)>,
        data: &Self::Data<'_>,
    ) -> Self::Cost;
}

/// The merit of a cost: the true cost plus the soft rows' penalties, what the
/// SCP step minimises and judges its steps by.
pub trait Merit {
    /// The merit.
    fn merit(&self) -> f64;
}

impl Merit for f64 {
    fn merit(&self) -> f64 {
        *self
    }
}

/// What an [`Scp`] keeps from one control sample to the next that decides its later
/// steps: the plan (the warm start; `None` when the next sample starts cold and sets its
/// own) and the trust region's radius. Everything else (the QPs, the cached
/// linearisation, the buffers) is rebuilt or refilled by the next step from the same
/// data, with the same bits: a controller's FMU state holds this.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ScpState {
    /// The plan, flat ([`Scp::plan`]).
    pub plan: Option<Vec<f64>>,
    /// The trust region's radius.
    pub radius: f64,
}

/// The SCP's working memory over a subproblem, and its step (module docs).
#[derive(Debug)]
pub struct Scp<P: Subproblem> {
    problem: P,
    layouts: Layouts,
    rows: P::Rows,
    trust: TrustRegion,
    plan: Vec<f64>,
    candidate: Vec<f64>,
    previous: Vec<f64>,
    lo: Vec<f64>,
    hi: Vec<f64>,
    lin: P::Linearisation,
    /// The `(key, plan)` of `lin`: a step from the same point reuses it.
    lin_key: Option<P::Key>,
    lin_plan: Vec<f64>,
    traj: P::Trajectory,
    candidate_traj: P::Trajectory,
    quad: QuadModel,
}

impl<P: Subproblem> Scp<P> {
    /// The working memory and the QPs of `problem`; the plan at zero.
    ///
    /// # Errors
    /// A QP that cannot be built.
    pub fn with_problem(problem: P, settings: ScpSettings) -> Result<Scp<P>, QpBuildError> {
        let rows = problem.rows();
        let layouts = Layouts::new(problem.space(), &rows)?;
        let n = problem.space().len();
        let per_step = problem.space().per_step();
        let (traj, lin) = problem.buffers();
        Ok(Scp {
            layouts,
            rows,
            trust: TrustRegion::new(settings),
            plan: vec![0.0; n],
            candidate: vec![0.0; n],
            previous: vec![0.0; per_step],
            lo: vec![0.0; n],
            hi: vec![0.0; n],
            lin,
            lin_key: None,
            lin_plan: vec![0.0; n],
            traj,
            candidate_traj: traj,
            quad: QuadModel::new(n),
            problem,
        })
    }

    /// The subproblem.
    #[must_use]
    pub fn problem(&self) -> &P {
        &self.problem
    }

    /// The plan, flat (sample-major, [`InputSpace::index`]).
    #[must_use]
    pub fn plan(&self) -> &[f64] {
        &self.plan
    }

    /// Replaces the plan (warm start); it is projected at the next step.
    ///
    /// # Panics
    /// If the length differs from the space's.
    pub fn set_plan(&mut self, plan: &[f64]) {
        self.plan.copy_from_slice(plan);
    }

    /// The predicted trajectory of the plan as of the last step.
    #[must_use]
    pub fn predicted(&self) -> &P::Trajectory {
        &self.traj
    }

    /// The trust region.
    #[must_use]
    pub fn trust_region(&self) -> &TrustRegion {
        &self.trust
    }

    /// The trust region, to reset it (e.g. at a new sample).
    pub fn trust_region_mut(&mut self) -> &mut TrustRegion {
        &mut self.trust
    }

    /// Forgets the cached linearisation (the next step linearises anew).
    pub fn forget_linearisation(&mut self) {
        self.lin_key = None;
    }

    /// The state to carry over ([`ScpState`]); the plan only when `warm` (the next
    /// sample starts from it).
    #[must_use]
    pub fn snapshot(&self, warm: bool) -> ScpState {
        ScpState {
            plan: warm.then(|| self.plan.clone()),
            radius: self.trust.radius(),
        }
    }

    /// Whether [`restore`](Self::restore) takes `state`.
    ///
    /// # Errors
    /// A plan of another length, a radius outside the trust region's bounds.
    pub fn fits(&self, state: &ScpState) -> Result<(), String> {
        let s = self.trust.settings();
        if !(s.min_radius..=s.max_radius).contains(&state.radius) {
            return Err(format!(
                "trust radius {} is outside [{}, {}]",
                state.radius, s.min_radius, s.max_radius
            ));
        }
        if let Some(plan) = &state.plan {
            if plan.len() != self.plan.len() {
                return Err(format!(
                    "a plan of {} values, the problem has {}",
                    plan.len(),
                    self.plan.len()
                ));
            }
        }
        Ok(())
    }

    /// Goes on from `state` (a [`snapshot`](Self::snapshot), possibly of another
    /// instance of the same problem); the linearisation is made anew at the next step.
    ///
    /// # Errors
    /// As [`fits`](Self::fits) (nothing changes then).
    pub fn restore(&mut self, state: &ScpState) -> Result<(), String> {
        self.fits(state)?;
        if let Some(plan) = &state.plan {
            self.plan.copy_from_slice(plan);
        }
        self.trust.set_radius(state.radius);
        self.forget_linearisation();
        Ok(())
    }

    /// Moves the plan one sample ahead, the last sample repeated (warm start of
    /// the next control sample).
    pub fn shift(&mut self) {
        let per_step = self.problem.space().per_step();
        let n = self.plan.len();
        // Samples 1.. move to 0..; the last one stays where it was (repeated).
        self.plan.copy_within(per_step.min(n).., 0);
    }

    /// The true cost of `plan` for `data` (nonlinear rollout; the plan as it is,
    /// not projected).
    #[must_use]
    pub fn cost(&self, plan: &[f64], data: &P::Data<'_>) -> P::Cost {
        let mut traj = self.traj;
        self.problem.rollout(data, plan, &mut traj);
        let mut quad = QuadModel::new(0);
        quad.reset(true);
        self.problem.terms(&mut quad, &traj, plan, None, data)
    }

    /// The trajectory and cost of the current plan (the nonlinear rollout), e.g.
    /// after the last step of a sample.
    pub fn settle(&mut self, data: &P::Data<'_>) -> P::Cost {
        self.problem.rollout(data, &self.plan, &mut self.traj);
        self.quad.reset(true);
        self.problem
            .terms(&mut self.quad, &self.traj, &self.plan, None, data)
    }

    /// One SCP step (module docs). Allocation-free once its QP layout exists (a
    /// combination of soft rows met for the first time builds one).
    pub fn step(&mut self, data: &P::Data<'_>) -> ScpReport {
        self.problem.prepare(data);
        let space = self.problem.space();
        let n_u = space.len();
        self.problem.previous(data, &mut self.previous);
        space.project(&mut self.plan, &self.previous);
        let key = self.problem.key(data);
        if self.lin_key != Some(key) || self.lin_plan != self.plan {
            self.problem.linearise(data, &self.plan, &mut self.lin);
            self.lin_key = Some(key);
            self.lin_plan.copy_from_slice(&self.plan);
        }
        self.traj = *P::nominal(&self.lin);
        self.quad.reset(false);
        self.rows.clear();
        let cost_before = self
            .problem
            .terms(
                &mut self.quad,
                &self.traj,
                &self.plan,
                Some((&self.lin, &mut self.rows)),
                data,
            )
            .merit();
        space.boxes(
            &self.plan,
            &self.previous,
            self.trust.radius(),
            &mut self.lo,
            &mut self.hi,
        );
        let (outcome, iterations, predicted) = {
            let loaded = self.layouts.load(
                space,
                &mut self.rows,
                &self.quad,
                &self.plan,
                &self.lo,
                &self.hi,
            );
            let solved = match loaded {
                Ok(layout) => layout.solve(&self.rows, &self.quad, n_u),
                Err(_) => Err((QpOutcome::Failed(QpFailure::Other), 0)),
            };
            match solved {
                Ok(solved) => solved,
                Err((outcome, iterations)) => {
                    self.trust.fail();
                    return ScpReport::rejected(
                        outcome,
                        cost_before,
                        self.trust.radius(),
                        iterations,
                    );
                }
            }
        };
        let du = self.layouts.solution();
        for ((c, p), d) in self.candidate.iter_mut().zip(&self.plan).zip(du) {
            *c = p + d;
        }
        // Removes the solver's tolerance (about 1e-6) on the constraints.
        space.project(&mut self.candidate, &self.previous);
        self.problem
            .rollout(data, &self.candidate, &mut self.candidate_traj);
        self.quad.reset(true);
        let cost_candidate = self
            .problem
            .terms(
                &mut self.quad,
                &self.candidate_traj,
                &self.candidate,
                None,
                data,
            )
            .merit();
        let (accepted, ratio) = self.trust.judge(cost_before, cost_candidate, predicted);
        let mut first_move_change = 0.0;
        if accepted {
            first_move_change = space.first_move_change(&self.candidate, &self.plan);
            std::mem::swap(&mut self.plan, &mut self.candidate);
            self.traj = self.candidate_traj;
        }
        ScpReport {
            qp: outcome,
            accepted,
            cost_before,
            cost_after: if accepted {
                cost_candidate
            } else {
                cost_before
            },
            predicted_decrease: predicted,
            ratio,
            radius: self.trust.radius(),
            qp_iterations: iterations,
            first_move_change,
        }
    }
}
