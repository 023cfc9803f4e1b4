//! The coordination problem on the ship, eq. (26), as a [`Subproblem`] of the
//! SCP engine (`docs/controller-design.md`, "Coordination MPC on the ship").
//!
//! Decision: `(F_1, F_2, alpha_1, alpha_2)` per sample, `4 H = 12` increments `du`
//! (index `4 h + k`). Given the ship's state, the command applied in the previous
//! sample, the reference poses `eta_Sd`, the tugs' reported poses `g_i`, the
//! multipliers `lambda_i` and `rho`, the step linearises the ship's rollout around
//! the plan, condenses the states, and minimises the quadratic model of
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
//! Constraints (the engine's [`InputSpace`]): the box `F_min <= F_i <= F_max`,
//! `|alpha_i| <= alpha_max` and the rate bounds (eq. (17)-(18), (20)-(21)), the
//! first sample's measured from the previous command; the hard clearance rows with
//! L1-penalised slacks ([`ClearanceParams`]; default `d_min = 0.75 m`, about half
//! a CyberShip II plus a margin).

// Index loops over (sample, channel) pairs: the indices also address the
// flat increment vector (`4 h + k`), clearer than zipped iterators.
#![allow(clippy::needless_range_loop)]

use nalgebra::Matrix6x4;

use crate::costs::{
    angle_difference, bank_terms, obstacle_terms, ship_stage_terms, At, ClearanceParams,
    MotionLimits, Waterway,
};
use crate::engine::{
    Block, BlockMut, Channel, InputSpace, QuadModel, RowSet, Scp, ScpSettings, SlotRows,
    Subproblem, ALL_VESSELS,
};
use crate::formation::FormationMap;
use crate::obstacle::{DistanceCost, Obstacle};
use crate::qp::QpBuildError;
use crate::ship::{ShipInput, ShipLinearisation, ShipModel, ShipState};
use crate::{condense, HORIZON};

const N: usize = 4 * HORIZON;

