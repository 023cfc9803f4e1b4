//! A tug local controller's model (Du et al. 2022, eq. (16)).
//!
//! State `x_i = [x, y, psi, u, v, r]` (m, m, rad, m/s, m/s, rad/s), input
//! `tau_Ti = [X, Y, N]` (N, N, N m; thruster forces in the tug's body frame), and an
//! exogenous [`TowlinePull`] per sample from the coordination plan: the tension
//! `F_i` and the line's world bearing `psi_S + alpha_i`, held over the sample. The
//! dynamics are
//!
//! ```text
//! eta_dot = R(psi) nu
//! nu_dot  = M^-1 (tau_Ti + tau_line(psi, F_i, bearing) - C(nu) nu - D(nu) nu)
//! ```
//!
//! with `tau_line` the reaction the plant applies: `-F_i e` at the tug's attachment
//! point (tug 1: bow, `+l_T1`; tug 2: stern, `-l_T2`), `e` the unit vector from the
//! ship's point to the tug's ([`crate::lines`]), moment `r x F`. This is eq. (3)'s
//! `B_i(beta_i) F_i` with `beta_i = alpha_i + psi_S - psi_i` of eq. (7), computed
//! from the geometry by the plant's `line_loads` rather than from the printed
//! matrix. The bearing is fixed in the world frame, so the load turns in the tug's
//! body frame as the tug yaws (the plant's behaviour at the start of the sample).
//!
//! Not applied, because the plant applies nothing else: the plant saturates the
//! thrust at the tug's limits (`max_surge_force`, ...), and the model does not; the
//! MPC keeps the commands inside the same bounds (eq. (19)), so saturation never
//! acts on a feasible plan and the model stays smooth for the linearisation. Neither
//! is the tension clamped to `[0, F_max]` (eq. (18) keeps it there).
//! Discretisation and heading convention as for the ship model
//! ([`crate::ship`]).

use nalgebra::{Matrix6, Matrix6x2, Matrix6x3, SMatrix, Vector3};
use towing_model::{HullModel, ParamError, Scenario, VesselData};

use crate::hull::PredictionHull;
use crate::lines::{line_direction, loads_along};
use crate::params::{PredictionParams, Substeps};
use crate::rk4::{self, StageJacobian};

/// Tug state `[x, y, psi, u, v, r]` (m, m, rad, m/s, m/s, rad/s).
pub type TugState = [f64; 6];

/// Tug thruster input `[X, Y, N]` (N, N, N m), body frame.
pub type TugInput = [f64; 3];

/// The towline as the coordination plan gives it to a tug for one sample.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct TowlinePull {
    /// Tension `F_i` (N).
    pub tension: f64,
    /// World bearing of the line taken from aft to forward (rad, from North,
    /// clockwise): `psi_S + alpha_i` for the plant's towing angle `alpha_i`.
    pub bearing: f64,
}

impl TowlinePull {
    /// The pull of a plan: tension `F_i`, towing angle `alpha_i` at ship heading
    /// `psi_S` (bearing `psi_S + alpha_i`).
    #[must_use]
    pub fn from_plan(tension: f64, ship_psi: f64, towing_angle: f64) -> TowlinePull {
        TowlinePull {
            tension,
            bearing: ship_psi + towing_angle,
        }
    }
}

/// One linearised sample of a tug model: `x_next = step(x, tau, pull)` and its
/// Jacobians.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TugLinearisation {
    /// `step(x, tau, pull)`.
    pub x_next: TugState,
    /// `d x_next / d x` (6x6).
    pub a: Matrix6<f64>,
    /// `d x_next / d tau` (6x3).
    pub b: Matrix6x3<f64>,
    /// `d x_next / d (tension, bearing)` (6x2).
    pub e: Matrix6x2<f64>,
}

impl Default for TugLinearisation {
    /// Zeros (a buffer to fill).
    fn default() -> Self {
        TugLinearisation {
            x_next: [0.0; 6],
            a: Matrix6::zeros(),
            b: Matrix6x3::zeros(),
            e: Matrix6x2::zeros(),
        }
    }
}

/// The model of one tug (module docs).
#[derive(Debug, Clone)]
pub struct TugModel {
    hull: PredictionHull,
    line: usize,
    /// Body x of the tug's towing point (m, from CO).
    tow_point_x: f64,
    params: PredictionParams,
    substeps: Substeps,
}

impl TugModel {
    /// The model of the tug on towline `line` (0 = tug 1, aft, towing from its
    /// bow; 1 = tug 2, forward, towing from its stern) with the built-in hull
    /// `hull_model` (the plant's [`HullModel::build`]) and analytic Jacobians.
    pub fn new(
        line: usize,
        hull_model: HullModel,
        tug: &VesselData,
        params: PredictionParams,
    ) -> Result<TugModel, ParamError> {
        TugModel::with_hull(line, PredictionHull::new(hull_model, tug)?, tug, params)
    }

