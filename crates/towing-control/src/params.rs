//! The controller's parameter registry: every tuning value of [`Tuning`] is one
//! entry here, with its name, type, unit, range, description (with its source)
//! and how it reads and writes the tuning. From it come the FMU's parameters and
//! their model-description variables, the checks both the FMU and
//! [`crate::ControllerConfig`] apply (one function, one message), and the
//! parameter table of `docs/interface.md`. A new parameter is one entry.
//!
//! Names are grouped, `group.name` (`docs/interface.md`, "Parameters"):
//!
//! | group | what |
//! |---|---|
//! | `mpc` | the MPC's sampling, prediction, time budget and hull |
//! | `mpc.ship` | the coordination (ship) problem: weights of eq. (13), bounds (17)-(21) |
//! | `mpc.tug` | the tug problems: weights of eq. (16), thrust bounds (19) |
//! | `admm` | the distributed MPC's ADMM (Algorithm 1) |
//! | `centralized` | the centralized MPC's SCP loop and move suppression |
//! | `guidance` | the COLREGS reference system (eq. (8)-(11), (14)) |
//! | `waterway` | the waterway's half width |
//! | `tracking` | how the MPC tracks the reference (lookahead, line of sight, heading floor) |
//! | `inner_loop` | the tugs' inner stabilising loop |
//! | `fmi` | how the FMU reports to its master (fmi2DoStep statuses) |
//!
//! `architecture` and `avoidance_scheme` keep their ungrouped names (the masters
//! and the interface contract use them). Every Real declares its unit, one unit
//! per name; a value that comes from the scenario has a Boolean switch
//! (`mpc.hull_from_scenario`, `waterway.from_scenario`), never a sentinel value; a
//! choice is an FMI Enumeration whose items keep the codes masters have always set
//! (`architecture` [`Architecture::ENUMERATION`], `avoidance_scheme`
//! [`AvoidanceScheme::ENUMERATION`], `mpc.hull_model` [`HullModel::ENUMERATION`]).

use towing_model::registry;
use towing_model::HullModel;

pub use towing_model::registry::{Kind as GenericKind, Limit, Value};

use crate::config::{Architecture, AvoidanceScheme, Tuning};
use crate::error::ConfigError;

/// A parameter of the controller.
pub type Parameter = registry::Parameter<Tuning>;
/// Its type, range and accessors.
pub type Kind = registry::Kind<Tuning>;

/// The parameter named `name`.
#[must_use]
pub fn find(name: &str) -> Option<&'static Parameter> {
    registry::find(PARAMETERS, name)
}

/// The rules between parameters, after each one's range: `F_min <= F_max`, at
/// most [`towing_mpc::params::MAX_SUBSTEPS`] RK4 substeps per sample, and the
/// settings structs' own checks (which the ranges above imply; kept as a
/// backstop, reported under the registry's names).
///
/// # Errors
/// The first rule broken, by the parameter that breaks it.
pub fn check_relations(t: &Tuning) -> Result<(), ConfigError> {
    let s = &t.ship;
    if s.min_tension > s.max_tension {
        return Err(ConfigError::new(
            "mpc.ship.min_tension",
            format!(
                "must be <= mpc.ship.max_tension = {} N, got {} N",
                s.max_tension, s.min_tension
            ),
        ));
    }
    let prefixed = |group: &str| {
        let group = group.to_owned();
        move |e: towing_model::ParamError| {
            ConfigError::new(&format!("{group}.{}", e.field), e.reason)
        }
    };
    t.prediction.validate().map_err(|e| {
        let name = if e.field == "sample_time" {
            "mpc.sample_time"
        } else {
            "mpc.prediction_step"
        };
        ConfigError::new(name, e.reason)
    })?;
    t.admm.validate().map_err(prefixed("admm"))?;
    t.centralized.validate().map_err(prefixed("centralized"))?;
    Ok(())
}

