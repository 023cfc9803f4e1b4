//! The world: ship, two tugs and two towlines integrated jointly, plus the traffic.
//!
//! The state is the three vessels' `(eta, nu)` (Du et al. 2022, eq. (1) for each)
//! and, with the elastic line model, the two paid-out lengths `l0`. It is
//! integrated with the classical fixed-step Runge-Kutta method (RK4), with the
//! towline forces recomputed from the geometry at every stage, so the coupling is
//! as accurate as the vessels' own motion. A communication step `h` is split into
//! `n = ceil(h / integration_step)` equal substeps of `h / n`.
//!
//! Choice of the default `integration_step = 0.01 s`: the fastest time scales of
//! the default models are the elastic line's axial mode (stiffness 100 N/m against
//! an effective mass of about 3-10 kg at the attachment points: 3-6 rad/s, so
//! `omega h <= 0.06`), the winch loop (`k * winch_gain = 10 1/s`, `h / tau = 0.1`),
//! the tug's sway (`m22 / d22 = 66.1 / 21.9 = 3 s`) and yaw (set B: `2.31 / 3.87 =
//! 0.6 s`; set A: 22 s). RK4's stability limit (`|lambda h| < 2.8`) is far away and
//! its local error, of order `(lambda h)^5`, is negligible; the non-smooth events
//! (slack, winch speed limit) are resolved to 0.01 s. The bench
//! (`benches/world_step.rs`) puts a 0.1 s step at about 5 us, so accuracy costs
//! little. [`WorldConfig::validate`] refuses steps above
//! [`WorldConfig::MAX_INTEGRATION_STEP`].
//!
//! Steps are atomic: the state is integrated in a scratch copy and committed only
//! if every value is finite; otherwise [`World::step`] returns an error and the
//! world is unchanged (the plant FMU reports `fmi2Discard`). A step allocates
//! nothing.
//!
//! Traffic: target ships activated by time move analytically from their
//! `activation_time`, exactly, even when it falls inside a step. Target ships
//! with an `activation_range` are also checked at `t = 0` and at the end of
//! every step: the first time the ship's centre (its body origin CO) is within
//! the range of the spawn position, the target appears there with that time as
//! its activation time, unless the time trigger came first. The effective
//! activation times are dynamic state ([`World::activation_time`], saved by
//! [`World::write_state`]).
//!
//! The hulls' kinetics are [`HullDynamics`] trait objects, one per vessel, boxed
//! once at construction: [`World::new`] builds the built-in model that
//! [`WorldConfig::hull_model`] selects, [`World::with_hulls`] takes your own (see
//! [`crate::kinetics`] for how to implement one).

use nalgebra::{Matrix3, Vector3};
use thiserror::Error;

use crate::angle::wrap_angle;
use crate::geometry::{HullRect, Lane};
use crate::kinetics::{HullDynamics, HullModel};
use crate::scenario::{Scenario, ScenarioError};
use crate::towline::{
    self, clamp_command, elastic_params, elastic_tension, geometry_kin, ideal_winch_tension,
    loads_kin, winch_rate, ElasticTowlineParams, Kin, TowlineOutput,
};
use crate::traffic::{ObstacleShape, ObstacleSlot, TrafficObstacle};
use crate::vessel::{ParamError, VesselData};
use crate::MAX_OBSTACLES;

pub use crate::config::WorldConfig;
pub use crate::state::VesselState;

/// Largest number of RK4 substeps in one [`World::step`]; a larger `h /
/// integration_step` is refused as [`StepError::InvalidStep`] (at the default
/// 0.01 s this allows steps up to 10 000 s).
pub const MAX_SUBSTEPS: u64 = 1_000_000;

/// Inputs held constant over one step.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct WorldInputs {
    /// Generalised thruster forces of tug 1 (aft) and tug 2 (forward) in their body
    /// frames, `[surge N, sway N, yaw N m]`. Saturated at the tug's actuator limits
    /// (physics: the thrusters cannot do more).
    pub tug_tau: [[f64; 3]; 2],
    /// Tension commands of towline 1 and towline 2 (N), clamped to
    /// `[0, winch_max_tension]` of the tug's winch.
    pub tension_cmd: [f64; 2],
}

/// Why a step was refused. The world is unchanged after an error.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum StepError {
    /// An input or the integrated state was not finite.
    #[error("non-finite value in the step ({what}); the state was left unchanged")]
    NonFinite {
        /// Which input or state variable, e.g. `tug2.v` or `input tension_cmd[0]`.
        what: String,
    },
    /// The step size was not finite, not positive, or needs more than
    /// [`MAX_SUBSTEPS`] substeps.
    #[error(
        "invalid step size h = {0} s: must be finite, > 0 and at most {MAX_SUBSTEPS} integration steps"
    )]
    InvalidStep(f64),
}