/// Parameters of the coordination problem.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShipMpcParams {
    /// `w_S1` on the position error `x, y` (1/m^2), eq. (13) (Table 3: 1).
    pub weight_position: f64,
    /// `w_S1` on the heading error (1/rad^2), eq. (13) (Table 3: 1; here 10 by
    /// default, so that the ship turns to her reference course instead of being
    /// dragged sideways towards the tracked point: `docs/assumptions.md`).
    pub weight_heading: f64,
    /// `w_S2` on the surge speed `u` (s^2/m^2), eq. (13) (Table 3: 75).
    pub weight_surge: f64,
    /// `w_S2` on the sway speed `v` (s^2/m^2), eq. (13) (Table 3: 75).
    pub weight_sway: f64,
    /// `w_S2` on the yaw rate `r` (s^2/rad^2), eq. (13) (Table 3: 75); the
    /// paper weights all three components of `nu` alike.
    pub weight_yaw_rate: f64,
    /// `w_S3` on the distance cost `phi` (m^2, as `phi` is in 1/m^2), eq. (13)
    /// (Table 3: 1).
    pub weight_distance: f64,
    /// `F_min` (N), eq. (18), where the paper has 0: a pretension keeping both
    /// lines taut. With slack lines the formation (eq. (4)-(6)) no longer fixes
    /// the tugs, the towing angles drift with them, and the next pull starts
    /// from a crooked formation (`docs/assumptions.md`). 0 is the printed bound.
    pub min_tension: f64,
    /// `F_max` (N), eq. (18).
    pub max_tension: f64,
    /// `alpha_max` (rad), eq. (17).
    pub max_angle: f64,
    /// Largest tension change per second (N/s), eq. (21) (Table 3: 0.3 N per
    /// 1 s sample); the bound of a sample is `tension_rate * T_s`.
    pub tension_rate: f64,
    /// Largest towing-angle change per second (rad/s), eq. (20) (Table 3: 5 deg
    /// per 1 s sample); the bound of a sample is `angle_rate * T_s`.
    pub angle_rate: f64,
    /// `w_alpha` (1/rad^2): weight of `sum_h alpha_ih^2`, a regulariser the paper
    /// does not have. Without it the towing angles are free whenever the
    /// tensions are zero (they then move only the tugs' references), drift with
    /// the tugs to the bounds, and the next pull starts from a crooked formation
    /// (`docs/assumptions.md`). 0 reproduces eq. (13) as printed.
    pub weight_towing_angle: f64,
    /// `w_F` (1/N^2): weight of `sum_h F_ih^2`, a regulariser the paper does not
    /// have. Eq. (13) has no input cost, so equal and opposite tensions cost
    /// nothing and the lines can end in a tug of war at `F_max`; a small `w_F`
    /// picks the least tension among plans of (nearly) equal cost. 0 reproduces
    /// eq. (13) as printed.
    pub weight_tension: f64,
    /// `F_hold` (N): while the way is off (the plan's surge capped,
    /// [`crate::SampleInput::max_surge`]) the smallest tension of each line is `F_hold`
    /// instead of `F_min`, reached within the rate bound
    /// ([`ShipMpcParams::tension_floor`]). A stopped ship is turned and held by the tugs'
    /// sideways pull `F sin alpha`; with the lines at `F_min` that pull barely changes
    /// with the towing angle to first order, and the SCP step left the stopped ship
    /// yawing off her course (`docs/controller-design.md`, "Standing on"). Tugs holding
    /// a ship stopped keep their lines tight. At most `F_min`: `F_min` always.
    pub holding_tension: f64,
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
    /// [`crate::costs`].
    pub weight_port_turn: f64,
    /// Soft limits on the predicted drift angle, sternway and speed
    /// ([`MotionLimits`]). Not in the paper (`docs/assumptions.md`).
    pub motion: MotionLimits,
    /// Bank rows ([`crate::Waterway`], one per sample) built into the problem; `false`
    /// (the default) builds none. The controller sets it when its configuration has a
    /// waterway.
    pub waterway_rows: bool,
}

