//! The controller: reference system, MPC, fallback and the tugs' inner loop.
//!
//! One control sample ([`Controller::sample`], every `T_s`):
//!
//! 1. the measurement is checked (every value finite, every active obstacle
//!    valid); a refused measurement leaves the controller unchanged;
//! 2. the ship reference system (eq. (8)-(11)) gives `eta_Sd` and the COLREGS
//!    situation of every target; scheme III follows the unaltered route instead;
//! 3. a measurement that describes no tow (two vessels closer than half a beam,
//!    [`Overlap`]: e.g. inputs never set, every vessel at (0, 0)) is not
//!    solved: the rest command is applied ([`Rest`]; not a fallback);
//! 4. the obstacles nearest to the tow (at most the QP's clearance slots) become
//!    the MPC's obstacles, at their measured pose (held over the horizon);
//! 5. the MPC (ADMM, Algorithm 1, or the centralized problem) computes the plan;
//! 6. if a subproblem's last solve failed or the plan (or its prediction) is not
//!    finite, the previous sample's plan, shifted by one sample and held within
//!    the bounds and rate bounds, is applied instead, the fallback is counted and
//!    the reason returned (the FMU logs it as a warning), and the next sample
//!    starts cold.
//!
//! Every value of the report is finite: a residual of an iterate that
//! overflowed is reported as `f64::MAX`, and the prediction of a fallback is
//! the measured state held where its rollout overflows.
//!
//! Between samples, [`Controller::command_at`] adds the tugs' inner loop
//! ([`InnerLoopParams`]) to the held tug thrusts; the tensions hold.
//!
//! ADMM stopping at `S` iterations without meeting eq. (29) is not a fallback:
//! Algorithm 1 then applies its last iterate, which satisfies every bound; the
//! report says `converged = false` and the FMU reports it as a diagnostic.

use std::time::{Duration, Instant};

use serde::{Deserialize, Serialize};

use towing_guidance::{
    body_to_ned, role, segment_distance, ActiveObstacle, GuidanceOutput, GuidanceParams,
    ReferenceSystem, Role, Situation, TowState,
};
use towing_model::geometry::{abaft_and_opening, starboard_offset, Lane, Polyline};
use towing_model::{
    wrap_angle, ObstacleKind, ObstacleSlot, Pose, VesselData, VesselState, World, MAX_OBSTACLES,
};
use towing_mpc::{
    Admm, AdmmBuildError, AppliedCommand, Budget, Centralized, FormationMap, MpcReport, Obstacle,
    Optimizer, OptimizerState, PredictionHull, QpOutcome, SampleInput, ShipInput, ShipModel,
    ShipMpc, TugInput, TugModel, TugMpc, Waterway, HORIZON,
};

use crate::config::{Architecture, ControllerConfig, InnerLoopParams};
use crate::error::{ConfigError, MeasurementError};
use crate::mpc_input::MpcInput;

/// What the controller reads every step: the plant's outputs.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Measurement {
    /// Ship `[x, y, psi, u, v, r]` (NED pose, body velocity).
    pub ship: [f64; 6],
    /// Tug 1 (aft) and tug 2 (forward), as the ship.
    pub tugs: [[f64; 6]; 2],
    /// The obstacle slots (`obstacle[k]`).
    pub obstacles: [ObstacleSlot; MAX_OBSTACLES],
}

const VESSEL_FIELDS: [&str; 6] = ["x", "y", "psi", "u", "v", "r"];
const VESSEL_NAMES: [&str; 3] = ["ship", "tug1", "tug2"];

impl Measurement {
    /// Every value finite, every active obstacle valid.
    ///
    /// # Errors
    /// The first offending input, by its FMI name.
    pub fn validate(&self) -> Result<(), MeasurementError> {
        let vessels = [&self.ship, &self.tugs[0], &self.tugs[1]];
        for (vessel, state) in VESSEL_NAMES.iter().zip(vessels) {
            for (field, &value) in VESSEL_FIELDS.iter().zip(state.iter()) {
                if !value.is_finite() {
                    return Err(MeasurementError::NonFinite {
                        name: format!("{vessel}.{field}"),
                        value,
                    });
                }
            }
        }
        for (k, o) in self.obstacles.iter().enumerate() {
            ActiveObstacle::from_slot(o).map_err(|e| MeasurementError::Obstacle {
                slot: k + 1,
                reason: e.to_string(),
            })?;
        }
        Ok(())
    }

    /// The plant's outputs, read straight from a [`World`] (the Rust-only
    /// closed loop of the example, the bench and the tests; an FMU master copies
    /// the same values by name).
    #[must_use]
    pub fn from_world(world: &World) -> Measurement {
        let v = |s: &VesselState| [s.eta[0], s.eta[1], s.eta[2], s.nu[0], s.nu[1], s.nu[2]];
        let mut m = Measurement {
            ship: v(world.ship()),
            tugs: [v(world.tug(0)), v(world.tug(1))],
            ..Measurement::default()
        };
        for (k, slot) in m.obstacles.iter_mut().enumerate() {
            *slot = world.obstacle(k);
        }
        m
    }

    /// The positions `[x, y]` of the ship, tug 1 and tug 2.
    fn positions(&self) -> [[f64; 2]; 3] {
        [
            [self.ship[0], self.ship[1]],
            [self.tugs[0][0], self.tugs[0][1]],
            [self.tugs[1][0], self.tugs[1][1]],
        ]
    }

    fn tow_state(&self) -> TowState {
        let pose = |s: &[f64; 6]| Pose::new(s[0], s[1], s[2]);
        TowState {
            ship: pose(&self.ship),
            ship_vel_n: body_to_ned(self.ship[2], self.ship[3], self.ship[4]),
            tug1: pose(&self.tugs[0]),
            tug2: pose(&self.tugs[1]),
        }
    }
}

/// The plant's inputs.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Command {
    /// `tau_Ti = [X, Y, N]` per tug (N, N, N m, tug body frame).
    pub tug_thrust: [[f64; 3]; 2],
    /// Commanded towline tensions `[F_1, F_2]` (N).
    pub tension: [f64; 2],
}

/// Predicted trajectories of the applied plan (states after samples 1..H).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Prediction {
    /// Ship `[x, y, psi, u, v, r]`.
    pub ship: [[f64; 6]; HORIZON],
    /// Tugs, as the ship.
    pub tugs: [[[f64; 6]; HORIZON]; 2],
}

/// Result and diagnostics of one control sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SampleReport {
    /// The MPC's command (tug thrusts before the inner loop).
    pub command: Command,
    /// Desired towing angles `[alpha_1, alpha_2]` (rad) of the applied plan.
    pub desired_angle: [f64; 2],
    /// The reference system's output.
    pub guidance: GuidanceOutput,
    /// The reference the MPC tracked (`eta_Sd`, or the route waypoint in scheme III).
    pub reference: [f64; 3],
    /// COLREGS situation per obstacle slot (`None`: static hazard or empty
    /// slot).
    pub situation: [Option<Situation>; MAX_OBSTACLES],
    /// The tow's role per slot (`None`: none).
    pub role: [Option<Role>; MAX_OBSTACLES],
    /// ADMM iterations (1 for the centralized problem's single SCP loop count).
    pub iterations: usize,
    /// Whether eq. (29) stopped the ADMM (the centralized problem: its
    /// first-move rule).
    pub converged: bool,
    /// Whether the sample's time budget ([`ControllerConfig::sample_time_budget`])
    /// ended the optimisation: the best iterate within every bound so far was
    /// applied.
    pub budget_hit: bool,
    /// Last primal residual per tug.
    pub r_pri: [f64; 2],
    /// Last dual residual per tug.
    pub r_dual: [f64; 2],
    /// Wall time of the sample (s).
    pub compute_time: f64,
    /// Why the fallback plan was applied, if it was.
    pub fallback: Option<Fallback>,
    /// Fallbacks since instantiation.
    pub fallbacks: u64,
    /// Set when the measurement does not describe a tow ([`Overlap`]): the
    /// sample applied the rest command instead of solving (not a fallback).
    pub rest: Option<Rest>,
    /// The heading floor of this sample (rad; `None`: none): no turn to port
    /// during a head-on or crossing encounter ([`TrackingParams::port_turn_margin`]).
    pub heading_floor: Option<f64>,
    /// Predicted trajectories of the plan.
    pub prediction: Prediction,
}