    /// The model of the scenario's tug on towline `line`.
    pub fn from_scenario(
        scenario: &Scenario,
        line: usize,
        hull_model: HullModel,
        params: PredictionParams,
    ) -> Result<TugModel, ParamError> {
        let tug = scenario
            .tug_data
            .get(line)
            .ok_or_else(|| line_error(line))?;
        TugModel::new(line, hull_model, tug, params)
    }

    /// The model with any hull (e.g. [`PredictionHull::custom`]); `tug` gives the
    /// towing point and is validated.
    pub fn with_hull(
        line: usize,
        hull: PredictionHull,
        tug: &VesselData,
        params: PredictionParams,
    ) -> Result<TugModel, ParamError> {
        tug.validate()?;
        let tow_point_x = match line {
            0 => tug.bow_tow_point_x,
            1 => tug.stern_tow_point_x,
            _ => return Err(line_error(line)),
        };
        Ok(TugModel {
            hull,
            line,
            tow_point_x,
            substeps: params.discretise()?,
            params,
        })
    }

    /// The towline index (0 = tug 1 aft, 1 = tug 2 forward).
    #[must_use]
    pub fn line(&self) -> usize {
        self.line
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

    /// The towline's load on the tug at heading `psi`, `[X, Y, N]` in the tug's
    /// body frame (N, N, N m): the plant's `line_loads(..).on_tug`.
    #[must_use]
    pub fn towline_load(&self, psi: f64, pull: &TowlinePull) -> [f64; 3] {
        let e = line_direction(self.line, pull.bearing);
        loads_along(e, 0.0, 0.0, psi, self.tow_point_x, pull.tension).on_tug
    }

    /// The continuous dynamics `dx/dt = f(x, tau, pull)`.
    #[must_use]
    pub fn derivative(&self, x: &TugState, tau: &TugInput, pull: &TowlinePull) -> TugState {
        let e = line_direction(self.line, pull.bearing);
        self.derivative_along(x, tau, e, pull.tension)
    }

    #[inline]
    fn derivative_along(
        &self,
        x: &TugState,
        tau: &TugInput,
        e: [f64; 2],
        tension: f64,
    ) -> TugState {
        self.derivative_at(x, x[2].sin_cos(), tau, e, tension).0
    }

    /// [`TugModel::derivative_along`] with `(s, c) = x[2].sin_cos()` given; also
    /// returns the total force `tau + load`.
    #[inline(always)]
    fn derivative_at(
        &self,
        x: &TugState,
        (s, c): (f64, f64),
        tau: &TugInput,
        e: [f64; 2],
        tension: f64,
    ) -> (TugState, [f64; 3]) {
        let load = loads_along(e, 0.0, 0.0, x[2], self.tow_point_x, tension).on_tug;
        // Thrust first, then the line: the plant's summation order.
        let forces = [tau[0] + load[0], tau[1] + load[1], tau[2] + load[2]];
        let nu_dot = self.hull.nu_dot(&[x[3], x[4], x[5]], &forces);
        let f = [
            c * x[3] - s * x[4],
            s * x[3] + c * x[4],
            x[5],
            nu_dot[0],
            nu_dot[1],
            nu_dot[2],
        ];
        (f, forces)
    }

    /// One sample: the state after `T_s` with `tau` and `pull` held.
    /// Allocation-free.
    #[must_use]
    pub fn step(&self, x: &TugState, tau: &TugInput, pull: &TowlinePull) -> TugState {
        let e = line_direction(self.line, pull.bearing);
        rk4::integrate(
            |x| self.derivative_along(x, tau, e, pull.tension),
            x,
            self.substeps.n,
            self.substeps.h,
        )
    }

    /// One sample and its exact Jacobians w.r.t. the state, the thrust and the
    /// pull (the RK4 recursion differentiated, see the crate docs); `x_next` equals
    /// [`TugModel::step`] bit for bit. Allocation-free.
    #[must_use]
    pub fn step_linearised(
        &self,
        x: &TugState,
        tau: &TugInput,
        pull: &TowlinePull,
    ) -> TugLinearisation {
        let (x_next, a, p) = self.step_sensitivities::<5>(x, tau, pull);
        TugLinearisation {
            x_next,
            a,
            b: p.fixed_columns::<3>(0).into_owned(),
            e: p.fixed_columns::<2>(3).into_owned(),
        }
    }

    /// The step and its sensitivities to the state and to the first `NP` of the
    /// inputs `(X, Y, N, tension, bearing)`: `NP = 3` leaves out the pull columns
    /// (the other results are bit-identical, each column is integrated on its own).
    #[inline(always)]
    fn step_sensitivities<const NP: usize>(
        &self,
        x: &TugState,
        tau: &TugInput,
        pull: &TowlinePull,
    ) -> (TugState, Matrix6<f64>, SMatrix<f64, 6, NP>) {
        let e = line_direction(self.line, pull.bearing);
        let m_inv = *self.hull.mass_matrix_inv();
        let xt = self.tow_point_x;
        rk4::integrate_linearised::<NP, _>(
            |x| {
                let sin_cos = x[2].sin_cos();
                let (s, c) = sin_cos;
                let (f, forces) = self.derivative_at(x, sin_cos, tau, e, pull.tension);
                // The load per newton of tension in the body frame, R(psi)^T (-e) at
                // the towing point (what `line_loads` computes, its partials checked
                // against it by the tests), and its turn rate:
                // d load / d bearing = F [-Y_1, X_1, x_t X_1] = -d load / d psi.
                let g = [-e[0], -e[1]];
                let l1 = [c * g[0] + s * g[1], -s * g[0] + c * g[1]];
                let l1 = Vector3::new(l1[0], l1[1], xt * l1[1]);
                let f_t = pull.tension;
                let dl_db = Vector3::new(-f_t * l1[1], f_t * l1[0], f_t * xt * l1[0]);
                let j = self.hull.nu_dot_jacobian(&[x[3], x[4], x[5]], &forces);
                let col = |v: Vector3<f64>| [v[0], v[1], v[2]];
                let nu_p = std::array::from_fn(|k| match k {
                    0..=2 => col(m_inv.column(k).into_owned()),
                    3 => col(m_inv * l1),
                    _ => col(m_inv * dl_db),
                });
                (
                    f,
                    StageJacobian::new(x, sin_cos, col(m_inv * (-dl_db)), j, nu_p),
                )
            },
            x,
            self.substeps.n,
            self.substeps.h,
        )
    }

    /// The states after each of `H` samples, `tau[k]` and `pulls[k]` held over
    /// sample `k`: `out[k] = x(k + 1)`. Equal to repeated [`TugModel::step`];
    /// allocation-free.
    #[must_use]
    pub fn rollout<const H: usize>(
        &self,
        x0: &TugState,
        tau: &[TugInput; H],
        pulls: &[TowlinePull; H],
    ) -> [TugState; H] {
        let mut out = [[0.0; 6]; H];
        self.rollout_into(x0, tau, pulls, &mut out);
        out
    }

    /// [`TugModel::rollout`] into a caller's buffer (any horizon).
    ///
    /// # Panics
    /// If the three slices differ in length.
    pub fn rollout_into(
        &self,
        x0: &TugState,
        tau: &[TugInput],
        pulls: &[TowlinePull],
        out: &mut [TugState],
    ) {
        assert!(
            tau.len() == out.len() && pulls.len() == out.len(),
            "rollout buffer, thrust and pull lengths differ"
        );
        let mut x = *x0;
        for ((t, p), slot) in tau.iter().zip(pulls).zip(out) {
            x = self.step(&x, t, p);
            *slot = x;
        }
    }

    /// The rollout with each sample linearised at the predicted state it starts
    /// from (`out[k]` at `(x(k), tau[k], pulls[k])`). Allocation-free.
    ///
    /// # Panics
    /// If the three slices differ in length.
    pub fn linearise_rollout_into(
        &self,
        x0: &TugState,
        tau: &[TugInput],
        pulls: &[TowlinePull],
        out: &mut [TugLinearisation],
    ) {
        assert!(
            tau.len() == out.len() && pulls.len() == out.len(),
            "linearisation buffer, thrust and pull lengths differ"
        );
        let mut x = *x0;
        for ((t, p), slot) in tau.iter().zip(pulls).zip(out) {
            *slot = self.step_linearised(&x, t, p);
            x = slot.x_next;
        }
    }

    /// As [`TugModel::linearise_rollout_into`] without the pull sensitivities
    /// (`e` is left as it was; `x_next`, `a`, `b` are bit-identical): what the MPC
    /// uses, about a fifth less work.
    pub(crate) fn linearise_thrust_rollout_into(
        &self,
        x0: &TugState,
        tau: &[TugInput],
        pulls: &[TowlinePull],
        out: &mut [TugLinearisation],
    ) {
        let mut x = *x0;
        for ((t, p), slot) in tau.iter().zip(pulls).zip(out) {
            let (x_next, a, b) = self.step_sensitivities::<3>(&x, t, p);
            slot.x_next = x_next;
            slot.a = a;
            slot.b = b;
            x = x_next;
        }
    }
}

fn line_error(line: usize) -> ParamError {
    ParamError {
        field: "line".to_owned(),
        reason: format!("towline index {line} out of range (0 = tug 1 aft, 1 = tug 2 forward)"),
    }
}