impl Default for ShipMpcParams {
    fn default() -> Self {
        ShipMpcParams {
            weight_position: 1.0,
            weight_heading: 10.0,
            weight_surge: 75.0,
            weight_sway: 75.0,
            weight_yaw_rate: 75.0,
            weight_distance: 1.0,
            min_tension: 0.1,
            max_tension: 3.0,
            max_angle: 30f64.to_radians(),
            tension_rate: 0.3,
            angle_rate: 5f64.to_radians(),
            weight_towing_angle: 0.0,
            weight_tension: 0.01,
            holding_tension: 0.3,
            terminal: Some(TerminalCost {
                weight: 1.0,
                horizon: 10.0,
            }),
            trust_scale: [1.0, 0.2],
            scp: ScpSettings::default(),
            distance: DistanceCost::default(),
            clearance: ClearanceParams::with_min_distance(0.75),
            weight_port_turn: 100.0,
            motion: MotionLimits::default(),
            waterway_rows: false,
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
    /// The pose-error weights `[x, y, psi]` and the velocity weights `[u, v, r]`
    /// (as [`crate::TugMpcParams::state_weights`]).
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

    /// `(lower, upper, largest change per sample)` of channel `k` (0, 1:
    /// tensions; 2, 3: angles) for samples of `sample_time` s: eq. (17)-(18)
    /// and (20)-(21).
    #[must_use]
    pub fn channel_limits(&self, k: usize, sample_time: f64) -> (f64, f64, f64) {
        if k < 2 {
            (
                self.min_tension,
                self.max_tension,
                self.tension_rate * sample_time,
            )
        } else {
            (
                -self.max_angle,
                self.max_angle,
                self.angle_rate * sample_time,
            )
        }
    }

    /// The smallest tension (N) of a line whose previous command was `previous` (N),
    /// for samples of `sample_time` s: `F_min`, or while the way is off (`way_off`)
    /// `F_hold`, no more above the previous command than one sample's rate bound
    /// allows (so the floor never makes the first sample infeasible).
    #[must_use]
    pub fn tension_floor(&self, way_off: bool, previous: f64, sample_time: f64) -> f64 {
        if !way_off {
            return self.min_tension;
        }
        let reach = previous.max(self.min_tension) + self.tension_rate * sample_time;
        self.holding_tension
            .min(reach)
            .min(self.max_tension)
            .max(self.min_tension)
    }

    /// Sets the lower bounds of the tension channels 0 and 1 of `space` to their
    /// [`ShipMpcParams::tension_floor`] from the `previous` command (its first two
    /// entries, the tensions).
    pub fn floor_tensions(
        &self,
        space: &mut InputSpace,
        way_off: bool,
        previous: &[f64],
        sample_time: f64,
    ) {
        for k in 0..2 {
            space.set_lower(k, self.tension_floor(way_off, previous[k], sample_time));
        }
    }

    /// The four input channels of a sample (`F_1, F_2, alpha_1, alpha_2`) for
    /// samples of `sample_time` s.
    #[must_use]
    pub fn channels(&self, sample_time: f64) -> [Channel; 4] {
        std::array::from_fn(|k| {
            let (lower, upper, rate) = self.channel_limits(k, sample_time);
            Channel {
                lower,
                upper,
                rate,
                trust_scale: self.trust_scale[k / 2],
                moves: ALL_VESSELS,
            }
        })
    }

    /// Projects `plan` (samples of `sample_time` s) onto the bounds and the rate
    /// bounds, sample by sample, the first measured from `previous` (itself
    /// clamped to the bounds).
    pub fn project(&self, plan: &mut [ShipInput; HORIZON], previous: &ShipInput, sample_time: f64) {
        let space = InputSpace::new(self.channels(sample_time).to_vec(), HORIZON);
        space.project(plan.as_flattened_mut(), previous);
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
    /// Obstacles left out of the distance cost ([`crate::SampleInput::distance_cost_off`]).
    pub distance_cost_off: u64,
    /// The lowest heading the ship may take over the horizon (rad), from
    /// COLREGS: no turn to port while the tow gives way or stands on.
    pub heading_floor: Option<f64>,
    /// The largest surge speed (m/s) of the plan ([`crate::SampleInput::max_surge`]).
    pub max_surge: Option<f64>,
    /// The waterway ([`crate::SampleInput::waterway`]).
    pub waterway: Option<Waterway<'a>>,
}

/// The coordination problem (module docs).
#[derive(Debug)]
pub struct ShipProblem {
    model: ShipModel,
    formation: FormationMap,
    params: ShipMpcParams,
    space: InputSpace,
}

/// The linearised rollout of the ship: per sample the linearised step, the
/// condensed sensitivities (`condense`, Maciejowski 2002, section 3.1) and the nominal states.
#[derive(Debug, Clone)]
pub struct ShipLinearised {
    steps: [ShipLinearisation; HORIZON],
    sens: [[Matrix6x4<f64>; HORIZON]; HORIZON],
    states: [ShipState; HORIZON],
}

/// The coordination problem's soft rows: the clearance rows, the motion limits and the
/// bank.
#[derive(Debug, Clone)]
pub struct ShipRows {
    clearance: SlotRows,
    motion: SlotRows,
    bank: SlotRows,
}

impl RowSet for ShipRows {
    fn blocks(&self) -> impl Iterator<Item = Block<'_>> {
        [
            Block::Slots(&self.clearance),
            Block::Slots(&self.motion),
            Block::Slots(&self.bank),
        ]
        .into_iter()
    }
    fn blocks_mut(&mut self) -> impl Iterator<Item = BlockMut<'_>> {
        [
            BlockMut::Slots(&mut self.clearance),
            BlockMut::Slots(&mut self.motion),
            BlockMut::Slots(&mut self.bank),
        ]
        .into_iter()
    }
}

/// A flat plan (`4 h + k`) as inputs per sample.
#[must_use]
pub fn ship_inputs(plan: &[f64]) -> [ShipInput; HORIZON] {
    std::array::from_fn(|h| std::array::from_fn(|k| plan[4 * h + k]))
}

impl ShipProblem {
    /// The problem for `model` and `formation`.
    #[must_use]
    pub fn new(model: ShipModel, formation: FormationMap, params: ShipMpcParams) -> ShipProblem {
        ShipProblem {
            space: InputSpace::new(
                params.channels(model.params().sample_time).to_vec(),
                HORIZON,
            ),
            model,
            formation,
            params,
        }
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
}

impl Subproblem for ShipProblem {
    type Data<'a> = ShipStepData<'a>;
    type Trajectory = [ShipState; HORIZON];
    type Linearisation = ShipLinearised;
    type Key = ShipState;
    type Rows = ShipRows;
    type Cost = f64;

