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
//! // At every communication step: a control sample when one is due (every T_s),
//! // then the command with the tugs' inner loop.
//! let step = controller.step(0.0, &m)?;
//! assert!(step.sample.is_some());
//! let between = controller.step(0.1, &m)?;
//! assert!(between.sample.is_none());
//! # let _ = (step.command, between.command);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![forbid(unsafe_code)]
#![cfg_attr(test, allow(clippy::unwrap_used))]

pub mod config;
pub mod controller;
pub mod error;
pub mod mpc_input;
pub mod params;

pub use config::{
    Architecture, AvoidanceScheme, ControllerConfig, InnerLoopParams, PredictionHulls,
    TrackingParams, Tuning, WaterwaySettings,
};
pub use controller::{
    centralized_mpc, mpc_params, Command, Controller, ControllerState, Fallback, Measurement,
    Overlap, Prediction, Rest, SampleReport, Step, StepError, SAMPLE_TOLERANCE,
};
pub use error::{ConfigError, MeasurementError};
pub use mpc_input::MpcInput;
pub use params::{Parameter, Value, PARAMETERS};