/// The reference system's part of a sample.
struct Guided {
    output: GuidanceOutput,
    reference: [f64; 3],
    situation: [Option<Situation>; MAX_OBSTACLES],
    role: [Option<Role>; MAX_OBSTACLES],
    heading_floor: Option<f64>,
    max_surge: Option<f64>,
}

/// What one [`Controller::step`] did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Step {
    /// The command for the communication step.
    pub command: Command,
    /// The control sample run at its start, if one was due.
    pub sample: Option<SampleReport>,
}

/// A step refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StepError {
    /// The control sample refused its measurement.
    #[error("sample at t = {t} s refused: {source}")]
    Sample {
        /// The step's time (s).
        t: f64,
        /// Why.
        #[source]
        source: MeasurementError,
    },
    /// The inner loop refused its measurement.
    #[error("command at t = {t} s refused: {source}")]
    Command {
        /// The step's time (s).
        t: f64,
        /// Why.
        #[source]
        source: MeasurementError,
    },
}

/// The optimiser's report of a sample at rest ([`Rest`]): nothing solved.
const REST_REPORT: MpcReport = MpcReport {
    iterations: 0,
    converged: false,
    budget_hit: false,
    failed: None,
    r_pri: [0.0; 2],
    r_dual: [0.0; 2],
};

/// A communication point within this of a sample instant samples (1 us).
pub const SAMPLE_TOLERANCE: Duration = Duration::from_micros(1);
const SAMPLE_TOLERANCE_NS: i64 = 1_000;

/// The sampling clock of [`Controller::step`], in whole nanoseconds since the
/// start time.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
struct Clock {
    start: Option<f64>,
    sample_ns: i64,
    next_ns: i64,
    last_ns: i64,
    samples: u64,
}

/// Why a sample applied the fallback plan.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Fallback {
    /// The last QP of a subproblem gave no usable solution.
    SolveFailed {
        /// `tug 1`, `tug 2`, `ship` or `centralized`.
        problem: &'static str,
        /// Clarabel's outcome.
        outcome: QpOutcome,
    },
    /// The plan, or the states it predicts, hold a NaN or an infinity.
    NonFinitePlan,
}

impl std::fmt::Display for Fallback {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Fallback::SolveFailed { problem, outcome } => {
                write!(f, "the {problem} QP gave no usable solution ({outcome:?})")
            }
            Fallback::NonFinitePlan => write!(f, "the plan or its prediction is not finite"),
        }
    }
}

/// Everything a [`Controller`] carries from one step to the next that decides its later
/// commands and reports, and nothing it can rebuild from its configuration: what a
/// controller's FMU state holds ([`Controller::snapshot`], [`Controller::restore`]). Serde
/// writes it; every float in it is finite.
///
/// In: the guidance's memory (active waypoint, encounters, situations), the optimizer's
/// warm start ([`OptimizerState`]: plans, ADMM multipliers, trust radii), the applied
/// command, the fallback's spare plan, the inner loop's velocity ramp, the fallback
/// count, the port-turn anchors and the sample clock. Not in: the configuration, the
/// solvers (QPs, factorisations, linearisations, buffers), the inner-loop gains and
/// thrust limits (all rebuilt from the configuration), the MPC obstacle list and the last
/// MPC input (both written by a sample before they are read).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ControllerState {
    guidance: ReferenceSystem,
    optimizer: OptimizerState,
    carried: Carried,
}

/// The controller's own part of its [`ControllerState`]: what [`Controller`] carries from
/// one sample to the next besides the guidance and the optimizer, one field each, held as
/// one value so that the state is this value, never a field-by-field copy of it.
#[derive(Debug, Clone, Copy, Serialize, Deserialize)]
struct Carried {
    /// The command applied last.
    applied: AppliedCommand,
    /// The previous sample's plans, shifted: the fallback.
    spare_ship: [ShipInput; HORIZON],
    spare_tugs: [[TugInput; HORIZON]; 2],
    /// Genuine samples left in the spare plan (`H - 1` after a solved sample,
    /// one less after each fallback; 0: the plan is used up).
    spare_left: usize,
    /// Tug velocities at the start of the sample and predicted at its end.
    nu_start: [[f64; 3]; 2],
    nu_end: [[f64; 3]; 2],
    fallbacks: u64,
    /// Per obstacle slot: the most starboard heading off the route's course
    /// ([`Controller::route_course`]) reached since an encounter began in which the
    /// tow may not turn to port ([`TrackingParams::port_turn_margin`]), rad.
    port_turn_anchor: [Option<f64>; MAX_OBSTACLES],
    /// The obstacle slot of the crossing for which the tow gives way whose altered course
    /// ran out of water ([`Controller::short_of_water`]): she keeps the way off until
    /// that alteration ends.
    short_of_water: Option<usize>,
    /// The reference course of the last sample ([`TrackingParams::course_rate`]);
    /// `None` before the first sample.
    course: Option<f64>,
    clock: Clock,
    /// The last sample rested ([`Rest`]).
    resting: bool,
}

/// Two vessels of a measurement closer than half the larger one's beam: one
/// centre lies inside the other's hull (a hull contains the disc of its half
/// beam about its centre), which no tow can be in. What a controller sees whose
/// inputs were never set (every vessel at their start value (0, 0), as
/// fmuCheck, fmusim and `fmpy.simulate_fmu` run an FMU alone).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Overlap {
    /// The two vessels (`ship`, `tug1`, `tug2`).
    pub vessels: [&'static str; 2],
    /// The distance between their centres (m).
    pub distance: f64,
    /// Half the larger beam (m).
    pub limit: f64,
}

impl std::fmt::Display for Overlap {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let [a, b] = self.vessels;
        write!(
            f,
            "the measured {b} is {} m from the {a}, less than half a beam ({} m): one lies inside \
             the other's hull, so the inputs describe no tow (inputs never set are all 0, every \
             vessel at (0, 0))",
            self.distance, self.limit
        )
    }
}

/// A sample that applied the rest command (the tensions towards the
/// pretension and the angles towards zero within their rate bounds, no thrust)
/// because the measurement describes no tow.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rest {
    /// Why.
    pub overlap: Overlap,
    /// Whether the sample before solved (or there was none): this one begins a
    /// run of resting samples, the one to report.
    pub first: bool,
}

/// The controller (module docs).
#[derive(Debug)]
pub struct Controller {
    config: ControllerConfig,
    guidance: ReferenceSystem,
    solver: Box<dyn Optimizer>,
    inner_k: [[[f64; 3]; 3]; 2],
    thrust_limit: [[f64; 3]; 2],
    /// Everything else the next samples depend on ([`ControllerState`]).
    carried: Carried,
    mpc_obstacles: [Obstacle; MAX_OBSTACLES],
    /// The waterway of the MPC ([`ControllerConfig::waterway`]).
    waterway: Option<(Lane, [f64; 3])>,
    /// The scenario's route as a line, for the course of following it
    /// ([`Controller::route_course`]).
    route: Polyline,
    /// A copy of the last sample's MPC input ([`Controller::last_mpc_input`]).
    last_input: Option<MpcInput>,
}

fn mass_matrix(d: &VesselData) -> [[f64; 3]; 3] {
    // Fossen (2011), eq. (6.46) and (6.52): M = M_RB + M_A, symmetric part.
    let m = d.mass;
    let c = 0.5 * (m * d.x_g - d.y_rdot + m * d.x_g - d.n_vdot);
    [
        [m - d.x_udot, 0.0, 0.0],
        [0.0, m - d.y_vdot, c],
        [0.0, c, d.inertia_z - d.n_rdot],
    ]
}