    fn space(&self) -> &InputSpace {
        &self.space
    }

    fn prepare(&mut self, data: &ShipStepData<'_>) {
        let sample_time = self.model.params().sample_time;
        let way_off = data.max_surge.is_some();
        (self.params).floor_tensions(&mut self.space, way_off, &data.previous, sample_time);
    }

    fn rows(&self) -> ShipRows {
        ShipRows {
            clearance: self.params.clearance.rows(4, ALL_VESSELS),
            motion: self.params.motion.rows(4, ALL_VESSELS),
            bank: (self.params.clearance)
                .single(self.params.waterway_rows)
                .rows(4, ALL_VESSELS),
        }
    }

    fn buffers(&self) -> (Self::Trajectory, ShipLinearised) {
        (
            [[0.0; 6]; HORIZON],
            ShipLinearised {
                steps: [ShipLinearisation::default(); HORIZON],
                sens: [[Matrix6x4::zeros(); HORIZON]; HORIZON],
                states: [[0.0; 6]; HORIZON],
            },
        )
    }

    fn previous(&self, data: &ShipStepData<'_>, out: &mut [f64]) {
        out.copy_from_slice(&data.previous);
    }

    fn key(&self, data: &ShipStepData<'_>) -> ShipState {
        data.state
    }

    fn rollout(&self, data: &ShipStepData<'_>, plan: &[f64], out: &mut Self::Trajectory) {
        self.model
            .rollout_into(&data.state, &ship_inputs(plan), out);
    }

    fn linearise(&self, data: &ShipStepData<'_>, plan: &[f64], lin: &mut ShipLinearised) {
        self.model
            .linearise_rollout_into(&data.state, &ship_inputs(plan), &mut lin.steps);
        condense(
            std::array::from_fn(|h| &lin.steps[h].a),
            std::array::from_fn(|h| &lin.steps[h].b),
            &mut lin.sens,
        );
        for h in 0..HORIZON {
            lin.states[h] = lin.steps[h].x_next;
        }
    }

    fn nominal(lin: &ShipLinearised) -> &Self::Trajectory {
        &lin.states
    }

