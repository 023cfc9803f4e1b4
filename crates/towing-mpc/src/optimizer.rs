//! The MPC architectures behind one trait: the distributed MPC ([`Admm`],
//! Algorithm 1) and the centralized MPC ([`Centralized`], eq. (12)) each compute
//! one control sample's plans for the ship and both tugs. The controller holds a
//! `Box<dyn Optimizer>` and never asks which one it has.

use serde::{Deserialize, Serialize};

use crate::admm::{Admm, AdmmState, SampleInput};
use crate::centralized::{Centralized, CentralizedState};
use crate::engine::Budget;
use crate::qp::QpOutcome;
use crate::ship::{ShipInput, ShipModel, ShipState};
use crate::tug::{TugInput, TugState};
use crate::HORIZON;

/// What one control sample's optimisation did, whatever the architecture.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MpcReport {
    /// ADMM iterations, or the centralized problem's SCP steps.
    pub iterations: usize,
    /// Whether the stopping rule ended the loop (eq. (29); the centralized
    /// first-move rule).
    pub converged: bool,
    /// Whether the sample's time budget ended the loop.
    pub budget_hit: bool,
    /// The first subproblem (`tug 1`, `tug 2`, `ship`, `centralized`) whose last
    /// QP gave no usable solution, and how.
    pub failed: Option<(&'static str, QpOutcome)>,
    /// Last primal residual per tug (the centralized problem: the largest
    /// violation of the configuration restriction, for both).
    pub r_pri: [f64; 2],
    /// Last dual residual per tug (0 for the centralized problem).
    pub r_dual: [f64; 2],
}

/// What an optimizer carries from one control sample to the next: its warm start
/// (plans, multipliers, trust radii). The QPs and their factorisations, the cached
/// linearisations and every buffer are rebuilt from the configuration; the next sample
/// refills them with the same bits.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum OptimizerState {
    /// The distributed MPC's.
    Admm(Box<AdmmState>),
    /// The centralized MPC's.
    Centralized(CentralizedState),
}

/// An MPC architecture (module docs).
pub trait Optimizer: std::fmt::Debug + Send {
    /// Solves one control sample within `budget`.
    fn solve(&mut self, input: &SampleInput<'_>, budget: Budget) -> MpcReport;
    /// The ship's plan `[F_1, F_2, alpha_1, alpha_2]` per sample.
    fn ship_plan(&self) -> [ShipInput; HORIZON];
    /// Tug `i`'s thrust plan (`i` = 0, 1).
    fn tug_plan(&self, i: usize) -> [TugInput; HORIZON];
    /// The ship's predicted states of the plan.
    fn ship_predicted(&self) -> &[ShipState; HORIZON];
    /// Tug `i`'s predicted states of the plan.
    fn tug_predicted(&self, i: usize) -> [TugState; HORIZON];
    /// The ship's prediction model.
    fn ship_model(&self) -> &ShipModel;
    /// The next sample starts cold.
    fn reset(&mut self);
    /// Warm start of the next sample: everything one sample ahead.
    fn shift(&mut self);
    /// The state to carry over ([`OptimizerState`]).
    fn snapshot(&self) -> OptimizerState;
    /// Goes on from `state`, a snapshot of an optimizer of the same architecture and
    /// problem.
    ///
    /// # Errors
    /// Another architecture's state, or one that does not fit (nothing changes then).
    fn restore(&mut self, state: &OptimizerState) -> Result<(), String>;
}

fn wrong_architecture(state: &OptimizerState, expected: &str) -> String {
    let found = match state {
        OptimizerState::Admm(_) => "distributed (ADMM)",
        OptimizerState::Centralized(_) => "centralized",
    };
    format!("the state is of the {found} MPC, this controller's is {expected}")
}

impl Optimizer for Admm {
    fn solve(&mut self, input: &SampleInput<'_>, budget: Budget) -> MpcReport {
        let r = self.solve_within(input, budget);
        MpcReport {
            iterations: r.iterations,
            converged: r.converged,
            budget_hit: r.budget_hit,
            failed: ["tug 1", "tug 2", "ship"]
                .into_iter()
                .zip(r.last_steps)
                .find(|(_, s)| !s.qp.is_usable())
                .map(|(name, s)| (name, s.qp)),
            r_pri: r.r_pri,
            r_dual: r.r_dual,
        }
    }

    fn ship_plan(&self) -> [ShipInput; HORIZON] {
        self.ship().inputs()
    }

    fn tug_plan(&self, i: usize) -> [TugInput; HORIZON] {
        self.tug(i).inputs()
    }

    fn ship_predicted(&self) -> &[ShipState; HORIZON] {
        self.ship().predicted()
    }

    fn tug_predicted(&self, i: usize) -> [TugState; HORIZON] {
        *self.tug(i).predicted()
    }

    fn ship_model(&self) -> &ShipModel {
        self.ship().problem().model()
    }

    fn reset(&mut self) {
        Admm::reset(self);
    }

    fn shift(&mut self) {
        Admm::shift(self);
    }

    fn snapshot(&self) -> OptimizerState {
        OptimizerState::Admm(Box::new(Admm::snapshot(self)))
    }

    fn restore(&mut self, state: &OptimizerState) -> Result<(), String> {
        match state {
            OptimizerState::Admm(s) => Admm::restore(self, s),
            other => Err(wrong_architecture(other, "distributed (ADMM)")),
        }
    }
}

impl Optimizer for Centralized {
    fn solve(&mut self, input: &SampleInput<'_>, budget: Budget) -> MpcReport {
        let r = self.solve_within(input, budget);
        MpcReport {
            iterations: r.iterations,
            converged: r.converged,
            budget_hit: r.budget_hit,
            failed: r.failed.then_some(("centralized", r.last_step.qp)),
            // The consensus violation plays the primal residual's part.
            r_pri: [r.breakdown.consensus_max; 2],
            r_dual: [0.0; 2],
        }
    }

    fn ship_plan(&self) -> [ShipInput; HORIZON] {
        Centralized::ship_plan(self)
    }

    fn tug_plan(&self, i: usize) -> [TugInput; HORIZON] {
        Centralized::tug_plan(self, i)
    }

    fn ship_predicted(&self) -> &[ShipState; HORIZON] {
        Centralized::ship_predicted(self)
    }

    fn tug_predicted(&self, i: usize) -> [TugState; HORIZON] {
        *Centralized::tug_predicted(self, i)
    }

    fn ship_model(&self) -> &ShipModel {
        Centralized::ship_model(self)
    }

    fn reset(&mut self) {
        Centralized::reset(self);
    }

    fn shift(&mut self) {
        Centralized::shift(self);
    }

    fn snapshot(&self) -> OptimizerState {
        OptimizerState::Centralized(Centralized::snapshot(self))
    }

    fn restore(&mut self, state: &OptimizerState) -> Result<(), String> {
        match state {
            OptimizerState::Centralized(s) => Centralized::restore(self, s),
            other => Err(wrong_architecture(other, "centralized")),
        }
    }
}
