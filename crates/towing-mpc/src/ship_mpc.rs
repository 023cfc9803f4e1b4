//! The coordination problem on the ship, eq. (26), as one sequential-convex-
//! programming step (`docs/controller-design.md`, "Coordination MPC on the ship").
//!
//! Decision: `(F_1, F_2, alpha_1, alpha_2)` per sample, `4 H = 12` increments `du`
//! (index `4 h + k`). Given the ship's state, the command applied in the previous
//! sample, the reference poses `eta_Sd`, the tugs' reported poses `g_i`, the
//! multipliers `lambda_i` and `rho`, the step linearises the ship's rollout around
//! the plan, condenses the states as in [`crate::tug_mpc`], and minimises the
//! quadratic model ([`crate::scp`]) of
//!
//! ```text
//! sum_h  w_S1 |eta_{h+1} - eta_Sd,h|^2 + w_S2 |nu_{h+1}|^2 + w_S3 sum_j phi(d_j(p_{h+1}))
//!      + sum_i [ -lambda_ih^T f_i(eta_{h+1}, alpha_ih) + rho/2 |g_ih - f_i(eta_{h+1}, alpha_ih)|^2 ]
//! ```
//!
//! with `f_i` the tug reference of eq. (4) ([`FormationMap::tug_reference_linearised`]),
//! linearised through the ship's linearised trajectory and the towing angle of the
//! same sample. (`-lambda^T f = lambda^T (g - f) - lambda^T g`, and `g` is given, so
//! the ADMM terms are the residual `g - f` with linear weight `lambda`.) Heading
//! differences are wrapped to `(-pi, pi]`.
//!
//! Constraints: the box `0 <= F_i <= F_max`, `|alpha_i| <= alpha_max` merged with the
//! trust region and, for the first sample, with the rate bound measured from the
//! previous command; the rate bounds between samples 1..H as 2 rows per channel and
//! sample (16 rows): 24 box rows + 16 rows in all. Before the step the plan is
//! projected onto the constraints (the previous command first clamped into the
//! box, then each sample clamped into the box and the rate band of the sample
//! before), so that `du = 0` is feasible and the QP always has a solution.
//!
//! Obstacles: the distance cost `w_S3 phi` and the hard clearance rows with
//! L1-penalised slacks as in [`crate::tug_mpc`] ([`ClearanceParams`]; default
//! `d_min = 0.65 m`, about half a CyberShip II).
//!
//! Allocation: as [`crate::tug_mpc`]; all buffers are made in [`ShipMpc::new`].

// Index loops over (sample, channel) pairs: the indices also address the
// flat increment vector (`3 h + c`, `4 h + k`), clearer than zipped iterators.
#![allow(clippy::needless_range_loop)]

use nalgebra::Matrix6x4;

use crate::formation::FormationMap;
use crate::obstacle::{DistanceCost, Obstacle};
use crate::qp::QpBuildError;
use crate::scp::{
    angle_difference, box_qp, condense, load_layout, obstacle_terms, solve_layout, Clearance,
    ClearanceParams, QuadModel, ScpReport, ScpSettings, TrustRegion,
};
use crate::ship::{ShipInput, ShipLinearisation, ShipModel, ShipState};
use crate::tug_mpc::HORIZON;
use crate::Qp;

const N: usize = 4 * HORIZON;
const RATE_ROWS: usize = 2 * 4 * (HORIZON - 1);

