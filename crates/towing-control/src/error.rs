//! Errors: a refused configuration or a refused measurement, each naming the
//! value and the reason, and keeping the error it came from as its source.

use thiserror::Error;

/// A configuration the controller refuses.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ConfigError {
    /// A parameter out of range, or in conflict with another one.
    #[error("parameter `{name}`: {reason}")]
    Parameter {
        /// The parameter's registry (FMI) name.
        name: String,
        /// Why it was refused.
        reason: String,
    },
    /// No parameter of that name.
    #[error("unknown parameter `{name}` (docs/interface.md lists them)")]
    UnknownParameter {
        /// The name asked for.
        name: String,
    },
    /// The scenario's route, refused by the reference system.
    #[error("scenario route: {source}")]
    Route {
        /// Why.
        #[source]
        source: towing_guidance::ParamError,
    },
    /// The reference system's settings with the scenario's values.
    #[error("reference system: {source}")]
    Guidance {
        /// Why.
        #[source]
        source: towing_guidance::ParamError,
    },
    /// The MPC could not be built from the scenario's vessels.
    #[error("{architecture} MPC: {source}")]
    Mpc {
        /// `distributed` or `centralized`.
        architecture: &'static str,
        /// Why.
        #[source]
        source: towing_mpc::AdmmBuildError,
    },
}

impl From<towing_model::ParamError> for ConfigError {
    /// A registry check's error: the parameter and the reason.
    fn from(e: towing_model::ParamError) -> Self {
        ConfigError::Parameter {
            name: e.field,
            reason: e.reason,
        }
    }
}

impl ConfigError {
    /// A parameter refused for `reason`.
    #[must_use]
    pub fn new(name: &str, reason: impl Into<String>) -> ConfigError {
        ConfigError::Parameter {
            name: name.to_owned(),
            reason: reason.into(),
        }
    }
}

/// A measurement the controller cannot use. The controller state is unchanged.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum MeasurementError {
    /// A vessel state component is NaN or infinite.
    #[error("input `{name}` is not finite ({value})")]
    NonFinite {
        /// FMI name of the input, e.g. `ship.u`.
        name: String,
        /// The value received.
        value: f64,
    },
    /// An obstacle slot the guidance refuses.
    #[error("input `obstacle[{slot}]`: {reason}")]
    Obstacle {
        /// Slot, 1-based as in the FMI names.
        slot: usize,
        /// Why.
        reason: String,
    },
}