/// Every parameter of the controller (module docs), in the order of the model
/// description.
pub static PARAMETERS: &[Parameter] = &[
    Parameter {
        name: "architecture",
        old_name: Some("architecture"),
        description: "Which MPC computes the commands: distributed, ADMM over the coordination and the tug problems (Du et al. 2022, Algorithm 1; the paper's method), or centralized, one MPC over all inputs (eq. (12); the paper's Table 7 comparison)",
        kind: Kind::Enumeration {
            enumeration: &Architecture::ENUMERATION,
            get: |t| t.architecture.code(),
            // Only an item's value reaches the setter (`Parameter::set`).
            set: |t, v| t.architecture = Architecture::from_code(v).unwrap_or_default(),
        },
    },
    Parameter {
        name: "avoidance_scheme",
        old_name: Some("avoidance_scheme"),
        description: "The paper's avoidance schemes (Du et al. 2022, section 4.2): I waypoint altering and distance cost, the paper's main scheme; II altering only (the distance weights forced to 0); III distance cost only (unaltered route)",
        kind: Kind::Enumeration {
            enumeration: &AvoidanceScheme::ENUMERATION,
            get: |t| t.scheme.code(),
            // Only an item's value reaches the setter (`Parameter::set`).
            set: |t, v| t.scheme = AvoidanceScheme::from_code(v).unwrap_or_default(),
        },
    },
    Parameter {
        name: "mpc.sample_time",
        old_name: Some("sample_time"),
        description: "MPC sample time T_s: the controller samples at startTime + k T_s (a communication point within 1 us of it, or the first one after it) and holds its plan in between, independent of the communication step; 1 s as Du et al. 2022, Table 3",
        kind: Kind::Real {
            unit: "s",
            min: Limit::Above(0.0),
            max: Limit::AtMost(60.0),
            get: |t| t.prediction.sample_time,
            set: |t, v| t.prediction.sample_time = v,
        },
    },
    Parameter {
        name: "mpc.prediction_step",
        old_name: Some("prediction_step"),
        description: "Largest RK4 substep of the MPC's predictions (at most 100000 substeps per sample); 0.1 s keeps the linearisation accurate at the paper's speeds (docs/assumptions.md)",
        kind: Kind::Real {
            unit: "s",
            min: Limit::Above(0.0),
            max: Limit::AtMost(60.0),
            get: |t| t.prediction.integration_step,
            set: |t, v| t.prediction.integration_step = v,
        },
    },
    Parameter {
        name: "mpc.sample_time_budget",
        old_name: None,
        description: "Wall-clock budget of one control sample; 0: none (the default: runs are deterministic). When set, the optimisation stops after the ADMM iteration or SCP step that spends it and applies the best iterate so far, which satisfies every bound (reported by mpc.budget_hit)",
        kind: Kind::Real {
            unit: "s",
            min: Limit::AtLeast(0.0),
            max: Limit::AtMost(60.0),
            get: |t| t.sample_time_budget,
            set: |t, v| t.sample_time_budget = v,
        },
    },
    Parameter {
        name: "mpc.hull_from_scenario",
        old_name: Some("hull_model"),
        description: "true: the MPC's prediction models use the hull damping model of the scenario's [simulation] section (the plant's default too); false: mpc.hull_model",
        kind: Kind::Boolean {
            get: |t| t.hull_from_scenario,
            set: |t, v| t.hull_from_scenario = v,
        },
    },
    Parameter {
        name: "mpc.hull_model",
        old_name: Some("hull_model"),
        description: "Hull damping of the MPC's prediction models when mpc.hull_from_scenario is false: linear_damping (constant D, the paper's eq. (1)) or nonlinear_damping (Skjetne et al. 2004)",
        kind: Kind::Enumeration {
            enumeration: &HullModel::ENUMERATION,
            get: |t| t.hull.code(),
            // Only an item's value reaches the setter (`Parameter::set`).
            set: |t, v| t.hull = HullModel::from_code(v).unwrap_or_default(),
        },
    },
    Parameter {
        name: "mpc.ship.weight_position",
        old_name: Some("w_S1"),
        description: "Coordination (ship) MPC: weight of the position error x, y in eq. (13); 1 as Du et al. 2022, Table 3",
        kind: Kind::Real {
            unit: "1/m2",
            min: Limit::AtLeast(0.0),
            max: Limit::None,
            get: |t| t.ship.weight_position,
            set: |t, v| t.ship.weight_position = v,
        },
    },
    Parameter {
        name: "mpc.ship.weight_heading",
        old_name: Some("w_S1"),
        description: "Coordination (ship) MPC: weight of the heading error in eq. (13); 10 (Du et al. 2022, Table 3: 1), so that the ship turns to her reference course rather than being dragged sideways (docs/assumptions.md)",
        kind: Kind::Real {
            unit: "1/rad2",
            min: Limit::AtLeast(0.0),
            max: Limit::None,
            get: |t| t.ship.weight_heading,
            set: |t, v| t.ship.weight_heading = v,
        },
    },
    Parameter {
        name: "mpc.ship.weight_surge",
        old_name: Some("w_S2"),
        description: "Coordination (ship) MPC: weight of the surge speed u in eq. (13); 75 as Du et al. 2022, Table 3",
        kind: Kind::Real {
            unit: "s2/m2",
            min: Limit::AtLeast(0.0),
            max: Limit::None,
            get: |t| t.ship.weight_surge,
            set: |t, v| t.ship.weight_surge = v,
        },
    },
    Parameter {
        name: "mpc.ship.weight_sway",
        old_name: Some("w_S2"),
        description: "Coordination (ship) MPC: weight of the sway speed v in eq. (13); 75 as Du et al. 2022, Table 3",
        kind: Kind::Real {
            unit: "s2/m2",
            min: Limit::AtLeast(0.0),
            max: Limit::None,
            get: |t| t.ship.weight_sway,
            set: |t, v| t.ship.weight_sway = v,
        },
    },
    Parameter {
        name: "mpc.ship.weight_yaw_rate",
        old_name: Some("w_S2_yaw"),
        description: "Coordination (ship) MPC: weight of the yaw rate r in eq. (13); 75 as Du et al. 2022, Table 3",
        kind: Kind::Real {
            unit: "s2/rad2",
            min: Limit::AtLeast(0.0),
            max: Limit::None,
            get: |t| t.ship.weight_yaw_rate,
            set: |t, v| t.ship.weight_yaw_rate = v,
        },
    },
    Parameter {
        name: "mpc.ship.weight_distance",
        old_name: Some("w_S3"),
        description: "Coordination (ship) MPC: weight of the obstacle distance cost phi (in 1/m2) in eq. (13); 1 as Du et al. 2022, Table 3 (forced to 0 by avoidance_scheme 2)",
        kind: Kind::Real {
            unit: "m2",
            min: Limit::AtLeast(0.0),
            max: Limit::None,
            get: |t| t.ship.weight_distance,
            set: |t, v| t.ship.weight_distance = v,
        },
    },
    Parameter {
        name: "mpc.ship.weight_tension",
        old_name: Some("tension_weight"),
        description: "Weight w_F of the tensions' squares, a regulariser the paper does not have: it picks the least tension among equal-cost plans instead of a tug of war (docs/assumptions.md); 0 reproduces eq. (13)",
        kind: Kind::Real {
            unit: "1/N2",
            min: Limit::AtLeast(0.0),
            max: Limit::None,
            get: |t| t.ship.weight_tension,
            set: |t, v| t.ship.weight_tension = v,
        },
    },
    Parameter {
        name: "mpc.ship.weight_towing_angle",
        old_name: Some("angle_weight"),
        description: "Weight w_alpha of the towing angles' squares, a regulariser the paper does not have: without it the angles drift while the lines are slack (docs/assumptions.md); 0 reproduces eq. (13)",
        kind: Kind::Real {
            unit: "1/rad2",
            min: Limit::AtLeast(0.0),
            max: Limit::None,
            get: |t| t.ship.weight_towing_angle,
            set: |t, v| t.ship.weight_towing_angle = v,
        },
    },
    Parameter {
        name: "mpc.ship.weight_port_turn",
        old_name: Some("port_turn_weight"),
        description: "Weight w_P of the one-sided heading term w_P min(0, psi - psi_floor)^2 below the COLREGS heading floor; not in the paper; 100 (docs/assumptions.md)",
        kind: Kind::Real {
            unit: "1/rad2",
            min: Limit::AtLeast(0.0),
            max: Limit::None,
            get: |t| t.ship.weight_port_turn,
            set: |t, v| t.ship.weight_port_turn = v,
        },
    },
    Parameter {
        name: "mpc.ship.min_tension",
        old_name: Some("min_tension"),
        description: "Smallest commanded tension F_min, eq. (18), where the paper has 0: a pretension keeping both lines taut so the formation stays defined (docs/assumptions.md); at most mpc.ship.max_tension",
        kind: Kind::Real {
            unit: "N",
            min: Limit::AtLeast(0.0),
            max: Limit::None,
            get: |t| t.ship.min_tension,
            set: |t, v| t.ship.min_tension = v,
        },
    },
    Parameter {
        name: "mpc.ship.holding_tension",
        old_name: None,
        description: "While the way is off (the ship's plan capped in surge: Rule 17's way off, the give-way way off) the smallest tension of each line instead of mpc.ship.min_tension, reached from the previous command within the rate bound mpc.ship.tension_rate, so the tugs' sideways pull F sin(alpha) can turn and hold the stopped ship; at most mpc.ship.min_tension: no effect; 0.3 N (docs/assumptions.md)",
        kind: Kind::Real {
            unit: "N",
            min: Limit::AtLeast(0.0),
            max: Limit::None,
            get: |t| t.ship.holding_tension,
            set: |t, v| t.ship.holding_tension = v,
        },
    },
    Parameter {
        name: "mpc.ship.max_tension",
        old_name: Some("max_tension"),
        description: "Largest towline tension F_max, eq. (18); 3 N as Table 3",
        kind: Kind::Real {
            unit: "N",
            min: Limit::Above(0.0),
            max: Limit::None,
            get: |t| t.ship.max_tension,
            set: |t, v| t.ship.max_tension = v,
        },
    },
    Parameter {
        name: "mpc.ship.max_towing_angle",
        old_name: Some("max_towing_angle"),
        description: "Largest towing angle alpha_max, eq. (17); 30 deg as Table 3",
        kind: Kind::Real {
            unit: "rad",
            min: Limit::Above(0.0),
            max: Limit::Below(std::f64::consts::FRAC_PI_2),
            get: |t| t.ship.max_angle,
            set: |t, v| t.ship.max_angle = v,
        },
    },
    Parameter {
        name: "mpc.ship.tension_rate",
        old_name: Some("tension_rate"),
        description: "Largest tension change per second, eq. (21): the change per sample is bounded by tension_rate * mpc.sample_time; 0.3 N per 1 s sample as Table 3",
        kind: Kind::Real {
            unit: "N/s",
            min: Limit::Above(0.0),
            max: Limit::None,
            get: |t| t.ship.tension_rate,
            set: |t, v| t.ship.tension_rate = v,
        },
    },
    Parameter {
        name: "mpc.ship.towing_angle_rate",
        old_name: Some("angle_rate"),
        description: "Largest towing-angle change per second, eq. (20): the change per sample is bounded by towing_angle_rate * mpc.sample_time; 5 deg per 1 s sample as Table 3",
        kind: Kind::Real {
            unit: "rad/s",
            min: Limit::Above(0.0),
            max: Limit::None,
            get: |t| t.ship.angle_rate,
            set: |t, v| t.ship.angle_rate = v,
        },
    },
    Parameter {
        name: "mpc.tug.weight_position",
        old_name: Some("w_T1"),
        description: "Tug MPCs: weight of the position error x, y in eq. (16); 1 as Du et al. 2022, Table 3",
        kind: Kind::Real {
            unit: "1/m2",
            min: Limit::AtLeast(0.0),
            max: Limit::None,
            get: |t| t.tug.weight_position,
            set: |t, v| t.tug.weight_position = v,
        },
    },
    Parameter {
        name: "mpc.tug.weight_heading",
        old_name: Some("w_T1"),
        description: "Tug MPCs: weight of the heading error in eq. (16); 1 as Du et al. 2022, Table 3",
        kind: Kind::Real {
            unit: "1/rad2",
            min: Limit::AtLeast(0.0),
            max: Limit::None,
            get: |t| t.tug.weight_heading,
            set: |t, v| t.tug.weight_heading = v,
        },
    },
    Parameter {
        name: "mpc.tug.weight_surge",
        old_name: Some("w_T2"),
        description: "Tug MPCs: weight of the surge speed u in eq. (16); 6 as Du et al. 2022, Table 3",
        kind: Kind::Real {
            unit: "s2/m2",
            min: Limit::AtLeast(0.0),
            max: Limit::None,
            get: |t| t.tug.weight_surge,
            set: |t, v| t.tug.weight_surge = v,
        },
    },
    Parameter {
        name: "mpc.tug.weight_sway",
        old_name: Some("w_T2"),
        description: "Tug MPCs: weight of the sway speed v in eq. (16); 6 as Du et al. 2022, Table 3",
        kind: Kind::Real {
            unit: "s2/m2",
            min: Limit::AtLeast(0.0),
            max: Limit::None,
            get: |t| t.tug.weight_sway,
            set: |t, v| t.tug.weight_sway = v,
        },
    },
    Parameter {
        name: "mpc.tug.weight_yaw_rate",
        old_name: Some("w_T2"),
        description: "Tug MPCs: weight of the yaw rate r in eq. (16); 6 as Du et al. 2022, Table 3",
        kind: Kind::Real {
            unit: "s2/rad2",
            min: Limit::AtLeast(0.0),
            max: Limit::None,
            get: |t| t.tug.weight_yaw_rate,
            set: |t, v| t.tug.weight_yaw_rate = v,
        },
    },
    Parameter {
        name: "mpc.tug.weight_distance",
        old_name: Some("w_T3"),
        description: "Tug MPCs: weight of the obstacle distance cost phi (in 1/m2) in eq. (16); 1 as Du et al. 2022, Table 3 (forced to 0 by avoidance_scheme 2)",
        kind: Kind::Real {
            unit: "m2",
            min: Limit::AtLeast(0.0),
            max: Limit::None,
            get: |t| t.tug.weight_distance,
            set: |t, v| t.tug.weight_distance = v,
        },
    },
    Parameter {
        name: "mpc.tug.max_force_surge",
        old_name: Some("max_thrust_surge"),
        description: "Tug surge force |X| limit, eq. (19) (the tug's own actuator limit of the scenario applies too); 10 as Table 3",
        kind: Kind::Real {
            unit: "N",
            min: Limit::Above(0.0),
            max: Limit::None,
            get: |t| t.tug.thrust_limit[0],
            set: |t, v| t.tug.thrust_limit[0] = v,
        },
    },
    Parameter {
        name: "mpc.tug.max_force_sway",
        old_name: Some("max_thrust_sway"),
        description: "Tug sway force |Y| limit, eq. (19) (the tug's own actuator limit of the scenario applies too); 10 as Table 3",
        kind: Kind::Real {
            unit: "N",
            min: Limit::Above(0.0),
            max: Limit::None,
            get: |t| t.tug.thrust_limit[1],
            set: |t, v| t.tug.thrust_limit[1] = v,
        },
    },
    Parameter {
        name: "mpc.tug.max_moment_yaw",
        old_name: Some("max_yaw_moment"),
        description: "Tug yaw moment |N| limit, eq. (19) (the tug's own actuator limit of the scenario applies too); 10 as Table 3",
        kind: Kind::Real {
            unit: "N.m",
            min: Limit::Above(0.0),
            max: Limit::None,
            get: |t| t.tug.thrust_limit[2],
            set: |t, v| t.tug.thrust_limit[2] = v,
        },
    },
    Parameter {
        name: "mpc.tug.max_yaw_rate",
        old_name: None,
        description: "Soft limit of each tug's predicted yaw rate |r| (schemes I and II; not in the paper): the TitoNeri's yaw is nearly undamped and 10 N.m held over a sample spins it up by 4.3 rad/s; without the limit tugs spun up to 30 rad/s in the encounter suites; 0.5 rad/s (docs/assumptions.md)",
        kind: Kind::Real {
            unit: "rad/s",
            min: Limit::Above(0.0),
            max: Limit::None,
            get: |t| t.tug.max_yaw_rate,
            set: |t, v| t.tug.max_yaw_rate = v,
        },
    },
    Parameter {
        name: "admm.rho",
        old_name: Some("rho"),
        description: "ADMM penalty rho of eq. (22), per m^2 of position and per rad^2 of heading residual; not given by the paper, 10 chosen by measurement (the paper scenario's distributed runs under small perturbations, docs/assumptions.md)",
        kind: Kind::Real {
            unit: "1/m2",
            min: Limit::AtLeast(0.0),
            max: Limit::None,
            get: |t| t.admm.rho,
            set: |t, v| t.admm.rho = v,
        },
    },
    Parameter {
        name: "admm.max_iterations",
        old_name: Some("max_iterations"),
        description: "Most ADMM iterations S per sample (Algorithm 1); not given by the paper, 30 chosen by measurement (docs/assumptions.md). The last iterate is applied when eq. (29) is not met (admm.converged = false)",
        kind: Kind::Integer {
            min: 1,
            max: 100,
            get: |t| i32::try_from(t.admm.max_iterations).unwrap_or(i32::MAX),
            set: |t, v| t.admm.max_iterations = usize::try_from(v).unwrap_or(1),
        },
    },
    Parameter {
        name: "admm.eps_abs",
        old_name: Some("eps_abs"),
        description: "Absolute tolerance of the ADMM stopping rule, eq. (29), in the residual's units (m of position, rad of heading); 1e-3 as Table 3",
        kind: Kind::Real {
            unit: "m",
            min: Limit::Above(0.0),
            max: Limit::None,
            get: |t| t.admm.eps_abs,
            set: |t, v| t.admm.eps_abs = v,
        },
    },
    Parameter {
        name: "admm.eps_rel",
        old_name: Some("eps_rel"),
        description: "Relative tolerance of the ADMM stopping rule, eq. (29); 1e-3 as Table 3",
        kind: Kind::Real {
            unit: "1",
            min: Limit::AtLeast(0.0),
            max: Limit::None,
            get: |t| t.admm.eps_rel,
            set: |t, v| t.admm.eps_rel = v,
        },
    },
    Parameter {
        name: "admm.parallel_tugs",
        old_name: None,
        description: "true: each ADMM iteration steps the two tug problems at the same time (tug 2 on a helper thread), as the distributed architecture has each tug solve its own problem; the results are bit-identical to false (one thread)",
        kind: Kind::Boolean {
            get: |t| t.admm.parallel_tugs,
            set: |t, v| t.admm.parallel_tugs = v,
        },
    },
    Parameter {
        name: "centralized.max_iterations",
        old_name: None,
        description: "Centralized MPC only (architecture 2): most SCP steps (QPs) per sample; 60 (docs/assumptions.md)",
        kind: Kind::Integer {
            min: 1,
            max: 1000,
            get: |t| i32::try_from(t.centralized.max_iterations).unwrap_or(i32::MAX),
            set: |t, v| t.centralized.max_iterations = usize::try_from(v).unwrap_or(1),
        },
    },
    Parameter {
        name: "centralized.cost_tolerance",
        old_name: None,
        description: "Centralized MPC only: the SCP stops when an accepted step lowers its merit by less than this fraction of it (or moves the first move by less than 1e-3); 1e-5 (docs/assumptions.md)",
        kind: Kind::Real {
            unit: "1",
            min: Limit::AtLeast(0.0),
            max: Limit::Below(1.0),
            get: |t| t.centralized.cost_tolerance,
            set: |t, v| t.centralized.cost_tolerance = v,
        },
    },
    Parameter {
        name: "centralized.weight_force_rate",
        old_name: Some("centralized_thrust_rate_weight"),
        description: "Centralized MPC only: weight of the tugs' force changes sum (X_h - X_h-1)^2 + (Y_h - Y_h-1)^2, not in the paper; without it the tugs' thrusts, slaved to the ship's plan by the configuration restriction, alternate from sample to sample and grow; 0.01 (docs/assumptions.md)",
        kind: Kind::Real {
            unit: "1/N2",
            min: Limit::AtLeast(0.0),
            max: Limit::None,
            get: |t| t.centralized.weight_force_rate,
            set: |t, v| t.centralized.weight_force_rate = v,
        },
    },
    Parameter {
        name: "centralized.weight_moment_rate",
        old_name: Some("centralized_thrust_rate_weight"),
        description: "Centralized MPC only: the same for the tugs' yaw moment changes; 0.01 (docs/assumptions.md)",
        kind: Kind::Real {
            unit: "1/(N.m)2",
            min: Limit::AtLeast(0.0),
            max: Limit::None,
            get: |t| t.centralized.weight_moment_rate,
            set: |t, v| t.centralized.weight_moment_rate = v,
        },
    },
    Parameter {
        name: "guidance.detection_distance",
        old_name: Some("detection_distance"),
        description: "Detection distance d_D for target ships, eq. (8); not given by the paper, 7 m is where its first avoidance starts (docs/assumptions.md)",
        kind: Kind::Real {
            unit: "m",
            min: Limit::Above(0.0),
            max: Limit::None,
            get: |t| t.guidance.detection_distance,
            set: |t, v| t.guidance.detection_distance = v,
        },
    },
    Parameter {
        name: "guidance.static_detection_distance",
        old_name: Some("static_detection_distance"),
        description: "Detection distance for static hazards; 2.5 m lies between the largest hazard safe distance and the closest pass of the paper's route, so the tow follows its route between encounters (docs/assumptions.md)",
        kind: Kind::Real {
            unit: "m",
            min: Limit::Above(0.0),
            max: Limit::None,
            get: |t| t.guidance.static_detection_distance,
            set: |t, v| t.guidance.static_detection_distance = v,
        },
    },
    Parameter {
        name: "guidance.release_margin",
        old_name: None,
        description: "Hysteresis: an obstacle that altered the route keeps it altered until its distance exceeds its detection distance plus this margin; 0.5 m, one horizon's relative motion at the paper's closing speed (docs/assumptions.md)",
        kind: Kind::Real {
            unit: "m",
            min: Limit::AtLeast(0.0),
            max: Limit::None,
            get: |t| t.guidance.release_margin,
            set: |t, v| t.guidance.release_margin = v,
        },
    },
    Parameter {
        name: "guidance.resume_speed",
        old_name: None,
        description: "Speed at which the tow is taken to resume her route when the guidance judges whether a target she acted for (alteration or way off) is finally past and clear (COLREGS Rule 8(d)): the action is held while the resumed track would not pass the target clear; 0.1 m/s, the paper's tow speed (docs/assumptions.md)",
        kind: Kind::Real {
            unit: "m/s",
            min: Limit::Above(0.0),
            max: Limit::None,
            get: |t| t.guidance.resume_speed,
            set: |t, v| t.guidance.resume_speed = v,
        },
    },
    Parameter {
        name: "guidance.safety_buffer",
        old_name: Some("safety_buffer"),
        description: "Buffer d_S0 of the safe distance, eq. (14); not given by the paper, 0.25 m (a fifth of a ship length, docs/assumptions.md)",
        kind: Kind::Real {
            unit: "m",
            min: Limit::AtLeast(0.0),
            max: Limit::None,
            get: |t| t.guidance.safety_buffer,
            set: |t, v| t.guidance.safety_buffer = v,
        },
    },
    Parameter {
        name: "guidance.altering_angle",
        old_name: Some("altering_angle"),
        description: "Waypoint altering angle theta of eq. (10)-(11); 15 deg as Table 3",
        kind: Kind::Real {
            unit: "rad",
            min: Limit::Above(0.0),
            max: Limit::Below(std::f64::consts::FRAC_PI_2),
            get: |t| t.guidance.altering_angle,
            set: |t, v| t.guidance.altering_angle = v,
        },
    },
    Parameter {
        name: "guidance.acceptance_radius",
        old_name: Some("acceptance_radius"),
        description: "A waypoint is reached within this distance of the ship's centre; 0.6275 m, half the ship length, the paper's own settling tolerance (docs/assumptions.md)",
        kind: Kind::Real {
            unit: "m",
            min: Limit::Above(0.0),
            max: Limit::None,
            get: |t| t.guidance.acceptance_radius,
            set: |t, v| t.guidance.acceptance_radius = v,
        },
    },
    Parameter {
        name: "waterway.from_scenario",
        old_name: Some("waterway_half_width"),
        description: "true: the waterway's half width is the scenario's [waterway] half_width (none without that section); false: waterway.half_width",
        kind: Kind::Boolean {
            get: |t| t.waterway.from_scenario,
            set: |t, v| t.waterway.from_scenario = v,
        },
    },
    Parameter {
        name: "waterway.half_width",
        old_name: Some("waterway_half_width"),
        description: "Distance from the route to the waterway edge, d_2 of theta_max = arctan(d_2 / d_1), when waterway.from_scenario is false; 5 m as the paper scenario",
        kind: Kind::Real {
            unit: "m",
            min: Limit::Above(0.0),
            max: Limit::None,
            get: |t| t.waterway.half_width,
            set: |t, v| t.waterway.half_width = v,
        },
    },
    Parameter {
        name: "tracking.lookahead",
        old_name: Some("lookahead"),
        description: "Distance ahead of the ship's projection on the active leg of the point the MPC tracks (lookahead line of sight, Fossen 2011, 10.3.2); 0 tracks the waypoint eta_Sd itself as the paper does, which stalls the 3 s horizon MPC beside its waypoints (docs/assumptions.md)",
        kind: Kind::Real {
            unit: "m",
            min: Limit::AtLeast(0.0),
            max: Limit::None,
            get: |t| t.tracking.lookahead,
            set: |t, v| t.tracking.lookahead = v,
        },
    },
    Parameter {
        name: "tracking.give_way_lookahead",
        old_name: Some("give_way_lookahead"),
        description: "Lookahead while the route is altered for a crossing in which the tow gives way: the nearer tracked point slackens the tow's speed so the target crosses ahead (COLREGS Rule 8(e), 16); 0 m: the tow takes the way off (docs/assumptions.md)",
        kind: Kind::Real {
            unit: "m",
            min: Limit::AtLeast(0.0),
            max: Limit::None,
            get: |t| t.tracking.give_way_lookahead,
            set: |t, v| t.tracking.give_way_lookahead = v,
        },
    },
    Parameter {
        name: "tracking.los_distance",
        old_name: Some("los_distance"),
        description: "Beyond this distance from the tracked point the reference heading is the line-of-sight bearing to it, within it the route heading (Table 4); 2.5 m, two ship lengths; 0 always uses the route heading (docs/assumptions.md)",
        kind: Kind::Real {
            unit: "m",
            min: Limit::AtLeast(0.0),
            max: Limit::None,
            get: |t| t.tracking.los_distance,
            set: |t, v| t.tracking.los_distance = v,
        },
    },
    Parameter {
        name: "tracking.port_turn_margin",
        old_name: Some("port_turn_margin"),
        description: "While a head-on or crossing encounter lasts (schemes I, II), the ship's predicted heading stays to starboard of the route's course plus the most starboard heading off it reached since the encounter began (the heading off it at the start for a stand-on tow that has not altered), less this margin (the reference course too) (COLREGS Rules 8(d), 14, 15, 17(c): no turn to port; following the route's bends is keeping course); 2 deg (docs/assumptions.md)",
        kind: Kind::Real {
            unit: "rad",
            min: Limit::AtLeast(0.0),
            max: Limit::Below(std::f64::consts::FRAC_PI_2),
            get: |t| t.tracking.port_turn_margin,
            set: |t, v| t.tracking.port_turn_margin = v,
        },
    },
    Parameter {
        name: "inner_loop.bandwidth_surge",
        old_name: Some("inner_loop_gain_surge"),
        description: "Surge bandwidth of the tugs' inner loop (K = diag(bandwidth) M added to the MPC thrust every communication step); 1/s moves the TitoNeri's unstable sway-yaw pole to about -0.5 1/s (docs/controller-design.md); 0 turns the axis off",
        kind: Kind::Real {
            unit: "1/s",
            min: Limit::AtLeast(0.0),
            max: Limit::None,
            get: |t| t.inner.gain[0],
            set: |t, v| t.inner.gain[0] = v,
        },
    },
    Parameter {
        name: "inner_loop.bandwidth_sway",
        old_name: Some("inner_loop_gain_sway"),
        description: "Sway bandwidth of the tugs' inner loop (K = diag(bandwidth) M added to the MPC thrust every communication step); 1/s moves the TitoNeri's unstable sway-yaw pole to about -0.5 1/s (docs/controller-design.md); 0 turns the axis off",
        kind: Kind::Real {
            unit: "1/s",
            min: Limit::AtLeast(0.0),
            max: Limit::None,
            get: |t| t.inner.gain[1],
            set: |t, v| t.inner.gain[1] = v,
        },
    },
    Parameter {
        name: "inner_loop.bandwidth_yaw",
        old_name: Some("inner_loop_gain_yaw"),
        description: "Yaw bandwidth of the tugs' inner loop (K = diag(bandwidth) M added to the MPC thrust every communication step); 1/s moves the TitoNeri's unstable sway-yaw pole to about -0.5 1/s (docs/controller-design.md); 0 turns the axis off",
        kind: Kind::Real {
            unit: "1/s",
            min: Limit::AtLeast(0.0),
            max: Limit::None,
            get: |t| t.inner.gain[2],
            set: |t, v| t.inner.gain[2] = v,
        },
    },
    Parameter {
        name: "fmi.warning_on_fallback",
        old_name: None,
        description: "true: a control sample that falls back (its plan replaced by the previous plan, shifted) makes fmi2DoStep return fmi2Warning (FMI 2.0 section 4.2.2), which stops masters that end on any status above fmi2OK (fmusim, OMSimulator); false: fmi2OK. Either way the fallback is logged as a warning (category logStatusWarning, and the MCAP log's /controller/log) and counted in controller.fallbacks",
        kind: Kind::Boolean {
            get: |t| t.warning_on_fallback,
            set: |t, v| t.warning_on_fallback = v,
        },
    },
    Parameter {
        name: "mpc.ship.max_drift",
        old_name: None,
        description: "Soft limit of the ship's predicted drift angle: |v| <= tan(max_drift) u + 0.005 m/s (seamanship, docs/colregs.md); 22 deg, inside the 30 deg bound (docs/assumptions.md)",
        kind: Kind::Real {
            unit: "rad",
            min: Limit::Above(0.0),
            max: Limit::Below(std::f64::consts::FRAC_PI_2),
            get: |t| t.ship.motion.max_drift,
            set: |t, v| t.ship.motion.max_drift = v,
        },
    },
    Parameter {
        name: "mpc.ship.max_sternway",
        old_name: None,
        description: "Soft limit of the ship's predicted surge astern; 0.01 m/s, inside the 0.03 m/s bound (docs/assumptions.md)",
        kind: Kind::Real {
            unit: "m/s",
            min: Limit::AtLeast(0.0),
            max: Limit::None,
            get: |t| t.ship.motion.max_sternway,
            set: |t, v| t.ship.motion.max_sternway = v,
        },
    },
    Parameter {
        name: "mpc.ship.max_speed",
        old_name: None,
        description: "Soft limit of the ship's predicted surge ahead; 0.11 m/s, about 1.2 times the tow's cruise (docs/assumptions.md)",
        kind: Kind::Real {
            unit: "m/s",
            min: Limit::Above(0.0),
            max: Limit::None,
            get: |t| t.ship.motion.max_speed,
            set: |t, v| t.ship.motion.max_speed = v,
        },
    },
    Parameter {
        name: "mpc.ship.motion_penalty",
        old_name: None,
        description: "Exact L1 penalty on the slack of the motion limits (drift, sternway, speed); 1e4 as the clearance rows; 0 turns the limits off",
        kind: Kind::Real {
            unit: "s/m",
            min: Limit::AtLeast(0.0),
            max: Limit::None,
            get: |t| t.ship.motion.penalty,
            set: |t, v| t.ship.motion.penalty = v,
        },
    },
    Parameter {
        name: "tracking.course_rate",
        old_name: None,
        description: "Largest rate at which the reference course turns towards the line of sight to the tracked point, whose position is kept on that course (no sideways or astern reference after an alteration is released); 1.5 deg/s, about the yaw rate the tow reaches in the paper's alterations (docs/assumptions.md); 0: no limit",
        kind: Kind::Real {
            unit: "rad/s",
            min: Limit::AtLeast(0.0),
            max: Limit::Below(std::f64::consts::PI),
            get: |t| t.tracking.course_rate,
            set: |t, v| t.tracking.course_rate = v,
        },
    },
    Parameter {
        name: "tracking.course_lead",
        old_name: None,
        description: "Largest angle between the reference course and the ship's heading: the tracked point leads a turn the ship is making but never lies abeam of her (seamanship: drift angle under 30 deg); 20 deg (docs/assumptions.md); 0: no limit",
        kind: Kind::Real {
            unit: "rad",
            min: Limit::AtLeast(0.0),
            max: Limit::Below(std::f64::consts::PI),
            get: |t| t.tracking.course_lead,
            set: |t, v| t.tracking.course_lead = v,
        },
    },
    Parameter {
        name: "tracking.give_way_way_off",
        old_name: None,
        description: "true (default): while the route is altered for a crossing in which the tow gives way, she takes the way off (tracking.give_way_deceleration) and keeps it off (tracking.give_way_surge) until the encounter is over (COLREGS Rule 8(e)); false: only once the tow, slowed to half guidance.resume_speed, finds her altered course out of water (docs/colregs.md, section 4; docs/assumptions.md: without it, more Rule 8(d) give-ups)",
        kind: Kind::Boolean {
            get: |t| t.tracking.give_way_way_off,
            set: |t, v| t.tracking.give_way_way_off = v,
        },
    },
    Parameter {
        name: "tracking.give_way_surge",
        old_name: None,
        description: "While the route is altered for a crossing in which the tow gives way and she takes the way off (tracking.give_way_way_off, or her altered course out of water), she slows (tracking.give_way_deceleration) down to this surge and keeps the way off (COLREGS Rule 8(e)) until the encounter is over; 0.04 m/s, under the 0.05 m/s at which the analyzer counts the way off (docs/assumptions.md)",
        kind: Kind::Real {
            unit: "m/s",
            min: Limit::Above(0.0),
            max: Limit::None,
            get: |t| t.tracking.give_way_surge,
            set: |t, v| t.tracking.give_way_surge = v,
        },
    },
    Parameter {
        name: "tracking.give_way_deceleration",
        old_name: None,
        description: "The deceleration at which the tow takes the way off while giving way in a crossing: each sample the ship's plan keeps its surge at or below the measured surge less this times the sample time, down to tracking.give_way_surge; 0.005 m/s^2, cruise to 0.04 m/s in about 14 s (docs/assumptions.md)",
        kind: Kind::Real {
            unit: "m/s2",
            min: Limit::AtLeast(0.0),
            max: Limit::None,
            get: |t| t.tracking.give_way_deceleration,
            set: |t, v| t.tracking.give_way_deceleration = v,
        },
    },
    Parameter {
        name: "guidance.rule17_tcpa",
        old_name: None,
        description: "Rule 17(a)(ii): a stand-on tow acts once the TCPA of a target still closing to under guidance.rule17_dcpa is at most this, wherever the target is (not only within the detection distance); a give-way tow acts by the same test at the latest (docs/colregs.md, Acting by the CPA); 55 s, 5 s inside the analyzer's 60 s (docs/assumptions.md)",
        kind: Kind::Real {
            unit: "s",
            min: Limit::Above(0.0),
            max: Limit::None,
            get: |t| t.guidance.colregs.rule17.tcpa,
            set: |t, v| t.guidance.colregs.rule17.tcpa = v,
        },
    },
    Parameter {
        name: "guidance.rule17_dcpa",
        old_name: None,
        description: "Rule 17(a)(ii): the DCPA (ship centre to target centre) below which the give-way vessel is deemed not to have acted; 2.5 m, about two ship lengths (docs/assumptions.md)",
        kind: Kind::Real {
            unit: "m",
            min: Limit::Above(0.0),
            max: Limit::None,
            get: |t| t.guidance.colregs.rule17.dcpa,
            set: |t, v| t.guidance.colregs.rule17.dcpa = v,
        },
    },
    Parameter {
        name: "guidance.rule17_way_off_speed",
        old_name: None,
        description: "Rule 17(a)(ii), (b) with 8(e): when the stand-on tow must act and the target's track clears the tow going on at this speed, she keeps the route and takes the way off (at guidance.rule17_way_off_deceleration) down to this surge until the target is finally past and clear, else she alters to starboard; 0.01 m/s, the slowest at which she still held her head (docs/assumptions.md)",
        kind: Kind::Real {
            unit: "m/s",
            min: Limit::Above(0.0),
            max: Limit::None,
            get: |t| t.guidance.colregs.rule17.way_off_speed,
            set: |t, v| t.guidance.colregs.rule17.way_off_speed = v,
        },
    },
    Parameter {
        name: "guidance.rule17_way_off_deceleration",
        old_name: None,
        description: "The deceleration at which the stand-on tow takes the way off under Rule 17 (guidance.rule17_way_off_speed): each sample the ship's plan keeps its surge at or below the measured surge less this times the sample time; the guidance counts the headway she carries meanwhile; 0.01 m/s^2, cruise to 0.01 m/s in about 10 s (docs/assumptions.md)",
        kind: Kind::Real {
            unit: "m/s2",
            min: Limit::Above(0.0),
            max: Limit::None,
            get: |t| t.guidance.colregs.rule17.way_off_deceleration,
            set: |t, v| t.guidance.colregs.rule17.way_off_deceleration = v,
        },
    },
    Parameter {
        name: "guidance.rule17_close_quarters_tcpa",
        old_name: None,
        description: "Rule 17(b), close quarters: a target the tow stands on without acting (being overtaken) enters the MPC's distance cost once its TCPA is at most this and its DCPA under guidance.rule17_dcpa; 30 s (docs/assumptions.md)",
        kind: Kind::Real {
            unit: "s",
            min: Limit::Above(0.0),
            max: Limit::None,
            get: |t| t.guidance.colregs.rule17.close_quarters_tcpa,
            set: |t, v| t.guidance.colregs.rule17.close_quarters_tcpa = v,
        },
    },
];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_unique_and_grouped() {
        for (i, p) in PARAMETERS.iter().enumerate() {
            assert!(
                PARAMETERS[..i].iter().all(|q| q.name != p.name),
                "{} twice",
                p.name
            );
            let ungrouped = ["architecture", "avoidance_scheme"].contains(&p.name);
            assert_eq!(p.group().is_empty(), ungrouped, "{}", p.name);
            if let Kind::Real { unit, .. } = p.kind {
                assert!(!unit.is_empty(), "{} has no unit", p.name);
            }
        }
    }

    #[test]
    fn defaults_pass_their_own_checks() {
        for p in PARAMETERS {
            p.check(&p.default_value())
                .unwrap_or_else(|e| panic!("{}: {e}", p.name));
        }
        assert!(Tuning::default().validate().is_ok());
    }

    #[test]
    fn set_then_get_round_trips() {
        for p in PARAMETERS {
            let mut t = Tuning::default();
            let v = match p.kind {
                Kind::Real { min, max, .. } => {
                    let lo = min.value().unwrap_or(0.0);
                    let hi = max.value().unwrap_or(lo + 2.0);
                    Value::Real(0.5 * (lo + hi))
                }
                Kind::Integer { min, max, .. } => Value::Integer(max.min(min + 1)),
                Kind::Boolean { get, .. } => Value::Boolean(!get(&t)),
                // An item other than the default.
                Kind::Enumeration {
                    enumeration, get, ..
                } => Value::Integer(
                    enumeration
                        .items
                        .iter()
                        .map(|i| i.value)
                        .find(|&v| v != get(&t))
                        .unwrap(),
                ),
                Kind::String { .. } => unreachable!("the controller has no String parameter"),
            };
            p.set(&mut t, v.clone()).unwrap();
            assert_eq!(p.get(&t), v, "{}", p.name);
        }
    }

    #[test]
    fn out_of_range_values_are_refused_by_name() {
        let e: ConfigError = find("mpc.sample_time")
            .unwrap()
            .check(&Value::Real(0.0))
            .unwrap_err()
            .into();
        assert_eq!(
            e.to_string(),
            "parameter `mpc.sample_time`: must be finite and in (0, 60] s, got 0 s"
        );
        let e: ConfigError = find("admm.max_iterations")
            .unwrap()
            .check(&Value::Integer(0))
            .unwrap_err()
            .into();
        assert_eq!(
            e.to_string(),
            "parameter `admm.max_iterations`: must be in 1..=100, got 0"
        );
        let e = find("admm.rho")
            .unwrap()
            .check(&Value::Boolean(true))
            .unwrap_err();
        assert!(e.to_string().contains("expects a Real value"), "{e}");
        let e: ConfigError = find("architecture")
            .unwrap()
            .check(&Value::Integer(3))
            .unwrap_err()
            .into();
        assert_eq!(
            e.to_string(),
            "parameter `architecture`: must be one of 1 distributed, 2 centralized, got 3"
        );
        let mut t = Tuning::default();
        t.ship.min_tension = 5.0;
        assert_eq!(
            t.validate().unwrap_err().to_string(),
            "parameter `mpc.ship.min_tension`: must be <= mpc.ship.max_tension = 3 N, got 5 N"
        );
    }

    /// The choices keep the codes masters set before they were enumerations, and every
    /// item maps to its Rust value and back.
    #[test]
    fn choices_are_enumerations_with_the_codes_masters_use() {
        let codes = |name: &str| match find(name).unwrap().kind {
            Kind::Enumeration { enumeration, .. } => enumeration
                .items
                .iter()
                .map(|i| (i.value, i.name))
                .collect::<Vec<_>>(),
            other => panic!("{name} is {other:?}"),
        };
        assert_eq!(
            codes("architecture"),
            [(1, "distributed"), (2, "centralized")]
        );
        assert_eq!(
            codes("avoidance_scheme"),
            [(1, "alter_and_cost"), (2, "alter_only"), (3, "cost_only")]
        );
        assert_eq!(
            codes("mpc.hull_model"),
            [(1, "linear_damping"), (2, "nonlinear_damping")]
        );
        for item in Architecture::ENUMERATION.items {
            assert_eq!(
                Architecture::from_code(item.value).map(Architecture::code),
                Ok(item.value)
            );
        }
        for item in AvoidanceScheme::ENUMERATION.items {
            assert_eq!(
                AvoidanceScheme::from_code(item.value).map(AvoidanceScheme::code),
                Ok(item.value)
            );
        }
        assert_eq!(
            AvoidanceScheme::from_code(4).unwrap_err().to_string(),
            "parameter `avoidance_scheme`: must be one of 1 alter_and_cost, 2 alter_only, 3 cost_only, got 4"
        );
        let mut t = Tuning::default();
        find("mpc.hull_model")
            .unwrap()
            .set(&mut t, Value::Integer(1))
            .unwrap();
        assert_eq!(t.hull, HullModel::LinearDamping);
    }
}