/// Why a world could not be built.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum WorldError {
    /// The scenario does not validate.
    #[error(transparent)]
    Scenario(#[from] ScenarioError),
    /// The configuration does not validate.
    #[error("invalid world configuration: {0}")]
    Config(ParamError),
    /// A hull given to [`World::with_hulls`] breaks a property the world relies on
    /// (field path `hull.ship`, `hull.tug1` or `hull.tug2` plus the quantity).
    #[error("invalid hull model: {0}")]
    Hull(ParamError),
}

const NX: usize = 20;
type StateVec = [f64; NX];
const L0: usize = 18;
const STATE_NAMES: [&str; NX] = [
    "ship.x",
    "ship.y",
    "ship.psi",
    "ship.u",
    "ship.v",
    "ship.r",
    "tug1.x",
    "tug1.y",
    "tug1.psi",
    "tug1.u",
    "tug1.v",
    "tug1.r",
    "tug2.x",
    "tug2.y",
    "tug2.psi",
    "tug2.u",
    "tug2.v",
    "tug2.r",
    "towline1.paid_out_length",
    "towline2.paid_out_length",
];

const STATE_MAGIC: &[u8; 8] = b"TOWWORLD";
const STATE_VERSION: u32 = 2;
/// Size of [`World::write_state`]'s output (bytes).
pub const STATE_BYTES: usize = 8 + 4 + 8 + 8 * (1 + 18 + 2 + 2) + 2 + 8 * MAX_OBSTACLES;

/// Ship, tugs, towlines and traffic. See the module docs.
#[derive(Debug, Clone)]
pub struct World {
    config: WorldConfig,
    elastic: Option<ElasticTowlineParams>,
    /// Ship, tug 1, tug 2.
    data: [VesselData; 3],
    /// Kinetics of ship, tug 1, tug 2 (boxed once, at construction).
    hulls: [Box<dyn HullDynamics>; 3],
    /// Per line: `[ship point x, tug point x]` (body, from CO).
    points: [[f64; 2]; 2],
    winch_max: [f64; 2],
    tau_max: [[f64; 3]; 2],
    obstacles: Vec<TrafficObstacle>,
    /// The scenario's waterway (the bank the hulls are judged against).
    lane: Option<Lane>,
    fingerprint: u64,
    // Dynamic state.
    time: f64,
    vessels: [VesselState; 3],
    l0: [f64; 2],
    tension: [f64; 2],
    slack: [bool; 2],
    /// Effective activation time of each target-ship slot (s), once activated by
    /// time or range; `None` before, and always for static obstacles and empty
    /// slots.
    activated_at: [Option<f64>; MAX_OBSTACLES],
}

impl World {
    /// Builds the world at `t = 0` from a scenario (re-validated, since its fields
    /// are public) and a configuration, with the built-in hulls that
    /// `config.hull_model` selects ([`HullModel::build`] from the scenario's vessel
    /// data). With the elastic line, `l0` starts at the initial attachment distance
    /// (line just taut, zero tension).
    pub fn new(scenario: &Scenario, config: WorldConfig) -> Result<World, WorldError> {
        scenario.validate()?;
        config.validate().map_err(WorldError::Config)?;
        let data = vessel_data(scenario);
        let hull = |i: usize| {
            config.hull_model.build(&data[i]).map_err(|e| {
                WorldError::Scenario(ScenarioError::invalid(
                    &scenario.origin,
                    e.within(&format!("vessels.{}", VESSEL_NAMES[i])),
                ))
            })
        };
        let hulls = [hull(0)?, hull(1)?, hull(2)?];
        Ok(World::assemble(scenario, config, hulls))
    }

    /// Like [`World::new`], with your own hull models (see [`crate::kinetics`] for
    /// how to implement [`HullDynamics`]): `hulls[0]` is the ship, `hulls[1]` tug 1
    /// (aft), `hulls[2]` tug 2 (forward).
    ///
    /// The hulls replace only the kinetics (`M`, `C(nu)`, `D(nu)`, `nu_dot`): the
    /// scenario's vessel data still give the towing points, the actuator and winch
    /// limits and the dimensions (and are validated as usual), and
    /// `config.hull_model` is then only a label that enters the state fingerprint.
    /// Each hull is checked once: `M` finite, exactly symmetric and positive
    /// definite, `M^-1 M = I` to 1e-9, and at a few reference velocities `C(nu)`
    /// skew-symmetric (to 1e-9 relative), `D(nu)` and `nu_dot` finite; a failure is
    /// [`WorldError::Hull`].
    ///
    /// [`World::read_state`] accepts a saved state only from a world whose hulls
    /// have the same mass matrix and give the same `D(nu)` and `nu_dot` at those
    /// reference points (see [`World::write_state`]).
    pub fn with_hulls(
        scenario: &Scenario,
        config: WorldConfig,
        hulls: [Box<dyn HullDynamics>; 3],
    ) -> Result<World, WorldError> {
        scenario.validate()?;
        config.validate().map_err(WorldError::Config)?;
        for (i, hull) in hulls.iter().enumerate() {
            check_hull(&**hull)
                .map_err(|e| WorldError::Hull(e.within(&format!("hull.{}", VESSEL_NAMES[i]))))?;
        }
        Ok(World::assemble(scenario, config, hulls))
    }