impl Controller {
    /// Builds every solver once (no allocation per sample afterwards).
    ///
    /// # Errors
    /// A value out of range, or a solver that cannot be set up, named.
    pub fn new(config: ControllerConfig) -> Result<Controller, ConfigError> {
        config.validate()?;
        let guidance = ReferenceSystem::new(
            config.route()?,
            GuidanceParams::new(config.guidance())
                .map_err(|e| ConfigError::new("guidance", e.to_string()))?,
        );
        let solver = build_optimizer(&config)?;
        let s = &config.scenario;
        let inner_k = std::array::from_fn(|i| {
            let m = mass_matrix(&s.tug_data[i]);
            std::array::from_fn(|r| std::array::from_fn(|c| config.tuning.inner.gain[r] * m[r][c]))
        });
        let thrust_limit = std::array::from_fn(|i| {
            let d = &s.tug_data[i];
            let l = config.tuning.tug.thrust_limit;
            [
                l[0].min(d.max_surge_force),
                l[1].min(d.max_sway_force),
                l[2].min(d.max_yaw_moment),
            ]
        });
        let f0 = config.tuning.ship.min_tension;
        let sample_time = config.tuning.prediction.sample_time;
        let waterway = config.waterway();
        let route = Polyline::of_route(&config.scenario.route);
        Ok(Controller {
            waterway,
            route,
            config,
            guidance,
            solver,
            inner_k,
            thrust_limit,
            carried: Carried {
                // The lines start at their pretension (`min_tension`), straight.
                applied: AppliedCommand {
                    ship: [f0, f0, 0.0, 0.0],
                    tugs: [[0.0; 3]; 2],
                },
                spare_ship: [[0.0; 4]; HORIZON],
                spare_tugs: [[[0.0; 3]; HORIZON]; 2],
                spare_left: 0,
                nu_start: [[0.0; 3]; 2],
                nu_end: [[0.0; 3]; 2],
                fallbacks: 0,
                port_turn_anchor: [None; MAX_OBSTACLES],
                short_of_water: None,
                course: None,
                clock: Clock {
                    // sample_time > 0 and finite (checked); at least 1 ns.
                    sample_ns: ((sample_time * 1e9).round() as i64).max(1),
                    ..Clock::default()
                },
                resting: false,
            },
            mpc_obstacles: [Obstacle::Circle {
                centre: [0.0; 2],
                radius: 1.0,
            }; MAX_OBSTACLES],
            last_input: None,
        })
    }

    /// The state to carry over ([`ControllerState`]).
    #[must_use]
    pub fn snapshot(&self) -> ControllerState {
        ControllerState {
            guidance: self.guidance.clone(),
            optimizer: self.solver.snapshot(),
            carried: self.carried,
        }
    }

    /// Goes on from `state`, a [`snapshot`](Self::snapshot) of a controller with the same
    /// configuration (possibly in another process): the next steps give the commands
    /// and reports, bit for bit, that the snapshot's controller would have given.
    ///
    /// # Errors
    /// A state that does not fit this controller (another architecture or sample time,
    /// a waypoint outside the route, a plan of another size), named; nothing changes
    /// then.
    pub fn restore(&mut self, state: &ControllerState) -> Result<(), String> {
        let (own, carried) = (&self.carried, &state.carried);
        if carried.clock.sample_ns != own.clock.sample_ns {
            return Err(format!(
                "the state's sample time is {} ns, this controller's {} ns",
                carried.clock.sample_ns, own.clock.sample_ns
            ));
        }
        if carried.spare_left >= HORIZON {
            return Err(format!(
                "{} samples left in the spare plan, at most {} possible",
                carried.spare_left,
                HORIZON - 1
            ));
        }
        let mut guidance = self.guidance.clone();
        guidance.restore(&state.guidance)?;
        self.solver.restore(&state.optimizer)?;
        self.guidance = guidance;
        self.carried = state.carried;
        Ok(())
    }

    /// The configuration.
    #[must_use]
    pub fn config(&self) -> &ControllerConfig {
        &self.config
    }

    /// Fallbacks since instantiation.
    #[must_use]
    pub fn fallbacks(&self) -> u64 {
        self.carried.fallbacks
    }

    /// The command applied in the last sample.
    #[must_use]
    pub fn applied(&self) -> &AppliedCommand {
        &self.carried.applied
    }

    /// The input the MPC was given in the last control sample (`None` before
    /// the first): the states, previous command, reference, obstacles and
    /// heading floor of [`towing_mpc::SampleInput`], owned. Read-only; for
    /// replaying the same problem elsewhere ([`MpcInput`]).
    #[must_use]
    pub fn last_mpc_input(&self) -> Option<&MpcInput> {
        self.last_input.as_ref()
    }

    /// One control sample (module docs).
    ///
    /// # Errors
    /// A refused measurement; nothing changes then.
    pub fn sample(&mut self, m: &Measurement) -> Result<SampleReport, MeasurementError> {
        let start = Instant::now();
        m.validate()?;
        let guided = self.guide(m)?;
        let rest = self.overlap(m).map(|overlap| Rest {
            overlap,
            first: !self.carried.resting,
        });
        self.carried.resting = rest.is_some();
        let (report, (ship_cmd, tug_cmd, fallback)) = if rest.is_some() {
            (REST_REPORT, self.rest())
        } else {
            let report = self.solve(m, &guided, start);
            (report, self.apply(report.failed))
        };
        let prediction = self.prediction(m, fallback.is_none() && rest.is_none());
        for i in 0..2 {
            self.carried.nu_start[i] = [m.tugs[i][3], m.tugs[i][4], m.tugs[i][5]];
            self.carried.nu_end[i] = [
                prediction.tugs[i][0][3],
                prediction.tugs[i][0][4],
                prediction.tugs[i][0][5],
            ];
        }
        // A residual of an iterate that overflowed (the sample then fell back):
        // the largest finite value, never NaN.
        let residual = |r: [f64; 2]| r.map(|v| finite_or(v, f64::MAX));
        Ok(SampleReport {
            command: Command {
                tug_thrust: tug_cmd,
                tension: [ship_cmd[0], ship_cmd[1]],
            },
            desired_angle: [ship_cmd[2], ship_cmd[3]],
            guidance: guided.output,
            reference: guided.reference,
            situation: guided.situation,
            role: guided.role,
            iterations: report.iterations,
            converged: report.converged,
            budget_hit: report.budget_hit,
            r_pri: residual(report.r_pri),
            r_dual: residual(report.r_dual),
            compute_time: start.elapsed().as_secs_f64(),
            fallback,
            fallbacks: self.carried.fallbacks,
            rest,
            heading_floor: guided.heading_floor,
            prediction,
        })
    }

    /// The MPC's part of a sample: its obstacles (nearest first), its input, the
    /// optimisation within the sample's time budget.
    fn solve(&mut self, m: &Measurement, guided: &Guided, start: Instant) -> MpcReport {
        let (n_obstacles, distance_cost_off) = self.select_obstacles(m);
        let input = SampleInput {
            ship: m.ship,
            tugs: m.tugs,
            previous: self.carried.applied,
            reference: [guided.reference; HORIZON],
            obstacles: &self.mpc_obstacles[..n_obstacles],
            distance_cost_off,
            heading_floor: guided.heading_floor,
            max_surge: guided.max_surge,
            waterway: (self.waterway.as_ref()).map(|(lane, margin)| Waterway {
                lane,
                margin: *margin,
            }),
        };
        self.last_input = Some(MpcInput::of(&input));
        let budget_s = self.config.tuning.sample_time_budget;
        let budget = Budget::from(
            start,
            (budget_s > 0.0).then(|| Duration::from_secs_f64(budget_s)),
        );
        self.solver.solve(&input, budget)
    }

    /// The first two vessels of `m` closer than half the larger beam
    /// ([`Overlap`]), if any.
    fn overlap(&self, m: &Measurement) -> Option<Overlap> {
        let s = &self.config.scenario;
        let vessels = [
            (&m.ship, s.ship_data.width),
            (&m.tugs[0], s.tug_data[0].width),
            (&m.tugs[1], s.tug_data[1].width),
        ];
        [(0, 1), (0, 2), (1, 2)].into_iter().find_map(|(a, b)| {
            let ((pa, wa), (pb, wb)) = (vessels[a], vessels[b]);
            let distance = (pa[0] - pb[0]).hypot(pa[1] - pb[1]);
            let limit = 0.5 * wa.max(wb);
            (distance < limit).then_some(Overlap {
                vessels: [VESSEL_NAMES[a], VESSEL_NAMES[b]],
                distance,
                limit,
            })
        })
    }

