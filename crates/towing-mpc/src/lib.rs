//! Prediction models of the distributed MPC of Du, Negenborn, Reppa (2022),
//! "COLREGS-compliant collision avoidance for physically coupled multi-vessel
//! systems with distributed MPC", Ocean Engineering 260, 111917 (CC BY 4.0),
//! sections 3.2-3.3, their exact linearisations for sequential convex
//! programming, the optimisation engine ([`engine`]: one SCP step for any
//! [`Subproblem`] on one working memory, [`Scp`]) with its three subproblems (the
//! tug local problem (25), [`TugProblem`]; the coordination problem (26),
//! [`ShipProblem`]; the centralized problem (12)), and the two optimizers on top
//! behind one trait ([`Optimizer`]): the ADMM of Algorithm 1 ([`Admm`]) and the
//! centralized SCP ([`Centralized`]). The FMU is elsewhere.
//!
//! - [`ShipModel`]: the coordination controller's model, eq. (15) in the
//!   consistent form of `paper/NOTES.md` (state `[x, y, psi, u, v, r]`, input
//!   `[F_1, F_2, alpha_1, alpha_2]`).
//! - [`TugModel`]: a tug local controller's model, eq. (16) (input `[X, Y, N]`,
//!   exogenous [`TowlinePull`]: tension and line bearing from the plan).
//! - [`FormationMap`]: the configuration map eq. (4)-(7), `f_i(tau_S)` of eq. (23)
//!   on a predicted ship trajectory.
//! - [`PredictionHull`]: the plant's hull kinetics plus `d nu_dot / d nu`
//!   (analytic for the built-in hulls, finite differences for user hulls; why in
//!   [`hull`]).
//! - [`PredictionParams`]: sample time and RK4 substep (zero-order hold).
//! - [`TugMpc`], [`ShipMpc`]: the engine over the ADMM subproblems (25) and (26)
//!   (condensed QP in the input increments, trust region, accept/reject on the
//!   true merit), the cost terms they share ([`costs`]), [`Obstacle`] and the
//!   distance cost [`DistanceCost`] (`phi`, made honest), [`Qp`]: the Clarabel
//!   wrapper with a fixed structure updated in place ([`QpOutcome`] as a value).
//!
//! Physics honesty (DESIGN.md): the models use the plant's own code for
//! everything the plant computes: the hull ([`towing_model::HullModel::build`] and
//! its `nu_dot`), the towline loads ([`towing_model::towline::line_loads`]), the
//! formation ([`towing_model::towline::formation_pose`]) and the RK4 arithmetic of
//! `World::step`. With the same hull model a one-sample prediction agrees with the
//! plant up to the one modelling choice of the MPC: the towing angles (ship model)
//! and line bearings (tug model) are held over the sample, while the plant's
//! follow the moving geometry (`tests/plant_agreement.rs` measures and bounds it).
//!
//! Linearisation: the RK4 recursion itself is differentiated in forward mode.
//! With `S_x = dx / dx_0` (6x6) and `S_p = dx / dp` (inputs held), every stage
//! gives `dk = A(x_t) S_t (+ B(x_t))`, with `A = df/dx`, `B = df/dp` the analytic
//! partials of the continuous dynamics at the stage point and `S_t` the stage
//! point's sensitivity (`S + c h dk_prev`), and
//! `S += h / 6 (dk_1 + 2 dk_2 + 2 dk_3 + dk_4)`. The Jacobians are therefore those
//! of the discrete map the model evaluates (to rounding), not of the ODE, and
//! `x_next` of a linearised step is bit-identical to the plain step.
//!
//! Allocation: nothing in a step, rollout or linearisation allocates. States and
//! inputs are fixed-size arrays, matrices `nalgebra` static (stack) matrices,
//! rollouts write into fixed-size arrays (`const H`) or caller buffers; the only
//! heap object, the boxed hull, is made once at construction. (This is by
//! construction; a counting global allocator would need `unsafe`, which the
//! workspace keeps in `fmi2-slave`.)
//!
//! ```
//! use towing_model::{HullModel, Scenario};
//! use towing_mpc::{FormationMap, PredictionParams, ShipModel, TowlinePull, TugModel};
//!
//! let scenario = Scenario::paper()?;
//! let params = PredictionParams::default(); // T_s = 1 s, RK4 substeps of 0.1 s
//! let ship = ShipModel::from_scenario(&scenario, HullModel::NonlinearDamping, params)?;
//! let tug2 = TugModel::from_scenario(&scenario, 1, HullModel::NonlinearDamping, params)?;
//! let formation = FormationMap::from_scenario(&scenario)?;
//!
//! let s = scenario.ship;
//! let x0 = [s.eta[0], s.eta[1], s.eta[2], s.nu[0], s.nu[1], s.nu[2]];
//! // H_P = 3 samples: F_1 = 0.5 N, F_2 = 2 N, both lines straight behind / ahead.
//! let u = [[0.5, 2.0, 0.0, 0.0]; 3];
//! let ship_path = ship.rollout(&x0, &u);
//! assert!(ship_path[2][3] > 0.0); // moving ahead
//!
//! // The tug's desired poses along the prediction (eq. (23)) ...
//! let mut refs = [[0.0; 3]; 3];
//! formation.tug_references_into(1, &ship_path, &u, &mut refs);
//! // ... and the tug's own prediction under the planned pull (eq. (24)).
//! let t = scenario.tugs[1];
//! let pull = TowlinePull::from_plan(2.0, x0[2], 0.0);
//! let tug_path = tug2.rollout(&[t.eta[0], t.eta[1], t.eta[2], 0.0, 0.0, 0.0], &[[3.0, 0.0, 0.0]; 3], &[pull; 3]);
//! let lin = ship.step_linearised(&x0, &u[0]); // x_next, A (6x6), B (6x4)
//! assert_eq!(lin.x_next, ship.step(&x0, &u[0]));
//! # let _ = (refs, tug_path);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![forbid(unsafe_code)]
// Tests may unwrap: a panic is the failure report.
#![cfg_attr(test, allow(clippy::unwrap_used))]

