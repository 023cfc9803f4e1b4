//! A tug's local problem, eq. (25), as one sequential-convex-programming step
//! (`docs/controller-design.md`, "Tug local MPCs").
//!
//! Decision: the thrust plan `tau_Ti` over the horizon, `3 H = 9` increments
//! `du` (index `3 h + j`, `j` = X, Y, N). Given the tug's state, the towline pull per
//! sample from the coordination plan (tension, bearing), the reference poses `f_i`
//! (from [`crate::FormationMap`] along the coordination's predicted ship
//! trajectory), the multipliers `lambda_i` and `rho`, the step
//!
//! 1. linearises the rollout around the current plan (exact Jacobians of the
//!    discretised model) and condenses the states: `x_{h+1} ~ x_{h+1} + sum_{k <= h}
//!    S_{h,k} du_k`, `S_{h,h} = B_h`, `S_{h,k} = A_h S_{h-1,k}`;
//! 2. builds the convex quadratic model ([`crate::scp`]) of
//!
//!    ```text
//!    sum_h  w_1 |eta_{h+1} - f_h|^2 + w_2 |nu_{h+1}|^2 + w_3 sum_j phi(d_j(p_{h+1}))
//!         + lambda_h^T (eta_{h+1} - f_h) + rho/2 |eta_{h+1} - f_h|^2
//!    ```
//!
//!    (heading difference wrapped to `(-pi, pi]`; the state after sample `h` is
//!    compared with the reference of sample `h`, the layout of
//!    [`crate::FormationMap::tug_references_into`]);
//! 3. solves the QP with one box per variable: the thrust bounds `|tau| <= tau_max`
//!    (19) intersected with the trust region `|du_j| <= radius * scale_j`;
//! 4. accepts or rejects the candidate by the ratio of the true (nonlinear
//!    rollout) to the predicted cost decrease, and adapts the radius.
//!
//! 5. the hard clearance rows of the design document, linearised, with an L1-
//!    penalised slack per sample and obstacle slot ([`ClearanceParams`]): the QP
//!    variables are the 9 increments and `3 c` slacks, `c <= max_obstacles` the
//!    obstacle slots in use (one QP per `c`, built in [`TugMpc::new`]; rows the
//!    increments' boxes imply are left out).
//!
//! A step from the point of the last linearisation (same state, plan and pulls:
//! after a rejected step) reuses the linearised rollout.
//!
//! Allocation: everything is allocated in [`TugMpc::new`] (the QPs and their solvers,
//! the model buffers); the plan, rollouts, linearisations and sensitivities are
//! fixed-size arrays. [`TugMpc::solve_step`] only writes into them, and into
//! Clarabel's preallocated data (`update_P/q/A/b`, then `solve`).

// Index loops over (sample, channel) pairs: the indices also address the
// flat increment vector (`3 h + c`, `4 h + k`), clearer than zipped iterators.
#![allow(clippy::needless_range_loop)]

use nalgebra::Matrix6x3;

use crate::obstacle::{DistanceCost, Obstacle};
use crate::qp::QpBuildError;
use crate::scp::{
    angle_difference, box_qp, condense, load_layout, obstacle_terms, solve_layout, Clearance,
    ClearanceParams, QuadModel, ScpReport, ScpSettings, TrustRegion,
};
use crate::tug::{TowlinePull, TugInput, TugLinearisation, TugModel, TugState};
use crate::Qp;

/// Prediction horizon `H_P` (Table 3).
pub const HORIZON: usize = 3;
const N: usize = 3 * HORIZON;

/// Parameters of a tug's local problem.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TugMpcParams {
    /// `w_i = (w_1, w_2, w_3)`: pose error, velocity, distance cost (Table 3: 1, 6, 1).
    pub weights: [f64; 3],
    /// `|X|, |Y|, |N|` limits (N, N, N m), eq. (19).
    pub thrust_limit: [f64; 3],
    /// Per-variable trust-region scale (N, N, N m): the box is `radius * scale`.
    pub trust_scale: [f64; 3],
    /// Trust region.
    pub scp: ScpSettings,
    /// `phi` of the distance term.
    pub distance: DistanceCost,
    /// Hard clearance rows (default `d_min = 0.5 m`, about half a TitoNeri).
    pub clearance: ClearanceParams,
}

