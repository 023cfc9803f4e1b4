//! The configuration map of Du et al. (2022) eq. (4)-(7) in the consistent form of
//! `paper/NOTES.md` section 1: the desired tug pose `eta_id` as a function of the
//! ship's pose and the towing angle, i.e. `f_i(tau_S)` of eq. (23) when applied to
//! the ship model's predicted trajectory.
//!
//! The pose is the plant's [`formation_pose`] (the function `Scenario::place_tugs`
//! places the tugs with): tug 2 at `bow + (l_tow2 + l_T2) (cos, sin)(psi_S +
//! alpha_2)`, tug 1 at `stern - (l_tow1 + l_T1) (cos, sin)(psi_S + alpha_1)`, heading
//! `psi_S + alpha_i` (tug angle `beta_i = 0` in eq. (7)). One deviation: the heading
//! is returned unwrapped, `psi_S + alpha_i`, consistent with the models' continuous
//! headings; `formation_pose` wraps it to `(-pi, pi]` (equal modulo `2 pi`).

use nalgebra::Matrix3x4;
use towing_model::geometry::body_to_ned;
use towing_model::towline::formation_pose;
use towing_model::{ParamError, Scenario, VesselData};

use crate::obstacle::Obstacle;
use crate::ship::{ShipInput, ShipState};
use crate::HORIZON;

/// Desired tug poses from the ship's pose and towing angles (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FormationMap {
    ship: VesselData,
    tugs: [VesselData; 2],
    desired_length: [f64; 2],
}

impl FormationMap {
    /// A hull as the other vessels of the tow keep clear of it (`docs/controller-design.md`,
    /// "Tug local MPCs"): the ellipse through the corners of its `L x B` rectangle
    /// (semi-axes `L / sqrt 2`, `B / sqrt 2`, the smallest ellipse of the hull's aspect
    /// that contains it) at `pose` `[x, y, psi]`, moving by `drift` per sample, heading
    /// held (the constant-velocity motion [`Obstacle::after`] predicts). `vessel`: 0 the
    /// ship, `1 + i` tug `i`.
    #[must_use]
    pub fn hull(&self, vessel: usize, pose: [f64; 3], drift: [f64; 2]) -> Obstacle {
        let data = if vessel == 0 {
            &self.ship
        } else {
            &self.tugs[vessel - 1]
        };
        Obstacle::Ellipse {
            centre: [pose[0], pose[1]],
            semi_major: data.length * std::f64::consts::FRAC_1_SQRT_2,
            semi_minor: data.width.min(data.length) * std::f64::consts::FRAC_1_SQRT_2,
            orientation: pose[2],
            drift,
        }
    }

    /// The ship's hull as the tugs' local problems keep clear of it ([`FormationMap::hull`])
    /// at the ship's present pose `ship`, moving by the mean displacement per sample of
    /// the coordination's predicted trajectory `predicted`.
    #[must_use]
    pub fn ship_obstacle(&self, ship: &ShipState, predicted: &[ShipState; HORIZON]) -> Obstacle {
        let last = predicted[HORIZON - 1];
        let k = HORIZON as f64;
        let drift = [(last[0] - ship[0]) / k, (last[1] - ship[1]) / k];
        self.hull(0, [ship[0], ship[1], ship[2]], drift)
    }

    /// Tug `i`'s hull as the other tug's local problem keeps clear of it
    /// ([`FormationMap::hull`]) at its present state `tug` `[x, y, psi, u, v, r]`, moving
    /// at its present velocity over ground for `sample_time` per sample (constant
    /// velocity, as the targets are predicted). The two tugs plan in parallel, so each
    /// sees the other where it is and where it is going, not where the other's new plan
    /// will take it.
    #[must_use]
    pub fn tug_obstacle(&self, i: usize, tug: &[f64; 6], sample_time: f64) -> Obstacle {
        // The body velocity over a sample, rotated into NED.
        let drift = body_to_ned(0.0, 0.0, tug[2], tug[3] * sample_time, tug[4] * sample_time);
        self.hull(1 + i, [tug[0], tug[1], tug[2]], drift)
    }