    /// A sample at rest ([`Rest`]): the rest command within the rate bounds;
    /// no plan to keep, and the next solved sample starts cold.
    fn rest(&mut self) -> (ShipInput, [TugInput; 2], Option<Fallback>) {
        self.solver.reset();
        self.carried.spare_left = 0;
        let (ship, tugs) = self.within_bounds(self.rest_plan());
        self.carried.applied = AppliedCommand { ship, tugs };
        (ship, tugs, None)
    }

    /// The reference system's part of a sample: the reference to track, the
    /// COLREGS situations and roles, the heading floor.
    fn guide(&mut self, m: &Measurement) -> Result<Guided, MeasurementError> {
        let guidance = self
            .guidance
            .update(&m.tow_state(), &m.obstacles)
            .map_err(|e| MeasurementError::Obstacle {
                slot: 0,
                reason: e.to_string(),
            })?;
        let t = &self.config.tuning;
        let target = if t.scheme.alters() {
            guidance.eta_sd
        } else {
            guidance.route_waypoint
        };
        let altered = guidance.altered && t.scheme.alters();
        // Rule 8(e) and 16: give way in a crossing also by slackening speed (the
        // tracked point comes nearer), so the target can pass ahead.
        let giving_way = altered
            && guidance
                .governing
                .is_some_and(|g| g.situation == Some(Situation::CrossingGiveWay));
        let lookahead = if giving_way {
            t.tracking.give_way_lookahead
        } else {
            t.tracking.lookahead
        };
        let status = t.guidance.colregs.tow_status;
        let heading_floor = self.heading_floor(m, altered);
        let reference = self.reference(
            m,
            (guidance.active_waypoint, target, guidance.offset_held),
            altered,
            lookahead,
            heading_floor,
        );
        let giving_way_to = guidance.governing.filter(|_| giving_way).map(|g| g.index);
        let short_of_water = self.short_of_water(m, reference[2], giving_way_to);
        let t = &self.config.tuning;
        // Rule 8(e): giving way in a crossing, the tow takes the way off at a
        // bounded deceleration and keeps it off: the plan's surge stays at or
        // below the measured surge less `give_way_deceleration` T_s, and at or
        // below `give_way_surge` once she has slowed to it. Off the altered leg
        // the tracked point lies abeam or ahead and drew her ahead again before
        // the target was past; a sudden cap at cruise speed made her crab (drift
        // 37-55 deg) as she slowed and turned. Always with `give_way_way_off`, and
        // once the altered course has run out of water ([`Controller::short_of_water`]).
        // Rule 17(a)(ii), (b) with 8(e): a stand-on tow that must act and can let the
        // target pass ahead takes the way off the same way, down to `way_off_speed`.
        // Both caps take the way off the same way: the measured surge less the
        // deceleration times T_s, down to a floor.
        let cap = |floor: f64, deceleration: f64| {
            floor.max(m.ship[3] - deceleration * t.prediction.sample_time)
        };
        let rule17 = &t.guidance.colregs.rule17;
        let max_surge = [
            (giving_way && (t.tracking.give_way_way_off || short_of_water))
                .then(|| cap(t.tracking.give_way_surge, t.tracking.give_way_deceleration)),
            (guidance.way_off && t.scheme.alters())
                .then(|| cap(rule17.way_off_speed, rule17.way_off_deceleration)),
        ]
        .into_iter()
        .flatten()
        .reduce(f64::min);
        let situation: [Option<Situation>; MAX_OBSTACLES] =
            std::array::from_fn(|k| self.guidance.situation(k));
        Ok(Guided {
            output: guidance,
            reference,
            situation,
            role: situation.map(|s| s.and_then(|s| role(s, status))),
            heading_floor,
            max_surge,
        })
    }