impl Default for TugMpcParams {
    fn default() -> Self {
        TugMpcParams {
            weights: [1.0, 6.0, 1.0],
            thrust_limit: [10.0; 3],
            trust_scale: [10.0, 10.0, 1.0],
            scp: ScpSettings::default(),
            distance: DistanceCost::default(),
            clearance: ClearanceParams::with_min_distance(0.6),
        }
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
}

/// A tug's local MPC (module docs).
#[derive(Debug)]
pub struct TugMpc {
    model: TugModel,
    params: TugMpcParams,
    /// Per number of obstacle slots per sample `c` (`0..=max_obstacles`), the QP
    /// and its clearance rows: a step uses the smallest layout holding the
    /// obstacles present (unused slots only add rows, see [`Clearance::copy_from`]);
    /// the last one records the linearisation.
    variants: Vec<(Qp, Clearance)>,
    trust: TrustRegion,
    plan: [TugInput; HORIZON],
    candidate: [TugInput; HORIZON],
    lin: [TugLinearisation; HORIZON],
    /// The `(state, plan, pulls)` that `lin`, `sens` and `states` were computed
    /// for: a step from the same point (after a rejected step) reuses them.
    lin_key: Option<(TugState, [TugInput; HORIZON], [TowlinePull; HORIZON])>,
    sens: [[Matrix6x3<f64>; HORIZON]; HORIZON],
    states: [TugState; HORIZON],
    candidate_states: [TugState; HORIZON],
    quad: QuadModel,
}

impl TugMpc {
    /// The problem for `model`, the plan at zero thrust.
    pub fn new(model: TugModel, params: TugMpcParams) -> Result<TugMpc, QpBuildError> {
        let variants = (0..=params.clearance.max_obstacles)
            .map(|max_obstacles| {
                let cp = ClearanceParams {
                    max_obstacles,
                    ..params.clearance
                };
                let ns = Clearance::slacks(&cp, HORIZON);
                let entries = Clearance::entries(&cp, 3, HORIZON, 0);
                let (qp, slots) = box_qp(N + ns, N, ns, &entries)?;
                let clearance = Clearance::new(cp, 3, HORIZON, 2 * (N + ns), slots);
                Ok((qp, clearance))
            })
            .collect::<Result<Vec<_>, QpBuildError>>()?;
        Ok(TugMpc {
            model,
            params,
            variants,
            trust: TrustRegion::new(params.scp),
            plan: [[0.0; 3]; HORIZON],
            candidate: [[0.0; 3]; HORIZON],
            lin: [TugLinearisation::default(); HORIZON],
            lin_key: None,
            sens: [[Matrix6x3::zeros(); HORIZON]; HORIZON],
            states: [[0.0; 6]; HORIZON],
            candidate_states: [[0.0; 6]; HORIZON],
            quad: QuadModel::new(N),
        })
    }

    /// The current plan.
    #[must_use]
    pub fn plan(&self) -> &[TugInput; HORIZON] {
        &self.plan
    }

    /// Replaces the plan (warm start); it is clamped to the bounds at the next step.
    pub fn set_plan(&mut self, plan: [TugInput; HORIZON]) {
        self.plan = plan;
    }