    /// The world from validated parts.
    fn assemble(
        scenario: &Scenario,
        config: WorldConfig,
        hulls: [Box<dyn HullDynamics>; 3],
    ) -> World {
        let data = vessel_data(scenario);
        let points = [
            [data[0].stern_tow_point_x, data[1].bow_tow_point_x],
            [data[0].bow_tow_point_x, data[2].stern_tow_point_x],
        ];
        let tau_of = |d: &VesselData| [d.max_surge_force, d.max_sway_force, d.max_yaw_moment];
        let vessels = [
            normalised(scenario.ship),
            normalised(scenario.tugs[0]),
            normalised(scenario.tugs[1]),
        ];
        let mut world = World {
            config,
            elastic: elastic_params(&config.towline_model),
            data,
            hulls,
            points,
            winch_max: [data[1].winch_max_tension, data[2].winch_max_tension],
            tau_max: [tau_of(&data[1]), tau_of(&data[2])],
            obstacles: scenario.obstacles.clone(),
            lane: Lane::of_scenario(scenario),
            fingerprint: 0,
            time: 0.0,
            vessels,
            l0: [0.0; 2],
            tension: [0.0; 2],
            slack: [true; 2],
            activated_at: [None; MAX_OBSTACLES],
        };
        if world.elastic.is_some() {
            for line in 0..2 {
                world.l0[line] = world.line_geometry(line).length;
            }
        }
        world.fingerprint = world.compute_fingerprint();
        world.update_activations();
        world
    }

    /// Records the targets that become active at [`World::time`]: by time if
    /// `activation_time <= time` (with `activation_time` itself, so the motion
    /// stays exact), else by range if the ship's centre is within
    /// `activation_range` of the spawn position (with the current time).
    fn update_activations(&mut self) {
        let [x, y, _] = self.vessels[0].eta;
        for (slot, o) in self.obstacles.iter().enumerate() {
            if self.activated_at[slot].is_some() {
                continue;
            }
            let ObstacleShape::Vessel {
                activation_time,
                activation_range,
                ..
            } = o.shape
            else {
                continue;
            };
            if activation_time <= self.time {
                self.activated_at[slot] = Some(activation_time);
            } else if activation_range.is_some_and(|r| (o.x - x).hypot(o.y - y) <= r) {
                self.activated_at[slot] = Some(self.time);
            }
        }
    }