pub mod admm;
pub mod centralized;
pub mod costs;
pub mod engine;
pub mod formation;
pub mod hull;
pub mod lines;
pub mod obstacle;
pub mod optimizer;
pub mod params;
pub mod qp;
mod rk4;
pub mod ship;
pub mod ship_mpc;
pub mod tug;
pub mod tug_mpc;

/// Prediction horizon `H_P` in samples (Du et al. 2022, Table 3): the QPs'
/// structure is built for it.
pub const HORIZON: usize = 3;

pub(crate) use engine::condense;

pub use admm::{
    Admm, AdmmBuildError, AdmmReport, AdmmSettings, AdmmState, AppliedCommand, IterationRecord,
    SampleInput,
};
pub use centralized::{
    Centralized, CentralizedReport, CentralizedSettings, CentralizedState, CostBreakdown,
};
pub use costs::{angle_difference, ClearanceParams, MotionLimits, Waterway};
pub use engine::{Budget, Merit, Scp, ScpReport, ScpSettings, ScpState, Subproblem, TrustRegion};
pub use formation::FormationMap;
pub use hull::{JacobianMethod, PredictionHull};
pub use lines::line_direction;
pub use obstacle::{DistanceCost, Obstacle};
pub use optimizer::{MpcReport, Optimizer, OptimizerState};
pub use params::PredictionParams;
pub use qp::{Qp, QpFailure, QpOutcome};
pub use ship::{ShipInput, ShipLinearisation, ShipModel, ShipState};
pub use ship_mpc::{ShipMpc, ShipMpcParams, ShipProblem, ShipStepData, TerminalCost};
pub use tug::{TowlinePull, TugInput, TugLinearisation, TugModel, TugState};
pub use tug_mpc::{TugMpc, TugMpcParams, TugProblem, TugStepData};

#[cfg(test)]
mod tests;