    /// The predicted states of the plan as of the last step (`g_i`: the pose part).
    #[must_use]
    pub fn predicted_states(&self) -> &[TugState; HORIZON] {
        &self.states
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

    /// The true cost of `plan` for `data` (nonlinear rollout).
    #[must_use]
    pub fn cost(&self, plan: &[TugInput; HORIZON], data: &TugStepData<'_>) -> f64 {
        let states = self.model.rollout(&data.state, plan, &data.pulls);
        let mut quad = QuadModel::new(0);
        quad.reset(true);
        accumulate(&mut quad, &self.params, &states, None, None, data);
        quad.value
    }

    /// One SCP step (module docs). Allocation-free.
    pub fn solve_step(&mut self, data: &TugStepData<'_>) -> ScpReport {
        let lim = self.params.thrust_limit;
        for tau in &mut self.plan {
            for (t, l) in tau.iter_mut().zip(lim) {
                *t = t.clamp(-l, l);
            }
        }
        let key = (data.state, self.plan, data.pulls);
        if self.lin_key != Some(key) {
            self.model.linearise_thrust_rollout_into(
                &data.state,
                &self.plan,
                &data.pulls,
                &mut self.lin,
            );
            condense(
                std::array::from_fn(|h| &self.lin[h].a),
                std::array::from_fn(|h| &self.lin[h].b),
                &mut self.sens,
            );
            self.lin_key = Some(key);
        }
        for h in 0..HORIZON {
            self.states[h] = self.lin[h].x_next;
        }
        self.quad.reset(false);
        let full = self.variants.len() - 1;
        self.variants[full].1.clear();
        accumulate(
            &mut self.quad,
            &self.params,
            &self.states,
            Some(&self.sens),
            Some(&mut self.variants[full].1),
            data,
        );
        let radius = self.trust.radius();
        let (mut lo, mut hi) = ([0.0; N], [0.0; N]);
        for h in 0..HORIZON {
            for c in 0..3 {
                let tr = radius * self.params.trust_scale[c];
                let u = self.plan[h][c];
                lo[3 * h + c] = (-lim[c] - u).max(-tr);
                hi[3 * h + c] = (lim[c] - u).min(tr);
            }
        }
        let used = load_layout(&mut self.variants, tug_layout, &self.quad, &lo, &hi);
        let cost_before = self.quad.value;
        let (qp, rows) = &mut self.variants[used];
        let (outcome, iterations, predicted) =
            match solve_layout(qp, rows, &self.quad, N, &mut self.trust) {
                Ok(solved) => solved,
                Err(report) => return report,
            };
        let du = qp.solution();
        for h in 0..HORIZON {
            for c in 0..3 {
                self.candidate[h][c] = (self.plan[h][c] + du[3 * h + c]).clamp(-lim[c], lim[c]);
            }
        }
        self.model.rollout_into(
            &data.state,
            &self.candidate,
            &data.pulls,
            &mut self.candidate_states,
        );
        self.quad.reset(true);
        accumulate(
            &mut self.quad,
            &self.params,
            &self.candidate_states,
            None,
            None,
            data,
        );
        let cost_candidate = self.quad.value;
        let (accepted, ratio) = self.trust.judge(cost_before, cost_candidate, predicted);
        if accepted {
            self.plan = self.candidate;
            self.states = self.candidate_states;
        }
        ScpReport::judged(
            outcome,
            [cost_before, cost_candidate, predicted],
            accepted,
            ratio,
            self.trust.radius(),
            iterations,
        )
    }
}

/// A tug layout's QP and clearance rows.
fn tug_layout(v: &mut (Qp, Clearance)) -> (&mut Qp, &mut Clearance) {
    (&mut v.0, &mut v.1)
}

/// The cost terms of the states `states` (after samples 0..H); with `sens` the
/// model rows too.
fn accumulate(
    quad: &mut QuadModel,
    params: &TugMpcParams,
    states: &[TugState; HORIZON],
    sens: Option<&[[Matrix6x3<f64>; HORIZON]; HORIZON]>,
    mut clearance: Option<&mut Clearance>,
    data: &TugStepData<'_>,
) {
    let [w1, w2, w3] = params.weights;
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
            quad.residual(err[c], w1 + 0.5 * data.rho, data.lambda[h][c], &rows[c]);
            quad.residual(x[3 + c], w2, 0.0, &rows[3 + c]);
        }
        obstacle_terms(
            quad,
            data.obstacles,
            &params.distance,
            w3,
            &params.clearance,
            clearance.as_deref_mut(),
            h,
            [x[0], x[1]],
            &rows[0],
            &rows[1],
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use towing_model::{HullModel, Scenario};

    use crate::PredictionParams;

    fn tug_mpc() -> TugMpc {
        let scenario = Scenario::paper().unwrap();
        let model = TugModel::from_scenario(
            &scenario,
            1,
            HullModel::NonlinearDamping,
            PredictionParams::default(),
        )
        .unwrap();
        TugMpc::new(model, TugMpcParams::default()).unwrap()
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
        }
    }

    fn within_bounds(mpc: &TugMpc) -> bool {
        let lim = mpc.params().thrust_limit;
        mpc.plan()
            .iter()
            .all(|t| t.iter().zip(lim).all(|(v, l)| v.abs() <= l + 1e-9))
    }

    #[test]
    fn converges_to_a_reference_ahead() {
        let mut mpc = tug_mpc();
        let data = data_ahead(&[]);
        // Start from a poor plan (sway and yaw thrust): several nonlinear steps.
        mpc.set_plan([[0.0, 8.0, -5.0]; HORIZON]);
        let initial = mpc.cost(mpc.plan(), &data);
        let mut last = initial;
        let mut accepted = 0;
        for _ in 0..30 {
            let report = mpc.solve_step(&data);
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
        assert!(mpc.plan()[0][0] > 0.5, "{:?}", mpc.plan());
        assert!(mpc.predicted_states()[HORIZON - 1][0] > 0.1);
        // Converged: one more step changes (almost) nothing.
        let report = mpc.solve_step(&data);
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
            free.solve_step(&data);
            priced.solve_step(&with_lambda);
        }
        assert!(priced.plan()[0][0] < free.plan()[0][0]);
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
            free.solve_step(&data);
            let r = blocked.solve_step(&data_obs);
            assert!(within_bounds(&blocked) && r.qp.is_usable());
        }
        assert!(
            blocked.predicted_states()[HORIZON - 1][0] < free.predicted_states()[HORIZON - 1][0]
        );
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
            let mut params = TugMpcParams::default();
            params.weights[2] = 0.0;
            params.clearance.max_obstacles = max_obstacles;
            let scenario = Scenario::paper().unwrap();
            let model = TugModel::from_scenario(
                &scenario,
                1,
                HullModel::NonlinearDamping,
                PredictionParams::default(),
            )
            .unwrap();
            let mut mpc = TugMpc::new(model, params).unwrap();
            let mut data = data_ahead(&obstacles);
            data.reference = [[1.5, 0.0, 0.0]; HORIZON];
            let mut last = f64::INFINITY;
            for _ in 0..40 {
                let report = mpc.solve_step(&data);
                assert!(report.qp.is_usable(), "{report:?}");
                assert!(within_bounds(&mpc));
                assert!(report.cost_after <= last);
                last = report.cost_after;
            }
            mpc.predicted_states()
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
}
