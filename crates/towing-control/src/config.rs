//! Controller configuration: the scenario, every tuning value ([`Tuning`], the
//! values of the parameter registry [`crate::params`], with the defaults of
//! `docs/assumptions.md`) and, from Rust only, user hulls for the prediction
//! models ([`PredictionHulls`]).

use std::sync::Arc;

use towing_guidance::{GuidanceParams, GuidanceSettings, Route};
use towing_model::geometry::{HullRect, Lane, Polyline};
use towing_model::registry::{Enumeration, Item};
use towing_model::{HullDynamics, HullModel, Scenario};
use towing_mpc::{
    AdmmSettings, CentralizedSettings, PredictionParams, ShipMpcParams, TugMpcParams,
};

use crate::error::ConfigError;
use crate::params;

/// Which optimisation computes the commands (FMI parameter `architecture`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Architecture {
    /// 1: the distributed MPC, ADMM over the coordination and the tug problems
    /// (Du et al. 2022, Algorithm 1).
    #[default]
    Distributed,
    /// 2: one MPC over all inputs (eq. (12)), for the paper's Table 7.
    Centralized,
}

impl Architecture {
    /// The FMI Enumeration type `Architecture` of the parameter `architecture` (FMI 2.0
    /// section 2.2.3): 1 `distributed`, 2 `centralized`, the codes masters have always
    /// set.
    pub const ENUMERATION: Enumeration = Enumeration {
        name: "Architecture",
        description: "Which MPC computes the commands",
        items: &[
            Item {
                name: "distributed",
                value: 1,
                description: "ADMM over the coordination (ship) and the tug problems (Du et al. 2022, Algorithm 1; the paper's method)",
            },
            Item {
                name: "centralized",
                value: 2,
                description: "one MPC over all inputs (Du et al. 2022, eq. (12); the paper's Table 7 comparison)",
            },
        ],
    };

    /// From the FMI code (an item's value of [`Architecture::ENUMERATION`]).
    ///
    /// # Errors
    /// Any other code, naming the items.
    pub fn from_code(code: i32) -> Result<Self, ConfigError> {
        match code {
            1 => Ok(Architecture::Distributed),
            2 => Ok(Architecture::Centralized),
            _ => Err(ConfigError::new(
                "architecture",
                Self::ENUMERATION.refusal(code),
            )),
        }
    }

    /// The FMI code.
    #[must_use]
    pub fn code(self) -> i32 {
        match self {
            Architecture::Distributed => 1,
            Architecture::Centralized => 2,
        }
    }
}

/// The paper's avoidance schemes (section 4.2, Table 6; FMI parameter
/// `avoidance_scheme`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum AvoidanceScheme {
    /// I: waypoint altering (eq. (8)-(11)) and the distance cost (eq. (13)).
    #[default]
    AlterAndCost,
    /// II: waypoint altering only (`w_S3 = w_i3 = 0`). The hard clearance rows
    /// stay: safety is never switched off (`docs/controller-design.md`).
    AlterOnly,
    /// III: the distance cost only; the reference is the unaltered route.
    CostOnly,
}

impl AvoidanceScheme {
    /// The FMI Enumeration type `AvoidanceScheme` of the parameter `avoidance_scheme`
    /// (FMI 2.0 section 2.2.3): the paper's schemes I, II, III as 1 `alter_and_cost`,
    /// 2 `alter_only`, 3 `cost_only`, the codes masters have always set.
    pub const ENUMERATION: Enumeration = Enumeration {
        name: "AvoidanceScheme",
        description: "The paper's avoidance schemes (Du et al. 2022, section 4.2)",
        items: &[
            Item {
                name: "alter_and_cost",
                value: 1,
                description: "scheme I: waypoint altering (eq. (8)-(11)) and the distance cost (eq. (13)), the paper's main scheme",
            },
            Item {
                name: "alter_only",
                value: 2,
                description: "scheme II: waypoint altering only (the distance weights forced to 0)",
            },
            Item {
                name: "cost_only",
                value: 3,
                description: "scheme III: the distance cost only (the unaltered route)",
            },
        ],
    };

