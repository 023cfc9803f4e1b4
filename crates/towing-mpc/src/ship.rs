//! The coordination controller's ship model (Du et al. 2022, eq. (15), in the
//! consistent form of `paper/NOTES.md`).
//!
//! State `x_S = [x, y, psi, u, v, r]` (m, m, rad, m/s, m/s, rad/s; NED pose, body
//! velocities), input `u_S = [F_1, F_2, alpha_1, alpha_2]` (N, N, rad, rad): the
//! two towline tensions and towing angles (`tau_S` of the paper). The dynamics are
//!
//! ```text
//! eta_dot = R(psi) nu
//! nu_dot  = M^-1 (tau_S(u_S) - C(nu) nu - D(nu) nu)     (the plant's HullDynamics)
//! ```
//!
//! with `tau_S` the loads the plant applies when each line points along its towing
//! angle ([`crate::lines`]): line 2 pulls the bow point towards `psi + alpha_2`
//! with `F_2`, line 1 pulls the stern point towards the aft tug, along
//! `psi + alpha_1 + pi`, with `F_1`; moments `r x F` from the attachment points.
//! The printed signs of eq. (2)/(15) are not used (NOTES.md section 1). In the body
//! frame `tau_S` depends on `u_S` only, so it is constant over a sample.
//!
//! Discretisation: zero-order hold over `T_s`, fixed-step RK4 ([`PredictionParams`]).
//! The heading is not wrapped (a continuous `psi` keeps the linearisations and the
//! heading references of an optimiser free of `2 pi` jumps); wrap it for display.
//!
//! What the model does not do that the plant does: it does not clamp `F_i` to
//! `[0, F_max]` or treat a line as slack; the optimiser's constraints (eq. (17)-(21))
//! keep the inputs in range. And the plant's towing angles follow the geometry
//! during the sample, while the model holds `alpha_i` relative to the ship: this is
//! the model's only approximation with the same hull (measured in
//! `tests/plant_agreement.rs`).

use nalgebra::{Matrix3x4, Matrix6, Matrix6x4};
use towing_model::{HullModel, ParamError, Scenario, VesselData};

use crate::hull::PredictionHull;
use crate::lines::{line_direction, loads_along, turned};
use crate::params::{PredictionParams, Substeps};
use crate::rk4::{self, StageJacobian};

/// Ship state `[x, y, psi, u, v, r]` (m, m, rad, m/s, m/s, rad/s).
pub type ShipState = [f64; 6];

/// Ship input `[F_1, F_2, alpha_1, alpha_2]` (N, N, rad, rad).
pub type ShipInput = [f64; 4];

/// One linearised sample of the ship model: `x_next = step(x, u)` and the
/// Jacobians `a = d x_next / d x`, `b = d x_next / d u`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShipLinearisation {
    /// `step(x, u)`.
    pub x_next: ShipState,
    /// `d x_next / d x` (6x6).
    pub a: Matrix6<f64>,
    /// `d x_next / d u` (6x4), columns `F_1, F_2, alpha_1, alpha_2`.
    pub b: Matrix6x4<f64>,
}

impl Default for ShipLinearisation {
    /// Zeros (a buffer to fill).
    fn default() -> Self {
        ShipLinearisation {
            x_next: [0.0; 6],
            a: Matrix6::zeros(),
            b: Matrix6x4::zeros(),
        }
    }
}

/// The ship's prediction model (module docs).
#[derive(Debug, Clone)]
pub struct ShipModel {
    hull: PredictionHull,
    /// Body x of the ship's towing points (m, from CO): `[stern (towline 1), bow
    /// (towline 2)]`.
    tow_point_x: [f64; 2],
    params: PredictionParams,
    substeps: Substeps,
}

impl ShipModel {
    /// The model with the built-in hull `hull_model` of `ship` (the plant's
    /// [`HullModel::build`]) and analytic Jacobians.
    pub fn new(
        hull_model: HullModel,
        ship: &VesselData,
        params: PredictionParams,
    ) -> Result<ShipModel, ParamError> {
        ShipModel::with_hull(PredictionHull::new(hull_model, ship)?, ship, params)
    }