/// Parameters of the coordination problem.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShipMpcParams {
    /// `w_S = (w_S1, w_S2, w_S3)`: pose error, velocity, distance (Table 3: 1, 75, 1).
    pub weights: [f64; 3],
    /// Weight of the yaw rate in the velocity term (s^2/rad^2); `None` uses
    /// `w_S2` as eq. (13) does for all three components of `nu`.
    pub yaw_rate_weight: Option<f64>,
    /// `F_min` (N), eq. (18), where the paper has 0: a pretension keeping both
    /// lines taut. With slack lines the formation (eq. (4)-(6)) no longer fixes
    /// the tugs, the towing angles drift with them, and the next pull starts
    /// from a crooked formation (`docs/assumptions.md`). 0 is the printed bound.
    pub min_tension: f64,
    /// `F_max` (N), eq. (18).
    pub max_tension: f64,
    /// `alpha_max` (rad), eq. (17).
    pub max_angle: f64,
    /// `|Delta F|` per sample (N), eq. (21).
    pub tension_rate: f64,
    /// `|Delta alpha|` per sample (rad), eq. (20).
    pub angle_rate: f64,
    /// `w_alpha` (1/rad^2): weight of `sum_h alpha_ih^2`, a regulariser the paper
    /// does not have. Without it the towing angles are free whenever the
    /// tensions are zero (they then move only the tugs' references), drift with
    /// the tugs to the bounds, and the next pull starts from a crooked formation
    /// (`docs/assumptions.md`). 0 reproduces eq. (13) as printed.
    pub angle_weight: f64,
    /// `w_F` (1/N^2): weight of `sum_h F_ih^2`, a regulariser the paper does not
    /// have. Eq. (13) has no input cost, so equal and opposite tensions cost
    /// nothing and the lines can end in a tug of war at `F_max`; a small `w_F`
    /// picks the least tension among plans of (nearly) equal cost. 0 reproduces
    /// eq. (13) as printed.
    pub tension_weight: f64,
    /// Optional terminal term, not in the paper (`docs/assumptions.md`).
    pub terminal: Option<TerminalCost>,
    /// Trust-region scale of `(F, alpha)` (N, rad): the box is `radius * scale`.
    pub trust_scale: [f64; 2],
    /// Trust region.
    pub scp: ScpSettings,
    /// `phi` of the distance term.
    pub distance: DistanceCost,
    /// Hard clearance rows.
    pub clearance: ClearanceParams,
    /// `w_P`: weight of the one-sided heading term `w_P min(0, psi_h - psi_floor)^2`
    /// (per rad^2), active only when the sample carries a heading floor
    /// ([`ShipStepData::heading_floor`]). Not in the paper: see
    /// [`ship_stage_terms`].
    pub port_turn_weight: f64,
}

impl Default for ShipMpcParams {
    fn default() -> Self {
        ShipMpcParams {
            weights: [1.0, 75.0, 1.0],
            yaw_rate_weight: None,
            min_tension: 0.1,
            max_tension: 3.0,
            max_angle: 30f64.to_radians(),
            tension_rate: 0.3,
            angle_rate: 5f64.to_radians(),
            angle_weight: 0.0,
            tension_weight: 0.01,
            terminal: Some(TerminalCost {
                weight: 1.0,
                horizon: 10.0,
            }),
            trust_scale: [1.0, 0.2],
            scp: ScpSettings::default(),
            distance: DistanceCost::default(),
            clearance: ClearanceParams::with_min_distance(0.75),
            port_turn_weight: 100.0,
        }
    }
}

/// A terminal term `w |e_H + tau eta_dot_H|^2` on the last predicted state: the
/// pose error extrapolated `tau` seconds with the predicted velocity over
/// ground. A 3 s horizon sees too little of a turn or an approach to start it
/// (the gain comes after the horizon, the velocity cost within it); the
/// extrapolation credits the velocity that is heading the right way (a
/// cost-to-go approximation, e.g. Rawlings, Mayne, Diehl 2017, section 2.5).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TerminalCost {
    /// `w` (per m^2 and per rad^2).
    pub weight: f64,
    /// `tau` (s).
    pub horizon: f64,
}

impl ShipMpcParams {
    /// `(lower, upper, rate)` of channel `k` (0, 1: tensions; 2, 3: angles):
    /// eq. (17)-(18) and (20)-(21).
    #[must_use]
    pub fn channel_limits(&self, k: usize) -> (f64, f64, f64) {
        if k < 2 {
            (self.min_tension, self.max_tension, self.tension_rate)
        } else {
            (-self.max_angle, self.max_angle, self.angle_rate)
        }
    }