    /// From the FMI code (an item's value of [`AvoidanceScheme::ENUMERATION`]).
    ///
    /// # Errors
    /// Any other code, naming the items.
    pub fn from_code(code: i32) -> Result<Self, ConfigError> {
        match code {
            1 => Ok(AvoidanceScheme::AlterAndCost),
            2 => Ok(AvoidanceScheme::AlterOnly),
            3 => Ok(AvoidanceScheme::CostOnly),
            _ => Err(ConfigError::new(
                "avoidance_scheme",
                Self::ENUMERATION.refusal(code),
            )),
        }
    }

    /// The FMI code.
    #[must_use]
    pub fn code(self) -> i32 {
        match self {
            AvoidanceScheme::AlterAndCost => 1,
            AvoidanceScheme::AlterOnly => 2,
            AvoidanceScheme::CostOnly => 3,
        }
    }

    /// Whether the reference follows the altered waypoint.
    #[must_use]
    pub fn alters(self) -> bool {
        !matches!(self, AvoidanceScheme::CostOnly)
    }

    /// Whether the distance term of the cost is on.
    #[must_use]
    pub fn distance_cost(self) -> bool {
        !matches!(self, AvoidanceScheme::AlterOnly)
    }
}

/// The tugs' inner stabilising loop (`docs/controller-design.md`, "Tug local
/// MPCs"): at every communication step each tug adds
/// `K (nu_plan(t) - nu(t))` to its MPC thrust, `K = diag(gain) M` with `M` the
/// tug's mass matrix including added mass, and `nu_plan` the MPC's predicted
/// velocity interpolated over the sample; the sum is saturated at the thrust
/// limits (eq. (19)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InnerLoopParams {
    /// Bandwidth per axis (surge, sway, yaw; 1/s, >= 0; all zero turns the loop
    /// off).
    pub gain: [f64; 3],
}

impl Default for InnerLoopParams {
    /// `[1, 1, 1] 1/s`: moves the linearised TitoNeri's unstable sway-yaw pole
    /// (up to +0.5 1/s at the paper's speeds) to about -0.5 1/s and leaves the
    /// MPC's 1 s sample the outer loop (`docs/assumptions.md`).
    fn default() -> Self {
        InnerLoopParams {
            gain: [1.0, 1.0, 1.0],
        }
    }
}

/// How the MPC tracks the reference (`docs/controller-design.md`, "Reference").
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrackingParams {
    /// Lookahead distance (m) of the tracked point on the active leg
    /// ([`Controller`](crate::Controller) docs); 0 tracks the reference
    /// system's waypoint `eta_Sd` itself, as the paper does.
    pub lookahead: f64,
    /// Lookahead (m) while the route is altered for a crossing in which the tow
    /// gives way: a nearer tracked point slackens the tow's speed (COLREGS Rule
    /// 8(e), Rule 16) so the target crosses ahead and the tow passes astern.
    pub give_way_lookahead: f64,
    /// The tow keeps the way off while giving way in a crossing (`give_way_surge`,
    /// `give_way_deceleration`; `true`, the default, COLREGS Rule 8(e)); `false`: only
    /// once she has slowed to half the resume speed and finds her altered course out of
    /// water ([`Controller`](crate::Controller), `docs/colregs.md` section 4;
    /// `docs/assumptions.md`: without it, more Rule 8(d) give-ups).
    pub give_way_way_off: bool,
    /// While the route is altered for a crossing in which the tow gives way, the
    /// ship's plan does not gather way (its surge stays at or below the measured
    /// surge) and, once she has slowed to this speed (m/s), keeps the way off
    /// (COLREGS Rule 8(e)) until the encounter is over, whatever the tracked point
    /// asks.
    pub give_way_surge: f64,
    /// The deceleration (m/s^2) at which the tow takes the way off while giving way
    /// in a crossing: each sample the plan's surge stays at or below the measured
    /// surge less this times the sample time, until it reaches `give_way_surge`.
    pub give_way_deceleration: f64,
    /// Line-of-sight distance (m): while the ship is farther than this from the
    /// tracked point, the reference heading is the bearing from the ship to it
    /// (line of sight, Fossen 2011, section 10.3.2) instead of the waypoint's
    /// heading of Table 4 / eq. (11); 0 turns it off. On the route the two are
    /// equal; off the route (after an avoidance) the printed heading and a short
    /// horizon leave the ship in a local minimum beside its waypoint.
    pub los_distance: f64,
    /// Port-turn margin (rad) of the heading floor: while an encounter in which
    /// the tow may not turn to port is under way (head-on, Rule 14; crossing,
    /// Rules 15 and 17(c)) and the scheme alters waypoints (I, II), the ship's
    /// predicted heading is kept to starboard of the route's course plus her
    /// heading off it at the start of the encounter (ratcheted to starboard,
    /// `Controller::heading_floor`) minus this margin
    /// ([`towing_mpc::ShipMpcParams::weight_port_turn`]).
    pub port_turn_margin: f64,
    /// Largest rate (rad/s) at which the reference course turns
    /// ([`Controller`](crate::Controller) docs, `docs/controller-design.md`,
    /// "Reference course"); 0: no limit (the course jumps to the wanted one).
    pub course_rate: f64,
    /// Largest angle (rad) between the reference course and the ship's heading;
    /// 0: no limit.
    pub course_lead: f64,
}