    /// Effective activation time (s) of the target ship in obstacle slot `slot`:
    /// its `activation_time` once that has passed, or the end of the step at which
    /// the ship came within its `activation_range`, whichever was first. `None`
    /// while it is not active, and for static obstacles and empty slots.
    ///
    /// # Panics
    /// If `slot >= MAX_OBSTACLES`.
    #[must_use]
    pub fn activation_time(&self, slot: usize) -> Option<f64> {
        assert!(
            slot < MAX_OBSTACLES,
            "obstacle slot {slot} out of range (0..{MAX_OBSTACLES})"
        );
        let by_time = self
            .obstacles
            .get(slot)
            .and_then(TrafficObstacle::activation_time)
            .filter(|&t_a| self.time >= t_a);
        match (by_time, self.activated_at[slot]) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        }
    }

    /// Simulation time (s): the sum of all committed step sizes.
    #[must_use]
    pub fn time(&self) -> f64 {
        self.time
    }

    /// The configuration the world was built with.
    #[must_use]
    pub fn config(&self) -> &WorldConfig {
        &self.config
    }

    /// The scenario's waterway, if it has one.
    #[must_use]
    pub fn lane(&self) -> Option<&Lane> {
        self.lane.as_ref()
    }

    /// How far each hull (ship, tug 1, tug 2) reaches beyond the bank of the
    /// scenario's waterway now ([`Lane::hull_excess`] of its footprint, the
    /// [`HullRect`] of its length and beam; positive: aground by that much, m);
    /// `None` without a waterway. The world has no physics of grounding: a hull
    /// beyond the bank keeps moving as in open water (`docs/assumptions.md`).
    #[must_use]
    pub fn bank_excess(&self) -> Option<[f64; 3]> {
        let lane = self.lane.as_ref()?;
        Some(std::array::from_fn(|k| {
            let [x, y, psi] = self.vessels[k].eta;
            lane.hull_excess(&HullRect::of(&self.data[k]), x, y, psi)
        }))
    }

    /// The ship's state.
    #[must_use]
    pub fn ship(&self) -> &VesselState {
        &self.vessels[0]
    }

    /// Tug `i`'s state: 0 = tug 1 (aft), 1 = tug 2 (forward).
    ///
    /// # Panics
    /// If `i > 1`.
    #[must_use]
    pub fn tug(&self, i: usize) -> &VesselState {
        assert!(
            i < 2,
            "tug index {i} out of range (0 = tug 1 aft, 1 = tug 2 forward)"
        );
        &self.vessels[1 + i]
    }

    /// The ship's parameters.
    #[must_use]
    pub fn ship_data(&self) -> &VesselData {
        &self.data[0]
    }

    /// Tug `i`'s parameters (0 = tug 1, 1 = tug 2).
    ///
    /// # Panics
    /// If `i > 1`.
    #[must_use]
    pub fn tug_data(&self, i: usize) -> &VesselData {
        assert!(
            i < 2,
            "tug index {i} out of range (0 = tug 1 aft, 1 = tug 2 forward)"
        );
        &self.data[1 + i]
    }

    /// The kinetics of vessel `index`: 0 ship, 1 tug 1 (aft), 2 tug 2 (forward)
    /// (the order of [`World::with_hulls`]).
    ///
    /// # Panics
    /// If `index > 2`.
    #[must_use]
    pub fn hull(&self, index: usize) -> &dyn HullDynamics {
        assert!(
            index < 3,
            "hull index {index} out of range (0 = ship, 1 = tug 1, 2 = tug 2)"
        );
        &*self.hulls[index]
    }

    /// The obstacles of the scenario (at most [`MAX_OBSTACLES`]).
    #[must_use]
    pub fn obstacles(&self) -> &[TrafficObstacle] {
        &self.obstacles
    }

    /// Towline `i` (0 = towline 1, stern <-> tug 1; 1 = towline 2, bow <-> tug 2):
    /// length and angle of the current geometry, tension and slack as of the end of
    /// the last step (see [`TowlineOutput`]).
    ///
    /// # Panics
    /// If `i > 1`.
    #[must_use]
    pub fn towline(&self, i: usize) -> TowlineOutput {
        assert!(
            i < 2,
            "towline index {i} out of range (0 = towline 1, 1 = towline 2)"
        );
        let g = self.line_geometry(i);
        TowlineOutput {
            length: g.length,
            angle: towline::towing_angle(i, g.ship_point, g.tug_point, self.vessels[0].eta[2]),
            tension: self.tension[i],
            slack: self.slack[i],
        }
    }

    /// Rate of change of towline `i`'s attachment distance (m/s).
    ///
    /// # Panics
    /// If `i > 1`.
    #[must_use]
    pub fn towline_length_rate(&self, i: usize) -> f64 {
        assert!(i < 2, "towline index {i} out of range");
        self.line_geometry(i).length_rate
    }

    /// Paid-out unstretched length `l0` of towline `i` (m) with the elastic model,
    /// `None` with the ideal winch.
    ///
    /// # Panics
    /// If `i > 1`.
    #[must_use]
    pub fn towline_paid_out_length(&self, i: usize) -> Option<f64> {
        assert!(i < 2, "towline index {i} out of range");
        self.elastic.map(|_| self.l0[i])
    }

    /// Obstacle slot `slot` (0..[`MAX_OBSTACLES`]) at [`World::time`], with the
    /// effective activation ([`World::activation_time`]); slots beyond the
    /// scenario's obstacles are [`ObstacleSlot::EMPTY`].
    ///
    /// # Panics
    /// If `slot >= MAX_OBSTACLES`.
    #[must_use]
    pub fn obstacle(&self, slot: usize) -> ObstacleSlot {
        assert!(
            slot < MAX_OBSTACLES,
            "obstacle slot {slot} out of range (0..{MAX_OBSTACLES})"
        );
        self.obstacles.get(slot).map_or(ObstacleSlot::EMPTY, |o| {
            o.output_activated(self.time, self.activation_time(slot))
        })
    }

    fn line_geometry(&self, line: usize) -> towline::LineGeometry {
        let ship = &self.vessels[0];
        let tug = &self.vessels[1 + line];
        geometry_kin(
            &Kin::new(ship.eta, ship.nu),
            self.points[line][0],
            &Kin::new(tug.eta, tug.nu),
            self.points[line][1],
        )
    }

    /// Advances the world by `h` seconds with the inputs held constant (zero-order
    /// hold). Atomic: on error nothing changes. Tug forces are saturated at the
    /// actuator limits and tension commands clamped to the winch range; non-finite
    /// inputs are refused, not clamped.
    pub fn step(&mut self, inputs: &WorldInputs, h: f64) -> Result<(), StepError> {
        if !(h.is_finite() && h > 0.0) {
            return Err(StepError::InvalidStep(h));
        }
        let ratio = h / self.config.integration_step;
        if ratio > MAX_SUBSTEPS as f64 {
            return Err(StepError::InvalidStep(h));
        }
        // The tolerance keeps e.g. 0.1 / 0.01 at 10 substeps despite rounding.
        let n = ((ratio - 1e-9).ceil() as u64).max(1);
        let hs = h / n as f64;

        let mut tau = [[0.0; 3]; 2];
        let mut cmd = [0.0; 2];
        for tug in 0..2 {
            for (k, saturated) in tau[tug].iter_mut().enumerate() {
                let value = inputs.tug_tau[tug][k];
                if !value.is_finite() {
                    return Err(StepError::NonFinite {
                        what: format!("input tug_tau[{tug}][{k}] = {value}"),
                    });
                }
                let limit = self.tau_max[tug][k];
                *saturated = value.max(-limit).min(limit);
            }
            let value = inputs.tension_cmd[tug];
            if !value.is_finite() {
                return Err(StepError::NonFinite {
                    what: format!("input tension_cmd[{tug}] = {value}"),
                });
            }
            cmd[tug] = clamp_command(value, self.winch_max[tug]);
        }

        let mut x = self.pack();
        let mut k1 = [0.0; NX];
        let mut k2 = [0.0; NX];
        let mut k3 = [0.0; NX];
        let mut k4 = [0.0; NX];
        let mut xt = [0.0; NX];
        for _ in 0..n {
            self.derivative(&x, &tau, &cmd, &mut k1);
            for i in 0..NX {
                xt[i] = x[i] + 0.5 * hs * k1[i];
            }
            self.derivative(&xt, &tau, &cmd, &mut k2);
            for i in 0..NX {
                xt[i] = x[i] + 0.5 * hs * k2[i];
            }
            self.derivative(&xt, &tau, &cmd, &mut k3);
            for i in 0..NX {
                xt[i] = x[i] + hs * k3[i];
            }
            self.derivative(&xt, &tau, &cmd, &mut k4);
            for i in 0..NX {
                x[i] += hs / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
            }
            if let Some(bad) = x.iter().position(|v| !v.is_finite()) {
                return Err(StepError::NonFinite {
                    what: format!("{} after integration", STATE_NAMES[bad]),
                });
            }
            for psi in [2, 8, 14] {
                x[psi] = wrap_angle(x[psi]);
            }
        }
        let time = self.time + h;
        // Commit, unless a towline's geometry or tension overflows (states far
        // apart but finite): the outputs must be finite too.
        let before = (self.vessels, self.l0);
        self.unpack(&x);
        let tension = match self.line_tensions(&cmd) {
            Ok(tension) => tension,
            Err(e) => {
                (self.vessels, self.l0) = before;
                return Err(e);
            }
        };
        self.time = time;
        self.tension = tension;
        self.slack = tension.map(|t| t <= 0.0);
        self.update_activations();
        Ok(())
    }

    /// Each towline's tension for the commands `cmd` in the current geometry;
    /// an error naming the line when its length, length rate, angle or
    /// tension is not finite.
    fn line_tensions(&self, cmd: &[f64; 2]) -> Result<[f64; 2], StepError> {
        let mut tension = [0.0; 2];
        for (line, &command) in cmd.iter().enumerate() {
            let g = self.line_geometry(line);
            let t = match &self.elastic {
                None => ideal_winch_tension(command, g.length),
                Some(p) => elastic_tension(p, g.length, g.length_rate, self.l0[line]),
            };
            let angle =
                towline::towing_angle(line, g.ship_point, g.tug_point, self.vessels[0].eta[2]);
            if let Some((name, value)) = [
                ("length", g.length),
                ("length rate", g.length_rate),
                ("angle", angle),
                ("tension", t),
            ]
            .into_iter()
            .find(|(_, v)| !v.is_finite())
            {
                return Err(StepError::NonFinite {
                    what: format!("towline{} {name} = {value} after integration", line + 1),
                });
            }
            tension[line] = t;
        }
        Ok(tension)
    }

    fn pack(&self) -> StateVec {
        let mut x = [0.0; NX];
        for (v, state) in self.vessels.iter().enumerate() {
            x[6 * v..6 * v + 3].copy_from_slice(&state.eta);
            x[6 * v + 3..6 * v + 6].copy_from_slice(&state.nu);
        }
        x[L0] = self.l0[0];
        x[L0 + 1] = self.l0[1];
        x
    }

    fn unpack(&mut self, x: &StateVec) {
        for (v, state) in self.vessels.iter_mut().enumerate() {
            state.eta.copy_from_slice(&x[6 * v..6 * v + 3]);
            state.nu.copy_from_slice(&x[6 * v + 3..6 * v + 6]);
        }
        if self.elastic.is_some() {
            self.l0 = [x[L0], x[L0 + 1]];
        }
    }

    /// `dx/dt` of the joint state; `cmd` is already clamped, `tau` saturated.
    #[inline]
    fn derivative(&self, x: &StateVec, tau: &[[f64; 3]; 2], cmd: &[f64; 2], dx: &mut StateVec) {
        let kin = |v: usize| {
            let o = 6 * v;
            Kin::new([x[o], x[o + 1], x[o + 2]], [x[o + 3], x[o + 4], x[o + 5]])
        };
        let k = [kin(0), kin(1), kin(2)];
        // [eta, nu] of vessel v are chunks 2 v and 2 v + 1.
        let (eta_nu, _) = x.as_chunks::<3>();
        let mut forces = [[0.0; 3], tau[0], tau[1]];
        for line in 0..2 {
            let tug = 1 + line;
            let [xs, xt] = self.points[line];
            let g = geometry_kin(&k[0], xs, &k[tug], xt);
            let tension = match &self.elastic {
                None => {
                    dx[L0 + line] = 0.0;
                    ideal_winch_tension(cmd[line], g.length)
                }
                Some(p) => {
                    let l0 = x[L0 + line];
                    let t = elastic_tension(p, g.length, g.length_rate, l0);
                    dx[L0 + line] = winch_rate(p, t, cmd[line], l0);
                    t
                }
            };
            if tension > 0.0 {
                let loads = loads_kin(&g, &k[0], xs, &k[tug], xt, tension);
                for (f, l) in forces[0].iter_mut().zip(loads.on_ship) {
                    *f += l;
                }
                for (f, l) in forces[tug].iter_mut().zip(loads.on_tug) {
                    *f += l;
                }
            }
        }
        for v in 0..3 {
            let o = 6 * v;
            let kv = &k[v];
            dx[o] = kv.c * kv.u - kv.s * kv.v;
            dx[o + 1] = kv.s * kv.u + kv.c * kv.v;
            dx[o + 2] = kv.r;
            // nu straight from the state (no fresh copy: see HullDynamics::nu_dot).
            let nu_dot = self.hulls[v].nu_dot(&eta_nu[2 * v + 1], &forces[v]);
            dx[o + 3] = nu_dot[0];
            dx[o + 4] = nu_dot[1];
            dx[o + 5] = nu_dot[2];
        }
    }

    /// Writes the dynamic state (time, the three vessels, the elastic lines'
    /// paid-out lengths, the applied tensions and slack flags, the targets'
    /// activation times) as versioned little-endian bytes, replacing `out`'s
    /// content. Layout (version 2):
    /// `b"TOWWORLD"`, `u32` version, `u64` fingerprint of the world's parameters,
    /// `f64` time, 3 x `[x, y, psi, u, v, r]` (ship, tug 1, tug 2), `f64 l0[2]`,
    /// `f64 tension[2]`, `u8 slack[2]`, `f64 activated_at[MAX_OBSTACLES]` (effective
    /// activation time per obstacle slot, NaN = not activated); [`STATE_BYTES`]
    /// bytes in all. Version 1 lacked `activated_at`.
    ///
    /// The fingerprint (FNV-1a) covers the configuration (including the
    /// `hull_model` label), the three vessels' data, the obstacles (including
    /// their `activation_time` and `activation_range`) and, per hull,
    /// its mass matrix and its `D(nu)` and `nu_dot(nu, tau)` at a fixed set of
    /// reference points (so it also tells apart user hulls from
    /// [`World::with_hulls`] that differ in `C`, `D` or `M^-1`). It is a check
    /// against loading a state into the wrong world, not a proof of equality: two
    /// hulls that agree at every reference point but differ elsewhere are not told
    /// apart.
    pub fn write_state(&self, out: &mut Vec<u8>) {
        out.clear();
        out.reserve(STATE_BYTES);
        out.extend_from_slice(STATE_MAGIC);
        out.extend_from_slice(&STATE_VERSION.to_le_bytes());
        out.extend_from_slice(&self.fingerprint.to_le_bytes());
        out.extend_from_slice(&self.time.to_le_bytes());
        for v in self.pack() {
            out.extend_from_slice(&v.to_le_bytes());
        }
        for t in self.tension {
            out.extend_from_slice(&t.to_le_bytes());
        }
        for s in self.slack {
            out.push(u8::from(s));
        }
        for a in self.activated_at {
            out.extend_from_slice(&a.unwrap_or(f64::NAN).to_le_bytes());
        }
    }

    /// Restores a state written by [`World::write_state`] on a world built from the
    /// same scenario and configuration (checked with a parameter fingerprint).
    /// Refuses wrong length, magic, version or fingerprint and non-finite or
    /// out-of-range values; on error the world is unchanged.
    pub fn read_state(&mut self, bytes: &[u8]) -> Result<(), String> {
        if bytes.len() != STATE_BYTES {
            return Err(format!(
                "state has {} bytes, expected {STATE_BYTES}",
                bytes.len()
            ));
        }
        if &bytes[..8] != STATE_MAGIC {
            return Err("not a towing-world state (bad magic)".to_owned());
        }
        let mut pos = 8;
        let mut take = |n: usize| {
            let s = &bytes[pos..pos + n];
            pos += n;
            s
        };
        let mut word4 = [0u8; 4];
        word4.copy_from_slice(take(4));
        let version = u32::from_le_bytes(word4);
        if version != STATE_VERSION {
            return Err(format!(
                "state format version {version}, this build reads version {STATE_VERSION}"
            ));
        }
        let mut word8 = [0u8; 8];
        word8.copy_from_slice(take(8));
        let fingerprint = u64::from_le_bytes(word8);
        if fingerprint != self.fingerprint {
            return Err(
                "state was written by a world with a different scenario or configuration"
                    .to_owned(),
            );
        }
        let mut read_f64 = || {
            let mut w = [0u8; 8];
            w.copy_from_slice(take(8));
            f64::from_le_bytes(w)
        };
        let time = read_f64();
        let mut x = [0.0; NX];
        for v in &mut x {
            *v = read_f64();
        }
        let tension = [read_f64(), read_f64()];
        let slack_bytes = [take(1)[0], take(1)[0]];
        let mut activated_raw = [0.0; MAX_OBSTACLES];
        for a in &mut activated_raw {
            let mut w = [0u8; 8];
            w.copy_from_slice(take(8));
            *a = f64::from_le_bytes(w);
        }
        if !time.is_finite() || time < 0.0 {
            return Err(format!("time {time} is not a finite value >= 0"));
        }
        if let Some(bad) = x.iter().position(|v| !v.is_finite()) {
            return Err(format!("{} is not finite", STATE_NAMES[bad]));
        }
        for psi in [2, 8, 14] {
            if !(x[psi] > -std::f64::consts::PI && x[psi] <= std::f64::consts::PI) {
                return Err(format!(
                    "{} = {} is outside (-pi, pi]",
                    STATE_NAMES[psi], x[psi]
                ));
            }
        }
        if x[L0] < 0.0 || x[L0 + 1] < 0.0 {
            return Err("negative paid-out towline length".to_owned());
        }
        if !tension.iter().all(|t| t.is_finite() && *t >= 0.0) {
            return Err("tensions must be finite and >= 0".to_owned());
        }
        if slack_bytes.iter().any(|&b| b > 1) {
            return Err("slack flags must be 0 or 1".to_owned());
        }
        let mut activated_at = [None; MAX_OBSTACLES];
        for (slot, &a) in activated_raw.iter().enumerate() {
            if a.is_nan() {
                continue;
            }
            let is_target = matches!(
                self.obstacles.get(slot).map(|o| o.shape),
                Some(ObstacleShape::Vessel { .. })
            );
            if !is_target {
                return Err(format!(
                    "activated_at[{slot}] = {a}, but slot {slot} is not a target ship \
                     (must be NaN, not activated)"
                ));
            }
            if !(a.is_finite() && a >= 0.0 && a <= time) {
                return Err(format!(
                    "activated_at[{slot}] = {a} is neither NaN (not activated) nor a finite \
                     time in [0, {time}] s"
                ));
            }
            activated_at[slot] = Some(a);
        }
        self.time = time;
        self.unpack(&x);
        self.l0 = [x[L0], x[L0 + 1]];
        self.tension = tension;
        self.slack = [slack_bytes[0] == 1, slack_bytes[1] == 1];
        self.activated_at = activated_at;
        Ok(())
    }

    /// FNV-1a over every parameter that shapes the dynamics or the outputs.
    fn compute_fingerprint(&self) -> u64 {
        let mut h: u64 = 0xcbf2_9ce4_8422_2325;
        let mut eat = |bytes: &[u8]| {
            for &b in bytes {
                h ^= u64::from(b);
                h = h.wrapping_mul(0x0000_0100_0000_01b3);
            }
        };
        eat(&STATE_VERSION.to_le_bytes());
        eat(&[match self.config.hull_model {
            HullModel::LinearDamping => 1,
            HullModel::NonlinearDamping => 2,
        }]);
        eat(&self.config.integration_step.to_le_bytes());
        match self.elastic {
            None => eat(&[1]),
            Some(p) => {
                eat(&[2]);
                for v in [p.stiffness, p.damping, p.winch_gain, p.winch_speed_max] {
                    eat(&v.to_le_bytes());
                }
            }
        }
        for d in &self.data {
            for (_, v) in d.scalar_fields() {
                eat(&v.to_le_bytes());
            }
            for (_, v) in d.damping.fields() {
                eat(&v.to_le_bytes());
            }
        }
        for hull in &self.hulls {
            for v in hull.mass_matrix().iter() {
                eat(&v.to_le_bytes());
            }
            for (nu, tau) in HULL_REFERENCE_POINTS {
                for v in hull.damping_matrix(&Vector3::from(nu)).iter() {
                    eat(&v.to_le_bytes());
                }
                for v in hull.nu_dot(&nu, &tau) {
                    eat(&v.to_le_bytes());
                }
            }
        }
        for o in &self.obstacles {
            eat(o.name.as_bytes());
            eat(&o.x.to_le_bytes());
            eat(&o.y.to_le_bytes());
            match o.shape {
                ObstacleShape::Circle { diameter } => eat(&diameter.to_le_bytes()),
                ObstacleShape::Vessel {
                    length,
                    width,
                    course,
                    speed,
                    activation_time,
                    activation_range,
                } => {
                    for v in [length, width, course, speed, activation_time] {
                        eat(&v.to_le_bytes());
                    }
                    match activation_range {
                        None => eat(&[0]),
                        Some(r) => {
                            eat(&[1]);
                            eat(&r.to_le_bytes());
                        }
                    }
                }
            }
        }
        h
    }
}