    /// Projects `plan` onto the bounds and the rate bounds, sample by sample,
    /// the first measured from `previous` (itself clamped to the bounds).
    pub fn project(&self, plan: &mut [ShipInput; HORIZON], previous: &ShipInput) {
        for k in 0..4 {
            let (lo, hi, rate) = self.channel_limits(k);
            let mut before = previous[k].clamp(lo, hi);
            for u in plan.iter_mut() {
                u[k] = u[k].clamp(lo.max(before - rate), hi.min(before + rate));
                before = u[k];
            }
        }
    }
}

/// The data of one step. Per sample `h`: `reference[h]`, `tug_poses[i][h]`,
/// `lambda[i][h]` for the state after sample `h` (tug index `i`: 0 = tug 1).
#[derive(Debug, Clone, Copy)]
pub struct ShipStepData<'a> {
    /// The ship's current state.
    pub state: ShipState,
    /// The command applied in the previous sample (rate bounds of sample 0).
    pub previous: ShipInput,
    /// Reference poses `eta_Sd` `[x, y, psi]`.
    pub reference: [[f64; 3]; HORIZON],
    /// Poses the tugs predict, `g_i`.
    pub tug_poses: [[[f64; 3]; HORIZON]; 2],
    /// Multipliers `lambda_i`.
    pub lambda: [[[f64; 3]; HORIZON]; 2],
    /// ADMM penalty `rho` (>= 0).
    pub rho: f64,
    /// Static obstacles.
    pub obstacles: &'a [Obstacle],
    /// The lowest heading the ship may take over the horizon (rad), from
    /// COLREGS: no turn to port while the tow gives way or stands on.
    pub heading_floor: Option<f64>,
}

/// The coordination MPC (module docs).
#[derive(Debug)]
pub struct ShipMpc {
    model: ShipModel,
    formation: FormationMap,
    params: ShipMpcParams,
    /// Per number of obstacle slots per sample `c` (`0..=max_obstacles`), the QP,
    /// its clearance rows and its first rate row: a step uses the smallest layout
    /// holding the obstacles present (unused slots only add rows, see
    /// [`Clearance::copy_from`]); the last one records the linearisation.
    variants: Vec<(Qp, Clearance, usize)>,
    trust: TrustRegion,
    plan: [ShipInput; HORIZON],
    candidate: [ShipInput; HORIZON],
    lin: [ShipLinearisation; HORIZON],
    /// The `(state, plan)` that `lin` and `sens` were computed for: a step from
    /// the same point (after a rejected step) reuses them.
    lin_key: Option<(ShipState, [ShipInput; HORIZON])>,
    sens: [[Matrix6x4<f64>; HORIZON]; HORIZON],
    states: [ShipState; HORIZON],
    candidate_states: [ShipState; HORIZON],
    quad: QuadModel,
}