impl Default for TrackingParams {
    /// `lookahead = 3.5 m`, `give_way_lookahead = 0 m`, `give_way_surge = 0.04 m/s`,
    /// `give_way_deceleration = 0.005 m/s^2`,
    /// `los_distance = 2.5 m`
    /// (two CyberShip II lengths), `port_turn_margin = 2 deg` (the course change
    /// evaluators count as none, `docs/colregs.md`);
    /// why in `docs/assumptions.md`.
    fn default() -> Self {
        TrackingParams {
            lookahead: 3.5,
            give_way_lookahead: 0.0,
            give_way_way_off: true,
            give_way_surge: 0.04,
            give_way_deceleration: 0.005,
            los_distance: 2.5,
            port_turn_margin: 2f64.to_radians(),
            course_rate: 1.5f64.to_radians(),
            course_lead: 20f64.to_radians(),
        }
    }
}

/// Where the waterway's half width comes from (the reference system's `d_2`,
/// `docs/colregs.md`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WaterwaySettings {
    /// Take the scenario's `[waterway] half_width` (none without that section).
    pub from_scenario: bool,
    /// The half width (m, > 0) when not from the scenario.
    pub half_width: f64,
}

impl Default for WaterwaySettings {
    /// From the scenario; 5 m (the paper scenario's) otherwise.
    fn default() -> Self {
        WaterwaySettings {
            from_scenario: true,
            half_width: 5.0,
        }
    }
}

