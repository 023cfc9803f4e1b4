//! The plant's parameter registry ([`towing_model::registry`]): each parameter one
//! entry over [`PlantParams`], from which come the FMU's parameters, their
//! model-description variables, their checks and the table of `docs/interface.md`.
//!
//! | group | what |
//! |---|---|
//! | `model` | the physics: hull damping, towline model, integration step, each from the scenario's `[simulation]` section unless switched off |
//! | `log` | the MCAP log's Foxglove scene topics |
//!
//! A choice is an FMI Enumeration whose items keep the codes masters have always set:
//! `model.hull` ([`HullModel::ENUMERATION`]), `model.towline`
//! ([`TowlineChoice::ENUMERATION`]).

use towing_model::registry::{self, Enumeration, Item, Kind, Limit};
use towing_model::{HullModel, Scenario, TowlineModel, WorldConfig};

/// A plant parameter.
pub type Parameter = registry::Parameter<PlantParams>;

/// The towline model the parameter `model.towline` chooses; an elastic line's constants
/// come from the scenario's `[elastic_towline]` section.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum TowlineChoice {
    /// The paper's ideal winch ([`TowlineModel::IdealWinch`]).
    #[default]
    IdealWinch,
    /// An elastic line paid out by a winch ([`TowlineModel::Elastic`]).
    Elastic,
}

impl TowlineChoice {
    /// The FMI Enumeration type `TowlineModel` of `model.towline` (FMI 2.0 section
    /// 2.2.3): 1 `ideal_winch`, 2 `elastic` (the scenario format's names, the codes
    /// masters have always set).
    pub const ENUMERATION: Enumeration = Enumeration {
        name: "TowlineModel",
        description: "How a towline transmits force",
        items: &[
            Item {
                name: "ideal_winch",
                value: 1,
                description:
                    "the commanded tension while the line is taut (Du et al. 2022, below eq. (3))",
            },
            Item {
                name: "elastic",
                value: 2,
                description: "an elastic line paid out by a winch, its constants from the scenario",
            },
        ],
    };

    /// The value of its item of [`TowlineChoice::ENUMERATION`].
    #[must_use]
    pub const fn code(self) -> i32 {
        match self {
            TowlineChoice::IdealWinch => 1,
            TowlineChoice::Elastic => 2,
        }
    }

    /// The choice of an item's value; `None` for another value.
    #[must_use]
    pub const fn from_code(code: i32) -> Option<TowlineChoice> {
        match code {
            1 => Some(TowlineChoice::IdealWinch),
            2 => Some(TowlineChoice::Elastic),
            _ => None,
        }
    }
}

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
    /// The towline model when not from the scenario.
    pub towline: TowlineChoice,
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
            towline: TowlineChoice::IdealWinch,
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
            config.towline_model = match self.towline {
                TowlineChoice::Elastic => scenario.elastic_towline.into(),
                TowlineChoice::IdealWinch => TowlineModel::IdealWinch,
            };
        }
        if !self.integration_step_from_scenario {
            config.integration_step = self.integration_step;
        }
        config
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
        description: "Hull damping model when model.hull_from_scenario is false: linear_damping (constant D, the paper's eq. (1)) or nonlinear_damping (Skjetne et al. 2004 for CyberShip II)",
        kind: Kind::Enumeration {
            enumeration: &HullModel::ENUMERATION,
            get: |p| p.hull.code(),
            // Only an item's value reaches the setter (`Parameter::set`).
            set: |p, v| p.hull = HullModel::from_code(v).unwrap_or_default(),
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
        description: "Towline model when model.towline_from_scenario is false: ideal_winch holding the commanded tension while taut, or elastic, a line paid out by a winch (constants from the scenario)",
        kind: Kind::Enumeration {
            enumeration: &TowlineChoice::ENUMERATION,
            get: |p| p.towline.code(),
            // Only an item's value reaches the setter (`Parameter::set`).
            set: |p, v| p.towline = TowlineChoice::from_code(v).unwrap_or_default(),
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

    /// The choices keep the codes masters set before they were enumerations.
    #[test]
    fn choices_are_enumerations_with_the_codes_masters_use() {
        let find = |name| registry::find(PARAMETERS, name).unwrap();
        let mut p = PlantParams::default();
        find("model.towline")
            .set(&mut p, registry::Value::Integer(2))
            .unwrap();
        assert_eq!(p.towline, TowlineChoice::Elastic);
        let e = find("model.towline")
            .check(&registry::Value::Integer(0))
            .unwrap_err();
        assert_eq!(
            e.to_string(),
            "model.towline: must be one of 1 ideal_winch, 2 elastic, got 0"
        );
        find("model.hull")
            .set(&mut p, registry::Value::Integer(1))
            .unwrap();
        assert_eq!(p.hull, HullModel::LinearDamping);
        for item in TowlineChoice::ENUMERATION.items {
            let choice = TowlineChoice::from_code(item.value).unwrap();
            assert_eq!(choice.code(), item.value);
        }
        assert_eq!(TowlineChoice::from_code(3), None);
        let scenario = Scenario::paper().unwrap();
        let elastic = PlantParams {
            towline_from_scenario: false,
            towline: TowlineChoice::Elastic,
            ..PlantParams::default()
        };
        assert!(matches!(
            elastic.world_config(&scenario).towline_model,
            TowlineModel::Elastic { .. }
        ));
    }
}