    /// The model of the scenario's ship.
    pub fn from_scenario(
        scenario: &Scenario,
        hull_model: HullModel,
        params: PredictionParams,
    ) -> Result<ShipModel, ParamError> {
        ShipModel::new(hull_model, &scenario.ship_data, params)
    }

    /// The model with any hull (e.g. [`PredictionHull::custom`]); `ship` gives the
    /// towing points and is validated.
    pub fn with_hull(
        hull: PredictionHull,
        ship: &VesselData,
        params: PredictionParams,
    ) -> Result<ShipModel, ParamError> {
        ship.validate()?;
        Ok(ShipModel {
            hull,
            tow_point_x: [ship.stern_tow_point_x, ship.bow_tow_point_x],
            substeps: params.discretise()?,
            params,
        })
    }

    /// The discretisation.
    #[must_use]
    pub fn params(&self) -> &PredictionParams {
        &self.params
    }

    /// The hull kinetics.
    #[must_use]
    pub fn hull(&self) -> &PredictionHull {
        &self.hull
    }

    /// `tau_S(u_S)`: the towlines' generalised force on the ship in its body frame
    /// `[X, Y, N]` (N, N, N m), summed in the plant's order (towline 1, then 2).
    #[must_use]
    pub fn towline_loads(&self, u: &ShipInput) -> [f64; 3] {
        let mut tau = [0.0; 3];
        for line in 0..2 {
            let e = line_direction(line, u[2 + line]);
            let loads = loads_along(e, 0.0, self.tow_point_x[line], 0.0, 0.0, u[line]);
            for (t, l) in tau.iter_mut().zip(loads.on_ship) {
                *t += l;
            }
        }
        tau
    }

    /// `tau_S(u_S)` and `d tau_S / d u_S` (3x4).
    fn towline_loads_linearised(&self, u: &ShipInput) -> ([f64; 3], Matrix3x4<f64>) {
        let mut jac = Matrix3x4::zeros();
        for line in 0..2 {
            let e = line_direction(line, u[2 + line]);
            let xs = self.tow_point_x[line];
            let per_newton = loads_along(e, 0.0, xs, 0.0, 0.0, 1.0).on_ship;
            let turning = loads_along(turned(e), 0.0, xs, 0.0, 0.0, u[line]).on_ship;
            for k in 0..3 {
                jac[(k, line)] = per_newton[k];
                jac[(k, 2 + line)] = turning[k];
            }
        }
        (self.towline_loads(u), jac)
    }

    /// The continuous dynamics `dx/dt = f(x, u)`.
    #[must_use]
    pub fn derivative(&self, x: &ShipState, u: &ShipInput) -> ShipState {
        self.derivative_with_loads(x, &self.towline_loads(u))
    }

    #[inline]
    fn derivative_with_loads(&self, x: &ShipState, tau: &[f64; 3]) -> ShipState {
        self.derivative_at(x, x[2].sin_cos(), tau)
    }

    /// [`ShipModel::derivative_with_loads`] with `(s, c) = x[2].sin_cos()` given.
    #[inline(always)]
    fn derivative_at(&self, x: &ShipState, (s, c): (f64, f64), tau: &[f64; 3]) -> ShipState {
        let nu_dot = self.hull.nu_dot(&[x[3], x[4], x[5]], tau);
        // eta_dot = R(psi) nu, written out as the plant's derivative does.
        [
            c * x[3] - s * x[4],
            s * x[3] + c * x[4],
            x[5],
            nu_dot[0],
            nu_dot[1],
            nu_dot[2],
        ]
    }

    /// One sample: the state after `T_s` with `u` held. Allocation-free.
    #[must_use]
    pub fn step(&self, x: &ShipState, u: &ShipInput) -> ShipState {
        let tau = self.towline_loads(u);
        rk4::integrate(
            |x| self.derivative_with_loads(x, &tau),
            x,
            self.substeps.n,
            self.substeps.h,
        )
    }