impl ShipMpc {
    /// The problem for `model` and `formation`; the plan at zero tension, straight
    /// lines.
    pub fn new(
        model: ShipModel,
        formation: FormationMap,
        params: ShipMpcParams,
    ) -> Result<ShipMpc, QpBuildError> {
        // Rate rows: row 2 (4 (h - 1) + k) (+1): du_{h,k} - du_{h-1,k} <= .. (and -).
        let mut entries = Vec::with_capacity(2 * RATE_ROWS);
        for h in 1..HORIZON {
            for k in 0..4 {
                let row = 2 * (4 * (h - 1) + k);
                entries.extend([
                    (row, 4 * h + k),
                    (row, 4 * (h - 1) + k),
                    (row + 1, 4 * h + k),
                    (row + 1, 4 * (h - 1) + k),
                ]);
            }
        }
        let n_rate = entries.len();
        let variants = (0..=params.clearance.max_obstacles)
            .map(|max_obstacles| {
                let cp = ClearanceParams {
                    max_obstacles,
                    ..params.clearance
                };
                let mut entries = entries.clone();
                let ns = Clearance::slacks(&cp, HORIZON);
                entries.extend(Clearance::entries(&cp, 4, HORIZON, RATE_ROWS));
                let (mut qp, mut slots) = box_qp(N + ns, N, RATE_ROWS + ns, &entries)?;
                for (slot, v) in slots[..n_rate]
                    .iter()
                    .zip([1.0, -1.0, -1.0, 1.0].iter().cycle())
                {
                    qp.a_mut()[*slot] = *v;
                }
                let rate_row = 2 * (N + ns);
                let clearance_slots = slots.split_off(n_rate);
                let clearance =
                    Clearance::new(cp, 4, HORIZON, rate_row + RATE_ROWS, clearance_slots);
                Ok((qp, clearance, rate_row))
            })
            .collect::<Result<Vec<_>, QpBuildError>>()?;
        Ok(ShipMpc {
            model,
            formation,
            params,
            variants,
            trust: TrustRegion::new(params.scp),
            plan: [[0.0; 4]; HORIZON],
            candidate: [[0.0; 4]; HORIZON],
            lin: [ShipLinearisation::default(); HORIZON],
            lin_key: None,
            sens: [[Matrix6x4::zeros(); HORIZON]; HORIZON],
            states: [[0.0; 6]; HORIZON],
            candidate_states: [[0.0; 6]; HORIZON],
            quad: QuadModel::new(N),
        })
    }

    /// The current plan.
    #[must_use]
    pub fn plan(&self) -> &[ShipInput; HORIZON] {
        &self.plan
    }

    /// Replaces the plan (warm start); it is projected onto the constraints at the
    /// next step.
    pub fn set_plan(&mut self, plan: [ShipInput; HORIZON]) {
        self.plan = plan;
    }

    /// The predicted ship states of the plan as of the last step.
    #[must_use]
    pub fn predicted_states(&self) -> &[ShipState; HORIZON] {
        &self.states
    }

    /// The prediction model.
    #[must_use]
    pub fn model(&self) -> &ShipModel {
        &self.model
    }

    /// The configuration map.
    #[must_use]
    pub fn formation(&self) -> &FormationMap {
        &self.formation
    }