/// Names of ship, tug 1, tug 2 in field paths.
const VESSEL_NAMES: [&str; 3] = ["ship", "tug1", "tug2"];

fn vessel_data(scenario: &Scenario) -> [VesselData; 3] {
    [
        scenario.ship_data,
        scenario.tug_data[0],
        scenario.tug_data[1],
    ]
}

/// `(nu, tau)` at which [`World::with_hulls`] checks a hull and the state
/// fingerprint samples it: rest, and model-scale velocities and forces of both
/// signs in every component.
const HULL_REFERENCE_POINTS: [([f64; 3], [f64; 3]); 4] = [
    ([0.0, 0.0, 0.0], [1.0, -0.5, 0.25]),
    ([0.3, 0.05, -0.1], [2.0, 1.0, -0.5]),
    ([-0.8, -0.4, 0.6], [-3.0, 2.0, 1.0]),
    ([1.5, 0.8, -1.2], [5.0, -4.0, -2.0]),
];

/// The properties of a user hull the world and the energy functions rely on
/// (see [`crate::kinetics`]).
fn check_hull(hull: &dyn HullDynamics) -> Result<(), ParamError> {
    let m = hull.mass_matrix();
    if !m.iter().all(|v| v.is_finite()) {
        return Err(ParamError::new(
            "mass_matrix",
            format!("must be finite, got {m}"),
        ));
    }
    if *m != m.transpose() {
        return Err(ParamError::new(
            "mass_matrix",
            format!("must be symmetric (use (M + M^T) / 2), got {m}"),
        ));
    }
    if m.cholesky().is_none() {
        return Err(ParamError::new(
            "mass_matrix",
            format!("must be positive definite, got {m}"),
        ));
    }
    let inv = hull.mass_matrix_inv();
    let error = (inv * m - Matrix3::identity()).abs().max();
    if !inv.iter().all(|v| v.is_finite()) || error > 1e-9 {
        return Err(ParamError::new(
            "mass_matrix_inv",
            format!("must be the inverse of the mass matrix (|M^-1 M - I| = {error:e})"),
        ));
    }
    for (nu, tau) in HULL_REFERENCE_POINTS {
        let nu_v = Vector3::from(nu);
        let c = hull.coriolis_matrix(&nu_v);
        let asym = (c + c.transpose()).abs().max();
        if !c.iter().all(|v| v.is_finite()) || asym > 1e-9 * (1.0 + c.abs().max()) {
            return Err(ParamError::new(
                "coriolis_matrix",
                format!("must be finite and skew-symmetric, got {c} at nu = {nu:?}"),
            ));
        }
        let d = hull.damping_matrix(&nu_v);
        if !d.iter().all(|v| v.is_finite()) {
            return Err(ParamError::new(
                "damping_matrix",
                format!("must be finite, got {d} at nu = {nu:?}"),
            ));
        }
        let nu_dot = hull.nu_dot(&nu, &tau);
        if !nu_dot.iter().all(|v| v.is_finite()) {
            return Err(ParamError::new(
                "nu_dot",
                format!("must be finite, got {nu_dot:?} at nu = {nu:?}, tau = {tau:?}"),
            ));
        }
    }
    Ok(())
}

fn normalised(mut s: VesselState) -> VesselState {
    s.eta[2] = wrap_angle(s.eta[2]);
    s
}

#[cfg(test)]
mod tests;
