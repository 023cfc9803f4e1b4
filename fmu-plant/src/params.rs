//! The plant's parameter registry ([`towing_model::registry`]): each parameter one
//! entry over [`PlantParams`], from which come the FMU's parameters, their
//! model-description variables, their checks and the table of `docs/interface.md`.
//!
//! | group | what |
//! |---|---|
//! | `model` | the physics: hull damping, towline model, integration step, each from the scenario's `[simulation]` section unless switched off |
//! | `log` | the MCAP log's Foxglove scene topics |

use towing_model::registry::{self, Kind, Limit};
use towing_model::{HullModel, Scenario, TowlineModel, WorldConfig};

/// A plant parameter.
pub type Parameter = registry::Parameter<PlantParams>;

/// The plant's parameter values; the default takes the physics from the scenario.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlantParams {
    /// Interval of the Foxglove topics `/tf` and `/plant/scene` in the log (s); 0:
    /// every step.
    pub log_scene_interval: f64,
    /// The hull damping model as the scenario says (`true`) or [`PlantParams::hull`].
    pub hull_from_scenario: bool,
    /// The hull damping model when not from the scenario.
    pub hull: HullModel,
    /// The towline model as the scenario says (`true`) or [`PlantParams::towline`].
    pub towline_from_scenario: bool,
    /// The towline model when not from the scenario: 1 ideal winch, 2 elastic line
    /// (its constants from the scenario).
    pub towline: i32,
    /// The integration step as the scenario says (`true`) or
    /// [`PlantParams::integration_step`].
    pub integration_step_from_scenario: bool,
    /// Largest RK4 substep (s) when not from the scenario.
    pub integration_step: f64,
}

impl Default for PlantParams {
    fn default() -> Self {
        let physics = WorldConfig::default();
        PlantParams {
            log_scene_interval: 0.5,
            hull_from_scenario: true,
            hull: physics.hull_model,
            towline_from_scenario: true,
            towline: 1,
            integration_step_from_scenario: true,
            integration_step: physics.integration_step,
        }
    }
}

impl PlantParams {
    /// The world's configuration: the scenario's `[simulation]` section where the
    /// switches say so, else the parameters.
    #[must_use]
    pub fn world_config(&self, scenario: &Scenario) -> WorldConfig {
        let mut config = scenario.world_config;
        if !self.hull_from_scenario {
            config.hull_model = self.hull;
        }
        if !self.towline_from_scenario {
            config.towline_model = if self.towline == 2 {
                scenario.elastic_towline.into()
            } else {
                TowlineModel::IdealWinch
            };
        }
        if !self.integration_step_from_scenario {
            config.integration_step = self.integration_step;
        }
        config
    }
}

/// The FMI code of a hull model (`model.hull`).
fn hull_code(h: HullModel) -> i32 {
    match h {
        HullModel::LinearDamping => 1,
        HullModel::NonlinearDamping => 2,
    }
}

/// Every parameter of the plant, in model-description order.
pub static PARAMETERS: &[Parameter] = &[
    Parameter {
        name: "log.scene_interval",
        old_name: Some("log_scene_interval"),
        description: "Interval of the Foxglove topics /tf and /plant/scene in the MCAP log (docs/logging.md): written at the first step that reaches each multiple of it after the start time; 0: every step. Every other plant topic is written every step",
        kind: Kind::Real {
            unit: "s",
            min: Limit::AtLeast(0.0),
            max: Limit::None,
            get: |p| p.log_scene_interval,
            set: |p, v| p.log_scene_interval = v,
        },
    },
    Parameter {
        name: "model.hull_from_scenario",
        old_name: Some("hull_model"),
        description: "true: the hull damping model of the scenario's [simulation] section (default nonlinear); false: model.hull",
        kind: Kind::Boolean {
            get: |p| p.hull_from_scenario,
            set: |p, v| p.hull_from_scenario = v,
        },
    },
    Parameter {
        name: "model.hull",
        old_name: Some("hull_model"),
        description: "Hull damping model when model.hull_from_scenario is false: 1 linear (constant D, the paper's eq. (1)), 2 nonlinear (Skjetne et al. 2004 for CyberShip II)",
        kind: Kind::Integer {
            min: 1,
            max: 2,
            get: |p| hull_code(p.hull),
            set: |p, v| {
                p.hull = if v == 1 {
                    HullModel::LinearDamping
                } else {
                    HullModel::NonlinearDamping
                };
            },
        },
    },
    Parameter {
        name: "model.towline_from_scenario",
        old_name: Some("towline_model"),
        description: "true: the towline model of the scenario's [simulation] section (default ideal winch); false: model.towline",
        kind: Kind::Boolean {
            get: |p| p.towline_from_scenario,
            set: |p, v| p.towline_from_scenario = v,
        },
    },
    Parameter {
        name: "model.towline",
        old_name: Some("towline_model"),
        description: "Towline model when model.towline_from_scenario is false: 1 ideal winch holding the commanded tension while taut, 2 elastic line paid out by a winch (constants from the scenario)",
        kind: Kind::Integer {
            min: 1,
            max: 2,
            get: |p| p.towline,
            set: |p, v| p.towline = v,
        },
    },
    Parameter {
        name: "model.integration_step_from_scenario",
        old_name: Some("integration_step"),
        description: "true: the integration step of the scenario's [simulation] section (default 0.01 s); false: model.integration_step",
        kind: Kind::Boolean {
            get: |p| p.integration_step_from_scenario,
            set: |p, v| p.integration_step_from_scenario = v,
        },
    },
    Parameter {
        name: "model.integration_step",
        old_name: Some("integration_step"),
        description: "Largest fixed RK4 substep when model.integration_step_from_scenario is false: a communication step h is split into ceil(h / integration_step) equal substeps",
        kind: Kind::Real {
            unit: "s",
            min: Limit::Above(0.0),
            max: Limit::AtMost(WorldConfig::MAX_INTEGRATION_STEP),
            get: |p| p.integration_step,
            set: |p, v| p.integration_step = v,
        },
    },
];

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn defaults_pass_their_checks_and_take_the_scenario() {
        for p in PARAMETERS {
            p.check(&p.default_value())
                .unwrap_or_else(|e| panic!("{e}"));
            if let Kind::Real { unit, .. } = p.kind {
                assert!(!unit.is_empty(), "{}", p.name);
            }
        }
        let scenario = Scenario::paper().unwrap();
        assert_eq!(
            PlantParams::default().world_config(&scenario),
            scenario.world_config
        );
        let linear = PlantParams {
            hull_from_scenario: false,
            hull: HullModel::LinearDamping,
            ..PlantParams::default()
        };
        assert_eq!(
            linear.world_config(&scenario).hull_model,
            HullModel::LinearDamping
        );
    }
}