    /// The command of a solved sample (the plan's first move), or the fallback
    /// if a subproblem failed or the plan (or its prediction) is not finite; keeps the next
    /// sample's spare plan and warm start, and records the applied command.
    fn apply(
        &mut self,
        failed: Option<(&'static str, QpOutcome)>,
    ) -> (ShipInput, [TugInput; 2], Option<Fallback>) {
        let ship_plan = self.solver.ship_plan();
        let tug_plans = [self.solver.tug_plan(0), self.solver.tug_plan(1)];
        let tug_predicted = [self.solver.tug_predicted(0), self.solver.tug_predicted(1)];
        let finite = ship_plan.iter().flatten().all(|v| v.is_finite())
            && tug_plans.iter().flatten().flatten().all(|v| v.is_finite())
            && self
                .solver
                .ship_predicted()
                .iter()
                .flatten()
                .all(|v| v.is_finite())
            && tug_predicted
                .iter()
                .flatten()
                .flatten()
                .all(|v| v.is_finite());
        let fallback = if let Some((problem, outcome)) = failed {
            Some(Fallback::SolveFailed { problem, outcome })
        } else if !finite {
            Some(Fallback::NonFinitePlan)
        } else {
            None
        };
        let shift = |h: usize| (h + 1).min(HORIZON - 1);
        let (ship_cmd, tug_cmd) = if fallback.is_some() {
            self.carried.fallbacks += 1;
            let (s, t) = self.fallback_command();
            self.solver.reset();
            self.carried.spare_ship = std::array::from_fn(|h| self.carried.spare_ship[shift(h)]);
            self.carried.spare_tugs = std::array::from_fn(|i| {
                std::array::from_fn(|h| self.carried.spare_tugs[i][shift(h)])
            });
            (s, t)
        } else {
            // The next sample's spare plan, and the warm start.
            self.carried.spare_ship = std::array::from_fn(|h| ship_plan[shift(h)]);
            self.carried.spare_tugs =
                std::array::from_fn(|i| std::array::from_fn(|h| tug_plans[i][shift(h)]));
            self.carried.spare_left = HORIZON - 1;
            self.solver.shift();
            (ship_plan[0], [tug_plans[0][0], tug_plans[1][0]])
        };
        self.carried.applied = AppliedCommand {
            ship: ship_cmd,
            tugs: tug_cmd,
        };
        (ship_cmd, tug_cmd, fallback)
    }

    /// The command for the communication step starting at `t` (s), owning the
    /// sampling clock: a control sample ([`Controller::sample`]) runs first when
    /// `t` has reached the next sample instant `t_0 + k T_s` (within
    /// [`SAMPLE_TOLERANCE`], on a nanosecond clock, `t_0` the time of the first
    /// step or [`Controller::set_start_time`]); then the command is
    /// [`Controller::command_at`] the time since that sample. The FMU, the
    /// examples and the benchmarks all step through this.
    ///
    /// # Errors
    /// A refused measurement (the sample's or the inner loop's); nothing changes
    /// then.
    pub fn step(&mut self, t: f64, m: &Measurement) -> Result<Step, StepError> {
        let start = *self.carried.clock.start.get_or_insert(t);
        let now_ns = ((t - start) * 1e9).round() as i64;
        let mut sample = None;
        if now_ns + SAMPLE_TOLERANCE_NS >= self.carried.clock.next_ns {
            let report = self
                .sample(m)
                .map_err(|source| StepError::Sample { t, source })?;
            self.carried.clock.last_ns = now_ns;
            while self.carried.clock.next_ns <= now_ns + SAMPLE_TOLERANCE_NS {
                self.carried.clock.next_ns += self.carried.clock.sample_ns;
            }
            self.carried.clock.samples += 1;
            sample = Some(report);
        }
        let elapsed = (now_ns - self.carried.clock.last_ns) as f64 * 1e-9;
        let command = self
            .command_at(elapsed, m)
            .map_err(|source| StepError::Command { t, source })?;
        Ok(Step { command, sample })
    }

    /// Sets the time of the first sample instant (s); by default the time of
    /// the first [`Controller::step`].
    pub fn set_start_time(&mut self, t0: f64) {
        self.carried.clock.start = Some(t0);
    }

    /// Control samples run by [`Controller::step`] so far.
    #[must_use]
    pub fn samples(&self) -> u64 {
        self.carried.clock.samples
    }

    /// The command at `elapsed` seconds after the last sample, with the tugs'
    /// inner loop on the measured velocities; the tensions hold.
    ///
    /// # Errors
    /// A non-finite tug velocity, by name.
    pub fn command_at(&self, elapsed: f64, m: &Measurement) -> Result<Command, MeasurementError> {
        let s = (elapsed / self.config.tuning.prediction.sample_time).clamp(0.0, 1.0);
        let mut tug_thrust = self.carried.applied.tugs;
        for i in 0..2 {
            for c in 0..3 {
                let value = m.tugs[i][3 + c];
                if !value.is_finite() {
                    return Err(MeasurementError::NonFinite {
                        name: format!("{}.{}", VESSEL_NAMES[1 + i], VESSEL_FIELDS[3 + c]),
                        value,
                    });
                }
            }
            let err: [f64; 3] = std::array::from_fn(|c| {
                self.carried.nu_start[i][c]
                    + s * (self.carried.nu_end[i][c] - self.carried.nu_start[i][c])
                    - m.tugs[i][3 + c]
            });
            for ((tau, k), l) in tug_thrust[i]
                .iter_mut()
                .zip(&self.inner_k[i])
                .zip(self.thrust_limit[i])
            {
                let extra = k[0] * err[0] + k[1] * err[1] + k[2] * err[2];
                *tau = (*tau + extra).clamp(-l, l);
            }
        }
        Ok(Command {
            tug_thrust,
            tension: [self.carried.applied.ship[0], self.carried.applied.ship[1]],
        })
    }

    /// The pose the MPC tracks (`docs/controller-design.md`, "Reference"): with
    /// `lookahead = 0` the reference system's waypoint `eta_Sd` (eq. (8)-(11));
    /// otherwise the point `lookahead` metres ahead of the ship's projection on
    /// the active leg (previous waypoint to `target`, the altered one while
    /// altered), continued onto the next leg past `target`; while altered it runs
    /// on along the altered leg instead (the next leg is the unaltered route, which
    /// leads back towards the target, and homing onto the altered waypoint itself
    /// made the tow crawl sideways and astern around it while giving way); and the
    /// destination (altered or not) on the last leg (lookahead-based line of sight, Fossen 2011, section
    /// 10.3.2). The heading is the bearing from the ship to that point while it
    /// is farther than `los_distance`, else the point's route heading.
    fn reference(
        &mut self,
        m: &Measurement,
        (active, target, offset_held): (usize, Pose, f64),
        altered: bool,
        lookahead: f64,
        floor: Option<f64>,
    ) -> [f64; 3] {
        let ship = &m.ship;
        let points = self.guidance.route().points();
        let last = points.len() - 1;
        let mut goal = target.eta();
        if self.config.tuning.tracking.lookahead > 0.0 {
            let prev = points[active - 1];
            let seg = [target.x - prev.x, target.y - prev.y];
            let len = seg[0].hypot(seg[1]);
            if len > 0.0 {
                let e = [seg[0] / len, seg[1] / len];
                let along = ((ship[0] - prev.x) * e[0] + (ship[1] - prev.y) * e[1]).clamp(0.0, len);
                let remaining = len - along;
                if remaining >= lookahead || (altered && active < last) {
                    // An altered waypoint is a direction, not a place to stop at:
                    // the point runs on past it along the altered leg.
                    let s = along + lookahead;
                    goal = [prev.x + s * e[0], prev.y + s * e[1], target.psi];
                } else if active < last {
                    let next = points[active + 1];
                    let seg2 = [next.x - target.x, next.y - target.y];
                    let len2 = seg2[0].hypot(seg2[1]);
                    let s = (lookahead - remaining).min(len2);
                    if len2 > 0.0 {
                        goal = [
                            target.x + s * seg2[0] / len2,
                            target.y + s * seg2[1] / len2,
                            next.psi,
                        ];
                    }
                }
            }
        }
        let leg = (points[active - 1].position(), points[active].position());
        if altered {
            goal = lift_to_offset(goal, leg, offset_held);
        }
        let goal = self.clear_of_hazards(ship, goal, leg, &m.obstacles);
        let reference = self.steer(ship, goal, floor);
        self.short_of_hazards(ship, reference, &m.obstacles)
    }

    /// The static hazards of `obstacles`, each as its centre and the ship's hazard
    /// safe range from it ([`ActiveObstacle::safe_range`], eq. (14): `L + R + d_S0`,
    /// 2.005 m for the paper's ship and hazards). The slots were checked by the
    /// guidance's update of this sample.
    fn hazard_circles<'a>(
        &self,
        obstacles: &'a [ObstacleSlot],
    ) -> impl Iterator<Item = ([f64; 2], f64)> + 'a {
        let g = self.guidance.params().settings();
        let (own, buffer) = (g.ship_length, g.safety_buffer);
        obstacles
            .iter()
            .filter_map(move |o| match ActiveObstacle::from_slot(o) {
                Ok(Some(c @ ActiveObstacle::Circle { .. })) => {
                    Some((c.centre(), c.safe_range(own, buffer)))
                }
                _ => None,
            })
    }

    /// The tracked position of `reference` brought back along the line from the
    /// ship to where that line first comes within a hazard's safe range (not for a
    /// circle the ship is already inside): the reference course, limited in its
    /// rate and its lead over the ship's heading ([`Controller::steer`]), may
    /// still point at a hazard the line of sight turns away from
    /// ([`Controller::clear_of_hazards`]), and a tracked position beyond the
    /// hazard held the tow against it, her forward tug kept off by the clearance
    /// rows (the issue's stall mode). Short of the hazard the heading term turns
    /// her first, as a seaman turns before going on past a danger close ahead.
    fn short_of_hazards(
        &self,
        ship: &[f64; 6],
        mut reference: [f64; 3],
        obstacles: &[ObstacleSlot],
    ) -> [f64; 3] {
        for (centre, rho) in self.hazard_circles(obstacles) {
            let (sx, sy) = (reference[0] - ship[0], reference[1] - ship[1]);
            let (cx, cy) = (centre[0] - ship[0], centre[1] - ship[1]);
            // |s t - c| = rho: t^2 |s|^2 - 2 t s.c + |c|^2 - rho^2 = 0, first root in [0, 1].
            let (a, b, c) = (
                sx * sx + sy * sy,
                sx * cx + sy * cy,
                cx * cx + cy * cy - rho * rho,
            );
            let disc = b * b - a * c;
            // Inside the circle already (c <= 0) the point is not held: held at the
            // ship, the tow stayed inside (the paper scenario's centralized scheme II
            // lay 55 s at 1.97 m from hazard c); the line of sight leads out.
            if a <= 0.0 || disc < 0.0 || c <= 0.0 {
                continue;
            }
            let t = (b - disc.sqrt()) / a;
            if (0.0..1.0).contains(&t) {
                reference[0] = ship[0] + t * sx;
                reference[1] = ship[1] + t * sy;
            }
        }
        reference
    }

    /// The tracked point `goal` moved so that the line of sight from the ship to it
    /// keeps clear of every static hazard (`docs/colregs.md`, "Static hazards": the
    /// line of sight passes a hazard clear). A hazard whose circle of the ship's
    /// hazard safe range ([`Controller::hazard_circles`]) cuts the segment from the
    /// ship to `goal` turns the line of sight, at the same range, onto the tangent
    /// from the ship to that circle on the side the route `leg` (start, end) passes
    /// the hazard (the port tangent for a hazard to starboard of the leg), or, when
    /// the ship is already inside the circle, square to the line to its centre on
    /// that side. Without it the tracked point came to lie on a hazard beside a
    /// turn and the tow was held against it, its forward tug kept off the hazard by
    /// the clearance rows while the position term pulled it on (the issue's stall
    /// mode; measured in `docs/assumptions.md`, row "line of sight clear of
    /// hazards"). A tangent line of sight is the classical way round a circular
    /// obstacle (Fossen 2011, section 10.3.2 for the line of sight; the tangent as
    /// in the "tangent bug" of Kamon, Rivlin and Rimon 1998, "TangentBug", Int. J.
    /// Robotics Research 17(9)).
    fn clear_of_hazards(
        &self,
        ship: &[f64; 6],
        mut goal: [f64; 3],
        (start, end): ([f64; 2], [f64; 2]),
        obstacles: &[ObstacleSlot],
    ) -> [f64; 3] {
        let e = [end[0] - start[0], end[1] - start[1]];
        for (centre, rho) in self.hazard_circles(obstacles) {
            let reach = (goal[0] - ship[0]).hypot(goal[1] - ship[1]);
            if reach <= 0.0
                || segment_distance(centre, [ship[0], ship[1]], [goal[0], goal[1]]) >= rho
            {
                continue;
            }
            let (cx, cy) = (centre[0] - ship[0], centre[1] - ship[1]);
            // The side the route passes the hazard: to starboard of the leg (NED,
            // x north, y east: e x w > 0), it is passed on the port hand.
            let starboard = e[0] * (centre[1] - start[1]) - e[1] * (centre[0] - start[0]) >= 0.0;
            let range = cx.hypot(cy);
            let off = if range > rho {
                (rho / range).asin()
            } else {
                std::f64::consts::FRAC_PI_2
            };
            let bearing = wrap_angle(cy.atan2(cx) + if starboard { -off } else { off });
            let (sin, cos) = bearing.sin_cos();
            goal = [ship[0] + reach * cos, ship[1] + reach * sin, bearing];
        }
        goal
    }

    /// The reference pose the MPC tracks, from the tracked point `goal`
    /// (`docs/controller-design.md`, "Reference course"). The wanted course is the
    /// line-of-sight bearing from the ship to `goal` while it is farther than
    /// `los_distance`, else `goal`'s route heading; the reference course follows it
    /// at most [`TrackingParams::course_rate`] per second (a bounded-rate reference,
    /// so that a released alteration or a new leg never asks the tow to face up to
    /// 95 deg off its heading at once, which the tugs answered by dragging the ship
    /// sideways); it also stays within [`TrackingParams::course_lead`] of the
    /// ship's heading, so it leads a turn the ship is making but never lies abeam.
    /// Before that lead limit it is lifted onto the heading `floor`
    /// ([`Controller::heading_floor`]) if it lies to port of it: the floor holds
    /// the ship's head, and a reference course to port of it was answered by a
    /// sideways drag (41 of the 50 drift failures of the centralized random
    /// encounters, before). Beyond `los_distance` the tracked position is moved
    /// onto the reference course, at the range of `goal` but no farther than the
    /// lookahead (or `los_distance`, the larger), so position and heading ask for the same motion: ahead along the
    /// course at the cruise pull, never sideways, never faster for being far off.
    /// Within `los_distance` the tracked position stays, less any part of it abaft
    /// the ship's beam: the tow never gathers sternway to reach its reference.
    fn steer(&mut self, ship: &[f64; 6], mut goal: [f64; 3], floor: Option<f64>) -> [f64; 3] {
        let t = &self.config.tuning;
        let (dx, dy) = (goal[0] - ship[0], goal[1] - ship[1]);
        let range = dx.hypot(dy);
        let los = t.tracking.los_distance;
        let far = los > 0.0 && range > los;
        let wanted = if far { dy.atan2(dx) } else { goal[2] };
        let step = t.tracking.course_rate * t.prediction.sample_time;
        // The first sample turns from the ship's own heading.
        let mut course = if step > 0.0 {
            turn_towards(self.carried.course.unwrap_or(ship[2]), wanted, step)
        } else {
            wanted
        };
        if let Some(f) = floor {
            if wrap_angle(course - f) < 0.0 {
                course = f;
            }
        }
        let lead = t.tracking.course_lead;
        if lead > 0.0 {
            course = turn_towards(ship[2], course, lead);
        }
        self.carried.course = Some(course);
        if far {
            let (s, c) = course.sin_cos();
            let reach = match t.tracking.lookahead {
                l if l > 0.0 => range.min(l.max(los)),
                _ => range,
            };
            goal = [ship[0] + reach * c, ship[1] + reach * s, course];
        } else {
            // Near: never a point abaft the ship's beam (no sternway to reach it, as
            // the give-way slow-down's projection on the altered leg asked): its
            // part astern of the ship is dropped, the part abeam kept.
            let (s, c) = ship[2].sin_cos();
            let astern = (dx * c + dy * s).min(0.0);
            goal = [goal[0] - astern * c, goal[1] - astern * s, course];
        }
        goal
    }

    /// The heading floor of this sample (`None`: none), after updating the
    /// encounters' anchors from the guidance's situations.
    ///
    /// COLREGS: in a head-on situation (Rule 14) and a crossing in which the tow
    /// gives way (Rule 15) the tow alters to starboard; in a crossing in which
    /// it stands on it must not turn to port for the vessel on its port side
    /// (Rule 17(c)). In all three the tow therefore never turns to port off the
    /// course of her route ([`Controller::route_course`]: rounding a bend of the
    /// route is keeping her course, Rule 17(a)(i), as the analyzer judges it): the
    /// most starboard heading off the route's course reached since the encounter
    /// began, less [`TrackingParams::port_turn_margin`], laid off from the route's
    /// course of the sample, is a floor for the ship's predicted
    /// headings until the target is past and clear (Rule 8(d); the guidance's
    /// test) or the encounter ends: an alteration is not taken back, and a swing
    /// past the intended course is not taken back either while the target is not
    /// past (turning back is a turn to port, towards a target on the starboard bow
    /// or across the bow of one on the port side; capping the floor at the course
    /// steered gave a 15 deg port turn for a give-way target in a suite encounter). The
    /// reference course follows the floor ([`Controller::steer`]), so the head is
    /// not held against the tracked point. Held beyond past and clear, the floor
    /// kept the ship's head to starboard while the reference course returned to
    /// the route, and the tugs dragged her sideways (drift 100 deg). Without it the
    /// centralized MPC, trading the heading error against the tugs' distance
    /// terms of (16), let the stopped tow swing 40 deg to port while giving way
    /// to target A (`docs/controller-design.md`).
    ///
    /// A target overtaking the tow on her port side binds the floor as well (Rules 13
    /// and 17(a)(i): she keeps her course, and a port turn is a turn into the
    /// overtaking vessel's path): without it the tow's aft tug, pushed off the
    /// target by its distance terms, swung the ship's head up to 15 deg towards
    /// it at close quarters. Scheme III (distance cost only, no COLREGS logic)
    /// has no floor, as in the paper.
    fn heading_floor(&mut self, m: &Measurement, altered: bool) -> Option<f64> {
        let psi = m.ship[2];
        // The heading off the route's course, + to starboard.
        let off = wrap_angle(psi - self.route_course(m));
        let alters = self.config.tuning.scheme.alters();
        let mut floor: Option<f64> = None;
        for k in 0..MAX_OBSTACLES {
            let situation = self.guidance.situation(k);
            let no_port_turn = match situation {
                Some(
                    Situation::HeadOn | Situation::CrossingGiveWay | Situation::CrossingStandOn,
                ) => true,
                Some(Situation::BeingOvertaken) => {
                    let o = &m.obstacles[k];
                    wrap_angle((o.y - m.ship[1]).atan2(o.x - m.ship[0]) - psi) < 0.0
                }
                _ => false,
            };
            let binding = alters && !self.guidance.past_and_clear(k) && no_port_turn;
            if !binding {
                self.carried.port_turn_anchor[k] = None;
                continue;
            }
            // Ratchet: a starboard alteration is not taken back before the
            // situation ends (Rule 8(d): until the target is past and clear). A tow
            // that stands on and has not altered keeps the course she had (Rule
            // 17(a)(i)): no ratchet, since her head lagging behind a port bend of
            // the route is no alteration to hold.
            let stands_on = matches!(
                situation,
                Some(Situation::CrossingStandOn | Situation::BeingOvertaken)
            );
            let anchor = match self.carried.port_turn_anchor[k] {
                Some(a) if a > off || (stands_on && !altered) => a,
                _ => off,
            };
            self.carried.port_turn_anchor[k] = Some(anchor);
            // Relative to the current heading, so that wrapping cannot matter.
            let limit = anchor - off - self.config.tuning.tracking.port_turn_margin;
            floor = Some(floor.map_or(limit, |f: f64| f.max(limit)));
        }
        floor.map(|f| psi + f)
    }

    /// The course of following the route from where the ship is (rad): the bearing of
    /// the point [`TrackingParams::lookahead`] farther along the route from her nearest
    /// point on it ([`Polyline::course_ahead`], the course the analyzer measures course
    /// changes against, `docs/analyzer.md`, "Course changes"); 0 for a route without
    /// length.
    fn route_course(&self, m: &Measurement) -> f64 {
        let lookahead = self.config.tuning.tracking.lookahead;
        (self.route)
            .course_ahead([m.ship[0], m.ship[1]], lookahead)
            .unwrap_or(0.0)
    }

    /// Whether the tow gives way to the crossing target in slot `giving_way_to` with her
    /// altered course out of water: she has slackened to half
    /// [`towing_guidance::GuidanceSettings::resume_speed`] or less, and on the reference
    /// `course` a vessel of the tow (ship, tugs, from where they are now) comes within
    /// its bank margin of the waterway ([`ControllerConfig::waterway`]) inside the water
    /// she needs to take her way off at `give_way_deceleration` from her present surge,
    /// plus one ship length in hand ([`towing_model::Lane::room_ahead`]). Latched for
    /// the slot until the alteration for it ends: the tow then keeps the way off (Rule
    /// 8(e): "slacken her speed or take all way off"), since she can neither hold the
    /// altered course nor turn back to port while the target is not past and clear
    /// (Rules 8(d), 15; `docs/colregs.md`, section 4). Held against the bank she
    /// crabbed and gathered way again before the target was past (random-12-0042). A tow
    /// still at speed is not braked by this rule: braking with her head held off the
    /// bank made her crab (drift 31-33 deg, `docs/assumptions.md`). No waterway (or
    /// scheme III): never.
    fn short_of_water(
        &mut self,
        m: &Measurement,
        course: f64,
        giving_way_to: Option<usize>,
    ) -> bool {
        let Some(slot) = giving_way_to else {
            self.carried.short_of_water = None;
            return false;
        };
        if self.carried.short_of_water == Some(slot) {
            return true;
        }
        let Some((lane, margins)) = &self.waterway else {
            return false;
        };
        let settings = self.guidance.params().settings();
        let u = m.ship[3].max(0.0);
        if u > 0.5 * settings.resume_speed {
            return false;
        }
        let need = u * u / (2.0 * self.config.tuning.tracking.give_way_deceleration)
            + settings.ship_length;
        let short = m
            .positions()
            .iter()
            .zip(margins)
            .any(|(&p, &margin)| lane.room_ahead(p, course, margin, need) < need);
        self.carried.short_of_water = if short { Some(slot) } else { None };
        short
    }

    /// The inner loop's parameters.
    #[must_use]
    pub fn inner_loop(&self) -> InnerLoopParams {
        self.config.tuning.inner
    }

    /// The spare plan's first sample, within the bounds and rate bounds of the
    /// applied command. Once the spare plan is used up (or without one), the
    /// command goes to rest ([`Controller::rest_plan`]); the tow then drifts to a
    /// stop.
    fn fallback_command(&mut self) -> (ShipInput, [TugInput; 2]) {
        let have_spare = self.carried.spare_left > 0;
        self.carried.spare_left = self.carried.spare_left.saturating_sub(1);
        let wanted = if have_spare {
            (
                self.carried.spare_ship[0],
                [self.carried.spare_tugs[0][0], self.carried.spare_tugs[1][0]],
            )
        } else {
            self.rest_plan()
        };
        self.within_bounds(wanted)
    }

    /// At rest: the tensions at the pretension, the angles at zero, no thrust.
    fn rest_plan(&self) -> (ShipInput, [TugInput; 2]) {
        let p = &self.config.tuning.ship;
        ([p.min_tension, p.min_tension, 0.0, 0.0], [[0.0; 3]; 2])
    }

    /// `wanted` as near as one sample allows: the tensions and angles within
    /// their bounds and their rate bounds from the applied command (a value not
    /// finite holds the applied one), the thrusts within their limits (not
    /// finite: 0).
    fn within_bounds(
        &self,
        (wanted, wanted_tugs): (ShipInput, [TugInput; 2]),
    ) -> (ShipInput, [TugInput; 2]) {
        let p = &self.config.tuning.ship;
        let ts = self.config.tuning.prediction.sample_time;
        let (tension_step, angle_step) = (p.tension_rate * ts, p.angle_rate * ts);
        let prev = self.carried.applied.ship;
        let mut ship = [0.0; 4];
        for i in 0..2 {
            let lo = (prev[i] - tension_step).max(p.min_tension);
            let hi = (prev[i] + tension_step).min(p.max_tension);
            ship[i] = finite_or(wanted[i], prev[i]).clamp(lo.min(hi), hi);
            let lo = (prev[2 + i] - angle_step).max(-p.max_angle);
            let hi = (prev[2 + i] + angle_step).min(p.max_angle);
            ship[2 + i] = finite_or(wanted[2 + i], prev[2 + i]).clamp(lo.min(hi), hi);
        }
        let tugs = std::array::from_fn(|i| {
            std::array::from_fn(|c| {
                let l = self.thrust_limit[i][c];
                finite_or(wanted_tugs[i][c], 0.0).clamp(-l, l)
            })
        });
        (ship, tugs)
    }

    /// Copies the nearest obstacles (by range from the tow) into the MPC's list;
    /// returns how many, and which of them the distance cost leaves out: in schemes
    /// I and II, the targets the tow stands on until Rule 17 allows action
    /// ([`towing_guidance::ReferenceSystem::stands_on`]) and the target ships past
    /// their closest approach abaft the beam ([`Controller::passed_abaft`]); their
    /// clearance rows stay.
    fn select_obstacles(&mut self, m: &Measurement) -> (usize, u64) {
        let t = &self.config.tuning;
        let slots = t
            .ship
            .clearance
            .max_obstacles
            .min(t.tug.clearance.max_obstacles);
        let points = m.positions();
        let ts = self.config.tuning.prediction.sample_time;
        let mut candidates: [(f64, usize); MAX_OBSTACLES] = [(f64::INFINITY, 0); MAX_OBSTACLES];
        let mut n = 0;
        for (k, o) in m.obstacles.iter().enumerate() {
            // Validated in `sample`.
            let Ok(Some(_)) = ActiveObstacle::from_slot(o) else {
                continue;
            };
            let obstacle = mpc_obstacle(o, ts);
            let range = points
                .iter()
                .map(|&p| obstacle.distance(p).0)
                .fold(f64::INFINITY, f64::min);
            candidates[n] = (range, k);
            n += 1;
        }
        candidates[..n].sort_by(|a, b| a.0.total_cmp(&b.0));
        let used = n.min(slots);
        let mut off = 0u64;
        let alters = self.config.tuning.scheme.alters();
        for (j, &(_, k)) in candidates[..used].iter().enumerate() {
            self.mpc_obstacles[j] = mpc_obstacle(&m.obstacles[k], ts);
            if alters && (self.guidance.stands_on(k) || Self::passed_abaft(m, &m.obstacles[k])) {
                off |= 1 << j;
            }
        }
        (used, off)
    }

    /// Whether target ship `o` is past its closest approach abaft the ship's beam: abaft
    /// the beam with the range opening ([`towing_model::geometry::abaft_and_opening`],
    /// the ship's ground velocity). The distance cost leaves it out (`docs/colregs.md`,
    /// section 4, "Passed abaft the beam"); its clearance rows stay.
    fn passed_abaft(m: &Measurement, o: &ObstacleSlot) -> bool {
        let [x, y, psi, u, v, _] = m.ship;
        o.kind == ObstacleKind::VesselEllipse
            && abaft_and_opening(
                [x, y],
                psi,
                body_to_ned(psi, u, v),
                [o.x, o.y],
                [o.speed * o.psi.cos(), o.speed * o.psi.sin()],
            )
    }

    /// The predicted states of the applied command: the plan's (finite, checked
    /// in [`Controller::apply`]); without a plan (a fallback, a rest) the ship's
    /// rollout of the applied command, or the measured states held where that
    /// rollout is not finite (speeds far beyond the model's range), and the tugs
    /// held.
    fn prediction(&self, m: &Measurement, from_plan: bool) -> Prediction {
        let mut out = Prediction {
            ship: [m.ship; HORIZON],
            tugs: [[m.tugs[0]; HORIZON], [m.tugs[1]; HORIZON]],
        };
        if from_plan {
            out.ship = *self.solver.ship_predicted();
            for i in 0..2 {
                out.tugs[i] = self.solver.tug_predicted(i);
            }
        } else {
            let model: &ShipModel = self.solver.ship_model();
            let rollout = model.rollout::<HORIZON>(&m.ship, &[self.carried.applied.ship; HORIZON]);
            if rollout.iter().flatten().all(|v| v.is_finite()) {
                out.ship = rollout;
            }
        }
        out
    }
}