    /// The parameters.
    #[must_use]
    pub fn params(&self) -> &ShipMpcParams {
        &self.params
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

    /// The true cost of `plan` for `data` (nonlinear rollout).
    #[must_use]
    pub fn cost(&self, plan: &[ShipInput; HORIZON], data: &ShipStepData<'_>) -> f64 {
        let states = self.model.rollout(&data.state, plan);
        let mut quad = QuadModel::new(0);
        quad.reset(true);
        accumulate(
            &mut quad,
            &self.params,
            &self.formation,
            &states,
            plan,
            None,
            None,
            data,
        );
        quad.value
    }

    /// One SCP step (module docs). Allocation-free.
    pub fn solve_step(&mut self, data: &ShipStepData<'_>) -> ScpReport {
        let limits: [(f64, f64, f64); 4] = std::array::from_fn(|k| self.params.channel_limits(k));
        // Project the plan onto the constraints.
        self.params.project(&mut self.plan, &data.previous);
        let key = (data.state, self.plan);
        if self.lin_key != Some(key) {
            self.model
                .linearise_rollout_into(&data.state, &self.plan, &mut self.lin);
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
            &self.formation,
            &self.states,
            &self.plan,
            Some(&self.sens),
            Some(&mut self.variants[full].1),
            data,
        );
        let radius = self.trust.radius();
        let (mut box_lo, mut box_hi) = ([0.0; N], [0.0; N]);
        for k in 0..4 {
            let (lo, hi, rate) = limits[k];
            let tr = radius * self.params.trust_scale[k / 2];
            let prev = data.previous[k].clamp(lo, hi);
            for h in 0..HORIZON {
                let u = self.plan[h][k];
                let (mut l, mut r) = ((lo - u).max(-tr), (hi - u).min(tr));
                if h == 0 {
                    l = l.max(prev - rate - u);
                    r = r.min(prev + rate - u);
                }
                // du = 0 is feasible after the projection; keep it so with rounding.
                box_lo[4 * h + k] = l.min(0.0);
                box_hi[4 * h + k] = r.max(0.0);
            }
        }
        let used = load_layout(
            &mut self.variants,
            ship_layout,
            &self.quad,
            &box_lo,
            &box_hi,
        );
        let cost_before = self.quad.value;
        let (qp, rows, rate_row) = &mut self.variants[used];
        let rate_row = *rate_row;
        for k in 0..4 {
            let rate = limits[k].2;
            for h in 1..HORIZON {
                let diff = self.plan[h][k] - self.plan[h - 1][k];
                let row = rate_row + 2 * (4 * (h - 1) + k);
                qp.b_mut()[row] = (rate - diff).max(0.0);
                qp.b_mut()[row + 1] = (rate + diff).max(0.0);
            }
        }
        let (outcome, iterations, predicted) =
            match solve_layout(qp, rows, &self.quad, N, &mut self.trust) {
                Ok(solved) => solved,
                Err(report) => return report,
            };
        let du = qp.solution();
        // The candidate, projected as the plan was (removes the solver's 1e-6
        // tolerance on the constraints).
        self.candidate =
            std::array::from_fn(|h| std::array::from_fn(|k| self.plan[h][k] + du[4 * h + k]));
        self.params.project(&mut self.candidate, &data.previous);
        self.model
            .rollout_into(&data.state, &self.candidate, &mut self.candidate_states);
        self.quad.reset(true);
        accumulate(
            &mut self.quad,
            &self.params,
            &self.formation,
            &self.candidate_states,
            &self.candidate,
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

/// A coordination layout's QP and clearance rows.
fn ship_layout(v: &mut (Qp, Clearance, usize)) -> (&mut Qp, &mut Clearance) {
    (&mut v.0, &mut v.1)
}

/// The ship's own terms of eq. (13) at one predicted state `x` (after sample
/// `h`) reached with the sample's input `u`, shared by the coordination and the
/// centralized problems: `w_S1 |eta - eta_d|^2` (heading wrapped), the velocity
/// term (`w_S2`, the yaw rate optionally weighted apart), the optional
/// regularisers of the tensions and angles and, on the last sample, the optional
/// terminal term. `rows[c]` is `d x_c / du` over the QP's variables, `columns`
/// the QP columns of `u` (`None`: value only).
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
    let [w1, w2, _] = params.weights;
    if let Some(floor) = heading_floor {
        // One-sided: zero (with its gradient) at or to starboard of the floor.
        let e = angle_difference(x[2], floor);
        if e < 0.0 {
            quad.curved(e * e, 2.0 * e, 2.0, params.port_turn_weight, &rows[2]);
        }
    }
    let err = [
        x[0] - reference[0],
        x[1] - reference[1],
        angle_difference(x[2], reference[2]),
    ];
    let wv = [w2, w2, params.yaw_rate_weight.unwrap_or(w2)];
    for c in 0..3 {
        quad.residual(err[c], w1, 0.0, &rows[c]);
        quad.residual(x[3 + c], wv[c], 0.0, &rows[3 + c]);
    }
    let wu = [
        params.tension_weight,
        params.tension_weight,
        params.angle_weight,
        params.angle_weight,
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
        // The pose error extrapolated `tau` seconds with the predicted velocity
        // over ground: e + tau eta_dot, eta_dot = R(psi) nu.
        let (sn, cs) = x[2].sin_cos();
        let xdot = [cs * x[3] - sn * x[4], sn * x[3] + cs * x[4], x[5]];
        // d eta_dot / d(psi, u, v, r).
        let d_psi = [-sn * x[3] - cs * x[4], cs * x[3] - sn * x[4], 0.0];
        let d_nu = [[cs, -sn, 0.0], [sn, cs, 0.0], [0.0, 0.0, 1.0]];
        for c in 0..3 {
            let mut row = [0.0; N];
            for (v, slot) in row.iter_mut().enumerate() {
                *slot = rows[c][v]
                    + t.horizon
                        * (d_psi[c] * rows[2][v]
                            + d_nu[c][0] * rows[3][v]
                            + d_nu[c][1] * rows[4][v]
                            + d_nu[c][2] * rows[5][v]);
            }
            quad.residual(err[c] + t.horizon * xdot[c], t.weight, 0.0, &row);
        }
    }
}

/// The cost terms of `states` (after samples 0..H) reached with `plan`; with
/// `sens` the model rows too (and the clearance rows recorded).
#[allow(clippy::too_many_arguments)] // one call site per use; a struct would only rename them
fn accumulate(
    quad: &mut QuadModel,
    params: &ShipMpcParams,
    formation: &FormationMap,
    states: &[ShipState; HORIZON],
    plan: &[ShipInput; HORIZON],
    sens: Option<&[[Matrix6x4<f64>; HORIZON]; HORIZON]>,
    mut clearance: Option<&mut Clearance>,
    data: &ShipStepData<'_>,
) {
    let w3 = params.weights[2];
    let mut rows = [[0.0; N]; 6];
    for (h, x) in states.iter().enumerate() {
        if let Some(sens) = sens {
            for (c, row) in rows.iter_mut().enumerate() {
                row.fill(0.0);
                for (k, s) in sens[h][..=h].iter().enumerate() {
                    for j in 0..4 {
                        row[4 * k + j] = s[(c, j)];
                    }
                }
            }
        }
        let eta = [x[0], x[1], x[2]];
        let columns = std::array::from_fn(|k| 4 * h + k);
        ship_stage_terms(
            quad,
            params,
            x,
            data.reference[h],
            &plan[h],
            &rows,
            sens.is_some().then_some(columns),
            h + 1 == HORIZON,
            data.heading_floor,
        );
        for i in 0..2 {
            let (f, jac) = formation.tug_reference_linearised(eta, plan[h][2 + i], i);
            let g = data.tug_poses[i][h];
            let res = [g[0] - f[0], g[1] - f[1], angle_difference(g[2], f[2])];
            for c in 0..3 {
                // d(g - f)/du = -(J_eta d eta/du + J_alpha e_{alpha_ih}).
                let mut row = [0.0; N];
                if sens.is_some() {
                    for (v, slot) in row.iter_mut().enumerate() {
                        *slot = -(jac[(c, 0)] * rows[0][v]
                            + jac[(c, 1)] * rows[1][v]
                            + jac[(c, 2)] * rows[2][v]);
                    }
                    row[4 * h + 2 + i] -= jac[(c, 3)];
                }
                quad.residual(res[c], 0.5 * data.rho, data.lambda[i][h][c], &row);
            }
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
    use proptest::prelude::*;
    use towing_model::{HullModel, Scenario};

    use crate::PredictionParams;

    fn ship_mpc() -> ShipMpc {
        ship_mpc_with(ShipMpcParams::default())
    }

    fn ship_mpc_with(params: ShipMpcParams) -> ShipMpc {
        let scenario = Scenario::paper().unwrap();
        let model = ShipModel::from_scenario(
            &scenario,
            HullModel::NonlinearDamping,
            PredictionParams::default(),
        )
        .unwrap();
        let formation = FormationMap::from_scenario(&scenario).unwrap();
        ShipMpc::new(model, formation, params).unwrap()
    }

    /// At rest at the origin heading North; the tugs where the formation wants
    /// them for straight lines (so the ADMM terms are zero at alpha = 0).
    fn data_at_rest(mpc: &ShipMpc, reference: [f64; 3], rho: f64) -> ShipStepData<'static> {
        let mut tug_poses = [[[0.0; 3]; HORIZON]; 2];
        for (i, poses) in tug_poses.iter_mut().enumerate() {
            *poses = [mpc.formation.tug_reference([0.0; 3], 0.0, i); HORIZON];
        }
        ShipStepData {
            state: [0.0; 6],
            previous: [0.0; 4],
            reference: [reference; HORIZON],
            tug_poses,
            lambda: [[[0.0; 3]; HORIZON]; 2],
            rho,
            obstacles: &[],
            heading_floor: None,
        }
    }

    fn check_feasible(mpc: &ShipMpc, previous: &ShipInput) -> Result<(), String> {
        let p = mpc.params();
        let tol = 1e-9;
        let mut before = *previous;
        for k in 0..4 {
            let (lo, hi, _) = mpc.params().channel_limits(k);
            before[k] = before[k].clamp(lo, hi);
        }
        for u in mpc.plan() {
            for k in 0..4 {
                let (lo, hi, rate) = mpc.params().channel_limits(k);
                if u[k] < lo - tol || u[k] > hi + tol {
                    return Err(format!("bound {k}: {u:?}"));
                }
                if (u[k] - before[k]).abs() > rate + tol {
                    return Err(format!("rate {k}: {u:?} after {before:?}"));
                }
            }
            before = *u;
        }
        let _ = p;
        Ok(())
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(24))]
        #[test]
        fn plans_respect_bounds_and_rates(
            x in -5.0f64..5.0, y in -5.0f64..5.0, psi in -3.0f64..3.0,
            u in -0.1f64..0.3, v in -0.05f64..0.05, r in -0.05f64..0.05,
            f1 in -1.0f64..4.0, f2 in -1.0f64..4.0, a1 in -0.7f64..0.7, a2 in -0.7f64..0.7,
            dx in -3.0f64..3.0, dy in -3.0f64..3.0,
        ) {
            let mut mpc = ship_mpc();
            let mut data = data_at_rest(&mpc, [x + dx, y + dy, psi], 1.0);
            data.state = [x, y, psi, u, v, r];
            data.previous = [f1, f2, a1, a2];
            mpc.set_plan([[f1 + 1.0, f2 - 1.0, a1 * 2.0, -a2]; HORIZON]);
            for _ in 0..4 {
                let report = mpc.solve_step(&data);
                prop_assert!(report.qp.is_usable(), "{:?}", report);
                if let Err(e) = check_feasible(&mpc, &data.previous) {
                    return Err(TestCaseError::fail(e));
                }
            }
        }
    }

    #[test]
    fn at_rest_with_reference_ahead() {
        let mut mpc = ship_mpc();
        let data = data_at_rest(&mpc, [2.0, 0.0, 0.0], 0.0);
        let mut last = mpc.cost(mpc.plan(), &data);
        for _ in 0..40 {
            let report = mpc.solve_step(&data);
            assert!(report.qp.is_usable(), "{report:?}");
            let now = mpc.cost(mpc.plan(), &data);
            assert!(now <= last + 1e-12, "{now} > {last}");
            last = now;
            check_feasible(&mpc, &data.previous).unwrap();
        }
        // The first move pulls ahead harder than astern (the last sample may brake:
        // the velocity weight w_S2 = 75 prices the speed left at the horizon).
        let plan = mpc.plan();
        assert!(plan[0][1] > plan[0][0] + 0.1, "{plan:?}");
        let total = |k: usize| plan.iter().map(|u| u[k]).sum::<f64>();
        assert!(total(1) > total(0), "{plan:?}");
        let states = mpc.predicted_states();
        assert!(states[HORIZON - 1][0] > 0.0 && states[HORIZON - 1][3] > 0.0);
    }

    /// A reference to port turns the ship to port; a heading floor at the
    /// current heading keeps its predicted headings (nearly) to starboard of it,
    /// and a floor below every predicted heading changes nothing.
    #[test]
    fn a_heading_floor_stops_a_turn_to_port() {
        let run = |floor: Option<f64>| {
            let mut mpc = ship_mpc_with(ShipMpcParams {
                port_turn_weight: 1e4,
                ..ShipMpcParams::default()
            });
            let mut data = data_at_rest(&mpc, [1.0, -1.0, -0.5], 0.0);
            data.heading_floor = floor;
            for _ in 0..40 {
                assert!(mpc.solve_step(&data).qp.is_usable());
            }
            mpc.predicted_states().map(|x| x[2])
        };
        let free = run(None);
        assert!(free[HORIZON - 1] < -1e-3, "{free:?}");
        let held = run(Some(0.0));
        assert!(held.iter().all(|&psi| psi > -1e-3), "{held:?}");
        let low = run(Some(-1.0));
        for (a, b) in free.iter().zip(low) {
            assert!((a - b).abs() < 1e-9, "{free:?} vs {low:?}");
        }
    }

    /// g_2 displaced to starboard (+y at heading North) pulls alpha_2 positive.
    #[test]
    fn admm_terms_pull_towards_the_tug() {
        let run = |shift: f64| {
            let mut mpc = ship_mpc();
            let mut data = data_at_rest(&mpc, [0.0; 3], 5.0);
            for g in &mut data.tug_poses[1] {
                g[1] += shift;
            }
            mpc.set_plan([[1.0, 1.0, 0.0, 0.0]; HORIZON]);
            data.previous = [1.0, 1.0, 0.0, 0.0];
            for _ in 0..30 {
                assert!(mpc.solve_step(&data).qp.is_usable());
            }
            *mpc.plan()
        };
        let straight = run(0.0);
        let shifted = run(1.0);
        for h in 0..HORIZON {
            assert!(shifted[h][3] > 0.0, "{shifted:?}");
            assert!(
                shifted[h][3] > straight[h][3] + 1e-3,
                "{shifted:?} {straight:?}"
            );
        }
    }

    /// Scheme II (no distance cost): at rest with slack lines, an obstacle 5 mm
    /// beyond `d_min` ahead, the reference behind it. Without clearance rows the
    /// predicted ship closes in below `d_min` (measured 0.59 m vs 0.65 m); with them
    /// it keeps `d >= d_min` (to the linearisation's accuracy; holding still is
    /// feasible here, so the slack is zero), and the plans stay feasible.
    #[test]
    fn clearance_rows_keep_the_distance() {
        let d_min = ShipMpcParams::default().clearance.min_distance;
        let obstacles = [Obstacle::Circle {
            centre: [d_min + 0.3 + 0.005, 0.0],
            radius: 0.3,
        }];
        let run = |max_obstacles: usize| {
            let mut params = ShipMpcParams::default();
            params.weights[2] = 0.0;
            params.clearance.max_obstacles = max_obstacles;
            let mut mpc = ship_mpc_with(params);
            let mut data = data_at_rest(&mpc, [3.0, 0.0, 0.0], 0.0);
            data.obstacles = &obstacles;
            data.previous = [0.0; 4]; // at rest, lines slack: holding still is feasible

            for _ in 0..40 {
                let report = mpc.solve_step(&data);
                assert!(report.qp.is_usable(), "{report:?}");
                check_feasible(&mpc, &data.previous).unwrap();
            }
            mpc.predicted_states()
                .iter()
                .map(|x| obstacles[0].distance([x[0], x[1]]).0)
                .fold(f64::INFINITY, f64::min)
        };
        let free = run(0);
        let kept = run(4);
        assert!(free < d_min - 0.02, "{free}");
        assert!(kept >= d_min - 1e-3, "{kept}");
    }
}
