//! The world's physics configuration ([`WorldConfig`]): hull and towline models and the
//! integration step. The scenario file's `[simulation]` section fills one
//! ([`crate::Scenario::world_config`]) and [`crate::World`] is built with one; both import
//! it from here, so neither module imports the other's types for it.

use crate::kinetics::HullModel;
use crate::towline::TowlineModel;
use crate::vessel::{check_positive, ParamError};

/// Configuration of the world's physics (not part of the dynamic state).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WorldConfig {
    /// Damping model of the hulls that [`World::new`] builds. With
    /// [`World::with_hulls`] the hulls are given and this is only a label that
    /// enters the state fingerprint.
    pub hull_model: HullModel,
    /// Towline model.
    pub towline_model: TowlineModel,
    /// Largest RK4 substep (s); see the module docs for the default 0.01 s.
    pub integration_step: f64,
}

impl Default for WorldConfig {
    /// Nonlinear hull damping, ideal winch, 0.01 s integration step.
    fn default() -> Self {
        WorldConfig {
            hull_model: HullModel::NonlinearDamping,
            towline_model: TowlineModel::IdealWinch,
            integration_step: 0.01,
        }
    }
}

impl WorldConfig {
    /// Upper bound of `integration_step` (s).
    pub const MAX_INTEGRATION_STEP: f64 = 0.1;

    /// Checks the configuration: `0 < integration_step <= 0.1 s`, towline
    /// constants valid ([`TowlineModel::validate`]). Field paths are those of the
    /// scenario file's `[simulation]` section.
    pub fn validate(&self) -> Result<(), ParamError> {
        check_positive("integration_step", self.integration_step, "s")?;
        if self.integration_step > Self::MAX_INTEGRATION_STEP {
            return Err(ParamError::new(
                "integration_step",
                format!(
                    "must be at most {} s (RK4 accuracy for the tug and towline time scales), got {} s",
                    Self::MAX_INTEGRATION_STEP,
                    self.integration_step
                ),
            ));
        }
        self.towline_model
            .validate()
            .map_err(|e| e.within("elastic_towline"))
    }
}