/// `goal` moved square to the segment `leg` to `offset` m to its starboard side if it
/// lies nearer the route than that (the offset the tow has gained while altered,
/// [`towing_guidance::GuidanceOutput::offset_held`]); else `goal`. The tracked point
/// of an alteration never lies to port of the track the tow has reached: past each
/// waypoint the altered leg starts on the route again, and its point lay up to 14 deg
/// to port of the route for a tow already 1.6-3.2 m to starboard of it, which turned
/// her back towards the vessel she was overtaking (random-12-0067,
/// `docs/colregs.md` section 2, step 7).
fn lift_to_offset(goal: [f64; 3], leg: ([f64; 2], [f64; 2]), offset: f64) -> [f64; 3] {
    let (a, b) = leg;
    let Some((across, n)) = starboard_offset(a, b, [goal[0], goal[1]]).filter(|_| offset > 0.0)
    else {
        return goal;
    };
    let lift = (offset - across).max(0.0);
    [goal[0] + lift * n[0], goal[1] + lift * n[1], goal[2]]
}

/// The angle `to`, or the one at most `max` (rad, > 0) from `from` towards it, wrapped to
/// `(-pi, pi]`.
fn turn_towards(from: f64, to: f64, max: f64) -> f64 {
    wrap_angle(from + wrap_angle(to - from).clamp(-max, max))
}