    fn terms(
        &self,
        quad: &mut QuadModel,
        traj: &Self::Trajectory,
        plan: &[f64],
        model: Option<(&ShipLinearised, &mut ShipRows)>,
        data: &ShipStepData<'_>,
    ) -> f64 {
        let (sens, rows) = match model {
            Some((lin, rows)) => (Some(&lin.sens), Some(rows)),
            None => (None, None),
        };
        accumulate(
            quad,
            &self.params,
            &self.formation,
            traj,
            &ship_inputs(plan),
            sens,
            rows,
            data,
        );
        quad.value
    }
}

/// The coordination MPC: the SCP engine over [`ShipProblem`].
pub type ShipMpc = Scp<ShipProblem>;

impl Scp<ShipProblem> {
    /// The problem for `model` and `formation`; the plan at zero tension, straight
    /// lines.
    ///
    /// # Errors
    /// A QP that cannot be built.
    pub fn new(
        model: ShipModel,
        formation: FormationMap,
        params: ShipMpcParams,
    ) -> Result<ShipMpc, QpBuildError> {
        Scp::with_problem(ShipProblem::new(model, formation, params), params.scp)
    }

    /// The plan as inputs per sample.
    #[must_use]
    pub fn inputs(&self) -> [ShipInput; HORIZON] {
        ship_inputs(self.plan())
    }

    /// Replaces the plan (warm start); it is projected at the next step.
    pub fn set_inputs(&mut self, plan: [ShipInput; HORIZON]) {
        self.set_plan(plan.as_flattened());
    }
}

/// The cost terms of `states` (after samples 0..H) reached with `plan`; with
/// `sens` the model rows too (and the clearance and motion rows recorded).
#[allow(clippy::too_many_arguments)] // one call site per use; a struct would only rename them
fn accumulate(
    quad: &mut QuadModel,
    params: &ShipMpcParams,
    formation: &FormationMap,
    states: &[ShipState; HORIZON],
    plan: &[ShipInput; HORIZON],
    sens: Option<&[[Matrix6x4<f64>; HORIZON]; HORIZON]>,
    mut soft: Option<&mut ShipRows>,
    data: &ShipStepData<'_>,
) {
    let w3 = params.weight_distance;
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
        let motion = soft.as_deref_mut().map(|r| &mut r.motion);
        params
            .motion
            .capped(data.max_surge)
            .terms(quad, motion, h, x, &rows);
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
            soft.as_deref_mut().map(|r| &mut r.clearance),
            at,
        );
        if let Some(waterway) = &data.waterway {
            let bank = soft.as_deref_mut().map(|r| &mut r.bank);
            bank_terms(quad, (waterway, 0), params.clearance.penalty, bank, at);
        }
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

    /// The holding tension is the floor only while the way is off, reached within one
    /// sample's rate bound from the previous command, never below `F_min` nor above
    /// `F_max`.
    #[test]
    fn the_holding_tension_is_the_floor_while_the_way_is_off() {
        let p = ShipMpcParams::default();
        assert!(p.holding_tension > p.min_tension);
        assert_eq!(p.tension_floor(false, 0.1, 1.0), p.min_tension);
        assert_eq!(p.tension_floor(true, 0.1, 1.0), p.holding_tension);
        // One sample of 0.1 s raises it by tension_rate * 0.1 only.
        let reach = p.min_tension + p.tension_rate * 0.1;
        assert!((p.tension_floor(true, 0.0, 0.1) - reach).abs() < 1e-12);
        let low = ShipMpcParams {
            holding_tension: 0.0,
            ..p
        };
        assert_eq!(low.tension_floor(true, 0.1, 1.0), p.min_tension);
        let high = ShipMpcParams {
            holding_tension: 10.0,
            ..p
        };
        assert_eq!(high.tension_floor(true, 2.9, 1.0), p.max_tension);
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
            *poses = [mpc.problem().formation().tug_reference([0.0; 3], 0.0, i); HORIZON];
        }
        ShipStepData {
            state: [0.0; 6],
            previous: [0.0; 4],
            reference: [reference; HORIZON],
            tug_poses,
            lambda: [[[0.0; 3]; HORIZON]; 2],
            rho,
            obstacles: &[],
            distance_cost_off: 0,
            heading_floor: None,
            max_surge: None,
            waterway: None,
        }
    }

