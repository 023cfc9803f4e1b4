//! Errors: a refused configuration or a refused measurement, each naming the
//! value and the reason.

use thiserror::Error;

/// A configuration value out of range.
#[derive(Debug, Clone, PartialEq, Error)]
#[error("parameter `{name}`: {reason}")]
pub struct ConfigError {
    /// The parameter (FMI name where there is one).
    pub name: String,
    /// Why it was refused.
    pub reason: String,
}

impl ConfigError {
    /// An error for `name`.
    #[must_use]
    pub fn new(name: &str, reason: impl Into<String>) -> ConfigError {
        ConfigError {
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