fn finite_or(v: f64, default: f64) -> f64 {
    if v.is_finite() {
        v
    } else {
        default
    }
}

/// The MPC's shape of an obstacle slot: a circle of radius `max(L, W) / 2`, or
/// the ellipse with semi-axes `L / 2`, `W / 2` along the target's course,
/// moving on at its course and speed over the horizon (`sample_time` s per
/// sample).
fn mpc_obstacle(o: &ObstacleSlot, sample_time: f64) -> Obstacle {
    if o.kind == ObstacleKind::StaticCircle {
        Obstacle::Circle {
            centre: [o.x, o.y],
            radius: 0.5 * o.length.max(o.width),
        }
    } else {
        Obstacle::Ellipse {
            centre: [o.x, o.y],
            semi_major: 0.5 * o.length,
            semi_minor: 0.5 * o.width.min(o.length),
            orientation: o.psi,
            drift: [
                o.speed * o.psi.cos() * sample_time,
                o.speed * o.psi.sin() * sample_time,
            ],
        }
    }
}

/// The ship's and the tugs' MPC parameters a [`Controller`] of `config` uses: the
/// tuning's, with the bank rows when [`ControllerConfig::mpc_waterway_half_width`] gives
/// a waterway (schemes I and II) and the distance weights zeroed when the scheme has no
/// distance cost (scheme II). Every scheme keeps
/// the tugs' yaw-rate and own-ship rows: they model the tugs, not the avoidance
/// (`docs/assumptions.md`, "SCP trust region").
#[must_use]
pub fn mpc_params(
    config: &ControllerConfig,
) -> (towing_mpc::ShipMpcParams, towing_mpc::TugMpcParams) {
    let (mut ship, mut tug) = (config.tuning.ship, config.tuning.tug);
    ship.waterway_rows = config.mpc_waterway_half_width().is_some();
    tug.waterway_rows = ship.waterway_rows;
    if !config.tuning.scheme.distance_cost() {
        ship.weight_distance = 0.0;
        tug.weight_distance = 0.0;
    }
    (ship, tug)
}