/// Every tuning value of the controller: the values of the parameter registry
/// ([`crate::params::PARAMETERS`], one FMI parameter each), independent of the
/// scenario. [`Tuning::default`] holds the documented defaults.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tuning {
    /// Distributed or centralized.
    pub architecture: Architecture,
    /// Scheme I, II or III.
    pub scheme: AvoidanceScheme,
    /// The prediction models' hull as the scenario's `[simulation]` says
    /// (`true`) or [`Tuning::hull`].
    pub hull_from_scenario: bool,
    /// The prediction models' hull when not from the scenario.
    pub hull: HullModel,
    /// Sample time `T_s` and RK4 substep of the predictions.
    pub prediction: PredictionParams,
    /// Wall-clock budget of one control sample (s; 0: none). When set, the
    /// optimisation stops iterating once the budget is spent (after at least one
    /// ADMM iteration or SCP step) and applies the best iterate so far, which
    /// satisfies every bound; the report says so (`budget_hit`). A budget makes
    /// the run depend on the machine's speed; 0 keeps it deterministic.
    pub sample_time_budget: f64,
    /// ADMM penalty, iterations, tolerances.
    pub admm: AdmmSettings,
    /// The centralized problem's SCP loop.
    pub centralized: CentralizedSettings,
    /// Coordination problem (Table 3 weights, bounds, rate bounds).
    pub ship: ShipMpcParams,
    /// Tug problems (Table 3 weights, thrust bounds).
    pub tug: TugMpcParams,
    /// Reference system (`d_D`, `theta`, `d_S0`); its waterway and vessel
    /// lengths are set from [`Tuning::waterway`] and the scenario when built.
    pub guidance: GuidanceSettings,
    /// The waterway's half width.
    pub waterway: WaterwaySettings,
    /// The tugs' inner loop.
    pub inner: InnerLoopParams,
    /// How the MPC tracks the reference system's output.
    pub tracking: TrackingParams,
    /// The FMU only: a sample that falls back makes `fmi2DoStep` return
    /// `fmi2Warning` (`true`) or `fmi2OK` (`false`, the default); the fallback
    /// is logged and counted either way. The Rust controller reports every
    /// fallback in its [`crate::SampleReport`] and ignores this.
    pub warning_on_fallback: bool,
}

impl Default for Tuning {
    fn default() -> Self {
        Tuning {
            architecture: Architecture::default(),
            scheme: AvoidanceScheme::default(),
            hull_from_scenario: true,
            hull: HullModel::default(),
            prediction: PredictionParams::default(),
            sample_time_budget: 0.0,
            admm: AdmmSettings::default(),
            centralized: CentralizedSettings::default(),
            ship: ShipMpcParams::default(),
            tug: TugMpcParams::default(),
            guidance: GuidanceSettings::default(),
            waterway: WaterwaySettings::default(),
            inner: InnerLoopParams::default(),
            tracking: TrackingParams::default(),
            warning_on_fallback: false,
        }
    }
}

impl Tuning {
    /// Checks every value: each registry parameter against its range
    /// ([`params::Parameter::check`]), then the rules between parameters
    /// ([`params::check_relations`]). The FMU checks the same, with the same
    /// messages.
    ///
    /// # Errors
    /// The first value refused, by its parameter name, with the reason.
    pub fn validate(&self) -> Result<(), ConfigError> {
        for p in params::PARAMETERS {
            p.check(&p.get(self))?;
        }
        params::check_relations(self)
    }
}

/// The prediction models' hulls given from Rust (not expressible as FMI
/// parameters): the ship's and each tug's [`HullDynamics`], e.g. the hulls of a
/// higher-fidelity plant (`docs/swap-plant.md`). Their `d nu_dot / d nu` is taken
/// by finite differences ([`towing_mpc::PredictionHull::custom`]).
#[derive(Debug, Clone)]
pub struct PredictionHulls {
    /// The ship's hull.
    pub ship: Arc<dyn HullDynamics>,
    /// Tug 1's and tug 2's hulls.
    pub tugs: [Arc<dyn HullDynamics>; 2],
}

/// Everything the controller needs; [`ControllerConfig::new`] gives the
/// documented defaults for a scenario.
#[derive(Debug, Clone)]
pub struct ControllerConfig {
    /// Vessels (prediction models), formation, route and waterway.
    pub scenario: Scenario,
    /// Every tuning value.
    pub tuning: Tuning,
    /// User hulls for the prediction models; `None`: the built-in hull of
    /// [`Tuning::hull`] (or the scenario's).
    pub hulls: Option<PredictionHulls>,
}

impl ControllerConfig {
    /// The defaults for `scenario` (distributed, scheme I, `T_s = 1 s`, hull and
    /// waterway as the scenario says).
    #[must_use]
    pub fn new(scenario: Scenario) -> ControllerConfig {
        ControllerConfig::with_tuning(scenario, Tuning::default())
    }