    /// The map for a ship, the two tugs (0 = tug 1 aft, 1 = tug 2 forward) and the
    /// desired line lengths `l_tow1`, `l_tow2` (m, attachment point to attachment
    /// point, finite and > 0). The vessel data are validated.
    pub fn new(
        ship: &VesselData,
        tugs: &[VesselData; 2],
        desired_length: [f64; 2],
    ) -> Result<FormationMap, ParamError> {
        ship.validate().map_err(|e| e.within("ship"))?;
        for (i, tug) in tugs.iter().enumerate() {
            tug.validate()
                .map_err(|e| e.within(&format!("tug{}", i + 1)))?;
        }
        for (i, l) in desired_length.iter().enumerate() {
            if !(l.is_finite() && *l > 0.0) {
                return Err(ParamError {
                    field: format!("towline{}.desired_length", i + 1),
                    reason: format!("must be finite and > 0 m, got {l} m"),
                });
            }
        }
        Ok(FormationMap {
            ship: *ship,
            tugs: *tugs,
            desired_length,
        })
    }

    /// The map of a scenario (its vessel data and `towline_desired_length`).
    pub fn from_scenario(scenario: &Scenario) -> Result<FormationMap, ParamError> {
        FormationMap::new(
            &scenario.ship_data,
            &scenario.tug_data,
            scenario.towline_desired_length,
        )
    }

    /// Desired pose `[x, y, psi]` of the tug on towline `line` (0 = tug 1, 1 =
    /// tug 2) for the ship at `ship_eta` and towing angle `alpha` (rad): eq. (4) via
    /// the plant's [`formation_pose`], heading unwrapped (module docs).
    ///
    /// # Panics
    /// If `line > 1`.
    #[must_use]
    pub fn tug_reference(&self, ship_eta: [f64; 3], alpha: f64, line: usize) -> [f64; 3] {
        let pose = formation_pose(
            line,
            &ship_eta,
            &self.ship,
            &self.tugs[line],
            self.desired_length[line],
            alpha,
        );
        [pose[0], pose[1], ship_eta[2] + alpha]
    }

    /// [`FormationMap::tug_reference`] and its Jacobian w.r.t. `[x_S, y_S, psi_S,
    /// alpha]` (3x4). With `p = ship + x_a (cos, sin)(psi_S) + s d (cos, sin)(psi_S +
    /// alpha)` (`x_a` the ship's towing point, `s = -1, d = l_tow1 + l_T1` for tug 1,
    /// `s = +1, d = l_tow2 + l_T2` for tug 2).
    ///
    /// # Panics
    /// If `line > 1`.
    #[must_use]
    pub fn tug_reference_linearised(
        &self,
        ship_eta: [f64; 3],
        alpha: f64,
        line: usize,
    ) -> ([f64; 3], Matrix3x4<f64>) {
        let pose = self.tug_reference(ship_eta, alpha, line);
        let (x_a, side, reach) = match line {
            0 => (
                self.ship.stern_tow_point_x,
                -1.0,
                self.desired_length[0] + self.tugs[0].bow_tow_point_x,
            ),
            _ => (
                self.ship.bow_tow_point_x,
                1.0,
                self.desired_length[1] - self.tugs[1].stern_tow_point_x,
            ),
        };
        let (s, c) = ship_eta[2].sin_cos();
        let (sh, ch) = (ship_eta[2] + alpha).sin_cos();
        let d_alpha = [-side * reach * sh, side * reach * ch];
        #[rustfmt::skip]
        let jac = Matrix3x4::new(
            1.0, 0.0, -x_a * s + d_alpha[0], d_alpha[0],
            0.0, 1.0, x_a * c + d_alpha[1], d_alpha[1],
            0.0, 0.0, 1.0, 1.0,
        );
        (pose, jac)
    }

    /// The desired poses of the tug on `line` along a predicted ship trajectory:
    /// `out[k] = tug_reference(eta of ship_states[k], alpha_i of inputs[k], line)`,
    /// pairing the state after sample `k` with the towing angle held over sample
    /// `k` (the layout of [`crate::ShipModel::rollout`]: `ship_states[k] = x(k + 1)`
    /// reached with `inputs[k]`). Allocation-free.
    ///
    /// # Panics
    /// If `line > 1` or the slices differ in length.
    pub fn tug_references_into(
        &self,
        line: usize,
        ship_states: &[ShipState],
        inputs: &[ShipInput],
        out: &mut [[f64; 3]],
    ) {
        assert!(line < 2, "towline index {line} out of range");
        assert!(
            ship_states.len() == out.len() && inputs.len() == out.len(),
            "trajectory, input and output lengths differ"
        );
        for ((x, u), slot) in ship_states.iter().zip(inputs).zip(out) {
            *slot = self.tug_reference([x[0], x[1], x[2]], u[2 + line], line);
        }
    }
}