fn mpc_error(architecture: Architecture) -> impl Fn(AdmmBuildError) -> ConfigError {
    move |source| ConfigError::Mpc {
        architecture: match architecture {
            Architecture::Distributed => "distributed",
            Architecture::Centralized => "centralized",
        },
        source,
    }
}

/// A fresh centralized MPC with exactly the parameters and prediction models a
/// [`Controller`] of `config` would use if its architecture were centralized: for
/// tools that solve the controller's recorded problems again outside the loop
/// ([`Controller::last_mpc_input`], the side-by-side baseline).
///
/// # Errors
/// As [`Controller::new`] for the MPC's models and parameters.
pub fn centralized_mpc(config: &ControllerConfig) -> Result<Centralized, ConfigError> {
    let mpc = mpc_error(Architecture::Centralized);
    let (ship_params, tug_params) = mpc_params(config);
    let (ship, tugs, formation) = prediction_models(config).map_err(&mpc)?;
    Centralized::new(
        ship,
        tugs,
        formation,
        ship_params,
        tug_params,
        config.tuning.centralized,
    )
    .map_err(mpc)
}

/// The optimizer of the configured architecture, on prediction models with the
/// configured hulls.
fn build_optimizer(config: &ControllerConfig) -> Result<Box<dyn Optimizer>, ConfigError> {
    let t = &config.tuning;
    Ok(match t.architecture {
        Architecture::Distributed => {
            let mpc = mpc_error(t.architecture);
            let (ship_params, tug_params) = mpc_params(config);
            let (ship, tugs, formation) = prediction_models(config).map_err(&mpc)?;
            let tug = |model| TugMpc::new(model, tug_params).map_err(AdmmBuildError::from);
            let [t1, t2] = tugs;
            Box::new(
                Admm::new(
                    ShipMpc::new(ship, formation, ship_params).map_err(|e| mpc(e.into()))?,
                    [tug(t1).map_err(&mpc)?, tug(t2).map_err(&mpc)?],
                    t.admm,
                )
                .map_err(|e| mpc(e.into()))?,
            )
        }
        Architecture::Centralized => Box::new(centralized_mpc(config)?),
    })
}

/// The prediction models of the scenario's vessels: the configured user hulls,
/// or the built-in hull ([`ControllerConfig::hull`]); and the formation map.
fn prediction_models(
    config: &ControllerConfig,
) -> Result<(ShipModel, [TugModel; 2], FormationMap), AdmmBuildError> {
    let s = &config.scenario;
    let p = config.tuning.prediction;
    let formation = FormationMap::from_scenario(s)?;
    Ok(match &config.hulls {
        None => {
            let hull = config.hull();
            (
                ShipModel::from_scenario(s, hull, p)?,
                [
                    TugModel::from_scenario(s, 0, hull, p)?,
                    TugModel::from_scenario(s, 1, hull, p)?,
                ],
                formation,
            )
        }
        Some(h) => {
            let tug = |i: usize| {
                TugModel::with_hull(
                    i,
                    PredictionHull::custom(h.tugs[i].clone_box()),
                    &s.tug_data[i],
                    p,
                )
            };
            (
                ShipModel::with_hull(PredictionHull::custom(h.ship.clone_box()), &s.ship_data, p)?,
                [tug(0)?, tug(1)?],
                formation,
            )
        }
    })
}

#[cfg(test)]
mod tests {
    use super::lift_to_offset;

    #[test]
    fn a_tracked_point_nearer_the_route_than_the_offset_held_is_lifted_to_it() {
        // A northbound leg; East is starboard.
        let leg = ([0.0, 0.0], [10.0, 0.0]);
        let lifted = lift_to_offset([5.0, 0.5, 0.3], leg, 1.5);
        assert_eq!(lifted, [5.0, 1.5, 0.3]);
        // Already as far to starboard, or nothing held: unchanged.
        assert_eq!(lift_to_offset([5.0, 2.0, 0.3], leg, 1.5), [5.0, 2.0, 0.3]);
        assert_eq!(lift_to_offset([5.0, -1.0, 0.3], leg, 0.0), [5.0, -1.0, 0.3]);
        // A point to port of the route goes square to the leg.
        let lifted = lift_to_offset([5.0, -1.0, 0.3], leg, 1.5);
        assert!((lifted[0] - 5.0).abs() < 1e-15 && (lifted[1] - 1.5).abs() < 1e-15);
    }
}