    /// `scenario` with the given tuning values (checked by
    /// [`ControllerConfig::validate`] and [`crate::Controller::new`]).
    #[must_use]
    pub fn with_tuning(scenario: Scenario, tuning: Tuning) -> ControllerConfig {
        ControllerConfig {
            scenario,
            tuning,
            hulls: None,
        }
    }

    /// Sets the parameter `name` of the registry ([`crate::params`]) to `value`,
    /// checked against its range.
    ///
    /// # Errors
    /// An unknown name, a value of the wrong type or out of range.
    pub fn set(&mut self, name: &str, value: params::Value) -> Result<(), ConfigError> {
        let p = params::find(name).ok_or_else(|| ConfigError::UnknownParameter {
            name: name.to_owned(),
        })?;
        p.check(&value)?;
        Ok(p.set(&mut self.tuning, value)?)
    }

    /// The prediction models' built-in hull (the scenario's or the tuning's).
    #[must_use]
    pub fn hull(&self) -> HullModel {
        if self.tuning.hull_from_scenario {
            self.scenario.world_config.hull_model
        } else {
            self.tuning.hull
        }
    }

    /// The waterway the MPC keeps every hull inside ([`towing_mpc::Waterway`],
    /// `docs/controller-design.md`, "The waterway"): the scenario's route with the half
    /// width guidance uses, and per vessel (ship, tug 1, tug 2) its hull's corner radius
    /// plus the 0.1 m the clearance rows' `d_min` allow for the motion within a sample
    /// (`docs/assumptions.md`). `None` without a waterway, and in scheme III: the paper's
    /// distance-cost-only baseline keeps the paper's formulation, which has no bank (its
    /// reference is the unaltered route, and only wide swings clear the hazards; held
    /// inside the bank it stalls between hazard a and the bank, `docs/RESULTS.md`).
    #[must_use]
    pub fn waterway(&self) -> Option<(Lane, [f64; 3])> {
        let half_width = self.mpc_waterway_half_width()?;
        let s = &self.scenario;
        let margin = |d: &towing_model::VesselData| HullRect::of(d).radius() + 0.1;
        Some((
            Lane::new(Polyline::of_route(&s.route), half_width),
            [
                margin(&s.ship_data),
                margin(&s.tug_data[0]),
                margin(&s.tug_data[1]),
            ],
        ))
    }

    /// The half width of the waterway the MPC keeps to ([`ControllerConfig::waterway`]),
    /// without building its lane.
    #[must_use]
    pub fn mpc_waterway_half_width(&self) -> Option<f64> {
        if !self.tuning.scheme.alters() {
            return None;
        }
        self.guidance().waterway_half_width
    }

    /// The reference system's settings: the tuning's, with the waterway and the
    /// vessel lengths of the scenario.
    #[must_use]
    pub fn guidance(&self) -> GuidanceSettings {
        let s = &self.scenario;
        GuidanceSettings {
            waterway_half_width: if self.tuning.waterway.from_scenario {
                s.waterway.as_ref().map(|w| w.half_width)
            } else {
                Some(self.tuning.waterway.half_width)
            },
            ship_length: s.ship_data.length,
            tug_length: s.tug_data[0].length.max(s.tug_data[1].length),
            ..self.tuning.guidance
        }
    }

    /// The route of the scenario for the reference system.
    ///
    /// # Errors
    /// A route the reference system refuses (e.g. repeated points).
    pub fn route(&self) -> Result<Route, ConfigError> {
        let points = self.scenario.route.points().copied().collect();
        Route::new(points).map_err(|source| ConfigError::Route { source })
    }

    /// Checks every value: the tuning ([`Tuning::validate`]), the reference
    /// system's settings with the scenario's values, the route.
    ///
    /// # Errors
    /// The first value refused, named.
    pub fn validate(&self) -> Result<(), ConfigError> {
        self.tuning.validate()?;
        GuidanceParams::new(self.guidance()).map_err(|source| ConfigError::Guidance { source })?;
        self.route()?;
        Ok(())
    }
}
