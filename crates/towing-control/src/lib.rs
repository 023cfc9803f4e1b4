//! The towing controller of Du, Negenborn, Reppa (2022), "COLREGS-compliant
//! collision avoidance for physically coupled multi-vessel systems with
//! distributed MPC", Ocean Engineering 260, 111917, without FFI: the ship
//! reference system ([`towing_guidance`]), the distributed MPC (ADMM,
//! Algorithm 1) or the centralized MPC (eq. (12)) of [`towing_mpc`], the
//! fallback path and the tugs' inner stabilising loop. The FMU
//! (`fmu-controller`) is a thin shell around [`Controller`].
//!
//! ```no_run
//! use towing_control::{Controller, ControllerConfig, Measurement};
//! use towing_model::Scenario;
//!
//! let mut controller = Controller::new(ControllerConfig::new(Scenario::paper()?))?;
//! let m = Measurement::default(); // from the plant's outputs
//! let report = controller.sample(&m)?; // every T_s
//! let between = controller.command_at(0.5, &m)?; // at every communication step
//! # let _ = (report, between);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![forbid(unsafe_code)]
#![cfg_attr(test, allow(clippy::unwrap_used))]

pub mod config;
pub mod controller;
pub mod error;
pub mod mpc_input;

pub use config::{
    Architecture, AvoidanceScheme, ControllerConfig, InnerLoopParams, TrackingParams,
};
pub use controller::{Command, Controller, Fallback, Measurement, Prediction, SampleReport};
pub use error::{ConfigError, MeasurementError};
pub use mpc_input::MpcInput;