    /// One sample and its exact Jacobians (the RK4 recursion differentiated,
    /// see the crate docs); `x_next` equals [`ShipModel::step`] bit for bit.
    /// Allocation-free.
    #[must_use]
    pub fn step_linearised(&self, x: &ShipState, u: &ShipInput) -> ShipLinearisation {
        let (tau, dtau) = self.towline_loads_linearised(u);
        // d nu_dot / d u = M^-1 d tau / d u, constant over the sample; the body-frame
        // loads do not depend on the state, so d nu_dot / d psi = 0.
        let dnu_du = self.hull.mass_matrix_inv() * dtau;
        let nu_p: [[f64; 3]; 4] =
            std::array::from_fn(|k| [dnu_du[(0, k)], dnu_du[(1, k)], dnu_du[(2, k)]]);
        let (x_next, a, b) = rk4::integrate_linearised(
            |x| {
                let sin_cos = x[2].sin_cos();
                let f = self.derivative_at(x, sin_cos, &tau);
                let j = self.hull.nu_dot_jacobian(&[x[3], x[4], x[5]], &tau);
                (f, StageJacobian::new(x, sin_cos, [0.0; 3], j, nu_p))
            },
            x,
            self.substeps.n,
            self.substeps.h,
        );
        ShipLinearisation { x_next, a, b }
    }

    /// The RK4 stage points of one sample (test support: where the `|.|` kinks of
    /// the damping are crossed).
    #[cfg(test)]
    pub(crate) fn stage_points(&self, x: &ShipState, u: &ShipInput) -> Vec<ShipState> {
        let tau = self.towline_loads(u);
        let mut points = Vec::new();
        let _ = rk4::integrate(
            |x| {
                points.push(*x);
                self.derivative_with_loads(x, &tau)
            },
            x,
            self.substeps.n,
            self.substeps.h,
        );
        points
    }

    /// The states after each of `H` samples, `inputs[k]` held over sample `k`:
    /// `out[k] = x(k + 1)`. Equal to repeated [`ShipModel::step`]; allocation-free
    /// (fixed-size arrays on the stack).
    #[must_use]
    pub fn rollout<const H: usize>(
        &self,
        x0: &ShipState,
        inputs: &[ShipInput; H],
    ) -> [ShipState; H] {
        let mut out = [[0.0; 6]; H];
        self.rollout_into(x0, inputs, &mut out);
        out
    }

    /// [`ShipModel::rollout`] into a caller's buffer (any horizon).
    ///
    /// # Panics
    /// If `out.len() != inputs.len()`.
    pub fn rollout_into(&self, x0: &ShipState, inputs: &[ShipInput], out: &mut [ShipState]) {
        assert_eq!(
            inputs.len(),
            out.len(),
            "rollout buffer length differs from the number of inputs"
        );
        let mut x = *x0;
        for (u, slot) in inputs.iter().zip(out) {
            x = self.step(&x, u);
            *slot = x;
        }
    }

    /// The rollout with each sample linearised at the predicted state it starts
    /// from (`out[k]` at `(x(k), inputs[k])`, `out[k].x_next = x(k + 1)`): the
    /// linear time-varying model of one sequential-convex-programming iteration.
    /// Allocation-free.
    ///
    /// # Panics
    /// If `out.len() != inputs.len()`.
    pub fn linearise_rollout_into(
        &self,
        x0: &ShipState,
        inputs: &[ShipInput],
        out: &mut [ShipLinearisation],
    ) {
        assert_eq!(
            inputs.len(),
            out.len(),
            "linearisation buffer length differs from the number of inputs"
        );
        let mut x = *x0;
        for (u, slot) in inputs.iter().zip(out) {
            *slot = self.step_linearised(&x, u);
            x = slot.x_next;
        }
    }
}