    fn check_feasible(mpc: &ShipMpc, previous: &ShipInput) -> Result<(), String> {
        let p = mpc.problem().params();
        let tol = 1e-9;
        let mut before = *previous;
        for k in 0..4 {
            let (lo, hi, _) = mpc.problem().params().channel_limits(k, 1.0);
            before[k] = before[k].clamp(lo, hi);
        }
        for u in &mpc.inputs() {
            for k in 0..4 {
                let (lo, hi, rate) = mpc.problem().params().channel_limits(k, 1.0);
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
            mpc.set_inputs([[f1 + 1.0, f2 - 1.0, a1 * 2.0, -a2]; HORIZON]);
            for _ in 0..4 {
                let report = mpc.step(&data);
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
            let report = mpc.step(&data);
            assert!(report.qp.is_usable(), "{report:?}");
            let now = mpc.cost(mpc.plan(), &data);
            assert!(now <= last + 1e-12, "{now} > {last}");
            last = now;
            check_feasible(&mpc, &data.previous).unwrap();
        }
        // The first move pulls ahead harder than astern (the last sample may brake:
        // the velocity weight w_S2 = 75 prices the speed left at the horizon).
        let plan = mpc.inputs();
        assert!(plan[0][1] > plan[0][0] + 0.1, "{plan:?}");
        let total = |k: usize| plan.iter().map(|u| u[k]).sum::<f64>();
        assert!(total(1) > total(0), "{plan:?}");
        let states = mpc.predicted();
        assert!(states[HORIZON - 1][0] > 0.0 && states[HORIZON - 1][3] > 0.0);
    }

    /// A reference astern, and one abeam: without the motion limits the plan backs
    /// the ship and drags her sideways beyond them; with them the predicted sternway
    /// and drift stay inside (to the slack the exact penalty leaves, below 1 mm/s).
    #[test]
    fn motion_limits_keep_the_plan_from_sternway_and_sideways_motion() {
        let worst = |params: ShipMpcParams, reference: [f64; 3]| {
            let mut mpc = ship_mpc_with(params);
            let data = data_at_rest(&mpc, reference, 0.0);
            for _ in 0..40 {
                assert!(mpc.step(&data).qp.is_usable());
            }
            let m = params.motion;
            let t = m.max_drift.tan();
            mpc.predicted().iter().fold(0.0f64, |w, x| {
                let drift = x[4].abs() - (t * x[3] + m.sway_allowance);
                let astern = -x[3] - m.max_sternway;
                w.max(drift).max(astern)
            })
        };
        let on = ShipMpcParams::default();
        let off = ShipMpcParams {
            motion: MotionLimits {
                penalty: 0.0,
                ..on.motion
            },
            ..on
        };
        for reference in [[-2.0, 0.0, 0.0], [0.0, 2.0, 0.0]] {
            let (with, without) = (worst(on, reference), worst(off, reference));
            assert!(with < 1e-3, "{reference:?}: {with} m/s beyond the limits");
            assert!(without > 5e-3, "{reference:?}: {without} m/s without them");
        }
    }

    /// A cap on the surge (the way kept off while giving way): the ship under way at
    /// 0.05 m/s with her reference 10 m ahead gathers way without it; with the cap at her
    /// own speed no predicted surge exceeds it (to the slack the exact penalty leaves).
    #[test]
    fn a_surge_cap_keeps_the_plan_from_gathering_way() {
        let fastest = |max_surge: Option<f64>| {
            let mut mpc = ship_mpc_with(ShipMpcParams::default());
            let mut data = data_at_rest(&mpc, [10.0, 0.0, 0.0], 0.0);
            data.state[3] = 0.05;
            data.max_surge = max_surge;
            for _ in 0..40 {
                assert!(mpc.step(&data).qp.is_usable());
            }
            mpc.predicted()
                .iter()
                .map(|x| x[3])
                .fold(f64::NEG_INFINITY, f64::max)
        };
        let (with, without) = (fastest(Some(0.05)), fastest(None));
        assert!(with < 0.05 + 1e-3, "{with} m/s with the cap");
        assert!(without > 0.05 + 5e-3, "{without} m/s without it");
        let limits = MotionLimits::default();
        assert_eq!(limits.capped(None), limits);
        assert_eq!(limits.capped(Some(1.0)), limits);
        assert_eq!(limits.capped(Some(0.04)).max_speed, 0.04);
    }

    /// The ship at the edge of its lane (its clearance from the bank just the margin) and a
    /// reference beyond the bank: without the bank rows the plan moves her out; with them
    /// every predicted position keeps the margin (to the slack the exact penalty leaves).
    #[test]
    fn the_bank_rows_keep_the_ship_inside_the_waterway() {
        use towing_model::geometry::{Lane, Polyline};
        let margin = 0.744;
        // The route runs North 0.25 m to port of the ship: clearance = half width - 0.25.
        let lane = Lane::new(
            Polyline::new(vec![[-10.0, -0.25], [10.0, -0.25]]).unwrap(),
            0.25 + margin,
        );
        let beyond = |waterway: Option<Waterway<'_>>| {
            let mut mpc = ship_mpc_with(ShipMpcParams {
                waterway_rows: true,
                ..ShipMpcParams::default()
            });
            let mut data = data_at_rest(&mpc, [1.0, 3.0, 0.0], 0.0);
            data.waterway = waterway;
            for _ in 0..40 {
                assert!(mpc.step(&data).qp.is_usable());
            }
            mpc.predicted()
                .iter()
                .map(|x| lane.excess([x[0], x[1]]) + margin)
                .fold(f64::NEG_INFINITY, f64::max)
        };
        let waterway = Waterway {
            lane: &lane,
            margin: [margin, 0.608, 0.608],
        };
        let (with, without) = (beyond(Some(waterway)), beyond(None));
        assert!(with < 1e-3, "{with} m beyond the margin");
        assert!(
            without > 5e-3,
            "{without} m beyond the margin without the rows"
        );
    }

    /// A reference to port turns the ship to port; a heading floor at the
    /// current heading keeps its predicted headings (nearly) to starboard of it,
    /// and a floor below every predicted heading changes nothing.
    #[test]
    fn a_heading_floor_stops_a_turn_to_port() {
        let run = |floor: Option<f64>| {
            // Table 3's heading weight: the floor's weight 1e4 against a pull of 1.
            let mut mpc = ship_mpc_with(ShipMpcParams {
                weight_port_turn: 1e4,
                weight_heading: 1.0,
                ..ShipMpcParams::default()
            });
            let mut data = data_at_rest(&mpc, [1.0, -1.0, -0.5], 0.0);
            data.heading_floor = floor;
            for _ in 0..40 {
                assert!(mpc.step(&data).qp.is_usable());
            }
            mpc.predicted().map(|x| x[2])
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
            mpc.set_inputs([[1.0, 1.0, 0.0, 0.0]; HORIZON]);
            data.previous = [1.0, 1.0, 0.0, 0.0];
            for _ in 0..30 {
                assert!(mpc.step(&data).qp.is_usable());
            }
            mpc.inputs()
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
            let defaults = ShipMpcParams::default();
            let params = ShipMpcParams {
                weight_distance: 0.0,
                clearance: ClearanceParams {
                    max_obstacles,
                    ..defaults.clearance
                },
                ..defaults
            };
            let mut mpc = ship_mpc_with(params);
            let mut data = data_at_rest(&mpc, [3.0, 0.0, 0.0], 0.0);
            data.obstacles = &obstacles;
            data.previous = [0.0; 4]; // at rest, lines slack: holding still is feasible

            for _ in 0..40 {
                let report = mpc.step(&data);
                assert!(report.qp.is_usable(), "{report:?}");
                check_feasible(&mpc, &data.previous).unwrap();
            }
            mpc.predicted()
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
