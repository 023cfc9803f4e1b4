//! The towing controller as an FMI 2.0 Co-Simulation FMU (modelIdentifier `TowingController`).
//!
//! Thin by design: the variable table ([`variables`]) and the table of the diagnostic
//! outputs ([`diagnostics`]), the [`Fmi2Model`](fmi2_slave::Fmi2Model)
//! implementation forwarding to the pure controller of `towing-control` ([`controller`]),
//! and one `export_fmi2!` that generates the 34 exported FMI functions. Every line of
//! `unsafe` lives in `fmi2-slave`; this crate denies it.
#![deny(unsafe_code)]

pub mod controller;
pub mod diagnostics;
pub mod logging;
pub mod variables;

pub use controller::ControllerFmu;

fmi2_slave::export_fmi2!(ControllerFmu);
